//! Paired bootstrap of a difference of pooled RMSEs over trajectories.
//!
//! Two models A and B predict the same `K` trajectories. Per trajectory `k` and output `j`
//! the sums of squared errors `S^A_kj`, `S^B_kj` over its `n_k` samples give the pooled
//! `RMSE_j = √(Σ_k S_kj / Σ_k n_k)`. A bootstrap draw resamples the trajectories with
//! replacement (the same ones for A and B: the pairing) and recomputes
//! `Δ_j = RMSE^A_j − RMSE^B_j`; the interval is the central `level` % of the draws (MATLAB
//! `prctile`, [`crate::stats`]). Trajectories, not samples, are the independent units: samples
//! within a trajectory are strongly correlated.

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result, param};
use crate::stats::{Interval, central_interval};

/// Per-trajectory sums of squared errors of one model: row-major `K × P` and the samples per
/// trajectory.
#[derive(Debug, Clone, PartialEq)]
pub struct TrajectoryErrors {
    /// `S_kj`, row-major `K × P`.
    pub sum_sq: Vec<f64>,
    /// `n_k`.
    pub n_samples: Vec<usize>,
    /// `P`.
    pub n_out: usize,
}

impl TrajectoryErrors {
    /// From per-trajectory row-major `n_k × P` error tables (measured − predicted, any units).
    ///
    /// # Errors
    /// [`AnalysisError::Shape`] for a table whose length is not a multiple of `n_out`.
    pub fn of_tables<'a>(
        errors: impl IntoIterator<Item = &'a [f64]>,
        n_out: usize,
    ) -> Result<Self> {
        let mut out = Self {
            sum_sq: Vec::new(),
            n_samples: Vec::new(),
            n_out,
        };
        for (k, e) in errors.into_iter().enumerate() {
            if n_out == 0 || e.len() % n_out != 0 {
                return Err(AnalysisError::Shape {
                    what: format!("errors of trajectory {k}"),
                    expected: format!("a multiple of {n_out} values"),
                    found: e.len().to_string(),
                });
            }
            let mut s = vec![0.0; n_out];
            for row in e.chunks_exact(n_out) {
                for (sj, v) in s.iter_mut().zip(row) {
                    *sj += v * v;
                }
            }
            out.sum_sq.extend(s);
            out.n_samples.push(e.len() / n_out);
        }
        Ok(out)
    }

    /// Trajectories `K`.
    pub fn len(&self) -> usize {
        self.n_samples.len()
    }

    /// Whether there are no trajectories.
    pub fn is_empty(&self) -> bool {
        self.n_samples.is_empty()
    }

    /// Pooled RMSE per output of the trajectories `draw` (indices, repeats allowed).
    fn pooled(&self, draw: impl Iterator<Item = usize>, out: &mut [f64]) {
        out.fill(0.0);
        let mut n = 0usize;
        for k in draw {
            for (o, s) in out.iter_mut().zip(&self.sum_sq[k * self.n_out..]) {
                *o += s;
            }
            n += self.n_samples[k];
        }
        for o in out.iter_mut() {
            *o = (*o / n.max(1) as f64).sqrt();
        }
    }

    /// Pooled RMSE per output over every trajectory.
    pub fn rmse(&self) -> Vec<f64> {
        let mut out = vec![0.0; self.n_out];
        self.pooled(0..self.len(), &mut out);
        out
    }
}

/// The paired difference of one output.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct PairedDifference {
    /// `RMSE_A − RMSE_B` on all trajectories.
    pub difference: f64,
    /// Its bootstrap interval.
    pub interval: Interval,
    /// Whether the interval excludes zero.
    pub significant: bool,
}

impl std::fmt::Display for PairedDifference {
    /// `+0.012 [−0.003, +0.027]`: the difference and its interval, signed, 3 decimals.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{:+.3} [{:+.3}, {:+.3}]",
            self.difference, self.interval.lo, self.interval.hi
        )
    }
}

/// The paired bootstrap of `RMSE_A − RMSE_B` per output (module docs): `n_draws` draws from
/// `seed`, central `level` % intervals.
///
/// # Errors
/// [`AnalysisError::Shape`] for error sets of different trajectories or outputs,
/// [`AnalysisError::Empty`] for none, a parameter error for `n_draws < 100` or `level` outside
/// (0, 100).
pub fn paired_bootstrap(
    a: &TrajectoryErrors,
    b: &TrajectoryErrors,
    n_draws: usize,
    level: f64,
    seed: u64,
) -> Result<Vec<PairedDifference>> {
    if a.n_samples != b.n_samples || a.n_out != b.n_out {
        return Err(AnalysisError::Shape {
            what: "paired errors".into(),
            expected: format!(
                "{} trajectories × {} outputs, as the first model",
                a.len(),
                a.n_out
            ),
            found: format!("{} × {}", b.len(), b.n_out),
        });
    }
    if a.is_empty() {
        return Err(AnalysisError::Empty {
            what: "paired errors".into(),
        });
    }
    if n_draws < 100 {
        return Err(param("n_draws", n_draws, "at least 100"));
    }
    if !(level > 0.0 && level < 100.0) {
        return Err(param("level", level, "between 0 and 100 (%)"));
    }
    let (k, p) = (a.len(), a.n_out);
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let mut draws = vec![Vec::with_capacity(n_draws); p];
    let (mut ra, mut rb) = (vec![0.0; p], vec![0.0; p]);
    let mut idx = vec![0usize; k];
    for _ in 0..n_draws {
        for i in idx.iter_mut() {
            *i = rng.random_range(0..k);
        }
        a.pooled(idx.iter().copied(), &mut ra);
        b.pooled(idx.iter().copied(), &mut rb);
        for j in 0..p {
            draws[j].push(ra[j] - rb[j]);
        }
    }
    let (full_a, full_b) = (a.rmse(), b.rmse());
    draws
        .iter()
        .enumerate()
        .map(|(j, d)| {
            let interval = central_interval(d, level)?;
            Ok(PairedDifference {
                difference: full_a[j] - full_b[j],
                interval,
                significant: interval.lo > 0.0 || interval.hi < 0.0,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand_distr::{Distribution, Normal};

    fn errors(scale: &[f64], k: usize, n: usize, seed: u64) -> TrajectoryErrors {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let normal = Normal::new(0.0, 1.0).unwrap();
        let tables: Vec<Vec<f64>> = (0..k)
            .map(|_| {
                (0..n)
                    .flat_map(|_| {
                        scale
                            .iter()
                            .map(|s| s * normal.sample(&mut rng))
                            .collect::<Vec<_>>()
                    })
                    .collect()
            })
            .collect();
        TrajectoryErrors::of_tables(tables.iter().map(|t| &t[..]), scale.len()).unwrap()
    }

    /// A model with errors 20 % larger on output 0 and equal on output 1: output 0 is
    /// significant, output 1 is not, and the pooled RMSE is that of the tables.
    #[test]
    fn finds_a_real_difference_and_not_a_null_one() {
        let a = errors(&[1.2, 1.0], 36, 50, 1);
        let b = errors(&[1.0, 1.0], 36, 50, 2);
        let d = paired_bootstrap(&a, &b, 2000, 95.0, 0).unwrap();
        assert!(d[0].significant && d[0].interval.lo > 0.0, "{:?}", d[0]);
        assert!(!d[1].significant, "{:?}", d[1]);
        assert!((d[0].difference - (a.rmse()[0] - b.rmse()[0])).abs() < 1e-15);
        // Same seed, same intervals.
        assert_eq!(d, paired_bootstrap(&a, &b, 2000, 95.0, 0).unwrap());
    }

    /// Under the null (both models the same error scale), about 5 % of 95 % intervals exclude
    /// zero: between 1 and 12 of 100 repetitions.
    #[test]
    fn null_rejections_are_near_the_level() {
        let hits = (0..100)
            .filter(|&r| {
                let a = errors(&[1.0], 36, 20, 10 + 2 * r);
                let b = errors(&[1.0], 36, 20, 11 + 2 * r);
                paired_bootstrap(&a, &b, 400, 95.0, r).unwrap()[0].significant
            })
            .count();
        assert!((1..=12).contains(&hits), "{hits} of 100");
    }

    #[test]
    fn mismatched_sets_are_refused() {
        let a = errors(&[1.0], 3, 5, 1);
        let b = errors(&[1.0], 4, 5, 1);
        assert!(paired_bootstrap(&a, &b, 200, 95.0, 0).is_err());
        assert!(paired_bootstrap(&a, &a, 10, 95.0, 0).is_err());
    }
}
