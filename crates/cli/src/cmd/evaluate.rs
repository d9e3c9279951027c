//! `flapssm evaluate`: both models on a dataset → metrics, authority analysis, figures, report.

use std::path::{Path, PathBuf};

use anyhow::Context;
use clap::Args;
use flapssm_jobs::evaluate::{EVALUATION_FILES, EvalOptions, EvaluationModels, evaluate_models};
use flapssm_jobs::models::baseline;
use flapssm_jobs::rig::RIG_FILES;
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::dataset::Dataset;

use crate::progress::Bars;

/// Evaluate load models (a PR-SSM, an LRQSM, baselines fitted on the spot) on a dataset's
/// training and test trajectories.
#[derive(Args)]
#[command(group(clap::ArgGroup::new("models").required(true).multiple(true).args(["prssm", "lrqsm", "baseline"])))]
pub struct EvaluateArgs {
    /// Dataset file (flapssm .npz) with outputs.
    #[arg(long)]
    dataset: PathBuf,
    /// PR-SSM model file (.json, from `flapssm train`).
    #[arg(long)]
    prssm: Option<PathBuf>,
    /// LRQSM model file (.json, from `flapssm qs fit`).
    #[arg(long)]
    lrqsm: Option<PathBuf>,
    /// Also fit this baseline on the dataset's training trajectories and evaluate it
    /// (repeatable): `arx` (least squares on 21 lags of the inputs, 2 samples apart),
    /// `gp-static` (sparse GP regression of the instantaneous inputs), `gp-history` (the same
    /// given a history of the inputs, its length chosen on the training trajectories).
    #[arg(long, value_name = "KEY", value_parser = baseline_key)]
    baseline: Vec<String>,
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
    /// Also check the dataset (the paper's trajectories, `simulate --source paper`) against this
    /// reference model of the rig (…/bayiz2021-prssm/reference.npz or a model imported from
    /// it): rig-check.json, rig-check.md, rig-examples.png and a report section
    /// (docs/rig-agreement.md).
    #[arg(long, value_name = "FILE")]
    reference: Option<PathBuf>,
}

/// Runs `flapssm evaluate`.
pub fn run(a: EvaluateArgs) -> anyhow::Result<()> {
    let inputs: Vec<&Path> = [
        Some(&a.dataset),
        a.prssm.as_ref(),
        a.lrqsm.as_ref(),
        a.reference.as_ref(),
    ]
    .into_iter()
    .flatten()
    .map(PathBuf::as_path)
    .collect();
    flapssm_jobs::files::check_output_dir(&a.out, &EVALUATION_FILES, &inputs)?;
    if a.reference.is_some() {
        flapssm_jobs::files::check_output_dir(&a.out, &RIG_FILES, &inputs)?;
    }
    let opts = EvalOptions {
        particles: a.particles,
        seed: a.seed,
        start_sample: a.start_sample,
        ..EvalOptions::default()
    };
    opts.check()?;
    let ds = Dataset::load(&a.dataset)
        .with_context(|| format!("loading dataset {}", a.dataset.display()))?;
    let prssm = a
        .prssm
        .as_ref()
        .map(|p| {
            PrssmModel::load(p).with_context(|| format!("loading PR-SSM model {}", p.display()))
        })
        .transpose()?;
    let lrqsm = a
        .lrqsm
        .as_ref()
        .map(|p| {
            LrqsmModel::load(p).with_context(|| format!("loading LRQSM model {}", p.display()))
        })
        .transpose()?;
    let models = EvaluationModels {
        prssm: prssm.as_ref(),
        lrqsm: lrqsm.as_ref(),
        baselines: &a.baseline,
        reference: a.reference.as_deref(),
    };
    let config = serde_json::json!({
        "dataset": a.dataset, "prssm": a.prssm, "lrqsm": a.lrqsm, "baselines": a.baseline,
        "reference": a.reference,
    });
    let r = evaluate_models(
        &ds,
        &a.dataset.display().to_string(),
        &models,
        &opts,
        config,
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
    for m in &r.models {
        println!(
            "{:<7} train RMSE (σ) {}",
            m.model,
            f(&m.train.rmse_standardized)
        );
        if let Some(t) = &m.test {
            println!("{:<7} test  RMSE (σ) {}", m.model, f(&t.rmse_standardized));
        }
    }
    if let [first, second, ..] = &r.models[..] {
        println!(
            "ratio {}/{}    {}",
            first.model,
            second.model,
            f(&r.rmse_ratio)
        );
    }
    for c in &r.comparisons {
        let name = |k: &str| r.model(k).map_or(k, |m| m.model.as_str()).to_string();
        println!(
            "{} − {} ({}, paired 95 % interval): {}",
            name(&c.a),
            name(&c.b),
            c.split,
            c.outputs
                .iter()
                .map(|d| format!("{d}{}", if d.significant { "*" } else { "" }))
                .collect::<Vec<_>>()
                .join("  ")
        );
    }
    for c in &r.authority_controls {
        let m = |m: &flapssm_jobs::evaluate::controls::ControlMeasure| {
            format!(
                "|r| {:.2} lag {:.3}{}",
                m.median_abs_r,
                m.median_lag_cycles,
                if m.reproduces { " ✓" } else { "  " }
            )
        };
        println!(
            "Fig. 5 {} → outputs: trained {}; loads {}; memoryless {}; stand-in {} — {}",
            c.input,
            m(&c.trained),
            m(&c.dataset_loads),
            m(&c.memoryless_loads),
            m(&c.stand_in),
            c.verdict()
        );
    }
    for h in &r.hidden_authority {
        println!(
            "hidden subspace ({} dims) ← {}: R {:.2} lag {:.3} (chance {:.2}), excess {:+.3} [{:+.3}, {:+.3}]{}",
            h.subspace.dimension,
            h.input,
            h.subspace.median_r,
            h.subspace.median_lag_cycles,
            h.subspace.chance_median_r,
            h.subspace.excess,
            h.subspace.excess_interval.lo,
            h.subspace.excess_interval.hi,
            if h.subspace.above_chance {
                " above chance"
            } else {
                ""
            }
        );
    }
    println!(
        "wrote {} (report.html, metrics.json, figures)",
        a.out.display()
    );
    Ok(())
}

/// A registered baseline's key (`--baseline`).
fn baseline_key(key: &str) -> Result<String, String> {
    baseline(key)
        .map(|b| b.key.to_string())
        .map_err(|e| e.to_string())
}
