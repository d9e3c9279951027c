//! Sparse GP regression of a static map `y = g(x) + ε` with the engine's kernel and inducing
//! inputs: the predictive mean of the subset-of-regressors / DTC approximation, which is also
//! the mean of Titsias' (2009) optimal `q(u)`,
//!
//! ```text
//! ĝ(x) = k(x, Z) w,   w = (σ² K_ZZ + K_ZX K_XZ)⁻¹ K_ZX Y,
//! ```
//!
//! with `K` an ARD kernel of [`crate::kernel`] (`σ_f² = 1`, one length scale per input), `Z`
//! the `M` inducing inputs (k-means of the training inputs, [`crate::train::inducing::kmeans`]),
//! `σ²` the noise variance, `Y` the `N × P` outputs. Inputs and outputs are taken as given: a
//! caller standardizes them.
//!
//! [`NormalEquations::accumulate`] forms `K_ZX K_XZ` and `K_ZX Y` once per kernel in blocks of
//! [`BLOCK_ROWS`] points (in parallel, summed in block order, so the result does not depend on
//! the thread count); [`NormalEquations::solve`] then gives the weights for any `σ²`, so a
//! noise grid costs one Cholesky factorization per value.

use faer::linalg::solvers::Solve;
use faer::{Mat, Side};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};

use crate::kernel::{KernelKind, cross_cov, scale_inducing, scale_points};
use crate::linalg::{gemm, view, view_mut};

/// Points per block of the accumulation (and of prediction).
pub const BLOCK_ROWS: usize = 2048;

/// Why a regression could not be fitted or evaluated.
#[derive(Debug, thiserror::Error, PartialEq)]
#[non_exhaustive]
pub enum RegressionError {
    /// Shapes that do not agree.
    #[error("GP regression {what}: expected {expected}, found {found}")]
    Shape {
        /// The array.
        what: &'static str,
        /// Its expected size.
        expected: String,
        /// The size given.
        found: String,
    },
    /// A setting out of its range.
    #[error("GP regression setting {name} = {value}: {expected}")]
    Setting {
        /// The setting.
        name: &'static str,
        /// The value given.
        value: String,
        /// What it must be.
        expected: &'static str,
    },
    /// `σ² K_ZZ + K_ZX K_XZ` is not positive definite.
    #[error("GP regression normal equations are not positive definite (noise variance {0})")]
    Singular(f64),
}

/// The kernel of a regression: its kind and one length scale per input (in the inputs' units).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RegressionKernel {
    /// Kernel shape.
    pub kind: KernelKind,
    /// Length scales `ℓ_j` (> 0), one per input.
    pub lengthscales: Vec<f64>,
}

impl RegressionKernel {
    fn check(&self) -> Result<(), RegressionError> {
        if self.lengthscales.is_empty()
            || !self.lengthscales.iter().all(|l| *l > 0.0 && l.is_finite())
        {
            return Err(RegressionError::Setting {
                name: "lengthscales",
                value: format!("{:?}", self.lengthscales),
                expected: "one finite length scale > 0 per input",
            });
        }
        Ok(())
    }

    fn inv_len(&self) -> Vec<f64> {
        self.lengthscales.iter().map(|l| 1.0 / l).collect()
    }

    /// `K(Z, X)` column-major `M × N` of row-major points `x` (`N × D`), `zt` from
    /// [`scale_inducing`].
    fn cross(&self, zt: &[f64], x: &[f64], inv_len: &[f64]) -> Vec<f64> {
        let d = inv_len.len();
        let (m, n) = (zt.len() / d, x.len() / d);
        let mut xs = vec![0.0; x.len()];
        scale_points(x, inv_len, &mut xs);
        let mut k = vec![0.0; m * n];
        let mut kd = vec![0.0; m * n];
        cross_cov(self.kind, 1.0, 0.0, zt, &xs, d, &mut k, &mut kd);
        k
    }
}

/// `K_ZX K_XZ`, `K_ZX Y` and `K_ZZ` of one kernel and one set of inducing inputs.
#[derive(Debug, Clone)]
pub struct NormalEquations {
    kernel: RegressionKernel,
    inducing: Vec<f64>,
    n_out: usize,
    n_points: usize,
    kzx_kxz: Mat<f64>,
    kzx_y: Mat<f64>,
    kzz: Mat<f64>,
}

fn check_rows(what: &'static str, data: &[f64], width: usize) -> Result<usize, RegressionError> {
    if width == 0 || data.len() % width != 0 || data.is_empty() {
        return Err(RegressionError::Shape {
            what,
            expected: format!("a non-empty row-major table of width {width}"),
            found: format!("{} values", data.len()),
        });
    }
    if let Some(i) = data.iter().position(|v| !v.is_finite()) {
        return Err(RegressionError::Shape {
            what,
            expected: "finite values".into(),
            found: format!("{} at row {}, column {}", data[i], i / width, i % width),
        });
    }
    Ok(data.len() / width)
}

impl NormalEquations {
    /// Accumulates the normal equations of `x` (row-major `N × D`) and `y` (row-major `N × P`)
    /// with inducing inputs `inducing` (row-major `M × D`), in parallel on the caller's rayon
    /// pool.
    ///
    /// # Errors
    /// [`RegressionError::Shape`] for tables that disagree or hold non-finite values,
    /// [`RegressionError::Setting`] for bad length scales.
    pub fn accumulate(
        kernel: &RegressionKernel,
        inducing: &[f64],
        x: &[f64],
        y: &[f64],
        n_out: usize,
    ) -> Result<Self, RegressionError> {
        kernel.check()?;
        let d = kernel.lengthscales.len();
        let m = check_rows("inducing inputs", inducing, d)?;
        let n = check_rows("inputs", x, d)?;
        let n_y = check_rows("outputs", y, n_out)?;
        if n_y != n {
            return Err(RegressionError::Shape {
                what: "outputs",
                expected: format!("{n} rows, as the inputs"),
                found: format!("{n_y} rows"),
            });
        }
        let inv_len = kernel.inv_len();
        let mut zt = vec![0.0; inducing.len()];
        scale_inducing(inducing, &inv_len, &mut zt);
        let block = |b: usize| {
            let rows = b * BLOCK_ROWS..((b + 1) * BLOCK_ROWS).min(n);
            let nb = rows.len();
            let k = kernel.cross(&zt, &x[rows.start * d..rows.end * d], &inv_len);
            // Y block as column-major `nb × P`.
            let mut yb = vec![0.0; nb * n_out];
            for (i, row) in y[rows.start * n_out..rows.end * n_out]
                .chunks_exact(n_out)
                .enumerate()
            {
                for (j, v) in row.iter().enumerate() {
                    yb[j * nb + i] = *v;
                }
            }
            let mut g = vec![0.0; m * m];
            let mut r = vec![0.0; m * n_out];
            let kv = view(&k, m, nb);
            gemm(
                view_mut(&mut g, m, m),
                faer::Accum::Replace,
                kv,
                kv.transpose(),
                1.0,
            );
            gemm(
                view_mut(&mut r, m, n_out),
                faer::Accum::Replace,
                kv,
                view(&yb, nb, n_out),
                1.0,
            );
            (g, r)
        };
        let n_blocks = n.div_ceil(BLOCK_ROWS);
        let mut kzx_kxz = Mat::<f64>::zeros(m, m);
        let mut kzx_y = Mat::<f64>::zeros(m, n_out);
        let wave = rayon::current_num_threads().max(1) * 2;
        for first in (0..n_blocks).step_by(wave) {
            let parts: Vec<_> = (first..(first + wave).min(n_blocks))
                .into_par_iter()
                .map(block)
                .collect();
            for (g, r) in parts {
                kzx_kxz += view(&g, m, m);
                kzx_y += view(&r, m, n_out);
            }
        }
        let kzz_cm = kernel.cross(&zt, inducing, &inv_len);
        Ok(Self {
            kernel: kernel.clone(),
            inducing: inducing.to_vec(),
            n_out,
            n_points: n,
            kzx_kxz,
            kzx_y,
            kzz: view(&kzz_cm, m, m).to_owned(),
        })
    }

    /// Points accumulated.
    pub fn n_points(&self) -> usize {
        self.n_points
    }

    /// The regression with noise variance `noise_variance` (`σ² > 0`, in the outputs' units
    /// squared).
    ///
    /// # Errors
    /// [`RegressionError::Setting`] for `σ² ≤ 0`; [`RegressionError::Singular`].
    pub fn solve(&self, noise_variance: f64) -> Result<SparseGpRegression, RegressionError> {
        if !(noise_variance > 0.0 && noise_variance.is_finite()) {
            return Err(RegressionError::Setting {
                name: "noise_variance",
                value: noise_variance.to_string(),
                expected: "finite and > 0",
            });
        }
        let m = self.kzz.nrows();
        let mut a = &self.kzx_kxz + &self.kzz * faer::Scale(noise_variance);
        // The jitter the engine puts on K_ZZ, scaled by σ² as the rest of that term.
        for i in 0..m {
            a[(i, i)] += noise_variance * 1e-8;
        }
        let llt = a
            .llt(Side::Lower)
            .map_err(|_| RegressionError::Singular(noise_variance))?;
        let w = llt.solve(&self.kzx_y);
        Ok(SparseGpRegression {
            kernel: self.kernel.clone(),
            inducing: self.inducing.clone(),
            n_out: self.n_out,
            noise_variance,
            weights: (0..m)
                .flat_map(|i| (0..self.n_out).map(move |j| (i, j)))
                .map(|(i, j)| w[(i, j)])
                .collect(),
        })
    }
}

/// A fitted sparse GP regression: `ĝ(x) = k(x, Z) w`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SparseGpRegression {
    /// The kernel.
    pub kernel: RegressionKernel,
    /// Inducing inputs `Z`, row-major `M × D`.
    pub inducing: Vec<f64>,
    /// Outputs `P`.
    pub n_out: usize,
    /// Noise variance `σ²` it was solved with.
    pub noise_variance: f64,
    /// Weights `w`, row-major `M × P`.
    pub weights: Vec<f64>,
}

impl SparseGpRegression {
    /// Inputs `D`.
    pub fn n_input(&self) -> usize {
        self.kernel.lengthscales.len()
    }

    /// Inducing inputs `M`.
    pub fn n_inducing(&self) -> usize {
        self.inducing.len() / self.n_input()
    }

    /// The predictive means of `x` (row-major `N × D`) into `out` (row-major `N × P`),
    /// block by block on the calling thread.
    ///
    /// # Errors
    /// [`RegressionError::Shape`] for tables of the wrong size or non-finite inputs.
    pub fn predict_into(&self, x: &[f64], out: &mut [f64]) -> Result<(), RegressionError> {
        let d = self.n_input();
        let n = check_rows("inputs", x, d)?;
        if out.len() != n * self.n_out {
            return Err(RegressionError::Shape {
                what: "prediction buffer",
                expected: format!("{n} × {} values", self.n_out),
                found: format!("{} values", out.len()),
            });
        }
        let (m, p) = (self.n_inducing(), self.n_out);
        let inv_len = self.kernel.inv_len();
        let mut zt = vec![0.0; self.inducing.len()];
        scale_inducing(&self.inducing, &inv_len, &mut zt);
        // Weights column-major `M × P`.
        let mut w = vec![0.0; m * p];
        for i in 0..m {
            for j in 0..p {
                w[j * m + i] = self.weights[i * p + j];
            }
        }
        let mut yb = vec![0.0; BLOCK_ROWS * p];
        for (xb, ob) in x.chunks(BLOCK_ROWS * d).zip(out.chunks_mut(BLOCK_ROWS * p)) {
            let nb = xb.len() / d;
            let k = self.kernel.cross(&zt, xb, &inv_len);
            gemm(
                view_mut(&mut yb, nb, p),
                faer::Accum::Replace,
                view(&k, m, nb).transpose(),
                view(&w, m, p),
                1.0,
            );
            for (i, row) in ob.chunks_exact_mut(p).enumerate() {
                for (j, v) in row.iter_mut().enumerate() {
                    *v = yb[j * nb + i];
                }
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn data(n: usize, seed: u64) -> (Vec<f64>, Vec<f64>) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let x: Vec<f64> = (0..2 * n).map(|_| rng.random_range(-2.0..2.0)).collect();
        let y = x
            .chunks_exact(2)
            .flat_map(|p| [p[0].sin() * p[1], (p[0] * p[0] - p[1]).tanh()])
            .collect();
        (x, y)
    }

    /// A smooth nonlinear map of two inputs is learnt within 4 % RMS of its spread from
    /// 5000 noise-free points with 64 inducing inputs (k-means), on 1000 fresh points.
    #[test]
    fn learns_a_smooth_map() {
        let (x, y) = data(5000, 1);
        let (z, _) = crate::train::inducing::kmeans(&x, 2, 64, 3);
        let kernel = RegressionKernel {
            kind: KernelKind::SquaredExponential,
            lengthscales: vec![1.0, 1.0],
        };
        let eq = NormalEquations::accumulate(&kernel, &z, &x, &y, 2).unwrap();
        assert_eq!(eq.n_points(), 5000);
        let model = eq.solve(1e-4).unwrap();
        let (xt, yt) = data(1000, 2);
        let mut pred = vec![0.0; yt.len()];
        model.predict_into(&xt, &mut pred).unwrap();
        for j in 0..2 {
            let err: f64 = (0..1000)
                .map(|i| (pred[2 * i + j] - yt[2 * i + j]).powi(2))
                .sum();
            let var: f64 = (0..1000).map(|i| yt[2 * i + j].powi(2)).sum();
            let rel = (err / var).sqrt();
            assert!(rel < 0.04, "output {j}: relative RMS error {rel}");
        }
    }

    /// With every training point an inducing input and a tiny noise, the fit interpolates the
    /// training outputs.
    #[test]
    fn interpolates_when_every_point_is_inducing() {
        let (x, y) = data(40, 5);
        let kernel = RegressionKernel {
            kind: KernelKind::Matern32,
            lengthscales: vec![0.7, 1.3],
        };
        let model = NormalEquations::accumulate(&kernel, &x, &x, &y, 2)
            .unwrap()
            .solve(1e-10)
            .unwrap();
        let mut pred = vec![0.0; y.len()];
        model.predict_into(&x, &mut pred).unwrap();
        for (p, t) in pred.iter().zip(&y) {
            assert!((p - t).abs() < 1e-5, "{p} vs {t}");
        }
    }

    /// Blocks summed in order: the same normal equations on 1 or 4 threads, bit for bit, over
    /// more than one block.
    #[test]
    fn accumulation_does_not_depend_on_threads() {
        let (x, y) = data(3 * BLOCK_ROWS + 17, 7);
        let (z, _) = crate::train::inducing::kmeans(&x, 2, 16, 1);
        let kernel = RegressionKernel {
            kind: KernelKind::Matern32,
            lengthscales: vec![1.0, 2.0],
        };
        let fit = |threads| {
            rayon::ThreadPoolBuilder::new()
                .num_threads(threads)
                .build()
                .unwrap()
                .install(|| NormalEquations::accumulate(&kernel, &z, &x, &y, 2).unwrap())
                .solve(1e-3)
                .unwrap()
        };
        assert_eq!(fit(1), fit(4));
    }

    #[test]
    fn bad_shapes_and_settings_are_named() {
        let kernel = RegressionKernel {
            kind: KernelKind::Matern32,
            lengthscales: vec![1.0, 1.0],
        };
        let z = [0.0, 0.0, 1.0, 1.0];
        let e = NormalEquations::accumulate(&kernel, &z, &[0.0, 1.0, 2.0], &[1.0], 1);
        assert!(matches!(
            e,
            Err(RegressionError::Shape { what: "inputs", .. })
        ));
        let e = NormalEquations::accumulate(&kernel, &z, &[0.0, f64::NAN], &[1.0], 1);
        assert!(
            e.unwrap_err()
                .to_string()
                .contains("NaN at row 0, column 1")
        );
        let e = NormalEquations::accumulate(&kernel, &z, &[0.0, 1.0], &[1.0, 2.0], 1);
        assert!(e.unwrap_err().to_string().contains("2 rows"));
        let bad = RegressionKernel {
            kind: KernelKind::Matern32,
            lengthscales: vec![1.0, 0.0],
        };
        let e = NormalEquations::accumulate(&bad, &z, &[0.0, 1.0], &[1.0], 1);
        assert!(matches!(
            e,
            Err(RegressionError::Setting {
                name: "lengthscales",
                ..
            })
        ));
        let eq = NormalEquations::accumulate(&kernel, &z, &[0.0, 1.0], &[1.0], 1).unwrap();
        assert!(eq.solve(0.0).is_err());
        let model = eq.solve(0.1).unwrap();
        let e = model.predict_into(&[0.0, 1.0], &mut [0.0; 2]);
        assert!(e.unwrap_err().to_string().contains("prediction buffer"));
    }
}
