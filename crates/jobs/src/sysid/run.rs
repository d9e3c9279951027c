//! The protocol's run: restarts per seed fitted in parallel, the test part predicted open loop,
//! the restarts combined and scored.

use rayon::prelude::*;
use std::time::Instant;

use flapssm_prssm::predict::Prediction;
use flapssm_prssm::train::TrainHooks;
use flapssm_prssm::train::fit::{FitError, fit};
use serde::{Deserialize, Serialize};

use super::score::mixture;
use super::{Combine, IoRecord, SysidError, SysidSpec, split_counts};
use crate::seed::{SYSID_PREDICTION_STREAM, SYSID_RESTART_STREAM, derive_seed};
use flapssm_analysis::scores::{MeanStd, Scores, rmse_per_channel, score};

/// One fitted restart: its record and test-part predictions (raw units).
struct Restart {
    run: RestartRun,
    best: Prediction,
    last: Option<Prediction>,
}

/// One restart (independent fit) of a seed.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RestartRun {
    /// Training seed of this fit.
    pub train_seed: u64,
    /// Epoch of the fit's selected parameters (lowest open-loop RMSE on the training part).
    pub best_epoch: Option<u64>,
    /// That open-loop RMSE on the training part (standardized units).
    pub best_train_rmse: Option<f64>,
    /// Test scores of this restart alone (diagnostics; never used for a choice).
    pub test: Scores,
    /// Test scores of its last parameters, when predicted (diagnostics).
    pub last_test: Option<Scores>,
    /// Steps rejected by the divergence guard.
    pub rejected_steps: u64,
}

/// One seed's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SeedRun {
    /// Seed.
    pub seed: u64,
    /// Test scores of the combined prediction ([`Combine`]).
    pub test: Scores,
    /// Per-output test RMSE, raw units (`D_y`).
    pub rmse_per_output: Vec<f64>,
    /// Wall time of all fits + predictions of this seed, seconds.
    pub wall_s: f64,
    /// Steps rejected by the divergence guard, over all restarts.
    pub rejected_steps: u64,
    /// Index of the restart chosen by [`Combine::Select`] (`None` for an ensemble of several).
    pub selected_restart: Option<usize>,
    /// Per restart.
    pub restarts: Vec<RestartRun>,
    /// Test scores of the last (not the selected best) parameters, combined the same way,
    /// when asked for.
    pub last_test: Option<Scores>,
}

/// The protocol's result.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SysidReport {
    /// Settings used.
    pub spec: SysidSpec,
    /// Input column names.
    pub inputs: Vec<String>,
    /// Output column names.
    pub outputs: Vec<String>,
    /// Training samples.
    pub n_train: usize,
    /// Test samples.
    pub n_test: usize,
    /// Test RMSE (raw units) of predicting the training mean.
    pub mean_predictor_rmse: f64,
    /// Per seed.
    pub runs: Vec<SeedRun>,
    /// Test RMSE over seeds.
    pub rmse: MeanStd,
    /// Test NLL over seeds.
    pub nll: MeanStd,
    /// Wall time per run over seeds.
    pub wall_s: MeanStd,
}

/// The test half and the first seed's prediction, for the figure.
#[derive(Debug, Clone, PartialEq)]
pub struct TestTrace {
    /// Measured test outputs, raw, row-major `T_test × D_y`.
    pub outputs: Vec<f64>,
    /// Prediction of the first seed (raw output moments).
    pub prediction: Prediction,
}

/// Runs the protocol on `record`, one fit per seed (sequentially; each fit is parallel
/// inside). The selected (`best`) model of each fit is scored; with `diagnose_last` the last
/// parameters are scored too ([`SeedRun::last_test`], diagnostics only). `progress` receives
/// each finished run.
///
/// # Errors
/// [`SysidError`] for bad settings, a bad split or a failed fit.
pub fn run(
    record: &IoRecord,
    spec: &SysidSpec,
    diagnose_last: bool,
    mut progress: impl FnMut(&SeedRun),
) -> Result<(SysidReport, TestTrace), SysidError> {
    let (du, dy) = (record.input_names.len(), record.output_names.len());
    spec.check(du, dy)?;
    let n = record.n_samples();
    let probe = &spec.fit;
    let window = match probe.train.windows {
        flapssm_prssm::train::WindowSpec::Windows { len, .. } => len,
        _ => 1,
    };
    let recog = match probe.initial_state {
        flapssm_prssm::train::InitialStateSpec::Recognition(rc) => rc.steps,
        _ => 1,
    };
    let (n_train, n_test) = split_counts(spec.split, n, recog)?;
    if n_train < window {
        return Err(SysidError::Split {
            split: spec.split,
            n_samples: n,
            n_train,
            n_test,
            min_train: window,
            min_test: recog,
        });
    }
    let train = record.sequence(0..n_train);
    let test = record.sequence(n_train..n);
    let norm = flapssm_prssm::Normalization::of_sequences(std::slice::from_ref(&train), du, dy);
    let mean_pred: Vec<f64> = (0..test.outputs.len())
        .map(|i| norm.output_mean[i % dy])
        .collect();
    let mean_predictor_rmse = score(
        test.outputs,
        &mean_pred,
        &vec![1.0; mean_pred.len()],
        &norm.output_std,
    )
    .rmse;
    let mut runs = Vec::new();
    let mut first: Option<Prediction> = None;
    let score_of = |p: &Prediction| {
        score(
            test.outputs,
            &p.output_mean,
            &p.output_var,
            &norm.output_std,
        )
    };
    for seed in 0..spec.seeds {
        let t0 = Instant::now();
        let err = |source| SysidError::Fit { seed, source };
        let one = |r: usize| -> Result<Restart, FitError> {
            let mut fs = spec.fit.clone();
            fs.train.seed = match r {
                0 => seed,
                _ => derive_seed(seed, SYSID_RESTART_STREAM, r as u64),
            };
            let out = fit(
                &fs,
                std::slice::from_ref(&train),
                &[],
                TrainHooks::default(),
                None,
            )?;
            let predict_seed = derive_seed(seed, SYSID_PREDICTION_STREAM, r as u64);
            let best = out
                .best
                .predict_sequence(test, spec.predict_particles, predict_seed)?;
            let last = match diagnose_last || spec.combine == Combine::Snapshots {
                true => Some(out.last.predict_sequence(
                    test,
                    spec.predict_particles,
                    predict_seed,
                )?),
                false => None,
            };
            let state = &out.outcome.state;
            Ok(Restart {
                run: RestartRun {
                    train_seed: fs.train.seed,
                    best_epoch: state.best.as_ref().map(|b| b.epoch),
                    best_train_rmse: state.best.as_ref().map(|b| b.score),
                    test: score_of(&best),
                    last_test: last.as_ref().map(&score_of),
                    rejected_steps: state.rejected,
                },
                best,
                last,
            })
        };
        let fits: Vec<Result<Restart, FitError>> =
            (0..spec.restarts).into_par_iter().map(one).collect();
        let fits = fits
            .into_iter()
            .collect::<Result<Vec<_>, _>>()
            .map_err(err)?;
        let selected = match (spec.combine, fits.len()) {
            (Combine::Snapshots, _) => None,
            (_, 1) => Some(0),
            (Combine::Ensemble, _) => None,
            (Combine::Select, _) => fits
                .iter()
                .enumerate()
                .min_by(|a, b| {
                    let key = |f: &Restart| f.run.best_train_rmse.unwrap_or(f64::INFINITY);
                    key(a.1).total_cmp(&key(b.1))
                })
                .map(|(i, _)| i),
        };
        let combined = |pick: &dyn Fn(&Restart) -> Option<&Prediction>| -> Option<Prediction> {
            match selected {
                Some(i) => pick(&fits[i]).cloned(),
                None => {
                    let preds: Option<Vec<Prediction>> =
                        fits.iter().map(|f| pick(f).cloned()).collect();
                    mixture(&preds?)
                }
            }
        };
        let pred = match spec.combine {
            Combine::Snapshots => {
                let preds: Vec<Prediction> = fits
                    .iter()
                    .flat_map(|f| std::iter::once(&f.best).chain(&f.last))
                    .cloned()
                    .collect();
                mixture(&preds)
            }
            _ => combined(&|f| Some(&f.best)),
        }
        .ok_or_else(|| SysidError::Setting {
            field: "restarts",
            value: spec.restarts.to_string(),
            why: "the restarts' predictions have different lengths".into(),
        })?;
        let last_scores = combined(&|f| f.last.as_ref()).map(|p| score_of(&p));
        let wall_s = t0.elapsed().as_secs_f64();
        let test_scores = score_of(&pred);
        let rmse_per_output = rmse_per_channel(test.outputs, &pred.output_mean, dy);
        let r = SeedRun {
            seed,
            test: test_scores,
            rmse_per_output,
            wall_s,
            rejected_steps: fits.iter().map(|f| f.run.rejected_steps).sum(),
            selected_restart: selected,
            restarts: fits.into_iter().map(|f| f.run).collect(),
            last_test: last_scores,
        };
        progress(&r);
        runs.push(r);
        first.get_or_insert(pred);
    }
    let report = SysidReport {
        spec: spec.clone(),
        inputs: record.input_names.clone(),
        outputs: record.output_names.clone(),
        n_train,
        n_test,
        mean_predictor_rmse,
        rmse: MeanStd::of(runs.iter().map(|r| r.test.rmse)),
        nll: MeanStd::of(runs.iter().map(|r| r.test.nll)),
        wall_s: MeanStd::of(runs.iter().map(|r| r.wall_s)),
        runs,
    };
    let trace = TestTrace {
        outputs: test.outputs.to_vec(),
        prediction: first.unwrap_or_else(|| Prediction {
            output_mean: Vec::new(),
            output_var: Vec::new(),
            latent_mean: Vec::new(),
            latent_var: Vec::new(),
        }),
    };
    Ok((report, trace))
}

#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_data::table::{Column, Table};

    fn prediction(mean: &[f64], var: &[f64]) -> Prediction {
        Prediction {
            output_mean: mean.to_vec(),
            output_var: var.to_vec(),
            latent_mean: vec![0.0; 4],
            latent_var: vec![1.0; 4],
        }
    }

    #[test]
    fn mixture_matches_moments_of_the_equal_weight_mixture() {
        // Components N(0, 1) and N(2, 3): mean 1, variance (1 + 3)/2 + (0² + 2²)/2 − 1² = 3.
        let a = prediction(&[0.0, -1.0], &[1.0, 0.5]);
        let b = prediction(&[2.0, -1.0], &[3.0, 0.25]);
        let m = mixture(&[a.clone(), b]).unwrap();
        assert_eq!(m.output_mean, [1.0, -1.0]);
        assert!((m.output_var[0] - 3.0).abs() < 1e-14);
        assert!((m.output_var[1] - 0.375).abs() < 1e-14);
        assert!(m.latent_mean.is_empty() && m.latent_var.is_empty());
        // One component is itself.
        let one = mixture(std::slice::from_ref(&a)).unwrap();
        assert_eq!(one.output_mean, a.output_mean);
        assert!(
            one.output_var
                .iter()
                .zip(&a.output_var)
                .all(|(x, y)| (x - y).abs() < 1e-15)
        );
        assert!(mixture(&[]).is_none());
        assert!(mixture(&[a, prediction(&[0.0], &[1.0])]).is_none());
    }

    #[test]
    fn mixture_rmse_never_exceeds_mean_member_rmse() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let std = [1.5];
        for _ in 0..100 {
            let y: Vec<f64> = (0..20).map(|_| rng.random_range(-2.0..2.0)).collect();
            let members: Vec<Prediction> = (0..rng.random_range(2..5))
                .map(|_| {
                    let m: Vec<f64> = (0..20).map(|_| rng.random_range(-3.0..3.0)).collect();
                    prediction(&m, &[0.5; 20])
                })
                .collect();
            let mix = mixture(&members).unwrap();
            let rmse = |p: &Prediction| score(&y, &p.output_mean, &p.output_var, &std).rmse;
            let mean_member = members.iter().map(rmse).sum::<f64>() / members.len() as f64;
            assert!(rmse(&mix) <= mean_member + 1e-12);
        }
    }

    #[test]
    fn record_is_row_major_in_selection_order() {
        let table = Table {
            source: "t.csv".into(),
            names: vec!["a".into(), "b".into(), "c".into()],
            columns: vec![
                vec![1.0, 2.0, 3.0],
                vec![4.0, 5.0, 6.0],
                vec![7.0, 8.0, 9.0],
            ],
        };
        let r = IoRecord::from_table(
            &table,
            &[Column::Name("c".into()), Column::Index(0)],
            &[Column::Index(1)],
        )
        .unwrap();
        assert_eq!(r.input_names, ["c", "a"]);
        assert_eq!(r.inputs, [7.0, 1.0, 8.0, 2.0, 9.0, 3.0]);
        assert_eq!(r.outputs, [4.0, 5.0, 6.0]);
        assert_eq!(r.n_samples(), 3);
        let h = r.head(2);
        assert_eq!((h.inputs.len(), h.outputs), (4, vec![4.0, 5.0]));
        let s = r.sequence(1..3);
        assert_eq!(s.inputs, [8.0, 2.0, 9.0, 3.0]);
        assert_eq!(s.outputs, [5.0, 6.0]);
    }

    #[test]
    fn split_counts_enforce_minimum_training_samples() {
        assert_eq!(split_counts(0.5, 1000, 16).unwrap(), (500, 500));
        assert_eq!(split_counts(0.1, 1000, 16).unwrap(), (100, 900));
        let e = split_counts(0.099, 1000, 16).unwrap_err().to_string();
        assert!(
            e.contains("99 training") && e.contains("at least 100"),
            "{e}"
        );
        assert!(split_counts(0.99, 1000, 16).is_err());
    }

    #[test]
    fn mismatched_fit_sizes_and_bad_settings_are_rejected() {
        let spec = SysidSpec::reference(2, 1);
        assert!(spec.check(2, 1).is_ok());
        let e = spec.check(1, 1).unwrap_err().to_string();
        assert!(e.contains("1 inputs and 1 outputs"), "{e}");
        let e = SysidSpec {
            seeds: 0,
            ..SysidSpec::reference(1, 1)
        }
        .check(1, 1)
        .unwrap_err()
        .to_string();
        assert!(e.contains("seeds"), "{e}");
        let e = SysidSpec {
            restarts: 0,
            ..SysidSpec::reference(1, 1)
        }
        .check(1, 1)
        .unwrap_err()
        .to_string();
        assert!(e.contains("restarts"), "{e}");
    }
}
