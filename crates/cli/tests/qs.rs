//! `flapssm qs …` end to end: scikit-learn conformance through `fit-csv --json`, a dataset
//! fit/predict round trip, and bad input.

mod common;

use std::path::{Path, PathBuf};

use common::{flapssm, json, ok, s};

use flapssm_data::npz::NpzReader;
use flapssm_wing::dataset::{Dataset, DatasetMeta, Trajectory, ValidDataset};
use flapssm_wing::features::published_features;

fn reference() -> PathBuf {
    common::reference("elastic-net/reference.npz")
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v).abs())
        .fold(0.0, f64::max)
}

fn floats(v: &serde_json::Value) -> Vec<f64> {
    match v {
        serde_json::Value::Array(a) => a.iter().flat_map(floats).collect(),
        v => vec![v.as_f64().expect("number")],
    }
}

fn write_csv(path: &Path, header: &[String], rows: impl Iterator<Item = Vec<f64>>) {
    let mut s = header.join(",") + "\n";
    for r in rows {
        s += &r
            .iter()
            .map(|v| v.to_string())
            .collect::<Vec<_>>()
            .join(",");
        s.push('\n');
    }
    std::fs::write(path, s).unwrap();
}

#[test]
fn fit_csv_matches_scikit_learn_reference() {
    let mut r = NpzReader::open(reference()).unwrap();
    let x = r.f64_shaped("X", &[2000, 11]).unwrap();
    let y = r.f64_shaped("y", &[2000]).unwrap();
    let dir = tempfile::tempdir().unwrap();
    let csv = dir.path().join("enet.csv");
    let mut header: Vec<String> = (0..11).map(|j| format!("x{j}")).collect();
    header.push("y".into());
    write_csv(
        &csv,
        &header,
        (0..2000).map(|i| {
            let mut row = x[i * 11..(i + 1) * 11].to_vec();
            row.push(y[i]);
            row
        }),
    );
    let model = dir.path().join("m.json");
    let out = flapssm(&[
        "qs",
        "fit-csv",
        csv.to_str().unwrap(),
        "--targets",
        "y",
        "--out",
        model.to_str().unwrap(),
        "--no-standardize",
        "--no-intercept",
        "--contiguous",
        "--folds",
        "10",
        "--alpha",
        "0.75",
        "--tol",
        "1e-13",
        "--json",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    let t = &v["fit"]["targets"][0];
    let mut check = |key: &str, json: &serde_json::Value| {
        let want = r.f64(key).unwrap().data;
        let d = max_abs_diff(&floats(json), &want);
        assert!(d < 1e-6, "{key} differs by {d}");
    };
    check("coef_path", &t["coef_path"]);
    check("cv_mse_mean", &t["cv_mse_mean"]);
    check("cv_mse_se", &t["cv_mse_se"]);
    check("coef_1se", &v["chosen"][0]["coef"]);
    assert_eq!(
        t["index_min"].as_u64(),
        Some(r.scalar("index_min").unwrap() as u64)
    );
    assert_eq!(
        t["index_1se"].as_u64(),
        Some(r.scalar("index_1se").unwrap() as u64)
    );
    // The file written is the same model.
    let file: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(&model).unwrap()).unwrap();
    assert_eq!(file, v);
}

/// Smooth deterministic inputs; outputs linear in the published features plus pseudo-noise
/// uniform in ±`noise` (std noise/√3).
fn dataset(n_traj: usize, n_t: usize, noise: f64) -> Dataset {
    let beta: [[f64; 11]; 5] =
        std::array::from_fn(|o| std::array::from_fn(|j| ((o * 11 + j) as f64 * 0.7).sin() * 0.1));
    let mut state = 12345u64;
    let mut uniform = move || {
        state = state
            .wrapping_mul(6364136223846793005)
            .wrapping_add(1442695040888963407);
        (state >> 11) as f64 / (1u64 << 53) as f64 * 2.0 - 1.0
    };
    let trajectories = (0..n_traj)
        .map(|k| {
            let f = 0.2 + 0.05 * (k % 7) as f64;
            let ph = k as f64 * 0.9;
            let mut inputs = Vec::with_capacity(n_t);
            let mut outputs = Vec::with_capacity(n_t);
            for i in 0..n_t {
                let t = i as f64 * 0.04;
                let w = std::f64::consts::TAU * f;
                let u = [
                    0.6 * (w * t + ph).sin() + 0.2 * (2.3 * w * t).cos(),
                    3.0 + 1.5 * (w * t).cos() + 0.4 * (1.7 * w * t + ph).sin(),
                    6.0 * (1.3 * w * t + ph).sin(),
                    4.0 * (0.7 * w * t).cos() + (2.9 * w * t + ph).sin(),
                    2.0 * (w * t).sin(),
                    0.7 * w * (w * t + 2.0 * ph).cos(),
                    -0.7 * w * w * (w * t + 2.0 * ph).sin() + 0.3 * (3.1 * w * t).cos(),
                ];
                let x = published_features(&u);
                let y: [f64; 5] = std::array::from_fn(|o| {
                    10.0 * o as f64
                        + beta[o].iter().zip(&x).map(|(b, v)| b * v).sum::<f64>()
                        + noise * uniform()
                });
                inputs.push(u);
                outputs.push(y);
            }
            Trajectory {
                euler_rad: vec![[0.0; 3]; n_t],
                inputs,
                outputs: Some(outputs),
                u_ref_m_s: 0.3,
                family: "test".into(),
            }
        })
        .collect();
    Dataset {
        meta: DatasetMeta::new("qs cli test", Some(1), serde_json::json!({})),
        dt_s: 0.04,
        trajectories,
        n_train: n_traj - 4,
    }
}

#[test]
fn fit_and_predict_a_dataset() {
    let dir = tempfile::tempdir().unwrap();
    let ds_path = dir.path().join("ds.npz");
    let noise = 0.05;
    ValidDataset::new(dataset(24, 200, noise))
        .unwrap()
        .save(&ds_path)
        .unwrap();
    let model = dir.path().join("lrqsm.json");
    let out = flapssm(&[
        "qs",
        "fit",
        ds_path.to_str().unwrap(),
        "--out",
        model.to_str().unwrap(),
        "--rule",
        "min",
        "--predict-intercept",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("index_1se") && text.contains("alphadot_vy"),
        "{text}"
    );

    let pred = dir.path().join("pred.npz");
    let out = flapssm(&[
        "qs",
        "predict",
        model.to_str().unwrap(),
        ds_path.to_str().unwrap(),
        "--out",
        pred.to_str().unwrap(),
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(String::from_utf8_lossy(&out.stdout).contains("test RMSE"));
    let mut r = NpzReader::open(&pred).unwrap();
    let y = r.f64_shaped("y_pred", &[24, 200, 5]).unwrap();
    assert_eq!(
        r.f64_shaped("y_pred_standardized", &[24, 200, 5])
            .unwrap()
            .len(),
        y.len()
    );
    // The model is linear in these features, so the test error is the noise level.
    let noise_std = noise / 3f64.sqrt();
    for v in r.f64_shaped("rmse_test", &[5]).unwrap() {
        assert!(
            (v / noise_std - 1.0).abs() < 0.15,
            "test RMSE {v} vs noise {noise_std}"
        );
    }

    assert_eq!(r.f64("intercept").unwrap().data, vec![1.0]);
    // Published mode drops the intercept: the outputs' offsets are then missing.
    let pred2 = dir.path().join("pred2.npz");
    let out = flapssm(&[
        "qs",
        "predict",
        model.to_str().unwrap(),
        ds_path.to_str().unwrap(),
        "--out",
        pred2.to_str().unwrap(),
        "--published",
    ]);
    assert!(out.status.success());
    let mut r2 = NpzReader::open(&pred2).unwrap();
    assert_eq!(r2.f64("intercept").unwrap().data, vec![0.0]);
    let offset_missing = r2.f64_shaped("rmse_test", &[5]).unwrap();
    assert!(
        offset_missing.iter().all(|v| v / noise_std > 1.5),
        "{offset_missing:?}"
    );

    // By default a model predicts as published (intercept dropped) and its folds are random
    // (seed 0); `--contiguous` keeps whole trajectories in a fold. Each choice is recorded.
    let published = dir.path().join("published.json");
    ok(&[
        "qs",
        "fit",
        s(&ds_path),
        "--out",
        s(&published),
        "--rule",
        "min",
    ]);
    let m = json(&published);
    assert_eq!(m["prediction_intercept"], "dropped");
    assert_eq!(m["options"]["folds"]["kind"], "random");
    assert_eq!(m["options"]["folds"]["seed"], 0);
    let pred3 = dir.path().join("pred3.npz");
    let text = ok(&[
        "qs",
        "predict",
        s(&published),
        s(&ds_path),
        "--out",
        s(&pred3),
    ]);
    assert!(text.contains("intercept dropped"), "{text}");
    let contiguous = dir.path().join("contiguous.json");
    ok(&[
        "qs",
        "fit",
        s(&ds_path),
        "--out",
        s(&contiguous),
        "--contiguous",
    ]);
    assert_eq!(json(&contiguous)["options"]["folds"]["kind"], "contiguous");
}

fn fails_with(args: &[&str], needles: &[&str]) {
    let out = flapssm(args);
    assert!(!out.status.success(), "should fail: {args:?}");
    let err = String::from_utf8_lossy(&out.stderr);
    for n in needles {
        assert!(err.contains(n), "stderr lacks '{n}': {err}");
    }
}

#[test]
fn bad_input_is_reported() {
    let dir = tempfile::tempdir().unwrap();
    let header: Vec<String> = ["a", "b", "c", "y"].map(String::from).to_vec();
    let rows = |f: fn(usize) -> Vec<f64>| (0..30).map(f);
    let csv = dir.path().join("t.csv");
    let model = dir.path().join("m.json");
    let m = model.to_str().unwrap();
    let c = csv.to_str().unwrap();

    write_csv(
        &csv,
        &header,
        rows(|i| vec![i as f64, (i * i % 7) as f64, 2.0, i as f64 * 0.5 + 1.0]),
    );
    fails_with(
        &["qs", "fit-csv", c, "--targets", "y", "--out", m],
        &["'c'", "constant"],
    );
    fails_with(
        &["qs", "fit-csv", c, "--targets", "z", "--out", m],
        &["'z'", "a, b, c, y"],
    );
    fails_with(
        &[
            "qs",
            "fit-csv",
            c,
            "--targets",
            "y",
            "--features",
            "a,b",
            "--folds",
            "40",
            "--out",
            m,
        ],
        &["30 rows", "40"],
    );
    let mut text = std::fs::read_to_string(&csv).unwrap();
    text = text.replacen("\n3,", "\nnan,", 1);
    std::fs::write(&csv, text).unwrap();
    fails_with(
        &["qs", "fit-csv", c, "--targets", "y", "--out", m],
        &["'a'", "nan", "line 5"],
    );
    assert!(!model.exists(), "no model written on error");

    std::fs::write(
        &model,
        "{\"kind\": \"flapssm-lrqsm\", \"format_version\": 99}",
    )
    .unwrap();
    fails_with(&["qs", "predict", m, c, "--out", "p.npz"], &["version 99"]);
}
