//! The design: Adam on the kinematic parameters from several starts, in parallel on the
//! caller's rayon pool; the best iterate of the best start is the design.

use flapssm_wing::trajectories::harmonic::HarmonicKinematics;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::DesignError;
use crate::objective::{Evaluation, Objective};

/// Adam's settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OptimizerSettings {
    /// Iterations per start.
    pub iterations: usize,
    /// Step size (rad).
    pub learning_rate_rad: f64,
}

impl Default for OptimizerSettings {
    /// 150 iterations of 0.01 rad.
    fn default() -> Self {
        Self {
            iterations: 150,
            learning_rate_rad: 0.01,
        }
    }
}

/// A finished design.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Design {
    /// The design model.
    pub model: String,
    /// The kinematics chosen.
    pub kinematics: HarmonicKinematics,
    /// Its objective and predicted cycle means.
    pub evaluation: Evaluation,
    /// Predictive SD of each cycle mean (particle models).
    pub cycle_mean_sd: Option<[f64; 7]>,
    /// The start that won.
    pub start: usize,
    /// `J` at every iteration of the winning start (the convergence history).
    pub convergence: Vec<f64>,
    /// The best `J` of every start.
    pub start_values: Vec<f64>,
    /// The analysed window (first sample, end).
    pub window: [usize; 2],
    /// Predicted wing-frame means over the window (`[F_x, F_y, M_x, M_y, M_z]` per sample).
    pub predicted_mean: Vec<[f64; 5]>,
    /// Predicted wing-frame variances over the window.
    pub predicted_var: Vec<[f64; 5]>,
    /// The largest excess over the kinematic limits, if any (`field = value > limit`).
    pub limit_excess: Option<String>,
    /// Objective evaluations made (with gradients).
    pub evaluations: usize,
}

/// One start: Adam from `theta`, keeping the best iterate.
fn run_start(
    objective: &mut Objective,
    theta: &[f64],
    settings: &OptimizerSettings,
) -> Result<(Vec<f64>, f64, Vec<f64>), DesignError> {
    let n = theta.len();
    let (b1, b2, eps) = (0.9, 0.999, 1e-12);
    let (mut th, mut m, mut v, mut g) = (theta.to_vec(), vec![0.0; n], vec![0.0; n], vec![0.0; n]);
    let mut best = (th.clone(), f64::INFINITY);
    let mut history = Vec::with_capacity(settings.iterations + 1);
    for it in 0..=settings.iterations {
        let ev = objective.evaluate(&th, Some(&mut g))?;
        history.push(ev.value);
        if ev.value < best.1 {
            best = (th.clone(), ev.value);
        }
        if it == settings.iterations {
            break;
        }
        let k = (it + 1) as i32;
        for i in 0..n {
            m[i] = b1 * m[i] + (1.0 - b1) * g[i];
            v[i] = b2 * v[i] + (1.0 - b2) * g[i] * g[i];
            let (mh, vh) = (m[i] / (1.0 - b1.powi(k)), v[i] / (1.0 - b2.powi(k)));
            th[i] -= settings.learning_rate_rad * mh / (vh.sqrt() + eps);
        }
    }
    Ok((best.0, best.1, history))
}

/// Designs with `objective` from each of `starts` (parameter vectors) in parallel; the best
/// iterate of all is the design, evaluated once more for its prediction.
///
/// # Errors
/// [`DesignError::Invalid`] without starts or for a start of the wrong length; the
/// objective's errors.
pub fn design(
    objective: &Objective,
    starts: &[Vec<f64>],
    settings: &OptimizerSettings,
) -> Result<Design, DesignError> {
    if starts.is_empty() {
        return Err(DesignError::invalid("starts", "no start given"));
    }
    if settings.iterations == 0
        || !(settings.learning_rate_rad > 0.0 && settings.learning_rate_rad.is_finite())
    {
        return Err(DesignError::invalid(
            "optimizer",
            "iterations must be ≥ 1 and the learning rate finite and > 0",
        ));
    }
    let forks: Vec<Objective> = starts.iter().map(|_| objective.fork()).collect();
    let runs: Vec<_> = forks
        .into_par_iter()
        .zip(starts)
        .map(|(mut obj, s)| run_start(&mut obj, s, settings))
        .collect::<Result<_, _>>()?;
    let start_values: Vec<f64> = runs.iter().map(|r| r.1).collect();
    let start = (0..runs.len())
        .min_by(|&a, &b| start_values[a].total_cmp(&start_values[b]))
        .expect("one start");
    let (theta, _, convergence) = runs.into_iter().nth(start).expect("start");
    let mut obj = objective.fork();
    let evaluation = obj.evaluate(&theta, None)?;
    let window = obj.window();
    let (mean, var) = obj.prediction();
    let rows = |v: &[f64]| -> Vec<[f64; 5]> {
        window
            .clone()
            .map(|t| v[t * 5..(t + 1) * 5].try_into().expect("5"))
            .collect()
    };
    let limit_excess = obj.problem().limits.violation(obj.states()).map(|v| {
        format!(
            "{} = {:.4} > {:.4} (sample {})",
            v.field, v.value, v.limit, v.sample
        )
    });
    Ok(Design {
        model: obj.model_name().to_string(),
        kinematics: obj.kinematics(&theta),
        evaluation,
        cycle_mean_sd: obj.cycle_mean_sd(),
        start,
        convergence,
        start_values,
        window: [window.start, window.end],
        predicted_mean: rows(mean),
        predicted_var: rows(var),
        limit_excess,
        evaluations: starts.len() * (settings.iterations + 1),
    })
}
