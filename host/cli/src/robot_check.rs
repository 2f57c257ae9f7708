//! `primo robot check`: does a trajectory keep to a robot's limits? Any
//! serial arm from its URDF (or the built-in LWR 4), a joint trajectory by
//! the joints' names or a tool trajectory of poses; the first violation is
//! the answer.

use std::path::PathBuf;

use primo_robot::envelope::{Limits, RobotLimits};
use primo_skill::csv::parse_demo;

use crate::error::CliError;
use crate::model::{ModelArgs, describe};
use crate::output::{read, say};

/// `primo robot check` options.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Trajectory CSV: header `t` then every joint of the chain by name
    /// (any order; rad or m), or `x,y,z,qw,qx,qy,qz` (the tool frame's
    /// pose in the base frame, m and a unit quaternion).
    trajectory: PathBuf,
    #[command(flatten)]
    model: ModelArgs,
    /// Also bound every joint's acceleration (finite differences), rad/s²
    /// or m/s².
    #[arg(long, value_name = "A")]
    max_acceleration: Option<f64>,
    /// For a tool trajectory: the robot's posture when it starts, every
    /// joint by name (rad or m). Its first pose is solved from there, so
    /// to the robot's own elbow (default: from the middle of the joints'
    /// ranges).
    #[arg(long, value_name = "JOINT=Q,...", value_delimiter = ',', value_parser = joint_position)]
    start: Vec<(String, f64)>,
}

/// `JOINT=Q`.
fn joint_position(arg: &str) -> Result<(String, f64), String> {
    let (joint, value) = arg
        .split_once('=')
        .ok_or_else(|| format!("`{arg}`: give JOINT=POSITION"))?;
    let value: f64 = (value.trim().parse().ok())
        .filter(|v: &f64| v.is_finite())
        .ok_or_else(|| format!("`{arg}`: the position `{value}` is not a number"))?;
    Ok((joint.trim().to_string(), value))
}

/// Runs `primo robot check`: exit 0 when the trajectory passes, 1 when it
/// does not (the violation on stdout), 2 for input that cannot be checked.
pub fn run(args: &CheckArgs) -> Result<(), CliError> {
    if let Some(a) = args.max_acceleration
        && !(a.is_finite() && a > 0.0)
    {
        return Err(CliError::input(format!(
            "--max-acceleration {a}: must be a positive number"
        )));
    }
    let chain = args.model.chain()?;
    let start = match args.start.as_slice() {
        [] => None,
        named => {
            let named = named.iter().map(|(joint, v)| (joint.as_str(), *v));
            let q = chain.posture(named);
            Some(q.map_err(|e| CliError::input(format!("--start: {e}")))?)
        }
    };
    let file = args.trajectory.display().to_string();
    let demo = parse_demo(&file, &read(None, &args.trajectory)?)?;
    let times: Vec<f64> = demo.times.iter().map(|t| f64::from(*t)).collect();
    let rows: Vec<f64> = demo.positions.iter().map(|v| f64::from(*v)).collect();
    let robot = describe(&chain);
    let duration = times.last().zip(times.first()).map_or(0.0, |(b, a)| b - a);
    let samples = times.len();
    let limits = Limits::Robot(RobotLimits {
        chain,
        max_acceleration: args.max_acceleration,
        start,
    });
    // Columns that are no trajectory of this robot are bad input, not a
    // failed check.
    (limits.covers(&demo.names)).map_err(|e| CliError::input(format!("{file}: {e}")))?;
    let checked = limits
        .check(&demo.names, times, &rows)
        .map(drop)
        .map_err(|e| e.to_string());
    match checked {
        Ok(()) => say(&format!(
            "primo robot check: {file} passes: {samples} samples over {duration:.3} s within the limits \
             of {robot}"
        )),
        Err(why) => {
            say(&format!("primo robot check: {file} fails: {why}"))?;
            Err(CliError::other(format!(
                "robot check: {file} does not keep to the limits of {robot}"
            )))
        }
    }
}
