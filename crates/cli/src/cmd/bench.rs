//! `flapssm bench`: speed of the PR-SSM engine in the paper's configuration, compared with
//! the authors' code (81.8 s per epoch, 0.152 s per 470-step prediction; prssm-notes §3).

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use flapssm_jobs::bench::{
    AUTHORS_EPOCH_S, AUTHORS_PREDICT_S, BenchSettings, bench, speed_against_reference_machine,
};
use flapssm_jobs::curve::{
    CONVERGED_TAIL, QUALITY_TOLERANCE, RUNNING_MEDIAN_WINDOW, early_stop_point, read_curve,
    time_to_quality,
};
use flapssm_prssm::Precision;
use flapssm_prssm::bench::REFERENCE_SOLVE_S;
use flapssm_prssm::train::fit::DEFAULT_WINDOWS_PER_TASK;

/// Measure training, prediction and streaming speed (release build, this machine).
#[derive(Args)]
pub struct BenchArgs {
    /// Minibatches timed (of 32 per epoch of 512 sequences); the epoch time is extrapolated.
    #[arg(long, default_value_t = 32, value_parser = clap::value_parser!(u8).range(1..=32))]
    batches: u8,
    /// Repetitions of the prediction timing (median reported).
    #[arg(long, default_value_t = 9, value_parser = super::positive::<usize>)]
    reps: usize,
    /// Seed of the synthetic data and parameters.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Also report time-to-quality: the wall time at which this learning curve (a training
    /// run's `<model stem>.curve.csv`) first came within 2 % of the converged validation RMSE.
    #[arg(long, value_name = "CURVE")]
    train: Option<PathBuf>,
    /// Learning curve of the published schedule (Adam 0.03, 1000 epochs) on the same data:
    /// its converged value is the median of its last 10 % of evaluated epochs (default: the
    /// --train curve itself).
    #[arg(long, value_name = "CURVE", requires = "train")]
    reference: Option<PathBuf>,
    /// Also say where early stopping with this patience (evaluated epochs without a new best
    /// validation RMSE) would have ended the --train run, and what it would have kept.
    #[arg(long, value_name = "N", requires = "train", value_parser = super::positive::<usize>)]
    patience: Option<usize>,
    /// Arithmetic of the timed training, prediction and streaming products: f64 (the
    /// reference) or mixed (the large products in f32; docs/training.md).
    #[arg(long, default_value = "f64")]
    precision: Precision,
    /// Windows (sequences) per parallel task of the timed minibatches: a minibatch of 16 keeps
    /// at most ceil(16 / N) threads busy.
    #[arg(long, value_name = "N", default_value_t = DEFAULT_WINDOWS_PER_TASK, value_parser = super::positive::<usize>)]
    windows_per_task: usize,
}

/// Prints the time-to-quality of `run` against `reference`.
fn print_time_to_quality(
    run: &Path,
    reference: &Path,
    patience: Option<usize>,
) -> anyhow::Result<()> {
    let points = read_curve(run)?;
    let reference_points = if reference == run {
        points.clone()
    } else {
        read_curve(reference)?
    };
    let q = time_to_quality(&points, &reference_points, reference, QUALITY_TOLERANCE)?;
    let ref_last = reference_points.last().map_or(0, |p| p.epoch + 1);
    println!(
        "time to quality of {}: converged validation RMSE {:.4} (median of the last {:.0} % of \
         {}, {} epochs), threshold {:.4} (+{:.0} %)",
        run.display(),
        q.converged_rmse,
        100.0 * CONVERGED_TAIL,
        reference.display(),
        ref_last,
        q.threshold,
        100.0 * QUALITY_TOLERANCE
    );
    match q.reached {
        Some(p) => println!(
            "  reached at epoch {} (step {}) after {:.1} s = {:.1} min of training",
            p.epoch,
            p.step,
            p.wall_s,
            p.wall_s / 60.0
        ),
        None => println!(
            "  not reached: last epoch {} (step {}, {:.1} min) at {:.4}, best {:.4}",
            q.last.epoch,
            q.last.step,
            q.last.wall_s / 60.0,
            q.last.val_rmse,
            q.best_rmse
        ),
    }
    match q.held {
        Some(p) => println!(
            "  held (median of the last {RUNNING_MEDIAN_WINDOW} evaluations at or below the \
             threshold) from epoch {} (step {}) after {:.1} s = {:.1} min of training",
            p.epoch,
            p.step,
            p.wall_s,
            p.wall_s / 60.0
        ),
        None => println!(
            "  not held: the median of no {RUNNING_MEDIAN_WINDOW} consecutive evaluations is at \
             or below the threshold"
        ),
    }
    if let Some(n) = patience {
        match early_stop_point(&points, n) {
            Some((stop, kept)) => println!(
                "  with --patience {n}: stops at epoch {} after {:.1} min, keeps epoch {} at \
                 {:.4} ({:+.1} % of converged)",
                stop.epoch,
                stop.wall_s / 60.0,
                kept.epoch,
                kept.val_rmse,
                100.0 * (kept.val_rmse / q.converged_rmse - 1.0)
            ),
            None => println!("  with --patience {n}: would not have stopped early"),
        }
    }
    Ok(())
}

/// Runs `flapssm bench`.
pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    if let Some(curve) = &args.train {
        print_time_to_quality(
            curve,
            args.reference.as_deref().unwrap_or(curve),
            args.patience,
        )
        .context("flapssm bench --train")?;
    }
    let r = bench(&BenchSettings {
        batches: usize::from(args.batches),
        reps: args.reps,
        seed: args.seed,
        precision: args.precision,
        windows_per_task: args.windows_per_task,
    })
    .context("flapssm bench")?;
    let threads = r.threads;
    println!(
        "this machine: f64 GEMM (512 x 512 x 512, faer, 1 thread) {:.1} GFLOP/s per core; f32 GEMM {:.1}",
        r.gemm_gflops, r.gemm_f32_gflops
    );
    println!(
        "  faer triangular solve (100 x 100, 480 right-hand sides, 1 thread): {:.1} us; \
         ~{:.0} us on the machine of the authors' timings (prssm-notes 4): x{:.2} its speed",
        r.reference_solve_s * 1e6,
        REFERENCE_SOLVE_S * 1e6,
        speed_against_reference_machine(&r)
    );
    println!(
        "training epoch (512 seq x 470 steps x 30 particles, batch 16, {threads} threads, {} windows per task, {} precision): \
         {:.3} s ({} batches timed); the authors' code took {AUTHORS_EPOCH_S} s on their machine, \
         not this one (a 2-core AMD EPYC Zen 5, prssm-notes 3): {:.1}x",
        r.windows_per_task,
        r.precision,
        r.epoch_s,
        r.batches,
        AUTHORS_EPOCH_S / r.epoch_s
    );
    println!(
        "  {:.1} GFLOP/s = {:.0} % of {threads} x the f64 GEMM rate; all FLOP at that rate (the f64 FLOP limit): {:.2} s per epoch",
        r.train_gflops,
        100.0 * r.train_gflops / (threads as f64 * r.gemm_gflops),
        r.flop_limit_epoch_s()
    );
    if r.precision == Precision::Mixed {
        println!(
            "  the mixed FLOP limit ({:.0} % of the FLOP, the f32 products, at {threads} x the f32 GEMM rate, the rest at the f64 rate): {:.2} s per epoch",
            100.0 * r.train_f32_share,
            r.precision_flop_limit_epoch_s()
        );
    }
    println!(
        "  fastest minibatch x 32: {:.3} s (the epoch above includes any outside load on this machine)",
        r.fastest_epoch_s
    );
    println!(
        "prediction (470 steps x 30 particles, 1 thread, in {}): {:.3} ms, {:.1} GFLOP/s ({:.0} % of the {} GEMM rate), \
         the authors' code {AUTHORS_PREDICT_S} s on their machine, not this one: {:.1}x",
        r.prediction_float(),
        r.predict_s * 1e3,
        r.predict_gflops,
        100.0 * r.predict_gflops / r.prediction_gemm_gflops(),
        r.prediction_float(),
        AUTHORS_PREDICT_S / r.predict_s
    );
    println!(
        "  all FLOP at the {} GEMM rate: {:.2} ms",
        r.prediction_float(),
        r.precision_flop_limit_predict_s() * 1e3
    );
    println!(
        "streaming step (30 particles, in {}): {:.1} us, {:.1} GFLOP/s",
        r.prediction_float(),
        r.stream_step_s * 1e6,
        r.stream_gflops
    );
    Ok(())
}
