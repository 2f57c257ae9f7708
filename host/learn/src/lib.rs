//! primo's learning library: the skill's roll-outs on a rig, the learners
//! driving them, and everything a run keeps and reports. It prints nothing
//! and knows no command line: the `primo` binary (`primo-cli`) does.
//!
//! - [`learning`]: the learning loop, the learner (in this process or on a
//!   coprocessor), and its settings.
//! - [`rig`]: where roll-outs happen (the simulated cell, the real
//!   instruments) and the one path every roll-out takes.
//! - [`objective`]: the simulated cell as an objective for any optimizer
//!   (`primo rollout`, the Python package).
//! - [`trial`]: what a roll-out measured, and its score.
//! - [`pouring`]: the built-in pouring task: its gate, its demonstrations.
//! - [`pour`]: a `primo pour` run: its header, log, resumption, reports.
//! - [`runlog`]: the durable log of a learning run, and its recovery.
//! - [`coprocessor`]: primo's devices (the learning coprocessor, the
//!   load-cell scale) over a serial port, and their firmware booted in QEMU.
//! - [`weigh`]: the scales a real cell weighs with: MT-SICS, or primo's.
//! - [`experiment`]: the paper's experiments, runs spread over all cores.
//! - [`report`]: roll-out tables, summaries and charts.
//! - [`series`]: a roll-out's time series and its CSV.
//! - [`plot`]: PNG charts.
//! - [`stats`]: medians, means and bootstrap intervals over seeded runs.
//! - [`output`]: writing result files safely.
#![deny(missing_docs)]

pub mod coprocessor;
mod error;
pub mod evaluator;
pub mod experiment;
pub mod learning;
pub mod objective;
pub mod output;
pub mod plot;
pub mod pour;
pub mod pouring;
pub mod report;
pub mod rig;
pub mod runlog;
pub mod series;
pub mod stats;
pub mod task;
pub mod teach;
pub mod trial;
pub mod weigh;

pub use error::Error;
