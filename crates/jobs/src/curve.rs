//! Learning curves: one row per evaluated epoch of a training run with its wall time, and the
//! time-to-quality read from them (`flapssm bench --train`).
//!
//! File (`<model stem>.curve.csv`, rewritten atomically after every evaluated epoch):
//!
//! ```text
//! # flapssm learning curve: wall_s = seconds of training since step 0 (a resumed run adds its
//! # own to the checkpoint's); RMSEs open-loop, in standard deviations of the outputs
//! epoch,step,wall_s,mean_loss,train_rmse,val_rmse
//! ```
//!
//! Time-to-quality: the **converged** validation RMSE `r∞` is the median of the last 10 % of
//! a reference curve's evaluated epochs (at least one), where the reference is a run of the
//! published schedule (Adam 0.03, 1000 epochs); a run reaches quality at its first evaluated
//! epoch with `val_rmse ≤ (1 + tolerance) · r∞` (tolerance 2 %). One evaluation can dip below
//! the threshold by luck, so the run is also said to **hold** quality from the first epoch at
//! which the median of its last [`RUNNING_MEDIAN_WINDOW`] evaluations is at or below it (a
//! trailing median: what the run had shown by then).

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::time::Instant;

use flapssm_data::table::{TableError, split_csv_line};
use flapssm_prssm::train::EpochRecord;

use crate::error::{JobError, Result};

/// Column names of a curve file.
pub const CURVE_COLUMNS: [&str; 6] = [
    "epoch",
    "step",
    "wall_s",
    "mean_loss",
    "train_rmse",
    "val_rmse",
];

/// Fraction of a reference curve's last evaluated epochs whose median is the converged value.
pub const CONVERGED_TAIL: f64 = 0.1;
/// Relative distance to the converged validation RMSE that counts as reached (2 %).
pub const QUALITY_TOLERANCE: f64 = 0.02;
/// Evaluated epochs in the trailing median of [`TimeToQuality::held`].
pub const RUNNING_MEDIAN_WINDOW: usize = 11;

/// One evaluated epoch.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CurvePoint {
    /// Epoch index (0-based).
    pub epoch: u64,
    /// Optimizer steps done.
    pub step: u64,
    /// Wall seconds of training since step 0.
    pub wall_s: f64,
    /// Epoch-mean minibatch loss (−ELBO).
    pub mean_loss: f64,
    /// Training-rollout RMSE (σ), NaN when not evaluated (an empty field in the file).
    pub train_rmse: f64,
    /// Validation RMSE (σ), NaN without a validation set.
    pub val_rmse: f64,
}

/// A learning curve being recorded to a file.
#[derive(Debug)]
pub struct CurveRecorder {
    path: PathBuf,
    points: Vec<CurvePoint>,
    /// Wall seconds before this invocation (from the resumed curve).
    offset_s: f64,
    started: Instant,
    /// Whether the file belongs to this run (resumed, or started by [`Self::begin`]).
    begun: bool,
}

impl CurveRecorder {
    /// A new curve written to `path`. When `resume_step` is given, the rows of an existing
    /// file at `path` up to that step are kept and this run's wall time is added to theirs;
    /// otherwise [`CurveRecorder::begin`] starts the file afresh once training is under way.
    ///
    /// # Errors
    /// The file's read errors, naming it, when resuming from an unreadable curve.
    pub fn new(path: &Path, resume_step: Option<u64>) -> Result<Self> {
        let mut points = Vec::new();
        if let Some(step) = resume_step.filter(|_| path.exists()) {
            points = read_curve(path)?;
            points.retain(|p| p.step <= step);
        }
        let offset_s = points.last().map_or(0.0, |p| p.wall_s);
        Ok(Self {
            path: path.to_path_buf(),
            points,
            offset_s,
            started: Instant::now(),
            begun: resume_step.is_some(),
        })
    }

    /// Called at every optimizer step: the first call of a fresh run writes the file with
    /// no rows, so that no earlier run's rows outlive this run's first step (a refused run
    /// changes nothing on disk).
    ///
    /// # Errors
    /// [`JobError::Io`] naming the file.
    pub fn begin(&mut self) -> Result<()> {
        if !self.begun {
            self.begun = true;
            crate::files::write_text(&self.path, &curve_text(&self.points))?;
        }
        Ok(())
    }

    /// Records an evaluated epoch and rewrites the file.
    ///
    /// # Errors
    /// [`JobError::Io`] naming the file.
    pub fn record(&mut self, r: &EpochRecord) -> Result<()> {
        self.points.push(CurvePoint {
            epoch: r.epoch,
            step: r.step,
            wall_s: self.offset_s + self.started.elapsed().as_secs_f64(),
            mean_loss: r.mean_loss,
            train_rmse: r.train_rmse.unwrap_or(f64::NAN),
            val_rmse: r.val_rmse.unwrap_or(f64::NAN),
        });
        crate::files::write_text(&self.path, &curve_text(&self.points))
    }
}

/// The curve file's text.
pub fn curve_text(points: &[CurvePoint]) -> String {
    let mut s = String::from(
        "# flapssm learning curve: wall_s = seconds of training since step 0 (a resumed run \
         adds its own to the checkpoint's); RMSEs open-loop, in standard deviations of the \
         outputs\n",
    );
    s.push_str(&CURVE_COLUMNS.join(","));
    s.push('\n');
    let metric = |v: f64| {
        if v.is_finite() {
            format!("{v:e}")
        } else {
            String::new()
        }
    };
    for p in points {
        let _ = writeln!(
            s,
            "{},{},{:.3},{:e},{},{}",
            p.epoch,
            p.step,
            p.wall_s,
            p.mean_loss,
            metric(p.train_rmse),
            metric(p.val_rmse)
        );
    }
    s
}

/// Reads a curve file. An empty RMSE field is a metric that was not computed (NaN).
///
/// # Errors
/// [`JobError::Table`] naming the file and line for a malformed file or a missing column.
pub fn read_curve(path: &Path) -> Result<Vec<CurvePoint>> {
    let text = std::fs::read_to_string(path).map_err(|error| TableError::Io {
        path: path.to_path_buf(),
        error,
    })?;
    let syntax = |line: usize, message: String| TableError::Syntax {
        path: path.to_path_buf(),
        line,
        message,
    };
    let mut lines = text
        .lines()
        .enumerate()
        .filter(|(_, l)| !l.trim().is_empty() && !l.starts_with('#'));
    let (hk, header) = lines.next().ok_or_else(|| TableError::Empty {
        path: path.to_path_buf(),
    })?;
    let names = split_csv_line(header).map_err(|m| syntax(hk + 1, m))?;
    let index: Vec<usize> = CURVE_COLUMNS
        .iter()
        .map(|c| {
            names.iter().position(|n| n.trim() == *c).ok_or_else(|| {
                syntax(
                    hk + 1,
                    format!("no column '{c}'; a curve has {}", CURVE_COLUMNS.join(",")),
                )
            })
        })
        .collect::<std::result::Result<_, _>>()?;
    let mut points = Vec::new();
    for (k, line) in lines {
        let fields = split_csv_line(line).map_err(|m| syntax(k + 1, m))?;
        if fields.len() != names.len() {
            return Err(TableError::Ragged {
                path: path.to_path_buf(),
                line: k + 1,
                found: fields.len(),
                expected: names.len(),
            }
            .into());
        }
        let mut v = [f64::NAN; 6];
        for (j, &i) in index.iter().enumerate() {
            let f = fields[i].trim();
            // Only the RMSEs may be missing.
            if f.is_empty() && j >= 4 {
                continue;
            }
            v[j] = f
                .parse::<f64>()
                .ok()
                .filter(|x| x.is_finite())
                .ok_or_else(|| TableError::Number {
                    path: path.to_path_buf(),
                    line: k + 1,
                    column: i + 1,
                    text: f.to_string(),
                })?;
        }
        points.push(CurvePoint {
            epoch: v[0] as u64,
            step: v[1] as u64,
            wall_s: v[2],
            mean_loss: v[3],
            train_rmse: v[4],
            val_rmse: v[5],
        });
    }
    Ok(points)
}

/// When a run first came within the tolerance of the converged value.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TimeToQuality {
    /// Converged validation RMSE of the reference (σ).
    pub converged_rmse: f64,
    /// The threshold `(1 + tolerance) · converged_rmse`.
    pub threshold: f64,
    /// The first evaluated epoch at or below the threshold, if any.
    pub reached: Option<CurvePoint>,
    /// The first evaluated epoch at which the median of the last [`RUNNING_MEDIAN_WINDOW`]
    /// validation RMSEs (a full window) is at or below the threshold, if any.
    pub held: Option<CurvePoint>,
    /// The run's last evaluated epoch.
    pub last: CurvePoint,
    /// The run's lowest validation RMSE.
    pub best_rmse: f64,
}

/// The converged validation RMSE of a reference curve: the median of its last
/// [`CONVERGED_TAIL`] evaluated epochs with a validation RMSE.
///
/// # Errors
/// [`JobError::Setting`] when the curve has no validation RMSE.
pub fn converged_rmse(reference: &[CurvePoint], source: &Path) -> Result<f64> {
    let vals: Vec<f64> = reference
        .iter()
        .map(|p| p.val_rmse)
        .filter(|v| v.is_finite())
        .collect();
    if vals.is_empty() {
        return Err(JobError::Setting {
            name: "reference".into(),
            value: source.display().to_string(),
            expected: "a learning curve with validation RMSEs (train with --val-fraction > 0)"
                .into(),
        });
    }
    let tail = ((vals.len() as f64 * CONVERGED_TAIL).ceil() as usize).max(1);
    flapssm_analysis::stats::median(&vals[vals.len() - tail..]).map_err(|e| JobError::Analysis {
        what: format!("converged RMSE of {}", source.display()),
        source: e,
    })
}

/// Time-to-quality of `run` against the converged value of `reference` (which may be the
/// same curve).
///
/// # Errors
/// [`converged_rmse`]'s errors; [`JobError::Setting`] for an empty run.
pub fn time_to_quality(
    run: &[CurvePoint],
    reference: &[CurvePoint],
    reference_path: &Path,
    tolerance: f64,
) -> Result<TimeToQuality> {
    let converged = converged_rmse(reference, reference_path)?;
    let last = *run.last().ok_or_else(|| JobError::Setting {
        name: "curve".into(),
        value: "empty".into(),
        expected: "at least one evaluated epoch".into(),
    })?;
    let threshold = (1.0 + tolerance) * converged;
    let evaluated: Vec<CurvePoint> = run
        .iter()
        .copied()
        .filter(|p| p.val_rmse.is_finite())
        .collect();
    let vals: Vec<f64> = evaluated.iter().map(|p| p.val_rmse).collect();
    let mut held = None;
    for (window, end) in vals
        .windows(RUNNING_MEDIAN_WINDOW)
        .zip(evaluated.iter().skip(RUNNING_MEDIAN_WINDOW - 1))
    {
        let median = flapssm_analysis::stats::median(window).map_err(|e| JobError::Analysis {
            what: "running median of the validation RMSE".into(),
            source: e,
        })?;
        if median <= threshold {
            held = Some(*end);
            break;
        }
    }
    Ok(TimeToQuality {
        converged_rmse: converged,
        threshold,
        reached: evaluated.iter().copied().find(|p| p.val_rmse <= threshold),
        held,
        last,
        best_rmse: vals.iter().copied().fold(f64::INFINITY, f64::min),
    })
}

/// Where early stopping with `patience` would have ended a run recorded without it: the
/// evaluated epoch at which the last `patience` epochs brought no new lowest validation RMSE,
/// and the best epoch kept then. `None` when the run never stalled that long.
pub fn early_stop_point(run: &[CurvePoint], patience: usize) -> Option<(CurvePoint, CurvePoint)> {
    let mut best: Option<CurvePoint> = None;
    let mut since = 0;
    for p in run {
        if best.is_none_or(|b| p.val_rmse < b.val_rmse) {
            best = Some(*p);
            since = 0;
        } else {
            since += 1;
            if since == patience {
                return best.map(|b| (*p, b));
            }
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    fn point(epoch: u64, wall_s: f64, val_rmse: f64) -> CurvePoint {
        CurvePoint {
            epoch,
            step: 10 * (epoch + 1),
            wall_s,
            mean_loss: -1.0,
            train_rmse: f64::NAN,
            val_rmse,
        }
    }

    #[test]
    fn converged_value_is_the_median_of_the_last_tenth() {
        // 20 epochs: the last two (0.30, 0.34) give 0.32; the noisy start does not count.
        let mut c: Vec<CurvePoint> = (0..18).map(|e| point(e, e as f64, 1.0)).collect();
        c.push(point(18, 18.0, 0.30));
        c.push(point(19, 19.0, 0.34));
        let p = Path::new("ref.csv");
        assert!((converged_rmse(&c, p).unwrap() - 0.32).abs() < 1e-15);
        // A faster run reaches 1.02 × 0.32 = 0.3264 at its first epoch at or below it.
        let run = [
            point(0, 5.0, 0.5),
            point(1, 9.0, 0.3265),
            point(2, 14.0, 0.326),
        ];
        let q = time_to_quality(&run, &c, p, QUALITY_TOLERANCE).unwrap();
        assert_eq!(q.reached.unwrap().epoch, 2);
        assert_eq!(q.reached.unwrap().wall_s, 14.0);
        assert_eq!(q.best_rmse, 0.326);
        assert!(q.held.is_none(), "three evaluations are no full window");
        // A lucky dip at epoch 3 is reached but not held; the trailing median of 11 first
        // comes below the threshold when 6 of the last 11 are: at epoch 15, were epoch 12
        // evaluated.
        let mut dip: Vec<CurvePoint> = (0..20)
            .map(|e| point(e, e as f64, if e >= 10 { 0.32 } else { 0.5 }))
            .collect();
        dip[3].val_rmse = 0.30;
        dip[12].val_rmse = f64::NAN;
        let q = time_to_quality(&dip, &c, p, QUALITY_TOLERANCE).unwrap();
        assert_eq!(q.reached.unwrap().epoch, 3);
        assert_eq!(q.held.unwrap().epoch, 16);
        let slow = [point(0, 5.0, 0.5), point(1, 9.0, 0.4)];
        assert!(
            time_to_quality(&slow, &c, p, QUALITY_TOLERANCE)
                .unwrap()
                .reached
                .is_none()
        );
        // Patience 2 on 0.5, 0.3265, 0.326: never stalls; on a rise it stops two epochs later.
        assert!(early_stop_point(&run, 2).is_none());
        let rise = [
            point(0, 1.0, 0.5),
            point(1, 2.0, 0.4),
            point(2, 3.0, 0.45),
            point(3, 4.0, 0.41),
            point(4, 5.0, 0.3),
        ];
        let (stop, kept) = early_stop_point(&rise, 2).unwrap();
        assert_eq!((stop.epoch, kept.epoch), (3, 1));
        let none = [point(0, 1.0, f64::NAN)];
        let e = converged_rmse(&none, p).unwrap_err().to_string();
        assert!(e.contains("ref.csv") && e.contains("validation"), "{e}");
    }

    #[test]
    fn a_curve_round_trips_through_its_file_and_resumes() {
        let dir = std::env::temp_dir().join(format!("flapssm-curve-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("m.curve.csv");
        let pts = [
            point(0, 1.5, 0.9),
            point(1, 3.25, f64::NAN),
            point(2, 5.0, 0.7),
        ];
        std::fs::write(&path, curve_text(&pts)).unwrap();
        let back = read_curve(&path).unwrap();
        assert_eq!(back.len(), 3);
        assert_eq!((back[1].step, back[1].wall_s), (20, 3.25));
        assert!(back[1].val_rmse.is_nan() && back[2].val_rmse == 0.7);
        // Resuming at step 20 keeps the first two rows and continues their wall time.
        let mut rec = CurveRecorder::new(&path, Some(20)).unwrap();
        let r = EpochRecord {
            epoch: 2,
            step: 30,
            mean_loss: -2.0,
            train_rmse: None,
            val_rmse: Some(0.6),
            lr: 0.01,
            is_best: true,
        };
        rec.record(&r).unwrap();
        let back = read_curve(&path).unwrap();
        assert_eq!(back.len(), 3);
        assert_eq!((back[1].epoch, back[2].epoch), (1, 2));
        assert!(back[2].wall_s >= 3.25 && back[2].val_rmse == 0.6);
        // A fresh run leaves the file alone until its first step, then starts it afresh.
        let mut fresh = CurveRecorder::new(&path, None).unwrap();
        assert_eq!(read_curve(&path).unwrap().len(), 3);
        fresh.begin().unwrap();
        assert!(read_curve(&path).unwrap().is_empty());
        std::fs::write(&path, "epoch,step\n1,2\n").unwrap();
        let e = read_curve(&path).unwrap_err().to_string();
        assert!(e.contains("m.curve.csv") && e.contains("wall_s"), "{e}");
        std::fs::write(&path, curve_text(&pts).replace("3.250", "x")).unwrap();
        let e = read_curve(&path).unwrap_err().to_string();
        assert!(e.contains("line 4, column 3") && e.contains("'x'"), "{e}");
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
