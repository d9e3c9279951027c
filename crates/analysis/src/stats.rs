//! Order statistics with MATLAB's definitions, and the row-major table view used throughout.
//!
//! # Percentiles (MATLAB `prctile`, default method)
//! For `n` sorted values `x₍₁₎ ≤ … ≤ x₍ₙ₎`, value `x₍ᵢ₎` is taken as the
//! `pᵢ = 100·(i − 0.5)/n` percentile. A percentile `p` between `p₁` and `pₙ` is the linear
//! interpolation between neighbouring `(pᵢ, x₍ᵢ₎)`; below `p₁` it is `x₍₁₎`, above `pₙ` it is
//! `x₍ₙ₎`. (This is Hyndman & Fan's type 5, "Hazen".) `median = prctile(x, 50)` and
//! `iqr = prctile(x, 75) − prctile(x, 25)`, as in MATLAB's `median` and `iqr`.

use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result, check_finite, param};

/// A read-only row-major table: `n_rows × n_cols` values, row `i` at `data[i*n_cols..][..n_cols]`.
/// A trajectory's outputs `Vec<[f64; 5]>` become a table with `Rows::new(v.as_flattened(), 5)`.
#[derive(Debug, Clone, Copy)]
pub struct Rows<'a> {
    data: &'a [f64],
    n_cols: usize,
}

impl<'a> Rows<'a> {
    /// Wraps `data` (length a multiple of `n_cols`, `n_cols ≥ 1`).
    ///
    /// # Errors
    /// [`AnalysisError::Shape`] if `n_cols == 0` or the length is not a multiple of `n_cols`.
    pub fn new(data: &'a [f64], n_cols: usize) -> Result<Self> {
        if n_cols == 0 || data.len() % n_cols != 0 {
            return Err(AnalysisError::Shape {
                what: "table".into(),
                expected: format!("a multiple of {n_cols} values (n_rows × {n_cols})"),
                found: format!("{} values", data.len()),
            });
        }
        Ok(Self { data, n_cols })
    }

    /// Number of rows (samples).
    pub fn n_rows(&self) -> usize {
        self.data.len() / self.n_cols
    }

    /// Number of columns (channels).
    pub fn n_cols(&self) -> usize {
        self.n_cols
    }

    /// Row `i` (length `n_cols`). Panics if `i >= n_rows` (internal use with checked indices).
    pub fn row(&self, i: usize) -> &'a [f64] {
        &self.data[i * self.n_cols..(i + 1) * self.n_cols]
    }

    /// Value at row `i`, column `j`.
    pub fn get(&self, i: usize, j: usize) -> f64 {
        self.data[i * self.n_cols + j]
    }

    /// The flat row-major values.
    pub fn as_slice(&self) -> &'a [f64] {
        self.data
    }

    /// Column `j` copied into a vector.
    pub fn column(&self, j: usize) -> Vec<f64> {
        (0..self.n_rows()).map(|i| self.get(i, j)).collect()
    }
}

/// A central interval `[lo, hi]`, e.g. the 2.5th and 97.5th percentiles of errors.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Interval {
    /// Lower bound, `prctile(x, (100 − level)/2)`.
    pub lo: f64,
    /// Upper bound, `prctile(x, 100 − (100 − level)/2)`.
    pub hi: f64,
}

/// Two-sided 95 % quantiles `t_{0.975, ν}` of Student's t for ν = 1 … 30 degrees of freedom
/// (standard tables, 3 decimals).
const STUDENT_T_975: [f64; 30] = [
    12.706, 4.303, 3.182, 2.776, 2.571, 2.447, 2.365, 2.306, 2.262, 2.228, 2.201, 2.179, 2.160,
    2.145, 2.131, 2.120, 2.110, 2.101, 2.093, 2.086, 2.080, 2.074, 2.069, 2.064, 2.060, 2.056,
    2.052, 2.048, 2.045, 2.042,
];

/// Mean of `values` and its 95 % Student-t interval `mean ± t_{0.975, n−1} s/√n` (`s` the
/// sample SD; the normal 1.96 beyond 30 degrees of freedom): the interval over a few
/// independent repeats, such as training seeds. `None` for fewer than two values.
pub fn mean_t_interval(values: &[f64]) -> Option<(f64, Interval)> {
    let n = values.len();
    if n < 2 {
        return None;
    }
    let mean = values.iter().sum::<f64>() / n as f64;
    let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1) as f64;
    let t = STUDENT_T_975.get(n - 2).copied().unwrap_or(1.96);
    let half = t * (var / n as f64).sqrt();
    Some((
        mean,
        Interval {
            lo: mean - half,
            hi: mean + half,
        },
    ))
}

/// Percentile `p` (in %, 0 ≤ p ≤ 100) of already **sorted** finite values, MATLAB definition
/// (see the module docs). Cost O(1).
///
/// # Errors
/// [`AnalysisError::Empty`] for no values, [`AnalysisError::Parameter`] for `p` outside [0, 100].
pub fn prctile_sorted(sorted: &[f64], p: f64) -> Result<f64> {
    let n = sorted.len();
    if n == 0 {
        return Err(AnalysisError::Empty {
            what: "percentile sample".into(),
        });
    }
    if !(0.0..=100.0).contains(&p) {
        return Err(param("percentile", p, "must lie in [0, 100]"));
    }
    let nf = n as f64;
    // Position in 1-based ranks: p = 100 (i − 0.5)/n  ⇔  i = n p/100 + 0.5.
    let rank = nf * p / 100.0 + 0.5;
    if rank <= 1.0 {
        return Ok(sorted[0]);
    }
    if rank >= nf {
        return Ok(sorted[n - 1]);
    }
    let i = rank.floor();
    let frac = rank - i;
    let lo = sorted[i as usize - 1];
    let hi = sorted[i as usize];
    Ok(lo + frac * (hi - lo))
}

/// Sorts a copy of `values` after checking they are finite.
pub(crate) fn sorted_copy(what: &str, values: &[f64]) -> Result<Vec<f64>> {
    check_finite(what, values)?;
    if values.is_empty() {
        return Err(AnalysisError::Empty { what: what.into() });
    }
    let mut v = values.to_vec();
    v.sort_by(f64::total_cmp);
    Ok(v)
}

/// Percentile `p` (%) of unsorted finite values, MATLAB `prctile` definition. Cost O(n log n).
///
/// # Errors
/// As [`prctile_sorted`], plus [`AnalysisError::NonFinite`].
pub fn prctile(values: &[f64], p: f64) -> Result<f64> {
    prctile_sorted(&sorted_copy("percentile sample", values)?, p)
}

/// Central `level`-% interval (e.g. 95 → 2.5th and 97.5th percentiles), as the published
/// `CIFcn = prctile(x, abs([0,100] − (100 − p)/2))`.
///
/// # Errors
/// As [`prctile`]; `level` must lie in [0, 100].
pub fn central_interval(values: &[f64], level: f64) -> Result<Interval> {
    if !(0.0..=100.0).contains(&level) {
        return Err(param("interval level", level, "must lie in [0, 100] (%)"));
    }
    let s = sorted_copy("interval sample", values)?;
    let tail = (100.0 - level) / 2.0;
    Ok(Interval {
        lo: prctile_sorted(&s, tail)?,
        hi: prctile_sorted(&s, 100.0 - tail)?,
    })
}

/// Median (MATLAB `median`, equal to `prctile(x, 50)`).
///
/// # Errors
/// As [`prctile`].
pub fn median(values: &[f64]) -> Result<f64> {
    prctile(values, 50.0)
}

/// Quartiles `(q25, q50, q75)` with MATLAB's percentile definition; `iqr = q75 − q25`.
///
/// # Errors
/// As [`prctile`].
pub fn quartiles(values: &[f64]) -> Result<(f64, f64, f64)> {
    let s = sorted_copy("quartile sample", values)?;
    Ok((
        prctile_sorted(&s, 25.0)?,
        prctile_sorted(&s, 50.0)?,
        prctile_sorted(&s, 75.0)?,
    ))
}

/// Arithmetic mean of a non-empty slice (NaN for an empty one; callers check lengths).
pub(crate) fn mean(values: &[f64]) -> f64 {
    values.iter().sum::<f64>() / values.len() as f64
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn prctile_matches_hand_computed_hazen_values() {
        // n = 4 → x(i) sits at p = 12.5, 37.5, 62.5, 87.5 %.
        let x = [4.0, 1.0, 3.0, 2.0];
        assert_eq!(prctile(&x, 0.0).unwrap(), 1.0);
        assert_eq!(prctile(&x, 2.5).unwrap(), 1.0); // below p1 → min
        assert_eq!(prctile(&x, 12.5).unwrap(), 1.0);
        assert!((prctile(&x, 30.0).unwrap() - 1.7).abs() < 1e-12); // 1 + 17.5/25
        assert!((prctile(&x, 50.0).unwrap() - 2.5).abs() < 1e-12);
        assert!((prctile(&x, 75.0).unwrap() - 3.5).abs() < 1e-12); // 3 + 12.5/25
        assert_eq!(prctile(&x, 97.5).unwrap(), 4.0); // above p4 → max
        assert_eq!(prctile(&x, 100.0).unwrap(), 4.0);
    }

    #[test]
    fn central_interval_of_1_to_100() {
        // x = 1..100: x(i) at p = i − 0.5, so prctile(p) = p + 0.5 inside [0.5, 99.5].
        let x: Vec<f64> = (1..=100).map(f64::from).collect();
        let ci = central_interval(&x, 95.0).unwrap();
        assert!((ci.lo - 3.0).abs() < 1e-12);
        assert!((ci.hi - 98.0).abs() < 1e-12);
        let (q1, q2, q3) = quartiles(&x).unwrap();
        assert!((q1 - 25.5).abs() < 1e-12 && (q2 - 50.5).abs() < 1e-12);
        assert!((q3 - 75.5).abs() < 1e-12);
    }

    #[test]
    fn odd_median_is_middle_value() {
        assert_eq!(median(&[5.0, -1.0, 2.0]).unwrap(), 2.0);
        assert_eq!(prctile(&[7.0], 2.5).unwrap(), 7.0);
    }

    #[test]
    fn bad_inputs_are_errors() {
        assert!(matches!(
            prctile(&[], 50.0),
            Err(AnalysisError::Empty { .. })
        ));
        assert!(matches!(
            prctile(&[1.0, f64::NAN], 50.0),
            Err(AnalysisError::NonFinite { index: 1, .. })
        ));
        assert!(prctile(&[1.0], 101.0).is_err());
        assert!(Rows::new(&[1.0, 2.0, 3.0], 2).is_err());
    }

    /// Two repeats: t = 12.706; the interval of {1, 3} is 2 ± 12.706 · √2/√2.
    #[test]
    fn t_interval_over_repeats() {
        let (m, i) = mean_t_interval(&[1.0, 3.0]).unwrap();
        assert_eq!(m, 2.0);
        assert!((i.hi - 2.0 - 12.706).abs() < 1e-12 && (2.0 - i.lo - 12.706).abs() < 1e-12);
        let (_, i) = mean_t_interval(&[1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
        assert!((i.hi - 3.0 - 2.776 * (2.5f64 / 5.0).sqrt()).abs() < 1e-12);
        assert!(mean_t_interval(&[1.0]).is_none());
    }
}
