//! Open-loop prediction: particles simulated from an initial state through the learned
//! transition, `x_{t+1} = x_t + μ(x_t, u_t) + √(σ²(x_t, u_t) + σ_x² + δ_t) ⊙ ε_t`.
//!
//! Reported moments (as the published code): particle mean, particle variance divided by
//! `P` (not `P − 1`), plus `σ_y²` for outputs and `σ_x²` for latent states.

use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::conditional::Posterior;
use crate::elbo::SequenceView;
use crate::objective::ObjectiveError;
use crate::params::{ModelConfig, Params};
use crate::step::{ParticleStep, StepFloat};
use crate::train::initial::{InitialStateError, InitialStateModel};

/// Predictive moments over `T` steps.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Prediction {
    /// Output means, row-major `T × D_y`.
    pub output_mean: Vec<f64>,
    /// Output variances (particle variance + `σ_y²`), row-major `T × D_y`.
    pub output_var: Vec<f64>,
    /// Latent means, row-major `T × D_x`.
    pub latent_mean: Vec<f64>,
    /// Latent variances (particle variance + `σ_x²`), row-major `T × D_x`.
    pub latent_var: Vec<f64>,
}

/// The conditional of a predictor with `particles` particles, after checking the
/// configuration, the parameters and the particle count.
///
/// # Errors
/// [`ObjectiveError::Shape`] for invalid settings or zero particles; factorization errors.
pub(crate) fn prediction_posterior(
    config: &ModelConfig,
    params: &Params,
    particles: usize,
) -> Result<Posterior, ObjectiveError> {
    config
        .check()
        .map_err(|e| ObjectiveError::Shape(e.to_string()))?;
    params
        .check(config)
        .map_err(|e| ObjectiveError::Shape(e.to_string()))?;
    if particles == 0 {
        return Err(ObjectiveError::Shape("particles must be ≥ 1".into()));
    }
    Posterior::new(config, params)
}

/// Why a prediction from a sequence's initial-state rule failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum PredictionError {
    /// The prediction failed (shapes, factorization).
    #[error(transparent)]
    Objective(#[from] ObjectiveError),
    /// The initial state could not be formed from the sequence.
    #[error(transparent)]
    InitialState(#[from] InitialStateError),
}

/// Open-loop prediction of a standardized sequence from its initial-state rule; moments in
/// standardized units.
///
/// # Errors
/// [`PredictionError`] when the initial state cannot be formed or the prediction fails.
pub fn predict_standardized(
    config: &ModelConfig,
    params: &Params,
    initial: &InitialStateModel,
    seq: SequenceView<'_>,
    particles: usize,
    seed: u64,
) -> Result<Prediction, PredictionError> {
    let dx = config.n_state;
    let (mut m0, mut s0) = (vec![0.0; dx], vec![0.0; dx]);
    initial.state(
        (config.n_input, config.n_output),
        seq.inputs,
        seq.outputs,
        0,
        &mut m0,
        &mut s0,
    )?;
    Ok(predict(
        config, params, seq.inputs, &m0, &s0, particles, seed,
    )?)
}

/// Particle mean and variance (divided by `P`) of `x` (`P × D_x`) at step `t`, plus the
/// noise variances. The sums over particles run in particle order for all dims at once.
pub(crate) fn moments<T: StepFloat>(
    x: &[T],
    dx: usize,
    dy: usize,
    vx: &[f64],
    vy: &[f64],
    out: &mut Prediction,
    t: usize,
) {
    let p = (x.len() / dx) as f64;
    let mean = &mut out.latent_mean[t * dx..(t + 1) * dx];
    mean.fill(0.0);
    for c in x.chunks_exact(dx) {
        mean.iter_mut().zip(c).for_each(|(m, &v)| *m += v.to_f64());
    }
    mean.iter_mut().for_each(|m| *m /= p);
    let var = &mut out.latent_var[t * dx..(t + 1) * dx];
    var.fill(0.0);
    for c in x.chunks_exact(dx) {
        var.iter_mut()
            .zip(c)
            .zip(mean.iter())
            .for_each(|((s, &v), &m)| *s += (v.to_f64() - m) * (v.to_f64() - m));
    }
    for dd in 0..dx {
        let v = var[dd] / p;
        var[dd] = v + vx[dd];
        if dd < dy {
            out.output_mean[t * dy + dd] = mean[dd];
            out.output_var[t * dy + dd] = v + vy[dd];
        }
    }
}

/// Expands per-(step, particle) draws shared by all dims (`S × P`) to `S × P × D_x`.
pub fn expand_shared_draws(eps: &[f64], dx: usize) -> Vec<f64> {
    eps.iter()
        .flat_map(|&e| std::iter::repeat_n(e, dx))
        .collect()
}

/// Simulates `P` particles from `x0` (`P × D_x` row-major) under `inputs` (row-major
/// `T × D_u`) with caller-supplied draws `eps` (`(T − 1) × P × D_x`), returning every
/// particle (`T × P × D_x`) and the moments.
///
/// # Errors
/// [`ObjectiveError::Shape`] on mismatched lengths; factorization errors.
pub fn simulate_with_draws(
    config: &ModelConfig,
    params: &Params,
    inputs: &[f64],
    x0: &[f64],
    eps: &[f64],
) -> Result<(Vec<f64>, Prediction), ObjectiveError> {
    let (dx, du, dy) = (config.n_state, config.n_input, config.n_output);
    if du == 0 && !inputs.is_empty() || du > 0 && (inputs.is_empty() || inputs.len() % du != 0) {
        return Err(ObjectiveError::Shape(format!(
            "{} input values are not a T × {du} array",
            inputs.len()
        )));
    }
    let t_n = inputs.len().checked_div(du).unwrap_or(1);
    if x0.is_empty() || x0.len() % dx != 0 {
        return Err(ObjectiveError::Shape(format!(
            "initial state has {} values, not P × {dx}",
            x0.len()
        )));
    }
    let np = x0.len() / dx;
    if eps.len() != (t_n - 1) * np * dx {
        return Err(ObjectiveError::Shape(format!(
            "draws have {} values, expected {} × {np} × {dx}",
            eps.len(),
            t_n - 1
        )));
    }
    let mut sp = ParticleStep::<f64>::new(config, params, np)?;
    let step = np * dx;
    let mut all = vec![0.0; t_n * step];
    all[..step].copy_from_slice(x0);
    let mut pred = empty_prediction(t_n, dx, dy);
    moments(
        &all[..step],
        dx,
        dy,
        &params.process_noise_var,
        &params.obs_noise_var,
        &mut pred,
        0,
    );
    for t in 0..t_n - 1 {
        let (cur, next) = all.split_at_mut((t + 1) * step);
        next[..step].copy_from_slice(&cur[t * step..]);
        sp.step(
            &mut next[..step],
            &inputs[t * du..(t + 1) * du],
            &eps[t * step..(t + 1) * step],
        );
        moments(
            &next[..step],
            dx,
            dy,
            &params.process_noise_var,
            &params.obs_noise_var,
            &mut pred,
            t + 1,
        );
    }
    Ok((all, pred))
}

pub(crate) fn empty_prediction(t_n: usize, dx: usize, dy: usize) -> Prediction {
    Prediction {
        output_mean: vec![0.0; t_n * dy],
        output_var: vec![0.0; t_n * dy],
        latent_mean: vec![0.0; t_n * dx],
        latent_var: vec![0.0; t_n * dx],
    }
}

/// [`predict`] with caller-supplied draws: `init_draws` (`P × D_x`) for
/// `x_0 = m₀ + s₀ ⊙ ε₀` and `eps` (`(T − 1) × P × D_x`).
///
/// # Errors
/// As [`simulate_with_draws`].
pub fn predict_with_draws(
    config: &ModelConfig,
    params: &Params,
    inputs: &[f64],
    init_mean: &[f64],
    init_std: &[f64],
    init_draws: &[f64],
    eps: &[f64],
) -> Result<Prediction, ObjectiveError> {
    let dx = config.n_state;
    if init_mean.len() != dx || init_std.len() != dx || init_draws.len() % dx != 0 {
        return Err(ObjectiveError::Shape(format!(
            "initial state must have {dx} means, {dx} stds and P × {dx} draws"
        )));
    }
    let x0: Vec<f64> = init_draws
        .chunks_exact(dx)
        .flat_map(|e| (0..dx).map(move |d| init_mean[d] + init_std[d] * e[d]))
        .collect();
    Ok(simulate_with_draws(config, params, inputs, &x0, eps)?.1)
}

/// Open-loop prediction with `particles` particles from `N(init_mean, diag init_std²)` under
/// `inputs` (row-major `T × D_u`, standardized as in training); draws from
/// `ChaCha8Rng::seed_from_u64(seed)` (initial draws first, then step by step, as
/// [`predict_with_draws`] takes them). Cost `O(T · P · (M D + M²))`; memory `O(P · D_x)`
/// besides the result: the particles and the draws of one step at a time.
///
/// # Errors
/// As [`simulate_with_draws`].
pub fn predict(
    config: &ModelConfig,
    params: &Params,
    inputs: &[f64],
    init_mean: &[f64],
    init_std: &[f64],
    particles: usize,
    seed: u64,
) -> Result<Prediction, ObjectiveError> {
    let init = (init_mean, init_std);
    run_prediction::<f64>(config, params, inputs, init, (particles, seed), None)
}

/// [`predict`] with the step in `T` ([`ParticleStep`]; `f64` is [`predict`]): the same draws,
/// rounded to `T`; the moments summed in `f64`.
///
/// # Errors
/// As [`predict`].
pub fn predict_in<T: StepFloat>(
    config: &ModelConfig,
    params: &Params,
    inputs: &[f64],
    init: (&[f64], &[f64]),
    particles: usize,
    seed: u64,
) -> Result<Prediction, ObjectiveError> {
    run_prediction::<T>(config, params, inputs, init, (particles, seed), None)
}

/// [`predict`] that also returns every particle, `T × P × D_x` row-major (standardized latent
/// units): the same draws, so the moments are [`predict`]'s exactly.
///
/// # Errors
/// As [`predict`].
pub fn predict_particles(
    config: &ModelConfig,
    params: &Params,
    inputs: &[f64],
    (init_mean, init_std): (&[f64], &[f64]),
    particles: usize,
    seed: u64,
) -> Result<(Prediction, Vec<f64>), ObjectiveError> {
    let t_n = inputs.len().checked_div(config.n_input).unwrap_or(1).max(1);
    let mut all = vec![0.0; t_n * particles * config.n_state];
    let init = (init_mean, init_std);
    let p = run_prediction::<f64>(
        config,
        params,
        inputs,
        init,
        (particles, seed),
        Some(&mut all),
    )?;
    Ok((p, all))
}

/// The initial particles `x` (`P × D_x`) `m₀ + s₀ ⊙ ε₀`, the draws particle by particle, dim by
/// dim, from `rng`: the first draws of every prediction from a seed.
pub(crate) fn draw_initial<T: StepFloat>(
    rng: &mut ChaCha8Rng,
    init_mean: &[f64],
    init_std: &[f64],
    x: &mut [T],
) {
    for c in x.chunks_exact_mut(init_mean.len().max(1)) {
        for ((x, m), s) in c.iter_mut().zip(init_mean).zip(init_std) {
            let e: f64 = StandardNormal.sample(&mut *rng);
            *x = T::of(m + s * e);
        }
    }
}

/// The prediction loop of [`predict`] in `T` with `(particles, seed)`, copying the particles
/// of every step into `keep` (`T × P × D_x`) when given.
fn run_prediction<T: StepFloat>(
    config: &ModelConfig,
    params: &Params,
    inputs: &[f64],
    (init_mean, init_std): (&[f64], &[f64]),
    (particles, seed): (usize, u64),
    mut keep: Option<&mut [f64]>,
) -> Result<Prediction, ObjectiveError> {
    let (dx, du, dy) = (config.n_state, config.n_input, config.n_output);
    if du == 0 && !inputs.is_empty() || du > 0 && (inputs.is_empty() || inputs.len() % du != 0) {
        return Err(ObjectiveError::Shape(format!(
            "{} input values are not a T × {du} array",
            inputs.len()
        )));
    }
    if init_mean.len() != dx || init_std.len() != dx {
        return Err(ObjectiveError::Shape(format!(
            "initial state must have {dx} means and {dx} stds"
        )));
    }
    let t_n = inputs.len().checked_div(du).unwrap_or(1);
    let mut sp = ParticleStep::<T>::new(config, params, particles)?;
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut x = vec![T::of(0.0); particles * dx];
    draw_initial(&mut rng, init_mean, init_std, &mut x);
    let (vx, vy) = (&params.process_noise_var, &params.obs_noise_var);
    let mut pred = empty_prediction(t_n, dx, dy);
    let mut record = |t: usize, x: &[T]| {
        if let Some(k) = keep.as_deref_mut() {
            let row = &mut k[t * x.len()..(t + 1) * x.len()];
            row.iter_mut().zip(x).for_each(|(k, &v)| *k = v.to_f64());
        }
    };
    moments(&x, dx, dy, vx, vy, &mut pred, 0);
    record(0, &x);
    let mut eps = vec![0.0; particles * dx];
    let mut u = vec![T::of(0.0); du];
    for t in 0..t_n - 1 {
        sp.draw(&mut rng, &mut eps);
        let row = &inputs[t * du..(t + 1) * du];
        u.iter_mut().zip(row).for_each(|(u, &v)| *u = T::of(v));
        sp.step(&mut x, &u, &eps);
        moments(&x, dx, dy, vx, vy, &mut pred, t + 1);
        record(t + 1, &x);
    }
    Ok(pred)
}

impl Prediction {
    /// Writes `step, mean_0..mean_{D_y−1}, var_0..var_{D_y−1}` as CSV (atomic), for
    /// `n_output` outputs.
    ///
    /// # Errors
    /// I/O errors of the atomic write.
    pub fn write_csv(&self, path: &std::path::Path, n_output: usize) -> std::io::Result<()> {
        let n = n_output.max(1);
        flapssm_data::atomic::write_atomic(path, |w| {
            write_csv_header(w, n_output)?;
            for (t, (mean, var)) in self
                .output_mean
                .chunks_exact(n)
                .zip(self.output_var.chunks_exact(n))
                .enumerate()
            {
                write_csv_row(w, t, mean, var)?;
            }
            Ok(())
        })
    }
}

/// The header of a prediction CSV: `step,mean_0..mean_{D_y−1},var_0..var_{D_y−1}`.
///
/// # Errors
/// Errors of `w`.
pub fn write_csv_header(w: &mut impl std::io::Write, n_output: usize) -> std::io::Result<()> {
    write!(w, "step")?;
    for d in 0..n_output {
        write!(w, ",mean_{d}")?;
    }
    for d in 0..n_output {
        write!(w, ",var_{d}")?;
    }
    writeln!(w)
}

/// One row of a prediction CSV: step `t`, the `D_y` means, the `D_y` variances (shortest
/// round-trip decimal form). Shared by [`Prediction::write_csv`] and streaming.
///
/// # Errors
/// Errors of `w`.
pub fn write_csv_row(
    w: &mut impl std::io::Write,
    t: usize,
    mean: &[f64],
    var: &[f64],
) -> std::io::Result<()> {
    write!(w, "{t}")?;
    for v in mean.iter().chain(var) {
        write!(w, ",{v}")?;
    }
    writeln!(w)
}
