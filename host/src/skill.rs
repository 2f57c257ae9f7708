//! The pouring skill: demonstrations fitted as DMPs, generalized over the
//! query (the bottle's volume), and executed on the simulated cell.
//!
//! A movement is `θ = G(q̂) + Δθ` (paper eq. 12) with the DMP parameter
//! layout `[weights row by row, goals, τ]`; the start is generalized with
//! the same coefficients (it is where the robot stands, not a learned
//! parameter). Every trajectory passes [`crate::safety`] before it reaches
//! the cell: joint position and velocity limits in joint space; in
//! Cartesian space the mouth's workspace box and speed limits, and the
//! joint limits of the arm's inverse kinematics along the poses. A
//! rejected roll-out has reward 0 and moves nothing.

use primo_core::dmp::{Execution, FitOptions, Scaling};
use primo_core::generalize::{Generalizer, Method};

use crate::csv::Demo;
use crate::safety::{self, JointPath};
use crate::series::Series;
use crate::sim::cell::{Cell, CellConfig};
use crate::sim::expert::{CARTESIAN_NAMES, JOINT_NAMES, rest_configuration};
use crate::{HostDmp, MAX_DOF, MAX_KERNELS};

/// Most examples a skill generalizes over.
pub const MAX_EXAMPLES: usize = 8;
/// Longest DMP parameter vector (weights, goals, τ).
pub const MAX_PARAMS: usize = MAX_DOF * MAX_KERNELS + MAX_DOF + 1;

type Gen = Generalizer<MAX_EXAMPLES, 1, MAX_PARAMS>;

/// Which coordinates the movement is learned in.
#[derive(
    Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum, serde::Serialize, serde::Deserialize,
)]
#[serde(rename_all = "lowercase")]
pub enum Space {
    /// Bottle pose: mouth position (m) and rotation vector (rad).
    Cartesian,
    /// The arm's seven joint angles (rad).
    Joint,
}

impl Space {
    /// Column names of the space's trajectories.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            Space::Cartesian => &CARTESIAN_NAMES,
            Space::Joint => &JOINT_NAMES,
        }
    }
}

/// Demonstrations fitted and generalized.
#[derive(Debug, Clone)]
pub struct Skill {
    space: Space,
    template: HostDmp,
    generalizer: Box<Gen>,
    starts: Vec<Vec<f32>>,
}

/// A trajectory sampled at the control step, row-major `dof` values per
/// sample, in f64 for the cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// Sample times, s.
    pub t: Vec<f64>,
    /// Positions.
    pub rows: Vec<f64>,
    /// DoF per row.
    pub dof: usize,
}

/// The result of one roll-out on the cell.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Trial {
    /// Poured volume as the scale reads it, l.
    pub poured: f64,
    /// Spilled volume, l.
    pub spilled: f64,
    /// `poured − target`, l.
    pub error: f64,
    /// `max(0, 1 − 5 |target − poured| − 5 spilled)`.
    pub reward: f64,
    /// Why the trajectory never reached the cell, if it did not.
    pub rejected: Option<String>,
    /// The time series, if the cell records one (`record_every > 0`).
    #[serde(skip)]
    pub series: Option<Series>,
    /// What the instruments read, on a real cell.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readings: Option<crate::rig::Readings>,
}

impl Trial {
    /// A roll-out the safety checks rejected (`why`): nothing moved, so
    /// nothing poured, and its reward is 0.
    pub fn rejected(target: f64, why: String) -> Trial {
        Trial {
            poured: 0.0,
            spilled: 0.0,
            error: -target,
            reward: 0.0,
            rejected: Some(why),
            series: None,
            readings: None,
        }
    }
}

/// The paper's reward `r = 1 − 5|v_d − v_m| − 5 v_s` (litres), kept ≥ 0.
pub fn reward(target: f64, poured: f64, spilled: f64) -> f64 {
    (1.0 - 5.0 * (target - poured).abs() - 5.0 * spilled).max(0.0)
}

impl Skill {
    /// Fits one DMP per demonstration, all with the same amplitude scaling
    /// (decided on the first: interpolating weights only makes sense when
    /// every example scales them alike), and generalizes over the queries.
    pub fn fit(
        space: Space,
        examples: &[(f32, &Demo)],
        kernels: usize,
        method: Method,
    ) -> Result<Skill, String> {
        let dof = space.names().len();
        let mut options = FitOptions::default();
        let mut dmps = Vec::new();
        for (i, (q, demo)) in examples.iter().enumerate() {
            if demo.names.len() != dof {
                return Err(format!(
                    "demonstration {} has {} columns; {:?} space needs {dof}",
                    i + 1,
                    demo.names.len(),
                    space
                ));
            }
            let dmp = HostDmp::fit(&demo.times, &demo.positions, dof, kernels, &options)
                .map_err(|e| format!("demonstration {} (q = {q}): {e}", i + 1))?;
            if i == 0 {
                let mask = (0..dof)
                    .filter(|d| dmp.is_scaled(*d))
                    .fold(0u32, |m, d| m | 1 << d);
                options.scaling = Scaling::Mask(mask);
            }
            dmps.push((*q, dmp));
        }
        let template = dmps
            .first()
            .map(|(_, d)| d.clone())
            .ok_or("a skill needs at least one demonstration")?;
        let mut generalizer = Box::new(Gen::new(1, template.param_len(), method));
        let mut theta = vec![0.0; template.param_len()];
        for (q, dmp) in &dmps {
            dmp.params(&mut theta).map_err(|e| e.to_string())?;
            generalizer
                .add_example(&[*q], &theta)
                .map_err(|e| format!("example q = {q}: {e}"))?;
        }
        generalizer.build().map_err(|e| e.to_string())?;
        Ok(Skill {
            space,
            starts: dmps
                .iter()
                .map(|(_, d)| d.start_position().to_vec())
                .collect(),
            template,
            generalizer,
        })
    }

    /// The space the skill moves in.
    pub fn space(&self) -> Space {
        self.space
    }

    /// Length of θ (weights, goals, τ): `dof·kernels + dof + 1`.
    pub fn param_len(&self) -> usize {
        self.template.param_len()
    }

    /// Kernels per DoF.
    pub fn kernels(&self) -> usize {
        self.template.kernels()
    }

    /// DoF count.
    pub fn dof(&self) -> usize {
        self.template.dof()
    }

    /// The examples `(q_i, θ_i)`.
    pub fn examples(&self) -> impl Iterator<Item = (f32, &[f32])> + Clone {
        (0..self.generalizer.len()).filter_map(|i| {
            let (q, theta) = self.generalizer.example(i)?;
            Some((*q.first()?, theta))
        })
    }

    /// How the skill generalizes.
    pub fn regression(&self) -> primo_core::generalize::Method {
        self.generalizer.method()
    }

    /// `G(q)`.
    pub fn generalize(&self, query: f32) -> Result<Vec<f32>, String> {
        let mut theta = vec![0.0; self.param_len()];
        self.generalizer
            .generalize(&[query], &mut theta)
            .map_err(|e| format!("generalizing to q = {query}: {e}"))?;
        Ok(theta)
    }

    /// The DMP and its execution for `θ = G(q̂) + Δθ`.
    pub fn movement(
        &self,
        query: f32,
        delta: &[f32],
    ) -> Result<(HostDmp, Execution<MAX_DOF>), String> {
        if delta.len() > self.param_len() {
            return Err(format!(
                "Δθ has {} values, θ has {}",
                delta.len(),
                self.param_len()
            ));
        }
        let mut theta = self.generalize(query)?;
        for (t, d) in theta.iter_mut().zip(delta) {
            *t += d;
        }
        let mut dmp = self.template.clone();
        dmp.set_params(&theta)
            .map_err(|e| format!("movement for q = {query}: {e}"))?;
        let mut c = [0.0f32; MAX_EXAMPLES];
        self.generalizer
            .coefficients(&[query], &mut c)
            .map_err(|e| e.to_string())?;
        let mut exec = dmp.execution();
        for (d, s) in exec.start.iter_mut().enumerate() {
            *s = self
                .starts
                .iter()
                .zip(c)
                .map(|(start, c)| c * start.get(d).copied().unwrap_or(0.0))
                .sum();
        }
        Ok((dmp, exec))
    }

    /// The movement sampled every `dt` seconds from 0 to τ.
    pub fn plan(&self, query: f32, delta: &[f32], dt: f64) -> Result<Plan, String> {
        let (dmp, exec) = self.movement(query, delta)?;
        let dof = dmp.dof();
        let mut plan = Plan {
            t: Vec::new(),
            rows: Vec::new(),
            dof,
        };
        let steps = dmp
            .trajectory(&exec, dt as f32)
            .map_err(|e| format!("integrating the movement: {e}"))?;
        for s in steps {
            plan.t.push(f64::from(s.time));
            plan.rows
                .extend(s.position.iter().take(dof).map(|v| f64::from(*v)));
        }
        Ok(plan)
    }

    /// Checks the plan with [`crate::safety`] (see the module docs): in
    /// joint space directly, in Cartesian space also the joint angles the
    /// inverse kinematics of `cell`'s arm gives for the bottle poses, from
    /// the rest posture between the demonstrators' elbows. Returns the
    /// checked joint angles.
    pub fn check(&self, cell: &CellConfig, plan: &Plan) -> Result<JointPath, String> {
        match self.space {
            Space::Joint => safety::check_joints(plan.t.clone(), rows(plan)),
            Space::Cartesian => {
                safety::check_cartesian(cell, &plan.t, &rows(plan), &rest_configuration(0.0))
            }
        }
    }

    /// The movement for `θ = G(query) + Δθ` planned at the cell's control
    /// step and checked ([`Skill::check`]); why not, if it is rejected.
    pub fn checked(
        &self,
        cell: &CellConfig,
        query: f32,
        delta: &[f32],
    ) -> Result<(Plan, JointPath), String> {
        let plan = self.plan(query, delta, cell.dt)?;
        let path = self.check(cell, &plan)?;
        Ok((plan, path))
    }

    /// Plans, checks and executes one roll-out with the bottle holding
    /// `volume` litres; the scale's noise comes from `seed`. The trial
    /// carries the time series when `cell.record_every > 0`.
    pub fn roll_out(
        &self,
        cell: &CellConfig,
        volume: f64,
        target: f64,
        query: f32,
        delta: &[f32],
        seed: u64,
    ) -> Result<Trial, String> {
        let plan = match self.checked(cell, query, delta) {
            Ok((plan, _)) => plan,
            Err(why) => return Ok(Trial::rejected(target, why)),
        };
        let mut sim = Cell::new(cell, volume, seed)?;
        for row in plan.rows.chunks_exact(plan.dof) {
            match self.space {
                Space::Joint => sim.step_joints(&std::array::from_fn(|j| row[j])),
                Space::Cartesian => sim.step_pose(
                    &cell.bottle_pose([row[0], row[1], row[2]], [row[3], row[4], row[5]]),
                ),
            }
        }
        let out = sim.finish();
        let recorded = !out.series.is_empty();
        Ok(Trial {
            poured: out.poured,
            spilled: out.spilled,
            error: out.poured - target,
            reward: reward(target, out.poured, out.spilled),
            rejected: None,
            series: recorded.then(|| {
                Series::new(
                    self.space,
                    &plan.rows,
                    plan.dof,
                    cell.record_every,
                    out.series,
                )
            }),
            readings: None,
        })
    }
}

/// The plan's samples as fixed-size rows (`N` = its DoF).
fn rows<const N: usize>(plan: &Plan) -> Vec<[f64; N]> {
    plan.rows
        .chunks_exact(N)
        .map(|r| std::array::from_fn(|j| r[j]))
        .collect()
}
