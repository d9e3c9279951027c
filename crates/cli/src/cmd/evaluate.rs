//! `flapssm evaluate`: both models on a dataset → metrics, authority analysis, figures, report.

use std::path::PathBuf;

use anyhow::Context;
use clap::Args;
use flapssm_data::Dataset;
use flapssm_jobs::evaluate::{EvalOptions, ReportContext, evaluate};
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;

use crate::progress::Bars;

/// Evaluate a PR-SSM and an LRQSM on a dataset's training and test trajectories.
#[derive(Args)]
pub struct EvaluateArgs {
    /// Dataset file (flapssm .npz) with outputs.
    #[arg(long)]
    dataset: PathBuf,
    /// PR-SSM model file (.json, from `flapssm train`).
    #[arg(long)]
    prssm: PathBuf,
    /// LRQSM model file (.json, from `flapssm qs fit`).
    #[arg(long)]
    lrqsm: PathBuf,
    /// Output folder.
    #[arg(long)]
    out: PathBuf,
    /// Particles of the PR-SSM predictions.
    #[arg(long, default_value_t = 30)]
    particles: usize,
    /// Seed of the prediction draws.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// First analysed sample (0-based; published 93).
    #[arg(long, default_value_t = 93)]
    start_sample: usize,
}

/// Runs `flapssm evaluate`.
pub fn run(a: EvaluateArgs) -> anyhow::Result<()> {
    let ds = Dataset::load(&a.dataset)
        .with_context(|| format!("loading dataset {}", a.dataset.display()))?;
    let prssm = PrssmModel::load(&a.prssm)
        .with_context(|| format!("loading PR-SSM model {}", a.prssm.display()))?;
    let lrqsm = LrqsmModel::load(&a.lrqsm)
        .with_context(|| format!("loading LRQSM model {}", a.lrqsm.display()))?;
    let opts = EvalOptions {
        particles: a.particles,
        seed: a.seed,
        start_sample: a.start_sample,
        ..EvalOptions::default()
    };
    let ctx = ReportContext {
        intro: format!(
            "PR-SSM {} and LRQSM {} evaluated on {}.",
            a.prssm.display(),
            a.lrqsm.display(),
            a.dataset.display()
        ),
        config: serde_json::json!({ "dataset": a.dataset, "prssm": a.prssm, "lrqsm": a.lrqsm }),
        ..ReportContext::default()
    };
    let r = evaluate(
        &ds,
        &a.dataset.display().to_string(),
        &prssm,
        &lrqsm,
        &opts,
        &ctx,
        &a.out,
        &Bars::new(),
    )
    .with_context(|| format!("evaluating on {}", a.dataset.display()))?;
    let f = |v: &[f64]| {
        v.iter()
            .map(|x| format!("{x:.3}"))
            .collect::<Vec<_>>()
            .join(" ")
    };
    for m in [&r.prssm, &r.lrqsm] {
        println!(
            "{:<7} train RMSE (σ) {}",
            m.model,
            f(&m.train.rmse_standardized)
        );
        if let Some(t) = &m.test {
            println!("{:<7} test  RMSE (σ) {}", m.model, f(&t.rmse_standardized));
        }
    }
    println!("ratio PR-SSM/LRQSM    {}", f(&r.rmse_ratio));
    println!(
        "wrote {} (report.html, metrics.json, figures)",
        a.out.display()
    );
    Ok(())
}
