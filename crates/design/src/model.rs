//! The load models a design can be made with: the PR-SSM (exact input gradients through its
//! prediction), the LRQSM and the quasi-steady wing (no input gradients: central differences
//! of the objective).

use std::sync::Arc;

use flapssm_prssm::PrssmModel;
use flapssm_prssm::sensitivity::InputSensitivity;
use flapssm_qs::LrqsmModel;
use flapssm_wing::kinematics::EulerState;
use flapssm_wing::virtual_wing::{VirtualWing, VirtualWingConfig};

use crate::error::DesignError;

/// Wing-frame outputs `[F_x, F_y, M_x, M_y, M_z]` (N, N·mm).
pub const N_OUTPUT: usize = 5;
/// Model inputs `[AoA, |v|, a_x, a_y, a_z, α̇, α̈]`.
pub const N_INPUT: usize = 7;

/// A load model as a design sees it.
pub trait DesignModel: Send {
    /// Short name (`prssm`, `lrqsm`, `quasi-steady`).
    fn name(&self) -> &str;

    /// Predicts wing-frame loads for Euler states sampled every `dt_s` from rest and their
    /// inputs (`T × 7`): means and variances (`T × 5`, zero for a deterministic model).
    ///
    /// # Errors
    /// [`DesignError::Model`].
    fn predict(
        &mut self,
        states: &[EulerState],
        inputs: &[f64],
        dt_s: f64,
        mean: &mut [f64],
        var: &mut [f64],
    ) -> Result<(), DesignError>;

    /// `∂J/∂u` (`T × 7`) of the last prediction from `∂J/∂mean`, `∂J/∂var`; `Ok(false)`
    /// for a model without input gradients.
    ///
    /// # Errors
    /// [`DesignError::Model`].
    fn input_gradient(
        &mut self,
        mean_bar: &[f64],
        var_bar: &[f64],
        out: &mut [f64],
    ) -> Result<bool, DesignError>;

    /// The last prediction's particle outputs (`T × P × 5`), `P`, and the observation-noise
    /// variances (5), for a particle model.
    fn particles(&self) -> Option<(Vec<f64>, usize, Vec<f64>)> {
        None
    }

    /// An independent copy (one per parallel start).
    fn boxed_clone(&self) -> Box<dyn DesignModel>;
}

/// A PR-SSM as design model: open-loop prediction from `x₀ = 0` with a fixed seed (common
/// random numbers, so the objective is a smooth function of the kinematics).
#[derive(Clone)]
pub struct PrssmDesign {
    sensitivity: InputSensitivity,
    seed: u64,
    zero: Vec<f64>,
}

impl PrssmDesign {
    /// `model` with `particles` particles and draws from `seed`.
    ///
    /// # Errors
    /// [`DesignError::Model`] for an invalid model or not 7 inputs and 5 outputs.
    pub fn new(model: &PrssmModel, particles: usize, seed: u64) -> Result<Self, DesignError> {
        let err = |message: String| DesignError::Model {
            model: "prssm".into(),
            message,
        };
        if model.config.n_input != N_INPUT || model.config.n_output != N_OUTPUT {
            return Err(err(format!(
                "{} inputs and {} outputs, a wing model has {N_INPUT} and {N_OUTPUT}",
                model.config.n_input, model.config.n_output
            )));
        }
        let sensitivity =
            InputSensitivity::for_model(model, particles).map_err(|e| err(e.to_string()))?;
        Ok(Self {
            sensitivity,
            seed,
            zero: vec![0.0; model.config.n_state],
        })
    }
}

impl DesignModel for PrssmDesign {
    fn name(&self) -> &str {
        "prssm"
    }

    fn predict(
        &mut self,
        _states: &[EulerState],
        inputs: &[f64],
        _dt_s: f64,
        mean: &mut [f64],
        var: &mut [f64],
    ) -> Result<(), DesignError> {
        let p = self
            .sensitivity
            .predict(inputs, (&self.zero, &self.zero), self.seed)
            .map_err(|e| DesignError::Model {
                model: "prssm".into(),
                message: e.to_string(),
            })?;
        mean.copy_from_slice(&p.output_mean);
        var.copy_from_slice(&p.output_var);
        Ok(())
    }

    fn input_gradient(
        &mut self,
        mean_bar: &[f64],
        var_bar: &[f64],
        out: &mut [f64],
    ) -> Result<bool, DesignError> {
        self.sensitivity
            .input_gradient(mean_bar, var_bar, out)
            .map_err(|e| DesignError::Model {
                model: "prssm".into(),
                message: e.to_string(),
            })?;
        Ok(true)
    }

    fn particles(&self) -> Option<(Vec<f64>, usize, Vec<f64>)> {
        let mut out = Vec::new();
        self.sensitivity.particle_outputs_into(&mut out);
        let obs = self.sensitivity.observation_variance();
        Some((out, self.sensitivity.particles(), obs))
    }

    fn boxed_clone(&self) -> Box<dyn DesignModel> {
        Box::new(self.clone())
    }
}

/// The LRQSM as design model: its published features of each input row, its coefficients
/// (intercept as the model says), on the outputs' raw scale. Deterministic.
#[derive(Clone)]
pub struct LrqsmDesign {
    model: Arc<LrqsmModel>,
}

impl LrqsmDesign {
    /// Wraps a model fitted on a wing dataset's features.
    ///
    /// # Errors
    /// [`DesignError::Model`] for a model of custom columns or other outputs.
    pub fn new(model: LrqsmModel) -> Result<Self, DesignError> {
        if model.feature_set.is_none()
            || model.target_scaling.is_none()
            || model.chosen.len() != N_OUTPUT
        {
            return Err(DesignError::Model {
                model: "lrqsm".into(),
                message: "not fitted on a wing dataset's features and its 5 outputs".into(),
            });
        }
        Ok(Self {
            model: Arc::new(model),
        })
    }
}

impl DesignModel for LrqsmDesign {
    fn name(&self) -> &str {
        "lrqsm"
    }

    fn predict(
        &mut self,
        _states: &[EulerState],
        inputs: &[f64],
        _dt_s: f64,
        mean: &mut [f64],
        var: &mut [f64],
    ) -> Result<(), DesignError> {
        let (Some(set), Some(scaling)) = (self.model.feature_set, &self.model.target_scaling)
        else {
            unreachable!("checked in new")
        };
        let mut features = vec![0.0; set.len()];
        for (u, (m, v)) in inputs.chunks_exact(N_INPUT).zip(
            mean.chunks_exact_mut(N_OUTPUT)
                .zip(var.chunks_exact_mut(N_OUTPUT)),
        ) {
            let u: [f64; N_INPUT] = u.try_into().expect("rows of 7");
            set.compute_into(&u, &mut features);
            self.model
                .predict_row(&features, self.model.prediction_intercept, m);
            for ((m, mean), std) in m.iter_mut().zip(&scaling.mean).zip(&scaling.std) {
                *m = mean + std * *m;
            }
            v.fill(0.0);
        }
        Ok(())
    }

    fn input_gradient(&mut self, _: &[f64], _: &[f64], _: &mut [f64]) -> Result<bool, DesignError> {
        Ok(false)
    }

    fn boxed_clone(&self) -> Box<dyn DesignModel> {
        Box::new(self.clone())
    }
}

/// A virtual wing's aerodynamics as design model (the classic quasi-steady design with L0):
/// the exact aerodynamic loads at the sensor for the design's states, the plate's mount
/// applied, without the sensor chain. Deterministic.
pub struct QuasiSteadyDesign {
    config: VirtualWingConfig,
    wing: VirtualWing,
    plate: Vec<EulerState>,
    loads: Vec<[f64; 5]>,
}

impl QuasiSteadyDesign {
    /// The wing of `config` (any fidelity; L0 is the quasi-steady design).
    ///
    /// # Errors
    /// [`DesignError::Model`] for an invalid wing.
    pub fn new(config: &VirtualWingConfig) -> Result<Self, DesignError> {
        let wing = VirtualWing::new(config).map_err(|e| DesignError::Model {
            model: "quasi-steady".into(),
            message: e.to_string(),
        })?;
        Ok(Self {
            config: config.clone(),
            wing,
            plate: Vec::new(),
            loads: Vec::new(),
        })
    }
}

impl DesignModel for QuasiSteadyDesign {
    fn name(&self) -> &str {
        "quasi-steady"
    }

    fn predict(
        &mut self,
        states: &[EulerState],
        _inputs: &[f64],
        dt_s: f64,
        mean: &mut [f64],
        var: &mut [f64],
    ) -> Result<(), DesignError> {
        let mount = self.config.mount;
        self.plate.clear();
        self.plate
            .extend(states.iter().map(|s| mount.plate_state(s)));
        self.loads.resize(states.len(), [0.0; 5]);
        self.wing
            .aero_loads_into(&self.plate, dt_s, &mut self.loads);
        for (y, m) in self.loads.iter_mut().zip(mean.chunks_exact_mut(N_OUTPUT)) {
            mount.plate_to_sensor(y);
            m.copy_from_slice(y);
        }
        var.fill(0.0);
        if mean.iter().any(|v| !v.is_finite()) {
            return Err(DesignError::Model {
                model: "quasi-steady".into(),
                message: "non-finite loads".into(),
            });
        }
        Ok(())
    }

    fn input_gradient(&mut self, _: &[f64], _: &[f64], _: &mut [f64]) -> Result<bool, DesignError> {
        Ok(false)
    }

    fn boxed_clone(&self) -> Box<dyn DesignModel> {
        Box::new(Self::new(&self.config).expect("the wing was valid"))
    }
}
