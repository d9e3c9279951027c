//! The one seed-derivation rule of every job.
//!
//! A job takes one master seed. Each random stream it needs is
//! [`derive_seed`]`(master, stream, index)` (a SplitMix64 mix of the three), with the stream
//! numbers below, so that two jobs given the same master seed draw the same numbers for the same
//! purpose: `flapssm predict`, `flapssm evaluate` and the demo predict trajectory `i` with
//! identical particle draws.

pub use flapssm_prssm::train::derive_seed;

/// Stream of the open-loop prediction draws (one index per trajectory).
pub const PREDICTION_STREAM: u64 = 7;

/// Seed of the particle draws when predicting trajectory `index` of a dataset (or the one
/// sequence of an input table, index 0) with master seed `seed`.
pub fn prediction_seed(seed: u64, index: usize) -> u64 {
    derive_seed(seed, PREDICTION_STREAM, index as u64)
}
