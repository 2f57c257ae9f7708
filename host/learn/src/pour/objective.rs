//! The simulated cell as an objective for any optimizer (`primo rollout`,
//! the Python package's `Cell`): a vector `x = [θ, q̂]`, θ the absolute
//! DMP parameters `[weights (dof × kernels, row by row), goals, τ]`, is
//! executed as `G(q̂) + Δθ` with `Δθ = θ − G(bottle)`, so the start vector
//! `[G(bottle), bottle]` executes the generalized movement and moving `q̂`
//! alone moves along the demonstrations' manifold.

use std::borrow::Cow;

use primo_skill::Skill;
use primo_skill::skill::check_duration;

use crate::Error;
use crate::learner::{QUERY_DECAY, power_blocks};

use super::rig::{Rig, Simulated};
use super::settings::check_target;
use super::skill::{Built, Converted, SkillSpec, Space};
use super::trial::Trial;

/// What the vector holds, in order, in `space`: in Cartesian space the
/// DoFs are x, y, z and the orientation's three log coordinates (a
/// `qw,qx,qy,qz` group is one orientation DMP), and the orientation's goal
/// is its rotation vector from the demonstrated goals' mean.
pub fn layout(space: Space) -> &'static str {
    match space {
        Space::Joint => "weights (dof x kernels, row by row), goals (dof), tau (s), query (l)",
        Space::Cartesian => {
            "weights (dof x kernels, row by row; dof: x, y, z, then the orientation's 3 log \
             coordinates), goals (x, y, z in m; the orientation's goal as a rotation vector \
             from the demonstrated goals' mean, rad), tau (s), query (l)"
        }
    }
}

/// PoWER's exploration scales behind [`Objective::start`]'s std: the
/// paper's s1 (query) and s2 (Δθ).
const S1: f32 = 0.2;
const S2: f32 = 0.05;

/// The cell and the skill, for one roll-out after another.
#[derive(Debug, Clone)]
pub struct Objective {
    space: Space,
    skill: Skill,
    rig: Simulated,
    base: Vec<f32>,
    bottle: f64,
    target: f64,
    converted: Vec<Converted>,
}

/// Where an optimizer starts: the generalized movement for the bottle and
/// PoWER's exploration standard deviation, per value of the vector.
#[derive(Debug, Clone, PartialEq)]
pub struct Start {
    /// `[G(bottle), bottle]`.
    pub start: Vec<f32>,
    /// PoWER's exploration std of each value (`pour::power_blocks`).
    pub std: Vec<f32>,
}

impl Objective {
    /// The cell and skill of `spec`, pouring `target` litres from a bottle
    /// holding `bottle`.
    pub fn new(spec: &SkillSpec, bottle: f64, target: f64) -> Result<Objective, Error> {
        check_target(bottle, target)?;
        let Built {
            cell,
            skill,
            converted,
        } = spec.build()?;
        // The rig's own seed numbers learning runs' roll-outs; every
        // roll-out here is given its seed.
        let rig = Simulated::new(cell, bottle, 0)?;
        let base = skill.generalize(&[bottle as f32])?;
        Ok(Objective {
            space: spec.space,
            skill,
            rig,
            base,
            bottle,
            target,
            converted,
        })
    }

    /// The demonstration files converted from rotation vectors.
    pub fn converted(&self) -> &[Converted] {
        &self.converted
    }

    /// The space the movement is in.
    pub fn space(&self) -> Space {
        self.space
    }

    /// The skill.
    pub fn skill(&self) -> &Skill {
        &self.skill
    }

    /// Length of the vector: θ and the query.
    pub fn len(&self) -> usize {
        self.base.len() + 1
    }

    /// Never: the vector holds at least the query.
    pub fn is_empty(&self) -> bool {
        false
    }

    /// Liquid in the bottle, l.
    pub fn bottle(&self) -> f64 {
        self.bottle
    }

    /// Volume to pour, l.
    pub fn target(&self) -> f64 {
        self.target
    }

    /// What the glass holds to its rim, l (`primo pour`'s `glass_holds`).
    pub fn glass_litres(&self) -> f64 {
        self.rig.glass_litres()
    }

    /// `values` as the vector: [`Objective::len`] numbers, each a finite
    /// `f32`, its τ a movement the skill plans ([`check_duration`]). The
    /// message says what is wrong (the caller names the input).
    pub fn vector(&self, values: &[f64]) -> Result<Vec<f32>, String> {
        let len = self.len();
        if values.len() != len {
            return Err(format!(
                "{} values, the layout needs {len} (weights, goals, τ, q̂)",
                values.len()
            ));
        }
        values
            .iter()
            .enumerate()
            .map(|(i, v)| {
                let x = *v as f32;
                match (x.is_finite(), v.is_finite()) {
                    (true, _) => Ok(x),
                    (false, true) => Err(format!("value {} is out of f32 range", i + 1)),
                    (false, false) => Err(format!("value {} is {v}, not a finite number", i + 1)),
                }
            })
            .collect::<Result<Vec<f32>, String>>()
            .and_then(|x| {
                // τ is θ's last value, before the query.
                check_duration(x[len - 2], self.rig.dt()).map_err(|e| e.to_string())?;
                Ok(x)
            })
    }

    /// One roll-out of the vector `x` ([`Objective::vector`]), the scale's
    /// noise from `seed`; with `record`, the trial keeps the time series
    /// of every control step. A movement the gate rejects is a trial with
    /// reward 0; an error means the cell could not run it.
    pub fn roll_out(&self, x: &[f32], seed: u64, record: bool) -> Result<Trial, Error> {
        if x.len() != self.len() {
            return Err(Error::Invalid(format!(
                "{} values, the layout needs {}",
                x.len(),
                self.len()
            )));
        }
        let (theta, query) = x.split_at(self.base.len());
        let delta: Vec<f32> = theta.iter().zip(&self.base).map(|(t, b)| t - b).collect();
        self.roll_out_delta(query, &delta, seed, record)
    }

    /// One roll-out of `G(query) + delta`, PoWER's extended vector `[q̂,
    /// Δθ]` as a learning run executes it: [`Objective::roll_out`] without
    /// the subtraction of `G(bottle)`, whose rounding would move Δθ.
    pub fn roll_out_delta(
        &self,
        query: &[f32],
        delta: &[f32],
        seed: u64,
        record: bool,
    ) -> Result<Trial, Error> {
        if delta.len() != self.base.len() || query.len() != self.skill.query_dim() {
            return Err(Error::Invalid(format!(
                "{} query and {} Δθ values, the layout needs {} and {}",
                query.len(),
                delta.len(),
                self.skill.query_dim(),
                self.base.len()
            )));
        }
        let rig = match record {
            true => Cow::Owned(self.rig.recording(1)),
            false => Cow::Borrowed(&self.rig),
        };
        Ok(
            match self.skill.checked(rig.gate(), rig.dt(), query, delta) {
                Ok((plan, path)) => {
                    Trial::scored(self.target, rig.execute_seeded(&plan, &path, seed)?)
                }
                Err(why) => Trial::rejected(self.target, why.to_string()),
            },
        )
    }

    /// The start vector and PoWER's exploration std for it.
    pub fn start(&self) -> Result<Start, Error> {
        let blocks = power_blocks(&self.skill, S1, S2, QUERY_DECAY)?;
        // Blocks are [q̂, weights, goals, τ]; the vector puts q̂ last.
        let mut std: Vec<f32> = blocks
            .iter()
            .flat_map(|b| std::iter::repeat_n(b.variance.sqrt(), b.len))
            .collect();
        std.rotate_left(1);
        let mut start = self.base.clone();
        start.push(self.bottle as f32);
        Ok(Start { start, std })
    }
}
