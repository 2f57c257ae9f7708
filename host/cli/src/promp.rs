//! `primo promp`: fit a ProMP to several demonstrations, run its mean
//! (conditioned on via-points, the goal) with its spread.

use std::path::{Path, PathBuf};

use primo_skill::csv::{parse_demo, write_rows};
use primo_skill::prompfile::{DEFAULT_RIDGE, MAX_KERNELS, PrompFile};
use primo_skill::shaping::Via;

use crate::dmp::{check_rows, parse_via};
use crate::error::CliError;
use crate::output::{check_out_file, emit, read};

/// `primo promp …`.
#[derive(Debug, clap::Subcommand)]
pub enum PrompCommand {
    /// Fit a probabilistic movement primitive (Paraschos et al. 2013) to
    /// two or more demonstration CSVs of the same columns: the weights'
    /// mean and covariance, each demonstration's duration its phase.
    Fit {
        /// A demonstration CSV (`t,<name>,...`); repeat for each (at least
        /// two).
        #[arg(long = "demo", required = true)]
        demos: Vec<PathBuf>,
        /// Kernels per column (2 to 40).
        #[arg(long, default_value_t = 20)]
        kernels: usize,
        /// Ridge on the weights' covariance, relative to its mean variance:
        /// what keeps it invertible with few demonstrations.
        #[arg(long, default_value_t = DEFAULT_RIDGE)]
        ridge: f64,
        /// Output JSON file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
    /// Write a fitted ProMP's mean movement as CSV `t,<names>` over the
    /// demonstrations' mean duration, conditioned on via-points first.
    Run {
        /// ProMP JSON written by `primo promp fit`.
        promp: PathBuf,
        /// Time step in seconds.
        #[arg(long, default_value_t = 0.001)]
        dt: f64,
        /// A via-point "T,COLUMN,VALUE": the column is at VALUE at T
        /// seconds (0 ≤ T ≤ the duration; T at the end is a new goal);
        /// repeat for more. The other columns and times move with their
        /// correlations to it.
        #[arg(
            long = "via",
            value_name = "T,COLUMN,VALUE",
            allow_hyphen_values = true
        )]
        vias: Vec<String>,
        /// How sure the via-points are, a variance in squared column units
        /// (0: passed exactly).
        #[arg(long, default_value_t = 0.0)]
        via_variance: f64,
        /// Also write each column's standard deviation, as `<name>_std`.
        #[arg(long)]
        std: bool,
        /// Output CSV file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Runs a `primo promp` command.
pub fn run(command: PrompCommand) -> Result<(), CliError> {
    match command {
        PrompCommand::Fit {
            demos,
            kernels,
            ridge,
            out,
        } => fit(&demos, kernels, ridge, out.as_deref()),
        PrompCommand::Run {
            promp,
            dt,
            vias,
            via_variance,
            std,
            out,
        } => {
            if !(dt.is_finite() && dt > 0.0) {
                return Err(CliError::input(format!(
                    "--dt: {dt} must be a positive number of seconds"
                )));
            }
            if !(via_variance.is_finite() && via_variance >= 0.0) {
                return Err(CliError::input(format!(
                    "--via-variance: {via_variance} must be a finite number >= 0"
                )));
            }
            let vias = vias
                .iter()
                .map(|v| parse_via(v))
                .collect::<Result<Vec<Via>, _>>()?;
            if let Some(out) = &out {
                check_out_file("--out", out, &[("PROMP", &promp)])?;
            }
            let file = promp.display().to_string();
            let mut fitted = PrompFile::parse(&file, &read(None, &promp)?)?;
            let duration = fitted.promp.duration();
            check_rows(dt as f32, duration as f32, "the ProMP's duration")?;
            for Via {
                time,
                column,
                value,
            } in vias
            {
                fitted
                    .condition(f64::from(time), &[(column.clone(), value)], via_variance)
                    .map_err(|e| CliError::input(format!("--via {time},{column},{value}: {e}")))?;
            }
            let mut names = fitted.names.clone();
            if std {
                names.extend(fitted.names.iter().map(|n| format!("{n}_std")));
            }
            let mut buf = Vec::new();
            write_rows(&mut buf, &names, fitted.run(dt, std).into_iter())
                .map_err(|e| CliError::other(format!("writing the trajectory: {e}")))?;
            emit(out.as_deref(), &buf)
        }
    }
}

fn fit(demos: &[PathBuf], kernels: usize, ridge: f64, out: Option<&Path>) -> Result<(), CliError> {
    if !(2..=MAX_KERNELS).contains(&kernels) {
        return Err(CliError::input(format!(
            "--kernels: {kernels} is outside 2..={MAX_KERNELS}"
        )));
    }
    if !(ridge.is_finite() && ridge >= 0.0) {
        return Err(CliError::input(format!(
            "--ridge: {ridge} must be a finite number >= 0"
        )));
    }
    if demos.len() < 2 {
        return Err(CliError::input(
            "--demo: a ProMP needs at least two demonstrations (give --demo for each)",
        ));
    }
    if let Some(out) = out {
        let inputs: Vec<(&str, &Path)> = demos.iter().map(|d| ("--demo", d.as_path())).collect();
        check_out_file("--out", out, &inputs)?;
    }
    let mut parsed = Vec::with_capacity(demos.len());
    for path in demos {
        let name = path.display().to_string();
        let demo = parse_demo(&name, &read(Some("--demo"), path)?)?;
        parsed.push((name, demo));
    }
    let refs: Vec<(&str, &_)> = parsed.iter().map(|(n, d)| (n.as_str(), d)).collect();
    let json = PrompFile::fit(&refs, kernels, ridge)?
        .to_json()
        .map_err(|e| CliError::other(format!("cannot serialize the ProMP: {e}")))?;
    emit(out, format!("{json}\n").as_bytes())
}
