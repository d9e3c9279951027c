//! `flapssm stream MODEL`: real-time PR-SSM prediction, one input sample in, the loads' mean and
//! variance out, allocation-free per step.
//!
//! [`LoadStream`] starts from `x₀ = 0` with the draws of [`prediction_seed`]`(seed, 0)`, exactly
//! as [`crate::predict::predict_inputs`]: both advance the particles through the engine's one
//! step (`flapssm_prssm::step::ParticleStep`), so streaming a table gives the batch
//! prediction draw for draw. [`stream_csv`] reads input rows as they arrive and writes each
//! prediction row at once (flushed), in the format of `flapssm predict --inputs`.
//!
//! Units: inputs in the model's units (physical when it carries normalization statistics:
//! rad, 1/s, 1/s², rad/s, rad/s² for the wing), outputs likewise (N, N·mm; variances squared).

use std::io::{BufRead, Write};

use flapssm_data::table::{is_number_row, split_csv_line};
use flapssm_prssm::PrssmModel;
use flapssm_prssm::predict::{write_csv_header, write_csv_row};
use flapssm_prssm::stream::StreamPredictor;

use crate::adapters::{input_columns, inputs_only_notes};
use crate::error::{JobError, Result};
use crate::seed::prediction_seed;

/// Settings of a stream.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct StreamSettings {
    /// Particles.
    pub particles: usize,
    /// Master seed of the draws ([`prediction_seed`]`(seed, 0)`).
    pub seed: u64,
}

impl Default for StreamSettings {
    /// 30 particles (the paper's prediction), seed 0.
    fn default() -> Self {
        Self {
            particles: 30,
            seed: 0,
        }
    }
}

/// A model's streaming predictor (see the module docs).
#[derive(Debug, Clone)]
pub struct LoadStream {
    predictor: StreamPredictor,
    n_input: usize,
    n_output: usize,
    notes: Vec<String>,
}

impl LoadStream {
    /// Prepares the predictor: factorizes the model's `K_mm` and draws the initial particles.
    ///
    /// # Errors
    /// [`JobError::Setting`] for no particle; [`JobError::Prssm`] for a model whose
    /// parameters do not factorize.
    pub fn new(model: &PrssmModel, settings: &StreamSettings) -> Result<Self> {
        if settings.particles == 0 {
            return Err(JobError::Setting {
                name: "particles".into(),
                value: "0".into(),
                expected: "must be at least 1".into(),
            });
        }
        let dx = model.config.n_state;
        crate::resources::check_prediction(&model.config, settings.particles, 1, 0.0)?;
        let zero = vec![0.0; dx];
        let predictor = StreamPredictor::new(
            model,
            settings.particles,
            &zero,
            &zero,
            prediction_seed(settings.seed, 0),
        )
        .map_err(|e| JobError::Prssm {
            what: "streaming predictor".into(),
            source: e.into(),
        })?;
        Ok(Self {
            predictor,
            n_input: model.config.n_input,
            n_output: model.config.n_output,
            notes: inputs_only_notes(model),
        })
    }

    /// Inputs per sample (`D_u`).
    pub fn n_input(&self) -> usize {
        self.n_input
    }

    /// Outputs per sample (`D_y`).
    pub fn n_output(&self) -> usize {
        self.n_output
    }

    /// Starts the stream again from `x₀ = 0` with its first draws: the next steps repeat
    /// those since creation exactly. Allocates nothing.
    pub fn reset(&mut self) {
        self.predictor.reset();
    }

    /// Notes for the user (an initial-state rule that inputs alone cannot apply).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The moments of `y_t` (mean, variance; `D_y` each), then the particles advanced by `u_t`
    /// (`D_u` values). Allocates nothing.
    ///
    /// # Errors
    /// [`JobError::Prssm`] for a wrong count or a non-finite input.
    pub fn step(&mut self, u: &[f64]) -> Result<(&[f64], &[f64])> {
        self.predictor.step(u).map_err(|e| JobError::Prssm {
            what: "streaming step".into(),
            source: e.into(),
        })
    }
}

/// Streams a CSV: a header line of `D_u` column names (matched to the model's inputs by
/// [`input_columns`]: by name for the wing's inputs), then one row of `D_u` numbers per time
/// step. Each row's prediction is written to `output` (`step,mean_0..,var_0..`, after a header
/// line) and flushed before the next row is read. `source` names the input in errors. Returns
/// the number of rows streamed.
///
/// # Errors
/// [`JobError::Parse`] naming `source`, the line and the column for a header of the wrong width,
/// a row of the wrong width or a field that is not a finite number; [`JobError::Io`] for read or
/// write failures.
pub fn stream_csv(
    stream: &mut LoadStream,
    input: impl BufRead,
    mut output: impl Write,
    source: &str,
) -> Result<u64> {
    let io = |e: std::io::Error| JobError::Io {
        path: source.into(),
        source: e,
    };
    let parse = |line: usize, message: String| JobError::Parse {
        path: source.into(),
        line,
        message,
    };
    let du = stream.n_input;
    let mut u = vec![0.0; du];
    let mut columns: Vec<usize> = (0..du).collect();
    let mut t = 0u64;
    let mut header = false;
    for (k, line) in input.lines().enumerate() {
        let line = line.map_err(io)?;
        let n = k + 1;
        let text = line.strip_prefix('\u{feff}').unwrap_or(&line);
        if text.trim().is_empty() {
            continue;
        }
        let fields = split_csv_line(text).map_err(|m| parse(n, m))?;
        if fields.len() != du {
            return Err(parse(
                n,
                format!("{} columns, expected the model's {du} inputs", fields.len()),
            ));
        }
        if !header {
            if is_number_row(&fields) {
                return Err(parse(
                    n,
                    "the first line holds numbers, not column names: a header line comes first"
                        .into(),
                ));
            }
            columns = input_columns(&fields, du).map_err(|e| parse(n, e.to_string()))?;
            header = true;
            write_csv_header(&mut output, stream.n_output).map_err(io)?;
            continue;
        }
        for (slot, &j) in u.iter_mut().zip(&columns) {
            let f = &fields[j];
            *slot = f
                .trim()
                .parse::<f64>()
                .ok()
                .filter(|v| v.is_finite())
                .ok_or_else(|| {
                    parse(n, format!("column {}: '{f}' is not a finite number", j + 1))
                })?;
        }
        let (mean, var) = stream.step(&u)?;
        write_csv_row(&mut output, t as usize, mean, var).map_err(io)?;
        output.flush().map_err(io)?;
        t += 1;
    }
    if !header {
        return Err(parse(0, "no header line".into()));
    }
    Ok(t)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::predict::predict_inputs;
    use crate::test_data::bare_model;
    use flapssm_prssm::ModelConfig;

    /// The stream writes, row for row and digit for digit, what `predict --inputs` writes.
    #[test]
    fn streaming_a_table_gives_the_batch_prediction() {
        let model = bare_model(ModelConfig::new(6, 5, 7, 8), 2);
        let rows: Vec<[f64; 7]> = (0..40)
            .map(|t| std::array::from_fn(|j| ((t * 7 + j) as f64 * 0.37).sin()))
            .collect();
        let mut csv = String::from("aoa,speed,a_x,a_y,a_z,pitch_rate,pitch_acc\n");
        for r in &rows {
            let line: Vec<String> = r.iter().map(f64::to_string).collect();
            csv.push_str(&line.join(","));
            csv.push('\n');
        }
        let settings = StreamSettings {
            particles: 7,
            seed: 11,
        };
        let mut stream = LoadStream::new(&model, &settings).unwrap();
        let mut out = Vec::new();
        let n = stream_csv(&mut stream, csv.as_bytes(), &mut out, "u.csv").unwrap();
        assert_eq!(n, 40);

        let batch = predict_inputs(&model, rows.as_flattened(), 7, 7, 11).unwrap();
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.csv");
        batch.prediction.write_csv(&path, 5).unwrap();
        let batch = std::fs::read_to_string(&path).unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), batch);

        // The same table with its columns in reverse order: matched by name, same output.
        let reversed: String = csv
            .lines()
            .map(|l| {
                let mut f: Vec<&str> = l.split(',').collect();
                f.reverse();
                f.join(",") + "\n"
            })
            .collect();
        let mut stream = LoadStream::new(&model, &settings).unwrap();
        let mut out = Vec::new();
        stream_csv(&mut stream, reversed.as_bytes(), &mut out, "u.csv").unwrap();
        assert_eq!(String::from_utf8(out).unwrap(), batch);
    }

    #[test]
    fn bad_rows_are_named_by_line_and_column() {
        let model = bare_model(ModelConfig::new(6, 5, 2, 4), 1);
        let settings = StreamSettings::default();
        let cases = [
            (
                "a,b\n1,2\n3\n",
                "u.csv line 3: 1 columns, expected the model's 2 inputs",
            ),
            (
                "a,b\n1,x\n",
                "u.csv line 2: column 2: 'x' is not a finite number",
            ),
            ("a,b\n1,inf\n", "column 2: 'inf' is not a finite number"),
            ("a\n", "line 1: 1 columns"),
            ("1,2\n3,4\n", "line 1: the first line holds numbers"),
            ("", "no header line"),
        ];
        for (text, message) in cases {
            let mut stream = LoadStream::new(&model, &settings).unwrap();
            let e = stream_csv(&mut stream, text.as_bytes(), Vec::new(), "u.csv").unwrap_err();
            assert!(e.to_string().contains(message), "{text:?}: {e}");
        }
        let zero = StreamSettings {
            particles: 0,
            seed: 0,
        };
        assert!(LoadStream::new(&model, &zero).is_err());
    }
}
