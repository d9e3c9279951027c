//! Trainer tests on analytic objectives: convergence to an independently computed optimum,
//! bit-identical resume, divergence recovery, best-model selection and schedules.

#![allow(clippy::needless_range_loop)] // index-based Newton solve reads like the math

use std::cell::RefCell;
use std::sync::atomic::{AtomicBool, Ordering};

use flapssm_prssm::train::{
    BestBy, Budget, Checkpoint, DivergenceGuard, Evaluation, LrSchedule, TrainConfig, TrainError,
    TrainEvent, TrainHooks, TrainOutcome, WindowSpec, train,
};
use flapssm_prssm::{Objective, ObjectiveError, Window};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

/// L2-regularized logistic regression; each "sequence" is one sample (length 1).
/// loss(w) = Σ_{i ∈ batch} log(1 + exp(−y_i xᵢᵀw)) · (n / |batch|) + ½ λ ‖w‖².
struct Logistic {
    x: Vec<Vec<f64>>,
    y: Vec<f64>,
    lambda: f64,
}

impl Logistic {
    fn new(n: usize, d: usize, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let w_true: Vec<f64> = (0..d).map(|i| 1.0 - 0.4 * i as f64).collect();
        let mut x = Vec::new();
        let mut y = Vec::new();
        for _ in 0..n {
            let xi: Vec<f64> = (0..d).map(|_| rng.sample(StandardNormal)).collect();
            let z: f64 = xi.iter().zip(&w_true).map(|(a, b)| a * b).sum();
            let p = 1.0 / (1.0 + (-z).exp());
            y.push(if rng.random::<f64>() < p { 1.0 } else { -1.0 });
            x.push(xi);
        }
        Self { x, y, lambda: 0.1 }
    }

    /// Full-batch minimizer by Newton's method (independent of the trainer).
    fn newton_optimum(&self) -> Vec<f64> {
        let d = self.x[0].len();
        let mut w = vec![0.0; d];
        for _ in 0..50 {
            let mut g: Vec<f64> = w.iter().map(|v| self.lambda * v).collect();
            let mut h = vec![vec![0.0; d]; d];
            for i in 0..d {
                h[i][i] = self.lambda;
            }
            for (xi, &yi) in self.x.iter().zip(&self.y) {
                let z: f64 = xi.iter().zip(&w).map(|(a, b)| a * b).sum();
                let s = 1.0 / (1.0 + (yi * z).exp());
                let curv = s * (1.0 - s);
                for a in 0..d {
                    g[a] -= yi * s * xi[a];
                    for b in 0..d {
                        h[a][b] += curv * xi[a] * xi[b];
                    }
                }
            }
            // Solve h Δ = g by Gaussian elimination.
            let mut aug: Vec<Vec<f64>> = (0..d)
                .map(|i| {
                    let mut r = h[i].clone();
                    r.push(g[i]);
                    r
                })
                .collect();
            for c in 0..d {
                for r in c + 1..d {
                    let f = aug[r][c] / aug[c][c];
                    for k in c..=d {
                        aug[r][k] -= f * aug[c][k];
                    }
                }
            }
            let mut delta = vec![0.0; d];
            for c in (0..d).rev() {
                let s: f64 = (c + 1..d).map(|k| aug[c][k] * delta[k]).sum();
                delta[c] = (aug[c][d] - s) / aug[c][c];
            }
            for a in 0..d {
                w[a] -= delta[a];
            }
        }
        w
    }
}

impl Objective for Logistic {
    fn n_params(&self) -> usize {
        self.x[0].len()
    }

    fn loss_and_grad(
        &self,
        w: &[f64],
        batch: &[Window],
        _seed: u64,
        grad: &mut [f64],
    ) -> Result<f64, ObjectiveError> {
        let scale = self.y.len() as f64 / batch.len() as f64;
        let mut loss = 0.5 * self.lambda * w.iter().map(|v| v * v).sum::<f64>();
        for (g, v) in grad.iter_mut().zip(w) {
            *g = self.lambda * v;
        }
        for win in batch {
            let (xi, yi) = (&self.x[win.sequence], self.y[win.sequence]);
            let m = yi * xi.iter().zip(w).map(|(a, b)| a * b).sum::<f64>();
            loss += scale * (-m).exp().ln_1p();
            let s = 1.0 / (1.0 + m.exp());
            for (g, a) in grad.iter_mut().zip(xi) {
                *g -= scale * yi * s * a;
            }
        }
        Ok(loss)
    }
}

/// ½‖θ − c‖² plus seeded gradient noise of size `noise`; NaN beyond radius `nan_radius`.
struct NoisyQuadratic {
    c: Vec<f64>,
    noise: f64,
    nan_radius: f64,
}

impl Objective for NoisyQuadratic {
    fn n_params(&self) -> usize {
        self.c.len()
    }

    fn loss_and_grad(
        &self,
        theta: &[f64],
        batch: &[Window],
        seed: u64,
        grad: &mut [f64],
    ) -> Result<f64, ObjectiveError> {
        let mut rng = ChaCha8Rng::seed_from_u64(seed ^ batch[0].sequence as u64);
        let r2: f64 = theta.iter().map(|v| v * v).sum();
        if r2.sqrt() > self.nan_radius {
            return Ok(f64::NAN);
        }
        let mut loss = 0.0;
        for ((g, t), c) in grad.iter_mut().zip(theta).zip(&self.c) {
            loss += 0.5 * (t - c) * (t - c);
            *g = t - c + self.noise * rng.sample::<f64, _>(StandardNormal);
        }
        Ok(loss)
    }
}

fn fd_gradient(obj: &dyn Objective, p: &[f64], batch: &[Window]) -> Vec<f64> {
    let mut g = vec![0.0; p.len()];
    let h = 1e-6;
    (0..p.len())
        .map(|i| {
            let mut q = p.to_vec();
            q[i] += h;
            let lp = obj.loss_and_grad(&q, batch, 0, &mut g).unwrap();
            q[i] -= 2.0 * h;
            let lm = obj.loss_and_grad(&q, batch, 0, &mut g).unwrap();
            (lp - lm) / (2.0 * h)
        })
        .collect()
}

#[test]
fn logistic_gradient_matches_finite_differences() {
    let obj = Logistic::new(40, 3, 1);
    let w = [0.3, -0.2, 0.5];
    let batch: Vec<Window> = (0..7)
        .map(|i| Window {
            sequence: i * 3,
            start: 0,
            len: 1,
        })
        .collect();
    let mut g = vec![0.0; 3];
    obj.loss_and_grad(&w, &batch, 0, &mut g).unwrap();
    let fd = fd_gradient(&obj, &w, &batch);
    for (a, b) in g.iter().zip(&fd) {
        assert!((a - b).abs() < 1e-6 * (1.0 + b.abs()), "{a} vs {b}");
    }
}

#[test]
fn minibatch_adam_with_cosine_decay_reaches_the_newton_optimum() {
    let obj = Logistic::new(200, 3, 2);
    let w_star = obj.newton_optimum();
    let config = TrainConfig {
        budget: Budget::Epochs(150),
        windows: WindowSpec::WholeSequences,
        batch_size: 20,
        lr: 0.05,
        schedule: LrSchedule::Cosine { final_factor: 0.0 },
        seed: 9,
        ..TrainConfig::default()
    };
    let out = train(
        &obj,
        &[1; 200],
        &[0.0; 3],
        &config,
        TrainHooks::default(),
        None,
    )
    .unwrap();
    assert_eq!(out.state.step, 150 * 10);
    for (a, b) in out.last_params().iter().zip(&w_star) {
        assert!((a - b).abs() < 5e-3, "trained {a} vs Newton {b}");
    }
}

/// Trains `obj` on one 3-step sequence from zero parameters (no checkpoint).
fn train_from_zero(
    obj: &NoisyQuadratic,
    config: &TrainConfig,
    hooks: TrainHooks<'_>,
) -> Result<TrainOutcome, TrainError> {
    train(obj, &[3], &[0.0; 3], config, hooks, None)
}

fn noisy() -> NoisyQuadratic {
    NoisyQuadratic {
        c: vec![1.0, -2.0, 0.5, 3.0],
        noise: 0.3,
        nan_radius: f64::INFINITY,
    }
}

fn resume_config() -> TrainConfig {
    TrainConfig {
        budget: Budget::Epochs(12),
        windows: WindowSpec::Windows { len: 5, stride: 2 },
        batch_size: 3,
        lr: 0.1,
        schedule: LrSchedule::Step {
            every: 20,
            factor: 0.7,
        },
        seed: 77,
        checkpoint_every: 5,
        ..TrainConfig::default()
    }
}

/// Deterministic evaluator whose "validation RMSE" is the distance to a point off the optimum.
fn eval_fn(p: &[f64]) -> Result<Evaluation, String> {
    let d: f64 = p
        .iter()
        .zip([0.8, -1.5, 0.0, 2.0])
        .map(|(a, b)| (a - b) * (a - b))
        .sum();
    Ok(Evaluation {
        train_rmse: Some(d.sqrt() * 0.5),
        val_rmse: Some(d.sqrt()),
    })
}

#[test]
fn resume_is_bit_identical_to_an_uninterrupted_run() {
    let obj = noisy();
    let lens = [20, 13, 9];
    let config = resume_config();
    let dir = tempfile::tempdir().unwrap();

    let mut ev = eval_fn;
    let full = train(
        &obj,
        &lens,
        &[0.0; 4],
        &config,
        TrainHooks {
            evaluate: Some(&mut ev),
            ..TrainHooks::default()
        },
        None,
    )
    .unwrap();
    assert!(!full.interrupted);

    // Interrupt mid-epoch (step 23 of 72) through the stop flag, as Ctrl-C would.
    let ck_path = dir.path().join("run.ckpt.json");
    let stop = AtomicBool::new(false);
    let mut on_event = |e: &TrainEvent<'_>| {
        if let TrainEvent::Step { step: 22, .. } = e {
            stop.store(true, Ordering::SeqCst);
        }
    };
    let mut ev = eval_fn;
    let part = train(
        &obj,
        &lens,
        &[0.0; 4],
        &config,
        TrainHooks {
            evaluate: Some(&mut ev),
            progress: Some(&mut on_event),
            stop: Some(&stop),
            checkpoint: Some(ck_path.clone()),
        },
        None,
    )
    .unwrap();
    assert!(part.interrupted);
    assert_eq!(part.state.step, 23);

    // Resume from the file; interrupt again after the periodic checkpoint at the end of epoch 10 (step 60), then
    // resume from that one.
    let ck = Checkpoint::load(&ck_path).unwrap();
    assert_eq!(ck.state, part.state);
    let stop2 = AtomicBool::new(false);
    let mut on_event2 = |e: &TrainEvent<'_>| {
        if let TrainEvent::Checkpoint { step, .. } = e
            && *step == 60
        {
            stop2.store(true, Ordering::SeqCst);
        }
    };
    let mut ev = eval_fn;
    let part2 = train(
        &obj,
        &lens,
        &[],
        &config,
        TrainHooks {
            evaluate: Some(&mut ev),
            progress: Some(&mut on_event2),
            stop: Some(&stop2),
            checkpoint: Some(ck_path.clone()),
        },
        Some(ck),
    )
    .unwrap();
    assert!(part2.interrupted);
    assert_eq!(part2.state.step, 60);
    // The last leg writes no periodic checkpoints: the interval is not part of the arithmetic.
    let mut ev = eval_fn;
    let resumed = train(
        &obj,
        &lens,
        &[],
        &TrainConfig {
            checkpoint_every: 0,
            ..config.clone()
        },
        TrainHooks {
            evaluate: Some(&mut ev),
            ..TrainHooks::default()
        },
        Some(Checkpoint::load(&ck_path).unwrap()),
    )
    .unwrap();

    let bits = |v: &[f64]| v.iter().map(|x| x.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(resumed.last_params()), bits(full.last_params()));
    assert_eq!(bits(resumed.best_params()), bits(full.best_params()));
    assert_eq!(bits(&resumed.state.adam.m), bits(&full.state.adam.m));
    assert_eq!(bits(&resumed.state.adam.v), bits(&full.state.adam.v));
    assert_eq!(resumed.state, full.state);
    // …and the run did learn: close to c despite the gradient noise.
    for (a, b) in full.last_params().iter().zip(&obj.c) {
        assert!((a - b).abs() < 0.3, "{a} vs {b}");
    }
}

#[test]
fn resume_with_a_different_configuration_is_refused() {
    let obj = noisy();
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("ck.json");
    let mut config = resume_config();
    config.budget = Budget::Epochs(5);
    train(
        &obj,
        &[20, 13, 9],
        &[0.0; 4],
        &config,
        TrainHooks {
            checkpoint: Some(path.clone()),
            ..TrainHooks::default()
        },
        None,
    )
    .unwrap();
    let ck = Checkpoint::load(&path).unwrap();
    config.lr = 0.2;
    let err = train(
        &obj,
        &[20, 13, 9],
        &[],
        &config,
        TrainHooks::default(),
        Some(ck),
    )
    .unwrap_err();
    assert!(
        matches!(&err, TrainError::ResumeMismatch { field, .. } if field == "lr"),
        "{err}"
    );
    std::fs::write(&path, b"{\"format_version\": 1, \"config\": 3}").unwrap();
    let err = Checkpoint::load(&path).unwrap_err().to_string();
    assert!(err.contains("ck.json") && err.contains("line 1"), "{err}");
}

#[test]
fn divergent_learning_rate_is_rejected_reduced_and_recovered() {
    // lr 50 overshoots ½‖θ − c‖² by ~50 per coordinate; beyond radius 20 the loss is NaN.
    let obj = NoisyQuadratic {
        c: vec![1.0, -2.0, 0.5],
        noise: 0.0,
        nan_radius: 20.0,
    };
    let config = TrainConfig {
        budget: Budget::Iterations(400),
        batch_size: 1,
        lr: 50.0,
        schedule: LrSchedule::Exponential { final_factor: 0.01 },
        ..TrainConfig::default()
    };
    let messages = RefCell::new(Vec::new());
    let mut on_event = |e: &TrainEvent<'_>| {
        if let TrainEvent::Rejected {
            step,
            reason,
            lr_scale,
            ..
        } = e
        {
            messages
                .borrow_mut()
                .push(format!("step {step}: {reason}; lr scale {lr_scale}"));
        }
    };
    let out = train_from_zero(
        &obj,
        &config,
        TrainHooks {
            progress: Some(&mut on_event),
            ..TrainHooks::default()
        },
    )
    .unwrap();
    let messages = messages.into_inner();
    assert!(!messages.is_empty());
    assert!(messages[0].contains("loss is NaN"), "{messages:?}");
    assert_eq!(out.state.rejected as usize, messages.len());
    assert!(out.state.lr_scale < 1.0);
    for (a, b) in out.last_params().iter().zip(&obj.c) {
        assert!((a - b).abs() < 1e-3, "{a} vs {b}");
    }

    // A jump of the loss (finite) is also caught.
    let obj = NoisyQuadratic {
        c: vec![1.0, -2.0, 0.5],
        noise: 0.0,
        nan_radius: f64::INFINITY,
    };
    let config = TrainConfig {
        lr: 200.0,
        ..config
    };
    let mut rejected = 0;
    let mut on_event = |e: &TrainEvent<'_>| {
        if let TrainEvent::Rejected { reason, .. } = e {
            assert!(reason.contains("before the last step"), "{reason}");
            rejected += 1;
        }
    };
    let out = train_from_zero(
        &obj,
        &config,
        TrainHooks {
            progress: Some(&mut on_event),
            ..TrainHooks::default()
        },
    )
    .unwrap();
    assert!(rejected > 0);
    for (a, b) in out.last_params().iter().zip(&obj.c) {
        assert!((a - b).abs() < 1e-3, "{a} vs {b}");
    }
}

#[test]
fn unrecoverable_divergence_and_bad_start_are_errors() {
    // NaN everywhere except the start: every retry fails.
    let obj = NoisyQuadratic {
        c: vec![5.0],
        noise: 0.0,
        nan_radius: 1e-9,
    };
    let config = TrainConfig {
        budget: Budget::Iterations(10),
        batch_size: 1,
        lr: 1.0,
        divergence: DivergenceGuard {
            max_retries: 3,
            ..DivergenceGuard::default()
        },
        ..TrainConfig::default()
    };
    let err = train(&obj, &[1], &[0.0], &config, TrainHooks::default(), None).unwrap_err();
    assert!(
        matches!(
            err,
            TrainError::Diverged {
                step: 1,
                retries: 3,
                ..
            }
        ),
        "{err}"
    );
    let err = train(&obj, &[1], &[1.0], &config, TrainHooks::default(), None).unwrap_err();
    assert!(matches!(err, TrainError::BadStart { step: 0, .. }), "{err}");
    let err = train(
        &obj,
        &[1],
        &[1.0, 2.0],
        &config,
        TrainHooks::default(),
        None,
    )
    .unwrap_err();
    assert!(
        matches!(
            err,
            TrainError::ParamCount {
                found: 2,
                expected: 1
            }
        ),
        "{err}"
    );
    let bad = TrainConfig { lr: -1.0, ..config };
    let err = train(&obj, &[1], &[0.0], &bad, TrainHooks::default(), None).unwrap_err();
    assert!(err.to_string().contains("lr"), "{err}");
}

#[test]
fn best_model_is_the_lowest_validation_error_and_lr_follows_the_schedule() {
    let obj = noisy();
    let config = TrainConfig {
        budget: Budget::Epochs(30),
        batch_size: 2,
        lr: 0.2,
        schedule: LrSchedule::Step {
            every: 7,
            factor: 0.5,
        },
        ..TrainConfig::default()
    };
    let mut lrs = Vec::new();
    let mut on_event = |e: &TrainEvent<'_>| {
        if let TrainEvent::Step { step, lr, .. } = e {
            lrs.push((*step, *lr));
        }
    };
    let mut ev = eval_fn;
    let out = train(
        &obj,
        &[4, 4, 4, 4],
        &[0.0; 4],
        &config,
        TrainHooks {
            evaluate: Some(&mut ev),
            progress: Some(&mut on_event),
            ..TrainHooks::default()
        },
        None,
    )
    .unwrap();
    for &(t, lr) in &lrs {
        assert_eq!(lr, 0.2 * 0.5f64.powi((t / 7) as i32));
    }
    assert_eq!(out.state.history.len(), 30);
    let (best_epoch, best_val) = out
        .state
        .history
        .iter()
        .map(|r| (r.epoch, r.val_rmse.unwrap()))
        .min_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap();
    let best = out.state.best.as_ref().unwrap();
    assert_eq!(best.epoch, best_epoch);
    assert_eq!(best.score, best_val);
    assert_eq!(eval_fn(&best.params).unwrap().val_rmse, Some(best_val));
    // The validation target is off the optimum, so the best is not the last epoch.
    assert_ne!(best_epoch, 29);
}

/// `BestBy::Rmse` keeps the epoch of the lowest evaluator RMSE; `BestBy::TrainingLoss` (the
/// published code's `best.ckpt`) the epoch of the lowest mean minibatch loss, whatever the
/// evaluator says. Here the evaluator's RMSE worsens every epoch while the loss falls.
#[test]
fn the_best_model_follows_the_chosen_criterion() {
    let obj = NoisyQuadratic {
        c: vec![1.0, -2.0, 0.5],
        noise: 0.0,
        nan_radius: f64::INFINITY,
    };
    let run = |best_by: BestBy| {
        let config = TrainConfig {
            budget: Budget::Epochs(20),
            batch_size: 1,
            lr: 0.05,
            best_by,
            ..TrainConfig::default()
        };
        let mut calls = 0.0;
        let mut evaluate = |_: &[f64]| {
            calls += 1.0;
            Ok(Evaluation {
                train_rmse: Some(calls),
                ..Evaluation::default()
            })
        };
        let out = train_from_zero(
            &obj,
            &config,
            TrainHooks {
                evaluate: Some(&mut evaluate),
                ..TrainHooks::default()
            },
        )
        .unwrap();
        let best = out.state.best.unwrap();
        let lowest_loss = out
            .state
            .history
            .iter()
            .min_by(|a, b| a.mean_loss.total_cmp(&b.mean_loss))
            .unwrap()
            .epoch;
        (best.epoch, lowest_loss)
    };
    assert_eq!(run(BestBy::Rmse).0, 0);
    let (best, lowest_loss) = run(BestBy::TrainingLoss);
    assert_eq!(best, lowest_loss);
    assert!(best > 10, "best epoch {best}");
}

/// The bindings' spellings of the best-model rule and the objective's form.
#[test]
fn best_by_and_objective_parse_from_their_names() {
    use flapssm_prssm::train::fit::ObjectiveForm;
    assert_eq!("rmse".parse::<BestBy>(), Ok(BestBy::Rmse));
    assert_eq!("training-loss".parse::<BestBy>(), Ok(BestBy::TrainingLoss));
    assert!(
        "lowest"
            .parse::<BestBy>()
            .unwrap_err()
            .contains("rmse or training-loss")
    );
    assert_eq!(
        "standard".parse::<ObjectiveForm>(),
        Ok(ObjectiveForm::Standard)
    );
    assert_eq!(
        "published-code".parse::<ObjectiveForm>(),
        Ok(ObjectiveForm::PublishedCode)
    );
    assert!("published_code".parse::<ObjectiveForm>().is_err());
}

/// Early stopping ends the run once `patience` evaluated epochs in a row bring no new best
/// model; the steps before are those of the full run, and resuming the final checkpoint
/// does not train further.
#[test]
fn early_stopping_ends_the_run_after_patience_epochs_without_a_new_best() {
    let obj = noisy();
    let lens = [20, 13, 9];
    let config = TrainConfig {
        budget: Budget::Epochs(200),
        patience: Some(4),
        ..resume_config()
    };
    let dir = tempfile::tempdir().unwrap();
    let ck_path = dir.path().join("early.ckpt.json");
    let run = |config: &TrainConfig, resume: Option<Checkpoint>| {
        let mut ev = eval_fn;
        train(
            &obj,
            &lens,
            &[0.0; 4],
            config,
            TrainHooks {
                evaluate: Some(&mut ev),
                checkpoint: Some(ck_path.clone()),
                ..TrainHooks::default()
            },
            resume,
        )
        .unwrap()
    };
    let early = run(&config, None);
    let h = &early.state.history;
    assert!(early.early_stopped && early.state.step < early.total_steps);
    // The validation distance falls, then rises as θ moves past the validation point
    // towards the optimum: the best epoch is followed by exactly 4 epochs without a new best.
    let best = early.state.best.as_ref().unwrap().epoch as usize;
    assert_eq!(h.len(), best + 1 + 4, "best epoch {best}");
    assert!(h[best].is_best && h[best + 1..].iter().all(|r| !r.is_best));

    let full = run(
        &TrainConfig {
            patience: None,
            ..config.clone()
        },
        None,
    );
    assert!(!full.early_stopped && full.state.step == full.total_steps);
    assert_eq!(&full.state.history[..h.len()], &h[..]);
    assert_eq!(full.state.best, early.state.best);

    // The final checkpoint (written by the full run) is replaced by the early run's.
    let early = run(&config, None);
    let again = run(&config, Some(Checkpoint::load(&ck_path).unwrap()));
    assert!(again.early_stopped);
    assert_eq!(again.state, early.state);

    let zero = TrainConfig {
        patience: Some(0),
        ..config
    };
    let err = train(&obj, &lens, &[0.0; 4], &zero, TrainHooks::default(), None).unwrap_err();
    assert!(err.to_string().contains("patience"), "{err}");
}
