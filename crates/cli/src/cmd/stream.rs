//! `flapssm stream MODEL`: real-time PR-SSM prediction from standard input to standard output.

use std::io::{BufWriter, IsTerminal};
use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use flapssm_jobs::stream::{LoadStream, StreamSettings, stream_csv};
use flapssm_prssm::PrssmModel;

/// Predict sample by sample: input rows on stdin, prediction rows on stdout as each arrives.
///
/// Standard input: a header line of D_u column names, then one row of D_u numbers per time step
/// (the model's units: physical when it carries normalization statistics). Standard output:
/// `step,mean_0..,var_0..`, one line per input row, flushed at once: the format of
/// `flapssm predict --inputs`, and for the same seed the same numbers.
#[derive(Args)]
pub struct StreamArgs {
    /// Model file (.json).
    model: PathBuf,
    /// Number of particles.
    #[arg(long, default_value_t = 30, value_parser = super::positive::<usize>)]
    particles: usize,
    /// Seed of the particle draws.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

/// Runs `flapssm stream`.
pub fn run(args: StreamArgs) -> anyhow::Result<()> {
    let model = PrssmModel::load(&args.model)
        .with_context(|| format!("loading model {}", args.model.display()))?;
    let settings = StreamSettings {
        particles: args.particles,
        seed: args.seed,
    };
    let mut stream = LoadStream::new(&model, &settings)
        .with_context(|| format!("streaming with {}", args.model.display()))?;
    for note in stream.notes() {
        eprintln!("warning: {}: {note}", args.model.display());
    }
    let stdin = std::io::stdin();
    if stdin.is_terminal() {
        eprintln!(
            "reading {} comma-separated inputs per line from the terminal (a header line first; Ctrl-D ends)",
            stream.n_input()
        );
    }
    let t0 = Instant::now();
    let n = stream_csv(
        &mut stream,
        stdin.lock(),
        BufWriter::new(std::io::stdout().lock()),
        "<stdin>",
    )?;
    let wall = t0.elapsed().as_secs_f64();
    eprintln!(
        "{n} steps, {} particles, {:.1} us per step including I/O",
        args.particles,
        wall * 1e6 / (n.max(1) as f64)
    );
    Ok(())
}
