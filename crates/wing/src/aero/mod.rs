//! Sectional (2-D strip) aerodynamics and their blade-element integration.
//!
//! Every fidelity level is a [`SectionModel`]: a 2-D section of the plate with memory, advanced
//! one time step at a time from its in-plane kinematics. One [`blade_element::BladeElement`]
//! integrator places one section model per strip along the span and turns the sectional loads
//! into the wing-frame loads at the sensor; the output pipeline is the same for all levels.
//!
//! # Section frame and sign conventions
//!
//! The section is the plate's cut at radius r, in the wing frame's x–y plane: x_w normal to the
//! plate, y_w chordwise towards the leading edge (LE), z_w spanwise (root → tip). The pitch axis
//! lies x̂0·c behind the LE. A chord point at y (m, positive towards the LE, pitch axis at
//! y = 0) moves with normal velocity n(y) = v_x − ω_z·y.
//!
//! | level | module | memory |
//! |---|---|---|
//! | L0 quasi-steady | [`quasi_steady`] | none |
//! | L1 unsteady low-order | [`unsteady`] | Wagner (Jones), LEV lag, induced inflow |
//! | L2 vortex method | `crate::vortex` | vortex lists |

pub mod blade_element;
pub mod quasi_steady;
pub mod unsteady;

/// Geometry and fluid of one 2-D section, fixed for a run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SectionGeometry {
    /// Chord c (m).
    pub chord_m: f64,
    /// Pitch axis behind the LE as a fraction x̂0 of the chord.
    pub pitch_axis_frac: f64,
    /// Distance of the section from the stroke axis along z_w (m).
    pub radius_m: f64,
    /// Fluid density ρ (kg/m³).
    pub density_kg_m3: f64,
}

/// In-plane kinematics of one section at the end of a time step, wing-frame components.
///
/// For a strip at radius r of a wing with unit-span velocity v̂, acceleration â and angular
/// velocity ω: v = r·v̂, ṅ = r·â_x + ω_z·r·v̂_y, ṫ = r·â_y − ω_z·r·v̂_x (derivatives of the
/// components in the rotating section frame).
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SectionKinematics {
    /// Normal velocity n = v_x of the pitch-axis point (m/s).
    pub normal_velocity_m_s: f64,
    /// Chordwise velocity t = v_y of the pitch-axis point, positive towards the LE (m/s).
    pub chord_velocity_m_s: f64,
    /// ṅ, rate of change of n in the section frame (m/s²).
    pub normal_velocity_rate_m_s2: f64,
    /// ṫ, rate of change of t in the section frame (m/s²).
    pub chord_velocity_rate_m_s2: f64,
    /// In-plane rotation rate ω_z about +z_w (rad/s).
    pub rotation_rate_rad_s: f64,
    /// ω̇_z (rad/s²).
    pub rotation_acc_rad_s2: f64,
    /// The global vertical (up) in section components [x_w, y_w] (not normalized: its part
    /// along the span is left out); `None` where the wing's orientation is not known.
    pub up_section: Option<[f64; 2]>,
}

impl SectionKinematics {
    /// Speed |v| = √(n² + t²) of the pitch-axis point (m/s).
    pub fn speed_m_s(&self) -> f64 {
        self.normal_velocity_m_s.hypot(self.chord_velocity_m_s)
    }
}

/// Loads per unit span on one section, wing frame.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct SectionLoads {
    /// Normal force along +x_w (N/m).
    pub normal_n_m: f64,
    /// Chordwise force along +y_w, towards the LE (N/m).
    pub chordwise_n_m: f64,
    /// Pitching moment about the pitch axis, about +z_w (N·m/m).
    pub moment_n: f64,
}

impl std::ops::Add for SectionLoads {
    type Output = SectionLoads;

    /// Component-wise sum.
    fn add(self, other: SectionLoads) -> SectionLoads {
        SectionLoads {
            normal_n_m: self.normal_n_m + other.normal_n_m,
            chordwise_n_m: self.chordwise_n_m + other.chordwise_n_m,
            moment_n: self.moment_n + other.moment_n,
        }
    }
}

/// A 2-D sectional aerodynamic model with memory.
///
/// Contract: after [`reset`](SectionModel::reset) the fluid is at rest. The first
/// [`step`](SectionModel::step) after a reset starts the motion impulsively at `kin`
/// (`dt_s` is ignored); each later call advances the state by `dt_s > 0` to the kinematics
/// `kin` at the end of the step and returns the loads at that instant. `step` must not
/// allocate.
pub trait SectionModel: Send {
    /// Returns the model to still fluid.
    fn reset(&mut self);
    /// Advances by `dt_s` (s) to the kinematics `kin` and returns the sectional loads there.
    fn step(&mut self, kin: &SectionKinematics, dt_s: f64) -> SectionLoads;
}

/// Builds one [`SectionModel`] per strip (called once per strip per run, outside hot loops).
pub trait SectionModelFactory: Sync {
    /// A fresh model (fluid at rest) for a section of the given geometry.
    fn build(&self, section: &SectionGeometry) -> Box<dyn SectionModel>;
}
