//! Helpers shared by the CLI integration tests: run the binary, check failures.
#![allow(dead_code)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `flapssm ARGS` and collects its output.
pub fn flapssm(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .args(args)
        .output()
        .expect("run flapssm")
}

/// Runs `flapssm ARGS`, asserting success; returns stdout.
pub fn ok(args: &[&str]) -> String {
    let o = flapssm(args);
    assert!(
        o.status.success(),
        "flapssm {args:?} failed: {}",
        String::from_utf8_lossy(&o.stderr)
    );
    String::from_utf8_lossy(&o.stdout).into_owned()
}

/// Parses the JSON file at `path`, naming it on failure.
pub fn json(path: &Path) -> serde_json::Value {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// A path as `&str`.
pub fn s(p: &Path) -> &str {
    p.to_str().expect("UTF-8 path")
}

/// The shared reference directory `shared/reference/<name>`.
pub fn reference(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference")
        .join(name)
}

/// Asserts exit code 1 (not a panic, not a usage error), a message on stderr containing
/// each of `needles`, that `out` does not exist and that no temporary file is left next to it.
pub fn assert_fails(o: &Output, needles: &[&str], out: &Path) {
    let err = String::from_utf8_lossy(&o.stderr);
    assert_eq!(o.status.code(), Some(1), "stderr: {err}");
    assert!(err.starts_with("error: "), "{err}");
    for n in needles {
        assert!(err.contains(n), "stderr lacks {n:?}: {err}");
    }
    assert!(!err.contains("panicked"), "{err}");
    assert!(!out.exists(), "{} was written", out.display());
    if let Some(dir) = out.parent().filter(|d| d.is_dir()) {
        let leftovers = temporaries(dir);
        assert!(leftovers.is_empty(), "temporary files left: {leftovers:?}");
    }
}

/// The temporary files (`*.tmp`) in `dir`.
pub fn temporaries(dir: &Path) -> Vec<PathBuf> {
    std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .map(|e| e.path())
        .filter(|p| p.to_string_lossy().ends_with(".tmp"))
        .collect()
}

/// A small simulated dataset with outputs (quasi-steady aerodynamics, sensor model):
/// `n` trajectories of 470 samples.
pub fn simulated(dir: &Path, n: usize, seed: u64) -> PathBuf {
    let out = dir.join(format!("sim{n}_{seed}.npz"));
    ok(&[
        "simulate",
        "--n",
        &n.to_string(),
        "--seed",
        &seed.to_string(),
        "--fidelity",
        "l0",
        "--quiet",
        "--out",
        s(&out),
    ]);
    out
}

/// Reads a CSV of numbers with one header line: (header, rows).
pub fn read_csv(path: &Path) -> (Vec<String>, Vec<Vec<f64>>) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut lines = text.lines();
    let header = lines
        .next()
        .unwrap()
        .split(',')
        .map(str::to_string)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(|v| v.parse().unwrap()).collect())
        .collect();
    (header, rows)
}
