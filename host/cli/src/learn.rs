//! `primo learn`: learn the skill a task file describes (the book's task
//! file reference, docs/src/reference/task-file.md), with the lab's
//! evaluator, the operator, or the built-in pouring cell.

use std::io::{BufRead, Write};
use std::path::PathBuf;

use primo_learn::Error;
use primo_learn::pour::run::{CellSpec, Pour, Resumed};
use primo_learn::rollouts::{Stop, query_text};
use primo_learn::run::{Event, Start, logged_kind};
use primo_learn::task::change::Changes;
use primo_learn::task::evaluator::Prompt;
use primo_learn::task::goals::point;
use primo_learn::task::run::{Robot, TaskCell, TaskRun, rollout_line};
use primo_learn::task::{Evaluate, Task};

use crate::error::CliError;
use crate::pour::{
    CellArgs, LearnerArgs, bounded, execute, finish, print, run_line, show_rollout, with_progress,
};
use crate::progress::Progress;

/// `primo learn` options.
#[derive(Debug, clap::Args)]
pub struct LearnArgs {
    /// The task file (TOML: demonstrations, query, limits, learner,
    /// evaluator; the book's task file reference, docs/src/reference/task-file.md).
    #[arg(long, value_name = "TASK.toml", required_unless_present = "resume")]
    task: Option<PathBuf>,
    /// Output directory: run.log (every roll-out, appended as it is made),
    /// trajectories/ (each roll-out's checked trajectory), and at the end
    /// rollouts.csv, summary.json and convergence.png.
    #[arg(long, default_value = "learn-out")]
    out: PathBuf,
    /// Seed of exploration.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Roll-out budget (default: `max_rollouts` in the task's `[learner]`).
    #[arg(long)]
    max_rollouts: Option<u32>,
    /// Start anew in --out though a run is logged there: the earlier run's
    /// directory is moved aside to OUT.replaced-TIME, nothing is deleted.
    #[arg(long)]
    force: bool,
    /// Continue the run logged in DIR: its task and settings come from the
    /// log, and no roll-out is lost or repeated. With --task, the task file
    /// as it is now may change the `[goal]` low/high bounds, `[learner]`
    /// max_rollouts and `[evaluate]` (each change is said, and kept in the
    /// log); with --max-rollouts, the budget (a run that used up its
    /// budget goes on).
    #[arg(long, value_name = "DIR", conflicts_with_all = ["out", "seed", "force"])]
    resume: Option<PathBuf>,
    #[command(flatten)]
    learner: LearnerArgs,
    /// For the built-in pour task only.
    #[command(flatten)]
    cell: CellArgs,
}

/// Runs `primo learn`.
pub fn run(args: &LearnArgs) -> Result<(), CliError> {
    // A ROS 2 controller or a Franka executes a task file's roll-outs; the
    // built-in pour's real cell is FRI and a scale.
    let executes = args
        .cell
        .robot()
        .is_some_and(|r| r.starts_with("ros2:") || r.starts_with("franka:"));
    let not_the_pour = || {
        CliError::input(
            "--robot ros2:/CONTROLLER or franka:ADDR: executes a task file's roll-outs; the \
             built-in pour's real cell is --robot fri:ADDR with --scale",
        )
    };
    let instruments = if executes {
        None
    } else {
        args.cell.instruments()?
    };
    let learner = args.learner.spec();
    if args.max_rollouts == Some(0) {
        return Err(CliError::input("--max-rollouts 0: must be at least 1"));
    }
    let robot;
    let start = match (&args.resume, &args.task) {
        (Some(dir), task) => match logged_kind(dir).map_err(|e| CliError::learning("learn", e))? {
            kind if kind == "pour" => {
                if executes {
                    return Err(not_the_pour());
                }
                if task.is_some() || args.cell.glass_holds_given() {
                    return Err(CliError::input(format!(
                        "--resume {}: the run is the built-in pour, its settings all in its \
                         log (--glass-holds among them): --task changes a task file's run",
                        dir.display()
                    )));
                }
                let start = Start::<Pour>::Resume {
                    dir: dir.clone(),
                    moved: Resumed {
                        instruments,
                        max_rollouts: args.max_rollouts,
                    },
                };
                return execute(start, &learner, "learn");
            }
            _ => {
                robot = task_robot(&args.cell)?;
                Start::Resume {
                    dir: dir.clone(),
                    moved: Changes {
                        task: task.as_deref().map(Task::load).transpose()?,
                        max_rollouts: args.max_rollouts,
                    },
                }
            }
        },
        (None, Some(file)) => {
            let mut task = Task::load(file)?;
            if let Some(n) = args.max_rollouts {
                task.learner.max_rollouts = n;
            }
            if let Some(mut start) = task.pour_start(args.out.clone(), args.force, args.seed) {
                if executes {
                    return Err(not_the_pour());
                }
                if let Start::New { run, .. } = &mut start {
                    run.settings.glass_holds = args
                        .cell
                        .glass_holds(run.skill.cell().glass_litres(), &instruments)?;
                    if let Some(spec) = instruments {
                        run.cell = CellSpec::Instruments(spec);
                    }
                }
                return execute(start, &learner, "learn");
            }
            robot = task_robot(&args.cell)?;
            Start::New {
                out: args.out.clone(),
                force: args.force,
                run: TaskRun {
                    task,
                    seed: args.seed,
                    robot: robot.as_ref().map(|(name, _)| name.clone()),
                },
            }
        }
        (None, None) => return Err(CliError::input("give --task TASK.toml or --resume DIR")),
    };
    let dir = start.dir().to_path_buf();
    finish(
        "learn",
        with_progress(&dir, "learn", |progress| {
            let cell = TaskCell {
                prompt: Box::new(Terminal),
                robot,
            };
            primo_learn::run::run(start, &learner, cell, |event| show(event, progress))
        }),
    )
}

/// The robot that executes a task's roll-outs (`--robot ros2:/CONTROLLER`
/// or `franka:ADDR[:PORT]`), if given; the built-in pour's cell is refused.
fn task_robot(cell: &CellArgs) -> Result<Option<Robot>, CliError> {
    let executes = |r: &&str| r.starts_with("ros2:") || r.starts_with("franka:");
    let Some(robot) = cell.robot().filter(executes) else {
        refuse_cell(cell)?;
        return Ok(None);
    };
    if cell.scale_given() || cell.glass_holds_given() {
        return Err(CliError::input(
            "--scale/--glass-holds: are the built-in pour's real cell; with a task file, the \
             task's evaluator measures what the robot did",
        ));
    }
    let executor = match robot.starts_with("franka:") {
        true => crate::franka::executor(robot)?,
        false => crate::robot_ros2::executor(robot)?,
    };
    Ok(Some((robot.to_string(), executor)))
}

/// --robot, --scale and --glass-holds are the built-in pour's cell.
fn refuse_cell(cell: &CellArgs) -> Result<(), CliError> {
    if cell.robot_given() {
        return Err(CliError::input(
            "--robot/--scale: the task's own evaluator executes its roll-outs (or a ROS 2 \
             controller, --robot ros2:/CONTROLLER, or a Franka, --robot franka:ADDR); the real \
             cell's instruments are for the built-in pour (builtin = \"pour\")",
        ));
    }
    if cell.glass_holds_given() {
        return Err(CliError::input(
            "--glass-holds: bounds the built-in pour's search (builtin = \"pour\"); the \
             task's own search is its [goal] low and high",
        ));
    }
    Ok(())
}

/// Prints what the run reports; a closed stdout or Ctrl-C ends the run.
fn show(event: Event<TaskRun>, progress: &mut Progress) -> Result<(), Error> {
    let line = match event {
        Event::Run(e) => match run_line("learn", e) {
            Some(line) => line,
            None => return Ok(()),
        },
        Event::Note(never) => match never {},
        Event::Learning {
            run,
            built,
            parameters,
        } => {
            let task = &run.task;
            progress.total = task.learner.max_rollouts.max(1);
            let evaluator = match &task.evaluate {
                Evaluate::Command { argv, .. } => format!("evaluator `{}`", argv.join(" ")),
                Evaluate::Operator => "the operator evaluates".into(),
                Evaluate::Pour(_) => "the built-in pouring cell".into(),
            };
            // The columns found on the skill: the task file may name none.
            let goals = match built.goals.as_ref().map(|g| &g.columns[..]) {
                None => String::new(),
                Some([column]) => format!(", the goal of {column}"),
                Some(columns) => format!(", the goals of {}", columns.join(", ")),
            };
            format!(
                "primo learn: {} ({}) toward q = {}{goals}, {} demonstrations, {parameters} \
                 learned parameter(s), {evaluator}",
                task.learner.method,
                task.learner.method.name(),
                query_text(&task.goal.desired),
                task.demos.len(),
            )
        }
        Event::Rollout {
            entry,
            logged,
            bounds,
        } => {
            let note = format!("reward {:.3}", entry.record.trial.reward);
            let line = bounded(rollout_line(&entry.record), bounds, &point(&entry.record));
            return show_rollout(progress, &line, logged, entry.record.rollout, &note);
        }
        Event::Finished(f) => {
            let best = match &f.best {
                Some(b) => format!("best roll-out {} (reward {:.3})", b.rollout, b.trial.reward),
                None => "no roll-out could be made".into(),
            };
            let verdict = match (f.converged_at, &f.stop) {
                (Some(n), _) => format!("reached the precision in {n} roll-outs"),
                (None, Stop::Learned) => best,
                (None, stop) => format!("did not reach the precision: {stop}; {best}"),
            };
            format!(
                "primo learn: {verdict}; last: {}; wrote {}",
                rollout_line(&f.last),
                f.dir.display()
            )
        }
    };
    print(&line)
}

/// The operator at the terminal: questions on stdout, answers on stdin.
struct Terminal;

impl Prompt for Terminal {
    fn ask(&mut self, question: &str) -> Result<Option<String>, Error> {
        let mut out = std::io::stdout().lock();
        write!(out, "{question}")
            .and_then(|()| out.flush())
            .map_err(Error::io("stdout"))?;
        let mut line = String::new();
        match std::io::stdin().lock().read_line(&mut line) {
            Ok(0) => Ok(None),
            Ok(_) => Ok(Some(line)),
            Err(e) => Err(Error::Instrument(format!(
                "reading the operator's answer: {e}"
            ))),
        }
    }
}
