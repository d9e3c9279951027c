//! `flapssm bench`: speed of the PR-SSM engine in the paper's configuration, compared with
//! the authors' code (81.8 s per epoch, 0.152 s per 470-step prediction; prssm-notes §3).

use anyhow::Context;
use clap::Args;
use flapssm_prssm::train::bench::{
    AUTHORS_EPOCH_S, AUTHORS_PREDICT_S, REFERENCE_SOLVE_S, gemm_rate_gflops, paper_model,
    paper_objective, predict_step_flops, reference_solve_seconds, time_batches, time_prediction,
    time_stream_step,
};

/// Steps of the timed prediction (the authors' trajectory length).
const PREDICT_STEPS: usize = 470;

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
    let gemm = gemm_rate_gflops(512, 0.3);
    println!("this machine: f64 GEMM (512 x 512 x 512, faer, 1 thread) {gemm:.1} GFLOP/s per core");
    let solve = reference_solve_seconds(0.2);
    println!(
        "  faer triangular solve (100 x 100, 480 right-hand sides, 1 thread): {:.1} us; \
         ~{:.0} us on the machine of the authors' timings (prssm-notes 4): x{:.2} its speed",
        solve * 1e6,
        REFERENCE_SOLVE_S * 1e6,
        REFERENCE_SOLVE_S / solve
    );
    let (elbo, params) =
        paper_objective(512, 470, args.seed).context("building the paper objective")?;
    let n_batches = usize::from(args.batches);
    let times =
        time_batches(&elbo, &params, n_batches, args.seed).context("timing training batches")?;
    let (secs, flop) = (times.total_s, times.flop);
    let epoch_s = secs * 32.0 / n_batches as f64;
    let rate = flop / secs / 1e9;
    let limit = threads as f64 * gemm;
    println!(
        "training epoch (512 seq x 470 steps x 30 particles, batch 16, {threads} threads): {epoch_s:.3} s \
         ({n_batches} batches timed), {:.1}x faster than the authors' {AUTHORS_EPOCH_S} s",
        AUTHORS_EPOCH_S / epoch_s
    );
    println!(
        "  {rate:.1} GFLOP/s = {:.0} % of {threads} x the GEMM rate; all FLOP at that rate: {:.2} s per epoch",
        100.0 * rate / limit,
        epoch_s * rate / limit
    );
    println!(
        "  fastest minibatch x 32: {:.3} s (the epoch above includes any outside load on this machine)",
        times.fastest_s * 32.0
    );
    let model = paper_model(args.seed);
    let pred_s =
        time_prediction(&model, PREDICT_STEPS, 30, args.reps).context("timing prediction")?;
    let transitions = (PREDICT_STEPS - 1) as f64;
    let pred_rate = transitions * predict_step_flops(&model.config, 30) / pred_s / 1e9;
    println!(
        "prediction (470 steps x 30 particles, 1 thread): {:.3} ms, {pred_rate:.1} GFLOP/s ({:.0} % of the GEMM rate), \
         {:.1}x faster than the authors' {AUTHORS_PREDICT_S} s",
        pred_s * 1e3,
        100.0 * pred_rate / gemm,
        AUTHORS_PREDICT_S / pred_s
    );
    let step_s = time_stream_step(&model, 30, 2000).context("timing streaming")?;
    println!(
        "streaming step (30 particles): {:.1} us, {:.1} GFLOP/s",
        step_s * 1e6,
        predict_step_flops(&model.config, 30) / step_s / 1e9
    );
    Ok(())
}
