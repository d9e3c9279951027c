//! One trajectory's tables for the analyses (standardized and coefficient forms of the measured
//! and predicted loads) and the metrics computed from sets of them.

use flapssm_analysis::cycles_avg::{CycleAverageErrors, CycleWindow};
use flapssm_analysis::metrics::{PooledErrors, window_rmse};
use flapssm_analysis::stats::{Rows, median};

use super::{EvalOptions, SplitMetrics};
use crate::error::{Result, analysis};

/// Picks a model's (standardized, coefficient) tables from a [`Prepared`].
pub(super) type Pick<'p> = &'p dyn Fn(&Prepared) -> (&[f64], &[f64]);

/// One trajectory's tables for the analyses.
pub(super) struct Prepared {
    pub(super) window: CycleWindow,
    pub(super) measured_z: Vec<f64>,
    pub(super) measured_c: Vec<f64>,
    pub(super) prssm_z: Vec<f64>,
    pub(super) prssm_c: Vec<f64>,
    pub(super) prssm_std_c: Vec<f64>,
    pub(super) lrqsm_z: Vec<f64>,
    pub(super) lrqsm_c: Vec<f64>,
}

pub(super) fn rows<'a>(v: &'a [f64], c: usize, what: &str) -> Result<Rows<'a>> {
    Rows::new(v, c).map_err(analysis(what))
}

pub(super) fn split_metrics(
    prep: &[&Prepared],
    pick: Pick<'_>,
    opts: &EvalOptions,
    what: &str,
) -> Result<SplitMetrics> {
    let meas_z: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_z, 5, what))
        .collect::<Result<_>>()?;
    let pred_z: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p).0, 5, what))
        .collect::<Result<_>>()?;
    let e = PooledErrors::new(&meas_z, &pred_z, opts.start_sample).map_err(analysis(what))?;
    let meas_c: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_c, 5, what))
        .collect::<Result<_>>()?;
    let pred_c: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p).1, 5, what))
        .collect::<Result<_>>()?;
    let windows: Vec<CycleWindow> = prep.iter().map(|p| p.window).collect();
    let cyc = CycleAverageErrors::new(&meas_c, &pred_c, &windows).map_err(analysis(what))?;
    let mut med = [0.0; 2];
    for (c, m) in med.iter_mut().enumerate() {
        let v: Vec<f64> = meas_c
            .iter()
            .zip(&pred_c)
            .zip(&windows)
            .map(|((a, b), w)| window_rmse(*a, *b, c, *w))
            .collect::<std::result::Result<_, _>>()
            .map_err(analysis(what))?;
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

/// Standardized errors of one model on a set, for the histograms.
pub(super) fn pooled(
    prep: &[&Prepared],
    pick: &dyn Fn(&Prepared) -> &[f64],
    start: usize,
) -> Result<PooledErrors> {
    let m: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_z, 5, "errors"))
        .collect::<Result<_>>()?;
    let q: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p), 5, "errors"))
        .collect::<Result<_>>()?;
    PooledErrors::new(&m, &q, start).map_err(analysis("pooled errors"))
}

pub(super) fn cycle_errors(
    prep: &[&Prepared],
    pick: &dyn Fn(&Prepared) -> &[f64],
) -> Result<CycleAverageErrors> {
    let m: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(&p.measured_c, 5, "cycle averages"))
        .collect::<Result<_>>()?;
    let q: Vec<Rows<'_>> = prep
        .iter()
        .map(|p| rows(pick(p), 5, "cycle averages"))
        .collect::<Result<_>>()?;
    let w: Vec<CycleWindow> = prep.iter().map(|p| p.window).collect();
    CycleAverageErrors::new(&m, &q, &w).map_err(analysis("cycle averages"))
}
