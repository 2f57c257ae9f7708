//! `primo robot check`: does a trajectory keep to a robot's limits? Any
//! serial arm from its URDF (or the built-in LWR 4), a joint trajectory by
//! the joints' names or a tool trajectory of poses; the first violation is
//! the answer.

use std::path::PathBuf;

use primo_robot::columns::Columns;
use primo_robot::ik::IkOptions;
use primo_robot::tool_path::check_tool_path;
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
    let file = args.trajectory.display().to_string();
    let demo = parse_demo(&file, &read(None, &args.trajectory)?)?;
    let times: Vec<f64> = demo.times.iter().map(|t| f64::from(*t)).collect();
    let rows: Vec<f64> = demo.positions.iter().map(|v| f64::from(*v)).collect();
    let robot = describe(&chain);
    let columns =
        Columns::of(&chain, &demo.names).map_err(|e| CliError::input(format!("{file}: {e}")))?;
    let ordered = columns.reorder(&rows);
    let checked = match columns {
        Columns::Joints(_) => chain
            .check_path(&times, &ordered, args.max_acceleration)
            .map_err(|v| v.to_string()),
        Columns::Pose(_) => {
            let poses: Vec<[f64; 7]> = ordered
                .chunks_exact(7)
                .map(|p| std::array::from_fn(|k| p[k]))
                .collect();
            check_tool_path(
                &chain,
                &times,
                &poses,
                None,
                args.max_acceleration,
                &IkOptions::default(),
            )
            .map(drop)
            .map_err(|e| e.to_string())
        }
    };
    let duration = times.last().zip(times.first()).map_or(0.0, |(b, a)| b - a);
    match checked {
        Ok(()) => say(&format!(
            "primo robot check: {file} passes: {} samples over {duration:.3} s within the limits \
             of {robot}",
            times.len()
        )),
        Err(why) => {
            say(&format!("primo robot check: {file} fails: {why}"))?;
            Err(CliError::other(format!(
                "robot check: {file} does not keep to the limits of {robot}"
            )))
        }
    }
}
