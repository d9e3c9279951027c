//! The virtual wing as a user's rig: the raw recording that the rig of a description would
//! write for a motion, so that the whole path from recording to model can be rehearsed before an
//! experiment, and the processing tested on known answers.
//!
//! A rehearsed recording is: `tare.rest_s` at rest at the home pose, a rest-to-rest move to the
//! motion's first pose over `trajectories.skip_s` (C² quintic), then the motion. Its sensor
//! channels are what the rig's sensor reports: the virtual wing's aerodynamic loads (the rig's
//! geometry and fluid) plus the weight, buoyancy and inertial loads of the rig's `[mass]` (all
//! three: they are physics, not a choice), in the sensor's axes about its origin, plus an offset
//! per recording (`sensor.bias_sd`) and white noise (`sensor.noise_sd`), in the sensor's units.
//! Its angles are recorded in the rig's convention and unit; its time column, if the rig has one,
//! counts from zero.

use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, Normal};

use super::RigError;
use super::description::{RigDescription, Subtract};
use super::recording::{RawRecording, cut};
use super::rigid_body::{SensorFrame, wrench_of_channels};
use crate::dataset::Trajectory;
use crate::kinematics::EulerState;
use crate::mount::Mount;
use crate::sensor::SensorConfig;
use crate::virtual_wing::{Fidelity, VirtualWing, VirtualWingConfig};

/// A rehearsed recording and what the rig should recover from it.
#[derive(Debug, Clone, PartialEq)]
pub struct Rehearsed {
    /// The raw recording.
    pub recording: RawRecording,
    /// The wing's own aerodynamic loads on the exact motion, cut and resampled as the
    /// processing cuts the recording: the known answer.
    pub truth: Vec<Trajectory>,
}

/// The virtual wing of a rig: its geometry and fluid at `fidelity`, loads about the wing root,
/// the plate aligned with the pitch axis, no sensor chain (the rehearsal adds the rig's own).
pub fn virtual_wing_of(desc: &RigDescription, fidelity: Fidelity) -> VirtualWingConfig {
    let wing = desc.geometry();
    VirtualWingConfig {
        fidelity,
        sensor_radius_m: wing.root_offset_m,
        wing,
        fluid: desc.fluid(),
        mount: Mount::default(),
        sensor: SensorConfig::noise_free(),
        ..VirtualWingConfig::default()
    }
}

/// Rehearses one recording of `motion` (flapssm Euler states at `sampling.rate_hz`, starting at
/// rest) on `wing` (built from [`virtual_wing_of`]), drawing the offset and noise from `rng`.
///
/// # Errors
/// [`RigError::Recording`] if the rig leaves no time to move from the home pose to the motion
/// (`trajectories.skip_s`) or the motion gives no trajectory.
pub fn rehearse(
    desc: &RigDescription,
    wing: &mut VirtualWing,
    motion: &[EulerState],
    source_name: &str,
    rng: &mut ChaCha8Rng,
) -> Result<Rehearsed, RigError> {
    let fail = |reason: String| RigError::recording(source_name, reason);
    let rate = desc.sampling.rate_hz;
    let dt = 1.0 / rate;
    let first = motion
        .first()
        .ok_or_else(|| fail("the motion has no sample".into()))?;
    let n_rest = (desc.tare.rest_s * rate).round() as usize;
    let n_move = (desc.trajectories.skip_s * rate).round() as usize;
    let home = desc.angles.to_flapssm(desc.tare.home_pose);
    let states = approach(home, first, n_rest, n_move, dt, motion).ok_or_else(|| {
        fail(format!(
            "the motion starts away from the home pose but trajectories.skip_s = {} s leaves \
             no time to move there",
            desc.trajectories.skip_s
        ))
    })?;
    let n = states.len();
    let mut aero = vec![[0.0; 5]; n];
    wing.aero_loads_into(&states, dt, &mut aero);
    let frame = SensorFrame::new(&desc.sensor);
    let body = desc.rigid_body();
    let physics = Subtract {
        gravity: true,
        buoyancy: true,
        inertia: true,
    };
    let si = desc.sensor.si_per_unit();
    let std = Normal::new(0.0, 1.0).expect("unit normal");
    let bias: [f64; 6] = std::array::from_fn(|c| desc.sensor.bias_sd[c] * std.sample(rng));
    let mut sensor = Vec::with_capacity(n);
    for (st, y) in states.iter().zip(&aero) {
        let mut w = wrench_of_channels(y);
        if let Some(b) = &body {
            let r = b.loads(st, &physics);
            w.iter_mut().zip(r).for_each(|(a, b)| *a += b);
        }
        let s = frame.to_sensor(&w);
        sensor.push(std::array::from_fn(|c| {
            s[c] / si[c] + bias[c] + desc.sensor.noise_sd[c] * std.sample(rng)
        }));
    }
    let mut previous = None;
    let angles = states
        .iter()
        .map(|st| {
            let a = desc.angles.from_flapssm(st.angles_rad, previous);
            previous = Some(a);
            a
        })
        .collect();
    let recording = RawRecording {
        source_name: source_name.to_string(),
        time_s: desc
            .sampling
            .time_column
            .as_ref()
            .map(|_| (0..n).map(|k| k as f64 * dt).collect()),
        angles,
        sensor,
    };
    let truth = cut(desc, &recording, &states, &aero, n_rest)?;
    Ok(Rehearsed { recording, truth })
}

/// The rest at `home`, the quintic rest-to-rest move to the motion's first pose (`n_move`
/// samples of `dt_s`) and the motion, its angles shifted by whole turns to continue the move; `None` if
/// the motion starts elsewhere than home with no move.
fn approach(
    home: [f64; 3],
    first: &EulerState,
    n_rest: usize,
    n_move: usize,
    dt_s: f64,
    motion: &[EulerState],
) -> Option<Vec<EulerState>> {
    use std::f64::consts::PI;
    let delta: [f64; 3] = std::array::from_fn(|a| {
        let d = (first.angles_rad[a] - home[a]).rem_euclid(2.0 * PI);
        if d > PI { d - 2.0 * PI } else { d }
    });
    let moves = delta.iter().any(|d| d.abs() > 1e-12);
    if moves && n_move == 0 {
        return None;
    }
    let shift: [f64; 3] = std::array::from_fn(|a| home[a] + delta[a] - first.angles_rad[a]);
    let mut out = Vec::with_capacity(n_rest + n_move + motion.len());
    out.extend(std::iter::repeat_n(
        EulerState {
            angles_rad: home,
            ..EulerState::default()
        },
        n_rest,
    ));
    let t_move = n_move as f64 * dt_s;
    for k in 0..n_move {
        let s = k as f64 / n_move as f64;
        let r = s * s * s * (10.0 - 15.0 * s + 6.0 * s * s);
        let r_d = 30.0 * s * s * (1.0 - s) * (1.0 - s) / t_move;
        let r_dd = 60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (t_move * t_move);
        out.push(EulerState {
            angles_rad: std::array::from_fn(|a| home[a] + r * delta[a]),
            rates_rad_s: std::array::from_fn(|a| r_d * delta[a]),
            accels_rad_s2: std::array::from_fn(|a| r_dd * delta[a]),
        });
    }
    out.extend(motion.iter().map(|st| EulerState {
        angles_rad: std::array::from_fn(|a| st.angles_rad[a] + shift[a]),
        ..*st
    }));
    Some(out)
}
