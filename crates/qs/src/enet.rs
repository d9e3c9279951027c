//! Elastic net by cyclic coordinate descent on the Gram (covariance) matrix, along a λ path.
//!
//! For a design X (n × p) and target y (n), the problem solved at each λ is
//!
//! ```text
//! minimize_w  1/(2n) ‖y − X w‖² + λ [α ‖w‖₁ + (1 − α)/2 ‖w‖²]
//! ```
//!
//! with α the l1 ratio (MATLAB's `Alpha`, scikit-learn's `l1_ratio`). Only the Gram matrix
//! G = XᵀX/n (p × p) and c = Xᵀy/n (p) enter, so one sweep costs O(p²) whatever n is.
//! Coordinate update, with r = c − G w kept current:
//!
//! ```text
//! ρ_j = r_j + G_jj w_j,   w_j ← S(ρ_j, λα) / (G_jj + λ(1 − α)),   S(z, t) = sign(z) max(|z| − t, 0)
//! r  ← r − G[:, j] Δw_j
//! ```
//!
//! The path is solved from the largest λ down, each λ warm-started at the previous solution.

/// The λ grid: `n` values geometric from `lambda_max` down to `lambda_max · min_ratio`
/// (both ends included), as `np.geomspace(lambda_max, lambda_max * min_ratio, n)`.
pub fn lambda_grid(lambda_max: f64, min_ratio: f64, n: usize) -> Vec<f64> {
    if n == 1 {
        return vec![lambda_max];
    }
    let step = min_ratio.ln() / (n - 1) as f64;
    (0..n)
        .map(|k| match k {
            0 => lambda_max,
            k if k == n - 1 => lambda_max * min_ratio,
            k => lambda_max * (step * k as f64).exp(),
        })
        .collect()
}

/// λ_max = max_j |c_j| / α: the smallest λ at which every coefficient is zero
/// (c = Xᵀy/n, α the l1 ratio).
pub fn lambda_max(c: &[f64], l1_ratio: f64) -> f64 {
    c.iter().fold(0.0_f64, |m, v| m.max(v.abs())) / l1_ratio
}

/// Convergence settings of coordinate descent.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Convergence {
    /// Stop when the largest coefficient change in a sweep is ≤ `tol` (units of w).
    pub tol: f64,
    /// Give up after this many sweeps at one λ.
    pub max_sweeps: usize,
}

/// Reusable buffers for [`solve_path`]: the residual correlation r = c − G w (p).
#[derive(Debug, Clone)]
pub struct CdWorkspace {
    r: Vec<f64>,
}

impl CdWorkspace {
    /// Buffers for `p` features.
    pub fn new(p: usize) -> Self {
        Self { r: vec![0.0; p] }
    }
}

/// Outcome of one path solve.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct PathStats {
    /// Total coordinate-descent sweeps over the path.
    pub sweeps: usize,
    /// Number of λ at which `max_sweeps` was reached before `tol`.
    pub unconverged: usize,
}

/// Solves the elastic net at every λ of `lambdas` (descending), warm-starting each from the
/// previous solution (the first from zero).
///
/// - `gram`: G = XᵀX/n, p × p row-major; `c`: Xᵀy/n, length p.
/// - `coefs`: output, `lambdas.len()` × p row-major, w at each λ.
///
/// Allocates nothing; `ws` must have been made for p features. Panics if the slice lengths
/// disagree (a programming error; callers validate user data first).
pub fn solve_path(
    gram: &[f64],
    c: &[f64],
    lambdas: &[f64],
    l1_ratio: f64,
    conv: Convergence,
    ws: &mut CdWorkspace,
    coefs: &mut [f64],
) -> PathStats {
    let p = c.len();
    assert!(gram.len() == p * p && coefs.len() == lambdas.len() * p && ws.r.len() == p);
    let mut stats = PathStats::default();
    let mut prev: Option<usize> = None;
    for (k, &lambda) in lambdas.iter().enumerate() {
        let (done, rest) = coefs.split_at_mut(k * p);
        let w = &mut rest[..p];
        match prev {
            Some(j) => w.copy_from_slice(&done[j * p..(j + 1) * p]),
            None => w.fill(0.0),
        }
        prev = Some(k);
        // r = c − G w, recomputed at each λ to shed rounding drift.
        for (i, ri) in ws.r.iter_mut().enumerate() {
            let row = &gram[i * p..(i + 1) * p];
            *ri = c[i] - row.iter().zip(w.iter()).map(|(g, x)| g * x).sum::<f64>();
        }
        let l1 = lambda * l1_ratio;
        let l2 = lambda * (1.0 - l1_ratio);
        let mut converged = false;
        for _ in 0..conv.max_sweeps {
            stats.sweeps += 1;
            let mut max_change = 0.0_f64;
            for j in 0..p {
                let gjj = gram[j * p + j];
                let rho = ws.r[j] + gjj * w[j];
                let denom = gjj + l2;
                let new = if denom > 0.0 {
                    soft_threshold(rho, l1) / denom
                } else {
                    0.0
                };
                let delta = new - w[j];
                if delta != 0.0 {
                    w[j] = new;
                    // G is symmetric: column j = row j.
                    let col = &gram[j * p..(j + 1) * p];
                    for (ri, g) in ws.r.iter_mut().zip(col) {
                        *ri -= g * delta;
                    }
                    max_change = max_change.max(delta.abs());
                }
            }
            if max_change <= conv.tol {
                converged = true;
                break;
            }
        }
        if !converged {
            stats.unconverged += 1;
        }
    }
    stats
}

/// S(z, t) = sign(z) · max(|z| − t, 0).
#[inline]
fn soft_threshold(z: f64, t: f64) -> f64 {
    if z > t {
        z - t
    } else if z < -t {
        z + t
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn orthonormal_design_has_closed_form() {
        // G = I: w_j = S(c_j, λα) / (1 + λ(1 − α)) exactly.
        let p = 3;
        let mut g = vec![0.0; 9];
        for j in 0..p {
            g[j * p + j] = 1.0;
        }
        let c = [0.9, -0.3, 0.05];
        let alpha = 0.75;
        let lmax = lambda_max(&c, alpha);
        assert!((lmax - 1.2).abs() < 1e-15);
        let lambdas = lambda_grid(lmax, 1e-3, 7);
        let mut coefs = vec![0.0; lambdas.len() * p];
        let conv = Convergence {
            tol: 1e-15,
            max_sweeps: 100,
        };
        let st = solve_path(
            &g,
            &c,
            &lambdas,
            alpha,
            conv,
            &mut CdWorkspace::new(p),
            &mut coefs,
        );
        assert_eq!(st.unconverged, 0);
        for (k, l) in lambdas.iter().enumerate() {
            for j in 0..p {
                let want = soft_threshold(c[j], l * alpha) / (1.0 + l * (1.0 - alpha));
                assert!((coefs[k * p + j] - want).abs() < 1e-15);
            }
        }
        assert!(
            coefs[..p].iter().all(|&w| w.abs() < 1e-15),
            "zero at lambda_max"
        );
    }

    #[test]
    fn grid_matches_geomspace_ends_and_ratio() {
        let g = lambda_grid(2.0, 1e-4, 100);
        assert_eq!(g.len(), 100);
        assert_eq!(g[0], 2.0);
        assert!((g[99] - 2e-4).abs() < 1e-18);
        let r = g[1] / g[0];
        assert!((r - 1e-4_f64.powf(1.0 / 99.0)).abs() < 1e-14);
    }
}
