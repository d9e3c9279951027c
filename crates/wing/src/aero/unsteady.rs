//! L1: unsteady low-order sectional aerodynamics — the quasi-steady model of
//! [`super::quasi_steady`] plus three memory effects per section.
//!
//! 1. **Induced inflow / wake** (§3.4 of the physics notes). The fluid near the section has a
//!    velocity w = (w_x, w_y) (fixed in inertial space, so its section-frame components rotate
//!    by −ω_z dt each step). It is driven by the shed circulation: by Kelvin's theorem the
//!    vorticity shed into the wake balances the bound circulation Γ ≈ F_c/(ρU), and a lumped
//!    wake vortex at distance d_w induces w* = −F̂_c/(2π d_w) (F̂_c = F_c/(ρU), N_c and T_c
//!    components, so the fluid is pushed opposite to the force). w relaxes to w* over a swept
//!    wing angle θ_w (rad, the distance travelled per metre of span):
//!    w ← w* + (w − w*)·exp(−Δθ/θ_w), Δθ = U·dt/r. All circulatory loads use the velocity
//!    relative to the fluid, v − w; after a stroke reversal the wing moves back into the flow
//!    it set in motion (wake capture).
//! 2. **LEV lag** (Goman–Khrabrov type). The translational normal force is split into an
//!    attached share cos²α_g (potential flow, lagged by Wagner) and an LEV share sin²α_g whose
//!    signed coefficient c_n relaxes to its static value over τ_lev chords travelled:
//!    c_n ← c_n* + (c_n − c_n*)·exp(−Δs_c/τ_lev), Δs_c = ∫U dt / c. It starts at 0 (no LEV).
//! 3. **Wagner lag** (Jones-type 2-state, per load channel N, T, M) on the attached share and the
//!    rotational circulation. With the circulatory input u = L_qs/(ρU) (circulation-like, m²/s)
//!    and s = 2∫U dt/c (semichords), dx_i/ds = −b_i x_i + u,
//!    L_c = ρU[(1 − A1 − A2)u + A1 b1 x1 + A2 b2 x2], integrated exactly for u linear over a
//!    step; in s the states freeze when U → 0. With the Wagner lag off, the whole translational
//!    force takes the LEV path.
//!
//! Added mass uses the true kinematics, as in L0. Every effect can be switched off; with all
//! three off the model equals L0.

use super::quasi_steady::{
    QuasiSteadyParams, added_mass_loads, circulatory_loads, translational_coefficients,
};
use super::{SectionGeometry, SectionKinematics, SectionLoads, SectionModel, SectionModelFactory};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Coefficients of the two-state Wagner approximation φ(s) = 1 − A1 e^{−b1 s} − A2 e^{−b2 s}.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WagnerCoefficients {
    /// A1.
    pub a1: f64,
    /// b1 (per semichord).
    pub b1: f64,
    /// A2.
    pub a2: f64,
    /// b2 (per semichord).
    pub b2: f64,
}

impl Default for WagnerCoefficients {
    /// A1 = 0.165, b1 = 0.041, A2 = 0.335, b2 = 0.32: a common variant of R. T. Jones'
    /// coefficients (0.0455, 0.3); it matches the Theodorsen function within 1.3 % and 1.4°
    /// for k ≤ 1 and the Wagner function within 0.011.
    fn default() -> Self {
        Self {
            a1: 0.165,
            b1: 0.041,
            a2: 0.335,
            b2: 0.32,
        }
    }
}

/// Settings of the L1 model. Defaults are physically plausible mid-range values
/// (physics notes §3.1, §3.4).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct UnsteadyParams {
    /// The quasi-steady parts.
    pub quasi_steady: QuasiSteadyParams,
    /// Wagner lag on the circulatory loads (true).
    pub wagner: bool,
    /// Wagner coefficients.
    pub wagner_coefficients: WagnerCoefficients,
    /// LEV lag on the translational normal coefficient (true).
    pub lev_lag: bool,
    /// LEV time constant τ_lev in chords travelled (2; revolving wings build their LEV within
    /// about 2 chords, airfoil dynamic stall 2–6).
    pub lev_time_constant_chords: f64,
    /// Induced inflow / wake state (true).
    pub inflow: bool,
    /// Distance d_w of the lumped wake vortex, in chords (2). Steady inflow
    /// w/U = C_N/(4π d_w) ≈ 0.1 at C_N = 2.5, below the momentum-theory hover value (≈ 0.2–0.3)
    /// because the static Dickinson coefficients already contain the Robofly's mean inflow.
    pub inflow_distance_chords: f64,
    /// Relaxation angle θ_w of the inflow, in radians of wing travel (0.8 ≈ 0.1–0.3 of a
    /// cycle for stroke amplitudes 40–100°).
    pub inflow_decay_rad: f64,
}

impl Default for UnsteadyParams {
    fn default() -> Self {
        Self {
            quasi_steady: QuasiSteadyParams::default(),
            wagner: true,
            wagner_coefficients: WagnerCoefficients::default(),
            lev_lag: true,
            lev_time_constant_chords: 2.0,
            inflow: true,
            inflow_distance_chords: 2.0,
            inflow_decay_rad: 0.8,
        }
    }
}

/// The L1 section: 12 scalars of state.
#[derive(Debug, Clone)]
pub struct UnsteadySection {
    geom: SectionGeometry,
    params: UnsteadyParams,
    started: bool,
    /// Fluid velocity near the section, section frame (m/s).
    inflow_m_s: [f64; 2],
    /// Lagged signed normal coefficient.
    c_n_lev: f64,
    /// Wagner states per channel (N, T, M), m²/s·semichord.
    wagner_x: [[f64; 2]; 3],
    /// Previous circulatory input per channel.
    u_prev: [f64; 3],
    /// Previous Wagner output per channel (circulation-like).
    g_prev: [f64; 3],
    /// Previous relative speed (m/s).
    speed_prev_m_s: f64,
}

impl UnsteadySection {
    /// A section at rest.
    pub fn new(geom: SectionGeometry, params: UnsteadyParams) -> Self {
        Self {
            geom,
            params,
            started: false,
            inflow_m_s: [0.0; 2],
            c_n_lev: 0.0,
            wagner_x: [[0.0; 2]; 3],
            u_prev: [0.0; 3],
            g_prev: [0.0; 3],
            speed_prev_m_s: 0.0,
        }
    }

    /// The fluid velocity [w_x, w_y] near the section (m/s, section frame).
    pub fn inflow_m_s(&self) -> [f64; 2] {
        self.inflow_m_s
    }
}

/// Exact one-step propagator of dx/ds = −b x + u(s) for u linear from u0 to u1 over Δ ≥ 0:
/// x(Δ) = e^{−bΔ}x0 + E1·u0 + R·(u1 − u0), E1 = (1 − e^{−bΔ})/b, R = (Δ − E1)/(bΔ).
#[derive(Debug, Clone, Copy)]
struct FohStep {
    decay: f64,
    e1: f64,
    ramp: f64,
}

impl FohStep {
    fn new(b: f64, delta: f64) -> Self {
        let bd = b * delta;
        let em1 = (-bd).exp_m1();
        let e1 = -em1 / b;
        // R by series when bΔ is small.
        let ramp = if bd < 1e-4 {
            delta * (0.5 - bd / 6.0)
        } else {
            (delta - e1) / bd
        };
        Self {
            decay: 1.0 + em1,
            e1,
            ramp,
        }
    }

    fn apply(&self, x: f64, u0: f64, u1: f64) -> f64 {
        self.decay * x + u0 * self.e1 + (u1 - u0) * self.ramp
    }
}

impl SectionModel for UnsteadySection {
    fn reset(&mut self) {
        *self = Self::new(self.geom, self.params);
    }

    fn step(&mut self, kin: &SectionKinematics, dt_s: f64) -> SectionLoads {
        let p = &self.params;
        let c = self.geom.chord_m;
        let rho = self.geom.density_kg_m3;
        let dt = if self.started { dt_s } else { 0.0 };
        let omega = kin.rotation_rate_rad_s;

        if p.inflow && self.started {
            let (s, co) = (omega * dt).sin_cos();
            let [wx, wy] = self.inflow_m_s;
            let wx_r = co * wx + s * wy;
            let wy_r = -s * wx + co * wy;
            let target = -1.0 / (2.0 * PI * p.inflow_distance_chords * c);
            let (tx, ty) = (target * self.g_prev[0], target * self.g_prev[1]);
            let swept = kin.speed_m_s() * dt / self.geom.radius_m;
            let keep = (-swept / p.inflow_decay_rad).exp();
            self.inflow_m_s = [tx + (wx_r - tx) * keep, ty + (wy_r - ty) * keep];
        }
        let n_rel = kin.normal_velocity_m_s - self.inflow_m_s[0];
        let t_rel = kin.chord_velocity_m_s - self.inflow_m_s[1];
        let speed = n_rel.hypot(t_rel);
        let prev_speed = if self.started {
            self.speed_prev_m_s
        } else {
            speed
        };
        let travel_m = 0.5 * (prev_speed + speed) * dt;

        // Attached (potential) share of the translational force, w_att = cos²α_g; the rest is
        // the LEV share.
        let mut coeffs = translational_coefficients(n_rel, t_rel, &p.quasi_steady);
        let cos2 = if speed > 0.0 {
            t_rel * t_rel / (speed * speed)
        } else {
            1.0
        };
        let c_n_static = coeffs.c_n;
        let c_n_lev = if p.lev_lag {
            let keep = (-travel_m / (c * p.lev_time_constant_chords)).exp();
            self.c_n_lev = c_n_static + (self.c_n_lev - c_n_static) * keep;
            self.c_n_lev
        } else {
            c_n_static
        };
        let (w_att, c_n_lagged) = if p.wagner {
            (cos2, c_n_lev)
        } else {
            (0.0, c_n_lev)
        };
        // Wagner channel: attached translational share plus rotational circulation (+ T, M).
        coeffs.c_n = w_att * c_n_static;
        let circ_att = circulatory_loads(&self.geom, &p.quasi_steady, n_rel, t_rel, omega, &coeffs);
        // LEV channel: the remaining translational share, lagged, no rotation.
        let q = 0.5 * rho * c * speed * speed;
        let n_lev = (1.0 - w_att) * c_n_lagged * q;
        let lev = SectionLoads {
            normal_n_m: n_lev,
            chordwise_n_m: 0.0,
            moment_n: (coeffs.cp_from_le - self.geom.pitch_axis_frac) * c * n_lev,
        };
        let qs = [
            circ_att.normal_n_m,
            circ_att.chordwise_n_m,
            circ_att.moment_n,
        ];
        let inv = if speed > 0.0 {
            1.0 / (rho * speed)
        } else {
            0.0
        };
        let u = qs.map(|l| l * inv);
        if !self.started {
            self.u_prev = u;
            self.started = true;
        }
        let mut g = u;
        if p.wagner {
            let WagnerCoefficients { a1, b1, a2, b2 } = p.wagner_coefficients;
            let ds = 2.0 * travel_m / c;
            let (step1, step2) = (FohStep::new(b1, ds), FohStep::new(b2, ds));
            for ch in 0..3 {
                let x = &mut self.wagner_x[ch];
                x[0] = step1.apply(x[0], self.u_prev[ch], u[ch]);
                x[1] = step2.apply(x[1], self.u_prev[ch], u[ch]);
                g[ch] = (1.0 - a1 - a2) * u[ch] + a1 * b1 * x[0] + a2 * b2 * x[1];
            }
        }
        self.u_prev = u;
        self.g_prev = g;
        self.speed_prev_m_s = speed;
        let circ = SectionLoads {
            normal_n_m: rho * speed * g[0],
            chordwise_n_m: rho * speed * g[1],
            moment_n: rho * speed * g[2],
        } + lev;
        self.g_prev = [
            self.g_prev[0] + lev.normal_n_m * inv,
            self.g_prev[1],
            self.g_prev[2],
        ];
        circ + added_mass_loads(&self.geom, &p.quasi_steady, kin)
    }
}

impl SectionModelFactory for UnsteadyParams {
    fn build(&self, section: &SectionGeometry) -> Box<dyn SectionModel> {
        Box::new(UnsteadySection::new(*section, *self))
    }
}
