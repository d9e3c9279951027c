//! Quasi-steady kinematic features of the LRQSM baseline.
//!
//! With u = [AoA, |v|, a_x, a_y, a_z, α̇, α̈] (the published input order) and
//! v_x = −|v| sin AoA, v_y = |v| cos AoA:
//!
//! | set | features, in order |
//! |---|---|
//! | [`FeatureSet::Published`] (11, `lasso_fit.m`) | \|v\|², AoA\|v\|², AoA²\|v\|², AoA³\|v\|², α̇\|v\|, a_x, a_y, α̇v_x, α̇v_y, α̈, α̇\|α̇\| |
//! | [`FeatureSet::PaperText`] (10, the paper's eq. 3) | \|v\|², AoA\|v\|, AoA\|v\|², AoA\|v\|³, α̇\|v\|, α̇\|α̇\|, a_x, a_y, α̇v_x, α̇v_y |
//!
//! These are blade-element integrals in disguise: a quasi-steady wing is (up to the polynomial
//! fit of C_N(AoA)) exactly a linear combination of them.

use serde::{Deserialize, Serialize};

/// Which quasi-steady feature set to build.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
#[serde(rename_all = "kebab-case")]
pub enum FeatureSet {
    /// The 11 features of the published code (default; produced the published results).
    #[default]
    Published,
    /// The 10 features written in the paper's text.
    PaperText,
}

/// Names of the 11 published features.
pub const PUBLISHED_NAMES: [&str; 11] = [
    "v2",
    "aoa_v2",
    "aoa2_v2",
    "aoa3_v2",
    "alphadot_v",
    "a_x",
    "a_y",
    "alphadot_vx",
    "alphadot_vy",
    "alphaddot",
    "alphadot_absalphadot",
];

/// Names of the 10 paper-text features.
pub const PAPER_TEXT_NAMES: [&str; 10] = [
    "v2",
    "aoa_v",
    "aoa_v2",
    "aoa_v3",
    "alphadot_v",
    "alphadot_absalphadot",
    "a_x",
    "a_y",
    "alphadot_vx",
    "alphadot_vy",
];

impl FeatureSet {
    /// Number of features.
    pub fn len(self) -> usize {
        self.names().len()
    }

    /// Always false: every set has features.
    pub fn is_empty(self) -> bool {
        false
    }

    /// Feature names, in order.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            FeatureSet::Published => &PUBLISHED_NAMES,
            FeatureSet::PaperText => &PAPER_TEXT_NAMES,
        }
    }

    /// Writes the features of one input sample `u` (published order) into `out`
    /// (`out.len() == self.len()`).
    pub fn compute_into(self, u: &[f64; 7], out: &mut [f64]) {
        let [aoa, speed, a_x, a_y, _a_z, alpha_dot, alpha_ddot] = *u;
        let v2 = speed * speed;
        let v_x = -speed * aoa.sin();
        let v_y = speed * aoa.cos();
        match self {
            FeatureSet::Published => out.copy_from_slice(&[
                v2,
                aoa * v2,
                aoa * aoa * v2,
                aoa * aoa * aoa * v2,
                alpha_dot * speed,
                a_x,
                a_y,
                alpha_dot * v_x,
                alpha_dot * v_y,
                alpha_ddot,
                alpha_dot * alpha_dot.abs(),
            ]),
            FeatureSet::PaperText => out.copy_from_slice(&[
                v2,
                aoa * speed,
                aoa * v2,
                aoa * v2 * speed,
                alpha_dot * speed,
                alpha_dot * alpha_dot.abs(),
                a_x,
                a_y,
                alpha_dot * v_x,
                alpha_dot * v_y,
            ]),
        }
    }
}

/// The 11 published features of one input sample.
pub fn published_features(u: &[f64; 7]) -> [f64; 11] {
    let mut out = [0.0; 11];
    FeatureSet::Published.compute_into(u, &mut out);
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn published_features_by_hand() {
        let aoa = 0.5_f64;
        let u = [aoa, 2.0, 3.0, 4.0, -1.0, -1.5, 7.0];
        let f = published_features(&u);
        let expect = [
            4.0,
            0.5 * 4.0,
            0.25 * 4.0,
            0.125 * 4.0,
            -3.0,
            3.0,
            4.0,
            -1.5 * (-2.0 * aoa.sin()),
            -1.5 * (2.0 * aoa.cos()),
            7.0,
            -2.25,
        ];
        for (a, b) in f.iter().zip(expect) {
            assert!((a - b).abs() < 1e-15, "{a} vs {b}");
        }
        let mut g = [0.0; 10];
        FeatureSet::PaperText.compute_into(&u, &mut g);
        assert_eq!(g[1], aoa * 2.0);
        assert_eq!(g[3], aoa * 8.0);
        assert_eq!(g[5], -2.25);
    }
}
