//! The sparse-GP conditional `f(X) | q(u)` of all latent dims at a batch of `N` points, and
//! its reverse mode. [`Posterior`] caches what depends only on the parameters (`L = chol(K_mm
//! + jitter·I)`, scaled `Z`); a [`ConditionalWorkspace`] holds the per-batch buffers.
//!
//! With `K = K_mn` (`M × N`), `A = L⁻¹K`, `W = L⁻ᵀA` (unwhitened) or `W = A` (whitened):
//!
//! ```text
//! μ_d(x_n)  = Σ_m m_{md} W_{mn}
//! σ²_d(x_n) = σ_f² − Σ_m A_{mn}² + Σ_m S_{md} W_{mn}²      (diagonal S)
//!           = σ_f² − Σ_m A_{mn}² + ‖L_dᵀ W_{:n}‖²            (full S = L_d L_dᵀ)
//! ```
//! Cost per batch: `O(M D N)` kernel, two (one whitened) triangular solves `M²N`.

use faer::Accum;

use crate::kernel::{self, KernelKind};
use crate::linalg::{cholesky_in_place, gemm, solve_lower, solve_lower_transpose, view, view_mut};
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
    /// `q(u)` means: row-major `M × D_x` = column-major `D_x × M`.
    pub(crate) q_mean: Vec<f64>,
    /// Diagonal: row-major `M × D_x`; full: `D_x` column-major `M × M` factors.
    pub(crate) q_cov: Vec<f64>,
    pub(crate) cov: CovarianceStructure,
    pub(crate) whitened: bool,
}

impl Posterior {
    /// Builds the cache; factorizes `K_mm + jitter·I` once.
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
        Ok(Self {
            kind: config.kernel,
            variance: params.kernel_variance,
            tau_jitter: config.matern_tau_jitter,
            m,
            d,
            dx: config.n_state,
            inv_len,
            zt,
            kmm,
            kmm_kd,
            l,
            q_mean: params.q_mean.clone(),
            q_cov: params.q_cov.clone(),
            cov: config.covariance,
            whitened: config.parametrization == Parametrization::Whitened,
        })
    }

    /// The lower Cholesky factor of `K_mm + jitter·I` (column-major `M × M`).
    pub fn kmm_factor(&self) -> &[f64] {
        &self.l
    }
}

/// Buffers of the conditional for up to `capacity` points (allocated once).
#[derive(Debug, Clone)]
pub struct ConditionalWorkspace {
    cap: usize,
    /// GP inputs `[x; u]`, column-major `D × N` (filled by the caller).
    pub input: Vec<f64>,
    xs: Vec<f64>,
    k: Vec<f64>,
    kd: Vec<f64>,
    a: Vec<f64>,
    b: Vec<f64>,
    w2: Vec<f64>,
    wbar: Vec<f64>,
    tmp: Vec<f64>,
    base_bar: Vec<f64>,
    cx: Vec<f64>,
    zc: Vec<f64>,
    rowsum: Vec<f64>,
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
    /// `∂/∂m`, row-major `M × D_x`.
    pub(crate) q_mean: Vec<f64>,
    /// `∂/∂S` or `∂/∂L_d` (layout of [`Params::q_cov`]).
    pub(crate) q_cov: Vec<f64>,
    /// `∂/∂L` of `chol(K_mm)` (full `M × M`; only the lower triangle is used).
    pub(crate) lbar: Vec<f64>,
}

impl ConditionalGrads {
    /// Zeros for `post`.
    pub fn zeros(post: &Posterior) -> Self {
        Self {
            zbar_t: vec![0.0; post.d * post.m],
            len_acc: vec![0.0; post.d],
            variance: 0.0,
            q_mean: vec![0.0; post.m * post.dx],
            q_cov: vec![0.0; post.q_cov.len()],
            lbar: vec![0.0; post.m * post.m],
        }
    }

    /// `self += other`.
    pub fn add(&mut self, o: &ConditionalGrads) {
        fn acc(a: &mut [f64], b: &[f64]) {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
        acc(&mut self.zbar_t, &o.zbar_t);
        acc(&mut self.len_acc, &o.len_acc);
        self.variance += o.variance;
        acc(&mut self.q_mean, &o.q_mean);
        acc(&mut self.q_cov, &o.q_cov);
        acc(&mut self.lbar, &o.lbar);
    }
}

impl ConditionalWorkspace {
    /// Buffers for up to `capacity` points.
    pub fn new(post: &Posterior, capacity: usize) -> Self {
        let (m, d, dx, n) = (post.m, post.d, post.dx, capacity);
        Self {
            cap: n,
            input: vec![0.0; d * n],
            xs: vec![0.0; d * n],
            k: vec![0.0; m * n],
            kd: vec![0.0; m * n],
            a: vec![0.0; m * n],
            b: if post.whitened {
                Vec::new()
            } else {
                vec![0.0; m * n]
            },
            w2: vec![0.0; m * n],
            wbar: vec![0.0; m * n],
            tmp: vec![0.0; m * n],
            base_bar: vec![0.0; n],
            cx: vec![0.0; m * d],
            zc: vec![0.0; d * n],
            rowsum: vec![0.0; m],
            mean: vec![0.0; dx * n],
            var: vec![0.0; dx * n],
        }
    }

    /// Capacity in points.
    pub fn capacity(&self) -> usize {
        self.cap
    }

    /// Computes `μ` and `σ²` at the first `n` columns of [`Self::input`] into
    /// [`Self::mean`] / [`Self::var`]. Allocates nothing.
    pub fn forward(&mut self, post: &Posterior, n: usize) {
        let (m, d, dx) = (post.m, post.d, post.dx);
        debug_assert!(n <= self.cap);
        kernel::scale_points(&self.input[..d * n], &post.inv_len, &mut self.xs[..d * n]);
        kernel::cross_cov(
            post.kind,
            post.variance,
            post.tau_jitter,
            &post.zt,
            &self.xs[..d * n],
            d,
            &mut self.k[..m * n],
            &mut self.kd[..m * n],
        );
        self.a[..m * n].copy_from_slice(&self.k[..m * n]);
        solve_lower(&post.l, m, &mut self.a, n);
        if !post.whitened {
            self.b[..m * n].copy_from_slice(&self.a[..m * n]);
            solve_lower_transpose(&post.l, m, &mut self.b, n);
        }
        let w = if post.whitened { &self.a } else { &self.b };
        gemm(
            view_mut(&mut self.mean, dx, n),
            Accum::Replace,
            view(&post.q_mean, dx, m),
            view(w, m, n),
            1.0,
        );
        for ((w2, wv), _) in self.w2[..m * n].iter_mut().zip(&w[..m * n]).zip(0..) {
            *w2 = wv * wv;
        }
        match post.cov {
            CovarianceStructure::Diagonal => gemm(
                view_mut(&mut self.var, dx, n),
                Accum::Replace,
                view(&post.q_cov, dx, m),
                view(&self.w2, m, n),
                1.0,
            ),
            CovarianceStructure::Full => {
                for dd in 0..dx {
                    let ld = &post.q_cov[dd * m * m..(dd + 1) * m * m];
                    gemm(
                        view_mut(&mut self.tmp, m, n),
                        Accum::Replace,
                        view(ld, m, m).transpose(),
                        view(w, m, n),
                        1.0,
                    );
                    for j in 0..n {
                        let s: f64 = self.tmp[j * m..(j + 1) * m].iter().map(|v| v * v).sum();
                        self.var[j * dx + dd] = s;
                    }
                }
            }
        }
        for j in 0..n {
            let s: f64 = self.a[j * m..(j + 1) * m].iter().map(|v| v * v).sum();
            let base = post.variance - s;
            for v in &mut self.var[j * dx..(j + 1) * dx] {
                *v += base;
            }
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
        let (m, dx) = (post.m, post.dx);
        let w = if post.whitened { &self.a } else { &self.b };
        // μ = mᵀ W: m̄ᵀ += μ̄ Wᵀ, W̄ = m μ̄.
        gemm(
            view_mut(&mut grads.q_mean, dx, m),
            Accum::Add,
            view(mean_bar, dx, n),
            view(w, m, n).transpose(),
            1.0,
        );
        gemm(
            view_mut(&mut self.wbar, m, n),
            Accum::Replace,
            view(&post.q_mean, dx, m).transpose(),
            view(mean_bar, dx, n),
            1.0,
        );
        match post.cov {
            CovarianceStructure::Diagonal => {
                gemm(
                    view_mut(&mut grads.q_cov, dx, m),
                    Accum::Add,
                    view(var_bar, dx, n),
                    view(&self.w2, m, n).transpose(),
                    1.0,
                );
                gemm(
                    view_mut(&mut self.tmp, m, n),
                    Accum::Replace,
                    view(&post.q_cov, dx, m).transpose(),
                    view(var_bar, dx, n),
                    1.0,
                );
                for ((wb, &t), &wv) in self.wbar[..m * n]
                    .iter_mut()
                    .zip(&self.tmp[..m * n])
                    .zip(&w[..m * n])
                {
                    *wb += 2.0 * wv * t;
                }
            }
            CovarianceStructure::Full => {
                for dd in 0..dx {
                    let ld = &post.q_cov[dd * m * m..(dd + 1) * m * m];
                    gemm(
                        view_mut(&mut self.tmp, m, n),
                        Accum::Replace,
                        view(ld, m, m).transpose(),
                        view(w, m, n),
                        1.0,
                    );
                    for j in 0..n {
                        let s = 2.0 * var_bar[j * dx + dd];
                        for v in &mut self.tmp[j * m..(j + 1) * m] {
                            *v *= s;
                        }
                    }
                    gemm(
                        view_mut(&mut self.wbar, m, n),
                        Accum::Add,
                        view(ld, m, m),
                        view(&self.tmp, m, n),
                        1.0,
                    );
                    let gl = &mut grads.q_cov[dd * m * m..(dd + 1) * m * m];
                    gemm(
                        view_mut(gl, m, m),
                        Accum::Add,
                        view(w, m, n),
                        view(&self.tmp, m, n).transpose(),
                        1.0,
                    );
                }
            }
        }
        // base = σ_f² − Σ A²: Ā = −2 A β̄.
        for j in 0..n {
            let bb: f64 = var_bar[j * dx..(j + 1) * dx].iter().sum();
            self.base_bar[j] = bb;
            grads.variance += bb;
        }
        if post.whitened {
            for j in 0..n {
                let s = -2.0 * self.base_bar[j];
                for (wb, &a) in self.wbar[j * m..(j + 1) * m]
                    .iter_mut()
                    .zip(&self.a[j * m..(j + 1) * m])
                {
                    *wb += s * a;
                }
            }
        } else {
            // W = L⁻ᵀA: C = L⁻¹W̄, Ā = C − 2Aβ̄, L̄ −= W Cᵀ.
            solve_lower(&post.l, m, &mut self.wbar, n);
            gemm(
                view_mut(&mut grads.lbar, m, m),
                Accum::Add,
                view(&self.b, m, n),
                view(&self.wbar, m, n).transpose(),
                -1.0,
            );
            for j in 0..n {
                let s = -2.0 * self.base_bar[j];
                for (wb, &a) in self.wbar[j * m..(j + 1) * m]
                    .iter_mut()
                    .zip(&self.a[j * m..(j + 1) * m])
                {
                    *wb += s * a;
                }
            }
        }
        // wbar holds Ā. A = L⁻¹K: K̄ = L⁻ᵀĀ, L̄ −= K̄ Aᵀ.
        solve_lower_transpose(&post.l, m, &mut self.wbar, n);
        gemm(
            view_mut(&mut grads.lbar, m, m),
            Accum::Add,
            view(&self.wbar, m, n),
            view(&self.a, m, n).transpose(),
            -1.0,
        );
        let inv_var = 1.0 / post.variance;
        let mut sv = 0.0;
        for ((kb, &k), &kd) in self.wbar[..m * n]
            .iter_mut()
            .zip(&self.k[..m * n])
            .zip(&self.kd[..m * n])
        {
            sv += *kb * k;
            *kb *= kd;
        }
        grads.variance += sv * inv_var;
        kernel::cross_cov_backward(
            &self.wbar[..m * n],
            &post.zt,
            &self.xs[..post.d * n],
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
