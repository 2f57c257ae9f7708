//! Learning to pour on the simulated cell without a run log: the
//! experiments' runs, and tests'.

use primo_sim::cell::CellConfig;
use primo_skill::Skill;

use crate::Error;
use crate::learner::Learner;
use crate::rollouts::{Record, Replay, learn_on};

use super::rig::{Simulated, roll_out};
use super::settings::{Settings, setup};
use super::trial::Trial;

/// Runs the learner of `s` on `skill` in the simulated `cell`, calling
/// `each` after every roll-out; returns all roll-outs.
pub fn learn(
    skill: &Skill,
    cell: &CellConfig,
    s: &Settings,
    learner: &mut Learner,
    mut each: impl FnMut(&Record<Trial>),
) -> Result<Vec<Record<Trial>>, Error> {
    let mut rig = Simulated::new(*cell, s.bottle, s.seed)?;
    let run = learn_on(
        skill,
        setup(skill, s)?,
        s.max_rollouts,
        learner,
        Replay::none(),
        |i, query, delta| roll_out(&mut rig, skill, s.target, i, query, delta),
        |e, _| {
            each(&e.record);
            Ok(())
        },
    )?;
    Ok(run.into_iter().map(|e| e.record).collect())
}
