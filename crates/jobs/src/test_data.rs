//! Small seeded data shared by the unit tests of the jobs.

use flapssm_prssm::{ModelConfig, Params, PrssmModel};
use flapssm_wing::dataset::ValidDataset;
use flapssm_wing::virtual_wing::{SimulationConfig, simulate_dataset};

/// Six simulated trajectories (four training), seed 3.
pub(crate) fn tiny_dataset() -> ValidDataset {
    let mut cfg = SimulationConfig::default();
    cfg.trajectories.n_trajectories = 6;
    cfg.trajectories.n_train = 4;
    cfg.trajectories.seed = 3;
    simulate_dataset(&cfg, &|| {}).unwrap()
}

/// A PR-SSM with fresh parameters and no normalization statistics.
pub(crate) fn bare_model(config: ModelConfig, seed: u64) -> PrssmModel {
    PrssmModel {
        params: Params::init(&config, &Default::default(), seed),
        config,
        normalization: None,
        training: serde_json::Value::Null,
    }
}
