//! Stationary ARD kernels `k(a, b) = σ_f² g(τ)` with the scaled squared distance
//! `τ = Σ_j ((a_j − b_j)/ℓ_j)²`, and their reverse-mode adjoints.
//!
//! | kind | `g(τ)` | `dg/dτ` |
//! |---|---|---|
//! | [`KernelKind::Matern32`] | `(1 + r) e^{−r}`, `r = √3 √(τ + δ)` | `−(3/2) e^{−r}` |
//! | [`KernelKind::SquaredExponential`] | `e^{−τ/2}` | `−g/2` |
//!
//! `δ` (`matern_tau_jitter`) is `1e-8` in the published code and `0` by default. Written in
//! `τ`, the Matern-3/2 derivative is finite at `a = b`.
//!
//! Layouts: point sets are column-major `D × N` slices (one point per column, i.e. point-major
//! rows of length `D`); kernel matrices are column-major `M × N`.

use serde::{Deserialize, Serialize};

/// Which stationary kernel the transition GP uses (one kernel shared by all latent dims).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum KernelKind {
    /// Matern-3/2 ARD (the paper's kernel).
    Matern32,
    /// Squared-exponential (RBF) ARD.
    SquaredExponential,
}

impl KernelKind {
    /// Shape function `g(τ)` and its derivative `dg/dτ` (dimensionless).
    #[inline(always)]
    pub fn shape(self, tau: f64, matern_tau_jitter: f64) -> (f64, f64) {
        match self {
            KernelKind::Matern32 => {
                let r = (3.0 * (tau + matern_tau_jitter)).sqrt();
                let e = (-r).exp();
                ((1.0 + r) * e, -1.5 * e)
            }
            KernelKind::SquaredExponential => {
                let g = (-0.5 * tau).exp();
                (g, -0.5 * g)
            }
        }
    }
}

/// Scales a row-major `N × D` point set by `1/ℓ` into a column-major `D × N` slice
/// (`out[j + n·D] = points[n·D + j] / ℓ_j`; the same memory order).
pub fn scale_points(points: &[f64], inv_len: &[f64], out: &mut [f64]) {
    let d = inv_len.len();
    for (o, p) in out.chunks_exact_mut(d).zip(points.chunks_exact(d)) {
        for j in 0..d {
            o[j] = p[j] * inv_len[j];
        }
    }
}

/// Transposes scaled inducing inputs into dimension-major `M`-vectors:
/// `zt[j·M + m] = Z[m, j] / ℓ_j` (`Z` row-major `M × D`).
pub fn scale_inducing(z: &[f64], inv_len: &[f64], zt: &mut [f64]) {
    let d = inv_len.len();
    let m_n = z.len() / d;
    for m in 0..m_n {
        for j in 0..d {
            zt[j * m_n + m] = z[m * d + j] * inv_len[j];
        }
    }
}

/// Cross-covariance `K[m, n] = σ_f² g(τ(z_m, x_n))` (column-major `M × N`) and
/// `kd[m, n] = σ_f² g'(τ)` for the backward pass.
///
/// `zt`: scaled inducing inputs from [`scale_inducing`] (`D·M`); `xs`: scaled points
/// (`D × N`, column-major). `k` and `kd` have `M·N` entries. Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn cross_cov(
    kind: KernelKind,
    variance: f64,
    matern_tau_jitter: f64,
    zt: &[f64],
    xs: &[f64],
    d: usize,
    k: &mut [f64],
    kd: &mut [f64],
) {
    let m_n = zt.len() / d;
    for ((kc, kdc), x) in k
        .chunks_exact_mut(m_n)
        .zip(kd.chunks_exact_mut(m_n))
        .zip(xs.chunks_exact(d))
    {
        kc.fill(0.0);
        for j in 0..d {
            let xj = x[j];
            let zj = &zt[j * m_n..(j + 1) * m_n];
            for (t, &z) in kc.iter_mut().zip(zj) {
                let diff = z - xj;
                *t += diff * diff;
            }
        }
        for (kv, kdv) in kc.iter_mut().zip(kdc.iter_mut()) {
            let (g, dg) = kind.shape(*kv, matern_tau_jitter);
            *kv = variance * g;
            *kdv = variance * dg;
        }
    }
}

/// Reverse mode of [`cross_cov`] with respect to the inducing inputs, the points and the
/// lengthscales, given `c[m, n] = K̄[m, n] · kd[m, n]` (`∂loss/∂τ`).
///
/// With `τ = Σ_j (z̃_{mj} − x̃_{nj})²` and `z̃ = z/ℓ`, `d = z̃_{mj} − x̃_{nj}`:
/// `Z̄[m,j] += 2/ℓ_j Σ_n c d`, `X̄[j,n] −= 2/ℓ_j Σ_m c d`, `ℓ̄_j −= 2/ℓ_j Σ c d²`, evaluated
/// through the products `C X̃ᵀ` and `Z̃ᵀ C` (two GEMMs). `zbar_t` is dimension-major
/// (`zbar_t[j·M + m]`, without the factor `2/ℓ_j`: see [`finish_inducing_grad`]); `xbar`
/// (`n_xbar_rows × N`) gets the full adjoint of rows `j < n_xbar_rows`; `len_acc[j]`
/// accumulates `Σ c d²`. Scratch: `cx` (`M·D`), `zc` (`D·N`), `rowsum` (`M`). Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub fn cross_cov_backward(
    c: &[f64],
    zt: &[f64],
    xs: &[f64],
    inv_len: &[f64],
    n_xbar_rows: usize,
    zbar_t: &mut [f64],
    xbar: &mut [f64],
    len_acc: &mut [f64],
    cx: &mut [f64],
    zc: &mut [f64],
    rowsum: &mut [f64],
) {
    use crate::linalg::{gemm, view, view_mut};
    let d = inv_len.len();
    let m_n = zt.len() / d;
    let n_pts = xs.len() / d;
    gemm(
        view_mut(cx, m_n, d),
        faer::Accum::Replace,
        view(c, m_n, n_pts),
        view(xs, d, n_pts).transpose(),
        1.0,
    );
    gemm(
        view_mut(zc, d, n_pts),
        faer::Accum::Replace,
        view(zt, m_n, d).transpose(),
        view(c, m_n, n_pts),
        1.0,
    );
    let rowsum = &mut rowsum[..m_n];
    rowsum.fill(0.0);
    for col in c[..m_n * n_pts].chunks_exact(m_n) {
        rowsum.iter_mut().zip(col).for_each(|(r, v)| *r += v);
    }
    for j in 0..d {
        let zj = &zt[j * m_n..(j + 1) * m_n];
        let cxj = &cx[j * m_n..(j + 1) * m_n];
        let mut l = 0.0;
        for (((zb, &z), &r), &q) in zbar_t[j * m_n..(j + 1) * m_n]
            .iter_mut()
            .zip(zj)
            .zip(rowsum.iter())
            .zip(cxj)
        {
            *zb += z * r - q;
            l += z * z * r - 2.0 * z * q;
        }
        len_acc[j] += l;
    }
    for n in 0..n_pts {
        let s: f64 = c[n * m_n..(n + 1) * m_n].iter().sum();
        for j in 0..d {
            let x = xs[n * d + j];
            len_acc[j] += x * x * s;
            if j < n_xbar_rows {
                xbar[n * n_xbar_rows + j] -= 2.0 * inv_len[j] * (zc[n * d + j] - x * s);
            }
        }
    }
}

/// Converts a dimension-major accumulator of `Σ c d` into `∂loss/∂Z` (row-major `M × D`):
/// `zbar[m·D + j] += 2/ℓ_j · acc[j·M + m]`.
pub fn finish_inducing_grad(acc: &[f64], inv_len: &[f64], zbar: &mut [f64]) {
    let d = inv_len.len();
    let m_n = acc.len() / d;
    for m in 0..m_n {
        for j in 0..d {
            zbar[m * d + j] += 2.0 * inv_len[j] * acc[j * m_n + m];
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn matern_shape_matches_closed_form_and_derivative() {
        for &tau in &[0.0, 1e-6, 0.3, 2.0, 9.0] {
            let (g, dg) = KernelKind::Matern32.shape(tau, 0.0);
            let r = (3.0 * tau).sqrt();
            assert!((g - (1.0 + r) * (-r).exp()).abs() < 1e-15);
            if tau > 1e-3 {
                let h = 1e-6;
                let fd = (KernelKind::Matern32.shape(tau + h, 0.0).0
                    - KernelKind::Matern32.shape(tau - h, 0.0).0)
                    / (2.0 * h);
                assert!((fd - dg).abs() < 1e-8, "{fd} {dg}");
            }
            let (g, dg) = KernelKind::SquaredExponential.shape(tau, 0.0);
            assert!((g - (-0.5 * tau).exp()).abs() < 1e-15);
            assert!((dg + 0.5 * g).abs() < 1e-15);
        }
    }
}
