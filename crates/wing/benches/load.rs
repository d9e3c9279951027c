//! Save/load time of a dataset file of the published size (548 trajectories × 470 samples).

use criterion::{Criterion, black_box, criterion_group, criterion_main};
use flapssm_wing::dataset::{Dataset, DatasetMeta, Trajectory, ValidDataset};
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

fn published_size() -> ValidDataset {
    let mut rng = ChaCha8Rng::seed_from_u64(1);
    let trajectories = (0..548)
        .map(|_| Trajectory {
            euler_rad: (0..470)
                .map(|_| std::array::from_fn(|_| rng.random()))
                .collect(),
            inputs: (0..470)
                .map(|_| std::array::from_fn(|_| rng.random()))
                .collect(),
            outputs: Some(
                (0..470)
                    .map(|_| std::array::from_fn(|_| rng.random()))
                    .collect(),
            ),
            u_ref_m_s: 0.37,
            family: "measured".into(),
        })
        .collect();
    ValidDataset::new(Dataset {
        meta: DatasetMeta::new("bench", Some(1), serde_json::Value::Null),
        dt_s: 0.04,
        trajectories,
        n_train: 512,
    })
    .unwrap()
}

fn bench(c: &mut Criterion) {
    let dir = tempfile::tempdir().unwrap();
    let path = dir.path().join("d.npz");
    let ds = published_size();
    let mut g = c.benchmark_group("dataset_548x470");
    g.sample_size(10);
    g.bench_function("save", |b| b.iter(|| black_box(&ds).save(&path).unwrap()));
    g.bench_function("load", |b| {
        b.iter(|| Dataset::load(black_box(&path)).unwrap())
    });
    let csv = dir.path().join("d.csv");
    ds.export_csv(&csv).unwrap();
    g.bench_function("import_csv", |b| {
        b.iter(|| Dataset::import_csv(black_box(&csv)).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
