//! The one-command demo: simulate the virtual wing, fit the LRQSM, train the PR-SSM, evaluate
//! both, analyse, plot, write the report and `summary.json`.
//!
//! Stages and their outputs in the demo folder:
//!
//! | stage | output | depends on |
//! |---|---|---|
//! | `simulate` | `dataset.npz` | simulation config |
//! | `lrqsm` | `lrqsm.json` | + LRQSM features and options |
//! | `prssm` | `prssm.json`, `prssm.last.json` (checkpoint `prssm.ckpt.json`) | + training options |
//! | `evaluate` | `eval/` (metrics, figures, `report.html`) | + evaluation options |
//! | — | `summary.json` | everything |
//!
//! Resumable: `stages.json` records, per finished stage, a key (its configuration and those of
//! the stages it depends on) and its wall time; a stage whose key matches and whose output
//! exists is skipped. An interrupted training resumes from its checkpoint when the training key
//! matches.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use flapssm_prssm::PrssmModel;
use flapssm_prssm::train::{BestBy, Checkpoint, LrSchedule, TrainConfig};
use flapssm_qs::{EnetOptions, LrqsmModel};
use flapssm_wing::dataset::{OUTPUT_NAMES, ValidDataset};
use flapssm_wing::features::FeatureSet;
use flapssm_wing::virtual_wing::SimulationConfig;
use serde::{Deserialize, Serialize};

use crate::curve::CurveRecorder;
use crate::error::{JobError, Result};
use crate::evaluate::paper::ComparisonRow;
use crate::evaluate::{
    AuthorityFinding, EvalOptions, EvaluationReport, METRICS_VERSION, PairedComparison,
    ReportContext, evaluate, versions,
};
use crate::files::{load_json, save_json};
use crate::models::lrqsm::LrqsmLoadModel;
use crate::models::prssm::PrssmLoadModel;
use crate::models::{BASELINES, Baseline, LoadModel, baseline};
use crate::progress::Progress;
use crate::rig::{
    RIG_FILES, RigCheck, RigSettings, load_reference_model, rig_check, rig_reference,
    write_rig_check,
};
use crate::simulate::{TrajectorySource, check_paper_count, paper_dataset, simulate};
use crate::train::{TrainingOptions, TrainingPlan, train_prssm};
use flapssm_analysis::stats::{Interval, median};

/// The files [`run_demo`] writes in its output folder, besides `eval/`
/// ([`crate::evaluate::EVALUATION_FILES`]); checked before any work by
/// [`crate::files::check_output_dir`].
pub const DEMO_FILES: [&str; 8] = [
    "stages.json",
    "dataset.npz",
    "lrqsm.json",
    "prssm.json",
    "prssm.last.json",
    "prssm.ckpt.json",
    "prssm.curve.csv",
    "summary.json",
];

/// Format tag of `summary.json`.
pub const SUMMARY_FORMAT: &str = "flapssm-demo-summary";

/// Everything that defines a demo run.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemoConfig {
    /// Master seed (simulation, training, prediction draws).
    pub seed: u64,
    /// `"default"` or `"full"`.
    pub name: String,
    /// The virtual wing and its trajectories.
    pub simulation: SimulationConfig,
    /// Where the trajectories come from: the generator of `simulation` or the paper's measured
    /// ones (the first `simulation.trajectories.n_trajectories`).
    #[serde(default)]
    pub source: TrajectorySource,
    /// LRQSM feature set.
    pub lrqsm_features: FeatureSet,
    /// LRQSM elastic-net options.
    pub lrqsm: EnetOptions,
    /// PR-SSM training.
    pub training: TrainingOptions,
    /// Baselines fitted in the evaluation stage beside the PR-SSM and the LRQSM (keys of
    /// [`BASELINES`]; default: all of them).
    pub baselines: Vec<String>,
    /// Evaluation.
    pub evaluation: EvalOptions,
    /// The reference model of the rig check ([`crate::rig`]: the published `.npz` or a model
    /// imported from it), run on the dataset when its trajectories are the paper's; its
    /// section heads the report and `summary.json` holds its agreement.
    #[serde(default)]
    pub rig_reference: Option<PathBuf>,
}

impl DemoConfig {
    /// The default (short) configuration: 192 trajectories (179 train, 13 test, the published
    /// split ratio) of 470 samples; PR-SSM D_x 8, M 32, 10 particles, minibatches of 4 whole
    /// trajectories in 2 parallel tasks of 2 (two cores busy), Adam lr 0.05 decaying
    /// exponentially to 0.005, 1000 epochs (41 000 steps).
    /// See docs/demo.md for its wall time.
    ///
    /// The wing is `flapssm simulate`'s default (L3, the same for every command; chosen on
    /// physics, not on the demo's outcome).
    pub fn default_for(seed: u64) -> Self {
        let mut simulation = SimulationConfig::default();
        simulation.trajectories.n_trajectories = 192;
        simulation.trajectories.n_train = flapssm_wing::trajectories::default_n_train(192);
        simulation.trajectories.seed = seed;
        Self {
            seed,
            name: "default".into(),
            simulation,
            source: TrajectorySource::Generator,
            lrqsm_features: FeatureSet::Published,
            lrqsm: EnetOptions::default(),
            training: TrainingOptions {
                dx: Some(8),
                inducing: Some(32),
                particles: Some(10),
                epochs: Some(1000),
                batch: Some(4),
                windows_per_task: Some(2),
                lr: Some(0.05),
                schedule: Some(LrSchedule::Exponential { final_factor: 0.1 }),
                eval_every: Some(25),
                seed,
                ..TrainingOptions::default()
            },
            baselines: all_baselines(),
            evaluation: EvalOptions {
                seed,
                ..EvalOptions::default()
            },
            rig_reference: None,
        }
    }

    /// The paper's configuration by the published protocol on the paper's 548 measured
    /// trajectories (512 train, 36 test; [`TrajectorySource::Paper`]), D_x 12, M 100, 30 particles, minibatches of 16, lr 0.03, 1000 epochs; all 512
    /// training trajectories fitted (no validation hold-out: the normalization is theirs and an
    /// epoch is 32 minibatches, 32 000 steps in all) and the model of the lowest epoch-mean
    /// training loss kept, as the authors' `best.ckpt`; the default wing (L3).
    pub fn full(seed: u64) -> Self {
        let mut simulation = SimulationConfig::default();
        simulation.trajectories.seed = seed;
        Self {
            seed,
            name: "full".into(),
            simulation,
            source: TrajectorySource::Paper,
            lrqsm_features: FeatureSet::Published,
            lrqsm: EnetOptions::default(),
            training: TrainingOptions {
                seed,
                val_fraction: 0.0,
                best_by: BestBy::TrainingLoss,
                ..TrainingOptions::default()
            },
            baselines: all_baselines(),
            evaluation: EvalOptions {
                seed,
                ..EvalOptions::default()
            },
            rig_reference: None,
        }
    }

    /// Checks every setting before any work: the wing and its trajectories, the LRQSM's
    /// elastic net, the PR-SSM training, the baselines' keys and the evaluation.
    ///
    /// # Errors
    /// The first invalid setting, named ([`JobError::Setting`], or the library's own error
    /// naming the field).
    pub fn check(&self) -> Result<DemoPlan> {
        self.simulation.wing.check()?;
        let t = &self.simulation.trajectories;
        t.check()
            .map_err(flapssm_wing::virtual_wing::SimulateError::from)?;
        crate::resources::check_dataset("trajectories", t.n_trajectories, t.sampling.n_samples)?;
        if self.source == TrajectorySource::Paper {
            check_paper_count("trajectories", t.n_trajectories)?;
        }
        if let Some(path) = &self.rig_reference {
            if self.source != TrajectorySource::Paper {
                return Err(JobError::Setting {
                    name: "reference".into(),
                    value: path.display().to_string(),
                    expected:
                        "the rig check needs the paper's trajectories (--full or --source paper)"
                            .into(),
                });
            }
            if !path.is_file() {
                return Err(JobError::Setting {
                    name: "reference".into(),
                    value: path.display().to_string(),
                    expected: "an existing reference model file".into(),
                });
            }
        }
        if t.n_train == 0 || t.n_train >= t.n_trajectories {
            return Err(JobError::Setting {
                name: "trajectories".into(),
                value: format!("{} ({} for training)", t.n_trajectories, t.n_train),
                expected: "at least one training and one test trajectory: the demo reports \
                           test errors"
                    .into(),
            });
        }
        self.lrqsm.validate()?;
        self.evaluation.check()?;
        Ok(DemoPlan {
            training: self.training.check()?,
            baselines: self
                .baselines
                .iter()
                .map(|k| baseline(k))
                .collect::<Result<_>>()?,
        })
    }
}

/// The checked parts of a [`DemoConfig`] that the stages run ([`DemoConfig::check`]).
#[derive(Debug, Clone, PartialEq)]
pub struct DemoPlan {
    /// PR-SSM training.
    pub training: TrainingPlan,
    /// The baselines.
    pub baselines: Vec<&'static Baseline>,
}

/// The keys of every registered baseline.
fn all_baselines() -> Vec<String> {
    BASELINES.iter().map(|b| b.key.to_string()).collect()
}

/// Wall time of one stage.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct StageTiming {
    /// Stage name.
    pub stage: String,
    /// Wall time when it ran (s).
    pub wall_s: f64,
    /// Whether this run skipped it (output up to date).
    pub skipped: bool,
}

/// Headline numbers of a demo run (`summary.json`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemoSummary {
    /// [`SUMMARY_FORMAT`].
    pub format: String,
    /// The configuration.
    pub config: DemoConfig,
    /// Training / test trajectories.
    pub n_train: usize,
    /// Test trajectories.
    pub n_test: usize,
    /// Output names.
    pub outputs: Vec<String>,
    /// The headline: every endpoint of the paper beside this run's
    /// ([`crate::evaluate::paper`]).
    #[serde(default)]
    pub paper_comparison: Vec<ComparisonRow>,
    /// PR-SSM test RMSE per output (σ units).
    pub prssm_test_rmse: Vec<f64>,
    /// LRQSM test RMSE per output (σ units).
    pub lrqsm_test_rmse: Vec<f64>,
    /// PR-SSM / LRQSM per output.
    pub rmse_ratio: Vec<f64>,
    /// Overall test RMSE (σ units) [PR-SSM, LRQSM].
    pub overall_test_rmse: [f64; 2],
    /// Half-stroke-average error intervals (coefficients, training + test) of the PR-SSM.
    pub prssm_cycle_average_ci: Vec<Interval>,
    /// Same for the LRQSM.
    pub lrqsm_cycle_average_ci: Vec<Interval>,
    /// Further baselines evaluated beside the PR-SSM and the LRQSM ([`DemoConfig::baselines`]).
    pub baselines: Vec<BaselineSummary>,
    /// The PR-SSM against the LRQSM and each baseline: per output the test RMSE difference
    /// with its paired bootstrap interval, "significant" only where it excludes 0
    /// ([`EvaluationReport::comparisons`]).
    #[serde(default)]
    pub comparisons: Vec<PairedComparison>,
    /// The Fig. 5 pairs the paper reports ([`EvaluationReport::authority_findings`]).
    pub authority: Vec<AuthorityFinding>,
    /// Median over the output states of AoA's median lag (cycles).
    pub aoa_median_lag_cycles: f64,
    /// Median over the output states of a_x's median lag (cycles).
    pub a_x_median_lag_cycles: f64,
    /// Median over the output states of the lag of AoA's KDE mode (cycles).
    pub aoa_mode_lag_cycles: f64,
    /// Median over the output states of the lag of a_x's KDE mode (cycles).
    pub a_x_mode_lag_cycles: f64,
    /// Stage timings.
    pub timings: Vec<StageTiming>,
    /// Wall time of this invocation (s).
    pub total_wall_s: f64,
    /// Versions.
    pub versions: Vec<(String, String)>,
    /// The evaluation report, relative to the demo folder.
    pub report: String,
    /// The rig check of the dataset ([`DemoConfig::rig_reference`]; its lag statistics in
    /// `rig/rig-check.json`).
    #[serde(default)]
    pub rig_agreement: Option<RigCheck>,
}

/// Test accuracy of a further baseline.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BaselineSummary {
    /// Display name.
    pub model: String,
    /// Test RMSE per output (σ units; training set without a test set).
    pub test_rmse: Vec<f64>,
    /// Overall test RMSE (σ units).
    pub overall_test_rmse: f64,
}

#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct StageRecord {
    key: serde_json::Value,
    wall_s: f64,
}

/// `stages.json`: finished stages.
#[derive(Debug, Clone, Default, Serialize, Deserialize)]
struct Stages {
    stages: BTreeMap<String, StageRecord>,
}

struct Runner<'a> {
    dir: PathBuf,
    stages: Stages,
    timings: Vec<StageTiming>,
    progress: &'a dyn Progress,
}

impl Runner<'_> {
    fn path(&self) -> PathBuf {
        self.dir.join("stages.json")
    }

    fn up_to_date(&self, stage: &str, key: &serde_json::Value, outputs: &[&Path]) -> bool {
        self.stages.stages.get(stage).is_some_and(|r| &r.key == key)
            && outputs.iter().all(|p| p.exists())
    }

    /// Runs `work` unless the stage is up to date; records its key and time.
    fn stage<T>(
        &mut self,
        stage: &str,
        key: &serde_json::Value,
        outputs: &[&Path],
        load: impl FnOnce() -> Result<T>,
        work: impl FnOnce(&dyn Progress) -> Result<T>,
    ) -> Result<T> {
        if self.up_to_date(stage, key, outputs) {
            let wall_s = self.stages.stages[stage].wall_s;
            self.progress.start(stage, 0);
            let v = load()?;
            self.progress.finish("up to date, skipped");
            self.timings.push(StageTiming {
                stage: stage.into(),
                wall_s,
                skipped: true,
            });
            return Ok(v);
        }
        self.stages.stages.remove(stage);
        let t0 = Instant::now();
        let v = work(self.progress)?;
        let wall_s = t0.elapsed().as_secs_f64();
        self.stages.stages.insert(
            stage.into(),
            StageRecord {
                key: key.clone(),
                wall_s,
            },
        );
        save_json(&self.path(), &self.stages)?;
        self.timings.push(StageTiming {
            stage: stage.into(),
            wall_s,
            skipped: false,
        });
        Ok(v)
    }
}

fn json<T: Serialize>(v: &T) -> serde_json::Value {
    serde_json::to_value(v).unwrap_or(serde_json::Value::Null)
}

/// Runs the demo into `dir` (created if needed), after [`DemoConfig::check`]. `stop` interrupts
/// the training, which can then be resumed by running again with the same configuration.
///
/// # Errors
/// An invalid setting before any work; any stage's error, naming the stage's file;
/// [`JobError::Interrupted`] when stopped.
pub fn run_demo(
    dir: &Path,
    cfg: &DemoConfig,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<DemoSummary> {
    let t_all = Instant::now();
    let DemoPlan {
        training: plan,
        baselines,
    } = cfg.check()?;
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    let stages_path = dir.join("stages.json");
    let stages: Stages = if stages_path.exists() {
        load_json(&stages_path)?
    } else {
        Stages::default()
    };
    let mut run = Runner {
        dir: dir.to_path_buf(),
        stages,
        timings: Vec::new(),
        progress,
    };

    // 1. Simulate.
    let ds_path = dir.join("dataset.npz");
    let k_sim = serde_json::json!({
        "simulation": json(&cfg.simulation),
        "source": cfg.source,
        "version": env!("CARGO_PKG_VERSION"),
    });
    let ds = run.stage(
        "simulate",
        &k_sim,
        &[&ds_path],
        || load_dataset(&ds_path),
        |p| match cfg.source {
            TrajectorySource::Generator => simulate(&cfg.simulation, Some(&ds_path), p),
            TrajectorySource::Paper => paper_dataset(&cfg.simulation, Some(&ds_path), p),
        },
    )?;

    // 1b. The rig check, on the paper's trajectories with a reference.
    let rig_dir = dir.join("rig");
    let rig_json = rig_dir.join(RIG_FILES[0]);
    let k_rig = cfg.rig_reference.as_ref().map(|path| {
        serde_json::json!({
            "upstream": k_sim,
            "reference": path,
            "reference_bytes": std::fs::metadata(path).map(|m| m.len()).ok(),
            "settings": json(&RigSettings::default()),
        })
    });
    let rig = match (&cfg.rig_reference, &k_rig) {
        (Some(path), Some(key)) => Some(run.stage(
            "rig",
            key,
            &[&rig_json],
            || load_json::<RigCheck>(&rig_json),
            |p| {
                let model = load_reference_model(path)?;
                let reference = rig_reference(&model, ds.len(), &RigSettings::default(), p)?;
                let check = rig_check(&ds, &reference, true)?;
                write_rig_check(&rig_dir, &check, &ds, &reference, "demo dataset")?;
                Ok(check)
            },
        )?),
        _ => None,
    };

    // 2. LRQSM.
    let lq_path = dir.join("lrqsm.json");
    let k_lq = serde_json::json!({ "upstream": k_sim, "features": json(&cfg.lrqsm_features), "options": json(&cfg.lrqsm) });
    let lrqsm = run.stage(
        "lrqsm",
        &k_lq,
        &[&lq_path],
        || Ok(LrqsmModel::load(&lq_path)?),
        |p| {
            p.start("fit LRQSM", 0);
            let m = flapssm_qs::lrqsm::fit_dataset(
                &ds,
                cfg.lrqsm_features,
                &cfg.lrqsm,
                &ds_path.display().to_string(),
            )?;
            m.save(&lq_path)?;
            p.finish("");
            Ok(m)
        },
    )?;

    // 3. PR-SSM.
    let pm_path = dir.join("prssm.json");
    let last_path = dir.join("prssm.last.json");
    let ck_path = dir.join("prssm.ckpt.json");
    let curve_path = dir.join("prssm.curve.csv");
    let k_pm = serde_json::json!({ "upstream": k_sim, "training": json(&cfg.training) });
    let started_key = "prssm (started)";
    let prssm = {
        let resume = (!run.up_to_date("prssm", &k_pm, &[&pm_path])
            && run
                .stages
                .stages
                .get(started_key)
                .is_some_and(|r| r.key == k_pm)
            && ck_path.exists())
        .then(|| Checkpoint::load(&ck_path))
        .transpose()
        .map_err(|e| JobError::Io {
            path: ck_path.clone(),
            source: std::io::Error::other(e.to_string()),
        })?
        // The plan's configuration has no run context (model, ELBO options, data fingerprint):
        // `fit` adds it, and the trainer refuses a checkpoint of another context by name.
        .filter(|ck| {
            TrainConfig {
                run_context: serde_json::Value::Null,
                ..ck.config.clone()
            } == plan.spec().train
        });
        if !run.up_to_date("prssm", &k_pm, &[&pm_path]) {
            run.stages.stages.insert(
                started_key.into(),
                StageRecord {
                    key: k_pm.clone(),
                    wall_s: 0.0,
                },
            );
            save_json(&run.path(), &run.stages)?;
        }
        run.stage(
            "prssm",
            &k_pm,
            &[&pm_path],
            || load_model(&pm_path),
            |p| {
                let note = match &resume {
                    Some(ck) => format!("resuming at step {}", ck.state.step),
                    None => String::new(),
                };
                p.start("train PR-SSM", 0);
                if !note.is_empty() {
                    p.println(&note);
                }
                let mut curve =
                    CurveRecorder::new(&curve_path, resume.as_ref().map(|c| c.state.step))?;
                let out = train_prssm(
                    ds.train(),
                    &plan,
                    Some(&ck_path),
                    resume,
                    Some(&mut curve),
                    p,
                    stop,
                )?;
                for (m, path) in [(&out.best, &pm_path), (&out.last, &last_path)] {
                    m.save(path).map_err(|source| JobError::ModelFile {
                        path: path.clone(),
                        source,
                    })?;
                }
                p.finish(&format!("{} steps", out.outcome.state.step));
                Ok(out.best)
            },
        )?
    };

    // 4. Evaluate.
    let eval_dir = dir.join("eval");
    let metrics_path = eval_dir.join("metrics.json");
    let report_path = eval_dir.join("report.html");
    let k_ev = serde_json::json!({
        "lrqsm": k_lq, "prssm": k_pm, "baselines": json(&cfg.baselines),
        "evaluation": json(&cfg.evaluation), "metrics_version": METRICS_VERSION,
        "rig": k_rig,
    });
    let timings_so_far: Vec<(String, String)> = run
        .timings
        .iter()
        .map(|t| {
            (
                format!("wall time: {}", t.stage),
                format!(
                    "{:.1} s{}",
                    t.wall_s,
                    if t.skipped { " (earlier run)" } else { "" }
                ),
            )
        })
        .collect();
    let report: EvaluationReport = run.stage(
        "evaluate",
        &k_ev,
        &[&metrics_path, &report_path],
        || load_json(&metrics_path),
        |p| {
            let ctx = ReportContext {
                title: format!("flapssm demo ({} configuration, seed {})", cfg.name, cfg.seed),
                intro: format!(
                    "Virtual flapping wing simulated with flapssm; PR-SSM, LRQSM (elastic net on quasi-steady features){} fitted on the training trajectories and evaluated open loop on all trajectories.",
                    baselines.iter().map(|b| format!(" and {}", b.about)).collect::<String>()
                ),
                headline: timings_so_far,
                config: json(cfg),
                extra_sections: rig
                    .iter()
                    .map(|c| {
                        let figure = rig_dir.join(RIG_FILES[2]);
                        c.report_section(figure.exists().then_some(figure))
                    })
                    .collect(),
                control_lags: None,
            };
            let e = &cfg.evaluation;
            let prssm = PrssmLoadModel::new(&prssm, &ds, e.particles, e.seed)?;
            let lrqsm = LrqsmLoadModel::new(&lrqsm)?;
            let fitted = baselines
                .iter()
                .map(|b| (b.fit)(&ds, p))
                .collect::<Result<Vec<_>>>()?;
            let mut models: Vec<&dyn LoadModel> = vec![&prssm, &lrqsm];
            models.extend(fitted.iter().map(|m| &**m));
            evaluate(
                &ds,
                &ds_path.display().to_string(),
                &models,
                e,
                &ctx,
                &eval_dir,
                p,
            )
        },
    )?;

    let mut summary = summarize(cfg, &report, run.timings, t_all.elapsed().as_secs_f64());
    summary.rig_agreement = rig.map(RigCheck::without_lags);
    save_json(&dir.join("summary.json"), &summary)?;
    Ok(summary)
}

fn load_dataset(path: &Path) -> Result<ValidDataset> {
    flapssm_wing::dataset::Dataset::load(path).map_err(|source| JobError::DatasetFile {
        path: path.to_path_buf(),
        source,
    })
}

fn load_model(path: &Path) -> Result<PrssmModel> {
    PrssmModel::load(path).map_err(|source| JobError::ModelFile {
        path: path.to_path_buf(),
        source,
    })
}

fn summarize(
    cfg: &DemoConfig,
    r: &EvaluationReport,
    timings: Vec<StageTiming>,
    total_wall_s: f64,
) -> DemoSummary {
    let (pm, lm) = (&r.models[0], &r.models[1]);
    let (p, l) = (pm.test_or_train(), lm.test_or_train());
    let lag_of = |input: &str, f: fn(&AuthorityFinding) -> f64| {
        let v: Vec<f64> = r
            .authority_findings
            .iter()
            .filter(|a| a.input == input)
            .map(f)
            .collect();
        median(&v).unwrap_or(f64::NAN)
    };
    DemoSummary {
        format: SUMMARY_FORMAT.into(),
        config: cfg.clone(),
        n_train: r.n_train,
        n_test: r.n_test,
        outputs: OUTPUT_NAMES.iter().map(|s| s.to_string()).collect(),
        paper_comparison: r.paper_comparison.clone(),
        prssm_test_rmse: p.rmse_standardized.clone(),
        lrqsm_test_rmse: l.rmse_standardized.clone(),
        rmse_ratio: r.rmse_ratio.clone(),
        overall_test_rmse: [p.overall_rmse_standardized, l.overall_rmse_standardized],
        prssm_cycle_average_ci: pm.cycle_average_error_interval_all.clone(),
        lrqsm_cycle_average_ci: lm.cycle_average_error_interval_all.clone(),
        baselines: r.models[2..]
            .iter()
            .map(|m| BaselineSummary {
                model: m.model.clone(),
                test_rmse: m.test_or_train().rmse_standardized.clone(),
                overall_test_rmse: m.test_or_train().overall_rmse_standardized,
            })
            .collect(),
        comparisons: r.comparisons.clone(),
        authority: r.authority_findings.clone(),
        aoa_median_lag_cycles: lag_of("AoA", |a| a.median_lag_cycles),
        a_x_median_lag_cycles: lag_of("a_x", |a| a.median_lag_cycles),
        aoa_mode_lag_cycles: lag_of("AoA", |a| a.mode_lag_cycles),
        a_x_mode_lag_cycles: lag_of("a_x", |a| a.mode_lag_cycles),
        timings,
        total_wall_s,
        versions: versions(),
        report: "eval/report.html".into(),
        rig_agreement: None,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::{NoProgress, StopAfter};
    use flapssm_prssm::Precision;

    /// A bad setting of any part fails before the demo creates its directory, naming the setting.
    #[test]
    fn every_setting_is_checked_before_any_work() {
        let dir = tempfile::tempdir().unwrap();
        let out = dir.path().join("demo");
        type Edit = fn(&mut DemoConfig);
        let cases: [(&str, Edit); 7] = [
            ("n_train", |c| c.simulation.trajectories.n_train = 500),
            // Regression: `demo --trajectories 1` reported the training RMSE as "test RMSE".
            (
                "trajectories = 1 (1 for training): at least one training and one test",
                |c| {
                    c.simulation.trajectories.n_trajectories = 1;
                    c.simulation.trajectories.n_train = 1;
                },
            ),
            ("fluid.kinematic_viscosity_m2_s", |c| {
                c.simulation.wing.fluid.kinematic_viscosity_m2_s = 0.0
            }),
            ("n_folds", |c| c.lrqsm.n_folds = 1),
            ("epochs", |c| c.training.epochs = Some(0)),
            ("particles", |c| c.evaluation.particles = 0),
            ("baseline = nope: one of arx", |c| {
                c.baselines = vec!["nope".into()]
            }),
        ];
        for (name, edit) in cases {
            let mut cfg = DemoConfig::default_for(1);
            edit(&mut cfg);
            let e = run_demo(&out, &cfg, &NoProgress, None).unwrap_err();
            assert!(e.to_string().contains(name), "{name}: {e}");
            assert!(!out.exists(), "{name}: work started");
        }
        assert!(DemoConfig::default_for(1).check().is_ok());
        assert!(DemoConfig::full(1).check().is_ok());
    }

    /// `--full` is the published protocol: all 512 training trajectories fitted (none held out),
    /// 32 minibatches of 16 per epoch for 1000 epochs (32 000 steps), the lowest training loss
    /// kept; the default configuration keeps validation-based selection.
    #[test]
    fn full_is_the_published_protocol() {
        let full = DemoConfig::full(3);
        assert_eq!(full.source, TrajectorySource::Paper);
        let mut too_many = full.clone();
        too_many.simulation.trajectories.n_trajectories = 600;
        let e = too_many.check().unwrap_err().to_string();
        assert!(e.contains("setting trajectories = 600"), "{e}");
        let plan = full.training.check().unwrap();
        let t = &full.simulation.trajectories;
        assert_eq!((t.n_trajectories, t.n_train), (548, 512));
        let spec = plan.spec();
        assert_eq!(spec.train.best_by, BestBy::TrainingLoss);
        assert_eq!(
            spec.train.budget,
            flapssm_prssm::train::Budget::Epochs(1000)
        );
        assert_eq!(spec.train.batch_size, 16);
        assert_eq!(plan.val_fraction(), 0.0);
        let trajectories = vec![crate::test_data::tiny_dataset().trajectories[0].clone(); 512];
        let (fit, val) = plan.split(&trajectories).unwrap();
        assert_eq!((fit.len(), val.len()), (512, 0));
        assert_eq!(fit.len().div_ceil(spec.train.batch_size) * 1000, 32_000);
        let default = DemoConfig::default_for(3).training.check().unwrap();
        assert_eq!(default.spec().train.best_by, BestBy::Rmse);
        assert!(default.val_fraction() > 0.0);
    }

    /// The default demo's minibatches of 4 are 2 parallel tasks: both cores of a 2-core
    /// machine train.
    #[test]
    fn the_default_demo_keeps_two_cores_busy() {
        let plan = DemoConfig::default_for(0).training.check().unwrap();
        let spec = plan.spec();
        assert_eq!(spec.train.batch_size, 4);
        assert_eq!(spec.windows_per_task, 2);
        let tasks = spec.train.batch_size.div_ceil(spec.windows_per_task);
        assert_eq!(tasks, 2);
    }

    /// A demo stopped in its training resumes from its checkpoint when run again, and ends
    /// with the model files of an uninterrupted run, in either precision. Regression: the
    /// rerun started the training over, because the checkpoint's configuration carries the run
    /// context that the plan's lacks.
    #[test]
    fn a_stopped_demo_resumes_to_the_uninterrupted_result() {
        let mut cfg = DemoConfig::default_for(5);
        cfg.simulation.trajectories.n_trajectories = 8;
        cfg.simulation.trajectories.n_train = 7;
        cfg.simulation.wing.fidelity = flapssm_wing::virtual_wing::Fidelity::L0;
        cfg.training.epochs = Some(4);
        cfg.training.inducing = Some(8);
        cfg.training.particles = Some(4);
        cfg.evaluation.particles = 4;
        let tmp = tempfile::tempdir().unwrap();
        for precision in [Precision::F64, Precision::Mixed] {
            cfg.training.precision = Some(precision);
            let name = format!("{precision:?}");
            let whole = tmp.path().join(format!("{name}-whole"));
            let stopped = tmp.path().join(format!("{name}-stopped"));
            run_demo(&whole, &cfg, &NoProgress, None).unwrap();

            let stop = AtomicBool::new(false);
            let progress = StopAfter::new(3, &stop);
            let e = run_demo(&stopped, &cfg, &progress, Some(&stop)).unwrap_err();
            assert!(matches!(e, JobError::Interrupted { step: 3, .. }), "{e}");
            assert!(stopped.join("prssm.ckpt.json").exists());
            assert!(!stopped.join("prssm.json").exists());
            run_demo(&stopped, &cfg, &progress, None).unwrap();
            let lines = progress.lines.lock().unwrap();
            assert!(
                lines.iter().any(|l| l == "resuming at step 3"),
                "{name}: {lines:?}"
            );
            let read = |dir: &Path, file: &str| std::fs::read(dir.join(file)).unwrap();
            for file in ["prssm.json", "prssm.last.json"] {
                assert!(
                    read(&stopped, file) == read(&whole, file),
                    "{name}: {file} differs"
                );
            }
            // The learning curve: the same steps and values; the wall times differ.
            let rows = |dir: &Path| -> Vec<String> {
                String::from_utf8(read(dir, "prssm.curve.csv"))
                    .unwrap()
                    .lines()
                    .map(|l| {
                        let c: Vec<&str> = l.split(',').collect();
                        [&c[..2.min(c.len())], &c[3.min(c.len())..]]
                            .concat()
                            .join(",")
                    })
                    .collect()
            };
            assert_eq!(rows(&stopped), rows(&whole), "{name}: learning curve");
        }
    }

    /// `--full --preset paper-fast` changes the training schedule only: the paper's model,
    /// 300 epochs of minibatches of 4 (38 400 steps), still all 512 fitted and the lowest
    /// training loss kept.
    #[test]
    fn full_with_the_fast_preset_keeps_the_published_protocol() {
        let mut fast = DemoConfig::full(3);
        fast.training.preset = crate::presets::Preset::PaperFast;
        let published = DemoConfig::full(3).training.check().unwrap();
        let published = published.spec();
        let plan = fast.training.check().unwrap();
        let spec = plan.spec();
        assert_eq!(spec.model, published.model);
        assert_eq!(spec.train.best_by, BestBy::TrainingLoss);
        assert_eq!(plan.val_fraction(), 0.0);
        assert_eq!(spec.train.budget, flapssm_prssm::train::Budget::Epochs(300));
        assert_eq!(spec.train.batch_size, 4);
        let trajectories = vec![crate::test_data::tiny_dataset().trajectories[0].clone(); 512];
        let (fit, val) = plan.split(&trajectories).unwrap();
        assert_eq!((fit.len(), val.len()), (512, 0));
        assert_eq!(fit.len().div_ceil(spec.train.batch_size) * 300, 38_400);
    }
}
