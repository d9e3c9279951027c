//! Known answers at the paper's scale: the published model as the plant.
//!
//! [`reference_draws`] draws loads from the reference model (the authors' trained PR-SSM, in
//! standardized units) on the paper's 548 measured trajectories: per trajectory one latent path
//! `x_{t+1} = x_t + f(x_t, u_t) + ε_t` from `x_0 = 0` and the observation `y_t = x_t[0..5] + v_t`,
//! `v_t ~ N(0, σ_y²)`, its inputs standardized on the 512 training trajectories as the rig
//! reference is predicted ([`crate::rig::rig_reference`]). The loads are in the reference's
//! standardized units ("σ of the rig's loads").
//!
//! A PR-SSM trained on those draws with the paper's configuration should recover the model
//! that drew them. [`recovery`] scores it on the 36 test trajectories, per channel: its mean
//! against the reference's mean (RMSE, r), and both against the draws, the reference's error
//! there being the floor that no model can beat, with the paired bootstrap of the difference.

use std::path::Path;

use flapssm_analysis::bootstrap::{PairedDifference, TrajectoryErrors, paired_bootstrap};
use flapssm_analysis::rig::pearson;
use flapssm_prssm::PrssmModel;
use flapssm_wing::dataset::{OUTPUT_NAMES, ValidDataset};
use flapssm_wing::trajectories::paper::{PAPER_N_TRAIN, PAPER_N_TRAJECTORIES, paper_kinematics};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rand_distr::{Distribution, StandardNormal};
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result, analysis};
use crate::models::map_trajectories;
use crate::models::prssm::PrssmLoadModel;
use crate::progress::Progress;
use crate::rig::{RigSettings, input_statistics, on_paper_inputs, rig_reference};
use crate::seed::{DRAW_NOISE_STREAM, DRAW_PATH_STREAM, derive_seed};

/// Units of the drawn loads.
pub const DRAW_UNITS: &str = "σ of the rig's loads (the reference model's standardized units)";

/// Files of [`write_recovery`]: the figures (JSON) and a Markdown table.
pub const RECOVERY_FILES: [&str; 2] = ["recovery.json", "recovery.md"];

/// The paper's 548 measured trajectories (512 training, the 36 test trajectories last) with loads
/// drawn from `model` (module docs): trajectory `i`'s latent path from
/// [`derive_seed`]`(seed, DRAW_PATH_STREAM, i)`, its observation noise from
/// `derive_seed(seed, DRAW_NOISE_STREAM, i)`. `progress.advance(1)` per trajectory.
///
/// # Errors
/// [`JobError::Mismatch`] for a model that is not 7 → 5 in standardized units;
/// [`JobError::Prssm`] naming the trajectory whose draw failed.
pub fn reference_draws(
    model: &PrssmModel,
    seed: u64,
    progress: &dyn Progress,
) -> Result<ValidDataset> {
    check_reference(model)?;
    let kinematics = paper_kinematics(PAPER_N_TRAJECTORIES)?;
    let (mean, std) = input_statistics(&kinematics);
    let plant = on_paper_inputs(model, &mean, &std);
    let dx = model.config.n_state;
    let noise_sd: Vec<f64> = model
        .params
        .obs_noise_var
        .iter()
        .map(|v| v.sqrt())
        .collect();
    progress.start("draws", kinematics.len() as u64);
    let loads = map_trajectories(&kinematics, |i, t| {
        let path_seed = derive_seed(seed, DRAW_PATH_STREAM, i as u64);
        let (_, path) = plant
            .predict_inputs_kept(t.inputs.as_flattened(), 1, path_seed, true)
            .map_err(|source| JobError::Prssm {
                what: format!("draw on trajectory {i}"),
                source: source.into(),
            })?;
        let path = path.expect("the particles were kept");
        let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(seed, DRAW_NOISE_STREAM, i as u64));
        let y: Vec<[f64; 5]> = path
            .chunks_exact(dx)
            .map(|x| {
                std::array::from_fn(|c| {
                    let v: f64 = StandardNormal.sample(&mut rng);
                    x[c] + noise_sd[c] * v
                })
            })
            .collect();
        progress.advance(1);
        Ok(y)
    })?;
    progress.finish("");
    let mut ds = kinematics.into_inner();
    for (t, y) in ds.trajectories.iter_mut().zip(loads) {
        t.outputs = Some(y);
    }
    ds.meta.generator = "flapssm rig draws".into();
    ds.meta.seed = Some(seed);
    ds.meta.settings = serde_json::json!({
        "source": "draws of a reference model on the paper's measured trajectories",
        "inputs_standardized_on": "the paper's 512 training trajectories",
        "initial_state": "zero",
        "seed": seed,
    });
    ds.meta.output_units = vec![DRAW_UNITS.to_string(); 5];
    ds.n_train = PAPER_N_TRAIN;
    Ok(ValidDataset::new(ds)?)
}

fn check_reference(model: &PrssmModel) -> Result<()> {
    let c = &model.config;
    if c.n_input != 7 || c.n_output != 5 || model.normalization.is_some() {
        return Err(JobError::Mismatch {
            what: "reference model".into(),
            expected: "7 inputs → 5 outputs in standardized units (the published model)".into(),
            found: format!("{} inputs → {} outputs", c.n_input, c.n_output),
        });
    }
    Ok(())
}

/// One output's recovery on the test trajectories (samples from `start_sample` on).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ChannelRecovery {
    /// The output (`F_x`, …).
    pub output: String,
    /// RMSE of the trained model's mean against the reference's mean (σ of the rig's loads).
    pub mean_rmse: f64,
    /// `mean_rmse` over the SD of the reference's mean on the same samples.
    pub mean_rmse_relative: f64,
    /// Correlation of the two means.
    pub mean_r: f64,
    /// RMSE of the trained model's mean against the draws.
    pub trained_draws_rmse: f64,
    /// RMSE of the reference's mean against the draws: the floor.
    pub reference_draws_rmse: f64,
    /// `trained_draws_rmse − reference_draws_rmse`, paired bootstrap over the test trajectories.
    pub excess: PairedDifference,
    /// Share of the draws inside the trained model's 95 % band (mean ± 1.96 SD).
    pub draws_in_band: f64,
    /// The same for the reference's band.
    pub draws_in_reference_band: f64,
    /// Mean predictive SD of the trained model over the reference's.
    pub band_width_ratio: f64,
}

/// [`recovery`]'s result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Recovery {
    /// Test trajectories scored.
    pub n_test: usize,
    /// First scored sample (93, the published transient).
    pub start_sample: usize,
    /// Particles of both predictions.
    pub particles: usize,
    /// Seed of the predictions' draws and of the bootstrap.
    pub seed: u64,
    /// Per output.
    pub channels: Vec<ChannelRecovery>,
}

/// Draws of the bootstrap of [`ChannelRecovery::excess`].
const BOOTSTRAP_DRAWS: usize = 2000;

/// Scores `trained` (a PR-SSM trained on `draws`, [`reference_draws`]) against `reference`, the
/// model that drew them (module docs), with `particles` particles per prediction.
///
/// # Errors
/// [`JobError::Mismatch`] for draws that are not the paper's 548 trajectories with loads, or
/// models of the wrong shape; the predictions' errors.
pub fn recovery(
    trained: &PrssmModel,
    reference: &PrssmModel,
    draws: &ValidDataset,
    settings: &RigSettings,
    progress: &dyn Progress,
) -> Result<Recovery> {
    check_reference(reference)?;
    if draws.len() != PAPER_N_TRAJECTORIES || draws.n_train != PAPER_N_TRAIN {
        return Err(JobError::Mismatch {
            what: "draws dataset".into(),
            expected: format!(
                "the paper's {PAPER_N_TRAJECTORIES} trajectories, {PAPER_N_TRAIN} training (`flapssm rig draws`)"
            ),
            found: format!("{} trajectories, {} training", draws.len(), draws.n_train),
        });
    }
    let rig = rig_reference(reference, PAPER_N_TRAJECTORIES, settings, progress)?;
    crate::rig::check_same_trajectories(draws, &rig)?;
    let model = PrssmLoadModel::new(trained, draws, settings.particles, settings.seed)?;
    let test: Vec<usize> = (PAPER_N_TRAIN..PAPER_N_TRAJECTORIES).collect();
    progress.start("trained model", test.len() as u64);
    let preds = test
        .iter()
        .map(|&i| {
            let p = model.predict(i, &draws.trajectories[i]);
            progress.advance(1);
            p
        })
        .collect::<Result<Vec<_>>>()?;
    progress.finish("");
    let s = settings.start_sample;
    let cut = |v: &[f64]| v[s * 5..].to_vec();
    let y: Vec<Vec<f64>> = test
        .iter()
        .map(|&i| {
            let y = draws.trajectories[i].outputs.as_ref().expect("validated");
            cut(y.as_flattened())
        })
        .collect();
    let ref_mean: Vec<Vec<f64>> = test.iter().map(|&i| cut(&rig.mean_z[i])).collect();
    let ref_var: Vec<Vec<f64>> = test.iter().map(|&i| cut(&rig.var_z[i])).collect();
    let mean: Vec<Vec<f64>> = preds.iter().map(|p| cut(&p.output_mean)).collect();
    let var: Vec<Vec<f64>> = preds.iter().map(|p| cut(&p.output_var)).collect();
    let errors = |m: &[Vec<f64>]| {
        let tables: Vec<Vec<f64>> = y
            .iter()
            .zip(m)
            .map(|(y, m)| y.iter().zip(m).map(|(a, b)| a - b).collect())
            .collect();
        TrajectoryErrors::of_tables(tables.iter().map(Vec::as_slice), 5)
            .map_err(analysis("recovery errors"))
    };
    let (trained_err, reference_err) = (errors(&mean)?, errors(&ref_mean)?);
    let excess = paired_bootstrap(
        &trained_err,
        &reference_err,
        BOOTSTRAP_DRAWS,
        95.0,
        settings.seed,
    )
    .map_err(analysis("recovery bootstrap"))?;
    let (trained_rmse, reference_rmse) = (trained_err.rmse(), reference_err.rmse());
    let column = |v: &[Vec<f64>], c: usize| -> Vec<f64> {
        v.iter()
            .flat_map(|t| t.iter().skip(c).step_by(5).copied())
            .collect()
    };
    let channels = (0..5)
        .map(|c| {
            let (m, r, yc) = (column(&mean, c), column(&ref_mean, c), column(&y, c));
            let (v, rv) = (column(&var, c), column(&ref_var, c));
            let n = m.len() as f64;
            let rmse = (m.iter().zip(&r).map(|(a, b)| (a - b).powi(2)).sum::<f64>() / n).sqrt();
            let r_mean = r.iter().sum::<f64>() / n;
            let r_sd = (r.iter().map(|x| (x - r_mean).powi(2)).sum::<f64>() / n).sqrt();
            let inside = |mu: &[f64], var: &[f64]| {
                let k = yc
                    .iter()
                    .zip(mu.iter().zip(var))
                    .filter(|(y, (m, v))| (*y - *m).abs() <= 1.96 * v.sqrt())
                    .count();
                k as f64 / n
            };
            let sd_sum = |v: &[f64]| v.iter().map(|x| x.sqrt()).sum::<f64>();
            Ok(ChannelRecovery {
                output: OUTPUT_NAMES[c].to_string(),
                mean_rmse: rmse,
                mean_rmse_relative: rmse / r_sd,
                mean_r: pearson(&m, &r, OUTPUT_NAMES[c]).map_err(analysis("recovery"))?,
                trained_draws_rmse: trained_rmse[c],
                reference_draws_rmse: reference_rmse[c],
                excess: excess[c],
                draws_in_band: inside(&m, &v),
                draws_in_reference_band: inside(&r, &rv),
                band_width_ratio: sd_sum(&v) / sd_sum(&rv),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(Recovery {
        n_test: test.len(),
        start_sample: s,
        particles: settings.particles,
        seed: settings.seed,
        channels,
    })
}

impl Recovery {
    /// The figures as a Markdown table, titled `title`.
    pub fn markdown(&self, title: &str) -> String {
        let mut s = format!(
            "# {title}\n\nThe trained PR-SSM against the model that drew its data, on the {} test \
             trajectories from sample {} ({} particles, seed {}); loads in σ of the rig's loads. \
             Excess: the trained model's RMSE against the draws minus the drawing model's (the \
             floor), paired 95 % bootstrap interval over the test trajectories (* excludes 0).\n\n\
             | output | mean RMSE | / SD of the mean | r | RMSE vs draws | floor | excess | draws in band | in the reference's band | band width ratio |\n\
             |---|---|---|---|---|---|---|---|---|---|\n",
            self.n_test, self.start_sample, self.particles, self.seed
        );
        for c in &self.channels {
            s.push_str(&format!(
                "| {} | {:.3} | {:.2} | {:.3} | {:.3} | {:.3} | {}{} | {:.3} | {:.3} | {:.2} |\n",
                c.output,
                c.mean_rmse,
                c.mean_rmse_relative,
                c.mean_r,
                c.trained_draws_rmse,
                c.reference_draws_rmse,
                c.excess,
                if c.excess.significant { "*" } else { "" },
                c.draws_in_band,
                c.draws_in_reference_band,
                c.band_width_ratio
            ));
        }
        s
    }
}

/// Writes [`RECOVERY_FILES`] into `dir` (created if missing; each file atomically).
///
/// # Errors
/// [`JobError::Io`] naming the directory or file.
pub fn write_recovery(dir: &Path, recovery: &Recovery, title: &str) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    crate::files::save_json(&dir.join(RECOVERY_FILES[0]), recovery)?;
    crate::files::write_text(&dir.join(RECOVERY_FILES[1]), &recovery.markdown(title))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::NoProgress;
    use crate::rig::load_reference_model;

    fn published() -> PrssmModel {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("../../../shared/reference/bayiz2021-prssm/reference.npz");
        load_reference_model(&path).unwrap()
    }

    /// The drawing model scored as if it had been trained (the plant itself) recovers itself:
    /// its mean is the reference's up to the particles' Monte Carlo error, its error against
    /// the draws is the floor (no significant excess), and its band holds about 95 % of them.
    /// A model that sees the inputs shifted by half an SD is caught on every output.
    #[test]
    fn the_plant_recovers_itself_and_a_wrong_model_is_caught() {
        let reference = published();
        let draws = reference_draws(&reference, 1, &NoProgress).unwrap();
        assert_eq!((draws.len(), draws.n_train), (548, 512));
        let again = reference_draws(&reference, 1, &NoProgress).unwrap();
        assert_eq!(
            draws.trajectories[547].outputs,
            again.trajectories[547].outputs
        );
        let other = reference_draws(&reference, 2, &NoProgress).unwrap();
        assert_ne!(draws.trajectories[0].outputs, other.trajectories[0].outputs);

        let (mean, std) = input_statistics(&draws);
        let plant = on_paper_inputs(&reference, &mean, &std);
        let settings = RigSettings::default();
        let own = recovery(&plant, &reference, &draws, &settings, &NoProgress).unwrap();
        for c in &own.channels {
            assert!(c.mean_r > 0.97 && c.mean_rmse_relative < 0.25, "{c:?}");
            assert!(!c.excess.significant || c.excess.difference < 0.0, "{c:?}");
            assert!((0.88..=0.99).contains(&c.draws_in_band), "{c:?}");
            assert!((c.band_width_ratio - 1.0).abs() < 0.1, "{c:?}");
        }
        let shifted: Vec<f64> = mean.iter().zip(&std).map(|(m, s)| m + 0.5 * s).collect();
        let wrong = on_paper_inputs(&reference, &shifted.try_into().unwrap(), &std);
        let caught = recovery(&wrong, &reference, &draws, &settings, &NoProgress).unwrap();
        for c in &caught.channels {
            assert!(c.excess.significant && c.excess.difference > 0.0, "{c:?}");
        }
        assert!(own.markdown("t").contains("| F_x |"));
    }

    /// Draws of other trajectories (fewer than the paper's 548) are refused by name.
    #[test]
    fn draws_of_other_trajectories_are_refused() {
        let reference = published();
        let mut ds = reference_draws(&reference, 1, &NoProgress)
            .unwrap()
            .into_inner();
        ds.trajectories.truncate(100);
        ds.n_train = 90;
        let ds = ValidDataset::new(ds).unwrap();
        let e = recovery(
            &reference,
            &reference,
            &ds,
            &RigSettings::default(),
            &NoProgress,
        )
        .unwrap_err();
        assert!(e.to_string().contains("548"), "{e}");
    }
}
