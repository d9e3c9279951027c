//! Controls of the Fig. 5 findings on the outputs: is a finding the trained model's, or does it
//! follow from the kinematics? The paper's cross-correlation rule is applied beside the trained
//! model's output states x1–x5 to
//!
//! - the dataset's own loads,
//! - the loads of a wing without fluid memory (L0, no sensor chain) on the same trajectories,
//! - the rig stand-in: the published model's mean prediction on them ([`crate::rig`]),
//!
//! each the median over the five outputs of the per-pair medians (the rig check's lag
//! statistics, on the paper's training trajectories). A finding that the memoryless wing
//! reproduces is marked "also without memory": it cannot be evidence of delayed circulation.
//!
//! What "reproduces" means, per claim of [`super::paper::FIG5_CLAIMS`] on the outputs:
//! AoA — median lag within ±0.05 cycle and median |r| ≥ 0.6 ("around 0 delay and |r| 0.75");
//! a_x — median lag in [0.15, 0.25] cycle ("around 20 % of the cycle"); dα/dt and d²α/dt² —
//! median |r| in [0.65, 0.85] ("within [0.7, 0.8]").

use flapssm_analysis::rig::LagPair;
use flapssm_analysis::stats::median;
use flapssm_wing::dataset::ValidDataset;
use flapssm_wing::virtual_wing::Fidelity;
use serde::{Deserialize, Serialize};

use super::paper::FIG5_CLAIMS;
use super::report::AuthorityFinding;
use crate::error::Result;
use crate::progress::Progress;
use crate::rig::{RigCheck, RigReference, rig_check};
use crate::simulate::{SimulateSettings, simulate_paper};

/// The lag statistics the controls are read from (the rig checks' training set).
#[derive(Debug, Clone, PartialEq)]
pub struct ControlLags {
    /// The rig check of the evaluated dataset: its loads (`dataset`) and the stand-in
    /// (`reference`).
    pub dataset: Vec<LagPair>,
    /// The rig check of the memoryless wing on the same trajectories (its `dataset` side).
    pub memoryless: Vec<LagPair>,
}

/// The control lags of `ds` (the paper's trajectories, as its rig check `check` against
/// `reference` has verified): the memoryless wing (the default wing at L0 without the sensor
/// chain) is simulated on the same measured trajectories and checked against the same
/// reference.
///
/// # Errors
/// The simulation's and the rig check's errors.
pub fn control_lags(
    ds: &ValidDataset,
    check: &RigCheck,
    reference: &RigReference,
    progress: &dyn Progress,
) -> Result<ControlLags> {
    let settings = SimulateSettings {
        n_trajectories: ds.len(),
        n_train: Some(ds.n_train),
        fidelity: Some(Fidelity::L0),
        noise_free: true,
        ..SimulateSettings::default()
    };
    let memoryless = simulate_paper(&settings, progress)?;
    let control = rig_check(&memoryless, reference, true)?;
    Ok(ControlLags {
        dataset: check.train.lags.clone(),
        memoryless: control.train.lags,
    })
}

/// One measure of a finding in every column.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct ControlMeasure {
    /// Median max |r| (median over the outputs).
    pub median_abs_r: f64,
    /// Median lag (cycles, median over the outputs).
    pub median_lag_cycles: f64,
    /// Whether this column reproduces the paper's finding.
    pub reproduces: bool,
}

/// One Fig. 5 finding on the outputs with its controls.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuthorityControl {
    /// Input label.
    pub input: String,
    /// The paper's words.
    pub paper: String,
    /// The rule applied (module docs).
    pub rule: String,
    /// The trained model's output states x1–x5.
    pub trained: ControlMeasure,
    /// The dataset's loads.
    pub dataset_loads: ControlMeasure,
    /// The memoryless wing's loads (L0, no sensor chain).
    pub memoryless_loads: ControlMeasure,
    /// The rig stand-in (the published model's prediction).
    pub stand_in: ControlMeasure,
    /// The memoryless wing reproduces the finding.
    pub also_without_memory: bool,
}

impl AuthorityControl {
    /// "also without memory" (the memoryless wing reproduces the finding), "not without
    /// memory" (the trained model does and the memoryless wing does not), or "not reproduced".
    pub fn verdict(&self) -> &'static str {
        if self.also_without_memory {
            "also without memory"
        } else if self.trained.reproduces {
            "not without memory"
        } else {
            "not reproduced"
        }
    }
}

/// The claims on the outputs: input, the rule and its test on (|r|, lag). The paper's words
/// are its claim's in [`FIG5_CLAIMS`].
type Rule = (&'static str, &'static str, fn(f64, f64) -> bool);

const RULES: [Rule; 4] = [
    ("AoA", "|lag| ≤ 0.05 cycle and |r| ≥ 0.6", |r, lag| {
        lag.abs() <= 0.05 && r >= 0.6
    }),
    ("a_x", "0.15 ≤ lag ≤ 0.25 cycle", |_, lag| {
        (0.15..=0.25).contains(&lag)
    }),
    ("dα/dt", "0.65 ≤ |r| ≤ 0.85", |r, _| {
        (0.65..=0.85).contains(&r)
    }),
    ("d²α/dt²", "0.65 ≤ |r| ≤ 0.85", |r, _| {
        (0.65..=0.85).contains(&r)
    }),
];

/// The paper's words on `input` → the outputs x1–x5.
fn paper_text(input: &str) -> &'static str {
    FIG5_CLAIMS
        .iter()
        .find(|c| c.states.len() == 5 && c.inputs.contains(&input))
        .map_or("", |c| c.text)
}

fn med(v: Vec<f64>) -> f64 {
    median(&v).unwrap_or(f64::NAN)
}

/// The controls of every claim on the outputs that the trained model's findings cover.
pub fn authority_controls(
    findings: &[AuthorityFinding],
    lags: &ControlLags,
) -> Vec<AuthorityControl> {
    let outputs: Vec<String> = (1..=5).map(|s| format!("x{s}")).collect();
    RULES
        .iter()
        .filter_map(|&(input, rule, test)| {
            let of: Vec<&AuthorityFinding> = findings
                .iter()
                .filter(|f| f.input == input && outputs.contains(&f.state))
                .collect();
            if of.len() != outputs.len() {
                return None;
            }
            let measure = |r: f64, lag: f64| ControlMeasure {
                median_abs_r: r,
                median_lag_cycles: lag,
                reproduces: test(r, lag),
            };
            let of_pairs = |pairs: &[LagPair], reference: bool| {
                let p: Vec<_> = pairs
                    .iter()
                    .filter(|p| p.input == input)
                    .map(|p| if reference { p.reference } else { p.dataset })
                    .collect();
                measure(
                    med(p.iter().map(|s| s.median_abs_r).collect()),
                    med(p.iter().map(|s| s.median_lag_cycles).collect()),
                )
            };
            let memoryless_loads = of_pairs(&lags.memoryless, false);
            Some(AuthorityControl {
                input: input.into(),
                paper: paper_text(input).into(),
                rule: rule.into(),
                trained: measure(
                    med(of.iter().map(|f| f.median_abs_r).collect()),
                    med(of.iter().map(|f| f.median_lag_cycles).collect()),
                ),
                dataset_loads: of_pairs(&lags.dataset, false),
                stand_in: of_pairs(&lags.dataset, true),
                also_without_memory: memoryless_loads.reproduces,
                memoryless_loads,
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use flapssm_analysis::rig::LagStats;

    fn stats(r: f64, lag: f64) -> LagStats {
        LagStats {
            n: 10,
            median_abs_r: r,
            median_lag_cycles: lag,
            lag_iqr_cycles: 0.01,
        }
    }

    fn pairs(input: &str, d: (f64, f64), r: (f64, f64)) -> Vec<LagPair> {
        ["F_x", "F_y", "M_x", "M_y", "M_z"]
            .iter()
            .map(|o| LagPair {
                input: input.into(),
                output: (*o).into(),
                dataset: stats(d.0, d.1),
                reference: stats(r.0, r.1),
            })
            .collect()
    }

    fn finding(input: &str, s: usize, r: f64, lag: f64) -> AuthorityFinding {
        AuthorityFinding {
            input: input.into(),
            state: format!("x{s}"),
            median_abs_r: r,
            median_lag_cycles: lag,
            lag_iqr_cycles: 0.0,
            mode_lag_cycles: lag,
            strong: r > 0.5,
        }
    }

    /// a_x at 0.2 cycle everywhere: reproduced by every column, so "also without memory"; AoA
    /// at 0.3 cycle on the memoryless wing only: reproduced by the model, not without memory.
    #[test]
    fn a_finding_the_memoryless_wing_shows_is_marked() {
        let findings: Vec<AuthorityFinding> = (1..=5)
            .flat_map(|s| [finding("a_x", s, 0.8, 0.2), finding("AoA", s, 0.75, 0.0)])
            .collect();
        let lags = ControlLags {
            dataset: [
                pairs("a_x", (0.8, 0.2), (0.7, 0.21)),
                pairs("AoA", (0.7, 0.01), (0.7, 0.0)),
            ]
            .concat(),
            memoryless: [
                pairs("a_x", (0.8, 0.19), (0.0, 0.0)),
                pairs("AoA", (0.7, 0.3), (0.0, 0.0)),
            ]
            .concat(),
        };
        let c = authority_controls(&findings, &lags);
        assert_eq!(c.len(), 2);
        let aoa = &c[0];
        assert_eq!(aoa.input, "AoA");
        assert_eq!(aoa.paper, "consistently around 0 delay and |r| 0.75");
        assert!(aoa.trained.reproduces && aoa.dataset_loads.reproduces && aoa.stand_in.reproduces);
        assert!(!aoa.memoryless_loads.reproduces && !aoa.also_without_memory);
        assert_eq!(aoa.verdict(), "not without memory");
        let ax = &c[1];
        assert!(ax.also_without_memory && ax.trained.reproduces);
        assert_eq!(ax.verdict(), "also without memory");
        assert_eq!(ax.memoryless_loads.median_lag_cycles, 0.19);
        assert_eq!(ax.stand_in.median_lag_cycles, 0.21);
    }
}
