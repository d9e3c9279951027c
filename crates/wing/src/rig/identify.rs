//! The rigid-body loads identified from reference recordings instead of given mass properties.
//!
//! The loads a sensor reads of a wing that feels no aerodynamic load are linear in the body's
//! parameters ([`super::rigid_body`]). After the tare at the home pose h, a reference recording
//! holds, in wing axes about the root,
//!
//! L(t) = Y_s(g_w(t) − g_w(h))·[k, s] + Y_i(t)·[m, h, I_P] (in air),
//! L(t) = Y_s(g_w(t) − g_w(h))·[k, s] (in the fluid, at rest or moving slowly),
//!
//! and least squares over every sample (less the differentiator's half window at each end)
//! gives the parameters:
//!
//! - **in air** (`medium = "air"`): the weight is the mass (k = m, s = h, the air's buoyancy
//!   neglected), so the ten parameters [m, h, I_P] are fitted; the buoyancy in the fluid then
//!   comes from `volume_m3` and `center_of_buoyancy_m`. The run must move the wing (a stroke
//!   motion excites every inertia parameter, a rest none);
//! - **in the fluid** (`medium = "fluid"`, poses held still): the net weight less buoyancy
//!   [k, s] (4 parameters), from the samples where the wing is still (every angle's rate below
//!   [`STILL_RAD_S`]: moving, it would feel its inertia and the fluid); the inertia, if
//!   subtracted, from `[mass]`.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use serde::{Deserialize, Serialize};

use super::RigError;
use super::description::RigDescription;
use super::recording::{Prepared, RawRecording, prepare};
use super::rigid_body::{
    InertialParameters, RigidBody, SensorFrame, StaticParameters, gravity_in_wing,
    inertial_regressor, static_regressor,
};
use crate::differentiate::SavitzkyGolayConfig;

/// The largest angular rate (rad/s, about 0.6°/s) of a sample taken as still in a run in the
/// fluid.
pub const STILL_RAD_S: f64 = 0.01;

/// Where a reference run was made.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Medium {
    /// In air: weight and inertia identified.
    Air,
    /// In the rig's fluid, at rest or slow: the net weight less buoyancy identified.
    Fluid,
}

/// The `[reference]` section: recordings (the rig's format) to identify the rigid-body loads
/// from, instead of `[mass]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Reference {
    /// The recordings (paths relative to the description's file).
    pub recordings: Vec<String>,
    /// Where they were made.
    pub medium: Medium,
    /// In air: the volume displacing fluid (m³), for the buoyancy in the fluid.
    #[serde(default)]
    pub volume_m3: Option<f64>,
    /// In air: the centre of buoyancy from the wing root (m).
    #[serde(default)]
    pub center_of_buoyancy_m: Option<[f64; 3]>,
}

/// What a reference run gave.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Identified {
    /// Where the runs were made.
    pub medium: Medium,
    /// The static parameters: the weight (air) or the weight less buoyancy (fluid).
    pub static_parameters: StaticParameters,
    /// The inertial parameters (air only).
    pub inertial: Option<InertialParameters>,
    /// Samples fitted.
    pub n_samples: usize,
    /// RMS of the fit's residual per channel (N, N·m), wing axes about the root.
    pub residual_rms: [f64; 6],
}

impl Identified {
    /// The rigid body the processing subtracts: the identified parameters, completed by the
    /// buoyancy of `[reference]` (air) or by the inertia of `[mass]` (fluid).
    pub fn rigid_body(&self, desc: &RigDescription) -> RigidBody {
        let r0 = desc.wing.root_offset_m;
        match self.medium {
            Medium::Air => {
                let reference = desc.reference.as_ref();
                let volume = reference.and_then(|r| r.volume_m3).unwrap_or(0.0);
                let inertia = self.inertial.unwrap_or_default();
                let c_mass = inertia.first_moment_kg_m.map(|h| h / inertia.mass_kg);
                let b = reference
                    .and_then(|r| r.center_of_buoyancy_m)
                    .unwrap_or(c_mass);
                let displaced = desc.fluid.density_kg_m3 * volume;
                RigidBody {
                    weight: self.static_parameters,
                    buoyancy: StaticParameters {
                        mass_kg: -displaced,
                        first_moment_kg_m: b.map(|x| -displaced * x),
                    },
                    inertia,
                    root_offset_m: r0,
                }
            }
            Medium::Fluid => RigidBody {
                weight: self.static_parameters,
                buoyancy: StaticParameters::default(),
                inertia: desc.rigid_body().map(|b| b.inertia).unwrap_or_default(),
                root_offset_m: r0,
            },
        }
    }
}

/// Identifies the rigid-body parameters from reference recordings (module docs) of a rig
/// whose description has a `[reference]`.
///
/// # Errors
/// [`RigError::Recording`] for a recording that fails the checks of
/// [`super::process_recording`] (or is too short for them); [`RigError::Field`] (`reference.recordings`)
/// when the runs do not determine the parameters (an air run without motion).
pub fn identify(
    desc: &RigDescription,
    recordings: &[RawRecording],
) -> Result<Identified, RigError> {
    let Some(reference) = &desc.reference else {
        return Err(RigError::field(
            "reference",
            "none",
            "identification needs a [reference]",
        ));
    };
    let medium = reference.medium;
    let k = match medium {
        Medium::Air => 10,
        Medium::Fluid => 4,
    };
    let rate = desc.sampling.rate_hz;
    let edge = SavitzkyGolayConfig::spanning_default(1.0 / rate).half_window;
    let frame = SensorFrame::new(&desc.sensor);
    let si = desc.sensor.si_per_unit();
    let mut normal = Mat::<f64>::zeros(k, k);
    let mut rhs = Mat::<f64>::zeros(k, 1);
    let mut rows: Vec<([[f64; 10]; 6], [f64; 6])> = Vec::new();
    for rec in recordings {
        let Prepared { states, rest } = prepare(desc, rec)?;
        let n = states.len();
        let (zero, home) = match &rest {
            Some(r) => (
                r.mean_reading,
                gravity_in_wing(&desc.angles.to_flapssm(r.home_pose)),
            ),
            None => ([0.0; 6], [0.0; 3]),
        };
        for (st, reading) in states.iter().zip(&rec.sensor).take(n - edge).skip(edge) {
            if medium == Medium::Fluid && st.rates_rad_s.iter().any(|r| r.abs() > STILL_RAD_S) {
                continue;
            }
            let zeroed: [f64; 6] = std::array::from_fn(|c| (reading[c] - zero[c]) * si[c]);
            let target = frame.to_wing(&zeroed);
            let g = gravity_in_wing(&st.angles_rad);
            let ys = static_regressor(std::array::from_fn(|i| g[i] - home[i]));
            let mut y = [[0.0; 10]; 6];
            if medium == Medium::Air {
                y = inertial_regressor(st, desc.wing.root_offset_m);
            }
            for (row, s_row) in y.iter_mut().zip(&ys) {
                row.iter_mut().zip(s_row).for_each(|(a, b)| *a += b);
            }
            for (row, t) in y.iter().zip(&target) {
                for a in 0..k {
                    rhs[(a, 0)] += row[a] * t;
                    for b in 0..=a {
                        normal[(a, b)] += row[a] * row[b];
                    }
                }
            }
            rows.push((y, target));
        }
    }
    if rows.is_empty() {
        return Err(RigError::field(
            "reference.recordings",
            "[]",
            "no recording to fit",
        ));
    }
    // Each parameter must be excited: its column's energy against the largest.
    let diag: Vec<f64> = (0..k).map(|a| normal[(a, a)]).collect();
    let top = diag.iter().cloned().fold(0.0, f64::max);
    if let Some(a) = diag.iter().position(|d| d.is_nan() || *d <= 1e-12 * top) {
        return Err(RigError::field(
            "reference.recordings",
            format!("parameter {a}"),
            "the runs do not determine the rigid body: an air run must move the wing (the \
             inertia), a run in the fluid must hold several poses",
        ));
    }
    for a in 0..k {
        for b in 0..a {
            normal[(b, a)] = normal[(a, b)];
        }
    }
    let llt = normal.llt(Side::Lower).map_err(|e| {
        RigError::field(
            "reference.recordings",
            format!("{e:?}"),
            "the runs do not determine the rigid body (a singular fit)",
        )
    })?;
    let theta = llt.solve(&rhs);
    let p: Vec<f64> = (0..k).map(|a| theta[(a, 0)]).collect();
    let mut residual = [0.0; 6];
    for (y, t) in &rows {
        for c in 0..6 {
            let fit: f64 = (0..k).map(|a| y[c][a] * p[a]).sum();
            residual[c] += (t[c] - fit).powi(2);
        }
    }
    let residual_rms = residual.map(|r| (r / rows.len() as f64).sqrt());
    let static_parameters = StaticParameters {
        mass_kg: p[0],
        first_moment_kg_m: [p[1], p[2], p[3]],
    };
    let inertial = (medium == Medium::Air).then(|| InertialParameters {
        mass_kg: p[0],
        first_moment_kg_m: [p[1], p[2], p[3]],
        inertia_p_kg_m2: [p[4], p[5], p[6], p[7], p[8], p[9]],
    });
    Ok(Identified {
        medium,
        static_parameters,
        inertial,
        n_samples: rows.len(),
        residual_rms,
    })
}
