//! Two-sample Kolmogorov–Smirnov test: are two samples drawn from one distribution?
//!
//! D = sup_x |F₁(x) − F₂(x)| over the empirical distribution functions. The p-value is the
//! asymptotic Kolmogorov distribution with Stephens' small-sample correction,
//! p = Q(λ), λ = (√nₑ + 0.12 + 0.11/√nₑ)·D, nₑ = n₁n₂/(n₁ + n₂),
//! Q(λ) = 2 Σ_{k≥1} (−1)^{k−1} exp(−2k²λ²) (Press et al., *Numerical Recipes* §14.3).

use crate::error::{Result, param};
use crate::stats::sorted_copy;

/// Result of [`ks_two_sample`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KsTest {
    /// The statistic D ∈ [0, 1].
    pub statistic: f64,
    /// Asymptotic p-value of D under "same distribution".
    pub p_value: f64,
}

/// The two-sample KS test of finite samples `a` and `b`.
///
/// # Errors
/// [`crate::AnalysisError::NonFinite`] for a NaN or infinite value; a parameter error for an
/// empty sample.
pub fn ks_two_sample(a: &[f64], b: &[f64]) -> Result<KsTest> {
    if a.is_empty() || b.is_empty() {
        return Err(param(
            "KS sample size",
            0.0,
            "both samples must be non-empty",
        ));
    }
    let (a, b) = (sorted_copy("KS sample", a)?, sorted_copy("KS sample", b)?);
    let (na, nb) = (a.len() as f64, b.len() as f64);
    let (mut i, mut j, mut d) = (0, 0, 0.0f64);
    while i < a.len() && j < b.len() {
        let x = a[i].min(b[j]);
        while i < a.len() && a[i] <= x {
            i += 1;
        }
        while j < b.len() && b[j] <= x {
            j += 1;
        }
        d = d.max((i as f64 / na - j as f64 / nb).abs());
    }
    let ne = (na * nb / (na + nb)).sqrt();
    let lambda = (ne + 0.12 + 0.11 / ne) * d;
    Ok(KsTest {
        statistic: d,
        p_value: kolmogorov_q(lambda),
    })
}

/// Q(λ) = 2 Σ (−1)^{k−1} exp(−2k²λ²), 1 for λ → 0.
fn kolmogorov_q(lambda: f64) -> f64 {
    if lambda < 0.2 {
        return 1.0;
    }
    let mut sum = 0.0;
    for k in 1..=100 {
        let term = (-2.0 * (k * k) as f64 * lambda * lambda).exp();
        sum += if k % 2 == 1 { term } else { -term };
        if term < 1e-16 {
            break;
        }
    }
    (2.0 * sum).clamp(0.0, 1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn statistic_and_p_value_match_the_closed_forms() {
        // Disjoint samples: D = 1, p tiny; identical samples: D = 0, p = 1.
        let a: Vec<f64> = (0..50).map(f64::from).collect();
        let b: Vec<f64> = (100..150).map(f64::from).collect();
        let t = ks_two_sample(&a, &b).unwrap();
        assert_eq!(t.statistic, 1.0);
        assert!(t.p_value < 1e-15);
        let t = ks_two_sample(&a, &a).unwrap();
        assert_eq!(t.statistic, 0.0);
        assert_eq!(t.p_value, 1.0);
        // Shift by 10 of 50 evenly spaced values: D = 0.2 exactly; with nₑ = 25,
        // λ = (5 + 0.12 + 0.022)·0.2 and Q(λ) by its series.
        let c: Vec<f64> = (10..60).map(f64::from).collect();
        let t = ks_two_sample(&a, &c).unwrap();
        assert!((t.statistic - 0.2).abs() < 1e-12);
        let lambda: f64 = (5.0 + 0.12 + 0.022) * 0.2;
        let q: f64 = 2.0
            * (1..50)
                .map(|k: i32| {
                    (-1f64).powi(k - 1) * (-2.0 * f64::from(k * k) * lambda * lambda).exp()
                })
                .sum::<f64>();
        assert!((t.p_value - q).abs() < 1e-12 && q > 0.2 && q < 0.3, "{q}");
        assert!(ks_two_sample(&a, &[]).is_err());
        assert!(ks_two_sample(&a, &[f64::NAN]).is_err());
    }
}
