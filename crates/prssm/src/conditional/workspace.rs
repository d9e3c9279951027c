//! The training conditional: the forward pass of a batch of points with the tape the reverse
//! mode reads, and the reverse pass into [`ConditionalGrads`].

use faer::Accum;

use super::predictive::write_predictive_variance;
use super::{Posterior, forward_product, forward_product_f32};
use crate::kernel;
use crate::linalg::{dot, f32_operand, gemm, round_into, view, view_mut, widen_into};
use crate::params::CovarianceStructure;
use crate::precision::Precision;

/// Per-step values kept for the reverse mode: the scaled inputs `X̃` (`D × N`),
/// `σ_f² g'` (`M × N`), `[W; μ]` (`(M + D_x) × N`) and `σ² − σ_f²` (`D_x × N`), stored in one
/// slice of [`tape_len`] values.
struct Tape<'a> {
    xs: &'a mut [f64],
    kd: &'a mut [f64],
    wm: &'a mut [f64],
    quad: &'a mut [f64],
}

/// Values per step stored for the reverse mode of a batch of `capacity` points.
pub fn tape_len(post: &Posterior, capacity: usize) -> usize {
    (post.d + 2 * post.m + 2 * post.dx) * capacity
}

fn split_tape<'a>(post: &Posterior, cap: usize, n: usize, tape: &'a mut [f64]) -> Tape<'a> {
    let (d, m, dx, r) = (post.d, post.m, post.dx, post.m + post.dx);
    let (xs, rest) = tape.split_at_mut(d * cap);
    let (kd, rest) = rest.split_at_mut(m * cap);
    let (wm, quad) = rest.split_at_mut(r * cap);
    Tape {
        xs: &mut xs[..d * n],
        kd: &mut kd[..m * n],
        wm: &mut wm[..r * n],
        quad: &mut quad[..dx * n],
    }
}

/// Buffers of the conditional for up to `capacity` points (allocated once).
#[derive(Debug, Clone)]
pub struct ConditionalWorkspace {
    cap: usize,
    /// GP inputs `[x; u]`, column-major `D × N` (filled by the caller).
    pub input: Vec<f64>,
    tape: Vec<f64>,
    /// `K` of the current step (`M × N`; not on the tape), or its `τ` under
    /// [`Precision::Mixed`] (`K` is then in `f32`).
    k: Vec<f64>,
    w2: Vec<f64>,
    wbar: Vec<f64>,
    kbar: Vec<f64>,
    base_bar: Vec<f64>,
    cx: Vec<f64>,
    zc: Vec<f64>,
    rowsum: Vec<f64>,
    input_group: usize,
    /// Means `μ`, column-major `D_x × N`.
    pub mean: Vec<f64>,
    /// Variances `σ²`, column-major `D_x × N`.
    pub var: Vec<f64>,
    /// `f32` operands and results of the large products under [`Precision::Mixed`].
    mixed: Option<MixedBuffers>,
}

/// The `f32` side of the three large products of a step ([`crate::precision`]).
#[derive(Debug, Clone)]
struct MixedBuffers {
    /// `K` (`M × N`).
    k: Vec<f32>,
    /// `[W; μ]` (`(M + D_x) × N`).
    wm: Vec<f32>,
    /// `[P; μ̄]`, then `[A; μ̄]` (`(M + D_x) × N`).
    wbar: Vec<f32>,
    /// `Y` (`M × N`); in the forward pass, the scratch of `W⊙W`.
    y: Vec<f32>,
    /// This step's `[A; μ̄] Wᵀ` (`(M + D_x) × M`).
    gbar: Vec<f32>,
    /// `σ²` (forward) or `σ̄²` (reverse), `D_x × N`.
    var: Vec<f32>,
    /// This step's `σ̄²(W⊙W)ᵀ` (`D_x × M`, diagonal `S`).
    q_cov_bar: Vec<f32>,
}

impl MixedBuffers {
    fn new(m: usize, dx: usize, n: usize) -> Self {
        let r = m + dx;
        Self {
            k: vec![0.0; m * n],
            wm: vec![0.0; r * n],
            wbar: vec![0.0; r * n],
            y: vec![0.0; m * n],
            gbar: vec![0.0; r * m],
            var: vec![0.0; dx * n],
            q_cov_bar: vec![0.0; dx * m],
        }
    }
}

/// Chunk-local gradient accumulators of the conditional.
#[derive(Debug, Clone)]
pub struct ConditionalGrads {
    /// `Σ c d` per inducing input, dimension-major `D·M` (see [`kernel::cross_cov_backward`]).
    pub(crate) zbar_t: Vec<f64>,
    /// `Σ c d²` per dimension.
    pub(crate) len_acc: Vec<f64>,
    /// `∂/∂σ_f²`.
    pub(crate) variance: f64,
    /// `∂/∂S` or `∂/∂L_d` (layout of [`Params::q_cov`]).
    pub(crate) q_cov: Vec<f64>,
    /// `[B; m̄ᵀ] = Σ [A; μ̄] Wᵀ`, column-major `(M + D_x) × M` (module doc;
    /// [`Self::split_stacked`] splits it).
    pub(crate) gbar: Vec<f64>,
}

impl ConditionalGrads {
    /// Zeros for `post`.
    pub fn zeros(post: &Posterior) -> Self {
        Self {
            zbar_t: vec![0.0; post.d * post.m],
            len_acc: vec![0.0; post.d],
            variance: 0.0,
            q_cov: vec![0.0; post.q_cov.len()],
            gbar: vec![0.0; (post.m + post.dx) * post.m],
        }
    }

    /// Splits [`Self::gbar`] into `∂/∂m` (row-major `M × D_x`, the bottom rows `m̄ᵀ`) and `B`
    /// (`M × M`, for [`Posterior::kmm_grad`]).
    pub(crate) fn split_stacked(&self, post: &Posterior) -> (Vec<f64>, Vec<f64>) {
        let (m, dx) = (post.m, post.dx);
        let stacked = view(&self.gbar, m + dx, m);
        let mut q_mean = vec![0.0; dx * m];
        view_mut(&mut q_mean, dx, m).copy_from(stacked.subrows(m, dx));
        let mut b = vec![0.0; m * m];
        view_mut(&mut b, m, m).copy_from(stacked.subrows(0, m));
        (q_mean, b)
    }

    /// `self += other`.
    pub fn add(&mut self, o: &ConditionalGrads) {
        fn acc(a: &mut [f64], b: &[f64]) {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
        acc(&mut self.zbar_t, &o.zbar_t);
        acc(&mut self.len_acc, &o.len_acc);
        self.variance += o.variance;
        acc(&mut self.q_cov, &o.q_cov);
        acc(&mut self.gbar, &o.gbar);
    }
}

impl ConditionalWorkspace {
    /// Buffers for up to `capacity` points, in the precision of `post`
    /// ([`Posterior::set_precision`]).
    pub fn new(post: &Posterior, capacity: usize) -> Self {
        let (m, d, dx, n) = (post.m, post.d, post.dx, capacity);
        let mixed = (post.precision() == Precision::Mixed).then(|| MixedBuffers::new(m, dx, n));
        Self {
            cap: n,
            input: vec![0.0; d * n],
            tape: vec![0.0; tape_len(post, n)],
            k: vec![0.0; m * n],
            w2: vec![0.0; m * n],
            wbar: vec![0.0; (m + dx) * n],
            kbar: vec![0.0; m * n],
            base_bar: vec![0.0; n],
            cx: vec![0.0; m * d],
            zc: vec![0.0; d * n],
            rowsum: vec![0.0; m],
            input_group: 1,
            mean: vec![0.0; dx * n],
            var: vec![0.0; dx * n],
            mixed,
        }
    }

    /// Whether the buffers serve `post`: the capacity is `n` and the precision `post`'s.
    pub(crate) fn fits(&self, post: &Posterior, n: usize) -> bool {
        self.cap == n && self.mixed.is_some() == (post.precision() == Precision::Mixed)
    }

    /// Declares that consecutive groups of `group` points share the input part `u` of
    /// [`Self::input`] (rows `D_x..D`), e.g. the particles of one window; the shared part of
    /// the kernel distances is then computed once per group. Default 1 (nothing shared).
    pub(crate) fn set_input_group(&mut self, group: usize) {
        self.input_group = group.max(1);
    }

    /// Capacity in points.
    pub fn capacity(&self) -> usize {
        self.cap
    }

    /// Computes `μ` and `σ²` at the first `n` columns of [`Self::input`] into
    /// [`Self::mean`] / [`Self::var`]. Allocates nothing.
    pub fn forward(&mut self, post: &Posterior, n: usize) {
        let mut tape = std::mem::take(&mut self.tape);
        self.forward_tape(post, n, &mut tape);
        self.tape = tape;
    }

    /// [`Self::forward`] storing the step's intermediates in `tape` ([`tape_len`] values).
    pub(crate) fn forward_tape(&mut self, post: &Posterior, n: usize, tape: &mut [f64]) {
        let (m, d, dx) = (post.m, post.d, post.dx);
        debug_assert!(n <= self.cap);
        let t = split_tape(post, self.cap, n, tape);
        let k = &mut self.k[..m * n];
        kernel::scale_points(&self.input[..d * n], &post.inv_len, t.xs);
        let points = post.grouped(t.xs, self.input_group);
        let r = m + dx;
        let (w2, var) = (&mut self.w2, &mut self.var);
        match self.mixed.as_mut() {
            None => {
                kernel::cross_cov_grouped(points, k, t.kd, &mut self.rowsum);
                forward_product(post, k, n, t.wm);
                let h = (!post.whitened).then_some(&*k);
                write_predictive_variance(post, t.wm, r, h, n, w2, var, Some(t.quad), None);
            }
            Some(mx) => {
                // `k` holds `τ`; `K` exists only in `f32`. `mx.y` is scratch until the reverse.
                let kd = Some(&mut *t.kd);
                kernel::cross_cov_grouped_f32(points, k, &mut mx.k, kd, &mut self.rowsum);
                forward_product_f32(post, &mx.k, n, t.wm, &mut mx.wm);
                let h = (!post.whitened).then_some(&mx.k[..m * n]);
                let mixed = Some((&mut mx.y[..], &mut mx.var[..]));
                write_predictive_variance(post, t.wm, r, h, n, w2, var, Some(t.quad), mixed);
            }
        }
        for (mean, col) in self.mean[..dx * n]
            .chunks_exact_mut(dx)
            .zip(t.wm.chunks_exact(r))
        {
            mean.copy_from_slice(&col[m..]);
        }
    }

    /// Reverse mode of the last [`Self::forward`] on `n` points: given `mean_bar`, `var_bar`
    /// (column-major `D_x × N`), accumulates parameter adjoints into `grads` and adds
    /// `∂loss/∂x` of the state part of the inputs into `xbar` (`D_x × N`). `var_bar` is
    /// read only. Allocates nothing.
    pub fn backward(
        &mut self,
        post: &Posterior,
        n: usize,
        mean_bar: &[f64],
        var_bar: &[f64],
        grads: &mut ConditionalGrads,
        xbar: &mut [f64],
    ) {
        let mut tape = std::mem::take(&mut self.tape);
        self.backward_tape(post, n, &mut tape, mean_bar, var_bar, grads, xbar);
        self.tape = tape;
    }

    /// [`Self::backward`] from the intermediates a [`Self::forward_tape`] stored in `tape`
    /// (the formulas of the module doc).
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn backward_tape(
        &mut self,
        post: &Posterior,
        n: usize,
        tape: &mut [f64],
        mean_bar: &[f64],
        var_bar: &[f64],
        grads: &mut ConditionalGrads,
        xbar: &mut [f64],
    ) {
        let (m, dx) = (post.m, post.dx);
        let r = m + dx;
        let t = split_tape(post, self.cap, n, tape);
        // `wm` holds `[W; μ]` (column stride `r`); `self.wbar` becomes `[P; μ̄]`, then `[A; μ̄]`.
        let wm = &*t.wm;
        let w_view = view(wm, r, n).subrows(0, m);
        let wbar = &mut self.wbar[..r * n];
        for (col, mb) in wbar.chunks_exact_mut(r).zip(mean_bar.chunks_exact(dx)) {
            col[m..].copy_from_slice(mb);
        }
        // β̄ = Σ_d σ̄²_d, the adjoint of the prior term σ_f² − Σ H⊙W.
        for (j, vb) in var_bar[..dx * n].chunks_exact(dx).enumerate() {
            let bb: f64 = vb.iter().sum();
            self.base_bar[j] = bb;
            grads.variance += bb;
        }
        let kbar = &mut self.kbar[..m * n];
        let whitened = post.whitened;
        match (post.cov, self.mixed.as_mut()) {
            (CovarianceStructure::Diagonal, Some(mx)) => {
                // As below, the three D_x-row products in f32 (S, σ̄², W⊙W ≥ 0 or of one sign).
                round_into(&var_bar[..dx * n], &mut mx.var);
                gemm(
                    view_mut(&mut mx.y, m, n),
                    Accum::Replace,
                    view(&post.q_cov32, dx, m).transpose(),
                    view(&mx.var, dx, n),
                    1.0,
                );
                let cols = mx.k[..m * n]
                    .chunks_exact_mut(m)
                    .zip(wbar.chunks_exact_mut(r))
                    .zip(mx.y.chunks_exact(m))
                    .zip(wm.chunks_exact(r))
                    .zip(&self.base_bar[..n]);
                for ((((w2, pc), vc), wc), &bb) in cols {
                    let (pc, wc) = (&mut pc[..m], &wc[..m]);
                    let s = -2.0 * bb;
                    for (((w2, p), &v), &wv) in w2.iter_mut().zip(pc.iter_mut()).zip(vc).zip(wc) {
                        *w2 = f32_operand(wv * wv);
                        *p = 2.0 * wv * f64::from(v);
                        if whitened {
                            *p += s * wv;
                        }
                    }
                }
                gemm(
                    view_mut(&mut mx.q_cov_bar, dx, m),
                    Accum::Replace,
                    view(&mx.var, dx, n),
                    view(&mx.k, m, n).transpose(),
                    1.0,
                );
                widen_into(&mx.q_cov_bar, &mut grads.q_cov, Accum::Add);
            }
            (CovarianceStructure::Diagonal, None) => {
                // `V = Sᵀσ̄²`, then one pass: `W⊙W` and `P = 2 W⊙V` (whitened: `− 2β̄W`).
                gemm(
                    view_mut(kbar, m, n),
                    Accum::Replace,
                    view(&post.q_cov, dx, m).transpose(),
                    view(var_bar, dx, n),
                    1.0,
                );
                let cols = self.w2[..m * n]
                    .chunks_exact_mut(m)
                    .zip(wbar.chunks_exact_mut(r))
                    .zip(kbar.chunks_exact(m))
                    .zip(wm.chunks_exact(r))
                    .zip(&self.base_bar[..n]);
                for ((((w2, pc), vc), wc), &bb) in cols {
                    let (pc, wc) = (&mut pc[..m], &wc[..m]);
                    let s = -2.0 * bb;
                    for (((w2, p), &v), &wv) in w2.iter_mut().zip(pc.iter_mut()).zip(vc).zip(wc) {
                        *w2 = wv * wv;
                        *p = 2.0 * wv * v;
                        if whitened {
                            *p += s * wv;
                        }
                    }
                }
                gemm(
                    view_mut(&mut grads.q_cov, dx, m),
                    Accum::Add,
                    view(var_bar, dx, n),
                    view(&self.w2, m, n).transpose(),
                    1.0,
                );
            }
            (CovarianceStructure::Full, _) => {
                for col in wbar.chunks_exact_mut(r) {
                    col[..m].fill(0.0);
                }
                for dd in 0..dx {
                    let ld = &post.q_cov[dd * m * m..(dd + 1) * m * m];
                    gemm(
                        view_mut(&mut self.w2, m, n),
                        Accum::Replace,
                        view(ld, m, m).transpose(),
                        w_view,
                        1.0,
                    );
                    for j in 0..n {
                        let s = 2.0 * var_bar[j * dx + dd];
                        for v in &mut self.w2[j * m..(j + 1) * m] {
                            *v *= s;
                        }
                    }
                    gemm(
                        view_mut(wbar, r, n).subrows_mut(0, m),
                        Accum::Add,
                        view(ld, m, m),
                        view(&self.w2, m, n),
                        1.0,
                    );
                    let gl = &mut grads.q_cov[dd * m * m..(dd + 1) * m * m];
                    gemm(
                        view_mut(gl, m, m),
                        Accum::Add,
                        w_view,
                        view(&self.w2, m, n).transpose(),
                        1.0,
                    );
                }
                if whitened {
                    for ((pc, wc), &bb) in wbar
                        .chunks_exact_mut(r)
                        .zip(wm.chunks_exact(r))
                        .zip(&self.base_bar[..n])
                    {
                        let s = -2.0 * bb;
                        pc[..m]
                            .iter_mut()
                            .zip(&wc[..m])
                            .for_each(|(p, &wv)| *p += s * wv);
                    }
                }
            }
        }
        // Y = [G; mᵀG]ᵀ [P; μ̄]; then A (into the top rows of `wbar`) and K̄ (into `kbar`).
        match self.mixed.as_mut() {
            None => gemm(
                view_mut(kbar, m, n),
                Accum::Replace,
                post.g_mean().transpose(),
                view(wbar, r, n),
                1.0,
            ),
            Some(mx) => {
                round_into(wbar, &mut mx.wbar);
                gemm(
                    view_mut(&mut mx.y, m, n),
                    Accum::Replace,
                    post.g_mean32().transpose(),
                    view(&mx.wbar, r, n),
                    1.0,
                );
                widen_into(&mx.y[..m * n], kbar, Accum::Replace);
            }
        }
        let cols = wbar
            .chunks_exact_mut(r)
            .zip(kbar.chunks_exact_mut(m))
            .zip(wm.chunks_exact(r))
            .zip(&self.base_bar[..n]);
        for (((ac, kc), wc), &bb) in cols {
            let (ac, wc) = (&mut ac[..m], &wc[..m]);
            if whitened {
                ac.copy_from_slice(kc);
            } else {
                for ((a, kb), &wv) in ac.iter_mut().zip(kc.iter_mut()).zip(wc) {
                    *a = *kb - bb * wv;
                    *kb = *a - bb * wv;
                }
            }
        }
        // [B; m̄ᵀ] += [A; μ̄] Wᵀ.
        match self.mixed.as_mut() {
            None => gemm(
                view_mut(&mut grads.gbar, r, m),
                Accum::Add,
                view(wbar, r, n),
                w_view.transpose(),
                1.0,
            ),
            Some(mx) => {
                round_into(wbar, &mut mx.wbar);
                round_into(wm, &mut mx.wm);
                gemm(
                    view_mut(&mut mx.gbar, r, m),
                    Accum::Replace,
                    view(&mx.wbar, r, n),
                    view(&mx.wm, r, n).subrows(0, m).transpose(),
                    1.0,
                );
                widen_into(&mx.gbar, &mut grads.gbar, Accum::Add);
            }
        }
        // ∂/∂σ_f² through K = σ_f² g: Σ K̄⊙K / σ_f², with Σ K̄⊙K = Σ μ̄⊙μ + 2 Σ σ̄²⊙(σ² − σ_f²).
        let mut euler = 0.0;
        for (((mb, col), vb), q) in mean_bar
            .chunks_exact(dx)
            .zip(wm.chunks_exact(r))
            .zip(var_bar.chunks_exact(dx))
            .zip(t.quad.chunks_exact(dx))
        {
            euler += dot(mb, &col[m..]) + 2.0 * dot(vb, q);
        }
        grads.variance += euler / post.variance;
        // C = K̄ ⊙ σ_f² g'.
        kbar.iter_mut().zip(&*t.kd).for_each(|(c, &g)| *c *= g);
        kernel::cross_cov_backward(
            kbar,
            &post.zt,
            t.xs,
            &post.inv_len,
            dx,
            &mut grads.zbar_t,
            &mut xbar[..dx * n],
            &mut grads.len_acc,
            &mut self.cx,
            &mut self.zc[..post.d * n],
            &mut self.rowsum,
        );
    }
}
