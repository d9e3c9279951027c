//! Two-dimensional Gaussian kernel density estimation with boundary reflection (MATLAB
//! `ksdensity(…, 'Support', 'positive', 'BoundaryCorrection', 'reflection', 'Bandwidth', h)`),
//! its evaluation on a grid, the mode, the published highest-density region and contours.
//!
//! Product Gaussian kernel with bandwidths `h = (h₀, h₁)`; in each dimension `d` with support
//! `[L_d, U_d]` every sample `x_{i,d}` is mirrored about each finite bound:
//!
//! ```text
//! f(x) = (1/n) Σᵢ Π_d [ φ_h(x_d − x_{i,d}) + φ_h(x_d − (2L_d − x_{i,d})) + φ_h(x_d − (2U_d − x_{i,d})) ]
//! φ_h(u) = exp(−u²/(2h²)) / (h √(2π))
//! ```
//!
//! (terms for infinite bounds are dropped; `f = 0` outside the support). With one finite bound
//! per dimension — MATLAB's `'positive'` support, `[0, ∞)` — `f` integrates to exactly 1.

use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result, check_finite, param};

/// Support of one dimension, `[lower, upper]`; either bound may be infinite.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Support {
    /// Lower bound (`f64::NEG_INFINITY` for none).
    pub lower: f64,
    /// Upper bound (`f64::INFINITY` for none).
    pub upper: f64,
}

impl Support {
    /// MATLAB `'positive'`: `[0, ∞)`.
    pub const POSITIVE: Self = Self {
        lower: 0.0,
        upper: f64::INFINITY,
    };
    /// The whole real line (no reflection).
    pub const UNBOUNDED: Self = Self {
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
    };

    fn contains(&self, v: f64) -> bool {
        v >= self.lower && v <= self.upper
    }
}

/// A 2-D kernel density estimate (see the module docs).
#[derive(Debug, Clone)]
pub struct Kde2 {
    points: Vec<[f64; 2]>,
    bandwidth: [f64; 2],
    support: [Support; 2],
}

const INV_SQRT_2PI: f64 = 0.398_942_280_401_432_7;

impl Kde2 {
    /// A KDE of `points` with bandwidths `bandwidth` and per-dimension `support`.
    ///
    /// # Errors
    /// [`AnalysisError::Empty`] for no points, [`AnalysisError::Parameter`] for a non-positive
    /// bandwidth, an empty support or a point outside the support, [`AnalysisError::NonFinite`].
    pub fn new(points: Vec<[f64; 2]>, bandwidth: [f64; 2], support: [Support; 2]) -> Result<Self> {
        if points.is_empty() {
            return Err(AnalysisError::Empty {
                what: "KDE points".into(),
            });
        }
        check_finite("KDE points", points.as_flattened())?;
        for (d, (h, s)) in bandwidth.iter().zip(&support).enumerate() {
            if !(h.is_finite() && *h > 0.0) {
                return Err(param(
                    &format!("bandwidth[{d}]"),
                    h,
                    "must be finite and > 0",
                ));
            }
            if s.lower.partial_cmp(&s.upper) != Some(std::cmp::Ordering::Less) {
                return Err(param(
                    &format!("support[{d}]"),
                    format!("[{}, {}]", s.lower, s.upper),
                    "needs lower < upper",
                ));
            }
        }
        if let Some(i) = points
            .iter()
            .position(|p| !(support[0].contains(p[0]) && support[1].contains(p[1])))
        {
            return Err(param(
                &format!("KDE point {i}"),
                format!("({}, {})", points[i][0], points[i][1]),
                "lies outside the support",
            ));
        }
        Ok(Self {
            points,
            bandwidth,
            support,
        })
    }

    /// MATLAB's published setting: `'positive'` support in both dimensions, one bandwidth `h`.
    ///
    /// # Errors
    /// As [`Kde2::new`].
    pub fn positive(points: Vec<[f64; 2]>, h: f64) -> Result<Self> {
        Self::new(points, [h, h], [Support::POSITIVE; 2])
    }

    /// Number of samples.
    pub fn n_points(&self) -> usize {
        self.points.len()
    }

    /// Reflected 1-D kernel of dimension `d` at `x` for sample value `xi`.
    fn kernel_1d(&self, d: usize, x: f64, xi: f64) -> f64 {
        let s = self.support[d];
        if !s.contains(x) {
            return 0.0;
        }
        let h = self.bandwidth[d];
        let g = |c: f64| {
            let u = (x - c) / h;
            (-0.5 * u * u).exp() * INV_SQRT_2PI / h
        };
        let mut k = g(xi);
        if s.lower.is_finite() {
            k += g(2.0 * s.lower - xi);
        }
        if s.upper.is_finite() {
            k += g(2.0 * s.upper - xi);
        }
        k
    }

    /// Density at `x`. Cost O(n).
    pub fn density(&self, x: [f64; 2]) -> f64 {
        self.points
            .iter()
            .map(|p| self.kernel_1d(0, x[0], p[0]) * self.kernel_1d(1, x[1], p[1]))
            .sum::<f64>()
            / self.points.len() as f64
    }

    /// Density at every grid node (`xs` × `ys`). Uses the kernel's separability: with
    /// `Kx[i][a] = k₀(xs[a], xᵢ)` and `Ky[i][b] = k₁(ys[b], yᵢ)`, `f[b][a] = (1/n) Σᵢ Ky[i][b] Kx[i][a]`.
    /// Cost O(n · (nx + ny + nx·ny)).
    ///
    /// # Errors
    /// [`AnalysisError::Empty`] for an empty axis, [`AnalysisError::NonFinite`].
    pub fn grid(&self, xs: Vec<f64>, ys: Vec<f64>) -> Result<DensityGrid> {
        if xs.is_empty() || ys.is_empty() {
            return Err(AnalysisError::Empty {
                what: "KDE grid axis".into(),
            });
        }
        check_finite("KDE grid x", &xs)?;
        check_finite("KDE grid y", &ys)?;
        let (nx, ny) = (xs.len(), ys.len());
        let mut kx = vec![0.0; nx];
        let mut values = vec![0.0; nx * ny];
        for p in &self.points {
            for (k, &x) in kx.iter_mut().zip(&xs) {
                *k = self.kernel_1d(0, x, p[0]);
            }
            for (b, &y) in ys.iter().enumerate() {
                let ky = self.kernel_1d(1, y, p[1]);
                if ky == 0.0 {
                    continue;
                }
                for (v, k) in values[b * nx..(b + 1) * nx].iter_mut().zip(&kx) {
                    *v += ky * k;
                }
            }
        }
        let inv_n = 1.0 / self.points.len() as f64;
        values.iter_mut().for_each(|v| *v *= inv_n);
        Ok(DensityGrid { xs, ys, values })
    }
}

/// Densities on a rectangular grid: `values[b * xs.len() + a] = f(xs[a], ys[b])`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DensityGrid {
    /// Grid abscissae (increasing).
    pub xs: Vec<f64>,
    /// Grid ordinates (increasing).
    pub ys: Vec<f64>,
    /// Densities, row-major over `ys` then `xs`.
    pub values: Vec<f64>,
}

/// The published highest-density region on a grid.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HdrRegion {
    /// Density threshold: the region is `{f ≥ threshold}`.
    pub threshold: f64,
    /// Fraction of the grid's total density sum inside the region (≤ the requested mass).
    pub grid_mass: f64,
}

/// `n` equally spaced values from `lo` to `hi` inclusive (MATLAB `linspace`).
pub fn linspace(lo: f64, hi: f64, n: usize) -> Vec<f64> {
    match n {
        0 => Vec::new(),
        1 => vec![hi],
        _ => (0..n)
            .map(|k| lo + (hi - lo) * k as f64 / (n - 1) as f64)
            .collect(),
    }
}

impl DensityGrid {
    /// Density at node `(a, b)` = `(xs[a], ys[b])`.
    pub fn at(&self, a: usize, b: usize) -> f64 {
        self.values[b * self.xs.len() + a]
    }

    /// The grid node of highest density, `[x, y]` (first one on ties).
    pub fn mode(&self) -> [f64; 2] {
        let (k, _) =
            self.values
                .iter()
                .enumerate()
                .fold((0, f64::NEG_INFINITY), |best, (k, &v)| {
                    if v > best.1 { (k, v) } else { best }
                });
        let nx = self.xs.len();
        [self.xs[k % nx], self.ys[k / nx]]
    }

    /// Trapezoidal integral of the density over the grid rectangle.
    pub fn integral(&self) -> f64 {
        self.integral_where(|_| true)
    }

    /// Trapezoidal integral of `f · 1{f ≥ threshold}` (the mass of an HDR, approximately).
    pub fn integral_above(&self, threshold: f64) -> f64 {
        self.integral_where(|v| v >= threshold)
    }

    fn integral_where(&self, keep: impl Fn(f64) -> bool) -> f64 {
        let w = |axis: &[f64], i: usize| -> f64 {
            let n = axis.len();
            if n < 2 {
                return 0.0;
            }
            let left = if i > 0 { axis[i] - axis[i - 1] } else { 0.0 };
            let right = if i + 1 < n {
                axis[i + 1] - axis[i]
            } else {
                0.0
            };
            0.5 * (left + right)
        };
        let mut s = 0.0;
        for b in 0..self.ys.len() {
            let wy = w(&self.ys, b);
            for a in 0..self.xs.len() {
                let v = self.at(a, b);
                if keep(v) {
                    s += v * wy * w(&self.xs, a);
                }
            }
        }
        s
    }

    /// The published `mass` highest-density region (`plotter.m`): nodes with density below
    /// `floor` (published 1e-5) are dropped, then the lowest remaining nodes are removed one by
    /// one until the remaining sum is `≤ mass ×` the sum over **all** nodes. The region is the
    /// remaining set, i.e. `{f ≥ threshold}` with `threshold` its smallest density.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] unless `0 < mass < 1`; [`AnalysisError::Empty`] if no node
    /// remains (density everywhere below `floor`).
    pub fn hdr(&self, mass: f64, floor: f64) -> Result<HdrRegion> {
        if !(mass > 0.0 && mass < 1.0) {
            return Err(param("hdr mass", mass, "must lie in (0, 1)"));
        }
        let total: f64 = self.values.iter().sum();
        let mut kept: Vec<f64> = self
            .values
            .iter()
            .copied()
            .filter(|&v| v >= floor)
            .collect();
        kept.sort_by(|a, b| b.total_cmp(a));
        let target = mass * total;
        let mut cum = 0.0;
        let mut last = None;
        for &v in &kept {
            if cum + v > target {
                break;
            }
            cum += v;
            last = Some(v);
        }
        match last {
            Some(threshold) => Ok(HdrRegion {
                threshold,
                grid_mass: cum / total,
            }),
            None => Err(AnalysisError::Empty {
                what: "highest-density region (density below floor or one node > mass)".into(),
            }),
        }
    }

    /// Line segments of the iso-density contour `f = level` (marching squares with linear
    /// interpolation along cell edges), as `[[x0, y0], [x1, y1]]`.
    pub fn contour_segments(&self, level: f64) -> Vec<[[f64; 2]; 2]> {
        let (nx, ny) = (self.xs.len(), self.ys.len());
        let mut segs = Vec::new();
        if nx < 2 || ny < 2 {
            return segs;
        }
        for b in 0..ny - 1 {
            for a in 0..nx - 1 {
                // Corners counter-clockwise: (a,b), (a+1,b), (a+1,b+1), (a,b+1).
                let c = [
                    ([self.xs[a], self.ys[b]], self.at(a, b)),
                    ([self.xs[a + 1], self.ys[b]], self.at(a + 1, b)),
                    ([self.xs[a + 1], self.ys[b + 1]], self.at(a + 1, b + 1)),
                    ([self.xs[a], self.ys[b + 1]], self.at(a, b + 1)),
                ];
                let mut cross = Vec::with_capacity(4);
                for e in 0..4 {
                    let (p0, v0) = c[e];
                    let (p1, v1) = c[(e + 1) % 4];
                    if (v0 >= level) != (v1 >= level) {
                        let t = (level - v0) / (v1 - v0);
                        cross.push([p0[0] + t * (p1[0] - p0[0]), p0[1] + t * (p1[1] - p0[1])]);
                    }
                }
                match cross.len() {
                    2 => segs.push([cross[0], cross[1]]),
                    4 => {
                        // Saddle: pair by the centre value.
                        let centre = 0.25 * c.iter().map(|x| x.1).sum::<f64>();
                        if (centre >= level) == (c[0].1 >= level) {
                            segs.push([cross[0], cross[3]]);
                            segs.push([cross[1], cross[2]]);
                        } else {
                            segs.push([cross[0], cross[1]]);
                            segs.push([cross[2], cross[3]]);
                        }
                    }
                    _ => {}
                }
            }
        }
        segs
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn single_point_is_the_kernel_and_reflects_at_zero() {
        let k = Kde2::positive(vec![[0.3, 0.5]], 0.1).unwrap();
        let phi = |u: f64| (-0.5 * u * u).exp() * INV_SQRT_2PI / 0.1;
        // At (0.3, 0.5): [φ(0) + φ(0.6/0.1·…)] in x, [φ(0) + φ(1.0)] in y (mirror images at −x).
        let want = (phi(0.0) + phi(6.0)) * (phi(0.0) + phi(10.0));
        assert!((k.density([0.3, 0.5]) - want).abs() < 1e-12);
        // On the boundary the reflected density is twice the plain kernel.
        let want0 = 2.0 * phi(3.0) * (phi(0.0) + phi(10.0));
        assert!((k.density([0.0, 0.5]) - want0).abs() < 1e-12);
        assert_eq!(k.density([-0.01, 0.5]), 0.0);
    }

    #[test]
    fn reflected_density_near_a_boundary_integrates_to_one() {
        let pts: Vec<[f64; 2]> = (0..50)
            .map(|i| [0.01 + 0.004 * i as f64, 0.02 + 0.01 * (i % 7) as f64])
            .collect();
        let k = Kde2::positive(pts.clone(), 0.09).unwrap();
        let g = k
            .grid(linspace(0.0, 1.5, 301), linspace(0.0, 1.5, 301))
            .unwrap();
        assert!((g.integral() - 1.0).abs() < 2e-3, "{}", g.integral());
        // Without reflection about half the mass would fall below zero.
        let u = Kde2::new(pts, [0.09; 2], [Support::UNBOUNDED; 2]).unwrap();
        let gu = u
            .grid(linspace(0.0, 1.5, 301), linspace(0.0, 1.5, 301))
            .unwrap();
        assert!(gu.integral() < 0.6);
    }

    #[test]
    fn grid_matches_pointwise_density() {
        let pts = vec![[0.2, 0.7], [0.4, 0.1], [0.9, 0.9]];
        let k = Kde2::new(
            pts,
            [0.1, 0.2],
            [
                Support::POSITIVE,
                Support {
                    lower: 0.0,
                    upper: 1.0,
                },
            ],
        )
        .unwrap();
        let g = k
            .grid(linspace(0.0, 1.0, 7), linspace(0.0, 1.0, 5))
            .unwrap();
        for b in 0..5 {
            for a in 0..7 {
                let d = k.density([g.xs[a], g.ys[b]]);
                assert!((g.at(a, b) - d).abs() < 1e-12);
            }
        }
    }

    #[test]
    fn hdr_follows_the_published_greedy_rule() {
        let g = DensityGrid {
            xs: vec![0.0, 1.0, 2.0, 3.0],
            ys: vec![0.0],
            values: vec![4.0, 3.0, 2.0, 1.0],
        };
        // Total 10; 70 % = 7: keep 4 + 3 = 7 (≤ 7), threshold 3.
        let r = g.hdr(0.7, 1e-5).unwrap();
        assert_eq!(r.threshold, 3.0);
        assert!((r.grid_mass - 0.7).abs() < 1e-15);
        // 65 %: only 4 fits.
        assert_eq!(g.hdr(0.65, 1e-5).unwrap().threshold, 4.0);
        assert!(g.hdr(1.0, 0.0).is_err());
    }

    #[test]
    fn contour_of_a_cone_is_a_closed_ring() {
        let xs = linspace(-1.0, 1.0, 41);
        let ys = xs.clone();
        let values = ys
            .iter()
            .flat_map(|y| xs.iter().map(move |x| 1.0 - (x * x + y * y).sqrt()))
            .collect();
        let g = DensityGrid { xs, ys, values };
        let segs = g.contour_segments(0.5);
        assert!(!segs.is_empty());
        for s in &segs {
            for p in s {
                let r = (p[0] * p[0] + p[1] * p[1]).sqrt();
                assert!((r - 0.5).abs() < 0.01, "{r}");
            }
        }
        let len: f64 = segs
            .iter()
            .map(|s| ((s[1][0] - s[0][0]).powi(2) + (s[1][1] - s[0][1]).powi(2)).sqrt())
            .sum();
        assert!((len - std::f64::consts::PI).abs() < 0.02, "{len}");
    }
}
