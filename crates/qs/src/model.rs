//! The LRQSM model file: a versioned JSON document with the features, their standardization,
//! the target scaling, the fitted paths, CV curves, the chosen λ per output and the options.
//!
//! Prediction on the fitted-target scale (standardized outputs for dataset fits):
//! ŷ_t = b₀_t + Σ_j x_j b_tj with b on the original feature scale, or, with
//! [`InterceptMode::Dropped`] (the published `y = x*LRmodel`), ŷ_t = Σ_j x_j b_tj.

use std::path::Path;

use flapssm_data::atomic::write_bytes_atomic;
use flapssm_wing::features::FeatureSet;
use serde::{Deserialize, Serialize};

use crate::cv::{EnetCvFit, EnetOptions};
use crate::error::QsError;

/// Value of the `kind` field of every model file.
pub const MODEL_KIND: &str = "flapssm-lrqsm";
/// Model file format version written (and the only one read) by this build.
pub const MODEL_FORMAT_VERSION: u32 = 1;

/// Affine scaling of the raw outputs into the fitted targets: target = (y − mean) / std.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TargetScaling {
    /// Raw output means (output units, e.g. N, N·mm), training set.
    pub mean: Vec<f64>,
    /// Raw output population standard deviations (ddof 0), training set, > 0.
    pub std: Vec<f64>,
}

/// The chosen model of one output, copied from its path for readability.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChosenFit {
    /// Output name.
    pub name: String,
    /// Index into the λ path.
    pub index: usize,
    /// Chosen λ.
    pub lambda: f64,
    /// Coefficients on the standardized features.
    pub coef_standardized: Vec<f64>,
    /// Coefficients on the original features (the published `LRmodel` column).
    pub coef: Vec<f64>,
    /// Intercept on the fitted-target scale.
    pub intercept: f64,
}

/// Whether prediction adds the fitted intercept.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum InterceptMode {
    /// ŷ = b₀ + xᵀb.
    Fitted,
    /// ŷ = xᵀb, as the published `y = x*LRmodel`: MATLAB's `lasso` centres the data and returns
    /// an intercept, which the published code does not add (the default, the published
    /// baseline).
    #[default]
    Dropped,
}

/// Model files written before [`LrqsmModel::prediction_intercept`] existed predicted with the
/// intercept.
fn fitted() -> InterceptMode {
    InterceptMode::Fitted
}

/// A fitted linear-regression quasi-steady model (LRQSM).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct LrqsmModel {
    /// Always [`MODEL_KIND`].
    pub kind: String,
    /// Always [`MODEL_FORMAT_VERSION`].
    pub format_version: u32,
    /// The wing feature set, or `None` for custom feature columns.
    pub feature_set: Option<FeatureSet>,
    /// Scaling of raw outputs into targets, or `None` if the targets were fitted as given.
    pub target_scaling: Option<TargetScaling>,
    /// What the model was fitted on (file name).
    pub source: String,
    /// Options of the fit.
    pub options: EnetOptions,
    /// Whether the model's predictions add the fitted intercept (default dropped, as published).
    #[serde(default = "fitted")]
    pub prediction_intercept: InterceptMode,
    /// Chosen model per output.
    pub chosen: Vec<ChosenFit>,
    /// Paths, CV curves and standardization.
    pub fit: EnetCvFit,
}

impl LrqsmModel {
    /// Wraps a fit into a model.
    pub fn new(
        fit: EnetCvFit,
        options: EnetOptions,
        feature_set: Option<FeatureSet>,
        target_scaling: Option<TargetScaling>,
        source: impl Into<String>,
    ) -> Self {
        let chosen = fit
            .targets
            .iter()
            .map(|t| ChosenFit {
                name: t.name.clone(),
                index: t.index_chosen,
                lambda: t.lambda(),
                coef_standardized: t.coef_standardized().to_vec(),
                coef: t.coef().to_vec(),
                intercept: t.intercept(),
            })
            .collect();
        Self {
            kind: MODEL_KIND.to_string(),
            format_version: MODEL_FORMAT_VERSION,
            feature_set,
            target_scaling,
            source: source.into(),
            options,
            prediction_intercept: InterceptMode::default(),
            chosen,
            fit,
        }
    }

    /// Number of features p.
    pub fn n_features(&self) -> usize {
        self.fit.feature_names.len()
    }

    /// Predicts every output for one feature row (length p) into `out` (length m), on the
    /// fitted-target scale, adding the intercept as `mode` says (the model's own choice is
    /// [`prediction_intercept`](Self::prediction_intercept)).
    pub fn predict_row(&self, features: &[f64], mode: InterceptMode, out: &mut [f64]) {
        for (o, c) in out.iter_mut().zip(&self.chosen) {
            let lin: f64 = c.coef.iter().zip(features).map(|(b, x)| b * x).sum();
            *o = match mode {
                InterceptMode::Fitted => c.intercept + lin,
                InterceptMode::Dropped => lin,
            };
        }
    }

    /// Writes the model as pretty JSON, atomically.
    ///
    /// # Errors
    /// [`QsError::Io`] on write failure.
    pub fn save(&self, path: &Path) -> Result<(), QsError> {
        let bytes = serde_json::to_vec_pretty(self).map_err(|e| QsError::ModelFormat {
            path: path.to_path_buf(),
            message: e.to_string(),
        })?;
        write_bytes_atomic(path, &bytes).map_err(|source| QsError::Io {
            path: path.to_path_buf(),
            source,
        })
    }

    /// Reads and validates a model file.
    ///
    /// # Errors
    /// [`QsError::Io`], [`QsError::ModelVersion`] for another format version, or
    /// [`QsError::ModelFormat`] naming the malformed field.
    pub fn load(path: &Path) -> Result<Self, QsError> {
        let text = std::fs::read_to_string(path).map_err(|source| QsError::Io {
            path: path.to_path_buf(),
            source,
        })?;
        Self::from_json(&text, path)
    }

    /// Parses and validates model JSON; `path` is only used in messages.
    ///
    /// # Errors
    /// As [`Self::load`].
    pub fn from_json(text: &str, path: &Path) -> Result<Self, QsError> {
        let bad = |message: String| QsError::ModelFormat {
            path: path.to_path_buf(),
            message,
        };
        let value: serde_json::Value =
            serde_json::from_str(text).map_err(|e| bad(e.to_string()))?;
        match value.get("kind").and_then(|k| k.as_str()) {
            Some(MODEL_KIND) => {}
            other => {
                return Err(bad(format!(
                    "field 'kind' is {other:?}, expected \"{MODEL_KIND}\""
                )));
            }
        }
        let version = value
            .get("format_version")
            .and_then(|v| v.as_u64())
            .ok_or_else(|| bad("field 'format_version' is missing or not an integer".into()))?;
        if version != u64::from(MODEL_FORMAT_VERSION) {
            return Err(QsError::ModelVersion {
                path: path.to_path_buf(),
                found: version,
                supported: MODEL_FORMAT_VERSION,
            });
        }
        let model: Self = serde_json::from_value(value).map_err(|e| bad(e.to_string()))?;
        model.check().map_err(bad)?;
        Ok(model)
    }

    /// Internal consistency: every array has the size its counts say.
    fn check(&self) -> Result<(), String> {
        let fit = &self.fit;
        let p = fit.feature_names.len();
        if p == 0 {
            return Err("fit.feature_names is empty".into());
        }
        if let Some(set) = self.feature_set {
            if set.names().iter().ne(fit.feature_names.iter()) {
                return Err(format!(
                    "fit.feature_names {:?} do not match feature_set {set:?}",
                    fit.feature_names
                ));
            }
        }
        for (field, len) in [
            ("fit.feature_center", fit.feature_center.len()),
            ("fit.feature_scale", fit.feature_scale.len()),
        ] {
            if len != p {
                return Err(format!("{field} has {len} entries, expected {p}"));
            }
        }
        if let Some(j) = fit
            .feature_scale
            .iter()
            .position(|s| !(*s > 0.0 && s.is_finite()))
        {
            return Err(format!("fit.feature_scale[{j}] is not positive"));
        }
        let m = fit.targets.len();
        if m == 0 || self.chosen.len() != m || fit.target_center.len() != m {
            return Err(format!(
                "{m} target paths, {} chosen fits and {} target centres must agree and be nonzero",
                self.chosen.len(),
                fit.target_center.len()
            ));
        }
        if let Some(s) = &self.target_scaling {
            if s.mean.len() != m || s.std.len() != m {
                return Err(format!("target_scaling must have {m} means and stds"));
            }
            if let Some(t) = s.std.iter().position(|v| !(*v > 0.0 && v.is_finite())) {
                return Err(format!("target_scaling.std[{t}] is not positive"));
            }
        }
        for (t, (path, ch)) in fit.targets.iter().zip(&self.chosen).enumerate() {
            let nl = path.lambdas.len();
            let rows_ok =
                |rows: &Vec<Vec<f64>>| rows.len() == nl && rows.iter().all(|r| r.len() == p);
            if nl == 0
                || !rows_ok(&path.coef_path)
                || !rows_ok(&path.coef_path_standardized)
                || path.intercept_path.len() != nl
                || path.cv_mse_mean.len() != nl
                || path.cv_mse_se.len() != nl
            {
                return Err(format!(
                    "fit.targets[{t}] ('{}'): path arrays must be {nl} λ × {p} features",
                    path.name
                ));
            }
            if [path.index_min, path.index_1se, path.index_chosen]
                .iter()
                .any(|&i| i >= nl)
            {
                return Err(format!("fit.targets[{t}]: an index is beyond the {nl} λ"));
            }
            let expect = ChosenFit {
                name: path.name.clone(),
                index: path.index_chosen,
                lambda: path.lambda(),
                coef_standardized: path.coef_standardized().to_vec(),
                coef: path.coef().to_vec(),
                intercept: path.intercept(),
            };
            if *ch != expect {
                return Err(format!(
                    "chosen[{t}] ('{}') does not match fit.targets[{t}] at index {}",
                    ch.name, path.index_chosen
                ));
            }
        }
        Ok(())
    }
}
