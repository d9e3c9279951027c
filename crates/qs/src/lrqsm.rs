//! The LRQSM on a flapssm dataset ([`ValidDataset`]): fit on the training trajectories, predict all.
//!
//! Rows are the samples of the trajectories in order (trajectory-major), so contiguous CV
//! folds hold whole trajectories up to the fold boundaries. Features are those of a
//! [`FeatureSet`] computed from the raw inputs u; targets are the outputs standardized with
//! the training statistics (ddof 0): ỹ_t = (y_t − ȳ_t) / σ_t, as the published `ds_y`.

use std::path::Path;

use flapssm_data::npz::{NpyData, NpzWriter};
use flapssm_wing::dataset::{OUTPUT_NAMES, Trajectory, ValidDataset};
use flapssm_wing::features::FeatureSet;

use crate::cv::{Columns, EnetOptions, fit_enet_cv};
use crate::error::QsError;
use crate::model::{InterceptMode, LrqsmModel, TargetScaling};

/// Features of every sample of `trajectories`, row-major `(Σ n_t) × set.len()`.
pub fn trajectory_features(trajectories: &[Trajectory], set: FeatureSet) -> Vec<f64> {
    let p = set.len();
    let n: usize = trajectories.iter().map(Trajectory::len).sum();
    let mut x = vec![0.0; n * p];
    for (row, u) in x
        .chunks_exact_mut(p)
        .zip(trajectories.iter().flat_map(|t| t.inputs.iter()))
    {
        set.compute_into(u, row);
    }
    x
}

/// Fits one elastic net per output on the training trajectories of `ds`, targets standardized
/// with the training statistics. `source` names the dataset in the model file.
///
/// # Errors
/// A dataset without outputs, and every error of [`fit_enet_cv`].
pub fn fit_dataset(
    ds: &ValidDataset,
    set: FeatureSet,
    opts: &EnetOptions,
    source: &str,
) -> Result<LrqsmModel, QsError> {
    let stats = ds.standardization()?;
    let train = ds.train();
    let x = trajectory_features(train, set);
    let mut y = Vec::with_capacity(x.len() / set.len() * 5);
    for t in train {
        for row in t.outputs.as_deref().unwrap_or_default() {
            y.extend_from_slice(&stats.normalize_y(row));
        }
    }
    let feature_names: Vec<String> = set.names().iter().map(|s| s.to_string()).collect();
    let target_names: Vec<String> = OUTPUT_NAMES.iter().map(|s| s.to_string()).collect();
    let fit = fit_enet_cv(
        Columns {
            names: &feature_names,
            data: &x,
        },
        Columns {
            names: &target_names,
            data: &y,
        },
        opts,
    )?;
    let scaling = TargetScaling {
        mean: stats.mean_y.to_vec(),
        std: stats.std_y.to_vec(),
    };
    Ok(LrqsmModel::new(
        fit,
        *opts,
        Some(set),
        Some(scaling),
        source,
    ))
}

/// Root-mean-square errors per output, raw units (N, N·mm) and standardized.
#[derive(Debug, Clone, PartialEq)]
pub struct Rmse {
    /// Samples compared.
    pub n_samples: usize,
    /// RMSE per output in output units.
    pub raw: Vec<f64>,
    /// RMSE per output on the standardized scale (raw / σ_t).
    pub standardized: Vec<f64>,
}

/// Predictions of a model for every trajectory of a dataset.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetPrediction {
    /// Trajectories.
    pub n_trajectories: usize,
    /// Samples per trajectory.
    pub n_samples: usize,
    /// The first `n_train` trajectories are the training set.
    pub n_train: usize,
    /// Output names.
    pub output_names: Vec<String>,
    /// Predicted outputs in raw units, `[n_trajectories, n_samples, m]` row-major.
    pub raw: Vec<f64>,
    /// Predicted standardized outputs, same shape.
    pub standardized: Vec<f64>,
    /// Whether the fitted intercept was added.
    pub intercept: bool,
    /// Errors on the training trajectories (if the dataset has outputs and training data).
    pub rmse_train: Option<Rmse>,
    /// Errors on the test trajectories (if the dataset has outputs and test data).
    pub rmse_test: Option<Rmse>,
}

/// Applies a dataset model (fitted by [`fit_dataset`]) to every trajectory of `ds`.
///
/// # Errors
/// [`QsError::Mismatch`] for a model without a wing feature set or output scaling, or whose
/// outputs are not the dataset's.
pub fn predict_dataset(
    model: &LrqsmModel,
    ds: &ValidDataset,
    mode: InterceptMode,
) -> Result<DatasetPrediction, QsError> {
    let (Some(set), Some(scaling)) = (model.feature_set, &model.target_scaling) else {
        return Err(QsError::Mismatch(
            "the model was fitted on custom columns (fit-csv), not on a dataset's wing features"
                .into(),
        ));
    };
    let names: Vec<String> = model.chosen.iter().map(|c| c.name.clone()).collect();
    if names.iter().ne(OUTPUT_NAMES.iter()) {
        return Err(QsError::Mismatch(format!(
            "model outputs {names:?} are not the dataset outputs {OUTPUT_NAMES:?}"
        )));
    }
    let m = names.len();
    let n_t = ds.n_samples();
    let x = trajectory_features(&ds.trajectories, set);
    let mut standardized = vec![0.0; x.len() / set.len() * m];
    for (row, out) in x
        .chunks_exact(set.len())
        .zip(standardized.chunks_exact_mut(m))
    {
        model.predict_row(row, mode, out);
    }
    let raw: Vec<f64> = standardized
        .chunks_exact(m)
        .flat_map(|z| (0..m).map(move |t| scaling.mean[t] + scaling.std[t] * z[t]))
        .collect();
    let rmse = |range: std::ops::Range<usize>| -> Option<Rmse> {
        let mut sse = vec![0.0; m];
        let mut n = 0;
        for k in range {
            let y = ds.trajectories[k].outputs.as_ref()?;
            for (i, row) in y.iter().enumerate() {
                let base = (k * n_t + i) * m;
                for t in 0..m {
                    let e = raw[base + t] - row[t];
                    sse[t] += e * e;
                }
            }
            n += y.len();
        }
        (n > 0).then(|| {
            let raw: Vec<f64> = sse.iter().map(|s| (s / n as f64).sqrt()).collect();
            Rmse {
                n_samples: n,
                standardized: raw.iter().zip(&scaling.std).map(|(r, s)| r / s).collect(),
                raw,
            }
        })
    };
    let n_train = ds.n_train.min(ds.len());
    Ok(DatasetPrediction {
        n_trajectories: ds.len(),
        n_samples: n_t,
        n_train,
        output_names: names,
        rmse_train: rmse(0..n_train),
        rmse_test: rmse(n_train..ds.len()),
        raw,
        standardized,
        intercept: mode == InterceptMode::Fitted,
    })
}

impl DatasetPrediction {
    /// Writes the predictions as `.npz`, atomically:
    ///
    /// | array | shape | meaning |
    /// |---|---|---|
    /// | `y_pred` | `[n_traj, n_t, 5]` | predicted outputs (N, N·mm) |
    /// | `y_pred_standardized` | `[n_traj, n_t, 5]` | predicted standardized outputs |
    /// | `is_train` | `[n_traj]` | training trajectory flags |
    /// | `output_names` | `[5]` | |
    /// | `intercept` | () | whether the intercept was added |
    /// | `rmse_train`, `rmse_test` | `[5]` | RMSE in output units (absent without outputs/data) |
    /// | `rmse_train_standardized`, `rmse_test_standardized` | `[5]` | RMSE / σ_y |
    ///
    /// # Errors
    /// [`QsError::Io`] on write failure.
    pub fn save_npz(&self, path: &Path) -> Result<(), QsError> {
        let m = self.output_names.len();
        let shape = [self.n_trajectories, self.n_samples, m];
        let mut w = NpzWriter::new();
        w.add("y_pred", &shape, NpyData::F64(self.raw.clone()))
            .add(
                "y_pred_standardized",
                &shape,
                NpyData::F64(self.standardized.clone()),
            )
            .add(
                "is_train",
                &[self.n_trajectories],
                NpyData::Bool((0..self.n_trajectories).map(|k| k < self.n_train).collect()),
            )
            .add(
                "output_names",
                &[m],
                NpyData::Str(self.output_names.clone()),
            )
            .add("intercept", &[], NpyData::Bool(vec![self.intercept]));
        for (name, r) in [("train", &self.rmse_train), ("test", &self.rmse_test)] {
            if let Some(r) = r {
                w.add(&format!("rmse_{name}"), &[m], NpyData::F64(r.raw.clone()));
                w.add(
                    &format!("rmse_{name}_standardized"),
                    &[m],
                    NpyData::F64(r.standardized.clone()),
                );
            }
        }
        w.save(path).map_err(|e| QsError::Io {
            path: path.to_path_buf(),
            source: std::io::Error::other(e.to_string()),
        })
    }
}
