//! `primo dmp`: fit a DMP to a demonstration, run a fitted DMP.

use std::path::{Path, PathBuf};

use primo_skill::MAX_KERNELS;
use primo_skill::csv::{parse_demo, write_rows};
use primo_skill::dmpfile::DmpFile;

use crate::error::CliError;
use crate::output::{check_out_file, emit, read};

/// `primo dmp …`.
#[derive(Debug, clap::Subcommand)]
pub enum DmpCommand {
    /// Fit a DMP to a demonstration CSV (`t,<name>,...`); four columns
    /// `<p>qw,<p>qx,<p>qy,<p>qz` are one orientation (a quaternion DMP).
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
        /// Start, one value per column, comma-separated (an orientation's
        /// four quaternion values included).
        #[arg(long, allow_hyphen_values = true)]
        start: Option<String>,
        /// Goal, one value per column, comma-separated (an orientation's
        /// four quaternion values included).
        #[arg(long, allow_hyphen_values = true)]
        goal: Option<String>,
        /// Output CSV file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// The most rows `primo dmp run` writes (10,000 s at 1 kHz).
pub const MAX_ROWS: usize = 10_000_000;

/// Runs a `primo dmp` command.
pub fn run(command: DmpCommand) -> Result<(), CliError> {
    match command {
        DmpCommand::Fit { demo, kernels, out } => fit(&demo, kernels, out.as_deref()),
        DmpCommand::Run {
            dmp,
            dt,
            tau,
            start,
            goal,
            out,
        } => run_dmp(
            &dmp,
            dt,
            tau,
            start.as_deref(),
            goal.as_deref(),
            out.as_deref(),
        ),
    }
}

fn fit(demo_path: &Path, kernels: usize, out: Option<&Path>) -> Result<(), CliError> {
    let file = demo_path.display().to_string();
    if !(2..=MAX_KERNELS).contains(&kernels) {
        return Err(CliError::input(format!(
            "--kernels: {kernels} is outside 2..={MAX_KERNELS}"
        )));
    }
    if let Some(out) = out {
        check_out_file("--out", out)?;
    }
    let demo = parse_demo(&file, &read(demo_path)?)?;
    let json = DmpFile::fit(&file, &demo, kernels)?
        .to_json()
        .map_err(|e| CliError::other(format!("cannot serialize the DMP: {e}")))?;
    emit(out, format!("{json}\n").as_bytes())
}

/// Parses `a,b,...` with exactly one value per DoF.
pub fn parse_vector(flag: &str, text: &str, names: &[String]) -> Result<Vec<f32>, CliError> {
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
    let dmp = DmpFile::parse(&file, &read(path)?)?;
    if !(dt.is_finite() && dt > 0.0) {
        return Err(CliError::input(format!(
            "--dt: {dt} must be a positive number of seconds"
        )));
    }
    if let Some(out) = out {
        check_out_file("--out", out)?;
    }
    if let Some(tau) = tau
        && !(tau.is_finite() && tau > 0.0)
    {
        return Err(CliError::input(format!(
            "--tau: {tau} must be a positive number of seconds"
        )));
    }
    let start = start
        .map(|text| parse_vector("--start", text, &dmp.names))
        .transpose()?;
    let goal = goal
        .map(|text| parse_vector("--goal", text, &dmp.names))
        .transpose()?;
    let duration = tau.unwrap_or(dmp.dmp.tau());
    let rows = duration / dt;
    if rows > MAX_ROWS as f32 {
        return Err(CliError::input(format!(
            "--dt {dt} with tau {duration} s would write {rows:.0} rows, at most {MAX_ROWS}"
        )));
    }
    let trajectory = dmp
        .run(dt, tau, start.as_deref(), goal.as_deref())
        .map_err(|e| CliError::input(format!("{file}: {e}")))?;
    let mut buf = Vec::new();
    write_rows(&mut buf, &dmp.names, trajectory)
        .map_err(|e| CliError::other(format!("writing the trajectory: {e}")))?;
    emit(out, &buf)
}
