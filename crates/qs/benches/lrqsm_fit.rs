//! The published LRQSM fit size: 5 outputs on 512 trajectories × 470 samples (240 640 rows) of
//! the 11 published features, 10-fold CV over 100 λ (MATLAB defaults, α = 0.75).
//! Run: `cargo bench -p flapssm-qs --bench lrqsm_fit`.

use criterion::{Criterion, criterion_group, criterion_main};
use flapssm_qs::cv::{Columns, EnetOptions, fit_enet_cv};
use flapssm_wing::features::{PUBLISHED_NAMES, published_features};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// Smooth random inputs (sums of 3 sinusoids per channel, exact α̇, α̈), features, and
/// 5 targets linear in the features plus uniform noise.
fn data() -> (Vec<f64>, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(2021);
    let (n_traj, n_t, dt_s) = (512, 470, 0.04);
    let mut x = Vec::with_capacity(n_traj * n_t * 11);
    let mut y = Vec::with_capacity(n_traj * n_t * 5);
    let beta: Vec<[f64; 11]> = (0..5)
        .map(|_| std::array::from_fn(|_| rng.random_range(-0.2..0.2)))
        .collect();
    for _ in 0..n_traj {
        let h: Vec<[(f64, f64, f64); 3]> = (0..6)
            .map(|_| {
                std::array::from_fn(|_| {
                    (
                        rng.random_range(0.3..1.0),
                        std::f64::consts::TAU * rng.random_range(0.1..0.8),
                        rng.random_range(0.0..6.3),
                    )
                })
            })
            .collect();
        let s = |c: usize, t: f64, d: i32| -> f64 {
            h[c].iter()
                .map(|&(a, w, p)| match d {
                    0 => a * (w * t + p).sin(),
                    1 => a * w * (w * t + p).cos(),
                    _ => -a * w * w * (w * t + p).sin(),
                })
                .sum()
        };
        for i in 0..n_t {
            let t = i as f64 * dt_s;
            let u = [
                0.6 * s(0, t, 0),
                4.0 + 1.5 * s(1, t, 0),
                8.0 * s(2, t, 0),
                5.0 * s(3, t, 0),
                3.0 * s(4, t, 0),
                0.7 * s(5, t, 1),
                0.7 * s(5, t, 2),
            ];
            let f = published_features(&u);
            x.extend_from_slice(&f);
            for b in &beta {
                let lin: f64 = b.iter().zip(&f).map(|(b, f)| b * f).sum();
                y.push(lin + rng.random_range(-0.5..0.5));
            }
        }
    }
    (x, y)
}

fn bench(c: &mut Criterion) {
    let (x, y) = data();
    let features: Vec<String> = PUBLISHED_NAMES.iter().map(|s| s.to_string()).collect();
    let targets: Vec<String> = ["F_x", "F_y", "M_x", "M_y", "M_z"]
        .map(String::from)
        .to_vec();
    let opts = EnetOptions::default();
    let mut g = c.benchmark_group("lrqsm");
    g.sample_size(10);
    g.bench_function("fit_5_outputs_240640x11_cv10_100lambda", |b| {
        b.iter(|| {
            fit_enet_cv(
                Columns {
                    names: &features,
                    data: &x,
                },
                Columns {
                    names: &targets,
                    data: &y,
                },
                &opts,
            )
            .unwrap()
        })
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
