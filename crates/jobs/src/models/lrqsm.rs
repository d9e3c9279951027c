//! The LRQSM as a [`LoadModel`]: the elastic-net fit on quasi-steady features, with its fitted
//! intercept, in the dataset's units.

use std::borrow::Cow;
use std::path::Path;

use flapssm_qs::lrqsm::{DatasetPrediction, fit_dataset, predict_dataset, trajectory_features};
use flapssm_qs::{EnetOptions, InterceptMode, LrqsmModel};
use flapssm_wing::dataset::{OUTPUT_NAMES, Trajectory, ValidDataset};
use flapssm_wing::features::FeatureSet;

use super::{Fit, LoadModel, LoadPrediction, check_buffer};
use crate::error::{JobError, Result};
use crate::progress::Progress;

/// An LRQSM fitted on a dataset's wing features (not on custom CSV columns).
#[derive(Debug, Clone)]
pub struct LrqsmLoadModel<'m> {
    model: Cow<'m, LrqsmModel>,
    features: FeatureSet,
}

impl<'m> LrqsmLoadModel<'m> {
    /// Wraps `model`.
    ///
    /// # Errors
    /// [`JobError::Qs`] for a model fitted on custom columns or on other outputs.
    pub fn new(model: &'m LrqsmModel) -> Result<Self> {
        Self::from_cow(Cow::Borrowed(model))
    }

    fn from_cow(model: Cow<'m, LrqsmModel>) -> Result<Self> {
        let (Some(features), Some(_)) = (model.feature_set, &model.target_scaling) else {
            return Err(flapssm_qs::QsError::Mismatch(
                "the model was fitted on custom columns (fit-csv), not on a dataset's wing \
                 features"
                    .into(),
            )
            .into());
        };
        if model
            .chosen
            .iter()
            .map(|c| c.name.as_str())
            .ne(OUTPUT_NAMES)
        {
            return Err(JobError::Mismatch {
                what: "LRQSM outputs".into(),
                expected: format!("{OUTPUT_NAMES:?}"),
                found: format!(
                    "{:?}",
                    model.chosen.iter().map(|c| &c.name).collect::<Vec<_>>()
                ),
            });
        }
        Ok(Self { model, features })
    }

    /// The fitted model.
    pub fn model(&self) -> &LrqsmModel {
        &self.model
    }
}

impl LoadModel for LrqsmLoadModel<'_> {
    fn name(&self) -> &str {
        "LRQSM"
    }

    fn key(&self) -> &str {
        "lrqsm"
    }

    fn parameters(&self) -> serde_json::Value {
        serde_json::json!({
            "feature_set": self.model.feature_set,
            "options": self.model.options,
            "lambda": self.model.chosen.iter().map(|c| c.lambda).collect::<Vec<_>>(),
        })
    }

    fn predict_into(
        &self,
        _index: usize,
        trajectory: &Trajectory,
        out: LoadPrediction<'_>,
    ) -> Result<()> {
        let n = trajectory.inputs.len();
        check_buffer("LRQSM mean", out.mean, n, 5)?;
        let scaling = self.model.target_scaling.as_ref().ok_or_else(|| {
            flapssm_qs::QsError::Mismatch("the model has no target scaling".into())
        })?;
        let x = trajectory_features(std::slice::from_ref(trajectory), self.features);
        let mut z = [0.0; 5];
        for (row, y) in x
            .chunks_exact(self.features.len())
            .zip(out.mean.chunks_exact_mut(5))
        {
            self.model
                .predict_row(row, self.model.prediction_intercept, &mut z);
            for t in 0..5 {
                y[t] = scaling.mean[t] + scaling.std[t] * z[t];
            }
        }
        Ok(())
    }
}

/// `flapssm qs predict`: the LRQSM's predictions of every trajectory of `ds` with its RMSE on
/// the training and test parts ([`predict_dataset`], intercept as `mode` says), written to `out`
/// (.npz, atomically).
///
/// # Errors
/// [`JobError::Qs`] for a model that does not fit the dataset or a file that cannot be written.
pub fn predict_file(
    model: &LrqsmModel,
    ds: &ValidDataset,
    mode: InterceptMode,
    out: &Path,
) -> Result<DatasetPrediction> {
    let p = predict_dataset(model, ds, mode)?;
    p.save_npz(out)?;
    Ok(p)
}

/// Fits the LRQSM ([`fit_dataset`]) with a feature set and elastic-net options.
#[derive(Debug, Clone)]
pub struct LrqsmFit {
    /// Quasi-steady feature set.
    pub features: FeatureSet,
    /// Elastic-net path and cross-validation options.
    pub options: EnetOptions,
    /// Whether the model's predictions add the fitted intercept (published: dropped).
    pub prediction_intercept: InterceptMode,
    /// Where the data came from (recorded in the model).
    pub source: String,
}

impl Fit for LrqsmFit {
    type Model = LrqsmLoadModel<'static>;

    fn fit(&self, ds: &ValidDataset, progress: &dyn Progress) -> Result<Self::Model> {
        progress.start("fit LRQSM", 0);
        let mut m = fit_dataset(ds, self.features, &self.options, &self.source)?;
        m.prediction_intercept = self.prediction_intercept;
        progress.finish("");
        LrqsmLoadModel::from_cow(Cow::Owned(m))
    }
}

/// `flapssm qs fit-csv`: an elastic net with cross-validation on the columns of a CSV table
/// (a header line of names): `targets` on `features` (default: every other column). The model
/// records the file as its source; it is not a [`LoadModel`] (no wing features).
///
/// # Errors
/// [`JobError::Qs`] naming the file, line and column of a malformed table, an unknown or
/// ambiguous column, and the fit's errors.
pub fn fit_csv(
    path: &Path,
    targets: &[String],
    features: Option<&[String]>,
    options: &EnetOptions,
) -> Result<LrqsmModel> {
    let table = flapssm_qs::table::read_csv(path)?;
    Ok(flapssm_qs::table::fit_table(
        &table, targets, features, options,
    )?)
}
