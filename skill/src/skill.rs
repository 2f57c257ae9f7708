//! A skill: demonstrations fitted as DMPs, generalized over the task
//! query (for pouring, the bottle's volume; any vector of 1 to
//! [`MAX_QUERY`] values), planned and checked.
//!
//! A movement is `θ = G(q̂) + Δθ` (paper eq. 12) with the DMP parameter
//! layout `[weights row by row, goals, τ]`; the start is generalized with
//! the same coefficients (it is where the robot stands, not a learned
//! parameter). Every plan passes the safety [`Gate`] before it can move
//! anything: joint position and velocity limits in joint space; in
//! Cartesian space the workspace box and speed limits, and the joint
//! limits of the arm's inverse kinematics along the poses. What passes is
//! a [`JointPath`], the only thing a rig executes.

use primo_core::dmp::{Execution, FitOptions, Scaling};
use primo_core::generalize::{Generalizer, Method};
use primo_robot::{Gate, JOINTS, JointPath};

use crate::csv::Demo;
use crate::{Error, HOST_MAX_DOF, HostDmp, MAX_KERNELS};

/// Names of the Cartesian columns: the controlled point (m) and the tool's
/// rotation vector (rad).
pub const CARTESIAN_NAMES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];
/// Names of the joint columns.
pub const JOINT_NAMES: [&str; JOINTS] = ["a1", "a2", "a3", "a4", "a5", "a6", "a7"];

/// Most examples a skill generalizes over.
pub const MAX_EXAMPLES: usize = 8;
/// Longest DMP parameter vector (weights, goals, τ).
pub const MAX_PARAMS: usize = HOST_MAX_DOF * MAX_KERNELS + HOST_MAX_DOF + 1;

/// Largest dimension of a query.
pub const MAX_QUERY: usize = 4;

type Gen = Generalizer<MAX_EXAMPLES, MAX_QUERY, MAX_PARAMS>;

/// Which coordinates the movement is learned in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
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

    /// The space whose columns are `names`, if any.
    pub fn of(names: &[String]) -> Option<Space> {
        [Space::Joint, Space::Cartesian]
            .into_iter()
            .find(|s| s.names().iter().eq(names.iter()))
    }
}

/// `names` are `expected`, by name and in order; the message names the
/// first column that differs.
pub fn same_columns(expected: &[String], names: &[String]) -> Result<(), String> {
    for (i, e) in expected.iter().enumerate() {
        match names.get(i) {
            Some(n) if n == e => {}
            Some(n) if expected.contains(n) => {
                return Err(format!(
                    "column {} is `{n}`, expected `{e}` (the columns are in another order)",
                    i + 2
                ));
            }
            Some(n) => return Err(format!("column {} is `{n}`, expected `{e}`", i + 2)),
            None => return Err(format!("column `{e}` is missing")),
        }
    }
    match names.get(expected.len()) {
        Some(extra) => Err(format!("column `{extra}` is extra")),
        None => Ok(()),
    }
}

/// Demonstrations fitted and generalized.
#[derive(Debug, Clone)]
pub struct Skill {
    names: Vec<String>,
    query_dim: usize,
    space: Option<Space>,
    template: HostDmp,
    generalizer: Box<Gen>,
    starts: Vec<Vec<f32>>,
}

/// A trajectory sampled at the control step, row-major `dof` values per
/// sample, in f64 for the cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The pouring cell's space of the coordinates, if they are one's.
    pub space: Option<Space>,
    /// Sample times, s.
    pub t: Vec<f64>,
    /// Positions.
    pub rows: Vec<f64>,
    /// DoF per row.
    pub dof: usize,
}

impl Skill {
    /// Fits one DMP per demonstration `(q_i, demo_i)`, all with the same
    /// amplitude scaling (decided on the first: interpolating weights only
    /// makes sense when every example scales them alike), and generalizes
    /// over the queries ([`Skill::from_dmps`]). Every demonstration has the
    /// first one's columns, by name and in order.
    pub fn fit(
        examples: &[(&[f32], &Demo)],
        kernels: usize,
        method: Method,
    ) -> Result<Skill, Error> {
        let (_, first) = examples.first().ok_or_else(|| {
            Error::Demonstrations("a skill needs at least one demonstration".into())
        })?;
        let names = first.names.clone();
        let dof = names.len();
        let mut options = FitOptions::default();
        let mut dmps = Vec::new();
        for (i, (q, demo)) in examples.iter().enumerate() {
            same_columns(&names, &demo.names)
                .map_err(|why| Error::Demonstrations(format!("demonstration {}: {why}", i + 1)))?;
            let dmp = HostDmp::fit(&demo.times, &demo.positions, dof, kernels, &options).map_err(
                |e| Error::Demonstrations(format!("demonstration {} (q = {q:?}): {e}", i + 1)),
            )?;
            if i == 0 {
                let mask = (0..dof)
                    .filter(|d| dmp.is_scaled(*d))
                    .fold(0u32, |m, d| m | 1 << d);
                options.scaling = Scaling::Mask(mask);
            }
            dmps.push((*q, dmp));
        }
        Skill::from_dmps(names, &dmps, method)
    }

    /// Generalizes over fitted DMPs `(q_i, dmp_i)` with columns `names`:
    /// every query of the first one's dimension (1 to [`MAX_QUERY`]), every
    /// DMP of the first one's DoF, kernels, gains and amplitude scaling.
    pub fn from_dmps(
        names: Vec<String>,
        dmps: &[(&[f32], HostDmp)],
        method: Method,
    ) -> Result<Skill, Error> {
        let (first_query, template) = dmps
            .first()
            .ok_or_else(|| Error::Demonstrations("no demonstration".into()))?;
        let query_dim = first_query.len();
        if !(1..=MAX_QUERY).contains(&query_dim) {
            return Err(Error::Demonstrations(format!(
                "a query has 1 to {MAX_QUERY} values, demonstration 1's has {query_dim}"
            )));
        }
        if names.len() != template.dof() {
            return Err(Error::Demonstrations(format!(
                "{} column names for a DMP of {} DoF",
                names.len(),
                template.dof()
            )));
        }
        let mut generalizer = Box::new(Gen::new(query_dim, template.param_len(), method));
        let mut theta = vec![0.0; template.param_len()];
        for (i, (q, dmp)) in dmps.iter().enumerate() {
            if q.len() != query_dim {
                return Err(Error::Demonstrations(format!(
                    "demonstration {}: its query has {} values, demonstration 1's has {query_dim}",
                    i + 1,
                    q.len()
                )));
            }
            if (dmp.dof(), dmp.kernels(), dmp.shape())
                != (template.dof(), template.kernels(), template.shape())
            {
                return Err(Error::Demonstrations(format!(
                    "demonstration {}: its DMP has {} DoF and {} kernels, demonstration 1's {} \
                     and {}, and both must have the same gains and amplitude scaling",
                    i + 1,
                    dmp.dof(),
                    dmp.kernels(),
                    template.dof(),
                    template.kernels()
                )));
            }
            dmp.params(&mut theta)
                .map_err(|e| Error::Demonstrations(e.to_string()))?;
            generalizer
                .add_example(q, &theta)
                .map_err(|e| Error::Demonstrations(format!("example q = {q:?}: {e}")))?;
        }
        generalizer
            .build()
            .map_err(|e| Error::Demonstrations(e.to_string()))?;
        Ok(Skill {
            space: Space::of(&names),
            names,
            query_dim,
            starts: dmps
                .iter()
                .map(|(_, d)| d.start_position().to_vec())
                .collect(),
            template: template.clone(),
            generalizer,
        })
    }

    /// The column names of the skill's movements.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// The query's dimension.
    pub fn query_dim(&self) -> usize {
        self.query_dim
    }

    /// The pouring cell's space the skill moves in, if its columns are
    /// one's.
    pub fn space(&self) -> Option<Space> {
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
    pub fn examples(&self) -> impl Iterator<Item = (&[f32], &[f32])> + Clone {
        (0..self.generalizer.len()).filter_map(|i| self.generalizer.example(i))
    }

    /// A query of the skill's dimension, every value finite.
    fn check_query(&self, query: &[f32]) -> Result<(), Error> {
        if query.len() != self.query_dim || query.iter().any(|q| !q.is_finite()) {
            return Err(Error::Movement(format!(
                "the query {query:?} is not {} finite value(s)",
                self.query_dim
            )));
        }
        Ok(())
    }

    /// How the skill generalizes.
    pub fn regression(&self) -> primo_core::generalize::Method {
        self.generalizer.method()
    }

    /// `G(q)`.
    pub fn generalize(&self, query: &[f32]) -> Result<Vec<f32>, Error> {
        self.check_query(query)?;
        let mut theta = vec![0.0; self.param_len()];
        self.generalizer
            .generalize(query, &mut theta)
            .map_err(|e| Error::Movement(format!("generalizing to q = {query:?}: {e}")))?;
        Ok(theta)
    }

    /// The DMP and its execution for `θ = G(q̂) + Δθ`.
    pub fn movement(
        &self,
        query: &[f32],
        delta: &[f32],
    ) -> Result<(HostDmp, Execution<HOST_MAX_DOF>), Error> {
        if delta.len() > self.param_len() {
            return Err(Error::Movement(format!(
                "Δθ has {} values, θ has {}",
                delta.len(),
                self.param_len()
            )));
        }
        let mut theta = self.generalize(query)?;
        for (t, d) in theta.iter_mut().zip(delta) {
            *t += d;
        }
        let mut dmp = self.template.clone();
        dmp.set_params(&theta)
            .map_err(|e| Error::Movement(format!("movement for q = {query:?}: {e}")))?;
        let mut c = [0.0f32; MAX_EXAMPLES];
        self.generalizer
            .coefficients(query, &mut c)
            .map_err(|e| Error::Movement(e.to_string()))?;
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
    pub fn plan(&self, query: &[f32], delta: &[f32], dt: f64) -> Result<Plan, Error> {
        let (dmp, exec) = self.movement(query, delta)?;
        let dof = dmp.dof();
        let mut plan = Plan {
            space: self.space,
            t: Vec::new(),
            rows: Vec::new(),
            dof,
        };
        let steps = dmp
            .trajectory(&exec, dt as f32)
            .map_err(|e| Error::Movement(format!("integrating the movement: {e}")))?;
        for s in steps {
            plan.t.push(f64::from(s.time));
            plan.rows
                .extend(s.position.iter().take(dof).map(|v| f64::from(*v)));
        }
        Ok(plan)
    }

    /// Checks the plan with the safety `gate` (see the module docs): in
    /// joint space directly, in Cartesian space also the joint angles the
    /// inverse kinematics of the gate's arm gives for the poses. Returns the
    /// checked joint angles.
    pub fn check(&self, gate: &Gate, plan: &Plan) -> Result<JointPath, Error> {
        Ok(match self.space {
            Some(Space::Joint) => gate.check_joints(plan.t.clone(), rows(plan))?,
            Some(Space::Cartesian) => gate.check_cartesian(&plan.t, &rows(plan))?,
            None => {
                return Err(Error::Movement(format!(
                    "the pouring cell moves joints ({}) or the bottle ({}), not ({})",
                    JOINT_NAMES.join(","),
                    CARTESIAN_NAMES.join(","),
                    self.names.join(",")
                )));
            }
        })
    }

    /// The movement for `θ = G(query) + Δθ` planned every `dt` seconds and
    /// checked ([`Skill::check`]).
    pub fn checked(
        &self,
        gate: &Gate,
        dt: f64,
        query: &[f32],
        delta: &[f32],
    ) -> Result<(Plan, JointPath), Error> {
        let plan = self.plan(query, delta, dt)?;
        let path = self.check(gate, &plan)?;
        Ok((plan, path))
    }
}

/// The plan's samples as fixed-size rows (`N` = its DoF).
fn rows<const N: usize>(plan: &Plan) -> Vec<[f64; N]> {
    plan.rows
        .chunks_exact(N)
        .map(|r| std::array::from_fn(|j| r[j]))
        .collect()
}
