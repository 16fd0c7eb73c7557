//! Accuracy of BPD on synthetic clouds with ground truth
//! (`testkit::synthetic`, scored by `testkit::evaluate`). Run with `--nocapture`
//! to see the measured numbers.

use testkit::{
    evaluate::{
        ideal_first_layer, noise_robustness, noise_robustness_with, percent_sweep, precision_recall,
    },
    synthetic::{self, SyntheticCloud},
};
use trim::{detect_boundary, BpdOptions, View};

const TARGET: f64 = 0.98;

/// Where the ideal first layer itself scores below [`TARGET`] (too few
/// samples per hole or corner, or a ragged first layer), BPD must come this
/// close to the ideal instead; see docs/results.md.
const IDEAL_SLACK: f64 = 0.01;

/// Precision and recall of BPD, and of the ideal first layer.
struct Scores {
    bpd: (f64, f64, f64),
    ideal: (f64, f64),
}

impl Scores {
    /// Each score must reach the target, or the ideal's score less the
    /// slack where the ideal cannot reach the target.
    fn failure(&self, name: &str) -> Option<String> {
        let need = |ideal: f64| TARGET.min(ideal - IDEAL_SLACK);
        let (p, r, _) = self.bpd;
        (p < need(self.ideal.0) || r < need(self.ideal.1)).then(|| {
            format!(
                "{name}: precision {p:.4}, recall {r:.4} (ideal layer {:.4} / {:.4})",
                self.ideal.0, self.ideal.1
            )
        })
    }
}

/// Detects with the default options, prints the scores (and the ideal
/// first layer's) and returns them.
fn scores(cloud: &SyntheticCloud) -> Scores {
    let det = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
    let a = precision_recall(&cloud.points, &det.boundary, cloud);
    let ideal = precision_recall(&cloud.points, &ideal_first_layer(cloud), cloud);
    let mean_beta = det.beta.iter().sum::<f64>() / det.beta.len() as f64;
    let mean_h = cloud.spacing.iter().sum::<f64>() / cloud.len() as f64;
    eprintln!(
        "{:<36} n={:>6} detected={:>5} precision={:.4} recall={:.4} f1={:.4} | ideal layer: n={:>5} precision={:.4} recall={:.4} | mean β/h={:.3}",
        cloud.name,
        cloud.len(),
        a.detected,
        a.precision,
        a.recall,
        a.f1,
        ideal.detected,
        ideal.precision,
        ideal.recall,
        mean_beta / mean_h,
    );
    Scores {
        bpd: (a.precision, a.recall, a.f1),
        ideal: (ideal.precision, ideal.recall),
    }
}

/// Detects with the default options, prints the scores and returns
/// (precision, recall, f1).
fn score(cloud: &SyntheticCloud) -> (f64, f64, f64) {
    scores(cloud).bpd
}

fn assert_accurate(cloud: &SyntheticCloud) {
    if let Some(failure) = scores(cloud).failure(&cloud.name) {
        panic!("{failure}");
    }
}

#[test]
fn plane_with_holes_of_2_4_8_beta() {
    assert_accurate(&synthetic::plane_with_holes(1.0, 1));
}

#[test]
fn notched_plate() {
    assert_accurate(&synthetic::notched_plate(1.0, 2));
}

#[test]
fn saddle_with_hole() {
    assert_accurate(&synthetic::saddle_with_hole(1.5, 3));
}

#[test]
fn cylinder_with_hole() {
    assert_accurate(&synthetic::cylinder_with_hole(1.5, 4));
}

#[test]
fn blade_at_4_8_16_34_mm() {
    assert_blades_accurate(synthetic::blade);
}

/// Blue noise as the paper's clouds were made: a dense scan decimated by
/// Poisson-disk elimination ([`synthetic::decimated_blade`]), not a lattice.
#[test]
fn blade_decimated_as_the_papers_were_at_4_8_16_34_mm() {
    assert_blades_accurate(synthetic::decimated_blade);
}

/// The paper's four blade resolutions, sampling seeds 10–13, all scored
/// before any failure is reported.
fn assert_blades_accurate(blade: fn(f64, u64) -> SyntheticCloud) {
    let mut failures = Vec::new();
    for (h, seed) in [4.0, 8.0, 16.0, 34.0].into_iter().zip(10..) {
        let cloud = blade(h, seed);
        failures.extend(scores(&cloud).failure(&cloud.name));
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Every one of ten samplings per resolution (seeds 1–10), both ways of
/// sampling: F1 ≥ 0.98, or, where the sampling itself cannot give it (the
/// ideal first layer's F1 below 0.99), within 0.01 of the ideal layer's.
/// Measured (`cargo run --release --example sampling_sweep`): decimated
/// 0.9953–1.0 over all 40; lattice 0.9829–0.9995 but the 34 mm seed 9
/// (100 points), 0.9697 where the ideal layer reaches 0.9699.
#[test]
fn blades_over_ten_samplings_per_resolution() {
    let mut failures = Vec::new();
    for blade in [synthetic::blade, synthetic::decimated_blade] {
        for h in [4.0, 8.0, 16.0, 34.0] {
            for seed in 1..=10 {
                let cloud = blade(h, seed);
                let det = detect_boundary(&cloud.points, &BpdOptions::default()).unwrap();
                let f1 = precision_recall(&cloud.points, &det.boundary, &cloud).f1;
                let ideal = precision_recall(&cloud.points, &ideal_first_layer(&cloud), &cloud).f1;
                if f1 < TARGET.min(ideal - IDEAL_SLACK) {
                    failures.push(format!(
                        "{} seed {seed}: F1 {f1:.4} (ideal {ideal:.4})",
                        cloud.name
                    ));
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// On the jittered lattice the graded columns leave a ragged first layer
/// (the ideal layer's precision is 0.98–0.99, docs/results.md), so the
/// slack rule applies.
#[test]
fn variable_density_x10() {
    assert_accurate(&synthetic::variable_density(3.4, 5));
}

/// The variable-density case with blue-noise sampling
/// ([`synthetic::decimated_variable_density`]): 3.4 → 34 mm, where the
/// ideal layer scores 1.0, so BPD must reach the target itself, with no
/// slack, on each of three sampling seeds.
#[test]
fn variable_density_x10_decimated_reaches_the_target_without_slack() {
    let mut failures = Vec::new();
    for seed in [5, 6, 7] {
        let cloud = synthetic::decimated_variable_density(3.4, seed);
        let (p, r, _) = score(&cloud);
        if p < TARGET || r < TARGET {
            failures.push(format!("seed {seed}: precision {p:.4}, recall {r:.4}"));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

#[test]
fn exactly_flat_perfect_grid() {
    let cloud = synthetic::flat_grid(1.0);
    assert!(cloud.points.iter().all(|p| p[2] == 0.0));
    assert_accurate(&cloud);
}

#[test]
fn line_scans_1_to_3_and_1_to_4_at_20_degrees() {
    let mut failures = Vec::new();
    for (i, ratio) in [3.0, 4.0].into_iter().enumerate() {
        let cloud = synthetic::line_scan(ratio, 20f64.to_radians(), 1.0, 20 + i as u64);
        let (p, r, f1) = score(&cloud);
        if f1 < TARGET {
            failures.push(format!(
                "{}: precision {p:.4}, recall {r:.4}, F1 {f1:.4}",
                cloud.name
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Depth-camera scans: the blade seen at 40° from its mean normal, depth
/// (or range, from a camera 3 m away) rounded to levels 1.5 spacings apart,
/// which leaves terraces. Projected along each neighbourhood's normal, the
/// terraces open gaps between their rows and most interior points turn
/// boundary (precision 0.12–0.29 measured); projected along the line of
/// sight (`BpdOptions::view`) the target holds.
#[test]
fn range_scans_with_quantised_depth_seen_along_the_line_of_sight() {
    let mut failures = Vec::new();
    for (h, jitter, seed) in [(4.0, 0.05, 40), (8.0, synthetic::JITTER, 41)] {
        let truth = synthetic::blade_with_jitter(h, jitter, seed);
        for scan in synthetic::range_scans(&truth, h) {
            let (what, points) = (scan.scanner, &scan.points);
            let [normal, along_sight] = [None, Some(scan.view)].map(|view| {
                let options = BpdOptions {
                    view,
                    ..BpdOptions::default()
                };
                let found = detect_boundary(points, &options).unwrap();
                precision_recall(&truth.points, &found.boundary, &truth)
            });
            eprintln!(
                "{} {what}: along normals P {:.4} R {:.4}; along the line of sight P {:.4} R {:.4}",
                truth.name,
                normal.precision,
                normal.recall,
                along_sight.precision,
                along_sight.recall
            );
            if along_sight.precision < TARGET || along_sight.recall < TARGET {
                failures.push(format!("{} {what}: {along_sight:?}", truth.name));
            }
            // The case must exercise the problem the view solves.
            if normal.precision > 0.5 {
                failures.push(format!(
                    "{} {what}: along normals P {:.4}, no terraces?",
                    truth.name, normal.precision
                ));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Rotation about a generic axis, translation, uniform scale.
fn transform(points: &[[f64; 3]], scale: f64, shift: [f64; 3], rotate: bool) -> Vec<[f64; 3]> {
    let (axis, angle) = ([0.36f64, -0.48, 0.8], 0.7f64); // unit axis
    let (s, c) = angle.sin_cos();
    let [x, y, z] = axis;
    let r = [
        [
            c + x * x * (1.0 - c),
            x * y * (1.0 - c) - z * s,
            x * z * (1.0 - c) + y * s,
        ],
        [
            y * x * (1.0 - c) + z * s,
            c + y * y * (1.0 - c),
            y * z * (1.0 - c) - x * s,
        ],
        [
            z * x * (1.0 - c) - y * s,
            z * y * (1.0 - c) + x * s,
            c + z * z * (1.0 - c),
        ],
    ];
    points
        .iter()
        .map(|p| {
            let q = if rotate {
                [
                    r[0][0] * p[0] + r[0][1] * p[1] + r[0][2] * p[2],
                    r[1][0] * p[0] + r[1][1] * p[1] + r[1][2] * p[2],
                    r[2][0] * p[0] + r[2][1] * p[1] + r[2][2] * p[2],
                ]
            } else {
                *p
            };
            [
                q[0] * scale + shift[0],
                q[1] * scale + shift[1],
                q[2] * scale + shift[2],
            ]
        })
        .collect()
}

#[test]
fn labels_are_invariant_under_rotation_translation_and_scale() {
    let clouds = [
        synthetic::blade(8.0, 30),
        synthetic::plane_with_holes(1.0, 31),
    ];
    let cases: [(&str, f64, [f64; 3], bool); 3] = [
        ("rotation", 1.0, [0.0; 3], true),
        ("translation by 1e5", 1.0, [1e5, -1e5, 1e5], false),
        ("scale ×0.001", 0.001, [0.0; 3], false),
    ];
    let mut report = Vec::new();
    for cloud in &clouds {
        let base = detect_boundary(&cloud.points, &BpdOptions::default())
            .unwrap()
            .boundary;
        for (what, scale, shift, rotate) in cases {
            let moved = transform(&cloud.points, scale, shift, rotate);
            let labels = detect_boundary(&moved, &BpdOptions::default())
                .unwrap()
                .boundary;
            let differ = base.iter().zip(&labels).filter(|(a, b)| a != b).count();
            eprintln!(
                "{} / {what}: {differ} of {} labels differ",
                cloud.name,
                cloud.len()
            );
            report.push((cloud.name.clone(), what, differ, labels == base));
        }
    }
    for (name, what, differ, same) in report {
        assert!(same, "{name} / {what}: {differ} labels differ");
    }
}

/// The paper's noise test (Ω, Ψ against the noise-free detection, swept in
/// steps of 5 % up to 75 %). The requirement: 20 % noise must lose no
/// boundary point and 75 % add no false one on at least one case; all cases
/// are printed. On jittered clouds a single point whose empty circle is
/// within a fraction of a percent of β decides Ω and Ψ, so the test also
/// checks what matters on every case: flips stay in the first two rows
/// (within 2.5 spacings of the true boundary) and at 20 % noise at most 5 %
/// of the boundary points change.
#[test]
fn noise_20_percent_loses_nothing_75_percent_adds_nothing() {
    let cases = [
        synthetic::blade(4.0, 40),
        synthetic::blade(8.0, 41),
        synthetic::blade(16.0, 42),
        synthetic::variable_density(3.4, 5),
    ];
    let options = BpdOptions::default();
    let mut meets_paper = Vec::new();
    let mut failures = Vec::new();
    for cloud in &cases {
        let r = noise_robustness(cloud, &percent_sweep(5.0, 75.0), &options, 7).unwrap();
        eprintln!(
            "{}: Ω = {} %, Ψ = {} %, against the truth Ω = {} %, Ψ = {} % (reference boundary {}); (p, lost, false, false and deep): {:?}",
            cloud.name,
            r.omega,
            r.psi,
            r.omega_truth,
            r.psi_truth,
            r.reference_boundary,
            r.steps
                .iter()
                .map(|s| (s.percent, s.lost, s.false_boundary, s.false_interior))
                .collect::<Vec<_>>()
        );
        if r.omega.percent >= 20.0 && r.psi.percent >= 75.0 {
            meets_paper.push(cloud.name.clone());
        }
        failures.extend(flips_beyond_the_first_rows(cloud, &options, Deep::AnyFlip));
    }
    assert!(
        !meets_paper.is_empty(),
        "no case reaches Ω ≥ 20 %, Ψ ≥ 75 %"
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

/// The paper's noise test on blades made as its clouds were, decimated
/// from a dense scan to the target resolution
/// ([`synthetic::decimated_blade`]), at 4, 8, 16 and 34 mm with two
/// sampling seeds each: 20 % noise must lose no boundary point and 75 %
/// add no false one on at least one blade, and on every blade the points
/// noise turns boundary stay in the first rows (the 4 mm blade with seed
/// 10 has one interior point labelled boundary without noise, 13.8
/// spacings deep, at a sampling gap wider than its β). Measured over five
/// noise patterns (`--example noise_decimated`, docs/results.md), 7 of 40
/// cases reach the paper's Ω ≥ 25 % and Ψ ≥ 75 %, against none of the
/// jittered lattice blades. Against the truth (no stretch of the true
/// border loses its last detected point; no point beyond one spacing of it
/// turns boundary) the paper's numbers must hold at every resolution, on
/// at least one of the two samplings (6 of the 8 blades reach them with
/// this noise pattern; 32 of 40 cases over five patterns).
#[test]
fn noise_on_blades_decimated_as_the_papers_were() {
    let options = BpdOptions::default();
    let mut meets_paper = Vec::new();
    let mut failures = Vec::new();
    for (h, seed) in [4.0, 8.0, 16.0, 34.0].into_iter().zip(10..) {
        let mut meets_paper_against_truth = false;
        for cloud in [seed, seed + 90].map(|s| synthetic::decimated_blade(h, s)) {
            let r = noise_robustness(&cloud, &percent_sweep(5.0, 75.0), &options, 7).unwrap();
            eprintln!(
                "{} ({} points): Ω = {} %, Ψ = {} %, against the truth Ω = {} %, Ψ = {} %",
                cloud.name,
                cloud.len(),
                r.omega,
                r.psi,
                r.omega_truth,
                r.psi_truth
            );
            if r.omega.percent >= 20.0 && r.psi.percent >= 75.0 {
                meets_paper.push(cloud.name.clone());
            }
            meets_paper_against_truth |=
                r.omega_truth.percent >= 25.0 && r.psi_truth.percent >= 75.0;
            failures.extend(flips_beyond_the_first_rows(
                &cloud,
                &options,
                Deep::NewBoundary,
            ));
        }
        if !meets_paper_against_truth {
            failures.push(format!(
                "{h} mm: neither sampling reaches Ω ≥ 25 %, Ψ ≥ 75 % against the truth"
            ));
        }
    }
    assert!(
        !meets_paper.is_empty(),
        "no decimated blade reaches Ω ≥ 20 %, Ψ ≥ 75 %"
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Which flips must stay within the first rows.
#[derive(Clone, Copy, PartialEq)]
enum Deep {
    /// Every changed label.
    AnyFlip,
    /// Only points that noise turned boundary: a point the noise-free
    /// detection labelled boundary deep inside (a sampling gap of the
    /// detector's own scale, as Poisson-disk decimation leaves) may lose
    /// that label anywhere.
    NewBoundary,
}

fn flips_beyond_the_first_rows(
    cloud: &SyntheticCloud,
    options: &BpdOptions,
    deep: Deep,
) -> Vec<String> {
    let index = testkit::synthetic::BoundaryIndex::new(cloud);
    let clean = detect_boundary(&cloud.points, options).unwrap().boundary;
    let boundary_count = clean.iter().filter(|&&b| b).count();
    let mut failures = Vec::new();
    for percent in [20.0, 75.0] {
        let noisy = detect_boundary(&cloud.with_noise(percent / 100.0, 7), options).unwrap();
        let flipped: Vec<usize> = (0..clean.len())
            .filter(|&i| clean[i] != noisy.boundary[i])
            .collect();
        let deepest = flipped
            .iter()
            .filter(|&&i| deep == Deep::AnyFlip || noisy.boundary[i])
            .map(|&i| index.distance(cloud.points[i]) / cloud.spacing[i])
            .fold(0.0, f64::max);
        eprintln!(
            "{} at {percent} %: {} of {boundary_count} boundary points flipped, deepest {deepest:.2} spacings",
            cloud.name,
            flipped.len()
        );
        if deepest > 2.5 {
            failures.push(format!(
                "{} at {percent} %: a flip {deepest:.2} spacings deep",
                cloud.name
            ));
        }
        if percent == 20.0 && flipped.len() * 20 > boundary_count {
            failures.push(format!("{} at 20 %: {} flips", cloud.name, flipped.len()));
        }
    }
    failures
}

/// The paper's noise levels against the truth, over ten samplings per
/// resolution and two noise patterns (decimated blades, seeds 1–10,
/// patterns 7 and 8, along the true normal): Ψ ≥ 75 % in at least nine
/// cases of ten at every resolution, and the median case at Ω ≥ 25 %.
/// Measured (75 is the sweep's end): Ψ ≥ 75 in 20 cases of 20 at 4, 8,
/// 16 and 34 mm; Ω ≥ 25 in 20, 20, 20, 13, medians Ω 75 / 75 / 75 /
/// 35 %. Ω at 34 mm is the limit of 100-point clouds: a border point about
/// 0.7 spacings in whose empty circle exceeds β by under 1 % (docs/results.md,
/// "Ten samplings per resolution").
#[test]
fn noise_over_ten_samplings_and_two_patterns() {
    let options = BpdOptions::default();
    let mut failures = Vec::new();
    for h in [4.0, 8.0, 16.0, 34.0] {
        let (mut omega, mut psi) = (Vec::new(), Vec::new());
        for seed in 1..=10 {
            let cloud = synthetic::decimated_blade(h, seed);
            for pattern in [7, 8] {
                let r =
                    noise_robustness(&cloud, &percent_sweep(5.0, 75.0), &options, pattern).unwrap();
                omega.push(r.omega_truth.percent);
                psi.push(r.psi_truth.percent);
            }
        }
        let median = |v: &mut Vec<f64>| {
            v.sort_unstable_by(f64::total_cmp);
            (v[v.len() / 2 - 1] + v[v.len() / 2]) / 2.0
        };
        let (o, p) = (median(&mut omega), median(&mut psi));
        let psi_reached = psi.iter().filter(|&&x| x >= 75.0).count();
        eprintln!(
            "{h} mm: median Ω {o} %, Ψ {p} %; worst Ω {} %, Ψ {} %; Ψ ≥ 75 in {psi_reached} of 20, Ω ≥ 25 in {} of 20",
            omega[0],
            psi[0],
            omega.iter().filter(|&&x| x >= 25.0).count()
        );
        if o < 25.0 || psi_reached < 18 {
            failures.push(format!(
                "{h} mm: median Ω {o} %, Ψ ≥ 75 in {psi_reached} of 20"
            ));
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Ω and Ψ against the truth over ten samplings per resolution (decimated
/// blades, seeds 1–10, noise pattern 7) with the noisy points of `noisy`
/// (given the cloud and the level), detected with `options_of` the cloud;
/// the failures of the medians to reach Ω ≥ 25 %, Ψ ≥ 75 %.
fn medians_short_of_the_paper(
    kind: &str,
    noisy: impl Fn(&SyntheticCloud, f64) -> Vec<[f64; 3]>,
    options_of: impl Fn(&SyntheticCloud) -> BpdOptions,
) -> Vec<String> {
    let mut failures = Vec::new();
    for h in [4.0, 8.0, 16.0, 34.0] {
        let (mut omega, mut psi) = (Vec::new(), Vec::new());
        for seed in 1..=10 {
            let cloud = synthetic::decimated_blade(h, seed);
            let sweep = percent_sweep(5.0, 75.0);
            let r =
                noise_robustness_with(&cloud, &sweep, &options_of(&cloud), |p| noisy(&cloud, p))
                    .unwrap();
            omega.push(r.omega_truth.percent);
            psi.push(r.psi_truth.percent);
        }
        omega.sort_unstable_by(f64::total_cmp);
        psi.sort_unstable_by(f64::total_cmp);
        let (o, p) = ((omega[4] + omega[5]) / 2.0, (psi[4] + psi[5]) / 2.0);
        eprintln!(
            "{kind}, {h} mm: median Ω {o} %, Ψ {p} %; worst Ω {} %, Ψ {} %",
            omega[0], psi[0]
        );
        if o < 25.0 || p < 75.0 {
            failures.push(format!("{kind}, {h} mm: median Ω {o} %, Ψ {p} %"));
        }
    }
    failures
}

/// The line of sight of a range scanner looking at `cloud` 30° off its
/// mean normal.
fn oblique_sight(cloud: &SyntheticCloud) -> [f64; 3] {
    let [nx, ny, nz] = cloud.mean_normal();
    let (c, s) = (30f64.to_radians().cos(), 30f64.to_radians().sin());
    [c * nx - s * ny, s * nx + c * ny, nz]
}

/// Depth noise along a range scanner's line of sight, 30° off the mean
/// normal, with that line of sight given to detection (`--view-along`):
/// the median case reaches the paper's levels at every resolution.
/// (Without the view, measured: median Ψ 55 % at 4 mm, median Ω 20 % at
/// 34 mm: the noise's component across the normal moves points within
/// the surface.)
#[test]
fn depth_noise_along_a_given_line_of_sight_at_the_median() {
    let failures = medians_short_of_the_paper(
        "line of sight",
        |cloud, p| cloud.with_depth_noise(oblique_sight(cloud), p, 7),
        |cloud| BpdOptions {
            view: Some(View::Along(oblique_sight(cloud))),
            ..BpdOptions::default()
        },
    );
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Noise within the tangent plane (sampling jitter of p spacings) changes
/// the sampling itself, and BPD's gaps with it: the paper's levels, set
/// for noise across the surface, are out of reach. Measured medians: Ω
/// 7.5 / 12.5 / 12.5 / 2.5 %, Ψ 20 / 27.5 / 37.5 / 67.5 % at 4 / 8 / 16 /
/// 34 mm. A strict expected failure: it fails the day the medians reach
/// the levels, and then becomes a plain requirement.
#[test]
#[should_panic(expected = "tangent plane")]
fn noise_in_the_tangent_plane_falls_short_of_the_paper() {
    let failures = medians_short_of_the_paper(
        "tangent plane",
        |cloud, p| cloud.with_tangent_noise(p, 7),
        |_| BpdOptions::default(),
    );
    assert!(failures.is_empty(), "{failures:#?}");
}
