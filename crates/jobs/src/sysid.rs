//! The system-identification protocol of Doerr et al. (2018) on one recorded input/output
//! table: fit a PR-SSM on the first part, simulate the rest open loop, score it.
//!
//! Protocol ([`SysidSpec::reference`], `docs/sysid.md`):
//!
//! 1. Split the `T` samples at `n_train = ⌊split · T⌋`: train `0..n_train`, test `n_train..T`.
//! 2. Fit the `sysid` preset of [`FitSpec`] (z-scoring with training statistics, ddof 0;
//!    windows of 50 at stride 1, batch 10, `D_x = 4`, `M = 20`, SE-ARD, 50 particles,
//!    Adam lr 0.1, 3000 iterations, recognition of `x₀` from the first 16 steps) `R` times
//!    per seed ([`SysidSpec::restarts`], in parallel; `R = 1` in the reference protocol).
//! 3. Predict the whole test part open loop, the initial state recognized from its first 16
//!    steps of `(u, y)`, combine the restarts ([`Combine`]; [`mixture`]) and score every
//!    test step:
//!
//! ```text
//! RMSE_raw = sqrt( 1/(T_test·D_y) Σ_t Σ_j (y_tj − m_tj)² )                     (raw units)
//! NLL      = 1/(T_test·D_y) Σ_t Σ_j [ ½ ln(2π v_tj) + (y_tj − m_tj)² / (2 v_tj) ]
//! ```
//!
//! with the predictive mean `m` and variance `v` (particle variance + `σ_y²`); the NLL is in
//! standardized units (`y`, `m`, `v` divided by the training std, so it is comparable across
//! data sets), per sample and output.

use std::path::Path;
use std::time::Instant;

use flapssm_data::table::{Column, Table, TableError};
use flapssm_prssm::Sequence;
use flapssm_prssm::predict::Prediction;
use flapssm_prssm::train::batches::derive_seed;
use flapssm_prssm::train::fit::{FitError, FitSpec, Preset, fit, predict_raw};
use flapssm_prssm::train::{Budget, TrainHooks};
use serde::{Deserialize, Serialize};

/// Seed stream of test-time particle draws.
const PREDICT_STREAM: u64 = 40;

/// Seed stream of the training seeds of restarts `r ≥ 1`.
const RESTART_STREAM: u64 = 41;

/// One fitted restart: its record and test-part predictions (raw units).
struct Restart {
    run: RestartRun,
    best: Prediction,
    last: Option<Prediction>,
}

/// Fewest training samples the protocol accepts.
pub const MIN_TRAIN_SAMPLES: usize = 100;

/// Why the protocol could not run.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum SysidError {
    /// The table could not be read or a column does not exist.
    #[error(transparent)]
    Table(#[from] TableError),
    /// A setting is out of range.
    #[error("{field} = {value}: {why}")]
    Setting {
        /// Option name.
        field: &'static str,
        /// Value, formatted.
        value: String,
        /// Requirement.
        why: String,
    },
    /// The split leaves too few samples on one side.
    #[error(
        "split {split} of {n_samples} samples leaves {n_train} training and {n_test} test samples; need at least {min_train} training and {min_test} test samples"
    )]
    Split {
        /// The split fraction.
        split: f64,
        /// Samples in the table.
        n_samples: usize,
        /// Training samples.
        n_train: usize,
        /// Test samples.
        n_test: usize,
        /// Minimum of training samples.
        min_train: usize,
        /// Minimum of test samples.
        min_test: usize,
    },
    /// Fitting or predicting failed.
    #[error("run with seed {seed} failed")]
    Fit {
        /// Seed of the failed run.
        seed: u64,
        /// Cause.
        source: FitError,
    },
}

/// Input/output columns of a recorded table, row-major.
#[derive(Debug, Clone, PartialEq)]
pub struct IoRecord {
    /// Input column names.
    pub input_names: Vec<String>,
    /// Output column names.
    pub output_names: Vec<String>,
    /// Inputs `u`, row-major `T × D_u`.
    pub inputs: Vec<f64>,
    /// Outputs `y`, row-major `T × D_y`.
    pub outputs: Vec<f64>,
}

impl IoRecord {
    /// Samples `T`.
    pub fn n_samples(&self) -> usize {
        self.outputs.len() / self.output_names.len().max(1)
    }

    /// Reads `path` ([`Table::read`] by extension; for `.mat`, only the named variables when
    /// every column is given by name) and selects the input and output columns.
    ///
    /// # Errors
    /// [`SysidError::Table`] for unreadable files and unknown columns (listing the available
    /// ones), [`SysidError::Setting`] when no input or output is selected.
    pub fn read(path: &Path, inputs: &[Column], outputs: &[Column]) -> Result<Self, SysidError> {
        if inputs.is_empty() || outputs.is_empty() {
            return Err(SysidError::Setting {
                field: if inputs.is_empty() { "input" } else { "output" },
                value: "none".into(),
                why: "select at least one column".into(),
            });
        }
        let is_mat = path
            .extension()
            .and_then(|e| e.to_str())
            .is_some_and(|e| e.eq_ignore_ascii_case("mat"));
        let names: Option<Vec<&str>> = inputs
            .iter()
            .chain(outputs)
            .map(|c| match c {
                Column::Name(n) => Some(n.as_str()),
                Column::Index(_) => None,
            })
            .collect();
        let table = match (is_mat, names) {
            (true, Some(n)) => {
                let mut uniq: Vec<&str> = Vec::new();
                for v in n {
                    if !uniq.contains(&v) {
                        uniq.push(v);
                    }
                }
                Table::read_mat(path, &uniq)?
            }
            _ => Table::read(path)?,
        };
        Ok(Self::from_table(&table, inputs, outputs)?)
    }

    /// Selects the input and output columns of `table`.
    ///
    /// # Errors
    /// [`TableError::UnknownColumn`].
    pub fn from_table(
        table: &Table,
        inputs: &[Column],
        outputs: &[Column],
    ) -> Result<Self, TableError> {
        let u = table.select(inputs)?;
        let y = table.select(outputs)?;
        let interleave = |t: &Table| -> Vec<f64> {
            (0..t.n_rows())
                .flat_map(|i| t.columns.iter().map(move |c| c[i]))
                .collect()
        };
        Ok(Self {
            inputs: interleave(&u),
            outputs: interleave(&y),
            input_names: u.names,
            output_names: y.names,
        })
    }

    /// The first `n` samples (all when `n ≥ T`), e.g. the training part for a validation split.
    pub fn head(&self, n: usize) -> IoRecord {
        let n = n.min(self.n_samples());
        let (du, dy) = (self.input_names.len(), self.output_names.len());
        IoRecord {
            input_names: self.input_names.clone(),
            output_names: self.output_names.clone(),
            inputs: self.inputs[..n * du].to_vec(),
            outputs: self.outputs[..n * dy].to_vec(),
        }
    }

    /// The samples `range` as a raw PR-SSM sequence.
    fn sequence(&self, range: std::ops::Range<usize>) -> Sequence {
        let (du, dy) = (self.input_names.len(), self.output_names.len());
        Sequence {
            inputs: self.inputs[range.start * du..range.end * du].to_vec(),
            outputs: self.outputs[range.start * dy..range.end * dy].to_vec(),
        }
    }
}

/// How the restarts of one seed are turned into one prediction.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Combine {
    /// Equal-weight mixture of the `R` restarts' predictive distributions, moment-matched:
    /// `m = (1/R) Σ_r m_r`, `v = (1/R) Σ_r (v_r + m_r²) − m²`. Its RMSE is never above the
    /// mean RMSE of the restarts (convexity of the squared error).
    Ensemble,
    /// The restart with the lowest open-loop RMSE on the training part (standardized units;
    /// `x₀` recognized from its first steps, as at test time).
    Select,
    /// Like [`Combine::Ensemble`] over `2R` members: the selected (best) and the last
    /// parameters of every restart (a snapshot ensemble).
    Snapshots,
}

/// Settings of the protocol.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SysidSpec {
    /// Fraction of the samples (the first ones) used for training, in (0, 1).
    pub split: f64,
    /// Seeds `0..seeds` (one fit each; the seed replaces `fit.train.seed`).
    pub seeds: u64,
    /// Independent fits per seed (≥ 1), run in parallel. Restart 0 uses the seed itself,
    /// restart `r ≥ 1` the training seed `derive_seed(seed, 41, r)`.
    #[serde(default = "one_restart")]
    pub restarts: usize,
    /// How the restarts are combined (irrelevant for one restart).
    #[serde(default = "ensemble")]
    pub combine: Combine,
    /// Particles of the test-time prediction (per restart).
    pub predict_particles: usize,
    /// The fit (model sizes must match the record's `D_u`, `D_y`).
    pub fit: FitSpec,
}

fn one_restart() -> usize {
    1
}

fn ensemble() -> Combine {
    Combine::Ensemble
}

impl SysidSpec {
    /// The reference protocol for `n_input` inputs and `n_output` outputs: split 0.5, 3 seeds,
    /// the `sysid` preset (3000 iterations), 50 prediction particles.
    pub fn reference(n_input: usize, n_output: usize) -> Self {
        Self {
            split: 0.5,
            seeds: 3,
            restarts: 1,
            combine: Combine::Ensemble,
            predict_particles: 50,
            fit: FitSpec::preset(Preset::Sysid, n_input, n_output),
        }
    }

    /// Sets the optimizer steps per fit.
    pub fn with_iterations(mut self, iterations: u64) -> Self {
        self.fit.train.budget = Budget::Iterations(iterations);
        self
    }

    fn check(&self, n_input: usize, n_output: usize) -> Result<(), SysidError> {
        let bad = |field, value: String, why: &str| {
            Err(SysidError::Setting {
                field,
                value,
                why: why.into(),
            })
        };
        if !(self.split > 0.0 && self.split < 1.0) {
            return bad("split", self.split.to_string(), "must be in (0, 1)");
        }
        if self.seeds == 0 {
            return bad("seeds", "0".into(), "must be ≥ 1");
        }
        if matches!(
            self.fit.train.budget,
            Budget::Iterations(0) | Budget::Epochs(0)
        ) {
            return bad("iterations", "0".into(), "must be ≥ 1");
        }
        if self.restarts == 0 {
            return bad("restarts", "0".into(), "must be ≥ 1");
        }
        if self.predict_particles == 0 {
            return bad("predict_particles", "0".into(), "must be ≥ 1");
        }
        let m = &self.fit.model;
        if (m.n_input, m.n_output) != (n_input, n_output) {
            return bad(
                "fit.model (n_input, n_output)",
                format!("({}, {})", m.n_input, m.n_output),
                &format!("the record has {n_input} inputs and {n_output} outputs"),
            );
        }
        Ok(())
    }
}

/// Test scores of one prediction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// RMSE over every test step and output, raw units.
    pub rmse: f64,
    /// Gaussian NLL per sample and output, standardized units (module docs).
    pub nll: f64,
}

/// Scores `pred` (raw units) against raw outputs `y` (`T × D_y`) with training stds `std`.
pub fn score(y: &[f64], mean: &[f64], var: &[f64], std: &[f64]) -> Scores {
    let dy = std.len().max(1);
    let (mut s2, mut nll) = (0.0, 0.0);
    for (i, ((y, m), v)) in y.iter().zip(mean).zip(var).enumerate() {
        let e = y - m;
        s2 += e * e;
        let s = std[i % dy];
        let vz = v / (s * s);
        let ez = e / s;
        nll += 0.5 * (2.0 * std::f64::consts::PI * vz).ln() + ez * ez / (2.0 * vz);
    }
    let n = y.len().max(1) as f64;
    Scores {
        rmse: (s2 / n).sqrt(),
        nll: nll / n,
    }
}

/// One restart (independent fit) of a seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RestartRun {
    /// Training seed of this fit.
    pub train_seed: u64,
    /// Epoch of the fit's selected parameters (lowest open-loop RMSE on the training part).
    pub best_epoch: Option<u64>,
    /// That open-loop RMSE on the training part (standardized units).
    pub best_train_rmse: Option<f64>,
    /// Test scores of this restart alone (diagnostics; never used for a choice).
    pub test: Scores,
    /// Test scores of its last parameters, when predicted (diagnostics).
    pub last_test: Option<Scores>,
    /// Steps rejected by the divergence guard.
    pub rejected_steps: u64,
}

/// One seed's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedRun {
    /// Seed.
    pub seed: u64,
    /// Test scores of the combined prediction ([`Combine`]).
    pub test: Scores,
    /// Per-output test RMSE, raw units (`D_y`).
    pub rmse_per_output: Vec<f64>,
    /// Wall time of all fits + predictions of this seed, seconds.
    pub wall_s: f64,
    /// Steps rejected by the divergence guard, over all restarts.
    pub rejected_steps: u64,
    /// Index of the restart chosen by [`Combine::Select`] (`None` for an ensemble of several).
    pub selected_restart: Option<usize>,
    /// Per restart.
    pub restarts: Vec<RestartRun>,
    /// Test scores of the last (not the selected best) parameters, combined the same way,
    /// when asked for.
    pub last_test: Option<Scores>,
}

/// Equal-weight moment-matched mixture of predictions of the same outputs:
/// `m = (1/R) Σ m_r`, `v = (1/R) Σ (v_r + m_r²) − m²` (outputs only; the latent moments are
/// left empty because latent coordinates of different fits are not comparable). `None` when
/// `preds` is empty or the output lengths differ.
pub fn mixture(preds: &[Prediction]) -> Option<Prediction> {
    let first = preds.first()?;
    let n = first.output_mean.len();
    if preds
        .iter()
        .any(|p| p.output_mean.len() != n || p.output_var.len() != n)
    {
        return None;
    }
    let r = preds.len() as f64;
    let mut mean = vec![0.0; n];
    let mut second = vec![0.0; n];
    for p in preds {
        for i in 0..n {
            let m = p.output_mean[i];
            mean[i] += m / r;
            second[i] += (p.output_var[i] + m * m) / r;
        }
    }
    let var = second
        .iter()
        .zip(&mean)
        .map(|(s, m)| (s - m * m).max(0.0))
        .collect();
    Some(Prediction {
        output_mean: mean,
        output_var: var,
        latent_mean: Vec::new(),
        latent_var: Vec::new(),
    })
}

/// Mean and standard deviation (ddof 0) over seeds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanStd {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (ddof 0).
    pub std: f64,
}

impl MeanStd {
    /// Of `values` (NaN when empty).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let v: Vec<f64> = values.into_iter().collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n;
        Self {
            mean,
            std: var.sqrt(),
        }
    }
}

/// The protocol's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SysidReport {
    /// Settings used.
    pub spec: SysidSpec,
    /// Input column names.
    pub inputs: Vec<String>,
    /// Output column names.
    pub outputs: Vec<String>,
    /// Training samples.
    pub n_train: usize,
    /// Test samples.
    pub n_test: usize,
    /// Test RMSE (raw units) of predicting the training mean.
    pub mean_predictor_rmse: f64,
    /// Per seed.
    pub runs: Vec<SeedRun>,
    /// Test RMSE over seeds.
    pub rmse: MeanStd,
    /// Test NLL over seeds.
    pub nll: MeanStd,
    /// Wall time per run over seeds.
    pub wall_s: MeanStd,
}

/// The test half and the first seed's prediction, for the figure.
#[derive(Debug, Clone, PartialEq)]
pub struct TestTrace {
    /// Measured test outputs, raw, row-major `T_test × D_y`.
    pub outputs: Vec<f64>,
    /// Prediction of the first seed (raw output moments).
    pub prediction: Prediction,
}

/// Training/test sample counts for `n` samples, checked.
///
/// # Errors
/// [`SysidError::Split`] when fewer than [`MIN_TRAIN_SAMPLES`] training samples or fewer test
/// samples than the recognition window remain.
pub fn split_counts(split: f64, n: usize, min_test: usize) -> Result<(usize, usize), SysidError> {
    let n_train = ((split * n as f64).floor() as usize).min(n);
    let n_test = n - n_train;
    if n_train < MIN_TRAIN_SAMPLES || n_test < min_test {
        return Err(SysidError::Split {
            split,
            n_samples: n,
            n_train,
            n_test,
            min_train: MIN_TRAIN_SAMPLES,
            min_test,
        });
    }
    Ok((n_train, n_test))
}

/// Runs the protocol on `record`, one fit per seed (sequentially; each fit is parallel
/// inside). The selected (`best`) model of each fit is scored; with `diagnose_last` the last
/// parameters are scored too ([`SeedRun::last_test`], diagnostics only). `progress` receives
/// each finished run.
///
/// # Errors
/// [`SysidError`] for bad settings, a bad split or a failed fit.
pub fn run(
    record: &IoRecord,
    spec: &SysidSpec,
    diagnose_last: bool,
    mut progress: impl FnMut(&SeedRun),
) -> Result<(SysidReport, TestTrace), SysidError> {
    let (du, dy) = (record.input_names.len(), record.output_names.len());
    spec.check(du, dy)?;
    let n = record.n_samples();
    let probe = &spec.fit;
    let window = match probe.train.windows {
        flapssm_prssm::train::WindowSpec::Windows { len, .. } => len,
        _ => 1,
    };
    let recog = match probe.initial_state {
        flapssm_prssm::train::InitialStateSpec::Recognition(rc) => rc.steps,
        _ => 1,
    };
    let (n_train, n_test) = split_counts(spec.split, n, recog)?;
    if n_train < window {
        return Err(SysidError::Split {
            split: spec.split,
            n_samples: n,
            n_train,
            n_test,
            min_train: window,
            min_test: recog,
        });
    }
    let train = record.sequence(0..n_train);
    let test = record.sequence(n_train..n);
    let norm = flapssm_prssm::train::fit::normalization(std::slice::from_ref(&train), du, dy);
    let mean_pred: Vec<f64> = (0..test.outputs.len())
        .map(|i| norm.output_mean[i % dy])
        .collect();
    let mean_predictor_rmse = score(
        &test.outputs,
        &mean_pred,
        &vec![1.0; mean_pred.len()],
        &norm.output_std,
    )
    .rmse;
    let mut runs = Vec::new();
    let mut first: Option<Prediction> = None;
    let score_of = |p: &Prediction| {
        score(
            &test.outputs,
            &p.output_mean,
            &p.output_var,
            &norm.output_std,
        )
    };
    for seed in 0..spec.seeds {
        let t0 = Instant::now();
        let err = |source| SysidError::Fit { seed, source };
        let one = |r: usize| -> Result<Restart, FitError> {
            let mut fs = spec.fit.clone();
            fs.train.seed = match r {
                0 => seed,
                _ => derive_seed(seed, RESTART_STREAM, r as u64),
            };
            let out = fit(
                &fs,
                std::slice::from_ref(&train),
                &[],
                TrainHooks::default(),
                None,
            )?;
            let predict_seed = derive_seed(seed, PREDICT_STREAM, r as u64);
            let best = predict_raw(&out.best, &test, spec.predict_particles, predict_seed)?;
            let last = match diagnose_last || spec.combine == Combine::Snapshots {
                true => Some(predict_raw(
                    &out.last,
                    &test,
                    spec.predict_particles,
                    predict_seed,
                )?),
                false => None,
            };
            let state = &out.outcome.state;
            Ok(Restart {
                run: RestartRun {
                    train_seed: fs.train.seed,
                    best_epoch: state.best.as_ref().map(|b| b.epoch),
                    best_train_rmse: state.best.as_ref().map(|b| b.score),
                    test: score_of(&best),
                    last_test: last.as_ref().map(&score_of),
                    rejected_steps: state.rejected,
                },
                best,
                last,
            })
        };
        let fits: Vec<Result<Restart, FitError>> = {
            #[cfg(feature = "parallel")]
            {
                use rayon::prelude::*;
                (0..spec.restarts).into_par_iter().map(one).collect()
            }
            #[cfg(not(feature = "parallel"))]
            {
                (0..spec.restarts).map(one).collect()
            }
        };
        let fits = fits
            .into_iter()
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        let selected = match (spec.combine, fits.len()) {
            (Combine::Snapshots, _) => None,
            (_, 1) => Some(0),
            (Combine::Ensemble, _) => None,
            (Combine::Select, _) => fits
                .iter()
                .enumerate()
                .min_by(|a, b| {
                    let key = |f: &Restart| f.run.best_train_rmse.unwrap_or(f64::INFINITY);
                    key(a.1).total_cmp(&key(b.1))
                })
                .map(|(i, _)| i),
        };
        let combined = |pick: &dyn Fn(&Restart) -> Option<&Prediction>| -> Option<Prediction> {
            match selected {
                Some(i) => pick(&fits[i]).cloned(),
                None => {
                    let preds: Option<Vec<Prediction>> =
                        fits.iter().map(|f| pick(f).cloned()).collect();
                    mixture(&preds?)
                }
            }
        };
        let pred = match spec.combine {
            Combine::Snapshots => {
                let preds: Vec<Prediction> = fits
                    .iter()
                    .flat_map(|f| std::iter::once(&f.best).chain(&f.last))
                    .cloned()
                    .collect();
                mixture(&preds)
            }
            _ => combined(&|f| Some(&f.best)),
        }
        .ok_or_else(|| SysidError::Setting {
            field: "restarts",
            value: spec.restarts.to_string(),
            why: "the restarts' predictions have different lengths".into(),
        })?;
        let last_scores = combined(&|f| f.last.as_ref()).map(|p| score_of(&p));
        let wall_s = t0.elapsed().as_secs_f64();
        let test_scores = score_of(&pred);
        let rmse_per_output = (0..dy)
            .map(|j| {
                let (mut s2, mut k) = (0.0, 0.0);
                for (y, m) in test
                    .outputs
                    .iter()
                    .zip(&pred.output_mean)
                    .skip(j)
                    .step_by(dy)
                {
                    s2 += (y - m) * (y - m);
                    k += 1.0;
                }
                (s2 / f64::max(k, 1.0)).sqrt()
            })
            .collect();
        let r = SeedRun {
            seed,
            test: test_scores,
            rmse_per_output,
            wall_s,
            rejected_steps: fits.iter().map(|f| f.run.rejected_steps).sum(),
            selected_restart: selected,
            restarts: fits.into_iter().map(|f| f.run).collect(),
            last_test: last_scores,
        };
        progress(&r);
        runs.push(r);
        first.get_or_insert(pred);
    }
    let report = SysidReport {
        spec: spec.clone(),
        inputs: record.input_names.clone(),
        outputs: record.output_names.clone(),
        n_train,
        n_test,
        mean_predictor_rmse,
        rmse: MeanStd::of(runs.iter().map(|r| r.test.rmse)),
        nll: MeanStd::of(runs.iter().map(|r| r.test.nll)),
        wall_s: MeanStd::of(runs.iter().map(|r| r.wall_s)),
        runs,
    };
    let trace = TestTrace {
        outputs: test.outputs,
        prediction: first.unwrap_or_else(|| Prediction {
            output_mean: Vec::new(),
            output_var: Vec::new(),
            latent_mean: Vec::new(),
            latent_var: Vec::new(),
        }),
    };
    Ok((report, trace))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_match_hand_computed_values() {
        // Two outputs with training stds 2 and 0.5; raw errors (2, 0.5) and (0, -1).
        let std = [2.0, 0.5];
        let y = [1.0, 1.0, 3.0, 0.0];
        let m = [-1.0, 0.5, 3.0, 1.0];
        let v = [4.0, 0.25, 16.0, 1.0];
        let s = score(&y, &m, &v, &std);
        assert!((s.rmse - ((4.0 + 0.25 + 0.0 + 1.0) / 4.0f64).sqrt()).abs() < 1e-15);
        // Standardized: (e, v) = (1, 1), (1, 1), (0, 4), (-2, 4).
        let ln2pi = (2.0 * std::f64::consts::PI).ln();
        let nll = [
            0.5 * ln2pi + 0.5,
            0.5 * ln2pi + 0.5,
            0.5 * (ln2pi + 4f64.ln()),
            0.5 * (ln2pi + 4f64.ln()) + 0.5,
        ];
        assert!((s.nll - nll.iter().sum::<f64>() / 4.0).abs() < 1e-14);
    }

    fn prediction(mean: &[f64], var: &[f64]) -> Prediction {
        Prediction {
            output_mean: mean.to_vec(),
            output_var: var.to_vec(),
            latent_mean: vec![0.0; 4],
            latent_var: vec![1.0; 4],
        }
    }

    #[test]
    fn mixture_matches_moments_of_the_equal_weight_mixture() {
        // Components N(0, 1) and N(2, 3): mean 1, variance (1 + 3)/2 + (0² + 2²)/2 − 1² = 3.
        let a = prediction(&[0.0, -1.0], &[1.0, 0.5]);
        let b = prediction(&[2.0, -1.0], &[3.0, 0.25]);
        let m = mixture(&[a.clone(), b]).unwrap();
        assert_eq!(m.output_mean, [1.0, -1.0]);
        assert!((m.output_var[0] - 3.0).abs() < 1e-14);
        assert!((m.output_var[1] - 0.375).abs() < 1e-14);
        assert!(m.latent_mean.is_empty() && m.latent_var.is_empty());
        // One component is itself.
        let one = mixture(std::slice::from_ref(&a)).unwrap();
        assert_eq!(one.output_mean, a.output_mean);
        assert!(
            one.output_var
                .iter()
                .zip(&a.output_var)
                .all(|(x, y)| (x - y).abs() < 1e-15)
        );
        assert!(mixture(&[]).is_none());
        assert!(mixture(&[a, prediction(&[0.0], &[1.0])]).is_none());
    }

    #[test]
    fn mixture_rmse_never_exceeds_mean_member_rmse() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let std = [1.5];
        for _ in 0..100 {
            let y: Vec<f64> = (0..20).map(|_| rng.random_range(-2.0..2.0)).collect();
            let members: Vec<Prediction> = (0..rng.random_range(2..5))
                .map(|_| {
                    let m: Vec<f64> = (0..20).map(|_| rng.random_range(-3.0..3.0)).collect();
                    prediction(&m, &[0.5; 20])
                })
                .collect();
            let mix = mixture(&members).unwrap();
            let rmse = |p: &Prediction| score(&y, &p.output_mean, &p.output_var, &std).rmse;
            let mean_member = members.iter().map(rmse).sum::<f64>() / members.len() as f64;
            assert!(rmse(&mix) <= mean_member + 1e-12);
        }
    }

    #[test]
    fn mean_std_is_population_std() {
        let ms = MeanStd::of([1.0, 2.0, 3.0, 6.0]);
        assert_eq!(ms.mean, 3.0);
        assert!((ms.std - 3.5f64.sqrt()).abs() < 1e-15);
    }

    #[test]
    fn record_is_row_major_in_selection_order() {
        let table = Table {
            source: "t.csv".into(),
            names: vec!["a".into(), "b".into(), "c".into()],
            columns: vec![
                vec![1.0, 2.0, 3.0],
                vec![4.0, 5.0, 6.0],
                vec![7.0, 8.0, 9.0],
            ],
        };
        let r = IoRecord::from_table(
            &table,
            &[Column::Name("c".into()), Column::Index(0)],
            &[Column::Index(1)],
        )
        .unwrap();
        assert_eq!(r.input_names, ["c", "a"]);
        assert_eq!(r.inputs, [7.0, 1.0, 8.0, 2.0, 9.0, 3.0]);
        assert_eq!(r.outputs, [4.0, 5.0, 6.0]);
        assert_eq!(r.n_samples(), 3);
        let h = r.head(2);
        assert_eq!((h.inputs.len(), h.outputs), (4, vec![4.0, 5.0]));
        let s = r.sequence(1..3);
        assert_eq!(
            (s.inputs, s.outputs),
            (vec![8.0, 2.0, 9.0, 3.0], vec![5.0, 6.0])
        );
    }

    #[test]
    fn split_counts_enforce_minimum_training_samples() {
        assert_eq!(split_counts(0.5, 1000, 16).unwrap(), (500, 500));
        assert_eq!(split_counts(0.1, 1000, 16).unwrap(), (100, 900));
        let e = split_counts(0.099, 1000, 16).unwrap_err().to_string();
        assert!(
            e.contains("99 training") && e.contains("at least 100"),
            "{e}"
        );
        assert!(split_counts(0.99, 1000, 16).is_err());
    }

    #[test]
    fn mismatched_fit_sizes_and_bad_settings_are_rejected() {
        let spec = SysidSpec::reference(2, 1);
        assert!(spec.check(2, 1).is_ok());
        let e = spec.check(1, 1).unwrap_err().to_string();
        assert!(e.contains("1 inputs and 1 outputs"), "{e}");
        let e = SysidSpec {
            seeds: 0,
            ..SysidSpec::reference(1, 1)
        }
        .check(1, 1)
        .unwrap_err()
        .to_string();
        assert!(e.contains("seeds"), "{e}");
        let e = SysidSpec {
            restarts: 0,
            ..SysidSpec::reference(1, 1)
        }
        .check(1, 1)
        .unwrap_err()
        .to_string();
        assert!(e.contains("restarts"), "{e}");
    }
}
