//! `flapssm bench`: the engine's speed in the paper's configuration (512 sequences × 470 steps,
//! D_x 12, M 100, 30 particles, batch 16) on synthetic data of its shapes, beside the authors'
//! code (prssm-notes §3) and this machine's own f64 GEMM rate.

use flapssm_prssm::Precision;
use flapssm_prssm::bench::{
    REFERENCE_SOLVE_S, gemm_rate_gflops, initial_model, predict_step_flops,
    reference_solve_seconds, synthetic_objective, time_batches, time_prediction, time_stream_step,
    train_step_f32_flops, train_step_flops,
};
use flapssm_prssm::train::fit::{DEFAULT_WINDOWS_PER_TASK, FitError, FitSpec};

use crate::presets::Preset;

use crate::error::{JobError, Result};
use crate::threads::current_threads;

/// The authors' code: one training epoch (s), prssm-notes §3.
pub const AUTHORS_EPOCH_S: f64 = 81.8;
/// The authors' code: prediction of one 470-step trajectory with 30 particles (s).
pub const AUTHORS_PREDICT_S: f64 = 0.152;
/// Steps of the timed prediction (one paper trajectory).
pub const PREDICT_STEPS: usize = 470;
/// Sequences of the timed training set (the paper's training set).
pub const TRAIN_SEQUENCES: usize = 512;
/// Minibatches per epoch of the paper's configuration (512 / 16).
pub const BATCHES_PER_EPOCH: usize = 32;

/// Settings of [`bench()`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BenchSettings {
    /// Minibatches timed (1..=32); the epoch is extrapolated from them.
    pub batches: usize,
    /// Repetitions of the prediction timing (the median is reported).
    pub reps: usize,
    /// Seed of the synthetic data and parameters.
    pub seed: u64,
    /// Arithmetic of the training products; with [`Precision::Mixed`] prediction and
    /// streaming are timed in `f32` (their step has no mixed form).
    pub precision: Precision,
    /// Windows per parallel task of the timed minibatches ([`FitSpec::windows_per_task`]).
    pub windows_per_task: usize,
}

impl Default for BenchSettings {
    fn default() -> Self {
        Self {
            batches: BATCHES_PER_EPOCH,
            reps: 9,
            seed: 0,
            precision: Precision::F64,
            windows_per_task: DEFAULT_WINDOWS_PER_TASK,
        }
    }
}

/// What [`bench()`] measured.
#[derive(Debug, Clone, PartialEq)]
pub struct BenchReport {
    /// Arithmetic of the timed training products.
    pub precision: Precision,
    /// Windows per parallel task of the timed minibatches.
    pub windows_per_task: usize,
    /// Threads of the pool the training ran on.
    pub threads: usize,
    /// f64 GEMM rate (512³, faer, one thread), GFLOP/s.
    pub gemm_gflops: f64,
    /// f32 GEMM rate (512³, faer, one thread), GFLOP/s.
    pub gemm_f32_gflops: f64,
    /// Share of the training FLOP that the timed precision runs in `f32` (0 for `f64`).
    pub train_f32_share: f64,
    /// Share of the prediction FLOP run in `f32`: 1 with [`Precision::Mixed`] (the `f32`
    /// step), 0 for `f64`.
    pub predict_f32_share: f64,
    /// prssm-notes §4's triangular solve (100 × 100, 480 right-hand sides, one thread), s.
    pub reference_solve_s: f64,
    /// Minibatches timed.
    pub batches: usize,
    /// One epoch (32 × the mean timed minibatch), s.
    pub epoch_s: f64,
    /// 32 × the fastest timed minibatch, s.
    pub fastest_epoch_s: f64,
    /// Training FLOP rate, GFLOP/s.
    pub train_gflops: f64,
    /// Median prediction of one 470-step trajectory with 30 particles (one thread), s.
    pub predict_s: f64,
    /// Prediction FLOP rate, GFLOP/s.
    pub predict_gflops: f64,
    /// Mean streaming step with 30 particles, s.
    pub stream_step_s: f64,
    /// Streaming FLOP rate, GFLOP/s.
    pub stream_gflops: f64,
}

impl BenchReport {
    /// Epoch time if every FLOP ran at `threads` × the f64 GEMM rate (the f64 FLOP limit), s.
    pub fn flop_limit_epoch_s(&self) -> f64 {
        self.epoch_s * self.train_gflops / (self.threads as f64 * self.gemm_gflops)
    }

    /// Epoch time if every FLOP ran at `threads` × the GEMM rate of its precision (the FLOP
    /// limit of the timed precision: the f64 one for `f64`), s.
    pub fn precision_flop_limit_epoch_s(&self) -> f64 {
        let gflop = self.epoch_s * self.train_gflops;
        gflop * self.seconds_per_gflop(self.train_f32_share) / self.threads as f64
    }

    /// Prediction time if every FLOP ran at the one-thread GEMM rate of its precision, s.
    pub fn precision_flop_limit_predict_s(&self) -> f64 {
        let gflop = self.predict_s * self.predict_gflops;
        gflop * self.seconds_per_gflop(self.predict_f32_share)
    }

    /// The arithmetic prediction and streaming were timed in: `"f32"` under
    /// [`Precision::Mixed`], else `"f64"`.
    pub fn prediction_float(&self) -> &'static str {
        if self.precision == Precision::Mixed {
            "f32"
        } else {
            "f64"
        }
    }

    /// The one-thread GEMM rate in [`Self::prediction_float`], GFLOP/s.
    pub fn prediction_gemm_gflops(&self) -> f64 {
        if self.precision == Precision::Mixed {
            self.gemm_f32_gflops
        } else {
            self.gemm_gflops
        }
    }

    /// Seconds one core takes per GFLOP at the GEMM rates when `f32_share` of the FLOP run
    /// in `f32` and the rest in `f64`.
    fn seconds_per_gflop(&self, f32_share: f64) -> f64 {
        f32_share / self.gemm_f32_gflops + (1.0 - f32_share) / self.gemm_gflops
    }
}

/// Times training minibatches, one prediction and streaming steps of the paper's
/// configuration, on the current thread pool.
///
/// # Errors
/// [`JobError::Setting`] for `batches` outside 1..=32 or no repetition; engine errors.
pub fn bench(settings: &BenchSettings) -> Result<BenchReport> {
    if !(1..=BATCHES_PER_EPOCH).contains(&settings.batches) {
        return Err(JobError::Setting {
            name: "batches".into(),
            value: settings.batches.to_string(),
            expected: format!("must be in 1..={BATCHES_PER_EPOCH}"),
        });
    }
    if settings.reps == 0 {
        return Err(JobError::Setting {
            name: "reps".into(),
            value: "0".into(),
            expected: "must be at least 1".into(),
        });
    }
    let engine = |what: &str, source: FitError| JobError::Prssm {
        what: format!("bench: {what}"),
        source,
    };
    if settings.windows_per_task == 0 {
        return Err(JobError::Setting {
            name: "windows_per_task".into(),
            value: "0".into(),
            expected: "must be at least 1".into(),
        });
    }
    let spec = FitSpec {
        windows_per_task: settings.windows_per_task,
        ..Preset::Paper.fit_spec(7, 5)
    };
    let gemm_gflops = gemm_rate_gflops::<f64>(512, 0.3);
    let gemm_f32_gflops = gemm_rate_gflops::<f32>(512, 0.3);
    let reference_solve_s = reference_solve_seconds(0.2);
    let (elbo, params) = synthetic_objective(&spec, TRAIN_SEQUENCES, PREDICT_STEPS, settings.seed)
        .map_err(|e| engine("building the paper objective", e.into()))?;
    let elbo = elbo.with_precision(settings.precision);
    let times = time_batches(&elbo, &params, settings.batches, settings.seed)
        .map_err(|e| engine("timing training batches", e.into()))?;
    let per_epoch = BATCHES_PER_EPOCH as f64 / settings.batches as f64;
    let model = initial_model(&spec, settings.seed);
    let mixed = settings.precision == Precision::Mixed;
    let (particles, reps) = (spec.particles, settings.reps);
    let predict_s = if mixed {
        time_prediction::<f32>(&model, PREDICT_STEPS, particles, reps)
    } else {
        time_prediction::<f64>(&model, PREDICT_STEPS, particles, reps)
    }
    .map_err(|e| engine("timing prediction", e.into()))?;
    let step_flops = predict_step_flops(&model.config, spec.particles);
    let stream_step_s = if mixed {
        time_stream_step::<f32>(&model, particles, 2000)
    } else {
        time_stream_step::<f64>(&model, particles, 2000)
    }
    .map_err(|e| engine("timing streaming", e.into()))?;
    let share = |part: f64, all: f64| if mixed { part / all } else { 0.0 };
    let train_f32_share = share(
        train_step_f32_flops(&spec.model, spec.particles),
        train_step_flops(&spec.model, spec.particles),
    );
    let predict_f32_share = share(1.0, 1.0);
    Ok(BenchReport {
        precision: settings.precision,
        windows_per_task: settings.windows_per_task,
        threads: current_threads(),
        gemm_gflops,
        gemm_f32_gflops,
        train_f32_share,
        predict_f32_share,
        reference_solve_s,
        batches: settings.batches,
        epoch_s: times.total_s * per_epoch,
        fastest_epoch_s: times.fastest_s * BATCHES_PER_EPOCH as f64,
        train_gflops: times.flop / times.total_s / 1e9,
        predict_s,
        predict_gflops: (PREDICT_STEPS - 1) as f64 * step_flops / predict_s / 1e9,
        stream_step_s,
        stream_gflops: step_flops / stream_step_s / 1e9,
    })
}

/// The machine of the authors' timings solved [`REFERENCE_SOLVE_S`]; this one's speed
/// relative to it.
pub fn speed_against_reference_machine(report: &BenchReport) -> f64 {
    REFERENCE_SOLVE_S / report.reference_solve_s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn report(precision: Precision, train_f32_share: f64, predict_f32_share: f64) -> BenchReport {
        BenchReport {
            precision,
            windows_per_task: 4,
            threads: 2,
            gemm_gflops: 40.0,
            gemm_f32_gflops: 80.0,
            train_f32_share,
            predict_f32_share,
            reference_solve_s: 1e-4,
            batches: 8,
            epoch_s: 10.0,
            fastest_epoch_s: 9.0,
            train_gflops: 40.0,
            predict_s: 0.01,
            predict_gflops: 20.0,
            stream_step_s: 2e-5,
            stream_gflops: 20.0,
        }
    }

    /// 400 GFLOP per epoch on 2 cores at 40 GFLOP/s each: 5 s; with half of them at the
    /// doubled f32 rate, 3.75 s. 0.2 GFLOP per prediction: 5 ms, and 3.75 ms.
    #[test]
    fn flop_limits_weigh_each_precision_by_its_rate() {
        let f64_run = report(Precision::F64, 0.0, 0.0);
        assert!((f64_run.flop_limit_epoch_s() - 5.0).abs() < 1e-12);
        assert!((f64_run.precision_flop_limit_epoch_s() - 5.0).abs() < 1e-12);
        assert!((f64_run.precision_flop_limit_predict_s() - 5e-3).abs() < 1e-15);
        let mixed = report(Precision::Mixed, 0.5, 0.5);
        assert!((mixed.flop_limit_epoch_s() - 5.0).abs() < 1e-12);
        assert!((mixed.precision_flop_limit_epoch_s() - 3.75).abs() < 1e-12);
        assert!((mixed.precision_flop_limit_predict_s() - 3.75e-3).abs() < 1e-15);
    }
}
