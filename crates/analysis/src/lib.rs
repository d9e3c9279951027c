//! # flapssm-analysis — the paper's analyses, figures and report
//!
//! Built on plain arrays ([`stats::Rows`]: row-major `n_time × n_channels` slices), not on model
//! types, so any model's predictions can be analysed.
//!
//! | module | what | published source |
//! |---|---|---|
//! | [`stats`] | MATLAB `prctile`/`median`/`iqr`, central intervals | — |
//! | [`metrics`] | standardized errors, RMSE, overall score, histograms, load coefficients | `ferrorgpssm.m`, `plotter.m` |
//! | [`cycles_avg`] | last-cycle windows, half-stroke averages and their errors | `fplotter.m` |
//! | [`xcorr`] | MATLAB `crosscorr`, peak |r| within one cycle | `plotter.m` |
//! | [`kde`] | 2-D reflected Gaussian KDE, mode, 70 % HDR, contours | `ksdensity` |
//! | [`authority`] | control-authority analysis (Fig. 5 as data, JSON/CSV) | `plotter.m` |
//! | [`hidden`] | the authority of each input on the hidden subspace beyond the outputs, basis-free, with its chance level | — |
//! | [`bootstrap`] | paired bootstrap of a difference of pooled RMSEs over trajectories | — |
//! | [`scores`] | RMSE and Gaussian NLL of a sequence prediction, per-output RMSE, mean ± std over seeds (the sysid protocol) | Doerr et al. (2018) |
//! | [`rig`] | a dataset's loads against a reference of the rig's (r, z-RMSE, 95 % band, couplings, Fig. 5 lags) | — |
//! | [`plots`] | PNG/SVG figures (Figs. 2C, 3, 4, 5, training curves) | — |
//! | [`report`] | one self-contained HTML page | — |
//!
//! Feature `plots` (default) builds [`plots`] (plotters, an embedded font, PNG encoding). Without
//! it the crate is the analyses and the HTML report alone. Per-trajectory loops run on the
//! caller's rayon pool; results do not depend on its size.
#![warn(missing_docs)]

pub mod authority;
pub mod bootstrap;
pub mod cycles_avg;
pub mod error;
pub mod hidden;
pub mod kde;
pub mod ks;
pub mod metrics;
#[cfg(feature = "plots")]
pub mod plots;
pub mod report;
pub mod rig;
pub mod scores;
pub mod stats;
pub mod xcorr;

pub use error::{AnalysisError, Result};
