//! Scores of a probabilistic sequence prediction against measured outputs, as the
//! system-identification protocol of Doerr et al. (2018) reports them: the RMSE over every step
//! and output (raw units), the Gaussian negative log-likelihood per sample and output in units
//! standardized by the training standard deviations,
//! `NLL = mean ½ ln(2π v/σ²) + (y − m)²/(2v)`, the RMSE of each output, and the mean ± std of a
//! score over seeds.

use serde::{Deserialize, Serialize};

/// Test scores of one prediction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// RMSE over every test step and output, raw units.
    pub rmse: f64,
    /// Gaussian NLL per sample and output, standardized units (module docs).
    pub nll: f64,
}

/// Scores a prediction's `mean` and `var` (raw units, `T × D_y` row-major) against raw outputs
/// `y` with the training standard deviations `std` (`D_y`).
pub fn score(y: &[f64], mean: &[f64], var: &[f64], std: &[f64]) -> Scores {
    let dy = std.len().max(1);
    let (mut s2, mut nll) = (0.0, 0.0);
    for (i, ((y, m), v)) in y.iter().zip(mean).zip(var).enumerate() {
        let e = y - m;
        s2 += e * e;
        let s = std[i % dy];
        let vz = v / (s * s);
        let ez = e / s;
        nll += 0.5 * (2.0 * std::f64::consts::PI * vz).ln() + ez * ez / (2.0 * vz);
    }
    let n = y.len().max(1) as f64;
    Scores {
        rmse: (s2 / n).sqrt(),
        nll: nll / n,
    }
}

/// RMSE of each of `d` channels of a prediction's `mean` against `y` (both `T × d` row-major,
/// raw units); 0 for a channel with no samples.
pub fn rmse_per_channel(y: &[f64], mean: &[f64], d: usize) -> Vec<f64> {
    (0..d)
        .map(|j| {
            let (mut s2, mut k) = (0.0, 0.0);
            for (y, m) in y.iter().zip(mean).skip(j).step_by(d) {
                s2 += (y - m) * (y - m);
                k += 1.0;
            }
            (s2 / f64::max(k, 1.0)).sqrt()
        })
        .collect()
}

/// Mean and standard deviation (ddof 0) over seeds.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct MeanStd {
    /// Mean.
    pub mean: f64,
    /// Standard deviation (ddof 0).
    pub std: f64,
}

impl MeanStd {
    /// Of `values` (NaN when empty).
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let v: Vec<f64> = values.into_iter().collect();
        let n = v.len() as f64;
        let mean = v.iter().sum::<f64>() / n;
        let var = v.iter().map(|x| (x - mean) * (x - mean)).sum::<f64>() / n;
        Self {
            mean,
            std: var.sqrt(),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn scores_match_hand_computed_values() {
        // Two outputs with training stds 2 and 0.5; raw errors (2, 0.5) and (0, -1).
        let std = [2.0, 0.5];
        let y = [1.0, 1.0, 3.0, 0.0];
        let m = [-1.0, 0.5, 3.0, 1.0];
        let v = [4.0, 0.25, 16.0, 1.0];
        let s = score(&y, &m, &v, &std);
        assert!((s.rmse - ((4.0 + 0.25 + 0.0 + 1.0) / 4.0f64).sqrt()).abs() < 1e-15);
        // Standardized: (e, v) = (1, 1), (1, 1), (0, 4), (-2, 4).
        let ln2pi = (2.0 * std::f64::consts::PI).ln();
        let nll = [
            0.5 * ln2pi + 0.5,
            0.5 * ln2pi + 0.5,
            0.5 * (ln2pi + 4f64.ln()),
            0.5 * (ln2pi + 4f64.ln()) + 0.5,
        ];
        assert!((s.nll - nll.iter().sum::<f64>() / 4.0).abs() < 1e-14);
    }

    #[test]
    fn rmse_per_channel_matches_hand_computed_values() {
        // Two channels: errors (1, 0) on the first, (0, −2) on the second.
        let y = [1.0, 2.0, 3.0, 4.0];
        let m = [0.0, 2.0, 3.0, 6.0];
        let r = rmse_per_channel(&y, &m, 2);
        assert!((r[0] - 0.5f64.sqrt()).abs() < 1e-15, "{r:?}");
        assert!((r[1] - 2f64.sqrt()).abs() < 1e-15, "{r:?}");
    }

    #[test]
    fn mean_std_is_population_std() {
        let ms = MeanStd::of([1.0, 2.0, 3.0, 6.0]);
        assert_eq!(ms.mean, 3.0);
        assert!((ms.std - 3.5f64.sqrt()).abs() < 1e-15);
    }
}
