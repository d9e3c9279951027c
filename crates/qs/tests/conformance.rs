//! Conformance with scikit-learn 1.9.1 `enet_path` + 10-fold CV
//! (/work/shared/reference/elastic-net, see its README): already standardized problem, no
//! intercept, contiguous folds.

use std::path::Path;

use flapssm_data::npz::NpzReader;
use flapssm_qs::cv::{Columns, EnetOptions, FoldLayout, LambdaRule, fit_enet_cv};

fn reference() -> NpzReader {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/elastic-net/reference.npz");
    NpzReader::open(&path).expect("reference.npz")
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(u, v)| (u - v).abs())
        .fold(0.0, f64::max)
}

#[test]
fn matches_scikit_learn_reference() {
    let mut r = reference();
    let x = r.f64_shaped("X", &[2000, 11]).unwrap();
    let y = r.f64_shaped("y", &[2000]).unwrap();
    let l1_ratio = r.scalar("l1_ratio").unwrap();
    let lambdas = r.f64_shaped("lambdas", &[100]).unwrap();
    let coef_path = r.f64_shaped("coef_path", &[100, 11]).unwrap();
    let mse_mean = r.f64_shaped("cv_mse_mean", &[100]).unwrap();
    let mse_se = r.f64_shaped("cv_mse_se", &[100]).unwrap();
    let index_min = r.scalar("index_min").unwrap() as usize;
    let index_1se = r.scalar("index_1se").unwrap() as usize;
    let coef_1se = r.f64_shaped("coef_1se", &[11]).unwrap();
    let coef_min = r.f64_shaped("coef_min", &[11]).unwrap();

    let names: Vec<String> = (0..11).map(|j| format!("x{j}")).collect();
    let target = vec!["y".to_string()];
    let opts = EnetOptions {
        l1_ratio,
        standardize: false,
        intercept: false,
        folds: FoldLayout::Contiguous,
        rule: LambdaRule::OneSe,
        tol: 1e-13,
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
    assert!(max_abs_diff(&t.lambdas, &lambdas) < 1e-12, "lambdas");
    let path: Vec<f64> = t.coef_path.concat();
    let d = max_abs_diff(&path, &coef_path);
    eprintln!(
        "max |diff|: coef_path {d:.2e}, cv_mse_mean {:.2e}, cv_mse_se {:.2e}; sweeps {}",
        max_abs_diff(&t.cv_mse_mean, &mse_mean),
        max_abs_diff(&t.cv_mse_se, &mse_se),
        t.sweeps
    );
    assert!(d < 1e-6, "coef_path differs by {d}");
    let d = max_abs_diff(&t.cv_mse_mean, &mse_mean);
    assert!(d < 1e-6, "cv_mse_mean differs by {d}");
    let d = max_abs_diff(&t.cv_mse_se, &mse_se);
    assert!(d < 1e-6, "cv_mse_se differs by {d}");
    assert_eq!(t.index_min, index_min);
    assert_eq!(t.index_1se, index_1se);
    assert_eq!(t.index_chosen, index_1se);
    assert!(max_abs_diff(t.coef(), &coef_1se) < 1e-6, "coef_1se");
    assert!(
        max_abs_diff(&t.coef_path[index_min], &coef_min) < 1e-6,
        "coef_min"
    );
    // No standardization, no intercept: both scales agree and the intercept is zero.
    assert_eq!(t.coef_path, t.coef_path_standardized);
    assert!(t.intercept_path.iter().all(|&b| b == 0.0));
    assert_eq!(fit.fold_sizes, vec![200; 10]);
}
