//! PR-SSM training end to end: the recognition-model gradient through the engine against
//! finite differences, identification of a simulated forced Duffing oscillator, and a fit
//! with validation that does not depend on the thread count.

mod common;

use flapssm_prssm::Elbo;
mod systems;

use flapssm_prssm::train::fit::{FitSpec, fit};
use flapssm_prssm::train::{
    Budget, InitialStateSpec, LrSchedule, RecognitionConfig, RecognizedElbo, TrainConfig,
    TrainEvent, TrainHooks, WindowSpec,
};
use flapssm_prssm::{
    ElboOptions, InitialStateMode, KernelKind, LossScaling, ModelConfig, Objective, ParamInit,
    Params, Sequence, SequenceView, TrainingData, Window,
};
use systems::{Duffing, duffing_dataset};

fn sequences(data: &systems::SimulatedData) -> Vec<Sequence> {
    data.inputs
        .iter()
        .zip(&data.outputs)
        .map(|(u, y)| Sequence {
            inputs: u.clone(),
            outputs: y.clone(),
        })
        .collect()
}

/// Doerr et al.'s configuration for one input and one output (the application's `sysid`
/// preset): `D_x` 4, `M` 20, squared exponential, 50 particles, recognition model, windows of
/// 50 steps in minibatches of 10, Adam at 0.1 for 3000 iterations.
fn doerr_spec() -> FitSpec {
    let mut model = ModelConfig::new(4, 1, 1, 20);
    model.kernel = KernelKind::SquaredExponential;
    let mut spec = FitSpec::new(model);
    spec.init = ParamInit {
        process_noise_var: 0.002 * 0.002,
        obs_noise_var: 1.0,
        ..ParamInit::default()
    };
    (spec.particles, spec.eval_particles, spec.burn_in_fraction) = (50, 50, 0.0);
    spec.initial_state = InitialStateSpec::Recognition(RecognitionConfig::default());
    spec.train = TrainConfig {
        budget: Budget::Iterations(3000),
        windows: WindowSpec::Windows { len: 50, stride: 1 },
        batch_size: 10,
        lr: 0.1,
        schedule: LrSchedule::Constant,
        ..TrainConfig::default()
    };
    spec
}

#[test]
fn recognized_elbo_gradient_matches_finite_differences() {
    let data = duffing_dataset(&Duffing::default(), 3, 30, 0.1, 1);
    let seqs = sequences(&data);
    let mut config = ModelConfig::new(3, 1, 1, 6);
    config.kernel = KernelKind::SquaredExponential;
    let training = TrainingData::new(1, 1, seqs).unwrap();
    let options = ElboOptions {
        particles: 4,
        burn_in_fraction: 0.0,
        scaling: LossScaling::Standard { n_windows: 3.0 },
        initial_state: InitialStateMode::Zeros,
        windows_per_task: 2,
    };
    let elbo = Elbo::new(config.clone(), training, options).unwrap();
    let rec = RecognizedElbo::new(
        &elbo,
        RecognitionConfig {
            steps: 4,
            hidden: 3,
            init_std: 0.2,
        },
    );
    let init = ParamInit {
        process_noise_var: 1e-2,
        obs_noise_var: 0.1,
        q_mean_scale: 0.3,
        ..ParamInit::default()
    };
    let mut p = Params::init(&config, &init, 2).unconstrained(&config);
    let mut rp = rec.recognition().init_params(3);
    // Make the recognition output depend visibly on every parameter.
    for (i, v) in rp.iter_mut().enumerate() {
        *v += 0.2 * ((i as f64) * 1.3).sin();
    }
    p.extend(rp);
    let batch = [
        Window {
            sequence: 0,
            start: 0,
            len: 12,
        },
        Window {
            sequence: 2,
            start: 5,
            len: 10,
        },
        Window {
            sequence: 1,
            start: 3,
            len: 15,
        },
    ];
    let n = rec.n_params();
    let mut g = vec![0.0; n];
    rec.loss_and_grad(&p, &batch, 42, &mut g).unwrap();
    let mut tmp = vec![0.0; n];
    let n_e = rec.n_elbo_params();
    let h = 1e-5;
    let mut checked = 0;
    for i in (n_e..n).chain((0..n_e).step_by(7)) {
        let mut q = p.clone();
        q[i] += h;
        let lp = rec.loss_and_grad(&q, &batch, 42, &mut tmp).unwrap();
        q[i] -= 2.0 * h;
        let lm = rec.loss_and_grad(&q, &batch, 42, &mut tmp).unwrap();
        let fd = (lp - lm) / (2.0 * h);
        assert!(
            (fd - g[i]).abs() < 1e-5 * (1.0 + fd.abs()),
            "param {i} (recognition from {n_e}): fd {fd} vs exact {}",
            g[i]
        );
        checked += 1;
    }
    assert!(checked > n - n_e);
    assert!(g[n_e..].iter().any(|v| v.abs() > 1e-6));
}

#[test]
fn learns_a_forced_duffing_oscillator_with_calibrated_intervals() {
    let noise = 0.1;
    let sys = Duffing::default();
    let train_data = duffing_dataset(&sys, 6, 300, noise, 10);
    let test_data = duffing_dataset(&sys, 3, 300, noise, 20);
    let (train, test) = (sequences(&train_data), sequences(&test_data));

    let mut spec = doerr_spec();
    spec.model.n_state = 3;
    spec.particles = 20;
    spec.initial_state = InitialStateSpec::Recognition(RecognitionConfig {
        steps: 8,
        hidden: 16,
        init_std: 0.1,
    });
    spec.train.windows = WindowSpec::Windows { len: 60, stride: 5 };
    spec.train.budget = Budget::Iterations(2500);
    spec.train.lr = 0.05;
    spec.train.schedule = LrSchedule::Cosine { final_factor: 0.05 };
    spec.train.eval_every = 1000;
    spec.train.seed = 3;
    spec.eval_particles = 50;
    let mut last_loss = f64::NAN;
    let mut progress = |e: &TrainEvent<'_>| {
        if let TrainEvent::Step { loss, step, .. } = e {
            last_loss = *loss;
            if step % 500 == 0 {
                eprintln!("step {step}: loss {loss:.3}");
            }
        }
    };
    let out = fit(
        &spec,
        &views(&train),
        &[],
        TrainHooks {
            progress: Some(&mut progress),
            ..TrainHooks::default()
        },
        None,
    )
    .unwrap();
    eprintln!(
        "final loss {last_loss}; noise var learned {:?}",
        out.last.params.obs_noise_var
    );

    let (mut se, mut inside, mut n) = (0.0, 0, 0);
    for (i, seq) in test.iter().enumerate() {
        let pred = out
            .last
            .predict_sequence(seq.view(), 100, 1000 + i as u64)
            .unwrap();
        for t in 0..seq.outputs.len() {
            let (m, v, y) = (pred.output_mean[t], pred.output_var[t], seq.outputs[t]);
            se += (m - y) * (m - y);
            inside += usize::from((y - m).abs() <= 2.0 * v.sqrt());
            n += 1;
        }
    }
    let rmse = (se / n as f64).sqrt();
    let coverage = inside as f64 / n as f64;
    let mean_rmse = {
        let (mut s, mut c) = (0.0, 0.0);
        let mu: f64 = train.iter().flat_map(|s| &s.outputs).sum::<f64>() / (6.0 * 300.0);
        for seq in &test {
            for y in &seq.outputs {
                s += (y - mu) * (y - mu);
                c += 1.0;
            }
        }
        (s / c).sqrt()
    };
    eprintln!(
        "open-loop test RMSE {rmse:.4} (noise {noise}, mean predictor {mean_rmse:.4}), ±2σ coverage {coverage:.3}"
    );
    assert!(rmse <= 1.5 * noise, "RMSE {rmse} > 1.5 × noise {noise}");
    assert!((0.90..=0.99).contains(&coverage), "coverage {coverage}");
}

/// The evaluation rollouts run in parallel: the epoch records (training and validation RMSE)
/// and the fitted parameters are the same bits on one thread and on three.
#[test]
fn fit_with_validation_is_independent_of_the_thread_count() {
    let sys = Duffing::default();
    let train = sequences(&duffing_dataset(&sys, 4, 80, 0.1, 30));
    let val = sequences(&duffing_dataset(&sys, 3, 80, 0.1, 31));
    let mut spec = doerr_spec();
    spec.model.n_state = 2;
    spec.particles = 8;
    spec.eval_particles = 8;
    spec.train.windows = WindowSpec::Windows {
        len: 20,
        stride: 10,
    };
    spec.train.budget = Budget::Epochs(2);
    spec.train.seed = 5;
    let run = |threads: usize| {
        common::with_threads(threads, || {
            let mut records = Vec::new();
            let mut progress = |e: &TrainEvent<'_>| {
                if let TrainEvent::Epoch(r) = e {
                    records.push((r.train_rmse, r.val_rmse));
                }
            };
            let out = fit(
                &spec,
                &views(&train),
                &views(&val),
                TrainHooks {
                    progress: Some(&mut progress),
                    ..TrainHooks::default()
                },
                None,
            )
            .unwrap();
            (records, out.last.params.unconstrained(&spec.model))
        })
    };
    let bits = |v: Option<f64>| v.map(f64::to_bits);
    let (r1, p1) = run(1);
    let (r3, p3) = run(3);
    assert_eq!(r1.len(), 2);
    assert!(r1.iter().all(|(t, v)| t.is_some() && v.is_some()));
    for ((t1, v1), (t3, v3)) in r1.iter().zip(&r3) {
        assert_eq!((bits(*t1), bits(*v1)), (bits(*t3), bits(*v3)));
    }
    assert!(p1.iter().zip(&p3).all(|(a, b)| a.to_bits() == b.to_bits()));
}

fn views(sequences: &[Sequence]) -> Vec<SequenceView<'_>> {
    sequences.iter().map(Sequence::view).collect()
}
