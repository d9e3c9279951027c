//! Recovery of a known linear model of the 11 published features from noisy data.

#![allow(clippy::needless_range_loop)] // index arithmetic mirrors the equations

mod common;

use flapssm_qs::cv::{Columns, EnetOptions, LambdaRule, fit_enet_cv};
use flapssm_wing::features::{PUBLISHED_NAMES, published_features};

#[test]
fn recovers_known_coefficients_within_noise() {
    let inputs = common::smooth_inputs(40, 400, 0.04, 7);
    let p = 11;
    let x: Vec<f64> = inputs
        .iter()
        .flatten()
        .flat_map(published_features)
        .collect();
    let n = x.len() / p;
    // True model: a few features zero (elastic-net can keep them at zero).
    let beta = [
        0.08, 0.35, 0.0, -0.12, 0.05, 0.02, -0.03, 0.0, 0.06, 0.01, -0.04,
    ];
    let b0 = 0.7;
    let sigma = 0.3;
    let noise = common::normals(n, 11);
    let y: Vec<f64> = (0..n)
        .map(|i| b0 + (0..p).map(|j| x[i * p + j] * beta[j]).sum::<f64>() + sigma * noise[i])
        .collect();

    let names: Vec<String> = PUBLISHED_NAMES.iter().map(|s| s.to_string()).collect();
    let target = vec!["y".to_string()];
    let opts = EnetOptions {
        rule: LambdaRule::Min,
        tol: 1e-12,
        ..EnetOptions::default()
    };
    let fit = fit_enet_cv(
        Columns {
            names: &names,
            data: &x,
        },
        Columns {
            names: &target,
            data: &y,
        },
        &opts,
    )
    .unwrap();
    let t = &fit.targets[0];
    assert_eq!(t.unconverged, 0);
    let (_, ols_b, se) = common::ols(&x, &y, p);

    // OLS itself is within 3 SE of the truth (the noise level of this design).
    for j in 0..p {
        assert!((ols_b[j] - beta[j]).abs() < 3.0 * se[j], "OLS {j}");
    }
    // The CV-chosen (min-MSE) coefficients are within 3 SE of the truth.
    for j in 0..p {
        let d = (t.coef()[j] - beta[j]).abs();
        eprintln!(
            "{:>22}: true {:+.4} fit {:+.4} (|d| = {:.2} SE)",
            names[j],
            beta[j],
            t.coef()[j],
            d / se[j]
        );
        assert!(d < 3.0 * se[j], "feature {j}: {d} > 3 SE = {}", 3.0 * se[j]);
    }
    // The CV minimum is close to the noise variance.
    let mse = t.cv_mse_mean[t.index_min];
    assert!((mse / (sigma * sigma) - 1.0).abs() < 0.05, "cv mse {mse}");
}
