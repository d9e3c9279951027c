//! Prediction in `f32` ([`ParticleStep<f32>`](flapssm_prssm::step::ParticleStep)) against
//! `f64` on the authors' trained model and reference input (470 steps, 30 particles, the same
//! draws), and the `f32` stream against the `f32` batch prediction.

use std::path::{Path, PathBuf};

use flapssm_data::npz::NpzReader;
use flapssm_prssm::predict::{Prediction, predict, predict_in};
use flapssm_prssm::published::import_published;
use flapssm_prssm::stream::StreamPredictor;

fn reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../../shared/reference/bayiz2021-prssm/reference.npz")
}

/// Every output and latent mean of the `f32` prediction within 2e-3 of its predictive
/// standard deviation of the `f64` one, every variance positive and within 1 % of it; the
/// `f32` stream reports the `f32` batch prediction's means to `f32` rounding (its moments are
/// summed in `f32`, the batch's in `f64`).
#[test]
fn published_model_prediction_in_single_precision() {
    let model = import_published(&reference()).unwrap();
    let u = NpzReader::open(reference())
        .unwrap()
        .f64_shaped("u_in", &[470, 7])
        .unwrap();
    let zero = vec![0.0; 12];
    let (c, p) = (&model.config, &model.params);
    let p64 = predict(c, p, &u, &zero, &zero, 30, 4).unwrap();
    let p32 = predict_in::<f32>(c, p, &u, (&zero, &zero), 30, 4).unwrap();
    let moments = |p: &Prediction| {
        [
            (p.output_mean.clone(), p.output_var.clone()),
            (p.latent_mean.clone(), p.latent_var.clone()),
        ]
    };
    let mut worst = (0.0f64, 0.0f64);
    for ((mean64, var64), (mean32, var32)) in moments(&p64).into_iter().zip(moments(&p32)) {
        for i in 0..mean64.len() {
            let dm = (mean32[i] - mean64[i]).abs() / var64[i].sqrt();
            let dv = (var32[i] - var64[i]).abs() / var64[i];
            worst = (worst.0.max(dm), worst.1.max(dv));
            assert!(var32[i] > 0.0, "variance {i} is {}", var32[i]);
            assert!(dm < 2e-3, "mean {i}: {} against {}", mean32[i], mean64[i]);
            assert!(dv < 1e-2, "variance {i}: {} against {}", var32[i], var64[i]);
        }
    }
    assert!(
        worst.0 > 0.0,
        "the f32 prediction equals the f64 one bit for bit"
    );
    println!(
        "f32 prediction: |Δmean| ≤ {:e} σ, |Δvar| ≤ {:e} relative",
        worst.0, worst.1
    );
    let mut stream = StreamPredictor::<f32>::new(&model, 30, &zero, &zero, 4).unwrap();
    // The imported model has no normalization: the stream reads and reports standardized units.
    assert!(model.normalization.is_none());
    let u32: Vec<f32> = u.iter().map(|&v| v as f32).collect();
    for t in 0..470 {
        let (mean, _) = stream.step(&u32[t * 7..(t + 1) * 7]).unwrap();
        for (k, &m) in mean.iter().enumerate() {
            let b = p32.output_mean[t * 5 + k];
            let scale = p32.output_var[t * 5 + k].sqrt();
            assert!(
                (f64::from(m) - b).abs() < 1e-5 * scale.max(b.abs()),
                "step {t}, output {k}: stream {m}, batch {b}"
            );
        }
    }
}
