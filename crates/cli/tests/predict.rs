//! `flapssm predict MODEL DATASET --out PRED.npz`: arrays, shapes, exact first step,
//! reproducibility (seed, thread count) and refusals.

mod common;

use std::path::{Path, PathBuf};
use std::process::Command;

use common::{assert_fails, flapssm, ok, reference, s, simulated};
use flapssm_data::npz::NpzReader;
use flapssm_wing::dataset::Dataset;

const T: usize = 470;

fn published_model(dir: &Path) -> PathBuf {
    let out = dir.join("published.json");
    ok(&[
        "model",
        "import-published",
        s(&reference("bayiz2021-prssm/reference.npz")),
        "--out",
        s(&out),
    ]);
    out
}

fn predict_with_threads(threads: &str, args: &[&str]) {
    let o = Command::new(env!("CARGO_BIN_EXE_flapssm"))
        .arg("predict")
        .args(args)
        .env("RAYON_NUM_THREADS", threads)
        .output()
        .unwrap();
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
}

/// The published model (no normalization statistics) on a simulated dataset: documented
/// arrays and shapes; `y` and `is_train` copied from the dataset; at step 0 every particle
/// is at x₀ = 0, so the output mean is the dataset's training mean of y and the variance is
/// σ_y² · std_y² (the model's standardized noise in raw units); same seed and any thread
/// count → identical bytes; another seed → another draw.
#[test]
fn published_model_on_a_dataset_writes_the_documented_arrays() {
    let dir = tempfile::tempdir().unwrap();
    let model = published_model(dir.path());
    let data = simulated(dir.path(), 5, 3);
    let ds = Dataset::load(&data).unwrap();
    let stats = ds.standardization().unwrap();
    let n = ds.len();

    let pred = dir.path().join("pred.npz");
    let args = [
        s(&model),
        s(&data),
        "--particles",
        "8",
        "--seed",
        "4",
        "--out",
        s(&pred),
    ];
    let o = flapssm(&[&["predict"], &args[..]].concat());
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("no normalization statistics"), "{err}");

    let mut r = NpzReader::open(&pred).unwrap();
    let mut names = r.names();
    names.sort();
    assert_eq!(
        names,
        [
            "is_train",
            "latent_mean",
            "latent_var",
            "output_mean",
            "output_var",
            "y"
        ]
    );
    let mean = r.f64_shaped("output_mean", &[n, T, 5]).unwrap();
    let var = r.f64_shaped("output_var", &[n, T, 5]).unwrap();
    let lmean = r.f64_shaped("latent_mean", &[n, T, 12]).unwrap();
    let lvar = r.f64_shaped("latent_var", &[n, T, 12]).unwrap();
    let y = r.f64_shaped("y", &[n, T, 5]).unwrap();
    let is_train = r.f64_shaped("is_train", &[n]).unwrap();
    let y_ds: Vec<f64> = ds
        .trajectories
        .iter()
        .flat_map(|t| t.outputs.as_ref().unwrap().iter().flatten().copied())
        .collect();
    assert_eq!(y, y_ds);
    let train: Vec<f64> = (0..n)
        .map(|i| f64::from(u8::from(i < ds.n_train)))
        .collect();
    assert_eq!(is_train, train);
    assert!(var.iter().chain(&lvar).all(|v| *v > 0.0 && v.is_finite()));
    assert!(mean.iter().chain(&lmean).all(|v| v.is_finite()));

    let mut rr = NpzReader::open(reference("bayiz2021-prssm/reference.npz")).unwrap();
    let var_y = rr.f64_shaped("param_var_y", &[5]).unwrap();
    for i in 0..n {
        let o = i * T * 5;
        for j in 0..5 {
            let (m_exp, v_exp) = (stats.mean_y[j], var_y[j] * stats.std_y[j].powi(2));
            assert!((mean[o + j] - m_exp).abs() <= 1e-12 * m_exp.abs().max(1.0));
            assert!((var[o + j] - v_exp).abs() <= 1e-12 * v_exp);
        }
        assert!(lmean[i * T * 12..i * T * 12 + 12].iter().all(|&m| m == 0.0));
    }

    let bytes = std::fs::read(&pred).unwrap();
    for threads in ["1", "3"] {
        let again = dir.path().join(format!("again{threads}.npz"));
        let mut a = args;
        a[7] = s(&again);
        predict_with_threads(threads, &a);
        assert!(
            std::fs::read(&again).unwrap() == bytes,
            "{threads} threads differ"
        );
    }
    // The --threads flag sizes the pool explicitly: same bytes.
    for threads in ["1", "3"] {
        let again = dir.path().join(format!("flag{threads}.npz"));
        let mut a = args;
        a[7] = s(&again);
        ok(&[&["--threads", threads, "predict"], &a[..]].concat());
        assert!(
            std::fs::read(&again).unwrap() == bytes,
            "--threads {threads} differs"
        );
    }
    let other = dir.path().join("other.npz");
    let mut a = args;
    a[5] = "5";
    a[7] = s(&other);
    predict_with_threads("2", &a);
    let m2 = NpzReader::open(&other)
        .unwrap()
        .f64_shaped("output_mean", &[n, T, 5])
        .unwrap();
    assert!(m2 != mean, "another seed gave the same draw");
}

/// A kinematics-only dataset has no output statistics to de-standardize the published
/// model's outputs: refused, naming both files.
#[test]
fn published_model_on_a_kinematics_dataset_is_refused() {
    let dir = tempfile::tempdir().unwrap();
    let model = published_model(dir.path());
    let kin = dir.path().join("kin.npz");
    ok(&["trajectories", "--n", "3", "--seed", "1", "--out", s(&kin)]);
    let out = dir.path().join("pred.npz");
    let o = flapssm(&["predict", s(&model), s(&kin), "--out", s(&out)]);
    assert_fails(&o, &[s(&model), s(&kin), "no outputs"], &out);
}

#[test]
fn zero_particles_is_a_usage_error() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("pred.npz");
    let o = flapssm(&[
        "predict",
        "m.json",
        "d.npz",
        "--particles",
        "0",
        "--out",
        s(&out),
    ]);
    assert_eq!(o.status.code(), Some(2));
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(err.contains("--particles") && err.contains(">= 1"), "{err}");
    assert!(!out.exists());
}
