//! The virtual robotic wing: a rigid flat plate flapping in oil, its aerodynamics at a chosen
//! fidelity, and the measurement chain of the experiment.
//!
//! Per trajectory: the Euler angles are sampled at the raw rate (250 Hz), the wing-frame
//! kinematics ([`WingKinematics`]) drive the blade-element integrator
//! ([`BladeElement`]) whose strips run the fidelity's [`SectionModel`](crate::aero::SectionModel),
//! giving F_x, F_y (N) and M_x, M_y, M_z (N·mm) about the sensor origin (default: wing root on
//! the pitch axis, r_s = r0). The sensor chain ([`crate::sensor`]) adds the experiment's errors,
//! low-passes and decimates to the dataset rate (25 Hz). Inputs are the 7 inputs at the dataset
//! rate, from encoder-quantized, Savitzky–Golay-differentiated angles (or the analytic ones
//! when `sensor.encoder` is off). Trajectories run in parallel (rayon); trajectory i uses
//! ChaCha8 stream i of the seed, so results do not depend on threading.

use crate::aero::blade_element::{AeroError, BladeElement, BladeGeometry};
use crate::aero::unsteady::UnsteadyParams;
use crate::aero::{SectionGeometry, SectionModelFactory};
use crate::check::first_not_positive;
use crate::cycles::{self, CycleError};
use crate::dataset::{Dataset, Trajectory, ValidDataset};
use crate::dataset::{DatasetMeta, FORMAT_VERSION, Fluid, INPUT_UNITS, OUTPUT_UNITS, WingGeometry};
use crate::kinematics::{EulerState, WingKinematics, rotation_global_from_wing};
use crate::lattice::{LatticeError, VortexLatticeParams, VortexLatticeWing};
use crate::mount::Mount;
use crate::sensor::{DatasetSensorErrors, SensorConfig, measure};
use crate::trajectories::{GeneratorConfig, TrajectoryError, TrajectorySpec};
use crate::vec3::{add, cross};
use crate::vortex::{StripLdvmFactory, StripLdvmParams, VortexError};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Standard gravity (m/s²).
pub const GRAVITY_M_S2: f64 = 9.806_65;

/// Aerodynamic fidelity.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "lowercase")]
pub enum Fidelity {
    /// Quasi-steady ([`crate::aero::quasi_steady`]): the default wing's, the closest of the
    /// four to the rig (docs/rig-agreement.md).
    #[default]
    L0,
    /// Unsteady low-order ([`crate::aero::unsteady`]).
    L1,
    /// Vortex method strips ([`crate::vortex`]): 2-D vortex sheets per strip with a free
    /// wake (chaotic, with LEV bursts; docs/vortex-method.md).
    L2,
    /// Unsteady vortex lattice of the whole plate with a prescribed shed wake
    /// ([`crate::lattice`]): repeatable, not chaotic, no bursts (docs/vortex-method.md).
    L3,
}

impl std::str::FromStr for Fidelity {
    type Err = SimulateError;
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "l0" => Ok(Fidelity::L0),
            "l1" => Ok(Fidelity::L1),
            "l2" => Ok(Fidelity::L2),
            "l3" => Ok(Fidelity::L3),
            _ => Err(SimulateError::UnknownFidelity {
                name: s.to_string(),
            }),
        }
    }
}

/// Errors of the simulator.
#[derive(Debug, Error)]
#[non_exhaustive]
pub enum SimulateError {
    /// Unknown fidelity name.
    #[error("unknown fidelity `{name}` (expected l0, l1, l2 or l3)")]
    UnknownFidelity {
        /// The name given.
        name: String,
    },
    /// The L2 (LDVM) settings are invalid.
    #[error("invalid L2 setting: {0}")]
    InvalidL2(VortexError),
    /// The L3 (vortex-lattice) settings are invalid.
    #[error("invalid L3 setting: {0}")]
    InvalidL3(#[from] LatticeError),
    /// A configuration value is out of range.
    #[error("invalid simulator setting `{field}` = {value}: {reason}")]
    InvalidConfig {
        /// Field name.
        field: &'static str,
        /// Its value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
    /// Bad aerodynamic parameters.
    #[error(transparent)]
    Aero(#[from] AeroError),
    /// Trajectory generation failed.
    #[error(transparent)]
    Trajectory(#[from] TrajectoryError),
    /// U_ref of a trajectory could not be computed.
    #[error("trajectory {index}: U_ref: {source}")]
    Cycle {
        /// Trajectory index.
        index: usize,
        /// Cause.
        source: CycleError,
    },
    /// Differentiating the encoder angles failed.
    #[error("trajectory {index}: encoder differentiation: {source}")]
    Differentiate {
        /// Trajectory index.
        index: usize,
        /// Cause.
        source: crate::differentiate::DifferentiateError,
    },
    /// Non-finite loads were produced.
    #[error("trajectory {index}: non-finite load at raw sample {sample}")]
    NonFinite {
        /// Trajectory index.
        index: usize,
        /// Raw sample index.
        sample: usize,
    },
    /// The assembled dataset failed [`Dataset::validate`].
    #[error("the simulated dataset is invalid: {0}")]
    Invalid(#[from] crate::dataset::DatasetError),
}

/// The virtual wing: geometry, fluid, fidelity, aerodynamic and sensor parameters.
///
/// [`Default`] is the default wing of every command, the one closest to the paper's rig by the
/// published model's prediction of its loads (docs/rig-agreement.md): the quasi-steady L0
/// without the chordwise Kirchhoff force, the plate 4.5° off the pitch encoder's zero and the
/// sensor's axes ([`Mount`]), identified on the paper's 512 training trajectories, and the
/// sensor chain without random cross-axis coupling (the mount is the rig's coupling).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct VirtualWingConfig {
    /// Aerodynamic fidelity (L0).
    pub fidelity: Fidelity,
    /// Plate geometry (0.18 × 0.06 m, r0 = 0.055 m, pitch axis at 15 % chord, U_ref at 0.235 m).
    pub wing: WingGeometry,
    /// Fluid (ρ = 800 kg/m³, ν = 1.05e-5 m²/s: Re = U_ref c/ν ≈ 1000 at the measured
    /// trajectories' U_ref = 0.175 m/s; see [`Fluid::default`]).
    pub fluid: Fluid,
    /// Sensor origin on the pitch axis, distance from the stroke axis (m; 0.055 = wing root).
    pub sensor_radius_m: f64,
    /// The plate's and the sensor's angles on the pitch shaft ([`Mount`]; the default wing's
    /// plate at 4.5°, its sensor at 0°: [`RIG_MOUNT`]).
    pub mount: Mount,
    /// Blade-element strips (Gauss–Legendre; 8, within 0.5 % of peak of 40 strips).
    pub n_strips: usize,
    /// L0/L1 parameters (L0 uses only `aero.quasi_steady`; the default wing's has no
    /// chordwise Kirchhoff force: a sharp-edged plate does not hold the leading-edge suction
    /// that carries it, and the rig shows none, docs/rig-agreement.md).
    pub aero: UnsteadyParams,
    /// L2 parameters (strip LDVM, docs/vortex-method.md).
    pub l2: StripLdvmParams,
    /// Blade-element strips at L2 (Gauss–Legendre; 2, exact for ∫r² and ∫r³; each strip is a
    /// vortex simulation, so `n_strips` applies to L0/L1 only).
    pub l2_strips: usize,
    /// L3 parameters (vortex lattice, [`crate::lattice`]).
    pub l3: VortexLatticeParams,
    /// Sensor and post-processing (the default wing's: [`SensorConfig::default`] without the
    /// random cross-axis coupling — the rig's chordwise channels follow its normal force with
    /// one sign, which a coupling of 1 % of full scale would make a coin toss, and the mount
    /// already is the rig's coupling; docs/rig-agreement.md).
    pub sensor: SensorConfig,
}

/// The rig's mount as `flapssm rig fit-mount` identified it on the paper's 512 training
/// trajectories (plate grid 2–7° by 0.5°, sensor −3–3° by 0.5°, the L0 wing without the
/// chordwise Kirchhoff force): the plate 4.5° off the encoder's zero and the sensor's axes.
pub const RIG_MOUNT: Mount = Mount {
    plate_pitch_deg: 4.5,
    sensor_pitch_deg: 0.0,
};

impl Default for VirtualWingConfig {
    fn default() -> Self {
        let wing = WingGeometry::default();
        let mut aero = UnsteadyParams::default();
        aero.quasi_steady.added_mass_chordwise = false;
        Self {
            fidelity: Fidelity::L0,
            sensor_radius_m: wing.root_offset_m,
            mount: RIG_MOUNT,
            wing,
            fluid: Fluid::default(),
            n_strips: 8,
            aero,
            sensor: SensorConfig {
                cross_axis: false,
                ..SensorConfig::default()
            },
            l2: StripLdvmParams::default(),
            l2_strips: 2,
            l3: VortexLatticeParams::default(),
        }
    }
}

impl VirtualWingConfig {
    /// The default wing's plate with its aerodynamic levels and sensor chain as their modules
    /// define them: the plate aligned with the encoder and the sensor, the chordwise Kirchhoff
    /// force of L0/L1 on, the random cross-axis coupling on (the physics checks' wing).
    pub fn ideal() -> Self {
        Self {
            mount: Mount::default(),
            aero: UnsteadyParams::default(),
            sensor: SensorConfig::default(),
            ..Self::default()
        }
    }

    fn blade_geometry(&self) -> BladeGeometry {
        BladeGeometry {
            span_m: self.wing.span_m,
            chord_m: self.wing.chord_m,
            root_offset_m: self.wing.root_offset_m,
            pitch_axis_frac: self.wing.pitch_axis_frac,
            density_kg_m3: self.fluid.density_kg_m3,
            sensor_radius_m: self.sensor_radius_m,
        }
    }

    /// Validates the configuration.
    pub fn check(&self) -> Result<(), SimulateError> {
        self.blade_geometry().check()?;
        let positive = [
            (
                "aero.lev_time_constant_chords",
                self.aero.lev_time_constant_chords,
            ),
            (
                "aero.inflow_distance_chords",
                self.aero.inflow_distance_chords,
            ),
            ("aero.inflow_decay_rad", self.aero.inflow_decay_rad),
            (
                "fluid.kinematic_viscosity_m2_s",
                self.fluid.kinematic_viscosity_m2_s,
            ),
            ("sensor.cutoff_hz", self.sensor.cutoff_hz),
            ("wing.u_ref_radius_m", self.wing.u_ref_radius_m),
        ];
        if let Some((field, value)) = self.mount.out_of_range() {
            return Err(SimulateError::InvalidConfig {
                field,
                value,
                reason: "must be within ±45°",
            });
        }
        if let Some(v) = self.sensor.home_pose_deg.iter().find(|v| !v.is_finite()) {
            return Err(SimulateError::InvalidConfig {
                field: "sensor.home_pose_deg",
                value: *v,
                reason: "must be finite",
            });
        }
        if let Some((field, value)) = first_not_positive(&positive) {
            return Err(SimulateError::InvalidConfig {
                field,
                value,
                reason: "must be finite and > 0",
            });
        }
        for (field, n) in [("n_strips", self.n_strips), ("l2_strips", self.l2_strips)] {
            if n == 0 || n > 200 {
                return Err(SimulateError::InvalidConfig {
                    field,
                    value: n as f64,
                    reason: "must be in 1..=200",
                });
            }
        }
        if self.fidelity == Fidelity::L2 {
            let section = SectionGeometry {
                chord_m: self.wing.chord_m,
                pitch_axis_frac: self.wing.pitch_axis_frac,
                radius_m: self.wing.u_ref_radius_m,
                density_kg_m3: self.fluid.density_kg_m3,
            };
            self.l2.check(&section).map_err(SimulateError::InvalidL2)?;
        }
        if self.fidelity == Fidelity::L3 {
            self.l3.check()?;
        }
        Ok(())
    }

    /// The section-model factory of a blade-element fidelity (`None` for L3, which models the
    /// whole plate).
    pub fn factory(&self) -> Option<Box<dyn SectionModelFactory>> {
        match self.fidelity {
            Fidelity::L0 => Some(Box::new(self.aero.quasi_steady)),
            Fidelity::L1 => Some(Box::new(self.aero)),
            Fidelity::L2 => Some(Box::new(StripLdvmFactory { params: self.l2 })),
            Fidelity::L3 => None,
        }
    }
}

/// Everything `flapssm simulate` needs: the wing and the trajectory generator.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, Default)]
#[serde(default)]
pub struct SimulationConfig {
    /// The virtual wing.
    pub wing: VirtualWingConfig,
    /// The trajectories (count, split, seed, sampling, families).
    pub trajectories: GeneratorConfig,
}

/// A wing ready to run trajectories (holds the per-strip models or the lattice; reuse it).
pub struct VirtualWing {
    cfg: VirtualWingConfig,
    aero: Aerodynamics,
}

/// The aerodynamic model of a wing: strips (L0–L2) or the whole-plate lattice (L3).
enum Aerodynamics {
    Strips(BladeElement),
    Lattice(Box<VortexLatticeWing>),
}

impl VirtualWing {
    /// Builds the wing.
    pub fn new(cfg: &VirtualWingConfig) -> Result<Self, SimulateError> {
        cfg.check()?;
        let aero = match cfg.factory() {
            Some(factory) => {
                let strips = match cfg.fidelity {
                    Fidelity::L2 => cfg.l2_strips,
                    _ => cfg.n_strips,
                };
                let blade = BladeElement::new(cfg.blade_geometry(), strips, factory.as_ref())?;
                Aerodynamics::Strips(blade)
            }
            None => Aerodynamics::Lattice(Box::new(VortexLatticeWing::new(
                &cfg.l3,
                &cfg.wing,
                &cfg.fluid,
                cfg.sensor_radius_m,
            )?)),
        };
        Ok(Self {
            cfg: cfg.clone(),
            aero,
        })
    }

    /// Exact aerodynamic loads [F_x, F_y (N), M_x, M_y, M_z (N·mm)] for Euler states sampled
    /// every `dt_s` from rest, written into `out` (same length as `states`).
    pub fn aero_loads_into(&mut self, states: &[EulerState], dt_s: f64, out: &mut [[f64; 5]]) {
        match &mut self.aero {
            Aerodynamics::Strips(blade) => {
                blade.reset();
                for (k, (st, y)) in states.iter().zip(out.iter_mut()).enumerate() {
                    let kin = WingKinematics::from_euler(st);
                    *y = blade.step(&kin, if k == 0 { 0.0 } else { dt_s });
                }
            }
            Aerodynamics::Lattice(lattice) => lattice.loads_into(states, dt_s, out),
        }
    }

    /// Static (weight − buoyancy) and rigid-plate inertial loads at the sensor for one state.
    ///
    /// Plate mass m = ρ_p·h·S and volume h·S, centroid p_c = (0, (x̂0 − ½)c, r0 + span/2) in the
    /// wing frame, sensor at p_s = (0, 0, r_s). Static: F = R_0wᵀ(0, −(m − ρV)g, 0),
    /// M = (p_c − p_s) × F. Inertial (d'Alembert): F = −m(ω̇ × p_c + ω × (ω × p_c)),
    /// M = (p_c − p_s) × F − (I ω̇ + ω × I ω), I = diag(m(c² + s²), m s², m c²)/12.
    pub fn plate_loads(&self, st: &EulerState) -> ([f64; 5], [f64; 5]) {
        let w = &self.cfg.wing;
        let s = &self.cfg.sensor;
        let volume = s.plate_thickness_m * w.span_m * w.chord_m;
        let m = s.plate_density_kg_m3 * volume;
        let r = rotation_global_from_wing(&st.angles_rad);
        let g_net = -(m - self.cfg.fluid.density_kg_m3 * volume) * GRAVITY_M_S2;
        let f_static = [r[1][0] * g_net, r[1][1] * g_net, r[1][2] * g_net];
        let pc = [
            0.0,
            (w.pitch_axis_frac - 0.5) * w.chord_m,
            w.root_offset_m + 0.5 * w.span_m,
        ];
        let arm = [pc[0], pc[1], pc[2] - self.cfg.sensor_radius_m];
        let kin = WingKinematics::from_euler(st);
        let (om, omd) = (kin.omega_rad_s, kin.omega_dot_rad_s2);
        let acc = add(cross(omd, pc), cross(om, cross(om, pc)));
        let f_in = acc.map(|a| -m * a);
        let inertia = [
            m * (w.chord_m * w.chord_m + w.span_m * w.span_m) / 12.0,
            m * w.span_m * w.span_m / 12.0,
            m * w.chord_m * w.chord_m / 12.0,
        ];
        let i_om = [inertia[0] * om[0], inertia[1] * om[1], inertia[2] * om[2]];
        let i_omd = [
            inertia[0] * omd[0],
            inertia[1] * omd[1],
            inertia[2] * omd[2],
        ];
        let gyro = add(i_omd, cross(om, i_om));
        let m_in = cross(arm, f_in);
        let m_st = cross(arm, f_static);
        (
            [
                f_static[0],
                f_static[1],
                1e3 * m_st[0],
                1e3 * m_st[1],
                1e3 * m_st[2],
            ],
            [
                f_in[0],
                f_in[1],
                1e3 * (m_in[0] - gyro[0]),
                1e3 * (m_in[1] - gyro[1]),
                1e3 * (m_in[2] - gyro[2]),
            ],
        )
    }

    /// Simulates one trajectory: raw loads, sensor chain, decimation, inputs and U_ref.
    pub fn simulate(
        &mut self,
        spec: &TrajectorySpec,
        sampling: &crate::trajectories::SamplingConfig,
        index: usize,
        errors: &DatasetSensorErrors,
        rng: &mut ChaCha8Rng,
    ) -> Result<Trajectory, SimulateError> {
        let states = spec.sample_raw(sampling);
        let family = spec.family.label();
        self.simulate_states(&states, family, sampling, index, errors, rng)
    }

    /// [`Self::simulate`] of given raw-rate states (`n_samples · decimation`, every
    /// `raw_dt_s`), labelled `family`.
    pub fn simulate_states(
        &mut self,
        states: &[EulerState],
        family: &str,
        sampling: &crate::trajectories::SamplingConfig,
        index: usize,
        errors: &DatasetSensorErrors,
        rng: &mut ChaCha8Rng,
    ) -> Result<Trajectory, SimulateError> {
        let outputs = self.measure_states(states, sampling, index, errors, rng)?;
        self.trajectory_of(states, family, sampling, index, outputs)
    }

    /// The sensor's loads `[F_x, F_y, M_x, M_y, M_z]` (N, N·mm) at the dataset rate
    /// (`n_samples` of them) for raw-rate states: the aerodynamics at the plate's mount, the
    /// plate's static and inertial residuals, the sensor chain, decimation. Errors name
    /// trajectory `index`.
    pub fn measure_states(
        &mut self,
        states: &[EulerState],
        sampling: &crate::trajectories::SamplingConfig,
        index: usize,
        errors: &DatasetSensorErrors,
        rng: &mut ChaCha8Rng,
    ) -> Result<Vec<[f64; 5]>, SimulateError> {
        let mount = self.cfg.mount;
        let plate_states: std::borrow::Cow<[EulerState]> = if mount.plate_aligned() {
            states.into()
        } else {
            states.iter().map(|st| mount.plate_state(st)).collect()
        };
        let mut raw = vec![[0.0; 5]; states.len()];
        self.aero_loads_into(&plate_states, sampling.raw_dt_s(), &mut raw);
        if let Some(sample) = raw.iter().position(|y| y.iter().any(|v| !v.is_finite())) {
            return Err(SimulateError::NonFinite { index, sample });
        }
        let (mut static_loads, mut inertial_loads): (Vec<[f64; 5]>, Vec<[f64; 5]>) =
            if self.cfg.sensor.static_residual || self.cfg.sensor.inertial_residual {
                plate_states.iter().map(|st| self.plate_loads(st)).unzip()
            } else {
                (vec![[0.0; 5]; states.len()], vec![[0.0; 5]; states.len()])
            };
        let home = EulerState {
            angles_rad: self.cfg.sensor.home_pose_deg.map(f64::to_radians),
            ..EulerState::default()
        };
        let mut home_loads = self.plate_loads(&mount.plate_state(&home)).0;
        for loads in raw
            .iter_mut()
            .chain(&mut static_loads)
            .chain(&mut inertial_loads)
            .chain(std::iter::once(&mut home_loads))
        {
            mount.plate_to_sensor(loads);
        }
        let mut outputs = measure(
            &self.cfg.sensor,
            errors,
            &mut raw,
            &static_loads,
            &inertial_loads,
            &home_loads,
            sampling.raw_rate_hz,
            sampling.decimation,
            rng,
        );
        outputs.truncate(sampling.n_samples);
        Ok(outputs)
    }

    /// The trajectory of raw-rate `states` and their measured `outputs`: the encoder's and
    /// differentiator's states, decimated, their inputs and U_ref.
    fn trajectory_of(
        &self,
        states: &[EulerState],
        family: &str,
        sampling: &crate::trajectories::SamplingConfig,
        index: usize,
        outputs: Vec<[f64; 5]>,
    ) -> Result<Trajectory, SimulateError> {
        let measured = if self.cfg.sensor.encoder {
            use crate::differentiate::{SavitzkyGolay, SavitzkyGolayConfig, quantize_to_encoder};
            let counts = self.cfg.sensor.encoder_counts_per_rev;
            let angles: Vec<[f64; 3]> = states
                .iter()
                .map(|s| s.angles_rad.map(|a| quantize_to_encoder(a, counts)))
                .collect();
            let sg = SavitzkyGolay::new(SavitzkyGolayConfig::default())
                .map_err(|source| SimulateError::Differentiate { index, source })?;
            let mut out = vec![EulerState::default(); angles.len()];
            let mut column = vec![0.0; angles.len()];
            sg.euler_states(&angles, sampling.raw_dt_s(), &mut out, &mut column)
                .map_err(|source| SimulateError::Differentiate { index, source })?;
            out
        } else {
            states.to_vec()
        };
        let decimated: Vec<&EulerState> = measured
            .iter()
            .step_by(sampling.decimation.max(1))
            .take(sampling.n_samples)
            .collect();
        let euler_rad: Vec<[f64; 3]> = decimated.iter().map(|s| s.angles_rad).collect();
        let inputs = decimated
            .iter()
            .map(|s| WingKinematics::from_euler(s).inputs())
            .collect();
        let dt_s = sampling.dataset_dt_s();
        let (u_ref_m_s, _) =
            cycles::published_u_ref(&euler_rad, dt_s, self.cfg.wing.u_ref_radius_m)
                .map_err(|source| SimulateError::Cycle { index, source })?;
        Ok(Trajectory {
            euler_rad,
            inputs,
            outputs: Some(outputs),
            u_ref_m_s,
            family: family.to_string(),
        })
    }
}

/// Seed offset of the sensor streams (independent of the trajectory generator's streams).
const SENSOR_SEED_SALT: u64 = 0x5e45_0f0a_11ce_d00d;

/// Simulates a whole dataset: generates the trajectories of `cfg.trajectories`, runs the wing
/// on each (in parallel on the caller's rayon pool; `progress` is called once per finished
/// trajectory) and assembles the [`Dataset`] with generator `"flapssm simulate"` and settings
/// {fidelity, the whole `SimulationConfig`, the per-dataset sensor errors, mean Re}, checked once
/// ([`ValidDataset`]).
pub fn simulate_dataset(
    cfg: &SimulationConfig,
    progress: &(dyn Fn() + Sync),
) -> Result<ValidDataset, SimulateError> {
    cfg.wing.check()?;
    let specs = cfg.trajectories.generate()?;
    let sampling = &cfg.trajectories.sampling;
    let drive = |index: usize| {
        let spec = &specs[index];
        Ok((spec.sample_raw(sampling), spec.family.label().to_string()))
    };
    let run = Run {
        wing: &cfg.wing,
        sampling,
        seed: cfg.trajectories.seed,
        n_train: cfg.trajectories.n_train,
        generator: "flapssm simulate",
        settings: serde_json::json!({ "simulation": cfg }),
    };
    run.simulate(specs.len(), &drive, progress)
}

/// Simulates the wing of `wing` on given Euler angles: `angles_rad[i]` holds trajectory `i`'s
/// rows [φ, ψ, α] (rad), `sampling.n_samples` of them every `sampling.dataset_dt_s()` (the
/// paper's measured trajectories: 470 at 25 Hz), driven at the raw rate by
/// [`crate::trajectories::measured::raw_states`]. The sensor noise is seeded by `seed`, the
/// first `n_train` trajectories are the training set, family label `"measured"`, generator
/// `"flapssm simulate (given angles)"`; `source` (where the angles come from) is recorded in
/// the metadata's settings as `angles_source`.
///
/// # Errors
/// A trajectory of the wrong length or too short to differentiate
/// ([`SimulateError::Differentiate`] naming it), and the errors of [`simulate_dataset`].
pub fn simulate_angles_dataset(
    wing: &VirtualWingConfig,
    angles_rad: &[Vec<[f64; 3]>],
    sampling: &crate::trajectories::SamplingConfig,
    seed: u64,
    n_train: usize,
    source: &str,
    progress: &(dyn Fn() + Sync),
) -> Result<ValidDataset, SimulateError> {
    wing.check()?;
    let drive = |index: usize| {
        crate::trajectories::measured::raw_states(&angles_rad[index], sampling)
            .map(|states| (states, "measured".to_string()))
            .map_err(|source| SimulateError::Differentiate { index, source })
    };
    let run = Run {
        wing,
        sampling,
        seed,
        n_train,
        generator: "flapssm simulate (given angles)",
        settings: serde_json::json!({ "wing": wing, "sampling": sampling, "angles_source": source }),
    };
    run.simulate(angles_rad.len(), &drive, progress)
}

/// What a dataset simulation shares, whatever drives the wing.
struct Run<'a> {
    wing: &'a VirtualWingConfig,
    sampling: &'a crate::trajectories::SamplingConfig,
    seed: u64,
    n_train: usize,
    generator: &'static str,
    /// Settings recorded in the metadata (the fidelity, sensor errors and mean Re are added).
    settings: serde_json::Value,
}

impl Run<'_> {
    /// Runs the wing on the raw states `drive(i)` of trajectories `0..n` in parallel.
    fn simulate(
        self,
        n: usize,
        drive: &(dyn Fn(usize) -> Result<(Vec<EulerState>, String), SimulateError> + Sync),
        progress: &(dyn Fn() + Sync),
    ) -> Result<ValidDataset, SimulateError> {
        let seed = self.seed ^ SENSOR_SEED_SALT;
        let mut dataset_rng = ChaCha8Rng::seed_from_u64(seed);
        dataset_rng.set_stream(u64::MAX);
        let errors = DatasetSensorErrors::draw(&self.wing.sensor, &mut dataset_rng);
        let run_one = |wing: &mut Result<VirtualWing, SimulateError>, index: usize| {
            let wing = wing.as_mut().map_err(|_| SimulateError::InvalidConfig {
                field: "wing",
                value: f64::NAN,
                reason: "invalid",
            })?;
            let (states, family) = drive(index)?;
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            rng.set_stream(index as u64);
            let t = wing.simulate_states(&states, &family, self.sampling, index, &errors, &mut rng);
            progress();
            t
        };
        let trajectories: Result<Vec<Trajectory>, SimulateError> = (0..n)
            .into_par_iter()
            .map_init(|| VirtualWing::new(self.wing), run_one)
            .collect();
        let trajectories = trajectories?;
        let count = trajectories.len().max(1) as f64;
        let mean_u_ref = trajectories.iter().map(|t| t.u_ref_m_s).sum::<f64>() / count;
        let reynolds =
            mean_u_ref * self.wing.wing.chord_m / self.wing.fluid.kinematic_viscosity_m2_s;
        let mut settings = serde_json::json!({
            "fidelity": self.wing.fidelity,
            "sensor_errors": errors,
            "mean_u_ref_m_s": mean_u_ref,
            "mean_reynolds_number": reynolds,
        });
        if let (Some(all), serde_json::Value::Object(extra)) =
            (settings.as_object_mut(), self.settings)
        {
            all.extend(extra);
        }
        let ds = Dataset {
            meta: DatasetMeta {
                format_version: FORMAT_VERSION,
                wing: self.wing.wing.clone(),
                fluid: self.wing.fluid.clone(),
                generator: self.generator.to_string(),
                seed: Some(self.seed),
                settings,
                input_units: INPUT_UNITS.iter().map(|s| s.to_string()).collect(),
                output_units: OUTPUT_UNITS.iter().map(|s| s.to_string()).collect(),
            },
            dt_s: self.sampling.dataset_dt_s(),
            trajectories,
            n_train: self.n_train,
        };
        Ok(ValidDataset::new(ds)?)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Each check names the field at fault.
    #[test]
    fn bad_parameters_are_named() {
        assert!(VirtualWingConfig::default().check().is_ok());
        let mut cfg = VirtualWingConfig::default();
        cfg.sensor.cutoff_hz = f64::NAN;
        assert!(
            matches!(
                cfg.check(),
                Err(SimulateError::InvalidConfig {
                    field: "sensor.cutoff_hz",
                    ..
                })
            ),
            "{:?}",
            cfg.check()
        );
        let mut cfg = VirtualWingConfig::default();
        cfg.mount.plate_pitch_deg = 60.0;
        assert!(matches!(
            cfg.check(),
            Err(SimulateError::InvalidConfig {
                field: "mount.plate_pitch_deg",
                ..
            })
        ));
        let mut cfg = VirtualWingConfig::default();
        cfg.wing.chord_m = -0.1;
        assert!(matches!(
            cfg.check(),
            Err(SimulateError::Aero(AeroError::InvalidParameter {
                name: "chord_m",
                value: -0.1,
                ..
            }))
        ));
        // The L2 and L3 settings are checked at their own fidelity.
        let mut cfg = VirtualWingConfig::default();
        cfg.l2.max_step_chords = 0.0;
        assert!(cfg.check().is_ok());
        cfg.fidelity = Fidelity::L2;
        assert!(matches!(
            cfg.check(),
            Err(SimulateError::InvalidL2(VortexError::InvalidParameter {
                name: "max_step_chords",
                ..
            }))
        ));
        let mut cfg = VirtualWingConfig::default();
        cfg.l3.step_chords = 0.0;
        assert!(cfg.check().is_ok());
        cfg.fidelity = Fidelity::L3;
        assert!(matches!(
            cfg.check(),
            Err(SimulateError::InvalidL3(LatticeError::InvalidParameter {
                name: "step_chords",
                ..
            }))
        ));
    }
}
