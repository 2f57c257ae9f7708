//! `primo dmp`: fit a DMP to a demonstration, run a fitted DMP.

use std::path::{Path, PathBuf};

use primo_core::coupling::Sphere;
use primo_core::dmp::{FinalVelocity, FitOptions, Margin, max_margin};
use primo_skill::MAX_KERNELS;
use primo_skill::coupled::{
    Avoidance, Coupled, DEFAULT_LIMIT_GAIN, MAX_OBSTACLES, OVERTIME, Repulsion,
};
use primo_skill::csv::{parse_demo, write_rows};
use primo_skill::dmpfile::{
    self, AmplitudeScaling, Change, DmpFile, Fitted, MAX_ROWS, RhythmicFile,
};
use primo_skill::shaping::{Shaping, Via};

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
        /// Fit a rhythmic (periodic) DMP to one period of the demonstration.
        #[arg(long)]
        rhythmic: bool,
        /// With --rhythmic: the period, s, from the first sample (default:
        /// the whole demonstration is one period).
        #[arg(long, requires = "rhythmic")]
        period: Option<f32>,
        /// Kernel spacings the outer kernels lie beyond the movement's ends
        /// (0: on them), or `auto`: whichever of 0 and 1 reproduces the
        /// demonstration better. DMPs to be generalized together need the
        /// same margin.
        #[arg(
            long,
            default_value = "auto",
            conflicts_with = "rhythmic",
            allow_hyphen_values = true
        )]
        margin: String,
        /// How the forcing term scales to a new start and goal: `per-dof`
        /// (each column by its own (g − y0)/(g_d − y0_d)), `none` (the
        /// shape as demonstrated) or `global` (the position columns turned
        /// and stretched together, Koutras & Doulgeri 2020).
        #[arg(
            long,
            default_value = "per-dof",
            value_parser = AmplitudeScaling::NAMES,
            conflicts_with = "rhythmic"
        )]
        scaling: String,
        /// The velocity at the goal: `rest` (the classic DMP, default) or
        /// `demonstrated` (the recording's speed at its end, for a hit or a
        /// throw: the goal moves at it until τ; `dmp run --goal-velocity`
        /// changes it).
        #[arg(long, default_value = "rest", value_parser = ["rest", "demonstrated"],
              conflicts_with = "rhythmic")]
        final_velocity: String,
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
        /// A rhythmic DMP: how long to run, s (default: 3 periods).
        #[arg(long, conflicts_with_all = ["tau", "start", "goal"])]
        duration: Option<f32>,
        /// A rhythmic DMP: the frequency, Hz (default: the demonstrated).
        #[arg(long, conflicts_with_all = ["tau", "start", "goal"])]
        frequency: Option<f32>,
        /// A rhythmic DMP: amplitudes relative to the demonstrated, one per
        /// column, comma-separated.
        #[arg(long, conflicts_with_all = ["tau", "start", "goal"])]
        amplitude: Option<String>,
        /// A rhythmic DMP: the oscillation's centre, one value per column.
        #[arg(long, allow_hyphen_values = true, conflicts_with_all = ["tau", "start", "goal"])]
        anchor: Option<String>,
        /// A rhythmic DMP: a change during the run, "T frequency=F
        /// amplitude=A,… anchor=C,…" (any of the three, from T seconds on;
        /// repeat for more). The run keeps its phase through a new
        /// frequency and glides onto a new amplitude or anchor.
        #[arg(long = "change", value_name = "T KEY=VALUE ...", allow_hyphen_values = true,
              conflicts_with_all = ["tau", "start", "goal"])]
        changes: Vec<String>,
        /// The velocity at the goal, one value per column, per second: the
        /// run reaches its goal at τ moving so (a DMP fitted with
        /// `--final-velocity demonstrated` has its recording's).
        #[arg(long, allow_hyphen_values = true,
              conflicts_with_all = ["duration", "frequency", "amplitude", "anchor", "changes"])]
        goal_velocity: Option<String>,
        /// A via-point "T,COLUMN,VALUE": the column passes VALUE at T
        /// seconds (0 < T < τ); repeat for more (up to 8). The DMP's
        /// weights change least to pass them, without a refit.
        #[arg(long = "via", value_name = "T,COLUMN,VALUE", allow_hyphen_values = true,
              conflicts_with_all = ["duration", "frequency", "amplitude", "anchor", "changes"])]
        vias: Vec<String>,
        /// A sphere to steer round, "X,Y,Z,R" in the units of the position
        /// columns (R ≥ 0; 0 is a point); repeat for more (up to 16). The
        /// run then goes on past τ until it reaches its goal (at most 3τ
        /// in all).
        #[arg(long = "obstacle", value_name = "X,Y,Z,R", allow_hyphen_values = true,
              conflicts_with_all = ["duration", "frequency", "amplitude", "anchor", "changes"])]
        obstacles: Vec<String>,
        /// The three position columns the obstacles are in.
        #[arg(
            long,
            value_name = "X,Y,Z",
            default_value = "x,y,z",
            requires = "obstacles"
        )]
        obstacle_columns: String,
        /// A column's limits "COLUMN,LOW,HIGH" (`-inf`, `inf`: none that
        /// side), to keep away from: within --limit-margin of a limit the
        /// run is pushed back; repeat for more columns. The run then goes
        /// on past τ until it reaches its goal (at most 3τ in all).
        #[arg(long = "limit", value_name = "COLUMN,LOW,HIGH", allow_hyphen_values = true,
              requires = "limit_margin",
              conflicts_with_all = ["duration", "frequency", "amplitude", "anchor", "changes"])]
        limits: Vec<String>,
        /// How near a limit the push starts, in the column's units (at most
        /// half of any limited range; the goal must lie outside it).
        #[arg(
            long,
            value_name = "M",
            allow_hyphen_values = true,
            requires = "limits"
        )]
        limit_margin: Option<f32>,
        /// The push at half the margin, units/s².
        #[arg(long, value_name = "G", default_value_t = DEFAULT_LIMIT_GAIN,
              allow_hyphen_values = true, requires = "limits")]
        limit_gain: f32,
        /// Output CSV file (stdout when absent).
        #[arg(long)]
        out: Option<PathBuf>,
    },
}

/// Runs a `primo dmp` command.
pub fn run(command: DmpCommand) -> Result<(), CliError> {
    match command {
        DmpCommand::Fit {
            demo,
            kernels,
            rhythmic,
            period,
            margin,
            scaling,
            final_velocity,
            out,
        } => fit(
            &demo,
            kernels,
            rhythmic.then_some(period),
            (&margin, &scaling, &final_velocity),
            out.as_deref(),
        ),
        DmpCommand::Run {
            dmp,
            dt,
            tau,
            start,
            goal,
            duration,
            frequency,
            amplitude,
            anchor,
            changes,
            goal_velocity,
            vias,
            obstacles,
            obstacle_columns,
            limits,
            limit_margin,
            limit_gain,
            out,
        } => {
            let file = dmp.display().to_string();
            if !(dt.is_finite() && dt > 0.0) {
                return Err(CliError::input(format!(
                    "--dt: {dt} must be a positive number of seconds"
                )));
            }
            if let Some(out) = &out {
                check_out_file("--out", out, &[("DMP", &dmp)])?;
            }
            let rows = match dmpfile::parse(&file, &read(None, &dmp)?)? {
                Fitted::Discrete(dmp) => {
                    if duration.is_some()
                        || frequency.is_some()
                        || amplitude.is_some()
                        || anchor.is_some()
                        || !changes.is_empty()
                    {
                        return Err(CliError::input(format!(
                            "--duration, --frequency, --amplitude, --anchor, --change: {file} is \
                             not a rhythmic DMP"
                        )));
                    }
                    let shape = Shaping {
                        goal_velocity: goal_velocity
                            .map(|text| parse_vector("--goal-velocity", &text, &dmp.names))
                            .transpose()?,
                        vias: vias
                            .iter()
                            .map(|v| parse_via(v))
                            .collect::<Result<_, _>>()?,
                        coupled: Coupled {
                            avoid: avoidance(&obstacles, &obstacle_columns)?,
                            repel: repulsion(&limits, limit_margin, limit_gain)?,
                        },
                    };
                    let ends = (start.as_deref(), goal.as_deref());
                    run_discrete(&file, &dmp, dt, tau, ends, &shape)?
                }
                Fitted::Rhythmic(dmp) => {
                    let from_start = Change {
                        at: 0.0,
                        frequency,
                        amplitude: amplitude
                            .map(|text| parse_vector("--amplitude", &text, &dmp.names))
                            .transpose()?,
                        anchor: anchor
                            .map(|text| parse_vector("--anchor", &text, &dmp.names))
                            .transpose()?,
                    };
                    let mut all = vec![from_start];
                    for text in &changes {
                        all.push(parse_change(text, &dmp.names)?);
                    }
                    run_rhythmic(&file, &dmp, dt, duration, &all)?
                }
            };
            emit(out.as_deref(), &rows)
        }
    }
}

fn fit(
    demo_path: &Path,
    kernels: usize,
    rhythmic: Option<Option<f32>>,
    (margin, scaling, final_velocity): (&str, &str, &str),
    out: Option<&Path>,
) -> Result<(), CliError> {
    // Clap kept to the names.
    let scaling = AmplitudeScaling::parse(scaling).unwrap_or_default();
    let final_velocity = match final_velocity {
        "demonstrated" => FinalVelocity::Demonstrated,
        _ => FinalVelocity::AtRest,
    };
    let file = demo_path.display().to_string();
    // A periodic DMP needs a kernel more than a discrete one.
    let fewest = if rhythmic.is_some() { 3 } else { 2 };
    if !(fewest..=MAX_KERNELS).contains(&kernels) {
        let what = if rhythmic.is_some() {
            " for a rhythmic DMP"
        } else {
            ""
        };
        return Err(CliError::input(format!(
            "--kernels: {kernels} is outside {fewest}..={MAX_KERNELS}{what}"
        )));
    }
    let margin = parse_margin(margin, kernels)?;
    if let Some(Some(period)) = rhythmic
        && !(period.is_finite() && period > 0.0)
    {
        return Err(CliError::input(format!(
            "--period: {period} must be a positive number of seconds"
        )));
    }
    if let Some(out) = out {
        check_out_file("--out", out, &[("--demo", demo_path)])?;
    }
    let demo = parse_demo(&file, &read(Some("--demo"), demo_path)?)?;
    let json = match rhythmic {
        None => {
            let options = FitOptions {
                margin,
                final_velocity,
                ..FitOptions::default()
            };
            DmpFile::fit_with(&file, &demo, kernels, (scaling, None), &options)?.to_json()
        }
        Some(period) => RhythmicFile::fit(&file, &demo, kernels, period)?.to_json(),
    }
    .map_err(|e| CliError::other(format!("cannot serialize the DMP: {e}")))?;
    emit(out, format!("{json}\n").as_bytes())
}

/// `--margin`: `auto`, or a number of kernel spacings that leaves at least
/// one spacing between the movement's ends.
fn parse_margin(text: &str, kernels: usize) -> Result<Margin, CliError> {
    if text == "auto" {
        return Ok(Margin::Auto);
    }
    let most = max_margin(kernels);
    match text.parse::<f32>() {
        Ok(m) if (0.0..=most).contains(&m) => Ok(Margin::Spacings(m)),
        _ => Err(CliError::input(format!(
            "--margin: `{text}` is neither `auto` nor a number of kernel spacings from 0 to \
             {most} (with --kernels {kernels}, one spacing must stay between the ends)"
        ))),
    }
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

/// `--obstacle X,Y,Z,R ...` and `--obstacle-columns`: none when no
/// obstacle is given.
fn avoidance(obstacles: &[String], columns: &str) -> Result<Option<Avoidance>, CliError> {
    if obstacles.is_empty() {
        return Ok(None);
    }
    let mut spheres = Vec::new();
    for text in obstacles {
        let bad = |why: &str| CliError::input(format!("--obstacle {text}: {why}"));
        let values: Vec<f32> = text
            .split(',')
            .map(|v| v.trim().parse::<f32>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad("expected four numbers X,Y,Z,R"))?;
        match values[..] {
            [x, y, z, r] if values.iter().all(|v| v.is_finite()) && r >= 0.0 => {
                spheres.push(Sphere {
                    center: [x, y, z],
                    radius: r,
                });
            }
            [_, _, _, r] if r < 0.0 => return Err(bad("the radius R must be >= 0")),
            _ => return Err(bad("expected four finite numbers X,Y,Z,R")),
        }
    }
    if spheres.len() > MAX_OBSTACLES {
        return Err(CliError::input(format!(
            "--obstacle: {} given, at most {MAX_OBSTACLES}",
            spheres.len()
        )));
    }
    let names: Vec<String> = columns.split(',').map(|n| n.trim().to_string()).collect();
    let columns: [String; 3] = names.try_into().map_err(|names: Vec<String>| {
        CliError::input(format!(
            "--obstacle-columns {columns}: expected three column names, found {}",
            names.len()
        ))
    })?;
    Ok(Some(Avoidance { spheres, columns }))
}

/// `--limit COLUMN,LOW,HIGH`s with their margin and gain.
fn repulsion(
    limits: &[String],
    margin: Option<f32>,
    gain: f32,
) -> Result<Option<Repulsion>, CliError> {
    let Some(margin) = margin else {
        return Ok(None);
    };
    if !(margin.is_finite() && margin > 0.0) {
        return Err(CliError::input(format!(
            "--limit-margin {margin}: must be a positive number"
        )));
    }
    if !(gain.is_finite() && gain > 0.0) {
        return Err(CliError::input(format!(
            "--limit-gain {gain}: must be a positive number"
        )));
    }
    let mut parsed: Vec<(String, f32, f32)> = Vec::new();
    for text in limits {
        let bad = |why: &str| CliError::input(format!("--limit {text}: {why}"));
        let parts: Vec<&str> = text.split(',').map(str::trim).collect();
        let [column, low, high] = parts[..] else {
            return Err(bad("expected COLUMN,LOW,HIGH"));
        };
        let (Ok(low), Ok(high)) = (low.parse::<f32>(), high.parse::<f32>()) else {
            return Err(bad("LOW and HIGH must be numbers (-inf, inf: none)"));
        };
        if column.is_empty() || low.is_nan() || high.is_nan() || low >= high {
            return Err(bad("expected a column and LOW < HIGH"));
        }
        if parsed.iter().any(|(c, ..)| c == column) {
            return Err(bad("the column's limits are given twice"));
        }
        parsed.push((column.to_string(), low, high));
    }
    Ok(Some(Repulsion {
        limits: parsed,
        margin,
        gain,
    }))
}

/// `--via T,COLUMN,VALUE`.
pub(crate) fn parse_via(text: &str) -> Result<Via, CliError> {
    let bad = || {
        CliError::input(format!(
            "--via {text}: expected T,COLUMN,VALUE (seconds, a column's name, a number)"
        ))
    };
    let mut parts = text.split(',').map(str::trim);
    let (Some(time), Some(column), Some(value), None) =
        (parts.next(), parts.next(), parts.next(), parts.next())
    else {
        return Err(bad());
    };
    match (time.parse::<f32>(), value.parse::<f32>()) {
        (Ok(time), Ok(value)) if time.is_finite() && value.is_finite() && !column.is_empty() => {
            Ok(Via {
                time,
                column: column.to_string(),
                value,
            })
        }
        _ => Err(bad()),
    }
}

/// The rows of a discrete DMP's run, as CSV: with the velocity at the
/// goal, through the via-points and round the obstacles `shape` gives.
fn run_discrete(
    file: &str,
    dmp: &DmpFile,
    dt: f32,
    tau: Option<f32>,
    (start, goal): (Option<&str>, Option<&str>),
    shape: &Shaping,
) -> Result<Vec<u8>, CliError> {
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
    match shape.coupled.is_none() {
        true => check_rows(dt, duration, "tau")?,
        false => check_rows(
            dt,
            duration * (1.0 + OVERTIME),
            "tau (3τ with obstacles or limits)",
        )?,
    }
    let movement = |e| CliError::input(format!("{file}: {e}"));
    let prepared = dmp
        .prepare(tau, start.as_deref(), goal.as_deref())
        .map_err(movement)?;
    let mut buf = trajectory_buffer(dt, duration, dmp.names.len());
    let written = match shape.is_plain() {
        // Streamed: the common case keeps no rows.
        true => write_rows(
            &mut buf,
            &dmp.names,
            dmp.run_prepared(&prepared, dt).map_err(movement)?,
        ),
        false => {
            let rows = dmp.run_shaped(prepared, dt, shape).map_err(movement)?;
            write_rows(&mut buf, &dmp.names, rows.into_iter())
        }
    };
    written.map_err(|e| CliError::other(format!("writing the trajectory: {e}")))?;
    Ok(buf)
}

/// One `--change "T KEY=VALUE …"`.
fn parse_change(text: &str, names: &[String]) -> Result<Change, CliError> {
    let bad = |why: String| CliError::input(format!("--change \"{text}\": {why}"));
    let mut words = text.split_whitespace();
    let at = match words.next().map(str::parse::<f32>) {
        Some(Ok(t)) if t.is_finite() && t >= 0.0 => t,
        _ => return Err(bad("must start with a time in seconds >= 0".into())),
    };
    let mut change = Change {
        at,
        ..Change::default()
    };
    for word in words {
        let flag = format!(
            "--change at {at} s: {}",
            word.split('=').next().unwrap_or("")
        );
        match word.split_once('=') {
            Some(("frequency", v)) => match v.parse::<f32>() {
                Ok(hz) if hz.is_finite() => change.frequency = Some(hz),
                _ => return Err(bad(format!("frequency `{v}` is not a number of Hz"))),
            },
            Some(("amplitude", v)) => change.amplitude = Some(parse_vector(&flag, v, names)?),
            Some(("anchor", v)) => change.anchor = Some(parse_vector(&flag, v, names)?),
            _ => {
                return Err(bad(format!(
                    "`{word}`: expected frequency=F, amplitude=A,… or anchor=C,…"
                )));
            }
        }
    }
    if change
        == (Change {
            at,
            ..Change::default()
        })
    {
        return Err(bad(
            "changes nothing: give frequency=, amplitude= or anchor=".into(),
        ));
    }
    Ok(change)
}

/// The rows of a rhythmic DMP's run, as CSV.
fn run_rhythmic(
    file: &str,
    dmp: &RhythmicFile,
    dt: f32,
    duration: Option<f32>,
    changes: &[Change],
) -> Result<Vec<u8>, CliError> {
    let duration = duration.unwrap_or(3.0 * dmp.rhythmic.period());
    if !(duration.is_finite() && duration >= 0.0) {
        return Err(CliError::input(format!(
            "--duration: {duration} must be a number of seconds >= 0"
        )));
    }
    check_rows(dt, duration, "duration")?;
    let rows = dmp
        .run(dt, duration, changes)
        .map_err(|e| CliError::input(format!("{file}: {e}")))?;
    let mut buf = trajectory_buffer(dt, duration, dmp.names.len());
    write_rows(&mut buf, &dmp.names, rows)
        .map_err(|e| CliError::other(format!("writing the trajectory: {e}")))?;
    Ok(buf)
}

/// Room for the CSV of `duration` s at steps of `dt` (checked by
/// [`check_rows`]) over `columns` columns, so that it is not copied as it
/// grows: the replay of a long movement spends a tenth of its time so.
fn trajectory_buffer(dt: f32, duration: f32, columns: usize) -> Vec<u8> {
    // About 12 bytes a value with its comma, as trajectories' values print
    // (a longer one only makes the buffer grow once more).
    let rows = (duration / dt) as usize + 2;
    Vec::with_capacity(rows.saturating_mul(columns + 1).saturating_mul(12))
}

/// At most [`MAX_ROWS`] rows.
pub(crate) fn check_rows(dt: f32, duration: f32, flag: &str) -> Result<(), CliError> {
    let rows = duration / dt;
    if rows > MAX_ROWS as f32 {
        return Err(CliError::input(format!(
            "--dt {dt} with {flag} {duration} s would write {rows:.0} rows, at most {MAX_ROWS}"
        )));
    }
    Ok(())
}
