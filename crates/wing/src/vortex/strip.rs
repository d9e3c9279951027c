//! The LDVM as a blade-element section model ([`crate::aero::SectionModel`]), so that the
//! blade-element integrator of [`crate::aero::blade_element`] runs it strip by strip (`l2`).
//!
//! # Section frame
//!
//! The strip at radius r is a 2-D plate in the wing frame's x–y plane (the unrolled arc): the
//! plate normal is n̂ = x_w, the chord unit vector (LE → TE) is t̂ = −y_w, and in-plane rotation
//! is about +z_w (counter-clockwise in the [`Ldvm`] plane). The pivot velocity in plate axes is
//! (V·n̂, V·t̂) = (n, −t) with n, t of [`SectionKinematics`]; the chord rotates at ω_z. The pose
//! in the plane is integrated with the trapezoidal rule from these (ϑ̇ = ω_z, Ṗ = n n̂ − t t̂),
//! so the plate re-enters the vortices it shed when it reverses.
//!
//! # Reference speed
//!
//! LESP = B0/U_ref with U_ref the section's mean speed over its recent travel: the travel over
//! the time it took, each weighted by e^{−s/(s_U·c)} with s the travel since (m),
//!
//! ```text
//! U_ref = ∫ e^{−s/(s_U c)} ds / ∫ e^{−s/(s_U c)} dt,
//! ```
//!
//! s_U = `reference_speed_chords` (default 4, the wake's decay length: what the plate has left
//! more than 4 chords behind it no longer sets its flow). It needs no prior knowledge of the
//! trajectory and scales with the motion, so coefficients are invariant under time scaling, and
//! it forgets how the motion began. With `None` it is the mean speed since the start,
//! (1/t) ∫₀ᵗ |v| dt: two histories of the same kinematics then kept
//! different LESP thresholds for the whole trajectory, and the chordwise loads of one trajectory
//! reached through ramp-ins of 0.5 s and 3.72 s still differed by 0.24 σ three cycles later
//! (0.06 σ with s_U = 4).
//!
//! # Sub-steps
//!
//! The vortex convection (forward Euler) needs steps of at most Δs_max = `max_step_chords`·c of
//! travel (UNSflow's Δt* = 0.015): with the 250 Hz samples of the rig (≈ 0.025 c per sample at
//! U_ref) vortices shed at reversal and met again jump too far in one step, and the loads show
//! isolated spikes of |C_N| up to 10³ (2-D hover test). Each sample interval is therefore split
//! into n = ⌈U_max Δt/(Δs_max c)⌉ (at most `max_substeps`) equal sub-steps, U_max the largest of
//! the pivot speed, U_ref and the edge speeds |ω|·max(x_p, c − x_p), with the section velocities
//! and ω interpolated linearly across the interval. The loads of a sample are the mean over its
//! sub-steps, i.e. over the interval (t − Δt, t], as an integrating sensor would see them: a
//! vortex passing within a core radius of an edge makes the shed strengths alternate from one
//! sub-step to the next (a two-step sawtooth of ±100 N/m at r_cp), which the mean removes. It
//! lags the instantaneous load by Δt/2 (2 ms at 250 Hz, 0.0006 of a 0.3 Hz cycle).
//!
//! The first call starts the plate impulsively from rest. Without a given interval its step is
//! the time of one sub-step of travel, Δs_max c / max(|v|, |ω|·edge), so that the start, like
//! every later step, is invariant under time scaling.
//!
//! # 3-D correction
//!
//! The normal force and the pitching moment are multiplied by `cn_3d_factor` (default 0.8 for the
//! AR = 3 plate: between the lifting-line slope ratio AR/(AR + 2) = 0.6 of attached flow and ≈ 1
//! for the LEV-dominated, high-α loads of revolving wings). The suction force is not scaled.
//!
//! # Induced inflow
//!
//! A hovering wing pushes the fluid down. With `inflow` ([`Inflow`]) other than `Still` the
//! strip sits in fluid that moves straight down at w: the vertical (the global y_0, from
//! [`SectionKinematics::up_section`]) projected on the strip's plane gives the direction, and the
//! strip works in the frame of that moving fluid — the plate rises through it at w on top of its
//! own motion, and the vortices it sheds stay with the fluid. With a frozen wake
//! ([`super::WakeMotion::Frozen`]) the wake is thus carried straight down at w without dynamics
//! of its own. `Inflow::Momentum` takes w from blade-element momentum theory and the strip's own
//! recent lift (module `inflow`); `Inflow::Uniform { ratio }` sets w = ratio·U_ref. Momentum
//! theory at C_L 1.6 and the measured median stroke of 128° gives w ≈ 0.23–0.34 U at the two
//! strips of the default wing. Sections that do not know which way is up (`up_section: None`)
//! get no inflow. With an inflow the profile drag uses the velocity relative to the moving fluid.
//! The options are for studies, not the default.
//!
//! # Profile drag
//!
//! The LDVM is inviscid and the plate infinitely thin: its only chordwise force is the
//! leading-edge suction. The strip adds the chordwise drag of the real plate (skin friction and
//! edge pressure), T_d = −C_D0·½ρc·U·t (N/m, along +y_w; t the chordwise velocity, U the
//! speed), i.e. C_D0·q·cos α_g against the chordwise motion. C_D0 = `profile_drag` defaults to the
//! zero-incidence drag of the L0 model, [`zero_incidence_drag`] = 0.260: the Dickinson C_D(0°)
//! = 0.393 with the Blasius friction of the fits' Re ≈ 150 (0.217) replaced by that of
//! Re = 1000 (0.084).

use serde::{Deserialize, Serialize};

use super::inflow::InflowState;
use super::{Inflow, Ldvm, LdvmParams, PlateState, VortexError};
use crate::aero::quasi_steady::{QuasiSteadyParams, translational_coefficients};
use crate::aero::{
    SectionGeometry, SectionKinematics, SectionLoads, SectionModel, SectionModelFactory,
};
use crate::check::first_not_positive;

/// Zero-incidence chordwise drag coefficient of the plate at Re = 1000 (dimensionless): the
/// default L0 model's chordwise coefficient for motion along the chord, with its sign turned,
/// C_D(0°) − C_f(Re 150) + C_f(Re 1000) = 0.260 (Dickinson fit, Blasius friction on both faces).
pub fn zero_incidence_drag() -> f64 {
    -translational_coefficients(0.0, 1.0, &QuasiSteadyParams::default()).c_t
}

/// Parameters of the L2 section model (the LDVM template; chord, pivot and density are taken
/// from the [`SectionGeometry`] of each strip).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct StripLdvmParams {
    /// LDVM settings (chord, pivot, density and U_ref are overwritten per strip).
    pub ldvm: LdvmParams,
    /// 3-D factor on the normal force and pitching moment (dimensionless, default 0.8).
    pub cn_3d_factor: f64,
    /// Largest travel per vortex step, in chords (default 0.0125).
    pub max_step_chords: f64,
    /// Cap on the sub-steps per sample interval (default 8).
    pub max_substeps: usize,
    /// Chordwise profile-drag coefficient C_D0 (dimensionless, default
    /// [`zero_incidence_drag`] = 0.260; 0 gives the inviscid plate).
    pub profile_drag: f64,
    /// Travel s_U (chords) over which the LESP reference speed averages, exponentially weighted
    /// (default 4); `None`: the mean speed since the start (module docs, "Reference speed").
    pub reference_speed_chords: Option<f64>,
    /// The fluid's vertical motion around the strip (module docs, "Induced inflow"; default
    /// [`Inflow::Still`]).
    pub inflow: Inflow,
}

impl StripLdvmParams {
    /// The LDVM settings of one strip: the template with the section's chord, pivot and density.
    pub fn section_params(&self, section: &SectionGeometry) -> LdvmParams {
        LdvmParams {
            chord_m: section.chord_m,
            pivot_frac: section.pitch_axis_frac,
            rho_kg_m3: section.density_kg_m3,
            ..self.ldvm
        }
    }

    /// Checks every field for the strip `section`; returns the first violation.
    pub fn check(&self, section: &SectionGeometry) -> Result<(), VortexError> {
        let positive = [
            ("max_step_chords", self.max_step_chords),
            ("cn_3d_factor", self.cn_3d_factor),
        ];
        if let Some((name, value)) = first_not_positive(&positive) {
            return Err(VortexError::InvalidParameter {
                name,
                value,
                reason: "must be finite and > 0",
            });
        }
        if let Some(s_u) = self.reference_speed_chords
            && !(s_u.is_finite() && s_u > 0.0)
        {
            return Err(VortexError::InvalidParameter {
                name: "reference_speed_chords",
                value: s_u,
                reason: "must be finite and > 0",
            });
        }
        if let Inflow::Uniform { ratio } = self.inflow
            && !(ratio.is_finite() && ratio >= 0.0)
        {
            return Err(VortexError::InvalidParameter {
                name: "inflow ratio",
                value: ratio,
                reason: "must be finite and >= 0",
            });
        }
        if self.max_substeps == 0 {
            return Err(VortexError::InvalidParameter {
                name: "max_substeps",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        if !(self.profile_drag.is_finite() && self.profile_drag >= 0.0) {
            return Err(VortexError::InvalidParameter {
                name: "profile_drag",
                value: self.profile_drag,
                reason: "must be finite and >= 0",
            });
        }
        self.section_params(section).check()
    }
}

/// Largest distance from the pivot to an edge, max(x_p, c − x_p) (m).
fn pivot_to_edge_m(p: &LdvmParams) -> f64 {
    p.pivot_frac.max(1.0 - p.pivot_frac) * p.chord_m
}

impl Default for StripLdvmParams {
    fn default() -> Self {
        Self {
            ldvm: LdvmParams::default(),
            cn_3d_factor: 0.8,
            max_step_chords: 0.0125,
            max_substeps: 8,
            profile_drag: zero_incidence_drag(),
            reference_speed_chords: Some(4.0),
            inflow: Inflow::Still,
        }
    }
}

/// Factory of [`StripLdvm`] section models.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct StripLdvmFactory {
    /// Settings shared by all strips.
    pub params: StripLdvmParams,
}

impl SectionModelFactory for StripLdvmFactory {
    fn build(&self, section: &SectionGeometry) -> Box<dyn SectionModel> {
        Box::new(StripLdvm::new(self.params, section))
    }
}

/// One strip of the L2 model: an [`Ldvm`] posed in the section frame.
#[derive(Debug, Clone)]
pub struct StripLdvm {
    ldvm: Option<Ldvm>,
    cn_3d_factor: f64,
    /// C_D0·½ρc (kg/m²).
    drag_factor: f64,
    max_step_m: f64,
    max_substeps: usize,
    /// s_U·c (m), or infinite (mean since the start).
    reference_travel_m: f64,
    inflow: InflowState,
    /// Loads of the last sub-step (for the inflow's lift).
    last_loads: SectionLoads,
    prev_kin: SectionKinematics,
    plate: PlateState,
    started: bool,
    recent_time_s: f64,
    recent_travel_m: f64,
    prev_speed_m_s: f64,
}

impl StripLdvm {
    /// Builds the strip. Invalid settings (see [`StripLdvmParams::check`]) give a model whose
    /// loads are NaN, so that the output pipeline's finiteness check reports them.
    pub fn new(params: StripLdvmParams, section: &SectionGeometry) -> Self {
        let valid = params.check(section).is_ok();
        Self {
            ldvm: Ldvm::new(params.section_params(section))
                .ok()
                .filter(|_| valid),
            cn_3d_factor: params.cn_3d_factor,
            drag_factor: params.profile_drag * 0.5 * section.density_kg_m3 * section.chord_m,
            max_step_m: params.max_step_chords * section.chord_m,
            max_substeps: params.max_substeps,
            reference_travel_m: params
                .reference_speed_chords
                .map_or(f64::INFINITY, |s_u| s_u * section.chord_m),
            inflow: InflowState::new(params.inflow, section.density_kg_m3, section.chord_m),
            last_loads: SectionLoads::default(),
            prev_kin: SectionKinematics::default(),
            plate: PlateState::default(),
            started: false,
            recent_time_s: 0.0,
            recent_travel_m: 0.0,
            prev_speed_m_s: 0.0,
        }
    }

    /// The 2-D solver (None when the settings were invalid).
    pub fn ldvm(&self) -> Option<&Ldvm> {
        self.ldvm.as_ref()
    }

    /// Deletes the free vortices of the 2-D solver (see [`Ldvm::clear_wake`]).
    pub fn clear_wake(&mut self) {
        if let Some(l) = self.ldvm.as_mut() {
            l.clear_wake();
        }
    }

    /// Pivot velocity (m/s) in the plane's axes relative to the fluid far away: the section's
    /// velocity, plus `inflow_m_s` along the unit vertical `up` ([x_w, y_w] components) when
    /// the fluid moves down (the plate rises through it).
    fn fluid_frame_velocity(
        angle_rad: f64,
        kin: &SectionKinematics,
        up: Option<[f64; 2]>,
        inflow_m_s: f64,
    ) -> [f64; 2] {
        let (s, c) = angle_rad.sin_cos();
        let (n_hat, t_hat) = ([-s, c], [c, s]);
        // n̂ = x_w and t̂ = −y_w in the plane
        let (mut vn, mut vt) = (kin.normal_velocity_m_s, -kin.chord_velocity_m_s);
        if let Some([ux, uy]) = up
            && inflow_m_s != 0.0
        {
            vn += inflow_m_s * ux;
            vt -= inflow_m_s * uy;
        }
        [vn * n_hat[0] + vt * t_hat[0], vn * n_hat[1] + vt * t_hat[1]]
    }
}

impl SectionModel for StripLdvm {
    fn reset(&mut self) {
        if let Some(l) = self.ldvm.as_mut() {
            l.reset();
        }
        self.plate = PlateState::default();
        self.started = false;
        self.recent_time_s = 0.0;
        self.recent_travel_m = 0.0;
        self.prev_speed_m_s = 0.0;
        self.prev_kin = SectionKinematics::default();
        self.inflow.reset();
        self.last_loads = SectionLoads::default();
    }

    fn step(&mut self, kin: &SectionKinematics, dt_s: f64) -> SectionLoads {
        let nan = SectionLoads {
            normal_n_m: f64::NAN,
            chordwise_n_m: f64::NAN,
            moment_n: f64::NAN,
        };
        let Some(ldvm) = self.ldvm.as_ref() else {
            return nan;
        };
        if !(self.started && dt_s.is_finite() && dt_s > 0.0) {
            return self.substep(kin, dt_s).unwrap_or(nan);
        }
        let p = ldvm.params();
        let edge = pivot_to_edge_m(p);
        let u_max = [
            kin.speed_m_s(),
            self.prev_kin.speed_m_s(),
            ldvm.reference_speed(),
            kin.rotation_rate_rad_s.abs() * edge,
            self.prev_kin.rotation_rate_rad_s.abs() * edge,
        ]
        .into_iter()
        .fold(0.0, f64::max);
        let n = ((u_max * dt_s / self.max_step_m).ceil() as usize).clamp(1, self.max_substeps);
        let k0 = self.prev_kin;
        let h = dt_s / n as f64;
        let mut out = SectionLoads {
            normal_n_m: 0.0,
            chordwise_n_m: 0.0,
            moment_n: 0.0,
        };
        for i in 1..=n {
            let f = i as f64 / n as f64;
            let lerp = |a: f64, b: f64| a + f * (b - a);
            let ki = if i == n {
                *kin
            } else {
                SectionKinematics {
                    normal_velocity_m_s: lerp(k0.normal_velocity_m_s, kin.normal_velocity_m_s),
                    chord_velocity_m_s: lerp(k0.chord_velocity_m_s, kin.chord_velocity_m_s),
                    rotation_rate_rad_s: lerp(k0.rotation_rate_rad_s, kin.rotation_rate_rad_s),
                    ..*kin
                }
            };
            match self.substep(&ki, h) {
                Some(l) => {
                    out.normal_n_m += l.normal_n_m / n as f64;
                    out.chordwise_n_m += l.chordwise_n_m / n as f64;
                    out.moment_n += l.moment_n / n as f64;
                }
                None => return nan,
            }
        }
        out
    }
}

impl StripLdvm {
    /// One LDVM step of `dt_s` to the kinematics `kin`; None on a solver error.
    fn substep(&mut self, kin: &SectionKinematics, dt_s: f64) -> Option<SectionLoads> {
        let ldvm = self.ldvm.as_mut()?;
        let speed = kin.speed_m_s();
        let omega = kin.rotation_rate_rad_s;
        // the vertical in section components [x_w, y_w], normalized in the strip's plane
        let up = kin.up_section.and_then(|[ux, uy]| {
            let norm = ux.hypot(uy);
            (norm > 1e-9).then(|| [ux / norm, uy / norm])
        });
        // The first step starts impulsively; its dt sets the first TEV position and the
        // impulse of the start. Without a given interval it is the time of one step of travel
        // (`max_step_chords`), which keeps the run invariant under time scaling.
        let dt = if self.started || (dt_s.is_finite() && dt_s > 0.0) {
            dt_s
        } else {
            let u = speed.max(omega.abs() * pivot_to_edge_m(ldvm.params()));
            if u > 0.0 { self.max_step_m / u } else { 1e-3 }
        };
        if self.started {
            // the travel and time of the recent motion, older parts weighted by e^{−s/(s_U c)}
            let ds = 0.5 * (self.prev_speed_m_s + speed) * dt;
            let keep = (-ds / self.reference_travel_m).exp();
            self.recent_time_s = keep * self.recent_time_s + dt;
            self.recent_travel_m = keep * self.recent_travel_m + ds;
            if let Some(up) = up
                && !self.inflow.is_still()
            {
                let l = &self.last_loads;
                let lift = l.normal_n_m * up[0] + l.chordwise_n_m * up[1];
                let horizontal = kin.normal_velocity_m_s * up[1] - kin.chord_velocity_m_s * up[0];
                self.inflow.advance(keep, dt, lift, horizontal);
            }
        }
        let u_ref = if self.recent_time_s > 0.0 {
            self.recent_travel_m / self.recent_time_s
        } else {
            speed
        };
        let inflow = if up.is_some() && !self.inflow.is_still() {
            // the time of s_U chords at U_ref (the weighted time since the start where longer,
            // or where there is no s_U)
            let window_s = if u_ref > 0.0 && self.reference_travel_m.is_finite() {
                (self.reference_travel_m / u_ref).max(self.recent_time_s)
            } else {
                self.recent_time_s
            };
            self.inflow.speed_m_s(u_ref, window_s)
        } else {
            0.0
        };
        if self.started {
            let prev_vel = self.plate.pivot_vel_m_s;
            let angle = self.plate.angle_rad + 0.5 * (self.plate.angle_rate_rad_s + omega) * dt;
            let vel = Self::fluid_frame_velocity(angle, kin, up, inflow);
            self.plate.pivot_m[0] += 0.5 * (prev_vel[0] + vel[0]) * dt;
            self.plate.pivot_m[1] += 0.5 * (prev_vel[1] + vel[1]) * dt;
            self.plate.angle_rad = angle;
            self.plate.pivot_vel_m_s = vel;
        } else {
            self.plate.pivot_vel_m_s = Self::fluid_frame_velocity(0.0, kin, up, inflow);
        }
        self.plate.angle_rate_rad_s = omega;
        self.prev_speed_m_s = speed;
        self.prev_kin = *kin;
        ldvm.set_reference_speed(u_ref);
        self.started = true;
        // the profile drag ∝ U·t of the flow relative to the plate (the section's own with no inflow)
        let drag_speed2 = if inflow == 0.0 {
            speed * kin.chord_velocity_m_s
        } else {
            let v = self.plate.pivot_vel_m_s;
            let (s, c) = self.plate.angle_rad.sin_cos();
            -v[0].hypot(v[1]) * (v[0] * c + v[1] * s)
        };
        let l = ldvm.step(&self.plate, dt).ok()?;
        self.last_loads = SectionLoads {
            normal_n_m: self.cn_3d_factor * l.normal_n_m,
            chordwise_n_m: -l.chord_n_m - self.drag_factor * drag_speed2,
            moment_n: self.cn_3d_factor * l.moment_pivot_n,
        };
        Some(self.last_loads)
    }
}
