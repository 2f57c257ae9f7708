//! The Franka side of `primo robot`: `play … --robot franka:ADDR[:PORT]`
//! streams a checked joint trajectory over the FCI, `sim-fci` is the
//! simulated controller.

use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};

use primo_core::coupling::PhaseStop;
use primo_franka::net::{FrankaRobot, PlayConfig, Progress, play as fci_play};
use primo_franka::plan::fr3;
use primo_franka::session::{Event, Report};
use primo_franka::{FrankaError, parse_robot};
use primo_robot::execute::Executor;
use primo_sim::fci::{Fault, FciConfig, SimFci};

use crate::error::CliError;
use crate::model::ModelArgs;
use crate::output::{read, say};

/// `primo robot sim-fci`'s options.
#[derive(Debug, clap::Args)]
pub struct SimFciArgs {
    /// The TCP port of the command channel on 127.0.0.1.
    #[arg(long, default_value_t = primo_franka::DEFAULT_PORT)]
    port: u16,
    /// The robot's URDF, served to clients (default: the built-in FR3).
    #[arg(long, value_name = "ROBOT.urdf")]
    model: Option<PathBuf>,
    /// Joint angles at power-on, rad, seven comma-separated (default: the
    /// FR3's usual start, 0,0,0,-1.57,0,1.57,0.785).
    #[arg(long, allow_hyphen_values = true)]
    start: Option<String>,
    /// Fault: a reflex after this many milliseconds of every motion.
    #[arg(long, value_name = "MS")]
    reflex_after: Option<u64>,
    /// The reflex's flag (libfranka's error name).
    #[arg(long, default_value = "joint_reflex", requires = "reflex_after")]
    reflex: String,
    /// Fault: stop sending states after this many milliseconds of a
    /// motion.
    #[arg(long, value_name = "MS", conflicts_with = "reflex_after")]
    silent_after: Option<u64>,
    /// Fault: close the command channel after this many milliseconds of a
    /// motion.
    #[arg(long, value_name = "MS", conflicts_with_all = ["reflex_after", "silent_after"])]
    hangup_after: Option<u64>,
    /// Fault: the arm held still after this many milliseconds of every
    /// motion, as by a person or a contact (it reports where it stopped
    /// while the commands go on), for --hold-for.
    #[arg(long, value_name = "MS", requires = "hold_for",
          conflicts_with_all = ["reflex_after", "silent_after", "hangup_after"])]
    hold_after: Option<u64>,
    /// How long the arm is held, ms.
    #[arg(long, value_name = "MS", requires = "hold_after")]
    hold_for: Option<u64>,
    /// Exit when the first client leaves.
    #[arg(long)]
    once: bool,
    /// Run the state stream at normal priority.
    #[arg(long)]
    no_realtime: bool,
}

/// The Franka at `robot` (`franka:ADDR[:PORT]`) as a learning run's
/// executor: each checked roll-out streamed as `play` does, approached at
/// 20 % of the velocity limits from wherever the arm is.
pub fn executor(robot: &str) -> Result<Box<dyn Executor>, CliError> {
    let addr = parse_robot(robot)
        .map_err(|e| CliError::input(format!("--robot `{}`: {}", e.spec, e.why)))?;
    let mut cfg = PlayConfig::default();
    cfg.session.approach_speed = 0.2;
    Ok(Box::new(FrankaRobot { addr, cfg }))
}

/// How `play` streams, its flags checked.
pub struct Streaming {
    /// `--approach-speed`.
    pub approach_speed: f64,
    /// `--phase-stop`.
    pub phase_stop: Option<PhaseStop>,
    /// Not `--no-realtime`.
    pub realtime: bool,
}

/// `--phase-stop K`: a positive gain.
pub fn phase_stop_gain(k: f64) -> Result<PhaseStop, CliError> {
    PhaseStop::new(k as f32)
        .ok()
        .filter(|_| k > 0.0)
        .ok_or_else(|| CliError::input(format!("--phase-stop: {k}: must be a positive number")))
}

/// Plays `trajectory` on the Franka at `robot`; the built-in FR3 unless
/// `--model` names another description.
pub fn play(
    trajectory: &Path,
    model: &ModelArgs,
    robot: &str,
    how: &Streaming,
) -> Result<(), CliError> {
    let addr = parse_robot(robot)
        .map_err(|e| CliError::input(format!("--robot `{}`: {}", e.spec, e.why)))?;
    let chain = model.chain_or(fr3)?;
    let path = crate::joint_path::load(trajectory, &chain, "the FCI")?;
    say(&format!(
        "primo robot play: {} samples over {:.3} s passed the limit checks of {}; \
         connecting to the Franka at {addr}",
        path.times().len(),
        path.duration(),
        chain.robot
    ))?;
    let mut cfg = PlayConfig {
        realtime: how.realtime,
        ..PlayConfig::default()
    };
    cfg.session.approach_speed = how.approach_speed;
    cfg.session.phase_stop = how.phase_stop;
    let mut said = Ok(());
    // Ctrl-C asks the robot to stop the motion (the roll-out then fails,
    // status 1); the FCI would stop it anyway once the stream goes silent.
    static STOP: AtomicBool = AtomicBool::new(false);
    ctrlc::set_handler(|| STOP.store(true, Ordering::Relaxed))
        .map_err(|e| CliError::other(format!("cannot catch Ctrl-C: {e}")))?;
    let result = fci_play(addr, &path, &cfg, &STOP, &mut |p| {
        if said.is_ok() {
            said = report(&p);
        }
    });
    said?;
    match result {
        Ok(r) => {
            print_report(&r)?;
            say("primo robot play: completed")
        }
        Err(e @ (FrankaError::Limit(_) | FrankaError::NotSeven { .. })) => Err(CliError::input(
            format!("{}: {e}; nothing moved", trajectory.display()),
        )),
        Err(e) => Err(CliError::other(format!("robot play: {e}"))),
    }
}

fn report(p: &Progress) -> Result<(), CliError> {
    let line = match p {
        Progress::Realtime(granted) if !granted.is_full() => {
            eprintln!(
                "primo robot play: warning: {granted}: answers may be late on a busy machine"
            );
            return Ok(());
        }
        Progress::Realtime(granted) => format!("FCI loop: {granted}"),
        Progress::Session(Event::Connected { version }) => {
            format!("connected, FCI protocol version {version}")
        }
        Progress::Session(Event::Model { bytes }) => format!("robot model: {bytes} bytes"),
        Progress::Session(Event::Planned {
            setpoints,
            approach,
        }) => format!(
            "planned {setpoints} setpoints at 1 ms ({approach} approaching the start), within the limits"
        ),
        Progress::Session(Event::MotionStarted) => "motion started".into(),
        Progress::Session(Event::Finished) => "motion finished".into(),
    };
    say(&format!("primo robot play: {line}"))
}

fn print_report(r: &Report) -> Result<(), CliError> {
    say(&format!(
        "sent {} of {} setpoints for {} states ({} skipped, {} duplicates); \
         lowest command success rate {}",
        r.commands,
        r.planned,
        r.states,
        r.skipped,
        r.duplicates,
        r.min_success_rate
            .map_or_else(|| "-".to_string(), |x| format!("{x:.3}"))
    ))?;
    if let Some(rate) = r.slowest_rate {
        say(&format!(
            "phase stopping: the slowest {:.3} of the planned speed, {:.3} s longer than planned",
            rate,
            r.commands.saturating_sub(r.planned as u64) as f64 * primo_franka::plan::DT
        ))?;
    }
    say("joint  max error [deg]  rms error [deg]  (measured - commanded a cycle before)")?;
    for j in 0..r.max_error.len() {
        say(&format!(
            "{:>5}  {:>15.4}  {:>15.4}",
            format!("j{}", j + 1),
            r.max_error[j].to_degrees(),
            r.rms_error[j].to_degrees()
        ))?;
    }
    Ok(())
}

/// `primo robot sim-fci`.
pub fn sim_fci(args: &SimFciArgs) -> Result<(), CliError> {
    let mut cfg = FciConfig::new(args.port);
    if let Some(path) = &args.model {
        cfg.urdf = read(Some("--model"), path)?;
    }
    if let Some(text) = &args.start {
        let names: Vec<String> = (1..=7).map(|j| format!("joint{j}")).collect();
        let q = crate::dmp::parse_vector("--start", text, &names)?;
        cfg.start = std::array::from_fn(|j| q.get(j).copied().map_or(0.0, f64::from));
    }
    cfg.fault = match (args.reflex_after, args.silent_after, args.hangup_after) {
        (Some(after), _, _) => {
            let flag = primo_franka::wire::Flags::index(&args.reflex).ok_or_else(|| {
                CliError::input(format!(
                    "--reflex `{}`: not one of libfranka's error names (e.g. joint_reflex)",
                    args.reflex
                ))
            })?;
            Some(Fault::Reflex { after, flag })
        }
        (_, Some(after), _) => Some(Fault::Silent { after }),
        (_, _, Some(after)) => Some(Fault::Hangup { after }),
        _ => args
            .hold_after
            .zip(args.hold_for)
            .map(|(after, cycles)| Fault::Hold { after, cycles }),
    };
    cfg.once = args.once;
    cfg.realtime = !args.no_realtime;
    let fci = SimFci::new(cfg)?;
    say(&format!(
        "primo robot sim-fci: FCI protocol version {} on {}",
        primo_franka::wire::VERSION,
        fci.local_addr()?
    ))?;
    let r = fci.run(&AtomicBool::new(false))?;
    say(&format!(
        "primo robot sim-fci: {} clients, {} motions ({} finished, {} reflexes); \
         {} motion cycles: {} answered in time, {} late, {} missed ({:.4} % late); \
         {} own sends late by more than 0.5 ms, the latest by {:.3} ms; {} malformed commands",
        r.clients,
        r.motions,
        r.finished,
        r.reflexes,
        r.motion_cycles,
        r.on_time,
        r.late,
        r.missed,
        r.late_rate() * 100.0,
        r.late_sends,
        r.max_send_delay * 1e3,
        r.malformed
    ))
}
