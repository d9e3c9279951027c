//! L0: quasi-steady sectional aerodynamics (Dickinson et al. 1999; Sane & Dickinson 2002).
//!
//! Per unit span, with n, t the normal and chordwise velocity of the pitch-axis point,
//! U = √(n² + t²), q = ½ρcU² and the acute angle between chord and motion
//! α_g = atan2(|n|, |t|) ∈ [0, π/2]:
//!
//! - translation: N_tr = −sgn(n)·k_N·C_N*(α_g)·q acting at x_cp = x̂_cp(α_g)·c behind the
//!   leading side (the LE when t ≥ 0, the TE otherwise), and the chordwise force
//!   T_tr = sgn(t)·[k_N·C_T*(α_g) + (C_f,fit − C_f)·cos α_g]·q, positive towards the leading
//!   side. C_T* is the Dickinson tangential coefficient (drag at low α, a weak suction at
//!   mid α); the friction it holds is moved from the fits' Re ≈ 150 (Blasius, both faces:
//!   C_f,fit = 2·1.328/√150 = 0.217) to this wing's Re = 1000 (C_f = 0.084);
//! - rotation: N_rot = πρc²ω_z[(x̂0 − ½)U − ¼t], applied at mid-chord. For LE-first motion
//!   along the chord (t = U) this is the Sane–Dickinson force −C_rot ρ c² U ω_z with
//!   C_rot = π(¾ − x̂0); the ¼t term moves the ¾-chord point continuously to the other side
//!   when the wing moves TE-first (thin-airfoil theory);
//! - added mass (Kirchhoff, 2-D flat plate, m_a = πρc²/4, d = (½ − x̂0)c, mid-chord normal
//!   velocity n_m = n + dω_z): N_am = −m_a(ṅ + dω̇_z), M_am = −m_a[dṅ + (d² + c²/32)ω̇_z]
//!   (the physics notes' strip form). The steady Munk moment is left out (the measured
//!   x̂_cp(α) already contains the steady moment). The chordwise Kirchhoff force
//!   T_am = −m_a ω_z n_m (−ω × impulse of the normal added mass) is on by default: the
//!   Sane–Dickinson model keeps only normal forces, but the plate's chordwise load at
//!   reversal is dominated by this term (the LRQSM features α̇·v_x, α̇·|α̇| mirror it).
//!
//! C_N* and C_T* are the Dickinson fits with the offsets a symmetric flat plate cannot have
//! removed: C_N*(α) = C_N(α) − C_N(0) cos α (no normal force at zero incidence) and
//! C_T*(α) = C_T(α) − C_T(90°) sin α (no chordwise force broadside on), so the loads stay
//! continuous where n or t changes sign. [`ChordwiseModel::SkinFriction`] keeps only the
//! friction, T_tr = −C_f·q·t/U.

use super::{SectionGeometry, SectionKinematics, SectionLoads, SectionModel, SectionModelFactory};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Dickinson lift coefficient C_L(α) = 0.225 + 1.58 sin(2.13α − 7.20°), α in rad.
pub fn dickinson_lift(aoa_rad: f64) -> f64 {
    0.225 + 1.58 * (2.13 * aoa_rad - 7.20_f64.to_radians()).sin()
}

/// Dickinson drag coefficient C_D(α) = 1.92 − 1.55 cos(2.04α − 9.82°), α in rad.
pub fn dickinson_drag(aoa_rad: f64) -> f64 {
    1.92 - 1.55 * (2.04 * aoa_rad - 9.82_f64.to_radians()).cos()
}

/// Normal coefficient C_N = C_L cos α + C_D sin α of the Dickinson fits.
pub fn dickinson_normal(aoa_rad: f64) -> f64 {
    dickinson_lift(aoa_rad) * aoa_rad.cos() + dickinson_drag(aoa_rad) * aoa_rad.sin()
}

/// Tangential coefficient C_T = C_L sin α − C_D cos α of the Dickinson fits (positive
/// towards the leading side).
pub fn dickinson_tangential(aoa_rad: f64) -> f64 {
    dickinson_lift(aoa_rad) * aoa_rad.sin() - dickinson_drag(aoa_rad) * aoa_rad.cos()
}

/// Flat-plate normal coefficient C_N*(α) = C_N(α) − C_N(0) cos α, α ∈ [0, π/2] (rad).
pub fn plate_normal(aoa_rad: f64) -> f64 {
    dickinson_normal(aoa_rad) - dickinson_normal(0.0) * aoa_rad.cos()
}

/// Flat-plate tangential coefficient C_T*(α) = C_T(α) − C_T(π/2) sin α, α ∈ [0, π/2] (rad),
/// positive towards the leading side: −0.393 at 0°, 0 at 90°.
pub fn plate_tangential(aoa_rad: f64) -> f64 {
    dickinson_tangential(aoa_rad) - dickinson_tangential(0.5 * PI) * aoa_rad.sin()
}

/// Laminar skin-friction coefficient of a plate wetted on both faces, C_f = 2·1.328/√Re
/// (Blasius).
pub fn blasius_skin_friction(reynolds: f64) -> f64 {
    2.0 * 1.328 / reynolds.sqrt()
}

/// Chordwise centre of pressure x̂_cp(α) = 0.82|α|/π + 0.05, fraction of the chord behind
/// the leading side.
pub fn centre_of_pressure_frac(aoa_rad: f64) -> f64 {
    0.82 * aoa_rad.abs() / PI + 0.05
}

/// Theoretical rotational coefficient C_rot = π(¾ − x̂0).
pub fn rotational_coefficient(pitch_axis_frac: f64) -> f64 {
    PI * (0.75 - pitch_axis_frac)
}

/// The chordwise translational force model.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum ChordwiseModel {
    /// Dickinson tangential coefficient C_T*, friction moved to this wing's Re (default).
    Dickinson,
    /// Skin friction only, −C_f·q·t/U (no pressure drag, no suction).
    SkinFriction,
}

/// Settings of the quasi-steady model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct QuasiSteadyParams {
    /// Scale k_N of the translational coefficients (Re ≈ 1000, AR = 3 nuisance factor; 1.0).
    pub translational_scale: f64,
    /// Chordwise translational force model (Dickinson).
    pub chordwise: ChordwiseModel,
    /// Skin-friction coefficient C_f at this wing's Re (0.084 = Blasius at Re = 1000).
    pub skin_friction: f64,
    /// Skin-friction coefficient C_f,fit contained in the Dickinson fits (0.217 = Blasius at
    /// Re = 150).
    pub fit_skin_friction: f64,
    /// Include the rotational circulation force (true).
    pub rotational: bool,
    /// Include the added-mass loads (true).
    pub added_mass: bool,
    /// Include the chordwise Kirchhoff added-mass force T_am = −m_a ω_z n_m (true).
    pub added_mass_chordwise: bool,
}

impl Default for QuasiSteadyParams {
    fn default() -> Self {
        Self {
            translational_scale: 1.0,
            chordwise: ChordwiseModel::Dickinson,
            skin_friction: blasius_skin_friction(1000.0),
            fit_skin_friction: blasius_skin_friction(150.0),
            rotational: true,
            added_mass: true,
            added_mass_chordwise: true,
        }
    }
}

/// Signed translational coefficients of a section: N_tr = c_n·q, T_tr = c_t·q (section
/// frame), acting at `cp_from_le`·c behind the LE.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TranslationalCoefficients {
    /// Signed normal coefficient c_n.
    pub c_n: f64,
    /// Signed chordwise coefficient c_t.
    pub c_t: f64,
    /// Centre of pressure behind the LE, fraction of the chord.
    pub cp_from_le: f64,
}

/// Translational coefficients for a section moving with (n, t) (m/s) relative to the fluid
/// (see the module docs for the equations).
pub fn translational_coefficients(
    normal_m_s: f64,
    chord_m_s: f64,
    params: &QuasiSteadyParams,
) -> TranslationalCoefficients {
    let aoa_g = normal_m_s.abs().atan2(chord_m_s.abs());
    let cp = centre_of_pressure_frac(aoa_g);
    let scale = params.translational_scale;
    let c_t = match params.chordwise {
        ChordwiseModel::Dickinson => {
            scale * plate_tangential(aoa_g)
                + (params.fit_skin_friction - params.skin_friction) * aoa_g.cos()
        }
        ChordwiseModel::SkinFriction => -params.skin_friction * aoa_g.cos(),
    };
    TranslationalCoefficients {
        c_n: -signum0(normal_m_s) * scale * plate_normal(aoa_g),
        c_t: signum0(chord_m_s) * c_t,
        cp_from_le: if chord_m_s >= 0.0 { cp } else { 1.0 - cp },
    }
}

/// Rotational circulation force per unit span N_rot = πρc²ω_z[(x̂0 − ½)U − ¼t] (N/m) for a
/// section moving with (n, t) relative to the fluid and rotating at ω_z.
pub fn rotational_normal(
    geom: &SectionGeometry,
    normal_m_s: f64,
    chord_m_s: f64,
    rotation_rate_rad_s: f64,
) -> f64 {
    let c = geom.chord_m;
    let speed = normal_m_s.hypot(chord_m_s);
    PI * geom.density_kg_m3
        * c
        * c
        * rotation_rate_rad_s
        * ((geom.pitch_axis_frac - 0.5) * speed - 0.25 * chord_m_s)
}

/// Added-mass loads of a 2-D flat plate (see module docs), per unit span, with the chordwise
/// Kirchhoff term.
pub fn added_mass(geom: &SectionGeometry, kin: &SectionKinematics) -> SectionLoads {
    let c = geom.chord_m;
    let m_a = 0.25 * PI * geom.density_kg_m3 * c * c;
    let d = (0.5 - geom.pitch_axis_frac) * c;
    let n_mid = kin.normal_velocity_m_s + d * kin.rotation_rate_rad_s;
    SectionLoads {
        normal_n_m: -m_a * (kin.normal_velocity_rate_m_s2 + d * kin.rotation_acc_rad_s2),
        chordwise_n_m: -m_a * kin.rotation_rate_rad_s * n_mid,
        moment_n: -m_a
            * (d * kin.normal_velocity_rate_m_s2
                + (d * d + c * c / 32.0) * kin.rotation_acc_rad_s2),
    }
}

/// The added-mass loads that `params` switch on (zero when `added_mass` is off).
pub fn added_mass_loads(
    geom: &SectionGeometry,
    params: &QuasiSteadyParams,
    kin: &SectionKinematics,
) -> SectionLoads {
    if !params.added_mass {
        return SectionLoads::default();
    }
    let mut am = added_mass(geom, kin);
    if !params.added_mass_chordwise {
        am.chordwise_n_m = 0.0;
    }
    am
}

/// Circulatory (translational + rotational) quasi-steady loads per unit span for a section
/// moving with (n, t) relative to the fluid and rotating at ω_z, for given translational
/// coefficients (L1 passes a lagged c_n).
pub fn circulatory_loads(
    geom: &SectionGeometry,
    params: &QuasiSteadyParams,
    normal_m_s: f64,
    chord_m_s: f64,
    rotation_rate_rad_s: f64,
    coeffs: &TranslationalCoefficients,
) -> SectionLoads {
    let TranslationalCoefficients {
        c_n,
        c_t,
        cp_from_le,
    } = *coeffs;
    let c = geom.chord_m;
    let q = 0.5 * geom.density_kg_m3 * c * (normal_m_s * normal_m_s + chord_m_s * chord_m_s);
    let n_tr = c_n * q;
    let n_rot = if params.rotational {
        rotational_normal(geom, normal_m_s, chord_m_s, rotation_rate_rad_s)
    } else {
        0.0
    };
    SectionLoads {
        normal_n_m: n_tr + n_rot,
        chordwise_n_m: c_t * q,
        moment_n: (cp_from_le - geom.pitch_axis_frac) * c * n_tr
            + (0.5 - geom.pitch_axis_frac) * c * n_rot,
    }
}

/// sgn with sgn(0) = 0.
pub(crate) fn signum0(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else {
        0.0
    }
}

/// The stateless L0 section.
#[derive(Debug, Clone)]
pub struct QuasiSteadySection {
    geom: SectionGeometry,
    params: QuasiSteadyParams,
}

impl QuasiSteadySection {
    /// A quasi-steady section.
    pub fn new(geom: SectionGeometry, params: QuasiSteadyParams) -> Self {
        Self { geom, params }
    }

    /// Loads for the given kinematics (no memory).
    pub fn loads(&self, kin: &SectionKinematics) -> SectionLoads {
        let (n, t) = (kin.normal_velocity_m_s, kin.chord_velocity_m_s);
        let coeffs = translational_coefficients(n, t, &self.params);
        let circ = circulatory_loads(
            &self.geom,
            &self.params,
            n,
            t,
            kin.rotation_rate_rad_s,
            &coeffs,
        );
        circ + added_mass_loads(&self.geom, &self.params, kin)
    }
}

impl SectionModel for QuasiSteadySection {
    fn reset(&mut self) {}

    fn step(&mut self, kin: &SectionKinematics, _dt_s: f64) -> SectionLoads {
        self.loads(kin)
    }
}

impl SectionModelFactory for QuasiSteadyParams {
    fn build(&self, section: &SectionGeometry) -> Box<dyn SectionModel> {
        Box::new(QuasiSteadySection::new(*section, *self))
    }
}
