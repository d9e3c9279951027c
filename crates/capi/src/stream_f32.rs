//! The single-precision streaming predictor: particles, kernel and products in `float`
//! (`flapssm_prssm::stream_f32`), for flight computers without a fast double-precision FPU.

use flapssm_jobs::seed::prediction_seed;
use flapssm_prssm::stream_f32::StreamPredictorF32;

use crate::model::FlapssmModel;
use crate::status::{FlapssmStatus, fail, guard};
use crate::stream::{Handle, checked_step, free_handle, reset_handle, with_arrays};

/// A single-precision streaming predictor (opaque). Allocated at creation; stepping and
/// resetting allocate nothing.
#[derive(Debug)]
pub struct FlapssmStreamF32 {
    stream: StreamPredictorF32,
    dims: (usize, usize),
}

impl Handle for FlapssmStreamF32 {
    fn dims(&self) -> (usize, usize) {
        self.dims
    }
    fn reset(&mut self) {
        self.stream.reset();
    }
}

/// Creates a single-precision streaming predictor of `model` (`particles` particles, the
/// draws of `seed`, from `x₀ = 0`: the same draws as [`crate::flapssm_stream_new`]) and
/// stores it in `*out` (to be freed with [`flapssm_stream_f32_free`]). The model's
/// factorization is computed in double precision once, then rounded.
///
/// # Safety
/// `model` is null or a live handle; `out` is null or points to writable storage for a
/// pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_f32_new(
    model: *const FlapssmModel,
    particles: usize,
    seed: u64,
    out: *mut *mut FlapssmStreamF32,
) -> FlapssmStatus {
    guard(|| {
        // SAFETY: null or live, by the caller's contract.
        let Some(model) = (unsafe { model.as_ref() }) else {
            return fail(
                FlapssmStatus::NullArgument,
                "flapssm_stream_f32_new: null model",
            );
        };
        if out.is_null() {
            return fail(
                FlapssmStatus::NullArgument,
                "flapssm_stream_f32_new: null out",
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
        match StreamPredictorF32::new(m, particles, prediction_seed(seed, 0)) {
            Ok(stream) => {
                let dims = (m.config.n_input, m.config.n_output);
                let handle = Box::into_raw(Box::new(FlapssmStreamF32 { stream, dims }));
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
pub unsafe extern "C" fn flapssm_stream_f32_step(
    stream: *mut FlapssmStreamF32,
    u: *const f32,
    n_input: usize,
    mean: *mut f32,
    var: *mut f32,
    n_output: usize,
) -> FlapssmStatus {
    // SAFETY: forwarded caller contract.
    unsafe {
        with_arrays(
            stream,
            u,
            n_input,
            mean,
            var,
            n_output,
            |s, u, mean, var| {
                checked_step(
                    u,
                    |u| s.stream.step(u),
                    |m, v| {
                        mean.copy_from_slice(m);
                        var.copy_from_slice(v);
                    },
                )
            },
        )
    }
}

/// Starts the stream again from `x₀ = 0` with its first draws. Allocates nothing.
///
/// # Safety
/// `stream` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_f32_reset(stream: *mut FlapssmStreamF32) -> FlapssmStatus {
    // SAFETY: forwarded caller contract.
    unsafe { reset_handle(stream, "flapssm_stream_f32_reset") }
}

/// Frees a single-precision stream handle (null is ignored).
///
/// # Safety
/// `stream` is null or a handle from [`flapssm_stream_f32_new`] not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_f32_free(stream: *mut FlapssmStreamF32) {
    // SAFETY: forwarded caller contract.
    unsafe { free_handle(stream) }
}
