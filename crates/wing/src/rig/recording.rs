//! From a raw recording of a rig to the dataset's trajectories.
//!
//! A raw recording holds, per sample at `sampling.rate_hz`, the three recorded angles and the
//! six sensor channels (optionally a time column). [`process_recording`] applies the rig
//! description, in this order:
//!
//! 1. checks: equal lengths, finite values, time increasing and at the stated rate;
//! 2. angles to flapssm's convention (rad, [`super::convention`]), unwrapped; angles, rates and
//!    accelerations by the Savitzky–Golay differentiator (window 0.48 s, degree 6);
//! 3. tare: over the first `tare.rest_s` the wing must rest at `tare.home_pose` (within
//!    `tare.tolerance_deg`); the sensor's zero is the mean reading there less the modelled
//!    weight and buoyancy at that pose (those to be subtracted; none: the mean reading);
//! 4. each sample: reading − zero, to SI, to wing axes about the wing root
//!    ([`super::rigid_body::SensorFrame`]), less the rigid-body loads `subtract` names (of the
//!    `[mass]` section, [`RigDescription::rigid_body`], or identified from reference runs,
//!    [`super::identify`]);
//! 5. the zero-phase low-pass `filter.cutoff_hz` ([`crate::sensor::filtfilt`]);
//! 6. after the rest and `trajectories.skip_s` (and at least the differentiator's half window
//!    from either end of the recording), cut into trajectories and resampled to
//!    `sampling.dataset_rate_hz` (linear interpolation; an integer rate ratio picks samples);
//!    inputs from the differentiated angles, U_ref by the published recipe at the wing's
//!    `u_ref_radius_m`.

use super::RigError;
use super::description::RigDescription;
use super::rigid_body::{RigidBody, SensorFrame, Wrench, dataset_channels};
use crate::cycles::published_u_ref;
use crate::dataset::{OUTPUT_NAMES, Trajectory};
use crate::differentiate::{SavitzkyGolay, SavitzkyGolayConfig};
use crate::kinematics::{EulerState, WingKinematics};
use crate::sensor::{butterworth4, filtfilt};

/// Family label of recorded trajectories.
pub const RECORDED_FAMILY: &str = "recorded";

/// A rig's raw recording, as read from its file.
#[derive(Debug, Clone, PartialEq)]
pub struct RawRecording {
    /// Its name in messages (the file).
    pub source_name: String,
    /// Time stamps (s), if the rig records them.
    pub time_s: Option<Vec<f64>>,
    /// Stroke, deviation, pitch as recorded (the rig's unit and convention).
    pub angles: Vec<[f64; 3]>,
    /// The six sensor channels as recorded (the sensor's axes and units).
    pub sensor: Vec<[f64; 6]>,
}

/// What the processing found, for checking each step.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct RecordingReport {
    /// The recording.
    pub source_name: String,
    /// Raw samples.
    pub n_samples: usize,
    /// Trajectories cut from it.
    pub n_trajectories: usize,
    /// Mean angles during the rest (as recorded); `None` without a tare.
    pub home_pose_measured: Option<[f64; 3]>,
    /// Largest distance of an angle from the home pose during the rest (deg).
    pub rest_motion_deg: Option<f64>,
    /// The sensor's zero set by the tare (sensor units), subtracted from every reading.
    pub tare_offset: [f64; 6],
    /// RMS of the processed loads over the rest (N, N·mm): what the processing leaves of a
    /// wing at rest, zero but for noise when the subtraction is right.
    pub rest_residual: Option<[f64; 5]>,
}

/// The processing's intermediate signals at the raw rate, dataset channels (N, N·mm).
#[derive(Debug, Clone, PartialEq, Default)]
pub struct ProcessingSteps {
    /// Time of each raw sample from the start (s).
    pub time_s: Vec<f64>,
    /// After the tare, in wing axes about the root.
    pub tared: Vec<[f64; 5]>,
    /// The rigid-body loads subtracted.
    pub subtracted: Vec<[f64; 5]>,
    /// After the subtraction and the filter: the aerodynamic loads.
    pub processed: Vec<[f64; 5]>,
}

/// A processed recording.
#[derive(Debug, Clone, PartialEq)]
pub struct ProcessedRecording {
    /// Its trajectories at the dataset rate.
    pub trajectories: Vec<Trajectory>,
    /// What each step found.
    pub report: RecordingReport,
    /// The signals between the steps.
    pub steps: ProcessingSteps,
}

/// Processes one raw recording with a (checked) rig description (module docs), subtracting the
/// rigid-body loads of `body` that `desc.subtract` names (none without a body).
///
/// # Errors
/// [`RigError::Recording`] naming the recording and the row, column or field at fault.
pub fn process_recording(
    desc: &RigDescription,
    body: Option<&RigidBody>,
    rec: &RawRecording,
) -> Result<ProcessedRecording, RigError> {
    let Prepared { states, rest } = prepare(desc, rec)?;
    let n = states.len();
    let rate = desc.sampling.rate_hz;
    let raw_dt = 1.0 / rate;
    let frame = SensorFrame::new(&desc.sensor);
    let subtract = desc.subtract;
    let si = desc.sensor.si_per_unit();
    let rigid = |st: &EulerState| -> Wrench {
        match body {
            Some(b) if subtract.any() => b.loads(st, &subtract),
            _ => [0.0; 6],
        }
    };

    // 3. The tare.
    let mut report = RecordingReport {
        source_name: rec.source_name.clone(),
        n_samples: n,
        n_trajectories: 0,
        home_pose_measured: None,
        rest_motion_deg: None,
        tare_offset: [0.0; 6],
        rest_residual: None,
    };
    let n_rest = rest.as_ref().map_or(0, |r| r.n_samples);
    if let Some(rest) = &rest {
        let home_state = EulerState {
            angles_rad: desc.angles.to_flapssm(rest.home_pose),
            ..EulerState::default()
        };
        let modelled = frame.to_sensor(&rigid(&home_state));
        report.tare_offset = std::array::from_fn(|c| rest.mean_reading[c] - modelled[c] / si[c]);
        report.home_pose_measured = Some(rest.home_pose);
        report.rest_motion_deg = Some(rest.motion_deg);
    }

    // 4. Zero, units, frame, subtraction.
    let mut steps = ProcessingSteps {
        time_s: (0..n).map(|k| k as f64 * raw_dt).collect(),
        tared: Vec::with_capacity(n),
        subtracted: Vec::with_capacity(n),
        processed: Vec::with_capacity(n),
    };
    for (reading, st) in rec.sensor.iter().zip(&states) {
        let zeroed: Wrench = std::array::from_fn(|c| (reading[c] - report.tare_offset[c]) * si[c]);
        let tared = frame.to_wing(&zeroed);
        let sub = rigid(st);
        let aero: Wrench = std::array::from_fn(|c| tared[c] - sub[c]);
        steps.tared.push(dataset_channels(&tared));
        steps.subtracted.push(dataset_channels(&sub));
        steps.processed.push(dataset_channels(&aero));
    }

    // 5. The low-pass.
    if let Some(cutoff) = desc.filter.cutoff_hz {
        let sections = butterworth4(cutoff, rate);
        let pad = ((3.0 * rate / cutoff).ceil() as usize).max(12);
        let mut work = Vec::with_capacity(n + 2 * pad);
        let mut column = vec![0.0; n];
        for c in 0..OUTPUT_NAMES.len() {
            column
                .iter_mut()
                .zip(&steps.processed)
                .for_each(|(v, y)| *v = y[c]);
            filtfilt(&sections, &mut column, pad, &mut work);
            steps
                .processed
                .iter_mut()
                .zip(&column)
                .for_each(|(y, v)| y[c] = *v);
        }
    }
    if n_rest > 0 {
        report.rest_residual = Some(std::array::from_fn(|c| {
            (steps.processed[..n_rest]
                .iter()
                .map(|y| y[c] * y[c])
                .sum::<f64>()
                / n_rest as f64)
                .sqrt()
        }));
    }

    // 6. Cut and resample.
    let trajectories = cut(desc, rec, &states, &steps.processed, n_rest)?;
    report.n_trajectories = trajectories.len();
    Ok(ProcessedRecording {
        trajectories,
        report,
        steps,
    })
}

/// The tare's rest at the start of a recording.
pub(super) struct Rest {
    /// Its samples.
    pub(super) n_samples: usize,
    /// The mean sensor reading over it (sensor units).
    pub(super) mean_reading: [f64; 6],
    /// The mean pose over it, as recorded.
    pub(super) home_pose: [f64; 3],
    /// The largest distance of an angle from `tare.home_pose` during it (deg).
    pub(super) motion_deg: f64,
}

/// A recording checked (step 1), its Euler states (step 2) and its rest (checked against the
/// home pose), as both the processing and the identification ([`super::identify`]) start.
pub(super) struct Prepared {
    /// flapssm's angles, rates and accelerations of every sample.
    pub(super) states: Vec<EulerState>,
    /// The tare's rest; `None` without a tare.
    pub(super) rest: Option<Rest>,
}

/// Steps 1 and 2 and the rest of the tare.
pub(super) fn prepare(desc: &RigDescription, rec: &RawRecording) -> Result<Prepared, RigError> {
    let fail = |reason: String| RigError::recording(&rec.source_name, reason);
    check_recording(desc, rec)?;
    let n = rec.angles.len();
    let rate = desc.sampling.rate_hz;
    let raw_dt = 1.0 / rate;
    let angles = desc.angles.to_flapssm_series(&rec.angles);
    let sg = SavitzkyGolay::new(SavitzkyGolayConfig::spanning_default(raw_dt))
        .map_err(|e| fail(format!("differentiator: {e}")))?;
    if n < sg.window() {
        return Err(fail(format!(
            "{n} samples, fewer than the differentiator's window of {} ({:.2} s)",
            sg.window(),
            sg.window() as f64 * raw_dt
        )));
    }
    let mut states = vec![EulerState::default(); n];
    let mut column = vec![0.0; n];
    sg.euler_states(&angles, raw_dt, &mut states, &mut column)
        .map_err(|e| fail(format!("differentiator: {e}")))?;
    let n_rest = (desc.tare.rest_s * rate).round() as usize;
    if n_rest == 0 {
        return Ok(Prepared { states, rest: None });
    }
    if n_rest >= n {
        return Err(fail(format!(
            "tare.rest_s = {} s is {n_rest} samples, but the recording has {n}",
            desc.tare.rest_s
        )));
    }
    let (home_pose, motion_deg) = check_rest(desc, rec, n_rest)?;
    let mean_reading = std::array::from_fn(|c| {
        rec.sensor[..n_rest].iter().map(|r| r[c]).sum::<f64>() / n_rest as f64
    });
    Ok(Prepared {
        states,
        rest: Some(Rest {
            n_samples: n_rest,
            mean_reading,
            home_pose,
            motion_deg,
        }),
    })
}

/// Step 1: lengths, finite values, time.
fn check_recording(desc: &RigDescription, rec: &RawRecording) -> Result<(), RigError> {
    let fail = |reason: String| RigError::recording(&rec.source_name, reason);
    let n = rec.angles.len();
    let angle_cols = &desc.angles.columns;
    let sensor_cols = &desc.sensor.columns;
    if rec.sensor.len() != n {
        return Err(fail(format!(
            "the sensor columns have {} rows but the angle columns {n}",
            rec.sensor.len()
        )));
    }
    if n < 2 {
        return Err(fail(format!("{n} samples: nothing to process")));
    }
    for (k, row) in rec.angles.iter().enumerate() {
        if let Some(c) = row.iter().position(|v| !v.is_finite()) {
            return Err(fail(format!(
                "data row {} of column '{}' is {}",
                k + 1,
                angle_cols[c],
                row[c]
            )));
        }
    }
    for (k, row) in rec.sensor.iter().enumerate() {
        if let Some(c) = row.iter().position(|v| !v.is_finite()) {
            return Err(fail(format!(
                "data row {} of column '{}' is {}",
                k + 1,
                sensor_cols[c],
                row[c]
            )));
        }
    }
    let Some(time) = &rec.time_s else {
        return Ok(());
    };
    let name = desc.sampling.time_column.as_deref().unwrap_or("time");
    if time.len() != n {
        return Err(fail(format!(
            "time column '{name}' has {} rows but the angle columns {n}",
            time.len()
        )));
    }
    for (k, w) in time.windows(2).enumerate() {
        if w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater) {
            return Err(fail(format!(
                "time column '{name}' is not increasing at data row {}: {} after {}",
                k + 2,
                w[1],
                w[0]
            )));
        }
    }
    let rate = desc.sampling.rate_hz;
    let measured = (n - 1) as f64 / (time[n - 1] - time[0]);
    if (measured / rate - 1.0).abs() > 0.01 {
        return Err(fail(format!(
            "time column '{name}' gives {measured:.6} Hz, but sampling.rate_hz is {rate} \
             (more than 1 % apart)"
        )));
    }
    let dt = 1.0 / rate;
    if let Some(k) = time
        .windows(2)
        .position(|w| (w[1] - w[0] - dt).abs() > 0.5 * dt)
    {
        return Err(fail(format!(
            "time column '{name}' steps by {} s at data row {}, not {dt} s: a gap or a \
             repeated sample",
            time[k + 1] - time[k],
            k + 2
        )));
    }
    Ok(())
}

/// The mean recorded pose over the rest and the largest distance (deg) of any angle from the
/// home pose, checked against the tolerance.
fn check_rest(
    desc: &RigDescription,
    rec: &RawRecording,
    n_rest: usize,
) -> Result<([f64; 3], f64), RigError> {
    let to_deg = desc.angles.unit.to_rad().to_degrees();
    let home = desc.tare.home_pose;
    let mut worst = (0.0, 0);
    for row in &rec.angles[..n_rest] {
        for a in 0..3 {
            let d = (row[a] - home[a]).abs() * to_deg;
            if d > worst.0 {
                worst = (d, a);
            }
        }
    }
    if worst.0 > desc.tare.tolerance_deg {
        return Err(RigError::recording(
            &rec.source_name,
            format!(
                "during the tare's rest (the first {} s) column '{}' is {:.3}° from \
                 tare.home_pose (tolerance {}°): the wing is not at rest at its home pose",
                desc.tare.rest_s, desc.angles.columns[worst.1], worst.0, desc.tare.tolerance_deg
            ),
        ));
    }
    let mean = std::array::from_fn(|a| {
        rec.angles[..n_rest].iter().map(|r| r[a]).sum::<f64>() / n_rest as f64
    });
    Ok((mean, worst.0))
}

/// Step 6: the trajectories after the rest and the skip, from the Euler `states` and `loads` of
/// every raw sample.
pub(super) fn cut(
    desc: &RigDescription,
    rec: &RawRecording,
    states: &[EulerState],
    loads: &[[f64; 5]],
    n_rest: usize,
) -> Result<Vec<Trajectory>, RigError> {
    let fail = |reason: String| RigError::recording(&rec.source_name, reason);
    let rate = desc.sampling.rate_hz;
    let ds_dt = 1.0 / desc.sampling.dataset_rate_hz;
    let n = states.len();
    // The differentiator's edge fits are less accurate: its half window at either end is left.
    let edge = SavitzkyGolayConfig::spanning_default(1.0 / rate).half_window as f64;
    let start_s = (n_rest as f64 + (desc.trajectories.skip_s * rate).round()).max(edge) / rate;
    let end_s = ((n - 1) as f64 - edge) / rate;
    let remaining_s = end_s - start_s;
    let (pieces, piece_s, samples) = match desc.trajectories.duration_s {
        Some(d) => (
            ((remaining_s + 1e-9) / d).floor() as usize,
            d,
            ((d + 1e-9) / ds_dt).floor() as usize,
        ),
        None => (
            usize::from(remaining_s > 0.0),
            remaining_s,
            ((remaining_s + 1e-9) / ds_dt).floor() as usize + 1,
        ),
    };
    if pieces == 0 {
        return Err(fail(format!(
            "after the tare's rest and trajectories.skip_s, and before the differentiator's \
             last half window, {remaining_s:.3} s remain: no trajectory{}",
            desc.trajectories
                .duration_s
                .map(|d| format!(" of trajectories.duration_s = {d} s"))
                .unwrap_or_default()
        )));
    }
    let radius = desc.geometry().u_ref_radius_m;
    (0..pieces)
        .map(|p| {
            let t0 = start_s + p as f64 * piece_s;
            let mut euler_rad = Vec::with_capacity(samples);
            let mut inputs = Vec::with_capacity(samples);
            let mut outputs = Vec::with_capacity(samples);
            for j in 0..samples {
                let (k, w) = position((t0 + j as f64 * ds_dt) * rate, n);
                let st = lerp_state(&states[k], &states[(k + 1).min(n - 1)], w);
                euler_rad.push(st.angles_rad);
                inputs.push(WingKinematics::from_euler(&st).inputs());
                let (a, b) = (&loads[k], &loads[(k + 1).min(n - 1)]);
                outputs.push(std::array::from_fn(|c| a[c] + w * (b[c] - a[c])));
            }
            let (u_ref_m_s, _) = published_u_ref(&euler_rad, ds_dt, radius).map_err(|e| {
                fail(format!(
                    "trajectory {p} (from {t0:.3} s): U_ref needs one full stroke cycle: {e}"
                ))
            })?;
            Ok(Trajectory {
                euler_rad,
                inputs,
                outputs: Some(outputs),
                u_ref_m_s,
                family: RECORDED_FAMILY.to_string(),
            })
        })
        .collect()
}

/// The raw sample k and weight w of the raw position x (samples): x = k + w, an integer
/// position (to 1e-9) taken exactly.
fn position(x: f64, n: usize) -> (usize, f64) {
    let r = x.round();
    let x = if (x - r).abs() < 1e-9 { r } else { x };
    let k = (x.floor() as usize).min(n - 1);
    (k, (x - k as f64).clamp(0.0, 1.0))
}

fn lerp_state(a: &EulerState, b: &EulerState, w: f64) -> EulerState {
    let l = |x: &[f64; 3], y: &[f64; 3]| std::array::from_fn(|i| x[i] + w * (y[i] - x[i]));
    EulerState {
        angles_rad: l(&a.angles_rad, &b.angles_rad),
        rates_rad_s: l(&a.rates_rad_s, &b.rates_rad_s),
        accels_rad_s2: l(&a.accels_rad_s2, &b.accels_rad_s2),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rig::convention::{AngleConvention, AngleUnit};
    use crate::rig::description::{
        ForceUnit, MomentUnit, RigFluid, RigSampling, RigWing, SensorPose,
    };

    fn desc() -> RigDescription {
        RigDescription {
            name: String::new(),
            wing: RigWing {
                span_m: 0.1,
                chord_m: Some(0.03),
                root_offset_m: 0.02,
                pitch_axis_frac: Some(0.25),
                outline: None,
                u_ref_radius_m: None,
            },
            fluid: RigFluid {
                density_kg_m3: 1000.0,
                kinematic_viscosity_m2_s: 1e-6,
            },
            angles: AngleConvention::flapssm(["a".into(), "b".into(), "c".into()], AngleUnit::Rad),
            sensor: SensorPose {
                columns: ["f1", "f2", "f3", "m1", "m2", "m3"].map(String::from),
                force_unit: ForceUnit::N,
                moment_unit: MomentUnit::NMm,
                offset_m: [0.0; 3],
                rotation_deg: [0.0; 3],
                noise_sd: [0.0; 6],
                bias_sd: [0.0; 6],
            },
            sampling: RigSampling {
                rate_hz: 100.0,
                time_column: Some("t".into()),
                dataset_rate_hz: 25.0,
            },
            filter: Default::default(),
            tare: Default::default(),
            mass: None,
            reference: None,
            subtract: Default::default(),
            trajectories: Default::default(),
        }
    }

    fn recording(n: usize) -> RawRecording {
        RawRecording {
            source_name: "r.csv".into(),
            time_s: Some((0..n).map(|k| k as f64 * 0.01).collect()),
            angles: (0..n)
                .map(|k| [(k as f64 * 0.05).sin(), 0.0, 0.3])
                .collect(),
            sensor: vec![[0.0; 6]; n],
        }
    }

    fn reason(r: Result<ProcessedRecording, RigError>) -> String {
        match r {
            Err(RigError::Recording {
                source_name,
                reason,
            }) => {
                assert_eq!(source_name, "r.csv");
                reason
            }
            other => panic!("expected a recording error, got {other:?}"),
        }
    }

    /// Lengths, finite values and time stamps, each refused naming the column or row; arrays
    /// from Python reach these checks without a table reader's.
    #[test]
    fn inconsistent_recordings_are_refused_naming_what() {
        let d = desc();
        let mut r = recording(400);
        r.sensor.pop();
        assert!(reason(process_recording(&d, None, &r)).contains("sensor columns have 399 rows"));
        let mut r = recording(400);
        r.angles[7][1] = f64::NAN;
        assert!(
            reason(process_recording(&d, None, &r)).contains("data row 8 of column 'b' is NaN")
        );
        let mut r = recording(400);
        r.sensor[9][4] = f64::INFINITY;
        assert!(reason(process_recording(&d, None, &r)).contains("column 'm2' is inf"));
        let mut r = recording(400);
        r.time_s.as_mut().unwrap().truncate(300);
        assert!(reason(process_recording(&d, None, &r)).contains("time column 't' has 300 rows"));
        let mut r = recording(400);
        r.time_s.as_mut().unwrap()[200] += 0.009;
        assert!(reason(process_recording(&d, None, &r)).contains("steps by"));
        let mut long_rest = desc();
        long_rest.tare.rest_s = 5.0;
        let r = recording(400);
        assert!(
            reason(process_recording(&long_rest, None, &r))
                .contains("tare.rest_s = 5 s is 500 samples")
        );
        let r = recording(20);
        assert!(
            reason(process_recording(&d, None, &r))
                .contains("fewer than the differentiator's window")
        );
    }
}
