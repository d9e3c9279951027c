//! The one seed-derivation rule of every job.
//!
//! A job takes one master seed. Each random stream it needs is
//! [`derive_seed`]`(master, stream, index)` (a SplitMix64 mix of the three), with the stream
//! numbers below, so that two jobs given the same master seed draw the same numbers for the same
//! purpose: `flapssm predict`, `flapssm evaluate` and the demo predict trajectory `i` with
//! identical particle draws.
//!
//! | stream | what |
//! |---|---|
//! | 7 ([`PREDICTION_STREAM`]) | open-loop prediction of trajectory `i` of a dataset |
//! | 40 ([`SYSID_PREDICTION_STREAM`]) | sysid test-part prediction |
//! | 41 ([`SYSID_RESTART_STREAM`]) | sysid restart training seeds |
//! | 42 ([`DRAW_PATH_STREAM`]) | a reference model's latent path drawn on trajectory `i` |
//! | 43 ([`DRAW_NOISE_STREAM`]) | its observation noise on trajectory `i` |
//!
//! The engine derives its own streams from the training seed (minibatch order, particle draws
//! per step, initialization): `flapssm_prssm::train` documents them.

pub use flapssm_prssm::train::derive_seed;

/// Stream of the open-loop prediction draws (one index per trajectory).
pub const PREDICTION_STREAM: u64 = 7;

/// Seed of the particle draws when predicting trajectory `index` of a dataset (or the one
/// sequence of an input table, index 0) with master seed `seed`.
pub fn prediction_seed(seed: u64, index: usize) -> u64 {
    derive_seed(seed, PREDICTION_STREAM, index as u64)
}

/// Stream of the sysid protocol's test-time particle draws (one index per seed and restart).
pub const SYSID_PREDICTION_STREAM: u64 = 40;

/// Stream of the training seeds of the sysid protocol's restarts `r ≥ 1` (restart 0 trains with
/// the seed itself).
pub const SYSID_RESTART_STREAM: u64 = 41;

/// Stream of the latent path a model draws on trajectory `i` ([`crate::known_answer`]).
pub const DRAW_PATH_STREAM: u64 = 42;

/// Stream of the observation noise added to that path.
pub const DRAW_NOISE_STREAM: u64 = 43;
