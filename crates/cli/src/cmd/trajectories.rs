//! `flapssm trajectories`: generate a kinematics-only dataset of random wing trajectories.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::Args;
use flapssm_wing::trajectories::{Family, GeneratorConfig, default_n_train, kinematics_dataset};

/// Generate random servo-feasible wing trajectories (analytic kinematics, no loads).
#[derive(Args)]
pub struct TrajectoriesArgs {
    /// Number of trajectories.
    #[arg(long, value_name = "N", default_value_t = 548)]
    n: usize,
    /// Seed of the generator (same seed → identical file).
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Output dataset file (.npz).
    #[arg(long, value_name = "FILE")]
    out: PathBuf,
    /// Training trajectories (the first K); default 512, or the published 512/548 split for N ≤ 512.
    #[arg(long, value_name = "K")]
    n_train: Option<usize>,
}

/// Runs `flapssm trajectories`.
pub fn run(args: TrajectoriesArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    flapssm_jobs::files::check_outputs(&[&args.out], &[])?;
    let cfg = GeneratorConfig {
        n_trajectories: args.n,
        n_train: args.n_train.unwrap_or_else(|| default_n_train(args.n)),
        seed: args.seed,
        ..GeneratorConfig::default()
    };
    let ds = kinematics_dataset(&cfg).context("generating trajectories")?;
    ds.save(&args.out)
        .with_context(|| format!("writing dataset {}", args.out.display()))?;
    let counts: Vec<String> = Family::ALL
        .iter()
        .map(|f| {
            format!(
                "{} {}",
                f.label(),
                ds.trajectories
                    .iter()
                    .filter(|t| t.family == f.label())
                    .count()
            )
        })
        .collect();
    println!(
        "wrote {}: {} trajectories ({} train) × {} samples at dt = {} s, seed {}; families: {}; {:.2} s",
        args.out.display(),
        ds.trajectories.len(),
        ds.n_train,
        cfg.sampling.n_samples,
        ds.dt_s,
        args.seed,
        counts.join(", "),
        start.elapsed().as_secs_f64()
    );
    Ok(())
}
