//! The particle ELBO of the PR-SSM and its exact gradient (reverse mode through time).
//!
//! For a minibatch `B` of windows, `P` particles each, the loss is
//!
//! ```text
//! loss = s · Σ_{b∈B} Σ_p Σ_{t=t₀(b)}^{len_b−1} −ln N(y_{b,t} | x^p_{b,t}[0..D_y], diag σ_y²)  +  KL(q(u) ‖ p(u))
//! ```
//! with `s = N_windows / (|B| · P)` ([`LossScaling::Standard`]: an unbiased estimate of the
//! negative ELBO of a dataset split into `N_windows` windows; use the number of sequences when
//! each window is a whole sequence) or `s = 1` ([`LossScaling::Published`]: the published
//! code's sum over particles). `t₀ = ⌊burn_in_fraction · len⌋` (paper: 0.2).
//!
//! Particles: `x_0 = m₀ + s₀ ⊙ ε₀`, `x_{t+1} = x_t + μ(x_t, u_t) + √(σ²(x_t, u_t) + σ_x² + δ_t) ⊙ ε_t`,
//! all `ε ~ N(0, I)` drawn from `ChaCha8Rng::seed_from_u64(seed)` on stream `b` (the batch
//! position), so results do not depend on the thread count. Windows are processed in fixed
//! chunks of `windows_per_task`, all particles of a chunk batched per step; chunk results are
//! reduced in chunk order. The backward pass reads each step's intermediates from a tape
//! ([`crate::conditional::tape_len`] values per step); beyond [`TAPE_BUDGET_BYTES`] per chunk, earlier
//! segments are recomputed from the stored states and draws.

use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::conditional::{ConditionalGrads, ConditionalWorkspace, Posterior};
use crate::kernel;
use crate::kl::kl_divergence;
use crate::objective::{Objective, ObjectiveError, Window};
use crate::params::{ConfigError, ModelConfig, ParamGrads, Parametrization, Params};
use crate::precision::Precision;
use crate::tape::TapeMemory;

mod chunk;

/// One training sequence in standardized units.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sequence {
    /// Inputs `u`, row-major `T × D_u`.
    pub inputs: Vec<f64>,
    /// Outputs `y`, row-major `T × D_y`.
    pub outputs: Vec<f64>,
}

/// A borrowed sequence: the caller's own `T × D_u` inputs and `T × D_y` outputs (row-major),
/// with no copy. The raw data of [`crate::train::fit::fit`] and
/// [`crate::PrssmModel::predict_sequence`] come in as views.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SequenceView<'a> {
    /// Inputs `u`, row-major `T × D_u`.
    pub inputs: &'a [f64],
    /// Outputs `y`, row-major `T × D_y` (empty where none are known).
    pub outputs: &'a [f64],
}

impl Sequence {
    /// This sequence as a view.
    pub fn view(&self) -> SequenceView<'_> {
        SequenceView {
            inputs: &self.inputs,
            outputs: &self.outputs,
        }
    }
}

/// Checks that every sequence has `T × D_u` inputs and `T × D_y` outputs, `T ≥ 1`, finite, and
/// returns each `T`.
///
/// # Errors
/// [`ElboError::Sequence`] naming the sequence.
pub fn sequence_lengths<'a>(
    n_input: usize,
    n_output: usize,
    sequences: impl IntoIterator<Item = SequenceView<'a>>,
) -> Result<Vec<usize>, ElboError> {
    let mut lens = Vec::new();
    for (index, s) in sequences.into_iter().enumerate() {
        let err = |message: String| Err(ElboError::Sequence { index, message });
        if n_output == 0 || s.outputs.len() % n_output != 0 || s.outputs.is_empty() {
            return err(format!(
                "{} output values are not a T × {n_output} array with T ≥ 1",
                s.outputs.len()
            ));
        }
        let t = s.outputs.len() / n_output;
        if s.inputs.len() != t * n_input {
            return err(format!(
                "{} input values, expected {t} × {n_input}",
                s.inputs.len()
            ));
        }
        if let Some(i) = s
            .inputs
            .iter()
            .chain(s.outputs)
            .position(|v| !v.is_finite())
        {
            return err(format!("non-finite value at flat index {i}"));
        }
        lens.push(t);
    }
    Ok(lens)
}

/// Validated training sequences.
#[derive(Debug, Clone, PartialEq)]
pub struct TrainingData {
    n_input: usize,
    n_output: usize,
    sequences: Vec<Sequence>,
    lens: Vec<usize>,
}

/// Why an [`Elbo`] could not be built.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum ElboError {
    /// Invalid model configuration.
    #[error(transparent)]
    Config(#[from] ConfigError),
    /// A sequence has inconsistent shapes or non-finite values.
    #[error("sequence {index}: {message}")]
    Sequence {
        /// Sequence index.
        index: usize,
        /// What is wrong.
        message: String,
    },
    /// An option is out of range.
    #[error("option {field}: {message}")]
    Option {
        /// The option.
        field: &'static str,
        /// What is wrong.
        message: String,
    },
}

impl TrainingData {
    /// Checks the sequences ([`sequence_lengths`]) and takes them.
    ///
    /// # Errors
    /// [`ElboError::Sequence`] naming the sequence.
    pub fn new(
        n_input: usize,
        n_output: usize,
        sequences: Vec<Sequence>,
    ) -> Result<Self, ElboError> {
        let lens = sequence_lengths(n_input, n_output, sequences.iter().map(Sequence::view))?;
        Ok(Self {
            n_input,
            n_output,
            sequences,
            lens,
        })
    }

    /// The sequences.
    pub fn sequences(&self) -> &[Sequence] {
        &self.sequences
    }

    /// Number of time steps of each sequence.
    pub fn lens(&self) -> &[usize] {
        &self.lens
    }
}

/// Scaling of the likelihood against the KL term (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum LossScaling {
    /// Unbiased minibatch estimate: likelihood × `n_windows / (batch · particles)`.
    Standard {
        /// Number of windows (sequences) the training data is divided into.
        n_windows: f64,
    },
    /// The published code: likelihood summed over batch and particles, KL added once.
    Published,
}

/// Initial-state rule used by the [`Objective`] implementation.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum InitialStateMode {
    /// `x_0 = 0` for every particle (the paper).
    Zeros,
    /// `x_0[0..D_y] = y_{start}`, the rest 0, no spread.
    Outputs,
}

/// Options of the ELBO.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ElboOptions {
    /// Particles per window (paper: 30).
    pub particles: usize,
    /// Fraction of each window excluded from the likelihood (paper: 0.2).
    pub burn_in_fraction: f64,
    /// Likelihood scaling.
    pub scaling: LossScaling,
    /// Initial state used by [`Objective::loss_and_grad`].
    pub initial_state: InitialStateMode,
    /// Windows batched together per parallel task (fixed, so results do not depend on the
    /// number of threads).
    pub windows_per_task: usize,
}

impl ElboOptions {
    /// The paper's options for a dataset of `n_sequences` sequences (standard scaling).
    pub fn paper(n_sequences: usize) -> Self {
        Self {
            particles: 30,
            burn_in_fraction: 0.2,
            scaling: LossScaling::Standard {
                n_windows: n_sequences as f64,
            },
            initial_state: InitialStateMode::Zeros,
            windows_per_task: 4,
        }
    }
}

/// Loss parts of one evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LossParts {
    /// `loss = nll + kl`.
    pub loss: f64,
    /// The scaled negative log-likelihood term.
    pub nll: f64,
    /// `KL(q(u) ‖ p(u))`.
    pub kl: f64,
}

/// Initial-state distributions of a batch: `N(mean, diag(std²))`, row-major `B × D_x`.
#[derive(Debug, Clone, Copy)]
pub struct InitialStates<'a> {
    /// Means `m₀`.
    pub mean: &'a [f64],
    /// Standard deviations `s₀` (any sign; `x_0 = m₀ + s₀ ε₀`).
    pub std: &'a [f64],
}

/// Gradients of the loss w.r.t. the initial states (row-major `B × D_x`, overwritten).
#[derive(Debug)]
pub struct InitialStateGrads<'a> {
    /// `∂loss/∂m₀`.
    pub mean: &'a mut [f64],
    /// `∂loss/∂s₀`.
    pub std: &'a mut [f64],
}

/// The PR-SSM negative ELBO over a training set: build once, evaluate many times.
#[derive(Debug, Clone)]
pub struct Elbo {
    config: ModelConfig,
    data: TrainingData,
    options: ElboOptions,
    tape_budget_bytes: usize,
    precision: Precision,
    scratch: ScratchPool,
}

/// Per-chunk buffers kept between evaluations (fresh pages cost more than the arithmetic);
/// every value is written before it is read.
#[derive(Debug, Default)]
struct ScratchPool(std::sync::Mutex<Vec<ChunkScratch>>);

#[derive(Debug, Default)]
struct ChunkScratch {
    tape: TapeMemory,
    xs: Vec<f64>,
    eps: Vec<f64>,
    sds: Vec<f64>,
    ws: Option<ConditionalWorkspace>,
}

impl Clone for ScratchPool {
    fn clone(&self) -> Self {
        Self::default()
    }
}

impl ScratchPool {
    fn take(&self) -> ChunkScratch {
        let mut pool = self.0.lock().unwrap_or_else(|e| e.into_inner());
        pool.pop().unwrap_or_default()
    }

    fn put(&self, v: ChunkScratch) {
        self.0.lock().unwrap_or_else(|e| e.into_inner()).push(v);
    }
}

/// Memory for the per-step intermediates of one chunk of windows (bytes); longer windows are
/// processed in segments whose forward steps are recomputed in the backward pass.
/// Default of [`Elbo::with_tape_budget`].
pub const TAPE_BUDGET_BYTES: usize = 512 << 20;

struct ChunkOut {
    nll: f64,
    cond: ConditionalGrads,
    process_noise: Vec<f64>,
    obs_noise: Vec<f64>,
    init_mean: Vec<f64>,
    init_std: Vec<f64>,
}

impl Elbo {
    /// Builds the objective.
    ///
    /// # Errors
    /// [`ElboError`] on an invalid configuration, data of the wrong dimensions or options out
    /// of range.
    pub fn new(
        config: ModelConfig,
        data: TrainingData,
        options: ElboOptions,
    ) -> Result<Self, ElboError> {
        config.check()?;
        if data.n_input != config.n_input || data.n_output != config.n_output {
            return Err(ElboError::Option {
                field: "data",
                message: format!(
                    "data has D_u = {}, D_y = {}; model has D_u = {}, D_y = {}",
                    data.n_input, data.n_output, config.n_input, config.n_output
                ),
            });
        }
        if options.particles == 0 {
            return Err(ElboError::Option {
                field: "particles",
                message: "must be ≥ 1".into(),
            });
        }
        if !(0.0..1.0).contains(&options.burn_in_fraction) {
            return Err(ElboError::Option {
                field: "burn_in_fraction",
                message: format!("{} must be in [0, 1)", options.burn_in_fraction),
            });
        }
        if options.windows_per_task == 0 {
            return Err(ElboError::Option {
                field: "windows_per_task",
                message: "must be ≥ 1".into(),
            });
        }
        if let LossScaling::Standard { n_windows } = options.scaling
            && !(n_windows > 0.0 && n_windows.is_finite())
        {
            return Err(ElboError::Option {
                field: "scaling.n_windows",
                message: format!("{n_windows} must be > 0"),
            });
        }
        Ok(Self {
            config,
            data,
            options,
            tape_budget_bytes: TAPE_BUDGET_BYTES,
            precision: Precision::F64,
            scratch: ScratchPool::default(),
        })
    }

    /// The model configuration.
    pub fn config(&self) -> &ModelConfig {
        &self.config
    }

    /// The options.
    pub fn options(&self) -> &ElboOptions {
        &self.options
    }

    /// Sets the memory for the per-step intermediates of one chunk of windows (bytes,
    /// default [`TAPE_BUDGET_BYTES`]; at least one step is always stored). Results do not
    /// depend on it; a smaller budget trades memory for forward recomputation.
    pub fn with_tape_budget(mut self, bytes: usize) -> Self {
        self.tape_budget_bytes = bytes;
        self
    }

    /// Sets the arithmetic of the large products (default [`Precision::F64`]; see
    /// [`crate::precision`]).
    pub fn with_precision(mut self, precision: Precision) -> Self {
        self.precision = precision;
        self
    }

    /// The arithmetic of the large products.
    pub fn precision(&self) -> Precision {
        self.precision
    }

    /// The training data.
    pub fn data(&self) -> &TrainingData {
        &self.data
    }

    /// Writes the initial state of `window` under [`ElboOptions::initial_state`] into `mean`
    /// and `std` (`D_x` each).
    pub fn initial_state(&self, window: Window, mean: &mut [f64], std: &mut [f64]) {
        mean.fill(0.0);
        std.fill(0.0);
        if self.options.initial_state == InitialStateMode::Outputs {
            let dy = self.config.n_output;
            let s = &self.data.sequences[window.sequence];
            mean[..dy].copy_from_slice(&s.outputs[window.start * dy..(window.start + 1) * dy]);
        }
    }

    fn check_batch(&self, params: &[f64], batch: &[Window]) -> Result<(), ObjectiveError> {
        let n = self.config.layout().len;
        if params.len() != n {
            return Err(ObjectiveError::Shape(format!(
                "{} parameters, expected {n}",
                params.len()
            )));
        }
        if params.iter().any(|v| !v.is_finite()) {
            return Err(ObjectiveError::NonFinite { what: "parameters" });
        }
        for (i, w) in batch.iter().enumerate() {
            let Some(&t) = self.data.lens.get(w.sequence) else {
                return Err(ObjectiveError::Shape(format!(
                    "window {i}: sequence {} of {}",
                    w.sequence,
                    self.data.lens.len()
                )));
            };
            if w.len == 0 || w.start + w.len > t {
                return Err(ObjectiveError::Shape(format!(
                    "window {i}: steps {}..{} of a {t}-step sequence",
                    w.start,
                    w.start + w.len
                )));
            }
        }
        Ok(())
    }

    /// Evaluates the loss on `batch` with caller-supplied initial states and writes the exact
    /// gradients w.r.t. the flat parameters (`grad`, `n_params()`) and the initial states.
    ///
    /// # Errors
    /// [`ObjectiveError`] on shape mismatches, a non-positive-definite `K_mm` or a non-finite
    /// result.
    pub fn evaluate(
        &self,
        params: &[f64],
        batch: &[Window],
        init: InitialStates<'_>,
        seed: u64,
        grad: &mut [f64],
        init_grad: InitialStateGrads<'_>,
    ) -> Result<LossParts, ObjectiveError> {
        self.check_batch(params, batch)?;
        let (dx, b_n) = (self.config.n_state, batch.len());
        for (what, len) in [
            ("initial mean", init.mean.len()),
            ("initial std", init.std.len()),
            ("initial mean gradient", init_grad.mean.len()),
            ("initial std gradient", init_grad.std.len()),
        ] {
            if len != b_n * dx {
                return Err(ObjectiveError::Shape(format!(
                    "{what} has {len} values, expected {b_n} × {dx}"
                )));
            }
        }
        if grad.len() != params.len() {
            return Err(ObjectiveError::Shape(format!(
                "gradient has {} values, expected {}",
                grad.len(),
                params.len()
            )));
        }
        let cfg = &self.config;
        let p = Params::from_unconstrained(cfg, params)
            .map_err(|e| ObjectiveError::Shape(e.to_string()))?;
        let mut post = Posterior::new(cfg, &p)?;
        post.set_precision(self.precision);
        let lik_scale = match self.options.scaling {
            LossScaling::Standard { n_windows } => {
                n_windows / (b_n.max(1) * self.options.particles) as f64
            }
            LossScaling::Published => 1.0,
        };
        let chunks: Vec<Vec<usize>> = (0..b_n)
            .collect::<Vec<_>>()
            .chunks(self.options.windows_per_task)
            .map(|c| {
                let mut c = c.to_vec();
                c.sort_by_key(|&i| std::cmp::Reverse(batch[i].len));
                c
            })
            .collect();
        let run = |c: &Vec<usize>| self.run_chunk(&post, &p, batch, c, init, seed, lik_scale);
        let outs: Vec<ChunkOut> = chunks.par_iter().map(run).collect();

        let mut nll = 0.0;
        let mut cond = ConditionalGrads::zeros(&post);
        let mut g = ParamGrads::zeros(cfg);
        for (c, o) in chunks.iter().zip(&outs) {
            nll += o.nll;
            cond.add(&o.cond);
            g.process_noise_var
                .iter_mut()
                .zip(&o.process_noise)
                .for_each(|(a, b)| *a += b);
            g.obs_noise_var
                .iter_mut()
                .zip(&o.obs_noise)
                .for_each(|(a, b)| *a += b);
            for (k, &bi) in c.iter().enumerate() {
                init_grad.mean[bi * dx..(bi + 1) * dx]
                    .copy_from_slice(&o.init_mean[k * dx..(k + 1) * dx]);
                init_grad.std[bi * dx..(bi + 1) * dx]
                    .copy_from_slice(&o.init_std[k * dx..(k + 1) * dx]);
            }
        }
        let whitened = cfg.parametrization == Parametrization::Whitened;
        let kl = kl_divergence(
            (!whitened).then_some(&post.l[..]),
            post.m,
            dx,
            &p.q_mean,
            &p.q_cov,
            cfg.covariance,
        );
        self.finish_grads(&post, &p, cond, &kl, &mut g);
        g.to_unconstrained(cfg, params, grad);
        let loss = nll + kl.value;
        if !loss.is_finite() {
            return Err(ObjectiveError::NonFinite { what: "loss" });
        }
        if grad.iter().any(|v| !v.is_finite()) {
            return Err(ObjectiveError::NonFinite { what: "gradient" });
        }
        Ok(LossParts {
            loss,
            nll,
            kl: kl.value,
        })
    }

    fn finish_grads(
        &self,
        post: &Posterior,
        p: &Params,
        mut cond: ConditionalGrads,
        kl: &crate::kl::KlTerms,
        g: &mut ParamGrads,
    ) {
        let (m, d) = (post.m, post.d);
        let (q_mean_bar, b_kmm) = cond.split_stacked(post);
        g.q_mean
            .iter_mut()
            .zip(q_mean_bar.iter().zip(&kl.q_mean))
            .for_each(|(a, (b, c))| *a += b + c);
        g.q_cov
            .iter_mut()
            .zip(cond.q_cov.iter().zip(&kl.q_cov))
            .for_each(|(a, (b, c))| *a += b + c);
        let mut kbar = post.kmm_grad(b_kmm);
        if let Some(kk) = &kl.kmm {
            kbar.iter_mut().zip(kk).for_each(|(a, b)| *a += b);
        }
        let mut sv = 0.0;
        for ((kb, &k), &kd) in kbar.iter_mut().zip(&post.kmm).zip(&post.kmm_kd) {
            sv += *kb * k;
            *kb *= kd;
        }
        g.kernel_variance += cond.variance + sv / p.kernel_variance;
        let mut zs = vec![0.0; d * m];
        kernel::scale_points(&p.inducing_inputs, &post.inv_len, &mut zs);
        let mut zbar_cols = vec![0.0; m * d];
        let (mut cx, mut zc, mut rs) = (vec![0.0; m * d], vec![0.0; d * m], vec![0.0; m]);
        kernel::cross_cov_backward(
            &kbar,
            &post.zt,
            &zs,
            &post.inv_len,
            d,
            &mut cond.zbar_t,
            &mut zbar_cols,
            &mut cond.len_acc,
            &mut cx,
            &mut zc,
            &mut rs,
        );
        g.inducing_inputs
            .iter_mut()
            .zip(&zbar_cols)
            .for_each(|(a, b)| *a += b);
        kernel::finish_inducing_grad(&cond.zbar_t, &post.inv_len, &mut g.inducing_inputs);
        for j in 0..d {
            g.lengthscales[j] += -2.0 * post.inv_len[j] * cond.len_acc[j];
        }
    }
}

impl Objective for Elbo {
    fn n_params(&self) -> usize {
        self.config.layout().len
    }

    fn loss_and_grad(
        &self,
        params: &[f64],
        batch: &[Window],
        seed: u64,
        grad: &mut [f64],
    ) -> Result<f64, ObjectiveError> {
        let dx = self.config.n_state;
        let mut mean = vec![0.0; batch.len() * dx];
        let mut std = vec![0.0; batch.len() * dx];
        self.check_batch(params, batch)?;
        for (i, w) in batch.iter().enumerate() {
            self.initial_state(
                *w,
                &mut mean[i * dx..(i + 1) * dx],
                &mut std[i * dx..(i + 1) * dx],
            );
        }
        let mut gm = vec![0.0; mean.len()];
        let mut gs = vec![0.0; mean.len()];
        let parts = self.evaluate(
            params,
            batch,
            InitialStates {
                mean: &mean,
                std: &std,
            },
            seed,
            grad,
            InitialStateGrads {
                mean: &mut gm,
                std: &mut gs,
            },
        )?;
        Ok(parts.loss)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::conditional;
    use crate::params::ParamInit;
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;
    use rand_distr::{Distribution, StandardNormal};

    /// Recomputing segments of the forward pass in the backward pass (small tape budgets)
    /// gives bit-identical loss and gradient.
    #[test]
    fn tape_budget_does_not_change_results() {
        let config = ModelConfig::new(3, 2, 2, 6);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        let seqs = (0..3)
            .map(|_| Sequence {
                inputs: (0..13 * 2)
                    .map(|_| StandardNormal.sample(&mut rng))
                    .collect(),
                outputs: (0..13 * 2)
                    .map(|_| StandardNormal.sample(&mut rng))
                    .collect(),
            })
            .collect();
        let data = TrainingData::new(2, 2, seqs).unwrap();
        let theta = Params::init(&config, &ParamInit::default(), 2).unconstrained(&config);
        let batch: Vec<Window> = [(0, 0, 13), (1, 2, 9), (2, 1, 12)]
            .iter()
            .map(|&(sequence, start, len)| Window {
                sequence,
                start,
                len,
            })
            .collect();
        let mut opts = ElboOptions::paper(3);
        opts.particles = 4;
        opts.windows_per_task = 2;
        let elbo = Elbo::new(config, data, opts).unwrap();
        let run = |e: &Elbo| {
            let mut g = vec![0.0; theta.len()];
            let loss = e.loss_and_grad(&theta, &batch, 11, &mut g).unwrap();
            (loss, g)
        };
        // Both tape layouts (mixed precision keeps its `f32` values in `f32`).
        for precision in [Precision::Mixed, Precision::F64] {
            let mut post = Posterior::new(
                elbo.config(),
                &Params::from_unconstrained(elbo.config(), &theta).unwrap(),
            )
            .unwrap();
            post.set_precision(precision);
            let step_bytes = 8 * conditional::tape_len(&post, 8);
            let elbo = elbo.clone().with_precision(precision);
            let full = run(&elbo);
            assert!(full.1.iter().any(|&v| v != 0.0));
            for steps in [1, 3, 5] {
                let e = elbo.clone().with_tape_budget(steps * step_bytes);
                assert_eq!(run(&e), full, "{precision:?}: {steps} steps per segment");
            }
        }
        let full = run(&elbo);
        // A repeated evaluation reuses the pooled buffers.
        assert_eq!(run(&elbo), full);
        // Other task sizes draw the same numbers (per window) and sum in another order: the
        // same loss and gradient up to rounding, and not bit for bit (the sizes are real).
        let mut differs = false;
        for per_task in [1, 3] {
            let mut o = elbo.options().clone();
            o.windows_per_task = per_task;
            let e = Elbo::new(elbo.config().clone(), elbo.data().clone(), o).unwrap();
            let (loss, g) = run(&e);
            assert!(
                (loss - full.0).abs() <= 1e-12 * full.0.abs(),
                "{per_task}: {loss}"
            );
            let scale = full.1.iter().fold(0.0f64, |a, v| a.max(v.abs()));
            for (a, b) in g.iter().zip(&full.1) {
                assert!((a - b).abs() <= 1e-11 * scale, "{per_task}: {a} vs {b}");
            }
            differs |= (loss, g) != full;
        }
        assert!(differs, "the task size changed nothing at all");
    }
}
