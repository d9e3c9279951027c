//! The named training presets of the application: a [`FitSpec`] for each.
//!
//! | setting | `paper` (notes §1) | `paper-fast` | `sysid` (notes §2, Doerr et al.) |
//! |---|---|---|---|
//! | `D_x`, `M`, kernel | 12, 100, Matern-3/2 | as `paper` | 4, 20, squared exponential |
//! | initial lengthscales | 2 | 10 | 2 |
//! | particles (training / evaluation) | 30 / 30 | 10 / 30 | 50 / 50 |
//! | minibatches | 16 whole sequences | 4 whole sequences | 10 windows of 50 steps, stride 1 |
//! | Adam | lr 0.03, 1000 epochs | lr 0.03 cosine-annealed to 0.003, 300 epochs | lr 0.1, 3000 iterations |
//! | precision, windows per task | f64, 4 | mixed, 2 | f64, 4 |
//! | initial state | zeros, 20 % burn-in | as `paper` | recognition model, first 16 steps |
//! | noise init `σ_x²`, `σ_y²` | 2.5e-5, 2.5e-3 | as `paper` | 0.002², 1.0 |
//!
//! `paper` is [`FitSpec::new`] of the paper's model. `paper-fast` is that model trained for
//! time to quality (docs/training.md, "Time to quality"): a start of the lengthscales near
//! where training takes them, more, cheaper steps, and a learning rate that anneals so that
//! the last epochs settle.

use flapssm_prssm::KernelKind;
use flapssm_prssm::Precision;
use flapssm_prssm::params::{ModelConfig, ParamInit};
use flapssm_prssm::train::fit::FitSpec;
use flapssm_prssm::train::{
    Budget, InitialStateSpec, LrSchedule, RecognitionConfig, TrainConfig, WindowSpec,
};
use serde::{Deserialize, Serialize};

/// Named training presets (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "snake_case")]
pub enum Preset {
    /// Bayiz & Cheng 2021, the published flapping-wing run.
    Paper,
    /// The paper's model trained for time to quality (see the module docs).
    #[serde(rename = "paper-fast")]
    PaperFast,
    /// Doerr et al. 2018 on the system-identification benchmarks.
    Sysid,
}

impl std::str::FromStr for Preset {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        match s {
            "paper" => Ok(Preset::Paper),
            "paper-fast" => Ok(Preset::PaperFast),
            "sysid" => Ok(Preset::Sysid),
            _ => Err(format!(
                "unknown preset {s:?} (expected paper, paper-fast or sysid)"
            )),
        }
    }
}

impl Preset {
    /// The fit specification of this preset for `n_input` inputs and `n_output` outputs.
    pub fn fit_spec(self, n_input: usize, n_output: usize) -> FitSpec {
        match self {
            Preset::Paper => {
                FitSpec::new(ModelConfig::new(12.max(n_output), n_output, n_input, 100))
            }
            Preset::PaperFast => {
                let paper = Preset::Paper.fit_spec(n_input, n_output);
                FitSpec {
                    init: ParamInit {
                        lengthscale: 10.0,
                        ..paper.init
                    },
                    particles: 10,
                    train: TrainConfig {
                        budget: Budget::Epochs(300),
                        batch_size: 4,
                        schedule: LrSchedule::Cosine { final_factor: 0.1 },
                        ..paper.train
                    },
                    precision: Precision::Mixed,
                    windows_per_task: 2,
                    ..paper
                }
            }
            Preset::Sysid => {
                let mut model = ModelConfig::new(4.max(n_output), n_output, n_input, 20);
                model.kernel = KernelKind::SquaredExponential;
                let base = FitSpec::new(model);
                FitSpec {
                    init: ParamInit {
                        process_noise_var: 0.002 * 0.002,
                        obs_noise_var: 1.0,
                        ..ParamInit::default()
                    },
                    particles: 50,
                    burn_in_fraction: 0.0,
                    initial_state: InitialStateSpec::Recognition(RecognitionConfig::default()),
                    train: TrainConfig {
                        budget: Budget::Iterations(3000),
                        windows: WindowSpec::Windows { len: 50, stride: 1 },
                        batch_size: 10,
                        lr: 0.1,
                        schedule: LrSchedule::Constant,
                        ..TrainConfig::default()
                    },
                    eval_particles: 50,
                    ..base
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_prssm::train::fit::DEFAULT_WINDOWS_PER_TASK;

    /// `paper-fast` is the paper's model (same structure, kernel, noise and initial state)
    /// with the fast training of docs/training.md; its names parse and serialize as the
    /// command line spells them.
    #[test]
    fn paper_fast_is_the_paper_model_with_fast_training() {
        let (paper, fast) = (
            Preset::Paper.fit_spec(7, 5),
            Preset::PaperFast.fit_spec(7, 5),
        );
        assert_eq!((paper.model.n_state, paper.model.n_inducing), (12, 100));
        assert_eq!(paper.model.kernel, KernelKind::Matern32);
        assert_eq!(fast.model, paper.model);
        assert_eq!(fast.initial_state, paper.initial_state);
        assert_eq!(fast.burn_in_fraction, paper.burn_in_fraction);
        assert_eq!(
            ParamInit {
                lengthscale: 2.0,
                ..fast.init
            },
            paper.init
        );
        assert_eq!(fast.init.lengthscale, 10.0);
        assert_eq!((fast.particles, fast.eval_particles), (10, 30));
        assert_eq!((fast.train.batch_size, fast.train.lr), (4, 0.03));
        assert_eq!(fast.train.budget, Budget::Epochs(300));
        assert_eq!(
            fast.train.schedule,
            LrSchedule::Cosine { final_factor: 0.1 }
        );
        assert_eq!(
            (fast.precision, fast.windows_per_task),
            (Precision::Mixed, 2)
        );
        assert_eq!(
            (paper.precision, paper.windows_per_task),
            (Precision::F64, DEFAULT_WINDOWS_PER_TASK)
        );
        for (name, preset) in [
            ("paper", Preset::Paper),
            ("paper-fast", Preset::PaperFast),
            ("sysid", Preset::Sysid),
        ] {
            assert_eq!(name.parse::<Preset>(), Ok(preset));
            assert_eq!(serde_json::to_value(preset).unwrap(), name);
        }
        assert!("fast".parse::<Preset>().unwrap_err().contains("paper-fast"));
    }

    /// `sysid` is Doerr et al.'s configuration (notes §2).
    #[test]
    fn sysid_is_doerr_et_al() {
        let s = Preset::Sysid.fit_spec(1, 1);
        assert_eq!((s.model.n_state, s.model.n_inducing), (4, 20));
        assert_eq!(s.model.kernel, KernelKind::SquaredExponential);
        assert_eq!(
            (s.particles, s.eval_particles, s.burn_in_fraction),
            (50, 50, 0.0)
        );
        assert_eq!(s.train.budget, Budget::Iterations(3000));
        assert_eq!((s.train.batch_size, s.train.lr), (10, 0.1));
        assert_eq!(s.init.obs_noise_var, 1.0);
        assert!(matches!(s.initial_state, InitialStateSpec::Recognition(_)));
    }
}
