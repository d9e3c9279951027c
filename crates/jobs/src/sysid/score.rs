//! Test scores of a prediction, the restart mixture and the mean ± std over seeds.

use flapssm_prssm::predict::Prediction;
use serde::{Deserialize, Serialize};

/// Test scores of one prediction.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Scores {
    /// RMSE over every test step and output, raw units.
    pub rmse: f64,
    /// Gaussian NLL per sample and output, standardized units (module docs).
    pub nll: f64,
}

/// Scores `pred` (raw units) against raw outputs `y` (`T × D_y`) with training stds `std`.
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

/// Equal-weight moment-matched mixture of predictions of the same outputs:
/// `m = (1/R) Σ m_r`, `v = (1/R) Σ (v_r + m_r²) − m²` (outputs only; the latent moments are
/// left empty because latent coordinates of different fits are not comparable). `None` when
/// `preds` is empty or the output lengths differ.
pub fn mixture(preds: &[Prediction]) -> Option<Prediction> {
    let first = preds.first()?;
    let n = first.output_mean.len();
    if preds
        .iter()
        .any(|p| p.output_mean.len() != n || p.output_var.len() != n)
    {
        return None;
    }
    let r = preds.len() as f64;
    let mut mean = vec![0.0; n];
    let mut second = vec![0.0; n];
    for p in preds {
        for i in 0..n {
            let m = p.output_mean[i];
            mean[i] += m / r;
            second[i] += (p.output_var[i] + m * m) / r;
        }
    }
    let var = second
        .iter()
        .zip(&mean)
        .map(|(s, m)| (s - m * m).max(0.0))
        .collect();
    Some(Prediction {
        output_mean: mean,
        output_var: var,
        latent_mean: Vec::new(),
        latent_var: Vec::new(),
    })
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
