//! The `primo robot` commands: check a trajectory against a robot's limits
//! (`check`, [`crate::robot_check`]), stream a joint trajectory to a KUKA
//! LWR4 over FRI or execute it through a ROS 2 joint trajectory controller
//! ([`crate::robot_ros2`]) (`play`), or be the KRC with the simulated arm
//! and cell (`sim-krc`).

use std::io::BufRead;
use std::net::SocketAddr;
use std::path::{Path, PathBuf};
use std::sync::atomic::AtomicBool;
use std::time::Duration;

use primo_fri::path::FriPath;
use primo_fri::session::SessionConfig;
use primo_fri::udp::{Ended, Event, PlayConfig, PlayResult, bind, play};
use primo_fri::{DEFAULT_PORT, parse_robot};
use primo_mtsics::{Fixed, quote};
use primo_robot::JOINT_COLUMNS as JOINT_NAMES;
use primo_sim::krc::{CellHandle, KrcConfig, LATE_SEND, SimKrc};

use crate::args::Glass;
use crate::error::CliError;
use crate::model::ModelArgs;
use crate::output::say;
use crate::terminal::in_background;

/// `primo robot …`.
#[derive(Debug, clap::Subcommand)]
pub enum RobotCommand {
    /// Check a trajectory against a robot's limits, without moving
    /// anything: any serial arm from its URDF (default: the built-in LWR
    /// 4), joint positions by the joints' names or the tool's poses
    /// (solved by inverse kinematics). Exit 0 when it passes, 1 when it
    /// does not (the first violation on stdout), 2 for bad input.
    Check(crate::robot_check::CheckArgs),
    /// Play a joint trajectory (CSV `t` and the joints, as `primo dmp run`
    /// writes) on a robot after the joint limit checks of its model: stream
    /// it to a KUKA LWR over FRI and report the tracking error, or execute
    /// it through a ROS 2 joint trajectory controller and report the joint
    /// states it went through. Exit 1 when the robot did not complete it.
    Play {
        /// Trajectory CSV: header `t` then the arm's joints by name, any
        /// order (the LWR 4's `a1..a7`, `A1..A7`, `j1..j7` or
        /// `joint_1..joint_7`; a URDF's joint names), t in seconds, angles
        /// in rad.
        trajectory: PathBuf,
        #[command(flatten)]
        model: crate::model::ModelArgs,
        /// `fri:ADDR[:PORT]`: the local UDP address to bind, where the KRC
        /// sends its packets (default port 49938); `franka:ADDR[:PORT]`: a
        /// Franka's FCI (default port 1337; the model defaults to the
        /// built-in FR3); or `ros2:/CONTROLLER`: a joint trajectory
        /// controller's FollowJointTrajectory action
        /// (`/CONTROLLER/follow_joint_trajectory`, on `ROS_DOMAIN_ID`), the
        /// robot's state from `/joint_states`.
        #[arg(long)]
        robot: String,
        /// Longest silence from the KRC while streaming before stopping, s.
        #[arg(long, default_value_t = 0.2)]
        cycle_timeout: f64,
        /// Longest wait for the robot, s: the KRC's command mode (FRI), the
        /// controller's action server (ROS 2).
        #[arg(long, default_value_t = 60.0)]
        start_timeout: f64,
        /// ROS 2: how far each joint may be from the trajectory's start
        /// before the goal is sent, rad (or m); the robot is not moved
        /// there (FRI approaches the start instead).
        #[arg(long, default_value_t = 0.01)]
        start_tolerance: f64,
        /// ROS 2: a robot further from the trajectory's start than
        /// --start-tolerance is first moved there (minimum jerk, at most
        /// --approach-speed of the velocity limits, checked with the
        /// trajectory) instead of refused.
        #[arg(long)]
        approach: bool,
        /// ROS 2: write the joint states the robot went through to this CSV
        /// (`t` from the goal's acceptance, then the model's joints), also
        /// when the roll-out fails.
        #[arg(long, value_name = "CSV")]
        record: Option<PathBuf>,
        /// ROS 2: the local address DDS advertises and multicasts on: the
        /// interface toward the controller's machine (default 127.0.0.1,
        /// the controller on this machine).
        #[arg(long, value_name = "ADDR", default_value = "127.0.0.1")]
        ros_address: std::net::IpAddr,
        /// Peak speed of the approach to the trajectory's start, as a
        /// fraction of the joint velocity limits.
        #[arg(long, default_value_t = 0.2)]
        approach_speed: f64,
        /// How long to hold still in command mode before the approach,
        /// weighing the held load (estExtTcpFT), s.
        #[arg(long, default_value_t = 0.3)]
        weigh: f64,
        /// How long to hold the final position after the trajectory
        /// (weighing again), s.
        #[arg(long, default_value_t = 0.3)]
        settle: f64,
        /// Franka: phase stopping (Ijspeert et al. 2013) with gain K, per
        /// rad²: while the arm lags its command by e rad, the trajectory
        /// runs at 1/(1 + K·|e|²) of its speed (K = 10000: half speed at
        /// 10 mrad), every setpoint still within the limits.
        #[arg(long, value_name = "K")]
        phase_stop: Option<f64>,
        /// Run the FRI loop at normal priority: no real-time scheduling or
        /// locked memory (to compare; a busy machine makes answers late).
        #[arg(long)]
        no_realtime: bool,
    },
    /// Be the KRC: send FRI measurements to 127.0.0.1:PORT every cycle,
    /// drive the simulated arm and pouring cell by the answers.
    ///
    /// Operator commands on stdin, one a line: `reset` refills the bottle
    /// and puts an empty glass back (the arm stays where it is). End of
    /// stdin changes nothing. Started in a shell's background (`sim-krc
    /// &`), it leaves the terminal alone: reading it would stop the job.
    SimKrc {
        /// The remote's UDP port on 127.0.0.1.
        #[arg(long, default_value_t = DEFAULT_PORT)]
        port: u16,
        /// The FRI cycle, ms (1 to 10).
        #[arg(long, default_value_t = 2)]
        cycle_ms: u64,
        /// Joint angles at power-on, rad, `a1,...,a7` (default: the
        /// pouring rest posture).
        #[arg(long, allow_hyphen_values = true)]
        start: Option<String>,
        /// Liquid in the bottle, l.
        #[arg(long, default_value_t = 0.5)]
        bottle: f64,
        /// The glass on the scale.
        #[arg(long, value_enum, default_value_t = Glass::Normal)]
        glass: Glass,
        /// Fault: fraction of measurement packets lost.
        #[arg(long, default_value_t = 0.0)]
        drop: f64,
        /// Seed of the losses and the scale's noise.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Fault: the quality drops to BAD at this time, s.
        #[arg(long)]
        quality_drop_at: Option<f64>,
        /// Fault: never switch to command mode.
        #[arg(long)]
        monitor_only: bool,
        /// Fault: stop sending at this time, s (and exit).
        #[arg(long)]
        stop_after: Option<f64>,
        /// Exit when a command session ends (the remote falls silent).
        #[arg(long)]
        once: bool,
        /// Serve the cell's scale over MT-SICS on a new pseudo-terminal
        /// (its path printed as `primo robot sim-krc: scale served on PATH`).
        #[arg(long)]
        scale: bool,
        /// Serve the cell's scale as a bare load cell, the raw counts for
        /// primo's scale firmware, on a new pseudo-terminal (its path
        /// printed as `primo robot sim-krc: load cell served on PATH`; take
        /// it with `--scale qemu:PATH`).
        #[arg(long)]
        load_cell: bool,
    },
    /// Be a Franka controller: the FCI's command channel on
    /// 127.0.0.1:PORT and its 1 kHz state stream, the arm following the
    /// joint positions commanded (libfranka's clients drive it too).
    SimFci(crate::franka::SimFciArgs),
}

/// Runs a `primo robot` command.
pub fn run(command: RobotCommand) -> Result<(), CliError> {
    match command {
        RobotCommand::Check(args) => crate::robot_check::run(&args),
        RobotCommand::Play {
            trajectory,
            model,
            robot,
            approach_speed,
            phase_stop,
            no_realtime,
            ..
        } if robot.starts_with("franka:") => crate::franka::play(
            &trajectory,
            &model,
            &robot,
            &crate::franka::Streaming {
                approach_speed: in_range("--approach-speed", approach_speed, 1e-3, 1.0)?,
                phase_stop: phase_stop.map(crate::franka::phase_stop_gain).transpose()?,
                realtime: !no_realtime,
            },
        ),
        RobotCommand::SimFci(args) => crate::franka::sim_fci(&args),
        RobotCommand::Play {
            trajectory,
            model,
            robot,
            cycle_timeout,
            start_timeout,
            start_tolerance,
            record,
            approach,
            ros_address,
            approach_speed,
            weigh,
            settle,
            phase_stop,
            no_realtime,
        } => {
            if phase_stop.is_some() {
                return Err(CliError::input(format!(
                    "--phase-stop: {robot}: phase stopping streams a Franka's setpoints \
                     (--robot franka:ADDR); FRI and ROS 2 play the trajectory as planned"
                )));
            }
            if robot.starts_with("ros2:") {
                let controller = crate::robot_ros2::controller(&robot)?;
                let how = crate::robot_ros2::Ros2Play {
                    discovery: seconds("--start-timeout", start_timeout)?,
                    start_tolerance: in_range("--start-tolerance", start_tolerance, 0.0, 1.0)?,
                    record: record.as_deref(),
                    address: ros_address,
                    approach: approach
                        .then(|| in_range("--approach-speed", approach_speed, 1e-3, 1.0))
                        .transpose()?,
                };
                let path = crate::joint_path::load(&trajectory, &model.chain()?, "ROS 2")?;
                return crate::robot_ros2::play(&trajectory, &path, &controller, &how);
            }
            let cfg = PlayConfig {
                session: SessionConfig {
                    approach_speed: in_range("--approach-speed", approach_speed, 1e-3, 1.0)?,
                    weigh: in_range("--weigh", weigh, 0.0, 60.0)?,
                    settle: in_range("--settle", settle, 0.0, 60.0)?,
                },
                cycle_timeout: seconds("--cycle-timeout", cycle_timeout)?,
                start_timeout: seconds("--start-timeout", start_timeout)?,
                realtime: !no_realtime,
                ..PlayConfig::default()
            };
            robot_play(&trajectory, &model, &robot, &cfg)
        }
        RobotCommand::SimKrc {
            port,
            cycle_ms,
            start,
            bottle,
            glass,
            drop,
            seed,
            quality_drop_at,
            monitor_only,
            stop_after,
            once,
            scale,
            load_cell,
        } => {
            let mut cfg = KrcConfig::new(SocketAddr::from(([127, 0, 0, 1], port)));
            cfg.cycle = Duration::from_millis(cycle_ms);
            if let Some(text) = start {
                let names = JOINT_NAMES.map(String::from);
                let q = crate::dmp::parse_vector("--start", &text, &names)?;
                cfg.start = std::array::from_fn(|j| q.get(j).copied().map_or(0.0, f64::from));
            }
            cfg.bottle = bottle;
            cfg.glass = glass.into();
            cfg.drop = drop;
            cfg.seed = seed;
            cfg.quality_drop_at = quality_drop_at
                .map(|s| seconds("--quality-drop-at", s))
                .transpose()?;
            cfg.monitor_only = monitor_only;
            cfg.stop_after = stop_after.map(|s| seconds("--stop-after", s)).transpose()?;
            cfg.once = once;
            sim_krc(cfg, scale, load_cell)
        }
    }
}

fn in_range(flag: &str, v: f64, lo: f64, hi: f64) -> Result<f64, CliError> {
    if (lo..=hi).contains(&v) {
        Ok(v)
    } else {
        Err(CliError::input(format!(
            "{flag}: {v} is outside [{lo}, {hi}]"
        )))
    }
}

fn seconds(flag: &str, v: f64) -> Result<Duration, CliError> {
    Duration::try_from_secs_f64(v)
        .ok()
        .filter(|d| !d.is_zero())
        .ok_or_else(|| CliError::input(format!("{flag}: {v} is not a positive number of seconds")))
}

/// Reads a joint trajectory of `model`'s arm and passes it through its
/// limit checks; FRI streams seven joints.
fn load_trajectory(path: &Path, model: &ModelArgs) -> Result<FriPath, CliError> {
    let checked = crate::joint_path::load(path, &model.chain()?, "FRI")?;
    FriPath::try_from(&checked).map_err(|why| {
        CliError::input(format!(
            "{}: trajectory rejected, nothing sent to the robot: {why}",
            path.display()
        ))
    })
}

fn robot_play(
    trajectory: &Path,
    model: &ModelArgs,
    robot: &str,
    cfg: &PlayConfig,
) -> Result<(), CliError> {
    let addr = parse_robot(robot).map_err(|e| {
        let mut e = CliError::from(e);
        if !robot.starts_with("fri:") {
            e.message.push_str(
                "; or franka:ADDR[:PORT], a Franka's controller, or ros2:/CONTROLLER, a ROS 2 \
                 joint trajectory controller's name",
            );
        }
        e
    })?;
    let path = load_trajectory(trajectory, model)?;
    let socket = bind(addr)?;
    say(&format!(
        "primo robot play: {} samples over {:.3} s passed the limit checks; \
         waiting for the KRC's packets on {addr}",
        path.rows().len(),
        path.path().duration()
    ))?;
    let mut said = Ok(());
    let result = play(&socket, &path, cfg, &mut |event| {
        if said.is_ok() {
            said = report(&event);
        }
    })?;
    said?;
    print_result(&result)?;
    match result.ended {
        Ended::Completed => {
            say("primo robot play: completed")?;
            Ok(())
        }
        ended => Err(CliError::other(format!("robot play: {ended}"))),
    }
}

/// One line for what the FRI loop is doing; on stderr if it is a warning.
fn report(event: &Event) -> Result<(), CliError> {
    let line = match event {
        Event::Realtime(granted) if !granted.is_full() => {
            eprintln!(
                "primo robot play: warning: {granted}: answers may be late on a busy machine"
            );
            return Ok(());
        }
        Event::Realtime(granted) => format!("FRI loop: {granted}"),
        Event::Krc(krc) => format!("KRC {krc} is sending; waiting for command mode"),
        Event::Weighing { setpoints } => {
            format!("commandable: holding still for {setpoints} cycles, weighing")
        }
        Event::Approaching { setpoints } => {
            format!("approaching the start in {setpoints} cycles")
        }
        Event::Streaming { sent, planned } => format!("streaming: setpoint {sent} of {planned}"),
        Event::Settling => "settling: holding the end, weighing".to_string(),
    };
    say(&format!("primo robot play: {line}"))
}

fn print_result(r: &PlayResult) -> Result<(), CliError> {
    for why in &r.rejections {
        eprintln!("primo robot play: rejected a datagram: {why}");
    }
    if r.rejected > r.rejections.len() as u64 {
        eprintln!(
            "primo robot play: {} more datagrams rejected",
            r.rejected - r.rejections.len() as u64
        );
    }
    if let Some(krc) = r.krc {
        say(&format!(
            "KRC {krc}: {} packets answered, {} missing from its sequence",
            r.answered, r.gaps
        ))?;
    }
    if r.planned > 0 {
        say(&format!(
            "sent {} of {} setpoints at {:.1} ms ({} holding still to weigh, {} approaching the start)",
            r.sent,
            r.planned,
            r.cycle * 1e3,
            r.weighing,
            r.approach
        ))?;
        say("joint  max error [deg]  rms error [deg]  (measured - commanded)")?;
        for (j, name) in JOINT_NAMES.iter().enumerate() {
            say(&format!(
                "{name:>5}  {:>15.4}  {:>15.4}",
                r.tracking.max[j].to_degrees(),
                r.tracking.rms[j].to_degrees()
            ))?;
        }
    }
    if let Some([before, after]) = r.load {
        let [n_before, n_after] = r.load_samples;
        say(&format!(
            "held load (estExtTcpFT): {before:.3} N before, {after:.3} N after \
             ({n_before} and {n_after} measurements)"
        ))?;
    }
    Ok(())
}

fn sim_krc(cfg: KrcConfig, scale: bool, load_cell: bool) -> Result<(), CliError> {
    let krc = SimKrc::new(cfg)?;
    let cell = krc.cell();
    // Kept until the KRC stops: the scale is served as long as the cell.
    let server = if scale {
        let server = krc.serve_scale()?;
        say(&format!(
            "primo robot sim-krc: scale served on {}",
            server.path()
        ))?;
        Some(server)
    } else {
        None
    };
    // Likewise; it stops when dropped.
    let _load_cell = if load_cell {
        let server = krc.serve_load_cell()?;
        say(&format!(
            "primo robot sim-krc: load cell served on {}",
            server.path()
        ))?;
        Some(server)
    } else {
        None
    };
    if !in_background() {
        let operator = cell.clone();
        std::thread::Builder::new()
            .name("sim-krc-stdin".into())
            .spawn(move || operate(&operator, &cfg))
            .map_err(|e| CliError::other(format!("cannot start the stdin thread: {e}")))?;
    }
    say(&format!(
        "primo robot sim-krc: FRI measurements every {} ms from {} to {}, monitor mode",
        cfg.cycle.as_millis(),
        krc.local_addr()?,
        cfg.remote
    ))?;
    let report = krc.run(&AtomicBool::new(false))?;
    if let Some(server) = server {
        server
            .stop()
            .map_err(|e| CliError::other(format!("serving the scale failed: {e}")))?;
    }
    let totals = cell.lock().totals();
    say(&format!(
        "primo robot sim-krc: {} cycles, {} answered on time, {} missed ({} lost on purpose), \
         {} stale answers, {} malformed datagrams",
        report.cycles,
        report.answered,
        report.missed,
        report.dropped,
        report.stale,
        report.malformed
    ))?;
    say(&format!(
        "primo robot sim-krc: {} sends late by more than {:.2} ms (its own lateness), the latest by {:.2} ms",
        report.late_sends,
        cfg.cycle.as_secs_f64() * 1e3 * LATE_SEND,
        report.max_send_delay * 1e3
    ))?;
    for why in &report.rejections {
        say(&format!("primo robot sim-krc: malformed datagram: {why}"))?;
    }
    say(&format!(
        "primo robot sim-krc: command mode for {:.3} s; commands too fast {}, beyond limits {}; \
         moved up to {:.2} deg from the start",
        report.command_cycles as f64 * cfg.cycle.as_secs_f64(),
        report.too_fast,
        report.beyond_limits,
        report.max_excursion.to_degrees()
    ))?;
    say(&format!(
        "primo robot sim-krc: in the glass {} ml, spilled {} ml, in the bottle {} ml",
        Fixed(totals.glass * 1e3, 1),
        Fixed(totals.spilled * 1e3, 1),
        Fixed(totals.bottle * 1e3, 1)
    ))?;
    Ok(())
}

/// The operator's commands on stdin, one a line, until it closes: `reset`
/// puts a fresh cell (full bottle, empty glass) in place of the old one.
fn operate(cell: &CellHandle, cfg: &KrcConfig) {
    for (i, line) in std::io::stdin().lock().split(b'\n').enumerate() {
        let line = match line {
            Ok(line) => line,
            Err(e) => {
                eprintln!("primo robot sim-krc: stdin: {e}; operator commands end");
                return;
            }
        };
        let line = line.trim_ascii();
        if line.is_empty() {
            continue;
        }
        let done = if line == b"reset" {
            cfg.fresh_cell()
                .map(|fresh| *cell.lock() = fresh)
                .map_err(|e| e.to_string())
        } else {
            Err(format!(
                "`{}`: unknown command; expected `reset`",
                quote(line)
            ))
        };
        let said = match done {
            Ok(()) => say(&format!(
                "primo robot sim-krc: cell reset: bottle {} l, glass empty",
                cfg.bottle
            ))
            .map_err(|e| e.message),
            Err(why) => {
                eprintln!("primo robot sim-krc: stdin line {}: {why}", i + 1);
                Ok(())
            }
        };
        if let Err(e) = said {
            eprintln!("primo robot sim-krc: {e}");
            return;
        }
    }
}
