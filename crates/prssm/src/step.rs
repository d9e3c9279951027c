//! The transition step of prediction, one for batch and streaming prediction, in `f64` or
//! `f32` ([`StepFloat`]).
//!
//! For `P` particles `x_c` (`P × D_x` row-major) and one standardized input `u`:
//! `z = [x_c; u] / ℓ`, `k_m = σ_f² g(‖z − z̃_m‖²)`, `[w; μ] = [G; mᵀG] k`,
//! `σ²_d = σ_f² − wᵀh + Σ_m S_{md} w_m²` (diagonal `S`; `‖L_dᵀw‖²` for full `S`), then
//! `x_c += μ + √(σ² + σ_x² + δ) ⊙ ε` (`G = (K_mm + jitter·I)⁻¹` and `h = k`, or `G = L⁻¹` and
//! `h = w` whitened). The factorization is done once in `f64` by
//! [`Posterior::new`](crate::conditional::Posterior::new) and rounded to `T`; the draws `ε`
//! are `f64` standard normals (of the same seed in either precision), rounded.
//!
//! The product `[G; mᵀG] K` of all particles at once is faer's GEMM in `T`; the other loops
//! run over contiguous rows with independent accumulator lanes and a branch-free `exp` in
//! `f32`, so that the compiler vectorizes them. No allocation per step.

use std::fmt::Debug;
use std::iter::Sum;

use faer::linalg::matmul::matmul;
use faer::traits::RealField;
use faer::{Accum, MatMut, MatRef, Par};
use rand::Rng;
use rand_distr::{Distribution, StandardNormal};

use crate::kernel::{self, KernelKind};
use crate::linalg::F32_OPERAND_FLOOR;
use crate::objective::ObjectiveError;
use crate::params::{CovarianceStructure, ModelConfig, Params};
use crate::predict::prediction_posterior;

/// The arithmetic of a prediction step: `f64` (as training) or `f32` (flight computers whose
/// FPU has no fast double precision).
pub trait StepFloat: RealField + Copy + Default + Sum + Debug + Send + Sync + 'static {
    /// Floor of a conditional variance before `σ_x² + δ` is added: none in `f64` (as the
    /// ELBO), `0` in `f32`, whose rounding of `σ_f² − wᵀh` can cancel below zero.
    const VARIANCE_FLOOR: Self;
    /// `v` rounded to this type.
    fn of(v: f64) -> Self;
    /// This value in `f64` (exact).
    fn to_f64(self) -> f64;
    /// `eˣ` as the kernel evaluates it.
    fn exp_kernel(self) -> Self;
    /// `√x`.
    fn root(self) -> Self;
    /// This value as a product operand: in `f32` zero below `2⁻⁶²` in magnitude, so that no
    /// product is subnormal (subnormals slow the `f32` kernels down many times over; see
    /// [`crate::precision`]); in `f64` unchanged.
    fn operand(self) -> Self;
}

impl StepFloat for f64 {
    const VARIANCE_FLOOR: Self = f64::NEG_INFINITY;
    #[inline(always)]
    fn of(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        self
    }
    #[inline(always)]
    fn exp_kernel(self) -> Self {
        kernel::exp(self)
    }
    #[inline(always)]
    fn root(self) -> Self {
        self.sqrt()
    }
    #[inline(always)]
    fn operand(self) -> Self {
        self
    }
}

impl StepFloat for f32 {
    const VARIANCE_FLOOR: Self = 0.0;
    #[inline(always)]
    fn of(v: f64) -> Self {
        v as f32
    }
    #[inline(always)]
    fn to_f64(self) -> f64 {
        f64::from(self)
    }
    #[inline(always)]
    fn exp_kernel(self) -> Self {
        kernel::exp_f32(self)
    }
    #[inline(always)]
    fn root(self) -> Self {
        self.sqrt()
    }
    #[inline(always)]
    fn operand(self) -> Self {
        if self.abs() < F32_OPERAND_FLOOR as f32 {
            0.0
        } else {
            self
        }
    }
}

/// `v` rounded element by element to `T`.
pub(crate) fn rounded<T: StepFloat>(v: &[f64]) -> Vec<T> {
    v.iter().map(|&x| T::of(x)).collect()
}

/// How the step's standard-normal draws fill `ε` (`P × D_x`): one per value, or one per
/// particle copied to all dims (the published code's shared draws).
#[derive(Debug, Clone, Copy)]
pub(crate) struct StepDraws {
    pub(crate) dx: usize,
    pub(crate) shared: bool,
}

impl StepDraws {
    pub(crate) fn fill(&self, rng: &mut impl Rng, eps: &mut [f64]) {
        for e in eps.chunks_exact_mut(self.dx) {
            if self.shared {
                let v: f64 = StandardNormal.sample(rng);
                e.fill(v);
            } else {
                for v in e.iter_mut() {
                    *v = StandardNormal.sample(rng);
                }
            }
        }
    }
}

/// One transition step for `P` particles on caller buffers, in `T` (see the module docs).
#[derive(Debug, Clone)]
pub struct ParticleStep<T: StepFloat> {
    kind: KernelKind,
    variance: T,
    tau_jitter: T,
    m: usize,
    d: usize,
    dx: usize,
    du: usize,
    particles: usize,
    /// `1/ℓ` (`D`).
    inv_len: Vec<T>,
    /// Scaled inducing inputs, dimension-major `D·M`.
    zt: Vec<T>,
    /// `[G; mᵀG]` column-major `(M + D_x) × M`.
    g_mean: Vec<T>,
    /// Diagonal `S`: row-major `D_x × M` (the diagonal of `S_d` in row `d`); full: `D_x`
    /// column-major `M × M` factors `L_d`.
    q_cov: Vec<T>,
    full: bool,
    whitened: bool,
    /// `σ_x² + δ` (`D_x`).
    step_var: Vec<T>,
    draws: StepDraws,
    /// The scaled state part of a particle's `z` (`D_x`).
    z: Vec<T>,
    /// The input part of `τ`, `Σ_{j ≥ D_x} (z̃_jm − u_j/ℓ_j)²` (`M`), shared by the particles.
    tau_input: Vec<T>,
    /// `K`, column-major `M × P`.
    k: Vec<T>,
    /// `[W; μ]`, column-major `(M + D_x) × P`.
    wm: Vec<T>,
    /// `W ⊙ W` (`M × P`, diagonal `S`).
    w2: Vec<T>,
    /// The quadratic terms `Σ_m S_{md} w_m²` or `‖L_dᵀw‖²`, column-major `D_x × P`.
    quad: Vec<T>,
    lw: Vec<T>,
}

impl<T: StepFloat> ParticleStep<T> {
    /// Factorizes the conditional (in `f64`) and prepares buffers for `particles` particles.
    ///
    /// # Errors
    /// [`ObjectiveError::Shape`] for invalid settings or zero particles; a `K_mm` that does
    /// not factorize.
    pub fn new(
        config: &ModelConfig,
        params: &Params,
        particles: usize,
    ) -> Result<Self, ObjectiveError> {
        let post = prediction_posterior(config, params, particles)?;
        let (m, d, dx) = (post.m, post.d, post.dx);
        let full = post.cov == CovarianceStructure::Full;
        let q_cov = if full {
            rounded(&post.q_cov)
        } else {
            let mut t = vec![T::of(0.0); dx * m];
            for i in 0..m {
                for dd in 0..dx {
                    t[dd * m + i] = T::of(post.q_cov[i * dx + dd]);
                }
            }
            t
        };
        let step_var = params
            .process_noise_var
            .iter()
            .map(|v| T::of(v + config.transition_jitter))
            .collect();
        let zero = T::of(0.0);
        Ok(Self {
            kind: post.kind,
            variance: T::of(post.variance),
            tau_jitter: T::of(post.tau_jitter),
            m,
            d,
            dx,
            du: config.n_input,
            particles,
            inv_len: rounded(&post.inv_len),
            zt: rounded(&post.zt),
            g_mean: rounded(&post.g_mean),
            q_cov,
            full,
            whitened: post.whitened,
            step_var,
            draws: StepDraws {
                dx,
                shared: config.shared_draws,
            },
            z: vec![zero; dx],
            tau_input: vec![zero; m],
            k: vec![zero; m * particles],
            wm: vec![zero; (m + dx) * particles],
            w2: vec![zero; if full { 0 } else { m * particles }],
            quad: vec![zero; dx * particles],
            lw: vec![zero; m],
        })
    }

    /// Number of particles.
    pub fn particles(&self) -> usize {
        self.particles
    }

    /// Fills `eps` (`P × D_x`) with standard-normal draws; with shared draws (published
    /// compat) one draw per particle is copied to all dims.
    pub fn draw(&self, rng: &mut impl Rng, eps: &mut [f64]) {
        self.draws.fill(rng, eps);
    }

    /// Advances the particles `x` (`P × D_x` row-major) by one step under the standardized
    /// input `u` (`D_u`) with draws `eps` (`P × D_x`), in place. Allocates nothing.
    pub fn step(&mut self, x: &mut [T], u: &[T], eps: &[f64]) {
        let (m, r, p) = (self.m, self.m + self.dx, self.particles);
        self.input_distances(&u[..self.du]);
        for c in 0..p {
            self.kernel(&x[c * self.dx..(c + 1) * self.dx], c);
        }
        matmul(
            MatMut::from_column_major_slice_mut(&mut self.wm, r, p),
            Accum::Replace,
            MatRef::from_column_major_slice(&self.g_mean, r, m),
            MatRef::from_column_major_slice(&self.k, m, p),
            T::of(1.0),
            Par::Seq,
        );
        self.quadratic_terms();
        for c in 0..p {
            let dx = self.dx;
            self.advance(&mut x[c * dx..(c + 1) * dx], &eps[c * dx..(c + 1) * dx], c);
        }
    }

    /// [`Self::quad`] from `W`: one product `S (W ⊙ W)` for diagonal `S`, `‖L_dᵀw‖²` per
    /// particle for full `S`.
    fn quadratic_terms(&mut self) {
        let (m, dx, p) = (self.m, self.dx, self.particles);
        let r = m + dx;
        if self.full {
            for c in 0..p {
                let w = &self.wm[c * r..c * r + m];
                for dd in 0..dx {
                    let ld = &self.q_cov[dd * m * m..(dd + 1) * m * m];
                    for (i, l) in self.lw.iter_mut().enumerate() {
                        *l = dot(&ld[i * m..(i + 1) * m], w);
                    }
                    self.quad[c * dx + dd] = dot(&self.lw, &self.lw);
                }
            }
            return;
        }
        for (w2, wm) in self.w2.chunks_exact_mut(m).zip(self.wm.chunks_exact(r)) {
            w2.iter_mut()
                .zip(&wm[..m])
                .for_each(|(a, &b)| *a = (b * b).operand());
        }
        matmul(
            MatMut::from_column_major_slice_mut(&mut self.quad, dx, p),
            Accum::Replace,
            MatRef::from_column_major_slice(&self.q_cov, m, dx).transpose(),
            MatRef::from_column_major_slice(&self.w2, m, p),
            T::of(1.0),
            Par::Seq,
        );
    }

    /// [`Self::tau_input`] for the input `u` of this step.
    fn input_distances(&mut self, u: &[T]) {
        let (m, d, dx) = (self.m, self.d, self.dx);
        self.tau_input.fill(T::of(0.0));
        for j in dx..d {
            let zj = u[j - dx] * self.inv_len[j];
            for (k, &t) in self.tau_input.iter_mut().zip(&self.zt[j * m..(j + 1) * m]) {
                *k += (t - zj) * (t - zj);
            }
        }
    }

    /// Column `c` of `K` (`M × P`): the kernel between `[x; u]` and the inducing inputs.
    fn kernel(&mut self, x: &[T], c: usize) {
        let (m, dx) = (self.m, self.dx);
        for (j, z) in self.z[..dx].iter_mut().enumerate() {
            *z = x[j] * self.inv_len[j];
        }
        let k = &mut self.k[c * m..(c + 1) * m];
        k.copy_from_slice(&self.tau_input);
        for j in 0..dx {
            let zj = self.z[j];
            for (k, &t) in k.iter_mut().zip(&self.zt[j * m..(j + 1) * m]) {
                *k += (t - zj) * (t - zj);
            }
        }
        let (var_f, jit) = (self.variance, self.tau_jitter);
        let (one, three, half) = (T::of(1.0), T::of(3.0), T::of(0.5));
        match self.kind {
            KernelKind::Matern32 => k.iter_mut().for_each(|k| {
                let r = (three * (*k + jit)).root();
                *k = ((one + r) * (var_f * (-r).exp_kernel())).operand();
            }),
            KernelKind::SquaredExponential => k
                .iter_mut()
                .for_each(|k| *k = (var_f * (-(half * *k)).exp_kernel()).operand()),
        }
    }

    /// Advances particle `x` (column `c` of `[W; μ]` and of the quadratic terms) with its
    /// draws `eps`.
    fn advance(&self, x: &mut [T], eps: &[f64], c: usize) {
        let (m, dx) = (self.m, self.dx);
        let r = m + dx;
        let (w, mu) = self.wm[c * r..(c + 1) * r].split_at(m);
        let h = if self.whitened {
            w
        } else {
            &self.k[c * m..(c + 1) * m]
        };
        let base = self.variance - dot(w, h);
        let quad = &self.quad[c * dx..(c + 1) * dx];
        for dd in 0..dx {
            let var = max(base + quad[dd], T::VARIANCE_FLOOR);
            x[dd] += mu[dd] + (var + self.step_var[dd]).root() * T::of(eps[dd]);
        }
    }
}

fn max<T: StepFloat>(a: T, b: T) -> T {
    if a < b { b } else { a }
}

/// `Σ aᵢbᵢ` in 16 independent lanes (vectorizable; the lanes are summed at the end).
#[inline(always)]
fn dot<T: StepFloat>(a: &[T], b: &[T]) -> T {
    const L: usize = 16;
    let mut acc = [T::of(0.0); L];
    let (ac, bc) = (a.chunks_exact(L), b.chunks_exact(L));
    let tail: T = ac
        .remainder()
        .iter()
        .zip(bc.remainder())
        .map(|(&x, &y)| x * y)
        .sum();
    for (x, y) in ac.zip(bc) {
        for l in 0..L {
            acc[l] += x[l] * y[l];
        }
    }
    acc.iter().copied().sum::<T>() + tail
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::{ParamInit, Parametrization};
    use rand::SeedableRng;
    use rand_chacha::ChaCha8Rng;

    /// The `f64` step against the module-doc formulas evaluated with naive loops: `K` from
    /// [`KernelKind::shape`], `G` from a dense Gauss–Jordan inverse of `K_mm + jitter·I`
    /// (unwhitened) or of its Cholesky factor (whitened). The step with `ε = 0` moves each
    /// particle by `μ`; with `ε = 1` by `μ + √(σ² + σ_x² + δ)`.
    #[test]
    fn step_matches_naive_formulas() {
        let (m, dx, du, n) = (9, 3, 2, 8);
        let d = dx + du;
        for whitened in [false, true] {
            for cov in [CovarianceStructure::Diagonal, CovarianceStructure::Full] {
                let mut rng = ChaCha8Rng::seed_from_u64(5);
                let mut config = ModelConfig::new(dx, 1, du, m);
                config.covariance = cov;
                config.kmm_jitter = 1e-6;
                config.transition_jitter = 1e-4;
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
                let x: Vec<f64> = (0..n * dx).map(|_| rng.random_range(-1.5..1.5)).collect();
                let u: Vec<f64> = (0..du).map(|_| rng.random_range(-1.5..1.5)).collect();
                let mut step = ParticleStep::<f64>::new(&config, &p, n).unwrap();
                let (mut moved, mut spread) = (x.clone(), x.clone());
                step.step(&mut moved, &u, &vec![0.0; n * dx]);
                step.step(&mut spread, &u, &vec![1.0; n * dx]);
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
                    let post = crate::conditional::Posterior::new(&config, &p).unwrap();
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
                    let point: Vec<f64> =
                        x[c * dx..(c + 1) * dx].iter().chain(&u).copied().collect();
                    let k: Vec<f64> = (0..m).map(|i| kf(&z[i * d..], &point)).collect();
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
                        let label = format!("whitened={whitened} {cov:?} particle {c} dim {dd}");
                        let i = c * dx + dd;
                        let got_mean = moved[i] - x[i];
                        assert!((got_mean - mean).abs() < 1e-9, "{label}: {got_mean} {mean}");
                        let sd = spread[i] - moved[i];
                        let got_var = sd * sd - p.process_noise_var[dd] - config.transition_jitter;
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

    #[test]
    fn dot_equals_the_plain_sum() {
        let a: Vec<f32> = (0..37).map(|i| (i as f32 * 0.37).sin()).collect();
        let b: Vec<f32> = (0..37).map(|i| (i as f32 * 0.11).cos()).collect();
        let plain: f64 = a
            .iter()
            .zip(&b)
            .map(|(x, y)| f64::from(*x) * f64::from(*y))
            .sum();
        assert!((f64::from(dot(&a, &b)) - plain).abs() < 1e-5);
        let a64: Vec<f64> = a.iter().map(|&v| f64::from(v)).collect();
        let b64: Vec<f64> = b.iter().map(|&v| f64::from(v)).collect();
        assert!((dot(&a64, &b64) - plain).abs() < 1e-13);
    }
}
