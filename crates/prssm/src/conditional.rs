//! The sparse-GP conditional `f(X) | q(u)` of all latent dims at a batch of `N` points, and
//! its reverse mode. [`Posterior`] caches what depends only on the parameters (the Cholesky
//! factor `L` of `K_mm + jitter·I`, the projection `G`, scaled `Z`); a
//! [`ConditionalWorkspace`] holds the per-batch buffers.
//!
//! With `K = K_mn` (`M × N`) and `W = G K`, where `G = (K_mm + jitter·I)⁻¹ = L⁻ᵀL⁻¹`
//! (unwhitened) or `G = L⁻¹` (whitened):
//!
//! ```text
//! μ_d(x_n)  = Σ_m m_{md} W_{mn}
//! σ²_d(x_n) = σ_f² − Σ_m H_{mn} W_{mn} + Σ_m S_{md} W_{mn}²      (diagonal S)
//!           = σ_f² − Σ_m H_{mn} W_{mn} + ‖L_dᵀ W_{:n}‖²            (full S = L_d L_dᵀ)
//! ```
//! with `H = K` (unwhitened: `Σ K⊙W = kᵀ(K_mm)⁻¹k`) or `H = W` (whitened: `Σ W² = ‖L⁻¹k‖²`).
//! Cost per batch: `O(M D N)` kernel and one `(M + D_x) × M × N` product `[W; μ] = [G; mᵀG] K`.
//!
//! Reverse mode. With `β̄ = Σ_d σ̄²_d` and `P` the variance terms (`2 W ⊙ (Sᵀσ̄²)` for diagonal
//! `S`, `Σ_d 2σ̄²_d L_d L_dᵀ W` for full `S`; whitened, also `− 2β̄W`), the adjoint of `W` is
//! `W̄ = m μ̄ + P` (unwhitened: `− β̄K` more, and `K̄` gets `− β̄W` directly). Then
//!
//! ```text
//! Y = [G; mᵀG]ᵀ [P; μ̄]                            (= Gᵀ(m μ̄ + P))
//! unwhitened: A = G W̄ = Y − β̄W, K̄ = A − β̄W        (G symmetric and G K = W)
//! whitened:   A = K̄ = GᵀW̄ = Y
//! [B; m̄ᵀ] += [A; μ̄] Wᵀ                             (Ḡ = W̄Kᵀ: −G Ḡ G = −A Wᵀ, Gᵀ Ḡ Gᵀ = K̄ Wᵀ)
//! Σ K̄⊙K = Σ μ̄⊙μ + 2 Σ σ̄²⊙(σ² − σ_f²)              (μ is linear, σ² − σ_f² quadratic in K)
//! ```
//!
//! Once per evaluation `B` (`M × M`) becomes `K̄_mm = −B` (unwhitened) or `L̄ = −tril(B)` and
//! the Cholesky adjoint (whitened) in `Posterior::kmm_grad`. The reverse mode never reads
//! `K`, so the tape holds `X̃`, `σ_f² g'`, `[W; μ]` and `σ² − σ_f²` but not `K`: a quarter less
//! memory traffic, which is the largest cost of a step outside the products.

use faer::{Accum, MatRef};

use crate::kernel::{self, KernelKind};
use crate::linalg::{
    cholesky_backward, cholesky_in_place, dot, gemm, lower_inverse, view, view_mut,
};
use crate::objective::ObjectiveError;
use crate::params::{CovarianceStructure, ModelConfig, Parametrization, Params};

/// Parameter-only quantities of the conditional, computed once per evaluation.
#[derive(Debug, Clone)]
pub struct Posterior {
    pub(crate) kind: KernelKind,
    pub(crate) variance: f64,
    pub(crate) tau_jitter: f64,
    pub(crate) m: usize,
    pub(crate) d: usize,
    pub(crate) dx: usize,
    pub(crate) inv_len: Vec<f64>,
    /// Scaled inducing inputs, dimension-major `D·M`.
    pub(crate) zt: Vec<f64>,
    /// `K(Z, Z)` without jitter (`M × M`).
    pub(crate) kmm: Vec<f64>,
    /// `σ_f² g'(τ(Z, Z))` (`M × M`).
    pub(crate) kmm_kd: Vec<f64>,
    /// Lower Cholesky factor of `K_mm + jitter·I`.
    pub(crate) l: Vec<f64>,
    /// `[G; mᵀG]`, column-major `(M + D_x) × M`, with `G = (K_mm + jitter·I)⁻¹` (unwhitened)
    /// or `L⁻¹` (whitened).
    pub(crate) g_mean: Vec<f64>,
    /// Diagonal: row-major `M × D_x`; full: `D_x` column-major `M × M` factors.
    pub(crate) q_cov: Vec<f64>,
    pub(crate) cov: CovarianceStructure,
    pub(crate) whitened: bool,
}

impl Posterior {
    /// Builds the cache; factorizes `K_mm + jitter·I` once and forms `G`.
    ///
    /// # Errors
    /// [`ObjectiveError::NotPositiveDefinite`] when the factorization fails.
    pub fn new(config: &ModelConfig, params: &Params) -> Result<Self, ObjectiveError> {
        let (m, d) = (config.n_inducing, config.n_gp_input());
        let inv_len: Vec<f64> = params.lengthscales.iter().map(|l| 1.0 / l).collect();
        let mut zt = vec![0.0; d * m];
        kernel::scale_inducing(&params.inducing_inputs, &inv_len, &mut zt);
        let mut zs = vec![0.0; d * m];
        kernel::scale_points(&params.inducing_inputs, &inv_len, &mut zs);
        let mut kmm = vec![0.0; m * m];
        let mut kmm_kd = vec![0.0; m * m];
        kernel::cross_cov(
            config.kernel,
            params.kernel_variance,
            config.matern_tau_jitter,
            &zt,
            &zs,
            d,
            &mut kmm,
            &mut kmm_kd,
        );
        let mut l = kmm.clone();
        for i in 0..m {
            l[i * m + i] += config.kmm_jitter;
        }
        cholesky_in_place(&mut l, m).map_err(|index| ObjectiveError::NotPositiveDefinite {
            what: "K_mm",
            index,
        })?;
        let whitened = config.parametrization == Parametrization::Whitened;
        let linv = lower_inverse(&l, m);
        let g = if whitened {
            linv
        } else {
            let mut p = vec![0.0; m * m];
            gemm(
                view_mut(&mut p, m, m),
                Accum::Replace,
                view(&linv, m, m).transpose(),
                view(&linv, m, m),
                1.0,
            );
            // Exactly symmetric.
            for j in 0..m {
                for i in j + 1..m {
                    p[i * m + j] = p[j * m + i];
                }
            }
            p
        };
        let dx = config.n_state;
        let mut mg = vec![0.0; dx * m];
        gemm(
            view_mut(&mut mg, dx, m),
            Accum::Replace,
            view(&params.q_mean, dx, m),
            view(&g, m, m),
            1.0,
        );
        let mut g_mean = vec![0.0; (m + dx) * m];
        for ((col, gc), mc) in g_mean
            .chunks_exact_mut(m + dx)
            .zip(g.chunks_exact(m))
            .zip(mg.chunks_exact(dx))
        {
            col[..m].copy_from_slice(gc);
            col[m..].copy_from_slice(mc);
        }
        Ok(Self {
            kind: config.kernel,
            variance: params.kernel_variance,
            tau_jitter: config.matern_tau_jitter,
            m,
            d,
            dx,
            inv_len,
            zt,
            kmm,
            kmm_kd,
            l,
            g_mean,
            q_cov: params.q_cov.clone(),
            cov: config.covariance,
            whitened,
        })
    }

    /// `[G; mᵀG]` (`(M + D_x) × M`).
    #[inline]
    pub(crate) fn g_mean(&self) -> MatRef<'_, f64> {
        view(&self.g_mean, self.m + self.dx, self.m)
    }

    /// The lower Cholesky factor of `K_mm + jitter·I` (column-major `M × M`).
    pub fn kmm_factor(&self) -> &[f64] {
        &self.l
    }

    /// Maps `B = Σ A Wᵀ` (`M × M`, see the module doc) to `∂loss/∂K_mm` (`M × M`,
    /// column-major; every entry treated as independent): unwhitened `K̄_mm = −B`; whitened
    /// `L̄ = −tril(B)` (the adjoint of `W = L⁻¹K`), then the Cholesky adjoint.
    pub(crate) fn kmm_grad(&self, mut b: Vec<f64>) -> Vec<f64> {
        b.iter_mut().for_each(|v| *v = -*v);
        if self.whitened {
            cholesky_backward(&self.l, &mut b, self.m)
        } else {
            b
        }
    }
}

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
    /// `K` of the current step (`M × N`; not on the tape).
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
    /// Buffers for up to `capacity` points.
    pub fn new(post: &Posterior, capacity: usize) -> Self {
        let (m, d, dx, n) = (post.m, post.d, post.dx, capacity);
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
        }
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
        kernel::cross_cov_grouped(
            post.kind,
            post.variance,
            post.tau_jitter,
            &post.zt,
            t.xs,
            d,
            (dx, self.input_group.max(1)),
            k,
            t.kd,
            &mut self.rowsum,
        );
        let r = m + dx;
        gemm(
            view_mut(t.wm, r, n),
            Accum::Replace,
            post.g_mean(),
            view(k, m, n),
            1.0,
        );
        let wm = &*t.wm;
        for (mean, col) in self.mean[..dx * n]
            .chunks_exact_mut(dx)
            .zip(wm.chunks_exact(r))
        {
            mean.copy_from_slice(&col[m..]);
        }
        let h = if post.whitened { None } else { Some(&*k) };
        write_predictive_variance(post, wm, r, h, n, &mut self.w2, &mut self.var, Some(t.quad));
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
        match post.cov {
            CovarianceStructure::Diagonal => {
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
            CovarianceStructure::Full => {
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
        gemm(
            view_mut(&mut grads.gbar, r, m),
            Accum::Add,
            view(wbar, r, n),
            w_view.transpose(),
            1.0,
        );
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

/// Forward-only conditional for prediction (no derivatives, no tape). `W` and the means come
/// from one product `[W; μ] = [G; mᵀG] K` (`(M + D_x) × N`); `σ²` as in [`ConditionalWorkspace`].
#[derive(Debug, Clone)]
pub(crate) struct PredictiveWorkspace {
    cap: usize,
    group: usize,
    /// GP inputs `[x; u]`, column-major `D × N` (filled by the caller).
    pub input: Vec<f64>,
    xs: Vec<f64>,
    k: Vec<f64>,
    /// `[W; μ]`, column-major `(M + D_x) × N`.
    wm: Vec<f64>,
    w2: Vec<f64>,
    tau_shared: Vec<f64>,
    /// Variances `σ²`, column-major `D_x × N`.
    pub var: Vec<f64>,
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
        kernel::cross_cov_grouped_values(
            post.kind,
            post.variance,
            post.tau_jitter,
            &post.zt,
            &self.xs[..d * n],
            d,
            (dx, self.group),
            &mut self.k[..m * n],
            &mut self.tau_shared,
        );
        gemm(
            view_mut(&mut self.wm, r, n),
            Accum::Replace,
            post.g_mean(),
            view(&self.k, m, n),
            1.0,
        );
        let k = if post.whitened {
            None
        } else {
            Some(&self.k[..])
        };
        write_predictive_variance(post, &self.wm, r, k, n, &mut self.w2, &mut self.var, None);
    }
}

/// Writes the predictive variances of `n` points into `var` (`D_x × N`, column-major):
/// `σ²_d(n) = k** − w_nᵀh_n + Σ_i S_d,ii w_in²` (diagonal `S`) or `+ ‖L_dᵀw_n‖²` (full
/// `S_d = L_dL_dᵀ`), with `w_n` the first `M` entries of column `n` of `w` (column stride
/// `stride ≥ M`) and `h_n = k_n` (column `n` of `k`, `M × N`) or `w_n` when `k` is `None`
/// (whitened). With `quad`, also writes `σ²_d(n) − k** = Σ_i … − w_nᵀh_n` there (`D_x × N`).
/// `w2` (`M × N`) is scratch. Allocates nothing.
#[allow(clippy::too_many_arguments)]
fn write_predictive_variance(
    post: &Posterior,
    w: &[f64],
    stride: usize,
    k: Option<&[f64]>,
    n: usize,
    w2: &mut [f64],
    var: &mut [f64],
    mut quad: Option<&mut [f64]>,
) {
    let (m, dx) = (post.m, post.dx);
    let w_view = view(&w[..stride * n], stride, n).subrows(0, m);
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
    for (j, v) in var[..dx * n].chunks_exact_mut(dx).enumerate() {
        let wc = &w[j * stride..j * stride + m];
        let hc = k.map_or(wc, |k| &k[j * m..(j + 1) * m]);
        let wh = dot(wc, hc);
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::ParamInit;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The forward-only path against the module-doc formulas evaluated with naive loops:
    /// `K` from [`KernelKind::shape`], `G` from a dense Gauss–Jordan inverse of
    /// `K_mm + jitter·I` (unwhitened) or of its Cholesky factor (whitened).
    #[test]
    fn predictive_forward_matches_naive_formulas() {
        let (m, dx, du, group, n) = (9, 3, 2, 4, 8);
        let d = dx + du;
        for whitened in [false, true] {
            for cov in [CovarianceStructure::Diagonal, CovarianceStructure::Full] {
                let mut rng = ChaCha8Rng::seed_from_u64(5);
                let mut config = ModelConfig::new(dx, 1, du, m);
                config.covariance = cov;
                config.kmm_jitter = 1e-6;
                if whitened {
                    config.parametrization = Parametrization::Whitened;
                }
                let mut p = Params::init(&config, &ParamInit::default(), 3);
                p.q_mean
                    .iter_mut()
                    .for_each(|v| *v = rng.random_range(-1.0..1.0));
                p.q_cov
                    .iter_mut()
                    .for_each(|v| *v = rng.random_range(0.05..0.3));
                if cov == CovarianceStructure::Full {
                    // Lower-triangular factors L_d.
                    for (idx, v) in p.q_cov.iter_mut().enumerate() {
                        if idx % m < (idx / m) % m {
                            *v = 0.0;
                        }
                    }
                }
                let post = Posterior::new(&config, &p).unwrap();
                let mut ws = PredictiveWorkspace::new(&post, n, group);
                for c in 0..n {
                    for j in 0..d {
                        let shared = j >= dx && c % group != 0;
                        ws.input[c * d + j] = if shared {
                            ws.input[(c - c % group) * d + j]
                        } else {
                            rng.random_range(-1.5..1.5)
                        };
                    }
                }
                ws.forward(&post, n);
                let kf = |a: &[f64], b: &[f64]| {
                    let tau: f64 = (0..d)
                        .map(|j| ((a[j] - b[j]) / p.lengthscales[j]).powi(2))
                        .sum();
                    p.kernel_variance * config.kernel.shape(tau, 0.0).0
                };
                let z = &p.inducing_inputs;
                // Dense A = K_mm + jitter·I (or its factor L), inverted by Gauss–Jordan.
                let mut a = vec![vec![0.0; m]; m];
                for i in 0..m {
                    for j in 0..m {
                        a[i][j] = kf(&z[i * d..], &z[j * d..]);
                    }
                    a[i][i] += config.kmm_jitter;
                }
                if whitened {
                    let l = &post.l;
                    a = (0..m)
                        .map(|i| (0..m).map(|j| l[j * m + i]).collect())
                        .collect();
                }
                let mut g = vec![vec![0.0; m]; m];
                for (i, row) in g.iter_mut().enumerate() {
                    row[i] = 1.0;
                }
                for col in 0..m {
                    let piv = a[col][col];
                    for j in 0..m {
                        a[col][j] /= piv;
                        g[col][j] /= piv;
                    }
                    for r in 0..m {
                        if r != col {
                            let f = a[r][col];
                            for j in 0..m {
                                a[r][j] -= f * a[col][j];
                                g[r][j] -= f * g[col][j];
                            }
                        }
                    }
                }
                for c in 0..n {
                    let x = &ws.input[c * d..(c + 1) * d];
                    let k: Vec<f64> = (0..m).map(|i| kf(&z[i * d..], x)).collect();
                    let w: Vec<f64> = (0..m)
                        .map(|i| (0..m).map(|j| g[i][j] * k[j]).sum())
                        .collect();
                    let h = if whitened { &w } else { &k };
                    let base = p.kernel_variance - (0..m).map(|i| h[i] * w[i]).sum::<f64>();
                    for dd in 0..dx {
                        let mean: f64 = (0..m).map(|i| p.q_mean[i * dx + dd] * w[i]).sum();
                        let quad: f64 = match cov {
                            CovarianceStructure::Diagonal => {
                                (0..m).map(|i| p.q_cov[i * dx + dd] * w[i] * w[i]).sum()
                            }
                            CovarianceStructure::Full => {
                                let ld = &p.q_cov[dd * m * m..];
                                (0..m)
                                    .map(|j| {
                                        (j..m).map(|i| ld[j * m + i] * w[i]).sum::<f64>().powi(2)
                                    })
                                    .sum()
                            }
                        };
                        let label = format!("whitened={whitened} {cov:?} point {c} dim {dd}");
                        let got_mean = ws.mean(&post, c)[dd];
                        assert!((got_mean - mean).abs() < 1e-9, "{label}: {got_mean} {mean}");
                        let got_var = ws.var[c * dx + dd];
                        assert!(
                            (got_var - (base + quad)).abs() < 1e-9,
                            "{label}: {got_var} {}",
                            base + quad
                        );
                    }
                }
            }
        }
    }
}
