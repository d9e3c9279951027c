//! Errors of a design.

/// Why a design could not be made.
#[derive(Debug, thiserror::Error)]
#[non_exhaustive]
pub enum DesignError {
    /// A target or setting is invalid, unreachable or out of limits; names the field.
    #[error("{field}: {message}")]
    Invalid {
        /// The field, e.g. `target.lift_n`.
        field: String,
        /// What is wrong.
        message: String,
    },
    /// The design model failed to predict.
    #[error("design model {model}: {message}")]
    Model {
        /// The model.
        model: String,
        /// Its error.
        message: String,
    },
}

impl DesignError {
    /// An [`DesignError::Invalid`] of `field`.
    pub fn invalid(field: impl Into<String>, message: impl Into<String>) -> Self {
        Self::Invalid {
            field: field.into(),
            message: message.into(),
        }
    }
}
