//! The `primo` command line.

use std::io::Write;
use std::path::{Path, PathBuf};

use clap::{Parser, Subcommand};
use primo_core::dmp::FitOptions;

use crate::csv::{parse_demo, write_rows};
use crate::dmpfile::DmpFile;
use crate::pour::{Method, Settings, built_in_skill, power_blocks};
use crate::report::PowerSummary;
use crate::rig::InstrumentsSpec;
use crate::run::{CellSpec, DemoFile, LearnerSpec, SkillSpec, Start, create_dir};
use crate::sim::cell::{CellConfig, GlassKind};
use crate::sim::expert::{Style, synthesize};
use crate::skill::{Skill, Space};
use crate::{CliError, HostDmp, MAX_DOF, MAX_KERNELS, write_atomically};

/// primo: learn a movement skill from a couple of demonstrations and a
/// handful of trials.
#[derive(Debug, Parser)]
#[command(name = "primo", version, about)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Debug, Subcommand)]
enum Command {
    /// Dynamic Movement Primitives: fit to a demonstration, run.
    #[command(subcommand)]
    Dmp(DmpCommand),
    /// Demonstrations: synthesize them on the simulated cell.
    #[command(subcommand)]
    Demo(DemoCommand),
    /// Learn to pour, on the simulated cell or a real one (--robot,
    /// --scale): fit the demonstrations, generalize to the bottle, learn,
    /// log and report every roll-out.
    Pour(PourArgs),
    /// Execute parameter vectors on the simulated cell (an objective for
    /// any optimizer).
    Rollout(RolloutArgs),
    /// Reproduce the paper's experiments.
    #[command(subcommand)]
    Experiment(ExperimentCommand),
    /// The precision scale over MT-SICS: serve the simulated one, read one.
    #[command(subcommand)]
    Scale(crate::mtsics::commands::ScaleCommand),
    /// The robot over KUKA FRI: stream a trajectory, or simulate the KRC.
    #[command(subcommand)]
    Robot(crate::fri::robot::RobotCommand),
}

#[derive(Debug, Subcommand)]
enum DemoCommand {
    /// A scripted, slightly imperfect expert pours on the simulated cell;
    /// the movement is written as CSV (`t,x,y,z,rx,ry,rz` or `t,a1..a7`).
    Synth {
        /// Record the bottle pose or the joint angles.
        #[arg(long, value_enum, default_value_t = Space::Cartesian)]
        space: Space,
        /// Liquid in the bottle, l.
        #[arg(long, default_value_t = 0.5)]
        bottle: f64,
        /// Volume to pour, l.
        #[arg(long, default_value_t = 0.2)]
        pour: f64,
        /// Angle at which the demonstrator holds joint 3, rad.
        #[arg(long, default_value_t = 0.0, allow_hyphen_values = true)]
        elbow: f64,
        /// Seed of the expert's imperfections.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output CSV file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// The cell and skill options shared by the learning commands.
#[derive(Debug, Clone, clap::Args)]
struct SkillArgs {
    /// Coordinates the movement is learned in.
    #[arg(long, value_enum)]
    space: Option<Space>,
    /// Kernels per DoF of the DMPs.
    #[arg(long, default_value_t = 30)]
    kernels: usize,
    /// The glass on the scale.
    #[arg(long, value_enum)]
    glass: Option<GlassKind>,
    /// Demonstrations `FILE=VOLUME` (repeat; CSV in the space's columns).
    /// Default: the built-in pair from 0.3 l and 1.0 l bottles.
    #[arg(long = "demo", value_name = "FILE=VOLUME")]
    demos: Vec<String>,
}

#[derive(Debug, clap::Args)]
struct PourArgs {
    /// Liquid in the bottle, l.
    #[arg(long, default_value_t = 0.5)]
    bottle: f64,
    /// Volume to pour, l.
    #[arg(long, default_value_t = 0.2)]
    target: f64,
    /// The learner.
    #[arg(long, value_enum, default_value_t = Method::Golden)]
    method: Method,
    #[command(flatten)]
    skill: SkillArgs,
    /// Seed of exploration and of the scale's noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Roll-out budget (default 30 for error learning, 200 for PoWER).
    #[arg(long)]
    max_rollouts: Option<u32>,
    /// Error learning stops at |error| below this, l.
    #[arg(long, default_value_t = 0.002)]
    precision: f64,
    /// Output directory: run.log (every roll-out, appended as it is made),
    /// and at the end rollouts.csv, summary.json, convergence.png and
    /// series.csv (the best roll-out's time series).
    #[arg(long, default_value = "pour-out")]
    out: PathBuf,
    /// Continue the run logged in DIR (after a crash, a kill or a failed
    /// instrument): its settings come from the log, and no roll-out is
    /// lost or repeated.
    #[arg(long, value_name = "DIR", conflicts_with_all = [
        "bottle", "target", "method", "seed", "max_rollouts", "precision", "out",
        "space", "kernels", "glass", "demos",
    ])]
    resume: Option<PathBuf>,
    /// Run the learner on a coprocessor: a serial port (e.g.
    /// /dev/ttyACM0), or `qemu` to boot the firmware on an emulated
    /// Cortex-M4F (qemu-system-arm) for the run.
    #[arg(long, value_name = "PORT|qemu")]
    coprocessor: Option<String>,
    /// With --coprocessor qemu: the firmware ELF (default: the release
    /// build in firmware/).
    #[arg(long, requires = "coprocessor", value_name = "ELF")]
    firmware: Option<PathBuf>,
    /// Roll out on a real cell: the robot, `fri:ADDR[:PORT]`, the local
    /// UDP address the KRC sends its FRI packets to (default port 49938).
    #[arg(long, requires = "scale", value_name = "fri:ADDR[:PORT]")]
    robot: Option<String>,
    /// With --robot: the MT-SICS scale's serial port.
    #[arg(long, requires = "robot", value_name = "PORT")]
    scale: Option<String>,
    /// The scale's baud rate.
    #[arg(long, requires = "robot", default_value_t = 9600)]
    baud: u32,
    /// The liquid's density, g/ml (the scale weighs, the learner wants
    /// volumes).
    #[arg(long, requires = "robot", default_value_t = 0.998)]
    density: f64,
    /// With --robot: before every roll-out, ask the operator to refill the
    /// bottle and empty the glass, and wait for Enter.
    #[arg(long, requires = "robot")]
    confirm: bool,
}

#[derive(Debug, clap::Args)]
struct RolloutArgs {
    /// JSON array `[weights (dof×kernels, row by row), goals (dof), τ,
    /// q̂]`: θ is absolute; the movement executed is θ + G(q̂) − G(bottle).
    #[arg(long, conflicts_with_all = ["serve", "print_start"])]
    params: Option<PathBuf>,
    /// Answer JSON-array lines on stdin with one JSON line each.
    #[arg(long, conflicts_with = "print_start")]
    serve: bool,
    /// Print the generalized start vector and PoWER's exploration std.
    #[arg(long)]
    print_start: bool,
    /// With --params: write the roll-out's time series (every 2 ms control
    /// step) to this CSV file.
    #[arg(long, requires = "params", conflicts_with_all = ["serve", "print_start"], value_name = "FILE")]
    series: Option<PathBuf>,
    /// Liquid in the bottle, l.
    #[arg(long, default_value_t = 0.5)]
    bottle: f64,
    /// Volume to pour, l.
    #[arg(long, default_value_t = 0.2)]
    target: f64,
    #[command(flatten)]
    skill: SkillArgs,
    /// Seed of the scale's noise.
    #[arg(long, default_value_t = 1)]
    seed: u64,
}

#[derive(Debug, Subcommand)]
enum ExperimentCommand {
    /// Fig. 3: error learning (golden section and Illinois) per volume.
    Golden {
        /// Bottle volumes, l.
        #[arg(
            long,
            value_delimiter = ',',
            default_value = "0.3,0.4,0.5,0.6,0.7,0.8,0.9,1.0"
        )]
        volumes: Vec<f64>,
        /// Stop at |error| below this, l.
        #[arg(long, default_value_t = 0.002)]
        precision: f64,
        /// Seed of the scale's noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, default_value = "experiment-golden")]
        out: PathBuf,
    },
    /// Figs. 5–6: extended against ordinary PoWER in joint space.
    Power {
        /// Seeded runs per variant.
        #[arg(long, default_value_t = 20)]
        runs: usize,
        /// Kernels per joint (30 gives the paper's 219 parameters).
        #[arg(long, default_value_t = 30)]
        kernels: usize,
        /// Updates per run (4 roll-outs each).
        #[arg(long, default_value_t = 100)]
        updates: u32,
        /// The glass (the paper's second experiment: small).
        #[arg(long, value_enum, default_value_t = GlassKind::Small)]
        glass: GlassKind,
        /// Seed of the first run.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output directory.
        #[arg(long, default_value = "experiment-power")]
        out: PathBuf,
    },
}

#[derive(Debug, Subcommand)]
enum DmpCommand {
    /// Fit a DMP to a demonstration CSV (`t,<name>,...`).
    Fit {
        /// Demonstration CSV: header `t,<name>,...`, t in seconds, strictly increasing.
        #[arg(long)]
        demo: PathBuf,
        /// Kernels per DoF (2 to 128).
        #[arg(long, default_value_t = 30)]
        kernels: usize,
        /// Output JSON file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Run a fitted DMP and write the trajectory as CSV `t,<names>`.
    Run {
        /// DMP JSON written by `primo dmp fit`.
        dmp: PathBuf,
        /// Time step in seconds.
        #[arg(long, default_value_t = 0.001)]
        dt: f32,
        /// Execution time τ in seconds (default: the demonstrated duration).
        #[arg(long)]
        tau: Option<f32>,
        /// Start position, one value per DoF, comma-separated.
        #[arg(long, allow_hyphen_values = true)]
        start: Option<String>,
        /// Goal position, one value per DoF, comma-separated.
        #[arg(long, allow_hyphen_values = true)]
        goal: Option<String>,
        /// Output CSV file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// The most rows `primo dmp run` writes (10,000 s at 1 kHz).
pub const MAX_ROWS: usize = 10_000_000;

/// Runs `primo` with these arguments; returns the process exit status.
pub fn main_with(args: impl IntoIterator<Item = String>) -> i32 {
    let cli = match Cli::try_parse_from(args) {
        Ok(cli) => cli,
        Err(e) => {
            let _ = e.print();
            return e.exit_code();
        }
    };
    match run(cli) {
        Ok(()) => 0,
        Err(e) => {
            eprintln!("primo: {e}");
            e.status
        }
    }
}

fn run(cli: Cli) -> Result<(), CliError> {
    match cli.command {
        Command::Demo(DemoCommand::Synth {
            space,
            bottle,
            pour,
            elbow,
            seed,
            out,
        }) => synth(space, bottle, pour, elbow, seed, out.as_deref()),
        Command::Pour(args) => pour(&args),
        Command::Rollout(args) => rollout(&args),
        Command::Experiment(ExperimentCommand::Golden {
            volumes,
            precision,
            seed,
            out,
        }) => experiment_golden(&volumes, precision, seed, &out),
        Command::Experiment(ExperimentCommand::Power {
            runs,
            kernels,
            updates,
            glass,
            seed,
            out,
        }) => experiment_power(runs, kernels, updates, glass, seed, &out),
        Command::Scale(command) => crate::mtsics::commands::run(command),
        Command::Robot(command) => crate::fri::robot::run(command),
        Command::Dmp(DmpCommand::Fit { demo, kernels, out }) => fit(&demo, kernels, out.as_deref()),
        Command::Dmp(DmpCommand::Run {
            dmp,
            dt,
            tau,
            start,
            goal,
            out,
        }) => run_dmp(
            &dmp,
            dt,
            tau,
            start.as_deref(),
            goal.as_deref(),
            out.as_deref(),
        ),
    }
}

/// Prints `line` on stdout at once: another program may be waiting for it.
pub(crate) fn say(line: &str) -> Result<(), CliError> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}")
        .and_then(|()| out.flush())
        .map_err(|e| CliError::other(format!("stdout: {e}")))
}

fn read(path: &Path) -> Result<String, CliError> {
    std::fs::read_to_string(path)
        .map_err(|e| CliError::input(format!("{}: cannot read: {e}", path.display())))
}

/// Writes to `out` atomically, or to stdout.
fn emit(out: Option<&Path>, bytes: &[u8]) -> Result<(), CliError> {
    match out {
        Some(path) => write_atomically(path, bytes),
        None => std::io::stdout()
            .write_all(bytes)
            .map_err(|e| CliError::other(format!("stdout: {e}"))),
    }
}

fn fit(demo_path: &Path, kernels: usize, out: Option<&Path>) -> Result<(), CliError> {
    let file = demo_path.display().to_string();
    if !(2..=MAX_KERNELS).contains(&kernels) {
        return Err(CliError::input(format!(
            "--kernels: {kernels} is outside 2..={MAX_KERNELS}"
        )));
    }
    let demo = parse_demo(&file, &read(demo_path)?)?;
    if demo.names.len() > MAX_DOF {
        return Err(CliError::input(format!(
            "{file}:1: {} DoF columns, at most {MAX_DOF}",
            demo.names.len()
        )));
    }
    let dmp = HostDmp::fit(
        &demo.times,
        &demo.positions,
        demo.names.len(),
        kernels,
        &FitOptions::default(),
    )
    .map_err(|e| {
        CliError::input(format!(
            "{file}: cannot fit {kernels} kernels to {} rows: {e}",
            demo.times.len()
        ))
    })?;
    let json = DmpFile::new(demo.names, dmp).to_json()?;
    emit(out, format!("{json}\n").as_bytes())
}

/// Parses `a,b,...` with exactly one value per DoF.
pub(crate) fn parse_vector(flag: &str, text: &str, names: &[String]) -> Result<Vec<f32>, CliError> {
    let values: Vec<&str> = text.split(',').map(str::trim).collect();
    if values.len() != names.len() {
        return Err(CliError::input(format!(
            "{flag}: expected {} values (one per DoF: {}), found {}",
            names.len(),
            names.join(","),
            values.len()
        )));
    }
    values
        .iter()
        .enumerate()
        .map(|(i, v)| match v.parse::<f32>() {
            Ok(x) if x.is_finite() => Ok(x),
            _ => Err(CliError::input(format!(
                "{flag}: value {} (`{v}`) is not a finite number",
                i + 1
            ))),
        })
        .collect()
}

fn run_dmp(
    path: &Path,
    dt: f32,
    tau: Option<f32>,
    start: Option<&str>,
    goal: Option<&str>,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let file = path.display().to_string();
    let DmpFile { names, dmp, .. } = DmpFile::parse(&file, &read(path)?)?;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(CliError::input(format!(
            "--dt: {dt} must be a positive number of seconds"
        )));
    }
    let mut exec = dmp.execution();
    if let Some(tau) = tau {
        if !(tau.is_finite() && tau > 0.0) {
            return Err(CliError::input(format!(
                "--tau: {tau} must be a positive number of seconds"
            )));
        }
        exec.tau = tau;
    }
    if let Some(text) = start {
        exec.start = parse_vector("--start", text, &names)?.into_iter().collect();
    }
    if let Some(text) = goal {
        exec.goal = parse_vector("--goal", text, &names)?.into_iter().collect();
    }
    let rows = exec.tau / dt;
    if rows > MAX_ROWS as f32 {
        return Err(CliError::input(format!(
            "--dt {dt} with tau {} s would write {rows:.0} rows, at most {MAX_ROWS}",
            exec.tau
        )));
    }
    let trajectory = dmp
        .trajectory(&exec, dt)
        .map_err(|e| CliError::input(format!("{file}: {e}")))?;
    let dof = dmp.dof();
    let mut buf = Vec::new();
    let rows = trajectory.map(|s| (s.time, s.position));
    write_rows(
        &mut buf,
        &names,
        rows.map(|(t, p)| (t, p.into_iter().take(dof))),
    )
    .map_err(|e| CliError::other(format!("writing the trajectory: {e}")))?;
    emit(out, &buf)
}

fn synth(
    space: Space,
    bottle: f64,
    pour: f64,
    elbow: f64,
    seed: u64,
    out: Option<&Path>,
) -> Result<(), CliError> {
    let cell = CellConfig::standard(GlassKind::Normal);
    let demo = synthesize(&cell, bottle, pour, &Style { elbow, seed }).map_err(CliError::input)?;
    eprintln!(
        "primo: the expert poured {:.1} ml (spilled {:.1} ml) from {bottle} l in {:.2} s",
        demo.poured * 1e3,
        demo.spilled * 1e3,
        demo.t.last().copied().unwrap_or(0.0)
    );
    let csv = crate::pour::to_csv_demo(&demo, space);
    let mut buf = Vec::new();
    let dof = csv.names.len();
    write_rows(
        &mut buf,
        &csv.names,
        csv.times
            .iter()
            .zip(csv.positions.chunks_exact(dof))
            .map(|(t, row)| (*t, row.iter().copied())),
    )
    .map_err(|e| CliError::other(format!("writing the demonstration: {e}")))?;
    emit(out, &buf)
}

impl SkillArgs {
    /// The skill these options describe; `space` and `glass` fall back to
    /// the given defaults. Demonstration paths become absolute, so a run
    /// log names them from anywhere.
    fn spec(&self, space: Space, glass: GlassKind) -> Result<SkillSpec, CliError> {
        let mut demos = Vec::new();
        for arg in &self.demos {
            let (file, volume) = arg
                .rsplit_once('=')
                .ok_or_else(|| CliError::input(format!("--demo {arg}: expected FILE=VOLUME")))?;
            let volume: f32 = match volume.parse() {
                Ok(v) if f32::is_finite(v) => v,
                _ => {
                    return Err(CliError::input(format!(
                        "--demo {arg}: volume `{volume}` is not a number"
                    )));
                }
            };
            let file = std::path::absolute(file)
                .map_err(|e| CliError::input(format!("--demo {arg}: {e}")))?;
            demos.push(DemoFile { file, volume });
        }
        Ok(SkillSpec {
            space: self.space.unwrap_or(space),
            glass: self.glass.unwrap_or(glass),
            kernels: self.kernels,
            demos,
        })
    }

    /// The cell and skill these options describe (see [`SkillArgs::spec`]).
    fn build(&self, space: Space, glass: GlassKind) -> Result<(CellConfig, Skill), CliError> {
        self.spec(space, glass)?.build()
    }
}

fn pour(args: &PourArgs) -> Result<(), CliError> {
    let instruments = match (&args.robot, &args.scale) {
        (Some(robot), Some(scale)) => Some(InstrumentsSpec {
            robot: robot.clone(),
            scale: scale.clone(),
            baud: args.baud,
            density: args.density,
            confirm: args.confirm,
        }),
        _ => None,
    };
    let start = match &args.resume {
        Some(dir) => Start::Resume {
            dir: dir.clone(),
            instruments,
        },
        None => {
            let space = match args.method {
                Method::Power => Space::Joint,
                _ => Space::Cartesian,
            };
            let mut settings = Settings::paper(args.method, args.bottle, args.target, args.seed);
            settings.precision = args.precision;
            if let Some(n) = args.max_rollouts {
                settings.max_rollouts = n;
            }
            Start::New {
                out: args.out.clone(),
                settings,
                skill: args.skill.spec(space, GlassKind::Normal)?,
                cell: instruments.map_or(CellSpec::Simulated, CellSpec::Instruments),
            }
        }
    };
    let learner = LearnerSpec {
        coprocessor: args.coprocessor.clone(),
        firmware: args.firmware.clone(),
    };
    crate::run::pour(start, &learner)
}

/// Parses a roll-out vector: a JSON array of `len` finite numbers.
fn parse_params(what: &str, text: &str, len: usize) -> Result<Vec<f32>, String> {
    let values: Vec<f64> = serde_json::from_str(text)
        .map_err(|e| format!("{what}: not a JSON array of numbers: {e}"))?;
    if values.len() != len {
        return Err(format!(
            "{what}: {} values, the layout needs {len} (weights, goals, τ, q̂)",
            values.len()
        ));
    }
    values
        .iter()
        .enumerate()
        .map(|(i, v)| {
            let x = *v as f32;
            if x.is_finite() {
                Ok(x)
            } else {
                Err(format!("{what}: value {} is out of f32 range", i + 1))
            }
        })
        .collect()
}

/// One roll-out of the vector `x = [θ, q̂]`: Δθ = θ − G(bottle).
fn rollout_json(
    skill: &Skill,
    cell: &CellConfig,
    base: &[f32],
    args: &RolloutArgs,
    x: &[f32],
    seed: u64,
) -> Result<(serde_json::Value, crate::skill::Trial), String> {
    let (theta, query) = x.split_at(base.len());
    let query = query.first().copied().unwrap_or(args.bottle as f32);
    let delta: Vec<f32> = theta.iter().zip(base).map(|(t, b)| t - b).collect();
    let trial = skill.roll_out(cell, args.bottle, args.target, query, &delta, seed)?;
    let answer = serde_json::json!({
        "poured": trial.poured,
        "spilled": trial.spilled,
        "error": trial.error,
        "reward": trial.reward,
        "safe": trial.rejected.is_none(),
        "rejected": trial.rejected,
    });
    Ok((answer, trial))
}

fn rollout(args: &RolloutArgs) -> Result<(), CliError> {
    let (mut cell, skill) = args.skill.build(Space::Joint, GlassKind::Normal)?;
    cell.record_every = usize::from(args.series.is_some());
    let base = skill
        .generalize(args.bottle as f32)
        .map_err(CliError::input)?;
    let len = base.len() + 1;
    if args.print_start {
        let blocks = power_blocks(&skill, 0.2, 0.05).map_err(CliError::other)?;
        // Blocks are [q̂, weights, goals, τ]; the vector puts q̂ last.
        let mut std: Vec<f32> = blocks
            .iter()
            .flat_map(|b| std::iter::repeat_n(b.variance.sqrt(), b.len))
            .collect();
        std.rotate_left(1);
        let mut start = base.clone();
        start.push(args.bottle as f32);
        let out = serde_json::json!({
            "layout": "weights (dof x kernels, row by row), goals (dof), tau (s), query (l)",
            "space": skill.space(),
            "dof": skill.dof(),
            "kernels": skill.kernels(),
            "bottle": args.bottle,
            "start": start,
            "std": std,
        });
        println!("{out}");
        return Ok(());
    }
    if args.serve {
        use std::io::BufRead;
        let stdin = std::io::stdin();
        let mut stdout = std::io::stdout();
        for (i, line) in stdin.lock().lines().enumerate() {
            let line = line.map_err(|e| CliError::other(format!("stdin: {e}")))?;
            if line.trim().is_empty() {
                continue;
            }
            let what = format!("stdin line {}", i + 1);
            let answer = parse_params(&what, &line, len)
                .and_then(|x| {
                    rollout_json(
                        &skill,
                        &cell,
                        &base,
                        args,
                        &x,
                        args.seed.wrapping_add(i as u64),
                    )
                    .map(|(answer, _)| answer)
                })
                .unwrap_or_else(|e| serde_json::json!({ "error": e }));
            writeln!(stdout, "{answer}")
                .and_then(|()| stdout.flush())
                .map_err(|e| CliError::other(format!("stdout: {e}")))?;
        }
        return Ok(());
    }
    let path = args
        .params
        .as_deref()
        .ok_or_else(|| CliError::input("give --params FILE, --serve or --print-start"))?;
    let x =
        parse_params(&path.display().to_string(), &read(path)?, len).map_err(CliError::input)?;
    let (answer, trial) =
        rollout_json(&skill, &cell, &base, args, &x, args.seed).map_err(CliError::input)?;
    println!("{answer}");
    match &args.series {
        Some(file) => crate::series::write_csv(file, skill.space(), trial.series.as_ref()),
        None => Ok(()),
    }
}

fn experiment_golden(
    volumes: &[f64],
    precision: f64,
    seed: u64,
    out: &Path,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, Space::Cartesian, 30).map_err(CliError::other)?;
    let runs = crate::experiment::golden(&skill, &cell, volumes, precision, seed)
        .map_err(CliError::input)?;
    create_dir(out)?;
    crate::report::write_golden(out, &runs, precision)?;
    println!(
        "volume  golden  illinois   (roll-outs to |error| < {} ml)",
        precision * 1e3
    );
    for pair in runs.chunks(2) {
        let show = |r: &crate::experiment::SearchRun| {
            r.rollouts_to_precision
                .map_or("-".to_string(), |n| n.to_string())
        };
        if let [g, i] = pair {
            println!("{:>5.2} l {:>7} {:>9}", g.volume, show(g), show(i));
        }
    }
    let median = |m| crate::report::median_rollouts(&runs, m).unwrap_or(f64::NAN);
    println!(
        "median: golden {}, illinois {}; {:.1} s; wrote {}",
        median(Method::Golden),
        median(Method::Illinois),
        started.elapsed().as_secs_f64(),
        out.display()
    );
    Ok(())
}

fn experiment_power(
    runs: usize,
    kernels: usize,
    updates: u32,
    glass: GlassKind,
    seed: u64,
    out: &Path,
) -> Result<(), CliError> {
    let started = std::time::Instant::now();
    if runs == 0 || updates == 0 {
        return Err(CliError::input("--runs and --updates must be at least 1"));
    }
    let args = SkillArgs {
        space: Some(Space::Joint),
        kernels,
        glass: Some(glass),
        demos: Vec::new(),
    };
    let (cell, skill) = args.build(Space::Joint, glass)?;
    let [extended, ordinary] =
        crate::experiment::power(&skill, &cell, runs, updates, seed).map_err(CliError::input)?;
    let summary = PowerSummary {
        runs,
        updates,
        kernels,
        parameters: skill.param_len() + 1,
        glass,
        error_ratio: ordinary.error.last() / extended.error.last(),
        spill_ratio: ordinary.spilled.last() / extended.spilled.last(),
        extended: &extended,
        ordinary: &ordinary,
        seconds: started.elapsed().as_secs_f64(),
    };
    create_dir(out)?;
    crate::report::write_power(out, &summary)?;
    for (name, c) in [("extended", &extended), ("ordinary", &ordinary)] {
        println!(
            "{name:>8}: start |error| {:.1} ml spilled {:.1} ml -> final |error| {:.2} ± {:.2} ml, spilled {:.2} ± {:.2} ml, reward {:.3}; {:.0} % of roll-outs reward 0, {} rejected",
            c.error.mean.first().copied().unwrap_or(f64::NAN) * 1e3,
            c.spilled.mean.first().copied().unwrap_or(f64::NAN) * 1e3,
            c.error.last() * 1e3,
            c.error.std.last().copied().unwrap_or(f64::NAN) * 1e3,
            c.spilled.last() * 1e3,
            c.spilled.std.last().copied().unwrap_or(f64::NAN) * 1e3,
            c.reward.last(),
            100.0 * c.zero_reward as f64 / c.rollouts.max(1) as f64,
            c.rejected
        );
    }
    println!(
        "ordinary/extended: final error x{:.2}, final spill x{:.2}; {} parameters, {runs} runs x {updates} updates each; {:.1} s; wrote {}",
        summary.error_ratio,
        summary.spill_ratio,
        summary.parameters,
        summary.seconds,
        out.display()
    );
    Ok(())
}
