//! Minibatches of training windows, shuffled by seed.
//!
//! The training set is cut into [`Window`]s once ([`WindowSpec`]); every epoch visits each
//! window exactly once, in an order that is a pure function of `(seed, epoch)`. The position
//! inside a run is therefore just `(epoch, batch)`, which is what a checkpoint stores.

use rand::SeedableRng;
use rand::seq::SliceRandom;
use rand_chacha::ChaCha8Rng;
use serde::{Deserialize, Serialize};

use crate::Window;

/// How training sequences are cut into windows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
#[non_exhaustive]
pub enum WindowSpec {
    /// One window per sequence, covering all of it (the paper's setting).
    WholeSequences,
    /// All windows of `len` steps starting at `0, stride, 2·stride, …` (Doerr et al.: len 50,
    /// stride 1). Sequences shorter than `len` are an error.
    Windows {
        /// Steps per window (≥ 1).
        len: usize,
        /// Offset between consecutive window starts (≥ 1).
        stride: usize,
    },
}

/// Why windows could not be formed.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum BatchError {
    /// There are no training sequences.
    #[error("no training sequences")]
    NoSequences,
    /// A sequence is shorter than the window length.
    #[error("sequence {sequence} has {len} steps, shorter than the window length {window_len}")]
    TooShort {
        /// Index of the sequence.
        sequence: usize,
        /// Its length.
        len: usize,
        /// Requested window length.
        window_len: usize,
    },
    /// A size parameter is zero.
    #[error("{field} must be at least 1")]
    Zero {
        /// `"batch_size"`, `"len"` or `"stride"`.
        field: &'static str,
    },
}

/// Mixes a base seed with a stream tag and an index (SplitMix64 finalizer), giving independent
/// seeds for e.g. the shuffle of epoch `e` or the objective's draws at step `t`.
pub fn derive_seed(seed: u64, stream: u64, index: u64) -> u64 {
    let mut z = seed
        ^ stream.wrapping_mul(0x9E37_79B9_7F4A_7C15)
        ^ index.wrapping_mul(0xD1B5_4A32_D192_ED03);
    for _ in 0..2 {
        z = (z ^ (z >> 30)).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94D0_49BB_1331_11EB);
        z ^= z >> 31;
    }
    z
}

/// Seed stream of the per-epoch shuffles.
const SHUFFLE_STREAM: u64 = 1;

/// All training windows and the minibatch layout of an epoch.
#[derive(Debug, Clone, PartialEq)]
pub struct BatchPlan {
    windows: Vec<Window>,
    batch_size: usize,
}

impl BatchPlan {
    /// Cuts sequences of lengths `seq_lens` into windows per `spec`, `batch_size` windows per
    /// minibatch (the last minibatch of an epoch may be smaller).
    ///
    /// # Errors
    /// [`BatchError`] for no sequences, zero sizes or a sequence shorter than the window.
    pub fn new(
        seq_lens: &[usize],
        spec: WindowSpec,
        batch_size: usize,
    ) -> Result<Self, BatchError> {
        if batch_size == 0 {
            return Err(BatchError::Zero {
                field: "batch_size",
            });
        }
        if seq_lens.is_empty() {
            return Err(BatchError::NoSequences);
        }
        let mut windows = Vec::new();
        match spec {
            WindowSpec::WholeSequences => {
                for (sequence, &len) in seq_lens.iter().enumerate() {
                    if len == 0 {
                        return Err(BatchError::TooShort {
                            sequence,
                            len,
                            window_len: 1,
                        });
                    }
                    windows.push(Window {
                        sequence,
                        start: 0,
                        len,
                    });
                }
            }
            WindowSpec::Windows { len, stride } => {
                if len == 0 {
                    return Err(BatchError::Zero { field: "len" });
                }
                if stride == 0 {
                    return Err(BatchError::Zero { field: "stride" });
                }
                for (sequence, &n) in seq_lens.iter().enumerate() {
                    if n < len {
                        return Err(BatchError::TooShort {
                            sequence,
                            len: n,
                            window_len: len,
                        });
                    }
                    windows.extend((0..=n - len).step_by(stride).map(|start| Window {
                        sequence,
                        start,
                        len,
                    }));
                }
            }
        }
        Ok(Self {
            windows,
            batch_size,
        })
    }

    /// All windows, in unshuffled order.
    pub fn windows(&self) -> &[Window] {
        &self.windows
    }

    /// Number of minibatches per epoch, `⌈n_windows / batch_size⌉`.
    pub fn batches_per_epoch(&self) -> usize {
        self.windows.len().div_ceil(self.batch_size)
    }

    /// Writes the window order of epoch `epoch` (a permutation of `0..n_windows`, a pure
    /// function of `(seed, epoch)`) into `order`.
    pub fn epoch_order(&self, seed: u64, epoch: u64, order: &mut Vec<usize>) {
        order.clear();
        order.extend(0..self.windows.len());
        let mut rng = ChaCha8Rng::seed_from_u64(derive_seed(seed, SHUFFLE_STREAM, epoch));
        order.shuffle(&mut rng);
    }

    /// Writes minibatch `batch` of an epoch with window order `order` into `out`.
    pub fn batch_into(&self, order: &[usize], batch: usize, out: &mut Vec<Window>) {
        out.clear();
        let lo = (batch * self.batch_size).min(order.len());
        let hi = (lo + self.batch_size).min(order.len());
        out.extend(order[lo..hi].iter().map(|&i| self.windows[i]));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn windows_at_stride_cover_every_start() {
        let plan = BatchPlan::new(&[5, 3], WindowSpec::Windows { len: 3, stride: 1 }, 2).unwrap();
        let starts: Vec<(usize, usize)> = plan
            .windows()
            .iter()
            .map(|w| (w.sequence, w.start))
            .collect();
        assert_eq!(starts, vec![(0, 0), (0, 1), (0, 2), (1, 0)]);
        assert_eq!(plan.batches_per_epoch(), 2);
        let plan = BatchPlan::new(&[10], WindowSpec::Windows { len: 4, stride: 3 }, 2).unwrap();
        let starts: Vec<usize> = plan.windows().iter().map(|w| w.start).collect();
        assert_eq!(starts, vec![0, 3, 6]);
    }

    #[test]
    fn each_epoch_is_a_seeded_permutation() {
        let lens = vec![7; 37];
        let plan = BatchPlan::new(&lens, WindowSpec::WholeSequences, 5).unwrap();
        assert_eq!(plan.batches_per_epoch(), 8);
        let (mut a, mut b, mut c) = (Vec::new(), Vec::new(), Vec::new());
        plan.epoch_order(42, 3, &mut a);
        plan.epoch_order(42, 3, &mut b);
        plan.epoch_order(42, 4, &mut c);
        assert_eq!(a, b);
        assert_ne!(a, c);
        let mut seen = [0; 37];
        let mut batch = Vec::new();
        let mut total = 0;
        for k in 0..plan.batches_per_epoch() {
            plan.batch_into(&a, k, &mut batch);
            total += batch.len();
            for w in &batch {
                seen[w.sequence] += 1;
                assert_eq!((w.start, w.len), (0, 7));
            }
        }
        assert_eq!(total, 37);
        assert!(seen.iter().all(|&s| s == 1));
    }

    #[test]
    fn bad_layouts_are_rejected_with_names() {
        let e = BatchPlan::new(&[5, 2], WindowSpec::Windows { len: 3, stride: 1 }, 2).unwrap_err();
        assert_eq!(
            e,
            BatchError::TooShort {
                sequence: 1,
                len: 2,
                window_len: 3
            }
        );
        assert!(BatchPlan::new(&[], WindowSpec::WholeSequences, 2).is_err());
        assert!(BatchPlan::new(&[4], WindowSpec::WholeSequences, 0).is_err());
        assert!(BatchPlan::new(&[4], WindowSpec::Windows { len: 2, stride: 0 }, 1).is_err());
    }

    #[test]
    fn derived_seeds_differ_across_streams_and_indices() {
        let s = [
            derive_seed(1, 0, 0),
            derive_seed(1, 0, 1),
            derive_seed(1, 1, 0),
            derive_seed(2, 0, 0),
        ];
        for i in 0..4 {
            for j in i + 1..4 {
                assert_ne!(s[i], s[j]);
            }
        }
    }
}
