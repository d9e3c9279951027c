//! The evaluation's HTML report: what it says and which figures it shows.

use std::path::PathBuf;

use flapssm_wing::dataset::OUTPUT_NAMES;

use flapssm_analysis::report::{Figure, Report, Section, Table};
use flapssm_analysis::stats::Interval;

use super::figures::ReportFigures;
use super::report::{COEFFICIENT_LABELS, EvaluationReport, ReportContext};
use crate::models::LoadModel;

fn f3(v: f64) -> String {
    format!("{v:.3}")
}

fn interval_cells(v: &[Interval]) -> Vec<String> {
    v.iter()
        .map(|i| format!("[{:.2}, {:.2}]", i.lo, i.hi))
        .collect()
}

/// "A / B / C" of the models' names.
fn names(models: &[&dyn LoadModel]) -> String {
    models
        .iter()
        .map(|m| m.name())
        .collect::<Vec<_>>()
        .join(" / ")
}

/// A table row: a label, then cells.
fn row(label: String, cells: Vec<String>) -> Vec<String> {
    std::iter::once(label).chain(cells).collect()
}

/// Owned cells from text.
fn strings(cells: &[&str]) -> Vec<String> {
    cells.iter().map(|s| s.to_string()).collect()
}

/// A table header: the first column's name, then `names`.
fn header(first: &str, names: &[&str]) -> Vec<String> {
    std::iter::once(first.to_string())
        .chain(strings(names))
        .collect()
}

/// "A / B" of the first two models, the ratios' label.
fn ratio_label(r: &EvaluationReport) -> Option<String> {
    match &r.models[..] {
        [a, b, ..] => Some(format!("{} / {}", a.model, b.model)),
        _ => None,
    }
}

/// The report: its headline, then the paper beside flapssm, any sections of the caller,
/// accuracy, control authority, the wing motions and the training curves.
pub(super) fn html_report(
    r: &EvaluationReport,
    ctx: &ReportContext,
    f: ReportFigures,
    models: &[&dyn LoadModel],
) -> Report {
    let mut sections = Vec::new();
    sections.extend(paper_section(r));
    sections.extend(ctx.extra_sections.iter().cloned());
    let accuracy_figs = accuracy_figures(&f, models);
    sections.push(accuracy_section(r, accuracy_figs));
    sections.extend(authority_section(r, f.fig5, models));
    sections.extend(controls_section(r));
    sections.extend(hidden_section(r));
    sections.push(Section {
        heading: "Wing motions".into(),
        figures: vec![Figure {
            caption: "Fig. 2C — last full cycle of the example test trajectories (chord at the U_ref radius, LE dotted)".into(),
            path: f.f_2c,
        }],
        ..Default::default()
    });
    sections.extend(training_section(f.training, models));
    Report {
        title: if ctx.title.is_empty() {
            format!(
                "flapssm evaluation: {}",
                names(models).replace(" / ", " vs ")
            )
        } else {
            ctx.title.clone()
        },
        intro: ctx.intro.clone(),
        headline: headline(r, ctx, models),
        sections,
        config: serde_json::json!({
            "run": ctx.config,
            "evaluation": r.options,
            "models": models
                .iter()
                .map(|m| serde_json::json!({ "model": m.name(), "parameters": m.parameters() }))
                .collect::<Vec<_>>(),
        }),
        versions: versions(),
    }
}

/// Every input's authority on the hidden subspace beyond the outputs, basis-free
/// ([`flapssm_analysis::hidden`]), beside the paper's rows on single hidden states.
fn hidden_section(r: &EvaluationReport) -> Option<Section> {
    let first = r.hidden_authority.first()?;
    let rows = r
        .hidden_authority
        .iter()
        .map(|h| {
            vec![
                h.input.clone(),
                if h.paper.is_empty() {
                    "—".into()
                } else {
                    h.paper.clone()
                },
                f3(h.subspace.median_r),
                f3(h.subspace.median_lag_cycles),
                f3(h.subspace.lag_iqr_cycles),
                f3(h.subspace.chance_median_r),
                format!(
                    "{:+.3} [{:+.3}, {:+.3}]",
                    h.subspace.excess, h.subspace.excess_interval.lo, h.subspace.excess_interval.hi
                ),
                if h.subspace.above_chance { "yes" } else { "no" }.into(),
            ]
        })
        .collect();
    Some(Section {
        heading: "Control authority on the hidden subspace".into(),
        paragraphs: vec![format!(
            "The states beyond the outputs are defined only up to a change of basis, so the paper's rows on x7, x8, x10 and x12 are restated on the subspace they span ({} dimensions, the part the outputs explain removed): per trajectory the peak over 0 < lag < {} cycle of the multiple correlation R of the input with that subspace (the largest correlation with any combination of hidden states, unchanged by a change of basis), and the same with another trajectory's input, the chance level. An input has authority there when the mean excess of R over chance has a 95 % bootstrap interval above zero.",
            first.subspace.dimension, r.options.authority.max_lag_cycles
        )],
        tables: vec![Table {
            caption: "Each input on the hidden subspace".into(),
            header: strings(&[
                "input",
                "paper (single hidden states)",
                "median R",
                "median lag (cycles)",
                "lag IQR",
                "chance median R",
                "excess over chance [95 %]",
                "above chance",
            ]),
            rows,
        }],
        figures: Vec::new(),
    })
}

/// The Fig. 5 findings on the outputs beside their controls ([`super::controls`]).
fn controls_section(r: &EvaluationReport) -> Option<Section> {
    if r.authority_controls.is_empty() {
        return None;
    }
    let cell = |m: &super::controls::ControlMeasure| {
        format!(
            "|r| {:.2}, lag {:.3}{}",
            m.median_abs_r,
            m.median_lag_cycles,
            if m.reproduces { " ✓" } else { "" }
        )
    };
    let rows = r
        .authority_controls
        .iter()
        .map(|c| {
            vec![
                format!("{} → outputs", c.input),
                c.paper.clone(),
                c.rule.clone(),
                cell(&c.trained),
                cell(&c.dataset_loads),
                cell(&c.memoryless_loads),
                cell(&c.stand_in),
                c.verdict().into(),
            ]
        })
        .collect();
    Some(Section {
        heading: "Fig. 5 findings against controls".into(),
        paragraphs: vec!["The paper's cross-correlation rule on the trained model's output states x1–x5, on the dataset's loads, on the loads of a wing without fluid memory (L0, no sensor chain) on the same trajectories, and on the rig stand-in (the published model's mean prediction); medians over the five outputs, on the paper's 512 training trajectories for the loads. ✓: the column reproduces the paper's finding by the rule given. A finding the memoryless wing reproduces follows from the kinematics and cannot be evidence of fluid memory.".into()],
        tables: vec![Table {
            caption: "Fig. 5 findings on the outputs and their controls".into(),
            header: strings(&["finding", "paper", "rule", "trained model x1–x5", "dataset loads", "memoryless wing loads", "rig stand-in", "verdict"]),
            rows,
        }],
        ..Default::default()
    })
}

/// The report's key figures: the dataset, the overall test RMSE of every model, the ratios of
/// the first two, the AoA and a_x lags on the output states, then the caller's lines.
fn headline(
    r: &EvaluationReport,
    ctx: &ReportContext,
    models: &[&dyn LoadModel],
) -> Vec<(String, String)> {
    let overall: Vec<String> = r
        .models
        .iter()
        .map(|m| format!("{:.3}", m.test_or_train().overall_rmse_standardized))
        .collect();
    let mut headline = vec![
        (
            "dataset".to_string(),
            format!("{} ({} train / {} test)", r.dataset, r.n_train, r.n_test),
        ),
        (
            format!("overall test RMSE {} (σ units)", names(models)),
            overall.join(" / "),
        ),
    ];
    if let Some(label) = ratio_label(r) {
        headline.push((
            format!("test RMSE ratio {label} per output"),
            r.rmse_ratio
                .iter()
                .zip(OUTPUT_NAMES)
                .map(|(v, n)| format!("{n} {v:.2}"))
                .collect::<Vec<_>>()
                .join(", "),
        ));
    }
    for input in ["AoA", "a_x"] {
        let lags: Vec<String> = r
            .authority_findings
            .iter()
            .filter(|a| a.input == input)
            .map(|a| format!("{} {:.2}", a.state, a.median_lag_cycles))
            .collect();
        if !lags.is_empty() {
            headline.push((
                format!("median lag of {input} → output states (cycles)"),
                lags.join(", "),
            ));
        }
    }
    headline.extend(ctx.headline.iter().cloned());
    headline
}

/// Every endpoint of the paper beside this evaluation's (none without comparison rows).
fn paper_section(r: &EvaluationReport) -> Option<Section> {
    if r.paper_comparison.is_empty() {
        return None;
    }
    Some(Section {
        heading: "The paper beside flapssm".into(),
        paragraphs: vec![
            "Every quantitative endpoint of Bayiz & Cheng (2021), its value as the paper states it (figure and line of the LaTeX source) and the same measure on this evaluation. The last column says where flapssm's range lies against the paper's; the definitions are in the documentation of flapssm_jobs::evaluate::paper and docs/paper-comparison.md.".into(),
        ],
        tables: vec![Table {
            caption: "Paper vs flapssm".into(),
            header: strings(&["endpoint", "source", "paper", "flapssm", "flapssm vs paper"]),
            rows: r
                .paper_comparison
                .iter()
                .map(|c| {
                    vec![
                        c.endpoint.clone(),
                        c.source.clone(),
                        c.paper.clone(),
                        c.flapssm.clone(),
                        c.relation.map_or("—", |x| x.words()).into(),
                    ]
                })
                .collect(),
        }],
        ..Default::default()
    })
}

/// Figs. 3, 4A (training and test, where written) and 4B.
fn accuracy_figures(f: &ReportFigures, models: &[&dyn LoadModel]) -> Vec<Figure> {
    let mut figures = vec![Figure {
        caption: format!(
            "Fig. 3 — last full cycle of test trajectories: chord sketch, Euler angles, measured and predicted C_Fx, C_Fy (title: last-cycle C_Fx RMSE {})",
            names(models).replace(" / ", "/")
        ),
        path: f.f_3.clone(),
    }];
    for (path, set) in [(&f.f_4a_train, "training"), (&f.f_4a_test, "test")] {
        if let Some(path) = path {
            figures.push(Figure {
                caption: format!(
                    "Fig. 4A — standardized-error histograms, {set} set, with 95 % intervals"
                ),
                path: path.clone(),
            });
        }
    }
    figures.push(Figure {
        caption: "Fig. 4B — half-stroke averages: error vs measured value, training and test, with 95 % intervals".into(),
        path: f.f_4b.clone(),
    });
    figures
}

/// RMSE, error intervals and half-stroke-average intervals per model and set, and the test
/// trajectories' last-cycle coefficient RMSE.
fn accuracy_section(r: &EvaluationReport, figures: Vec<Figure>) -> Section {
    let mut rmse_rows = Vec::new();
    let mut ci_rows = Vec::new();
    let mut cyc_rows = Vec::new();
    for m in &r.models {
        for (split, s) in [("train", Some(&m.train)), ("test", m.test.as_ref())] {
            let Some(s) = s else { continue };
            let mut cells: Vec<String> = s.rmse_standardized.iter().map(|v| f3(*v)).collect();
            cells.push(f3(s.overall_rmse_standardized));
            cells.push(format!(
                "{:.3} / {:.3}",
                s.median_cycle_rmse_cf[0], s.median_cycle_rmse_cf[1]
            ));
            rmse_rows.push(row(format!("{} {split}", m.model), cells));
            ci_rows.push(row(
                format!("{} {split}", m.model),
                interval_cells(&s.error_interval),
            ));
            cyc_rows.push(row(
                format!("{} {split}", m.model),
                interval_cells(&s.cycle_average_error_interval),
            ));
        }
        cyc_rows.push(row(
            format!("{} train + test", m.model),
            interval_cells(&m.cycle_average_error_interval_all),
        ));
    }
    if let Some(label) = ratio_label(r) {
        rmse_rows.push(row(
            format!("ratio {label} (test)"),
            r.rmse_ratio.iter().map(|v| f3(*v)).collect(),
        ));
    }
    let mut rmse_header = header("model, set", &OUTPUT_NAMES);
    rmse_header.push("overall".into());
    rmse_header.push("median last-cycle RMSE C_Fx / C_Fy".into());
    let (test_header, test_rows) = test_trajectory_table(r);
    let model_name = |key: &str| {
        r.model(key)
            .map_or_else(|| key.to_string(), |m| m.model.clone())
    };
    let paired_rows: Vec<Vec<String>> = r
        .comparisons
        .iter()
        .map(|c| {
            row(
                format!("{} − {} ({})", model_name(&c.a), model_name(&c.b), c.split),
                c.outputs
                    .iter()
                    .map(|d| format!("{d}{}", if d.significant { " *" } else { "" }))
                    .collect(),
            )
        })
        .collect();
    let mut tables = Vec::new();
    if !paired_rows.is_empty() {
        tables.push(Table {
            caption: format!(
                "Paired differences of RMSE (σ units) with {} % bootstrap intervals over trajectories; * the interval excludes 0",
                r.options.level
            ),
            header: header("models", &OUTPUT_NAMES),
            rows: paired_rows,
        });
    }
    Section {
        heading: "Accuracy".into(),
        paragraphs: vec![format!(
            "Errors are measured − predicted. Standardized errors use the training mean and standard deviation of each output and samples from {} on (0-based; the first {} samples are dropped). Intervals are the {}-% central percentile intervals (MATLAB prctile). Cycle averages are half-stroke means of the load coefficients over the last full stroke cycle.",
            r.options.start_sample, r.options.start_sample, r.options.level
        )],
        tables: vec![
            Table {
                caption: "RMSE per output (σ units) and median last-cycle coefficient RMSE".into(),
                header: rmse_header,
                rows: rmse_rows,
            },
            Table {
                caption: "95 % intervals of the standardized errors".into(),
                header: header("model, set", &OUTPUT_NAMES),
                rows: ci_rows,
            },
            Table {
                caption: "95 % intervals of the half-stroke-average errors (coefficients)".into(),
                header: header("model, set", &COEFFICIENT_LABELS),
                rows: cyc_rows,
            },
            Table {
                caption: "Test trajectories: last-cycle RMSE of the force coefficients".into(),
                header: test_header,
                rows: test_rows,
            },
        ]
        .into_iter()
        .chain(tables)
        .collect(),
        figures,
    }
}

/// Header and rows of the test trajectories' last-cycle C_Fx, C_Fy RMSE per model.
fn test_trajectory_table(r: &EvaluationReport) -> (Vec<String>, Vec<Vec<String>>) {
    let rows = r
        .trajectories
        .iter()
        .filter(|t| t.split == "test")
        .map(|t| {
            let mut cells = vec![
                format!("{}", t.index - r.n_train + 1),
                t.family.clone(),
                format!("{:.3}", t.u_ref_m_s),
                t.period_samples.to_string(),
            ];
            for c in 0..2 {
                cells.extend(t.models.iter().map(|m| f3(m.cycle_rmse_cf[c])));
            }
            cells
        })
        .collect();
    let mut header = strings(&["test #", "family", "U_ref (m/s)", "period (samples)"]);
    for c in ["C_Fx", "C_Fy"] {
        header.extend(r.models.iter().map(|m| format!("{c} {}", m.model)));
    }
    (header, rows)
}

/// Fig. 5 and its table, with a latent-state model and its figures.
fn authority_section(
    r: &EvaluationReport,
    fig5: Option<(PathBuf, PathBuf, PathBuf)>,
    models: &[&dyn LoadModel],
) -> Option<Section> {
    let (f_5a, f_5s, f_5b) = fig5?;
    let latent = models.iter().find(|m| m.n_latent() > 0)?;
    let rows: Vec<Vec<String>> = r
        .authority_findings
        .iter()
        .map(|a| {
            vec![
                a.input.clone(),
                a.state.clone(),
                f3(a.median_abs_r),
                f3(a.median_lag_cycles),
                f3(a.lag_iqr_cycles),
                f3(a.mode_lag_cycles),
                if a.strong { "yes" } else { "no" }.into(),
            ]
        })
        .collect();
    Some(Section {
        heading: format!(
            "Control authority (cross-correlation of the {} latent means)",
            latent.name()
        ),
        paragraphs: vec![format!(
            "Per trajectory, state and input: the largest |r| of the normalized cross-correlation (MATLAB crosscorr) over lags 0 < lag < {} cycle, state lagging input; pooled over all {} trajectories with a reflected 2-D Gaussian KDE (bandwidth {}).",
            r.options.authority.max_lag_cycles,
            r.n_train + r.n_test,
            r.options.authority.bandwidth
        )],
        tables: vec![Table {
            caption: "The pairs the paper reports (Fig. 5)".into(),
            header: strings(&[
                "input", "state", "median max |r|", "median lag (cycles)",
                "lag IQR", "mode lag", "strong (median |r| > 0.5)",
            ]),
            rows,
        }],
        figures: vec![
            Figure {
                caption: "Fig. 5Ai — 70 % highest-density regions and modes (+)".into(),
                path: f_5a,
            },
            Figure {
                caption: "Fig. 5Aii — state x1: max |r| vs lag per trajectory".into(),
                path: f_5s,
            },
            Figure {
                caption: "Fig. 5B — summary: radius ∝ median max |r|, lightness ∝ lag IQR, median lag printed for strong pairs".into(),
                path: f_5b,
            },
        ],
    })
}

/// The trained model's loss and RMSE curves, with a training history and its figures.
fn training_section(
    training: Option<(PathBuf, PathBuf)>,
    models: &[&dyn LoadModel],
) -> Option<Section> {
    let (loss, rmse) = training?;
    let trained = models.iter().find(|m| m.training_history().is_some())?;
    Some(Section {
        heading: format!("{} training", trained.name()),
        figures: vec![
            Figure {
                caption: "Mean minibatch negative ELBO per epoch".into(),
                path: loss,
            },
            Figure {
                caption: "Open-loop RMSE on training and validation sequences".into(),
                path: rmse,
            },
        ],
        ..Default::default()
    })
}

/// Versions of the flapssm crates used, the build and the threads of the pool it ran on.
pub fn versions() -> Vec<(String, String)> {
    vec![
        ("flapssm".into(), env!("CARGO_PKG_VERSION").into()),
        (
            "build".into(),
            if cfg!(debug_assertions) {
                "debug"
            } else {
                "release"
            }
            .into(),
        ),
        (
            "threads".into(),
            crate::threads::current_threads().to_string(),
        ),
    ]
}
