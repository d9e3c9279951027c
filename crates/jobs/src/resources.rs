//! Memory a job will need, estimated from its sizes and compared with what the machine has
//! before any work: a size that cannot fit is refused with the estimate, instead of aborting on
//! a failed allocation part-way (`simulate --n 1000000000000`, `--particles 1000000000`).
//!
//! The estimates are the dominant arrays, rounded up; they are meant to catch sizes that are
//! orders of magnitude too large, not to budget memory to the byte.

use crate::error::{JobError, Result};

/// Bytes of memory available to a new allocation: `MemAvailable` of `/proc/meminfo` (Linux);
/// `None` where it cannot be read (nothing is refused then).
pub fn available_bytes() -> Option<f64> {
    let text = std::fs::read_to_string("/proc/meminfo").ok()?;
    let line = text.lines().find(|l| l.starts_with("MemAvailable:"))?;
    let kib: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kib * 1024.0)
}

/// Refuses a job whose estimated memory (`bytes`) exceeds what is available, naming the
/// setting that drives it.
///
/// # Errors
/// [`JobError::Setting`] with `name = value` and the estimate against the available memory.
pub fn check_memory(name: &str, value: impl ToString, bytes: f64) -> Result<()> {
    check_memory_against(name, value, bytes, available_bytes())
}

fn check_memory_against(
    name: &str,
    value: impl ToString,
    bytes: f64,
    available: Option<f64>,
) -> Result<()> {
    match available {
        Some(have) if bytes > have => Err(JobError::Setting {
            name: name.into(),
            value: value.to_string(),
            expected: format!(
                "needs about {} of memory, more than the {} available",
                human(bytes),
                human(have)
            ),
        }),
        _ => Ok(()),
    }
}

/// `bytes` in B, KiB, MiB, GiB or TiB with three significant digits.
fn human(bytes: f64) -> String {
    let units = ["B", "KiB", "MiB", "GiB", "TiB", "PiB", "EiB"];
    let mut v = bytes;
    let mut k = 0;
    while v >= 1024.0 && k + 1 < units.len() {
        v /= 1024.0;
        k += 1;
    }
    format!("{v:.3} {}", units[k])
}

/// [`check_memory`] for a dataset of `n` trajectories of `n_samples` ([`dataset_bytes`]),
/// `name` being the setting that gives `n`.
///
/// # Errors
/// As [`check_memory`].
pub fn check_dataset(name: &str, n: usize, n_samples: usize) -> Result<()> {
    check_memory(name, n, dataset_bytes(n, n_samples))
}

/// [`check_memory`] for a prediction with `particles` particles of a model of `config`, run
/// `streams` at a time (one per thread), plus `kept` bytes of results.
///
/// # Errors
/// As [`check_memory`], naming `particles`.
pub fn check_prediction(
    config: &flapssm_prssm::ModelConfig,
    particles: usize,
    streams: usize,
    kept: f64,
) -> Result<()> {
    let bytes = particle_bytes(particles * streams, 2, config.n_state, config.n_inducing);
    check_memory("particles", particles, bytes + kept)
}

/// Bytes of a simulated dataset of `n` trajectories of `n_samples`: Euler angles, 7 inputs and
/// 5 outputs in f64, twice (the dataset and the file's arrays while it is written).
pub fn dataset_bytes(n: usize, n_samples: usize) -> f64 {
    2.0 * n as f64 * n_samples as f64 * 15.0 * 8.0
}

/// Bytes of one particle simulation of `steps` steps (training keeps them all for the
/// backward pass): per particle and step the state, its mean and variance and a row of the
/// cross-covariance to the `inducing` points, f64.
pub fn particle_bytes(particles: usize, steps: usize, dx: usize, inducing: usize) -> f64 {
    particles as f64 * steps as f64 * (inducing + 4 * dx) as f64 * 8.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sizes_beyond_the_machine_are_refused_with_the_estimate() {
        let gib = 1024f64.powi(3);
        assert!(check_memory_against("particles", 30, gib, Some(8.0 * gib)).is_ok());
        let e = check_memory_against("n", 10, 9.5 * gib, Some(8.0 * gib))
            .unwrap_err()
            .to_string();
        assert!(
            e.contains("n = 10") && e.contains("9.500 GiB") && e.contains("8.000 GiB available"),
            "{e}"
        );
        assert!(check_memory_against("n", 10, 1e30, None).is_ok());
        assert!(available_bytes().is_none_or(|b| b > 0.0));
        // The paper's training: 16 windows × 30 particles × 470 steps, D_x 12, M 100.
        let paper = particle_bytes(16 * 30, 470, 12, 100);
        assert!(paper < 0.5 * gib, "{paper}");
        assert!(dataset_bytes(548, 470) < 0.1 * gib);
    }
}
