//! The objective `J(θ)` of a design and its gradient (crate docs).

use std::ops::Range;

use flapssm_wing::input_jacobian::input_jacobian;
use flapssm_wing::kinematics::{EulerState, WingKinematics};
use flapssm_wing::stroke_loads::{mean_stroke_frame_loads, quantity, stroke_frame_jacobian};
use flapssm_wing::trajectories::harmonic::HarmonicKinematics;

use crate::error::DesignError;
use crate::model::{DesignModel, N_INPUT, N_OUTPUT};
use crate::problem::{DesignProblem, Target};

/// Step of the central differences of `J` for models without input gradients (rad).
pub const FD_STEP_RAD: f64 = 1e-5;

/// One evaluation of the objective.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Evaluation {
    /// `J`.
    pub value: f64,
    /// The target's term.
    pub fit: f64,
    /// The predictive variance's term.
    pub robust: f64,
    /// The power's term.
    pub power: f64,
    /// The limits' penalty.
    pub penalty: f64,
    /// Predicted cycle means of the 7 stroke-frame quantities over the window.
    pub cycle_means: [f64; 7],
}

/// `J` of one problem with one design model, with its buffers.
pub struct Objective {
    problem: DesignProblem,
    window: Range<usize>,
    model: Box<dyn DesignModel>,
    kinematics: HarmonicKinematics,
    states: Vec<EulerState>,
    inputs: Vec<f64>,
    mean: Vec<[f64; 5]>,
    var: Vec<f64>,
    mean_bar: Vec<f64>,
    var_bar: Vec<f64>,
    u_bar: Vec<f64>,
    s_bar: Vec<[f64; 9]>,
    basis: Vec<[f64; 3]>,
}

impl Objective {
    /// The objective of `problem` (checked) with `model`.
    ///
    /// # Errors
    /// [`DesignError::Invalid`] from [`DesignProblem::check`].
    pub fn new(problem: &DesignProblem, model: Box<dyn DesignModel>) -> Result<Self, DesignError> {
        let window = problem.check()?;
        let n = problem.grid.n_samples;
        Ok(Self {
            window,
            model,
            kinematics: HarmonicKinematics::zeros(
                problem.frequency_hz,
                problem.harmonics,
                problem.ramp_cycles,
            ),
            states: vec![EulerState::default(); n],
            inputs: vec![0.0; n * N_INPUT],
            mean: vec![[0.0; N_OUTPUT]; n],
            var: vec![0.0; n * N_OUTPUT],
            mean_bar: vec![0.0; n * N_OUTPUT],
            var_bar: vec![0.0; n * N_OUTPUT],
            u_bar: vec![0.0; n * N_INPUT],
            s_bar: vec![[0.0; 9]; n],
            basis: vec![[0.0; 3]; 1 + 2 * problem.harmonics],
            problem: problem.clone(),
        })
    }

    /// An independent copy (its own model and buffers), for a parallel start.
    pub fn fork(&self) -> Self {
        Self {
            problem: self.problem.clone(),
            window: self.window.clone(),
            model: self.model.boxed_clone(),
            kinematics: self.kinematics.clone(),
            states: self.states.clone(),
            inputs: self.inputs.clone(),
            mean: self.mean.clone(),
            var: self.var.clone(),
            mean_bar: self.mean_bar.clone(),
            var_bar: self.var_bar.clone(),
            u_bar: self.u_bar.clone(),
            s_bar: self.s_bar.clone(),
            basis: self.basis.clone(),
        }
    }

    /// The problem.
    pub fn problem(&self) -> &DesignProblem {
        &self.problem
    }

    /// The analysed window (samples).
    pub fn window(&self) -> Range<usize> {
        self.window.clone()
    }

    /// The design model's name.
    pub fn model_name(&self) -> &str {
        self.model.name()
    }

    /// The kinematics of parameters `theta`.
    pub fn kinematics(&self, theta: &[f64]) -> HarmonicKinematics {
        HarmonicKinematics {
            coefficients_rad: theta.to_vec(),
            ..self.kinematics.clone()
        }
    }

    /// The Euler states of the last evaluation (every sample).
    pub fn states(&self) -> &[EulerState] {
        &self.states
    }

    /// The predicted wing-frame means and variances of the last evaluation (`T × 5`).
    pub fn prediction(&self) -> (&[f64], &[f64]) {
        (self.mean.as_flattened(), &self.var)
    }

    /// The number of parameters.
    pub fn n_params(&self) -> usize {
        HarmonicKinematics::n_params(self.problem.harmonics)
    }

    /// `J(θ)`; with `grad`, also `∂J/∂θ` into it (exact through a model with input gradients,
    /// central differences of step [`FD_STEP_RAD`] otherwise). The state of the objective is
    /// that of `θ` afterwards.
    ///
    /// # Errors
    /// [`DesignError::Invalid`] for a `θ` of the wrong length or not finite (named);
    /// [`DesignError::Model`].
    pub fn evaluate(
        &mut self,
        theta: &[f64],
        grad: Option<&mut [f64]>,
    ) -> Result<Evaluation, DesignError> {
        let n_p = self.n_params();
        if theta.len() != n_p {
            return Err(DesignError::invalid(
                "kinematics.coefficients_rad",
                format!("{} values, expected {n_p}", theta.len()),
            ));
        }
        let Some(grad) = grad else {
            return self.forward(theta);
        };
        if grad.len() != n_p {
            return Err(DesignError::invalid(
                "gradient",
                format!("{} values, expected {n_p}", grad.len()),
            ));
        }
        let ev = self.forward(theta)?;
        if self.backward(&ev.cycle_means, grad)? {
            return Ok(ev);
        }
        let mut probe = theta.to_vec();
        for i in 0..n_p {
            probe[i] = theta[i] + FD_STEP_RAD;
            let up = self.forward(&probe)?.value;
            probe[i] = theta[i] - FD_STEP_RAD;
            let down = self.forward(&probe)?.value;
            probe[i] = theta[i];
            grad[i] = (up - down) / (2.0 * FD_STEP_RAD);
        }
        self.forward(theta)
    }

    fn forward(&mut self, theta: &[f64]) -> Result<Evaluation, DesignError> {
        if let Some(i) = theta.iter().position(|v| !v.is_finite()) {
            let names = HarmonicKinematics::parameter_names(self.problem.harmonics);
            return Err(DesignError::invalid(
                format!("kinematics.{}", names[i]),
                "not finite",
            ));
        }
        self.kinematics.coefficients_rad.copy_from_slice(theta);
        let dt = self.problem.grid.dt_s;
        self.kinematics.sample_into(dt, &mut self.states);
        for (s, u) in self
            .states
            .iter()
            .zip(self.inputs.chunks_exact_mut(N_INPUT))
        {
            u.copy_from_slice(&WingKinematics::from_euler(s).inputs());
        }
        self.model.predict(
            &self.states,
            &self.inputs,
            dt,
            self.mean.as_flattened_mut(),
            &mut self.var,
        )?;
        let p = &self.problem;
        let w = self.window.clone();
        let n_w = w.len() as f64;
        let q_bar = mean_stroke_frame_loads(
            &self.mean[w.clone()],
            &self.states[w.clone()],
            p.sensor_radius_m,
        );
        let (mut fit, mut robust) = (0.0, 0.0);
        for (j, t) in w.enumerate() {
            let y = self.mean[t];
            for k in 0..N_OUTPUT {
                let s2 = p.output_scales[k] * p.output_scales[k];
                robust += p.robust_weight * self.var[t * 5 + k] / (s2 * n_w);
                if let Target::History { outputs } = &p.target {
                    let e = y[k] - outputs[j][k];
                    fit += e * e / (s2 * n_w);
                }
            }
        }
        if let Target::CycleMeans { values } = &p.target {
            for (i, v) in values.iter().enumerate() {
                if let Some(v) = v {
                    fit += ((q_bar[i] - v) / p.quantity_scales[i]).powi(2);
                }
            }
        }
        let power = p.power_weight * q_bar[quantity::POWER] / p.quantity_scales[quantity::POWER];
        let lim = p.limits.as_vector();
        let mut penalty = 0.0;
        for s in &self.states {
            let v = flapssm_wing::input_jacobian::state_vector(s);
            for c in 0..9 {
                let e = (v[c].abs() / lim[c] - 1.0).max(0.0);
                penalty += p.limit_weight * e * e;
            }
        }
        Ok(Evaluation {
            value: fit + robust + power + penalty,
            fit,
            robust,
            power,
            penalty,
            cycle_means: q_bar,
        })
    }

    /// The exact gradient of the last [`Self::forward`] (its cycle means `q_bar`) into `grad`;
    /// `Ok(false)` when the model has no input gradient.
    fn backward(&mut self, q_bar: &[f64; 7], grad: &mut [f64]) -> Result<bool, DesignError> {
        let p = &self.problem;
        let n_w = self.window.len() as f64;
        // ∂J/∂q̄ of the cycle-mean terms.
        let mut g_q = [0.0; 7];
        if let Target::CycleMeans { values } = &p.target {
            for (i, v) in values.iter().enumerate() {
                if let Some(v) = v {
                    g_q[i] = 2.0 * (q_bar[i] - v) / p.quantity_scales[i].powi(2);
                }
            }
        }
        g_q[quantity::POWER] += p.power_weight / p.quantity_scales[quantity::POWER];
        self.mean_bar.fill(0.0);
        self.var_bar.fill(0.0);
        self.s_bar.iter_mut().for_each(|s| *s = [0.0; 9]);
        for (j, t) in self.window.clone().enumerate() {
            let y = self.mean[t];
            let (dy, ds) = stroke_frame_jacobian(&y, &self.states[t], p.sensor_radius_m);
            for ((g, dy_i), ds_i) in g_q.iter().zip(&dy).zip(&ds) {
                if *g == 0.0 {
                    continue;
                }
                let mb = &mut self.mean_bar[t * 5..(t + 1) * 5];
                mb.iter_mut().zip(dy_i).for_each(|(b, d)| *b += g * d / n_w);
                self.s_bar[t]
                    .iter_mut()
                    .zip(ds_i)
                    .for_each(|(b, d)| *b += g * d / n_w);
            }
            for k in 0..5 {
                let s2 = p.output_scales[k] * p.output_scales[k];
                self.var_bar[t * 5 + k] = p.robust_weight / (s2 * n_w);
                if let Target::History { outputs } = &p.target {
                    self.mean_bar[t * 5 + k] += 2.0 * (y[k] - outputs[j][k]) / (s2 * n_w);
                }
            }
        }
        if !self
            .model
            .input_gradient(&self.mean_bar, &self.var_bar, &mut self.u_bar)?
        {
            return Ok(false);
        }
        let lim = p.limits.as_vector();
        for (t, s) in self.states.iter().enumerate() {
            let v = flapssm_wing::input_jacobian::state_vector(s);
            for c in 0..9 {
                let e = (v[c].abs() / lim[c] - 1.0).max(0.0);
                self.s_bar[t][c] += p.limit_weight * 2.0 * e * v[c].signum() / lim[c];
            }
            let ub = &self.u_bar[t * N_INPUT..(t + 1) * N_INPUT];
            if ub.iter().any(|g| *g != 0.0) {
                let ju = input_jacobian(s);
                for (g, ju_r) in ub.iter().zip(&ju) {
                    self.s_bar[t]
                        .iter_mut()
                        .zip(ju_r)
                        .for_each(|(b, j)| *b += g * j);
                }
            }
        }
        grad.fill(0.0);
        let nb = 1 + 2 * p.harmonics;
        let dt = p.grid.dt_s;
        for (t, sb) in self.s_bar.iter().enumerate() {
            self.kinematics.basis_into(t as f64 * dt, &mut self.basis);
            for i in 0..3 {
                for (j, b) in self.basis.iter().enumerate() {
                    grad[i * nb + j] += sb[i] * b[0] + sb[3 + i] * b[1] + sb[6 + i] * b[2];
                }
            }
        }
        Ok(true)
    }

    /// The predictive standard deviation of each cycle mean of the last evaluation, from a
    /// particle model's particles (their spread plus the observation noise averaged over the
    /// window); `None` for a deterministic model.
    pub fn cycle_mean_sd(&self) -> Option<[f64; 7]> {
        let (y, n_p, obs) = self.model.particles()?;
        let p = &self.problem;
        let n_w = self.window.len() as f64;
        let mut per_particle = vec![[0.0; 7]; n_p];
        let mut obs_var = [0.0; 7];
        for t in self.window.clone() {
            let m = self.mean[t];
            let (dy, _) = stroke_frame_jacobian(&m, &self.states[t], p.sensor_radius_m);
            for (pp, q) in per_particle.iter_mut().enumerate() {
                let yp = &y[(t * n_p + pp) * 5..(t * n_p + pp + 1) * 5];
                for i in 0..7 {
                    q[i] += (0..5).map(|k| dy[i][k] * yp[k]).sum::<f64>() / n_w;
                }
            }
            for i in 0..7 {
                obs_var[i] +=
                    (0..5).map(|k| dy[i][k] * dy[i][k] * obs[k]).sum::<f64>() / (n_w * n_w);
            }
        }
        let mut sd = [0.0; 7];
        for i in 0..7 {
            let mean = per_particle.iter().map(|q| q[i]).sum::<f64>() / n_p as f64;
            let var = per_particle
                .iter()
                .map(|q| (q[i] - mean).powi(2))
                .sum::<f64>()
                / n_p as f64;
            sd[i] = (var + obs_var[i]).sqrt();
        }
        Some(sd)
    }
}
