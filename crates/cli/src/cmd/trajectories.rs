//! `flapssm trajectories`: generate a kinematics-only dataset of random wing trajectories.

use std::path::PathBuf;
use std::time::Instant;

use anyhow::Context;
use clap::{Args, ValueEnum};
use flapssm_jobs::kinematics_compare::compare_with_paper;
use flapssm_wing::trajectories::{Family, GeneratorConfig, default_n_train, kinematics_dataset};

/// Distributions of the generator.
#[derive(Clone, Copy, ValueEnum)]
enum Preset {
    /// Calibrated to the paper's 548 measured trajectories (the default).
    Measured,
    /// Hovering-like kinematics with the leading edge leading (the generator before calibration).
    Hovering,
}

/// Generate random servo-feasible wing trajectories (analytic kinematics, no loads).
#[derive(Args)]
pub struct TrajectoriesArgs {
    /// The generator's distributions.
    #[arg(long, value_enum, default_value = "measured")]
    preset: Preset,
    /// Number of trajectories.
    #[arg(long, value_name = "N", default_value_t = 548)]
    n: usize,
    /// Seed of the generator (same seed → identical file).
    #[arg(long, value_name = "S", default_value_t = 0)]
    seed: u64,
    /// Output dataset file (.npz).
    #[arg(long, value_name = "FILE", required_unless_present = "compare_paper")]
    out: Option<PathBuf>,
    /// Print the trajectories' statistics beside the paper's 548 measured ones (5 / 50 / 95th
    /// percentiles, two-sample Kolmogorov–Smirnov test per statistic).
    #[arg(long)]
    compare_paper: bool,
    /// Training trajectories (the first K); default 512, or the published 512/548 split for N ≤ 512.
    #[arg(long, value_name = "K")]
    n_train: Option<usize>,
}

/// Runs `flapssm trajectories`.
pub fn run(args: TrajectoriesArgs) -> anyhow::Result<()> {
    let start = Instant::now();
    if let Some(out) = &args.out {
        flapssm_jobs::files::check_outputs(&[out], &[])?;
    }
    let cfg = GeneratorConfig {
        n_trajectories: args.n,
        n_train: args.n_train.unwrap_or_else(|| default_n_train(args.n)),
        seed: args.seed,
        ..match args.preset {
            Preset::Measured => GeneratorConfig::default(),
            Preset::Hovering => GeneratorConfig::hovering(),
        }
    };
    if args.compare_paper {
        print_comparison(&cfg)?;
    }
    let Some(out) = &args.out else {
        return Ok(());
    };
    let ds = kinematics_dataset(&cfg).context("generating trajectories")?;
    ds.save(out)
        .with_context(|| format!("writing dataset {}", out.display()))?;
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
        out.display(),
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

/// Prints the generator's statistics beside the paper's measured set.
fn print_comparison(cfg: &GeneratorConfig) -> anyhow::Result<()> {
    let rows = compare_with_paper(cfg).context("comparing with the paper's trajectories")?;
    println!(
        "{} generated trajectories (seed {}) beside the paper's 548 measured ones: 5 / 50 / 95th \
         percentiles over trajectories, samples 93.. (two-sample KS test)",
        cfg.n_trajectories, cfg.seed
    );
    println!(
        "{:<32} {:>26} {:>26} {:>6} {:>9}",
        "statistic", "paper (measured)", "generator", "KS D", "p"
    );
    let fmt = |v: [f64; 3]| {
        let d = if v[2].abs() < 1.0 { 3 } else { 1 };
        format!("{:.d$} / {:.d$} / {:.d$}", v[0], v[1], v[2])
    };
    for r in rows {
        println!(
            "{:<32} {:>26} {:>26} {:>6.3} {:>9.2e}",
            r.name,
            fmt(r.paper),
            fmt(r.generated),
            r.ks.statistic,
            r.ks.p_value
        );
    }
    Ok(())
}
