//! The published hovering experiment of Wang, Birch & Dickinson (2004) against the virtual
//! wing: the lift and drag histories of the robotic-wing experiment and two computations
//! (../shared/data/wang2004-hovering) beside every fidelity's
//! ([`flapssm_wing::hovering2d`]), measured on the last of the four periods.
//!
//! Per source: the period means of C_L and C_D; in each half-stroke (from the reversals at
//! t/T = 3 and 3.5) the first peak (within 0.2 T of the reversal, where the wing meets the wake
//! of the stroke before and flips) and the mid-stroke peak (0.2–0.5 T) of C_L and C_D, their
//! times after the reversal and heights; the early share, the mean force over 0.005–0.15 T after
//! the reversal over its mean over 0.15–0.5 T, and the wake capture, the early share less the
//! memoryless wing's (L0): positive when the force after a reversal stands higher against the
//! rest of the half-stroke than a wing without memory gives, whatever the force's level (the
//! levels differ by up to 1.7× between sources); and each source's correlation with the
//! experiment over the period.

use std::path::Path;

use flapssm_data::table::Table;
use flapssm_wing::hovering2d::{Hovering2d, HoveringLoads};
use flapssm_wing::virtual_wing::Fidelity;
use serde::{Deserialize, Serialize};

use crate::error::{JobError, Result, analysis};

/// The published histories: display name and file stem (`CL_<stem>.dat`, `CD_<stem>.dat`).
pub const PUBLISHED: [(&str, &str); 3] = [
    ("experiment (Wang et al. 2004)", "EXP"),
    ("VVPM (Eldredge 2007)", "VVPM"),
    ("IB-CFD (Li et al. 2015)", "current"),
];

/// The fidelities run, in order.
pub const FIDELITIES: [Fidelity; 4] = [Fidelity::L0, Fidelity::L1, Fidelity::L2, Fidelity::L3];

/// Samples per period of the common grid every history is put on.
const GRID_PER_PERIOD: usize = 1000;
/// The period analysed: the last of the four.
const LAST_PERIOD: f64 = 3.0;

/// A lift and drag history on the common grid (t/T = k / 1000, 0 ≤ t/T ≤ 4).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct History {
    /// Source name.
    pub name: String,
    /// C_L.
    pub lift: Vec<f64>,
    /// C_D.
    pub drag: Vec<f64>,
}

/// The grid's times t/T.
pub fn grid() -> Vec<f64> {
    (0..=4 * GRID_PER_PERIOD)
        .map(|k| k as f64 / GRID_PER_PERIOD as f64)
        .collect()
}

/// Linear interpolation of the samples (t, y) (sorted by t here) at `at`, held constant beyond
/// the ends.
fn resample(t: &[f64], y: &[f64], at: &[f64]) -> Vec<f64> {
    let mut pairs: Vec<(f64, f64)> = t.iter().copied().zip(y.iter().copied()).collect();
    pairs.sort_by(|a, b| a.0.total_cmp(&b.0));
    at.iter()
        .map(|&x| {
            let k = pairs.partition_point(|p| p.0 <= x);
            match (k.checked_sub(1).map(|i| pairs[i]), pairs.get(k)) {
                (Some(a), Some(b)) if b.0 > a.0 => a.1 + (b.1 - a.1) * (x - a.0) / (b.0 - a.0),
                (Some(a), _) => a.1,
                (None, Some(b)) => b.1,
                (None, None) => f64::NAN,
            }
        })
        .collect()
}

/// Reads the published histories from `dir` onto the common grid.
///
/// # Errors
/// [`JobError::Table`] naming a missing or malformed file; [`JobError::Mismatch`] for a file
/// without two columns or with times outside 0–10 periods.
pub fn read_published(dir: &Path) -> Result<Vec<History>> {
    let at = grid();
    PUBLISHED
        .iter()
        .map(|&(name, stem)| {
            let read = |quantity: &str| -> Result<Vec<f64>> {
                let path = dir.join(format!("{quantity}_{stem}.dat"));
                let table = Table::read_ascii(&path)?;
                let bad_times = table
                    .columns
                    .first()
                    .is_some_and(|t| t.iter().any(|x| !(0.0..=10.0).contains(x)));
                if table.columns.len() != 2 || bad_times {
                    return Err(JobError::Mismatch {
                        what: path.display().to_string(),
                        expected: "two columns: t/T (0–10) and the coefficient".into(),
                        found: format!("{} columns", table.columns.len()),
                    });
                }
                Ok(resample(&table.columns[0], &table.columns[1], &at))
            };
            Ok(History {
                name: name.into(),
                lift: read("CL")?,
                drag: read("CD")?,
            })
        })
        .collect()
}

/// One fidelity's history on the common grid.
///
/// # Errors
/// The simulation's errors.
pub fn simulate_history(case: &Hovering2d, fidelity: Fidelity) -> Result<History> {
    let HoveringLoads {
        t_periods,
        lift,
        drag,
    } = case.simulate(fidelity)?;
    let at = grid();
    Ok(History {
        name: format!("flapssm {fidelity:?}"),
        lift: resample(&t_periods, &lift, &at),
        drag: resample(&t_periods, &drag, &at),
    })
}

/// A peak: its time after the reversal (periods) and height.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Peak {
    /// Time after the reversal, t/T.
    pub after_reversal: f64,
    /// Height.
    pub value: f64,
}

/// One half-stroke's features.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct HalfStroke {
    /// The reversal it starts at, t/T.
    pub reversal: f64,
    /// Largest C_L within 0.2 T of the reversal.
    pub early_lift: Peak,
    /// Largest C_L 0.2–0.5 T after it.
    pub mid_lift: Peak,
    /// Largest C_D 0.005–0.2 T after it.
    pub early_drag: Peak,
    /// Largest C_D 0.2–0.5 T after it.
    pub mid_drag: Peak,
    /// Mean C_L over 0.005–0.15 T after it over the mean over 0.15–0.5 T.
    pub early_share_lift: f64,
    /// The same of C_D.
    pub early_share_drag: f64,
    /// `early_share_lift` less the memoryless wing's.
    pub wake_lift: f64,
    /// `early_share_drag` less the memoryless wing's.
    pub wake_drag: f64,
}

/// A source's features on the last period.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct HoverFeatures {
    /// Source name.
    pub name: String,
    /// Mean C_L.
    pub mean_lift: f64,
    /// Mean C_D.
    pub mean_drag: f64,
    /// The two half-strokes.
    pub half_strokes: [HalfStroke; 2],
    /// r with the experiment's C_L over the period.
    pub r_lift_experiment: f64,
    /// r with the experiment's C_D.
    pub r_drag_experiment: f64,
}

/// Grid index of t/T.
fn index(t: f64) -> usize {
    (t * GRID_PER_PERIOD as f64).round() as usize
}

fn peak(y: &[f64], reversal: f64, from: f64, to: f64) -> Peak {
    let (a, b) = (index(reversal + from), index(reversal + to));
    let k = (a..b).max_by(|&i, &j| y[i].total_cmp(&y[j])).unwrap_or(a);
    Peak {
        after_reversal: (k - index(reversal)) as f64 / GRID_PER_PERIOD as f64,
        value: y[k],
    }
}

fn mean_over(y: &[f64], from: usize, to: usize) -> f64 {
    y[from..to].iter().sum::<f64>() / (to - from) as f64
}

/// The features of `h` on the last period, the wake capture against `memoryless` (L0) and the
/// correlation against `experiment`.
///
/// # Errors
/// [`JobError::Analysis`] when a history is constant over the period.
pub fn features(h: &History, memoryless: &History, experiment: &History) -> Result<HoverFeatures> {
    let (a, b) = (index(LAST_PERIOD), index(LAST_PERIOD + 1.0));
    let half = |reversal: f64| {
        let share = |y: &[f64]| {
            let at = |t: f64| index(reversal + t);
            mean_over(y, at(0.005), at(0.15)) / mean_over(y, at(0.15), at(0.5))
        };
        let (lift, drag) = (share(&h.lift), share(&h.drag));
        HalfStroke {
            reversal,
            early_lift: peak(&h.lift, reversal, 0.0, 0.2),
            mid_lift: peak(&h.lift, reversal, 0.2, 0.5),
            early_drag: peak(&h.drag, reversal, 0.005, 0.2),
            mid_drag: peak(&h.drag, reversal, 0.2, 0.5),
            early_share_lift: lift,
            early_share_drag: drag,
            wake_lift: lift - share(&memoryless.lift),
            wake_drag: drag - share(&memoryless.drag),
        }
    };
    let r = |x: &[f64], y: &[f64], what: &str| {
        flapssm_analysis::rig::pearson(&x[a..b], &y[a..b], what)
            .map_err(analysis(format!("{} {what}", h.name)))
    };
    Ok(HoverFeatures {
        name: h.name.clone(),
        mean_lift: mean_over(&h.lift, a, b),
        mean_drag: mean_over(&h.drag, a, b),
        half_strokes: [half(LAST_PERIOD), half(LAST_PERIOD + 0.5)],
        r_lift_experiment: r(&h.lift, &experiment.lift, "C_L")?,
        r_drag_experiment: r(&h.drag, &experiment.drag, "C_D")?,
    })
}

/// The comparison: every published source and every fidelity.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Wang2004 {
    /// The motion.
    pub case: Hovering2d,
    /// Features, the published sources first.
    pub features: Vec<HoverFeatures>,
    /// The histories on the grid (t/T = k/1000), same order; not in the JSON.
    #[serde(skip)]
    pub histories: Vec<History>,
}

/// Runs the comparison with the published histories of `dir`.
///
/// # Errors
/// Reading the files, the simulations and the features' errors.
pub fn wang2004(dir: &Path, case: &Hovering2d) -> Result<Wang2004> {
    let mut histories = read_published(dir)?;
    for fidelity in FIDELITIES {
        histories.push(simulate_history(case, fidelity)?);
    }
    let experiment = &histories[0];
    let memoryless = &histories[PUBLISHED.len()];
    let features = histories
        .iter()
        .map(|h| features(h, memoryless, experiment))
        .collect::<Result<_>>()?;
    Ok(Wang2004 {
        case: *case,
        features,
        histories,
    })
}

impl Wang2004 {
    /// The tables (Markdown).
    pub fn markdown(&self) -> String {
        use std::fmt::Write;
        let mut s = String::from(
            "Last period (t/T = 3–4), C = F/(½ρU_max²c). Half-strokes from the reversals at t/T = 3 \
             and 3.5, given as first / second.\n\n| source | mean C_L | mean C_D | r with the experiment, C_L | r, C_D |\n|---|---|---|---|---|\n",
        );
        for f in &self.features {
            let _ = writeln!(
                s,
                "| {} | {:.3} | {:.3} | {:.3} | {:.3} |",
                f.name, f.mean_lift, f.mean_drag, f.r_lift_experiment, f.r_drag_experiment
            );
        }
        s.push_str(
            "\n| source | first C_L peak: t/T after reversal, height | mid-stroke C_L peak | first C_D peak | \
             early share C_L (wake capture) | early share C_D (wake capture) |\n|---|---|---|---|---|---|\n",
        );
        let two = |f: &dyn Fn(&HalfStroke) -> String, h: &[HalfStroke; 2]| {
            format!("{} / {}", f(&h[0]), f(&h[1]))
        };
        let pk = |p: &Peak| format!("{:.3}, {:.2}", p.after_reversal, p.value);
        for f in &self.features {
            let h = &f.half_strokes;
            let _ = writeln!(
                s,
                "| {} | {} | {} | {} | {} | {} |",
                f.name,
                two(&|x| pk(&x.early_lift), h),
                two(&|x| pk(&x.mid_lift), h),
                two(&|x| pk(&x.early_drag), h),
                two(
                    &|x| format!("{:.2} ({:+.2})", x.early_share_lift, x.wake_lift),
                    h
                ),
                two(
                    &|x| format!("{:.2} ({:+.2})", x.early_share_drag, x.wake_drag),
                    h
                ),
            );
        }
        s
    }
}

pub use flapssm_analysis::plots::hovering::HoverSeries;

/// Draws the histories of the last two periods (t/T = 2–4) into `path`.
///
/// # Errors
/// [`JobError::Analysis`] naming the file.
pub fn figure(path: &Path, series: &[HoverSeries<'_>]) -> Result<()> {
    flapssm_analysis::plots::hovering::lift_drag(
        path,
        "Hovering 2-D case of Wang, Birch & Dickinson (2004): C = F/(½ρU_max²c)",
        series,
        2.0,
        4.0,
    )
    .map_err(analysis(path.display().to_string()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn resampling_interpolates_and_holds_the_ends() {
        let y = resample(&[1.0, 0.0, 2.0], &[10.0, 0.0, 0.0], &[-1.0, 0.5, 1.5, 3.0]);
        assert_eq!(y, vec![0.0, 5.0, 5.0, 0.0]);
    }

    #[test]
    fn features_of_a_known_history() {
        let t = grid();
        // Lift: a bump 0.1 T after each reversal of height 2 over a constant 1; drag 0.5.
        let lift: Vec<f64> = t
            .iter()
            .map(|&x| {
                let since = (x * 2.0).fract() / 2.0;
                1.0 + if (since - 0.1).abs() < 1e-9 { 1.0 } else { 0.0 }
            })
            .collect();
        let h = History {
            name: "h".into(),
            lift: lift.clone(),
            drag: t.iter().map(|x| 0.5 + 0.01 * x.sin()).collect(),
        };
        let flat = History {
            name: "flat".into(),
            lift: t.iter().map(|x| 1.0 + 0.01 * x.cos()).collect(),
            drag: t.iter().map(|x| 0.5 + 0.01 * x.cos()).collect(),
        };
        let f = features(&h, &flat, &h).unwrap();
        assert!((f.r_lift_experiment - 1.0).abs() < 1e-12);
        for hs in f.half_strokes {
            assert!((hs.early_lift.after_reversal - 0.1).abs() < 1e-12, "{hs:?}");
            assert!((hs.early_lift.value - 2.0).abs() < 1e-12);
            // The bump lies in the early window: its share rises by 1/(0.145·1000) against the
            // flat history's.
            assert!((hs.wake_lift - 1.0 / 145.0).abs() < 2e-3, "{hs:?}");
        }
        assert!((f.mean_lift - 1.0).abs() < 0.01);
        let e = features(&h, &flat, &flat);
        assert!(e.is_ok());
        let constant = History {
            name: "c".into(),
            lift: vec![1.0; t.len()],
            drag: vec![1.0; t.len()],
        };
        assert!(features(&constant, &flat, &h).is_err());
    }
}
