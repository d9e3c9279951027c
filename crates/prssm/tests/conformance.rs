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

/// The published-code objective (`ObjectiveForm::PublishedCode`) on the published model is the
/// authors' loss: `Σ_p Σ_{t ≥ 94} −ln N(y_t | x^p_t[0..5], σ_y²) + KL`, here computed from the
/// particles their code drew (`x_particles`). Ours draws its own particles, so the two agree
/// in distribution: the authors' value lies within 4 standard deviations of our mean over 24
/// seeds (measured: z = −2.0; with independent draws instead of shared ones, z = −19), and the
/// standard form's likelihood is exactly the published one ÷ 30 particles.
#[test]
fn published_code_objective_matches_the_authors_loss() {
    use flapssm_prssm::train::fit::{FitSpec, ObjectiveForm};
    use flapssm_prssm::{
        Elbo, ElboOptions, InitialStateGrads, InitialStateMode, InitialStates, LossScaling,
        Objective, Sequence, TrainingData, Window,
    };
    let m = model();
    let mut r = NpzReader::open(reference()).unwrap();
    let u = r.f64_shaped("u_in", &[470, 7]).unwrap();
    // Targets independent of the particles scored: the mean of the authors' five other runs
    // (their own `pred_mean` would favour the particles it was averaged from).
    let runs = r.f64_shaped("pred_mean_runs", &[5, 470, 5]).unwrap();
    let y: Vec<f64> = (0..470 * 5)
        .map(|i| (0..5).map(|k| runs[k * 470 * 5 + i]).sum::<f64>() / 5.0)
        .collect();
    let xp = r.f64_shaped("x_particles", &[470, 30, 12]).unwrap();
    let kl_ref = r.scalar("kl_reg").unwrap();

    // The fit spec of the mode samples as the published model does.
    let paper = FitSpec::new(flapssm_prssm::ModelConfig::new(12, 5, 7, 100));
    let spec = paper.with_objective(ObjectiveForm::PublishedCode);
    assert_eq!(spec.model, m.config, "published-code model config");
    assert!(spec.check_objective().is_ok());
    let standard = spec.clone().with_objective(ObjectiveForm::Standard);
    assert!(!standard.model.shared_draws && standard.model.matern_tau_jitter == 0.0);

    let vy = &m.params.obs_noise_var;
    let mut nll_ref = 0.0;
    for t in 94..470 {
        for p in 0..30 {
            for d in 0..5 {
                let e = y[t * 5 + d] - xp[(t * 30 + p) * 12 + d];
                nll_ref += 0.5 * (2.0 * std::f64::consts::PI * vy[d]).ln() + e * e / (2.0 * vy[d]);
            }
        }
    }
    let loss_ref = nll_ref + kl_ref;

    let data = TrainingData::new(
        7,
        5,
        vec![Sequence {
            inputs: u,
            outputs: y,
        }],
    )
    .unwrap();
    let elbo_with = |scaling| {
        let options = ElboOptions {
            particles: 30,
            burn_in_fraction: 0.2,
            scaling,
            initial_state: InitialStateMode::Zeros,
            windows_per_task: 4,
        };
        Elbo::new(m.config.clone(), data.clone(), options).unwrap()
    };
    let published = elbo_with(LossScaling::Published);
    let standard = elbo_with(LossScaling::Standard { n_windows: 1.0 });
    let flat = m.params.unconstrained(&m.config);
    let batch = [Window {
        sequence: 0,
        start: 0,
        len: 470,
    }];
    let mut grad = vec![0.0; published.n_params()];
    let zeros = vec![0.0; 12];
    let (mut gm, mut gs) = (vec![0.0; 12], vec![0.0; 12]);
    let mut parts = |elbo: &Elbo, seed: u64| {
        let init = InitialStates {
            mean: &zeros,
            std: &zeros,
        };
        let init_grad = InitialStateGrads {
            mean: &mut gm,
            std: &mut gs,
        };
        elbo.evaluate(&flat, &batch, init, seed, &mut grad, init_grad)
            .unwrap()
    };
    let losses: Vec<f64> = (0..24)
        .map(|seed| {
            let p = parts(&published, seed);
            let s = parts(&standard, seed);
            // Ours factors K_mm with its 1e-8 jitter, the authors' kl_reg without (−0.1 of 49 074).
            assert!(
                (p.kl - kl_ref).abs() / kl_ref < 1e-5,
                "KL {} vs {kl_ref}",
                p.kl
            );
            let rel = (p.nll / 30.0 - s.nll).abs() / s.nll.abs();
            assert!(
                rel < 1e-12,
                "seed {seed}: standard nll ≠ published / 30 (rel {rel:e})"
            );
            p.loss
        })
        .collect();
    let n = losses.len() as f64;
    let mean = losses.iter().sum::<f64>() / n;
    let sd = (losses.iter().map(|l| (l - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
    let z = (loss_ref - mean) / sd;
    eprintln!("authors' loss {loss_ref:.1}, ours {mean:.1} ± {sd:.1} (z = {z:.2})");
    assert!(
        z.abs() < 4.0,
        "authors' loss {loss_ref:.1}, ours {mean:.1} ± {sd:.1} (z = {z:.2})"
    );
}
