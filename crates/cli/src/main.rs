//! `flapssm` — command-line front end. Parses arguments, calls one library function per
//! subcommand, reports, and maps errors to a nonzero exit code. No numerics live here.

use clap::{Parser, Subcommand};

mod cmd;
mod progress;

/// Compact probabilistic state-space models of flapping-wing aerodynamics.
#[derive(Parser)]
#[command(name = "flapssm", version, about, long_about = None)]
struct Cli {
    /// Threads of the pool every parallel loop runs on (default: RAYON_NUM_THREADS, else one
    /// per core). Results do not depend on it.
    #[arg(long, global = true, value_parser = cmd::positive::<usize>)]
    threads: Option<usize>,
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print the version and build configuration.
    Version,
    /// Dataset files: info, export to CSV, import from MAT/CSV.
    Dataset(cmd::dataset::DatasetArgs),
    /// PR-SSM model files: import the published model.
    Model(cmd::model::ModelArgs),
    /// Open-loop PR-SSM prediction.
    Predict(cmd::predict::PredictArgs),
    /// Real-time PR-SSM prediction: input rows on stdin, predictions on stdout as they arrive.
    Stream(cmd::stream::StreamArgs),
    /// Train a PR-SSM on a dataset (presets paper, sysid; checkpoints, --resume).
    Train(cmd::train::TrainArgs),
    /// Measure PR-SSM training, prediction and streaming speed.
    Bench(cmd::bench::BenchArgs),
    /// Generate random wing trajectories (kinematics-only dataset).
    Trajectories(cmd::trajectories::TrajectoriesArgs),
    /// Simulate the virtual robotic wing (L0–L3 aerodynamics, sensor chain) into a dataset.
    Simulate(cmd::simulate::SimulateArgs),
    /// Quasi-steady baseline (LRQSM): elastic net with cross-validation.
    Qs {
        #[command(subcommand)]
        command: cmd::qs::QsCommand,
    },
    /// The rig as the judge: a dataset of the paper's trajectories against the published model's
    /// prediction of the rig's loads; the mount angles that bring a wing closest to it.
    Rig(cmd::rig::RigArgs),
    /// Wing kinematics chosen with a learned model, verified on the virtual wing; cycle-to-cycle
    /// control of the mean lift.
    Design(cmd::design::DesignArgs),
    /// Evaluate a PR-SSM and an LRQSM on a dataset: metrics, authority, figures, report.
    Evaluate(cmd::evaluate::EvaluateArgs),
    /// The history curve: a GP baseline's test error against the input history it is given.
    History(cmd::history::HistoryArgs),
    /// PR-SSM sweeps: `run` one configuration (D_x or training-set size), `merge` results.
    Sweep {
        #[command(subcommand)]
        command: cmd::sweep::SweepCommand,
    },
    /// The whole pipeline on a simulated wing (resumable; --full for the paper's configuration).
    Demo(cmd::demo::DemoArgs),
    /// System identification on recorded data (Doerr et al. protocol): fit, open-loop test.
    Sysid(cmd::sysid::SysidArgs),
}

/// Restores the default SIGPIPE action (Rust ignores it), so that writing to a closed pipe
/// (`flapssm … | head`) ends the process quietly instead of panicking in `println!`.
fn restore_sigpipe() {
    #[cfg(unix)]
    // SAFETY: runs first in `main`, before any other thread exists; SIG_DFL is a valid action.
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
}

fn main() {
    restore_sigpipe();
    let cli = Cli::parse();
    let result = flapssm_jobs::threads::run_with_threads(cli.threads, || run(cli.command))
        .map_err(anyhow::Error::from)
        .and_then(|r| r);
    if let Err(err) = result {
        eprintln!("error: {}", cmd::error_message(&err));
        std::process::exit(1);
    }
}

/// Runs one subcommand.
fn run(command: Command) -> anyhow::Result<()> {
    match command {
        Command::Version => cmd::version(),
        Command::Dataset(args) => cmd::dataset::run(args),
        Command::Model(args) => cmd::model::run(args),
        Command::Predict(args) => cmd::predict::run(args),
        Command::Stream(args) => cmd::stream::run(args),
        Command::Train(args) => cmd::train::run(args),
        Command::Bench(args) => cmd::bench::run(args),
        Command::Trajectories(args) => cmd::trajectories::run(args),
        Command::Simulate(args) => cmd::simulate::run(args),
        Command::Qs { command } => cmd::qs::run(command),
        Command::Rig(args) => cmd::rig::run(args),
        Command::Design(args) => cmd::design::run(args),
        Command::Evaluate(args) => cmd::evaluate::run(args),
        Command::History(args) => cmd::history::run(args),
        Command::Sweep { command } => cmd::sweep::run(command),
        Command::Demo(args) => cmd::demo::run(args),
        Command::Sysid(args) => cmd::sysid::run(args),
    }
}
