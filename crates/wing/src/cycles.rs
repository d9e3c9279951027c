//! Stroke cycles: stroke reversals, half-stroke and full-cycle windows, and the reference speed
//! U_ref exactly as the published post-processing computes it (`fplotter.m`).
//!
//! A stroke reversal is a zero crossing of the stroke rate φ̇. To be robust to noise, a crossing
//! only counts once φ̇ has gone beyond ∓`hysteresis_rad_s` after being beyond ±`hysteresis_rad_s`;
//! the reversal time is the mean of the first and last linearly interpolated zero crossings
//! inside that excursion (they coincide for clean data).

use thiserror::Error;

/// Radius used for U_ref in the published code (m): the wing-tip radius from the stroke axis.
pub const U_REF_RADIUS_M: f64 = 0.235;

/// Errors of the cycle analysis.
#[derive(Debug, Clone, PartialEq, Error)]
#[non_exhaustive]
pub enum CycleError {
    /// Too few samples.
    #[error("stroke signal has {n_samples} samples, need at least {min}")]
    TooShort {
        /// Number of samples given.
        n_samples: usize,
        /// Minimum needed.
        min: usize,
    },
    /// A sample is NaN or infinite.
    #[error("stroke signal sample {index} is not finite")]
    NonFinite {
        /// Sample index.
        index: usize,
    },
    /// The final stroke value is not crossed twice earlier, so no period can be found.
    #[error(
        "no stroke period found: the final stroke value is crossed {crossings} time(s) before the end (need 2)"
    )]
    NoPeriod {
        /// Number of earlier crossings found.
        crossings: usize,
    },
    /// The period is too long for a 5/4-cycle window before the end.
    #[error("stroke period of {duration} samples is too long for {n_samples} samples")]
    PeriodTooLong {
        /// Period in samples.
        duration: usize,
        /// Number of samples.
        n_samples: usize,
    },
    /// A parameter is out of range.
    #[error("invalid parameter {name} = {value}")]
    InvalidParameter {
        /// Parameter name.
        name: &'static str,
        /// Its value.
        value: f64,
    },
}

/// Direction of a half-stroke: the sign of φ̇.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum StrokeDirection {
    /// φ̇ > 0.
    Positive,
    /// φ̇ < 0.
    Negative,
}

/// A stroke reversal.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reversal {
    /// Time of the zero crossing of φ̇ (s), from sample 0.
    pub time_s: f64,
    /// Direction of the half-stroke that starts here.
    pub next: StrokeDirection,
}

/// A half-stroke window between two consecutive reversals.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct HalfStroke {
    /// Start (s).
    pub start_s: f64,
    /// End (s).
    pub end_s: f64,
    /// Sign of φ̇ during the half-stroke.
    pub direction: StrokeDirection,
}

impl HalfStroke {
    /// Mid-point time (s).
    pub fn mid_s(&self) -> f64 {
        0.5 * (self.start_s + self.end_s)
    }
}

/// Stroke reversals of a sampled stroke rate φ̇ (rad/s) with period `dt_s`, using a hysteresis
/// band ±`hysteresis_rad_s` (≥ 0). Cost O(n).
pub fn stroke_reversals(
    phi_dot_rad_s: &[f64],
    dt_s: f64,
    hysteresis_rad_s: f64,
) -> Result<Vec<Reversal>, CycleError> {
    if !(dt_s > 0.0 && dt_s.is_finite()) {
        return Err(CycleError::InvalidParameter {
            name: "dt_s",
            value: dt_s,
        });
    }
    if !(hysteresis_rad_s >= 0.0 && hysteresis_rad_s.is_finite()) {
        return Err(CycleError::InvalidParameter {
            name: "hysteresis_rad_s",
            value: hysteresis_rad_s,
        });
    }
    if let Some(index) = phi_dot_rad_s.iter().position(|x| !x.is_finite()) {
        return Err(CycleError::NonFinite { index });
    }
    let mut out = Vec::new();
    let mut state: Option<StrokeDirection> = None;
    // Last sample firmly on the current side of the band.
    let mut anchor = 0;
    for (i, &w) in phi_dot_rad_s.iter().enumerate() {
        let side = if w > hysteresis_rad_s {
            Some(StrokeDirection::Positive)
        } else if w < -hysteresis_rad_s {
            Some(StrokeDirection::Negative)
        } else {
            None
        };
        match (state, side) {
            (_, None) => {}
            (None, Some(s)) => {
                state = Some(s);
                anchor = i;
            }
            (Some(cur), Some(s)) if cur == s => anchor = i,
            (Some(_), Some(s)) => {
                let (mut first, mut last) = (f64::NAN, f64::NAN);
                for j in anchor..i {
                    let (a, b) = (phi_dot_rad_s[j], phi_dot_rad_s[j + 1]);
                    let crosses = match s {
                        StrokeDirection::Negative => a >= 0.0 && b < 0.0,
                        StrokeDirection::Positive => a <= 0.0 && b > 0.0,
                    };
                    if crosses {
                        let t = (j as f64 + a / (a - b)) * dt_s;
                        if first.is_nan() {
                            first = t;
                        }
                        last = t;
                    }
                }
                out.push(Reversal {
                    time_s: 0.5 * (first + last),
                    next: s,
                });
                state = Some(s);
                anchor = i;
            }
        }
    }
    Ok(out)
}

/// Half-strokes between consecutive reversals.
pub fn half_strokes(reversals: &[Reversal]) -> Vec<HalfStroke> {
    reversals
        .windows(2)
        .map(|w| HalfStroke {
            start_s: w[0].time_s,
            end_s: w[1].time_s,
            direction: w[0].next,
        })
        .collect()
}

/// Full cycles (start, end) in seconds: from each reversal to the next reversal of the same
/// kind (two reversals later).
pub fn full_cycles(reversals: &[Reversal]) -> Vec<(f64, f64)> {
    reversals
        .windows(3)
        .map(|w| (w[0].time_s, w[2].time_s))
        .collect()
}

/// The one-cycle window of the published post-processing, as 0-based sample indices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct PublishedWindow {
    /// Period in samples (`duration`).
    pub duration: usize,
    /// First sample of the window (0-based; MATLAB `first_str_rev − 1`).
    pub first: usize,
    /// Last sample of the window, inclusive (`first + duration`).
    pub last: usize,
}

/// The published one-cycle window (`fplotter.m`) of a sampled stroke angle φ (rad):
///
/// 1. δ = φ\[N−1\] − φ\[N−2\]; among samples 0..N−10, the last 10 with |φ\[i\] − φ\[N−1\]| < |δ|;
///    keep the last index of each run of consecutive indices; `ind` is the second-to-last of
///    those (the previous crossing of the final value in the same direction);
/// 2. `duration = N − ind` (1-based `ind`), `first = floor(N − 5·duration/4)` (1-based),
///    window `first ..= first + duration`.
///
/// Deviation from the MATLAB code: it compares with the signed δ, which finds nothing when the
/// stroke ends moving towards negative φ; here |δ| is used.
pub fn published_window(stroke_rad: &[f64]) -> Result<PublishedWindow, CycleError> {
    let n = stroke_rad.len();
    if n < 12 {
        return Err(CycleError::TooShort {
            n_samples: n,
            min: 12,
        });
    }
    if let Some(index) = stroke_rad.iter().position(|x| !x.is_finite()) {
        return Err(CycleError::NonFinite { index });
    }
    let end = stroke_rad[n - 1];
    let delta = (end - stroke_rad[n - 2]).abs();
    let mut found: Vec<usize> = (0..n - 10)
        .rev()
        .filter(|&i| (stroke_rad[i] - end).abs() < delta)
        .take(10)
        .collect();
    found.reverse();
    let run_ends: Vec<usize> = (0..found.len())
        .filter(|&k| k + 1 == found.len() || found[k + 1] - found[k] != 1)
        .map(|k| found[k])
        .collect();
    if run_ends.len() < 2 {
        return Err(CycleError::NoPeriod {
            crossings: run_ends.len(),
        });
    }
    let ind_1based = run_ends[run_ends.len() - 2] + 1;
    let duration = n - ind_1based;
    let first_1based = (n as f64 - 5.0 * duration as f64 / 4.0).floor();
    if first_1based < 1.0 || duration < 2 {
        return Err(CycleError::PeriodTooLong {
            duration,
            n_samples: n,
        });
    }
    let first = first_1based as usize - 1;
    Ok(PublishedWindow {
        duration,
        first,
        last: first + duration,
    })
}

/// U_ref (m/s) exactly as published: over the [`published_window`] of the stroke angle,
/// v = diff(pos)/T_s, distance = trapz(R·sqrt(φ̇² + ψ̇²)) (T_s spacing),
/// U_ref = distance / (T_s · duration). `euler_rad` rows are [φ, ψ, α] sampled every `dt_s`;
/// `radius_m` is R (published: [`U_REF_RADIUS_M`]). Returns the value and the window.
pub fn published_u_ref(
    euler_rad: &[[f64; 3]],
    dt_s: f64,
    radius_m: f64,
) -> Result<(f64, PublishedWindow), CycleError> {
    if !(dt_s > 0.0 && dt_s.is_finite()) {
        return Err(CycleError::InvalidParameter {
            name: "dt_s",
            value: dt_s,
        });
    }
    if !(radius_m > 0.0 && radius_m.is_finite()) {
        return Err(CycleError::InvalidParameter {
            name: "radius_m",
            value: radius_m,
        });
    }
    if let Some(index) = euler_rad
        .iter()
        .position(|r| !(r[0].is_finite() && r[1].is_finite()))
    {
        return Err(CycleError::NonFinite { index });
    }
    let stroke: Vec<f64> = euler_rad.iter().map(|r| r[0]).collect();
    let w = published_window(&stroke)?;
    let pos = &euler_rad[w.first..=w.last];
    let speed = |k: usize| {
        let d_phi = (pos[k + 1][0] - pos[k][0]) / dt_s;
        let d_psi = (pos[k + 1][1] - pos[k][1]) / dt_s;
        radius_m * d_phi.hypot(d_psi)
    };
    let distance: f64 = (0..w.duration - 1)
        .map(|k| 0.5 * (speed(k) + speed(k + 1)) * dt_s)
        .sum();
    Ok((distance / (dt_s * w.duration as f64), w))
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::Rng;
    use rand::SeedableRng;
    use std::f64::consts::PI;

    #[test]
    fn reversal_times_of_a_sinusoid() {
        let (amp, f, dt) = (1.2, 0.3, 0.004);
        let phi_dot: Vec<f64> = (0..5000)
            .map(|i| amp * 2.0 * PI * f * (2.0 * PI * f * i as f64 * dt).cos())
            .collect();
        let rev = stroke_reversals(&phi_dot, dt, 0.05).unwrap();
        // φ = A sin 2πft has φ̇ = 0 at t = (1/4 + k/2)/f; 20 s → 12 reversals.
        assert_eq!(rev.len(), 12);
        for (k, r) in rev.iter().enumerate() {
            let expect = (0.25 + 0.5 * k as f64) / f;
            assert!(
                (r.time_s - expect).abs() < 1e-5,
                "reversal {k}: {} vs {expect}",
                r.time_s
            );
            let want = if k % 2 == 0 {
                StrokeDirection::Negative
            } else {
                StrokeDirection::Positive
            };
            assert_eq!(r.next, want);
        }
        let halves = half_strokes(&rev);
        assert_eq!(halves.len(), 11);
        assert!((halves[0].mid_s() - 0.5 / f).abs() < 1e-5);
        let cycles = full_cycles(&rev);
        assert!(cycles.iter().all(|(a, b)| (b - a - 1.0 / f).abs() < 1e-5));
    }

    #[test]
    fn hysteresis_rejects_noise_chatter() {
        let (f, dt) = (0.25, 0.004);
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let phi_dot: Vec<f64> = (0..4000)
            .map(|i| (2.0 * PI * f * i as f64 * dt).cos() + rng.random_range(-0.02..0.02))
            .collect();
        assert!(
            stroke_reversals(&phi_dot, dt, 0.0).unwrap().len() > 8,
            "noise should chatter without hysteresis"
        );
        let rev = stroke_reversals(&phi_dot, dt, 0.1).unwrap();
        assert_eq!(rev.len(), 8);
        for (k, r) in rev.iter().enumerate() {
            let expect = (0.25 + 0.5 * k as f64) / f;
            assert!(
                (r.time_s - expect).abs() < 0.02,
                "reversal {k}: {} vs {expect}",
                r.time_s
            );
        }
    }

    #[test]
    fn u_ref_of_pure_sinusoidal_stroke() {
        // φ = Φ sin 2πft: mean tip speed = 4ΦfR; 25 Hz, 470 samples as in the dataset.
        for &(amp, f) in &[(1.4_f64, 0.25_f64), (0.9, 0.31), (1.6, 0.37)] {
            let dt = 0.04;
            let euler: Vec<[f64; 3]> = (0..470)
                .map(|i| [amp * (2.0 * PI * f * i as f64 * dt).sin(), 0.0, 0.3])
                .collect();
            let (u_ref, w) = published_u_ref(&euler, dt, U_REF_RADIUS_M).unwrap();
            let period = 1.0 / (f * dt);
            assert!(
                (w.duration as f64 - period).abs() <= 1.0,
                "duration {} vs {period}",
                w.duration
            );
            let expect = 4.0 * amp * f * U_REF_RADIUS_M;
            assert!(
                (u_ref / expect - 1.0).abs() < 0.03,
                "U_ref {u_ref} vs {expect}"
            );
            assert_eq!(w.last, w.first + w.duration);
            assert!(w.last < 470);
        }
    }

    #[test]
    fn u_ref_with_deviation_matches_quadrature() {
        let (amp, dev, f, dt) = (1.3_f64, 0.4_f64, 0.25_f64, 0.04);
        let euler: Vec<[f64; 3]> = (0..470)
            .map(|i| {
                let x = 2.0 * PI * f * i as f64 * dt;
                [amp * x.sin(), dev * (2.0 * x).sin(), 0.0]
            })
            .collect();
        let (u_ref, _) = published_u_ref(&euler, dt, U_REF_RADIUS_M).unwrap();
        // Cycle mean of R·sqrt(φ̇² + ψ̇²), midpoint rule on 10^5 points.
        let m = 100_000;
        let w = 2.0 * PI * f;
        let mean: f64 = (0..m)
            .map(|k| {
                let x = 2.0 * PI * (k as f64 + 0.5) / m as f64;
                U_REF_RADIUS_M * (amp * w * x.cos()).hypot(2.0 * dev * w * (2.0 * x).cos())
            })
            .sum::<f64>()
            / m as f64;
        assert!((u_ref / mean - 1.0).abs() < 0.03, "{u_ref} vs {mean}");
    }

    #[test]
    fn bad_signals_are_errors() {
        assert!(matches!(
            published_window(&[0.0; 5]),
            Err(CycleError::TooShort { .. })
        ));
        let mut s: Vec<f64> = (0..100).map(|i| (i as f64 * 0.1).sin()).collect();
        s[40] = f64::NAN;
        assert_eq!(
            published_window(&s),
            Err(CycleError::NonFinite { index: 40 })
        );
        let ramp: Vec<f64> = (0..100).map(|i| i as f64).collect();
        assert!(matches!(
            published_window(&ramp),
            Err(CycleError::NoPeriod { .. })
        ));
        assert!(stroke_reversals(&[1.0, -1.0], 0.0, 0.1).is_err());
    }
}
