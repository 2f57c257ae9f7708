//! Where roll-outs happen: the simulated cell in this process, or the real
//! instruments (a KUKA LWR4 over FRI and an MT-SICS scale) of a pouring
//! cell. The learners of [`crate::pour`] do not know which.

use serde::{Deserialize, Serialize};

use crate::sim::cell::CellConfig;
use crate::skill::{Skill, Trial};

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
