//! `flapssm bench`: speed of the PR-SSM engine in the paper's configuration, compared with
//! the authors' code (81.8 s per epoch, 0.152 s per 470-step prediction; prssm-notes §3).

use anyhow::Context;
use clap::Args;
use flapssm_prssm::train::bench::{
    AUTHORS_EPOCH_S, AUTHORS_PREDICT_S, PREDICT_FLOP_PER_POINT_STEP, TRAIN_FLOP_PER_POINT_STEP,
    paper_model, paper_objective, time_batches, time_prediction, time_stream_step,
};

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
}

/// Runs `flapssm bench`.
pub fn run(args: BenchArgs) -> anyhow::Result<()> {
    let threads = rayon::current_num_threads();
    let (elbo, params) =
        paper_objective(512, 470, args.seed).context("building the paper objective")?;
    let n_batches = usize::from(args.batches);
    let (secs, points) =
        time_batches(&elbo, &params, n_batches, args.seed).context("timing training batches")?;
    let epoch_s = secs * 32.0 / n_batches as f64;
    println!(
        "training epoch (512 seq x 470 steps x 30 particles, batch 16, {threads} threads): {epoch_s:.3} s \
         ({n_batches} batches timed), {:.1} GFLOP/s est., {:.1}x faster than the authors' {AUTHORS_EPOCH_S} s",
        points * TRAIN_FLOP_PER_POINT_STEP / secs / 1e9,
        AUTHORS_EPOCH_S / epoch_s
    );
    let model = paper_model(args.seed);
    let pred_s = time_prediction(&model, 470, 30, args.reps).context("timing prediction")?;
    println!(
        "prediction (470 steps x 30 particles, 1 thread): {:.3} ms, {:.1} GFLOP/s est., {:.1}x faster than the authors' {AUTHORS_PREDICT_S} s",
        pred_s * 1e3,
        470.0 * 30.0 * PREDICT_FLOP_PER_POINT_STEP / pred_s / 1e9,
        AUTHORS_PREDICT_S / pred_s
    );
    let step_s = time_stream_step(&model, 30, 2000).context("timing streaming")?;
    println!(
        "streaming step (30 particles): {:.1} us, {:.1} GFLOP/s est.",
        step_s * 1e6,
        30.0 * PREDICT_FLOP_PER_POINT_STEP / step_s / 1e9
    );
    Ok(())
}
