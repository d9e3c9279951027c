//! Progress of long jobs, reported to a caller-supplied sink (the CLI passes indicatif bars,
//! the Python bindings will pass a callback).

/// Progress of long stages (implemented by the CLI with progress bars). All methods default to
/// doing nothing; `advance` may be called from several threads.
pub trait Progress: Sync {
    /// A stage with `total` units of work starts (`total` 0: unknown).
    fn start(&self, _stage: &str, _total: u64) {}
    /// `n` units of the current stage are done.
    fn advance(&self, _n: u64) {}
    /// The current stage's position is `pos` of `total` units.
    fn set(&self, _pos: u64, _total: u64) {}
    /// A status line for the current stage.
    fn message(&self, _msg: &str) {}
    /// A line to print above the progress bars.
    fn println(&self, _line: &str) {}
    /// The current stage is done; `note` says how (e.g. "skipped: up to date").
    fn finish(&self, _note: &str) {}
}

/// A [`Progress`] that reports nothing.
#[derive(Debug, Clone, Copy, Default)]
pub struct NoProgress;
impl Progress for NoProgress {}
