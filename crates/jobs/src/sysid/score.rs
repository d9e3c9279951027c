//! The restart mixture of the sysid protocol's predictions (the scores are
//! [`flapssm_analysis::scores`]).

use flapssm_prssm::predict::Prediction;

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
