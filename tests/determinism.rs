//! The same bytes out whatever the number of threads, on a cloud large
//! enough for every parallel path: 102,400 points, so that detection runs
//! in several blocks of 16,384 points (the block size of its passes) and
//! the per-thread pieces of the readers, the tree and the writers all split.
//! Its ragged variant has its loops traced in the cloud's own plane.

use std::path::{Path, PathBuf};

mod common;
use common::{output_bytes, path_str};

/// A wavy 320 × 330 jittered grid with a round hole, as XYZ text; when
/// `ragged`, points within 4 of the outer edge are kept at random (three
/// in five), so that BPD's links leave the border open.
fn large_cloud(dir: &Path, ragged: bool) -> PathBuf {
    let mut state: u64 = 0x9e37_79b9_7f4a_7c15;
    let mut jitter = || {
        state = state
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        ((state >> 11) as f64 / (1u64 << 53) as f64 - 0.5) * 0.4
    };
    let mut text = String::new();
    for j in 0..320 {
        for i in 0..330 {
            let (x, y) = (i as f64 + jitter(), j as f64 + jitter());
            if (x - 160.0).powi(2) + (y - 160.0).powi(2) < 400.0 {
                continue;
            }
            let edge = x.min(y).min(329.0 - x).min(319.0 - y);
            if ragged && edge < 4.0 && jitter() > 0.04 {
                continue;
            }
            let z = 4.0 * (x / 40.0).sin() * (y / 55.0).cos();
            text.push_str(&format!("{x} {y} {z}\n"));
        }
    }
    let path = dir.join(if ragged { "ragged.xyz" } else { "large.xyz" });
    std::fs::write(&path, text).unwrap();
    path
}

#[test]
fn a_large_cloud_gives_the_same_bytes_on_1_2_and_4_threads() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = large_cloud(dir.path(), false);
    same_bytes_on_1_2_and_4_threads(dir.path(), path_str(&cloud));
}

#[test]
fn a_ragged_cloud_traced_in_its_own_plane_gives_the_same_bytes_on_1_2_and_4_threads() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = large_cloud(dir.path(), true);
    let cloud = path_str(&cloud);
    let out = dir.path().join("summary.json");
    let run = common::meshtrim(&["edges", cloud, "-o", path_str(&out), "--json"], None);
    let summary = String::from_utf8_lossy(&run.stdout);
    assert!(summary.contains(r#""loops_from":"own_plane""#), "{summary}");
    same_bytes_on_1_2_and_4_threads(dir.path(), cloud);
}

#[test]
fn a_range_map_whose_loops_cross_gives_the_same_bytes_on_1_2_and_4_threads() {
    let dir = tempfile::tempdir().unwrap();
    let cloud = common::shared_data("meshlab_scans/lato000.ply");
    let cloud = path_str(&cloud);
    let out = dir.path().join("mesh.ply");
    let run = common::meshtrim(&["mesh", cloud, path_str(&out), "--json"], None);
    let summary: serde_json::Value = serde_json::from_slice(&run.stdout).unwrap();
    assert!(summary["loop_crossings"].as_u64() > Some(0), "{summary}");
    same_bytes_on_1_2_and_4_threads(dir.path(), cloud);
}

/// Detection, edges and the Delaunay mesh of `cloud` give the same bytes
/// on 1, 2 and 4 threads.
fn same_bytes_on_1_2_and_4_threads(dir: &Path, cloud: &str) {
    for (args, name) in [
        (vec!["detect", cloud, "-o", "{out}"], "labels.csv"),
        (vec!["edges", cloud, "-o", "{out}"], "edges.json"),
        (vec!["mesh", cloud, "{out}"], "mesh.ply"),
    ] {
        let one = output_bytes(dir, &args, name, "1");
        assert!(!one.is_empty(), "{name}");
        for threads in ["2", "4"] {
            assert!(
                one == output_bytes(dir, &args, name, threads),
                "{name}: 1 and {threads} threads differ"
            );
        }
    }
}
