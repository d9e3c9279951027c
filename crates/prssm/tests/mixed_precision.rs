//! [`Precision::Mixed`] against the `f64` reference: the loss and every parameter group's
//! gradient of the ELBO on the paper's configuration (at its initial parameters and at the
//! authors' trained model), on small models of both kernels, parametrizations and covariance
//! structures, and the conditional's variances at the authors' probe points.
//!
//! Measured (2026-11-25): loss within 1.6e-7 relative, gradient groups within 2.0e-5 relative
//! (lengthscales of the trained model; ≤ 2e-7 at initial parameters); at the probe points,
//! variances within 8.8e-5 relative (the cancellation `σ_f² − Σ K⊙W` sees `W`'s rounding) and
//! means within 3.4e-7 of their spread. The tolerances below leave a factor ≥ 3.

use std::path::{Path, PathBuf};

use flapssm_data::npz::NpzReader;
use flapssm_prssm::bench::synthetic_sequences;
use flapssm_prssm::conditional::{ConditionalWorkspace, Posterior};
use flapssm_prssm::published::import_published;
use flapssm_prssm::train::fit::FitSpec;
use flapssm_prssm::{
    CovarianceStructure, Elbo, ElboOptions, KernelKind, ModelConfig, Objective, ParamInit,
    Parametrization, Params, Precision, TrainingData, Window,
};

/// Loss and gradient of `elbo` at `theta` on `batch`, in `precision`.
fn evaluate(elbo: &Elbo, precision: Precision, theta: &[f64], batch: &[Window]) -> (f64, Vec<f64>) {
    let e = elbo.clone().with_precision(precision);
    let mut grad = vec![0.0; theta.len()];
    let loss = e.loss_and_grad(theta, batch, 17, &mut grad).unwrap();
    (loss, grad)
}

/// Parameter groups of the flat vector: (name, index range).
fn groups(config: &ModelConfig, n: usize) -> Vec<(&'static str, std::ops::Range<usize>)> {
    let ly = config.layout();
    vec![
        ("inducing", 0..ly.kernel_variance),
        ("kernel_variance", ly.kernel_variance..ly.lengthscales),
        ("lengthscales", ly.lengthscales..ly.q_mean),
        ("q_mean", ly.q_mean..ly.q_cov),
        ("q_cov", ly.q_cov..ly.process_noise),
        ("process_noise", ly.process_noise..ly.obs_noise),
        ("obs_noise", ly.obs_noise..n),
    ]
}

/// Asserts that the mixed loss differs from the `f64` one (the mixed path ran) by at most
/// `loss_tol` relative, and each gradient group by at most `grad_tol` in `‖a − b‖ / ‖b‖`.
fn assert_close(label: &str, elbo: &Elbo, theta: &[f64], batch: &[Window], tol: (f64, f64)) {
    let (dl, groups) = compare(elbo, theta, batch);
    assert!(
        dl > 0.0,
        "{label}: the mixed loss equals the f64 one bit for bit"
    );
    assert!(dl <= tol.0, "{label}: loss differs by {dl:e} relative");
    for (name, rel) in groups {
        assert!(
            rel <= tol.1,
            "{label}: {name} gradient differs by {rel:e} relative"
        );
    }
}

/// `‖a − b‖ / ‖b‖` per parameter group; the loss's relative difference first.
fn compare(elbo: &Elbo, theta: &[f64], batch: &[Window]) -> (f64, Vec<(&'static str, f64)>) {
    let (l64, g64) = evaluate(elbo, Precision::F64, theta, batch);
    let (l32, g32) = evaluate(elbo, Precision::Mixed, theta, batch);
    let norm = |v: &[f64]| v.iter().map(|x| x * x).sum::<f64>().sqrt();
    let rel = groups(elbo.config(), theta.len())
        .into_iter()
        .map(|(name, r)| {
            let d: Vec<f64> = g32[r.clone()]
                .iter()
                .zip(&g64[r.clone()])
                .map(|(a, b)| a - b)
                .collect();
            (name, norm(&d) / norm(&g64[r]))
        })
        .collect();
    ((l32 - l64).abs() / l64.abs(), rel)
}

fn whole(n: usize, len: usize) -> Vec<Window> {
    (0..n)
        .map(|sequence| Window {
            sequence,
            start: 0,
            len,
        })
        .collect()
}

fn paper_elbo(config: &ModelConfig, n: usize, len: usize) -> Elbo {
    let data = synthetic_sequences(n, len, config.n_input, config.n_output, 3);
    let data = TrainingData::new(config.n_input, config.n_output, data).unwrap();
    Elbo::new(config.clone(), data, ElboOptions::paper(n)).unwrap()
}

#[test]
fn paper_configuration_at_its_start() {
    let spec = FitSpec::new(ModelConfig::new(12, 5, 7, 100));
    let elbo = paper_elbo(&spec.model, 8, 120);
    let theta = Params::init(&spec.model, &spec.init, 5).unconstrained(&spec.model);
    assert_close("paper start", &elbo, &theta, &whole(8, 120), (1e-9, 1e-6));
}

fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/bayiz2021-prssm/reference.npz")
}

#[test]
fn published_model() {
    let model = import_published(&reference()).unwrap();
    let elbo = paper_elbo(&model.config, 8, 120);
    let theta = model.params.unconstrained(&model.config);
    assert_close("published", &elbo, &theta, &whole(8, 120), (1e-6, 1e-4));
}

/// At the authors' 64 probe points the mixed conditional's variances stay positive and
/// within 3e-4 relative of the f64 ones, its means within 1e-5 of the f64 spread.
#[test]
fn published_model_conditional_at_probe_points() {
    let model = import_published(&reference()).unwrap();
    let x = NpzReader::open(reference())
        .unwrap()
        .f64_shaped("probe_in", &[64, 19])
        .unwrap();
    let run = |precision: Precision| {
        let mut post = Posterior::new(&model.config, &model.params).unwrap();
        post.set_precision(precision);
        let mut ws = ConditionalWorkspace::new(&post, 64);
        ws.input.copy_from_slice(&x);
        ws.forward(&post, 64);
        (ws.mean, ws.var)
    };
    let (m64, v64) = run(Precision::F64);
    let (m32, v32) = run(Precision::Mixed);
    let spread = m64.iter().map(|v| v.abs()).fold(0.0, f64::max);
    for i in 0..v64.len() {
        assert!(v32[i] > 0.0, "variance {i} is {}", v32[i]);
        let dv = (v32[i] - v64[i]).abs() / v64[i];
        assert!(dv < 3e-4, "variance {i}: {} against {}", v32[i], v64[i]);
        let dm = (m32[i] - m64[i]).abs() / spread;
        assert!(dm < 1e-5, "mean {i}: {} against {}", m32[i], m64[i]);
    }
}

#[test]
fn small_models() {
    for kernel in [KernelKind::Matern32, KernelKind::SquaredExponential] {
        for param in [Parametrization::Unwhitened, Parametrization::Whitened] {
            for cov in [CovarianceStructure::Diagonal, CovarianceStructure::Full] {
                let mut config = ModelConfig::new(4, 2, 3, 20);
                config.kernel = kernel;
                config.parametrization = param;
                config.covariance = cov;
                let elbo = paper_elbo(&config, 6, 60);
                let init = ParamInit {
                    lengthscale: 1.3,
                    ..ParamInit::default()
                };
                let theta = Params::init(&config, &init, 9).unconstrained(&config);
                let label = format!("{kernel:?} {param:?} {cov:?}");
                assert_close(&label, &elbo, &theta, &whole(6, 60), (2e-8, 1e-6));
            }
        }
    }
}

/// Mixed results are reproducible: the same on one thread and on two (chunks reduced in order,
/// each product sequential).
#[test]
fn mixed_results_do_not_depend_on_the_thread_count() {
    let spec = FitSpec::new(ModelConfig::new(12, 5, 7, 100));
    let elbo = paper_elbo(&spec.model, 8, 60);
    let theta = Params::init(&spec.model, &spec.init, 5).unconstrained(&spec.model);
    let on = |threads: usize| {
        rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap()
            .install(|| evaluate(&elbo, Precision::Mixed, &theta, &whole(8, 60)))
    };
    let (one, two) = (on(1), on(2));
    assert_eq!(one.0.to_bits(), two.0.to_bits());
    assert!(
        one.1
            .iter()
            .zip(&two.1)
            .all(|(a, b)| a.to_bits() == b.to_bits())
    );
}
