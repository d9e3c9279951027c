//! Properties of the ELBO estimate: Monte-Carlo convergence to the many-particle value,
//! determinism for a seed regardless of the thread count, and error handling.

mod common;

use flapssm_prssm::{
    Elbo, ElboOptions, InitialStateMode, LossScaling, ModelConfig, Objective, ObjectiveError,
    ParamInit, Params, Sequence, TrainingData, Window,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

fn setup(particles: usize) -> (Elbo, Vec<f64>, Vec<Window>) {
    let mut rng = ChaCha8Rng::seed_from_u64(21);
    let config = ModelConfig::new(3, 2, 2, 8);
    let seqs = (0..4)
        .map(|_| Sequence {
            inputs: (0..25 * 2)
                .map(|_| StandardNormal.sample(&mut rng))
                .collect(),
            outputs: (0..25 * 2)
                .map(|_| 0.3 * Distribution::<f64>::sample(&StandardNormal, &mut rng))
                .collect(),
        })
        .collect();
    let data = TrainingData::new(2, 2, seqs).unwrap();
    let init = ParamInit {
        process_noise_var: 0.01,
        obs_noise_var: 0.1,
        ..ParamInit::default()
    };
    let p = Params::init(&config, &init, 2);
    let options = ElboOptions {
        particles,
        burn_in_fraction: 0.2,
        scaling: LossScaling::Standard { n_windows: 4.0 },
        initial_state: InitialStateMode::Zeros,
        windows_per_task: 1,
    };
    let elbo = Elbo::new(config.clone(), data, options).unwrap();
    let batch = (0..4)
        .map(|s| Window {
            sequence: s,
            start: 0,
            len: 25,
        })
        .collect();
    (elbo, p.unconstrained(&config), batch)
}

fn mean_std(v: &[f64]) -> (f64, f64) {
    let n = v.len() as f64;
    let m = v.iter().sum::<f64>() / n;
    (
        m,
        (v.iter().map(|x| (x - m).powi(2)).sum::<f64>() / (n - 1.0)).sqrt(),
    )
}

#[test]
fn mc_estimate_converges_to_many_particle_value() {
    let (e_ref, theta, batch) = setup(4000);
    let mut g = vec![0.0; theta.len()];
    let reference = e_ref.loss_and_grad(&theta, &batch, 1, &mut g).unwrap();
    let mut stds = Vec::new();
    for p in [4usize, 64] {
        let (e, _, _) = setup(p);
        let vals: Vec<f64> = (0..60)
            .map(|s| e.loss_and_grad(&theta, &batch, 100 + s, &mut g).unwrap())
            .collect();
        let (m, sd) = mean_std(&vals);
        let se = sd / (vals.len() as f64).sqrt();
        // Unbiased: the mean of 60 independent estimates lies within 4 standard errors.
        assert!(
            (m - reference).abs() < 4.0 * se + 1e-9 * reference.abs(),
            "P={p}: {m} vs {reference} (se {se})"
        );
        stds.push(sd);
    }
    // Spread shrinks like 1/√P: 16× particles → ≈ 4× smaller.
    let ratio = stds[0] / stds[1];
    assert!((2.5..6.5).contains(&ratio), "std ratio {ratio}");
}

#[test]
fn same_seed_same_result_regardless_of_threads() {
    let (e, theta, batch) = setup(5);
    let run = |threads: usize| {
        common::with_threads(threads, || {
            let mut g = vec![0.0; theta.len()];
            let l = e.loss_and_grad(&theta, &batch, 9, &mut g).unwrap();
            (l, g)
        })
    };
    let (l1, g1) = run(1);
    let (l3, g3) = run(3);
    assert_eq!(l1.to_bits(), l3.to_bits());
    assert!(g1.iter().zip(&g3).all(|(a, b)| a.to_bits() == b.to_bits()));
    let mut g = vec![0.0; theta.len()];
    assert_ne!(e.loss_and_grad(&theta, &batch, 10, &mut g).unwrap(), l1);
}

#[test]
fn bad_windows_and_vectors_are_errors() {
    let (e, theta, _) = setup(2);
    let mut g = vec![0.0; theta.len()];
    let bad = [Window {
        sequence: 0,
        start: 20,
        len: 10,
    }];
    assert!(matches!(
        e.loss_and_grad(&theta, &bad, 0, &mut g),
        Err(ObjectiveError::Shape(_))
    ));
    let bad = [Window {
        sequence: 9,
        start: 0,
        len: 3,
    }];
    assert!(matches!(
        e.loss_and_grad(&theta, &bad, 0, &mut g),
        Err(ObjectiveError::Shape(_))
    ));
    let ok = [Window {
        sequence: 0,
        start: 0,
        len: 3,
    }];
    assert!(matches!(
        e.loss_and_grad(&theta[1..], &ok, 0, &mut g),
        Err(ObjectiveError::Shape(_))
    ));
    let mut nan = theta.clone();
    nan[0] = f64::NAN;
    assert!(matches!(
        e.loss_and_grad(&nan, &ok, 0, &mut g),
        Err(ObjectiveError::NonFinite { .. })
    ));
}
