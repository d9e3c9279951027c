//! Sample cross-correlation with MATLAB `crosscorr`'s definition (Box & Jenkins).
//!
//! For series `y1`, `y2` of length `T`, means `ȳ1`, `ȳ2` and population standard deviations
//! `s1 = √c₁₁(0)`, `s2 = √c₂₂(0)`:
//!
//! ```text
//! c₁₂(k) = (1/T) Σ_{t=1}^{T−k} (y1_t − ȳ1)(y2_{t+k} − ȳ2)      k ≥ 0
//! c₁₂(k) = (1/T) Σ_{t=1}^{T+k} (y2_t − ȳ2)(y1_{t−k} − ȳ1)      k < 0
//! r(k)   = c₁₂(k) / (s1 s2)
//! ```
//!
//! The divisor is `T` at every lag (not `T − k`). **Direction:** at a positive lag `k`, `y1` at
//! time `t` is paired with `y2` at `t + k`, so a peak at `k > 0` means **`y2` lags `y1`** by `k`
//! samples. The published analysis calls `crosscorr(input, state)`: positive lags = the state
//! lags the input.

use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result, check_finite, param};

/// Writes `(y − ȳ)/s` into `out` (`s` the population standard deviation).
///
/// # Errors
/// [`AnalysisError::Shape`] for unequal lengths, [`AnalysisError::Empty`],
/// [`AnalysisError::NonFinite`], [`AnalysisError::ConstantSeries`] if `s == 0`.
pub fn standardize_into(what: &str, y: &[f64], out: &mut [f64]) -> Result<()> {
    if y.len() != out.len() {
        return Err(AnalysisError::Shape {
            what: format!("{what} output buffer"),
            expected: y.len().to_string(),
            found: out.len().to_string(),
        });
    }
    if y.is_empty() {
        return Err(AnalysisError::Empty { what: what.into() });
    }
    check_finite(what, y)?;
    let n = y.len() as f64;
    let m = y.iter().sum::<f64>() / n;
    let var = y.iter().map(|v| (v - m) * (v - m)).sum::<f64>() / n;
    let s = var.sqrt();
    if s.is_nan() || s <= 1e-300 || s <= 1e-12 * m.abs() {
        return Err(AnalysisError::ConstantSeries { what: what.into() });
    }
    for (o, v) in out.iter_mut().zip(y) {
        *o = (v - m) / s;
    }
    Ok(())
}

/// `r(k)` for `k = 0..out.len()` of two **standardized** series of equal length `T`
/// (see [`standardize_into`]): `r(k) = (1/T) Σ_{t<T−k} z1_t z2_{t+k}`; lags `≥ T` give 0.
/// Allocation-free; cost O(T · out.len()).
pub fn xcf_positive_into(z1: &[f64], z2: &[f64], out: &mut [f64]) {
    let t_len = z1.len().min(z2.len());
    let inv_t = 1.0 / t_len as f64;
    for (k, o) in out.iter_mut().enumerate() {
        *o = if k >= t_len {
            0.0
        } else {
            z1[..t_len - k]
                .iter()
                .zip(&z2[k..t_len])
                .map(|(a, b)| a * b)
                .sum::<f64>()
                * inv_t
        };
    }
}

/// The full sample cross-correlation function of MATLAB `crosscorr(y1, y2, 'NumLags', L)`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CrossCorrelation {
    /// Lags `−L..=L` in samples.
    pub lags: Vec<i64>,
    /// `r(k)` at each lag.
    pub r: Vec<f64>,
}

/// Computes `crosscorr(y1, y2, 'NumLags', num_lags)` (see the module docs).
///
/// # Errors
/// [`AnalysisError::Shape`] for unequal lengths, [`AnalysisError::Parameter`] if
/// `num_lags ≥ T`, and the errors of [`standardize_into`].
pub fn crosscorr(y1: &[f64], y2: &[f64], num_lags: usize) -> Result<CrossCorrelation> {
    if y1.len() != y2.len() {
        return Err(AnalysisError::Shape {
            what: "crosscorr y2".into(),
            expected: format!("{} samples (as y1)", y1.len()),
            found: y2.len().to_string(),
        });
    }
    if num_lags >= y1.len() {
        return Err(param("num_lags", num_lags, "must be < the series length"));
    }
    let mut z1 = vec![0.0; y1.len()];
    let mut z2 = vec![0.0; y2.len()];
    standardize_into("crosscorr y1", y1, &mut z1)?;
    standardize_into("crosscorr y2", y2, &mut z2)?;
    let mut pos = vec![0.0; num_lags + 1];
    let mut neg = vec![0.0; num_lags + 1];
    xcf_positive_into(&z1, &z2, &mut pos);
    // r₁₂(−k) = r₂₁(k).
    xcf_positive_into(&z2, &z1, &mut neg);
    let lags = (-(num_lags as i64)..=num_lags as i64).collect();
    let r = neg[1..].iter().rev().chain(pos.iter()).copied().collect();
    Ok(CrossCorrelation { lags, r })
}

/// The lag of the largest `|r|` inside one stroke cycle.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PeakCorrelation {
    /// Lag in samples (> 0; the second series lags the first).
    pub lag_samples: usize,
    /// Lag as a fraction of the stroke period, `lag_samples / period_samples`.
    pub lag_cycles: f64,
    /// Signed correlation at that lag.
    pub r: f64,
}

impl PeakCorrelation {
    /// `|r|`.
    pub fn abs_r(&self) -> f64 {
        self.r.abs()
    }
}

/// Published peak search: among lags `k` with `0 < k/period_samples < max_lag_cycles` and
/// `k < xcf.len()`, the first lag of maximal `|r(k)|` (`xcf[k] = r(k)`, from
/// [`xcf_positive_into`]). `None` if no lag qualifies.
pub fn peak_within_cycle(
    xcf: &[f64],
    period_samples: f64,
    max_lag_cycles: f64,
) -> Option<PeakCorrelation> {
    let mut best: Option<PeakCorrelation> = None;
    for (k, &r) in xcf.iter().enumerate().skip(1) {
        let lag_cycles = k as f64 / period_samples;
        if lag_cycles.is_nan() || lag_cycles >= max_lag_cycles {
            break;
        }
        if best.is_none_or(|b| r.abs() > b.r.abs()) {
            best = Some(PeakCorrelation {
                lag_samples: k,
                lag_cycles,
                r,
            });
        }
    }
    best
}

#[cfg(test)]
mod tests {
    use super::*;

    fn noise(n: usize, seed: u64) -> Vec<f64> {
        // Small deterministic LCG so the unit tests need no RNG crate.
        let mut s = seed;
        (0..n)
            .map(|_| {
                s = s
                    .wrapping_mul(6364136223846793005)
                    .wrapping_add(1442695040888963407);
                ((s >> 11) as f64 / (1u64 << 53) as f64) - 0.5
            })
            .collect()
    }

    #[test]
    fn definition_by_hand() {
        // y1 = [1,2,3,4], y2 = [2,1,4,3]: means 2.5, deviations d1 = [-1.5,-.5,.5,1.5],
        // d2 = [-.5,-1.5,1.5,.5]; c(0) = (0.75+0.75+0.75+0.75)/4 = 0.75, s1 = s2 = √1.25.
        // c(1) = (d1_1 d2_2 + d1_2 d2_3 + d1_3 d2_4)/4 = (2.25 − 0.75 + 0.25)/4 = 0.4375.
        // c(−1) = (d2_1 d1_2 + d2_2 d1_3 + d2_3 d1_4)/4 = (0.25 − 0.75 + 2.25)/4 = 0.4375.
        let c = crosscorr(&[1.0, 2.0, 3.0, 4.0], &[2.0, 1.0, 4.0, 3.0], 2).unwrap();
        assert_eq!(c.lags, vec![-2, -1, 0, 1, 2]);
        assert!((c.r[2] - 0.75 / 1.25).abs() < 1e-15);
        assert!((c.r[3] - 0.4375 / 1.25).abs() < 1e-15);
        assert!((c.r[1] - 0.4375 / 1.25).abs() < 1e-15);
        // c(2) = d1_1 d2_3 + d1_2 d2_4 = −2.25 − 0.25 → −2.5/4.
        assert!((c.r[4] + 0.625 / 1.25).abs() < 1e-15);
    }

    #[test]
    fn delayed_copy_peaks_at_positive_lag_of_the_lagging_series() {
        let x = noise(400, 7);
        let delay = 6;
        // y_t = x_{t−delay}: y lags x.
        let y: Vec<f64> = (0..400)
            .map(|t| if t >= delay { x[t - delay] } else { 0.0 })
            .collect();
        let c = crosscorr(&x, &y, 20).unwrap();
        let (imax, _) =
            c.r.iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1))
                .unwrap();
        assert_eq!(c.lags[imax], delay as i64);
        assert!(c.r[imax] > 0.95);
        // Swapping the arguments mirrors the lag.
        let c2 = crosscorr(&y, &x, 20).unwrap();
        let (imax2, _) =
            c2.r.iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1))
                .unwrap();
        assert_eq!(c2.lags[imax2], -(delay as i64));
    }

    #[test]
    fn peak_search_keeps_strictly_inside_one_cycle_and_reports_sign() {
        let x = noise(500, 3);
        let delay = 9;
        let y: Vec<f64> = (0..500)
            .map(|t| if t >= delay { -x[t - delay] } else { 0.0 })
            .collect();
        let mut zx = vec![0.0; 500];
        let mut zy = vec![0.0; 500];
        standardize_into("x", &x, &mut zx).unwrap();
        standardize_into("y", &y, &mut zy).unwrap();
        let mut xcf = vec![0.0; 301];
        xcf_positive_into(&zx, &zy, &mut xcf);
        let p = peak_within_cycle(&xcf, 30.0, 1.0).unwrap();
        assert_eq!(p.lag_samples, delay);
        assert!((p.lag_cycles - 0.3).abs() < 1e-15);
        assert!(p.r < -0.95 && p.abs_r() > 0.95);
        // Period 9 samples: lag 9 is exactly one cycle and excluded.
        let p = peak_within_cycle(&xcf, 9.0, 1.0).unwrap();
        assert!(p.lag_samples < 9 && p.abs_r() < 0.3);
        assert!(peak_within_cycle(&xcf, 1.0, 1.0).is_none());
    }

    #[test]
    fn constant_series_is_an_error() {
        assert!(matches!(
            crosscorr(&[1.0; 10], &noise(10, 1), 3),
            Err(AnalysisError::ConstantSeries { .. })
        ));
    }
}
