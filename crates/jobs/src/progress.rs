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

/// A [`Progress`] for tests: sets `stop` once the training has taken `after` steps, and keeps
/// the lines printed.
#[cfg(test)]
pub(crate) struct StopAfter<'a> {
    pub after: u64,
    pub stop: &'a std::sync::atomic::AtomicBool,
    pub lines: std::sync::Mutex<Vec<String>>,
}

#[cfg(test)]
impl<'a> StopAfter<'a> {
    pub fn new(after: u64, stop: &'a std::sync::atomic::AtomicBool) -> Self {
        Self {
            after,
            stop,
            lines: std::sync::Mutex::default(),
        }
    }
}

#[cfg(test)]
impl Progress for StopAfter<'_> {
    fn set(&self, pos: u64, _total: u64) {
        if pos >= self.after {
            self.stop.store(true, std::sync::atomic::Ordering::SeqCst);
        }
    }
    fn println(&self, line: &str) {
        self.lines.lock().unwrap().push(line.into());
    }
}
