//! Generating the default 548-trajectory kinematics dataset, and writing it.

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use flapssm_wing::trajectories::{GeneratorConfig, kinematics_dataset};
use std::hint::black_box;

fn generate(c: &mut Criterion) {
    let mut group = c.benchmark_group("trajectories");
    group.sample_size(10);
    let cfg = GeneratorConfig {
        seed: 1,
        ..GeneratorConfig::default()
    };
    group.bench_with_input(
        BenchmarkId::new("specs", cfg.n_trajectories),
        &cfg,
        |b, cfg| b.iter(|| black_box(cfg.generate().expect("generate"))),
    );
    group.bench_with_input(
        BenchmarkId::new("dataset", cfg.n_trajectories),
        &cfg,
        |b, cfg| b.iter(|| black_box(kinematics_dataset(cfg).expect("dataset"))),
    );
    let path = std::env::temp_dir().join(format!(
        "flapssm-bench-trajectories-{}.npz",
        std::process::id()
    ));
    group.bench_with_input(
        BenchmarkId::new("dataset+save", cfg.n_trajectories),
        &cfg,
        |b, cfg| {
            b.iter(|| {
                kinematics_dataset(cfg)
                    .expect("dataset")
                    .save(&path)
                    .expect("save")
            })
        },
    );
    let _ = std::fs::remove_file(&path);
    group.finish();
}

criterion_group!(benches, generate);
criterion_main!(benches);
