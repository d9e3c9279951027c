//! Control-authority analysis (paper Fig. 5, published `plotter.m`, "Latent State Analysis").
//!
//! 1. For every trajectory, latent state `j` and input `k`: `r = crosscorr(u_k, x_j)` (positive
//!    lag = the state lags the input, see [`crate::xcorr`]) up to `num_lags`; lags are divided by
//!    that trajectory's stroke period; among lags `0 < lag < max_lag_cycles` cycles the largest
//!    `|r|` and its lag are kept ([`PeakTable`]).
//! 2. For every pair `(j, k)` the points `(lag, |r|)` of all trajectories are pooled; a 2-D
//!    Gaussian KDE ([`crate::kde`], `'positive'` support, reflection, bandwidth `h`) is evaluated
//!    on a `grid_points²` grid over `[0, max_lag_cycles] × [0, 1]`; its mode and the published
//!    `hdr_mass` highest-density region are reported, with the median `|r|`, the median lag and
//!    its interquartile range (MATLAB `median`/`iqr`). Pairs with median `|r| > strong_median_r`
//!    are "strong": the paper prints their median lag ([`AuthoritySummary`]).

use rayon::prelude::*;
use std::io::Write;
use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::{AnalysisError, Result, param};
use crate::kde::{DensityGrid, Kde2, linspace};
use crate::stats::{Rows, median, quartiles};
use crate::xcorr::{PeakCorrelation, peak_within_cycle, standardize_into, xcf_positive_into};

/// Settings of the analysis; [`Default`] gives the published values.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuthorityConfig {
    /// `NumLags` of `crosscorr` (published 300).
    pub num_lags: usize,
    /// Upper lag limit in stroke cycles, exclusive (published 1).
    pub max_lag_cycles: f64,
    /// KDE bandwidth on (lag in cycles, |r|) (published 0.085 for the contours, 0.09 for the
    /// scatter shading).
    pub bandwidth: f64,
    /// Grid nodes per axis for the density (published 30 in the code, 300 for the paper).
    pub grid_points: usize,
    /// Mass of the highest-density region (published 0.7).
    pub hdr_mass: f64,
    /// Densities below this are outside any region (published 1e-5).
    pub density_floor: f64,
    /// Median |r| above which a pair's median lag is printed (published 0.5).
    pub strong_median_r: f64,
}

impl Default for AuthorityConfig {
    fn default() -> Self {
        Self {
            num_lags: 300,
            max_lag_cycles: 1.0,
            bandwidth: 0.085,
            grid_points: 120,
            hdr_mass: 0.7,
            density_floor: 1e-5,
            strong_median_r: 0.5,
        }
    }
}

impl AuthorityConfig {
    /// Validates the settings.
    ///
    /// # Errors
    /// [`AnalysisError::Parameter`] naming the first invalid field.
    pub fn check(&self) -> Result<()> {
        if self.num_lags == 0 {
            return Err(param("num_lags", 0, "must be ≥ 1"));
        }
        if !(self.max_lag_cycles.is_finite() && self.max_lag_cycles > 0.0) {
            return Err(param("max_lag_cycles", self.max_lag_cycles, "must be > 0"));
        }
        if !(self.bandwidth.is_finite() && self.bandwidth > 0.0) {
            return Err(param("bandwidth", self.bandwidth, "must be > 0"));
        }
        if self.grid_points < 2 {
            return Err(param("grid_points", self.grid_points, "must be ≥ 2"));
        }
        if !(self.hdr_mass > 0.0 && self.hdr_mass < 1.0) {
            return Err(param("hdr_mass", self.hdr_mass, "must lie in (0, 1)"));
        }
        Ok(())
    }
}

/// One trajectory's series for the analysis.
#[derive(Debug, Clone, Copy)]
pub struct AuthorityTrajectory<'a> {
    /// Inputs, `n_time × n_input` (published: the 7 standardized inputs from sample 94 on).
    pub inputs: Rows<'a>,
    /// Latent-state means, `n_time × n_state` (same `n_time`).
    pub states: Rows<'a>,
    /// Stroke period in samples (published `duration`).
    pub period_samples: f64,
}

impl AuthorityTrajectory<'_> {
    /// Checks trajectory `i`: `n_input` inputs and `n_state` states over the same samples
    /// (`n_time` of them, when given) and a finite positive period.
    ///
    /// # Errors
    /// [`AnalysisError::Shape`] naming the trajectory, [`AnalysisError::Parameter`] for its
    /// period.
    pub fn check(
        &self,
        i: usize,
        n_input: usize,
        n_state: usize,
        n_time: Option<usize>,
    ) -> Result<()> {
        let t_len = n_time.unwrap_or(self.inputs.n_rows());
        if self.inputs.n_rows() != t_len
            || self.states.n_rows() != t_len
            || self.inputs.n_cols() != n_input
            || self.states.n_cols() != n_state
        {
            let rows = n_time.map_or("n_time".to_string(), |t| t.to_string());
            return Err(AnalysisError::Shape {
                what: format!("trajectory {i} inputs/states"),
                expected: format!("{rows} × {n_input} inputs and {rows} × {n_state} states"),
                found: format!(
                    "{} × {} inputs, {} × {} states",
                    self.inputs.n_rows(),
                    self.inputs.n_cols(),
                    self.states.n_rows(),
                    self.states.n_cols()
                ),
            });
        }
        if !(self.period_samples.is_finite() && self.period_samples > 0.0) {
            return Err(param(
                &format!("trajectory {i} period_samples"),
                self.period_samples,
                "must be finite and > 0",
            ));
        }
        Ok(())
    }
}

/// Peak cross-correlations, indexed `[trajectory][state][input]`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PeakTable {
    /// Number of trajectories.
    pub n_traj: usize,
    /// Number of latent states.
    pub n_state: usize,
    /// Number of inputs.
    pub n_input: usize,
    /// `peaks[(i * n_state + j) * n_input + k]`; `None` where no lag lies inside the window.
    pub peaks: Vec<Option<PeakCorrelation>>,
}

impl PeakTable {
    /// Peak of trajectory `i`, state `j`, input `k`.
    pub fn get(&self, i: usize, j: usize, k: usize) -> Option<PeakCorrelation> {
        self.peaks[(i * self.n_state + j) * self.n_input + k]
    }

    /// The pooled `(lag_cycles, |r|)` points of pair `(j, k)` over all trajectories.
    pub fn points(&self, j: usize, k: usize) -> Vec<[f64; 2]> {
        (0..self.n_traj)
            .filter_map(|i| self.get(i, j, k))
            .map(|p| [p.lag_cycles, p.abs_r()])
            .collect()
    }

    /// Writes one CSV row per trajectory, state and input (`trajectory,state,input,lag_samples,
    /// lag_cycles,r,abs_r`; empty fields where no peak), atomically.
    ///
    /// # Errors
    /// [`AnalysisError::Io`] naming the file.
    pub fn write_csv(
        &self,
        path: &Path,
        state_names: &[String],
        input_names: &[String],
    ) -> Result<()> {
        let name =
            |names: &[String], i: usize| names.get(i).cloned().unwrap_or_else(|| format!("{i}"));
        flapssm_data::atomic::write_atomic(path, |w| {
            writeln!(w, "trajectory,state,input,lag_samples,lag_cycles,r,abs_r")?;
            for i in 0..self.n_traj {
                for j in 0..self.n_state {
                    for k in 0..self.n_input {
                        let (s, u) = (name(state_names, j), name(input_names, k));
                        match self.get(i, j, k) {
                            Some(p) => writeln!(
                                w,
                                "{i},{s},{u},{},{},{},{}",
                                p.lag_samples,
                                p.lag_cycles,
                                p.r,
                                p.abs_r()
                            )?,
                            None => writeln!(w, "{i},{s},{u},,,,")?,
                        }
                    }
                }
            }
            Ok(())
        })
        .map_err(|source| AnalysisError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}

/// Computes the peak table. Per trajectory the series are standardized once; the lag loop is
/// allocation-free. Trajectories run in parallel on the caller's rayon pool; results do not
/// depend on it.
///
/// # Errors
/// [`AnalysisError::Shape`] for mismatched tables, [`AnalysisError::Parameter`] for a bad
/// config or period, [`AnalysisError::ConstantSeries`] naming the trajectory and series.
pub fn peak_table(
    trajectories: &[AuthorityTrajectory<'_>],
    config: &AuthorityConfig,
) -> Result<PeakTable> {
    config.check()?;
    let first = trajectories.first().ok_or_else(|| AnalysisError::Empty {
        what: "trajectory list".into(),
    })?;
    let (n_state, n_input) = (first.states.n_cols(), first.inputs.n_cols());
    let one = |(i, tr): (usize, &AuthorityTrajectory<'_>)| -> Result<Vec<Option<PeakCorrelation>>> {
        let t_len = tr.inputs.n_rows();
        tr.check(i, n_input, n_state, None)?;
        let std_cols = |tab: Rows<'_>, kind: &str| -> Result<Vec<f64>> {
            let mut z = vec![0.0; tab.n_rows() * tab.n_cols()];
            for (c, zc) in z.chunks_exact_mut(t_len).enumerate() {
                standardize_into(&format!("trajectory {i} {kind} {c}"), &tab.column(c), zc)?;
            }
            Ok(z)
        };
        let zu = std_cols(tr.inputs, "input")?;
        let zx = std_cols(tr.states, "state")?;
        // Lags needed: below max_lag_cycles · period, and at most num_lags and T − 1.
        let n_lags = ((config.max_lag_cycles * tr.period_samples).ceil() as usize)
            .min(config.num_lags)
            .min(t_len - 1)
            + 1;
        let mut xcf = vec![0.0; n_lags];
        let mut out = Vec::with_capacity(n_state * n_input);
        for j in 0..n_state {
            let x = &zx[j * t_len..(j + 1) * t_len];
            for k in 0..n_input {
                let u = &zu[k * t_len..(k + 1) * t_len];
                xcf_positive_into(u, x, &mut xcf);
                out.push(peak_within_cycle(
                    &xcf,
                    tr.period_samples,
                    config.max_lag_cycles,
                ));
            }
        }
        Ok(out)
    };
    let rows: Vec<Result<Vec<Option<PeakCorrelation>>>> =
        trajectories.par_iter().enumerate().map(one).collect();
    let mut peaks = Vec::with_capacity(trajectories.len() * n_state * n_input);
    for r in rows {
        peaks.extend(r?);
    }
    Ok(PeakTable {
        n_traj: trajectories.len(),
        n_state,
        n_input,
        peaks,
    })
}

/// Summary of one state–input pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct PairSummary {
    /// State index (0-based; the paper's `x^{state+1}`).
    pub state: usize,
    /// Input index (0-based).
    pub input: usize,
    /// Trajectories with a peak.
    pub n_points: usize,
    /// KDE mode: lag (cycles).
    pub mode_lag_cycles: f64,
    /// KDE mode: |r|.
    pub mode_abs_r: f64,
    /// Density threshold of the highest-density region (`{f ≥ threshold}`).
    pub hdr_threshold: f64,
    /// Grid mass fraction inside that region.
    pub hdr_grid_mass: f64,
    /// Median of max |r| over trajectories.
    pub median_abs_r: f64,
    /// Median lag (cycles).
    pub median_lag_cycles: f64,
    /// 25th percentile of the lag (cycles).
    pub lag_q25_cycles: f64,
    /// 75th percentile of the lag (cycles).
    pub lag_q75_cycles: f64,
    /// Interquartile range of the lag (cycles).
    pub lag_iqr_cycles: f64,
    /// `median_abs_r > strong_median_r`: the paper prints `median_lag_cycles` for this pair.
    pub strong: bool,
}

/// Fig. 5 as data: settings, names and one [`PairSummary`] per state–input pair.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct AuthoritySummary {
    /// Settings used.
    pub config: AuthorityConfig,
    /// State names (e.g. `x1`…`x12`).
    pub state_names: Vec<String>,
    /// Input names.
    pub input_names: Vec<String>,
    /// Pairs, state-major (`pairs[j * n_input + k]`).
    pub pairs: Vec<PairSummary>,
    /// Density grids of the pairs (same order), for figures; not serialized.
    #[serde(skip)]
    pub densities: Vec<DensityGrid>,
}

impl AuthoritySummary {
    /// Pools the peak table per pair and summarizes it (see the module docs).
    ///
    /// # Errors
    /// [`AnalysisError::Shape`] if the name lists do not match the table,
    /// [`AnalysisError::Empty`] if a pair has no points or no HDR.
    pub fn new(
        table: &PeakTable,
        state_names: Vec<String>,
        input_names: Vec<String>,
        config: &AuthorityConfig,
    ) -> Result<Self> {
        config.check()?;
        if state_names.len() != table.n_state || input_names.len() != table.n_input {
            return Err(AnalysisError::Shape {
                what: "state/input names".into(),
                expected: format!("{} states, {} inputs", table.n_state, table.n_input),
                found: format!("{}, {}", state_names.len(), input_names.len()),
            });
        }
        let xs = linspace(0.0, config.max_lag_cycles, config.grid_points);
        let ys = linspace(0.0, 1.0, config.grid_points);
        let mut pairs = Vec::new();
        let mut densities = Vec::new();
        for (j, state_name) in state_names.iter().enumerate() {
            for (k, input_name) in input_names.iter().enumerate() {
                let pts = table.points(j, k);
                if pts.is_empty() {
                    return Err(AnalysisError::Empty {
                        what: format!("peaks of {} vs {}", state_name, input_name),
                    });
                }
                let kde = Kde2::positive(pts.clone(), config.bandwidth)?;
                let grid = kde.grid(xs.clone(), ys.clone())?;
                let [mode_lag_cycles, mode_abs_r] = grid.mode();
                let hdr = grid.hdr(config.hdr_mass, config.density_floor)?;
                let lags: Vec<f64> = pts.iter().map(|p| p[0]).collect();
                let rs: Vec<f64> = pts.iter().map(|p| p[1]).collect();
                let (q25, q50, q75) = quartiles(&lags)?;
                let median_abs_r = median(&rs)?;
                pairs.push(PairSummary {
                    state: j,
                    input: k,
                    n_points: pts.len(),
                    mode_lag_cycles,
                    mode_abs_r,
                    hdr_threshold: hdr.threshold,
                    hdr_grid_mass: hdr.grid_mass,
                    median_abs_r,
                    median_lag_cycles: q50,
                    lag_q25_cycles: q25,
                    lag_q75_cycles: q75,
                    lag_iqr_cycles: q75 - q25,
                    strong: median_abs_r > config.strong_median_r,
                });
                densities.push(grid);
            }
        }
        Ok(Self {
            config: config.clone(),
            state_names,
            input_names,
            pairs,
            densities,
        })
    }

    /// Summary of state `j`, input `k`.
    pub fn pair(&self, j: usize, k: usize) -> &PairSummary {
        &self.pairs[j * self.input_names.len() + k]
    }

    /// Writes the summary as pretty JSON, atomically.
    ///
    /// # Errors
    /// [`AnalysisError::Json`], [`AnalysisError::Io`] naming the file.
    pub fn write_json(&self, path: &Path) -> Result<()> {
        let text = serde_json::to_string_pretty(self)?;
        flapssm_data::atomic::write_bytes_atomic(path, text.as_bytes()).map_err(|source| {
            AnalysisError::Io {
                path: path.to_path_buf(),
                source,
            }
        })
    }

    /// Writes one CSV row per pair, atomically.
    ///
    /// # Errors
    /// [`AnalysisError::Io`] naming the file.
    pub fn write_csv(&self, path: &Path) -> Result<()> {
        flapssm_data::atomic::write_atomic(path, |w| {
            writeln!(
                w,
                "state,input,n_points,mode_lag_cycles,mode_abs_r,hdr_threshold,hdr_grid_mass,\
                 median_abs_r,median_lag_cycles,lag_q25_cycles,lag_q75_cycles,lag_iqr_cycles,strong"
            )?;
            for p in &self.pairs {
                writeln!(
                    w,
                    "{},{},{},{},{},{},{},{},{},{},{},{},{}",
                    self.state_names[p.state],
                    self.input_names[p.input],
                    p.n_points,
                    p.mode_lag_cycles,
                    p.mode_abs_r,
                    p.hdr_threshold,
                    p.hdr_grid_mass,
                    p.median_abs_r,
                    p.median_lag_cycles,
                    p.lag_q25_cycles,
                    p.lag_q75_cycles,
                    p.lag_iqr_cycles,
                    p.strong
                )?;
            }
            Ok(())
        })
        .map_err(|source| AnalysisError::Io {
            path: path.to_path_buf(),
            source,
        })
    }
}
