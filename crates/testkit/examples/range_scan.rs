//! BPD on synthetic range scans: the blade seen by a depth camera whose
//! line of sight is inclined to the surface, with its depth quantised
//! (terraces) or noisy along the line of sight; precision and recall
//! against the true boundary with the paper's projection (along the
//! normal) and with the projection along the line of sight
//! (`BpdOptions::view`).
//!
//! `cargo run --release -p meshtrim-testkit --example range_scan`

use testkit::{
    evaluate::precision_recall,
    synthetic::{blade_with_jitter, tilted, SyntheticCloud, P3},
};
use trim::{detect_boundary, BpdOptions, View};

fn main() {
    println!("| cloud | incidence | depth | map | P / R along the normal | P / R along the line of sight |");
    println!("|---|---|---|---|---|---|");
    for (h, jitter, seed) in [
        (4.0, 0.0, 10),
        (4.0, 0.05, 10),
        (4.0, 0.15, 10),
        (8.0, 0.15, 11),
    ] {
        let truth = blade_with_jitter(h, jitter, seed);
        let normal = truth.mean_normal();
        for incidence in [0.0f64, 20.0, 40.0, 60.0] {
            let sight = tilted(normal, incidence.to_radians());
            for (label, points) in disturbed(&truth, sight, h) {
                for anisotropy in [true, false] {
                    let row = [None, Some(View::Along(sight))].map(|view| {
                        let options = BpdOptions {
                            anisotropy,
                            view,
                            ..BpdOptions::default()
                        };
                        let found = detect_boundary(&points, &options).expect("detect");
                        let a = precision_recall(&truth.points, &found.boundary, &truth);
                        format!("{:.3} / {:.3}", a.precision, a.recall)
                    });
                    let map = if anisotropy { "on" } else { "off" };
                    println!(
                        "| {} | {incidence}° | {label} | {map} | {} | {} |",
                        truth.name, row[0], row[1]
                    );
                }
            }
        }
    }
}

/// The cloud seen along `sight`: depth rounded to 0.5 and 1 spacing, and
/// uniform depth noise of ±50 % of the spacing.
fn disturbed(truth: &SyntheticCloud, sight: P3, h: f64) -> Vec<(String, Vec<P3>)> {
    vec![
        (
            "levels 0.5 h".into(),
            truth.with_quantised_depth(sight, 0.5 * h),
        ),
        ("levels 1 h".into(), truth.with_quantised_depth(sight, h)),
        (
            "levels 1.5 h".into(),
            truth.with_quantised_depth(sight, 1.5 * h),
        ),
        ("noise ±0.5 h".into(), truth.with_depth_noise(sight, 0.5, 7)),
    ]
}
