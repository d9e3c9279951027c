//! [`PrssmModel`]: a trained (or imported) PR-SSM — configuration, parameters, normalization
//! statistics and the training settings — and prediction in physical units.

use serde::{Deserialize, Serialize};

use crate::elbo::{Sequence, SequenceView};
use crate::objective::ObjectiveError;
use crate::params::{ConfigError, ModelConfig, Params};
use crate::predict::{self, Prediction, PredictionError};
use crate::train::initial::{InitialStateModel, InitialStateSpec};

/// Per-channel affine normalization `z = (v − mean) / std` of inputs and outputs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Normalization {
    /// Input means (`D_u`, physical units).
    pub input_mean: Vec<f64>,
    /// Input standard deviations (`D_u`, > 0).
    pub input_std: Vec<f64>,
    /// Output means (`D_y`).
    pub output_mean: Vec<f64>,
    /// Output standard deviations (`D_y`, > 0).
    pub output_std: Vec<f64>,
}

/// `out = (v − mean) / std` of a row-major table whose columns are the channels of `mean`,
/// `std`. Allocates nothing.
fn standardize_into(v: &[f64], mean: &[f64], std: &[f64], out: &mut [f64]) {
    let d = mean.len().max(1);
    for (i, (o, x)) in out.iter_mut().zip(v).enumerate() {
        *o = (x - mean[i % d]) / std[i % d];
    }
}

impl Normalization {
    /// Standardized inputs `(u − mean) / std` of a row-major `T × D_u` table.
    pub fn standardize_inputs(&self, inputs: &[f64]) -> Vec<f64> {
        let mut z = vec![0.0; inputs.len()];
        self.standardize_inputs_into(inputs, &mut z);
        z
    }

    /// [`Self::standardize_inputs`] into `out` (as long as `inputs`). Allocates nothing.
    pub fn standardize_inputs_into(&self, inputs: &[f64], out: &mut [f64]) {
        standardize_into(inputs, &self.input_mean, &self.input_std, out);
    }

    /// Standardized outputs `(y − mean) / std` of a row-major `T × D_y` table.
    pub fn standardize_outputs(&self, outputs: &[f64]) -> Vec<f64> {
        let mut z = vec![0.0; outputs.len()];
        standardize_into(outputs, &self.output_mean, &self.output_std, &mut z);
        z
    }

    /// Output moments (row-major `T × D_y` means and variances) from standardized to physical
    /// units, in place: means `m · std + mean`, variances `v · std²`. Allocates nothing.
    pub fn outputs_to_physical(&self, mean: &mut [f64], var: &mut [f64]) {
        let dy = self.output_std.len().max(1);
        for (i, (m, v)) in mean.iter_mut().zip(var.iter_mut()).enumerate() {
            let s = self.output_std[i % dy];
            *m = *m * s + self.output_mean[i % dy];
            *v *= s * s;
        }
    }

    /// The training set's normalization: per-channel mean and std (ddof 0; std 1 for constant
    /// channels) of the inputs (`D_u = n_input`) and outputs (`D_y = n_output`) of `sequences`.
    pub fn of_sequences<'a>(
        sequences: &[SequenceView<'a>],
        n_input: usize,
        n_output: usize,
    ) -> Self {
        let stats = |d: usize, get: &dyn Fn(&SequenceView<'a>) -> &'a [f64]| {
            let mut mean = vec![0.0; d];
            let mut n = 0.0;
            for s in sequences {
                for row in get(s).chunks_exact(d.max(1)) {
                    mean.iter_mut().zip(row).for_each(|(m, v)| *m += v);
                    n += 1.0;
                }
            }
            mean.iter_mut().for_each(|m| *m /= f64::max(n, 1.0));
            let mut var = vec![0.0; d];
            for s in sequences {
                for row in get(s).chunks_exact(d.max(1)) {
                    for ((v, x), m) in var.iter_mut().zip(row).zip(&mean) {
                        *v += (x - m) * (x - m);
                    }
                }
            }
            let std = var
                .iter()
                .map(|v| {
                    let s = (v / f64::max(n, 1.0)).sqrt();
                    if s > 0.0 && s.is_finite() { s } else { 1.0 }
                })
                .collect::<Vec<_>>();
            (mean, std)
        };
        let (input_mean, input_std) = stats(n_input, &|s| s.inputs);
        let (output_mean, output_std) = stats(n_output, &|s| s.outputs);
        Self {
            input_mean,
            input_std,
            output_mean,
            output_std,
        }
    }

    /// A raw sequence standardized (a new sequence).
    pub fn standardize_sequence(&self, s: SequenceView<'_>) -> Sequence {
        Sequence {
            inputs: self.standardize_inputs(s.inputs),
            outputs: self.standardize_outputs(s.outputs),
        }
    }
}

/// A PR-SSM with everything needed to predict.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PrssmModel {
    /// Structure and sizes.
    pub config: ModelConfig,
    /// Constrained parameters.
    pub params: Params,
    /// Normalization of inputs/outputs; `None`: the model works on standardized data.
    pub normalization: Option<Normalization>,
    /// Free-form training settings (optimizer, epochs, data, ...).
    pub training: serde_json::Value,
}

impl PrssmModel {
    /// Checks configuration, parameter shapes/positivity and normalization shapes.
    ///
    /// # Errors
    /// [`ConfigError`] naming the field.
    pub fn check(&self) -> Result<(), ConfigError> {
        self.config.check()?;
        self.params.check(&self.config)?;
        if let Some(n) = &self.normalization {
            for (field, v, len) in [
                (
                    "normalization.input_mean",
                    &n.input_mean,
                    self.config.n_input,
                ),
                ("normalization.input_std", &n.input_std, self.config.n_input),
                (
                    "normalization.output_mean",
                    &n.output_mean,
                    self.config.n_output,
                ),
                (
                    "normalization.output_std",
                    &n.output_std,
                    self.config.n_output,
                ),
            ] {
                if v.len() != len {
                    return Err(ConfigError {
                        field,
                        message: format!("length {}, expected {len}", v.len()),
                    });
                }
                if v.iter().any(|x| !x.is_finite()) {
                    return Err(ConfigError {
                        field,
                        message: "non-finite value".into(),
                    });
                }
            }
            for (field, v) in [
                ("normalization.input_std", &n.input_std),
                ("normalization.output_std", &n.output_std),
            ] {
                if v.iter().any(|x| *x <= 0.0) {
                    return Err(ConfigError {
                        field,
                        message: "standard deviations must be > 0".into(),
                    });
                }
            }
        }
        Ok(())
    }

    /// Open-loop prediction from `x_0 = 0` (all particles) under `inputs` (row-major
    /// `T × D_u`, physical units if the model has a normalization, else standardized);
    /// outputs returned in the same units (means de-standardized, variances × std²; latent
    /// moments stay standardized).
    ///
    /// # Errors
    /// [`ObjectiveError`] on shape mismatches or a non-positive-definite `K_mm`.
    pub fn predict_inputs(
        &self,
        inputs: &[f64],
        particles: usize,
        seed: u64,
    ) -> Result<Prediction, ObjectiveError> {
        Ok(self.predict_inputs_kept(inputs, particles, seed, false)?.0)
    }

    /// [`Self::predict_inputs`] that also returns every particle when `keep_particles`
    /// (`T × P × D_x` row-major, standardized latent units; the moments are unchanged).
    ///
    /// # Errors
    /// As [`Self::predict_inputs`].
    pub fn predict_inputs_kept(
        &self,
        inputs: &[f64],
        particles: usize,
        seed: u64,
        keep_particles: bool,
    ) -> Result<(Prediction, Option<Vec<f64>>), ObjectiveError> {
        let zero = vec![0.0; self.config.n_state];
        let standardized = self
            .normalization
            .as_ref()
            .map(|n| n.standardize_inputs(inputs));
        let z = standardized.as_deref().unwrap_or(inputs);
        let (c, p) = (&self.config, &self.params);
        let (mut pred, all) = if keep_particles {
            let (pred, all) = predict::predict_particles(c, p, z, (&zero, &zero), particles, seed)?;
            (pred, Some(all))
        } else {
            (
                predict::predict(c, p, z, &zero, &zero, particles, seed)?,
                None,
            )
        };
        if let Some(n) = &self.normalization {
            n.outputs_to_physical(&mut pred.output_mean, &mut pred.output_var);
        }
        Ok((pred, all))
    }

    /// The initial-state rule the model was trained with (the `initial_state` of its training
    /// record, [`crate::train::fit::training_record`]); `x₀ = 0` for a model without one (an
    /// imported model).
    pub fn initial_state_rule(&self) -> InitialStateModel {
        self.training
            .get("initial_state")
            .and_then(|v| serde_json::from_value(v.clone()).ok())
            .unwrap_or(InitialStateModel {
                spec: InitialStateSpec::Zeros,
                recognition: None,
                params: Vec::new(),
            })
    }

    /// Open-loop prediction of a raw sequence from the model's initial-state rule
    /// ([`Self::initial_state_rule`]). `seq.outputs` may be empty for the
    /// zero rule; the other rules read the first steps of the outputs. Output moments are in raw
    /// units, latent moments standardized.
    ///
    /// # Errors
    /// [`PredictionError`] for mismatched shapes, a missing initial-state input or a failed
    /// prediction.
    pub fn predict_sequence(
        &self,
        seq: SequenceView<'_>,
        particles: usize,
        seed: u64,
    ) -> Result<Prediction, PredictionError> {
        let initial = self.initial_state_rule();
        let z = self
            .normalization
            .as_ref()
            .map(|n| n.standardize_sequence(seq));
        let z = z.as_ref().map_or(seq, Sequence::view);
        let mut pred = predict::predict_standardized(
            &self.config,
            &self.params,
            &initial,
            z,
            particles,
            seed,
        )?;
        if let Some(n) = &self.normalization {
            n.outputs_to_physical(&mut pred.output_mean, &mut pred.output_var);
        }
        Ok(pred)
    }
}
