//! Sweeps of the PR-SSM configuration: one configuration per call ([`sweep_run`], one process
//! per configuration so any job scheduler can spread them) and the merge of their result files
//! into one table and figure ([`SweepTable`]).
//!
//! Kinds: latent dimension (the paper's `D_x ∈ {8, 12, 16}`); training-set size (the first
//! `V` training trajectories; the paper does not give its sizes, only that 512 made training
//! and test accuracy similar). Accuracy is the open-loop RMSE of
//! standardized outputs (the dataset's full training statistics, so all configurations share
//! one scale) from `start_sample` on, on the trajectories trained on and on the test set.

use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Instant;

use flapssm_analysis::stats::mean_t_interval;
use flapssm_prssm::train::EpochRecord;
use flapssm_prssm::train::fit::FitSpec;
use flapssm_wing::dataset::{OUTPUT_NAMES, Standardization, ValidDataset};
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result};
use crate::evaluate::paper::{ComparisonRow, SelectionDifference, SelectionPoint, selection_rows};
use crate::evaluate::prepared::pooled_errors;
use crate::files::save_json;
use crate::predict::predict_prssm;
use crate::progress::Progress;
use crate::train::{TrainingOptions, TrainingPlan, load_checkpoint, train_prssm};

/// Format tag of a sweep result file.
pub const RESULT_FORMAT: &str = "flapssm-sweep-result";
/// Version of the sweep result file.
pub const RESULT_VERSION: u32 = 1;

/// What a sweep varies.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum SweepKind {
    /// Latent dimension D_x.
    Dx,
    /// Number of training trajectories (the first V of the training set).
    DataSize,
}

impl SweepKind {
    /// The command-line name (`dx`, `data-size`).
    pub fn name(self) -> &'static str {
        match self {
            SweepKind::Dx => "dx",
            SweepKind::DataSize => "data-size",
        }
    }
}

impl std::str::FromStr for SweepKind {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "dx" => Ok(SweepKind::Dx),
            "data-size" => Ok(SweepKind::DataSize),
            _ => Err(format!(
                "unknown sweep kind {s:?} (expected dx or data-size)"
            )),
        }
    }
}

/// Standardized RMSE of one set.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SetRmse {
    /// Trajectories.
    pub n_trajectories: usize,
    /// RMSE per output [F_x, F_y, M_x, M_y, M_z] (σ units).
    pub rmse_standardized: Vec<f64>,
    /// `√mean(e²)` over all outputs (σ units).
    pub overall: f64,
}

/// The result of one sweep configuration (one JSON file).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepResult {
    /// [`RESULT_FORMAT`].
    pub format: String,
    /// [`RESULT_VERSION`].
    pub version: u32,
    /// What was varied.
    pub kind: SweepKind,
    /// Its value.
    pub value: usize,
    /// ValidDataset description.
    pub dataset: String,
    /// Trajectories fitted (after the validation hold-out).
    pub n_fit: usize,
    /// Validation trajectories (best-model selection).
    pub n_val: usize,
    /// The training options as given.
    pub options: TrainingOptions,
    /// The resulting fit specification.
    pub spec: FitSpec,
    /// Accuracy on the trajectories used for training (fit + validation).
    pub train: SetRmse,
    /// Accuracy on the test set (absent without test trajectories).
    pub test: Option<SetRmse>,
    /// Best epoch (by validation RMSE).
    pub best_epoch: Option<u64>,
    /// Optimizer steps.
    pub steps: u64,
    /// Training wall time of the process that finished the run (s): the part after the resumed
    /// step when it was resumed.
    pub train_wall_s: f64,
    /// Optimizer step the run was resumed at (absent when it ran in one process).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resumed_at_step: Option<u64>,
    /// Per-epoch history.
    pub history: Vec<EpochRecord>,
}

/// Settings of one sweep run: `kind = value` on top of the training options; predictions with
/// `particles` particles and `seed`; errors counted from `start_sample` on.
#[derive(Debug, Clone, PartialEq)]
pub struct SweepSettings {
    /// What is swept.
    pub kind: SweepKind,
    /// Its value in this run.
    pub value: usize,
    /// The training options the value is set on.
    pub training: TrainingOptions,
    /// Particles of the predictions.
    pub particles: usize,
    /// Seed of the predictions.
    pub seed: u64,
    /// First sample of the errors (0-based; published 93).
    pub start_sample: usize,
}

/// [`SweepSettings`] checked against a dataset ([`SweepSettings::check`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SweepPlan {
    settings: SweepSettings,
    options: TrainingOptions,
    training: TrainingPlan,
    used: usize,
    /// The dataset's training statistics: the one scale of every configuration's errors.
    stats: Standardization,
}

impl SweepSettings {
    /// Checks every setting against `ds` before any work.
    ///
    /// # Errors
    /// [`JobError::Setting`] for a data-size value outside `2 ..= n_train`, no prediction
    /// particle, a `start_sample` at or past the trajectories' length; the training options'
    /// errors.
    pub fn check(&self, ds: &ValidDataset) -> Result<SweepPlan> {
        let setting = |name: &str, value: String, expected: String| JobError::Setting {
            name: name.into(),
            value,
            expected,
        };
        let n_train = ds.n_train;
        let mut options = self.training.clone();
        let used = match self.kind {
            SweepKind::Dx => {
                options.dx = Some(self.value);
                n_train
            }
            SweepKind::DataSize => {
                if self.value < 2 || self.value > n_train {
                    return Err(setting(
                        "value",
                        self.value.to_string(),
                        format!("a data size in 2 ..= {n_train} (the training trajectories)"),
                    ));
                }
                self.value
            }
        };
        if self.particles == 0 {
            return Err(setting(
                "eval_particles",
                "0".into(),
                "must be at least 1".into(),
            ));
        }
        if self.start_sample >= ds.n_samples() {
            return Err(setting(
                "start_sample",
                self.start_sample.to_string(),
                format!(
                    "must be below the {} samples of each trajectory",
                    ds.n_samples()
                ),
            ));
        }
        Ok(SweepPlan {
            settings: self.clone(),
            training: options.check()?,
            options,
            used,
            stats: ds.standardization()?,
        })
    }
}

/// Trains and evaluates one configuration ([`SweepSettings`], checked against `ds`),
/// checkpointing to `checkpoint` (every `checkpoint_every` epochs of the training options, and
/// when stopped). With `resume`, a checkpoint already there is continued from (it must belong
/// to this configuration and dataset; the run then trains as the uninterrupted one would);
/// without one the run starts from the beginning.
///
/// # Errors
/// Training and prediction errors; [`JobError::Interrupted`] when stopped (the checkpoint is
/// written first); an unreadable checkpoint, or one of another configuration or dataset.
pub fn sweep_run(
    ds: &ValidDataset,
    dataset_label: &str,
    plan: &SweepPlan,
    checkpoint: Option<&Path>,
    resume: bool,
    progress: &dyn Progress,
    stop: Option<&AtomicBool>,
) -> Result<SweepResult> {
    let SweepSettings {
        kind,
        value,
        particles,
        seed,
        start_sample,
        ..
    } = plan.settings;
    let (used, opts, stats) = (plan.used, plan.options.clone(), &plan.stats);
    let plan = &plan.training;
    let train = &ds.trajectories[..used];
    let (fit_set, val_set) = plan.split(train)?;
    let (n_fit, n_val) = (fit_set.len(), val_set.len());
    let resume = match checkpoint {
        Some(path) if resume && path.exists() => {
            let c = load_checkpoint(path)?;
            progress.println(&format!(
                "resuming {} = {value} at step {} from {}",
                kind.name(),
                c.state.step,
                path.display()
            ));
            Some(c)
        }
        _ => None,
    };
    progress.start(&format!("train {} = {value}", kind.name()), 0);
    let resumed_at_step = resume.as_ref().map(|c| c.state.step);
    let t0 = Instant::now();
    let out = train_prssm(train, plan, checkpoint, resume, None, progress, stop)?;
    let train_wall_s = t0.elapsed().as_secs_f64();
    progress.finish("");

    progress.start("predict", ds.len() as u64);
    let sub = ds.with_training_prefix(used)?;
    let pred = predict_prssm(&out.best, &sub, particles, seed, progress)?;
    progress.finish("");
    let meas: Vec<Vec<f64>> = sub
        .trajectories
        .iter()
        .map(|t| stats.normalize_y_table(t.outputs.as_deref().unwrap_or_default().as_flattened()))
        .collect();
    let predz: Vec<Vec<f64>> = pred
        .iter()
        .map(|p| stats.normalize_y_table(&p.output_mean))
        .collect();
    let set = |r: std::ops::Range<usize>| -> Result<Option<SetRmse>> {
        if r.is_empty() {
            return Ok(None);
        }
        let tables = meas[r.clone()]
            .iter()
            .zip(&predz[r.clone()])
            .map(|(m, q)| (&m[..], &q[..]));
        let e = pooled_errors(tables, start_sample)?;
        Ok(Some(SetRmse {
            n_trajectories: r.len(),
            rmse_standardized: e.rmse(),
            overall: e.overall_rmse(),
        }))
    };
    let train_rmse = set(0..used)?.ok_or_else(|| JobError::Mismatch {
        what: "training trajectories".into(),
        expected: "at least one".into(),
        found: "none".into(),
    })?;
    Ok(SweepResult {
        format: RESULT_FORMAT.into(),
        version: RESULT_VERSION,
        kind,
        value,
        dataset: dataset_label.into(),
        n_fit,
        n_val,
        spec: plan.spec().clone(),
        options: opts,
        train: train_rmse,
        test: set(used..sub.len())?,
        best_epoch: out.outcome.state.best.as_ref().map(|b| b.epoch),
        steps: out.outcome.state.step,
        train_wall_s,
        resumed_at_step,
        history: out.outcome.state.history.clone(),
    })
}

/// The checkpoint of the run whose result file is `result`: `<stem>.ckpt.json` beside it.
pub fn checkpoint_beside(result: &Path) -> PathBuf {
    crate::train::sibling(result, ".ckpt.json")
}

/// Reads a sweep result file, checking its format tag and version.
///
/// # Errors
/// [`JobError::Io`] / [`JobError::Json`] naming the file, [`JobError::Mismatch`]
/// for another format or version.
pub fn load_result(path: &Path) -> Result<SweepResult> {
    let v: serde_json::Value = crate::files::load_json(path)?;
    let format = v.get("format").and_then(|f| f.as_str()).unwrap_or("");
    let version = v.get("version").and_then(|f| f.as_u64()).unwrap_or(0);
    if format != RESULT_FORMAT || version != u64::from(RESULT_VERSION) {
        return Err(JobError::Mismatch {
            what: format!("{}: format/version", path.display()),
            expected: format!("{RESULT_FORMAT} version {RESULT_VERSION}"),
            found: format!("{format:?} version {version}"),
        });
    }
    serde_json::from_value(v).map_err(|source| JobError::Json {
        path: path.to_path_buf(),
        source,
    })
}

/// The training-size curve's points on all training trajectories that a D_x run already is: a
/// `dx` result (trained on all of them) with the fit specification (seed included) of a
/// `data-size` result is the same configuration as the `data-size` run on all of them, which
/// then need not run (where one of that specification did, its own result is kept).
fn full_set_points(results: &[(String, SweepResult)]) -> Vec<SweepRow> {
    let sizes: Vec<&SweepResult> = results
        .iter()
        .map(|(_, r)| r)
        .filter(|r| r.kind == SweepKind::DataSize)
        .collect();
    results
        .iter()
        .filter(|(_, r)| r.kind == SweepKind::Dx)
        .filter_map(|(src, r)| {
            let all = r.n_fit + r.n_val;
            let same: Vec<_> = sizes.iter().filter(|d| d.spec == r.spec).collect();
            (!same.is_empty() && same.iter().all(|d| d.value != all)).then(|| {
                let source = format!("{src} (dx = {}: the same configuration)", r.value);
                SweepRow::of(r, SweepKind::DataSize, all, source)
            })
        })
        .collect()
}

/// The paper's latent dimension (Methods, line 95): the reference of the D_x differences.
const PAPER_DX: usize = 12;

/// One row of the merged table.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepRow {
    /// What was varied.
    pub kind: SweepKind,
    /// Its value.
    pub value: usize,
    /// Seed of the run.
    pub seed: u64,
    /// Trajectories fitted + validation.
    pub n_train: usize,
    /// Overall training RMSE (σ units).
    pub train_overall: f64,
    /// Overall test RMSE (σ units), if any.
    pub test_overall: Option<f64>,
    /// Test RMSE per output, if any.
    pub test_rmse: Option<Vec<f64>>,
    /// Training wall time of the process that finished the run (s): the part after the resumed
    /// step when it was resumed.
    pub train_wall_s: f64,
    /// Optimizer step the run was resumed at (absent when it ran in one process).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub resumed_at_step: Option<u64>,
    /// The source file.
    pub source: String,
}

impl SweepRow {
    /// The row of `r` as the point `kind = value`.
    fn of(r: &SweepResult, kind: SweepKind, value: usize, source: String) -> Self {
        Self {
            kind,
            value,
            seed: r.options.seed,
            n_train: r.n_fit + r.n_val,
            train_overall: r.train.overall,
            test_overall: r.test.as_ref().map(|t| t.overall),
            test_rmse: r.test.as_ref().map(|t| t.rmse_standardized.clone()),
            train_wall_s: r.train_wall_s,
            resumed_at_step: r.resumed_at_step,
            source,
        }
    }
}

/// Merged sweep results, sorted by kind, value and seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SweepTable {
    /// Rows.
    pub rows: Vec<SweepRow>,
    /// Per kind and value: mean and spread over seeds ([`SweepTable::selection`]).
    #[serde(default)]
    pub selection: Vec<(SweepKind, SelectionPoint)>,
    /// Each value against its kind's reference (D_x 12; the largest training set), paired by
    /// seed ([`SweepTable::differences`]).
    #[serde(default)]
    pub differences: Vec<(SweepKind, SelectionDifference)>,
    /// The paper's two selections beside these results
    /// ([`crate::evaluate::paper::selection_rows`]).
    #[serde(default)]
    pub paper_comparison: Vec<ComparisonRow>,
}

impl SweepTable {
    /// Builds the table from `(source name, result)` pairs. A D_x run with a training-size
    /// run's fit specification, trained on all the training trajectories, is also the size
    /// curve's point on all of them (the same configuration), unless that point was run.
    ///
    /// # Errors
    /// [`JobError::Mismatch`] for no results.
    pub fn new(results: &[(String, SweepResult)]) -> Result<Self> {
        if results.is_empty() {
            return Err(JobError::Mismatch {
                what: "sweep results".into(),
                expected: "at least one result file".into(),
                found: "none".into(),
            });
        }
        let mut rows: Vec<SweepRow> = results
            .iter()
            .map(|(src, r)| SweepRow::of(r, r.kind, r.value, src.clone()))
            .chain(full_set_points(results))
            .collect();
        rows.sort_by_key(|a| (a.kind, a.value, a.seed));
        let mut table = Self {
            rows,
            selection: Vec::new(),
            differences: Vec::new(),
            paper_comparison: Vec::new(),
        };
        let (dx, sizes) = (
            table.selection(SweepKind::Dx),
            table.selection(SweepKind::DataSize),
        );
        table.differences = [SweepKind::Dx, SweepKind::DataSize]
            .into_iter()
            .flat_map(|k| table.differences(k).into_iter().map(move |d| (k, d)))
            .collect();
        table.paper_comparison = selection_rows(&dx, &sizes, &table.differences);
        table.selection = dx
            .into_iter()
            .map(|p| (SweepKind::Dx, p))
            .chain(sizes.into_iter().map(|p| (SweepKind::DataSize, p)))
            .collect();
        Ok(table)
    }

    /// Mean and spread (max − min) over seeds of the overall training and test RMSE, per value
    /// of `kind`, ascending; values without a test set are left out.
    pub fn selection(&self, kind: SweepKind) -> Vec<SelectionPoint> {
        let mut values: Vec<usize> = self
            .rows
            .iter()
            .filter(|r| r.kind == kind)
            .map(|r| r.value)
            .collect();
        values.dedup();
        values
            .into_iter()
            .filter_map(|value| {
                let rows: Vec<&SweepRow> = self
                    .rows
                    .iter()
                    .filter(|r| r.kind == kind && r.value == value)
                    .collect();
                let test: Vec<f64> = rows.iter().filter_map(|r| r.test_overall).collect();
                if test.len() != rows.len() {
                    return None;
                }
                let train: Vec<f64> = rows.iter().map(|r| r.train_overall).collect();
                let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len() as f64;
                let spread = |v: &[f64]| {
                    v.iter().copied().fold(f64::NEG_INFINITY, f64::max)
                        - v.iter().copied().fold(f64::INFINITY, f64::min)
                };
                Some(SelectionPoint {
                    value,
                    train_rmse: mean(&train),
                    test_rmse: mean(&test),
                    test_spread: spread(&test),
                    train_spread: spread(&train),
                    seeds: rows.len(),
                })
            })
            .collect()
    }

    /// Every other value of `kind` against its reference (D_x 12, the paper's choice; the
    /// largest training set), paired by seed: per seed both ran, the difference of overall test
    /// RMSE; its mean with a 95 % Student-t interval over those seeds
    /// ([`flapssm_analysis::stats::mean_t_interval`]). Empty without the reference value or a
    /// test set.
    pub fn differences(&self, kind: SweepKind) -> Vec<SelectionDifference> {
        let rows: Vec<&SweepRow> = self.rows.iter().filter(|r| r.kind == kind).collect();
        let reference = match kind {
            SweepKind::Dx => rows.iter().find(|r| r.value == PAPER_DX).map(|r| r.value),
            SweepKind::DataSize => rows.iter().map(|r| r.value).max(),
        };
        let Some(reference) = reference else {
            return Vec::new();
        };
        let test_of = |value: usize, seed: u64| {
            rows.iter()
                .find(|r| r.value == value && r.seed == seed)
                .and_then(|r| r.test_overall)
        };
        let mut values: Vec<usize> = rows.iter().map(|r| r.value).collect();
        values.dedup();
        values
            .into_iter()
            .filter(|&v| v != reference)
            .filter_map(|value| {
                let diffs: Vec<f64> = rows
                    .iter()
                    .filter(|r| r.value == value)
                    .filter_map(|r| Some(r.test_overall? - test_of(reference, r.seed)?))
                    .collect();
                if diffs.is_empty() {
                    return None;
                }
                let interval = mean_t_interval(&diffs);
                Some(SelectionDifference {
                    value,
                    reference,
                    seeds: diffs.len(),
                    mean: diffs.iter().sum::<f64>() / diffs.len() as f64,
                    interval: interval.map(|(_, i)| i),
                    significant: interval.is_some_and(|(_, i)| i.lo > 0.0 || i.hi < 0.0),
                })
            })
            .collect()
    }

    /// CSV text: one row per configuration.
    pub fn to_csv(&self) -> String {
        let mut s = String::from("kind,value,seed,n_train,train_overall_rmse,test_overall_rmse");
        for n in OUTPUT_NAMES {
            s.push_str(&format!(",test_rmse_{n}"));
        }
        s.push_str(",train_wall_s,resumed_at_step,source\n");
        let opt = |v: Option<f64>| v.map_or(String::new(), |v| v.to_string());
        for r in &self.rows {
            s.push_str(&format!(
                "{},{},{},{},{},{}",
                r.kind.name(),
                r.value,
                r.seed,
                r.n_train,
                r.train_overall,
                opt(r.test_overall)
            ));
            for j in 0..5 {
                s.push_str(&format!(
                    ",{}",
                    opt(r.test_rmse.as_ref().and_then(|v| v.get(j).copied()))
                ));
            }
            s.push_str(&format!(
                ",{},{},{}\n",
                r.train_wall_s,
                r.resumed_at_step.map_or(String::new(), |s| s.to_string()),
                r.source.replace(',', ";")
            ));
        }
        s
    }

    /// Writes `table` (CSV), `table` with extension `.json`, and the figure (`.png`), atomically.
    ///
    /// # Errors
    /// I/O and figure errors naming the file.
    pub fn write(&self, table: &Path) -> Result<()> {
        flapssm_data::atomic::write_bytes_atomic(table, self.to_csv().as_bytes()).map_err(
            |source| JobError::Io {
                path: table.to_path_buf(),
                source,
            },
        )?;
        save_json(&table.with_extension("json"), self)?;
        let fig = table.with_extension("png");
        self.figure(&fig).map_err(|source| JobError::Analysis {
            what: "sweep figure".into(),
            source,
        })
    }

    /// Overall training and test RMSE vs the swept value, one panel per kind
    /// ([`flapssm_analysis::plots::sweep::accuracy_vs_setting`]).
    ///
    /// # Errors
    /// Plot and I/O errors.
    pub fn figure(&self, path: &Path) -> flapssm_analysis::Result<()> {
        use flapssm_analysis::plots::sweep::{SweepPanel, SweepPoint, accuracy_vs_setting};
        let mut kinds: Vec<SweepKind> = self.rows.iter().map(|r| r.kind).collect();
        kinds.dedup();
        let points: Vec<Vec<SweepPoint>> = kinds
            .iter()
            .map(|k| {
                self.rows
                    .iter()
                    .filter(|r| r.kind == *k)
                    .map(|r| SweepPoint {
                        value: r.value,
                        train: r.train_overall,
                        test: r.test_overall,
                    })
                    .collect()
            })
            .collect();
        let panels: Vec<SweepPanel<'_>> = kinds
            .iter()
            .zip(&points)
            .map(|(kind, points)| SweepPanel {
                title: match kind {
                    SweepKind::Dx => "accuracy vs latent dimension D_x",
                    SweepKind::DataSize => "accuracy vs training trajectories",
                },
                x_label: match kind {
                    SweepKind::Dx => "D_x",
                    SweepKind::DataSize => "training trajectories",
                },
                points,
            })
            .collect();
        accuracy_vs_setting(path, &panels)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::Preset;
    use crate::progress::NoProgress;
    use crate::progress::StopAfter;
    use crate::test_data::tiny_dataset;

    fn tiny_settings(dx: usize) -> SweepSettings {
        SweepSettings {
            kind: SweepKind::Dx,
            value: dx,
            training: TrainingOptions {
                preset: Preset::PaperFast,
                inducing: Some(8),
                particles: Some(2),
                epochs: Some(3),
                batch: Some(2),
                val_fraction: 0.25,
                checkpoint_every: 1,
                ..TrainingOptions::default()
            },
            particles: 3,
            seed: 2,
            start_sample: 93,
        }
    }

    /// A run stopped mid-way and resumed from its checkpoint (here under a cosine-annealed
    /// rate, which depends on the step) ends with the uninterrupted run's models and errors;
    /// a checkpoint of another configuration is refused.
    #[test]
    fn a_stopped_run_resumes_to_the_uninterrupted_result() {
        let ds = tiny_dataset();
        let dir = tempfile::tempdir().unwrap();
        let plan = tiny_settings(6).check(&ds).unwrap();
        let whole = sweep_run(&ds, "tiny", &plan, None, false, &NoProgress, None).unwrap();

        let ckpt = dir.path().join("dx6.ckpt.json");
        let stop = AtomicBool::new(false);
        let stopper = StopAfter::new(3, &stop);
        let err = sweep_run(&ds, "tiny", &plan, Some(&ckpt), true, &stopper, Some(&stop));
        assert!(
            matches!(err, Err(JobError::Interrupted { step: 3, .. })),
            "{err:?}"
        );
        let resumed = sweep_run(&ds, "tiny", &plan, Some(&ckpt), true, &NoProgress, None).unwrap();
        assert_eq!(resumed.resumed_at_step, Some(3));
        assert!(whole.steps > 3 && resumed.steps == whole.steps);
        assert_eq!(resumed.history, whole.history);
        assert_eq!((&resumed.train, &resumed.test), (&whole.train, &whole.test));

        let other = tiny_settings(7).check(&ds).unwrap();
        let err = sweep_run(&ds, "tiny", &other, Some(&ckpt), true, &NoProgress, None);
        assert!(
            err.as_ref()
                .is_err_and(|e| e.to_string().contains("differs")),
            "{err:?}"
        );
    }

    fn row(kind: SweepKind, value: usize, seed: u64, train: f64, test: f64) -> SweepRow {
        SweepRow {
            kind,
            value,
            seed,
            n_train: 10,
            train_overall: train,
            test_overall: Some(test),
            test_rmse: None,
            train_wall_s: 1.0,
            resumed_at_step: None,
            source: format!("{value}-{seed}"),
        }
    }

    /// A D_x run of the training-size runs' specification is also the size curve's point on
    /// all training trajectories; a run of another D_x is not, and a point that was run keeps
    /// its own result.
    #[test]
    fn a_dx_run_of_the_size_curves_configuration_is_its_full_set_point() {
        let ds = tiny_dataset();
        let run = |kind: SweepKind, value: usize, dx: Option<usize>| {
            let mut settings = tiny_settings(value);
            settings.kind = kind;
            settings.training.dx = dx;
            let plan = settings.check(&ds).unwrap();
            sweep_run(&ds, "tiny", &plan, None, false, &NoProgress, None).unwrap()
        };
        let (dx6, dx7) = (run(SweepKind::Dx, 6, None), run(SweepKind::Dx, 7, None));
        let size2 = run(SweepKind::DataSize, 2, Some(6));
        let sizes = |results: &[&SweepResult]| {
            let named: Vec<(String, SweepResult)> = results
                .iter()
                .enumerate()
                .map(|(i, r)| (format!("r{i}"), (*r).clone()))
                .collect();
            let table = SweepTable::new(&named).unwrap();
            table
                .rows
                .into_iter()
                .filter(|r| r.kind == SweepKind::DataSize)
                .map(|r| (r.value, r.source, r.test_overall))
                .collect::<Vec<_>>()
        };
        let test = |r: &SweepResult| r.test.as_ref().map(|t| t.overall);
        assert_eq!(
            sizes(&[&dx6, &dx7, &size2]),
            [
                (2, "r2".to_string(), test(&size2)),
                (4, "r0 (dx = 6: the same configuration)".into(), test(&dx6))
            ]
        );
        let size4 = run(SweepKind::DataSize, 4, Some(6));
        assert_eq!(test(&size4), test(&dx6));
        let kept = sizes(&[&dx6, &size2, &size4]);
        assert_eq!(kept.len(), 2);
        assert_eq!((kept[1].0, kept[1].1.as_str()), (4, "r2"));
    }

    /// Mean and max − min over seeds per value; the paper's two rows carry them.
    #[test]
    fn selection_averages_over_seeds() {
        let table = SweepTable {
            rows: vec![
                row(SweepKind::Dx, 8, 0, 0.30, 0.40),
                row(SweepKind::Dx, 8, 1, 0.34, 0.46),
                row(SweepKind::Dx, 12, 0, 0.20, 0.30),
                row(SweepKind::DataSize, 64, 0, 0.10, 0.50),
            ],
            selection: Vec::new(),
            differences: Vec::new(),
            paper_comparison: Vec::new(),
        };
        let dx = table.selection(SweepKind::Dx);
        assert_eq!(dx.len(), 2);
        assert_eq!((dx[0].value, dx[0].seeds, dx[1].seeds), (8, 2, 1));
        assert!((dx[0].test_rmse - 0.43).abs() < 1e-12 && (dx[0].test_spread - 0.06).abs() < 1e-12);
        assert!((dx[0].train_rmse - 0.32).abs() < 1e-12 && dx[1].test_spread == 0.0);
        let rows = selection_rows(&dx, &table.selection(SweepKind::DataSize), &[]);
        assert_eq!(rows.len(), 2);
        assert!(
            rows[0]
                .flapssm
                .starts_with("8: 0.430 ± 0.060 (2 seeds); 12: 0.300")
        );
        assert!(rows[1].flapssm.starts_with("64: 0.100 ± 0.000 / 0.500"));
    }

    /// Each value against the reference, paired by seed: a consistent gap over three seeds is
    /// significant, two seeds that disagree are not, a lone seed has no interval, and a value
    /// run only with seeds the reference lacks is left out.
    #[test]
    fn differences_are_paired_by_seed_with_a_t_interval() {
        let table = SweepTable {
            rows: vec![
                row(SweepKind::Dx, 8, 0, 0.2, 0.31),
                row(SweepKind::Dx, 8, 1, 0.2, 0.32),
                row(SweepKind::Dx, 8, 2, 0.2, 0.33),
                row(SweepKind::Dx, 12, 0, 0.2, 0.30),
                row(SweepKind::Dx, 12, 1, 0.2, 0.31),
                row(SweepKind::Dx, 12, 2, 0.2, 0.32),
                row(SweepKind::Dx, 16, 0, 0.2, 0.28),
                row(SweepKind::Dx, 16, 1, 0.2, 0.33),
                row(SweepKind::Dx, 20, 5, 0.2, 0.30),
                row(SweepKind::DataSize, 64, 0, 0.2, 0.40),
                row(SweepKind::DataSize, 512, 0, 0.2, 0.30),
            ],
            selection: Vec::new(),
            differences: Vec::new(),
            paper_comparison: Vec::new(),
        };
        let dx = table.differences(SweepKind::Dx);
        assert_eq!(dx.len(), 2, "{dx:?}");
        let (d8, d16) = (&dx[0], &dx[1]);
        assert_eq!((d8.value, d8.reference, d8.seeds), (8, 12, 3));
        assert!((d8.mean - 0.01).abs() < 1e-12 && d8.significant, "{d8:?}");
        let i = d16.interval.unwrap();
        assert!(i.lo < 0.0 && i.hi > 0.0 && !d16.significant, "{d16:?}");
        assert_eq!(
            d16.to_string(),
            format!(
                "16 − 12: {:+.3} [{:+.3}, {:+.3}] (2 seeds)",
                d16.mean, i.lo, i.hi
            )
        );
        let size = table.differences(SweepKind::DataSize);
        assert_eq!(
            (size[0].value, size[0].reference, size[0].seeds),
            (64, 512, 1)
        );
        assert!(size[0].interval.is_none() && !size[0].significant);
    }
}
