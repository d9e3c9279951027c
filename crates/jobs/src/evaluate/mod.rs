//! The evaluation pipeline: any number of load models on a dataset → accuracy metrics, cycle
//! averages, control authority of the latent states, figures and the HTML report.
//!
//! Per trajectory `i` (n samples) and model ([`LoadModel::predict_into`]):
//! - output means (N, N·mm), variances where the model has them, latent means where it has
//!   latent states (the PR-SSM: standardized latent units, `n × D_x`, particle draws seeded by
//!   [`crate::seed::prediction_seed`]`(seed, i)`).
//! - Standardized errors `e = (y − ŷ)/σ_y` with the dataset's training statistics
//!   ([`flapssm_wing::dataset::Dataset::standardization`]), pooled from `start_sample` on (published: the first 93
//!   samples dropped): per-output RMSE, overall `√mean(e²)`, 2.5/97.5 % intervals.
//! - Coefficients `C_F = F/(½ρSU_ref²)`, `C_M = M/(½ρc̄SU_ref²·1000)` per trajectory; the last
//!   full cycle from [`flapssm_wing::cycles::published_window`]; per-trajectory C_Fx/C_Fy RMSE
//!   over it; half-stroke averages and their errors (measured − predicted) with intervals.
//! - Control authority: [`flapssm_analysis::authority`] on (inputs, latent means of the first
//!   model with latent states) from `start_sample` on, every trajectory (training and test),
//!   period = the cycle duration.
//!
//! The first model is the one studied and the second its baseline: `rmse_ratio` is first /
//! second, as the paper's PR-SSM / LRQSM. Every other model is compared with the first by a
//! paired bootstrap over the test trajectories ([`PairedComparison`]).

use std::path::Path;

use flapssm_wing::dataset::ValidDataset;

use crate::error::{JobError, Result, analysis};
use crate::files::{write_json, write_text};
use crate::models::{LoadModel, predict_all};
use crate::progress::Progress;

mod authority;
pub mod controls;
mod figures;
mod html;
mod job;
pub mod paper;
pub(crate) mod prepared;
pub mod report;
mod scores;
mod tables;
#[cfg(test)]
mod tests;

pub use html::versions;
pub use job::{EvaluationModels, evaluate_models};
pub use report::{
    AuthorityFinding, COEFFICIENT_LABELS, COMPARISON_DRAWS, EVALUATION_FILES, EvalOptions,
    EvaluationReport, HiddenFinding, INPUT_LABELS, METRICS_VERSION, ModelMetrics, PairedComparison,
    PredictionTiming, ReportContext, SplitMetrics, TrajectoryMetrics, TrajectoryModelMetrics,
};

use authority::authority;
use figures::{draw_figures, example_trajectories};
use html::html_report;
use paper::compare;
use scores::{Sets, check, model_metrics, paired_comparisons, prepare, trajectory_metrics};
use tables::{trajectories_csv, write_predictions};

/// Evaluates `models` on `ds` and writes into `out_dir`: `metrics.json`
/// ([`EvaluationReport`]), `trajectories.csv`, `predictions.npz`, with a latent-state model
/// `authority_summary.{json,csv}` and `authority_peaks.csv`, the figures
/// (`fig2c_wing_motion.png`, `fig3_time_histories.png`, `fig4a_histograms_{train,test}.png`,
/// `fig4b_cycle_averages.png`, with a latent-state model `fig5a_hdr.png`,
/// `fig5a_scatter_x1.png`, `fig5b_summary.png`, with a training history `training_*.png`) and
/// `report.html`. Every file is written atomically.
///
/// # Errors
/// No model, a dataset without outputs or training trajectories, models that do not fit it,
/// trajectories without a full stroke cycle, analysis and I/O errors — each naming its item.
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    ds: &ValidDataset,
    dataset_label: &str,
    models: &[&dyn LoadModel],
    opts: &EvalOptions,
    context: &ReportContext,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<EvaluationReport> {
    check(ds, models, opts)?;
    std::fs::create_dir_all(out_dir).map_err(|source| JobError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;
    let mut predictions = Vec::with_capacity(models.len());
    for m in models {
        progress.start(&format!("predict {}", m.name()), ds.len() as u64);
        predictions.push(predict_all(*m, ds, progress)?);
        progress.finish("");
    }

    progress.start("analyse", 0);
    let prep = prepare(ds, &predictions)?;
    let n_train = ds.n_train.min(ds.len());
    let sets = Sets::new(&prep, n_train);
    let metrics = models
        .iter()
        .enumerate()
        .map(|(k, m)| model_metrics(m.name(), m.key(), k, &sets, opts))
        .collect::<Result<Vec<_>>>()?;
    let rmse_ratio = match &metrics[..] {
        [a, b, ..] => a
            .test_or_train()
            .rmse_standardized
            .iter()
            .zip(&b.test_or_train().rmse_standardized)
            .map(|(a, b)| a / b)
            .collect(),
        _ => Vec::new(),
    };
    let comparisons = paired_comparisons(models, &sets, opts)?;
    let trajectories = trajectory_metrics(ds, models, &prep, n_train, opts)?;
    let latent = models.iter().position(|m| m.n_latent() > 0);
    let authority = latent
        .map(|k| authority(ds, &predictions[k], models[k].n_latent(), &prep, opts))
        .transpose()?;
    progress.finish("");

    progress.start("write outputs", 0);
    let mut files = Vec::new();
    let mut file = |name: &str| {
        files.push(name.to_string());
        out_dir.join(name)
    };
    if let Some(a) = &authority {
        a.write(
            &file("authority_summary.json"),
            &file("authority_summary.csv"),
            &file("authority_peaks.csv"),
        )?;
    }
    write_text(
        &file("trajectories.csv"),
        &trajectories_csv(models, &trajectories),
    )?;
    write_predictions(&file("predictions.npz"), ds, models, &predictions)?;
    let examples = example_trajectories(ds, opts.example_trajectories);
    let figures = draw_figures(
        ds,
        models,
        &prep,
        &sets,
        &trajectories,
        authority.as_ref(),
        opts,
        &examples,
        &mut file,
    )?;
    let (report_findings, hidden_authority) = match authority {
        Some(a) => (Some(a.findings), a.hidden),
        None => (None, Vec::new()),
    };
    let mut report = EvaluationReport {
        version: METRICS_VERSION,
        dataset: dataset_label.to_string(),
        n_train,
        n_test: sets.test.len(),
        options: opts.clone(),
        models: metrics,
        rmse_ratio,
        trajectories,
        authority_findings: report_findings.clone().unwrap_or_default(),
        hidden_authority,
        example_trajectories: examples,
        paper_comparison: Vec::new(),
        prediction_timing: models
            .iter()
            .zip(&predictions)
            .filter_map(|(m, p)| {
                let wall: Vec<f64> = p.iter().map(|q| 1e3 * q.wall_s).collect();
                let median_ms = flapssm_analysis::stats::median(&wall).ok()?;
                Some(PredictionTiming {
                    model: m.key().into(),
                    median_ms,
                })
            })
            .collect(),
        comparisons,
        authority_controls: match (&context.control_lags, &report_findings) {
            (Some(lags), Some(findings)) => controls::authority_controls(findings, lags),
            _ => Vec::new(),
        },
        files: {
            let mut f = files.clone();
            f.retain(|f| figures.written(f));
            f.push("metrics.json".into());
            f.push("report.html".into());
            f
        },
    };
    report.paper_comparison = compare(&report);
    write_json(&out_dir.join("metrics.json"), &report)?;
    let html = html_report(&report, context, figures, models);
    let p_html = out_dir.join("report.html");
    html.write(&p_html)
        .map_err(analysis(p_html.display().to_string()))?;
    progress.finish("");
    Ok(report)
}
