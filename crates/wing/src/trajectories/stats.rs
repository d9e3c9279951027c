//! Per-trajectory statistics of Euler angles at the dataset rate, to set a trajectory set beside
//! another (the generator's beside the paper's measured one).
//!
//! Every statistic is taken over the published evaluation window, samples 93.. (MATLAB 94..:
//! past the ramp-in of a generated trajectory):
//!
//! | statistic | definition |
//! |---|---|
//! | stroke frequency (Hz) | crossings of the stroke's mid-value (max + min)/2 in either direction, linearly interpolated: (n − 1) half-periods over t_last − t_first, f = (n − 1) / (2(t_last − t_first)); defined from half a cycle on, so a trajectory of under two cycles in the window (38 % of the measured set, f < 0.13 Hz) is not left out |
//! | stroke, deviation half-amplitude (°) | (max − min)/2 of φ, ψ |
//! | pitch half-range (°) | (max − min)/2 of α |
//! | mean pitch (°) | mean of α over whole cycles (first to last upward crossing; the window without two) |
//! | max pitch rate (°/s) | max \|α_{i+1} − α_i\| / Δt |
//! | pitch–stroke-rate correlation | Pearson r of α and the central difference of φ (the pitch's phase: −1 for α opposite to φ̇, the leading edge leading in hovering) |
//! | U_ref (m/s) | the published recipe ([`crate::cycles::published_u_ref`], R = 0.235 m) |

use crate::cycles::{self, U_REF_RADIUS_M};

/// First sample of the window (0-based; MATLAB sample 94).
pub const STATS_START_SAMPLE: usize = 93;

/// Names of the statistics, in the order of [`TrajectoryStats::values`].
pub const STAT_NAMES: [&str; 8] = [
    "stroke frequency (Hz)",
    "stroke half-amplitude (deg)",
    "deviation half-amplitude (deg)",
    "pitch half-range (deg)",
    "mean pitch (deg)",
    "max pitch rate (deg/s)",
    "corr(pitch, stroke rate)",
    "U_ref (m/s)",
];

/// Statistics of one trajectory (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TrajectoryStats {
    /// Stroke frequency (Hz); NaN with fewer than two mid-value crossings in the window.
    pub stroke_frequency_hz: f64,
    /// Stroke half-amplitude (deg).
    pub stroke_half_amplitude_deg: f64,
    /// Deviation half-amplitude (deg).
    pub deviation_half_amplitude_deg: f64,
    /// Pitch half-range (deg).
    pub pitch_half_range_deg: f64,
    /// Mean pitch (deg).
    pub mean_pitch_deg: f64,
    /// Largest |pitch rate| between samples (deg/s).
    pub max_pitch_rate_deg_s: f64,
    /// Pearson correlation of α with φ̇ (NaN for a constant pitch).
    pub pitch_stroke_rate_corr: f64,
    /// U_ref by the published recipe (m/s); NaN where it cannot be computed.
    pub u_ref_m_s: f64,
}

impl TrajectoryStats {
    /// Statistics of the rows [φ, ψ, α] (rad) sampled every `dt_s`; `None` for rows that do not
    /// reach past the window's start.
    pub fn of(euler_rad: &[[f64; 3]], dt_s: f64) -> Option<Self> {
        let w = euler_rad
            .get(STATS_START_SAMPLE..)
            .filter(|w| w.len() >= 2)?;
        let range = |k: usize| {
            w.iter()
                .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), r| {
                    (lo.min(r[k]), hi.max(r[k]))
                })
        };
        let half = |k: usize| {
            let (lo, hi) = range(k);
            0.5 * (hi - lo).to_degrees()
        };
        let (lo, hi) = range(0);
        let mid = 0.5 * (lo + hi);
        // Times of the crossings of `mid` (upward only, or in either direction).
        let crossings_of = |upward_only: bool| -> Vec<f64> {
            w.windows(2)
                .enumerate()
                .filter(|(_, p)| {
                    (p[0][0] < mid && p[1][0] >= mid)
                        || (!upward_only && p[0][0] >= mid && p[1][0] < mid)
                })
                .map(|(i, p)| (i as f64 + (mid - p[0][0]) / (p[1][0] - p[0][0])) * dt_s)
                .collect()
        };
        let half_periods = crossings_of(false);
        let stroke_frequency_hz = match half_periods.as_slice() {
            [first, .., last] => (half_periods.len() - 1) as f64 / (2.0 * (last - first)),
            _ => f64::NAN,
        };
        let crossings = crossings_of(true);
        let u_ref_m_s = cycles::published_u_ref(euler_rad, dt_s, U_REF_RADIUS_M)
            .map(|(u, _)| u)
            .unwrap_or(f64::NAN);
        Some(Self {
            stroke_frequency_hz,
            stroke_half_amplitude_deg: half(0),
            deviation_half_amplitude_deg: half(1),
            pitch_half_range_deg: half(2),
            mean_pitch_deg: mean_pitch_deg(w, &crossings, dt_s),
            max_pitch_rate_deg_s: w
                .windows(2)
                .map(|p| (p[1][2] - p[0][2]).abs().to_degrees() / dt_s)
                .fold(0.0, f64::max),
            pitch_stroke_rate_corr: pitch_stroke_rate_corr(w),
            u_ref_m_s,
        })
    }

    /// The statistics in the order of [`STAT_NAMES`].
    pub fn values(&self) -> [f64; 8] {
        [
            self.stroke_frequency_hz,
            self.stroke_half_amplitude_deg,
            self.deviation_half_amplitude_deg,
            self.pitch_half_range_deg,
            self.mean_pitch_deg,
            self.max_pitch_rate_deg_s,
            self.pitch_stroke_rate_corr,
            self.u_ref_m_s,
        ]
    }
}

/// Mean of α (deg) over the samples between the first and last crossing time (whole cycles).
fn mean_pitch_deg(w: &[[f64; 3]], crossings: &[f64], dt_s: f64) -> f64 {
    let cycles = match crossings {
        [first, .., last] => &w[(first / dt_s).ceil() as usize..=(last / dt_s).floor() as usize],
        _ => w,
    };
    (cycles.iter().map(|r| r[2]).sum::<f64>() / cycles.len() as f64).to_degrees()
}

/// Pearson r of α_i and (φ_{i+1} − φ_{i−1}) over the interior samples.
fn pitch_stroke_rate_corr(w: &[[f64; 3]]) -> f64 {
    let (pitch, stroke_rate): (Vec<f64>, Vec<f64>) =
        w.windows(3).map(|p| (p[1][2], p[2][0] - p[0][0])).unzip();
    pearson(&pitch, &stroke_rate)
}

/// Pearson correlation of `a` and `b` (equal lengths; NaN when either is constant).
pub fn pearson(a: &[f64], b: &[f64]) -> f64 {
    let n = a.len() as f64;
    let (ma, mb) = (a.iter().sum::<f64>() / n, b.iter().sum::<f64>() / n);
    let (mut sab, mut saa, mut sbb) = (0.0, 0.0, 0.0);
    for (x, y) in a.iter().zip(b) {
        sab += (x - ma) * (y - mb);
        saa += (x - ma) * (x - ma);
        sbb += (y - mb) * (y - mb);
    }
    sab / (saa * sbb).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_harmonic_motion_gives_its_frequency_amplitudes_and_offset() {
        let (f, dt) = (0.16, 0.04);
        let rows: Vec<[f64; 3]> = (0..470)
            .map(|i| {
                let x = std::f64::consts::TAU * f * i as f64 * dt;
                [1.0 * x.sin(), 0.1 * (2.0 * x).cos(), 0.2 + 0.7 * x.cos()]
            })
            .collect();
        let s = TrajectoryStats::of(&rows, dt).unwrap();
        assert!((s.stroke_frequency_hz - f).abs() < 1e-3, "{s:?}");
        // Under two cycles in the window (f = 0.11 Hz over 377 samples of 0.04 s: one upward
        // crossing) the frequency still comes from the half-periods.
        let slow: Vec<[f64; 3]> = (0..470)
            .map(|i| {
                [
                    (std::f64::consts::TAU * 0.11 * i as f64 * dt - 1.0).sin(),
                    0.0,
                    0.0,
                ]
            })
            .collect();
        let s_slow = TrajectoryStats::of(&slow, dt).unwrap();
        assert!(
            (s_slow.stroke_frequency_hz - 0.11).abs() < 1e-3,
            "{s_slow:?}"
        );
        assert!((s.stroke_half_amplitude_deg - 1f64.to_degrees()).abs() < 0.1);
        assert!((s.deviation_half_amplitude_deg - 0.1f64.to_degrees()).abs() < 0.1);
        assert!((s.pitch_half_range_deg - 0.7f64.to_degrees()).abs() < 0.1);
        assert!((s.mean_pitch_deg - 0.2f64.to_degrees()).abs() < 1.0);
        // α = 0.2 + 0.7 cos x: in phase with φ̇ ∝ cos x, peak rate 0.7·2πf.
        assert!(s.pitch_stroke_rate_corr > 0.99, "{s:?}");
        let peak = (0.7 * std::f64::consts::TAU * f).to_degrees();
        assert!((s.max_pitch_rate_deg_s - peak).abs() < 0.01 * peak, "{s:?}");
        // U_ref ≈ mean |dφ/dt|·R (ψ at twice the frequency adds a little).
        let plain = 4.0 * f * U_REF_RADIUS_M;
        assert!(s.u_ref_m_s > plain && s.u_ref_m_s < 1.2 * plain, "{s:?}");
        assert!(TrajectoryStats::of(&rows[..94], dt).is_none());
    }
}
