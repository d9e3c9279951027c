//! Benchmarks of the control-authority analysis: the per-trajectory peak table (crosscorr of
//! 12 states × 7 inputs) and the per-pair KDE summary.

use criterion::{BenchmarkId, Criterion, black_box, criterion_group, criterion_main};
use flapssm_analysis::authority::{
    AuthorityConfig, AuthoritySummary, AuthorityTrajectory, peak_table,
};
use flapssm_analysis::stats::Rows;

/// Deterministic smooth signals: inputs are sums of harmonics of the stroke, states are delayed
/// mixtures of inputs.
fn synthetic(n_traj: usize, t_len: usize) -> (Vec<Vec<f64>>, Vec<Vec<f64>>, Vec<f64>) {
    let mut ins = Vec::new();
    let mut sts = Vec::new();
    let mut periods = Vec::new();
    for i in 0..n_traj {
        let period = 60.0 + (i % 30) as f64;
        let w = 2.0 * std::f64::consts::PI / period;
        let u: Vec<f64> = (0..t_len)
            .flat_map(|t| {
                (0..7).map(move |k| ((k + 1) as f64 * w * t as f64 + 0.3 * k as f64).sin())
            })
            .collect();
        let x: Vec<f64> = (0..t_len)
            .flat_map(|t| {
                (0..12).map(move |j| {
                    let d = (j % 5) as f64 * 3.0;
                    ((j % 7 + 1) as f64 * w * (t as f64 - d)).cos()
                        + 0.1 * (0.37 * (t * (j + 1)) as f64).sin()
                })
            })
            .collect();
        ins.push(u);
        sts.push(x);
        periods.push(period);
    }
    (ins, sts, periods)
}

fn bench(c: &mut Criterion) {
    let mut g = c.benchmark_group("authority");
    g.sample_size(10);
    for &n_traj in &[36usize, 548] {
        let (ins, sts, periods) = synthetic(n_traj, 377);
        let trajs: Vec<AuthorityTrajectory<'_>> = (0..n_traj)
            .map(|i| AuthorityTrajectory {
                inputs: Rows::new(&ins[i], 7).unwrap(),
                states: Rows::new(&sts[i], 12).unwrap(),
                period_samples: periods[i],
            })
            .collect();
        let cfg = AuthorityConfig::default();
        g.bench_with_input(BenchmarkId::new("peak_table", n_traj), &trajs, |b, t| {
            b.iter(|| peak_table(black_box(t), &cfg).unwrap())
        });
        let table = peak_table(&trajs, &cfg).unwrap();
        let names = |p: &str, n: usize| (1..=n).map(|i| format!("{p}{i}")).collect::<Vec<_>>();
        g.bench_with_input(BenchmarkId::new("summary", n_traj), &table, |b, t| {
            b.iter(|| {
                AuthoritySummary::new(black_box(t), names("x", 12), names("u", 7), &cfg).unwrap()
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
