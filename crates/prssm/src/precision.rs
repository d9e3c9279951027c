//! The arithmetic precision of the ELBO's large products.
//!
//! [`Precision::Mixed`] runs the three `(M + D_x) × M × N` products of every transition step in
//! `f32`, where they cost twice as much per FLOP in `f64`:
//!
//! ```text
//! forward   [W; μ]      = [G; mᵀG] K
//! reverse   Y           = [G; mᵀG]ᵀ [P; μ̄]
//!           [B; m̄ᵀ]    += [A; μ̄] Wᵀ
//! ```
//!
//! and, for diagonal `S`, the three `D_x`-row products `S(W⊙W)`, `Sᵀσ̄²` and `σ̄²(W⊙W)ᵀ`
//! (sums of terms of one sign, or one sign per factor, so `f32` loses no more than its rounding).
//! The kernel `K = σ_f² g(τ)` these products read is formed in `f32` too: `τ` is summed in
//! `f64`, then the shape (`√`, `exp`, `(1 + r)e⁻ʳ`) runs on `f32` lanes
//! (`kernel::cross_cov_grouped_f32`, twice the lanes of `f64`), which moves `K` by at most
//! `2·2⁻²³ σ_f²` (`kernel::tests::f32_shape_matches_the_f64_kernel`); the reverse pass reads
//! `σ_f² g' = c′ σ_f² eˣ` and `W` widened from the `f32` values the tape keeps. The other
//! operands are rounded to `f32` (`[G; mᵀG]` and `S` once per evaluation, the others per
//! step), the products are formed in `f32`, and their results are widened back: most feed
//! `f64` code, the parameter adjoints are added to their `f64` sums over steps.
//! Everything else stays `f64`: `τ`, the factorization of `K_mm`, `G`, the
//! cancellation `σ_f² − Σ H⊙W` of the predictive variance (summed in `f64` from the `f32` `K`
//! and the widened `W`), the KL, the likelihood, the draws, the kernel's reverse mode (whose
//! expanded sums `Σ z̃c − x̃s` cancel) and every reduction. The variance's cancellation sees
//! the `f32` rounding of `K` and `W`, so a variance can come out below zero by about
//! `2⁻²⁴ Σ|H||W|`; the transition adds `σ_x² + δ` to it, and a step whose total is not positive
//! gives a non-finite loss, which the trainer's divergence guard rejects like any other.
//!
//! Every `f32` operand is rounded by `linalg::f32_operand`: a magnitude below `2⁻⁶²` becomes
//! zero, so that no product of two operands is subnormal. Subnormal `f32` values (below
//! `1.2·10⁻³⁸`, reached by a far particle's kernel values or a small `W`'s squares) made the
//! `f32` kernels several times slower than the `f64` ones (a streaming step: 60 µs against
//! 26 µs before the floor, 22 µs after).
//!
//! Prediction does not take this choice: its one step ([`crate::step::ParticleStep`]) runs
//! wholly in `f64` or wholly in `f32`.
//!
//! [`Precision::F64`] is the reference; `tests/mixed_precision.rs` measures the difference.

use serde::{Deserialize, Serialize};

/// Arithmetic of the ELBO's large products (see the module docs).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Precision {
    /// Everything in `f64` (the reference).
    #[default]
    F64,
    /// The three large products of each step and the kernel's shape in `f32`, the rest in
    /// `f64`.
    Mixed,
}

impl std::str::FromStr for Precision {
    type Err = String;
    /// `f64` or `mixed` (the command line's and the bindings' spelling).
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "f64" => Ok(Precision::F64),
            "mixed" => Ok(Precision::Mixed),
            _ => Err(format!("unknown precision {s:?} (expected f64 or mixed)")),
        }
    }
}

impl std::fmt::Display for Precision {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            Precision::F64 => "f64",
            Precision::Mixed => "mixed",
        })
    }
}
