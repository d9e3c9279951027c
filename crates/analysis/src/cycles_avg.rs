//! Stroke-cycle windows and half-stroke cycle averages (published `fplotter.m`).
//!
//! The published analysis takes, per trajectory, a one-cycle window of `duration + 1` samples
//! (MATLAB `first_str_rev:third_str_rev`, both ends included) and averages the load
//! coefficients over two half strokes. In MATLAB's 1-based window indices, with
//! `h = floor(duration/2)`:
//! - "up" half stroke: rows `1:h` → 0-based window rows `0..h` (h rows);
//! - "down" half stroke: rows `h:end` → 0-based window rows `h−1..=duration` (the middle row is
//!   shared by both halves, exactly as in the published code).
//!
//! Errors are `measured mean − predicted mean` (`gt_bar − gp_bar`); each trajectory gives two
//! points (up first, then down).

use std::ops::RangeInclusive;

use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result, check_finite, param};
use crate::stats::{Interval, Rows, central_interval, mean};

/// A one-cycle window: samples `start ..= start + duration` (0-based, `duration + 1` samples),
/// `duration` being the stroke period in samples.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct CycleWindow {
    /// First sample of the window (0-based).
    pub start: usize,
    /// Stroke period in samples; the window's last sample is `start + duration`.
    pub duration: usize,
}

impl CycleWindow {
    /// The published window of a series of `n_samples` samples:
    /// `first_str_rev = floor(N − 5·duration/4)` (1-based), i.e. the cycle that ends a quarter
    /// period before the end of the series.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] if `duration == 0`, [`AnalysisError::Window`] if the window
    /// would start before the first sample.
    pub fn published(n_samples: usize, duration: usize) -> Result<Self> {
        if duration == 0 {
            return Err(param("duration", 0, "stroke period must be ≥ 1 sample"));
        }
        let first_1based = (n_samples as f64 - 5.0 * duration as f64 / 4.0).floor();
        if first_1based < 1.0 {
            return Err(AnalysisError::Window {
                start: 0,
                duration,
                n_samples,
            });
        }
        let w = Self {
            start: first_1based as usize - 1,
            duration,
        };
        w.range(n_samples)?;
        Ok(w)
    }

    /// Sample indices of the window, checked against a series of `n_samples`.
    ///
    /// # Errors
    /// [`AnalysisError::Window`] if the window does not fit.
    pub fn range(&self, n_samples: usize) -> Result<RangeInclusive<usize>> {
        let end = self.start.checked_add(self.duration);
        match end {
            Some(end) if end < n_samples => Ok(self.start..=end),
            _ => Err(AnalysisError::Window {
                start: self.start,
                duration: self.duration,
                n_samples,
            }),
        }
    }

    /// Sample ranges of the (up, down) half strokes, see the module docs.
    ///
    /// # Errors
    /// [`AnalysisError::Window`] if the window does not fit, [`AnalysisError::Parameter`] if
    /// `duration < 2` (no half stroke).
    pub fn half_strokes(
        &self,
        n_samples: usize,
    ) -> Result<(RangeInclusive<usize>, RangeInclusive<usize>)> {
        let r = self.range(n_samples)?;
        let h = self.duration / 2;
        if h == 0 {
            return Err(param(
                "duration",
                self.duration,
                "must be ≥ 2 for half strokes",
            ));
        }
        Ok((
            self.start..=self.start + h - 1,
            self.start + h - 1..=*r.end(),
        ))
    }
}

/// Means of every column over the up and down half strokes of one trajectory.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HalfStrokeMeans {
    /// Column means over the up half stroke (length `n_cols`).
    pub up: Vec<f64>,
    /// Column means over the down half stroke (length `n_cols`).
    pub down: Vec<f64>,
}

/// Half-stroke means of a `n_time × n_cols` table (e.g. load coefficients) in a cycle window.
///
/// # Errors
/// As [`CycleWindow::half_strokes`], plus [`AnalysisError::NonFinite`].
pub fn half_stroke_means(table: Rows<'_>, window: CycleWindow) -> Result<HalfStrokeMeans> {
    let (up, down) = window.half_strokes(table.n_rows())?;
    let col_means = |r: RangeInclusive<usize>| -> Result<Vec<f64>> {
        (0..table.n_cols())
            .map(|j| {
                let v: Vec<f64> = r.clone().map(|t| table.get(t, j)).collect();
                check_finite("half-stroke samples", &v)?;
                Ok(mean(&v))
            })
            .collect()
    };
    Ok(HalfStrokeMeans {
        up: col_means(up)?,
        down: col_means(down)?,
    })
}

/// Half-stroke averages of measured and predicted coefficients, pooled over trajectories
/// (Fig. 4B data).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CycleAverageErrors {
    /// `observed[j]`: measured half-stroke means of column `j`, two per trajectory (up, down).
    pub observed: Vec<Vec<f64>>,
    /// `error[j]`: `measured − predicted` half-stroke means, aligned with `observed`.
    pub error: Vec<Vec<f64>>,
}

impl CycleAverageErrors {
    /// Pools trajectories: `measured[i]`, `predicted[i]` are trajectory `i`'s coefficient tables
    /// (same shape) and `windows[i]` its last-cycle window.
    ///
    /// # Errors
    /// [`AnalysisError::Shape`] for mismatched counts or shapes, [`AnalysisError::Empty`],
    /// and the errors of [`half_stroke_means`].
    pub fn new(
        measured: &[Rows<'_>],
        predicted: &[Rows<'_>],
        windows: &[CycleWindow],
    ) -> Result<Self> {
        if measured.is_empty() {
            return Err(AnalysisError::Empty {
                what: "trajectory list".into(),
            });
        }
        if predicted.len() != measured.len() || windows.len() != measured.len() {
            return Err(AnalysisError::Shape {
                what: "predicted trajectories / windows".into(),
                expected: format!("{} each", measured.len()),
                found: format!("{} / {}", predicted.len(), windows.len()),
            });
        }
        let n = measured[0].n_cols();
        let mut observed = vec![Vec::new(); n];
        let mut error = vec![Vec::new(); n];
        for (i, ((m, p), w)) in measured.iter().zip(predicted).zip(windows).enumerate() {
            if m.n_cols() != n || p.n_cols() != n || p.n_rows() != m.n_rows() {
                return Err(AnalysisError::Shape {
                    what: format!("trajectory {i} coefficient tables"),
                    expected: format!("{} × {n} for both", m.n_rows()),
                    found: format!("predicted {} × {}", p.n_rows(), p.n_cols()),
                });
            }
            let hm = half_stroke_means(*m, *w)?;
            let hp = half_stroke_means(*p, *w)?;
            for j in 0..n {
                observed[j].extend([hm.up[j], hm.down[j]]);
                error[j].extend([hm.up[j] - hp.up[j], hm.down[j] - hp.down[j]]);
            }
        }
        Ok(Self { observed, error })
    }

    /// Per-column central `level`-% interval of the errors (published: 95).
    ///
    /// # Errors
    /// As [`central_interval`].
    pub fn intervals(&self, level: f64) -> Result<Vec<Interval>> {
        self.error
            .iter()
            .map(|e| central_interval(e, level))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_window_indices() {
        // N = 377, duration 75: floor(377 − 93.75) = 283 (1-based) → start 282, end 357.
        let w = CycleWindow::published(377, 75).unwrap();
        assert_eq!(w.start, 282);
        assert_eq!(w.range(377).unwrap(), 282..=357);
        assert!(CycleWindow::published(10, 9).is_err());
        assert!(
            CycleWindow {
                start: 5,
                duration: 5
            }
            .range(10)
            .is_err()
        );
    }

    #[test]
    fn half_strokes_follow_matlab_semantics() {
        // duration 4, window rows 0..=4: up = MATLAB 1:2 → rows 0,1; down = 2:end → rows 1..=4.
        let w = CycleWindow {
            start: 3,
            duration: 4,
        };
        let (up, down) = w.half_strokes(10).unwrap();
        assert_eq!(up, 3..=4);
        assert_eq!(down, 4..=7);
        // duration 5: h = 2 → same split, window has 6 rows.
        let (up, down) = CycleWindow {
            start: 0,
            duration: 5,
        }
        .half_strokes(6)
        .unwrap();
        assert_eq!((up, down), (0..=1, 1..=5));
    }

    #[test]
    fn half_stroke_means_of_ramp_and_square_wave() {
        // Column 0: ramp t; column 1: +1 on the first half (rows 0..2), −1 after.
        let d = 8;
        let data: Vec<f64> = (0..=d)
            .flat_map(|t| [t as f64, if t < 4 { 1.0 } else { -1.0 }])
            .collect();
        let m = half_stroke_means(
            Rows::new(&data, 2).unwrap(),
            CycleWindow {
                start: 0,
                duration: d,
            },
        )
        .unwrap();
        // Up rows 0..=3 → mean 1.5; down rows 3..=8 → mean 5.5.
        assert!((m.up[0] - 1.5).abs() < 1e-15 && (m.down[0] - 5.5).abs() < 1e-15);
        // Square wave: up all +1; down = one +1 (row 3) and five −1 → −4/6.
        assert!((m.up[1] - 1.0).abs() < 1e-15);
        assert!((m.down[1] + 4.0 / 6.0).abs() < 1e-15);
    }

    #[test]
    fn cycle_average_errors_of_sine_with_offset_prediction() {
        // Measured sin over one period, predicted = measured − 0.1 → every error is 0.1,
        // observed up/down means are ±(mean of |sin| over a half) up to the shared sample.
        let d = 40;
        let m: Vec<f64> = (0..=d)
            .map(|t| (2.0 * std::f64::consts::PI * t as f64 / d as f64).sin())
            .collect();
        let p: Vec<f64> = m.iter().map(|v| v - 0.1).collect();
        let w = CycleWindow {
            start: 0,
            duration: d,
        };
        let c = CycleAverageErrors::new(
            &[Rows::new(&m, 1).unwrap()],
            &[Rows::new(&p, 1).unwrap()],
            &[w],
        )
        .unwrap();
        assert_eq!(c.observed[0].len(), 2);
        assert!(c.error[0].iter().all(|e| (e - 0.1).abs() < 1e-12));
        // Σ_{t=0}^{19} sin(πt/20) = cot(π/40); down adds sin(19π/20) = sin(π/20) and t = 40 (0).
        let cot = 1.0 / (std::f64::consts::PI / 40.0).tan();
        let up = cot / 20.0;
        let down = ((std::f64::consts::PI / 20.0).sin() - cot) / 22.0;
        assert!((c.observed[0][0] - up).abs() < 1e-12);
        assert!((c.observed[0][1] - down).abs() < 1e-12);
        let ci = c.intervals(95.0).unwrap();
        assert!((ci[0].lo - 0.1).abs() < 1e-12 && (ci[0].hi - 0.1).abs() < 1e-12);
    }
}
