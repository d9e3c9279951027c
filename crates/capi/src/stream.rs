//! The streaming predictor: one input sample in, the loads' mean and variance out.

use flapssm_jobs::JobError;
use flapssm_jobs::stream::{LoadStream, StreamSettings};

use crate::model::FlapssmModel;
use crate::status::{FlapssmStatus, fail, guard};

/// A streaming predictor (opaque). Its buffers are allocated at creation; stepping and
/// resetting allocate nothing.
#[derive(Debug)]
pub struct FlapssmStream {
    stream: LoadStream,
    /// The `float` step's inputs in double precision (`D_u`).
    u: Vec<f64>,
}

/// What the C functions need of a stream handle.
pub(crate) trait Handle {
    /// `(D_u, D_y)`.
    fn dims(&self) -> (usize, usize);
    /// Back to `x₀ = 0` and the first draws.
    fn reset(&mut self);
}

impl Handle for FlapssmStream {
    fn dims(&self) -> (usize, usize) {
        (self.stream.n_input(), self.stream.n_output())
    }
    fn reset(&mut self) {
        self.stream.reset();
    }
}

/// Resets a handle; `name` is the C function's, for the null-pointer message.
///
/// # Safety
/// `stream` is null or a live handle.
pub(crate) unsafe fn reset_handle<H: Handle>(stream: *mut H, name: &str) -> FlapssmStatus {
    guard(|| {
        // SAFETY: null or live, by the caller's contract.
        match unsafe { stream.as_mut() } {
            Some(s) => {
                s.reset();
                FlapssmStatus::Ok
            }
            None => fail(FlapssmStatus::NullArgument, format!("{name}: null stream")),
        }
    })
}

/// Frees a handle made by `Box::into_raw` (null is ignored).
///
/// # Safety
/// `stream` is null or a live handle not freed before.
pub(crate) unsafe fn free_handle<H>(stream: *mut H) {
    if !stream.is_null() {
        // SAFETY: a live handle from `Box::into_raw`, by the caller's contract.
        drop(unsafe { Box::from_raw(stream) });
    }
}

/// `FLAPSSM_STATUS_INVALID_VALUE` naming the first non-finite input, if any.
pub(crate) fn check_finite<T: Copy + Into<f64>>(u: &[T]) -> Result<(), FlapssmStatus> {
    match u
        .iter()
        .map(|&v| v.into())
        .position(|v: f64| !v.is_finite())
    {
        Some(i) => Err(fail(
            FlapssmStatus::InvalidValue,
            format!("step: input {i} is not finite ({})", u[i].into()),
        )),
        None => Ok(()),
    }
}

/// Creates a streaming predictor of `model` with `particles` particles (the paper: 30) and
/// the draws of `seed`, started from `x₀ = 0`, and stores it in `*out` (to be freed with
/// [`flapssm_stream_free`]). The stream does not borrow the model: the model may be freed.
///
/// Returns `FLAPSSM_STATUS_INVALID_VALUE` for zero particles or more than memory holds,
/// `FLAPSSM_STATUS_INVALID_MODEL` when the model's `K_mm` does not factorize.
///
/// # Safety
/// `model` is null or a live handle; `out` is null or points to writable storage for a
/// pointer.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_new(
    model: *const FlapssmModel,
    particles: usize,
    seed: u64,
    out: *mut *mut FlapssmStream,
) -> FlapssmStatus {
    guard(|| {
        // SAFETY: null or live, by the caller's contract.
        let Some(model) = (unsafe { model.as_ref() }) else {
            return fail(
                FlapssmStatus::NullArgument,
                "flapssm_stream_new: null model",
            );
        };
        if out.is_null() {
            return fail(FlapssmStatus::NullArgument, "flapssm_stream_new: null out");
        }
        let settings = StreamSettings { particles, seed };
        match LoadStream::new(&model.model, &settings) {
            Ok(stream) => {
                let u = vec![0.0; stream.n_input()];
                let handle = Box::into_raw(Box::new(FlapssmStream { stream, u }));
                // SAFETY: non-null and writable by the caller's contract.
                unsafe { *out = handle };
                FlapssmStatus::Ok
            }
            Err(e @ (JobError::Setting { .. } | JobError::Mismatch { .. })) => {
                fail(FlapssmStatus::InvalidValue, e.to_string())
            }
            Err(e) => fail(FlapssmStatus::InvalidModel, e.to_string()),
        }
    })
}

/// Checks the handle, the pointers and the lengths of a step, then runs `body` on the stream
/// and the arrays as slices.
///
/// # Safety
/// As [`flapssm_stream_step`].
pub(crate) unsafe fn with_arrays<H: Handle, T>(
    stream: *mut H,
    u: *const T,
    n_input: usize,
    mean: *mut T,
    var: *mut T,
    n_output: usize,
    body: impl FnOnce(&mut H, &[T], &mut [T], &mut [T]) -> FlapssmStatus,
) -> FlapssmStatus {
    guard(|| {
        // SAFETY: null or live, by the caller's contract.
        let Some(s) = (unsafe { stream.as_mut() }) else {
            return fail(FlapssmStatus::NullArgument, "step: null stream");
        };
        if u.is_null() || mean.is_null() || var.is_null() {
            return fail(
                FlapssmStatus::NullArgument,
                "step: null input or output array",
            );
        }
        let (du, dy) = s.dims();
        if n_input != du || n_output != dy {
            return fail(
                FlapssmStatus::Shape,
                format!(
                    "step: {n_input} inputs and {n_output} outputs given, the model has {du} and {dy}"
                ),
            );
        }
        // SAFETY: lengths checked against the model; the caller guarantees the storage.
        let (u, mean, var) = unsafe {
            (
                std::slice::from_raw_parts(u, n_input),
                std::slice::from_raw_parts_mut(mean, n_output),
                std::slice::from_raw_parts_mut(var, n_output),
            )
        };
        body(s, u, mean, var)
    })
}

/// A handle whose stream steps in the precision of the caller's arrays.
pub(crate) trait SamePrecisionStep<T>: Handle {
    /// Why a step failed.
    type Error: std::fmt::Display;
    /// The moments of `y_t` (`D_y` each), then the particles advanced with `u` (`D_u`).
    fn step(&mut self, u: &[T]) -> Result<(&[T], &[T]), Self::Error>;
}

impl SamePrecisionStep<f64> for FlapssmStream {
    type Error = JobError;
    fn step(&mut self, u: &[f64]) -> Result<(&[f64], &[f64]), JobError> {
        self.stream.step(u)
    }
}

/// A step whose arrays are in the stream's own precision: the handle, pointers, lengths and
/// input checked ([`with_arrays`], [`checked_step`]), the step run, the moments copied out.
///
/// # Safety
/// As [`flapssm_stream_step`].
pub(crate) unsafe fn step_same_precision<H: SamePrecisionStep<T>, T: Copy + Into<f64>>(
    stream: *mut H,
    u: *const T,
    n_input: usize,
    mean: *mut T,
    var: *mut T,
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
                    |u| s.step(u),
                    |m, v| {
                        mean.copy_from_slice(m);
                        var.copy_from_slice(v);
                    },
                )
            },
        )
    }
}

/// Writes the moments of `y_t` into `mean` and `var` (`n_output` = `D_y` each) and advances
/// the particles with the input `u_t` (`n_input` = `D_u` values). Allocates nothing.
///
/// Returns `FLAPSSM_STATUS_SHAPE` for lengths other than the model's,
/// `FLAPSSM_STATUS_INVALID_VALUE` for a non-finite input (the stream is left unchanged).
///
/// # Safety
/// `stream` is null or a live handle; `u` holds `n_input` readable values and `mean`, `var`
/// `n_output` writable ones (or are null).
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_step(
    stream: *mut FlapssmStream,
    u: *const f64,
    n_input: usize,
    mean: *mut f64,
    var: *mut f64,
    n_output: usize,
) -> FlapssmStatus {
    // SAFETY: forwarded caller contract.
    unsafe { step_same_precision(stream, u, n_input, mean, var, n_output) }
}

/// [`flapssm_stream_step`] in single precision: the inputs are widened to `double`, the step
/// runs in double precision, and the moments are rounded to `float`. Allocates nothing.
///
/// # Safety
/// As [`flapssm_stream_step`], with `float` arrays.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_step_f32_arrays(
    stream: *mut FlapssmStream,
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
                s.u.iter_mut().zip(u).for_each(|(d, &v)| *d = f64::from(v));
                checked_step(
                    &s.u,
                    |u| s.stream.step(u),
                    |m, v| {
                        mean.iter_mut().zip(m).for_each(|(d, &x)| *d = x as f32);
                        var.iter_mut().zip(v).for_each(|(d, &x)| *d = x as f32);
                    },
                )
            },
        )
    }
}

/// One checked step of any stream: `u` refused if not finite (the stream untouched), then
/// `step(u)`, whose moments `write` receives; its error becomes `FLAPSSM_STATUS_INVALID_VALUE`.
pub(crate) fn checked_step<'s, T: Copy + Into<f64> + 's, E: std::fmt::Display>(
    u: &[T],
    step: impl FnOnce(&[T]) -> Result<(&'s [T], &'s [T]), E>,
    write: impl FnOnce(&[T], &[T]),
) -> FlapssmStatus {
    if let Err(status) = check_finite(u) {
        return status;
    }
    match step(u) {
        Ok((m, v)) => {
            write(m, v);
            FlapssmStatus::Ok
        }
        Err(e) => fail(FlapssmStatus::InvalidValue, e.to_string()),
    }
}

/// Starts the stream again from `x₀ = 0` with its first draws: the next steps repeat those
/// since creation exactly. Allocates nothing.
///
/// # Safety
/// `stream` is null or a live handle.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_reset(stream: *mut FlapssmStream) -> FlapssmStatus {
    // SAFETY: forwarded caller contract.
    unsafe { reset_handle(stream, "flapssm_stream_reset") }
}

/// Frees a stream handle (null is ignored).
///
/// # Safety
/// `stream` is null or a handle from [`flapssm_stream_new`] not freed before.
#[unsafe(no_mangle)]
pub unsafe extern "C" fn flapssm_stream_free(stream: *mut FlapssmStream) {
    // SAFETY: forwarded caller contract.
    unsafe { free_handle(stream) }
}
