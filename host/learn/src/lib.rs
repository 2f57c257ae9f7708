//! primo's learning library: the skill's roll-outs on a rig, the learners
//! driving them, and everything a run keeps and reports. It prints nothing
//! and knows no command line: the `primo` binary (`primo-cli`) does.
//!
//! The generic layers know no task:
//!
//! - [`run`]: one learning run for every kind of task: start or resume,
//!   the learner, the log, the loop, the report.
//! - [`rollouts`]: the roll-out loop (ask, roll out, tell) and the record
//!   of each roll-out.
//! - [`learner`]: the learner (in this process or on a coprocessor) and
//!   its setup; [`algorithm`]: the learning algorithms.
//! - [`runlog`]: the durable log of a run, and its recovery; [`lock`]:
//!   an output directory held by one process at a time.
//! - [`coprocessor`]: primo's devices (the learning coprocessor, the
//!   load-cell scale) over a serial port, and their firmware booted in QEMU.
//! - [`output`], [`plot`], [`stats`]: result files written safely, PNG
//!   charts, medians and bootstrap intervals.
//!
//! The kinds of task, and what is built on them:
//!
//! - [`pour`]: the built-in pouring task: its settings, skill, cells
//!   (simulated, real), scales, reports.
//! - [`task`]: a task file: its schema and checks, its evaluators, its
//!   run and reports.
//! - [`experiment`]: the paper's experiments on the simulated cell.
#![deny(missing_docs)]

pub mod algorithm;
pub mod clock;
pub mod coprocessor;
mod error;
pub mod experiment;
pub mod learner;
pub mod lock;
pub mod output;
pub mod plot;
pub mod pour;
pub mod rollouts;
pub mod run;
pub mod runlog;
pub mod stats;
pub mod task;

pub use error::{Error, Setting};
