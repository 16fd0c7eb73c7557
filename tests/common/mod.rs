//! Shared helpers of the integration tests.

use std::path::{Path, PathBuf};

/// A real scan by its path under the shared data directory (see its
/// SOURCES.md). The PCL scans are shipped in `fixtures/scans/pcl_test`
/// (BSD-3-Clause); the others are read where `MESHTRIM_SHARED_DATA`
/// points when it is set, else beside the repository or at the
/// workplace's `/work/shared/data` when the repository is a clone
/// elsewhere. The tests that need those are
/// in modules named `shared_data`, which `scripts/test.sh` skips (and
/// lists) when the data is missing, unless `MESHTRIM_REQUIRE_DATA` is set
/// as in CI; run directly without the data, they fail.
#[allow(dead_code)]
pub fn shared_data(rel: &str) -> PathBuf {
    if rel.starts_with("pcl_test/") {
        return PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/fixtures/scans")).join(rel);
    }
    let beside = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../shared/data"));
    let candidates: Vec<PathBuf> = match std::env::var_os("MESHTRIM_SHARED_DATA") {
        Some(dir) => vec![PathBuf::from(dir)],
        None => vec![beside, PathBuf::from("/work/shared/data")],
    };
    let root = candidates.iter().find(|c| c.is_dir()).unwrap_or_else(|| {
        panic!(
            "the real test data is missing: looked in {candidates:?} (set MESHTRIM_SHARED_DATA, \
             or run scripts/test.sh, which lists the tests it cannot run without it)"
        )
    });
    root.join(rel)
}

/// The fixture cloud the `detect` and `edges` tests run on.
#[allow(dead_code)]
pub const BLADE_HOLES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/fixtures/meshes/blade_holes.ply"
);

/// Runs the `meshtrim` binary with `args`, on `threads` rayon threads when
/// given.
#[allow(dead_code)] // each test binary uses its own share of the helpers
pub fn meshtrim(args: &[&str], threads: Option<&str>) -> std::process::Output {
    match threads {
        Some(t) => meshtrim_env(args, &[("RAYON_NUM_THREADS", t)]),
        None => meshtrim_env(args, &[]),
    }
}

/// Runs the `meshtrim` binary with `args` and extra environment variables.
#[allow(dead_code)]
pub fn meshtrim_env(args: &[&str], env: &[(&str, &str)]) -> std::process::Output {
    let mut cmd = std::process::Command::new(env!("CARGO_BIN_EXE_meshtrim"));
    cmd.args(args);
    for (key, value) in env {
        cmd.env(key, value);
    }
    cmd.output().expect("the meshtrim binary runs")
}

/// The bytes `meshtrim args` writes on `threads` threads, `{out}` in
/// `args` standing for a fresh output path in `dir` (named by the thread
/// count and `name`); the run must succeed.
#[allow(dead_code)]
pub fn output_bytes(dir: &Path, args: &[&str], name: &str, threads: &str) -> Vec<u8> {
    let out = dir.join(format!("{threads}-{name}"));
    let args: Vec<&str> = args
        .iter()
        .map(|&a| if a == "{out}" { path_str(&out) } else { a })
        .collect();
    let run = meshtrim_env(&args, &[("RAYON_NUM_THREADS", threads)]);
    assert!(run.status.success(), "{args:?}: {}", stderr(&run));
    std::fs::read(&out).unwrap()
}

/// A run's stderr as text.
#[allow(dead_code)]
pub fn stderr(out: &std::process::Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

/// A temporary path as the `&str` an argument list takes.
#[allow(dead_code)]
pub fn path_str(p: &std::path::Path) -> &str {
    p.to_str().expect("temp paths are UTF-8")
}

/// Asserts a run failed cleanly: exit status 1, one `error: ` message that
/// names `mentions`, no panic.
#[allow(dead_code)]
pub fn assert_clean_failure(out: &std::process::Output, mentions: &str) {
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(1), "{stderr}");
    assert!(stderr.starts_with("error: "), "{stderr}");
    assert!(stderr.contains(mentions), "{stderr} should name {mentions}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}

/// An n × n grid of jittered points at `scale` (a slightly bumpy square
/// panel, deterministic) as OBJ text: `v` lines, then two triangles per
/// cell when `faces`.
#[allow(dead_code)]
pub fn grid_obj(n: usize, scale: f64, faces: bool) -> String {
    // A fixed hash as the jitter, so every scale holds the same shape.
    let jitter = |i: usize, salt: usize| ((i * 7919 + salt * 104_729) % 1000) as f64 / 1000.0;
    let mut text = String::new();
    for j in 0..n {
        for i in 0..n {
            let at = j * n + i;
            let x = (i as f64 + 0.2 * jitter(at, 1) - 0.1) * scale;
            let y = (j as f64 + 0.2 * jitter(at, 2) - 0.1) * scale;
            text += &format!("v {x:e} {y:e} {:e}\n", 0.01 * jitter(at, 3) * scale);
        }
    }
    for j in (0..n - 1).filter(|_| faces) {
        for i in 0..n - 1 {
            let a = j * n + i + 1;
            text += &format!(
                "f {a} {} {}\nf {a} {} {}\n",
                a + 1,
                a + n + 1,
                a + n + 1,
                a + n
            );
        }
    }
    text
}
