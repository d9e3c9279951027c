//! What a design asks for: the target, the time grid, the kinematics' form and limits, the
//! weights of the objective — and the checks that refuse what cannot be asked.

use std::ops::Range;

use flapssm_wing::stroke_loads::QUANTITY_NAMES;
use flapssm_wing::trajectories::harmonic::KinematicLimits;
use serde::{Deserialize, Serialize};

use crate::error::DesignError;

/// How far beyond the largest cycle mean of the measured set a target may lie (× that value)
/// before it is refused as unreachable.
pub const REACH_MARGIN: f64 = 1.25;

/// The sampled time of a design: `n_samples` every `dt_s` from rest; the analysed window is
/// the last whole cycles after `skip` samples ([`Self::window`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DesignGrid {
    /// Sample period (s).
    pub dt_s: f64,
    /// Samples from rest.
    pub n_samples: usize,
    /// Samples skipped before the analysed window may start.
    pub skip: usize,
}

impl DesignGrid {
    /// The paper's: 470 samples at 25 Hz, the first 93 skipped (as its analyses).
    pub fn paper() -> Self {
        Self {
            dt_s: 0.04,
            n_samples: 470,
            skip: 93,
        }
    }

    /// The last whole cycles at `frequency_hz` that fit after `skip` samples and after a ramp
    /// of `ramp_cycles`: samples `n − round(N/(f·dt)) .. n`, `N` the largest whole number of
    /// cycles.
    ///
    /// # Errors
    /// [`DesignError::Invalid`] (`frequency_hz`) when not one cycle fits.
    pub fn window(&self, frequency_hz: f64, ramp_cycles: f64) -> Result<Range<usize>, DesignError> {
        let per_cycle = 1.0 / (frequency_hz * self.dt_s);
        let ramp = (ramp_cycles * per_cycle).ceil() as usize;
        let room = self.n_samples.saturating_sub(self.skip.max(ramp)) as f64;
        let cycles = (room / per_cycle + 1e-9).floor();
        if cycles < 1.0 || cycles.is_nan() {
            return Err(DesignError::invalid(
                "frequency_hz",
                format!(
                    "{frequency_hz} Hz: not one cycle fits in the {} samples after the first {} \
                     and the ramp",
                    self.n_samples - self.skip.min(self.n_samples),
                    self.skip
                ),
            ));
        }
        let len = (cycles * per_cycle).round() as usize;
        Ok(self.n_samples - len.min(self.n_samples)..self.n_samples)
    }
}

/// What the design must meet.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case", tag = "kind")]
pub enum Target {
    /// Cycle means of the stroke-frame quantities `[thrust, lift, side force (N), roll, yaw,
    /// pitch moment (N·mm)]` ([`flapssm_wing::stroke_loads`]); `None` leaves one free.
    CycleMeans {
        /// The targets, `None` where free.
        values: [Option<f64>; 6],
    },
    /// Wing-frame loads `[F_x, F_y (N), M_x, M_y, M_z (N·mm)]` at every sample of the window.
    History {
        /// One row per window sample.
        outputs: Vec<[f64; 5]>,
    },
}

/// A design problem (module docs).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DesignProblem {
    /// The target.
    pub target: Target,
    /// Time grid and window.
    pub grid: DesignGrid,
    /// Flapping frequency of the design (Hz).
    pub frequency_hz: f64,
    /// The measured set's frequencies (Hz): a design outside them is refused.
    pub frequency_range_hz: [f64; 2],
    /// Harmonics per angle.
    pub harmonics: usize,
    /// Ramp-in from rest (cycles).
    pub ramp_cycles: f64,
    /// Limits on angles, rates and accelerations.
    pub limits: KinematicLimits,
    /// Scales of the 7 stroke-frame quantities (their spread over the measured set).
    pub quantity_scales: [f64; 7],
    /// Scales of the 5 wing-frame outputs.
    pub output_scales: [f64; 5],
    /// Largest |cycle mean| of each stroke-frame quantity over the measured set.
    pub reachable: [f64; 7],
    /// Weight κ of the predictive variance (the robust term).
    pub robust_weight: f64,
    /// Weight of the mean aerodynamic power (per its scale; 0: power free).
    pub power_weight: f64,
    /// Weight μ of the limits' penalty.
    pub limit_weight: f64,
    /// Sensor distance from the stroke axis (m).
    pub sensor_radius_m: f64,
}

fn positive_finite(field: &str, values: &[f64]) -> Result<(), DesignError> {
    for (i, v) in values.iter().enumerate() {
        if !(*v > 0.0 && v.is_finite()) {
            let f = if values.len() > 1 {
                format!("{field}[{i}]")
            } else {
                field.to_string()
            };
            return Err(DesignError::invalid(
                f,
                format!("{v}: must be finite and > 0"),
            ));
        }
    }
    Ok(())
}

impl DesignProblem {
    /// Checks the problem, naming the field: the frequency within the measured set's, the
    /// targets finite and reachable (within [`REACH_MARGIN`] × the measured set's largest cycle
    /// mean), a history as long as the window, weights ≥ 0, scales and limits > 0.
    ///
    /// # Errors
    /// [`DesignError::Invalid`].
    pub fn check(&self) -> Result<Range<usize>, DesignError> {
        let f = self.frequency_hz;
        let [lo, hi] = self.frequency_range_hz;
        if !f.is_finite() || f < lo || f > hi {
            return Err(DesignError::invalid(
                "frequency_hz",
                format!("{f} Hz is outside the measured set's {lo:.3}–{hi:.3} Hz"),
            ));
        }
        positive_finite("ramp_cycles", &[self.ramp_cycles])?;
        let window = self.grid.window(f, self.ramp_cycles)?;
        self.limits
            .check()
            .map_err(|e| DesignError::invalid("limits", e.to_string()))?;
        if self.harmonics == 0 || self.harmonics > 16 {
            return Err(DesignError::invalid(
                "harmonics",
                format!("{}: must be in 1..=16", self.harmonics),
            ));
        }
        positive_finite("ramp_cycles", &[self.ramp_cycles])?;
        positive_finite("quantity_scales", &self.quantity_scales)?;
        positive_finite("output_scales", &self.output_scales)?;
        positive_finite("sensor_radius_m", &[self.sensor_radius_m])?;
        for (field, w) in [
            ("robust_weight", self.robust_weight),
            ("power_weight", self.power_weight),
            ("limit_weight", self.limit_weight),
        ] {
            if !(w >= 0.0 && w.is_finite()) {
                return Err(DesignError::invalid(
                    field,
                    format!("{w}: must be finite and ≥ 0"),
                ));
            }
        }
        match &self.target {
            Target::CycleMeans { values } => {
                if values.iter().all(Option::is_none) && self.power_weight == 0.0 {
                    return Err(DesignError::invalid(
                        "target",
                        "no load is targeted and power is free: nothing to design for",
                    ));
                }
                for (i, v) in values.iter().enumerate() {
                    let Some(v) = v else { continue };
                    let field = format!("target.{}", QUANTITY_NAMES[i]);
                    if !v.is_finite() {
                        return Err(DesignError::invalid(field, format!("{v} is not finite")));
                    }
                    let reach = REACH_MARGIN * self.reachable[i];
                    if v.abs() > reach {
                        return Err(DesignError::invalid(
                            field,
                            format!(
                                "{v} is unreachable: the measured set's cycle means reach {:.4} \
                                 in magnitude (targets up to {REACH_MARGIN} × that are accepted)",
                                self.reachable[i]
                            ),
                        ));
                    }
                }
            }
            Target::History { outputs } => {
                if outputs.len() != window.len() {
                    return Err(DesignError::invalid(
                        "target.outputs",
                        format!(
                            "{} rows, the window at {f} Hz has {} samples",
                            outputs.len(),
                            window.len()
                        ),
                    ));
                }
                if let Some(n) = outputs
                    .iter()
                    .position(|r| r.iter().any(|v| !v.is_finite()))
                {
                    return Err(DesignError::invalid(
                        format!("target.outputs[{n}]"),
                        "not finite",
                    ));
                }
            }
        }
        Ok(window)
    }
}
