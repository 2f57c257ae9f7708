//! Where roll-outs happen: the simulated cell in this process, or the real
//! instruments (a KUKA LWR4 over FRI and an MT-SICS scale) of a pouring
//! cell. The learners of [`crate::pour`] do not know which.

use std::io::BufRead;
use std::net::UdpSocket;
use std::time::{Duration, Instant};

use serde::{Deserialize, Serialize};

use crate::fri::client::{Ended, PlayConfig, SessionConfig, bind, play};
use crate::fri::parse_robot;
use crate::mtsics::{ClientConfig, ErrorKind, Scale};
use crate::sim::cell::CellConfig;
use crate::skill::{Skill, Trial, reward};

/// Standard gravity, m/s².
const G: f64 = 9.80665;

/// Executes roll-outs of a skill.
pub trait Rig {
    /// Rolls out roll-out number `rollout` (from 1): the movement
    /// `θ = G(query) + Δθ`. A movement the safety checks reject is a
    /// [`Trial`] with `rejected` set; an error means the roll-out could not
    /// be made or measured (an instrument failed) and the run must stop.
    fn roll_out(
        &mut self,
        skill: &Skill,
        rollout: u32,
        query: f32,
        delta: &[f32],
    ) -> Result<Trial, String>;
}

/// The simulated cell: every roll-out starts from a full bottle and an
/// empty glass, the scale's noise seeded per roll-out, so a run is a pure
/// function of its settings and seed.
#[derive(Debug, Clone)]
pub struct Simulated {
    /// The cell.
    pub cell: CellConfig,
    /// Liquid in the bottle, l.
    pub bottle: f64,
    /// Volume to pour, l.
    pub target: f64,
    /// The run's seed.
    pub seed: u64,
}

impl Simulated {
    /// The scale's noise seed for roll-out `i`.
    fn trial_seed(&self, i: u32) -> u64 {
        self.seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) ^ u64::from(i)
    }

    /// Roll-out `i` again, recording its time series (`series.csv`): the
    /// same trial as during the run.
    pub fn replay(
        &self,
        skill: &Skill,
        rollout: u32,
        query: f32,
        delta: &[f32],
    ) -> Result<Trial, String> {
        let mut recording = self.clone();
        recording.cell.record_every = 1;
        recording.roll_out(skill, rollout, query, delta)
    }
}

impl Rig for Simulated {
    fn roll_out(
        &mut self,
        skill: &Skill,
        rollout: u32,
        query: f32,
        delta: &[f32],
    ) -> Result<Trial, String> {
        skill.roll_out(
            &self.cell,
            self.bottle,
            self.target,
            query,
            delta,
            self.trial_seed(rollout),
        )
    }
}

/// What the instruments read around a roll-out on a real cell.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Readings {
    /// Stable scale weight before and after, g.
    pub scale: [f64; 2],
    /// The robot's estimated external force at the tool (the liquid in the
    /// bottle) standing still before and after, N; `None` if the robot
    /// reported too few still measurements.
    pub load: Option<[f64; 2]>,
}

/// A real cell (in a run log's header): where its instruments are.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct InstrumentsSpec {
    /// `fri:ADDR[:PORT]`: the local UDP address the KRC sends to.
    pub robot: String,
    /// The MT-SICS scale's serial port.
    pub scale: String,
    /// Its baud rate.
    pub baud: u32,
    /// The liquid's density, g/ml.
    pub density: f64,
    /// Ask the operator to reset the cell before every roll-out.
    pub confirm: bool,
}

/// How long the arm stands still before and after the movement while the
/// force at the tool is averaged, s: the estimate's noise (0.3 N per axis
/// on the simulated KRC, 250 cycles of 4 ms) averages to about 2 ml of
/// water.
const HOLD: f64 = 1.0;

/// How long to wait for a stable scale reading before giving up.
const SETTLE_LIMIT: Duration = Duration::from_secs(120);

/// A real pouring cell: a KUKA LWR4 over FRI and an MT-SICS scale.
///
/// A roll-out: the movement is planned and passes the safety checks (a
/// rejected one moves nothing); the operator resets the cell if asked to
/// confirm; the scale's stable weight is read; the joint trajectory is
/// streamed over FRI (approach, movement, hold); the stable weight is read
/// again. The poured volume is the weight's increase over the density;
/// the spill is, as in the paper, the bottle's loss, estimated from the
/// robot's external force at the tool standing still before and after,
/// minus the poured volume.
pub struct Instruments {
    spec: InstrumentsSpec,
    cell: CellConfig,
    bottle: f64,
    target: f64,
    socket: UdpSocket,
    scale: Scale,
    play: PlayConfig,
    operator: Box<dyn BufRead>,
}

impl Instruments {
    /// Binds the robot's address and opens the scale; `cell` is the arm's
    /// model for the checks. The operator answers on `operator`.
    pub fn open(
        spec: InstrumentsSpec,
        cell: CellConfig,
        bottle: f64,
        target: f64,
        operator: Box<dyn BufRead>,
    ) -> Result<Instruments, String> {
        if !(spec.density.is_finite() && spec.density > 0.0) {
            return Err(format!(
                "--density {}: must be a positive number of g/ml",
                spec.density
            ));
        }
        let addr = parse_robot(&spec.robot).map_err(|e| e.message)?;
        let socket = bind(addr).map_err(|e| e.message)?;
        let scale = Scale::open(
            &spec.scale,
            ClientConfig {
                baud: spec.baud,
                ..ClientConfig::default()
            },
        )
        .map_err(|e| e.to_string())?;
        Ok(Instruments {
            spec,
            cell,
            bottle,
            target,
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
        })
    }

    /// The scale's serial number.
    pub fn scale_serial(&self) -> &str {
        self.scale.serial()
    }

    /// The stable weight, g, waiting up to [`SETTLE_LIMIT`] for it.
    fn weigh(&mut self) -> Result<f64, String> {
        let started = Instant::now();
        loop {
            match self.scale.stable() {
                Ok(w) => return Ok(w.grams()),
                // Still settling (`S I`): the liquid is still moving.
                Err(e)
                    if matches!(e.kind, ErrorKind::NotExecutable { .. })
                        && started.elapsed() < SETTLE_LIMIT => {}
                Err(e) => return Err(e.to_string()),
            }
        }
    }

    /// Asks the operator to reset the cell and waits for Enter.
    fn confirm(&mut self, rollout: u32) -> Result<(), String> {
        crate::cli::say(&format!(
            "roll-out {rollout}: reset the cell (the bottle filled to {} l, the glass on the \
             scale emptied), then press Enter",
            self.bottle
        ))
        .map_err(|e| e.message)?;
        let mut line = String::new();
        match self.operator.read_line(&mut line) {
            Ok(0) => Err("the operator's input closed before the cell was reset".into()),
            Ok(_) => Ok(()),
            Err(e) => Err(format!("reading the operator's answer: {e}")),
        }
    }
}

impl Rig for Instruments {
    fn roll_out(
        &mut self,
        skill: &Skill,
        rollout: u32,
        query: f32,
        delta: &[f32],
    ) -> Result<Trial, String> {
        let path = match skill.checked(&self.cell, query, delta) {
            Ok((_, path)) => path,
            Err(why) => return Ok(Trial::rejected(self.target, why)),
        };
        if self.spec.confirm {
            self.confirm(rollout)?;
        }
        let before = self.weigh()?;
        let played = play(&self.socket, &path, &self.play).map_err(|e| e.message)?;
        if played.ended != Ended::Completed {
            return Err(format!(
                "roll-out {rollout} on the robot: {}; the cell may need a reset",
                played.ended
            ));
        }
        let after = self.weigh()?;
        let poured = (after - before) / self.spec.density * 1e-3;
        let load = played.load;
        if load.is_none() {
            eprintln!(
                "primo pour: roll-out {rollout}: the robot stood still too briefly to weigh the \
                 bottle; its spill counts as 0"
            );
        }
        // The bottle's loss: its liquid's weight, before minus after.
        let spilled = load.map_or(0.0, |[b, a]| {
            ((b - a) / G / self.spec.density - poured).max(0.0)
        });
        Ok(Trial {
            poured,
            spilled,
            error: poured - self.target,
            reward: reward(self.target, poured, spilled),
            rejected: None,
            series: None,
            readings: Some(Readings {
                scale: [before, after],
                load,
            }),
        })
    }
}
