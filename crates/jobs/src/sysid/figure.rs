//! The protocol's figure: the test part and the first seed's prediction with ±2σ.

use std::path::Path;

use super::{SysidReport, TestTrace};
use crate::error::{Result, analysis};

/// Draws the measured test outputs and the first seed's predictive mean ±2σ into `path`
/// (`.png`/`.svg`), titled with `label` (e.g. the file name) and the first seed's test RMSE.
///
/// # Errors
/// [`crate::JobError::Analysis`] for plot and I/O errors naming the file.
pub fn plot_test_prediction(
    path: &Path,
    label: &str,
    report: &SysidReport,
    trace: &TestTrace,
) -> Result<()> {
    let rmse = report.runs.first().map_or(f64::NAN, |r| r.test.rmse);
    let title = format!("{label} — seed 0, test RMSE {rmse:.4}");
    flapssm_analysis::plots::sysid::plot_test_prediction(
        path,
        &title,
        &report.outputs,
        &trace.outputs,
        &trace.prediction.output_mean,
        &trace.prediction.output_var,
    )
    .map_err(analysis(path.display().to_string()))
}
