//! The evaluation pipeline: both models on a dataset → accuracy metrics, cycle averages,
//! control authority of the PR-SSM latent states, figures and the HTML report.
//!
//! Per trajectory `i` (n samples):
//! - PR-SSM: open-loop prediction from the model's initial-state rule
//!   ([`flapssm_prssm::train::fit::predict_raw`], `particles` particles, seed
//!   `derive_seed(seed, 7, i)`): output mean/variance in N and N·mm, latent means (standardized
//!   latent units, `n × D_x`).
//! - LRQSM: [`flapssm_qs::lrqsm::predict_dataset`] with the fitted intercept.
//! - Standardized errors `e = (y − ŷ)/σ_y` with the dataset's training statistics
//!   ([`Dataset::standardization`]), pooled from `start_sample` on (published: the first 93
//!   samples dropped): per-output RMSE, overall `√mean(e²)`, 2.5/97.5 % intervals.
//! - Coefficients `C_F = F/(½ρSU_ref²)`, `C_M = M/(½ρc̄SU_ref²·1000)` per trajectory; the last
//!   full cycle from [`flapssm_wing::cycles::published_window`]; per-trajectory C_Fx/C_Fy RMSE
//!   over it; half-stroke averages and their errors (measured − predicted) with intervals.
//! - Control authority: [`flapssm_analysis::authority`] on (inputs, PR-SSM latent means) from
//!   `start_sample` on, every trajectory (training and test), period = the cycle duration.

use std::path::Path;

use flapssm_data::{Dataset, OUTPUT_NAMES};
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::cycles::published_window;
use serde::{Deserialize, Serialize};

use flapssm_analysis::authority::{
    AuthorityConfig, AuthoritySummary, AuthorityTrajectory, peak_table,
};
use flapssm_analysis::cycles_avg::CycleWindow;
use flapssm_analysis::metrics::{
    CoefficientScales, Histogram, PUBLISHED_START_SAMPLE, PooledErrors,
};
use flapssm_analysis::metrics::{coefficients_of, window_rmse};
use flapssm_analysis::plots::{authority as pa, errors as pe, wing3d};
use flapssm_analysis::stats::Interval;

use crate::error::{JobError, Result, analysis};
use crate::files::{write_json, write_text};
use crate::predict::{predict_lrqsm, predict_prssm};
use crate::progress::Progress;

mod figures;
mod html;
mod prepared;
mod tables;

use figures::{draw_fig3, draw_training, example_title, example_trajectories};
pub use html::versions;
use html::{ReportFigures, html_report};
use prepared::{Pick, Prepared, cycle_errors, pooled, rows, split_metrics};
use tables::{trajectories_csv, write_predictions};

/// Display names of the 7 inputs (dataset order).
pub const INPUT_LABELS: [&str; 7] = ["AoA", "|v|", "a_x", "a_y", "a_z", "dα/dt", "d²α/dt²"];
/// Display names of the 5 outputs as coefficients.
pub const COEFFICIENT_LABELS: [&str; 5] = ["C_Fx", "C_Fy", "C_Mx", "C_My", "C_Mz"];

/// Settings of [`evaluate`].
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvalOptions {
    /// Particles of the PR-SSM predictions (published 30).
    pub particles: usize,
    /// Seed of the PR-SSM prediction draws.
    pub seed: u64,
    /// First analysed sample, 0-based ([`PUBLISHED_START_SAMPLE`] = 93).
    pub start_sample: usize,
    /// Level of the central intervals, % (95).
    pub level: f64,
    /// Control-authority analysis settings.
    pub authority: AuthorityConfig,
    /// Test trajectories shown in Figs. 2C and 3 (at most).
    pub example_trajectories: usize,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            particles: 30,
            seed: 0,
            start_sample: PUBLISHED_START_SAMPLE,
            level: 95.0,
            authority: AuthorityConfig::default(),
            example_trajectories: 6,
        }
    }
}

/// Accuracy of one model on one set of trajectories.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SplitMetrics {
    /// Trajectories.
    pub n_trajectories: usize,
    /// Samples per output pooled (from `start_sample` on).
    pub n_samples: usize,
    /// RMSE per output of standardized errors [F_x, F_y, M_x, M_y, M_z] (σ units).
    pub rmse_standardized: Vec<f64>,
    /// `√mean(e²)` over all outputs and samples (σ units).
    pub overall_rmse_standardized: f64,
    /// Central interval of the standardized errors per output (σ units).
    pub error_interval: Vec<Interval>,
    /// Median over trajectories of the last-cycle RMSE of C_Fx and of C_Fy.
    pub median_cycle_rmse_cf: [f64; 2],
    /// Central interval of the half-stroke-average errors per coefficient (C_F, C_M).
    pub cycle_average_error_interval: Vec<Interval>,
}

/// Accuracy of one model.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelMetrics {
    /// "PR-SSM" or "LRQSM".
    pub model: String,
    /// Training trajectories.
    pub train: SplitMetrics,
    /// Test trajectories (none when the dataset has no test part).
    pub test: Option<SplitMetrics>,
    /// Half-stroke-average error intervals over training and test together (as the paper).
    pub cycle_average_error_interval_all: Vec<Interval>,
}

/// Per-trajectory results.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectoryMetrics {
    /// Index in the dataset.
    pub index: usize,
    /// "train" or "test".
    pub split: String,
    /// Family label.
    pub family: String,
    /// U_ref (m/s).
    pub u_ref_m_s: f64,
    /// Stroke period (samples).
    pub period_samples: usize,
    /// First sample of the last-cycle window (0-based).
    pub window_start: usize,
    /// PR-SSM last-cycle RMSE of [C_Fx, C_Fy].
    pub prssm_cycle_rmse_cf: [f64; 2],
    /// LRQSM last-cycle RMSE of [C_Fx, C_Fy].
    pub lrqsm_cycle_rmse_cf: [f64; 2],
    /// PR-SSM overall standardized RMSE from `start_sample` on.
    pub prssm_overall_rmse: f64,
    /// LRQSM overall standardized RMSE from `start_sample` on.
    pub lrqsm_overall_rmse: f64,
}

/// The influence of one input on one latent state (a row of Fig. 5B).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuthorityFinding {
    /// Input name.
    pub input: String,
    /// State name.
    pub state: String,
    /// Median over trajectories of max |r|.
    pub median_abs_r: f64,
    /// Median lag (stroke cycles).
    pub median_lag_cycles: f64,
    /// Interquartile range of the lag (cycles).
    pub lag_iqr_cycles: f64,
    /// Lag of the KDE mode (cycles).
    pub mode_lag_cycles: f64,
    /// Median |r| above the strong threshold (0.5).
    pub strong: bool,
}

/// Everything [`evaluate`] computes (written as `metrics.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct EvaluationReport {
    /// Dataset description (file name or origin).
    pub dataset: String,
    /// Training trajectories.
    pub n_train: usize,
    /// Test trajectories.
    pub n_test: usize,
    /// Settings.
    pub options: EvalOptions,
    /// PR-SSM accuracy.
    pub prssm: ModelMetrics,
    /// LRQSM accuracy.
    pub lrqsm: ModelMetrics,
    /// Test RMSE ratio PR-SSM / LRQSM per output (training set when there is no test set).
    pub rmse_ratio: Vec<f64>,
    /// Per-trajectory results.
    pub trajectories: Vec<TrajectoryMetrics>,
    /// Influence of AoA and a_x on the output states x1..x5 (paper: AoA near zero lag, a_x
    /// about 0.2 cycle).
    pub authority_findings: Vec<AuthorityFinding>,
    /// Files written, relative to the output folder.
    pub files: Vec<String>,
}

/// Text and settings the caller adds to the HTML report.
#[derive(Debug, Clone, Default)]
pub struct ReportContext {
    /// Page title.
    pub title: String,
    /// Introductory paragraph.
    pub intro: String,
    /// Extra headline rows (e.g. timings).
    pub headline: Vec<(String, String)>,
    /// Configuration shown in the report.
    pub config: serde_json::Value,
}

/// Evaluates both models on `ds` and writes into `out_dir`: `metrics.json`
/// ([`EvaluationReport`]), `trajectories.csv`, `authority_summary.{json,csv}`,
/// `authority_peaks.csv`, `predictions.npz`, the figures (`fig2c_wing_motion.png`,
/// `fig3_time_histories.png`, `fig4a_histograms_{train,test}.png`, `fig4b_cycle_averages.png`,
/// `fig5a_hdr.png`, `fig5a_scatter_x1.png`, `fig5b_summary.png`, `training_*.png`) and
/// `report.html`. Every file is written atomically.
///
/// # Errors
/// A dataset without outputs or training trajectories, models that do not fit it, trajectories
/// without a full stroke cycle, analysis and I/O errors — each naming its item.
#[allow(clippy::too_many_arguments)]
pub fn evaluate(
    ds: &Dataset,
    dataset_label: &str,
    prssm: &PrssmModel,
    lrqsm: &LrqsmModel,
    opts: &EvalOptions,
    context: &ReportContext,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<EvaluationReport> {
    ds.validate()?;
    if !ds.has_outputs() {
        return Err(flapssm_data::DatasetError::NoOutputs.into());
    }
    let stats = ds.standardization()?;
    let n = ds.n_samples();
    if opts.start_sample >= n {
        return Err(JobError::Mismatch {
            what: "start_sample".into(),
            expected: format!("fewer than the {n} samples per trajectory"),
            found: opts.start_sample.to_string(),
        });
    }
    std::fs::create_dir_all(out_dir).map_err(|source| JobError::Io {
        path: out_dir.to_path_buf(),
        source,
    })?;

    progress.start("predict PR-SSM", ds.len() as u64);
    let pp = predict_prssm(prssm, ds, opts.particles, opts.seed, progress)?;
    progress.finish("");
    let lq = predict_lrqsm(lrqsm, ds)?;
    let dx = prssm.config.n_state;

    progress.start("analyse", 0);
    let fluid = &ds.meta.fluid;
    let wing = &ds.meta.wing;
    let z = |y: &[f64]| -> Vec<f64> {
        y.chunks_exact(5)
            .flat_map(|r| (0..5).map(move |j| (r[j] - stats.mean_y[j]) / stats.std_y[j]))
            .collect()
    };
    let mut prep = Vec::with_capacity(ds.len());
    for (i, t) in ds.trajectories.iter().enumerate() {
        let what = format!("trajectory {i}");
        let stroke: Vec<f64> = t.euler_rad.iter().map(|e| e[0]).collect();
        let w = published_window(&stroke).map_err(|source| JobError::Cycle {
            trajectory: i,
            source,
        })?;
        let window = CycleWindow {
            start: w.first,
            duration: w.duration,
        };
        let scales = CoefficientScales::new(
            fluid.density_kg_m3,
            wing.area_m2(),
            wing.chord_m,
            t.u_ref_m_s,
        )
        .map_err(analysis(format!("{what} coefficient scales")))?;
        let measured = t.outputs.as_deref().unwrap_or_default().as_flattened();
        let coef = |v: &[f64]| -> Result<Vec<f64>> {
            coefficients_of(rows(v, 5, &what)?, &scales).map_err(analysis(what.clone()))
        };
        let std_raw: Vec<f64> = pp[i].output_var.iter().map(|v| v.max(0.0).sqrt()).collect();
        prep.push(Prepared {
            window,
            measured_z: z(measured),
            measured_c: coef(measured)?,
            prssm_z: z(&pp[i].output_mean),
            prssm_c: coef(&pp[i].output_mean)?,
            prssm_std_c: coef(&std_raw)?,
            lrqsm_z: z(&lq[i]),
            lrqsm_c: coef(&lq[i])?,
        });
    }
    let n_train = ds.n_train.min(ds.len());
    if n_train == 0 {
        return Err(flapssm_data::DatasetError::NoTrainingData { n_train }.into());
    }
    let train: Vec<&Prepared> = prep[..n_train].iter().collect();
    let test: Vec<&Prepared> = prep[n_train..].iter().collect();
    let all: Vec<&Prepared> = prep.iter().collect();
    fn pick_p(p: &Prepared) -> (&[f64], &[f64]) {
        (&p.prssm_z, &p.prssm_c)
    }
    fn pick_l(p: &Prepared) -> (&[f64], &[f64]) {
        (&p.lrqsm_z, &p.lrqsm_c)
    }
    let model_metrics = |name: &str, pick: Pick<'_>| {
        Ok::<_, JobError>(ModelMetrics {
            model: name.into(),
            train: split_metrics(&train, pick, opts, &format!("{name} training metrics"))?,
            test: if test.is_empty() {
                None
            } else {
                Some(split_metrics(
                    &test,
                    pick,
                    opts,
                    &format!("{name} test metrics"),
                )?)
            },
            cycle_average_error_interval_all: cycle_errors(&all, &|p| pick(p).1)?
                .intervals(opts.level)
                .map_err(analysis(format!("{name} cycle averages")))?,
        })
    };
    let pm = model_metrics("PR-SSM", &pick_p)?;
    let lm = model_metrics("LRQSM", &pick_l)?;
    let (pr, lr) = match (&pm.test, &lm.test) {
        (Some(a), Some(b)) => (&a.rmse_standardized, &b.rmse_standardized),
        _ => (&pm.train.rmse_standardized, &lm.train.rmse_standardized),
    };
    let rmse_ratio: Vec<f64> = pr.iter().zip(lr).map(|(a, b)| a / b).collect();

    let mut trajectories = Vec::with_capacity(ds.len());
    for (i, (t, p)) in ds.trajectories.iter().zip(&prep).enumerate() {
        let what = format!("trajectory {i} metrics");
        let m = rows(&p.measured_c, 5, &what)?;
        let cyc = |v: &[f64]| -> Result<[f64; 2]> {
            let q = rows(v, 5, &what)?;
            Ok([
                window_rmse(m, q, 0, p.window).map_err(analysis(what.clone()))?,
                window_rmse(m, q, 1, p.window).map_err(analysis(what.clone()))?,
            ])
        };
        let overall = |v: &[f64]| -> Result<f64> {
            let e = PooledErrors::new(
                &[rows(&p.measured_z, 5, &what)?],
                &[rows(v, 5, &what)?],
                opts.start_sample,
            )
            .map_err(analysis(what.clone()))?;
            Ok(e.overall_rmse())
        };
        trajectories.push(TrajectoryMetrics {
            index: i,
            split: if i < n_train { "train" } else { "test" }.into(),
            family: t.family.clone(),
            u_ref_m_s: t.u_ref_m_s,
            period_samples: p.window.duration,
            window_start: p.window.start,
            prssm_cycle_rmse_cf: cyc(&p.prssm_c)?,
            lrqsm_cycle_rmse_cf: cyc(&p.lrqsm_c)?,
            prssm_overall_rmse: overall(&p.prssm_z)?,
            lrqsm_overall_rmse: overall(&p.lrqsm_z)?,
        });
    }

    // Control authority on the latent means, every trajectory, transient dropped.
    let s0 = opts.start_sample;
    let auth_traj: Vec<AuthorityTrajectory<'_>> = ds
        .trajectories
        .iter()
        .zip(&pp)
        .zip(&prep)
        .map(|((t, p), q)| {
            Ok(AuthorityTrajectory {
                inputs: rows(&t.inputs.as_flattened()[s0 * 7..], 7, "authority inputs")?,
                states: rows(&p.latent_mean[s0 * dx..], dx, "authority states")?,
                period_samples: q.window.duration as f64,
            })
        })
        .collect::<Result<_>>()?;
    let table = peak_table(&auth_traj, &opts.authority).map_err(analysis("cross-correlations"))?;
    let state_names: Vec<String> = (1..=dx).map(|j| format!("x{j}")).collect();
    let input_names: Vec<String> = INPUT_LABELS.iter().map(|s| s.to_string()).collect();
    let summary = AuthoritySummary::new(
        &table,
        state_names.clone(),
        input_names.clone(),
        &opts.authority,
    )
    .map_err(analysis("control-authority summary"))?;
    let mut authority_findings = Vec::new();
    for input in [0usize, 2] {
        for (state, state_name) in state_names.iter().enumerate().take(5) {
            let s = summary.pair(state, input);
            authority_findings.push(AuthorityFinding {
                input: input_names[input].clone(),
                state: state_name.clone(),
                median_abs_r: s.median_abs_r,
                median_lag_cycles: s.median_lag_cycles,
                lag_iqr_cycles: s.lag_iqr_cycles,
                mode_lag_cycles: s.mode_lag_cycles,
                strong: s.strong,
            });
        }
    }
    progress.finish("");

    // Files.
    progress.start("write outputs", 0);
    let mut files = Vec::new();
    let mut file = |name: &str| {
        files.push(name.to_string());
        out_dir.join(name)
    };
    let p_json = file("authority_summary.json");
    summary
        .write_json(&p_json)
        .map_err(analysis(p_json.display().to_string()))?;
    let p_csv = file("authority_summary.csv");
    summary
        .write_csv(&p_csv)
        .map_err(analysis(p_csv.display().to_string()))?;
    let p_peaks = file("authority_peaks.csv");
    table
        .write_csv(&p_peaks, &state_names, &input_names)
        .map_err(analysis(p_peaks.display().to_string()))?;
    write_text(&file("trajectories.csv"), &trajectories_csv(&trajectories))?;
    write_predictions(&file("predictions.npz"), ds, &pp, &lq, dx)?;

    // Figures.
    let examples = example_trajectories(ds, opts.example_trajectories);
    let mut fig = |name: &str| file(name);
    let f_2c = fig("fig2c_wing_motion.png");
    let f_3 = fig("fig3_time_histories.png");
    let f_4a_train = fig("fig4a_histograms_train.png");
    let f_4a_test = fig("fig4a_histograms_test.png");
    let f_4b = fig("fig4b_cycle_averages.png");
    let f_5a = fig("fig5a_hdr.png");
    let f_5s = fig("fig5a_scatter_x1.png");
    let f_5b = fig("fig5b_summary.png");
    let f_loss = fig("training_loss.png");
    let f_rmse = fig("training_rmse.png");
    let labels: Vec<String> = examples
        .iter()
        .map(|&i| example_title(ds, i, &trajectories[i]))
        .collect();
    let paths: Vec<wing3d::WingPath<'_>> = examples
        .iter()
        .zip(&labels)
        .map(|(&i, l)| wing3d::WingPath {
            label: l,
            euler_rad: &ds.trajectories[i].euler_rad[prep[i].window.range(n).unwrap_or(0..=0)],
        })
        .collect();
    let geom = wing3d::WingSketchGeometry {
        r_m: wing.u_ref_radius_m,
        chord_m: wing.chord_m,
        pitch_axis_frac: wing.pitch_axis_frac,
        ..Default::default()
    };
    wing3d::wing_motion_3d(&f_2c, &paths, &geom).map_err(analysis("Fig. 2C"))?;
    draw_fig3(&f_3, ds, &prep, &examples, &labels)?;
    let names5: Vec<&str> = COEFFICIENT_LABELS.to_vec();
    let edges = Histogram::uniform_edges(-1.1, 1.1, 0.01);
    let out_names = OUTPUT_NAMES
        .iter()
        .map(|s| format!("{s}/σ"))
        .collect::<Vec<_>>();
    let out_refs: Vec<&str> = out_names.iter().map(String::as_str).collect();
    for (path, set, label) in [(&f_4a_train, &train, "train"), (&f_4a_test, &test, "test")] {
        if set.is_empty() {
            continue;
        }
        let ep = pooled(set, &|p| &p.prssm_z, s0)?;
        let el = pooled(set, &|p| &p.lrqsm_z, s0)?;
        let lp = format!("PR-SSM {label}");
        let ll = format!("LRQSM {label}");
        pe::error_histograms(
            path,
            &out_refs,
            &[
                pe::ModelErrors {
                    label: &lp,
                    errors: &ep.errors,
                },
                pe::ModelErrors {
                    label: &ll,
                    errors: &el.errors,
                },
            ],
            &edges,
            opts.level,
        )
        .map_err(analysis("Fig. 4A"))?;
    }
    let cp = cycle_errors(&all, &|p| &p.prssm_c)?;
    let cl = cycle_errors(&all, &|p| &p.lrqsm_c)?;
    pe::cycle_average_scatter(
        &f_4b,
        &names5,
        &[
            pe::ModelCycleAverages {
                label: "PR-SSM",
                observed: &cp.observed,
                error: &cp.error,
            },
            pe::ModelCycleAverages {
                label: "LRQSM",
                observed: &cl.observed,
                error: &cl.error,
            },
        ],
        Some(&[0.75, 0.75, 2.0, 2.0, 2.0]),
        opts.level,
    )
    .map_err(analysis("Fig. 4B"))?;
    pa::hdr_contours(&f_5a, &summary).map_err(analysis("Fig. 5Ai"))?;
    pa::pair_scatter(&f_5s, &table, &summary, 0).map_err(analysis("Fig. 5Aii"))?;
    pa::summary_grid(&f_5b, &summary).map_err(analysis("Fig. 5B"))?;
    let have_curves = draw_training(&f_loss, &f_rmse, prssm)?;
    if !have_curves {
        files.retain(|f| !f.starts_with("training_"));
    }
    if test.is_empty() {
        files.retain(|f| f != "fig4a_histograms_test.png");
    }

    let report = EvaluationReport {
        dataset: dataset_label.to_string(),
        n_train,
        n_test: test.len(),
        options: opts.clone(),
        prssm: pm,
        lrqsm: lm,
        rmse_ratio,
        trajectories,
        authority_findings,
        files: {
            let mut f = files.clone();
            f.push("metrics.json".into());
            f.push("report.html".into());
            f
        },
    };
    write_json(&out_dir.join("metrics.json"), &report)?;
    let html = html_report(
        &report,
        context,
        ReportFigures {
            f_2c,
            f_3,
            f_4a_train,
            f_4a_test: (!test.is_empty()).then_some(f_4a_test),
            f_4b,
            f_5a,
            f_5s,
            f_5b,
            training: have_curves.then_some((f_loss, f_rmse)),
        },
        prssm,
        lrqsm,
    );
    let p_html = out_dir.join("report.html");
    html.write(&p_html)
        .map_err(analysis(p_html.display().to_string()))?;
    progress.finish("");
    Ok(report)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use crate::train::{TrainingOptions, train_prssm};
    use flapssm_qs::InterceptMode;
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};

    fn tiny_dataset() -> Dataset {
        let mut cfg = SimulationConfig::default();
        cfg.trajectories.n_trajectories = 6;
        cfg.trajectories.n_train = 4;
        cfg.trajectories.seed = 3;
        simulate_dataset(&cfg, &|| {}).unwrap()
    }

    /// The pipeline's LRQSM errors agree with the qs crate's own RMSE (computed there from raw
    /// loads divided by σ), and its sums are consistent: overall² = mean of per-output RMSE²,
    /// ratio = PR-SSM / LRQSM, the windows are the published ones.
    #[test]
    fn metrics_agree_with_independent_computations() {
        let ds = tiny_dataset();
        let lrqsm =
            flapssm_qs::lrqsm::fit_dataset(&ds, Default::default(), &Default::default(), "tiny")
                .unwrap();
        let q = flapssm_qs::lrqsm::predict_dataset(&lrqsm, &ds, InterceptMode::Fitted).unwrap();
        let opts = TrainingOptions {
            dx: Some(5),
            inducing: Some(6),
            particles: Some(3),
            epochs: Some(1),
            val_fraction: 0.0,
            ..TrainingOptions::default()
        };
        let plan = opts.check().unwrap();
        let fit = train_prssm(ds.train(), &plan, None, None, &NoProgress, None).unwrap();
        let dir = std::env::temp_dir().join(format!("flapssm-pipeline-{}", std::process::id()));
        let eo = EvalOptions {
            start_sample: 0,
            particles: 3,
            authority: AuthorityConfig {
                grid_points: 20,
                ..AuthorityConfig::default()
            },
            ..EvalOptions::default()
        };
        let r = evaluate(
            &ds,
            "tiny",
            &fit.best,
            &lrqsm,
            &eo,
            &ReportContext::default(),
            &dir,
            &NoProgress,
        )
        .unwrap();
        let lt = r.lrqsm.test.as_ref().unwrap();
        let qt = q.rmse_test.as_ref().unwrap();
        for j in 0..5 {
            assert!((lt.rmse_standardized[j] - qt.standardized[j]).abs() < 1e-10);
            assert!(
                (r.lrqsm.train.rmse_standardized[j]
                    - q.rmse_train.as_ref().unwrap().standardized[j])
                    .abs()
                    < 1e-10
            );
        }
        let pt = r.prssm.test.as_ref().unwrap();
        let ms: f64 = pt.rmse_standardized.iter().map(|v| v * v).sum::<f64>() / 5.0;
        assert!((pt.overall_rmse_standardized - ms.sqrt()).abs() < 1e-12);
        for j in 0..5 {
            assert_eq!(
                r.rmse_ratio[j],
                pt.rmse_standardized[j] / lt.rmse_standardized[j]
            );
        }
        for (t, m) in ds.trajectories.iter().zip(&r.trajectories) {
            let stroke: Vec<f64> = t.euler_rad.iter().map(|e| e[0]).collect();
            let w = published_window(&stroke).unwrap();
            assert_eq!((m.window_start, m.period_samples), (w.first, w.duration));
        }
        assert_eq!(r.authority_findings.len(), 10);
        for f in &r.files {
            assert!(dir.join(f).exists(), "{f}");
        }
        std::fs::remove_dir_all(&dir).ok();
    }
}
