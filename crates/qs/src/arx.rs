//! The ARX baseline without autoregression (a finite-impulse-response model, so open-loop
//! prediction is stable by construction): each standardized load is a linear function of the
//! standardized inputs now and at `n_lags − 1` earlier samples, `stride` samples apart,
//!
//! ```text
//! ẑ_y(t) = c + Σ_{k=0}^{L−1} B_k z_u(t − k·s),      z = (x − mean) / std,
//! ```
//!
//! fitted by ridge-regularized least squares on every sample of the training trajectories
//! (inputs before the first sample are taken at their mean, `z_u = 0`). A reviewer's question
//! to the paper: how much of the PR-SSM's gain does a linear model with input memory get?
//!
//! The defaults see 40 samples (1.6 s at 25 Hz, about half a stroke cycle of the generator's
//! trajectories) in steps of 2 samples: 21 lags of 7 inputs, 148 coefficients per output.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use flapssm_wing::dataset::{Trajectory, ValidDataset};
use serde::{Deserialize, Serialize};

const N_INPUT: usize = 7;
const N_OUTPUT: usize = 5;

/// Why an ARX fit or prediction failed.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum ArxError {
    /// A setting out of its range.
    #[error("setting {name} = {value}: {expected}")]
    Setting {
        /// The setting (`arx.n_lags`, …).
        name: String,
        /// The value given.
        value: String,
        /// What it must be.
        expected: String,
    },
    /// The dataset cannot be fitted (no training outputs); worded as the jobs' dataset errors.
    #[error("dataset: {0}")]
    Dataset(#[from] flapssm_wing::dataset::DatasetError),
    /// The normal equations are not positive definite.
    #[error(
        "ARX normal equations: expected a positive definite system (add a ridge penalty), found {0}"
    )]
    Singular(String),
    /// An output buffer of the wrong size.
    #[error("ARX mean buffer: expected {expected} values, found {found}")]
    Shape {
        /// Values expected (`n × 5`).
        expected: usize,
        /// Values given.
        found: usize,
    },
}

/// Settings of the ARX baseline.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct ArxSettings {
    /// Lags `L` (the current sample counts as one).
    pub n_lags: usize,
    /// Samples between lags `s`.
    pub stride: usize,
    /// Ridge penalty added to the normal equations' diagonal (standardized units, per sample).
    pub ridge: f64,
}

impl Default for ArxSettings {
    fn default() -> Self {
        Self {
            n_lags: 21,
            stride: 2,
            ridge: 1e-6,
        }
    }
}

impl ArxSettings {
    /// Checks the settings.
    ///
    /// # Errors
    /// [`ArxError::Setting`] for no lag, a zero stride or a negative or non-finite ridge.
    pub fn check(&self) -> Result<(), ArxError> {
        let bad = |name: &str, value: String, expected: &str| {
            Err(ArxError::Setting {
                name: format!("arx.{name}"),
                value,
                expected: expected.into(),
            })
        };
        if self.n_lags == 0 {
            return bad("n_lags", "0".into(), "must be at least 1");
        }
        if self.stride == 0 {
            return bad("stride", "0".into(), "must be at least 1");
        }
        if !(self.ridge >= 0.0 && self.ridge.is_finite()) {
            return bad("ridge", self.ridge.to_string(), "must be finite and ≥ 0");
        }
        Ok(())
    }

    fn n_regressors(&self) -> usize {
        1 + N_INPUT * self.n_lags
    }
}

/// A fitted ARX baseline with the standardization it was fitted in.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ArxModel {
    /// Its settings.
    pub settings: ArxSettings,
    /// Input means and standard deviations of the training trajectories.
    pub input_mean: [f64; N_INPUT],
    /// Input standard deviations (> 0).
    pub input_std: [f64; N_INPUT],
    /// Output means (N, N·mm).
    pub output_mean: [f64; N_OUTPUT],
    /// Output standard deviations (N, N·mm; > 0).
    pub output_std: [f64; N_OUTPUT],
    /// Coefficients, row-major `n_regressors × 5`: intercept, then lag 0 inputs, lag 1, …
    pub coefficients: Vec<f64>,
}

impl ArxModel {
    /// Writes the regressors of sample `t` of the standardized inputs `z_u` (`n × 7`).
    fn regressors(&self, z_u: &[f64], t: usize, x: &mut [f64]) {
        let s = &self.settings;
        x[0] = 1.0;
        for k in 0..s.n_lags {
            let dst = &mut x[1 + k * N_INPUT..1 + (k + 1) * N_INPUT];
            match t.checked_sub(k * s.stride) {
                Some(tk) => dst.copy_from_slice(&z_u[tk * N_INPUT..(tk + 1) * N_INPUT]),
                None => dst.fill(0.0),
            }
        }
    }

    fn standardized_inputs(&self, t: &Trajectory) -> Vec<f64> {
        t.inputs
            .iter()
            .flat_map(|u| {
                (0..N_INPUT).map(move |j| (u[j] - self.input_mean[j]) / self.input_std[j])
            })
            .collect()
    }

    /// Fits `settings` by ridge-regularized least squares on every sample of `ds`'s training
    /// trajectories (module docs).
    ///
    /// # Errors
    /// [`ArxError::Setting`] for settings out of range; [`ArxError::Dataset`] for a dataset
    /// without training outputs; [`ArxError::Singular`] for normal equations that are not
    /// positive definite.
    pub fn fit(settings: &ArxSettings, ds: &ValidDataset) -> Result<Self, ArxError> {
        settings.check()?;
        let stats = ds.standardization()?;
        let mut model = ArxModel {
            settings: *settings,
            input_mean: stats.mean_u,
            input_std: stats.std_u,
            output_mean: stats.mean_y,
            output_std: stats.std_y,
            coefficients: Vec::new(),
        };
        let p = settings.n_regressors();
        let mut xtx = Mat::<f64>::zeros(p, p);
        let mut xty = Mat::<f64>::zeros(p, N_OUTPUT);
        let mut x = vec![0.0; p];
        let mut n_rows = 0usize;
        for t in ds.train() {
            let Some(y) = &t.outputs else { continue };
            let z_u = model.standardized_inputs(t);
            for (i, y_row) in y.iter().enumerate() {
                model.regressors(&z_u, i, &mut x);
                for a in 0..p {
                    let xa = x[a];
                    for b in 0..=a {
                        xtx[(a, b)] += xa * x[b];
                    }
                    for (j, yj) in y_row.iter().enumerate() {
                        xty[(a, j)] += xa * (yj - stats.mean_y[j]) / stats.std_y[j];
                    }
                }
                n_rows += 1;
            }
        }
        if n_rows == 0 {
            return Err(flapssm_wing::dataset::DatasetError::NoOutputs.into());
        }
        for a in 0..p {
            xtx[(a, a)] += settings.ridge * n_rows as f64;
            for b in 0..a {
                xtx[(b, a)] = xtx[(a, b)];
            }
        }
        let llt = xtx
            .llt(Side::Lower)
            .map_err(|e| ArxError::Singular(format!("{e:?}")))?;
        let beta = llt.solve(&xty);
        model.coefficients = (0..p)
            .flat_map(|a| (0..N_OUTPUT).map(move |j| (a, j)))
            .map(|(a, j)| beta[(a, j)])
            .collect();
        Ok(model)
    }

    /// The predicted loads of `trajectory` (N, N·mm), row-major `n × 5` into `mean`.
    ///
    /// # Errors
    /// [`ArxError::Shape`] when `mean` does not hold `n × 5` values.
    pub fn predict_into(&self, trajectory: &Trajectory, mean: &mut [f64]) -> Result<(), ArxError> {
        let n = trajectory.inputs.len();
        if mean.len() != n * N_OUTPUT {
            return Err(ArxError::Shape {
                expected: n * N_OUTPUT,
                found: mean.len(),
            });
        }
        let p = self.settings.n_regressors();
        let z_u = self.standardized_inputs(trajectory);
        let mut x = vec![0.0; p];
        for (t, y) in mean.chunks_exact_mut(N_OUTPUT).enumerate() {
            self.regressors(&z_u, t, &mut x);
            for (j, yj) in y.iter_mut().enumerate() {
                let z: f64 = (0..p)
                    .map(|a| x[a] * self.coefficients[a * N_OUTPUT + j])
                    .sum();
                *yj = self.output_mean[j] + self.output_std[j] * z;
            }
        }
        Ok(())
    }
}
#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};

    fn dataset() -> ValidDataset {
        let mut cfg = SimulationConfig::default();
        cfg.trajectories.n_trajectories = 5;
        cfg.trajectories.n_train = 4;
        cfg.trajectories.seed = 2;
        simulate_dataset(&cfg, &|| {}).unwrap()
    }

    /// Loads that are an exact FIR function of the inputs are recovered: y = 2 u₀(t) − u₃(t − 4)
    /// (output 0, raw units) and 0.5 u₁(t − 2) (output 1), with lags 0..=4 (inputs before the
    /// first sample at their training mean, as the model takes them).
    #[test]
    fn recovers_a_known_fir_system() {
        let mut ds = dataset().into_inner();
        let mean_u = ds.standardization().unwrap().mean_u;
        for t in &mut ds.trajectories {
            let u = t.inputs.clone();
            let y = t.outputs.as_mut().unwrap();
            for (i, row) in y.iter_mut().enumerate() {
                let lag = |k: usize, j: usize| i.checked_sub(k).map_or(mean_u[j], |i| u[i][j]);
                *row = [0.0; 5];
                row[0] = 2.0 * u[i][0] - lag(4, 3);
                row[1] = 0.5 * lag(2, 1);
                row[2] = u[i][6];
                row[3] = u[i][4];
                row[4] = u[i][5];
            }
        }
        let settings = ArxSettings {
            n_lags: 5,
            stride: 1,
            ridge: 0.0,
        };
        let ds = ValidDataset::new(ds).unwrap();
        let m = ArxModel::fit(&settings, &ds).unwrap();
        let t = &ds.trajectories[4];
        let n = t.inputs.len();
        let mut mean = vec![0.0; n * 5];
        m.predict_into(t, &mut mean).unwrap();
        let y = t.outputs.as_ref().unwrap();
        let scale = y
            .iter()
            .flat_map(|r| r.iter())
            .fold(0.0f64, |a, v| a.max(v.abs()));
        for i in 0..n {
            for j in 0..5 {
                let e = (mean[i * 5 + j] - y[i][j]).abs();
                assert!(e < 1e-8 * scale, "sample {i} output {j}: error {e}");
            }
        }
    }

    #[test]
    fn bad_settings_are_named() {
        let e = ArxSettings {
            n_lags: 0,
            ..ArxSettings::default()
        }
        .check()
        .unwrap_err();
        assert!(e.to_string().contains("arx.n_lags"), "{e}");
        let e = ArxSettings {
            ridge: -1.0,
            ..ArxSettings::default()
        }
        .check()
        .unwrap_err();
        assert!(e.to_string().contains("arx.ridge"), "{e}");
    }
}
