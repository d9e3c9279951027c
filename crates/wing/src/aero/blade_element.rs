//! Blade-element integration: one [`SectionModel`] per strip, summed into wing-frame loads at
//! the force sensor.
//!
//! Strip k sits at radius r_k on the pitch axis (Gauss–Legendre nodes on [r0, r0 + span],
//! weights w_k, so polynomial integrands such as ∫r² dr are exact). Its section sees
//! v = r_k v̂, ṅ = r_k(â_x + ω_z v̂_y), ṫ = r_k(â_y − ω_z v̂_x), ω_z, ω̇_z (v̂, â: unit-span
//! velocity and acceleration of [`WingKinematics`]). With sectional loads (N_k, T_k, M_k) and
//! the sensor origin on the pitch axis at radius r_s:
//!
//! F_x = Σ w_k N_k, F_y = Σ w_k T_k (N);
//! M_x = −Σ w_k (r_k − r_s) T_k, M_y = Σ w_k (r_k − r_s) N_k, M_z = Σ w_k M_k (× 1000, N·mm).

use super::{SectionGeometry, SectionKinematics, SectionModel, SectionModelFactory};
use crate::check::first_not_positive;
use crate::kinematics::WingKinematics;
use thiserror::Error;

/// Errors of the aerodynamic setup.
#[derive(Debug, Error, Clone, PartialEq)]
#[non_exhaustive]
pub enum AeroError {
    /// A parameter is out of its valid range.
    #[error("invalid aerodynamic parameter `{name}` = {value}: {reason}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Offending value.
        value: f64,
        /// What is required.
        reason: &'static str,
    },
}

/// Gauss–Legendre nodes and weights on [−1, 1] (n ≥ 1), by Newton iteration on P_n.
pub fn gauss_legendre(n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut nodes = vec![0.0; n];
    let mut weights = vec![0.0; n];
    for i in 0..n {
        let mut x = (std::f64::consts::PI * (i as f64 + 0.75) / (n as f64 + 0.5)).cos();
        let mut dp = 1.0;
        for _ in 0..100 {
            let (mut p0, mut p1) = (1.0, x);
            for k in 2..=n {
                let p2 = ((2 * k - 1) as f64 * x * p1 - (k - 1) as f64 * p0) / k as f64;
                p0 = p1;
                p1 = p2;
            }
            let pn = if n == 1 { x } else { p1 };
            let pnm1 = if n == 1 { 1.0 } else { p0 };
            dp = n as f64 * (x * pn - pnm1) / (x * x - 1.0);
            let dx = pn / dp;
            x -= dx;
            if dx.abs() < 1e-16 {
                break;
            }
        }
        nodes[i] = x;
        weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
    (nodes, weights)
}

/// Wing planform and fluid as the integrator needs them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BladeGeometry {
    /// Span of the rectangular plate (m).
    pub span_m: f64,
    /// Chord (m).
    pub chord_m: f64,
    /// Root offset r0 from the stroke axis (m).
    pub root_offset_m: f64,
    /// Pitch axis behind the LE, fraction of the chord.
    pub pitch_axis_frac: f64,
    /// Fluid density ρ (kg/m³).
    pub density_kg_m3: f64,
    /// Sensor origin on the pitch axis, radius r_s from the stroke axis (m).
    pub sensor_radius_m: f64,
}

impl BladeGeometry {
    /// Checks that lengths and density are positive and finite and x̂0 ∈ [0, 1].
    pub fn check(&self) -> Result<(), AeroError> {
        let positive = [
            ("span_m", self.span_m),
            ("chord_m", self.chord_m),
            ("density_kg_m3", self.density_kg_m3),
        ];
        if let Some((name, value)) = first_not_positive(&positive) {
            return Err(AeroError::InvalidParameter {
                name,
                value,
                reason: "must be finite and > 0",
            });
        }
        if !(self.root_offset_m.is_finite() && self.root_offset_m >= 0.0) {
            return Err(AeroError::InvalidParameter {
                name: "root_offset_m",
                value: self.root_offset_m,
                reason: "must be finite and >= 0",
            });
        }
        if !(0.0..=1.0).contains(&self.pitch_axis_frac) {
            return Err(AeroError::InvalidParameter {
                name: "pitch_axis_frac",
                value: self.pitch_axis_frac,
                reason: "must lie in [0, 1]",
            });
        }
        if !self.sensor_radius_m.is_finite() {
            return Err(AeroError::InvalidParameter {
                name: "sensor_radius_m",
                value: self.sensor_radius_m,
                reason: "must be finite",
            });
        }
        Ok(())
    }
}

/// The blade-element integrator with its per-strip section models.
pub struct BladeElement {
    geom: BladeGeometry,
    radii_m: Vec<f64>,
    weights_m: Vec<f64>,
    models: Vec<Box<dyn SectionModel>>,
}

impl BladeElement {
    /// Builds `n_strips` section models with `factory`.
    ///
    /// # Errors
    /// [`AeroError::InvalidParameter`] for a bad geometry or `n_strips == 0`.
    pub fn new(
        geom: BladeGeometry,
        n_strips: usize,
        factory: &dyn SectionModelFactory,
    ) -> Result<Self, AeroError> {
        geom.check()?;
        if n_strips == 0 {
            return Err(AeroError::InvalidParameter {
                name: "n_strips",
                value: 0.0,
                reason: "must be >= 1",
            });
        }
        let (x, w) = gauss_legendre(n_strips);
        let half = 0.5 * geom.span_m;
        let mid = geom.root_offset_m + half;
        let radii_m: Vec<f64> = x.iter().map(|x| mid + half * x).collect();
        let weights_m: Vec<f64> = w.iter().map(|w| half * w).collect();
        let models = radii_m
            .iter()
            .map(|&r| {
                factory.build(&SectionGeometry {
                    chord_m: geom.chord_m,
                    pitch_axis_frac: geom.pitch_axis_frac,
                    radius_m: r,
                    density_kg_m3: geom.density_kg_m3,
                })
            })
            .collect();
        Ok(Self {
            geom,
            radii_m,
            weights_m,
            models,
        })
    }

    /// Strip radii r_k (m).
    pub fn radii_m(&self) -> &[f64] {
        &self.radii_m
    }

    /// Strip quadrature weights w_k (m); Σ w_k f(r_k) ≈ ∫_{r0}^{r0+span} f(r) dr.
    pub fn weights_m(&self) -> &[f64] {
        &self.weights_m
    }

    /// Returns every section to still fluid.
    pub fn reset(&mut self) {
        self.models.iter_mut().for_each(|m| m.reset());
    }

    /// Advances all strips by `dt_s` to the wing kinematics `kin` and returns
    /// [F_x, F_y (N), M_x, M_y, M_z (N·mm)] at the sensor origin. No allocation.
    pub fn step(&mut self, kin: &WingKinematics, dt_s: f64) -> [f64; 5] {
        let wz = kin.omega_rad_s[2];
        let wz_dot = kin.omega_dot_rad_s2[2];
        let n_rate = kin.a[0] + wz * kin.v_y;
        let t_rate = kin.a[1] - wz * kin.v_x;
        let mut out = [0.0; 5];
        for ((model, &r), &w) in self
            .models
            .iter_mut()
            .zip(&self.radii_m)
            .zip(&self.weights_m)
        {
            let section = SectionKinematics {
                normal_velocity_m_s: r * kin.v_x,
                chord_velocity_m_s: r * kin.v_y,
                normal_velocity_rate_m_s2: r * n_rate,
                chord_velocity_rate_m_s2: r * t_rate,
                rotation_rate_rad_s: wz,
                rotation_acc_rad_s2: wz_dot,
                up_section: kin.up_wing.map(|u| [u[0], u[1]]),
            };
            let l = model.step(&section, dt_s);
            let arm = r - self.geom.sensor_radius_m;
            out[0] += w * l.normal_n_m;
            out[1] += w * l.chordwise_n_m;
            out[2] -= 1e3 * w * arm * l.chordwise_n_m;
            out[3] += 1e3 * w * arm * l.normal_n_m;
            out[4] += 1e3 * w * l.moment_n;
        }
        out
    }
}
