//! Speed measurements of a fit specification (used by `flapssm bench`, which picks the paper's,
//! and the criterion benches), on synthetic data of its shapes, with the FLOP model that turns
//! times into GFLOP/s and the machine's own GEMM rate that bounds them.

use std::time::Instant;

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rand_distr::StandardNormal;

use faer::linalg::matmul::matmul;
use faer::linalg::triangular_solve::solve_lower_triangular_in_place;
use faer::traits::ComplexField;
use faer::{Accum, Mat, Par};

use crate::elbo::{Elbo, ElboError, ElboOptions, Sequence, TrainingData};
use crate::model::PrssmModel;
use crate::params::{ModelConfig, Params};
use crate::predict;
use crate::step::StepFloat;
use crate::stream::StreamPredictor;
use crate::train::batches::{BatchPlan, WindowSpec, derive_seed};
use crate::train::fit::FitSpec;
use crate::{Objective, ObjectiveError, Window};

/// Smooth random excitation: Gaussian levels of standard deviation `amplitude`, held for
/// `hold` samples, passed through a first-order low-pass `ū_t = ū_{t−1} + (u_t − ū_{t−1})/2`.
pub fn random_input(len: usize, amplitude: f64, hold: usize, seed: u64) -> Vec<f64> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let hold = hold.max(1);
    let mut level = 0.0;
    let mut smooth = 0.0;
    (0..len)
        .map(|t| {
            if t % hold == 0 {
                level = amplitude * rng.sample::<f64, _>(StandardNormal);
            }
            smooth += 0.5 * (level - smooth);
            smooth
        })
        .collect()
}

/// FLOP of one training transition step (forward + backward) of `n_points`
/// particle-windows, dominant terms: the three `M × M × N` products `W = G K`, `Y = Gᵀ W̄`
/// and `B += A Wᵀ` (`6 M² N`; see [`crate::conditional`]), the kernel distances and their two
/// adjoint products (`6 M D N`), the mean and variance products and their adjoints
/// (`12 M D_x N`).
/// Paper configuration (`M` 100, `D` 19, `D_x` 12), `N = 480`: 41 MFLOP.
pub fn train_step_flops(config: &ModelConfig, n_points: usize) -> f64 {
    let (m, d, dx) = (
        config.n_inducing as f64,
        config.n_gp_input() as f64,
        config.n_state as f64,
    );
    let n = n_points as f64;
    6.0 * m * m * n + 6.0 * m * d * n + 12.0 * m * dx * n
}

/// FLOP of one forward-only prediction step of `particles` particles, dominant terms:
/// `[W; μ] = [G; mᵀG] K` (`2 (M + D_x) M P`), the variance product `S (W ⊙ W)`
/// (`2 D_x M P`) and the state part of the kernel distances (`2 M D_x P`).
/// Paper configuration, `P = 30`: 0.82 MFLOP.
pub fn predict_step_flops(config: &ModelConfig, particles: usize) -> f64 {
    let (m, dx) = (config.n_inducing as f64, config.n_state as f64);
    let p = particles as f64;
    2.0 * (m + dx) * m * p + 2.0 * dx * m * p + 2.0 * m * dx * p
}

/// The part of [`train_step_flops`] that [`Precision::Mixed`](crate::Precision::Mixed) runs in `f32`: the three large
/// products with their `D_x` mean rows and the three `D_x`-row variance products
/// (`6 M² N + 12 M D_x N`); the kernel's distances and their adjoint products stay `f64`.
pub fn train_step_f32_flops(config: &ModelConfig, n_points: usize) -> f64 {
    let (m, dx) = (config.n_inducing as f64, config.n_state as f64);
    let n = n_points as f64;
    6.0 * m * m * n + 12.0 * m * dx * n
}

/// This machine's matrix-product rate on one thread (GFLOP/s) in `T` (`f64` or `f32`): the
/// best of repeated `size × size × size` faer products over at least `min_seconds`. Near the
/// core's FLOP limit, it bounds what the engine (≈ 70 % of its FLOP in such products) can
/// reach.
pub fn gemm_rate_gflops<T: ComplexField + From<f32>>(size: usize, min_seconds: f64) -> f64 {
    let size = size.max(8);
    let entry = |v: usize, q: usize| T::from(v as f32 / q as f32);
    let a = Mat::<T>::from_fn(size, size, |i, j| entry((i * 31 + j * 17) % 97, 97));
    let b = Mat::<T>::from_fn(size, size, |i, j| entry((i * 13 + j * 29) % 89, 89));
    let mut c = Mat::<T>::zeros(size, size);
    let flop = 2.0 * (size as f64).powi(3);
    let one = T::from(1.0);
    let best = fastest_seconds(
        min_seconds,
        &mut c,
        |_| {},
        |c| {
            matmul(
                c.as_mut(),
                Accum::Replace,
                a.as_ref(),
                b.as_ref(),
                one.clone(),
                Par::Seq,
            )
        },
    );
    flop / best / 1e9
}

/// Seconds the machine of prssm-notes §3–4 (the authors' timings, a 2-core Zen 5 EPYC) took
/// for one faer triangular solve with a `100 × 100` lower factor and 480 right-hand sides,
/// one thread ("≈ 0.08 ms each", §4): the kernel [`reference_solve_seconds`] times here.
pub const REFERENCE_SOLVE_S: f64 = 0.08e-3;

/// One thread's fastest time (s) over at least `min_seconds` of the kernel of
/// [`REFERENCE_SOLVE_S`]: `X ← L⁻¹X`, `L` lower triangular `100 × 100`, `X` `100 × 480` (the
/// paper's `M` and one step's `N`). The ratio of the two says how fast this machine's faer
/// kernels run against the machine the targets were set on, which the authors' 81.8 s and
/// 0.152 s do not: they were not measured here.
pub fn reference_solve_seconds(min_seconds: f64) -> f64 {
    let (l, b) = reference_system();
    let mut x = b.clone();
    fastest_seconds(
        min_seconds,
        &mut x,
        |x| x.copy_from(&b),
        |x| solve_lower_triangular_in_place(l.as_ref(), x.as_mut(), Par::Seq),
    )
}

/// The fastest of at least 3 runs of `timed` on `state` over at least `min_seconds` (s), each
/// after an untimed `prepare`.
fn fastest_seconds<S>(
    min_seconds: f64,
    state: &mut S,
    mut prepare: impl FnMut(&mut S),
    mut timed: impl FnMut(&mut S),
) -> f64 {
    let mut best = f64::INFINITY;
    let start = Instant::now();
    let mut reps = 0;
    while reps < 3 || start.elapsed().as_secs_f64() < min_seconds {
        prepare(state);
        let t0 = Instant::now();
        timed(state);
        best = best.min(t0.elapsed().as_secs_f64());
        std::hint::black_box(&*state);
        reps += 1;
    }
    best
}

/// The well-conditioned system `(L, B)` of [`reference_solve_seconds`].
fn reference_system() -> (Mat<f64>, Mat<f64>) {
    let (m, n) = (100, 480);
    let l = Mat::<f64>::from_fn(m, m, |i, j| match i.cmp(&j) {
        std::cmp::Ordering::Equal => 2.0 + 0.01 * i as f64,
        std::cmp::Ordering::Greater => 0.01 * ((i * 7 + j * 3) % 11) as f64,
        std::cmp::Ordering::Less => 0.0,
    });
    let b = Mat::<f64>::from_fn(m, n, |i, j| ((i * 13 + j * 5) % 17) as f64 / 17.0);
    (l, b)
}

/// `n` synthetic sequences of `len` steps with `n_input` smooth random inputs and `n_output`
/// outputs (standardized scale), seeded.
pub fn synthetic_sequences(
    n: usize,
    len: usize,
    n_input: usize,
    n_output: usize,
    seed: u64,
) -> Vec<Sequence> {
    (0..n)
        .map(|i| {
            let chans = |d: usize, stream: u64| -> Vec<Vec<f64>> {
                (0..d)
                    .map(|c| {
                        random_input(len, 1.0, 6, derive_seed(seed, stream, (i * 16 + c) as u64))
                    })
                    .collect()
            };
            let (u, y) = (chans(n_input, 10), chans(n_output, 11));
            Sequence {
                inputs: (0..len).flat_map(|t| u.iter().map(move |c| c[t])).collect(),
                outputs: (0..len).flat_map(|t| y.iter().map(move |c| c[t])).collect(),
            }
        })
        .collect()
}

/// The ELBO of `spec` (its model, particles and burn-in, the standard minibatch scaling) on
/// `n_sequences` synthetic sequences of `len` steps, with its initial parameters.
///
/// # Errors
/// [`ElboError`] for a specification that does not fit the shapes.
pub fn synthetic_objective(
    spec: &FitSpec,
    n_sequences: usize,
    len: usize,
    seed: u64,
) -> Result<(Elbo, Vec<f64>), ElboError> {
    let (du, dy) = (spec.model.n_input, spec.model.n_output);
    let data = TrainingData::new(du, dy, synthetic_sequences(n_sequences, len, du, dy, seed))?;
    let options = ElboOptions {
        particles: spec.particles,
        burn_in_fraction: spec.burn_in_fraction,
        windows_per_task: spec.windows_per_task,
        ..ElboOptions::paper(n_sequences)
    };
    let elbo = Elbo::new(spec.model.clone(), data, options)?;
    let params = Params::init(&spec.model, &spec.init, seed).unconstrained(&spec.model);
    Ok((elbo, params))
}

/// Timings of [`time_batches`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BatchTimes {
    /// Seconds of all timed minibatches together.
    pub total_s: f64,
    /// Seconds of the fastest one (what the machine can do when nothing else runs on it).
    pub fastest_s: f64,
    /// FLOP by [`train_step_flops`] of the transitions computed.
    pub flop: f64,
}

/// Times `n_batches` minibatches (batch 16 whole sequences) of `objective` at `params`,
/// after one untimed minibatch that allocates the objective's reusable buffers (a cost paid
/// once per run, not per epoch).
///
/// # Errors
/// The objective's error.
pub fn time_batches(
    objective: &Elbo,
    params: &[f64],
    n_batches: usize,
    seed: u64,
) -> Result<BatchTimes, ObjectiveError> {
    let lens = objective.data().lens().to_vec();
    let plan = BatchPlan::new(&lens, WindowSpec::WholeSequences, 16)
        .map_err(|e| ObjectiveError::Shape(e.to_string()))?;
    let mut order = Vec::new();
    plan.epoch_order(seed, 0, &mut order);
    let mut batch: Vec<Window> = Vec::new();
    let mut grad = vec![0.0; objective.n_params()];
    let window_step_flops = train_step_flops(objective.config(), objective.options().particles);
    let mut flop = 0.0;
    plan.batch_into(&order, 0, &mut batch);
    objective.loss_and_grad(params, &batch, derive_seed(seed, 3, 0), &mut grad)?;
    let (mut total_s, mut fastest_s) = (0.0, f64::INFINITY);
    for b in 0..n_batches.min(plan.batches_per_epoch()) {
        plan.batch_into(&order, b, &mut batch);
        let t0 = Instant::now();
        objective.loss_and_grad(params, &batch, derive_seed(seed, 2, b as u64), &mut grad)?;
        let s = t0.elapsed().as_secs_f64();
        total_s += s;
        fastest_s = fastest_s.min(s);
        let transitions: usize = batch.iter().map(|w| w.len.saturating_sub(1)).sum();
        flop += transitions as f64 * window_step_flops;
    }
    Ok(BatchTimes {
        total_s,
        fastest_s,
        flop,
    })
}

/// A model of `spec`'s shapes (fresh parameters) for prediction timings.
pub fn initial_model(spec: &FitSpec, seed: u64) -> PrssmModel {
    let spec = spec.clone();
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
pub fn time_prediction<T: StepFloat>(
    model: &PrssmModel,
    len: usize,
    particles: usize,
    reps: usize,
) -> Result<f64, ObjectiveError> {
    let (du, dy) = (model.config.n_input, model.config.n_output);
    let seq = &synthetic_sequences(1, len, du, dy, 5)[0];
    let zero = vec![0.0; model.config.n_state];
    let mut times = Vec::with_capacity(reps);
    for r in 0..reps.max(1) {
        let t0 = Instant::now();
        let p = predict::predict_in::<T>(
            &model.config,
            &model.params,
            &seq.inputs,
            (&zero, &zero),
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
pub fn time_stream_step<T: StepFloat>(
    model: &PrssmModel,
    particles: usize,
    steps: usize,
) -> Result<f64, ObjectiveError> {
    let (du, dy) = (model.config.n_input, model.config.n_output);
    let seq = &synthetic_sequences(1, steps.max(1), du, dy, 6)[0];
    let zero = vec![0.0; model.config.n_state];
    let mut s = StreamPredictor::<T>::new(model, particles, &zero, &zero, 1)?;
    let du = model.config.n_input;
    let inputs: Vec<T> = seq.inputs.iter().map(|&v| T::of(v)).collect();
    s.step(&inputs[..du])?;
    let t0 = Instant::now();
    for t in 0..steps.max(1) {
        let (m, _) = s.step(&inputs[t * du..(t + 1) * du])?;
        std::hint::black_box(m);
    }
    Ok(t0.elapsed().as_secs_f64() / steps.max(1) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The FLOP model against a hand count for the paper's shapes (M 100, D 19, D_x 12):
    /// `6·100²·480 + 6·100·19·480 + 12·100·12·480` and `2·112·100·30 + 2·12·100·30 + 2·100·12·30`.
    #[test]
    fn flop_model_of_the_paper_configuration() {
        let spec = FitSpec::new(ModelConfig::new(12, 5, 7, 100));
        let train = train_step_flops(&spec.model, 480);
        assert_eq!(train, 28_800_000.0 + 5_472_000.0 + 6_912_000.0);
        let predict = predict_step_flops(&spec.model, 30);
        assert_eq!(predict, 672_000.0 + 72_000.0 + 72_000.0);
        // Both are linear in the number of points.
        assert_eq!(train_step_flops(&spec.model, 30) * 16.0, train);
        // Mixed precision's f32 part: the M² and D_x terms.
        let f32_part = train_step_f32_flops(&spec.model, 480);
        assert_eq!(f32_part, 28_800_000.0 + 6_912_000.0);
    }

    #[test]
    fn gemm_rate_is_a_finite_positive_rate() {
        let r = gemm_rate_gflops::<f64>(16, 0.0);
        assert!(r.is_finite() && r > 0.0, "{r}");
        let r = gemm_rate_gflops::<f32>(16, 0.0);
        assert!(r.is_finite() && r > 0.0, "{r}");
    }

    /// The reference kernel's system is lower triangular and what it times solves it:
    /// `L X = B` to rounding.
    #[test]
    fn reference_solve_solves_its_system() {
        let (l, b) = reference_system();
        assert_eq!(
            (l.nrows(), l.ncols(), b.nrows(), b.ncols()),
            (100, 100, 100, 480)
        );
        assert!((0..100).all(|i| (i + 1..100).all(|j| l[(i, j)] == 0.0)));
        let mut x = b.clone();
        solve_lower_triangular_in_place(l.as_ref(), x.as_mut(), Par::Seq);
        let residual = &l * &x - &b;
        assert!(residual.norm_max() < 1e-13, "{}", residual.norm_max());
        let t = reference_solve_seconds(0.0);
        assert!(t.is_finite() && t > 0.0, "{t}");
    }

    /// Two minibatches of a small paper-shaped objective: the fastest is one of them, and the
    /// FLOP count is that of the transitions computed (2 × 16 windows × 9 steps).
    #[test]
    fn batch_times_are_consistent() {
        let spec = FitSpec::new(ModelConfig::new(12, 5, 7, 100));
        let (elbo, params) = synthetic_objective(&spec, 32, 10, 1).unwrap();
        let t = time_batches(&elbo, &params, 2, 1).unwrap();
        assert!(t.fastest_s > 0.0 && 2.0 * t.fastest_s <= t.total_s, "{t:?}");
        let per_step = train_step_flops(elbo.config(), elbo.options().particles);
        assert_eq!(t.flop, 2.0 * 16.0 * 9.0 * per_step);
    }
}
