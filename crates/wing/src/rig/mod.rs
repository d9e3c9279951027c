//! A user's own rig: the description of a robotic wing, its fluid, angle convention and
//! force sensor ([`RigDescription`]), the processing that turns its raw recordings into the
//! dataset's wing-frame loads ([`recording`]), and the virtual wing as such a rig
//! ([`rehearse`]), which writes the raw recordings a rig would (docs/own-rig.md).
//!
//! # Frames, points and units
//!
//! Every position in a description is in the wing frame (x normal to the plate, y chordwise
//! towards the leading edge, z along the span, root → tip; [`crate::kinematics`]) measured from
//! the **wing root on the pitch axis**, the point (0, 0, `root_offset_m`) from the stroke axis.
//! The dataset's loads are the aerodynamic loads on the wing in the wing frame, forces in N,
//! moments in N·mm about that point: the frame and point of the default wing's sensor.

pub mod convention;
pub mod description;
pub mod identify;
pub mod recording;
pub mod rehearse;
pub mod rigid_body;

pub use convention::{AngleConvention, AngleUnit, EulerAngle};
pub use description::{
    Cutting, ForceUnit, LoadFilter, MassProperties, MomentUnit, RigDescription, RigFluid,
    RigSampling, RigWing, SensorPose, Subtract, Tare,
};
pub use identify::{Identified, Medium, Reference, identify};
pub use recording::{
    ProcessedRecording, ProcessingSteps, RawRecording, RecordingReport, process_recording,
};
pub use rehearse::{Rehearsed, rehearse, virtual_wing_of};
pub use rigid_body::RigidBody;

/// Errors of a rig description or of a recording processed with it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[non_exhaustive]
pub enum RigError {
    /// A field of the description is out of range or inconsistent with another.
    #[error("rig description field '{field}' = {value}: {reason}")]
    Field {
        /// The field, as written in the description (`sensor.rotation_deg`).
        field: String,
        /// Its value, as written.
        value: String,
        /// What it must be.
        reason: String,
    },
    /// A recording cannot be processed.
    #[error("recording {source_name}: {reason}")]
    Recording {
        /// The recording (its file name).
        source_name: String,
        /// What is wrong, naming the column, row or field.
        reason: String,
    },
}

impl RigError {
    pub(crate) fn field(field: &str, value: impl std::fmt::Display, reason: &str) -> Self {
        RigError::Field {
            field: field.to_string(),
            value: value.to_string(),
            reason: reason.to_string(),
        }
    }

    pub(crate) fn recording(source_name: &str, reason: String) -> Self {
        RigError::Recording {
            source_name: source_name.to_string(),
            reason,
        }
    }
}
