//! The static nonlinear baseline and its history-given form: sparse GP regression
//! ([`flapssm_prssm::regression`], with the PR-SSM's Matern-3/2 kernel) of the standardized
//! loads on the standardized inputs now and at `K` earlier taps spread evenly over a history of
//! `h` samples,
//!
//! ```text
//! ŷ_z(t) = g([z_u(t), z_u(t − ⌈h/K⌉), z_u(t − ⌈2h/K⌉), …, z_u(t − h)]),
//! ```
//!
//! inputs before a trajectory's first sample taken at its first sample. With `h = 0` the model
//! is a nonlinear function of the instantaneous inputs: what a wing without fluid memory
//! allows, the control that separates the PR-SSM's memory from its nonlinearity. With `h > 0`
//! it is given a controlled history; test error against `h` is the history curve
//! ([`crate::history`]).
//!
//! Settings are chosen on the training trajectories only, by the error on the last
//! [`GpSettings::validation_share`] of them after a fit on the others: a common length scale
//! `ℓ = c·√D` on every standardized feature (`D = 7·(K+1)`) and the noise variance `σ²` from
//! grids, then one sweep that halves or doubles each input's length scale; then the model is
//! refitted on all training trajectories. `gp-history` also chooses `h` that way among
//! [`GpSettings::history_cycles`].

use flapssm_prssm::KernelKind;
use flapssm_prssm::regression::{NormalEquations, RegressionKernel, SparseGpRegression};
use flapssm_prssm::train::inducing::{KMEANS_MAX_POINTS, kmeans};
use flapssm_wing::dataset::{Standardization, Trajectory, ValidDataset};
use serde::{Deserialize, Serialize};

use super::{Baseline, LoadModel, LoadPrediction, check_buffer};
use crate::error::{JobError, Result};
use crate::progress::Progress;

const N_INPUT: usize = 7;
const N_OUTPUT: usize = 5;

/// The registry entry of the static model (`h = 0`).
pub const STATIC: Baseline = Baseline {
    key: "gp-static",
    about: "GP-static: sparse GP regression (Matern-3/2, 512 inducing inputs) of the instantaneous inputs",
    fit: |ds, progress| {
        let mut m = fit_histories(ds, &[0], &GpSettings::default(), progress)?;
        Ok(Box::new(m.remove(0)))
    },
};

/// The registry entry of the history-given model, `h` chosen on the training trajectories.
pub const HISTORY: Baseline = Baseline {
    key: "gp-history",
    about: "GP-history: the same regression given the inputs at 4 taps over the past h samples, h chosen on training data",
    fit: |ds, progress| {
        Ok(Box::new(fit_best_history(
            ds,
            &GpSettings::default(),
            progress,
        )?))
    },
};

/// Settings of the GP baselines.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GpSettings {
    /// Past taps `K` spread over the history (the current sample is one more).
    pub n_taps: usize,
    /// Inducing inputs `M` of the final fit (k-means of the training features).
    pub n_inducing: usize,
    /// Inducing inputs of the fits that choose the settings.
    pub n_inducing_choice: usize,
    /// Candidate length-scale factors `c` (`ℓ = c·√D`).
    pub lengthscale_factors: Vec<f64>,
    /// Candidate noise variances `σ²` (standardized units).
    pub noise_variances: Vec<f64>,
    /// Share of the training trajectories (the last ones) held out to choose settings.
    pub validation_share: f64,
    /// Every `fit_stride`-th sample enters the fits that choose settings (all enter the
    /// final fit).
    pub fit_stride: usize,
    /// History lengths `gp-history` chooses among, in stroke cycles (the training
    /// trajectories' median last-cycle duration).
    pub history_cycles: Vec<f64>,
    /// Seed of the k-means.
    pub seed: u64,
}

impl Default for GpSettings {
    fn default() -> Self {
        Self {
            n_taps: 4,
            n_inducing: 512,
            n_inducing_choice: 256,
            lengthscale_factors: vec![0.125, 0.25, 0.5, 1.0],
            noise_variances: vec![1e-3, 1e-2, 1e-1],
            validation_share: 0.125,
            fit_stride: 2,
            history_cycles: vec![0.125, 0.25, 0.5, 1.0],
            seed: 0,
        }
    }
}

impl GpSettings {
    /// Checks the settings.
    ///
    /// # Errors
    /// [`JobError::Setting`] naming the setting out of range.
    pub fn check(&self) -> Result<()> {
        let bad = |name: &str, value: String, expected: &str| {
            Err(JobError::Setting {
                name: format!("gp.{name}"),
                value,
                expected: expected.into(),
            })
        };
        let positive = |v: &[f64]| !v.is_empty() && v.iter().all(|x| *x > 0.0 && x.is_finite());
        if self.n_taps == 0 {
            return bad("n_taps", "0".into(), "at least 1");
        }
        if self.n_inducing < 2 {
            return bad("n_inducing", self.n_inducing.to_string(), "at least 2");
        }
        if self.n_inducing_choice < 2 {
            return bad(
                "n_inducing_choice",
                self.n_inducing_choice.to_string(),
                "at least 2",
            );
        }
        if !positive(&self.lengthscale_factors) {
            return bad(
                "lengthscale_factors",
                format!("{:?}", self.lengthscale_factors),
                "one or more finite values > 0",
            );
        }
        if !positive(&self.noise_variances) {
            return bad(
                "noise_variances",
                format!("{:?}", self.noise_variances),
                "one or more finite values > 0",
            );
        }
        if !(self.validation_share > 0.0 && self.validation_share < 1.0) {
            return bad(
                "validation_share",
                self.validation_share.to_string(),
                "between 0 and 1",
            );
        }
        if self.fit_stride == 0 {
            return bad("fit_stride", "0".into(), "at least 1");
        }
        if !positive(&self.history_cycles) {
            return bad(
                "history_cycles",
                format!("{:?}", self.history_cycles),
                "one or more finite values > 0",
            );
        }
        Ok(())
    }
}

/// One candidate of the settings' choice and its validation error.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Candidate {
    /// History `h` (samples).
    pub history_samples: usize,
    /// Length scale of each input now (standardized units).
    pub input_lengthscales: [f64; N_INPUT],
    /// Length scale of each input on every past tap (standardized units; [`HISTORY_OFF`]:
    /// the history is ignored, the static model).
    pub history_lengthscales: [f64; N_INPUT],
    /// Noise variance `σ²`.
    pub noise_variance: f64,
    /// Pooled standardized RMSE on the held-out training trajectories.
    pub validation_rmse: f64,
}

/// A past tap's length scale that makes the kernel blind to it: with it the history-given
/// model is the static one, so a history is kept only where it lowers the held-out error.
pub const HISTORY_OFF: f64 = 1e6;

/// A fitted GP baseline.
#[derive(Debug, Clone)]
pub struct GpLoadModel {
    key: &'static str,
    name: String,
    /// History `h` (samples) and the taps' lags (samples, the first 0).
    pub taps: Vec<usize>,
    /// The training standardization.
    pub stats: Standardization,
    /// The regression in standardized units.
    pub regression: SparseGpRegression,
    /// Every candidate tried, the chosen one first.
    pub candidates: Vec<Candidate>,
}

/// Lags of the taps for a history of `h` samples: `0, ⌈h/K⌉, …, h` without repeats.
pub fn tap_lags(history_samples: usize, n_taps: usize) -> Vec<usize> {
    let mut lags = vec![0];
    for k in 1..=n_taps {
        let lag = (history_samples * k).div_ceil(n_taps);
        if lag > *lags.last().unwrap_or(&0) {
            lags.push(lag);
        }
    }
    lags
}

/// Features of every sample of `t` (row-major `n × 7·taps`), inputs standardized by `stats`.
fn features(t: &Trajectory, stats: &Standardization, lags: &[usize]) -> Vec<f64> {
    let z: Vec<[f64; 7]> = t.inputs.iter().map(|u| stats.normalize_u(u)).collect();
    let mut x = Vec::with_capacity(z.len() * N_INPUT * lags.len());
    for i in 0..z.len() {
        for lag in lags {
            x.extend_from_slice(&z[i.saturating_sub(*lag)]);
        }
    }
    x
}

/// Features and standardized outputs of `trajectories`, every `stride`-th sample from sample
/// `first` on.
fn table(
    trajectories: &[Trajectory],
    stats: &Standardization,
    lags: &[usize],
    stride: usize,
    first: usize,
) -> (Vec<f64>, Vec<f64>) {
    let width = N_INPUT * lags.len();
    let (mut x, mut y) = (Vec::new(), Vec::new());
    for t in trajectories {
        let Some(out) = &t.outputs else { continue };
        let f = features(t, stats, lags);
        for i in (first..out.len()).step_by(stride) {
            x.extend_from_slice(&f[i * width..(i + 1) * width]);
            y.extend_from_slice(&stats.normalize_y(&out[i]));
        }
    }
    (x, y)
}

/// `M` k-means inducing inputs of the feature table `x`, from at most `max_points` of its rows
/// (an even stride). The present's features are taken as they are and each past tap's feature
/// is weighted by `ℓ_now/ℓ_past` of the kernel: a history the kernel ignores does not spread
/// the centres, and the static model's centres are those of the present alone.
fn inducing(
    x: &[f64],
    kernel: &RegressionKernel,
    m: usize,
    max_points: usize,
    seed: u64,
) -> Result<Vec<f64>> {
    let ls = &kernel.lengthscales;
    let width = ls.len();
    let weights: Vec<f64> = (0..width).map(|i| ls[i % N_INPUT] / ls[i]).collect();
    let n = x.len() / width;
    if n < m {
        return Err(JobError::Mismatch {
            what: "GP baseline training samples".into(),
            expected: format!("at least as many as the {m} inducing inputs"),
            found: n.to_string(),
        });
    }
    let stride = n.div_ceil(max_points).max(1);
    let points: Vec<f64> = x
        .chunks_exact(width)
        .step_by(stride)
        .flat_map(|row| row.iter().zip(&weights).map(|(v, w)| v * w))
        .collect();
    let mut z = kmeans(&points, width, m, seed).0;
    for row in z.chunks_exact_mut(width) {
        for (v, w) in row.iter_mut().zip(&weights) {
            *v /= w;
        }
    }
    Ok(z)
}

/// The Matern-3/2 kernel with `now[j]` on input `j` at lag 0 and `past[j]` at each of the
/// other `n_taps − 1` taps.
fn kernel(n_taps: usize, now: &[f64; N_INPUT], past: &[f64; N_INPUT]) -> RegressionKernel {
    RegressionKernel {
        kind: KernelKind::Matern32,
        lengthscales: (0..n_taps)
            .flat_map(|k| if k == 0 { now } else { past }.iter().copied())
            .collect(),
    }
}

fn pooled_rmse(pred: &[f64], y: &[f64]) -> f64 {
    let s: f64 = pred.iter().zip(y).map(|(p, t)| (p - t) * (p - t)).sum();
    (s / y.len().max(1) as f64).sqrt()
}

/// The training stroke cycle in samples: the median last-cycle duration of the training
/// trajectories.
///
/// # Errors
/// A training trajectory without a full cycle.
pub fn cycle_samples(ds: &ValidDataset) -> Result<usize> {
    let mut d = ds
        .train()
        .iter()
        .enumerate()
        .map(|(i, t)| {
            t.published_window()
                .map(|w| w.duration)
                .map_err(|source| JobError::Cycle {
                    trajectory: i,
                    source,
                })
        })
        .collect::<Result<Vec<_>>>()?;
    d.sort_unstable();
    Ok(d[d.len() / 2])
}

/// The held-out choice of settings for one history: the fit and validation tables of the
/// training trajectories (the last [`GpSettings::validation_share`] held out). The fit takes
/// every sample (a history before the first sample at the first sample's inputs); the held-out
/// error is scored from `val_first` on, the longest history of the job, so that the errors of
/// every history are on the same samples.
struct Choice<'a> {
    lags: Vec<usize>,
    x: Vec<f64>,
    y: Vec<f64>,
    xv: Vec<f64>,
    yv: Vec<f64>,
    settings: &'a GpSettings,
    tried: Vec<Candidate>,
    /// The last inducing inputs and the past-to-present length-scale ratios they were placed
    /// with.
    last_inducing: Option<(Vec<f64>, Vec<f64>)>,
}

impl<'a> Choice<'a> {
    fn new(
        ds: &ValidDataset,
        stats: &Standardization,
        lags: Vec<usize>,
        val_first: usize,
        settings: &'a GpSettings,
    ) -> Result<Self> {
        let train = ds.train();
        let n_val = ((train.len() as f64 * settings.validation_share).round() as usize).max(1);
        if train.len() <= n_val {
            return Err(JobError::Mismatch {
                what: "GP baseline training trajectories".into(),
                expected: "at least 2 (one held out to choose the settings)".into(),
                found: train.len().to_string(),
            });
        }
        let (fit, val) = train.split_at(train.len() - n_val);
        let (x, y) = table(fit, stats, &lags, settings.fit_stride, 0);
        let (xv, yv) = table(val, stats, &lags, 1, val_first);
        if yv.is_empty() {
            return Err(JobError::Mismatch {
                what: "GP baseline held-out samples".into(),
                expected: format!(
                    "trajectories longer than the longest history, {val_first} samples"
                ),
                found: format!("{} samples", ds.n_samples()),
            });
        }
        Ok(Self {
            lags,
            x,
            y,
            xv,
            yv,
            settings,
            tried: Vec::new(),
            last_inducing: None,
        })
    }

    /// Fits the length scales `now`, `past` with every noise variance; returns the best
    /// candidate so far.
    fn try_scales(&mut self, now: [f64; N_INPUT], past: [f64; N_INPUT]) -> Result<Candidate> {
        let k = kernel(self.lags.len(), &now, &past);
        let s = self.settings;
        let ratios: Vec<f64> = (0..N_INPUT).map(|j| past[j] / now[j]).collect();
        let z = match &self.last_inducing {
            Some((r, z)) if *r == ratios => z.clone(),
            _ => inducing(&self.x, &k, s.n_inducing_choice, KMEANS_MAX_POINTS, s.seed)?,
        };
        let eq = NormalEquations::accumulate(&k, &z, &self.x, &self.y, N_OUTPUT)?;
        self.last_inducing = Some((ratios, z));
        let mut pred = vec![0.0; self.yv.len()];
        for &s2 in &s.noise_variances {
            eq.solve(s2)?.predict_into(&self.xv, &mut pred)?;
            self.tried.push(Candidate {
                history_samples: *self.lags.last().unwrap_or(&0),
                input_lengthscales: now,
                history_lengthscales: past,
                noise_variance: s2,
                validation_rmse: pooled_rmse(&pred, &self.yv),
            });
        }
        Ok(self.best())
    }

    fn best(&self) -> Candidate {
        self.tried
            .iter()
            .min_by(|a, b| a.validation_rmse.total_cmp(&b.validation_rmse))
            .cloned()
            .expect("a candidate was tried")
    }

    /// Every candidate tried, best first.
    fn into_sorted(mut self) -> Vec<Candidate> {
        self.tried
            .sort_by(|a, b| a.validation_rmse.total_cmp(&b.validation_rmse));
        self.tried
    }
}

/// The static model's settings, best first: a common length scale `c·√7` from the grid, then
/// one sweep that halves or doubles each input's length scale where that lowers the held-out
/// error.
fn choose_static(
    ds: &ValidDataset,
    stats: &Standardization,
    val_first: usize,
    settings: &GpSettings,
) -> Result<Vec<Candidate>> {
    let mut c = Choice::new(ds, stats, vec![0], val_first, settings)?;
    let off = [HISTORY_OFF; N_INPUT];
    for &f in &settings.lengthscale_factors {
        c.try_scales([f * (N_INPUT as f64).sqrt(); N_INPUT], off)?;
    }
    for j in 0..N_INPUT {
        for factor in [0.5, 2.0] {
            let mut now = c.best().input_lengthscales;
            now[j] *= factor;
            c.try_scales(now, off)?;
        }
    }
    Ok(c.into_sorted())
}

/// The settings of a history of `lags`, best first: the history ignored with the static
/// model's length scales `now` (the static model itself), its taps at `ρ` times `now`
/// (`ρ` ∈ {4, 1}), or a common length scale `c·√D` on every feature (the static grid's `c`);
/// then, unless the history is ignored, one sweep that halves or doubles each input's length
/// scales (now and past together).
fn choose_history(
    ds: &ValidDataset,
    stats: &Standardization,
    lags: Vec<usize>,
    val_first: usize,
    now: [f64; N_INPUT],
    settings: &GpSettings,
) -> Result<Vec<Candidate>> {
    let mut c = Choice::new(ds, stats, lags, val_first, settings)?;
    c.try_scales(now, [HISTORY_OFF; N_INPUT])?;
    for rho in [4.0, 1.0] {
        c.try_scales(now, now.map(|l| rho * l))?;
    }
    let common = ((N_INPUT * c.lags.len()) as f64).sqrt();
    for &f in &settings.lengthscale_factors {
        c.try_scales([f * common; N_INPUT], [f * common; N_INPUT])?;
    }
    if c.best().history_lengthscales[0] < HISTORY_OFF {
        for j in 0..N_INPUT {
            for factor in [0.5, 2.0] {
                let (mut now, mut past) = {
                    let b = c.best();
                    (b.input_lengthscales, b.history_lengthscales)
                };
                now[j] *= factor;
                past[j] *= factor;
                c.try_scales(now, past)?;
            }
        }
    }
    Ok(c.into_sorted())
}

/// Refits the best of `candidates` on every sample of every training trajectory.
/// A history the chosen length scales ignore counts as none.
fn refit(
    ds: &ValidDataset,
    stats: Standardization,
    candidates: Vec<Candidate>,
    key: &'static str,
    settings: &GpSettings,
) -> Result<GpLoadModel> {
    let best = &candidates[0];
    let h = if best.history_lengthscales[0] >= HISTORY_OFF {
        0
    } else {
        best.history_samples
    };
    let lags = tap_lags(h, settings.n_taps);
    let k = kernel(
        lags.len(),
        &best.input_lengthscales,
        &best.history_lengthscales,
    );
    let (x, y) = table(ds.train(), &stats, &lags, 1, 0);
    let z = inducing(
        &x,
        &k,
        settings.n_inducing,
        KMEANS_MAX_POINTS,
        settings.seed,
    )?;
    let regression =
        NormalEquations::accumulate(&k, &z, &x, &y, N_OUTPUT)?.solve(best.noise_variance)?;
    let name = if key == STATIC.key {
        "GP-static".to_string()
    } else {
        format!("GP-history (h = {h})")
    };
    Ok(GpLoadModel {
        key,
        name,
        taps: lags,
        stats,
        regression,
        candidates,
    })
}

/// The static model's candidates and those of each history `h > 0` in `history_samples`
/// (empty for `h = 0`), all scored on the same held-out samples, from the longest history on.
/// `progress.advance(1)` after the static choice and after each history.
fn choose_all(
    ds: &ValidDataset,
    stats: &Standardization,
    history_samples: &[usize],
    settings: &GpSettings,
    progress: &dyn Progress,
) -> Result<(Vec<Candidate>, Vec<Vec<Candidate>>)> {
    let val_first = history_samples.iter().copied().max().unwrap_or(0);
    let static_choice = choose_static(ds, stats, val_first, settings)?;
    progress.advance(1);
    let now = static_choice[0].input_lengthscales;
    let histories = history_samples
        .iter()
        .map(|&h| {
            let c = if h == 0 {
                Vec::new()
            } else {
                let lags = tap_lags(h, settings.n_taps);
                choose_history(ds, stats, lags, val_first, now, settings)?
            };
            progress.advance(1);
            Ok(c)
        })
        .collect::<Result<_>>()?;
    Ok((static_choice, histories))
}

/// The GP baselines of each history in `history_samples` (module docs), sharing the static
/// model's choice of its length scales.
///
/// # Errors
/// Bad settings, too few training trajectories or samples, regression errors.
pub fn fit_histories(
    ds: &ValidDataset,
    history_samples: &[usize],
    settings: &GpSettings,
    progress: &dyn Progress,
) -> Result<Vec<GpLoadModel>> {
    settings.check()?;
    let stats = ds.standardization()?;
    progress.start("fit GP baselines", history_samples.len() as u64 + 1);
    let (static_choice, choices) = choose_all(ds, &stats, history_samples, settings, progress)?;
    let models = history_samples
        .iter()
        .zip(choices)
        .map(|(&h, candidates)| {
            let (candidates, key) = if h == 0 {
                (static_choice.clone(), STATIC.key)
            } else {
                (candidates, HISTORY.key)
            };
            refit(ds, stats.clone(), candidates, key, settings)
        })
        .collect::<Result<_>>()?;
    progress.finish("");
    Ok(models)
}

/// The GP baseline at the history, among [`GpSettings::history_cycles`] of the training
/// cycle, with the lowest held-out training error; every candidate of every history is kept
/// in [`GpLoadModel::candidates`] (best first).
///
/// # Errors
/// As [`fit_histories`]; a training trajectory without a full cycle.
pub fn fit_best_history(
    ds: &ValidDataset,
    settings: &GpSettings,
    progress: &dyn Progress,
) -> Result<GpLoadModel> {
    settings.check()?;
    let period = cycle_samples(ds)?;
    let stats = ds.standardization()?;
    let histories: Vec<usize> = settings
        .history_cycles
        .iter()
        .map(|c| ((c * period as f64).round() as usize).max(1))
        .collect();
    progress.start("choose the GP's history", histories.len() as u64 + 1);
    let (_, choices) = choose_all(ds, &stats, &histories, settings, progress)?;
    progress.finish("");
    let mut all: Vec<Candidate> = choices.into_iter().flatten().collect();
    all.sort_by(|a, b| a.validation_rmse.total_cmp(&b.validation_rmse));
    progress.start("fit GP-history", 0);
    let model = refit(ds, stats, all, HISTORY.key, settings)?;
    progress.finish("");
    Ok(model)
}

impl GpLoadModel {
    /// History `h` (samples).
    pub fn history_samples(&self) -> usize {
        *self.taps.last().unwrap_or(&0)
    }
}

impl LoadModel for GpLoadModel {
    fn name(&self) -> &str {
        &self.name
    }

    fn key(&self) -> &str {
        self.key
    }

    fn parameters(&self) -> serde_json::Value {
        serde_json::json!({
            "history_samples": self.history_samples(),
            "tap_lags": self.taps,
            "kernel": self.regression.kernel,
            "n_inducing": self.regression.n_inducing(),
            "noise_variance": self.regression.noise_variance,
            "candidates": self.candidates,
        })
    }

    fn predict_into(
        &self,
        _index: usize,
        trajectory: &Trajectory,
        out: LoadPrediction<'_>,
    ) -> Result<()> {
        let n = trajectory.inputs.len();
        check_buffer("GP mean", out.mean, n, N_OUTPUT)?;
        let x = features(trajectory, &self.stats, &self.taps);
        self.regression.predict_into(&x, out.mean)?;
        for row in out.mean.chunks_exact_mut(N_OUTPUT) {
            for (j, v) in row.iter_mut().enumerate() {
                *v = self.stats.mean_y[j] + self.stats.std_y[j] * *v;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn taps_spread_over_the_history_without_repeats() {
        assert_eq!(tap_lags(0, 4), vec![0]);
        assert_eq!(tap_lags(2, 4), vec![0, 1, 2]);
        assert_eq!(tap_lags(40, 4), vec![0, 10, 20, 30, 40]);
        assert_eq!(tap_lags(10, 4), vec![0, 3, 5, 8, 10]);
    }

    #[test]
    fn bad_settings_are_named() {
        let s = GpSettings {
            noise_variances: vec![0.0],
            ..GpSettings::default()
        };
        let e = s.check().unwrap_err().to_string();
        assert!(e.contains("gp.noise_variances"), "{e}");
        let s = GpSettings {
            validation_share: 1.0,
            ..GpSettings::default()
        };
        assert!(
            s.check()
                .unwrap_err()
                .to_string()
                .contains("gp.validation_share")
        );
    }
}
