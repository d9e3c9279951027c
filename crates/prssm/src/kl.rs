//! `KL(q(u) ‖ p(u)) = Σ_d KL(N(m_d, S_d) ‖ N(0, K))` and its gradients, with `K = K_mm`
//! (unwhitened) or `K = I` (whitened):
//!
//! ```text
//! KL_d = ½ [tr(K⁻¹S_d) + m_dᵀK⁻¹m_d − M + ln|K| − ln|S_d|]
//! ∂/∂m_d = K⁻¹m_d,   ∂/∂S_d = ½(K⁻¹ − S_d⁻¹),   ∂/∂K = ½ Σ_d (K⁻¹ − K⁻¹(S_d + m_d m_dᵀ)K⁻¹)
//! ```
//! Cost `O(D_x M²)` (diagonal) or `O(D_x M³)` (full), once per evaluation.

use faer::Accum;

use crate::linalg::{gemm, lower_inverse, view, view_mut};
use crate::params::CovarianceStructure;

/// KL value and gradients.
#[derive(Debug, Clone)]
pub struct KlTerms {
    /// `Σ_d KL_d` (nats).
    pub value: f64,
    /// `∂KL/∂m`, row-major `M × D_x`.
    pub q_mean: Vec<f64>,
    /// `∂KL/∂S` (diagonal, row-major `M × D_x`) or `∂KL/∂L_d` (full, lower triangles of
    /// `D_x` column-major `M × M`).
    pub q_cov: Vec<f64>,
    /// `∂KL/∂K` (symmetric `M × M`, column-major); `None` when whitened.
    pub kmm: Option<Vec<f64>>,
}

/// KL of `q(u)` (means `q_mean` row-major `M × D_x`; `q_cov` as in
/// [`crate::Params::q_cov`]) from the prior with Cholesky factor `l` of `K` (`None`:
/// whitened, `K = I`).
pub fn kl_divergence(
    l: Option<&[f64]>,
    m: usize,
    dx: usize,
    q_mean: &[f64],
    q_cov: &[f64],
    cov: CovarianceStructure,
) -> KlTerms {
    // P = K⁻¹ (identity when whitened), ln|K|.
    let (p, logdet_k) = match l {
        Some(l) => {
            let li = lower_inverse(l, m);
            let mut p = vec![0.0; m * m];
            gemm(
                view_mut(&mut p, m, m),
                Accum::Replace,
                view(&li, m, m).transpose(),
                view(&li, m, m),
                1.0,
            );
            let ld: f64 = (0..m).map(|i| 2.0 * l[i * m + i].ln()).sum();
            (p, ld)
        }
        None => {
            let mut p = vec![0.0; m * m];
            (0..m).for_each(|i| p[i * m + i] = 1.0);
            (p, 0.0)
        }
    };
    let mut value = 0.0;
    let mut g_mean = vec![0.0; m * dx];
    let mut g_cov = vec![0.0; q_cov.len()];
    // Q = Σ_d (S_d + m_d m_dᵀ).
    let mut q = vec![0.0; m * m];
    for d in 0..dx {
        // P m_d and m_dᵀ P m_d.
        let mut quad = 0.0;
        for i in 0..m {
            let mut s = 0.0;
            for j in 0..m {
                s += p[j * m + i] * q_mean[j * dx + d];
            }
            g_mean[i * dx + d] = s;
            quad += q_mean[i * dx + d] * s;
        }
        for j in 0..m {
            for i in 0..m {
                q[j * m + i] += q_mean[i * dx + d] * q_mean[j * dx + d];
            }
        }
        let (trace, logdet_s) = match cov {
            CovarianceStructure::Diagonal => {
                let mut tr = 0.0;
                let mut ld = 0.0;
                for i in 0..m {
                    let s = q_cov[i * dx + d];
                    tr += p[i * m + i] * s;
                    ld += s.ln();
                    g_cov[i * dx + d] = 0.5 * (p[i * m + i] - 1.0 / s);
                    q[i * m + i] += s;
                }
                (tr, ld)
            }
            CovarianceStructure::Full => {
                let ld_ = &q_cov[d * m * m..(d + 1) * m * m];
                // P L_d and S_d = L_d L_dᵀ.
                let mut pl = vec![0.0; m * m];
                gemm(
                    view_mut(&mut pl, m, m),
                    Accum::Replace,
                    view(&p, m, m),
                    view(ld_, m, m),
                    1.0,
                );
                gemm(
                    view_mut(&mut q, m, m),
                    Accum::Add,
                    view(ld_, m, m),
                    view(ld_, m, m).transpose(),
                    1.0,
                );
                let tr: f64 = pl.iter().zip(ld_).map(|(a, b)| a * b).sum();
                let mut ld = 0.0;
                let g = &mut g_cov[d * m * m..(d + 1) * m * m];
                for j in 0..m {
                    let djj = ld_[j * m + j];
                    ld += 2.0 * djj.abs().ln();
                    for i in j..m {
                        g[j * m + i] = pl[j * m + i];
                    }
                    g[j * m + j] -= 1.0 / djj;
                }
                (tr, ld)
            }
        };
        value += 0.5 * (trace + quad - m as f64 + logdet_k - logdet_s);
    }
    let kmm = l.map(|_| {
        // ½ (D_x P − P Q P).
        let mut pq = vec![0.0; m * m];
        gemm(
            view_mut(&mut pq, m, m),
            Accum::Replace,
            view(&p, m, m),
            view(&q, m, m),
            1.0,
        );
        let mut g = p.iter().map(|v| 0.5 * dx as f64 * v).collect::<Vec<_>>();
        gemm(
            view_mut(&mut g, m, m),
            Accum::Add,
            view(&pq, m, m),
            view(&p, m, m),
            -0.5,
        );
        g
    });
    KlTerms {
        value,
        q_mean: g_mean,
        q_cov: g_cov,
        kmm,
    }
}
