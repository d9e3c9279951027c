//! Engine benchmarks at the paper's configuration (D_x 12, D_u 7, D_y 5, M 100, Matern-3/2,
//! diagonal unwhitened q(u), 30 particles):
//! - `elbo/batch16_len470`: one minibatch forward + backward (16 sequences × 470 steps ×
//!   30 particles = 1/32 of an epoch of 512 sequences);
//! - `elbo/batch16_len2`: one forward + backward transition step of 480 particle-points
//!   (plus the per-evaluation K_mm factorization and KL);
//! - `predict/len470_p30`: one 470-step open-loop prediction with 30 particles (one thread).
//!
//! Run: `cargo bench -p flapssm-prssm --bench engine` (`-- zzz` skips the criterion groups
//! and prints only the projections). The projected epoch time is printed from wall time and
//! from CPU time (the latter is what idle cores would give on a shared, loaded machine), and
//! the CPU time of one prediction. `WPT=<n>` sets `windows_per_task` (default 8);
//! `PREDICT_ONLY=1` skips the minibatch projection (for profiling the prediction).

use std::hint::black_box;
use std::time::Instant;

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use flapssm_prssm::bench::{gemm_rate_gflops, predict_step_flops, train_step_flops};
use flapssm_prssm::predict::predict;
use flapssm_prssm::{
    Elbo, ElboOptions, ModelConfig, Objective, ParamInit, Params, Sequence, TrainingData, Window,
};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};

const T: usize = 470;

/// The authors' code, prssm-notes §3: one training epoch (s) and one 470-step prediction with
/// 30 particles (s), the figures this bench prints its speed against.
const AUTHORS_EPOCH_S: f64 = 81.8;
const AUTHORS_PREDICT_S: f64 = 0.152;

fn setup() -> (Elbo, Vec<f64>, ModelConfig, Params, Vec<f64>) {
    let mut rng = ChaCha8Rng::seed_from_u64(0);
    let config = ModelConfig::new(12, 5, 7, 100);
    let seqs: Vec<Sequence> = (0..16)
        .map(|_| Sequence {
            inputs: (0..T * 7)
                .map(|_| StandardNormal.sample(&mut rng))
                .collect(),
            outputs: (0..T * 5)
                .map(|_| StandardNormal.sample(&mut rng))
                .collect(),
        })
        .collect();
    let u = seqs[0].inputs.clone();
    let data = TrainingData::new(7, 5, seqs).unwrap();
    let params = Params::init(&config, &ParamInit::default(), 1);
    let theta = params.unconstrained(&config);
    let mut opts = ElboOptions::paper(512);
    opts.windows_per_task = std::env::var("WPT")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(8);
    let elbo = Elbo::new(config.clone(), data, opts).unwrap();
    (elbo, theta, config, params, u)
}

/// CPU time (user + system) of this process so far, seconds (Linux `/proc/self/stat`,
/// 100 ticks per second); `None` elsewhere.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let fields: Vec<&str> = stat.rsplit_once(')')?.1.split_whitespace().collect();
    let ticks: f64 = fields.get(11)?.parse::<f64>().ok()? + fields.get(12)?.parse::<f64>().ok()?;
    Some(ticks / 100.0)
}

fn bench(c: &mut Criterion) {
    let (elbo, theta, config, params, u) = setup();
    let gemm = gemm_rate_gflops::<f64>(512, 0.3);
    println!("f64 GEMM 512 x 512 x 512 (faer, one thread): {gemm:.1} GFLOP/s per core");
    if std::env::var_os("PREDICT_ONLY").is_none() {
        bench_elbo(c, &elbo, &theta, gemm);
    }
    bench_predict(c, &config, &params, &u, gemm);
}

fn bench_elbo(c: &mut Criterion, elbo: &Elbo, theta: &[f64], gemm: f64) {
    let mut grad = vec![0.0; theta.len()];
    let mut g = c.benchmark_group("elbo");
    g.sample_size(10);
    for len in [2usize, T] {
        let batch: Vec<Window> = (0..16)
            .map(|s| Window {
                sequence: s,
                start: 0,
                len,
            })
            .collect();
        g.bench_with_input(BenchmarkId::new("batch16_len", len), &batch, |b, batch| {
            b.iter(|| {
                elbo.loss_and_grad(black_box(theta), batch, 7, &mut grad)
                    .unwrap()
            })
        });
    }
    g.finish();
    // Projection printed once (median of 5 timed minibatches).
    let batch: Vec<Window> = (0..16)
        .map(|s| Window {
            sequence: s,
            start: 0,
            len: T,
        })
        .collect();
    elbo.loss_and_grad(theta, &batch, 99, &mut grad).unwrap();
    let cpu0 = cpu_seconds();
    let mut times: Vec<f64> = (0..5)
        .map(|i| {
            let t0 = Instant::now();
            elbo.loss_and_grad(theta, &batch, i, &mut grad).unwrap();
            t0.elapsed().as_secs_f64()
        })
        .collect();
    let cpu = cpu_seconds().zip(cpu0).map(|(a, b)| (a - b) / 5.0);
    times.sort_by(f64::total_cmp);
    let tb = times[2];
    let epoch = 32.0 * tb;
    let step_flops = train_step_flops(elbo.config(), 480);
    let gflops = step_flops * (T - 1) as f64 / tb / 1e9;
    println!(
        "minibatch (16 × 470 × 30) forward+backward: {tb:.3} s (median of 5); projected epoch \
         (512 seqs): {epoch:.2} s (authors: {AUTHORS_EPOCH_S} s, {:.1}× faster); {gflops:.1} GFLOP/s; threads: {}",
        AUTHORS_EPOCH_S / epoch,
        rayon::current_num_threads()
    );
    let threads = rayon::current_num_threads() as f64;
    println!(
        "  {:.0} % of {threads} × the GEMM rate; all FLOP at that rate: {:.2} s per epoch",
        100.0 * gflops / (threads * gemm),
        epoch * gflops / (threads * gemm)
    );
    if let Some(cpu) = cpu {
        println!(
            "  CPU time per minibatch {cpu:.3} s → epoch on {threads} idle cores ≈ {:.2} s \
             ({:.1} GFLOP/s per core)",
            32.0 * cpu / threads,
            step_flops * (T - 1) as f64 / cpu / 1e9
        );
    }
}

fn bench_predict(c: &mut Criterion, config: &ModelConfig, params: &Params, u: &[f64], gemm: f64) {
    let zero = vec![0.0; 12];
    let reps = 100;
    let cpu0 = cpu_seconds();
    let t0 = Instant::now();
    for i in 0..reps {
        black_box(predict(config, params, u, &zero, &zero, 30, i).unwrap());
    }
    let wall = t0.elapsed().as_secs_f64() / reps as f64;
    if let Some(cpu) = cpu_seconds().zip(cpu0).map(|(a, b)| (a - b) / reps as f64) {
        let rate = predict_step_flops(config, 30) * (T - 1) as f64 / cpu / 1e9;
        println!(
            "prediction (470 steps × 30 particles, one thread): {:.2} ms wall, {:.2} ms CPU \
             (authors: {:.0} ms, {:.0}× faster; {rate:.1} GFLOP/s = {:.0} % of the GEMM rate)",
            1e3 * wall,
            1e3 * cpu,
            1e3 * AUTHORS_PREDICT_S,
            AUTHORS_PREDICT_S / cpu,
            100.0 * rate / gemm
        );
    }
    let mut g = c.benchmark_group("predict");
    g.bench_function("len470_p30", |b| {
        b.iter(|| predict(config, params, black_box(u), &zero, &zero, 30, 3).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
