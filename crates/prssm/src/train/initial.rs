//! Initial latent states `x₀ ~ N(m₀, diag(s₀²))` of a window or a prediction.
//!
//! | rule | `m₀` | `s₀` |
//! |---|---|---|
//! | [`InitialStateSpec::Zeros`] | 0 (use with a burn-in window) | 0 |
//! | [`InitialStateSpec::Outputs`] | `[y_start, 0, …, 0]` | 0 |
//! | [`InitialStateSpec::Recognition`] | recognition model of the first `k` steps of `(u, y)` | same |
//!
//! With a recognition model, [`RecognizedElbo`] trains the model and the recognition map
//! jointly: its flat parameters are `[ELBO parameters | recognition parameters]`, and the
//! engine's `∂loss/∂m₀`, `∂loss/∂s₀` are chained through [`Recognition::backward`].

use serde::{Deserialize, Serialize};

use super::recognition::{Recognition, RecognitionConfig};
use crate::elbo::{Elbo, InitialStateGrads, InitialStates};
use crate::{Objective, ObjectiveError, Window};

/// How the initial state is obtained.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum InitialStateSpec {
    /// `x₀ = 0` (the paper, with 20 % burn-in).
    Zeros,
    /// `x₀[0..D_y] = y_start`, the rest 0.
    Outputs,
    /// A learned recognition model (Doerr et al. use the first 16 steps).
    Recognition(RecognitionConfig),
}

/// A fitted initial-state rule: the spec and, for a recognition model, its parameters.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InitialStateModel {
    /// The rule.
    pub spec: InitialStateSpec,
    /// Recognition model dimensions (recognition rule only).
    pub recognition: Option<Recognition>,
    /// Recognition parameters (recognition rule only).
    pub params: Vec<f64>,
}

/// Why an initial state cannot be formed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum InitialStateError {
    /// Too few steps of `(u, y)` for the rule.
    #[error(
        "initial state: the rule needs {needed} steps of outputs from step {start}, the sequence has {available}"
    )]
    TooShort {
        /// Steps needed.
        needed: usize,
        /// First step.
        start: usize,
        /// Steps available.
        available: usize,
    },
    /// The recognition parameters do not fit the model.
    #[error("initial state: recognition model has {found} parameters, expected {expected}")]
    ParamCount {
        /// Found.
        found: usize,
        /// Expected.
        expected: usize,
    },
}

impl InitialStateModel {
    /// Writes `m₀`, `s₀` (`D_x` each) for a model with `(D_u, D_y)` = `dims` and the sequence
    /// with row-major standardized inputs `u`
    /// (`T × D_u`) and outputs `y` (`T × D_y`) starting at step `start`.
    ///
    /// # Errors
    /// [`InitialStateError`] when `y` is too short for the rule.
    pub fn state(
        &self,
        (d_u, d_y): (usize, usize),
        u: &[f64],
        y: &[f64],
        start: usize,
        mean: &mut [f64],
        std: &mut [f64],
    ) -> Result<(), InitialStateError> {
        mean.fill(0.0);
        std.fill(0.0);
        let available = y.len() / d_y.max(1);
        match (&self.spec, &self.recognition) {
            (InitialStateSpec::Zeros, _) => Ok(()),
            (InitialStateSpec::Outputs, _) => {
                if start >= available {
                    return Err(InitialStateError::TooShort {
                        needed: 1,
                        start,
                        available,
                    });
                }
                mean[..d_y].copy_from_slice(&y[start * d_y..(start + 1) * d_y]);
                Ok(())
            }
            (InitialStateSpec::Recognition(_), Some(rec)) => {
                if self.params.len() != rec.n_params() {
                    return Err(InitialStateError::ParamCount {
                        found: self.params.len(),
                        expected: rec.n_params(),
                    });
                }
                let mut z = vec![0.0; rec.input_len()];
                let needed = rec.config.steps;
                if d_u != rec.d_u || d_y != rec.d_y || !rec.gather(u, y, start, &mut z) {
                    return Err(InitialStateError::TooShort {
                        needed,
                        start,
                        available,
                    });
                }
                let mut ws = rec.workspace();
                rec.forward(&self.params, &z, &mut ws, mean, std);
                Ok(())
            }
            (InitialStateSpec::Recognition(_), None) => Err(InitialStateError::ParamCount {
                found: self.params.len(),
                expected: 0,
            }),
        }
    }
}

/// The ELBO with the initial state of every window from a jointly trained recognition model.
/// Flat parameters: `[Elbo (n_e) | Recognition (n_r)]`.
#[derive(Debug)]
pub struct RecognizedElbo<'a> {
    elbo: &'a Elbo,
    recognition: Recognition,
}

impl<'a> RecognizedElbo<'a> {
    /// Wraps `elbo` with a recognition model of architecture `config`.
    pub fn new(elbo: &'a Elbo, config: RecognitionConfig) -> Self {
        let c = elbo.config();
        Self {
            elbo,
            recognition: Recognition::new(config, c.n_input, c.n_output, c.n_state),
        }
    }

    /// The recognition model.
    pub fn recognition(&self) -> &Recognition {
        &self.recognition
    }

    /// Number of ELBO parameters (the recognition parameters follow them).
    pub fn n_elbo_params(&self) -> usize {
        self.elbo.n_params()
    }
}

impl Objective for RecognizedElbo<'_> {
    fn n_params(&self) -> usize {
        self.elbo.n_params() + self.recognition.n_params()
    }

    fn loss_and_grad(
        &self,
        params: &[f64],
        batch: &[Window],
        seed: u64,
        grad: &mut [f64],
    ) -> Result<f64, ObjectiveError> {
        let n_e = self.elbo.n_params();
        if params.len() != self.n_params() || grad.len() != self.n_params() {
            return Err(ObjectiveError::Shape(format!(
                "{} parameters / {} gradient values, expected {}",
                params.len(),
                grad.len(),
                self.n_params()
            )));
        }
        let (pe, pr) = params.split_at(n_e);
        let (ge, gr) = grad.split_at_mut(n_e);
        let rec = &self.recognition;
        let dx = rec.d_x;
        let nb = batch.len();
        let seqs = self.elbo.data().sequences();
        let mut z = vec![0.0; nb * rec.input_len()];
        let mut mean = vec![0.0; nb * dx];
        let mut std = vec![0.0; nb * dx];
        let mut ws = rec.workspace();
        for (i, w) in batch.iter().enumerate() {
            let s = seqs.get(w.sequence).ok_or_else(|| {
                ObjectiveError::Shape(format!("window {i}: no sequence {}", w.sequence))
            })?;
            let zi = &mut z[i * rec.input_len()..(i + 1) * rec.input_len()];
            if !rec.gather(&s.inputs, &s.outputs, w.start, zi) {
                return Err(ObjectiveError::Shape(format!(
                    "window {i}: recognition needs {} steps from step {} of sequence {}",
                    rec.config.steps, w.start, w.sequence
                )));
            }
            rec.forward(
                pr,
                zi,
                &mut ws,
                &mut mean[i * dx..(i + 1) * dx],
                &mut std[i * dx..(i + 1) * dx],
            );
        }
        let mut gm = vec![0.0; nb * dx];
        let mut gs = vec![0.0; nb * dx];
        let parts = self.elbo.evaluate(
            pe,
            batch,
            InitialStates {
                mean: &mean,
                std: &std,
            },
            seed,
            ge,
            InitialStateGrads {
                mean: &mut gm,
                std: &mut gs,
            },
        )?;
        gr.fill(0.0);
        let (mut m1, mut s1) = (vec![0.0; dx], vec![0.0; dx]);
        for i in 0..nb {
            let zi = &z[i * rec.input_len()..(i + 1) * rec.input_len()];
            rec.forward(pr, zi, &mut ws, &mut m1, &mut s1);
            rec.backward(
                pr,
                zi,
                &mut ws,
                &gm[i * dx..(i + 1) * dx],
                &gs[i * dx..(i + 1) * dx],
                gr,
            );
        }
        if gr.iter().any(|v| !v.is_finite()) {
            return Err(ObjectiveError::NonFinite { what: "gradient" });
        }
        Ok(parts.loss)
    }
}
