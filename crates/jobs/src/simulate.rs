//! `flapssm simulate`: the virtual robotic wing on seeded random trajectories, into a dataset.

use std::path::Path;

use serde::{Deserialize, Serialize};

use flapssm_wing::dataset::ValidDataset;
use flapssm_wing::sensor::SensorConfig;
use flapssm_wing::trajectories::paper::{PAPER_ANGLE_SIGNS, PAPER_N_TRAJECTORIES, paper_angles};
use flapssm_wing::trajectories::{GeneratorConfig, default_n_train};
use flapssm_wing::virtual_wing::{
    Fidelity, SimulationConfig, VirtualWingConfig, simulate_angles_dataset, simulate_dataset,
};
use flapssm_wing::vortex::{Inflow, WakeMotion};

use crate::error::{JobError, Result};
use crate::progress::Progress;

/// Settings of [`simulate`]: a few choices over a wing (by default [`VirtualWingConfig::default`]).
#[derive(Debug, Clone, PartialEq)]
pub struct SimulateSettings {
    /// Trajectories.
    pub n_trajectories: usize,
    /// Training trajectories (the first ones); `None`: the published ratio (512 of 548).
    pub n_train: Option<usize>,
    /// Seed of the trajectories and the sensor.
    pub seed: u64,
    /// The wing the choices below apply to (`None`: [`VirtualWingConfig::default`]); a wing
    /// file of `flapssm simulate --wing-config`.
    pub wing: Option<VirtualWingConfig>,
    /// Aerodynamic fidelity (`None`: the wing's).
    pub fidelity: Option<Fidelity>,
    /// Without the sensor chain (no noise, drift, filtering).
    pub noise_free: bool,
    /// No stroke deviation (planar strokes).
    pub flat: bool,
    /// How the L2 strips' free vortices move (`None`: the strips' default, free); refused at
    /// any other fidelity.
    pub wake_motion: Option<WakeMotion>,
    /// The induced inflow of the L2 strips or of the L3 lattice's wake (`None`: the fidelity's
    /// default, still for L2 and momentum for L3); refused at L0 and L1.
    pub inflow: Option<Inflow>,
}

impl Default for SimulateSettings {
    /// 548 trajectories (512 training), seed 0, the default wing, with the sensor.
    fn default() -> Self {
        Self {
            n_trajectories: 548,
            n_train: None,
            seed: 0,
            wing: None,
            fidelity: None,
            noise_free: false,
            flat: false,
            wake_motion: None,
            inflow: None,
        }
    }
}

impl SimulateSettings {
    /// Checks the settings and returns the full simulation configuration.
    ///
    /// # Errors
    /// [`JobError::Setting`] for no trajectory, more training trajectories than there are, or a
    /// wake motion or inflow at a fidelity that has none.
    pub fn check(&self) -> Result<SimulationConfig> {
        let n = self.n_trajectories;
        if n == 0 {
            return Err(JobError::Setting {
                name: "n".into(),
                value: "0".into(),
                expected: "must be at least 1".into(),
            });
        }
        let n_train = self.n_train.unwrap_or_else(|| default_n_train(n));
        if n_train > n {
            return Err(JobError::Setting {
                name: "n_train".into(),
                value: n_train.to_string(),
                expected: format!("must be at most the {n} trajectories"),
            });
        }
        let mut trajectories = GeneratorConfig {
            n_trajectories: n,
            n_train,
            seed: self.seed,
            ..GeneratorConfig::default()
        };
        if self.flat {
            trajectories.max_deviation_deg = 0.0;
        }
        crate::resources::check_dataset("n", n, trajectories.sampling.n_samples)?;
        let mut wing = self.wing.clone().unwrap_or_default();
        if let Some(fidelity) = self.fidelity {
            wing.fidelity = fidelity;
        }
        if self.noise_free {
            wing.sensor = SensorConfig::noise_free();
        }
        let fidelity = wing.fidelity;
        let refuse = |name: &str, value: String, expected: &str| JobError::Setting {
            name: name.into(),
            value,
            expected: format!("{expected} (the fidelity is {fidelity:?})"),
        };
        if let Some(motion) = self.wake_motion {
            if fidelity != Fidelity::L2 {
                return Err(refuse(
                    "wake",
                    motion.to_string(),
                    "applies to the L2 strips only",
                ));
            }
            wing.l2.ldvm.wake_motion = motion;
        }
        if let Some(inflow) = self.inflow {
            match fidelity {
                Fidelity::L2 => wing.l2.inflow = inflow,
                Fidelity::L3 => wing.l3.inflow = inflow,
                Fidelity::L0 | Fidelity::L1 => {
                    let value = inflow.to_string();
                    return Err(refuse("inflow", value, "applies to L2 and L3 only"));
                }
            }
        }
        Ok(SimulationConfig { wing, trajectories })
    }
}

/// Simulates `cfg` (`progress.advance(1)` per trajectory) and, with `out`, writes the dataset
/// file atomically.
///
/// # Errors
/// [`JobError::Simulate`] for a failed simulation, [`JobError::DatasetFile`] naming `out`.
pub fn simulate(
    cfg: &SimulationConfig,
    out: Option<&Path>,
    progress: &dyn Progress,
) -> Result<ValidDataset> {
    progress.start("simulate", cfg.trajectories.n_trajectories as u64);
    let ds = simulate_dataset(cfg, &|| progress.advance(1))?;
    save_if(&ds, out)?;
    progress.finish(&format!("{} trajectories", ds.len()));
    Ok(ds)
}

/// Simulates the wing of `settings` (fidelity, sensor, seed, split; `n_trajectories` must be
/// `angles_rad.len()`, `flat` does not apply) on given Euler angles: trajectory `i` is
/// `angles_rad[i]`, 470 rows [φ, ψ, α] (rad) at 25 Hz, as the paper's measured trajectories
/// ([`flapssm_wing::virtual_wing::simulate_angles_dataset`]). `progress.advance(1)` per
/// trajectory.
///
/// # Errors
/// [`JobError::Setting`] for a count that is not the number of trajectories or a bad split;
/// [`JobError::Simulate`] naming a trajectory of the wrong length.
pub fn simulate_angles(
    settings: &SimulateSettings,
    angles_rad: &[Vec<[f64; 3]>],
    source: &str,
    progress: &dyn Progress,
) -> Result<ValidDataset> {
    if settings.n_trajectories != angles_rad.len() {
        return Err(JobError::Setting {
            name: "n".into(),
            value: settings.n_trajectories.to_string(),
            expected: format!("the {} trajectories given", angles_rad.len()),
        });
    }
    let cfg = settings.check()?;
    progress.start("simulate", angles_rad.len() as u64);
    let ds = simulate_angles_dataset(
        &cfg.wing,
        angles_rad,
        &cfg.trajectories.sampling,
        settings.seed,
        cfg.trajectories.n_train,
        source,
        &|| progress.advance(1),
    )?;
    progress.finish(&format!("{} trajectories", ds.len()));
    Ok(ds)
}

/// Where a simulation's trajectories come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum TrajectorySource {
    /// The seeded generator of the configuration.
    #[default]
    Generator,
    /// The paper's measured trajectories ([`flapssm_wing::trajectories::paper`]).
    Paper,
}

/// Simulates the wing of `settings` on the paper's measured trajectories
/// ([`flapssm_wing::trajectories::paper`]): the first `n_trajectories` (at most 548, in the
/// authors' order; all 548 give the published split, 512 training and the paper's 36 test
/// trajectories last).
///
/// # Errors
/// [`JobError::Setting`] for more than 548 trajectories, `flat` (the measured deviation is
/// what it is) or a bad split.
pub fn simulate_paper(
    settings: &SimulateSettings,
    progress: &dyn Progress,
) -> Result<ValidDataset> {
    if settings.flat {
        return Err(JobError::Setting {
            name: "flat".into(),
            value: "true".into(),
            expected: "not with the measured trajectories (their deviation is measured)".into(),
        });
    }
    paper_dataset(&settings.check()?, None, progress)
}

/// Refuses more than the paper's 548 measured trajectories, naming the setting `name`.
///
/// # Errors
/// [`JobError::Setting`] for `n` above 548.
pub fn check_paper_count(name: &str, n: usize) -> Result<()> {
    if n > PAPER_N_TRAJECTORIES {
        return Err(JobError::Setting {
            name: name.into(),
            value: n.to_string(),
            expected: format!("at most the paper's {PAPER_N_TRAJECTORIES} measured trajectories"),
        });
    }
    Ok(())
}

/// The wing of `cfg` (its sensor seed and split from `cfg.trajectories`) on the paper's first
/// `cfg.trajectories.n_trajectories` measured trajectories; the generator's other settings do
/// not apply. `progress.advance(1)` per trajectory; with `out`, the dataset file is written
/// atomically, as [`simulate`] writes it.
///
/// # Errors
/// [`JobError::Setting`] for more than 548 trajectories; the simulation's errors;
/// [`JobError::DatasetFile`] naming `out`.
pub fn paper_dataset(
    cfg: &SimulationConfig,
    out: Option<&Path>,
    progress: &dyn Progress,
) -> Result<ValidDataset> {
    let t = &cfg.trajectories;
    let n = t.n_trajectories;
    check_paper_count("n", n)?;
    let source = format!(
        "Bayiz & Cheng (2021) measured trajectories 0..{n} (crates/wing/data/bayiz2021-euler-angles.npy, \
         signs {PAPER_ANGLE_SIGNS:?} to [stroke, deviation, pitch])"
    );
    progress.start("simulate", n as u64);
    let ds = simulate_angles_dataset(
        &cfg.wing,
        &paper_angles(n),
        &t.sampling,
        t.seed,
        t.n_train,
        &source,
        &|| progress.advance(1),
    )?;
    save_if(&ds, out)?;
    progress.finish(&format!("{} trajectories", ds.len()));
    Ok(ds)
}

/// Writes `ds` to `out` atomically, if given.
fn save_if(ds: &ValidDataset, out: Option<&Path>) -> Result<()> {
    match out {
        Some(path) => ds.save(path).map_err(|source| JobError::DatasetFile {
            path: path.to_path_buf(),
            source,
        }),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;

    #[test]
    fn settings_reach_the_configuration_and_bad_ones_are_named() {
        let cfg = SimulateSettings {
            n_trajectories: 3,
            seed: 9,
            noise_free: true,
            flat: true,
            ..SimulateSettings::default()
        }
        .check()
        .unwrap();
        assert_eq!(cfg.trajectories.n_trajectories, 3);
        assert_eq!(cfg.trajectories.seed, 9);
        assert_eq!(cfg.trajectories.max_deviation_deg, 0.0);
        assert_eq!(cfg.wing.sensor, SensorConfig::noise_free());
        let ds = simulate(&cfg, None, &NoProgress).unwrap();
        assert_eq!(ds.len(), 3);
        for (n, n_train, name) in [
            (0, None, "setting n = 0"),
            (4, Some(5), "setting n_train = 5"),
        ] {
            let e = SimulateSettings {
                n_trajectories: n,
                n_train,
                ..SimulateSettings::default()
            }
            .check()
            .unwrap_err();
            assert!(e.to_string().contains(name), "{e}");
        }
    }

    #[test]
    fn wake_and_inflow_reach_their_fidelity_or_are_refused() {
        let with = |fidelity, wake_motion, inflow| {
            SimulateSettings {
                fidelity: Some(fidelity),
                wake_motion,
                inflow,
                ..SimulateSettings::default()
            }
            .check()
        };
        let l3 = with(Fidelity::L3, None, None).unwrap();
        assert_eq!(l3.wing.l3.inflow, Inflow::Momentum);
        let still = with(Fidelity::L3, None, Some(Inflow::Still)).unwrap();
        assert_eq!(still.wing.l3.inflow, Inflow::Still);
        assert_eq!(still.wing.l2, l3.wing.l2);
        let l2 = with(
            Fidelity::L2,
            Some(WakeMotion::Frozen),
            Some(Inflow::Momentum),
        )
        .unwrap();
        assert_eq!(l2.wing.l2.ldvm.wake_motion, WakeMotion::Frozen);
        assert_eq!(l2.wing.l2.inflow, Inflow::Momentum);
        assert_eq!(l2.wing.l3, l3.wing.l3);
        for (fidelity, wake, inflow, said) in [
            (
                Fidelity::L3,
                Some(WakeMotion::Frozen),
                None,
                "setting wake = frozen",
            ),
            (
                Fidelity::L0,
                Some(WakeMotion::Free),
                None,
                "setting wake = free",
            ),
            (
                Fidelity::L1,
                None,
                Some(Inflow::Momentum),
                "setting inflow = momentum",
            ),
            (
                Fidelity::L0,
                None,
                Some(Inflow::Uniform { ratio: 0.5 }),
                "setting inflow = uniform:0.5",
            ),
        ] {
            let e = with(fidelity, wake, inflow).unwrap_err().to_string();
            assert!(e.contains(said) && e.contains("applies to"), "{e}");
        }
    }

    #[test]
    fn the_papers_trajectories_are_a_source_with_the_published_split() {
        let settings = SimulateSettings {
            n_trajectories: 3,
            noise_free: true,
            fidelity: Some(flapssm_wing::virtual_wing::Fidelity::L0),
            ..SimulateSettings::default()
        };
        let ds = simulate_paper(&settings, &NoProgress).unwrap();
        assert_eq!(ds.len(), 3);
        assert_eq!(ds.trajectories[0].family, "measured");
        let src = ds.meta.settings["angles_source"].as_str().unwrap();
        assert!(src.contains("0..3"), "{src}");
        let first = paper_angles(1);
        let d = (ds.trajectories[0].euler_rad[200][2] - first[0][200][2]).abs();
        assert!(d < 0.02, "pitch differs by {d} rad from the measured one");
        for (bad, name) in [
            (
                SimulateSettings {
                    n_trajectories: 549,
                    ..settings.clone()
                },
                "setting n = 549",
            ),
            (
                SimulateSettings {
                    flat: true,
                    ..settings.clone()
                },
                "setting flat",
            ),
        ] {
            let e = simulate_paper(&bad, &NoProgress).unwrap_err().to_string();
            assert!(e.contains(name), "{e}");
        }
    }
}
