//! `examples/c/replay.c`, built against `libflapssm_c.a` and `include/flapssm.h`, replays the
//! published model's reference trajectory; its output equals the Rust streaming predictor's
//! to 1e-12 in double precision, and the float interface stays within float rounding.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{DU, T, inputs, published_model};
use flapssm_jobs::stream::{LoadStream, StreamSettings};

fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Builds the static library (the test harness builds only the rlib) and the C example.
fn build_example(dir: &Path) -> PathBuf {
    let mut cargo = Command::new(env!("CARGO"));
    cargo.args(["build", "-q", "-p", "flapssm-capi", "--lib"]);
    if !cfg!(debug_assertions) {
        cargo.arg("--release");
    }
    assert!(
        cargo.status().unwrap().success(),
        "cargo build -p flapssm-capi"
    );
    // target/<profile>/deps/c_example-… → target/<profile>
    let exe = std::env::current_exe().unwrap();
    let lib = exe
        .parent()
        .unwrap()
        .parent()
        .unwrap()
        .join("libflapssm_c.a");
    let out = dir.join("replay");
    let root = workspace();
    let status = Command::new(std::env::var("CC").unwrap_or_else(|_| "cc".into()))
        .args(["-O2", "-std=c11", "-Wall", "-Wextra", "-Werror", "-I"])
        .arg(root.join("crates/capi/include"))
        .arg(root.join("examples/c/replay.c"))
        .arg(&lib)
        .args(["-lm", "-lpthread", "-ldl", "-o"])
        .arg(&out)
        .status()
        .expect("a C compiler (cc)");
    assert!(status.success(), "compiling examples/c/replay.c");
    out
}

/// The rows (`step,mean…,var…`) the example prints.
fn run(replay: &Path, args: &[&str]) -> Vec<Vec<f64>> {
    let o = Command::new(replay).args(args).output().unwrap();
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(o.status.success(), "{args:?}: {err}");
    assert!(err.contains("us per step"), "{err}");
    String::from_utf8(o.stdout)
        .unwrap()
        .lines()
        .skip(1)
        .map(|l| l.split(',').skip(1).map(|v| v.parse().unwrap()).collect())
        .collect()
}

/// The Rust stream's rows on `u`.
fn rust_rows(model: &flapssm_prssm::PrssmModel, u: &[f64]) -> Vec<Vec<f64>> {
    let settings = StreamSettings {
        particles: 30,
        seed: 4,
    };
    let mut stream = LoadStream::new(model, &settings).unwrap();
    u.chunks_exact(DU)
        .map(|ut| {
            let (m, v) = stream.step(ut).unwrap();
            [m, v].concat()
        })
        .collect()
}

fn max_relative(a: &[Vec<f64>], b: &[Vec<f64>]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .flatten()
        .zip(b.iter().flatten())
        .map(|(x, y)| (x - y).abs() / y.abs().max(1e-300))
        .fold(0.0, f64::max)
}

#[test]
fn the_c_example_matches_the_rust_stream() {
    let dir = tempfile::tempdir().unwrap();
    let (model, model_path) = published_model(dir.path());
    let u = inputs();
    let csv = dir.path().join("u.csv");
    let mut text = String::from("aoa,speed,a_x,a_y,a_z,pitch_rate,pitch_acc\n");
    for row in u.chunks_exact(DU) {
        let cells: Vec<String> = row.iter().map(|v| format!("{v:?}")).collect();
        text.push_str(&(cells.join(",") + "\n"));
    }
    std::fs::write(&csv, text).unwrap();
    let replay = build_example(dir.path());
    let (m, c) = (model_path.to_str().unwrap(), csv.to_str().unwrap());

    let expected = rust_rows(&model, &u);
    let c64 = run(&replay, &[m, c, "--particles", "30", "--seed", "4"]);
    assert_eq!(c64.len(), T);
    let rel64 = max_relative(&c64, &expected);
    assert!(rel64 <= 1e-12, "f64: relative difference {rel64:e}");

    // The float interface rounds the inputs and the moments: against the Rust stream fed the
    // same rounded inputs it differs by the moments' rounding only.
    let u32: Vec<f64> = u.iter().map(|&v| f64::from(v as f32)).collect();
    let expected32 = rust_rows(&model, &u32);
    let c32 = run(
        &replay,
        &[m, c, "--particles", "30", "--seed", "4", "--f32"],
    );
    let rel32 = max_relative(&c32, &expected32);
    assert!(
        rel32 <= 2.0f64.powi(-24),
        "f32: relative difference {rel32:e}"
    );
    let drift = max_relative(&c32, &expected);

    // The single-precision stream: the same draws, float arithmetic. Its means differ from
    // the double-precision stream's (fed the same rounded inputs) by a small fraction of the
    // predictive standard deviation, its variances by a small relative amount.
    let native = run(
        &replay,
        &[m, c, "--particles", "30", "--seed", "4", "--f32-native"],
    );
    let (mut mean_sd, mut var_rel) = (0.0f64, 0.0f64);
    for (a, b) in native.iter().zip(&expected32) {
        for k in 0..5 {
            mean_sd = mean_sd.max((a[k] - b[k]).abs() / b[5 + k].sqrt());
            var_rel = var_rel.max((a[5 + k] - b[5 + k]).abs() / b[5 + k]);
        }
    }
    assert!(mean_sd <= 1e-3, "f32 native: |Δmean| {mean_sd:e} σ");
    assert!(var_rel <= 1e-2, "f32 native: variance relative {var_rel:e}");
    println!(
        "C example: f64 max relative difference {rel64:e}; f32 I/O {rel32:e} (same rounded \
         inputs), {drift:e} against unrounded inputs; f32 native |Δmean| ≤ {mean_sd:e} σ, \
         variance ≤ {var_rel:e} relative"
    );

    // A reset replays the same draws: the timing mode repeats the first replay.
    let repeated = run(
        &replay,
        &[m, c, "--particles", "30", "--seed", "4", "--repeat", "3"],
    );
    assert_eq!(repeated, c64);
}
