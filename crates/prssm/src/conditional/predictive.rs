//! The prediction conditional: forward only, no tape.

use faer::Accum;

use super::{Posterior, forward_product, forward_product_f32};
use crate::kernel;
use crate::linalg::{dot, f32_operand, gemm, view, view_mut, widen_into};
use crate::params::CovarianceStructure;
use crate::precision::Precision;

/// Forward-only conditional for prediction (no derivatives, no tape). `W` and the means come
/// from one product `[W; μ] = [G; mᵀG] K` (`(M + D_x) × N`); `σ²` as in [`ConditionalWorkspace`].
/// Under a [`Precision::Mixed`] posterior the kernel's shape (`τ` stays `f64`), the product and
/// `S(W⊙W)` run in `f32` ([`crate::precision`]); the cancellation `σ_f² − Σ H⊙W` is summed in
/// `f64` from the `f32` `K` and the widened `W`.
#[derive(Debug, Clone)]
pub(crate) struct PredictiveWorkspace {
    cap: usize,
    group: usize,
    /// GP inputs `[x; u]`, column-major `D × N` (filled by the caller).
    pub input: Vec<f64>,
    xs: Vec<f64>,
    /// `K` (`M × N`), or `τ` under [`Precision::Mixed`] (`K` is then in `f32`).
    k: Vec<f64>,
    /// `[W; μ]`, column-major `(M + D_x) × N`.
    wm: Vec<f64>,
    w2: Vec<f64>,
    tau_shared: Vec<f64>,
    /// Variances `σ²`, column-major `D_x × N`.
    pub var: Vec<f64>,
    /// `f32` operands and results under [`Precision::Mixed`]: `K` (`M × N`), `[W; μ]`
    /// (`(M + D_x) × N`), `S(W⊙W)` (`D_x × N`), `W⊙W` (`M × N`).
    mixed: Option<[Vec<f32>; 4]>,
}

impl PredictiveWorkspace {
    /// Buffers for up to `capacity` points whose consecutive groups of `group` share the
    /// input part `u` (see [`ConditionalWorkspace::set_input_group`]).
    pub(crate) fn new(post: &Posterior, capacity: usize, group: usize) -> Self {
        let (m, d, dx, n) = (post.m, post.d, post.dx, capacity);
        Self {
            cap: n,
            group: group.max(1),
            input: vec![0.0; d * n],
            xs: vec![0.0; d * n],
            k: vec![0.0; m * n],
            wm: vec![0.0; (m + dx) * n],
            w2: vec![0.0; m * n],
            tau_shared: vec![0.0; m],
            var: vec![0.0; dx * n],
            mixed: (post.precision() == Precision::Mixed).then(|| {
                [
                    vec![0.0; m * n],
                    vec![0.0; (m + dx) * n],
                    vec![0.0; dx * n],
                    vec![0.0; m * n],
                ]
            }),
        }
    }

    /// Means `μ` of the last [`Self::forward`]: column `n` is `mean(n)` (`D_x` values).
    #[inline]
    pub(crate) fn mean(&self, post: &Posterior, n: usize) -> &[f64] {
        let r = post.m + post.dx;
        &self.wm[n * r + post.m..(n + 1) * r]
    }

    /// Computes `μ` and `σ²` at the first `n` columns of [`Self::input`]. Allocates nothing.
    pub(crate) fn forward(&mut self, post: &Posterior, n: usize) {
        let (m, d, dx) = (post.m, post.d, post.dx);
        debug_assert!(n <= self.cap);
        let r = m + dx;
        kernel::scale_points(&self.input[..d * n], &post.inv_len, &mut self.xs[..d * n]);
        let points = post.grouped(&self.xs[..d * n], self.group);
        let (w2, var) = (&mut self.w2, &mut self.var);
        match self.mixed.as_mut() {
            None => {
                let k = &mut self.k[..m * n];
                kernel::cross_cov_grouped_values(points, k, &mut self.tau_shared);
                forward_product(post, k, n, &mut self.wm);
                let h = (!post.whitened).then_some(&*k);
                write_predictive_variance(post, &self.wm, r, h, n, w2, var, None);
            }
            Some([k32, wm32, var32, w2_32]) => {
                // `self.k` holds `τ`; `K` exists only in `f32`.
                let tau = &mut self.k;
                kernel::cross_cov_grouped_f32(points, tau, k32, None, &mut self.tau_shared);
                forward_product_f32(post, k32, n, wm32);
                widen_into(&wm32[..r * n], &mut self.wm, Accum::Replace);
                let h = (!post.whitened).then_some(&k32[..m * n]);
                let mixed = Some((&mut w2_32[..], &mut var32[..]));
                write_predictive_variance(post, &self.wm, r, h, n, w2, var, mixed);
            }
        }
    }
}

/// Writes the predictive variances of `n` points into `var` (`D_x × N`, column-major):
/// `σ²_d(n) = k** − w_nᵀh_n + Σ_i S_d,ii w_in²` (diagonal `S`) or `+ ‖L_dᵀw_n‖²` (full
/// `S_d = L_dL_dᵀ`), with `w_n` the first `M` entries of column `n` of `w` (column stride
/// `stride ≥ M`) and `h_n = k_n` (column `n` of `k`, `M × N`, in `f64` or, under mixed
/// precision, the `f32` kernel; the sum is `f64` either way) or `w_n` when `k` is `None`
/// (whitened). `w2` (`M × N`) is scratch. With `mixed` (`M × N` and `D_x × N` scratch) and a
/// mixed posterior of diagonal `S`, the sum `S(W⊙W)` of positive terms is formed in `f32`
/// ([`write_quadratic_term_f32`]). Allocates nothing.
#[allow(clippy::too_many_arguments)]
pub(super) fn write_predictive_variance<H: Copy + Into<f64>>(
    post: &Posterior,
    w: &[f64],
    stride: usize,
    k: Option<&[H]>,
    n: usize,
    w2: &mut [f64],
    var: &mut [f64],
    mixed: Option<(&mut [f32], &mut [f32])>,
) {
    match mixed {
        Some((w2_32, var32)) if uses_f32_quadratic_term(post) => {
            write_quadratic_term_f32(post, w, stride, n, w2_32, var32, var)
        }
        _ => write_quadratic_term(post, w, stride, n, w2, var),
    }
    add_base_variance(post, w, stride, k, n, var, None);
}

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
