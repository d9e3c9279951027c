//! Open-loop predictions of the PR-SSM: every trajectory of a dataset (mean, variance, latent
//! moments), or one table of inputs.
//!
//! PR-SSM draws: trajectory `i` uses seed [`crate::seed::prediction_seed`]`(seed, i)`, so the
//! same seed gives the same draws whichever job predicts.

use std::path::Path;

use flapssm_data::npz::{NpyData, NpzWriter};
use flapssm_prssm::PrssmModel;
use flapssm_prssm::predict::Prediction;
use flapssm_wing::dataset::ValidDataset;

use crate::adapters::{input_columns, inputs_only_notes};
use crate::error::{JobError, Result};
use crate::models::map_trajectories;
use crate::models::prssm::PrssmLoadModel;
use crate::progress::Progress;
use crate::seed::prediction_seed;

/// Predicts every trajectory of `ds` with the PR-SSM (in parallel on the caller's rayon pool;
/// results do not depend on threading): output means (N, N·mm) and variances, row-major
/// `n × 5`; latent means and variances (standardized), `n × D_x`. `progress.advance(1)` per
/// trajectory.
///
/// # Errors
/// [`JobError::Mismatch`] for a model that is not 7 → 5, [`JobError::Prssm`] naming
/// the trajectory.
pub fn predict_prssm(
    model: &PrssmModel,
    ds: &ValidDataset,
    particles: usize,
    seed: u64,
    progress: &dyn Progress,
) -> Result<Vec<Prediction>> {
    let model = PrssmLoadModel::new(model, ds, particles, seed)?;
    map_trajectories(ds, |i, t| {
        let p = model.predict(i, t)?;
        progress.advance(1);
        Ok(p)
    })
}

/// What [`predict_dataset_file`] did.
#[derive(Debug, Clone, PartialEq)]
pub struct DatasetPredictionSummary {
    /// Trajectories predicted.
    pub n_trajectories: usize,
    /// Samples per trajectory.
    pub n_samples: usize,
    /// Notes for the user (e.g. whose statistics standardized the data).
    pub notes: Vec<String>,
}

/// `flapssm predict MODEL DATASET`: predicts every trajectory of `ds` ([`predict_prssm`]) and
/// writes `out` (.npz, atomically): `output_mean`, `output_var` (`n_traj × T × 5`, N and N·mm),
/// `latent_mean`, `latent_var` (`n_traj × T × D_x`, standardized), `is_train` (`n_traj`) and
/// `y` (the dataset's outputs, when it has them). A model without normalization statistics (the
/// published one) works in standardized units: `ds`'s training statistics are used, and a
/// note says so.
///
/// # Errors
/// A model that is not 7 → 5, one without statistics on a dataset without outputs, prediction
/// and file errors naming the trajectory or file.
pub fn predict_dataset_file(
    model: &PrssmModel,
    ds: &ValidDataset,
    particles: usize,
    seed: u64,
    out: &Path,
    progress: &dyn Progress,
) -> Result<DatasetPredictionSummary> {
    let mut notes = Vec::new();
    if model.normalization.is_none() {
        notes.push(
            "the model has no normalization statistics; standardizing with the dataset's \
             training statistics"
                .into(),
        );
    }
    let (n, t_n, dx) = (ds.len(), ds.n_samples(), model.config.n_state);
    progress.start("predict", n as u64);
    let preds = predict_prssm(model, ds, particles, seed, progress)?;
    progress.finish("");
    let cat =
        |f: fn(&Prediction) -> &[f64]| NpyData::F64(preds.iter().flat_map(f).copied().collect());
    let mut w = NpzWriter::new();
    w.add("output_mean", &[n, t_n, 5], cat(|p| &p.output_mean))
        .add("output_var", &[n, t_n, 5], cat(|p| &p.output_var))
        .add("latent_mean", &[n, t_n, dx], cat(|p| &p.latent_mean))
        .add("latent_var", &[n, t_n, dx], cat(|p| &p.latent_var))
        .add(
            "is_train",
            &[n],
            NpyData::Bool((0..n).map(|i| i < ds.n_train).collect()),
        );
    if ds.has_outputs() {
        let y: Vec<f64> = ds
            .trajectories
            .iter()
            .flat_map(|t| t.outputs.as_deref().unwrap_or_default().as_flattened())
            .copied()
            .collect();
        w.add("y", &[n, t_n, 5], NpyData::F64(y));
    }
    w.save(out).map_err(|e| JobError::Io {
        path: out.to_path_buf(),
        source: std::io::Error::other(e.to_string()),
    })?;
    Ok(DatasetPredictionSummary {
        n_trajectories: n,
        n_samples: t_n,
        notes,
    })
}

/// A prediction from an input table, with notes for the user.
#[derive(Debug, Clone, PartialEq)]
pub struct InputsPrediction {
    /// Output and latent moments (outputs in the model's units).
    pub prediction: Prediction,
    /// Every particle, `T × P × D_x` row-major (standardized latent units), when asked for.
    pub particles: Option<Vec<f64>>,
    /// Notes (e.g. an initial-state rule that the inputs alone cannot apply).
    pub notes: Vec<String>,
}

/// `flapssm predict MODEL --inputs U.csv`: [`predict_inputs`] on a CSV table with a header line,
/// its columns matched to the model's inputs by [`input_columns`].
///
/// # Errors
/// The table's errors naming the file, line and column; [`input_columns`]' errors; prediction
/// errors.
pub fn predict_input_file(
    model: &PrssmModel,
    path: &Path,
    particles: usize,
    seed: u64,
) -> Result<InputsPrediction> {
    let table = flapssm_data::table::Table::read_csv(path)?;
    let cols = input_columns(&table.names, model.config.n_input)?;
    let rows: Vec<f64> = (0..table.n_rows())
        .flat_map(|t| cols.iter().map(move |&c| (c, t)))
        .map(|(c, t)| table.columns[c][t])
        .collect();
    predict_inputs(model, &rows, cols.len(), particles, seed)
}

/// `flapssm predict MODEL --inputs U.csv`: open-loop prediction from `inputs` (row-major
/// `T × n_columns`, physical units when the model has normalization statistics, else
/// standardized) with draws seeded by [`prediction_seed`]`(seed, 0)`, from `x₀ = 0`.
///
/// # Errors
/// [`JobError::Mismatch`] when `n_columns` is not the model's input count; prediction errors.
pub fn predict_inputs(
    model: &PrssmModel,
    inputs: &[f64],
    n_columns: usize,
    particles: usize,
    seed: u64,
) -> Result<InputsPrediction> {
    predict_inputs_kept(model, inputs, n_columns, particles, seed, false)
}

/// [`predict_inputs`] that, with `keep_particles`, also returns every particle
/// ([`InputsPrediction::particles`]); the moments are the same.
///
/// # Errors
/// As [`predict_inputs`]; a particle history larger than memory is refused up front.
pub fn predict_inputs_kept(
    model: &PrssmModel,
    inputs: &[f64],
    n_columns: usize,
    particles: usize,
    seed: u64,
    keep_particles: bool,
) -> Result<InputsPrediction> {
    let du = model.config.n_input;
    if n_columns != du {
        return Err(JobError::Mismatch {
            what: "input columns".into(),
            expected: format!("the model's D_u = {du} inputs"),
            found: format!("{n_columns} columns"),
        });
    }
    let kept = if keep_particles {
        (inputs.len() / du.max(1)) as f64 * (particles * model.config.n_state * 8) as f64
    } else {
        0.0
    };
    crate::resources::check_prediction(&model.config, particles, 1, kept)?;
    let notes = inputs_only_notes(model);
    let (prediction, particles) = model
        .predict_inputs_kept(inputs, particles, prediction_seed(seed, 0), keep_particles)
        .map_err(|e| JobError::Prssm {
            what: "prediction".into(),
            source: e.into(),
        })?;
    Ok(InputsPrediction {
        prediction,
        particles,
        notes,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use crate::test_data::{bare_model, tiny_dataset};

    #[test]
    /// Regression: a model without normalization statistics (the published one works in
    /// standardized units) used to receive raw inputs. It must predict exactly as the same
    /// model carrying the dataset's training statistics.
    fn a_model_without_statistics_uses_the_dataset_training_statistics() {
        let ds = tiny_dataset();
        let bare = bare_model(flapssm_prssm::ModelConfig::new(6, 5, 7, 4), 3);
        let s = ds.standardization().unwrap();
        let mut with_stats = bare.clone();
        with_stats.normalization = Some(flapssm_prssm::Normalization {
            input_mean: s.mean_u.to_vec(),
            input_std: s.std_u.to_vec(),
            output_mean: s.mean_y.to_vec(),
            output_std: s.std_y.to_vec(),
        });
        let a = predict_prssm(&bare, &ds, 3, 5, &NoProgress).unwrap();
        let b = predict_prssm(&with_stats, &ds, 3, 5, &NoProgress).unwrap();
        assert_eq!(a.len(), b.len());
        for (x, y) in a.iter().zip(&b) {
            assert_eq!(x.output_mean, y.output_mean);
            assert_eq!(x.output_var, y.output_var);
        }
        // Raw inputs fed as if standardized would differ.
        let mut raw = bare.clone();
        raw.normalization = Some(flapssm_prssm::Normalization {
            input_mean: vec![0.0; 7],
            input_std: vec![1.0; 7],
            output_mean: vec![0.0; 5],
            output_std: vec![1.0; 5],
        });
        let c = predict_prssm(&raw, &ds, 3, 5, &NoProgress).unwrap();
        assert_ne!(a[0].output_mean, c[0].output_mean);
    }

    #[test]
    fn model_of_the_wrong_shape_is_rejected() {
        let ds = tiny_dataset();
        let m = bare_model(flapssm_prssm::ModelConfig::new(4, 2, 3, 5), 1);
        let e = predict_prssm(&m, &ds, 2, 0, &NoProgress).unwrap_err();
        assert!(e.to_string().contains("7 inputs and 5 outputs"), "{e}");
    }
}
