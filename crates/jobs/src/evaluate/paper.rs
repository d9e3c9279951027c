//! The paper beside flapssm: every quantitative endpoint of Bayiz & Cheng (2021), transcribed
//! once here with the figure and the line of `shared/paper/bayiz-cheng-2021-state-space-aero-model.tex`
//! it comes from, and the same measure computed from an [`EvaluationReport`].
//!
//! Definitions on the flapssm side (the paper's where it states them):
//! - Fig. 3 rows: last-cycle RMSE of C_Fx / C_Fy on the six example test trajectories — on the
//!   paper's own trajectories the paper's six (test #26, #14, #13, #33, #5, #32), else six
//!   test trajectories of distinct shape families; ratios are LRQSM / PR-SSM per trajectory.
//! - Fig. 4A rows: the range, over the five outputs, of the absolute 2.5 % and 97.5 % bounds of
//!   the standardized errors (σ of the training outputs).
//! - Fig. 4B rows: the 95 % interval of the half-stroke-average coefficient errors, training
//!   and test together.
//! - Fig. 5 rows: medians over trajectories of the largest |r| and its lag (cycles) of the
//!   PR-SSM latent means; "on the outputs" is the median over x1..x5. Latent states beyond the
//!   outputs are identified only up to a change of basis, so flapssm's x7 need not be the
//!   paper's x7: those rows are reported for the same index, and say so.
//! - Prediction time: median wall time of one trajectory's prediction (one thread, the
//!   evaluation's particles).
//! - The D_x and training-set-size selections come from sweeps, not from one evaluation:
//!   [`selection_rows`] fills them from sweep results.

use serde::{Deserialize, Serialize};

use flapssm_analysis::stats::{Interval, median};

use crate::sweep::SweepKind;

use super::report::{AuthorityFinding, EvaluationReport};
pub use super::report::{ComparisonRow, Relation};

/// The paper's LaTeX source, for the `source` column.
pub const PAPER_TEX: &str = "shared/paper/bayiz-cheng-2021-state-space-aero-model.tex";

/// The paper's six example test trajectories of Fig. 3 (1-based test numbers) in its order.
pub const FIG3_TEST_NUMBERS: [usize; 6] = [26, 14, 13, 33, 5, 32];
/// Fig. 3 caption (line 113): last-cycle C_Fx RMSE per example, [PR-SSM, LRQSM].
pub const FIG3_CFX_RMSE: [[f64; 2]; 6] = [
    [0.11, 0.33],
    [0.19, 0.33],
    [0.17, 0.35],
    [0.21, 0.54],
    [0.13, 0.26],
    [0.20, 0.38],
];
/// Fig. 3 caption (line 113): C_Fy RMSE per example, [PR-SSM, LRQSM].
pub const FIG3_CFY_RMSE: [[f64; 2]; 6] = [
    [0.042, 0.16],
    [0.094, 0.271],
    [0.086, 0.208],
    [0.063, 0.240],
    [0.051, 0.150],
    [0.04, 0.190],
];
/// Line 121: LRQSM / PR-SSM RMSE over the examples, as the text states it, [C_Fx, C_Fy].
pub const FIG3_RATIO_TEXT: [[f64; 2]; 2] = [[1.7, 3.0], [2.5, 4.0]];
/// Line 128: range over outputs of the 95 % bounds of the standardized errors (σ),
/// [[PR-SSM train, PR-SSM test], [LRQSM train, LRQSM test]].
pub const FIG4A_BOUNDS: [[[f64; 2]; 2]; 2] =
    [[[0.20, 0.36], [0.23, 0.48]], [[0.40, 0.88], [0.41, 0.92]]];
/// Line 140: 95 % intervals of the half-stroke-average errors, training and test together,
/// [[PR-SSM C_Fx, PR-SSM C_Fy], [LRQSM C_Fx, LRQSM C_Fy]].
pub const FIG4B_INTERVALS: [[[f64; 2]; 2]; 2] = [
    [[-0.19, 0.15], [-0.07, 0.08]],
    [[-0.36, 0.31], [-0.20, 0.20]],
];
/// Line 118: prediction of one trajectory (s), GTX 1070 GPU + i7-7700K, TensorFlow.
pub const PREDICTION_S: f64 = 0.25;

/// A Fig. 5 finding: input(s), state(s), the paper's words (with its median max |r| and lag
/// in cycles where it states them), and its line. A claim about several inputs gives one row per input.
#[derive(Debug, Clone, Copy)]
pub struct AuthorityClaim {
    /// Input labels (as [`crate::evaluate::INPUT_LABELS`]).
    pub inputs: &'static [&'static str],
    /// States, 1-based (`x1..x5` are the outputs).
    pub states: &'static [usize],
    /// The paper's words.
    pub text: &'static str,
    /// Line of [`PAPER_TEX`].
    pub line: u32,
}

const OUTPUTS: &[usize] = &[1, 2, 3, 4, 5];

/// Every Fig. 5 finding the text states.
pub const FIG5_CLAIMS: [AuthorityClaim; 8] = [
    AuthorityClaim {
        inputs: &["AoA"],
        states: OUTPUTS,
        text: "consistently around 0 delay and |r| 0.75",
        line: 158,
    },
    AuthorityClaim {
        inputs: &["a_x"],
        states: OUTPUTS,
        text: "strong, delay persistently around 20 % of the cycle",
        line: 158,
    },
    AuthorityClaim {
        inputs: &["dα/dt", "d²α/dt²"],
        states: OUTPUTS,
        text: "median |r| within [0.7, 0.8]; delays scattered",
        line: 158,
    },
    AuthorityClaim {
        inputs: &["d²α/dt²"],
        states: &[7],
        text: "exclusive to 0 delay, median |r| 0.72",
        line: 160,
    },
    AuthorityClaim {
        inputs: &["dα/dt"],
        states: &[7],
        text: "median |r| 0.80, tightly clustered at 21.1 % of the cycle",
        line: 160,
    },
    AuthorityClaim {
        inputs: &["a_y"],
        states: &[8],
        text: "delayed by 17 % of the cycle",
        line: 160,
    },
    AuthorityClaim {
        inputs: &["a_y"],
        states: &[10],
        text: "delayed by 9.5 % of the cycle",
        line: 160,
    },
    AuthorityClaim {
        inputs: &["a_y"],
        states: &[12],
        text: "delayed by 15.3 % of the cycle",
        line: 160,
    },
];

/// The (input label, 1-based state) pairs of every Fig. 5 claim, in the claims' order: the
/// pairs an evaluation reports ([`crate::evaluate::EvaluationReport::authority_findings`]).
pub fn fig5_pairs() -> impl Iterator<Item = (&'static str, usize)> {
    FIG5_CLAIMS.iter().flat_map(|c| {
        c.inputs
            .iter()
            .flat_map(move |&input| c.states.iter().map(move |&state| (input, state)))
    })
}

fn range_text(r: [f64; 2], digits: usize) -> String {
    format!("{:.digits$}–{:.digits$}", r[0], r[1])
}

fn interval_text(r: [f64; 2]) -> String {
    format!("[{:.2}, {:.2}]", r[0], r[1])
}

fn min_max(v: impl IntoIterator<Item = f64>) -> Option<[f64; 2]> {
    v.into_iter().fold(None, |acc, x| match acc {
        None => Some([x, x]),
        Some([lo, hi]) => Some([lo.min(x), hi.max(x)]),
    })
}

/// Rows comparing every endpoint of one evaluation with the paper. The PR-SSM and the LRQSM
/// are found by their keys (`prssm`, `lrqsm`); rows of a missing model are left out.
pub fn compare(report: &EvaluationReport) -> Vec<ComparisonRow> {
    let mut rows = Vec::new();
    let index = |key: &str| report.models.iter().position(|m| m.key == key);
    let (kp, kl) = (index("prssm"), index("lrqsm"));
    let (prssm, lrqsm) = (report.model("prssm"), report.model("lrqsm"));
    let ex = &report.example_trajectories;
    let per_example = |k: usize, c: usize| -> Vec<f64> {
        ex.iter()
            .filter_map(|&i| report.trajectories.get(i))
            .map(|t| t.models[k].cycle_rmse_cf[c])
            .collect()
    };
    let src3 = "Fig. 3 caption, line 113".to_string();
    for (c, label, table) in [(0, "C_Fx", FIG3_CFX_RMSE), (1, "C_Fy", FIG3_CFY_RMSE)] {
        let digits = if c == 0 { 2 } else { 3 };
        for (m, k, name) in [(0, kp, "PR-SSM"), (1, kl, "LRQSM")] {
            let Some(k) = k else { continue };
            let paper = min_max(table.iter().map(|r| r[m])).unwrap_or_default();
            let ours = per_example(k, c);
            let Some(range) = min_max(ours.iter().copied()) else {
                continue;
            };
            rows.push(ComparisonRow {
                endpoint: format!("{label} RMSE, {name}, six example test trajectories"),
                source: src3.clone(),
                paper: range_text(paper, digits),
                flapssm: format!(
                    "{} ({})",
                    range_text(range, digits),
                    ours.iter()
                        .map(|v| format!("{v:.digits$}"))
                        .collect::<Vec<_>>()
                        .join(" ")
                ),
                relation: Some(Relation::of(range, paper)),
            });
        }
    }
    if let (Some(kp), Some(kl)) = (kp, kl) {
        for (c, label) in [(0, "C_Fx"), (1, "C_Fy")] {
            let ratios: Vec<f64> = per_example(kl, c)
                .iter()
                .zip(per_example(kp, c))
                .map(|(l, p)| l / p)
                .collect();
            let Some(range) = min_max(ratios.iter().copied()) else {
                continue;
            };
            let paper = FIG3_RATIO_TEXT[c];
            rows.push(ComparisonRow {
                endpoint: format!("{label} RMSE ratio LRQSM / PR-SSM, six examples"),
                source: "Fig. 3, line 121".into(),
                paper: format!("{:.1}–{:.0}×", paper[0], paper[1]),
                flapssm: format!("{}×", range_text(range, 2)),
                relation: Some(Relation::of(range, paper)),
            });
        }
    }
    for (m, model, name) in [(0, prssm, "PR-SSM"), (1, lrqsm, "LRQSM")] {
        let Some(model) = model else { continue };
        for (s, split, metrics) in [
            (0, "training", Some(&model.train)),
            (1, "test", model.test.as_ref()),
        ] {
            let Some(metrics) = metrics else { continue };
            let Some(range) = min_max(
                metrics
                    .error_interval
                    .iter()
                    .flat_map(|i| [i.lo.abs(), i.hi.abs()]),
            ) else {
                continue;
            };
            let paper = FIG4A_BOUNDS[m][s];
            rows.push(ComparisonRow {
                endpoint: format!("95 % error bounds over the 5 outputs (σ), {name}, {split}"),
                source: "Fig. 4A, line 128".into(),
                paper: range_text(paper, 2),
                flapssm: range_text(range, 2),
                relation: Some(Relation::of(range, paper)),
            });
        }
    }
    for (m, model, name) in [(0, prssm, "PR-SSM"), (1, lrqsm, "LRQSM")] {
        let Some(model) = model else { continue };
        for (c, label) in [(0, "C_Fx"), (1, "C_Fy")] {
            let Some(i) = model.cycle_average_error_interval_all.get(c) else {
                continue;
            };
            let paper = FIG4B_INTERVALS[m][c];
            rows.push(ComparisonRow {
                endpoint: format!(
                    "95 % interval of half-stroke-average {label} errors, {name}, train + test"
                ),
                source: "Fig. 4B, line 140".into(),
                paper: interval_text(paper),
                flapssm: format!(
                    "{} (width {:.2} vs {:.2})",
                    interval_text([i.lo, i.hi]),
                    i.hi - i.lo,
                    paper[1] - paper[0]
                ),
                relation: None,
            });
        }
    }
    rows.extend(authority_rows(&report.authority_findings));
    if let Some(ms) = report
        .prediction_timing
        .iter()
        .find(|t| t.model == "prssm")
        .map(|t| t.median_ms)
    {
        rows.push(ComparisonRow {
            endpoint: "prediction of one trajectory, PR-SSM".into(),
            source: "line 118".into(),
            paper: format!("< {PREDICTION_S} s (GPU)"),
            flapssm: format!("{:.4} s (one CPU thread, median)", ms / 1000.0),
            relation: Some(Relation::of([ms / 1000.0; 2], [0.0, PREDICTION_S])),
        });
    }
    rows
}

fn authority_rows(findings: &[AuthorityFinding]) -> Vec<ComparisonRow> {
    let mut rows = Vec::new();
    let per_input = FIG5_CLAIMS
        .iter()
        .flat_map(|c| c.inputs.iter().map(move |&input| (input, c)));
    for (input, claim) in per_input {
        let of_claim: Vec<&AuthorityFinding> = findings
            .iter()
            .filter(|f| f.input == input)
            .filter(|f| claim.states.iter().any(|s| f.state == format!("x{s}")))
            .collect();
        if of_claim.len() != claim.states.len() {
            continue;
        }
        let med = |get: fn(&AuthorityFinding) -> f64| {
            let v: Vec<f64> = of_claim.iter().map(|f| get(f)).collect();
            median(&v).unwrap_or(f64::NAN)
        };
        let (r, lag, iqr) = (
            med(|f| f.median_abs_r),
            med(|f| f.median_lag_cycles),
            med(|f| f.lag_iqr_cycles),
        );
        let states = if claim.states.len() > 1 {
            "the outputs x1–x5 (median over them)".to_string()
        } else {
            format!(
                "x{} (latent, identified up to a change of basis)",
                claim.states[0]
            )
        };
        rows.push(ComparisonRow {
            endpoint: format!("{input} → {states}: median max |r|, lag (cycles)"),
            source: format!("Fig. 5, line {}", claim.line),
            paper: claim.text.into(),
            flapssm: format!("|r| {r:.2}, lag {lag:.3} (IQR {iqr:.3})"),
            relation: None,
        });
    }
    rows
}

/// One swept value's result over seeds (a D_x or training-set-size sweep).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectionPoint {
    /// The swept value (D_x or training trajectories).
    pub value: usize,
    /// Mean over seeds of the overall RMSE (σ) on the training trajectories.
    pub train_rmse: f64,
    /// Mean over seeds of the overall test RMSE (σ).
    pub test_rmse: f64,
    /// Spread (max − min) of the test RMSE over seeds.
    pub test_spread: f64,
    /// Spread (max − min) of the training RMSE over seeds.
    pub train_spread: f64,
    /// Seeds.
    pub seeds: usize,
}

/// One swept value against the reference value (D_x 12, the paper's; the largest training
/// set), paired by seed: the mean over the seeds both ran of the difference of overall test
/// RMSE, with its 95 % Student-t interval over those seeds.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SelectionDifference {
    /// The swept value.
    pub value: usize,
    /// The value it is compared with.
    pub reference: usize,
    /// Seeds both ran.
    pub seeds: usize,
    /// Mean of `RMSE(value) − RMSE(reference)` over those seeds (σ).
    pub mean: f64,
    /// Its 95 % interval over seeds (`None` with a single seed).
    pub interval: Option<Interval>,
    /// Whether the interval excludes zero.
    pub significant: bool,
}

impl std::fmt::Display for SelectionDifference {
    /// `16 − 12: +0.001 [−0.010, +0.012] (2 seeds)`, `*` when significant.
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{} − {}: {:+.3}", self.value, self.reference, self.mean)?;
        if let Some(i) = self.interval {
            write!(f, " [{:+.3}, {:+.3}]", i.lo, i.hi)?;
        }
        write!(
            f,
            " ({} seed{}){}",
            self.seeds,
            if self.seeds == 1 { "" } else { "s" },
            if self.significant { "*" } else { "" }
        )
    }
}

/// The rows of the paper's two selections (line 95) from sweep results: `dx` points for
/// D_x ∈ {8, 12, 16}, `sizes` points for the training-set size, and each value's paired
/// difference from its reference over seeds.
pub fn selection_rows(
    dx: &[SelectionPoint],
    sizes: &[SelectionPoint],
    differences: &[(SweepKind, SelectionDifference)],
) -> Vec<ComparisonRow> {
    let paired = |kind: SweepKind| {
        let d: Vec<String> = differences
            .iter()
            .filter(|(k, _)| *k == kind)
            .map(|(_, d)| d.to_string())
            .collect();
        if d.is_empty() {
            String::new()
        } else {
            format!(
                "; paired over seeds, test RMSE difference [95 % t interval]: {}",
                d.join("; ")
            )
        }
    };
    let mut rows = Vec::new();
    if !dx.is_empty() {
        rows.push(ComparisonRow {
            endpoint: "latent dimension D_x ∈ {8, 12, 16}: test RMSE (σ), mean ± spread over seeds"
                .into(),
            source: "Methods, line 95".into(),
            paper: "12 noticeably better than 8; 12 and 16 indistinguishable".into(),
            flapssm: dx
                .iter()
                .map(|p| {
                    format!(
                        "{}: {:.3} ± {:.3} ({} seeds)",
                        p.value, p.test_rmse, p.test_spread, p.seeds
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
                + &paired(SweepKind::Dx),
            relation: None,
        });
    }
    if !sizes.is_empty() {
        rows.push(ComparisonRow {
            endpoint: "training-set size: training / test RMSE (σ), mean ± spread over seeds"
                .into(),
            source: "Methods, line 95".into(),
            paper: "512 training trajectories: training and test accuracy similar".into(),
            flapssm: sizes
                .iter()
                .map(|p| {
                    format!(
                        "{}: {:.3} ± {:.3} / {:.3} ± {:.3}",
                        p.value, p.train_rmse, p.train_spread, p.test_rmse, p.test_spread
                    )
                })
                .collect::<Vec<_>>()
                .join("; ")
                + &paired(SweepKind::DataSize),
            relation: None,
        });
    }
    rows
}

/// The rows as a Markdown table (pipes in the text escaped).
pub fn markdown(rows: &[ComparisonRow]) -> String {
    let cell = |t: &str| t.replace('|', "\\|");
    let mut s = String::from("| endpoint | source | paper | flapssm | flapssm vs paper |\n");
    s.push_str("|---|---|---|---|---|\n");
    for r in rows {
        s.push_str(&format!(
            "| {} | {} | {} | {} | {} |\n",
            cell(&r.endpoint),
            cell(&r.source),
            cell(&r.paper),
            cell(&r.flapssm),
            r.relation.map_or("—", Relation::words)
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn markdown_escapes_pipes() {
        let row = ComparisonRow {
            endpoint: "AoA: median max |r|".into(),
            source: "line 158".into(),
            paper: "|r| 0.75".into(),
            flapssm: "|r| 0.74".into(),
            relation: None,
        };
        let md = markdown(&[row]);
        let line = md.lines().nth(2).unwrap();
        assert_eq!(
            line.matches('|').count() - line.matches("\\|").count(),
            6,
            "{line}"
        );
    }

    /// Every Fig. 5 input is one the evaluation knows, and the pairs cover each claim.
    #[test]
    fn fig5_pairs_name_known_inputs() {
        let pairs: Vec<_> = fig5_pairs().collect();
        assert_eq!(pairs.len(), 4 * 5 + 2 + 3);
        for (input, state) in pairs {
            assert!(crate::evaluate::INPUT_LABELS.contains(&input), "{input}");
            assert!((1..=12).contains(&state));
        }
    }

    #[test]
    fn relation_of_ranges() {
        assert_eq!(Relation::of([0.1, 0.2], [0.0, 0.3]), Relation::Inside);
        assert_eq!(Relation::of([0.1, 0.4], [0.0, 0.3]), Relation::Overlaps);
        assert_eq!(Relation::of([0.0, 0.05], [0.1, 0.3]), Relation::Below);
        assert_eq!(Relation::of([0.4, 0.5], [0.1, 0.3]), Relation::Above);
    }

    /// The transcription agrees with the caption's own arithmetic: the text's ratio ranges
    /// bracket the caption's per-trajectory ratios to the precision the text states them.
    #[test]
    fn transcribed_values_are_consistent() {
        let ratio = |t: &[[f64; 2]; 6]| min_max(t.iter().map(|r| r[1] / r[0])).unwrap();
        let fx = ratio(&FIG3_CFX_RMSE);
        assert!(
            (fx[0] - 1.74).abs() < 0.01 && (fx[1] - 3.0).abs() < 0.01,
            "{fx:?}"
        );
        let fy = ratio(&FIG3_CFY_RMSE);
        // The caption's #32 (0.04 / 0.190 = 4.75) and #13 (2.42) lie outside the text's 2.5–4.
        assert!(
            (fy[0] - 2.42).abs() < 0.01 && (fy[1] - 4.75).abs() < 0.01,
            "{fy:?}"
        );
        assert_eq!(FIG3_TEST_NUMBERS.len(), FIG3_CFX_RMSE.len());
    }
}
