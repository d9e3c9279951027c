//! Conformance with the published model run by its authors' code
//! (`shared/reference/bayiz2021-prssm/reference.npz`, see its README).

use std::path::{Path, PathBuf};

use flapssm_data::npz::NpzReader;
use flapssm_prssm::conditional::{ConditionalWorkspace, Posterior};
use flapssm_prssm::kl::kl_divergence;
use flapssm_prssm::predict::{expand_shared_draws, simulate_with_draws};
use flapssm_prssm::published::import_published;
use flapssm_prssm::{CovarianceStructure, PrssmModel};

fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/bayiz2021-prssm/reference.npz")
}

fn model() -> PrssmModel {
    import_published(&reference()).expect("import published parameters")
}

fn max_abs_diff(a: &[f64], b: &[f64]) -> f64 {
    assert_eq!(a.len(), b.len());
    a.iter()
        .zip(b)
        .map(|(x, y)| (x - y).abs())
        .fold(0.0, f64::max)
}

#[test]
fn gp_conditional_matches_probe_points() {
    let m = model();
    let mut r = NpzReader::open(reference()).unwrap();
    let x = r.f64_shaped("probe_in", &[64, 19]).unwrap();
    let fmean = r.f64_shaped("probe_fmean", &[64, 12]).unwrap();
    let fvar = r.f64_shaped("probe_fvar", &[64, 12]).unwrap();
    let post = Posterior::new(&m.config, &m.params).unwrap();
    let mut ws = ConditionalWorkspace::new(&post, 64);
    ws.input.copy_from_slice(&x);
    ws.forward(&post, 64);
    // Both are row-major 64 × 12 (= column-major D_x × N).
    let dm = max_abs_diff(&ws.mean, &fmean);
    let dv = max_abs_diff(&ws.var, &fvar);
    assert!(dm < 1e-10, "mean max diff {dm:e}");
    assert!(dv < 1e-10, "var max diff {dv:e}");
}

#[test]
fn kl_matches_published_value() {
    let m = model();
    let mut r = NpzReader::open(reference()).unwrap();
    let kl_ref = r.scalar("kl_reg").unwrap();
    assert!((kl_ref - 49074.03164220472).abs() < 1e-6);
    // K_mm without jitter, as the published code computes kl_reg.
    let mut config = m.config.clone();
    config.kmm_jitter = 0.0;
    let post0 = Posterior::new(&config, &m.params).unwrap();
    let l = post0.kmm_factor();
    let kl = kl_divergence(
        Some(l),
        config.n_inducing,
        12,
        &m.params.q_mean,
        &m.params.q_cov,
        CovarianceStructure::Diagonal,
    );
    let rel = (kl.value - kl_ref).abs() / kl_ref;
    assert!(rel < 1e-8, "KL {} vs {kl_ref}: rel {rel:e}", kl.value);
}

#[test]
fn particles_and_moments_match_published_run() {
    let m = model();
    let mut r = NpzReader::open(reference()).unwrap();
    let u = r.f64_shaped("u_in", &[470, 7]).unwrap();
    let eps = r.f64_shaped("eps", &[469, 30]).unwrap();
    let xp = r.f64_shaped("x_particles", &[470, 30, 12]).unwrap();
    let x0 = vec![0.0; 30 * 12];
    let eps_full = expand_shared_draws(&eps, 12);
    let (all, pred) = simulate_with_draws(&m.config, &m.params, &u, &x0, &eps_full).unwrap();
    let dx = max_abs_diff(&all, &xp);
    assert!(dx < 1e-9, "particles max diff {dx:e}");
    for (name, ours, shape) in [
        ("pred_mean", &pred.output_mean, [470, 5]),
        ("pred_var", &pred.output_var, [470, 5]),
        ("latent_mean", &pred.latent_mean, [470, 12]),
        ("latent_var", &pred.latent_var, [470, 12]),
    ] {
        let want = r.f64_shaped(name, &shape).unwrap();
        let d = max_abs_diff(ours, &want);
        assert!(d < 1e-9, "{name} max diff {d:e}");
    }
}
