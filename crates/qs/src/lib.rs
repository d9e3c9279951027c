//! # flapssm-qs — the linear baselines: the quasi-steady LRQSM and an ARX with input memory
//!
//! Elastic net with a regularization path and K-fold cross-validation, fitted per output on
//! quasi-steady kinematic features, as the published baseline did with MATLAB's
//! `lasso(X, y, 'Alpha', 0.75, 'CV', 10)`.
//!
//! - [`enet`]: coordinate descent on a Gram matrix along a λ path.
//! - [`cv`]: standardization, K-fold cross-validation and the λ choice ([`cv::fit_enet_cv`]).
//! - [`model`]: the versioned JSON model file ([`model::LrqsmModel`]) and prediction.
//! - [`lrqsm`]: fit on a dataset's training trajectories, predict every trajectory.
//! - [`table`]: fits on custom columns of a CSV table.
//! - [`arx`]: least squares on lagged standardized inputs (a linear model with input memory).
#![warn(missing_docs)]

pub mod arx;
pub mod cv;
pub mod enet;
pub mod error;
pub mod lrqsm;
pub mod model;
pub mod table;

pub use cv::{EnetOptions, FoldLayout, LambdaRule};
pub use error::QsError;
pub use model::{InterceptMode, LrqsmModel};
