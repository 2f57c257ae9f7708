//! primo on the host: file formats and the `primo` command line.
//!
//! - [`csv`]: demonstration and trajectory CSV files (`t,<DoF names>`).
//! - [`dmpfile`]: the versioned JSON format of a fitted DMP.
//! - [`cli`]: the `primo` commands.
//! - [`coprocessor`]: the learning coprocessor over a serial port, and the
//!   firmware booted in QEMU.
//! - [`sim`]: the simulated pouring cell.
//! - [`plot`]: PNG charts (learning curves).
//! - [`skill`]: demonstrations → DMPs → generalization → checked roll-outs.
//! - [`pour`]: the learners driving the skill's roll-outs.
//! - [`experiment`]: the paper's experiments, runs spread over all cores.
//! - [`fri`]: the KUKA LWR4 over FRI (UDP), and a simulated KRC.
//! - [`report`]: roll-out tables, summaries and charts.
//! - [`rig`]: where roll-outs happen: the simulated cell or the real instruments.
//! - [`run`]: a `primo pour` run: its header, log, resumption and reports.
//! - [`runlog`]: the durable log of a learning run, and its recovery.
//! - [`mtsics`]: MT-SICS precision scales: client, simulated device, `primo scale`.
//! - [`series`]: a roll-out's time series and its CSV.
//! - [`safety`]: the limit checks every trajectory passes before it moves anything.
#![deny(missing_docs)]

pub mod cli;
pub mod coprocessor;
pub mod csv;
pub mod dmpfile;
mod error;
pub mod experiment;
pub mod fri;
pub mod mtsics;
pub mod plot;
pub mod pour;
pub mod report;
pub mod rig;
pub mod run;
pub mod runlog;
pub mod safety;
pub mod series;
pub mod sim;
pub mod skill;

pub use error::{CliError, write_atomically};

/// Largest DoF count the host's DMPs hold.
pub const MAX_DOF: usize = 16;
/// Largest kernel count per DoF the host's DMPs hold.
pub const MAX_KERNELS: usize = 128;
/// The DMP type the host uses for files and commands.
pub type HostDmp = primo_core::dmp::Dmp<MAX_DOF, MAX_KERNELS>;
