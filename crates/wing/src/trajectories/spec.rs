//! One trajectory as an analytic function of time: periodic angles under a C² ramp-in, sampled
//! exactly (angles, rates, accelerations).

use std::f64::consts::PI;

use serde::{Deserialize, Serialize};

use super::{Family, FourierSeries, SamplingConfig};
use crate::kinematics::EulerState;

/// One trajectory: an analytic function of time.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct TrajectorySpec {
    /// Family of the tip path.
    pub family: Family,
    /// Flapping frequency f (Hz).
    pub frequency_hz: f64,
    /// Ramp-in duration T_ramp (s).
    pub ramp_s: f64,
    /// Phase x₀ (rad) in x = 2πft + x₀, chosen so that the last dataset sample falls at x ≡ 0
    /// (mid-stroke, φ̇ > 0), where the published post-processing expects it: its U_ref window
    /// then starts at a stroke reversal.
    pub phase_rad: f64,
    /// Periodic parts g of [φ, ψ, α] as functions of x = 2πft + x₀ (rad).
    pub angles: [FourierSeries; 3],
    /// Target signed AoA at the pitch plateau centres of the φ̇ > 0 and φ̇ < 0 half-strokes (rad).
    pub aoa_targets_rad: [f64; 2],
}

impl TrajectorySpec {
    /// Exact Euler angles, rates and accelerations at time `t_s` (s).
    pub fn euler_state(&self, t_s: f64) -> EulerState {
        let w = 2.0 * PI * self.frequency_hz;
        let x = w * t_s + self.phase_rad;
        let (r, r_d, r_dd) = ramp(t_s, self.ramp_s);
        let mut st = EulerState::default();
        for (i, g) in self.angles.iter().enumerate() {
            let [g0, g1, g2] = g.eval(x);
            let (g_d, g_dd) = (w * g1, w * w * g2);
            st.angles_rad[i] = r * g0;
            st.rates_rad_s[i] = r_d * g0 + r * g_d;
            st.accels_rad_s2[i] = r_dd * g0 + 2.0 * r_d * g_d + r * g_dd;
        }
        st
    }

    /// Samples `out.len()` states at t = k·`dt_s`, k = 0, 1, …. Allocates nothing.
    pub fn sample_into(&self, dt_s: f64, out: &mut [EulerState]) {
        for (k, st) in out.iter_mut().enumerate() {
            *st = self.euler_state(k as f64 * dt_s);
        }
    }

    /// Samples at the raw rate of `cfg` (default 250 Hz, 4700 samples).
    pub fn sample_raw(&self, cfg: &SamplingConfig) -> Vec<EulerState> {
        let mut out = vec![EulerState::default(); cfg.n_raw()];
        self.sample_into(cfg.raw_dt_s(), &mut out);
        out
    }

    /// Samples at the dataset rate of `cfg` (every `decimation`-th raw sample; default 25 Hz,
    /// 470 samples). Identical to decimating [`Self::sample_raw`].
    pub fn sample_dataset(&self, cfg: &SamplingConfig) -> Vec<EulerState> {
        let mut out = vec![EulerState::default(); cfg.n_samples];
        self.sample_into(cfg.dataset_dt_s(), &mut out);
        out
    }
}

/// C² ramp r(t) = 10s³ − 15s⁴ + 6s⁵ (s = t/T clamped to [0, 1]) and its derivatives.
pub fn ramp(t_s: f64, ramp_s: f64) -> (f64, f64, f64) {
    if t_s >= ramp_s {
        return (1.0, 0.0, 0.0);
    }
    if t_s <= 0.0 {
        return (0.0, 0.0, 0.0);
    }
    let s = t_s / ramp_s;
    let s2 = s * s;
    (
        s2 * s * (10.0 - 15.0 * s + 6.0 * s2),
        30.0 * s2 * (1.0 - s) * (1.0 - s) / ramp_s,
        60.0 * s * (1.0 - s) * (1.0 - 2.0 * s) / (ramp_s * ramp_s),
    )
}
