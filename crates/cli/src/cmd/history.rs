//! `flapssm history`: the history curve — the GP baseline's test error against the length of
//! input history it is given, on one or more datasets.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use flapssm_jobs::history::{HISTORY_FILES, HistoryOptions, run_history_curves};
use flapssm_wing::dataset::{Dataset, OUTPUT_NAMES};

use crate::progress::Bars;

/// The history curve: sparse GP regression of the loads on the inputs now and over a history
/// of h samples, h from 0 to a stroke cycle, fitted on each dataset's training trajectories and
/// scored on its test trajectories, each h > 0 against h = 0 with a paired bootstrap interval.
#[derive(Args)]
pub struct HistoryArgs {
    /// Dataset files (flapssm .npz) with outputs; one panel and one curve each.
    #[arg(long, required = true)]
    dataset: Vec<PathBuf>,
    /// Output folder (history_curve.json, .csv, .png).
    #[arg(long)]
    out: PathBuf,
    /// Histories given, in stroke cycles, increasing from 0.
    #[arg(long, value_delimiter = ',', default_values_t = HistoryOptions::default().history_cycles)]
    cycles: Vec<f64>,
    /// First scored sample of each test trajectory (published 93).
    #[arg(long, default_value_t = 93)]
    start_sample: usize,
    /// Seed of the bootstrap.
    #[arg(long, default_value_t = 0)]
    seed: u64,
}

/// Runs `flapssm history`.
pub fn run(a: HistoryArgs) -> anyhow::Result<()> {
    let inputs: Vec<&std::path::Path> = a.dataset.iter().map(PathBuf::as_path).collect();
    flapssm_jobs::files::check_output_dir(&a.out, &HISTORY_FILES, &inputs)?;
    let opts = HistoryOptions {
        history_cycles: a.cycles,
        start_sample: a.start_sample,
        seed: a.seed,
        ..HistoryOptions::default()
    };
    let datasets = a
        .dataset
        .iter()
        .map(|p| {
            let ds =
                Dataset::load(p).with_context(|| format!("loading dataset {}", p.display()))?;
            let label = p.file_name().map_or_else(
                || p.display().to_string(),
                |f| f.to_string_lossy().into_owned(),
            );
            Ok((label, ds))
        })
        .collect::<anyhow::Result<Vec<_>>>()?;
    let curves =
        run_history_curves(&datasets, &opts, &a.out, &Bars::new()).context("history curve")?;
    for c in &curves.curves {
        println!(
            "{} (cycle {} samples, {} test trajectories; test RMSE in σ: {})",
            c.dataset,
            c.cycle_samples,
            c.n_test,
            OUTPUT_NAMES.join(" ")
        );
        for r in &c.rows {
            let marks: String = r
                .versus_static
                .iter()
                .map(|d| if d.significant { '*' } else { ' ' })
                .collect();
            println!(
                "  h = {:>6.4} cycle ({:>3} samples): {}  overall {:.3}  [{}]",
                r.history_cycles,
                r.history_samples,
                r.test_rmse
                    .iter()
                    .map(|x| format!("{x:.3}"))
                    .collect::<Vec<_>>()
                    .join(" "),
                r.test_overall,
                marks
            );
        }
        println!(
            "  lowest held-out training error at h = {} cycle",
            c.best_by_validation_cycles
        );
    }
    println!(
        "wrote {} (history_curve.json, .csv, .png; * : differs from h = 0, paired 95 % interval)",
        a.out.display()
    );
    Ok(())
}
