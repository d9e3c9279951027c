//! Training and streaming benches, paper configuration (D_x 12, M 100, Matern-3/2, 7 inputs):
//! one minibatch of 16 × 470-step sequences × 30 particles (× 32 = one epoch), prediction of
//! one 470-step trajectory with 30 particles, one streaming step with 30 particles, one Adam
//! step over the paper's parameter vector.

use criterion::{BenchmarkId, Criterion, black_box, criterion_group, criterion_main};
use flapssm_prssm::ModelConfig;
use flapssm_prssm::Objective;
use flapssm_prssm::bench::{initial_model, synthetic_objective, time_batches, time_prediction};
use flapssm_prssm::stream::StreamPredictor;
use flapssm_prssm::train::Adam;
use flapssm_prssm::train::fit::FitSpec;

fn benches(c: &mut Criterion) {
    let mut g = c.benchmark_group("train");
    g.sample_size(10);
    let spec = FitSpec::new(ModelConfig::new(12, 5, 7, 100));
    let (elbo, params) = synthetic_objective(&spec, 16, 470, 0).unwrap();
    g.bench_with_input(
        BenchmarkId::new("paper_minibatch_16x470x30", 16),
        &16,
        // `time_batches` runs an untimed warm-up minibatch first: report its own timing.
        |b, _| {
            b.iter_custom(|iters| {
                let secs: f64 = (0..iters)
                    .map(|_| {
                        time_batches(&elbo, black_box(&params), 1, 0)
                            .unwrap()
                            .total_s
                    })
                    .sum();
                std::time::Duration::from_secs_f64(secs)
            })
        },
    );
    let model = initial_model(&spec, 0);
    g.bench_with_input(BenchmarkId::new("predict_470x30", 470), &470, |b, _| {
        b.iter(|| time_prediction::<f64>(&model, 470, 30, 1).unwrap())
    });
    let mut stream = StreamPredictor::new(&model, 30, &[0.0; 12], &[0.0; 12], 0).unwrap();
    let u = [0.1, -0.3, 0.2, 0.5, -0.1, 0.0, 0.3];
    g.bench_with_input(BenchmarkId::new("stream_step", 30), &30, |b, _| {
        b.iter(|| {
            let (m, _) = stream.step(black_box(&u)).unwrap();
            black_box(m[0])
        })
    });
    let n = elbo.n_params();
    let mut adam = Adam::new(n, Default::default());
    let mut theta = params.clone();
    let grad: Vec<f64> = (0..n).map(|i| ((i as f64) * 0.1).sin()).collect();
    g.bench_with_input(BenchmarkId::new("adam_step", n), &n, |b, _| {
        b.iter(|| adam.step(&mut theta, black_box(&grad), 1e-9))
    });
    g.finish();
}

criterion_group!(train_benches, benches);
criterion_main!(train_benches);
