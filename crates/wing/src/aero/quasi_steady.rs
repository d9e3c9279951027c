//! L0: quasi-steady sectional aerodynamics (Dickinson et al. 1999; Sane & Dickinson 2002).
//!
//! Per unit span, with n, t the normal and chordwise velocity of the pitch-axis point,
//! U = √(n² + t²), q = ½ρcU² and the acute angle between chord and motion
//! α_g = atan2(|n|, |t|) ∈ [0, π/2]:
//!
//! - translation: N_tr = −sgn(n)·k_N·C_N*(α_g)·q acting at x_cp = x̂_cp(α_g)·c behind the
//!   leading side (the LE when t ≥ 0, the TE otherwise); chordwise only skin friction,
//!   T_tr = −C_f·q·t/U (the separated-flow force is normal to the plate: no leading-edge
//!   suction). C_f = 2·1.328/√Re (Blasius, both faces) at the nominal Re = 1000: 0.084;
//! - rotation: N_rot = πρc²ω_z[(x̂0 − ½)U − ¼t], applied at mid-chord. For LE-first motion
//!   along the chord (t = U) this is the Sane–Dickinson force −C_rot ρ c² U ω_z with
//!   C_rot = π(¾ − x̂0); the ¼t term moves the ¾-chord point continuously to the other side
//!   when the wing moves TE-first (thin-airfoil theory);
//! - added mass (Kirchhoff, 2-D flat plate, m_a = πρc²/4, d = (½ − x̂0)c, mid-chord normal
//!   velocity n_m = n + dω_z): N_am = −m_a(ṅ + dω̇_z), M_am = −m_a[dṅ + (d² + c²/32)ω̇_z]
//!   (the physics notes' strip form). The steady Munk moment is left out (the measured
//!   x̂_cp(α) already contains the steady moment); the chordwise Kirchhoff term
//!   T_am = −m_a ω_z n_m is off by default, as in the Sane–Dickinson model, and can be switched on.
//!
//! C_N* is the Dickinson fit with its offset at 0° removed, C_N*(α) = C_N(α) − C_N(0) cos α,
//! so that a flat plate gets no normal force at zero incidence (the load stays continuous where
//! n changes sign); C_N*(90°) = C_N(90°). The Dickinson C_T (−0.39 at 0°) is not used: it
//! holds the Re ≈ 150 drag of the fits, not the Re ≈ 1000 friction of this wing.

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

/// Chordwise centre of pressure x̂_cp(α) = 0.82|α|/π + 0.05, fraction of the chord behind
/// the leading side.
pub fn centre_of_pressure_frac(aoa_rad: f64) -> f64 {
    0.82 * aoa_rad.abs() / PI + 0.05
}

/// Theoretical rotational coefficient C_rot = π(¾ − x̂0).
pub fn rotational_coefficient(pitch_axis_frac: f64) -> f64 {
    PI * (0.75 - pitch_axis_frac)
}

/// Settings of the quasi-steady model.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct QuasiSteadyParams {
    /// Scale k_N of the translational coefficients (Re ≈ 1000, AR = 3 nuisance factor; 1.0).
    pub translational_scale: f64,
    /// Skin-friction coefficient C_f of the chordwise force (0.084 = Blasius at Re = 1000).
    pub skin_friction: f64,
    /// Include the rotational circulation force (true).
    pub rotational: bool,
    /// Include the added-mass loads (true).
    pub added_mass: bool,
    /// Include the chordwise Kirchhoff added-mass force T_am = −m_a ω_z n_m (false).
    pub added_mass_chordwise: bool,
}

impl Default for QuasiSteadyParams {
    fn default() -> Self {
        Self {
            translational_scale: 1.0,
            skin_friction: 2.0 * 1.328 / 1000f64.sqrt(),
            rotational: true,
            added_mass: true,
            added_mass_chordwise: false,
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

/// Translational coefficients for a section moving with (n, t) (m/s) relative to the fluid:
/// normal scaled by k_N = `scale`, chordwise friction C_f = `skin_friction`.
pub fn translational_coefficients(
    normal_m_s: f64,
    chord_m_s: f64,
    scale: f64,
    skin_friction: f64,
) -> TranslationalCoefficients {
    let aoa_g = normal_m_s.abs().atan2(chord_m_s.abs());
    let cp = centre_of_pressure_frac(aoa_g);
    TranslationalCoefficients {
        c_n: -signum0(normal_m_s) * scale * plate_normal(aoa_g),
        c_t: -skin_friction * signum0(chord_m_s) * aoa_g.cos(),
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
        let coeffs = translational_coefficients(
            n,
            t,
            self.params.translational_scale,
            self.params.skin_friction,
        );
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
