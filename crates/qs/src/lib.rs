//! # flapssm-qs — the quasi-steady baseline (LRQSM)
//!
//! Elastic net with a regularization path and K-fold cross-validation, fitted per output on
//! quasi-steady kinematic features, as the published baseline did with MATLAB's
//! `lasso(X, y, 'Alpha', 0.75, 'CV', 10)`.
#![warn(missing_docs)]
