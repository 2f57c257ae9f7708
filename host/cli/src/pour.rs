//! `primo pour`: learn to pour on the simulated cell or a real one.

use std::io::{BufRead, Write};
use std::path::PathBuf;

use primo_learn::Error;
use primo_learn::algorithm::Algorithm;
use primo_learn::pour::report::rollout_line;
use primo_learn::pour::rig::{InstrumentsSpec, Operator};
use primo_learn::pour::run::{CellSpec, Note, Pour, Resumed};
use primo_learn::pour::settings::Settings;
use primo_learn::pour::skill::{DemoFile, SkillSpec};
use primo_learn::rollouts::Point;
use primo_learn::run::{Event, Failure, LearnerSpec, Start};
use primo_learn::runlog::RunEvent;
use primo_mtsics::Fixed;

use crate::args::{Glass, Method, Space};
use crate::error::CliError;
use crate::progress::Progress;

/// The cell and skill options shared by the learning commands.
#[derive(Debug, Clone, clap::Args)]
pub struct SkillArgs {
    /// Coordinates the movement is learned in [default: cartesian for
    /// error learning, joint for PoWER and `primo rollout`].
    #[arg(long, value_enum)]
    pub space: Option<Space>,
    /// Kernels per DoF of the DMPs.
    #[arg(long, default_value_t = 30)]
    pub kernels: usize,
    /// The glass on the scale [default: normal for `primo pour`, small
    /// for `primo rollout`, as `primo experiment power`].
    #[arg(long, value_enum)]
    pub glass: Option<Glass>,
    /// Demonstrations `FILE=VOLUME` (repeat; CSV in the space's columns:
    /// t,x,y,z,qw,qx,qy,qz or t,a1..a7; the earlier t,x,y,z,rx,ry,rz are
    /// converted, saying so). Default: the built-in pair from 0.3 l and
    /// 1.0 l bottles.
    #[arg(long = "demo", value_name = "FILE=VOLUME")]
    pub demos: Vec<String>,
}

impl SkillArgs {
    /// The skill these options describe; `space` and `glass` fall back to
    /// the given defaults. Demonstration paths become absolute, so a run
    /// log names them from anywhere.
    pub fn spec(
        &self,
        space: primo_learn::pour::skill::Space,
        glass: Glass,
    ) -> Result<SkillSpec, CliError> {
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
            space: self.space.map_or(space, Into::into),
            glass: self.glass.unwrap_or(glass).into(),
            kernels: self.kernels,
            demos,
        })
    }
}

/// `primo pour` options.
#[derive(Debug, clap::Args)]
pub struct PourArgs {
    /// Liquid in the bottle, l.
    #[arg(long, default_value_t = 0.5)]
    bottle: f64,
    /// Volume to pour, l.
    #[arg(long, default_value_t = 0.2, allow_hyphen_values = true)]
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
    /// Error learning's query bounds LOW,HIGH, l: the queries it may try
    /// (golden section and Illinois try the ends early: bound them by
    /// what the demonstrations support and the glass holds).
    #[arg(long, value_name = "LOW,HIGH", default_value = "0.1,1.5", value_parser = bounds)]
    search: [f32; 2],
    /// The error learners' gain K in l per l of error (the first for
    /// secant, the only one for fixed-gain, weighted-gain and power-el).
    #[arg(long, default_value_t = 1.0, allow_hyphen_values = true)]
    gain: f32,
    /// PoWER's importance sampler: the best roll-outs each update
    /// averages, 1 to 3 (default: the paper's 3 for power, 2 for power-el).
    #[arg(long)]
    sampler: Option<usize>,
    /// Output directory: run.log (every roll-out, appended as it is made),
    /// and at the end rollouts.csv, summary.json, convergence.png and
    /// series.csv (the best roll-out's time series).
    #[arg(long, default_value = "pour-out")]
    out: PathBuf,
    /// Start anew in --out though a run is logged there: the earlier run's
    /// directory is moved aside to OUT.replaced-TIME, nothing is deleted.
    #[arg(long)]
    force: bool,
    /// Continue the run logged in DIR (after a crash, a kill or a failed
    /// instrument): its settings come from the log, and no roll-out is
    /// lost or repeated. With --max-rollouts, a new budget (a run that
    /// used up its budget goes on).
    #[arg(long, value_name = "DIR", conflicts_with_all = [
        "bottle", "target", "method", "seed", "precision", "gain", "sampler", "search",
        "glass_holds", "out",
        "force",
        "space", "kernels", "glass", "demos",
    ])]
    resume: Option<PathBuf>,
    #[command(flatten)]
    learner: LearnerArgs,
    #[command(flatten)]
    cell: CellArgs,
}

/// Where a pour's roll-outs happen, when not on the simulated cell.
#[derive(Debug, Clone, clap::Args)]
pub struct CellArgs {
    /// Roll out on a real cell: the robot, `fri:ADDR[:PORT]`, the local
    /// UDP address the KRC sends its FRI packets to (default port 49938).
    /// For `primo learn` with a task file: `ros2:/CONTROLLER`, a ROS 2
    /// joint trajectory controller, or `franka:ADDR[:PORT]`, a Franka's
    /// FCI, that executes each roll-out before the task's evaluator
    /// measures it.
    #[arg(
        long,
        value_name = "fri:ADDR[:PORT]|ros2:/CONTROLLER|franka:ADDR[:PORT]"
    )]
    robot: Option<String>,
    /// With --robot: the scale. An MT-SICS scale's serial port;
    /// `postcard:PORT`, primo's scale on a serial port; or
    /// `qemu:LOAD_CELL`, primo's scale firmware booted on an emulated
    /// Cortex-M4F, its ADC line on LOAD_CELL (`primo robot sim-krc
    /// --load-cell` prints it).
    #[arg(long, value_name = "PORT|postcard:PORT|qemu:LOAD_CELL")]
    scale: Option<String>,
    /// With --robot: an MT-SICS scale's baud rate [default: 9600].
    #[arg(long)]
    baud: Option<u32>,
    /// With --robot: the liquid's density, g/ml (the scale weighs, the
    /// learner wants volumes) [default: 0.998, water].
    #[arg(long, value_name = "G_PER_ML")]
    density: Option<f64>,
    /// With --robot: before every roll-out, ask the operator to refill the
    /// bottle and empty the glass, and wait for Enter.
    #[arg(long)]
    confirm: bool,
    /// What the glass holds, l, or `none`: error learning then tries no
    /// query that would let more leave the bottle (it raises the search's
    /// low end to bottle + target − this) [default: the simulated glass's
    /// capacity; with --robot, required: give your glass's, or `none` to
    /// search without that bound]
    #[arg(long, value_name = "LITRES|none", value_parser = glass_holds)]
    glass_holds: Option<Holds>,
}

impl CellArgs {
    /// What error learning takes the glass to hold, l (`None`: no bound):
    /// the simulated glass's `simulated` unless given, and on a real cell
    /// always given, since a real glass overflows where the simulated one
    /// would not.
    pub fn glass_holds(
        &self,
        simulated: f64,
        instruments: &Option<InstrumentsSpec>,
    ) -> Result<Option<f64>, CliError> {
        match (self.glass_holds, instruments) {
            (Some(Holds::Litres(l)), _) => Ok(Some(l)),
            (Some(Holds::Unbounded), _) => Ok(None),
            (None, None) => Ok(Some(simulated)),
            (None, Some(_)) => Err(CliError::input(
                "--robot: give --glass-holds LITRES, what your glass holds (error learning \
                 then never tries a volume that would overflow it), or --glass-holds none to \
                 search without that bound",
            )),
        }
    }

    /// Whether a real cell is given.
    pub fn robot_given(&self) -> bool {
        self.robot.is_some()
    }

    /// The robot, as given.
    pub fn robot(&self) -> Option<&str> {
        self.robot.as_deref()
    }

    /// Whether the scale or a setting of it is given.
    pub fn scale_given(&self) -> bool {
        self.scale.is_some() || self.baud.is_some() || self.density.is_some() || self.confirm
    }

    /// Whether --glass-holds is given.
    pub fn glass_holds_given(&self) -> bool {
        self.glass_holds.is_some()
    }

    /// The real cell's instruments, if given; the real cell's settings
    /// without it are refused in one line (not clap's usage).
    pub fn instruments(&self) -> Result<Option<InstrumentsSpec>, CliError> {
        let (robot, scale) = match (&self.robot, &self.scale) {
            (Some(robot), Some(scale)) => (robot, scale),
            (Some(_), None) => {
                return Err(CliError::input(
                    "--robot: give --scale too, the scale that weighs what the robot pours",
                ));
            }
            (None, Some(_)) => {
                return Err(CliError::input(
                    "--scale: is for the real cell: give it with --robot (the simulated cell \
                     has its own scale)",
                ));
            }
            (None, None) => {
                let given = [
                    (self.baud.is_some(), "--baud"),
                    (self.density.is_some(), "--density"),
                    (self.confirm, "--confirm"),
                ];
                return match given.iter().find(|(given, _)| *given) {
                    Some((_, flag)) => Err(CliError::input(format!(
                        "{flag}: is for the real cell's scale: give it with --robot and \
                         --scale (the simulated cell pours water)"
                    ))),
                    None => Ok(None),
                };
            }
        };
        Ok(Some(InstrumentsSpec {
            robot: robot.clone(),
            scale: scale.clone(),
            baud: self.baud.unwrap_or(9600),
            density: self
                .density
                .unwrap_or(primo_learn::pour::weigh::Density::WATER.g_per_ml()),
            confirm: self.confirm,
        }))
    }
}

/// Where the learner runs.
#[derive(Debug, Clone, clap::Args)]
pub struct LearnerArgs {
    /// Run the learner on a coprocessor: a serial port (e.g.
    /// /dev/ttyACM0), `qemu` to boot the firmware on an emulated
    /// Cortex-M4F (qemu-system-arm) for the run, or `scale` for primo's
    /// scale of --scale (postcard:PORT or qemu:LOAD_CELL) over its line.
    #[arg(long, value_name = "PORT|qemu|scale")]
    coprocessor: Option<String>,
    /// With --coprocessor qemu: the firmware ELF (default: $PRIMO_FIRMWARE,
    /// else the release build of firmware/ under $CARGO_TARGET_DIR or
    /// firmware/target, or beside primo).
    #[arg(long, requires = "coprocessor", value_name = "ELF")]
    firmware: Option<PathBuf>,
}

impl LearnerArgs {
    /// The learner's place.
    pub fn spec(&self) -> LearnerSpec {
        LearnerSpec {
            coprocessor: self.coprocessor.clone(),
            firmware: self.firmware.clone(),
        }
    }
}

/// `--glass-holds`: a volume, or no bound.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Holds {
    Litres(f64),
    Unbounded,
}

fn glass_holds(text: &str) -> Result<Holds, String> {
    match text.trim() {
        "none" => Ok(Holds::Unbounded),
        v => v
            .parse()
            .map(Holds::Litres)
            .map_err(|_| format!("`{text}`: expected what the glass holds in litres, or `none`")),
    }
}

/// `LOW,HIGH` as two numbers.
fn bounds(text: &str) -> Result<[f32; 2], String> {
    let parsed: Option<Vec<f32>> = text.split(',').map(|v| v.trim().parse().ok()).collect();
    match parsed.as_deref() {
        Some(&[low, high]) => Ok([low, high]),
        _ => Err(format!("`{text}`: expected two volumes LOW,HIGH in litres")),
    }
}

/// Runs `primo pour`.
pub fn run(args: &PourArgs) -> Result<(), CliError> {
    let instruments = args.cell.instruments()?;
    let start = match &args.resume {
        Some(dir) => Start::Resume {
            dir: dir.clone(),
            moved: Resumed {
                instruments,
                max_rollouts: args.max_rollouts,
            },
        },
        None => {
            let method: Algorithm = args.method.into();
            let mut settings = Settings::paper(method, args.bottle, args.target, args.seed);
            settings.precision = args.precision;
            settings.gain = args.gain;
            settings.search = args.search;
            if let Some(n) = args.sampler {
                if !method.is_power() {
                    return Err(CliError::input(format!(
                        "--sampler {n}: PoWER's importance sampler; --method {} is error \
                         learning",
                        method.key()
                    )));
                }
                settings.sampler = n;
            }
            if let Some(n) = args.max_rollouts {
                settings.max_rollouts = n;
            }
            let skill = args.skill.spec(
                primo_learn::pour::skill::Space::default_for(method),
                Glass::Normal,
            )?;
            settings.glass_holds = args
                .cell
                .glass_holds(skill.cell().glass_litres(), &instruments)?;
            Start::New {
                out: args.out.clone(),
                force: args.force,
                run: Pour {
                    settings,
                    skill,
                    cell: instruments.map_or(CellSpec::Simulated, CellSpec::Instruments),
                },
            }
        }
    };
    execute(start, &args.learner.spec(), "pour")
}

/// Runs a pour (`primo pour`, or `primo learn` of the built-in pour task:
/// `command` names which, for the messages).
pub fn execute(start: Start<Pour>, learner: &LearnerSpec, command: &str) -> Result<(), CliError> {
    let dir = start.dir().to_path_buf();
    finish(
        command,
        with_progress(&dir, command, |progress| {
            primo_learn::run::run(start, learner, Box::new(Terminal), |event| {
                show(event, progress)
            })
        }),
    )
}

/// Runs `run` with Ctrl-C caught and a progress bar, cleared at the end.
pub fn with_progress<T>(
    dir: &std::path::Path,
    command: &str,
    run: impl FnOnce(&mut Progress) -> T,
) -> Result<T, CliError> {
    crate::interrupt::install(resume_hint(command, dir))?;
    let mut progress = Progress::new();
    let result = run(&mut progress);
    progress.clear();
    Ok(result)
}

/// The end of a learning run: a failure's message says how to resume.
pub fn finish(
    command: &str,
    result: Result<Result<(), Failure>, CliError>,
) -> Result<(), CliError> {
    match result? {
        Ok(()) => Ok(()),
        Err(failure) => {
            let mut e = CliError::learning(command, *failure.error);
            // Ctrl-C asked the run to stop: however the roll-out in
            // progress then ended (its evaluator timed out), it stopped
            // because the user asked.
            if crate::interrupt::pressed() && e.status == 1 {
                e.status = crate::error::INTERRUPTED;
            }
            if let Some(dir) = failure.resumable
                && e.status != 2
            {
                if e.status == crate::error::CLOSED {
                    // Nobody reads stdout any more: say it where one may.
                    eprintln!(
                        "primo {command}: stdout closed; {}",
                        resume_hint(command, &dir)
                    );
                } else if !e.message.is_empty() {
                    e.message = format!(
                        "{}\nprimo {command}: {}",
                        e.message,
                        resume_hint(command, &dir)
                    );
                }
            }
            Err(e)
        }
    }
}

fn resume_hint(command: &str, dir: &std::path::Path) -> String {
    format!(
        "the run log in {} keeps every roll-out made; continue with `primo {command} --resume {}`",
        dir.display(),
        dir.display()
    )
}

/// The line a run's learner and log events print, if one (a recovered
/// log's note goes to stderr).
pub fn run_line(command: &str, event: RunEvent) -> Option<String> {
    match event {
        RunEvent::Learner(line) => Some(line),
        RunEvent::Recovered(note) => {
            eprintln!("primo {command}: {note}");
            None
        }
        RunEvent::Changed(change) => {
            eprintln!("primo {command}: resuming with {change}");
            None
        }
        RunEvent::SetAside { dir, to } => Some(format!(
            "primo {command}: the run in {} moved aside to {}",
            dir.display(),
            to.display()
        )),
        RunEvent::Resuming {
            dir,
            complete,
            logged,
        } => Some(format!(
            "primo {command}: {} {} after roll-out {logged}",
            if complete {
                "the run is complete: reporting"
            } else {
                "resuming"
            },
            dir.display()
        )),
    }
}

/// Prints what the run reports; a closed stdout or Ctrl-C ends the run.
fn show(event: Event<Pour>, progress: &mut Progress) -> Result<(), Error> {
    let line = match event {
        Event::Run(e) => match run_line("pour", e) {
            Some(line) => line,
            None => return Ok(()),
        },
        Event::Learning {
            run, parameters, ..
        } => {
            let s = &run.settings;
            progress.total = s.max_rollouts.max(1);
            format!(
                "primo pour: {} ({}) from a {} l bottle, target {} l, {:?} space, {parameters} learned parameter(s)",
                s.method,
                s.method.name(),
                s.bottle,
                s.target,
                run.skill.space,
            )
        }
        Event::Note(Note::Converted(c)) => {
            eprintln!("primo pour: {c}");
            return Ok(());
        }
        Event::Note(Note::Cell { spec, scale_serial }) => format!(
            "cell: robot {}, scale {} (serial {scale_serial}){}",
            spec.robot,
            spec.scale,
            if spec.confirm {
                "; the operator resets the cell before every roll-out"
            } else {
                ""
            }
        ),
        Event::Rollout {
            entry,
            logged,
            bounds,
        } => {
            let note = format!("error {:+.1} ml", entry.record.trial.error * 1e3);
            let at = Point::query(&entry.record.query);
            let line = bounded(rollout_line(&entry.record), bounds, &at);
            return show_rollout(progress, &line, logged, entry.record.rollout, &note);
        }
        Event::Finished(f) => {
            let s = &f.settings;
            let verdict = match (s.method, f.converged_at) {
                (m, _) if m.is_power() => "learned".to_string(),
                (_, Some(n)) => format!(
                    "converged to |error| < {} ml in {n} roll-outs",
                    s.precision * 1e3
                ),
                (_, None) => format!("did not reach {} ml: {}", s.precision * 1e3, f.stop),
            };
            let series = match (f.series_of, f.simulated) {
                (Some(n), _) => format!("roll-out {n} (best reward)"),
                (None, false) => "empty (a real cell records no series)".into(),
                (None, true) => "empty (no roll-out was executed)".into(),
            };
            let last = &f.last;
            format!(
                "primo pour: {verdict}; last: q {:.4} l, poured {} ml, spilled {} ml, reward {:.3}; series.csv: {series}; wrote {}",
                last.volume(),
                Fixed(last.trial.poured * 1e3, 1),
                Fixed(last.trial.spilled * 1e3, 1),
                last.trial.reward,
                f.dir.display()
            )
        }
    };
    print(&line)
}

/// A roll-out's line, and if the error learner takes it as a bound of its
/// search, that it does.
pub fn bounded(line: String, bounds: bool, at: &Point) -> String {
    match bounds {
        true => format!("{line}; error learning now searches away from {at}"),
        false => line,
    }
}

/// A roll-out's line (marked when replayed from the log), then the
/// progress bar at roll-out `rollout` with `note`; Ctrl-C ends the run.
pub fn show_rollout(
    progress: &Progress,
    line: &str,
    logged: bool,
    rollout: u32,
    note: &str,
) -> Result<(), Error> {
    progress.clear();
    if logged {
        print(&format!("{line}  (logged)"))?;
    } else {
        print(line)?;
    }
    progress.show(rollout, note);
    if crate::interrupt::pressed() {
        return Err(Error::Interrupted);
    }
    Ok(())
}

/// A line on stdout; a closed stdout is an error that ends the run.
pub fn print(line: &str) -> Result<(), Error> {
    let mut out = std::io::stdout().lock();
    writeln!(out, "{line}")
        .and_then(|()| out.flush())
        .map_err(Error::io("stdout"))
}

/// The operator at the terminal: prompts on stdout, answers on stdin.
struct Terminal;

impl Operator for Terminal {
    fn reset(&mut self, rollout: u32, bottle: f64) -> Result<(), Error> {
        print(&format!(
            "roll-out {rollout}: reset the cell (the bottle filled to {bottle} l, the glass on the \
             scale emptied), then press Enter"
        ))?;
        let mut line = String::new();
        match std::io::stdin().lock().read_line(&mut line) {
            Ok(0) => Err(Error::Instrument(
                "the operator's input closed before the cell was reset".into(),
            )),
            Ok(_) => Ok(()),
            Err(e) => Err(Error::Instrument(format!(
                "reading the operator's answer: {e}"
            ))),
        }
    }

    fn warn(&mut self, rollout: u32, message: &str) {
        eprintln!("primo pour: roll-out {rollout}: {message}");
    }
}
