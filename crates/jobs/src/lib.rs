//! # flapssm-jobs — every job a flapssm user runs, written once
//!
//! The command-line tool and the language bindings call these functions; they hold no
//! training, prediction or analysis logic of their own.
//!
//! | module | job |
//! |---|---|
//! | [`pipeline`] | evaluation of both models on a dataset: metrics, authority, figures, report; PR-SSM training on a dataset |
//! | [`sweep`] | one-configuration PR-SSM sweep runs (D_x, training-set size) and their merge |
//! | [`demo`] | the one-command demo: simulate, fit, train, evaluate (resumable) |
//! | [`sysid`] | Doerr et al. system-identification protocol (fit, open-loop test, RMSE/NLL) |
//!
//! Features: `parallel` (default) predicts trajectories and runs restarts on rayon.
#![warn(missing_docs)]

pub mod demo;
pub mod pipeline;
pub mod sweep;
pub mod sysid;
