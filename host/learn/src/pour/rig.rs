//! Where roll-outs happen: the simulated cell in this process, or the real
//! instruments (a KUKA LWR4 over FRI and an MT-SICS scale) of a pouring
//! cell. The learning loop does not know which: every roll-out takes one
//! path ([`roll_out`]): plan, check once, execute the checked joint path,
//! measure, score once.

use std::net::UdpSocket;
use std::time::Duration;

use primo_fri::parse_robot;
use primo_fri::path::FriPath;
use primo_fri::session::SessionConfig;
use primo_fri::udp::{Ended, Event, PlayConfig, bind, play};
use primo_robot::{Gate, JointPath};
use primo_sim::cell::{Cell, CellConfig};
use primo_skill::{Plan, Skill};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::coprocessor::Link;
use crate::error::Setting;

use super::series::Series;
use super::skill::{Space, gate};
use super::trial::{Measured, Readings, Trial};
use super::weigh::{ScaleSpec, Weigher};

/// Standard gravity, m/s².
const G: f64 = 9.80665;

/// Executes checked movements and measures what they did.
pub trait Rig {
    /// The gate every movement passes before it is executed here.
    fn gate(&self) -> &Gate;
    /// The control step movements are planned at, s.
    fn dt(&self) -> f64;
    /// Executes roll-out number `rollout` (from 1): `path` is the checked
    /// joint path of `plan`. An error means the roll-out could not be made
    /// or measured (an instrument failed) and the run must stop.
    fn execute(&mut self, rollout: u32, plan: &Plan, path: &JointPath) -> Result<Measured, Error>;
}

/// Roll-out `rollout` of `θ = G(query) + Δθ` on `rig`, pouring toward
/// `target` litres: planned, checked by the rig's gate (a rejected movement
/// moves nothing and scores 0), executed, measured, scored.
pub fn roll_out(
    rig: &mut dyn Rig,
    skill: &Skill,
    target: f64,
    rollout: u32,
    query: &[f32],
    delta: &[f32],
) -> Result<Trial, Error> {
    match skill.checked(rig.gate(), rig.dt(), query, delta) {
        Ok((plan, path)) => Ok(Trial::scored(target, rig.execute(rollout, &plan, &path)?)),
        Err(why) => Ok(Trial::rejected(target, why.to_string())),
    }
}

/// The scale's noise seed of roll-out `rollout` (numbered from 1) of a
/// learning run seeded `seed`: a pure function, so a roll-out can be
/// repeated outside the run (the Python package's `Cell.pour_seed`).
pub fn rollout_seed(seed: u64, rollout: u32) -> u64 {
    seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ u64::from(rollout)
}

/// The simulated cell: every roll-out starts from a full bottle and an
/// empty glass, the scale's noise seeded per roll-out, so a run is a pure
/// function of its settings and seed.
#[derive(Debug, Clone)]
pub struct Simulated {
    cell: CellConfig,
    gate: Gate,
    bottle: f64,
    seed: u64,
}

impl Simulated {
    /// The cell `cell` with `bottle` litres in the bottle at every
    /// roll-out; `seed` is the run's.
    pub fn new(cell: CellConfig, bottle: f64, seed: u64) -> Result<Simulated, Error> {
        cell.validate()?;
        Ok(Simulated {
            gate: gate(&cell),
            cell,
            bottle,
            seed,
        })
    }

    /// The same cell recording its time series every `every` control
    /// steps (0: none).
    pub fn recording(&self, every: usize) -> Simulated {
        let mut rig = self.clone();
        rig.cell.record_every = every;
        rig
    }

    /// What the simulated glass holds to its rim, l.
    pub fn glass_litres(&self) -> f64 {
        self.cell.glass_litres()
    }

    /// Executes `path` with the scale's noise from `noise`.
    pub fn execute_seeded(
        &self,
        plan: &Plan,
        path: &JointPath,
        noise: u64,
    ) -> Result<Measured, Error> {
        let mut sim = Cell::new(&self.cell, self.bottle, noise)?;
        for q in path.rows() {
            let q = q.try_into().map_err(|_| {
                Error::Invalid(format!(
                    "the simulated cell's arm is an LWR 4 of 7 joints, the path's {} has {}",
                    path.chain().robot,
                    q.len()
                ))
            })?;
            sim.step_joints(&q);
        }
        let out = sim.finish();
        let recorded = !out.series.is_empty();
        let space = Space::of(&plan.names)
            .ok_or_else(|| Error::Invalid("the pouring cell runs pouring movements only".into()))?;
        Ok(Measured {
            poured: out.poured,
            spilled: out.spilled,
            series: recorded.then(|| {
                Series::new(
                    space,
                    &plan.rows,
                    plan.dof,
                    self.cell.record_every,
                    out.series,
                )
            }),
            readings: None,
        })
    }
}

impl Rig for Simulated {
    fn gate(&self) -> &Gate {
        &self.gate
    }

    fn dt(&self) -> f64 {
        self.cell.dt
    }

    fn execute(&mut self, rollout: u32, plan: &Plan, path: &JointPath) -> Result<Measured, Error> {
        self.execute_seeded(plan, path, rollout_seed(self.seed, rollout))
    }
}

/// A real cell (in a run log's header): where its instruments are.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InstrumentsSpec {
    /// `fri:ADDR[:PORT]`: the local UDP address the KRC sends to.
    pub robot: String,
    /// The scale: an MT-SICS scale's serial port, or primo's scale
    /// (`postcard:PORT`, `qemu:LOAD_CELL`; see [`ScaleSpec`]).
    pub scale: String,
    /// An MT-SICS scale's baud rate.
    pub baud: u32,
    /// The liquid's density, g/ml.
    pub density: f64,
    /// Ask the operator to reset the cell before every roll-out.
    pub confirm: bool,
}

impl InstrumentsSpec {
    /// Checks the settings without touching an instrument.
    pub fn validate(&self) -> Result<(), Error> {
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(Error::setting(
                Setting::Density,
                self.density,
                "must be a positive number of g/ml",
            ));
        }
        if self.baud == 0 {
            return Err(Error::setting(Setting::Baud, 0, "must be a positive rate"));
        }
        parse_robot(&self.robot)?;
        ScaleSpec::parse(&self.scale)?;
        Ok(())
    }
}

/// The person at a real cell.
pub trait Operator {
    /// Asks them to reset the cell before roll-out `rollout` (the bottle
    /// filled to `bottle` litres, the glass emptied) and waits until they
    /// have.
    fn reset(&mut self, rollout: u32, bottle: f64) -> Result<(), Error>;
    /// Tells them something they should know about roll-out `rollout`.
    fn warn(&mut self, rollout: u32, message: &str);
}

/// How long the arm stands still before and after the movement while the
/// force at the tool is averaged, s: the estimate's noise (0.3 N per axis
/// on the simulated KRC, 250 cycles of 4 ms) averages to about 2 ml of
/// water.
const HOLD: f64 = 1.0;

/// How long to wait for a stable scale reading before giving up.
const SETTLE_LIMIT: Duration = Duration::from_secs(120);

/// A real pouring cell: a KUKA LWR4 over FRI and a scale (MT-SICS, or
/// primo's).
///
/// A roll-out: the operator resets the cell if asked to confirm; the
/// scale's stable weight is read; the checked joint path is streamed over
/// FRI (approach, movement, hold); the stable weight is read again. The
/// poured volume is the weight's increase over the density; the spill is,
/// as in the paper, the bottle's loss, estimated from the robot's external
/// force at the tool standing still before and after, minus the poured
/// volume.
pub struct Instruments {
    spec: InstrumentsSpec,
    gate: Gate,
    dt: f64,
    bottle: f64,
    socket: UdpSocket,
    scale: Weigher,
    play: PlayConfig,
    operator: Box<dyn Operator>,
    /// The operator was told the FRI loop is not real-time (once a run).
    warned_realtime: bool,
}

impl Instruments {
    /// Binds the robot's address and opens the scale; `cell` is the cell's
    /// geometry for the checks. The operator answers through `operator`.
    pub fn open(
        spec: InstrumentsSpec,
        cell: &CellConfig,
        bottle: f64,
        operator: Box<dyn Operator>,
    ) -> Result<Instruments, Error> {
        spec.validate()?;
        let socket = bind(parse_robot(&spec.robot)?)?;
        // The liquid in the glass may still be moving: SETTLE_LIMIT.
        let scale = Weigher::open(&ScaleSpec::parse(&spec.scale)?, spec.baud, SETTLE_LIMIT)?;
        Ok(Instruments {
            spec,
            gate: gate(cell),
            dt: cell.dt,
            bottle,
            socket,
            scale,
            play: PlayConfig {
                session: SessionConfig {
                    weigh: HOLD,
                    settle: HOLD,
                    ..SessionConfig::default()
                },
                ..PlayConfig::default()
            },
            operator,
            warned_realtime: false,
        })
    }

    /// The scale's serial number.
    pub fn scale_serial(&self) -> String {
        self.scale.serial()
    }

    /// The line to primo's scale, which can run the learner too.
    pub fn scale_link(&self) -> Option<Link> {
        self.scale.link()
    }

    /// The stable weight, g (waited for up to [`SETTLE_LIMIT`]).
    fn weigh(&mut self) -> Result<f64, Error> {
        self.scale.stable_grams()
    }
}

impl Rig for Instruments {
    fn gate(&self) -> &Gate {
        &self.gate
    }

    fn dt(&self) -> f64 {
        self.dt
    }

    fn execute(&mut self, rollout: u32, _: &Plan, path: &JointPath) -> Result<Measured, Error> {
        if self.spec.confirm {
            self.operator.reset(rollout, self.bottle)?;
        }
        let before = self.weigh()?;
        let mut slow = None;
        let path = FriPath::try_from(path).map_err(|e| Error::Invalid(e.to_string()))?;
        let played = play(&self.socket, &path, &self.play, &mut |event| {
            if let Event::Realtime(granted) = event
                && !granted.is_full()
            {
                slow = Some(granted);
            }
        })?;
        if let Some(granted) = slow.filter(|_| !self.warned_realtime) {
            self.warned_realtime = true;
            self.operator.warn(
                rollout,
                &format!("FRI loop: {granted}: answers may be late on a busy machine"),
            );
        }
        if played.ended != Ended::Completed {
            return Err(Error::RobotStopped(format!(
                "roll-out {rollout} on the robot: {}; the cell may need a reset",
                played.ended
            )));
        }
        // The first stable weight of the glass after the pour, never the
        // one before its last drops.
        let after = self.scale.next_stable_grams()?;
        let poured = (after - before) / self.spec.density * 1e-3;
        let load = played.load;
        if load.is_none() {
            self.operator.warn(
                rollout,
                "the robot stood still too briefly to weigh the bottle; its spill counts as 0",
            );
        }
        // The bottle's loss: its liquid's weight, before minus after.
        let spilled = load.map_or(0.0, |[b, a]| {
            ((b - a) / G / self.spec.density - poured).max(0.0)
        });
        Ok(Measured {
            poured,
            spilled,
            series: None,
            readings: Some(Readings {
                scale: [before, after],
                load,
            }),
        })
    }
}
