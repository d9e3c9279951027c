//! # flapssm-jobs — every job a flapssm user runs, written once
//!
//! The command-line tool and the language bindings call these functions; they hold no
//! training, prediction or analysis logic of their own.
//!
//! | module | job |
//! |---|---|
//! | [`simulate`] | the virtual wing on seeded random or the paper's measured trajectories, into a dataset |
//! | [`kinematics_compare`] | the generator's trajectory statistics beside the paper's measured set |
//! | [`train`] | PR-SSM training on a dataset's training trajectories (settings, checkpoints, resume) |
//! | [`predict`] | open-loop predictions of every trajectory of a dataset (PR-SSM, LRQSM) |
//! | [`stream`] | real-time PR-SSM prediction, one sample at a time (CSV in, CSV out) |
//! | [`models`] | the load models behind one trait (PR-SSM, LRQSM, ARX, GP-static, GP-history) |
//! | [`evaluate`] | both models on a dataset: metrics, authority, figures, report |
//! | [`history`] | the history curve: a GP baseline's test error against the input history it is given |
//! | [`rig`] | a dataset on the paper's trajectories against the published model's prediction of the rig's loads |
//! | [`known_answer`] | the published model as the plant: its draws on the paper's trajectories, and a trained PR-SSM's recovery of it |
//! | [`own_rig`] | a user's rig: its description, raw recordings into a dataset, the virtual wing rehearsing it |
//! | [`sweep`] | one-configuration PR-SSM sweep runs (D_x, training-set size) and their merge |
//! | [`demo`] | the one-command demo: simulate, fit, train, evaluate (resumable) |
//! | [`design`] | kinematics chosen with a load model and verified on the wing; hover at least power; the closed loop |
//! | [`bench`](mod@bench) | the engine's speed in the paper's configuration beside the authors' code |
//! | [`curve`] | learning curves with wall times, and the time-to-quality read from them |
//! | [`wang2004`] | the published 2-D hovering experiment (Wang, Birch & Dickinson 2004) beside every fidelity |
//! | [`sysid`] | Doerr et al. system-identification protocol (fit, open-loop test, RMSE/NLL) |
//!
//! Shared pieces: [`presets`] (the named training presets: paper, paper-fast, sysid),
//! [`adapters`] (datasets to the engine's sequences), [`error`] (one error type naming the
//! file, trajectory or stage), [`progress`]
//! (the progress sink a caller supplies), [`resources`] (memory estimates checked before any
//! work), [`seed`] (the one seed-derivation rule), [`files`]
//! (atomic JSON and text files), [`threads`] (the pool a job runs on).
#![warn(missing_docs)]

pub mod adapters;
pub mod bench;
pub mod curve;
pub mod demo;
pub mod design;
pub mod error;
pub mod evaluate;
pub mod files;
pub mod history;
pub mod kinematics_compare;
pub mod known_answer;
pub mod models;
pub mod own_rig;
pub mod predict;
pub mod presets;
pub mod progress;
pub mod resources;
pub mod rig;
pub mod seed;
pub mod simulate;
pub mod stream;
pub mod sweep;
pub mod sysid;
#[cfg(test)]
mod test_data;
pub mod threads;
pub mod train;
pub mod wang2004;

pub use error::{JobError, Result};
pub use progress::{NoProgress, Progress};
