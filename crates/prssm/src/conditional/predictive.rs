//! The terms of the predictive variance `σ²_d = σ_f² − wᵀh + Σ_m S_{md} w_m²` (diagonal `S`;
//! `‖L_dᵀw‖²` full) that the conditional's forward pass writes.

use faer::Accum;

use super::Posterior;
use crate::linalg::{dot, f32_operand, gemm, view, view_mut, widen_into};
use crate::params::CovarianceStructure;

/// Whether [`write_quadratic_term_f32`] serves `post`: mixed precision and diagonal `S`.
pub(super) fn uses_f32_quadratic_term(post: &Posterior) -> bool {
    post.cov == CovarianceStructure::Diagonal && !post.q_cov32.is_empty()
}

/// `var = S(W⊙W)` for diagonal `S` in `f32` (the operands `W⊙W` rounded into `w2_32`, the
/// product into `var32`, widened into `var`), from `W` in `f64` or `f32` (first `M` rows of
/// `w`, column stride `stride`). Allocates nothing.
pub(super) fn write_quadratic_term_f32<W: Copy + Into<f64>>(
    post: &Posterior,
    w: &[W],
    stride: usize,
    n: usize,
    w2_32: &mut [f32],
    var32: &mut [f32],
    var: &mut [f64],
) {
    let (m, dx) = (post.m, post.dx);
    for (c2, wc) in w2_32[..m * n].chunks_exact_mut(m).zip(w.chunks(stride)) {
        c2.iter_mut().zip(&wc[..m]).for_each(|(a, &b)| {
            let b: f64 = b.into();
            *a = f32_operand(b * b);
        });
    }
    gemm(
        view_mut(var32, dx, n),
        Accum::Replace,
        view(&post.q_cov32, dx, m),
        view(w2_32, m, n),
        1.0,
    );
    widen_into(&var32[..dx * n], var, Accum::Replace);
}

/// `var = Σ_i S_d,ii w_in²` (diagonal `S`) or `‖L_dᵀw_n‖²` (full `S`) in `f64`, from the
/// first `M` rows of `w` (column stride `stride`); `w2` (`M × N`) is scratch. Allocates
/// nothing.
pub(super) fn write_quadratic_term(
    post: &Posterior,
    w: &[f64],
    stride: usize,
    n: usize,
    w2: &mut [f64],
    var: &mut [f64],
) {
    let (m, dx) = (post.m, post.dx);
    match post.cov {
        CovarianceStructure::Diagonal => {
            for (c2, wc) in w2[..m * n].chunks_exact_mut(m).zip(w.chunks(stride)) {
                c2.iter_mut().zip(&wc[..m]).for_each(|(a, &b)| *a = b * b);
            }
            gemm(
                view_mut(var, dx, n),
                Accum::Replace,
                view(&post.q_cov, dx, m),
                view(w2, m, n),
                1.0,
            )
        }
        CovarianceStructure::Full => {
            let w_view = view(&w[..stride * n], stride, n).subrows(0, m);
            for dd in 0..dx {
                let ld = &post.q_cov[dd * m * m..(dd + 1) * m * m];
                gemm(
                    view_mut(w2, m, n),
                    Accum::Replace,
                    view(ld, m, m).transpose(),
                    w_view,
                    1.0,
                );
                for j in 0..n {
                    let c = &w2[j * m..(j + 1) * m];
                    var[j * dx + dd] = dot(c, c);
                }
            }
        }
    }
}

/// Adds `k** − w_nᵀh_n` to the quadratic terms in `var` (see [`write_predictive_variance`];
/// `w` in `f64` or `f32`, the sums in `f64`). With `quad`, first writes the quadratic term
/// less `w_nᵀh_n` (`σ²_d(n) − k**`) there (`D_x × N`). Allocates nothing.
pub(super) fn add_base_variance<W: Copy + Into<f64>, H: Copy + Into<f64>>(
    post: &Posterior,
    w: &[W],
    stride: usize,
    k: Option<&[H]>,
    n: usize,
    var: &mut [f64],
    mut quad: Option<&mut [f64]>,
) {
    let (m, dx) = (post.m, post.dx);
    for (j, v) in var[..dx * n].chunks_exact_mut(dx).enumerate() {
        let wc = &w[j * stride..j * stride + m];
        let wh = match k {
            Some(k) => dot(wc, &k[j * m..(j + 1) * m]),
            None => dot(wc, wc),
        };
        if let Some(q) = quad.as_deref_mut() {
            q[j * dx..(j + 1) * dx]
                .iter_mut()
                .zip(v.iter())
                .for_each(|(q, &v)| *q = v - wh);
        }
        let base = post.variance - wh;
        v.iter_mut().for_each(|v| *v += base);
    }
}
