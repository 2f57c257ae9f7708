//! `primo robot check`: does a trajectory keep to a robot's limits? Any
//! serial arm from its URDF (or the built-in LWR 4), a joint trajectory by
//! the joints' names or a tool trajectory of poses; the first violation is
//! the answer.

use std::path::PathBuf;

use primo_robot::chain::Chain;
use primo_robot::envelope::joint_index;
use primo_robot::ik::IkOptions;
use primo_robot::tool_path::check_tool_path;
use primo_robot::urdf::Urdf;
use primo_robot::{POSE_COLUMNS, Robot, Tip};
use primo_skill::csv::parse_demo;

use crate::error::CliError;
use crate::output::{read, say};

/// `primo robot check` options.
#[derive(Debug, clap::Args)]
pub struct CheckArgs {
    /// Trajectory CSV: header `t` then every joint of the chain by name
    /// (any order; rad or m), or `x,y,z,qw,qx,qy,qz` (the tool frame's
    /// pose in the base frame, m and a unit quaternion).
    trajectory: PathBuf,
    /// The robot's URDF (default: the built-in KUKA LWR 4, joints
    /// `a1..a7`, also `A1..A7`, `j1..j7`, `joint_1..joint_7`).
    #[arg(long, value_name = "ROBOT.urdf")]
    model: Option<PathBuf>,
    /// The chain's base link (default: the URDF's root link).
    #[arg(long, value_name = "LINK", requires = "model")]
    base: Option<String>,
    /// The chain's tip link (default: the one leaf below the base).
    #[arg(long, value_name = "LINK", requires = "model")]
    tip: Option<String>,
    /// Also bound every joint's acceleration (finite differences), rad/s²
    /// or m/s².
    #[arg(long, value_name = "A")]
    max_acceleration: Option<f64>,
}

/// How the trajectory's columns map onto the chain.
enum Columns {
    /// Column `c` is joint `joints[c]`.
    Joints(Vec<usize>),
    /// Column `c` is pose coordinate `coordinates[c]` of [`POSE_COLUMNS`].
    Pose(Vec<usize>),
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
    let (chain, builtin) = match &args.model {
        Some(path) => {
            let file = path.display().to_string();
            let urdf = Urdf::parse(&file, &read(Some("--model"), path)?)
                .map_err(|e| CliError::input(e.to_string()))?;
            let tip = Tip {
                base: args.base.clone(),
                tip: args.tip.clone(),
                ..Tip::default()
            };
            let chain =
                Chain::from_urdf(&urdf, &tip).map_err(|e| CliError::input(e.to_string()))?;
            (chain, false)
        }
        None => (Robot::lwr4().chain(), true),
    };
    let file = args.trajectory.display().to_string();
    let demo = parse_demo(&file, &read(None, &args.trajectory)?)?;
    let times: Vec<f64> = demo.times.iter().map(|t| f64::from(*t)).collect();
    let rows = demo.positions.chunks_exact(demo.names.len());
    let robot = describe(&chain);
    let checked = match columns(&file, &demo.names, &chain, builtin)? {
        Columns::Joints(joints) => {
            let mut positions = vec![0.0; times.len() * chain.dof()];
            for (row, values) in positions.chunks_exact_mut(chain.dof()).zip(rows) {
                for (&joint, &v) in joints.iter().zip(values) {
                    row[joint] = f64::from(v);
                }
            }
            chain
                .check_path(&times, &positions, args.max_acceleration)
                .map_err(|v| v.to_string())
        }
        Columns::Pose(coordinates) => {
            let poses: Vec<[f64; 7]> = rows
                .map(|values| {
                    let mut pose = [0.0; 7];
                    for (&k, &v) in coordinates.iter().zip(values) {
                        pose[k] = f64::from(v);
                    }
                    pose
                })
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

/// `NAME (J joints, BASE to TIP)`.
fn describe(chain: &Chain) -> String {
    format!(
        "{} ({} joints, {} to {})",
        chain.robot,
        chain.dof(),
        chain.base,
        chain.tip
    )
}

/// The joint each column names, every joint once, or the pose
/// coordinates; anything else is refused naming the column.
fn columns(
    file: &str,
    names: &[String],
    chain: &Chain,
    builtin: bool,
) -> Result<Columns, CliError> {
    let joint = |name: &str| {
        chain
            .index(name)
            .or_else(|| builtin.then(|| joint_index(name)).flatten())
    };
    let joints = chain.names().join(", ");
    let pose = names.iter().all(|n| joint(n).is_none())
        && names.iter().any(|n| POSE_COLUMNS.contains(&n.as_str()));
    if pose {
        let mut coordinates = Vec::with_capacity(names.len());
        for (c, name) in names.iter().enumerate() {
            let Some(k) = POSE_COLUMNS.iter().position(|p| p == name) else {
                return Err(unknown(file, c, name, &joints));
            };
            coordinates.push(k);
        }
        if let Some(missing) = POSE_COLUMNS.iter().find(|p| !names.iter().any(|n| n == *p)) {
            return Err(CliError::input(format!(
                "{file}: no column `{missing}`: a tool trajectory has the columns t,{}",
                POSE_COLUMNS.join(",")
            )));
        }
        return Ok(Columns::Pose(coordinates));
    }
    let mut columns: Vec<usize> = Vec::with_capacity(names.len());
    for (c, name) in names.iter().enumerate() {
        let Some(j) = joint(name) else {
            return Err(unknown(file, c, name, &joints));
        };
        if let Some(first) = columns.iter().position(|&k| k == j) {
            return Err(CliError::input(format!(
                "{file}: columns `{}` and `{name}` both name joint {}",
                names[first],
                chain.names()[j]
            )));
        }
        columns.push(j);
    }
    if let Some(missing) = chain
        .names()
        .iter()
        .enumerate()
        .find(|(j, _)| !columns.contains(j))
    {
        return Err(CliError::input(format!(
            "{file}: no column for joint `{}`: a joint trajectory of {} has every joint ({joints})",
            missing.1, chain.robot
        )));
    }
    Ok(Columns::Joints(columns))
}

/// A column that names no joint: which it is, and what the columns can be.
fn unknown(file: &str, c: usize, name: &str, joints: &str) -> CliError {
    CliError::input(format!(
        "{file}: column {} `{name}` names no joint; the columns after t are the joints ({joints}) \
         or the tool pose ({})",
        c + 2,
        POSE_COLUMNS.join(",")
    ))
}
