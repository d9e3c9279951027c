//! Cycle-to-cycle control: the stroke amplitude of each cycle chosen by a receding-horizon
//! prediction of the streaming PR-SSM, corrected by the loads measured so far.
//!
//! The kinematics are a design's, with the stroke angle scaled cycle by cycle:
//! `φ(t) = r(t) s(t) g_φ(2πft)` ([`AmplitudeSchedule`]), `s` moving from cycle `k−1`'s scale to
//! cycle `k`'s by the generator's C² ramp over the first `blend_cycles` of cycle `k`, so the
//! commanded angle stays C² (rates and accelerations exact). At the end of cycle `k` the
//! controller has the plant's mean lift `L_k` of that cycle and the predictor's `L̂_k` (the
//! streaming predictor driven by the same inputs); their difference `d_k = L_k − L̂_k` is the
//! disturbance the model does not know (an output-disturbance observer, as offset-free model
//! predictive control uses). The next scale solves `L̂_{k+H}(s) + d_k = L*` by the secant
//! method, `L̂_{k+H}(s)` the mean lift of the last of `H` cycles predicted ahead from the
//! predictor's current particles with scale `s` ([`next_scale`]).

use flapssm_prssm::stream::StreamPredictor;
use flapssm_wing::kinematics::{EulerState, WingKinematics};
use flapssm_wing::stroke_loads::{mean_stroke_frame_loads, quantity, stroke_frame_loads};
use flapssm_wing::trajectories::harmonic::HarmonicKinematics;
use flapssm_wing::trajectories::ramp;

use crate::error::DesignError;

/// A design's kinematics with the stroke scaled cycle by cycle (module docs).
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct AmplitudeSchedule {
    /// The design.
    pub base: HarmonicKinematics,
    /// Scale of cycle `k` (the last one holds on).
    pub scales: Vec<f64>,
    /// Blend from one scale to the next (cycles).
    pub blend_cycles: f64,
}

impl AmplitudeSchedule {
    /// `s(t)` and its first two time derivatives.
    fn scale(&self, t_s: f64) -> (f64, f64, f64) {
        let f = self.base.frequency_hz;
        let k = (t_s * f).floor().max(0.0) as usize;
        let at = |i: usize| self.scales[i.min(self.scales.len() - 1)];
        if k == 0 {
            return (at(0), 0.0, 0.0);
        }
        let (from, to) = (at(k - 1), at(k));
        let (r, rd, rdd) = ramp(t_s - k as f64 / f, self.blend_cycles / f);
        (from + (to - from) * r, (to - from) * rd, (to - from) * rdd)
    }

    /// The Euler state at `t_s`.
    pub fn euler_state(
        &self,
        t_s: f64,
        spec: &flapssm_wing::trajectories::TrajectorySpec,
    ) -> EulerState {
        let mut st = spec.euler_state(t_s);
        let (s, sd, sdd) = self.scale(t_s);
        let phi = st.angles_rad[0];
        let phid = st.rates_rad_s[0];
        let phidd = st.accels_rad_s2[0];
        st.angles_rad[0] = s * phi;
        st.rates_rad_s[0] = sd * phi + s * phid;
        st.accels_rad_s2[0] = sdd * phi + 2.0 * sd * phid + s * phidd;
        st
    }

    /// States at `t = k·dt_s`, `k = 0..n`.
    pub fn sample(&self, dt_s: f64, n: usize) -> Vec<EulerState> {
        let spec = self.base.spec();
        (0..n)
            .map(|k| self.euler_state(k as f64 * dt_s, &spec))
            .collect()
    }
}

/// Samples of cycle `k` at period `dt_s`: `round(k/(f dt)) .. round((k+1)/(f dt))`.
pub fn cycle_samples(frequency_hz: f64, dt_s: f64, k: usize) -> std::ops::Range<usize> {
    let per = 1.0 / (frequency_hz * dt_s);
    (k as f64 * per).round() as usize..((k + 1) as f64 * per).round() as usize
}

/// Mean lift (N) of predicted or measured wing-frame loads over `states`.
pub fn mean_lift(loads: &[[f64; 5]], states: &[EulerState], sensor_radius_m: f64) -> f64 {
    mean_stroke_frame_loads(loads, states, sensor_radius_m)[quantity::LIFT]
}

/// Advances `predictor` over `states` (one sample each), returning the predicted mean lift.
///
/// # Errors
/// [`DesignError::Model`] when the predictor refuses an input.
pub fn advance(
    predictor: &mut StreamPredictor<f64>,
    states: &[EulerState],
    sensor_radius_m: f64,
) -> Result<f64, DesignError> {
    let mut sum = 0.0;
    for s in states {
        let u = WingKinematics::from_euler(s).inputs();
        let (m, _) = predictor.step(&u).map_err(|e| DesignError::Model {
            model: "prssm".into(),
            message: e.to_string(),
        })?;
        let y: [f64; 5] = m[..5].try_into().expect("5 outputs");
        sum += stroke_frame_loads(&y, s, sensor_radius_m)[quantity::LIFT];
    }
    Ok(sum / states.len().max(1) as f64)
}

/// The receding-horizon choice of cycle `k + 1`'s scale (module docs): `predictor` holds the
/// particles at the end of cycle `k`; `schedule` the scales up to cycle `k`; `horizon` cycles
/// ahead; the result within `bounds`.
///
/// # Errors
/// The predictor's errors.
#[allow(clippy::too_many_arguments)]
pub fn next_scale(
    predictor: &StreamPredictor<f64>,
    schedule: &AmplitudeSchedule,
    k: usize,
    horizon: usize,
    lift_target_n: f64,
    disturbance_n: f64,
    dt_s: f64,
    bounds: [f64; 2],
    sensor_radius_m: f64,
) -> Result<f64, DesignError> {
    let f = schedule.base.frequency_hz;
    let end = cycle_samples(f, dt_s, k + horizon).end;
    let start = cycle_samples(f, dt_s, k).end;
    let last = cycle_samples(f, dt_s, k + horizon);
    let predict = |s: f64| -> Result<f64, DesignError> {
        let mut sched = schedule.clone();
        sched.scales.truncate(k + 1);
        sched.scales.push(s);
        let states = sched.sample(dt_s, end);
        let mut p = predictor.clone();
        advance(&mut p, &states[start..last.start], sensor_radius_m)?;
        Ok(
            advance(&mut p, &states[last.clone()], sensor_radius_m)? + disturbance_n
                - lift_target_n,
        )
    };
    let s0 = schedule.scales[k.min(schedule.scales.len() - 1)];
    let (mut a, mut b) = (s0, (s0 * 1.05).clamp(bounds[0], bounds[1]));
    if (b - a).abs() < 1e-9 {
        b = s0 * 0.95;
    }
    let (mut fa, mut fb) = (predict(a)?, predict(b)?);
    for _ in 0..6 {
        if (fb - fa).abs() < 1e-12 {
            break;
        }
        let c = (b - fb * (b - a) / (fb - fa)).clamp(bounds[0], bounds[1]);
        (a, fa) = (b, fb);
        b = c;
        fb = predict(b)?;
        if fb.abs() < 1e-4 * lift_target_n.abs().max(1e-9) {
            break;
        }
    }
    Ok(if fb.abs() <= fa.abs() { b } else { a })
}
