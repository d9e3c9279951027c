//! L2 aerodynamics: a 2-D discrete-vortex method of the LDVM type (Ramesh et al. 2014, *JFM*
//! 751:500) for a flat plate in arbitrary planar motion, and blade-element strips of it along
//! the span of the flapping wing.
//!
//! # The 2-D problem ([`Ldvm`])
//!
//! A flat plate of chord c (m) moves in a plane (inertial axes X, Z). Its pose is the pivot
//! position P_p (m, at x_p = x̂0·c behind the leading edge) and the chord angle ϑ (rad), so the
//! chord unit vector (leading edge → trailing edge) is t̂ = (cos ϑ, sin ϑ) and the plate normal is
//! n̂ = (−sin ϑ, cos ϑ) (t̂ rotated by +90°). Positive circulation and moments are
//! counter-clockwise (the sense of positive ϑ̇ = Ω).
//!
//! Bound vorticity (clockwise-positive γ, chord point x = (c/2)(1 − cos θ) from the leading edge):
//!
//! γ(θ) = 2 [B0 (1 + cos θ)/sin θ + Σ_{n≥1} B_n sin nθ],  B_n = A_n·U (m/s),
//!
//! B0 = (1/π) ∫₀^π W_n dθ,  B_n = −(2/π) ∫₀^π W_n cos nθ dθ,
//!
//! where W_n(x) = (u_free(x) − V_p)·n̂ − Ω (x − x_p) is the normal velocity of the fluid relative to the plate produced by everything except the bound
//! sheet (free vortices u_free, plate translation V_p, plate rotation Ω). The coefficients are
//! kept dimensional (m/s) so that nothing divides by a speed that vanishes at stroke reversal;
//! the leading-edge suction parameter is LESP = A0 = B0/U_ref.
//!
//! Each step: (1) convect the free vortices with the velocities of the previous step (forward
//! Euler, Vatistas n = 2 cores between free vortices, each growing by viscous diffusion, the
//! exact velocity of the truncated bound sheet from the conformal map, vortices that would cross
//! the plate mirrored back), (2) decay, delete and amalgamate them, (3) place a new
//! trailing-edge vortex (TEV) 1/3 of the way from the trailing edge to the previous TEV and solve
//! Kelvin's condition Γ_bound + Σ Γ_free = 0 for its strength, (4) if |LESP| > LESP_crit also place
//! a leading-edge vortex (LEV) and solve the 2×2 system {Kelvin, B0 = ±LESP_crit·U_ref} for both
//! strengths, (5) compute loads, (6) compute the free-vortex velocities for the next step.
//! The downwash is linear in the new strengths, so steps (3)–(4) are exact linear solves (what
//! UNSflow's Newton iterations converge to).
//!
//! Loads per unit span (linearised pressure jump Δp = ρ[V_t γ + ∂/∂t ∫₀ˣ γ dξ] integrated over the
//! chord; V_t = −V_p·t̂ is the chordwise speed of the oncoming flow, u_t,j the chordwise velocity
//! induced by the free vortices at bound element j, Γ_j its clockwise circulation):
//!
//! N' = ρ[V_t cπ(B0 + B1/2) + Σ_j u_t,j Γ_j] + ρπc² (¾Ḃ0 + ¼Ḃ1 + ⅛Ḃ2) − ρc Γ_LEV/Δt  (along n̂)
//!
//! The last term is the potential jump carried by the LE feeding sheet: circulation shed at the
//! LE stays connected to it, so the jump across the plate is ∫₀ˣγ dξ + Σ Γ_LEV,cw, not ∫₀ˣγ dξ
//! alone (UNSflow omits it). With it, N' equals the force −dI/dt from the vortex impulse (tested);
//! without it the lift collapses whenever LEVs are shed. The moment gets the same uniform jump:
//! −ρcΓ_LEV/Δt · c/2 about the LE.
//!
//! S' = ρπc B0²  (leading-edge suction, along −t̂, times `suction_factor`)
//!
//! M_p = ρ[V_t c²π(B0/4 + B1/4 − B2/8) + Σ_j x_j u_t,j Γ_j]
//!       + ρπc³ d/dt(7/16 B0 + 11/64 B1 + 1/16 B2 − 1/64 B3) − x_p N'                     (CCW)
//!
//! These are eqs. 2.30–2.31 of Ramesh et al. in dimensional form; the B1 weight of the moment's
//! unsteady term is 11/64 (exact pressure integral, checked by quadrature in the tests) where
//! UNSflow's `postprocess.jl` codes 3/16.
//!
//! Wake capture and wing–wake interaction are not modelled separately: they come from the free
//! vortices that the plate meets again after it reverses.
//!
//! # Strips along the span ([`StripLdvm`])
//!
//! [`StripLdvmFactory`] implements [`crate::aero::SectionModelFactory`]: the blade-element
//! integrator places one LDVM per strip; see [`strip`] for the section frame, the reference speed
//! and the 3-D correction.

mod inflow;
mod ldvm;
pub mod strip;
mod wake;

pub use inflow::Inflow;
pub use ldvm::{Ldvm, LdvmDiagnostics, PlateState, SectionLoads};
pub use strip::{StripLdvm, StripLdvmFactory, StripLdvmParams};
pub use wake::{VortexKind, Wake};

use serde::{Deserialize, Serialize};

/// Errors of the vortex method.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum VortexError {
    /// A parameter is out of its valid range.
    #[error("vortex method parameter `{name}` = {value} is invalid: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// Valid range.
        reason: &'static str,
    },
    /// A kinematic input is NaN or infinite.
    #[error("vortex method step {step}: kinematic input `{field}` is not finite ({value})")]
    NonFiniteKinematics {
        /// Step index (0-based).
        step: u64,
        /// Field name.
        field: &'static str,
        /// Offending value.
        value: f64,
    },
    /// A setting's name is not one of its choices.
    #[error("unknown {setting} `{name}` (expected {expected})")]
    UnknownChoice {
        /// The setting.
        setting: &'static str,
        /// The name given.
        name: String,
        /// The choices.
        expected: &'static str,
    },
    /// The shedding system (Kelvin + LESP) is singular.
    #[error("vortex method step {step}: shedding system is singular (determinant {det})")]
    SingularShedding {
        /// Step index (0-based).
        step: u64,
        /// Determinant of the linear system.
        det: f64,
    },
}

/// Spalart-type vortex amalgamation.
///
/// Two same-sign free vortices j, k (not among the protected newest ones) are merged into one at
/// their circulation-weighted centroid, with Γ = Γ_j + Γ_k, when
///
/// (|Γ_j Γ_k| / |Γ_j + Γ_k|) · |z_j − z_k| / ((D0 + d_j)^{3/2} (D0 + d_k)^{3/2}) < V0,
///
/// d = distance from the plate (segment LE–TE), D0 = `d0_chords`·c, V0 = `v0`·U_ref/c. Far-away
/// vortices merge readily; vortices closer than `near_chords`·c to the plate never merge in this
/// pass (they carry the near-wake and LEV structure that sets the loads). When the count still exceeds `max_vortices`,
/// pairs are merged in increasing order of that measure until it is below 0.8·`max_vortices`.
/// Merging conserves total circulation exactly.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MergeParams {
    /// D0 / c (dimensionless).
    pub d0_chords: f64,
    /// V0 · c / U_ref (dimensionless threshold).
    pub v0: f64,
    /// Vortices closer than this to the plate (chords) are exempt from threshold merging.
    pub near_chords: f64,
    /// Merge pass every this many steps (≥ 1).
    pub interval_steps: usize,
}

impl Default for MergeParams {
    fn default() -> Self {
        Self {
            d0_chords: 1.0,
            v0: 2e-4,
            near_chords: 1.0,
            interval_steps: 5,
        }
    }
}

/// How the free vortices move.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum WakeMotion {
    /// Free vortex dynamics: every free vortex moves with the velocity induced by the other
    /// free vortices and the bound sheet (Ramesh et al.'s LDVM).
    #[default]
    Free,
    /// A frozen wake: free vortices stay where they were shed, in the frame of the fluid at rest
    /// far away (the planar wake of Wagner's and Theodorsen's theories, which the plate leaves
    /// behind). They still decay, grow their cores, are deleted far away and amalgamated. No
    /// vortex-on-vortex induction, so the wake has no dynamics of its own.
    Frozen,
}

/// The name [`std::str::FromStr`] reads: `free` or `frozen`.
impl std::fmt::Display for WakeMotion {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Self::Free => "free",
            Self::Frozen => "frozen",
        })
    }
}

impl std::str::FromStr for WakeMotion {
    type Err = VortexError;
    /// `free` or `frozen`.
    fn from_str(s: &str) -> Result<Self, Self::Err> {
        match s.to_ascii_lowercase().as_str() {
            "free" => Ok(Self::Free),
            "frozen" => Ok(Self::Frozen),
            _ => Err(VortexError::UnknownChoice {
                setting: "wake motion",
                name: s.into(),
                expected: "free or frozen",
            }),
        }
    }
}

/// Parameters of the 2-D LDVM (unchecked; [`Ldvm::new`] validates them once).
///
/// | field | default | meaning |
/// |---|---|---|
/// | `chord_m` | 0.06 | chord c (m) |
/// | `pivot_frac` | 0.15 | pitch axis x̂0 = x_p/c from the leading edge |
/// | `rho_kg_m3` | 800 | fluid density ρ (mineral oil) |
/// | `u_ref_m_s` | 0.37 | reference speed U_ref for LESP = B0/U_ref and amalgamation |
/// | `n_chord` | 24 | chord collocation points (θ uniform in [0, π]; also the bound elements) |
/// | `n_fourier` | 10 | Fourier terms B0..B_{n−1} |
/// | `lesp_crit` | Some(0.15) | critical LESP; `None` turns LEV shedding off |
/// | `core_radius_frac` | 0.02 | Vatistas core radius r_c / c of a new vortex |
/// | `core_growth_reynolds` | Some(1000) | Re = U_ref c/ν of the viscous core growth (Lamb–Oseen) |
/// | `suction_factor` | 1.0 | multiplies the leading-edge suction ρπcB0² |
/// | `lev_decay_chords` | Some(4.0) | LEV circulation decays as exp(−s/s_d), s = plate travel / c |
/// | `tev_decay_chords` | Some(4.0) | same for trailing-edge (wake) vortices |
/// | `far_field_chords` | Some(12.0) | free vortices farther than this from the pivot are deleted |
/// | `merge` | Some(default) | Spalart amalgamation, see [`MergeParams`] |
/// | `max_vortices` | 110 | hard cap on free vortices (storage is allocated once) |
/// | `wake_motion` | `Free` | free vortex dynamics or a frozen wake, see [`WakeMotion`] |
///
/// LESP_crit: Ramesh et al. report 0.1–0.2 for Re 10³–10⁴; UNSflow uses 0.11 for a flat plate in
/// the Eldredge pitch-up. The default 0.15 sits in the middle; 2-D models shed the LEV too readily
/// compared with a revolving AR = 3 wing, which is why the default leans above 0.11.
///
/// Decay is measured in chords travelled by the plate (not seconds), so the method stays
/// invariant under time scaling. The LEV decay (s_d = 4 chords, ≈ 4 convective times) mimics the
/// spanwise drainage of LEV vorticity into the tip vortex of a revolving wing. The TEV decay
/// (4 chords, about one half-stroke of travel at r_cp for the smallest stroke amplitudes) mimics
/// what a 2-D wake lacks: the downwash and the roll-up into tip and root vortices carry a
/// hovering wing's wake away within about a half-stroke, so the wing meets the wake of the last
/// reversal (wake capture) but not an accumulation of older ones. With a long-lived 2-D wake
/// (40 chords) the loads were chaotic: a
/// 0.1 % change of the core radius moved F_x by 0.4–0.5 σ.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct LdvmParams {
    /// Chord c (m).
    pub chord_m: f64,
    /// Pitch axis x̂0 = x_p/c from the leading edge (dimensionless, in [0, 1]).
    pub pivot_frac: f64,
    /// Fluid density ρ (kg/m³).
    pub rho_kg_m3: f64,
    /// Reference speed U_ref (m/s) for LESP and amalgamation.
    pub u_ref_m_s: f64,
    /// Chord collocation points (≥ 8).
    pub n_chord: usize,
    /// Fourier terms B0..B_{n−1} (≥ 4).
    pub n_fourier: usize,
    /// Critical leading-edge suction parameter; `None` disables LEV shedding.
    pub lesp_crit: Option<f64>,
    /// Core radius r_c / c of a newly shed vortex.
    pub core_radius_frac: f64,
    /// Viscous core growth: each free vortex's core grows as a Lamb–Oseen vortex,
    /// r_c² = r_c0² + 5.0257·ν·t, with ν·t = s·c²/Re for s chords of plate travel since it was
    /// shed (Re = U_ref·c/ν). `None` keeps every core at r_c0 (inviscid).
    pub core_growth_reynolds: Option<f64>,
    /// Factor on the leading-edge suction force (1 = thin-airfoil suction, 0 = none).
    pub suction_factor: f64,
    /// LEV decay length s_d (chords of plate travel); `None` = no decay.
    pub lev_decay_chords: Option<f64>,
    /// TEV decay length (chords of plate travel); `None` = no decay.
    pub tev_decay_chords: Option<f64>,
    /// Deletion distance from the pivot (chords); `None` = never delete.
    pub far_field_chords: Option<f64>,
    /// Spalart amalgamation; `None` = off (then `max_vortices` must hold every shed vortex).
    pub merge: Option<MergeParams>,
    /// Hard cap on the number of free vortices.
    pub max_vortices: usize,
    /// How the free vortices move.
    #[serde(default)]
    pub wake_motion: WakeMotion,
}

impl Default for LdvmParams {
    fn default() -> Self {
        Self {
            chord_m: 0.06,
            pivot_frac: 0.15,
            rho_kg_m3: 800.0,
            u_ref_m_s: 0.37,
            n_chord: 24,
            n_fourier: 10,
            lesp_crit: Some(0.15),
            core_radius_frac: 0.02,
            core_growth_reynolds: Some(1000.0),
            suction_factor: 1.0,
            lev_decay_chords: Some(4.0),
            tev_decay_chords: Some(4.0),
            far_field_chords: Some(12.0),
            merge: Some(MergeParams::default()),
            max_vortices: 110,
            wake_motion: WakeMotion::Free,
        }
    }
}

impl LdvmParams {
    /// Attached-flow potential-flow settings: no LEV, no decay, no deletion, no merging.
    /// Used for the Wagner/Theodorsen/Kelvin checks.
    pub fn inviscid(chord_m: f64, u_ref_m_s: f64, max_vortices: usize) -> Self {
        Self {
            chord_m,
            u_ref_m_s,
            lesp_crit: None,
            core_growth_reynolds: None,
            lev_decay_chords: None,
            tev_decay_chords: None,
            far_field_chords: None,
            merge: None,
            max_vortices,
            ..Self::default()
        }
    }

    /// Checks every field; returns the first violation.
    pub fn check(&self) -> Result<(), VortexError> {
        fn bad(name: &'static str, value: f64, reason: &'static str) -> Result<(), VortexError> {
            Err(VortexError::InvalidParameter {
                name,
                value,
                reason,
            })
        }
        let pos = |x: f64| x.is_finite() && x > 0.0;
        if !pos(self.chord_m) {
            return bad("chord_m", self.chord_m, "must be finite and > 0");
        }
        if !(self.pivot_frac.is_finite() && (0.0..=1.0).contains(&self.pivot_frac)) {
            return bad("pivot_frac", self.pivot_frac, "must be in [0, 1]");
        }
        if !pos(self.rho_kg_m3) {
            return bad("rho_kg_m3", self.rho_kg_m3, "must be finite and > 0");
        }
        if !pos(self.u_ref_m_s) {
            return bad("u_ref_m_s", self.u_ref_m_s, "must be finite and > 0");
        }
        if self.n_chord < 8 {
            return bad("n_chord", self.n_chord as f64, "must be >= 8");
        }
        if self.n_fourier < 4 || self.n_fourier > self.n_chord {
            return bad(
                "n_fourier",
                self.n_fourier as f64,
                "must be in [4, n_chord]",
            );
        }
        if let Some(l) = self.lesp_crit.filter(|&l| !pos(l)) {
            return bad("lesp_crit", l, "must be finite and > 0");
        }
        if !pos(self.core_radius_frac) {
            return bad(
                "core_radius_frac",
                self.core_radius_frac,
                "must be finite and > 0",
            );
        }
        if !(self.suction_factor.is_finite() && self.suction_factor >= 0.0) {
            return bad(
                "suction_factor",
                self.suction_factor,
                "must be finite and >= 0",
            );
        }
        for (name, v) in [
            ("core_growth_reynolds", self.core_growth_reynolds),
            ("lev_decay_chords", self.lev_decay_chords),
            ("tev_decay_chords", self.tev_decay_chords),
            ("far_field_chords", self.far_field_chords),
        ] {
            if let Some(v) = v.filter(|&v| !pos(v)) {
                return bad(name, v, "must be finite and > 0");
            }
        }
        if let Some(m) = self.merge {
            if !(m.d0_chords.is_finite() && m.d0_chords >= 0.0) {
                return bad("merge.d0_chords", m.d0_chords, "must be finite and >= 0");
            }
            if !(m.v0.is_finite() && m.v0 >= 0.0) {
                return bad("merge.v0", m.v0, "must be finite and >= 0");
            }
            if !(m.near_chords.is_finite() && m.near_chords >= 0.0) {
                return bad(
                    "merge.near_chords",
                    m.near_chords,
                    "must be finite and >= 0",
                );
            }
            if m.interval_steps == 0 {
                return bad("merge.interval_steps", 0.0, "must be >= 1");
            }
        }
        if self.max_vortices < 8 {
            return bad("max_vortices", self.max_vortices as f64, "must be >= 8");
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Display writes the name FromStr reads; other names are refused by name.
    #[test]
    fn wake_motion_names_round_trip() {
        for motion in [WakeMotion::Free, WakeMotion::Frozen] {
            assert_eq!(motion.to_string().parse::<WakeMotion>().unwrap(), motion);
        }
        let e = "rolled".parse::<WakeMotion>().unwrap_err().to_string();
        assert!(e.contains("rolled") && e.contains("free or frozen"), "{e}");
    }
}
