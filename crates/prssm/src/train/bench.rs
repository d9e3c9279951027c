//! Speed measurements of the paper's configuration (used by `flapssm bench` and the
//! criterion benches), on synthetic data of the paper's shapes.
//!
//! FLOP estimates (prssm-notes §4): a training step of the paper's shapes costs ≈ 45 MFLOP
//! forward + backward for `N = 480` particle-windows, i.e. [`TRAIN_FLOP_PER_POINT_STEP`] per
//! particle, window and time step; a prediction step ≈ 14 MFLOP / 480 =
//! [`PREDICT_FLOP_PER_POINT_STEP`] per particle and step.

use std::time::Instant;

use super::batches::{BatchPlan, WindowSpec, derive_seed};
use super::fit::{FitSpec, Preset};
use crate::elbo::{Elbo, ElboError, ElboOptions, Sequence, TrainingData};
use crate::model::PrssmModel;
use crate::params::Params;
use crate::predict;
use crate::stream::StreamPredictor;
use crate::systems::random_input;
use crate::{Objective, ObjectiveError, Window};

/// Estimated FLOP per (particle, window, step) of a training step (forward + backward).
pub const TRAIN_FLOP_PER_POINT_STEP: f64 = 45e6 / 480.0;
/// Estimated FLOP per (particle, step) of prediction (forward only).
pub const PREDICT_FLOP_PER_POINT_STEP: f64 = 14e6 / 480.0;
/// The authors' code: one training epoch (s), prssm-notes §3.
pub const AUTHORS_EPOCH_S: f64 = 81.8;
/// The authors' code: prediction of one 470-step trajectory with 30 particles (s).
pub const AUTHORS_PREDICT_S: f64 = 0.152;

/// `n` synthetic sequences of `len` steps with 7 smooth random inputs and 5 outputs
/// (standardized scale), seeded.
pub fn synthetic_sequences(n: usize, len: usize, seed: u64) -> Vec<Sequence> {
    (0..n)
        .map(|i| {
            let chans = |d: usize, stream: u64| -> Vec<Vec<f64>> {
                (0..d)
                    .map(|c| {
                        random_input(len, 1.0, 6, derive_seed(seed, stream, (i * 16 + c) as u64))
                    })
                    .collect()
            };
            let (u, y) = (chans(7, 10), chans(5, 11));
            Sequence {
                inputs: (0..len).flat_map(|t| u.iter().map(move |c| c[t])).collect(),
                outputs: (0..len).flat_map(|t| y.iter().map(move |c| c[t])).collect(),
            }
        })
        .collect()
}

/// The paper's ELBO (D_x 12, M 100, Matern-3/2, 30 particles, 20 % burn-in) on
/// `n_sequences` synthetic sequences of `len` steps, with its initial parameters.
///
/// # Errors
/// [`ElboError`] (not expected for these shapes).
pub fn paper_objective(
    n_sequences: usize,
    len: usize,
    seed: u64,
) -> Result<(Elbo, Vec<f64>), ElboError> {
    let spec = FitSpec::preset(Preset::Paper, 7, 5);
    let data = TrainingData::new(7, 5, synthetic_sequences(n_sequences, len, seed))?;
    let elbo = Elbo::new(spec.model.clone(), data, ElboOptions::paper(n_sequences))?;
    let params = Params::init(&spec.model, &spec.init, seed).unconstrained(&spec.model);
    Ok((elbo, params))
}

/// Times `n_batches` minibatches (batch 16 whole sequences) of `objective` at `params`;
/// returns (seconds, number of (particle, window, step) points processed).
///
/// # Errors
/// The objective's error.
pub fn time_batches(
    objective: &Elbo,
    params: &[f64],
    n_batches: usize,
    seed: u64,
) -> Result<(f64, f64), ObjectiveError> {
    let lens = objective.data().lens().to_vec();
    let plan = BatchPlan::new(&lens, WindowSpec::WholeSequences, 16)
        .map_err(|e| ObjectiveError::Shape(e.to_string()))?;
    let mut order = Vec::new();
    plan.epoch_order(seed, 0, &mut order);
    let mut batch: Vec<Window> = Vec::new();
    let mut grad = vec![0.0; objective.n_params()];
    let particles = objective.options().particles as f64;
    let mut points = 0.0;
    let t0 = Instant::now();
    for b in 0..n_batches.min(plan.batches_per_epoch()) {
        plan.batch_into(&order, b, &mut batch);
        objective.loss_and_grad(params, &batch, derive_seed(seed, 2, b as u64), &mut grad)?;
        points += batch.iter().map(|w| w.len as f64).sum::<f64>() * particles;
    }
    Ok((t0.elapsed().as_secs_f64(), points))
}

/// A paper-shaped model (fresh parameters) for prediction timings.
pub fn paper_model(seed: u64) -> PrssmModel {
    let spec = FitSpec::preset(Preset::Paper, 7, 5);
    PrssmModel {
        params: Params::init(&spec.model, &spec.init, seed),
        config: spec.model,
        normalization: None,
        training: serde_json::Value::Null,
    }
}

/// Median seconds of `reps` open-loop predictions of a `len`-step trajectory with
/// `particles` particles (single-threaded).
///
/// # Errors
/// Prediction errors.
pub fn time_prediction(
    model: &PrssmModel,
    len: usize,
    particles: usize,
    reps: usize,
) -> Result<f64, ObjectiveError> {
    let seq = &synthetic_sequences(1, len, 5)[0];
    let zero = vec![0.0; model.config.n_state];
    let mut times = Vec::with_capacity(reps);
    for r in 0..reps.max(1) {
        let t0 = Instant::now();
        let p = predict::predict(
            &model.config,
            &model.params,
            &seq.inputs,
            &zero,
            &zero,
            particles,
            r as u64,
        )?;
        times.push(t0.elapsed().as_secs_f64());
        std::hint::black_box(p);
    }
    times.sort_by(f64::total_cmp);
    Ok(times[times.len() / 2])
}

/// Mean seconds per streaming step with `particles` particles over `steps` steps.
///
/// # Errors
/// Prediction errors.
pub fn time_stream_step(
    model: &PrssmModel,
    particles: usize,
    steps: usize,
) -> Result<f64, ObjectiveError> {
    let seq = &synthetic_sequences(1, steps.max(1), 6)[0];
    let zero = vec![0.0; model.config.n_state];
    let mut s = StreamPredictor::new(model, particles, &zero, &zero, 1)?;
    let du = model.config.n_input;
    s.step(&seq.inputs[..du])?;
    let t0 = Instant::now();
    for t in 0..steps.max(1) {
        let (m, _) = s.step(&seq.inputs[t * du..(t + 1) * du])?;
        std::hint::black_box(m);
    }
    Ok(t0.elapsed().as_secs_f64() / steps.max(1) as f64)
}
