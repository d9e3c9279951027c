//! Progress on the terminal: indicatif bars implementing [`flapssm_jobs::Progress`],
//! and the stop flag that Ctrl-C sets.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex};

use anyhow::Context;
use flapssm_jobs::Progress;
use indicatif::{ProgressBar, ProgressStyle};

/// Progress bars: one per stage, lines printed above.
pub struct Bars {
    bar: Mutex<Option<ProgressBar>>,
}

impl Bars {
    /// No stage running yet.
    pub fn new() -> Self {
        Self {
            bar: Mutex::new(None),
        }
    }

    fn with(&self, f: impl FnOnce(&ProgressBar)) {
        if let Ok(g) = self.bar.lock()
            && let Some(b) = g.as_ref()
        {
            f(b);
        }
    }
}

impl Progress for Bars {
    fn start(&self, stage: &str, total: u64) {
        let style = if total > 0 {
            ProgressStyle::with_template(
                "{prefix:>16} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta}) {msg}",
            )
        } else {
            ProgressStyle::with_template("{prefix:>16} {spinner} {elapsed_precise} {msg}")
        };
        let bar = ProgressBar::new(total);
        if let Ok(s) = style {
            bar.set_style(s.progress_chars("=> "));
        }
        bar.set_prefix(stage.to_string());
        bar.enable_steady_tick(std::time::Duration::from_millis(200));
        if let Ok(mut g) = self.bar.lock() {
            if let Some(old) = g.take() {
                old.finish();
            }
            *g = Some(bar);
        }
    }
    fn advance(&self, n: u64) {
        self.with(|b| b.inc(n));
    }
    fn set(&self, pos: u64, total: u64) {
        self.with(|b| {
            if b.length() != Some(total) {
                b.set_length(total);
                if let Ok(s) = ProgressStyle::with_template(
                    "{prefix:>16} [{bar:30}] {pos}/{len} {elapsed_precise} (eta {eta}) {msg}",
                ) {
                    b.set_style(s.progress_chars("=> "));
                }
            }
            b.set_position(pos);
        });
    }
    fn message(&self, msg: &str) {
        self.with(|b| b.set_message(msg.to_string()));
    }
    fn println(&self, line: &str) {
        let mut printed = false;
        self.with(|b| {
            if !b.is_hidden() {
                b.println(line);
                printed = true;
            }
        });
        if !printed {
            eprintln!("{line}");
        }
    }
    fn finish(&self, note: &str) {
        if let Ok(mut g) = self.bar.lock()
            && let Some(b) = g.take()
        {
            if b.is_hidden() && !note.is_empty() {
                eprintln!("{}: {note}", b.prefix());
            }
            b.finish_with_message(note.to_string());
        }
    }
}

/// A stop flag set by Ctrl-C (SIGINT) and, on Unix, by SIGTERM and SIGHUP (what `timeout`,
/// job schedulers and a closed terminal send): training then writes its checkpoint and the
/// command exits nonzero, resumable.
pub fn stop_flag() -> anyhow::Result<Arc<AtomicBool>> {
    let stop = Arc::new(AtomicBool::new(false));
    let s = Arc::clone(&stop);
    ctrlc::set_handler(move || s.store(true, Ordering::SeqCst))
        .context("installing the Ctrl-C / SIGTERM handler")?;
    Ok(stop)
}
