//! Exact gradients of the ELBO against central finite differences (fixed draws via the
//! seed), for every parameter group, both kernels, both parametrizations, both covariance
//! structures, and for the caller-supplied initial state.

use flapssm_prssm::{
    CovarianceStructure, Elbo, ElboOptions, InitialStateGrads, InitialStateMode, InitialStates,
    KernelKind, LossScaling, ModelConfig, Objective, ParamInit, Parametrization, Params, Sequence,
    TrainingData, Window,
};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const DX: usize = 3;
const DY: usize = 2;
const DU: usize = 2;
const M: usize = 6;

fn n01(rng: &mut ChaCha8Rng) -> f64 {
    StandardNormal.sample(rng)
}

fn data(rng: &mut ChaCha8Rng) -> TrainingData {
    let seqs = (0..3)
        .map(|_| Sequence {
            inputs: (0..10 * DU).map(|_| n01(rng)).collect(),
            outputs: (0..10 * DY).map(|_| 0.5 * n01(rng)).collect(),
        })
        .collect();
    TrainingData::new(DU, DY, seqs).unwrap()
}

fn params(config: &ModelConfig, rng: &mut ChaCha8Rng) -> Params {
    let init = ParamInit {
        inducing_range: 1.5,
        lengthscale: 1.3,
        kernel_variance: 0.6,
        ..ParamInit::default()
    };
    let mut p = Params::init(config, &init, 7);
    for v in &mut p.q_mean {
        *v = 0.5 * n01(rng);
    }
    match config.covariance {
        CovarianceStructure::Diagonal => p
            .q_cov
            .iter_mut()
            .for_each(|v| *v = rng.random_range(0.05..0.3)),
        CovarianceStructure::Full => {
            for d in 0..DX {
                for j in 0..M {
                    for i in j..M {
                        p.q_cov[d * M * M + j * M + i] = if i == j {
                            rng.random_range(0.2..0.5)
                        } else {
                            0.1 * n01(rng)
                        };
                    }
                }
            }
        }
    }
    p.lengthscales
        .iter_mut()
        .for_each(|v| *v = rng.random_range(0.8..2.0));
    p.process_noise_var = vec![0.02, 0.01, 0.03];
    p.obs_noise_var = vec![0.2, 0.3];
    p
}

fn batch() -> Vec<Window> {
    vec![
        Window {
            sequence: 0,
            start: 0,
            len: 8,
        },
        Window {
            sequence: 1,
            start: 2,
            len: 5,
        },
        Window {
            sequence: 2,
            start: 1,
            len: 7,
        },
    ]
}

fn group_of(config: &ModelConfig, i: usize) -> &'static str {
    let ly = config.layout();
    match i {
        _ if i < ly.kernel_variance => "inducing",
        _ if i < ly.lengthscales => "kernel_variance",
        _ if i < ly.q_mean => "lengthscales",
        _ if i < ly.q_cov => "q_mean",
        _ if i < ly.process_noise => "q_cov",
        _ if i < ly.obs_noise => "process_noise",
        _ => "obs_noise",
    }
}

/// Max over a group of |fd − an|, relative to the group's largest |an|.
fn check(config: &ModelConfig, an: &[f64], fd: &[f64], label: &str) {
    let mut groups: std::collections::BTreeMap<&str, (f64, f64)> = Default::default();
    for i in 0..an.len() {
        let g = groups.entry(group_of(config, i)).or_default();
        g.0 = g.0.max((an[i] - fd[i]).abs());
        g.1 = g.1.max(an[i].abs());
    }
    assert_eq!(groups.len(), 7);
    for (name, (err, scale)) in groups {
        assert!(
            scale > 1e-6,
            "{label} {name}: gradient vanishes ({scale:e})"
        );
        let rel = err / scale;
        assert!(
            rel <= 1e-5,
            "{label} {name}: relative error {rel:e} (scale {scale:e})"
        );
    }
}

fn run_case(kernel: KernelKind, param: Parametrization, cov: CovarianceStructure, shared: bool) {
    let label = format!("{kernel:?}/{param:?}/{cov:?}/shared={shared}");
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let mut config = ModelConfig::new(DX, DY, DU, M);
    config.kernel = kernel;
    config.parametrization = param;
    config.covariance = cov;
    config.shared_draws = shared;
    config.kmm_jitter = 1e-6;
    let data = data(&mut rng);
    let p = params(&config, &mut rng);
    let options = ElboOptions {
        particles: 4,
        burn_in_fraction: 0.25,
        scaling: LossScaling::Standard { n_windows: 5.0 },
        initial_state: InitialStateMode::Outputs,
        windows_per_task: 2,
    };
    let elbo = Elbo::new(config.clone(), data, options).unwrap();
    let theta = p.unconstrained(&config);
    let b = batch();
    let seed = 99;
    let mut grad = vec![0.0; theta.len()];
    elbo.loss_and_grad(&theta, &b, seed, &mut grad).unwrap();
    let h = 1e-5;
    let mut scratch = vec![0.0; theta.len()];
    let fd: Vec<f64> = (0..theta.len())
        .map(|i| {
            let mut tp = theta.clone();
            tp[i] += h;
            let fp = elbo.loss_and_grad(&tp, &b, seed, &mut scratch).unwrap();
            tp[i] -= 2.0 * h;
            let fm = elbo.loss_and_grad(&tp, &b, seed, &mut scratch).unwrap();
            (fp - fm) / (2.0 * h)
        })
        .collect();
    check(&config, &grad, &fd, &label);
}

#[test]
fn matern_unwhitened_diagonal() {
    run_case(
        KernelKind::Matern32,
        Parametrization::Unwhitened,
        CovarianceStructure::Diagonal,
        false,
    );
}

#[test]
fn matern_unwhitened_diagonal_shared_draws() {
    run_case(
        KernelKind::Matern32,
        Parametrization::Unwhitened,
        CovarianceStructure::Diagonal,
        true,
    );
}

#[test]
fn matern_whitened_diagonal() {
    run_case(
        KernelKind::Matern32,
        Parametrization::Whitened,
        CovarianceStructure::Diagonal,
        false,
    );
}

#[test]
fn matern_unwhitened_full() {
    run_case(
        KernelKind::Matern32,
        Parametrization::Unwhitened,
        CovarianceStructure::Full,
        false,
    );
}

#[test]
fn matern_whitened_full() {
    run_case(
        KernelKind::Matern32,
        Parametrization::Whitened,
        CovarianceStructure::Full,
        false,
    );
}

#[test]
fn se_unwhitened_diagonal() {
    run_case(
        KernelKind::SquaredExponential,
        Parametrization::Unwhitened,
        CovarianceStructure::Diagonal,
        false,
    );
}

#[test]
fn se_whitened_diagonal() {
    run_case(
        KernelKind::SquaredExponential,
        Parametrization::Whitened,
        CovarianceStructure::Diagonal,
        false,
    );
}

#[test]
fn se_unwhitened_full() {
    run_case(
        KernelKind::SquaredExponential,
        Parametrization::Unwhitened,
        CovarianceStructure::Full,
        false,
    );
}

#[test]
fn se_whitened_full() {
    run_case(
        KernelKind::SquaredExponential,
        Parametrization::Whitened,
        CovarianceStructure::Full,
        false,
    );
}

#[test]
fn initial_state_gradients() {
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let config = ModelConfig::new(DX, DY, DU, M);
    let data = data(&mut rng);
    let p = params(&config, &mut rng);
    let options = ElboOptions {
        particles: 3,
        burn_in_fraction: 0.0,
        scaling: LossScaling::Published,
        initial_state: InitialStateMode::Zeros,
        windows_per_task: 1,
    };
    let elbo = Elbo::new(config.clone(), data, options).unwrap();
    let theta = p.unconstrained(&config);
    let b = batch();
    let n0 = b.len() * DX;
    let mean: Vec<f64> = (0..n0).map(|_| 0.3 * n01(&mut rng)).collect();
    let std: Vec<f64> = (0..n0).map(|_| rng.random_range(0.1..0.4)).collect();
    let eval = |mean: &[f64], std: &[f64], gm: &mut [f64], gs: &mut [f64]| {
        let mut g = vec![0.0; theta.len()];
        elbo.evaluate(
            &theta,
            &b,
            InitialStates { mean, std },
            3,
            &mut g,
            InitialStateGrads { mean: gm, std: gs },
        )
        .unwrap()
        .loss
    };
    let (mut gm, mut gs) = (vec![0.0; n0], vec![0.0; n0]);
    eval(&mean, &std, &mut gm, &mut gs);
    let (mut s1, mut s2) = (vec![0.0; n0], vec![0.0; n0]);
    let h = 1e-5;
    for (which, an) in [(0, &gm), (1, &gs)] {
        let scale = an.iter().fold(0.0f64, |a, v| a.max(v.abs()));
        assert!(scale > 1e-6);
        for i in 0..n0 {
            let (mut mp, mut sp) = (mean.clone(), std.clone());
            let v = if which == 0 { &mut mp } else { &mut sp };
            v[i] += h;
            let fp = eval(&mp, &sp, &mut s1, &mut s2);
            let v = if which == 0 { &mut mp } else { &mut sp };
            v[i] -= 2.0 * h;
            let fm = eval(&mp, &sp, &mut s1, &mut s2);
            let fd = (fp - fm) / (2.0 * h);
            assert!(
                (fd - an[i]).abs() / scale <= 1e-5,
                "init {which} [{i}]: fd {fd} an {}",
                an[i]
            );
        }
    }
}
