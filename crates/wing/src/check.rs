//! Parameter checks shared by the configuration types.

/// The first `(name, value)` whose value is not finite and `> 0` (NaN and ±∞ included).
pub(crate) fn first_not_positive(fields: &[(&'static str, f64)]) -> Option<(&'static str, f64)> {
    fields
        .iter()
        .copied()
        .find(|&(_, value)| !(value.is_finite() && value > 0.0))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn finds_the_first_bad_field() {
        assert_eq!(first_not_positive(&[("a", 1.0), ("b", 2e-300)]), None);
        assert_eq!(
            first_not_positive(&[("a", 1.0), ("b", 0.0), ("c", -1.0)]),
            Some(("b", 0.0))
        );
        for bad in [f64::NAN, f64::INFINITY, f64::NEG_INFINITY, -0.0] {
            let (name, value) = first_not_positive(&[("a", 1.0), ("b", bad)]).unwrap();
            assert_eq!(name, "b");
            assert!(value.is_nan() || value == bad);
        }
    }
}
