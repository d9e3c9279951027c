//! `flapssm._native`: the Rust side of the Python package (see `python/flapssm`). Thin: each
//! function converts numpy arrays, releases the GIL and calls the application layer
//! (`flapssm-jobs`); errors become Python exceptions carrying the CLI's messages.

mod dataset;
mod design;
mod errors;
mod evaluate;
mod lrqsm;
mod own_rig;
mod progress;
mod prssm;
mod rig;
mod sysid;

use pyo3::prelude::*;

#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<dataset::Dataset>()?;
    m.add_class::<lrqsm::Lrqsm>()?;
    m.add_class::<prssm::Prssm>()?;
    m.add_class::<prssm::Stream>()?;
    m.add_function(wrap_pyfunction!(dataset::simulate, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::simulate_angles, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::paper_angles, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::trajectories, m)?)?;
    m.add_function(wrap_pyfunction!(dataset::kinematics, m)?)?;
    m.add_function(wrap_pyfunction!(sysid::sysid, m)?)?;
    m.add_function(wrap_pyfunction!(prssm::train, m)?)?;
    m.add(
        "TRAINING_OPTIONS",
        flapssm_jobs::train::TrainingOptions::NAMES.to_vec(),
    )?;
    m.add_function(wrap_pyfunction!(evaluate::evaluate, m)?)?;
    m.add_function(wrap_pyfunction!(evaluate::history_curve, m)?)?;
    m.add_function(wrap_pyfunction!(rig::rig_check, m)?)?;
    m.add_function(wrap_pyfunction!(design::design_target, m)?)?;
    m.add_function(wrap_pyfunction!(design::design_control, m)?)?;
    m.add_function(wrap_pyfunction!(own_rig::rig_template, m)?)?;
    m.add_function(wrap_pyfunction!(own_rig::load_rig_description, m)?)?;
    m.add_function(wrap_pyfunction!(own_rig::build_dataset, m)?)?;
    m.add_function(wrap_pyfunction!(own_rig::rehearse_rig, m)?)?;
    m.add("INPUT_NAMES", flapssm_wing::dataset::INPUT_NAMES.to_vec())?;
    m.add("OUTPUT_NAMES", flapssm_wing::dataset::OUTPUT_NAMES.to_vec())?;
    m.add("INPUT_UNITS", flapssm_wing::dataset::INPUT_UNITS.to_vec())?;
    m.add("OUTPUT_UNITS", flapssm_wing::dataset::OUTPUT_UNITS.to_vec())?;
    Ok(())
}
