//! The ARX baseline ([`flapssm_qs::arx`]) as a load model: its registry entry, its settings
//! checked once, fitted with progress, predicting into the evaluation's buffers.

use flapssm_qs::arx::{ArxModel, ArxSettings};
use flapssm_wing::dataset::{Trajectory, ValidDataset};

use super::{Baseline, Fit, LoadModel, LoadPrediction};
use crate::error::Result;
use crate::progress::Progress;

/// The registry entry ([`super::BASELINES`]): ARX with [`ArxSettings::default`].
pub const BASELINE: Baseline = Baseline {
    key: "arx",
    about: "ARX: least squares on 21 lags of the standardized inputs, 2 samples apart",
    fit: |ds, progress| {
        Ok(Box::new(
            checked(ArxSettings::default())?.fit(ds, progress)?,
        ))
    },
};

/// Validated [`ArxSettings`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ArxFit {
    settings: ArxSettings,
}

/// `settings` checked once, before any work.
///
/// # Errors
/// [`crate::JobError::Arx`] naming the setting out of range.
pub fn checked(settings: ArxSettings) -> Result<ArxFit> {
    settings.check()?;
    Ok(ArxFit { settings })
}

impl Fit for ArxFit {
    type Model = ArxModel;

    fn fit(&self, ds: &ValidDataset, progress: &dyn Progress) -> Result<ArxModel> {
        progress.start("fit ARX", 0);
        let model = ArxModel::fit(&self.settings, ds)?;
        progress.finish("");
        Ok(model)
    }
}

impl LoadModel for ArxModel {
    fn name(&self) -> &str {
        "ARX"
    }

    fn key(&self) -> &str {
        "arx"
    }

    fn parameters(&self) -> serde_json::Value {
        serde_json::json!({
            "settings": self.settings,
            "n_coefficients": self.coefficients.len(),
        })
    }

    fn predict_into(
        &self,
        _index: usize,
        trajectory: &Trajectory,
        out: LoadPrediction<'_>,
    ) -> Result<()> {
        Ok(ArxModel::predict_into(self, trajectory, out.mean)?)
    }
}
