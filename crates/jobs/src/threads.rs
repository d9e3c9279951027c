//! The thread count of a job: an explicit setting that sizes the pool the job runs in.
//!
//! Every parallel loop of flapssm (trajectories, minibatch windows, cross-validation folds,
//! restarts) runs on the rayon pool of the calling thread. [`run_with_threads`] runs a job on a
//! pool of exactly the requested size; without a request the job runs on rayon's global pool
//! (sized by `RAYON_NUM_THREADS`, else one thread per core). Results never depend on the count.

use crate::error::{JobError, Result};

/// Runs `job` on a pool of `threads` threads (`None`: the global pool); `Some(1)` runs every
/// parallel loop of the job on one thread.
///
/// # Errors
/// [`JobError::Setting`] for `Some(0)` or a pool that cannot be built.
pub fn run_with_threads<T: Send>(
    threads: Option<usize>,
    job: impl FnOnce() -> T + Send,
) -> Result<T> {
    let Some(n) = threads else {
        return Ok(job());
    };
    if n == 0 {
        return Err(JobError::Setting {
            name: "threads".into(),
            value: "0".into(),
            expected: "must be at least 1".into(),
        });
    }
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(n)
        .build()
        .map_err(|e| JobError::Setting {
            name: "threads".into(),
            value: n.to_string(),
            expected: format!("a pool of that size could not be started: {e}"),
        })?;
    Ok(pool.install(job))
}

/// Threads of the pool the caller runs on.
pub fn current_threads() -> usize {
    rayon::current_num_threads()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_job_runs_on_a_pool_of_the_requested_size() {
        for n in [1, 3] {
            let seen = run_with_threads(Some(n), current_threads).unwrap();
            assert_eq!(seen, n);
        }
        assert!(run_with_threads(Some(0), || ()).is_err());
        assert_eq!(run_with_threads(None, || 7).unwrap(), 7);
    }
}
