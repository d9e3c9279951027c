//! The rig's stand-in as a second judge of a design: the published model (fitted to the rig's
//! loads, [`crate::rig`]) predicts what the rig would have measured for a design's kinematics.
//!
//! It predicts in the rig's standardized units, from inputs standardized on the paper's 512
//! training trajectories, as the rig check does. Those units become newtons and newton-
//! millimetres through the plant's own output statistics on the same 512 trajectories — the
//! assumption of the rig check, which compares z-scores, made explicit: the rig's loads spread
//! about their mean as the wing's do. A design's cycle means on the stand-in are then read as
//! on the wing ([`super::cycle_means`]).

use flapssm_prssm::PrssmModel;
use flapssm_wing::kinematics::{EulerState, WingKinematics};
use flapssm_wing::trajectories::paper::{PAPER_N_TRAIN, PAPER_N_TRAJECTORIES, paper_kinematics};

use super::{DesignContext, cycle_means};
use crate::error::{JobError, Result};
use crate::rig::{input_statistics, on_paper_inputs};

/// The published model on physical inputs, with the plant's output scale.
pub struct RigStandIn {
    model: PrssmModel,
    output_mean: [f64; 5],
    output_std: [f64; 5],
    particles: usize,
    seed: u64,
}

impl RigStandIn {
    /// The stand-in of `reference` (the published model, standardized units) for the measured
    /// set of `ctx`; predictions with `particles` particles from `seed`.
    ///
    /// # Errors
    /// [`JobError::Mismatch`] for a reference that is not 7 → 5; the paper's kinematics.
    pub fn new(
        reference: &PrssmModel,
        ctx: &DesignContext,
        particles: usize,
        seed: u64,
    ) -> Result<Self> {
        if reference.config.n_input != 7 || reference.config.n_output != 5 {
            return Err(JobError::Mismatch {
                what: "rig reference".into(),
                expected: "a model of 7 inputs and 5 outputs".into(),
                found: format!(
                    "{} inputs, {} outputs",
                    reference.config.n_input, reference.config.n_output
                ),
            });
        }
        let (mean, std) = input_statistics(&paper_kinematics(PAPER_N_TRAJECTORIES)?);
        let rows: Vec<&[f64; 5]> = ctx.cases[..PAPER_N_TRAIN]
            .iter()
            .flat_map(|c| c.outputs.iter())
            .collect();
        let n = rows.len() as f64;
        let output_mean: [f64; 5] =
            std::array::from_fn(|k| rows.iter().map(|r| r[k]).sum::<f64>() / n);
        let output_std = std::array::from_fn(|k| {
            (rows
                .iter()
                .map(|r| (r[k] - output_mean[k]).powi(2))
                .sum::<f64>()
                / n)
                .sqrt()
        });
        Ok(Self {
            model: on_paper_inputs(reference, &mean, &std),
            output_mean,
            output_std,
            particles,
            seed,
        })
    }

    /// The stand-in's cycle means of the 7 stroke-frame quantities for Euler `states` at the
    /// dataset rate, over `window`.
    ///
    /// # Errors
    /// [`JobError::Prssm`] when the prediction fails.
    pub fn cycle_means(
        &self,
        states: &[EulerState],
        window: std::ops::Range<usize>,
        sensor_radius_m: f64,
    ) -> Result<[f64; 7]> {
        let inputs: Vec<f64> = states
            .iter()
            .flat_map(|s| WingKinematics::from_euler(s).inputs())
            .collect();
        let p = self
            .model
            .predict_inputs(&inputs, self.particles, self.seed)
            .map_err(|e| JobError::Prssm {
                what: "rig stand-in prediction".into(),
                source: e.into(),
            })?;
        let loads: Vec<[f64; 5]> = p
            .output_mean
            .chunks_exact(5)
            .map(|z| std::array::from_fn(|k| z[k] * self.output_std[k] + self.output_mean[k]))
            .collect();
        Ok(cycle_means(&loads, states, window, sensor_radius_m))
    }
}
