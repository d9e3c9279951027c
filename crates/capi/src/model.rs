//! A PR-SSM model loaded from its file.

use std::ffi::{CStr, c_char};
use std::path::Path;

use flapssm_prssm::PrssmModel;
use flapssm_prssm::io::ModelFileError;

use crate::status::{FlapssmStatus, fail, guard};

/// A loaded PR-SSM model (opaque; read only once loaded).
#[derive(Debug)]
pub struct FlapssmModel {
    pub(crate) model: PrssmModel,
}

/// Loads a flapssm PR-SSM model file (`flapssm train`'s JSON; a published `.npz` model is
/// converted first with `flapssm model import-published`) and stores a new handle in `*out`
/// (to be freed with [`flapssm_model_free`]).
///
/// Returns `FLAPSSM_STATUS_IO` for an unreadable file, `FLAPSSM_STATUS_INVALID_MODEL` for a
/// file that is not a valid model, `FLAPSSM_STATUS_NULL_ARGUMENT` for a null pointer.
///
/// # Safety
/// `path` is null or a NUL-terminated string; `out` is null or points to writable storage
/// for a pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_model_load(
    path: *const c_char,
    out: *mut *mut FlapssmModel,
) -> FlapssmStatus {
    guard(|| {
        if path.is_null() || out.is_null() {
            return fail(
                FlapssmStatus::NullArgument,
                "flapssm_model_load: null argument",
            );
        }
        // SAFETY: non-null and NUL-terminated by the caller's contract.
        let Ok(path) = unsafe { CStr::from_ptr(path) }.to_str() else {
            return fail(FlapssmStatus::Io, "model path is not valid UTF-8");
        };
        match PrssmModel::load(Path::new(path)) {
            Ok(model) => {
                let handle = Box::into_raw(Box::new(FlapssmModel { model }));
                // SAFETY: `out` is non-null and writable by the caller's contract.
                unsafe { *out = handle };
                FlapssmStatus::Ok
            }
            Err(e @ ModelFileError::Io { .. }) => fail(FlapssmStatus::Io, e.to_string()),
            Err(e) => fail(FlapssmStatus::InvalidModel, e.to_string()),
        }
    })
}

/// Frees a model handle (null is ignored). Streams created from it stay valid.
///
/// # Safety
/// `model` is null or a handle from [`flapssm_model_load`] not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_model_free(model: *mut FlapssmModel) {
    if !model.is_null() {
        // SAFETY: a live handle from `Box::into_raw`, by the caller's contract.
        drop(unsafe { Box::from_raw(model) });
    }
}

/// Inputs per sample, `D_u` (7 for the wing); 0 for a null handle.
///
/// # Safety
/// `model` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_model_n_input(model: *const FlapssmModel) -> usize {
    // SAFETY: null or live, by the caller's contract.
    unsafe { model.as_ref() }.map_or(0, |m| m.model.config.n_input)
}

/// Outputs per sample, `D_y` (5 for the wing); 0 for a null handle.
///
/// # Safety
/// `model` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_model_n_output(model: *const FlapssmModel) -> usize {
    // SAFETY: null or live, by the caller's contract.
    unsafe { model.as_ref() }.map_or(0, |m| m.model.config.n_output)
}

/// Latent states, `D_x` (12 for the paper's model); 0 for a null handle.
///
/// # Safety
/// `model` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_model_n_state(model: *const FlapssmModel) -> usize {
    // SAFETY: null or live, by the caller's contract.
    unsafe { model.as_ref() }.map_or(0, |m| m.model.config.n_state)
}
