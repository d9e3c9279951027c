//! A user's own rig (docs/own-rig.md): its description read from TOML, its raw recordings (CSV,
//! whitespace text, MAT) built into a dataset with its geometry and fluid, and the virtual wing
//! rehearsing it by writing the raw recordings that rig would.

use std::path::{Path, PathBuf};

use flapssm_analysis::plots::processing::{ProcessingPanel, processing_steps};
use flapssm_data::table::{Column, Table};
use flapssm_wing::dataset::{
    Dataset, DatasetMeta, FORMAT_VERSION, INPUT_UNITS, OUTPUT_NAMES, OUTPUT_UNITS, Trajectory,
    ValidDataset,
};
use flapssm_wing::rig::{
    Identified, ProcessedRecording, RawRecording, RecordingReport, RigDescription, RigError,
    RigidBody, identify, process_recording, rehearse, virtual_wing_of,
};
use flapssm_wing::trajectories::{GeneratorConfig, SamplingConfig, default_n_train};
use flapssm_wing::virtual_wing::{Fidelity, VirtualWing};
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rayon::prelude::*;

use crate::error::{JobError, Result, analysis};
use crate::files::save_text;
use crate::progress::Progress;

/// A documented rig description to start from (`flapssm dataset rig-template`): a water rig
/// unlike the paper's, the one the guide rehearses.
pub const RIG_TEMPLATE: &str = include_str!("template.toml");

/// Reads and checks a rig description (TOML).
///
/// # Errors
/// [`JobError::Io`]; [`JobError::Parse`] with the line of a TOML error, an unknown or missing
/// field; [`JobError::Rig`] naming a field out of range.
pub fn load_rig(path: &Path) -> Result<RigDescription> {
    let text = std::fs::read_to_string(path).map_err(|source| JobError::Io {
        path: path.to_path_buf(),
        source,
    })?;
    parse_rig(&text, path)
}

/// [`load_rig`] of the text of `source`.
///
/// # Errors
/// As [`load_rig`].
pub fn parse_rig(text: &str, source: &Path) -> Result<RigDescription> {
    let desc: RigDescription = toml::from_str(text).map_err(|e| JobError::Parse {
        path: source.to_path_buf(),
        line: e.span().map_or(0, |s| {
            text[..s.start.min(text.len())].lines().count().max(1)
        }),
        message: e.message().to_string(),
    })?;
    desc.check().map_err(|source_error| JobError::Rig {
        path: source.to_path_buf(),
        source: source_error,
    })?;
    Ok(desc)
}

/// A rig description given as JSON (Python's dict), checked as [`load_rig`] checks a file;
/// `source` names it in messages.
///
/// # Errors
/// [`JobError::Json`] for a wrong, missing or unknown field; [`JobError::Rig`] naming a field
/// out of range.
pub fn rig_from_json(text: &str, source: &Path) -> Result<RigDescription> {
    let desc: RigDescription = serde_json::from_str(text).map_err(|e| JobError::Json {
        path: source.to_path_buf(),
        source: e,
    })?;
    desc.check().map_err(|e| JobError::Rig {
        path: source.to_path_buf(),
        source: e,
    })?;
    Ok(desc)
}

/// Reads a raw recording: a CSV with a header, whitespace-separated numbers (columns named
/// `0`, `1`, …) or a MAT file (v4, v5; a variable per column, or `name[k]` for column k of a
/// matrix), its channels named by the rig description.
///
/// # Errors
/// [`JobError::Table`] naming the file, line and column (a missing channel lists those present).
pub fn read_recording(desc: &RigDescription, path: &Path) -> Result<RawRecording> {
    let table = Table::read(path)?;
    let column = |name: &str| -> Result<&[f64]> {
        let c: Column = name.parse().unwrap_or_else(|e| match e {});
        Ok(table.column(&c)?)
    };
    let angles: Vec<&[f64]> = desc
        .angles
        .columns
        .iter()
        .map(|c| column(c))
        .collect::<Result<_>>()?;
    let sensor: Vec<&[f64]> = desc
        .sensor
        .columns
        .iter()
        .map(|c| column(c))
        .collect::<Result<_>>()?;
    let time_s = desc
        .sampling
        .time_column
        .as_deref()
        .map(|c| column(c).map(<[f64]>::to_vec))
        .transpose()?;
    let n = table.n_rows();
    Ok(RawRecording {
        source_name: path.display().to_string(),
        time_s,
        angles: (0..n)
            .map(|k| std::array::from_fn(|a| angles[a][k]))
            .collect(),
        sensor: (0..n)
            .map(|k| std::array::from_fn(|c| sensor[c][k]))
            .collect(),
    })
}

/// A dataset built from recordings, with what each recording's processing found.
#[derive(Debug, Clone)]
pub struct Built {
    /// The dataset: the rig's geometry and fluid, generator `"flapssm dataset build"`, the
    /// description and the reports in its settings.
    pub dataset: ValidDataset,
    /// One report per recording, in the order given.
    pub reports: Vec<RecordingReport>,
    /// The processed recordings (their intermediate signals), in the order given.
    pub processed: Vec<ProcessedRecording>,
    /// The rigid body identified from the description's reference runs, if it has any.
    pub identified: Option<Identified>,
}

/// The reference recordings of a description, relative to the directory of its file.
pub fn reference_files(desc: &RigDescription, rig_source: &Path) -> Vec<PathBuf> {
    let base = rig_source.parent().unwrap_or(Path::new(""));
    desc.reference
        .iter()
        .flat_map(|r| r.recordings.iter().map(|f| base.join(f)))
        .collect()
}

/// The rigid body the processing subtracts: identified from the reference runs (read relative
/// to the description's file) if the description has any, else its `[mass]`.
///
/// # Errors
/// Reading the reference recordings; [`JobError::Rig`] if they do not determine the body.
pub fn rigid_body(
    desc: &RigDescription,
    rig_source: &Path,
) -> Result<(Option<RigidBody>, Option<Identified>)> {
    if desc.reference.is_none() {
        return Ok((desc.rigid_body(), None));
    }
    let runs = reference_files(desc, rig_source)
        .iter()
        .map(|p| read_recording(desc, p))
        .collect::<Result<Vec<_>>>()?;
    let found = identify(desc, &runs).map_err(|source| match source {
        RigError::Recording { .. } => JobError::Recording(source),
        _ => JobError::Rig {
            path: rig_source.to_path_buf(),
            source,
        },
    })?;
    Ok((Some(found.rigid_body(desc)), Some(found)))
}

/// Builds a dataset from raw recordings (module [`flapssm_wing::rig::recording`]): their
/// trajectories in the order of `files`, the first `n_train` for training (default: the
/// published share, 512 of 548).
///
/// # Errors
/// [`JobError::Setting`] for no recording or a bad `n_train`; reading and processing errors
/// naming the file; [`JobError::Mismatch`] for recordings whose trajectories differ in length.
pub fn build_dataset(
    desc: &RigDescription,
    rig_source: &Path,
    files: &[PathBuf],
    n_train: Option<usize>,
    progress: &dyn Progress,
) -> Result<Built> {
    if files.is_empty() {
        return Err(JobError::Setting {
            name: "recordings".into(),
            value: "none".into(),
            expected: "at least one recording file".into(),
        });
    }
    let (body, identified) = rigid_body(desc, rig_source)?;
    progress.start("processing recordings", files.len() as u64);
    let processed: Vec<ProcessedRecording> = files
        .par_iter()
        .map(|path| {
            let rec = read_recording(desc, path)?;
            let out = process_recording(desc, body.as_ref(), &rec).map_err(JobError::Recording);
            progress.advance(1);
            out
        })
        .collect::<Result<_>>()?;
    progress.finish("");
    let mut trajectories: Vec<Trajectory> = Vec::new();
    let mut first: Option<(usize, &Path)> = None;
    for (p, path) in processed.iter().zip(files) {
        for t in &p.trajectories {
            match first {
                None => first = Some((t.inputs.len(), path)),
                Some((len, first_path)) if len != t.inputs.len() => {
                    return Err(JobError::Mismatch {
                        what: format!(
                            "trajectory length of {} (set trajectories.duration_s in the rig \
                             description to cut equal pieces)",
                            path.display()
                        ),
                        expected: format!("{len} samples, as {}", first_path.display()),
                        found: format!("{} samples", t.inputs.len()),
                    });
                }
                Some(_) => {}
            }
            trajectories.push(t.clone());
        }
    }
    let n = trajectories.len();
    let n_train = n_train.unwrap_or_else(|| default_n_train(n));
    if n_train > n {
        return Err(JobError::Setting {
            name: "n_train".into(),
            value: n_train.to_string(),
            expected: format!("at most the {n} trajectories of the recordings"),
        });
    }
    let reports: Vec<RecordingReport> = processed.iter().map(|p| p.report.clone()).collect();
    let settings = serde_json::json!({
        "rig": desc,
        "rig_file": rig_source.display().to_string(),
        "recordings": reports,
        "identified": identified,
    });
    let dataset = dataset_of(
        desc,
        "flapssm dataset build",
        None,
        settings,
        trajectories,
        n_train,
    )?;
    Ok(Built {
        dataset,
        reports,
        processed,
        identified,
    })
}

/// The dataset of a rig's trajectories: its geometry and fluid, its dataset rate.
fn dataset_of(
    desc: &RigDescription,
    generator: &str,
    seed: Option<u64>,
    settings: serde_json::Value,
    trajectories: Vec<Trajectory>,
    n_train: usize,
) -> Result<ValidDataset> {
    let meta = DatasetMeta {
        format_version: FORMAT_VERSION,
        wing: desc.geometry(),
        fluid: desc.fluid(),
        generator: generator.into(),
        seed,
        settings,
        input_units: INPUT_UNITS.iter().map(|s| s.to_string()).collect(),
        output_units: OUTPUT_UNITS.iter().map(|s| s.to_string()).collect(),
    };
    Ok(ValidDataset::new(Dataset {
        meta,
        dt_s: 1.0 / desc.sampling.dataset_rate_hz,
        trajectories,
        n_train,
    })?)
}

/// The files [`write_steps`] writes for a recording.
pub fn steps_file_names(recording: &Path) -> [String; 2] {
    let stem = recording
        .file_stem()
        .map_or("recording".into(), |s| s.to_string_lossy());
    [format!("{stem}.steps.csv"), format!("{stem}.steps.png")]
}

/// Writes, per recording, `<stem>.steps.csv` and the figure `<stem>.steps.png`: the loads after
/// the tare, the rigid-body loads subtracted and the processed loads at the raw rate (wing axes
/// about the root; N, N·mm), to check each step (docs/own-rig.md).
///
/// # Errors
/// [`JobError::Io`] naming the file, [`JobError::Analysis`] for the figure.
pub fn write_steps(
    dir: &Path,
    desc: &RigDescription,
    files: &[PathBuf],
    processed: &[ProcessedRecording],
) -> Result<()> {
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    for (path, p) in files.iter().zip(processed) {
        let [csv, png] = steps_file_names(path);
        let mut text = String::from("time_s");
        for step in ["tared", "subtracted", "processed"] {
            for name in OUTPUT_NAMES {
                text.push_str(&format!(",{step}_{name}"));
            }
        }
        text.push('\n');
        let s = &p.steps;
        for k in 0..s.time_s.len() {
            text.push_str(&format!("{}", s.time_s[k]));
            for row in [&s.tared[k], &s.subtracted[k], &s.processed[k]] {
                row.iter().for_each(|v| text.push_str(&format!(",{v}")));
            }
            text.push('\n');
        }
        save_text(&dir.join(csv), &text)?;
        let title = format!("{}: processing steps", path.display());
        let labels: Vec<String> = OUTPUT_NAMES
            .iter()
            .zip(OUTPUT_UNITS)
            .map(|(n, u)| format!("{n} ({u})"))
            .collect();
        let panel = ProcessingPanel {
            title: &title,
            t_s: &s.time_s,
            tared: &s.tared,
            subtracted: &s.subtracted,
            processed: &s.processed,
            rest_end_s: (desc.tare.rest_s > 0.0).then_some(desc.tare.rest_s),
            channels: std::array::from_fn(|c| labels[c].as_str()),
        };
        processing_steps(&dir.join(&png), &panel).map_err(analysis(png))?;
    }
    Ok(())
}

/// Settings of a rehearsal with the virtual wing.
#[derive(Debug, Clone, PartialEq)]
pub struct RehearsalSettings {
    /// Recordings (one generated trajectory each).
    pub n_recordings: usize,
    /// Seed of the trajectories, offsets and noise.
    pub seed: u64,
    /// Aerodynamic fidelity of the virtual wing.
    pub fidelity: Fidelity,
    /// Length of each motion after the move from home (s).
    pub motion_s: f64,
    /// Training trajectories of the known-answer dataset (default: the published share).
    pub n_train: Option<usize>,
}

impl Default for RehearsalSettings {
    /// Ten recordings of 16 s, seed 0, the quasi-steady wing.
    fn default() -> Self {
        Self {
            n_recordings: 10,
            seed: 0,
            fidelity: Fidelity::L0,
            motion_s: 16.0,
            n_train: None,
        }
    }
}

/// The file name of rehearsed recording `i`.
pub fn rehearsal_file_name(i: usize) -> String {
    format!("recording_{i:03}.csv")
}

/// Writes the raw recordings (CSV, the rig's column names) that the rig of `desc` would make
/// of `settings.n_recordings` generated motions (the generator's defaults at the rig's rate, at
/// least two cycles per motion) into `dir` ([`rehearsal_file_name`]), and returns
/// the known answer: the virtual wing's own loads on them, cut as the processing cuts them.
///
/// # Errors
/// [`JobError::Setting`] for no recording or a motion too short; generator, simulation and I/O
/// errors.
pub fn rehearse_rig(
    desc: &RigDescription,
    rig_source: &Path,
    settings: &RehearsalSettings,
    dir: &Path,
    progress: &dyn Progress,
) -> Result<ValidDataset> {
    if settings.n_recordings == 0 {
        return Err(JobError::Setting {
            name: "n".into(),
            value: "0".into(),
            expected: "at least one recording".into(),
        });
    }
    if !(settings.motion_s.is_finite() && settings.motion_s >= 1.0) {
        return Err(JobError::Setting {
            name: "motion_s".into(),
            value: settings.motion_s.to_string(),
            expected: "at least 1 s".into(),
        });
    }
    let rate = desc.sampling.rate_hz;
    let defaults = GeneratorConfig::default();
    // At least two cycles per motion, for U_ref: a short motion flaps faster.
    let [lo, hi] = defaults.frequency_hz;
    let lo = lo.max(2.0 / settings.motion_s);
    let generator = GeneratorConfig {
        frequency_hz: [lo, hi.max(lo)],
        n_trajectories: settings.n_recordings,
        n_train: settings.n_recordings,
        seed: settings.seed,
        sampling: SamplingConfig {
            raw_rate_hz: rate,
            decimation: 1,
            n_samples: (settings.motion_s * rate).round() as usize,
        },
        ..defaults
    };
    let specs = generator.generate()?;
    let wing_cfg = virtual_wing_of(desc, settings.fidelity);
    wing_cfg.check()?;
    std::fs::create_dir_all(dir).map_err(|source| JobError::Io {
        path: dir.to_path_buf(),
        source,
    })?;
    progress.start("rehearsing recordings", specs.len() as u64);
    let truths: Vec<Vec<Trajectory>> = specs
        .par_iter()
        .enumerate()
        .map(|(i, spec)| {
            let mut wing = VirtualWing::new(&wing_cfg)?;
            let mut rng = ChaCha8Rng::seed_from_u64(settings.seed);
            rng.set_stream(i as u64);
            let name = rehearsal_file_name(i);
            let motion = spec.sample_raw(&generator.sampling);
            let r =
                rehearse(desc, &mut wing, &motion, &name, &mut rng).map_err(JobError::Recording)?;
            save_text(&dir.join(&name), &recording_csv(desc, &r.recording))?;
            progress.advance(1);
            Ok(r.truth
                .into_iter()
                .map(|t| Trajectory {
                    family: spec.family.label().to_string(),
                    ..t
                })
                .collect())
        })
        .collect::<Result<_>>()?;
    progress.finish("");
    let trajectories: Vec<Trajectory> = truths.into_iter().flatten().collect();
    let n = trajectories.len();
    let n_train = settings
        .n_train
        .unwrap_or_else(|| default_n_train(n))
        .min(n);
    let meta_settings = serde_json::json!({
        "rig": desc,
        "rig_file": rig_source.display().to_string(),
        "fidelity": settings.fidelity,
        "motion_s": settings.motion_s,
        "recordings": (0..settings.n_recordings).map(rehearsal_file_name).collect::<Vec<_>>(),
    });
    dataset_of(
        desc,
        "flapssm simulate --rig",
        Some(settings.seed),
        meta_settings,
        trajectories,
        n_train,
    )
}

/// A raw recording as CSV: the time column (if the rig has one), the angle and sensor columns.
pub fn recording_csv(desc: &RigDescription, rec: &RawRecording) -> String {
    let mut header: Vec<&str> = desc
        .sampling
        .time_column
        .iter()
        .map(String::as_str)
        .collect();
    header.extend(desc.angles.columns.iter().map(String::as_str));
    header.extend(desc.sensor.columns.iter().map(String::as_str));
    let mut text = header.join(",");
    text.push('\n');
    for k in 0..rec.angles.len() {
        let mut fields: Vec<String> = rec.time_s.iter().map(|t| format!("{}", t[k])).collect();
        fields.extend(rec.angles[k].iter().map(|v| format!("{v}")));
        fields.extend(rec.sensor[k].iter().map(|v| format!("{v}")));
        text.push_str(&fields.join(","));
        text.push('\n');
    }
    text
}
