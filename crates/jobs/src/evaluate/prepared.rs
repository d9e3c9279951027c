//! One trajectory's tables for the analyses (standardized and coefficient forms of the measured
//! and predicted loads) and the metrics computed from sets of them.

use flapssm_analysis::cycles_avg::{CycleAverageErrors, CycleWindow};
use flapssm_analysis::metrics::{PooledErrors, window_rmse};
use flapssm_analysis::stats::{Rows, median};

use super::report::{EvalOptions, SplitMetrics};
use crate::error::{Result, analysis};

/// One model's tables of one trajectory.
pub(super) struct ModelTables {
    /// Predicted loads, standardized, `n × 5`.
    pub(super) z: Vec<f64>,
    /// Predicted loads as coefficients, `n × 5`.
    pub(super) c: Vec<f64>,
    /// Predicted standard deviations as coefficients, for a model with variances.
    pub(super) std_c: Option<Vec<f64>>,
}

/// One trajectory's tables for the analyses.
pub(super) struct Prepared {
    pub(super) window: CycleWindow,
    pub(super) measured_z: Vec<f64>,
    pub(super) measured_c: Vec<f64>,
    /// Each model's tables, in the evaluation's model order.
    pub(super) models: Vec<ModelTables>,
}

pub(super) fn rows<'a>(v: &'a [f64], c: usize, what: &str) -> Result<Rows<'a>> {
    Rows::new(v, c).map_err(analysis(what))
}

/// Accuracy of model `k` on a set of trajectories.
pub(super) fn split_metrics(
    prep: &[&Prepared],
    k: usize,
    opts: &EvalOptions,
    what: &str,
) -> Result<SplitMetrics> {
    let e = pooled(prep, k, opts.start_sample)?;
    let cyc = cycle_errors(prep, k)?;
    let mut med = [0.0; 2];
    for (c, m) in med.iter_mut().enumerate() {
        let v: Vec<f64> = prep
            .iter()
            .map(|p| {
                let a = rows(&p.measured_c, 5, what)?;
                let b = rows(&p.models[k].c, 5, what)?;
                window_rmse(a, b, c, p.window).map_err(analysis(what))
            })
            .collect::<Result<_>>()?;
        *m = median(&v).map_err(analysis(what))?;
    }
    Ok(SplitMetrics {
        n_trajectories: prep.len(),
        n_samples: e.errors[0].len(),
        rmse_standardized: e.rmse(),
        overall_rmse_standardized: e.overall_rmse(),
        error_interval: e.intervals(opts.level).map_err(analysis(what))?,
        median_cycle_rmse_cf: med,
        cycle_average_error_interval: cyc.intervals(opts.level).map_err(analysis(what))?,
    })
}

/// Standardized errors of model `k` on a set, pooled from sample `start` on.
pub(super) fn pooled(prep: &[&Prepared], k: usize, start: usize) -> Result<PooledErrors> {
    pooled_errors(
        prep.iter().map(|p| (&p.measured_z[..], &p.models[k].z[..])),
        start,
    )
}

/// Errors of (measured, predicted) `n × 5` tables of a set of trajectories, pooled from sample
/// `start` on.
pub(crate) fn pooled_errors<'a>(
    tables: impl Iterator<Item = (&'a [f64], &'a [f64])>,
    start: usize,
) -> Result<PooledErrors> {
    let (m, q): (Vec<Rows<'_>>, Vec<Rows<'_>>) = tables
        .map(|(m, q)| Ok((rows(m, 5, "errors")?, rows(q, 5, "errors")?)))
        .collect::<Result<Vec<_>>>()?
        .into_iter()
        .unzip();
    PooledErrors::new(&m, &q, start).map_err(analysis("pooled errors"))
}

/// Half-stroke-average errors of model `k` on a set.
pub(super) fn cycle_errors(prep: &[&Prepared], k: usize) -> Result<CycleAverageErrors> {
    let m: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_c, 5, "cycle averages"))
        .collect::<Result<_>>()?;
    let q: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.models[k].c, 5, "cycle averages"))
        .collect::<Result<_>>()?;
    let w: Vec<CycleWindow> = prep.iter().map(|p| p.window).collect();
    CycleAverageErrors::new(&m, &q, &w).map_err(analysis("cycle averages"))
}
