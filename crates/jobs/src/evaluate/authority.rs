//! The control-authority stage: cross-correlations of the inputs with one model's latent means
//! (every trajectory, transient dropped), their summary and the paper's Fig. 5 pairs read from it.

use std::path::Path;

use flapssm_analysis::authority::{AuthoritySummary, AuthorityTrajectory, PeakTable, peak_table};
use flapssm_analysis::hidden::hidden_authority;
use flapssm_wing::dataset::ValidDataset;

use super::paper::{FIG5_CLAIMS, fig5_pairs};
use super::prepared::{Prepared, rows};
use super::report::{AuthorityFinding, EvalOptions, HiddenFinding, INPUT_LABELS};
use crate::error::{Result, analysis};
use crate::models::ModelPrediction;

/// The control-authority analysis of one model's latent states.
pub(super) struct Authority {
    pub(super) table: PeakTable,
    pub(super) summary: AuthoritySummary,
    pub(super) state_names: Vec<String>,
    pub(super) input_names: Vec<String>,
    pub(super) findings: Vec<AuthorityFinding>,
    pub(super) hidden: Vec<HiddenFinding>,
}

impl Authority {
    pub(super) fn write(
        &self,
        summary_json: &Path,
        summary_csv: &Path,
        peaks_csv: &Path,
    ) -> Result<()> {
        self.summary
            .write_json(summary_json)
            .map_err(analysis(summary_json.display().to_string()))?;
        self.summary
            .write_csv(summary_csv)
            .map_err(analysis(summary_csv.display().to_string()))?;
        self.table
            .write_csv(peaks_csv, &self.state_names, &self.input_names)
            .map_err(analysis(peaks_csv.display().to_string()))
    }
}

/// Control authority on the latent means, every trajectory, transient dropped.
pub(super) fn authority(
    ds: &ValidDataset,
    predictions: &[ModelPrediction],
    dx: usize,
    prep: &[Prepared],
    opts: &EvalOptions,
) -> Result<Authority> {
    let s0 = opts.start_sample;
    let auth_traj: Vec<AuthorityTrajectory<'_>> = ds
        .trajectories
        .iter()
        .zip(predictions)
        .zip(prep)
        .map(|((t, p), q)| {
            Ok(AuthorityTrajectory {
                inputs: rows(&t.inputs.as_flattened()[s0 * 7..], 7, "authority inputs")?,
                states: rows(&p.latent_mean[s0 * dx..], dx, "authority states")?,
                period_samples: q.window.duration as f64,
            })
        })
        .collect::<Result<_>>()?;
    let table = peak_table(&auth_traj, &opts.authority).map_err(analysis("cross-correlations"))?;
    let state_names: Vec<String> = (1..=dx).map(|j| format!("x{j}")).collect();
    let input_names: Vec<String> = INPUT_LABELS.iter().map(|s| s.to_string()).collect();
    let summary = AuthoritySummary::new(
        &table,
        state_names.clone(),
        input_names.clone(),
        &opts.authority,
    )
    .map_err(analysis("control-authority summary"))?;
    let findings = fig5_pairs()
        .filter(|&(_, state)| state <= dx)
        .filter_map(|(label, state)| {
            let input = INPUT_LABELS.iter().position(|l| *l == label)?;
            let s = summary.pair(state - 1, input);
            Some(AuthorityFinding {
                input: input_names[input].clone(),
                state: state_names[state - 1].clone(),
                median_abs_r: s.median_abs_r,
                median_lag_cycles: s.median_lag_cycles,
                lag_iqr_cycles: s.lag_iqr_cycles,
                mode_lag_cycles: s.mode_lag_cycles,
                strong: s.strong,
            })
        })
        .collect();
    let hidden = if dx > N_OUTPUT {
        hidden_findings(&auth_traj, opts)?
    } else {
        Vec::new()
    };
    Ok(Authority {
        table,
        summary,
        state_names,
        input_names,
        findings,
        hidden,
    })
}

/// The output states x1..x5.
const N_OUTPUT: usize = 5;

/// Every input's authority on the hidden subspace (states beyond x5), beside what the paper
/// says of it on single hidden states.
fn hidden_findings(
    trajectories: &[AuthorityTrajectory<'_>],
    opts: &EvalOptions,
) -> Result<Vec<HiddenFinding>> {
    let found = hidden_authority(trajectories, N_OUTPUT, &opts.authority, opts.seed)
        .map_err(analysis("authority on the hidden subspace"))?;
    Ok(found
        .into_iter()
        .map(|h| {
            let input = INPUT_LABELS[h.input];
            let paper = FIG5_CLAIMS
                .iter()
                .filter(|c| c.inputs.contains(&input))
                .flat_map(|c| {
                    c.states
                        .iter()
                        .filter(|&&s| s > N_OUTPUT)
                        .map(move |s| format!("x{s}: {}", c.text))
                })
                .collect::<Vec<_>>()
                .join("; ");
            HiddenFinding {
                input: input.to_string(),
                paper,
                subspace: h,
            }
        })
        .collect())
}
