//! Properties of the fit: optimality (KKT) on independently standardized data, invariance
//! under affine changes of units, fold layouts, errors, the model file.

#![allow(clippy::needless_range_loop)] // index arithmetic mirrors the equations

mod common;

use flapssm_qs::QsError;
use flapssm_qs::cv::{Columns, EnetOptions, FoldLayout, LambdaRule, fit_enet_cv, fold_rows};
use flapssm_qs::model::{InterceptMode, LrqsmModel, MODEL_FORMAT_VERSION};
use flapssm_wing::features::{PUBLISHED_NAMES, published_features};

fn names(k: usize, prefix: &str) -> Vec<String> {
    (0..k).map(|j| format!("{prefix}{j}")).collect()
}

/// Published features of smooth random inputs and two noisy linear targets.
fn problem(seed: u64) -> (Vec<f64>, Vec<f64>, usize) {
    let inputs = common::smooth_inputs(12, 150, 0.04, seed);
    let x: Vec<f64> = inputs
        .iter()
        .flatten()
        .flat_map(published_features)
        .collect();
    let n = x.len() / 11;
    let noise = common::normals(2 * n, seed + 1);
    let y = (0..n)
        .flat_map(|i| {
            let r = &x[i * 11..(i + 1) * 11];
            [
                1.0 + 0.1 * r[0] - 0.3 * r[1] + 0.05 * r[5] + 0.5 * noise[2 * i],
                -2.0 + 0.02 * r[6] + 0.2 * r[8] - 0.1 * r[10] + 0.2 * noise[2 * i + 1],
            ]
        })
        .collect();
    (x, y, n)
}

fn fit(x: &[f64], y: &[f64], opts: &EnetOptions) -> Result<flapssm_qs::cv::EnetCvFit, QsError> {
    fit_enet_cv(
        Columns {
            names: &names(x.len() / (y.len() / 2), "x"),
            data: x,
        },
        Columns {
            names: &names(2, "y"),
            data: y,
        },
        opts,
    )
}

#[test]
fn path_satisfies_kkt_on_independently_standardized_data() {
    let (x, y, n) = problem(3);
    let p = 11;
    let opts = EnetOptions {
        tol: 1e-13,
        ..EnetOptions::default()
    };
    let f = fit(&x, &y, &opts).unwrap();
    // Two-pass means and population stds, computed here.
    let mean: Vec<f64> = (0..p)
        .map(|j| (0..n).map(|i| x[i * p + j]).sum::<f64>() / n as f64)
        .collect();
    let sd: Vec<f64> = (0..p)
        .map(|j| {
            ((0..n)
                .map(|i| (x[i * p + j] - mean[j]).powi(2))
                .sum::<f64>()
                / n as f64)
                .sqrt()
        })
        .collect();
    for j in 0..p {
        assert!((f.feature_center[j] - mean[j]).abs() <= 1e-12 * (1.0 + mean[j].abs()));
        assert!((f.feature_scale[j] / sd[j] - 1.0).abs() < 1e-12);
    }
    let z: Vec<f64> = (0..n * p)
        .map(|k| (x[k] - mean[k % p]) / sd[k % p])
        .collect();
    for (t, path) in f.targets.iter().enumerate() {
        let ym = (0..n).map(|i| y[2 * i + t]).sum::<f64>() / n as f64;
        for (l, &lambda) in path.lambdas.iter().enumerate() {
            let w = &path.coef_path_standardized[l];
            // Gradient of the smooth part: (1/n) Zᵀ(ỹ − Z w) − λ(1−α) w.
            let mut g = vec![0.0; p];
            for i in 0..n {
                let zi = &z[i * p..(i + 1) * p];
                let r = y[2 * i + t] - ym - zi.iter().zip(w).map(|(a, b)| a * b).sum::<f64>();
                g.iter_mut()
                    .zip(zi)
                    .for_each(|(gj, zj)| *gj += zj * r / n as f64);
            }
            let l1 = lambda * opts.l1_ratio;
            for j in 0..p {
                let gj = g[j] - lambda * (1.0 - opts.l1_ratio) * w[j];
                let viol = if w[j] != 0.0 {
                    (gj - l1 * w[j].signum()).abs()
                } else {
                    (gj.abs() - l1).max(0.0)
                };
                assert!(
                    viol < 1e-9,
                    "target {t} λ#{l} feature {j}: KKT violation {viol}"
                );
                // Original scale and intercept follow from w.
                assert!(
                    (path.coef_path[l][j] - w[j] / sd[j]).abs()
                        < 1e-12 * (1.0 + (w[j] / sd[j]).abs())
                );
            }
            let b0 = ym - (0..p).map(|j| mean[j] * path.coef_path[l][j]).sum::<f64>();
            assert!((path.intercept_path[l] - b0).abs() < 1e-9 * (1.0 + b0.abs()));
        }
        assert_eq!(
            path.coef_path_standardized[0]
                .iter()
                .filter(|w| w.abs() > 1e-14)
                .count(),
            0
        );
    }
}

#[test]
fn invariant_to_feature_units_and_target_offset() {
    // With standardization and intercept, x → a x + c per column leaves w, λ and CV unchanged
    // (each fold is re-standardized on its own rows); b scales by 1/a; y → y + d moves b₀ only.
    let (x, y, n) = problem(5);
    let p = 11;
    let scale: Vec<f64> = (0..p).map(|j| 10f64.powi(j as i32 % 5 - 2)).collect();
    let shift: Vec<f64> = (0..p).map(|j| 100.0 * (j as f64 - 5.0)).collect();
    let x2: Vec<f64> = (0..n * p)
        .map(|k| scale[k % p] * x[k] + shift[k % p])
        .collect();
    let y2: Vec<f64> = y.iter().map(|v| v + 3.0).collect();
    let opts = EnetOptions {
        tol: 1e-13,
        folds: FoldLayout::Random { seed: 9 },
        ..EnetOptions::default()
    };
    let a = fit(&x, &y, &opts).unwrap();
    let b = fit(&x2, &y2, &opts).unwrap();
    for (ta, tb) in a.targets.iter().zip(&b.targets) {
        for l in 0..ta.lambdas.len() {
            assert!((ta.lambdas[l] / tb.lambdas[l] - 1.0).abs() < 1e-9);
            assert!(
                (ta.cv_mse_mean[l] / tb.cv_mse_mean[l] - 1.0).abs() < 1e-7,
                "cv mse at {l}"
            );
            for j in 0..p {
                let (wa, wb) = (
                    ta.coef_path_standardized[l][j],
                    tb.coef_path_standardized[l][j],
                );
                assert!(
                    (wa - wb).abs() < 1e-8,
                    "w at λ#{l} feature {j}: {wa} vs {wb}"
                );
                let (ba, bb) = (ta.coef_path[l][j], tb.coef_path[l][j] * scale[j]);
                assert!((ba - bb).abs() < 1e-8 * (1.0 + ba.abs()));
            }
        }
        assert_eq!((ta.index_min, ta.index_1se), (tb.index_min, tb.index_1se));
    }
}

#[test]
fn fold_layouts() {
    // np.array_split(range(23), 10): three folds of 3, seven of 2, in order.
    let f = fold_rows(23, 10, FoldLayout::Contiguous).unwrap();
    let sizes: Vec<usize> = f.iter().map(Vec::len).collect();
    assert_eq!(sizes, [3, 3, 3, 2, 2, 2, 2, 2, 2, 2]);
    assert_eq!(f.concat(), (0..23).collect::<Vec<_>>());
    let r1 = fold_rows(23, 10, FoldLayout::Random { seed: 1 }).unwrap();
    let r1b = fold_rows(23, 10, FoldLayout::Random { seed: 1 }).unwrap();
    let r2 = fold_rows(23, 10, FoldLayout::Random { seed: 2 }).unwrap();
    assert_eq!(r1, r1b, "same seed, same folds");
    assert_ne!(r1, r2, "another seed, other folds");
    let mut all = r1.concat();
    all.sort_unstable();
    assert_eq!(all, (0..23).collect::<Vec<_>>(), "a partition of the rows");
    assert_eq!(r1.iter().map(Vec::len).collect::<Vec<_>>(), sizes);
    assert!(matches!(
        fold_rows(9, 10, FoldLayout::Contiguous),
        Err(QsError::TooFewRows { rows: 9, folds: 10 })
    ));
}

#[test]
fn bad_input_is_named() {
    let (mut x, y, _) = problem(4);
    let opts = EnetOptions::default();
    x[5 * 11 + 3] = f64::NAN;
    let e = fit(&x, &y, &opts).unwrap_err().to_string();
    assert!(e.contains("'x3'") && e.contains("row 5"), "{e}");
    let (mut x, y, n) = problem(4);
    (0..n).for_each(|i| x[i * 11 + 7] = 2.5);
    let e = fit(&x, &y, &opts).unwrap_err().to_string();
    assert!(e.contains("'x7'") && e.contains("constant"), "{e}");
    let (x, y, _) = problem(4);
    let e = fit(&x[..9 * 11], &y[..18], &opts).unwrap_err();
    assert!(
        matches!(e, QsError::TooFewRows { rows: 9, folds: 10 }),
        "{e}"
    );
    let (x, _, n) = problem(4);
    let flat = vec![1.0; 2 * n];
    let e = fit(&x, &flat, &opts).unwrap_err().to_string();
    assert!(e.contains("'y0'") && e.contains("constant"), "{e}");
    let e = fit(
        &x,
        &flat,
        &EnetOptions {
            l1_ratio: 0.0,
            ..opts
        },
    )
    .unwrap_err()
    .to_string();
    assert!(e.contains("l1_ratio"), "{e}");
}

#[test]
fn seeded_random_folds_are_reproducible() {
    let (x, y, _) = problem(6);
    let opts = EnetOptions {
        folds: FoldLayout::Random { seed: 42 },
        ..EnetOptions::default()
    };
    assert_eq!(fit(&x, &y, &opts).unwrap(), fit(&x, &y, &opts).unwrap());
}

fn model() -> LrqsmModel {
    let (x, y, _) = problem(8);
    let features: Vec<String> = PUBLISHED_NAMES.iter().map(|s| s.to_string()).collect();
    let opts = EnetOptions {
        rule: LambdaRule::Min,
        ..EnetOptions::default()
    };
    let f = fit_enet_cv(
        Columns {
            names: &features,
            data: &x,
        },
        Columns {
            names: &names(2, "y"),
            data: &y,
        },
        &opts,
    )
    .unwrap();
    LrqsmModel::new(
        f,
        opts,
        Some(flapssm_wing::features::FeatureSet::Published),
        None,
        "test",
    )
}

#[test]
fn model_file_round_trip_and_validation() {
    let m = model();
    assert_eq!(m.chosen[0].index, m.fit.targets[0].index_min);
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("m.json");
    m.save(&path).unwrap();
    assert_eq!(LrqsmModel::load(&path).unwrap(), m);

    // Prediction: b₀ + xᵀb, or xᵀb without intercept.
    let row = [0.3; 11];
    let mut out = [0.0; 2];
    m.predict_row(&row, InterceptMode::Fitted, &mut out);
    let lin: f64 = m.chosen[1].coef.iter().map(|b| 0.3 * b).sum();
    assert!((out[1] - lin - m.chosen[1].intercept).abs() < 1e-12);
    m.predict_row(&row, InterceptMode::Dropped, &mut out);
    assert!((out[1] - lin).abs() < 1e-12);

    // The published baseline by default: random folds (seed 0), intercept not added; a file
    // written before `prediction_intercept` existed predicted with the intercept and still does.
    assert_eq!(EnetOptions::default().folds, FoldLayout::Random { seed: 0 });
    assert_eq!(m.prediction_intercept, InterceptMode::Dropped);
    let mut old: serde_json::Value = serde_json::to_value(&m).unwrap();
    old.as_object_mut().unwrap().remove("prediction_intercept");
    let old = LrqsmModel::from_json(&old.to_string(), &path).unwrap();
    assert_eq!(old.prediction_intercept, InterceptMode::Fitted);

    let mut v: serde_json::Value = serde_json::to_value(&m).unwrap();
    v["format_version"] = (MODEL_FORMAT_VERSION + 1).into();
    let e = LrqsmModel::from_json(&v.to_string(), &path).unwrap_err();
    assert!(matches!(e, QsError::ModelVersion { found: 2, .. }), "{e}");

    let mut v: serde_json::Value = serde_json::to_value(&m).unwrap();
    v["chosen"][0]["coef"][3] = 99.0.into();
    let e = LrqsmModel::from_json(&v.to_string(), &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("chosen[0]"), "{e}");

    let mut v: serde_json::Value = serde_json::to_value(&m).unwrap();
    v["fit"]["targets"][1]["cv_mse_se"] = serde_json::json!([1.0]);
    let e = LrqsmModel::from_json(&v.to_string(), &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("fit.targets[1]"), "{e}");

    let mut v: serde_json::Value = serde_json::to_value(&m).unwrap();
    v.as_object_mut().unwrap().remove("options");
    let e = LrqsmModel::from_json(&v.to_string(), &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("options"), "{e}");

    let e = LrqsmModel::from_json("{\"kind\": \"other\"}", &path)
        .unwrap_err()
        .to_string();
    assert!(e.contains("kind"), "{e}");
    assert!(matches!(
        LrqsmModel::load(&dir.path().join("none.json")),
        Err(QsError::Io { .. })
    ));
}
