//! `flapssm` — command-line front end. Parses arguments, calls one library function per
//! subcommand, reports, and maps errors to a nonzero exit code. No numerics live here.

use clap::{Parser, Subcommand};

mod cmd;

/// Compact probabilistic state-space models of flapping-wing aerodynamics.
#[derive(Parser)]
#[command(name = "flapssm", version, about, long_about = None)]
struct Cli {
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
    /// Train a PR-SSM on a dataset (presets paper, sysid; checkpoints, --resume).
    Train(cmd::train::TrainArgs),
    /// Measure PR-SSM training, prediction and streaming speed.
    Bench(cmd::bench::BenchArgs),
    /// Generate random wing trajectories (kinematics-only dataset).
    Trajectories(cmd::trajectories::TrajectoriesArgs),
    /// Quasi-steady baseline (LRQSM): elastic net with cross-validation.
    Qs {
        #[command(subcommand)]
        command: cmd::qs::QsCommand,
    },
    /// System identification on recorded data (Doerr et al. protocol): fit, open-loop test.
    Sysid(cmd::sysid::SysidArgs),
}

fn main() {
    let cli = Cli::parse();
    let result = match cli.command {
        Command::Version => cmd::version(),
        Command::Dataset(args) => cmd::dataset::run(args),
        Command::Model(args) => cmd::model::run(args),
        Command::Predict(args) => cmd::predict::run(args),
        Command::Train(args) => cmd::train::run(args),
        Command::Bench(args) => cmd::bench::run(args),
        Command::Trajectories(args) => cmd::trajectories::run(args),
        Command::Qs { command } => cmd::qs::run(command),
        Command::Sysid(args) => cmd::sysid::run(args),
    };
    if let Err(err) = result {
        eprintln!("error: {err:#}");
        std::process::exit(1);
    }
}
