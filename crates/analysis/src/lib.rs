//! # flapssm-analysis — the paper's analyses, figures and report
//!
//! Accuracy metrics, standardized-error intervals, half-stroke cycle averages, latent-state
//! cross-correlation ("control authority") with kernel density estimates, sweeps, figures and
//! a self-contained HTML report.
#![warn(missing_docs)]
