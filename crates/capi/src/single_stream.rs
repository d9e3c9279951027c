//! The single-precision streaming predictor: particles, kernel and products in `float`
//! (`flapssm_prssm::stream::StreamPredictor<f32>`), for flight computers without a fast
//! double-precision FPU.

use flapssm_jobs::seed::prediction_seed;
use flapssm_prssm::stream::StreamPredictor;

use crate::model::FlapssmModel;
use crate::status::{FlapssmStatus, fail, guard};
use crate::stream::{Handle, SamePrecisionStep, free_handle, reset_handle, step_same_precision};
use flapssm_prssm::ObjectiveError;

/// A single-precision streaming predictor (opaque). Allocated at creation; stepping and
/// resetting allocate nothing.
#[derive(Debug)]
pub struct FlapssmSingleStream {
    stream: StreamPredictor<f32>,
    dims: (usize, usize),
}

impl SamePrecisionStep<f32> for FlapssmSingleStream {
    type Error = ObjectiveError;
    fn step(&mut self, u: &[f32]) -> Result<(&[f32], &[f32]), ObjectiveError> {
        self.stream.step(u)
    }
}

impl Handle for FlapssmSingleStream {
    fn dims(&self) -> (usize, usize) {
        self.dims
    }
    fn reset(&mut self) {
        self.stream.reset();
    }
}

/// Creates a single-precision streaming predictor of `model` (`particles` particles, the
/// draws of `seed`, from `x₀ = 0`: the same draws as [`crate::flapssm_stream_new`]) and
/// stores it in `*out` (to be freed with [`flapssm_single_stream_free`]). The model's
/// factorization is computed in double precision once, then rounded.
///
/// # Safety
/// `model` is null or a live handle; `out` is null or points to writable storage for a
/// pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_single_stream_new(
    model: *const FlapssmModel,
    particles: usize,
    seed: u64,
    out: *mut *mut FlapssmSingleStream,
) -> FlapssmStatus {
    guard(|| {
        // SAFETY: null or live, by the caller's contract.
        let Some(model) = (unsafe { model.as_ref() }) else {
            return fail(
                FlapssmStatus::NullArgument,
                "flapssm_single_stream_new: null model",
            );
        };
        if out.is_null() {
            return fail(
                FlapssmStatus::NullArgument,
                "flapssm_single_stream_new: null out",
            );
        }
        let m = &model.model;
        if particles == 0 {
            return fail(
                FlapssmStatus::InvalidValue,
                "particles: 0: must be at least 1",
            );
        }
        if let Err(e) = flapssm_jobs::resources::check_prediction(&m.config, particles, 1, 0.0) {
            return fail(FlapssmStatus::InvalidValue, e.to_string());
        }
        let zero = vec![0.0; m.config.n_state];
        match StreamPredictor::new(m, particles, &zero, &zero, prediction_seed(seed, 0)) {
            Ok(stream) => {
                let dims = (m.config.n_input, m.config.n_output);
                let handle = Box::into_raw(Box::new(FlapssmSingleStream { stream, dims }));
                // SAFETY: non-null and writable by the caller's contract.
                unsafe { *out = handle };
                FlapssmStatus::Ok
            }
            Err(e) => fail(FlapssmStatus::InvalidModel, e.to_string()),
        }
    })
}

/// Writes the moments of `y_t` into `mean` and `var` (`n_output` = `D_y` each) and advances
/// the particles with `u_t` (`n_input` = `D_u` values), all in single precision. Allocates
/// nothing. Statuses as [`crate::flapssm_stream_step`].
///
/// # Safety
/// `stream` is null or a live handle; `u` holds `n_input` readable values and `mean`, `var`
/// `n_output` writable ones (or are null).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_single_stream_step(
    stream: *mut FlapssmSingleStream,
    u: *const f32,
    n_input: usize,
    mean: *mut f32,
    var: *mut f32,
    n_output: usize,
) -> FlapssmStatus {
    // SAFETY: forwarded caller contract.
    unsafe { step_same_precision(stream, u, n_input, mean, var, n_output) }
}

/// Starts the stream again from `x₀ = 0` with its first draws. Allocates nothing.
///
/// # Safety
/// `stream` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_single_stream_reset(
    stream: *mut FlapssmSingleStream,
) -> FlapssmStatus {
    // SAFETY: forwarded caller contract.
    unsafe { reset_handle(stream, "flapssm_single_stream_reset") }
}

/// Frees a single-precision stream handle (null is ignored).
///
/// # Safety
/// `stream` is null or a handle from [`flapssm_single_stream_new`] not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_single_stream_free(stream: *mut FlapssmSingleStream) {
    // SAFETY: forwarded caller contract.
    unsafe { free_handle(stream) }
}
