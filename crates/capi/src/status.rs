//! Return codes and the last error message of the calling thread.

use std::cell::RefCell;
use std::ffi::{CString, c_char};
use std::panic::{AssertUnwindSafe, catch_unwind};

/// What a call did. `FLAPSSM_STATUS_OK` (0) on success; any other value is an error whose
/// message [`flapssm_last_error`] returns.
#[repr(C)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FlapssmStatus {
    /// Success.
    Ok = 0,
    /// A required pointer argument was null.
    NullArgument = 1,
    /// A file could not be read (missing, unreadable, not UTF-8 path).
    Io = 2,
    /// Not a valid flapssm PR-SSM model file, or its parameters do not factorize.
    InvalidModel = 3,
    /// An array length that does not match the model (`D_u` inputs, `D_y` outputs).
    Shape = 4,
    /// A value out of range: a non-finite input, zero particles, a size beyond memory.
    InvalidValue = 5,
    /// An internal error (a Rust panic, caught at the boundary); the handle should be freed.
    Panic = 6,
}

thread_local! {
    static LAST_ERROR: RefCell<CString> = RefCell::new(CString::default());
}

/// Records `message` as this thread's last error and returns `status`.
pub(crate) fn fail(status: FlapssmStatus, message: impl Into<String>) -> FlapssmStatus {
    let text = message.into().replace('\0', " ");
    LAST_ERROR.with(|e| *e.borrow_mut() = CString::new(text).unwrap_or_default());
    status
}

/// Runs `body`, turning a panic into [`FlapssmStatus::Panic`].
pub(crate) fn guard(body: impl FnOnce() -> FlapssmStatus) -> FlapssmStatus {
    catch_unwind(AssertUnwindSafe(body)).unwrap_or_else(|p| {
        let what = p
            .downcast_ref::<&str>()
            .map(|s| s.to_string())
            .or_else(|| p.downcast_ref::<String>().cloned())
            .unwrap_or_default();
        fail(FlapssmStatus::Panic, format!("internal error: {what}"))
    })
}

/// The message of the last failed call on this thread (UTF-8, NUL-terminated; empty when
/// none failed). Valid until the next failing call on this thread; never null.
#[unsafe(no_mangle)]
pub extern "C" fn flapssm_last_error() -> *const c_char {
    LAST_ERROR.with(|e| e.borrow().as_ptr())
}
