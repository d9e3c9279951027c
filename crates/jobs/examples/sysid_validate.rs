//! Hyperparameter check of the sysid protocol on training data only: the training part of a
//! record is split again (first 75 % fit, last 25 % validation, open loop) and each variant
//! of the fit is scored there. Never looks at the test part.
//!
//! `cargo run --release -p flapssm-jobs --example sysid_validate -- FILE IN OUT VARIANT [SEEDS]`
//! with VARIANT a comma-separated list of `reference`, `linear-recognition`, `lr=X`,
//! `cosine=FINAL_FACTOR`, `restarts=R`, `select` (combine restarts by selection instead of
//! the ensemble).

use std::path::Path;

use flapssm_jobs::sysid::{Combine, IoRecord, SysidSpec, run};
use flapssm_prssm::train::{InitialStateSpec, LrSchedule, RecognitionConfig};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    if a.len() < 5 {
        return Err("usage: FILE IN OUT VARIANT [SEEDS]".into());
    }
    let record = IoRecord::read(Path::new(&a[1]), &[a[2].parse()?], &[a[3].parse()?])?;
    let n_train = record.n_samples() / 2;
    let train_part = record.head(n_train);
    let mut spec = SysidSpec {
        split: 0.75,
        seeds: a.get(5).map_or(Ok(2), |s| s.parse())?,
        ..SysidSpec::reference(1, 1)
    };
    for token in a[4].split(',') {
        match token.split_once('=') {
            None if token == "reference" => {}
            None if token == "select" => spec.combine = Combine::Select,
            None if token == "snapshots" => spec.combine = Combine::Snapshots,
            Some(("restarts", v)) => spec.restarts = v.parse()?,
            None if token == "linear-recognition" => {
                spec.fit.initial_state = InitialStateSpec::Recognition(RecognitionConfig {
                    hidden: 0,
                    ..RecognitionConfig::default()
                })
            }
            Some(("lr", v)) => spec.fit.train.lr = v.parse()?,
            Some(("cosine", v)) => {
                spec.fit.train.schedule = LrSchedule::Cosine {
                    final_factor: v.parse()?,
                }
            }
            _ => return Err(format!("unknown variant {token}").into()),
        }
    }
    let (report, _) = run(&train_part, &spec, true, |r| {
        eprintln!(
            "seed {}: val RMSE best {:.4} last {:.4} ({:.0} s); restarts (train, val, val last): {}",
            r.seed,
            r.test.rmse,
            r.last_test.map_or(f64::NAN, |l| l.rmse),
            r.wall_s,
            r.restarts
                .iter()
                .map(|x| format!(
                    "({:.4}, {:.4}, {:.4})",
                    x.best_train_rmse.unwrap_or(f64::NAN),
                    x.test.rmse,
                    x.last_test.map_or(f64::NAN, |l| l.rmse)
                ))
                .collect::<Vec<_>>()
                .join(" ")
        )
    })?;
    let last: Vec<f64> = report
        .runs
        .iter()
        .filter_map(|r| r.last_test.map(|l| l.rmse))
        .collect();
    println!(
        "{} {}: validation RMSE best {:.4} ± {:.4}, last {:.4} (mean predictor {:.4})",
        a[1],
        a[4],
        report.rmse.mean,
        report.rmse.std,
        last.iter().sum::<f64>() / last.len() as f64,
        report.mean_predictor_rmse
    );
    Ok(())
}
