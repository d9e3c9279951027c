//! L3: an unsteady vortex-lattice method (UVLM) of the whole plate with a shed wake
//! (docs/vortex-method.md).
//!
//! # Model
//!
//! The plate (wing frame: x_w normal, y_w chordwise towards the LE, z_w root → tip) carries
//! N_c × N_s vortex rings (Katz & Plotkin ch. 12–13): ring (i, j) has its leading filament on
//! the quarter line of panel (i, j) and its trailing one on the quarter line of the panel behind
//! (a quarter panel behind the trailing edge for the last row); no flow through the plate at the
//! three-quarter points,
//!
//! ```text
//! Σ_l A_kl Γ_l = −(u_fluid + u_wake − ω × p_k)·x̂_w,
//! ```
//!
//! A_kl the normal velocity at point k of ring l of unit strength (constant for the rigid plate:
//! inverted once). Every step the trailing-edge rings shed their strengths of the step before as
//! a new row of wake rings between the trailing-edge lines of the two steps (the Kutta
//! condition). The wake is prescribed: it stays in the fluid, which moves straight down in the
//! slipstream of momentum theory, at the induced inflow w in the stroke plane and speeding up to
//! 2w far below (module `inflow`); it does not move itself, so the loads are a smooth function
//! of the kinematics, not chaotic. The shed vorticity leaves the plate
//! spread over its boundary layer: a new filament's core is the Blasius thickness at the trailing
//! edge, r_c0 = 5c/√Re (0.158c at Re = 1000), and it grows by viscous diffusion,
//! r_c² = r_c0² + 4·1.25643·ν·t (Lamb–Oseen); the filament on the trailing edge itself has the
//! bound lattice's zero core, so that it cancels the bound trailing filament but for the shed
//! part. Rows older than `wake_length_chords` of travel of the reference point go (whole rings:
//! Kelvin's theorem holds).
//!
//! # Loads
//!
//! Normal force from the unsteady Bernoulli equation, as Kutta–Joukowski on the bound filaments
//! plus the rate of the potential jump, with Q the fluid's velocity relative to the plate
//! (motion, inflow and wake; the planar bound lattice induces only normal velocity on itself):
//!
//! ```text
//! spanwise filament (i, j):   ΔF_x = ρ (Γ_ij − Γ_{i−1,j}) Q_y Δs       at the quarter line
//! streamwise filament (i, j): ΔF_x = −ρ (Γ_ij − Γ_{i,j−1}) Q_z Δc      at the node line
//! ring (i, j):                ΔF_x = −ρ ∂Γ_ij/∂t ΔS (its area on the plate) at the ring centre
//! ```
//!
//! A thin plate carries a chordwise force only at its leading edge, whose singularity is locally
//! 2-D: with γ ≈ A/√x near the edge, the first panel's circulation is Γ_0j = A√c·g(Δc/c),
//! g(θ) = √(θ(1 − θ)) + asin √θ (exact for the thin-airfoil loading), and the suction per span is
//! πρA²/4 = πρΓ_0j²/(4c g²) (N/m; for steady 2-D flow πρU²cα², the lift times α). The LESP of the
//! column is A/(2U√c) = Γ_0j/(2cgU), U the column's speed relative to the fluid at the pitch
//! axis. Above `lesp_crit` the flow separates at the edge: the suction keeps the fraction
//! LESP_crit/|LESP| and the rest acts normal to the plate on the side of the column's normal
//! force (the leading-edge-suction analogy of Polhamus), so nothing switches on or off. The
//! profile drag of the strips (`vortex::strip`), −C_D0·½ρc·U·t per span, adds the viscous
//! chordwise force. Moments are taken about the sensor (0, 0, r_s) from the points above.
//!
//! # Time steps
//!
//! The lattice steps every k samples, k the whole number of samples in which the reference point
//! (the pitch axis at the U_ref radius) travels `step_chords` chords at its mean speed over the
//! trajectory, so the steps scale with the motion; the loads in between are interpolated
//! linearly in time.

mod biot_savart;
mod inflow;
mod wake;
mod wing;

pub use wing::VortexLatticeWing;

use crate::check::first_not_positive;
use crate::vortex::{Inflow, strip::zero_incidence_drag};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Errors of the vortex-lattice settings.
#[derive(Debug, Error, PartialEq)]
#[non_exhaustive]
pub enum LatticeError {
    /// A setting is out of range.
    #[error("vortex lattice: `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// The field.
        name: &'static str,
        /// Its value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
}

/// Settings of the L3 vortex lattice (module docs).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct VortexLatticeParams {
    /// Rings along the chord N_c (default 8).
    pub chordwise_panels: usize,
    /// Rings along the span N_s (default 6).
    pub spanwise_panels: usize,
    /// Travel of the reference point per lattice step, in chords, at its mean speed (default
    /// 0.125: one chordwise panel).
    pub step_chords: f64,
    /// Initial core radius of the wake filaments r_c0/c; `None` (default): the Blasius thickness
    /// of the plate's boundary layer at the trailing edge, r_c0 = 5c/√Re with Re = Uc/ν and U
    /// the reference point's mean speed over the trajectory (0.158c at Re = 1000): the shed
    /// vorticity leaves the plate spread over that layer.
    pub core_radius_frac: Option<f64>,
    /// Wake kept, in chords of travel of the reference point (default 40: about two cycles of
    /// the measured trajectories, when the wake has sunk about two spans).
    pub wake_length_chords: f64,
    /// Critical leading-edge suction parameter (default 0.15, the strips' value); `None` keeps
    /// the whole suction (attached flow).
    pub lesp_crit: Option<f64>,
    /// Chordwise profile-drag coefficient C_D0 (default the strips' 0.260).
    pub profile_drag: f64,
    /// The fluid's vertical motion that carries the wake (default [`Inflow::Momentum`], module
    /// `inflow`; `Uniform { ratio }` is w = ratio × the reference point's recent mean speed).
    pub inflow: Inflow,
    /// Travel over which the inflow averages the lift, in chords (default 4, as the strips).
    pub inflow_window_chords: f64,
    /// Include the unsteady term −ρ ∂Γ/∂t ΔS of the normal force (default true): the plate's
    /// added mass and the growth of its circulation. Off only to measure its share (the rig
    /// ablation of docs/rig-agreement.md).
    pub unsteady_term: bool,
}

impl Default for VortexLatticeParams {
    fn default() -> Self {
        Self {
            chordwise_panels: 8,
            spanwise_panels: 6,
            step_chords: 0.125,
            core_radius_frac: None,
            wake_length_chords: 40.0,
            lesp_crit: Some(0.15),
            profile_drag: zero_incidence_drag(),
            inflow: Inflow::Momentum,
            inflow_window_chords: 4.0,
            unsteady_term: true,
        }
    }
}

impl VortexLatticeParams {
    /// Checks every field; returns the first violation.
    pub fn check(&self) -> Result<(), LatticeError> {
        let bad = |name, value: f64, reason| {
            Err(LatticeError::InvalidParameter {
                name,
                value,
                reason,
            })
        };
        for (name, n) in [
            ("chordwise_panels", self.chordwise_panels),
            ("spanwise_panels", self.spanwise_panels),
        ] {
            if !(1..=64).contains(&n) {
                return bad(name, n as f64, "must be in 1..=64");
            }
        }
        if let Some((name, v)) = first_not_positive(&[
            ("step_chords", self.step_chords),
            ("wake_length_chords", self.wake_length_chords),
            ("inflow_window_chords", self.inflow_window_chords),
        ]) {
            return bad(name, v, "must be finite and > 0");
        }
        for (name, v) in [
            ("core_radius_frac", self.core_radius_frac.unwrap_or(0.0)),
            ("profile_drag", self.profile_drag),
        ] {
            if !(v.is_finite() && v >= 0.0) {
                return bad(name, v, "must be finite and >= 0");
            }
        }
        if let Some(l) = self.lesp_crit.filter(|l| !(l.is_finite() && *l > 0.0)) {
            return bad("lesp_crit", l, "must be finite and > 0");
        }
        if let Inflow::Uniform { ratio } = self.inflow {
            if !(ratio.is_finite() && ratio >= 0.0) {
                return bad("inflow", ratio, "the uniform ratio must be finite and >= 0");
            }
        }
        Ok(())
    }
}
