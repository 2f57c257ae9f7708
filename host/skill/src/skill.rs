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
//!
//! Columns `<p>qw,<p>qx,<p>qy,<p>qz` are one orientation, fitted as
//! [`crate::dmpfile`] fits them: three DMP DoFs, the log coordinates
//! `log(q ⊗ ḡ)` relative to the demonstration's goal `g`. They are
//! generalized as [`primo_core::generalize::orientation`] says: the goals
//! and starts as tangent vectors at the mean of the demonstrated goals,
//! the weights as they are. In `θ` such a group has its three DoFs' weights
//! in its place among the DoFs, and as its three goals the goal's rotation
//! vector from that mean (rad, world frame): `Δθ` there turns the goal. A
//! plan writes the four columns back, unit-norm.
use primo_core::dmp::{FinalVelocity, FitOptions};
use primo_core::generalize::{Generalizer, Method};
use primo_core::orientation::{from_coordinates, nearest_coordinates};
use primo_core::quaternion::Quaternion;
use primo_core::tangent::Tangent;
use primo_robot::{Gate, JointPath};

use crate::coupled::{Avoidance, Coupled, OVERTIME, Repulsion};
use crate::csv::Demo;
use crate::dmpfile::{
    AmplitudeScaling, DmpFile, FORMAT, Orientation, VERSION, orientation_groups, scalar_dof,
};
use crate::shaping::Via;
use crate::{Error, HOST_MAX_DOF, HostDmp, MAX_KERNELS};

/// Most examples a skill generalizes over.
pub const MAX_EXAMPLES: usize = 8;
/// Longest DMP parameter vector (weights, goals, τ).
pub const MAX_PARAMS: usize = HOST_MAX_DOF * MAX_KERNELS + HOST_MAX_DOF + 1;

/// Largest dimension of a query: the learner's, on the wire and in process.
pub use primo_protocol::learner::MAX_QUERY;

type Gen = Generalizer<MAX_EXAMPLES, MAX_QUERY, MAX_PARAMS>;

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
    template: HostDmp,
    generalizer: Box<Gen>,
    /// Per example, the DMP's start (an orientation's: its log
    /// coordinates, the turn to its goal).
    starts: Vec<Vec<f32>>,
    /// Per example, global scaling's demonstrated `g − y0` (none: per
    /// DoF), generalized as the starts are.
    references: Vec<Vec<f32>>,
    /// Per example, the velocity at the goal (none: at rest), generalized
    /// as the starts are.
    velocities: Vec<Vec<f32>>,
    /// Per example and orientation, the start's tangent vector.
    start_orientations: Vec<Vec<[f32; 3]>>,
    groups: Vec<Group>,
    /// Obstacles every planned movement steers round, limits it keeps away
    /// from (none: planned as the DMP runs).
    coupled: Coupled,
    /// Via-points every planned movement passes (none: as generalized).
    vias: Vec<Via>,
}

/// An orientation among the columns.
#[derive(Debug, Clone)]
struct Group {
    /// Its four columns.
    columns: [String; 4],
    /// Its first DoF in the DMP.
    dof: usize,
    /// Where its goals and starts are vectors.
    tangent: Tangent,
    /// Its chart's axis, every demonstration's.
    axis: [f32; 3],
}

/// A trajectory sampled at the control step, row-major `dof` values per
/// sample, in f64 for the cell.
#[derive(Debug, Clone, PartialEq)]
pub struct Plan {
    /// The columns, in order.
    pub names: Vec<String>,
    /// Sample times, s.
    pub t: Vec<f64>,
    /// Positions, one value per column.
    pub rows: Vec<f64>,
    /// Values per row: the columns.
    pub dof: usize,
}

impl Skill {
    /// Fits one DMP per demonstration `(q_i, demo_i)` ([`Skill::fit_demos`]:
    /// every one with the first one's amplitude scaling and orientation
    /// charts) and generalizes over the queries ([`Skill::from_files`]).
    pub fn fit(
        examples: &[(&[f32], &Demo)],
        kernels: usize,
        method: Method,
    ) -> Result<Skill, Error> {
        let files = Skill::fit_demos(
            examples,
            kernels,
            AmplitudeScaling::PerDof,
            FinalVelocity::AtRest,
        )?;
        let examples: Vec<(&[f32], &DmpFile)> = examples
            .iter()
            .zip(&files)
            .map(|((q, _), f)| (*q, f))
            .collect();
        Skill::from_files(&examples, method)
    }

    /// The DMP of each demonstration `(q_i, demo_i)` of a skill, in order
    /// (as [`DmpFile::fit`]: orientations as the module docs say, but with
    /// the fit of [`FitOptions::LEARNING`]: narrower kernels, none beyond
    /// the ends), their forcing terms scaled by `scaling` and their
    /// orientations charted, all alike (decided on the first: interpolating
    /// weights only makes sense when every example scales and charts them
    /// alike), each ending at rest or at its demonstrated velocity
    /// (`final_velocity`). Every demonstration has the
    /// first one's columns, by name and in order.
    pub fn fit_demos(
        examples: &[(&[f32], &Demo)],
        kernels: usize,
        scaling: AmplitudeScaling,
        final_velocity: FinalVelocity,
    ) -> Result<Vec<DmpFile>, Error> {
        let options = FitOptions {
            final_velocity,
            ..FitOptions::LEARNING
        };
        let (_, first) = examples.first().ok_or_else(|| {
            Error::Demonstrations("a skill needs at least one demonstration".into())
        })?;
        let mut scaled = None;
        let mut axes: Option<Vec<[f32; 3]>> = None;
        let mut files = Vec::new();
        for (i, (q, demo)) in examples.iter().enumerate() {
            same_columns(&first.names, &demo.names)
                .map_err(|why| Error::Demonstrations(format!("demonstration {}: {why}", i + 1)))?;
            let label = format!("demonstration {} (q = {q:?})", i + 1);
            let file = DmpFile::fit_charted(
                &label,
                demo,
                kernels,
                (scaling, scaled),
                axes.as_deref(),
                &options,
            )
            .map_err(|e| Error::Demonstrations(e.to_string()))?;
            // Every orientation charted as the first demonstration's.
            axes.get_or_insert_with(|| file.orientations.iter().map(|o| o.axis).collect());
            let dmp = &file.dmp;
            scaled.get_or_insert(
                (0..dmp.dof())
                    .filter(|d| dmp.is_scaled(*d))
                    .fold(0, |m, d| m | 1 << d),
            );
            files.push(file);
        }
        Ok(files)
    }

    /// Generalizes over fitted DMPs `(q_i, file_i)`: every query of the
    /// first one's dimension (1 to [`MAX_QUERY`]), every file of the first
    /// one's columns, kernels, gains and amplitude scaling.
    pub fn from_files(examples: &[(&[f32], &DmpFile)], method: Method) -> Result<Skill, Error> {
        let (first_query, first) = examples
            .first()
            .ok_or_else(|| Error::Demonstrations("no demonstration".into()))?;
        let template = &first.dmp;
        let query_dim = first_query.len();
        if !(1..=MAX_QUERY).contains(&query_dim) {
            return Err(Error::Demonstrations(format!(
                "a query has 1 to {MAX_QUERY} values, demonstration 1's has {query_dim}"
            )));
        }
        let names = first.names.clone();
        let mut goals: Vec<Vec<Quaternion>> = Vec::new();
        for (i, (q, file)) in examples.iter().enumerate() {
            same_columns(&names, &file.names)
                .map_err(|why| Error::Demonstrations(format!("demonstration {}: {why}", i + 1)))?;
            if q.len() != query_dim {
                return Err(Error::Demonstrations(format!(
                    "demonstration {}: its query has {} values, demonstration 1's has {query_dim}",
                    i + 1,
                    q.len()
                )));
            }
            let dmp = &file.dmp;
            let global = |d: &HostDmp| d.reference().is_some();
            let moving = |d: &HostDmp| !d.goal_velocity().is_empty();
            if (
                dmp.dof(),
                dmp.kernels(),
                dmp.shape(),
                global(dmp),
                moving(dmp),
            ) != (
                template.dof(),
                template.kernels(),
                template.shape(),
                global(template),
                moving(template),
            ) {
                return Err(Error::Demonstrations(format!(
                    "demonstration {}: its DMP has {} DoF and {} kernels, demonstration 1's {} \
                     and {}, and both must have the same gains, kernel layout (width and \
                     margin: fit them with one fixed margin), amplitude scaling and final \
                     velocity (at rest or demonstrated)",
                    i + 1,
                    dmp.dof(),
                    dmp.kernels(),
                    template.dof(),
                    template.kernels()
                )));
            }
            goals.push(
                file.orientations
                    .iter()
                    .map(|o| Quaternion::from_array(o.goal).normalized())
                    .collect::<Result<_, _>>()
                    .map_err(|e| {
                        Error::Demonstrations(format!("demonstration {}: a goal: {e}", i + 1))
                    })?,
            );
        }
        let groups = orientation_groups(&names)
            .into_iter()
            .enumerate()
            .map(|(j, (columns, dof))| {
                let of_group: Vec<Quaternion> =
                    goals.iter().filter_map(|g| g.get(j)).copied().collect();
                if of_group.len() != goals.len() {
                    return Err(Error::Demonstrations(format!(
                        "{}…: an orientation without its goal",
                        columns[0]
                    )));
                }
                let tangent = Tangent::mean(&of_group)
                    .map_err(|e| Error::Demonstrations(format!("{}…: {e}", columns[0])))?;
                // One chart for all: the weights of different charts are
                // no vectors of one space.
                let axis = first.orientations.get(j).map_or([0.0; 3], |o| o.axis);
                for (i, (_, file)) in examples.iter().enumerate() {
                    if file.orientations.get(j).map(|o| o.axis) != Some(axis) {
                        return Err(Error::Demonstrations(format!(
                            "demonstration {}: {}… is charted about another axis than demonstration 1's (fit them \
                             with Skill::fit, which charts them alike)",
                            i + 1,
                            columns[0]
                        )));
                    }
                }
                Ok(Group {
                    columns,
                    dof,
                    tangent,
                    axis,
                })
            })
            .collect::<Result<Vec<_>, Error>>()?;
        let mut generalizer = Box::new(Gen::new(query_dim, template.param_len(), method));
        let mut theta = vec![0.0; template.param_len()];
        let goal_at = template.dof() * template.kernels();
        let mut start_orientations = Vec::new();
        for ((q, file), goals) in examples.iter().zip(&goals) {
            file.dmp
                .params(&mut theta)
                .map_err(|e| Error::Demonstrations(e.to_string()))?;
            let start = file.dmp.start_position();
            let mut starts = Vec::new();
            for (g, goal) in groups.iter().zip(goals) {
                let at = goal_at + g.dof;
                theta[at..at + 3].copy_from_slice(&g.tangent.log(goal));
                starts.push(g.tangent.log(&from_coordinates(
                    &start[g.dof..g.dof + 3],
                    goal,
                    &g.axis,
                )));
            }
            start_orientations.push(starts);
            generalizer
                .add_example(q, &theta)
                .map_err(|e| Error::Demonstrations(format!("example q = {q:?}: {e}")))?;
        }
        generalizer
            .build()
            .map_err(|e| Error::Demonstrations(e.to_string()))?;
        Ok(Skill {
            names,
            query_dim,
            starts: examples
                .iter()
                .map(|(_, f)| f.dmp.start_position().to_vec())
                .collect(),
            references: examples
                .iter()
                .filter_map(|(_, f)| f.dmp.reference().map(<[f32]>::to_vec))
                .collect(),
            velocities: examples
                .iter()
                .map(|(_, f)| f.dmp.goal_velocity().to_vec())
                .filter(|v| !v.is_empty())
                .collect(),
            start_orientations,
            groups,
            template: template.clone(),
            generalizer,
            coupled: Coupled::default(),
            vias: Vec::new(),
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

    /// Length of θ (weights, goals, τ): `dof·kernels + dof + 1` (DMP DoFs:
    /// an orientation's four columns are three).
    pub fn param_len(&self) -> usize {
        self.template.param_len()
    }

    /// Kernels per DoF.
    pub fn kernels(&self) -> usize {
        self.template.kernels()
    }

    /// The DMP's DoF count (an orientation's four columns are three).
    pub fn dof(&self) -> usize {
        self.template.dof()
    }

    /// The DMP DoF of the position column `column`, if it is one of the
    /// skill's (an orientation's columns are none).
    pub fn position_dof(&self, column: &str) -> Option<usize> {
        scalar_dof(&self.names, column)
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

    /// `G(q)` (an orientation's goal as its rotation vector from the
    /// demonstrated goals' mean: see the module docs).
    pub fn generalize(&self, query: &[f32]) -> Result<Vec<f32>, Error> {
        self.check_query(query)?;
        let mut theta = vec![0.0; self.param_len()];
        self.generalizer
            .generalize(query, &mut theta)
            .map_err(|e| Error::Movement(format!("generalizing to q = {query:?}: {e}")))?;
        Ok(theta)
    }

    /// The movement for `θ = G(q̂) + Δθ`, as a DMP file whose DMP starts
    /// at the generalized start and whose orientations' goals are the
    /// generalized ones.
    pub fn movement(&self, query: &[f32], delta: &[f32]) -> Result<DmpFile, Error> {
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
        let mut c = [0.0f32; MAX_EXAMPLES];
        self.generalizer
            .coefficients(query, &mut c)
            .map_err(|e| Error::Movement(e.to_string()))?;
        let mut start = combine(&self.starts, &c, self.dof());
        let goal_at = self.dof() * self.kernels();
        let mut orientations = Vec::new();
        for (j, g) in self.groups.iter().enumerate() {
            let at = goal_at + g.dof;
            let goal = g.tangent.exp(&theta[at..at + 3]);
            // The log DMP's own goal is 0: the goal is the orientation's.
            theta[at..at + 3].fill(0.0);
            let mut vector = [0.0f32; 3];
            for (starts, c) in self.start_orientations.iter().zip(c) {
                for (v, s) in vector.iter_mut().zip(starts.get(j).unwrap_or(&[0.0; 3])) {
                    *v += c * s;
                }
            }
            let turn = &mut start[g.dof..g.dof + 3];
            let e = nearest_coordinates(&g.tangent.exp(&vector), &goal, turn, &g.axis);
            turn.copy_from_slice(&e);
            orientations.push(Orientation {
                columns: g.columns.clone(),
                goal: goal.to_array(),
                axis: g.axis,
            });
        }
        let t = &self.template;
        let mut dmp = HostDmp::from_shape(&t.shape(), t.dof(), t.kernels(), &start, &theta)
            .map_err(|e| Error::Movement(format!("movement for q = {query:?}: {e}")))?;
        if !self.references.is_empty() {
            let reference = combine(&self.references, &c, self.dof());
            dmp.set_reference(Some(&reference)).map_err(|e| {
                Error::Movement(format!("movement for q = {query:?}: global scaling: {e}"))
            })?;
        }
        if !self.velocities.is_empty() {
            let velocity = combine(&self.velocities, &c, self.dof());
            dmp.set_goal_velocity(&velocity).map_err(|e| {
                Error::Movement(format!("movement for q = {query:?}: goal velocity: {e}"))
            })?;
        }
        Ok(DmpFile {
            format: FORMAT.into(),
            version: VERSION,
            names: self.names.clone(),
            orientations,
            dmp,
        })
    }

    /// This skill with every planned movement steered round `avoid`'s
    /// obstacles ([`DmpFile::run_coupled`]); its columns must be
    /// position columns of the skill's.
    pub fn with_obstacles(mut self, avoid: Avoidance) -> Result<Self, Error> {
        self.position_columns("obstacles", avoid.columns.iter())?;
        self.coupled.avoid = Some(avoid);
        Ok(self)
    }

    /// This skill with every planned movement pushed back from `repel`'s
    /// limits ([`DmpFile::run_coupled`]); its columns must be position
    /// columns of the skill's.
    pub fn with_repulsion(mut self, repel: Repulsion) -> Result<Self, Error> {
        self.position_columns("joint limits", repel.limits.iter().map(|(c, ..)| c))?;
        self.coupled.repel = Some(repel);
        Ok(self)
    }

    /// This skill with every planned movement bent through `vias`
    /// ([`DmpFile::through`]: the least change of its weights, without a
    /// refit); their columns must be position columns of the skill's.
    pub fn with_vias(mut self, vias: Vec<Via>) -> Result<Self, Error> {
        self.position_columns("via-points", vias.iter().map(|v| &v.column))?;
        self.vias = vias;
        Ok(self)
    }

    /// Refuses a name among `columns` that is no position column of the
    /// skill's, saying what named it.
    fn position_columns<'a>(
        &self,
        what: &str,
        mut columns: impl Iterator<Item = &'a String>,
    ) -> Result<(), Error> {
        match columns.find(|c| self.position_dof(c).is_none()) {
            Some(name) => Err(Error::Movement(format!(
                "{what}: no position column `{name}` among {}",
                self.names.join(",")
            ))),
            None => Ok(()),
        }
    }

    /// The movement sampled every `dt` seconds from 0 to τ, one value per
    /// column (through the skill's via-points, with its coupling terms, if
    /// any, until it reaches its goal: at most 3τ); a movement beyond
    /// [`check_duration`]'s bounds
    /// is refused before anything is allocated.
    pub fn plan(&self, query: &[f32], delta: &[f32], dt: f64) -> Result<Plan, Error> {
        let mut file = self.movement(query, delta)?;
        check_duration(file.dmp.tau(), dt)?;
        if !self.vias.is_empty() {
            let prepared = file.prepare(None, None, None)?;
            file = file.through(&prepared, dt as f32, &self.vias)?;
        }
        if !self.coupled.is_none() {
            check_duration(file.dmp.tau() * (1.0 + OVERTIME), dt)?;
            let prepared = file.prepare(None, None, None)?;
            let rows = file.run_coupled(&prepared, dt as f32, &self.coupled)?;
            let dof = self.names.len();
            let mut plan = Plan {
                names: self.names.clone(),
                t: Vec::with_capacity(rows.len()),
                rows: Vec::with_capacity(rows.len() * dof),
                dof,
            };
            for (time, row) in rows {
                plan.t.push(f64::from(time));
                plan.rows.extend(row.into_iter().map(f64::from));
            }
            return Ok(plan);
        }
        let (prepared, mut steps) = file
            .steps(dt as f32, None, None, None)
            .map_err(|e| Error::Movement(format!("integrating the movement: {e}")))?;
        let (samples, dof) = (steps.size_hint().0, self.names.len());
        let mut plan = Plan {
            names: self.names.clone(),
            t: Vec::with_capacity(samples),
            rows: Vec::with_capacity(samples * dof),
            dof,
        };
        while let Some((time, position)) = steps.next_position() {
            plan.t.push(f64::from(time));
            prepared.each_column(position, |v| plan.rows.push(f64::from(v)));
        }
        Ok(plan)
    }

    /// Checks the plan with the safety `gate` (see the module docs): in
    /// joint space directly, in Cartesian space also the joint angles the
    /// inverse kinematics of the gate's arm gives for the poses. Returns the
    /// checked joint angles.
    pub fn check(&self, gate: &Gate, plan: &Plan) -> Result<JointPath, Error> {
        Ok(gate.check_columns(&self.names, &plan.t, &plan.rows)?)
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

/// The longest movement a skill plans, s (a pour lasts seconds): a
/// longer one, given or learned, is refused before it is computed.
pub const MAX_DURATION: f32 = 600.0;

/// The most samples a skill plans for one movement (600 s at 1 ms
/// steps, with room): each is a row of every column.
pub const MAX_SAMPLES: usize = 1_000_000;

/// `Σ_i c_i·rows_i`, `n` values: a value the examples give per example,
/// generalized with the skill's coefficients.
fn combine(rows: &[Vec<f32>], c: &[f32], n: usize) -> Vec<f32> {
    (0..n)
        .map(|d| {
            (rows.iter().zip(c))
                .map(|(row, c)| c * row.get(d).copied().unwrap_or(0.0))
                .sum()
        })
        .collect()
}

/// Checks a movement of `tau` seconds sampled every `dt` seconds against
/// [`MAX_DURATION`] and [`MAX_SAMPLES`].
pub fn check_duration(tau: f32, dt: f64) -> Result<(), Error> {
    if !(tau.is_finite() && tau > 0.0 && tau <= MAX_DURATION) {
        return Err(Error::Movement(format!(
            "τ {tau} s: a movement lasts more than 0 and at most {MAX_DURATION} s"
        )));
    }
    let samples = f64::from(tau) / dt;
    if samples.is_nan() || samples > MAX_SAMPLES as f64 {
        return Err(Error::Movement(format!(
            "τ {tau} s sampled every {dt} s: {samples:.0} samples, at most {MAX_SAMPLES}"
        )));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn yaw(deg: f32) -> Quaternion {
        Quaternion::exp([0.0, 0.0, deg.to_radians()])
    }

    /// `x` from 0 to `x`, yaw from `from`° to `to`°, the quaternion's sign
    /// flipped on every third row (as some recorders do).
    fn demo(x: f32, from: f32, to: f32) -> Demo {
        let times: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
        let positions = times
            .iter()
            .enumerate()
            .flat_map(|(i, &t)| {
                let s = t * t * (3.0 - 2.0 * t);
                let q = yaw(from + (to - from) * s);
                let q = if i % 3 == 1 { q.neg() } else { q };
                [x * s].into_iter().chain(q.to_array())
            })
            .collect();
        Demo {
            names: ["x", "qw", "qx", "qy", "qz"].map(String::from).to_vec(),
            times,
            positions,
        }
    }

    fn last_orientation(plan: &Plan) -> Quaternion {
        let row = &plan.rows[plan.rows.len() - 5..];
        Quaternion::from_array([row[1], row[2], row[3], row[4]].map(|v| v as f32))
    }

    #[test]
    fn a_movement_too_long_is_refused_before_it_is_computed() {
        let skill = Skill::fit(
            &[
                (&[0.0], &demo(0.2, 0.0, 10.0)),
                (&[1.0], &demo(0.4, 0.0, 20.0)),
            ],
            10,
            Method::Lwr { bandwidth: None },
        )
        .unwrap();
        let mut delta = vec![0.0; skill.param_len()];
        let tau = delta.len() - 1;
        delta[tau] = 1e5;
        let e = skill.plan(&[0.5], &delta, 0.002).unwrap_err().to_string();
        assert!(
            e.contains("a movement lasts more than 0 and at most 600 s"),
            "{e}"
        );
        let e = skill.plan(&[0.5], &[], 1e-7).unwrap_err().to_string();
        assert!(e.contains("samples, at most 1000000"), "{e}");
        assert!(skill.plan(&[0.5], &[], 0.002).is_ok());
    }

    #[test]
    fn an_orientation_group_is_generalized_in_the_tangent_space() {
        let (a, b) = (demo(0.2, 140.0, 170.0), demo(0.4, -140.0, -170.0));
        let skill = Skill::fit(
            &[(&[0.0], &a), (&[1.0], &b)],
            10,
            Method::Lwr { bandwidth: None },
        )
        .unwrap();
        // x: 1 DoF, the orientation: 3.
        assert_eq!((skill.dof(), skill.param_len()), (4, 4 * 10 + 4 + 1));
        for (q, expect) in [(0.0, 170.0), (0.5, 180.0), (1.0, 190.0)] {
            let plan = skill.plan(&[q], &[], 0.01).unwrap();
            assert_eq!(plan.dof, 5);
            for row in plan.rows.chunks_exact(5) {
                let norm = row[1..].iter().map(|v| v * v).sum::<f64>().sqrt();
                assert!((norm - 1.0).abs() < 1e-5, "{row:?}");
            }
            let end = last_orientation(&plan);
            assert!(end.dot(&yaw(expect)).abs() > 1.0 - 1e-6, "q {q}: {end:?}");
            let first = &plan.rows[..5];
            let start =
                Quaternion::from_array([first[1], first[2], first[3], first[4]].map(|v| v as f32));
            let from = 140.0 + 80.0 * q;
            assert!(start.dot(&yaw(from)).abs() > 1.0 - 1e-6, "q {q}: {start:?}");
        }
        // Δθ on the group's third goal value turns the goal about z.
        let mut delta = vec![0.0; skill.param_len()];
        delta[4 * 10 + 3] = 5f32.to_radians();
        let plan = skill.plan(&[0.5], &delta, 0.01).unwrap();
        let end = last_orientation(&plan);
        assert!(end.dot(&yaw(185.0)).abs() > 1.0 - 1e-6, "{end:?}");
        // The changed goal leaves the start where it was.
        let first = &plan.rows[..5];
        let start =
            Quaternion::from_array([first[1], first[2], first[3], first[4]].map(|v| v as f32));
        assert!(start.dot(&yaw(180.0)).abs() > 1.0 - 1e-6, "{start:?}");
    }

    #[test]
    fn a_position_column_after_an_orientation_is_its_dof_less_one() {
        // The columns x, qw, qx, qy, qz, then as qw, qx, qy, qz, x.
        let moved = |d: Demo| Demo {
            names: ["qw", "qx", "qy", "qz", "x"].map(String::from).to_vec(),
            positions: (d.positions.chunks_exact(5))
                .flat_map(|r| [r[1], r[2], r[3], r[4], r[0]])
                .collect(),
            times: d.times,
        };
        let lwr = Method::Lwr { bandwidth: None };
        let (a, b) = (demo(0.2, 140.0, 170.0), demo(0.4, 150.0, 170.0));
        let first = Skill::fit(&[(&[0.0], &a), (&[1.0], &b)], 5, lwr).unwrap();
        assert_eq!(first.position_dof("x"), Some(0));
        let (a, b) = (moved(a), moved(b));
        let last = Skill::fit(&[(&[0.0], &a), (&[1.0], &b)], 5, lwr).unwrap();
        assert_eq!(last.position_dof("x"), Some(3));
        for skill in [first, last] {
            assert_eq!(skill.position_dof("qw"), None);
            assert_eq!(skill.position_dof("y"), None);
        }
    }

    /// A screw of `deg` degrees about a tool axis wobbling by 1°, its
    /// sign flipped on every third row.
    fn screw(deg: f32) -> (Demo, impl Fn(f32) -> Quaternion) {
        let pose = Quaternion::exp([0.4, -0.3, 0.2]);
        let at = move |t: f32| {
            let s = t * t * (3.0 - 2.0 * t);
            let w = 1f32.to_radians();
            pose.mul(&Quaternion::exp([
                w * (5.0 * t).sin(),
                w * (3.0 * t).cos(),
                0.0,
            ]))
            .mul(&Quaternion::exp([0.0, 0.0, deg.to_radians() * s]))
        };
        let times: Vec<f32> = (0..=500).map(|i| i as f32 / 500.0).collect();
        let positions = times
            .iter()
            .enumerate()
            .flat_map(|(i, &t)| {
                let q = if i % 3 == 1 { at(t).neg() } else { at(t) };
                [0.03 * t].into_iter().chain(q.to_array())
            })
            .collect();
        let names = ["z", "qw", "qx", "qy", "qz"].map(String::from).to_vec();
        (
            Demo {
                names,
                times,
                positions,
            },
            at,
        )
    }

    fn angle(a: &Quaternion, b: &Quaternion) -> f32 {
        let d = a.mul(&b.conj());
        2.0 * (d.x * d.x + d.y * d.y + d.z * d.z).sqrt().atan2(d.w.abs())
    }

    #[test]
    fn screws_of_several_turns_generalize_in_one_chart_and_keep_their_start() {
        let ((a, at_a), (b, _)) = (screw(540.0), screw(630.0));
        let skill = Skill::fit(
            &[(&[0.0], &a), (&[1.0], &b)],
            30,
            Method::Lwr { bandwidth: None },
        )
        .unwrap();
        let orientation = |row: &[f64]| {
            Quaternion::from_array([row[1], row[2], row[3], row[4]].map(|v| v as f32))
        };
        let plan = skill.plan(&[0.0], &[], 0.002).unwrap();
        let worst = plan
            .rows
            .chunks_exact(5)
            .zip(&plan.t)
            .map(|(row, &t)| angle(&orientation(row), &at_a(t as f32)))
            .fold(0.0, f32::max);
        assert!(
            worst.to_degrees() < 0.5,
            "the first screw off by {}°",
            worst.to_degrees()
        );
        // Half way: 585°, travelled step by step; a changed goal keeps the start.
        let mut delta = vec![0.0; skill.param_len()];
        delta[4 * 30 + 1] = 0.2;
        let plan = skill.plan(&[0.5], &delta, 0.002).unwrap();
        let path: Vec<Quaternion> = plan.rows.chunks_exact(5).map(orientation).collect();
        let travelled: f32 = path.windows(2).map(|w| angle(&w[0], &w[1])).sum();
        assert!(
            (travelled.to_degrees() - 585.0).abs() < 30.0,
            "{}°",
            travelled.to_degrees()
        );
        assert!(angle(&path[0], &at_a(0.0)) < 1e-4, "{:?}", path[0]);
        // Fitted each on its own, the two screws are charted about their
        // own axes: refused, in words.
        let fit = |demo: &Demo| {
            DmpFile::fit_with(
                "demo",
                demo,
                30,
                (AmplitudeScaling::PerDof, None),
                &FitOptions::LEARNING,
            )
            .unwrap()
        };
        let (fa, fb) = (fit(&a), fit(&b));
        assert_ne!(fa.orientations[0].axis, fb.orientations[0].axis);
        let e = Skill::from_files(
            &[(&[0.0], &fa), (&[1.0], &fb)],
            Method::Lwr { bandwidth: None },
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("charted about another axis"), "{e}");
    }
}
