//! Accuracy metrics of the published post-processing (`ferrorgpssm.m`, `plotter.m`).
//!
//! - Errors are `e = measured − predicted` (`Er = T − P`), in **standardized** units (each output
//!   z-scored with the training mean and std), pooled over trajectories and over samples from
//!   `start_sample` on (published: MATLAB sample 94, i.e. the first 93 samples are dropped).
//! - Per-output RMSE `√(Σe²/n)`; overall score `√(mean over all outputs and samples of e²)`.
//! - 95 % "confidence interval" = 2.5th and 97.5th percentiles of the errors
//!   ([`crate::stats::central_interval`]).
//! - Error histograms with MATLAB's `'Normalization','probability'`: bin count / total count.
//! - Load coefficients: `C_F = F / (½ ρ S U_ref²)` (F in N) and
//!   `C_M = M / (½ ρ c̄ S U_ref² · 1000)` (M in N·mm).

use serde::{Deserialize, Serialize};

use crate::cycles_avg::CycleWindow;
use crate::error::{AnalysisError, Result, check_finite, param};
use crate::stats::{Interval, Rows, central_interval};

/// Published first kept sample, 0-based (MATLAB `traj_start_ind = 94`).
pub const PUBLISHED_START_SAMPLE: usize = 93;

/// Errors `measured − predicted` of one model, pooled over trajectories, one vector per output.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PooledErrors {
    /// `errors[j]` = all errors of output `j` (trajectory-major, then time).
    pub errors: Vec<Vec<f64>>,
}

impl PooledErrors {
    /// Pools errors of standardized outputs. `measured[i]` and `predicted[i]` are trajectory
    /// `i`'s tables (`n_time × n_out`, same shapes); samples `start_sample..n_time` are kept.
    ///
    /// # Errors
    /// [`AnalysisError::Shape`] for mismatched counts/shapes or `start_sample ≥ n_time`,
    /// [`AnalysisError::Empty`] for no trajectories, [`AnalysisError::NonFinite`].
    pub fn new(measured: &[Rows<'_>], predicted: &[Rows<'_>], start_sample: usize) -> Result<Self> {
        if measured.is_empty() {
            return Err(AnalysisError::Empty {
                what: "trajectory list".into(),
            });
        }
        if measured.len() != predicted.len() {
            return Err(AnalysisError::Shape {
                what: "predicted trajectories".into(),
                expected: format!("{} (as measured)", measured.len()),
                found: predicted.len().to_string(),
            });
        }
        let n_out = measured[0].n_cols();
        let mut errors = vec![Vec::new(); n_out];
        for (i, (m, p)) in measured.iter().zip(predicted).enumerate() {
            if m.n_cols() != n_out || p.n_cols() != n_out || m.n_rows() != p.n_rows() {
                return Err(AnalysisError::Shape {
                    what: format!("trajectory {i} predicted/measured"),
                    expected: format!("{} × {n_out} for both", m.n_rows()),
                    found: format!(
                        "measured {} × {}, predicted {} × {}",
                        m.n_rows(),
                        m.n_cols(),
                        p.n_rows(),
                        p.n_cols()
                    ),
                });
            }
            if start_sample >= m.n_rows() {
                return Err(AnalysisError::Shape {
                    what: format!("trajectory {i}"),
                    expected: format!("more than start_sample = {start_sample} samples"),
                    found: format!("{} samples", m.n_rows()),
                });
            }
            check_finite(&format!("trajectory {i} measured"), m.as_slice())?;
            check_finite(&format!("trajectory {i} predicted"), p.as_slice())?;
            for t in start_sample..m.n_rows() {
                for (j, e) in errors.iter_mut().enumerate() {
                    e.push(m.get(t, j) - p.get(t, j));
                }
            }
        }
        Ok(Self { errors })
    }

    /// Per-output RMSE `√(Σ e²/n)` (standardized units). Shape `n_out`.
    pub fn rmse(&self) -> Vec<f64> {
        self.errors.iter().map(|e| rms(e)).collect()
    }

    /// Overall score `√(mean(e²))` over all outputs and samples (`ave_rmse`).
    pub fn overall_rmse(&self) -> f64 {
        let (s, n) = self.errors.iter().fold((0.0, 0usize), |(s, n), e| {
            (s + e.iter().map(|v| v * v).sum::<f64>(), n + e.len())
        });
        (s / n as f64).sqrt()
    }

    /// Per-output central `level`-% interval of the errors (published: 95).
    ///
    /// # Errors
    /// As [`central_interval`].
    pub fn intervals(&self, level: f64) -> Result<Vec<Interval>> {
        self.errors
            .iter()
            .map(|e| central_interval(e, level))
            .collect()
    }
}

/// Root mean square of a slice, `√(Σ v²/n)` (NaN for an empty slice).
pub fn rms(v: &[f64]) -> f64 {
    (v.iter().map(|x| x * x).sum::<f64>() / v.len() as f64).sqrt()
}

/// A histogram with MATLAB's `'probability'` normalization.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Histogram {
    /// Bin edges, increasing, length `n_bins + 1`.
    pub edges: Vec<f64>,
    /// Fraction of **all** samples in each bin (samples outside the edges count in the total
    /// but in no bin). Bins are `[eₖ, eₖ₊₁)`, the last one closed.
    pub probability: Vec<f64>,
}

impl Histogram {
    /// Histogram of `values` over `edges` (≥ 2 strictly increasing finite edges).
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] for bad edges, [`AnalysisError::Empty`], non-finite values.
    pub fn new(values: &[f64], edges: Vec<f64>) -> Result<Self> {
        if edges.len() < 2
            || edges
                .windows(2)
                .any(|w| w[1].partial_cmp(&w[0]) != Some(std::cmp::Ordering::Greater))
        {
            return Err(param(
                "histogram edges",
                edges.len(),
                "need ≥ 2 strictly increasing edges",
            ));
        }
        check_finite("histogram edges", &edges)?;
        check_finite("histogram values", values)?;
        if values.is_empty() {
            return Err(AnalysisError::Empty {
                what: "histogram values".into(),
            });
        }
        let n_bins = edges.len() - 1;
        let mut counts = vec![0usize; n_bins];
        let last = edges[n_bins];
        for &v in values {
            if v < edges[0] || v > last {
                continue;
            }
            // First edge strictly greater than v, minus one; v == last goes to the last bin.
            let k = edges
                .partition_point(|&e| e <= v)
                .saturating_sub(1)
                .min(n_bins - 1);
            counts[k] += 1;
        }
        let total = values.len() as f64;
        Ok(Self {
            edges,
            probability: counts.into_iter().map(|c| c as f64 / total).collect(),
        })
    }

    /// Equally spaced edges `lo, lo + step, …, hi` (MATLAB `lo:step:hi`, published
    /// `-1.1:0.01:1.1`).
    pub fn uniform_edges(lo: f64, hi: f64, step: f64) -> Vec<f64> {
        let n = ((hi - lo) / step + 1e-9).floor() as usize;
        (0..=n).map(|k| lo + k as f64 * step).collect()
    }
}

/// Reference scales that turn loads into coefficients, for one trajectory.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct CoefficientScales {
    /// Force scale `½ ρ S U_ref²` (N per unit C_F).
    pub force_n: f64,
    /// Moment scale `½ ρ c̄ S U_ref² · 1000` (N·mm per unit C_M).
    pub moment_n_mm: f64,
}

impl CoefficientScales {
    /// Scales from fluid density `rho_kg_m3`, wing area `area_m2`, mean chord `mean_chord_m`
    /// and reference speed `u_ref_m_s`.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] unless all four are finite and positive.
    pub fn new(rho_kg_m3: f64, area_m2: f64, mean_chord_m: f64, u_ref_m_s: f64) -> Result<Self> {
        for (name, v) in [
            ("rho_kg_m3", rho_kg_m3),
            ("area_m2", area_m2),
            ("mean_chord_m", mean_chord_m),
            ("u_ref_m_s", u_ref_m_s),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(param(name, v, "must be finite and > 0"));
            }
        }
        let q_s = 0.5 * rho_kg_m3 * area_m2 * u_ref_m_s * u_ref_m_s;
        Ok(Self {
            force_n: q_s,
            moment_n_mm: q_s * mean_chord_m * 1000.0,
        })
    }

    /// `[C_Fx, C_Fy, C_Mx, C_My, C_Mz]` from loads `[F_x, F_y (N), M_x, M_y, M_z (N·mm)]`.
    pub fn coefficients(&self, loads: &[f64; 5]) -> [f64; 5] {
        [
            loads[0] / self.force_n,
            loads[1] / self.force_n,
            loads[2] / self.moment_n_mm,
            loads[3] / self.moment_n_mm,
            loads[4] / self.moment_n_mm,
        ]
    }
}

/// Undoes z-scoring, `y = z·σ + μ`, for one `n_time × n_out` table into `out` (same length).
///
/// # Errors
/// [`AnalysisError::Shape`] if `mean`/`std` are not `n_out` long or `out` has the wrong length.
pub fn destandardize_into(z: Rows<'_>, mean: &[f64], std: &[f64], out: &mut [f64]) -> Result<()> {
    let n = z.n_cols();
    if mean.len() != n || std.len() != n || out.len() != z.as_slice().len() {
        return Err(AnalysisError::Shape {
            what: "destandardize mean/std/out".into(),
            expected: format!("{n}, {n}, {}", z.as_slice().len()),
            found: format!("{}, {}, {}", mean.len(), std.len(), out.len()),
        });
    }
    for (k, (o, v)) in out.iter_mut().zip(z.as_slice()).enumerate() {
        *o = v * std[k % n] + mean[k % n];
    }
    Ok(())
}

/// Loads (`n_time × 5`, N and N·mm) to coefficients (`n_time × 5`) with one trajectory's scales.
///
/// # Errors
/// [`AnalysisError::Shape`] unless the table has 5 columns.
pub fn coefficients_of(loads: Rows<'_>, scales: &CoefficientScales) -> Result<Vec<f64>> {
    if loads.n_cols() != 5 {
        return Err(AnalysisError::Shape {
            what: "loads table".into(),
            expected: "n_time × 5 [F_x, F_y, M_x, M_y, M_z]".into(),
            found: format!("{} × {}", loads.n_rows(), loads.n_cols()),
        });
    }
    let mut out = Vec::with_capacity(loads.as_slice().len());
    for i in 0..loads.n_rows() {
        let r = loads.row(i);
        out.extend_from_slice(&scales.coefficients(&[r[0], r[1], r[2], r[3], r[4]]));
    }
    Ok(out)
}

/// RMSE of `measured − predicted` in column `col` over a cycle window (published: C_Fx and C_Fy
/// over the last full cycle, `goodnessOfFit(…,'MSE')^0.5`).
///
/// # Errors
/// [`AnalysisError::Shape`] for mismatched tables or a bad column, [`AnalysisError::Window`].
pub fn window_rmse(
    measured: Rows<'_>,
    predicted: Rows<'_>,
    col: usize,
    window: CycleWindow,
) -> Result<f64> {
    if measured.n_rows() != predicted.n_rows()
        || measured.n_cols() != predicted.n_cols()
        || col >= measured.n_cols()
    {
        return Err(AnalysisError::Shape {
            what: "window RMSE tables".into(),
            expected: format!(
                "equal shapes {} × {} with column {col} inside",
                measured.n_rows(),
                measured.n_cols()
            ),
            found: format!("{} × {}", predicted.n_rows(), predicted.n_cols()),
        });
    }
    let range = window.range(measured.n_rows())?;
    let e: Vec<f64> = range
        .map(|t| measured.get(t, col) - predicted.get(t, col))
        .collect();
    check_finite("window errors", &e)?;
    Ok(rms(&e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rmse_and_overall_score_by_hand() {
        // Two trajectories, 3 samples, 2 outputs; start at sample 1 (drop sample 0).
        let m1 = [9.0, 9.0, 1.0, 2.0, 3.0, 4.0];
        let p1 = [0.0, 0.0, 0.0, 2.0, 3.0, 0.0];
        let m2 = [9.0, 9.0, 0.0, 0.0, 0.0, 0.0];
        let p2 = [0.0, 0.0, 1.0, 0.0, 0.0, 3.0];
        let e = PooledErrors::new(
            &[Rows::new(&m1, 2).unwrap(), Rows::new(&m2, 2).unwrap()],
            &[Rows::new(&p1, 2).unwrap(), Rows::new(&p2, 2).unwrap()],
            1,
        )
        .unwrap();
        assert_eq!(e.errors[0], vec![1.0, 0.0, -1.0, 0.0]);
        assert_eq!(e.errors[1], vec![0.0, 4.0, 0.0, -3.0]);
        let r = e.rmse();
        assert!((r[0] - (2.0f64 / 4.0).sqrt()).abs() < 1e-15);
        assert!((r[1] - (25.0f64 / 4.0).sqrt()).abs() < 1e-15);
        assert!((e.overall_rmse() - (27.0f64 / 8.0).sqrt()).abs() < 1e-15);
    }

    #[test]
    fn coefficient_scales_by_hand() {
        // ρ = 800, S = 0.0108, c̄ = 0.06, U = 0.5: ½·800·0.0108·0.25 = 1.08 N; ×0.06×1000 = 64.8.
        let s = CoefficientScales::new(800.0, 0.0108, 0.06, 0.5).unwrap();
        assert!((s.force_n - 1.08).abs() < 1e-12);
        assert!((s.moment_n_mm - 64.8).abs() < 1e-9);
        let c = s.coefficients(&[2.16, -1.08, 64.8, 129.6, -32.4]);
        for (a, b) in c.iter().zip([2.0, -1.0, 1.0, 2.0, -0.5]) {
            assert!((a - b).abs() < 1e-12);
        }
        assert!(CoefficientScales::new(800.0, 0.0108, 0.06, 0.0).is_err());
    }

    #[test]
    fn histogram_probability_counts_outliers_in_total() {
        let h = Histogram::new(&[-0.5, 0.0, 0.25, 1.0, 5.0], vec![-1.0, 0.0, 1.0]).unwrap();
        // [-1,0): -0.5; [0,1]: 0, 0.25, 1.0 (last bin closed); 5.0 outside; total 5.
        assert_eq!(h.probability, vec![0.2, 0.6]);
        let e = Histogram::uniform_edges(-1.1, 1.1, 0.01);
        assert_eq!(e.len(), 221);
        assert!((e[220] - 1.1).abs() < 1e-12);
    }

    #[test]
    fn destandardize_by_hand() {
        let z = [1.0, -1.0, 0.0, 2.0];
        let mut out = [0.0; 4];
        destandardize_into(
            Rows::new(&z, 2).unwrap(),
            &[10.0, 0.0],
            &[2.0, 3.0],
            &mut out,
        )
        .unwrap();
        assert_eq!(out, [12.0, -3.0, 10.0, 6.0]);
    }

    #[test]
    fn window_rmse_uses_inclusive_window() {
        // Window start 1, duration 2 → samples 1, 2, 3.
        let m = [0.0, 1.0, 1.0, 1.0, 100.0];
        let p = [50.0, 0.0, 1.0, 3.0, 0.0];
        let w = CycleWindow {
            start: 1,
            duration: 2,
        };
        let r = window_rmse(Rows::new(&m, 1).unwrap(), Rows::new(&p, 1).unwrap(), 0, w).unwrap();
        assert!((r - (5.0f64 / 3.0).sqrt()).abs() < 1e-15);
    }
}
