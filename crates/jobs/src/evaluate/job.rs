//! The one evaluation entry point of the front ends: the models as a user names them (a trained
//! PR-SSM, an LRQSM, registered baselines fitted on the spot, the published model as the rig's
//! reference) turned into load models, the rig check added to the report, then [`evaluate`].

use std::path::Path;

use flapssm_prssm::PrssmModel;
use flapssm_qs::LrqsmModel;
use flapssm_wing::dataset::ValidDataset;

use super::controls::control_lags;
use super::evaluate;
use super::report::{EvalOptions, EvaluationReport, ReportContext};
use crate::error::Result;
use crate::models::lrqsm::LrqsmLoadModel;
use crate::models::prssm::PrssmLoadModel;
use crate::models::{LoadModel, baseline};
use crate::progress::Progress;
use crate::rig::{
    RIG_FILES, RigSettings, load_reference_model, rig_check, rig_reference, write_rig_check,
};

/// The models of an evaluation, in report order: the PR-SSM, the LRQSM, then each baseline.
#[derive(Debug, Clone, Copy, Default)]
pub struct EvaluationModels<'a> {
    /// A trained (or imported) PR-SSM.
    pub prssm: Option<&'a PrssmModel>,
    /// A fitted LRQSM.
    pub lrqsm: Option<&'a LrqsmModel>,
    /// Keys of registered baselines ([`crate::models::BASELINES`]), fitted on the dataset's
    /// training trajectories.
    pub baselines: &'a [String],
    /// The published model's file (`.npz` or flapssm JSON): the rig check
    /// ([`crate::rig`]) is written beside the evaluation and added to its report.
    pub reference: Option<&'a Path>,
}

/// Evaluates `models` on `ds` into `out_dir` (every file of [`evaluate`], with a reference
/// also [`RIG_FILES`]); `dataset_label` names the dataset in the report and `config` is shown
/// in it.
///
/// # Errors
/// A model that does not fit the dataset, an unknown baseline, a reference that cannot be
/// read or predicted, and [`evaluate`]'s errors (no model among them).
pub fn evaluate_models(
    ds: &ValidDataset,
    dataset_label: &str,
    models: &EvaluationModels<'_>,
    opts: &EvalOptions,
    config: serde_json::Value,
    out_dir: &Path,
    progress: &dyn Progress,
) -> Result<EvaluationReport> {
    opts.check()?;
    let prssm = models
        .prssm
        .map(|m| PrssmLoadModel::new(m, ds, opts.particles, opts.seed))
        .transpose()?;
    let lrqsm = models.lrqsm.map(LrqsmLoadModel::new).transpose()?;
    let baselines = models
        .baselines
        .iter()
        .map(|k| (baseline(k)?.fit)(ds, progress))
        .collect::<Result<Vec<_>>>()?;
    let mut all: Vec<&dyn LoadModel> = Vec::new();
    if let Some(m) = &prssm {
        all.push(m);
    }
    if let Some(m) = &lrqsm {
        all.push(m);
    }
    all.extend(baselines.iter().map(|m| &**m));
    let (rig_section, control_lags) = match models.reference {
        Some(path) => {
            let model = load_reference_model(path)?;
            let reference = rig_reference(&model, ds.len(), &RigSettings::default(), progress)?;
            let check = rig_check(ds, &reference, true)?;
            write_rig_check(out_dir, &check, ds, &reference, dataset_label)?;
            let figure = out_dir.join(RIG_FILES[2]);
            let lags = control_lags(ds, &check, &reference, progress)?;
            (
                Some(check.report_section(figure.exists().then_some(figure))),
                Some(lags),
            )
        }
        None => (None, None),
    };
    let names: Vec<&str> = all.iter().map(|m| m.name()).collect();
    let context = ReportContext {
        intro: format!("{} evaluated on {dataset_label}.", names.join(", ")),
        config,
        extra_sections: rig_section.into_iter().collect(),
        control_lags,
        ..ReportContext::default()
    };
    evaluate(ds, dataset_label, &all, opts, &context, out_dir, progress)
}
