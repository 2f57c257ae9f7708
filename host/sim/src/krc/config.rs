//! What the simulated KRC does ([`KrcConfig`]) and the cell it drives,
//! shared with the other simulated instruments ([`CellHandle`]).

use std::net::SocketAddr;
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::Duration;

use primo_robot::JOINTS;

use crate::Error;
use crate::cell::{Cell, CellConfig, GlassKind, MAX_DT};
use crate::scale_device::LoadSource;

/// What the simulated KRC does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KrcConfig {
    /// Where the remote listens (primo's `fri:ADDR:PORT`).
    pub remote: SocketAddr,
    /// The FRI cycle, 1–10 ms.
    pub cycle: Duration,
    /// The arm's joint angles at power-on, rad.
    pub start: [f64; JOINTS],
    /// Liquid in the bottle, l.
    pub bottle: f64,
    /// The glass on the scale.
    pub glass: GlassKind,
    /// Fraction of measurement packets lost on the way to the remote.
    pub drop: f64,
    /// Seed of the losses and of the scale's noise.
    pub seed: u64,
    /// From this time on the quality is BAD.
    pub quality_drop_at: Option<Duration>,
    /// Never switch to command mode.
    pub monitor_only: bool,
    /// Stop sending (and return) at this time.
    pub stop_after: Option<Duration>,
    /// Return when a command session ends (the remote fell silent).
    pub once: bool,
    /// Silence in command mode before falling back to monitor mode.
    pub release_after: Duration,
    /// Answer rates (over [`STAT_WINDOW`](super::STAT_WINDOW) cycles) for the qualities BAD,
    /// OK and PERFECT; below the first it is UNACCEPTABLE. A real KRC's
    /// thresholds are configured too.
    pub thresholds: [f64; 3],
    /// Keep a [`CycleRecord`](super::CycleRecord) of every cycle in the report.
    pub record: bool,
}

impl KrcConfig {
    /// A 2 ms KRC sending to `remote`: the arm at the pouring rest
    /// posture, 0.5 l in the bottle, the normal glass, no faults, falling
    /// back to monitor mode after 0.5 s of silence, quality OK from 80 %
    /// answers on time, PERFECT from 98 %.
    pub fn new(remote: SocketAddr) -> Self {
        KrcConfig {
            remote,
            cycle: Duration::from_millis(2),
            start: crate::expert::rest_configuration(0.0),
            bottle: 0.5,
            glass: GlassKind::Normal,
            drop: 0.0,
            seed: 1,
            quality_drop_at: None,
            monitor_only: false,
            stop_after: None,
            once: false,
            release_after: Duration::from_millis(500),
            thresholds: [0.5, 0.8, 0.98],
            record: false,
        }
    }

    /// Refuses a cycle, loss, start, thresholds or release time out of range.
    pub(super) fn validate(&self) -> Result<(), Error> {
        let ms = self.cycle.as_secs_f64() * 1e3;
        if !(1.0..=10.0).contains(&ms) {
            return Err(Error::Invalid(format!(
                "FRI cycle {ms} ms: must be 1 to 10 ms"
            )));
        }
        if !(0.0..1.0).contains(&self.drop) {
            return Err(Error::Invalid(format!(
                "packet loss {}: must be a fraction in [0, 1)",
                self.drop
            )));
        }
        if let Err(v) = primo_robot::Robot::lwr4()
            .chain()
            .check_samples([(0.0, &self.start[..])])
        {
            return Err(Error::Invalid(format!("start position: {v}")));
        }
        let [bad, ok, perfect] = self.thresholds;
        if !(0.0 <= bad && bad <= ok && ok <= perfect && perfect <= 1.0) {
            return Err(Error::Invalid(format!(
                "quality thresholds {:?}: must rise within [0, 1]",
                self.thresholds
            )));
        }
        if self.release_after < self.cycle {
            return Err(Error::Invalid(
                "release time must be at least one cycle".into(),
            ));
        }
        Ok(())
    }

    /// The cell the arm pours in: the standard one with `glass`, stepped
    /// in equal steps of at most [`MAX_DT`] within each cycle.
    pub fn cell_config(&self) -> CellConfig {
        let cycle = self.cycle.as_secs_f64();
        let mut cell = CellConfig::standard(self.glass);
        cell.dt = cycle / (cycle / MAX_DT).ceil().max(1.0);
        cell
    }

    /// The cell at power-on, and after an operator's reset: `bottle`
    /// litres in the bottle, an empty glass on the tared scale, the
    /// scale's noise from `seed`.
    pub fn fresh_cell(&self) -> Result<Cell, Error> {
        Cell::new(&self.cell_config(), self.bottle, self.seed)
    }
}

/// The simulated cell, shared with other instruments of the process.
#[derive(Debug, Clone)]
pub struct CellHandle(Arc<Mutex<Cell>>);

impl CellHandle {
    pub(super) fn new(cell: Cell) -> Self {
        CellHandle(Arc::new(Mutex::new(cell)))
    }

    /// The cell, for as long as the guard lives (the KRC waits for it).
    pub fn lock(&self) -> MutexGuard<'_, Cell> {
        // A panic elsewhere while holding the lock leaves a consistent
        // cell (every step completes before it returns): carry on.
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A scale under the cell's glass weighs what is on the pan.
impl LoadSource for CellHandle {
    fn grams(&self) -> f64 {
        self.lock().load_on_pan()
    }
}
