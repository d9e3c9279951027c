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
//! memory traffic, which is the largest cost of a step outside the products. Under mixed
//! precision the tape keeps `σ_f² eˣ` (`σ_f² g' = c′ σ_f² eˣ`) and `[W; μ]` in the `f32` the
//! shape and the product formed them in, and the reverse mode widens them exactly as it reads
//! them: the same values at half their traffic.

mod predictive;
mod workspace;

pub use workspace::{ConditionalGrads, ConditionalWorkspace, tape_len};

use faer::traits::ComplexField;
use faer::{Accum, MatRef};

use crate::kernel::{self, GroupedPoints, KernelKind};
use crate::linalg::{
    cholesky_backward, cholesky_in_place, f32_operand, gemm, lower_inverse, view, view_mut,
};
use crate::objective::ObjectiveError;
use crate::params::{CovarianceStructure, ModelConfig, Parametrization, Params};
use crate::precision::Precision;

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
    /// `[G; mᵀG]` rounded to `f32` under [`Precision::Mixed`]; empty under [`Precision::F64`].
    pub(crate) g_mean32: Vec<f32>,
    /// Diagonal `S` (row-major `M × D_x`) rounded to `f32` under [`Precision::Mixed`]; empty
    /// otherwise and for full `S`.
    pub(crate) q_cov32: Vec<f32>,
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
            g_mean32: Vec::new(),
            q_cov32: Vec::new(),
            q_cov: params.q_cov.clone(),
            cov: config.covariance,
            whitened,
        })
    }

    /// The kernel's operands for the scaled points `xs` (`D × N`) whose consecutive groups of
    /// `group` share the input part `u` (rows `D_x..D`).
    pub(crate) fn grouped<'a>(&'a self, xs: &'a [f64], group: usize) -> GroupedPoints<'a> {
        GroupedPoints {
            kind: self.kind,
            variance: self.variance,
            tau_jitter: self.tau_jitter,
            zt: &self.zt,
            xs,
            d: self.d,
            shared_from: self.dx,
            group: group.max(1),
        }
    }

    /// `[G; mᵀG]` (`(M + D_x) × M`).
    #[inline]
    pub(crate) fn g_mean(&self) -> MatRef<'_, f64> {
        view(&self.g_mean, self.m + self.dx, self.m)
    }

    /// Sets the precision of the large products of the workspaces that use this cache
    /// ([`Precision::Mixed`] rounds `[G; mᵀG]` to `f32` here, once).
    pub fn set_precision(&mut self, precision: Precision) {
        let round = |v: &[f64]| v.iter().map(|&x| f32_operand(x)).collect();
        let mixed = precision == Precision::Mixed;
        self.g_mean32 = if mixed {
            round(&self.g_mean)
        } else {
            Vec::new()
        };
        self.q_cov32 = if mixed && self.cov == CovarianceStructure::Diagonal {
            round(&self.q_cov)
        } else {
            Vec::new()
        };
    }

    /// The precision set by [`Self::set_precision`].
    pub fn precision(&self) -> Precision {
        if self.g_mean32.is_empty() {
            Precision::F64
        } else {
            Precision::Mixed
        }
    }

    /// `[G; mᵀG]` in `f32` (`(M + D_x) × M`; empty unless mixed).
    #[inline]
    pub(crate) fn g_mean32(&self) -> MatRef<'_, f32> {
        view(&self.g_mean32, self.m + self.dx, self.m)
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

/// The forward product `[W; μ] = [G; mᵀG] K` of `n` points into `wm` (`(M + D_x) × N`), in
/// `f64`.
pub(crate) fn forward_product(post: &Posterior, k: &[f64], n: usize, wm: &mut [f64]) {
    stacked_product(post.g_mean(), k, n, wm);
}

/// [`forward_product`] in `f32` for a mixed posterior ([`crate::precision`]), from the `f32`
/// kernel `k32` (`M × N`) into `wm32` (`(M + D_x) × N`). Allocates nothing.
pub(crate) fn forward_product_f32(post: &Posterior, k32: &[f32], n: usize, wm32: &mut [f32]) {
    stacked_product(post.g_mean32(), k32, n, wm32);
}

/// `out = [G; mᵀG] K` for the first `n` columns of `k` (`M × N`), in `f64` or `f32`.
fn stacked_product<T: ComplexField + From<f32>>(
    g_mean: MatRef<'_, T>,
    k: &[T],
    n: usize,
    out: &mut [T],
) {
    let (r, m) = (g_mean.nrows(), g_mean.ncols());
    gemm(
        view_mut(out, r, n),
        Accum::Replace,
        g_mean,
        view(k, m, n),
        T::from(1.0),
    );
}
