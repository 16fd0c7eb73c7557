//! Accuracy of meshtrim's BPD and of a peer (Open3D) on the synthetic
//! clouds with ground truth of `docs/results.md`'s accuracy table, scored
//! the same way (`testkit::evaluate`). Used by `bench/accuracy.sh`:
//!
//! ```text
//! cargo run --release --example accuracy_peer -- write DIR
//! (the peer writes DIR/NAME.RULE.labels, one 0 or 1 per point)
//! cargo run --release --example accuracy_peer -- score DIR RULE...
//! ```
//!
//! `write` writes each cloud as `DIR/NAME.xyz` (x y z per line, every bit
//! kept). `score` regenerates the same seeded clouds, runs meshtrim's
//! detection with its defaults, reads the peer's labels for each RULE (the
//! peer's search-radius rule) and prints a markdown table of precision,
//! recall and F1 for both, with the ideal first layer's as the ceiling.

use std::fmt::Write as _;
use std::path::Path;

use anyhow::{bail, Context};
use testkit::{
    evaluate::{ideal_first_layer, precision_recall, Accuracy},
    synthetic::{self, SyntheticCloud},
};
use trim::{detect_boundary, BpdOptions};

/// A cloud as given to both detectors: its points with out-of-plane
/// noise of `noise` (a fraction of the local resolution, the paper's p;
/// `SyntheticCloud::with_noise`, pattern 7), then rotated when `rotated`
/// is set. Scores are taken on the original points, where the truth is.
struct Case {
    key: String,
    cloud: SyntheticCloud,
    noise: f64,
    rotated: bool,
}

impl Case {
    fn points(&self) -> Vec<[f64; 3]> {
        let noisy = self.cloud.with_noise(self.noise, 7);
        if self.rotated {
            noisy.into_iter().map(generic_rotation).collect()
        } else {
            noisy
        }
    }

    fn name(&self) -> String {
        let mut name = self.cloud.name.clone();
        if self.noise > 0.0 {
            name += &format!(", noise {} %", self.noise * 100.0);
        }
        if self.rotated {
            name += ", rotated";
        }
        name
    }
}

/// Every cloud; a generically rotated copy of those that lie in the plane
/// z = 0 (Open3D finds no boundary there, so the rotated copy shows what
/// it finds otherwise); and the decimated 8 mm blade and variable-density
/// blade with the paper's noise at 25 % and 75 %.
fn cases() -> Vec<Case> {
    let mut cases = Vec::new();
    let mut rotated = Vec::new();
    let mut noisy = Vec::new();
    for (key, cloud) in clouds() {
        if cloud.points.iter().all(|p| p[2] == 0.0) {
            rotated.push(Case {
                key: format!("{key}_rotated"),
                cloud: cloud.clone(),
                noise: 0.0,
                rotated: true,
            });
        }
        if key == "blade_8_decimated" || key == "variable_density_decimated" {
            for percent in [25, 75] {
                noisy.push(Case {
                    key: format!("{key}_noise_{percent}"),
                    cloud: cloud.clone(),
                    noise: f64::from(percent) / 100.0,
                    rotated: false,
                });
            }
        }
        cases.push(Case {
            key,
            cloud,
            noise: 0.0,
            rotated: false,
        });
    }
    cases.extend(rotated);
    cases.extend(noisy);
    cases
}

/// A rotation by 0.7 rad about the axis (1, 2, 3) (Rodrigues' formula).
fn generic_rotation(p: [f64; 3]) -> [f64; 3] {
    let norm = 14f64.sqrt();
    let k = [1.0 / norm, 2.0 / norm, 3.0 / norm];
    let (sin, cos) = 0.7f64.sin_cos();
    let cross = [
        k[1] * p[2] - k[2] * p[1],
        k[2] * p[0] - k[0] * p[2],
        k[0] * p[1] - k[1] * p[0],
    ];
    let dot = k[0] * p[0] + k[1] * p[1] + k[2] * p[2];
    [0, 1, 2].map(|i| p[i] * cos + cross[i] * sin + k[i] * dot * (1.0 - cos))
}

/// The clouds of the accuracy table, with a file-name-safe key each.
fn clouds() -> Vec<(String, SyntheticCloud)> {
    let mut clouds = vec![
        (
            "plane_holes".to_string(),
            synthetic::plane_with_holes(1.0, 1),
        ),
        (
            "notched_plate".to_string(),
            synthetic::notched_plate(1.0, 2),
        ),
        ("saddle".to_string(), synthetic::saddle_with_hole(1.5, 3)),
        (
            "cylinder".to_string(),
            synthetic::cylinder_with_hole(1.5, 4),
        ),
    ];
    for (h, seed) in [4.0, 8.0, 16.0, 34.0].into_iter().zip(10..) {
        clouds.push((format!("blade_{h}"), synthetic::blade(h, seed)));
    }
    for (h, seed) in [4.0, 8.0, 16.0, 34.0].into_iter().zip(10..) {
        let cloud = synthetic::decimated_blade(h, seed);
        clouds.push((format!("blade_{h}_decimated"), cloud));
    }
    clouds.push((
        "variable_density".to_string(),
        synthetic::variable_density(3.4, 5),
    ));
    clouds.push((
        "variable_density_decimated".to_string(),
        synthetic::decimated_variable_density(3.4, 5),
    ));
    clouds.push(("flat_grid".to_string(), synthetic::flat_grid(1.0)));
    for (i, ratio) in [3.0, 4.0].into_iter().enumerate() {
        let cloud = synthetic::line_scan(ratio, 20f64.to_radians(), 1.0, 20 + i as u64);
        clouds.push((format!("line_scan_1_{ratio}"), cloud));
    }
    clouds
}

fn main() -> anyhow::Result<()> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [mode, dir] if mode == "write" => write_clouds(Path::new(dir)),
        [mode, dir, rules @ ..] if mode == "score" && !rules.is_empty() => {
            print!("{}", score_table(Path::new(dir), rules)?);
            Ok(())
        }
        _ => bail!("usage: accuracy_peer write DIR | accuracy_peer score DIR RULE..."),
    }
}

fn write_clouds(dir: &Path) -> anyhow::Result<()> {
    std::fs::create_dir_all(dir)?;
    for case in cases() {
        let mut text = String::with_capacity(case.cloud.len() * 64);
        for [x, y, z] in case.points() {
            // `{:?}` round-trips every f64 bit.
            writeln!(text, "{x:?} {y:?} {z:?}")?;
        }
        std::fs::write(dir.join(format!("{}.xyz", case.key)), text)?;
    }
    Ok(())
}

fn score_table(dir: &Path, rules: &[String]) -> anyhow::Result<String> {
    let mut table = String::from("| cloud | points | ideal layer P / R | meshtrim P / R / F1 |");
    for rule in rules {
        write!(table, " Open3D ({rule}) P / R / F1 |")?;
    }
    table.push_str("\n|---|---:|---|---|");
    table.push_str(&"---|".repeat(rules.len()));
    table.push('\n');
    for case in cases() {
        let cloud = &case.cloud;
        let ideal = precision_recall(&cloud.points, &ideal_first_layer(cloud), cloud);
        let ours = detect_boundary(&case.points(), &BpdOptions::default())?;
        let ours = precision_recall(&cloud.points, &ours.boundary, cloud);
        write!(
            table,
            "| {} | {} | {:.3} / {:.3} | {} |",
            case.name(),
            cloud.len(),
            ideal.precision,
            ideal.recall,
            scores(&ours)
        )?;
        for rule in rules {
            let path = dir.join(format!("{}.{rule}.labels", case.key));
            let labels = read_labels(&path, cloud.len())?;
            let theirs = precision_recall(&cloud.points, &labels, cloud);
            write!(table, " {} |", scores(&theirs))?;
        }
        table.push('\n');
    }
    Ok(table)
}

/// "P / R / F1 (n)", n the number of points labelled boundary.
fn scores(a: &Accuracy) -> String {
    format!(
        "{:.3} / {:.3} / {:.3} ({})",
        a.precision, a.recall, a.f1, a.detected
    )
}

fn read_labels(path: &Path, points: usize) -> anyhow::Result<Vec<bool>> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    let labels = text
        .lines()
        .enumerate()
        .map(|(i, line)| match line.trim() {
            "0" => Ok(false),
            "1" => Ok(true),
            other => bail!(
                "{}: line {}: {other:?} is not 0 or 1",
                path.display(),
                i + 1
            ),
        })
        .collect::<anyhow::Result<Vec<bool>>>()?;
    if labels.len() != points {
        bail!(
            "{}: {} labels for {points} points",
            path.display(),
            labels.len()
        );
    }
    Ok(labels)
}
