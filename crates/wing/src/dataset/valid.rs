//! A dataset checked once: [`ValidDataset`] is a [`Dataset`] that passed
//! [`Dataset::validate`], read-only from then on.
//!
//! Every reader and simulator returns one ([`Dataset::load`], [`Dataset::import_csv`],
//! [`super::published::import_published_mat`], [`crate::virtual_wing::simulate_dataset`]), and every job takes
//! one, so a dataset is validated where it enters the program and never again. It dereferences
//! to [`Dataset`] for reading; to edit, take the [`Dataset`] out ([`ValidDataset::into_inner`])
//! and check it again ([`ValidDataset::new`]).

use std::ops::Deref;

use super::{Dataset, DatasetError};

/// A [`Dataset`] that passed [`Dataset::validate`] (see the module docs).
#[derive(Debug, Clone, PartialEq)]
pub struct ValidDataset(Dataset);

impl ValidDataset {
    /// Checks `ds` ([`Dataset::validate`]).
    ///
    /// # Errors
    /// The first violation found, naming trajectory, field and sample.
    pub fn new(ds: Dataset) -> Result<Self, DatasetError> {
        ds.validate()?;
        Ok(Self(ds))
    }

    /// Wraps a dataset the caller has just validated (the crate's readers).
    pub(crate) fn validated(ds: Dataset) -> Self {
        debug_assert!(ds.validate().is_ok());
        Self(ds)
    }

    /// The first `n` training trajectories and every test trajectory, as a dataset whose
    /// training part is those `n` (a training-set-size study).
    ///
    /// # Errors
    /// [`DatasetError::BadNTrain`] for `n` above the training trajectories; [`DatasetError::Empty`]
    /// when nothing is left.
    pub fn with_training_prefix(&self, n: usize) -> Result<Self, DatasetError> {
        let ds = &self.0;
        let n_train = ds.n_train;
        if n > n_train {
            return Err(DatasetError::BadNTrain {
                n_train: n,
                n_trajectories: n_train,
            });
        }
        let trajectories: Vec<_> = ds.trajectories[..n]
            .iter()
            .chain(&ds.trajectories[n_train..])
            .cloned()
            .collect();
        if trajectories.is_empty() {
            return Err(DatasetError::Empty);
        }
        Ok(Self(Dataset {
            meta: ds.meta.clone(),
            dt_s: ds.dt_s,
            trajectories,
            n_train: n,
        }))
    }

    /// The dataset, for editing.
    pub fn into_inner(self) -> Dataset {
        self.0
    }
}

impl Deref for ValidDataset {
    type Target = Dataset;

    fn deref(&self) -> &Dataset {
        &self.0
    }
}

impl AsRef<Dataset> for ValidDataset {
    fn as_ref(&self) -> &Dataset {
        &self.0
    }
}

impl TryFrom<Dataset> for ValidDataset {
    type Error = DatasetError;

    fn try_from(ds: Dataset) -> Result<Self, DatasetError> {
        Self::new(ds)
    }
}

impl PartialEq<Dataset> for ValidDataset {
    fn eq(&self, other: &Dataset) -> bool {
        self.0 == *other
    }
}
