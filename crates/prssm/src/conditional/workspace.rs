//! The training conditional: the forward pass of a batch of points with the tape the reverse
//! mode reads, and the reverse pass into [`ConditionalGrads`].

use faer::Accum;

use faer::MatRef;

use super::predictive::{
    add_base_variance, uses_f32_quadratic_term, write_quadratic_term, write_quadratic_term_f32,
};
use super::{Posterior, forward_product, forward_product_f32};
use crate::kernel;
use crate::linalg::{dot, f32_operand, gemm, round_into, view, view_mut, widen_into};
use crate::params::CovarianceStructure;
use crate::precision::Precision;

/// Per-step values kept for the reverse mode, in one slice of [`tape_len`] `f64` slots: the
/// scaled inputs `X̃` (`D × N`) and `σ² − σ_f²` (`D_x × N`) in `f64`, then the kernel's
/// derivative and `[W; μ]` (`(M + D_x) × N`) in the precision that formed them.
struct Tape<'a> {
    xs: &'a mut [f64],
    quad: &'a mut [f64],
    values: TapeValues<'a>,
}

enum TapeValues<'a> {
    /// `σ_f² g'` (`M × N`) and `[W; μ]`.
    F64 {
        kd: &'a mut [f64],
        wm: &'a mut [f64],
    },
    /// Mixed precision: `σ_f² eˣ` (`M × N`, with `σ_f² g' = c' σ_f² eˣ`,
    /// [`kernel::shape_slope`]) and `[W; μ]` as the `f32` shape and product gave them. The
    /// reverse mode reads their exact widenings, at half the memory traffic of `f64` copies.
    F32 {
        scaled_exp: &'a mut [f32],
        wm: &'a mut [f32],
    },
}

/// `f64` slots per step of the tape of a batch of `capacity` points.
pub fn tape_len(post: &Posterior, capacity: usize) -> usize {
    let (f64_rows, value_rows) = (post.d + post.dx, 2 * post.m + post.dx);
    match post.precision() {
        Precision::F64 => (f64_rows + value_rows) * capacity,
        Precision::Mixed => f64_rows * capacity + (value_rows * capacity).div_ceil(2),
    }
}

fn split_tape<'a>(post: &Posterior, cap: usize, n: usize, tape: &'a mut [f64]) -> Tape<'a> {
    let (d, m, dx, r) = (post.d, post.m, post.dx, post.m + post.dx);
    let (xs, rest) = tape.split_at_mut(d * cap);
    let (quad, rest) = rest.split_at_mut(dx * cap);
    let values = match post.precision() {
        Precision::F64 => {
            let (kd, wm) = rest.split_at_mut(m * cap);
            TapeValues::F64 {
                kd: &mut kd[..m * n],
                wm: &mut wm[..r * n],
            }
        }
        Precision::Mixed => {
            let (e, wm) = bytemuck::cast_slice_mut::<f64, f32>(rest).split_at_mut(m * cap);
            TapeValues::F32 {
                scaled_exp: &mut e[..m * n],
                wm: &mut wm[..r * n],
            }
        }
    };
    Tape {
        xs: &mut xs[..d * n],
        quad: &mut quad[..dx * n],
        values,
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
    /// `K` (`M × N`); in the reverse pass, the operands `W⊙W`.
    k: Vec<f32>,
    /// `W` as a product operand (`M × N`, reverse pass).
    w: Vec<f32>,
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
            w: vec![0.0; m * n],
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
        let var = &mut self.var[..dx * n];
        match (self.mixed.as_mut(), t.values) {
            (None, TapeValues::F64 { kd, wm }) => {
                kernel::cross_cov_grouped(points, k, kd, &mut self.rowsum);
                forward_product(post, k, n, wm);
                write_quadratic_term(post, wm, r, n, &mut self.w2, var);
                let h = (!post.whitened).then_some(&*k);
                add_base_variance(post, wm, r, h, n, var, Some(t.quad));
                copy_means(wm, m, dx, &mut self.mean[..dx * n]);
            }
            (Some(mx), TapeValues::F32 { scaled_exp, wm }) => {
                // `k` holds `τ`; `K` exists only in `f32`. `mx.y` is scratch until the reverse.
                let e = Some(&mut *scaled_exp);
                kernel::cross_cov_grouped_f32(points, k, &mut mx.k, e, &mut self.rowsum);
                forward_product_f32(post, &mx.k, n, wm);
                if uses_f32_quadratic_term(post) {
                    write_quadratic_term_f32(post, wm, r, n, &mut mx.y, &mut mx.var, var);
                } else {
                    // Full `S`: its `f64` products read `W` widened (`kbar` is free until the
                    // reverse pass).
                    let w = &mut self.kbar[..m * n];
                    widen_rows(wm, r, m, w);
                    write_quadratic_term(post, w, m, n, &mut self.w2, var);
                }
                let h = (!post.whitened).then_some(&mx.k[..m * n]);
                add_base_variance(post, wm, r, h, n, var, Some(t.quad));
                copy_means(wm, m, dx, &mut self.mean[..dx * n]);
            }
            _ => unreachable!("the tape and the workspace follow the posterior's precision"),
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
        let adjoints = (mean_bar, var_bar);
        self.backward_tape(post, n, &mut tape, adjoints, grads, (xbar, post.dx));
        self.tape = tape;
    }

    /// [`Self::backward`] that adds `∂loss/∂[x; u]` of all `D = D_x + D_u` GP inputs into
    /// `xbar` (`D × N`, the layout of [`Self::input`]): the sensitivity of the conditional to
    /// its inputs as well as its states. Allocates nothing.
    pub fn backward_all_inputs(
        &mut self,
        post: &Posterior,
        n: usize,
        mean_bar: &[f64],
        var_bar: &[f64],
        grads: &mut ConditionalGrads,
        xbar: &mut [f64],
    ) {
        let mut tape = std::mem::take(&mut self.tape);
        let adjoints = (mean_bar, var_bar);
        self.backward_tape(post, n, &mut tape, adjoints, grads, (xbar, post.d));
        self.tape = tape;
    }

    /// [`Self::backward`] from the intermediates a [`Self::forward_tape`] stored in `tape`
    /// (the formulas of the module doc); the adjoints of the first `rows` GP inputs (`D_x`:
    /// the states; `D`: states and inputs) are added into `xbar` (`rows × N`).
    pub(crate) fn backward_tape(
        &mut self,
        post: &Posterior,
        n: usize,
        tape: &mut [f64],
        (mean_bar, var_bar): (&[f64], &[f64]),
        grads: &mut ConditionalGrads,
        (xbar, rows): (&mut [f64], usize),
    ) {
        let (m, dx) = (post.m, post.dx);
        let r = m + dx;
        let t = split_tape(post, self.cap, n, tape);
        let (mean_bar, var_bar) = (&mean_bar[..dx * n], &var_bar[..dx * n]);
        // β̄ = Σ_d σ̄²_d, the adjoint of the prior term σ_f² − Σ H⊙W.
        for (j, vb) in var_bar.chunks_exact(dx).enumerate() {
            let bb: f64 = vb.iter().sum();
            self.base_bar[j] = bb;
            grads.variance += bb;
        }
        let base_bar = &self.base_bar[..n];
        let kbar = &mut self.kbar[..m * n];
        let wbar = &mut self.wbar[..r * n];
        let whitened = post.whitened;
        // `kbar` becomes K̄, then C = K̄ ⊙ σ_f² g' (the adjoint of τ).
        let euler = match (self.mixed.as_mut(), t.values) {
            (None, TapeValues::F64 { kd, wm }) => {
                // `wbar` becomes [P; μ̄], then [A; μ̄].
                copy_mean_adjoint(mean_bar, m, dx, wbar);
                match post.cov {
                    CovarianceStructure::Diagonal => {
                        // V = Sᵀσ̄², then one pass: W⊙W and P = 2 W⊙V (whitened: − 2β̄W).
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
                            .zip(base_bar);
                        for ((((w2, pc), vc), wc), &bb) in cols {
                            let (pc, wc) = (&mut pc[..m], &wc[..m]);
                            let s = -2.0 * bb;
                            let terms = w2.iter_mut().zip(pc.iter_mut()).zip(vc).zip(wc);
                            for (((w2, p), &v), &wv) in terms {
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
                    CovarianceStructure::Full => {
                        let w = view(wm, r, n).subrows(0, m);
                        full_cov_adjoint(post, w, var_bar, base_bar, wbar, &mut self.w2, grads);
                    }
                }
                // Y = [G; mᵀG]ᵀ [P; μ̄]; then A (into the top rows of `wbar`) and K̄.
                gemm(
                    view_mut(kbar, m, n),
                    Accum::Replace,
                    post.g_mean().transpose(),
                    view(wbar, r, n),
                    1.0,
                );
                let cols = wbar
                    .chunks_exact_mut(r)
                    .zip(kbar.chunks_exact_mut(m))
                    .zip(wm.chunks_exact(r))
                    .zip(base_bar);
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
                gemm(
                    view_mut(&mut grads.gbar, r, m),
                    Accum::Add,
                    view(wbar, r, n),
                    view(wm, r, n).subrows(0, m).transpose(),
                    1.0,
                );
                kbar.iter_mut().zip(&*kd).for_each(|(c, &g)| *c *= g);
                euler_sum(mean_bar, var_bar, wm, m, dx, t.quad)
            }
            (Some(mx), TapeValues::F32 { scaled_exp, wm }) => {
                // `mx.wbar` becomes the operands [P; μ̄], then [A; μ̄].
                match post.cov {
                    CovarianceStructure::Diagonal => {
                        // As above, the three D_x-row products in f32 (S, σ̄², W⊙W ≥ 0 or of
                        // one sign), and P and W⊙W rounded as they are formed.
                        round_into(var_bar, &mut mx.var);
                        gemm(
                            view_mut(&mut mx.y, m, n),
                            Accum::Replace,
                            view(&post.q_cov32, dx, m).transpose(),
                            view(&mx.var, dx, n),
                            1.0,
                        );
                        let cols = mx.k[..m * n]
                            .chunks_exact_mut(m)
                            .zip(mx.wbar.chunks_exact_mut(r))
                            .zip(mx.y.chunks_exact(m))
                            .zip(wm.chunks_exact(r))
                            .zip(mean_bar.chunks_exact(dx))
                            .zip(base_bar);
                        for (((((w2, pc), vc), wc), mb), &bb) in cols {
                            let (pc, mc) = pc.split_at_mut(m);
                            round_into(mb, mc);
                            let s = -2.0 * bb;
                            let terms = w2.iter_mut().zip(pc).zip(vc).zip(&wc[..m]);
                            for (((w2, p), &v), &w) in terms {
                                let wv = f64::from(w);
                                *w2 = f32_operand(wv * wv);
                                let mut pv = 2.0 * wv * f64::from(v);
                                if whitened {
                                    pv += s * wv;
                                }
                                *p = f32_operand(pv);
                            }
                        }
                        add_product_f32(
                            &mut grads.q_cov,
                            &mut mx.q_cov_bar,
                            view(&mx.var, dx, n),
                            view(&mx.k, m, n).transpose(),
                        );
                    }
                    CovarianceStructure::Full => {
                        // Its `f64` products read `W` widened (`k` is free in the reverse pass).
                        let w = &mut self.k[..m * n];
                        widen_rows(wm, r, m, w);
                        copy_mean_adjoint(mean_bar, m, dx, wbar);
                        let w = view(w, m, n);
                        full_cov_adjoint(post, w, var_bar, base_bar, wbar, &mut self.w2, grads);
                        round_into(wbar, &mut mx.wbar);
                    }
                }
                // Y in f32; then one pass: A and W as operands, and C = K̄ ⊙ σ_f² g'.
                gemm(
                    view_mut(&mut mx.y, m, n),
                    Accum::Replace,
                    post.g_mean32().transpose(),
                    view(&mx.wbar, r, n),
                    1.0,
                );
                let slope = kernel::shape_slope(post.kind);
                let cols = mx
                    .wbar
                    .chunks_exact_mut(r)
                    .zip(mx.w.chunks_exact_mut(m))
                    .zip(kbar.chunks_exact_mut(m))
                    .zip(mx.y.chunks_exact(m))
                    .zip(wm.chunks_exact(r))
                    .zip(scaled_exp.chunks_exact(m))
                    .zip(base_bar);
                for ((((((ac, wo), cc), yc), wc), ec), &bb) in cols {
                    let terms = ac.iter_mut().zip(wo).zip(cc).zip(yc).zip(wc).zip(ec);
                    for (((((a, wo), c), &y), &w), &e) in terms {
                        let (wv, kb) = (f64::from(w), f64::from(y));
                        let (av, kb) = if whitened {
                            (kb, kb)
                        } else {
                            let av = kb - bb * wv;
                            (av, av - bb * wv)
                        };
                        *a = f32_operand(av);
                        *wo = f32_operand(wv);
                        *c = kb * (slope * f64::from(e));
                    }
                }
                add_product_f32(
                    &mut grads.gbar,
                    &mut mx.gbar,
                    view(&mx.wbar, r, n),
                    view(&mx.w, m, n).transpose(),
                );
                euler_sum(mean_bar, var_bar, wm, m, dx, t.quad)
            }
            _ => unreachable!("the tape and the workspace follow the posterior's precision"),
        };
        // ∂/∂σ_f² through K = σ_f² g: Σ K̄⊙K / σ_f².
        grads.variance += euler / post.variance;
        kernel::cross_cov_backward(
            kbar,
            &post.zt,
            t.xs,
            &post.inv_len,
            rows,
            &mut grads.zbar_t,
            &mut xbar[..rows * n],
            &mut grads.len_acc,
            &mut self.cx,
            &mut self.zc[..post.d * n],
            &mut self.rowsum,
        );
    }
}

/// `sums += a b` (column-major, `a.nrows() × b.ncols()`): the product formed in `f32` into
/// `product`, then widened and added to the `f64` sums.
fn add_product_f32(sums: &mut [f64], product: &mut [f32], a: MatRef<'_, f32>, b: MatRef<'_, f32>) {
    let len = a.nrows() * b.ncols();
    let out = view_mut(&mut product[..len], a.nrows(), b.ncols());
    gemm(out, Accum::Replace, a, b, 1.0);
    widen_into(&product[..len], sums, Accum::Add);
}

/// The means `μ` (the bottom `D_x` rows of `[W; μ]`, column stride `M + D_x`) into `mean`
/// (`D_x × N`).
fn copy_means<W: Copy + Into<f64>>(wm: &[W], m: usize, dx: usize, mean: &mut [f64]) {
    for (mean, col) in mean.chunks_exact_mut(dx).zip(wm.chunks_exact(m + dx)) {
        mean.iter_mut()
            .zip(&col[m..])
            .for_each(|(a, &b)| *a = b.into());
    }
}

/// The first `rows` rows of `src` (column stride `stride`) widened into `dst`
/// (column-major `rows × N`).
fn widen_rows(src: &[f32], stride: usize, rows: usize, dst: &mut [f64]) {
    for (d, s) in dst.chunks_exact_mut(rows).zip(src.chunks_exact(stride)) {
        widen_into(&s[..rows], d, Accum::Replace);
    }
}

/// `μ̄` (`D_x × N`) into the bottom rows of `wbar` (`(M + D_x) × N`).
fn copy_mean_adjoint(mean_bar: &[f64], m: usize, dx: usize, wbar: &mut [f64]) {
    for (col, mb) in wbar.chunks_exact_mut(m + dx).zip(mean_bar.chunks_exact(dx)) {
        col[m..].copy_from_slice(mb);
    }
}

/// `Σ K̄⊙K = Σ μ̄⊙μ + 2 Σ σ̄²⊙(σ² − σ_f²)` (`μ` linear, `σ² − σ_f²` quadratic in `K`), with
/// `μ` the bottom rows of `[W; μ]` and `quad = σ² − σ_f²` from the tape.
fn euler_sum<W: Copy + Into<f64>>(
    mean_bar: &[f64],
    var_bar: &[f64],
    wm: &[W],
    m: usize,
    dx: usize,
    quad: &[f64],
) -> f64 {
    let mut euler = 0.0;
    for (((mb, col), vb), q) in mean_bar
        .chunks_exact(dx)
        .zip(wm.chunks_exact(m + dx))
        .zip(var_bar.chunks_exact(dx))
        .zip(quad.chunks_exact(dx))
    {
        euler += dot(mb, &col[m..]) + 2.0 * dot(vb, q);
    }
    euler
}

/// Full `S = L_d L_dᵀ`: `P = Σ_d 2σ̄²_d L_d L_dᵀ W` (whitened: `− 2β̄W`) into the top rows
/// of `wbar` and `∂/∂L_d += W (2σ̄²_d ⊙ L_dᵀW)ᵀ`, from `W` (`M × N`); `w2` (`M × N`) is
/// scratch.
fn full_cov_adjoint(
    post: &Posterior,
    w: MatRef<'_, f64>,
    var_bar: &[f64],
    base_bar: &[f64],
    wbar: &mut [f64],
    w2: &mut [f64],
    grads: &mut ConditionalGrads,
) {
    let (m, dx, n) = (post.m, post.dx, w.ncols());
    let r = m + dx;
    for col in wbar.chunks_exact_mut(r) {
        col[..m].fill(0.0);
    }
    for dd in 0..dx {
        let ld = &post.q_cov[dd * m * m..(dd + 1) * m * m];
        gemm(
            view_mut(w2, m, n),
            Accum::Replace,
            view(ld, m, m).transpose(),
            w,
            1.0,
        );
        for j in 0..n {
            let s = 2.0 * var_bar[j * dx + dd];
            for v in &mut w2[j * m..(j + 1) * m] {
                *v *= s;
            }
        }
        gemm(
            view_mut(wbar, r, n).subrows_mut(0, m),
            Accum::Add,
            view(ld, m, m),
            view(w2, m, n),
            1.0,
        );
        let gl = &mut grads.q_cov[dd * m * m..(dd + 1) * m * m];
        gemm(
            view_mut(gl, m, m),
            Accum::Add,
            w,
            view(w2, m, n).transpose(),
            1.0,
        );
    }
    if post.whitened {
        for (j, (pc, &bb)) in wbar.chunks_exact_mut(r).zip(base_bar).enumerate() {
            let s = -2.0 * bb;
            for (i, p) in pc[..m].iter_mut().enumerate() {
                *p += s * w[(i, j)];
            }
        }
    }
}
