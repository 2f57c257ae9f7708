//! `primo`: learn a movement skill from a couple of demonstrations and a
//! handful of trials. A thin binary: each subcommand's module parses its
//! arguments, checks them, and calls a library operation; exit statuses
//! are chosen here ([`error`]).

mod args;
mod demo;
mod dmp;
mod error;
mod experiment;
mod franka;
mod interrupt;
mod joint_path;
mod learn;
mod memory;
mod model;
mod output;
mod pour;
mod progress;
mod promp;
mod robot;
mod robot_check;
mod robot_ros2;
mod rollout;
mod scale;
mod terminal;

use clap::{Parser, Subcommand};

use crate::error::CliError;

/// primo: learn a movement skill from a couple of demonstrations and a
/// handful of trials.
#[derive(Debug, Parser)]
#[command(name = "primo", version, about)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Dynamic Movement Primitives: fit to a demonstration, run.
    #[command(subcommand)]
    Dmp(dmp::DmpCommand),
    /// Probabilistic movement primitives: fit to several demonstrations,
    /// run the mean conditioned on via-points.
    #[command(subcommand)]
    Promp(promp::PrompCommand),
    /// Demonstrations: synthesize them on the simulated cell.
    #[command(subcommand)]
    Demo(demo::DemoCommand),
    /// Learn to pour, on the simulated cell or a real one (--robot,
    /// --scale): fit the demonstrations, generalize to the bottle, learn,
    /// log and report every roll-out.
    Pour(pour::PourArgs),
    /// Learn any skill from a task file: your demonstrations and query,
    /// your limits, your evaluator (a program, the operator) or the
    /// built-in pouring cell.
    Learn(learn::LearnArgs),
    /// Execute parameter vectors on the simulated cell (an objective for
    /// any optimizer).
    Rollout(rollout::RolloutArgs),
    /// Reproduce the paper's experiments.
    #[command(subcommand)]
    Experiment(experiment::ExperimentCommand),
    /// The precision scale over MT-SICS: serve the simulated one, read one.
    #[command(subcommand)]
    Scale(scale::ScaleCommand),
    /// The robot: check a trajectory against its limits, stream one over
    /// KUKA FRI, or simulate the KRC.
    #[command(subcommand)]
    Robot(robot::RobotCommand),
}

fn main() {
    memory::keep_freed_blocks();
    let cli = match Cli::try_parse() {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            std::process::exit(e.exit_code());
        }
    };
    let result = match cli.command {
        Command::Dmp(command) => dmp::run(command),
        Command::Promp(command) => promp::run(command),
        Command::Demo(command) => demo::run(command),
        Command::Pour(args) => pour::run(&args),
        Command::Learn(args) => learn::run(&args),
        Command::Rollout(args) => rollout::run(&args),
        Command::Experiment(command) => experiment::run(command),
        Command::Scale(command) => scale::run(command),
        Command::Robot(command) => robot::run(command),
    };
    std::process::exit(match result {
        Ok(()) => 0,
        Err(CliError { message, status }) => {
            if !message.is_empty() {
                eprintln!("primo: {message}");
            }
            status
        }
    });
}
