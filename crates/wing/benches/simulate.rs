//! Virtual-wing throughput: one trajectory (4700 raw samples at 250 Hz, sensor chain on) per
//! iteration, at L0 and L1 (8 strips) and L2 (2 vortex strips, the default generator). Multiply
//! by 548 / cores for a dataset (trajectories differ in length of travel, so L2's mean over the
//! default set differs from this one figure-eight).

use criterion::{BenchmarkId, Criterion, criterion_group, criterion_main};
use flapssm_wing::sensor::DatasetSensorErrors;
use flapssm_wing::trajectories::{Family, GeneratorConfig};
use flapssm_wing::virtual_wing::{Fidelity, VirtualWing, VirtualWingConfig};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;

fn bench_simulate(c: &mut Criterion) {
    let gen_cfg = GeneratorConfig::default();
    let spec = gen_cfg
        .generate_one(0, Family::FigureEight)
        .expect("trajectory");
    let mut group = c.benchmark_group("simulate_trajectory");
    group.sample_size(10);
    for fidelity in [Fidelity::L0, Fidelity::L1, Fidelity::L2, Fidelity::L3] {
        let cfg = VirtualWingConfig {
            fidelity,
            ..VirtualWingConfig::default()
        };
        let mut wing = VirtualWing::new(&cfg).expect("wing");
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        let errors = DatasetSensorErrors::draw(&cfg.sensor, &mut rng);
        group.bench_function(BenchmarkId::from_parameter(format!("{fidelity:?}")), |b| {
            b.iter(|| {
                wing.simulate(&spec, &gen_cfg.sampling, 0, &errors, &mut rng)
                    .expect("simulate")
            })
        });
    }
    group.finish();
}

criterion_group!(benches, bench_simulate);
criterion_main!(benches);
