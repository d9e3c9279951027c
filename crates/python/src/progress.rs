//! Progress of a job reported to a Python callback `callback(stage, position, total)`, and
//! Ctrl-C: every report runs Python's signal handlers, and a `KeyboardInterrupt` (or an
//! exception of the callback) stops the job at its next step.

use std::sync::Mutex;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};

use flapssm_jobs::Progress;
use pyo3::prelude::*;

/// A [`Progress`] that calls back into Python.
pub struct PyProgress {
    callback: Option<Py<PyAny>>,
    stage: Mutex<String>,
    position: AtomicU64,
    total: AtomicU64,
    /// Set when the job must stop (Ctrl-C or a callback's exception).
    pub stop: AtomicBool,
    error: Mutex<Option<PyErr>>,
}

impl PyProgress {
    /// Reports to `callback` (or only watches for Ctrl-C).
    pub fn new(callback: Option<Py<PyAny>>) -> Self {
        Self {
            callback,
            stage: Mutex::new(String::new()),
            position: AtomicU64::new(0),
            total: AtomicU64::new(0),
            stop: AtomicBool::new(false),
            error: Mutex::new(None),
        }
    }

    /// The exception that stopped the job, if one did.
    pub fn take_error(&self) -> Option<PyErr> {
        self.error.lock().ok()?.take()
    }

    fn report(&self) {
        Python::attach(|py| {
            let mut result = py.check_signals();
            if result.is_ok()
                && let Some(cb) = &self.callback
            {
                let stage = self.stage.lock().map(|s| s.clone()).unwrap_or_default();
                let (p, t) = (
                    self.position.load(Ordering::Relaxed),
                    self.total.load(Ordering::Relaxed),
                );
                result = cb.call1(py, (stage, p, t)).map(drop);
            }
            if let Err(e) = result {
                self.stop.store(true, Ordering::SeqCst);
                if let Ok(mut slot) = self.error.lock() {
                    slot.get_or_insert(e);
                }
            }
        });
    }
}

impl Progress for PyProgress {
    fn start(&self, stage: &str, total: u64) {
        if let Ok(mut s) = self.stage.lock() {
            *s = stage.to_string();
        }
        self.position.store(0, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
        self.report();
    }
    fn advance(&self, n: u64) {
        self.position.fetch_add(n, Ordering::Relaxed);
        self.report();
    }
    fn set(&self, pos: u64, total: u64) {
        self.position.store(pos, Ordering::Relaxed);
        self.total.store(total, Ordering::Relaxed);
        self.report();
    }
    fn finish(&self, _note: &str) {
        let total = self.total.load(Ordering::Relaxed);
        if total > 0 {
            self.position.store(total, Ordering::Relaxed);
        }
        self.report();
    }
}
