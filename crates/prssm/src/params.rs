//! Model configuration, constrained parameters and the flat unconstrained parameter vector.
//!
//! Positive quantities `v` are stored unconstrained as `θ` with `v = softplus(θ) + 1e-10`
//! (as in the published code). Flat layout ([`ParamLayout`]), in order:
//!
//! | block | length | meaning |
//! |---|---|---|
//! | `inducing` | `M·D` | inducing inputs `Z`, row-major `M × D`, `D = D_x + D_u` |
//! | `kernel_variance` | 1 | softplus⁻¹ of `σ_f²` |
//! | `lengthscales` | `D` | softplus⁻¹ of `ℓ` (states first, then inputs) |
//! | `q_mean` | `M·D_x` | `q(u)` means, row-major `M × D_x` |
//! | `q_cov` | diag: `M·D_x`; full: `D_x·M(M+1)/2` | diag: softplus⁻¹ of variances (row-major `M × D_x`); full: lower Cholesky factor of each `S_d`, row by row, unconstrained |
//! | `process_noise` | `D_x` | softplus⁻¹ of `σ_x²` |
//! | `obs_noise` | `D_y` | softplus⁻¹ of `σ_y²` |

use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::kernel::KernelKind;

/// Floor added to every softplus-constrained positive parameter.
pub const POSITIVE_FLOOR: f64 = 1e-10;

/// Structure of the variational covariances `S_d` of `q(u_d) = N(m_d, S_d)`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum CovarianceStructure {
    /// `S_d = diag(s_d)` (the paper).
    Diagonal,
    /// `S_d = L_d L_dᵀ` with a lower-triangular `L_d`.
    Full,
}

/// How `q(u)` relates to the GP prior.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Parametrization {
    /// `q(u_d)` directly over the inducing outputs (the paper); prior `N(0, K_mm)`.
    Unwhitened,
    /// `u_d = L v_d`, `K_mm = L Lᵀ`, `q(v_d) = N(m_d, S_d)`, prior `N(0, I)`.
    Whitened,
}

/// Sizes and structural choices of a PR-SSM (validated by [`ModelConfig::check`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ModelConfig {
    /// Latent state dimension `D_x` (≥ `n_output`).
    pub n_state: usize,
    /// Output dimension `D_y`; outputs are `x[0..D_y]` (`C = [I 0]`).
    pub n_output: usize,
    /// Input dimension `D_u`.
    pub n_input: usize,
    /// Number of inducing points `M` (default 100).
    pub n_inducing: usize,
    /// Transition kernel, shared by all latent dimensions.
    pub kernel: KernelKind,
    /// Structure of `S_d`.
    pub covariance: CovarianceStructure,
    /// Whitened or not.
    pub parametrization: Parametrization,
    /// Jitter added to the diagonal of `K_mm` (published: 1e-8).
    pub kmm_jitter: f64,
    /// `δ` in the Matern distance `r = √3 √(τ + δ)` (published: 1e-8; correct: 0).
    pub matern_tau_jitter: f64,
    /// Added under the square root of the transition std `√(σ_f|x² + σ_x² + δ_t)` (published 1e-8).
    pub transition_jitter: f64,
    /// Published-code sampling: one standard-normal draw per particle and step shared by all
    /// latent dims (default `false`: independent draws per dim).
    pub shared_draws: bool,
}

impl ModelConfig {
    /// The paper's structure with the given sizes: Matern-3/2, diagonal, unwhitened, jitters
    /// as published except `matern_tau_jitter = 0`, independent draws.
    pub fn new(n_state: usize, n_output: usize, n_input: usize, n_inducing: usize) -> Self {
        Self {
            n_state,
            n_output,
            n_input,
            n_inducing,
            kernel: KernelKind::Matern32,
            covariance: CovarianceStructure::Diagonal,
            parametrization: Parametrization::Unwhitened,
            kmm_jitter: 1e-8,
            matern_tau_jitter: 0.0,
            transition_jitter: 1e-8,
            shared_draws: false,
        }
    }

    /// Published-code compatibility: `matern_tau_jitter = 1e-8` and shared draws.
    pub fn published_compat(mut self) -> Self {
        self.matern_tau_jitter = 1e-8;
        self.shared_draws = true;
        self
    }

    /// The correct sampling of [`Self::new`]: `matern_tau_jitter = 0` and independent draws.
    pub fn standard_sampling(mut self) -> Self {
        self.matern_tau_jitter = 0.0;
        self.shared_draws = false;
        self
    }

    /// GP input dimension `D = D_x + D_u`.
    pub fn n_gp_input(&self) -> usize {
        self.n_state + self.n_input
    }

    /// Checks sizes and jitters.
    ///
    /// # Errors
    /// [`ConfigError`] naming the offending field.
    pub fn check(&self) -> Result<(), ConfigError> {
        let bad = |field: &'static str, message: String| Err(ConfigError { field, message });
        if self.n_state == 0 {
            return bad("n_state", "must be ≥ 1".into());
        }
        if self.n_output == 0 || self.n_output > self.n_state {
            return bad(
                "n_output",
                format!(
                    "{} must be in 1..=n_state ({})",
                    self.n_output, self.n_state
                ),
            );
        }
        if self.n_inducing == 0 {
            return bad("n_inducing", "must be ≥ 1".into());
        }
        for (field, v) in [
            ("kmm_jitter", self.kmm_jitter),
            ("matern_tau_jitter", self.matern_tau_jitter),
            ("transition_jitter", self.transition_jitter),
        ] {
            if !(v >= 0.0 && v.is_finite()) {
                return bad(field, format!("{v} must be finite and ≥ 0"));
            }
        }
        Ok(())
    }

    /// The flat-vector layout of this configuration.
    pub fn layout(&self) -> ParamLayout {
        let (m, d, dx) = (self.n_inducing, self.n_gp_input(), self.n_state);
        let inducing = 0;
        let kernel_variance = m * d;
        let lengthscales = kernel_variance + 1;
        let q_mean = lengthscales + d;
        let q_cov = q_mean + m * dx;
        let q_cov_len = match self.covariance {
            CovarianceStructure::Diagonal => m * dx,
            CovarianceStructure::Full => dx * m * (m + 1) / 2,
        };
        let process_noise = q_cov + q_cov_len;
        let obs_noise = process_noise + dx;
        ParamLayout {
            inducing,
            kernel_variance,
            lengthscales,
            q_mean,
            q_cov,
            process_noise,
            obs_noise,
            len: obs_noise + self.n_output,
        }
    }
}

/// An invalid configuration field.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("invalid model configuration: {field}: {message}")]
#[non_exhaustive]
pub struct ConfigError {
    /// The field.
    pub field: &'static str,
    /// What is wrong.
    pub message: String,
}

/// Offsets of the parameter blocks in the flat unconstrained vector (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct ParamLayout {
    /// Offset of `Z`.
    pub inducing: usize,
    /// Offset of the kernel variance.
    pub kernel_variance: usize,
    /// Offset of the lengthscales.
    pub lengthscales: usize,
    /// Offset of the `q(u)` means.
    pub q_mean: usize,
    /// Offset of the `q(u)` covariance parameters.
    pub q_cov: usize,
    /// Offset of the process-noise variances.
    pub process_noise: usize,
    /// Offset of the observation-noise variances.
    pub obs_noise: usize,
    /// Total length.
    pub len: usize,
}

/// The model's parameters in constrained (natural) form.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Params {
    /// Inducing inputs `Z`, row-major `M × D` (standardized GP-input units).
    pub inducing_inputs: Vec<f64>,
    /// Kernel variance `σ_f²` (> 0).
    pub kernel_variance: f64,
    /// ARD lengthscales `ℓ` (`D`, > 0; states first, then inputs).
    pub lengthscales: Vec<f64>,
    /// `q(u)` means, row-major `M × D_x`.
    pub q_mean: Vec<f64>,
    /// Diagonal: variances, row-major `M × D_x` (> 0). Full: `D_x` lower-triangular
    /// Cholesky factors `L_d`, each column-major `M × M` (strict upper triangle zero).
    pub q_cov: Vec<f64>,
    /// Process-noise variances `σ_x²` (`D_x`, > 0).
    pub process_noise_var: Vec<f64>,
    /// Observation-noise variances `σ_y²` (`D_y`, > 0).
    pub obs_noise_var: Vec<f64>,
}

/// Initial values of a fresh model (defaults: the published run, notes §1).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ParamInit {
    /// `Z ~ U[−r, r]^D` (2).
    pub inducing_range: f64,
    /// `σ_f²` (0.25).
    pub kernel_variance: f64,
    /// All lengthscales (2).
    pub lengthscale: f64,
    /// `m ~ scale · U[0, 1)` (0.01).
    pub q_mean_scale: f64,
    /// Diagonal of `S_d` (0.01).
    pub q_var: f64,
    /// `σ_x²` (2.5e-5).
    pub process_noise_var: f64,
    /// `σ_y²` (2.5e-3).
    pub obs_noise_var: f64,
}

impl Default for ParamInit {
    fn default() -> Self {
        Self {
            inducing_range: 2.0,
            kernel_variance: 0.25,
            lengthscale: 2.0,
            q_mean_scale: 0.01,
            q_var: 0.01,
            process_noise_var: 2.5e-5,
            obs_noise_var: 2.5e-3,
        }
    }
}

/// `softplus(θ) = ln(1 + e^θ)`, overflow-safe.
#[inline]
pub fn softplus(theta: f64) -> f64 {
    if theta > 30.0 {
        theta
    } else {
        theta.exp().ln_1p()
    }
}

/// `d softplus/dθ = 1/(1 + e^{−θ})`.
#[inline]
pub fn softplus_grad(theta: f64) -> f64 {
    1.0 / (1.0 + (-theta).exp())
}

/// `θ` with `softplus(θ) + 1e-10 = v` (values at or below the floor map to `ln(1e-300)`).
#[inline]
pub fn positive_to_unconstrained(v: f64) -> f64 {
    let a = (v - POSITIVE_FLOOR).max(1e-300);
    if a > 30.0 { a } else { a.exp_m1().ln() }
}

#[inline]
fn positive(theta: f64) -> f64 {
    softplus(theta) + POSITIVE_FLOOR
}

impl Params {
    /// Fresh parameters drawn with `seed` (see [`ParamInit`]).
    pub fn init(config: &ModelConfig, init: &ParamInit, seed: u64) -> Self {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (m, d, dx) = (config.n_inducing, config.n_gp_input(), config.n_state);
        let r = init.inducing_range;
        let inducing_inputs = (0..m * d).map(|_| rng.random_range(-r..=r)).collect();
        let q_mean = (0..m * dx)
            .map(|_| init.q_mean_scale * rng.random::<f64>())
            .collect();
        let q_cov = match config.covariance {
            CovarianceStructure::Diagonal => vec![init.q_var; m * dx],
            CovarianceStructure::Full => {
                let mut v = vec![0.0; dx * m * m];
                for dd in 0..dx {
                    for i in 0..m {
                        v[dd * m * m + i * m + i] = init.q_var.sqrt();
                    }
                }
                v
            }
        };
        Self {
            inducing_inputs,
            kernel_variance: init.kernel_variance,
            lengthscales: vec![init.lengthscale; d],
            q_mean,
            q_cov,
            process_noise_var: vec![init.process_noise_var; dx],
            obs_noise_var: vec![init.obs_noise_var; config.n_output],
        }
    }

    /// Checks every block's length and the positivity of positive quantities.
    ///
    /// # Errors
    /// [`ConfigError`] naming the block.
    pub fn check(&self, config: &ModelConfig) -> Result<(), ConfigError> {
        let (m, d, dx) = (config.n_inducing, config.n_gp_input(), config.n_state);
        let q_cov_len = match config.covariance {
            CovarianceStructure::Diagonal => m * dx,
            CovarianceStructure::Full => dx * m * m,
        };
        for (field, got, want) in [
            ("inducing_inputs", self.inducing_inputs.len(), m * d),
            ("lengthscales", self.lengthscales.len(), d),
            ("q_mean", self.q_mean.len(), m * dx),
            ("q_cov", self.q_cov.len(), q_cov_len),
            ("process_noise_var", self.process_noise_var.len(), dx),
            ("obs_noise_var", self.obs_noise_var.len(), config.n_output),
        ] {
            if got != want {
                return Err(ConfigError {
                    field,
                    message: format!("length {got}, expected {want}"),
                });
            }
        }
        let all_finite = self
            .inducing_inputs
            .iter()
            .chain(&self.q_mean)
            .chain(&self.q_cov)
            .all(|v| v.is_finite());
        if !all_finite {
            return Err(ConfigError {
                field: "params",
                message: "non-finite value".into(),
            });
        }
        let pos = |field: &'static str, vals: &[f64]| -> Result<(), ConfigError> {
            match vals.iter().position(|v| !(*v > 0.0 && v.is_finite())) {
                Some(i) => Err(ConfigError {
                    field,
                    message: format!("entry {i} = {} must be > 0", vals[i]),
                }),
                None => Ok(()),
            }
        };
        pos("kernel_variance", &[self.kernel_variance])?;
        pos("lengthscales", &self.lengthscales)?;
        pos("process_noise_var", &self.process_noise_var)?;
        pos("obs_noise_var", &self.obs_noise_var)?;
        if config.covariance == CovarianceStructure::Diagonal {
            pos("q_cov", &self.q_cov)?;
        }
        Ok(())
    }

    /// Writes the flat unconstrained vector (`out.len() == layout.len`).
    pub fn to_unconstrained(&self, config: &ModelConfig, out: &mut [f64]) {
        let ly = config.layout();
        let (m, dx) = (config.n_inducing, config.n_state);
        out[ly.inducing..ly.kernel_variance].copy_from_slice(&self.inducing_inputs);
        out[ly.kernel_variance] = positive_to_unconstrained(self.kernel_variance);
        for (o, v) in out[ly.lengthscales..ly.q_mean]
            .iter_mut()
            .zip(&self.lengthscales)
        {
            *o = positive_to_unconstrained(*v);
        }
        out[ly.q_mean..ly.q_cov].copy_from_slice(&self.q_mean);
        match config.covariance {
            CovarianceStructure::Diagonal => {
                for (o, v) in out[ly.q_cov..ly.process_noise].iter_mut().zip(&self.q_cov) {
                    *o = positive_to_unconstrained(*v);
                }
            }
            CovarianceStructure::Full => {
                let mut k = ly.q_cov;
                for dd in 0..dx {
                    for i in 0..m {
                        for j in 0..=i {
                            out[k] = self.q_cov[dd * m * m + j * m + i];
                            k += 1;
                        }
                    }
                }
            }
        }
        for (o, v) in out[ly.process_noise..ly.obs_noise]
            .iter_mut()
            .zip(&self.process_noise_var)
        {
            *o = positive_to_unconstrained(*v);
        }
        for (o, v) in out[ly.obs_noise..ly.len]
            .iter_mut()
            .zip(&self.obs_noise_var)
        {
            *o = positive_to_unconstrained(*v);
        }
    }

    /// The flat unconstrained vector as a new `Vec`.
    pub fn unconstrained(&self, config: &ModelConfig) -> Vec<f64> {
        let mut v = vec![0.0; config.layout().len];
        self.to_unconstrained(config, &mut v);
        v
    }

    /// Constrained parameters from a flat unconstrained vector.
    ///
    /// # Errors
    /// [`ConfigError`] when `flat.len()` does not match the layout.
    pub fn from_unconstrained(config: &ModelConfig, flat: &[f64]) -> Result<Self, ConfigError> {
        let ly = config.layout();
        if flat.len() != ly.len {
            return Err(ConfigError {
                field: "params",
                message: format!(
                    "flat vector has {} entries, expected {}",
                    flat.len(),
                    ly.len
                ),
            });
        }
        let (m, dx) = (config.n_inducing, config.n_state);
        let q_cov = match config.covariance {
            CovarianceStructure::Diagonal => flat[ly.q_cov..ly.process_noise]
                .iter()
                .map(|&t| positive(t))
                .collect(),
            CovarianceStructure::Full => {
                let mut v = vec![0.0; dx * m * m];
                let mut k = ly.q_cov;
                for dd in 0..dx {
                    for i in 0..m {
                        for j in 0..=i {
                            v[dd * m * m + j * m + i] = flat[k];
                            k += 1;
                        }
                    }
                }
                v
            }
        };
        Ok(Self {
            inducing_inputs: flat[ly.inducing..ly.kernel_variance].to_vec(),
            kernel_variance: positive(flat[ly.kernel_variance]),
            lengthscales: flat[ly.lengthscales..ly.q_mean]
                .iter()
                .map(|&t| positive(t))
                .collect(),
            q_mean: flat[ly.q_mean..ly.q_cov].to_vec(),
            q_cov,
            process_noise_var: flat[ly.process_noise..ly.obs_noise]
                .iter()
                .map(|&t| positive(t))
                .collect(),
            obs_noise_var: flat[ly.obs_noise..ly.len]
                .iter()
                .map(|&t| positive(t))
                .collect(),
        })
    }
}

/// Gradients with respect to the constrained parameters, in the layouts of [`Params`].
#[derive(Debug, Clone, PartialEq)]
pub struct ParamGrads {
    /// `∂/∂Z`, row-major `M × D`.
    pub inducing_inputs: Vec<f64>,
    /// `∂/∂σ_f²`.
    pub kernel_variance: f64,
    /// `∂/∂ℓ`.
    pub lengthscales: Vec<f64>,
    /// `∂/∂m`, row-major `M × D_x`.
    pub q_mean: Vec<f64>,
    /// `∂/∂S` (diagonal, `M × D_x`) or `∂/∂L_d` (full, `D_x × M × M`, lower part meaningful).
    pub q_cov: Vec<f64>,
    /// `∂/∂σ_x²`.
    pub process_noise_var: Vec<f64>,
    /// `∂/∂σ_y²`.
    pub obs_noise_var: Vec<f64>,
}

impl ParamGrads {
    /// Zero gradients shaped for `config`.
    pub fn zeros(config: &ModelConfig) -> Self {
        let (m, d, dx) = (config.n_inducing, config.n_gp_input(), config.n_state);
        Self {
            inducing_inputs: vec![0.0; m * d],
            kernel_variance: 0.0,
            lengthscales: vec![0.0; d],
            q_mean: vec![0.0; m * dx],
            q_cov: vec![
                0.0;
                match config.covariance {
                    CovarianceStructure::Diagonal => m * dx,
                    CovarianceStructure::Full => dx * m * m,
                }
            ],
            process_noise_var: vec![0.0; dx],
            obs_noise_var: vec![0.0; config.n_output],
        }
    }

    /// `self += other`.
    pub fn add(&mut self, other: &ParamGrads) {
        fn acc(a: &mut [f64], b: &[f64]) {
            a.iter_mut().zip(b).for_each(|(x, y)| *x += y);
        }
        acc(&mut self.inducing_inputs, &other.inducing_inputs);
        self.kernel_variance += other.kernel_variance;
        acc(&mut self.lengthscales, &other.lengthscales);
        acc(&mut self.q_mean, &other.q_mean);
        acc(&mut self.q_cov, &other.q_cov);
        acc(&mut self.process_noise_var, &other.process_noise_var);
        acc(&mut self.obs_noise_var, &other.obs_noise_var);
    }

    /// Chain rule to the flat unconstrained vector (`flat` holds the unconstrained values,
    /// `out` receives `∂/∂θ`).
    pub fn to_unconstrained(&self, config: &ModelConfig, flat: &[f64], out: &mut [f64]) {
        let ly = config.layout();
        let (m, dx) = (config.n_inducing, config.n_state);
        out[ly.inducing..ly.kernel_variance].copy_from_slice(&self.inducing_inputs);
        out[ly.kernel_variance] = self.kernel_variance * softplus_grad(flat[ly.kernel_variance]);
        let chain = |out: &mut [f64], flat: &[f64], g: &[f64]| {
            for ((o, t), g) in out.iter_mut().zip(flat).zip(g) {
                *o = g * softplus_grad(*t);
            }
        };
        chain(
            &mut out[ly.lengthscales..ly.q_mean],
            &flat[ly.lengthscales..ly.q_mean],
            &self.lengthscales,
        );
        out[ly.q_mean..ly.q_cov].copy_from_slice(&self.q_mean);
        match config.covariance {
            CovarianceStructure::Diagonal => chain(
                &mut out[ly.q_cov..ly.process_noise],
                &flat[ly.q_cov..ly.process_noise],
                &self.q_cov,
            ),
            CovarianceStructure::Full => {
                let mut k = ly.q_cov;
                for dd in 0..dx {
                    for i in 0..m {
                        for j in 0..=i {
                            out[k] = self.q_cov[dd * m * m + j * m + i];
                            k += 1;
                        }
                    }
                }
            }
        }
        chain(
            &mut out[ly.process_noise..ly.obs_noise],
            &flat[ly.process_noise..ly.obs_noise],
            &self.process_noise_var,
        );
        chain(
            &mut out[ly.obs_noise..ly.len],
            &flat[ly.obs_noise..ly.len],
            &self.obs_noise_var,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn flat_roundtrip_both_structures() {
        for cov in [CovarianceStructure::Diagonal, CovarianceStructure::Full] {
            let mut c = ModelConfig::new(3, 2, 1, 4);
            c.covariance = cov;
            let p = Params::init(&c, &ParamInit::default(), 3);
            let flat = p.unconstrained(&c);
            assert_eq!(flat.len(), c.layout().len);
            let q = Params::from_unconstrained(&c, &flat).unwrap();
            for (a, b) in [
                (&p.lengthscales, &q.lengthscales),
                (&p.q_cov, &q.q_cov),
                (&p.obs_noise_var, &q.obs_noise_var),
            ] {
                for (x, y) in a.iter().zip(b.iter()) {
                    assert!((x - y).abs() <= 1e-15 * x.abs().max(1.0));
                }
            }
            assert_eq!(p.inducing_inputs, q.inducing_inputs);
        }
    }

    #[test]
    fn softplus_inverse() {
        for v in [1e-9, 1e-3, 0.5, 40.0] {
            let t = positive_to_unconstrained(v);
            assert!((positive(t) - v).abs() <= 1e-12 * v, "{v}");
        }
    }
}
