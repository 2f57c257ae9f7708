//! `primo robot play TRAJ.csv --robot ros2:/CONTROLLER`: the checked
//! trajectory as a FollowJointTrajectory goal to a ROS 2 joint trajectory
//! controller ([`primo_ros2`]).

use std::net::IpAddr;
use std::path::Path;
use std::time::Duration;

use primo_learn::task::run::executed_csv;
use primo_robot::JointPath;
use primo_robot::execute::Executor;
use primo_ros2::dds::{Event, Ros2Config, Ros2Robot, Run, execute};
use primo_ros2::execution::ExecutionConfig;
use primo_ros2::{Controller, Ros2Error, domain_from_env};

use crate::error::CliError;
use crate::output::{check_out_file, emit, say};

/// How `play` reaches the controller.
pub struct Ros2Play<'a> {
    /// `--start-timeout`: the wait for the controller's action server.
    pub discovery: Duration,
    /// `--start-tolerance`, rad or m.
    pub start_tolerance: f64,
    /// `--record`: the executed joint series' CSV.
    pub record: Option<&'a Path>,
    /// `--ros-address`: where DDS advertises and multicasts.
    pub address: IpAddr,
    /// `--approach`: at this fraction of the velocity limits.
    pub approach: Option<f64>,
}

impl From<Ros2Error> for CliError {
    /// An address or a `ROS_DOMAIN_ID` that cannot be used is bad input;
    /// everything else happened while talking to ROS 2.
    fn from(e: Ros2Error) -> Self {
        match e {
            Ros2Error::Address { .. } => {
                let message = e.to_string();
                let message = message.strip_prefix("robot address ").unwrap_or(&message);
                CliError::input(format!("--robot {message}"))
            }
            e => CliError::other(format!("robot play: {e}")),
        }
    }
}

/// `--robot ros2:…`: parses it (exit 2 when it is no controller's name).
pub fn controller(robot: &str) -> Result<Controller, CliError> {
    Ok(Controller::parse(robot)?)
}

/// The robot behind `robot` (`ros2:/CONTROLLER`) for a learning run: each
/// roll-out starts where the last one ended, so the robot approaches each
/// one's start (at 20 % of its velocity limits).
pub fn executor(robot: &str) -> Result<Box<dyn Executor>, CliError> {
    let controller = controller(robot)?;
    let domain = domain_from_env().map_err(|e| CliError::input(e.to_string()))?;
    let config = Ros2Config {
        domain,
        discovery: Duration::from_secs(30),
        execution: ExecutionConfig {
            approach_speed: Some(0.2),
            ..ExecutionConfig::default()
        },
        ..Ros2Config::default()
    };
    Ok(Box::new(Ros2Robot { controller, config }))
}

/// Executes `path` through `controller`; exit 1 when the roll-out failed.
pub fn play(
    trajectory: &Path,
    path: &JointPath,
    controller: &Controller,
    how: &Ros2Play,
) -> Result<(), CliError> {
    let domain = domain_from_env().map_err(|e| CliError::input(e.to_string()))?;
    if let Some(record) = how.record {
        check_out_file("--record", record, &[("the trajectory", trajectory)])?;
    }
    let cfg = Ros2Config {
        domain,
        discovery: how.discovery,
        execution: ExecutionConfig {
            start_tolerance: how.start_tolerance,
            approach_speed: how.approach,
            ..ExecutionConfig::default()
        },
        networks: vec![how.address],
    };
    say(&format!(
        "primo robot play: {} samples over {:.3} s passed the limit checks; \
         looking for {controller} on ROS_DOMAIN_ID {domain}",
        path.times().len(),
        path.duration()
    ))?;
    let mut said = Ok(());
    let run = execute(controller, path, &cfg, &mut |event| {
        if said.is_ok() {
            said = report(&event);
        }
    })?;
    said?;
    summary(path, &run)?;
    if let Some(record) = how.record {
        emit(Some(record), &executed_csv(path, &run.executed))?;
    }
    match run.outcome {
        Ok(()) => say("primo robot play: completed"),
        Err(e) => Err(e.into()),
    }
}

fn report(event: &Event) -> Result<(), CliError> {
    let line = match event {
        Event::Discovering => return Ok(()),
        Event::Matched(after) => format!(
            "found the controller after {:.2} s; reading /joint_states",
            after.as_secs_f64()
        ),
        Event::GoalSent => "the robot is at the start; goal sent".to_string(),
        Event::Accepted => "the controller accepted the goal".to_string(),
    };
    say(&format!("primo robot play: {line}"))
}

fn summary(path: &JointPath, run: &Run) -> Result<(), CliError> {
    let e = &run.executed;
    if e.times.is_empty() {
        return Ok(());
    }
    say(&format!(
        "primo robot play: {} joint states over {:.3} s, {} feedback messages, \
         largest feedback error {:.4} deg",
        e.times.len(),
        e.times.last().copied().unwrap_or(0.0),
        run.feedback,
        run.max_feedback_error.to_degrees()
    ))?;
    if let (Some(last), Some(end)) = (e.rows(path.chain().dof()).last(), path.rows().last()) {
        let off = last
            .iter()
            .zip(end)
            .map(|(q, p)| (q - p).abs())
            .fold(0.0, f64::max);
        say(&format!(
            "primo robot play: the last joint state is {:.4} deg from the trajectory's end",
            off.to_degrees()
        ))?;
    }
    Ok(())
}
