//! Kinematics chosen with a load model, verified on the virtual wing.
//!
//! The plant is the default virtual wing. A design is judged by the loads the wing makes, its
//! exact aerodynamic loads at the sensor ([`exact_wing`]: the sensor chain's noise, drift,
//! residuals and filter off), so that a small target is not lost in a sensor's drift; the
//! closed loop ([`control`]) flies the wing with its whole sensor chain, as a controller
//! reads it.
//!
//! [`DesignContext::paper`] reads what a design needs from the paper's 548 measured
//! trajectories run through the plant: the kinematic limits (largest angle, rate and
//! acceleration of the 512 training trajectories after the first 93 samples), their
//! frequencies, the scales and reach of the stroke-frame cycle means, each trajectory's
//! harmonic fit (the starts of a design) and, for the 36 test trajectories, the loads that
//! make achievable targets. [`design_with`] designs with one model from the training fits
//! nearest the target; [`verify`] runs a design through the plant.
//!
//! Jobs: [`target`] (one design for given cycle means), [`study`] (the held-out targets with
//! the PR-SSM, the LRQSM and the quasi-steady wing), [`hover`] (a weight held at least power),
//! [`control`] (the closed loop).

pub mod control;
pub mod hover;
pub mod standin;
pub mod study;

use flapssm_design::{
    Design, DesignGrid, DesignModel, DesignProblem, LrqsmDesign, Objective, OptimizerSettings,
    PrssmDesign, QuasiSteadyDesign, Target,
};
use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::cycles::stroke_reversals;
use flapssm_wing::kinematics::EulerState;
use flapssm_wing::sensor::DatasetSensorErrors;
use flapssm_wing::stroke_loads::mean_stroke_frame_loads;
use flapssm_wing::trajectories::SamplingConfig;
use flapssm_wing::trajectories::harmonic::{HarmonicKinematics, KinematicLimits};
use flapssm_wing::trajectories::measured::raw_states;
use flapssm_wing::trajectories::paper::{PAPER_N_TRAIN, paper_angles, paper_sampling};
use flapssm_wing::virtual_wing::{VirtualWing, VirtualWingConfig};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result};
use crate::progress::Progress;
use crate::seed::derive_seed;

/// Stream of the plant's sensor draws when a design is verified.
pub const PLANT_STREAM: u64 = 44;

/// How far beyond the training trajectories' frequencies a design may go (× the highest, ÷
/// the lowest).
pub const FREQUENCY_MARGIN: f64 = 1.1;

/// Settings of a design.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DesignSettings {
    /// Harmonics per angle (3).
    pub harmonics: usize,
    /// Ramp-in from rest (cycles; 0.25: the measured set's 0.1–0.3 Hz leave one to three whole
    /// cycles after the 93 samples its analyses skip).
    pub ramp_cycles: f64,
    /// PR-SSM particles of the design's prediction (16).
    pub particles: usize,
    /// Starts: the training fits nearest the target (4).
    pub starts: usize,
    /// Adam.
    pub optimizer: OptimizerSettings,
    /// Weight κ of the predictive variance (0.5).
    pub robust_weight: f64,
    /// Weight of the limits' penalty (100).
    pub limit_weight: f64,
    /// Master seed (the design model's draws, the plant's sensor).
    pub seed: u64,
}

impl Default for DesignSettings {
    fn default() -> Self {
        Self {
            harmonics: 3,
            ramp_cycles: 0.25,
            particles: 16,
            starts: 4,
            optimizer: OptimizerSettings::default(),
            robust_weight: 0.5,
            limit_weight: 100.0,
            seed: 0,
        }
    }
}

impl DesignSettings {
    /// Checks the settings, naming the one out of range.
    ///
    /// # Errors
    /// [`JobError::Setting`].
    pub fn check(&self) -> Result<()> {
        let bad = |name: &str, value: String, expected: &str| {
            Err(JobError::Setting {
                name: name.into(),
                value,
                expected: expected.into(),
            })
        };
        if self.harmonics == 0 || self.harmonics > 8 {
            return bad("harmonics", self.harmonics.to_string(), "1..=8");
        }
        if self.particles == 0 {
            return bad("particles", "0".into(), "≥ 1");
        }
        if self.starts == 0 {
            return bad("starts", "0".into(), "≥ 1");
        }
        if self.optimizer.iterations == 0 {
            return bad("iterations", "0".into(), "≥ 1");
        }
        let lr = self.optimizer.learning_rate_rad;
        if !(lr > 0.0 && lr.is_finite()) {
            return bad("learning_rate", lr.to_string(), "finite and > 0");
        }
        for (name, v) in [
            ("ramp_cycles", self.ramp_cycles),
            ("robust_weight", self.robust_weight + 1.0),
            ("limit_weight", self.limit_weight + 1.0),
        ] {
            if !(v > 0.0 && v.is_finite()) {
                return bad(name, v.to_string(), "finite and ≥ 0 (ramp_cycles > 0)");
            }
        }
        Ok(())
    }
}

/// One measured trajectory run through the plant.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct MeasuredCase {
    /// Index among the paper's 548.
    pub index: usize,
    /// Its flapping frequency (Hz): from its stroke reversals, refined by the fit.
    pub frequency_hz: f64,
    /// Its harmonic fit over its periodic part.
    pub fit: HarmonicKinematics,
    /// Its smoothed Euler states at the dataset rate.
    #[serde(skip)]
    pub states: Vec<EulerState>,
    /// The plant's exact loads `[F_x, F_y, M_x, M_y, M_z]` at the dataset rate.
    pub outputs: Vec<[f64; 5]>,
}

impl MeasuredCase {
    /// Cycle means of the 7 stroke-frame quantities over `window`.
    pub fn cycle_means(&self, window: std::ops::Range<usize>, sensor_radius_m: f64) -> [f64; 7] {
        cycle_means(&self.outputs, &self.states, window, sensor_radius_m)
    }
}

/// Cycle means of the stroke-frame quantities of loads `outputs` at `states` over `window`.
pub fn cycle_means(
    outputs: &[[f64; 5]],
    states: &[EulerState],
    window: std::ops::Range<usize>,
    sensor_radius_m: f64,
) -> [f64; 7] {
    mean_stroke_frame_loads(&outputs[window.clone()], &states[window], sensor_radius_m)
}

/// What a design on the measured set needs (module docs).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct DesignContext {
    /// The plant (designs are judged on [`exact_wing`] of it).
    pub wing: VirtualWingConfig,
    /// The plant's sampling.
    pub sampling: SamplingConfig,
    /// Limits of the training trajectories.
    pub limits: KinematicLimits,
    /// The training trajectories' frequencies (Hz), widened by [`FREQUENCY_MARGIN`].
    pub frequency_range_hz: [f64; 2],
    /// SD of each stroke-frame cycle mean over the training trajectories.
    pub quantity_scales: [f64; 7],
    /// SD of each wing-frame output over the training trajectories' windows.
    pub output_scales: [f64; 5],
    /// Largest |cycle mean| of each quantity over the training trajectories.
    pub reachable: [f64; 7],
    /// Every trajectory (the first 512 the training set).
    pub cases: Vec<MeasuredCase>,
    /// Harmonics of the fits.
    pub harmonics: usize,
    /// Ramp of a design (cycles).
    pub ramp_cycles: f64,
}

/// The plant's wing without its sensor chain: its exact aerodynamic loads at the sensor.
pub fn exact_wing(wing: &VirtualWingConfig) -> VirtualWingConfig {
    VirtualWingConfig {
        sensor: flapssm_wing::sensor::SensorConfig::noise_free(),
        ..wing.clone()
    }
}

/// The plant's loads (`n_samples × 5` at the dataset rate) for raw-rate states; sensor draws
/// from `seed`.
pub fn plant_loads(
    wing: &mut VirtualWing,
    wing_cfg: &VirtualWingConfig,
    raw: &[EulerState],
    sampling: &SamplingConfig,
    seed: u64,
) -> Result<Vec<[f64; 5]>> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let errors = DatasetSensorErrors::draw(&wing_cfg.sensor, &mut rng);
    Ok(wing.measure_states(raw, sampling, 0, &errors, &mut rng)?)
}

/// The frequency of measured smoothed states: from the stroke reversals after `skip`, then
/// the one within ±3 % (0.25 % steps) whose harmonic fit leaves the least residual.
fn measured_frequency(
    states: &[EulerState],
    dt_s: f64,
    skip: usize,
    harmonics: usize,
) -> Option<(f64, HarmonicKinematics)> {
    let phi_dot: Vec<f64> = states[skip..].iter().map(|s| s.rates_rad_s[0]).collect();
    let rev = stroke_reversals(&phi_dot, dt_s, 0.05).ok()?;
    if rev.len() < 3 {
        return None;
    }
    let span = rev.last()?.time_s - rev.first()?.time_s;
    let f0 = (rev.len() - 1) as f64 / (2.0 * span);
    let angles: Vec<[f64; 3]> = states.iter().map(|s| s.angles_rad).collect();
    let mut best: Option<(f64, f64, HarmonicKinematics)> = None;
    for step in -12..=12 {
        let f = f0 * (1.0 + 0.0025 * step as f64);
        let Ok(fit) = HarmonicKinematics::fit(&angles, dt_s, f, harmonics, skip..states.len())
        else {
            continue;
        };
        let mut st = vec![EulerState::default(); states.len()];
        let periodic = HarmonicKinematics {
            ramp_cycles: 1e-9,
            ..fit.clone()
        };
        periodic.sample_into(dt_s, &mut st);
        let sse: f64 = (skip..states.len())
            .map(|t| {
                (0..3)
                    .map(|i| (st[t].angles_rad[i] - angles[t][i]).powi(2))
                    .sum::<f64>()
            })
            .sum();
        if best.as_ref().is_none_or(|b| sse < b.0) {
            best = Some((sse, f, fit));
        }
    }
    best.map(|(_, f, fit)| (f, fit))
}

impl DesignContext {
    /// The context of the paper's measured trajectories on the plant `wing` (module docs);
    /// sensor draws of trajectory `i` from `derive_seed(seed, PLANT_STREAM, i)`.
    /// `progress.advance(1)` per trajectory.
    ///
    /// # Errors
    /// A trajectory that cannot be differentiated, simulated or fitted (named).
    pub fn paper(
        wing: &VirtualWingConfig,
        harmonics: usize,
        ramp_cycles: f64,
        seed: u64,
        progress: &dyn Progress,
    ) -> Result<Self> {
        let angles = paper_angles(flapssm_wing::trajectories::paper::PAPER_N_TRAJECTORIES);
        let sampling = paper_sampling();
        let grid = DesignGrid::paper();
        let exact = exact_wing(wing);
        VirtualWing::new(&exact)?;
        progress.start("measured set through the plant", angles.len() as u64);
        let cases: Vec<MeasuredCase> = angles
            .par_iter()
            .enumerate()
            .map_init(
                || VirtualWing::new(&exact).expect("the wing was checked"),
                |plant, (index, a)| -> Result<MeasuredCase> {
                    let raw = raw_states(a, &sampling).map_err(|source| {
                        JobError::Trajectories(
                            flapssm_wing::trajectories::TrajectoryError::Differentiate {
                                index,
                                source,
                            },
                        )
                    })?;
                    let states: Vec<EulerState> =
                        raw.iter().step_by(sampling.decimation).copied().collect();
                    let (frequency_hz, fit) = measured_frequency(
                        &states, grid.dt_s, grid.skip, harmonics,
                    )
                    .ok_or_else(|| JobError::Mismatch {
                        what: format!("measured trajectory {index}"),
                        expected: "a periodic stroke with two cycles after sample 93".into(),
                        found: "too few stroke reversals".into(),
                    })?;
                    let seed = derive_seed(seed, PLANT_STREAM, index as u64);
                    let outputs = plant_loads(plant, &exact, &raw, &sampling, seed)?;
                    progress.advance(1);
                    Ok(MeasuredCase {
                        index,
                        frequency_hz,
                        fit: HarmonicKinematics { ramp_cycles, ..fit },
                        states,
                        outputs,
                    })
                },
            )
            .collect::<Result<_>>()?;
        progress.finish("");
        let train = &cases[..PAPER_N_TRAIN];
        let limits = KinematicLimits::of_states(
            &train.iter().map(|c| c.states.clone()).collect::<Vec<_>>(),
            grid.skip,
        );
        let f: Vec<f64> = train.iter().map(|c| c.frequency_hz).collect();
        let frequency_range_hz = [
            f.iter().copied().fold(f64::INFINITY, f64::min) / FREQUENCY_MARGIN,
            f.iter().copied().fold(0.0, f64::max) * FREQUENCY_MARGIN,
        ];
        let r_s = wing.sensor_radius_m;
        let mut means = Vec::with_capacity(train.len());
        let mut out_sum = [0.0; 5];
        let mut out_sq = [0.0; 5];
        let mut n_out = 0.0;
        for c in train {
            let w = grid
                .window(c.frequency_hz, ramp_cycles)
                .map_err(design_error)?;
            means.push(c.cycle_means(w.clone(), r_s));
            for t in w {
                for k in 0..5 {
                    out_sum[k] += c.outputs[t][k];
                    out_sq[k] += c.outputs[t][k] * c.outputs[t][k];
                }
                n_out += 1.0;
            }
        }
        let n = means.len() as f64;
        let mut quantity_scales = [0.0; 7];
        let mut reachable = [0.0_f64; 7];
        for i in 0..7 {
            let m = means.iter().map(|q| q[i]).sum::<f64>() / n;
            let v = means.iter().map(|q| (q[i] - m).powi(2)).sum::<f64>() / n;
            quantity_scales[i] = v.sqrt();
            reachable[i] = means.iter().fold(0.0, |a, q| a.max(q[i].abs()));
        }
        let output_scales = std::array::from_fn(|k| {
            let m = out_sum[k] / n_out;
            (out_sq[k] / n_out - m * m).max(0.0).sqrt()
        });
        Ok(Self {
            wing: wing.clone(),
            sampling,
            limits,
            frequency_range_hz,
            quantity_scales,
            output_scales,
            reachable,
            cases,
            harmonics,
            ramp_cycles,
        })
    }

    /// The design problem of `target` at `frequency_hz`.
    pub fn problem(
        &self,
        target: Target,
        frequency_hz: f64,
        settings: &DesignSettings,
        power_weight: f64,
    ) -> DesignProblem {
        DesignProblem {
            target,
            grid: DesignGrid::paper(),
            frequency_hz,
            frequency_range_hz: self.frequency_range_hz,
            harmonics: self.harmonics,
            ramp_cycles: self.ramp_cycles,
            limits: self.limits,
            quantity_scales: self.quantity_scales,
            output_scales: self.output_scales,
            reachable: self.reachable,
            robust_weight: settings.robust_weight,
            power_weight,
            limit_weight: settings.limit_weight,
            sensor_radius_m: self.wing.sensor_radius_m,
        }
    }

    /// The `n` training fits whose plant cycle means at their own windows are nearest
    /// `values` (scaled distance over the targeted quantities; every fit alike when none is
    /// targeted), excluding trajectory `exclude`.
    pub fn starts(
        &self,
        values: &[Option<f64>; 6],
        n: usize,
        exclude: Option<usize>,
    ) -> Vec<Vec<f64>> {
        let grid = DesignGrid::paper();
        let mut scored: Vec<(f64, usize)> = self.cases[..PAPER_N_TRAIN]
            .iter()
            .filter(|c| Some(c.index) != exclude)
            .filter_map(|c| {
                let w = grid.window(c.frequency_hz, self.ramp_cycles).ok()?;
                let q = c.cycle_means(w, self.wing.sensor_radius_m);
                let d: f64 = values
                    .iter()
                    .enumerate()
                    .filter_map(|(i, v)| v.map(|v| ((q[i] - v) / self.quantity_scales[i]).powi(2)))
                    .sum();
                Some((d, c.index))
            })
            .collect();
        scored.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        scored
            .iter()
            .take(n)
            .map(|&(_, i)| self.cases[i].fit.coefficients_rad.clone())
            .collect()
    }
}

fn design_error(e: flapssm_design::DesignError) -> JobError {
    JobError::Design(e)
}

/// The design models a job can use.
pub enum ModelChoice<'a> {
    /// A PR-SSM (exact gradients).
    Prssm(&'a PrssmModel),
    /// An LRQSM.
    Lrqsm(&'a LrqsmModel),
    /// The quasi-steady wing (L0 of the ideal plate: aligned, the chordwise Kirchhoff force
    /// on, no sensor chain).
    QuasiSteady,
}

impl ModelChoice<'_> {
    /// The model's name in reports.
    pub fn name(&self) -> &'static str {
        match self {
            Self::Prssm(_) => "prssm",
            Self::Lrqsm(_) => "lrqsm",
            Self::QuasiSteady => "quasi-steady",
        }
    }

    fn build(&self, settings: &DesignSettings) -> Result<Box<dyn DesignModel>> {
        Ok(match self {
            Self::Prssm(m) => {
                let seed = derive_seed(settings.seed, PLANT_STREAM + 1, 0);
                Box::new(PrssmDesign::new(m, settings.particles, seed).map_err(design_error)?)
            }
            Self::Lrqsm(m) => Box::new(LrqsmDesign::new((*m).clone()).map_err(design_error)?),
            Self::QuasiSteady => {
                let mut cfg = VirtualWingConfig::ideal();
                cfg.fidelity = flapssm_wing::virtual_wing::Fidelity::L0;
                Box::new(QuasiSteadyDesign::new(&cfg).map_err(design_error)?)
            }
        })
    }
}

/// A design with `model` for `problem` from `starts`.
///
/// # Errors
/// [`JobError::Setting`] naming a bad target or setting; the model's errors.
pub fn design_with(
    model: &ModelChoice<'_>,
    problem: &DesignProblem,
    starts: &[Vec<f64>],
    settings: &DesignSettings,
) -> Result<Design> {
    settings.check()?;
    let objective = Objective::new(problem, model.build(settings)?).map_err(design_error)?;
    flapssm_design::design(&objective, starts, &settings.optimizer).map_err(design_error)
}

/// What the plant did with a design.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Achieved {
    /// Cycle means of the 7 stroke-frame quantities over the design's window.
    pub cycle_means: [f64; 7],
    /// The plant's wing-frame loads over the window.
    pub outputs: Vec<[f64; 5]>,
}

/// Runs `kinematics` through the plant of `ctx` ([`exact_wing`]; `seed` seeds what sensor
/// draws remain) and reads its loads over `window`.
///
/// # Errors
/// The plant's errors.
pub fn verify(
    ctx: &DesignContext,
    kinematics: &HarmonicKinematics,
    window: std::ops::Range<usize>,
    seed: u64,
) -> Result<Achieved> {
    let exact = exact_wing(&ctx.wing);
    let mut wing = VirtualWing::new(&exact)?;
    let raw = kinematics.spec().sample_raw(&ctx.sampling);
    let outputs = plant_loads(&mut wing, &exact, &raw, &ctx.sampling, seed)?;
    let states: Vec<EulerState> = raw
        .iter()
        .step_by(ctx.sampling.decimation)
        .copied()
        .collect();
    Ok(Achieved {
        cycle_means: cycle_means(&outputs, &states, window.clone(), ctx.wing.sensor_radius_m),
        outputs: outputs[window].to_vec(),
    })
}
