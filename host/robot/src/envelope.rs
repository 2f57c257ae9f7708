//! Limits of a trajectory of named coordinates, for skills that are not the
//! pouring cell's: a robot's (any [`Chain`]'s joint limits, the columns
//! being its joints by name or its tool's pose, solved by inverse
//! kinematics) or per-column position and speed limits with an optional
//! workspace box over three position columns. What passes is a
//! [`Checked`] trajectory, the only thing a task's evaluator is given.
//!
//! ```
//! use primo_robot::envelope::{ColumnLimit, Envelope, Limits};
//! let limits = Limits::Envelope(Envelope {
//!     columns: vec![ColumnLimit { name: "x".into(), min: 0.0, max: 1.0, max_speed: 2.0 }],
//!     workspace: None,
//! });
//! let names = ["x".to_string()];
//! assert!(limits.check(&names, vec![0.0, 0.1], &[0.2, 0.3]).is_ok());
//! let err = limits.check(&names, vec![0.0, 0.1], &[0.2, 0.6]).unwrap_err();
//! assert_eq!(err.to_string(), "column `x` at sample 1: speed 4.0000 per s beyond the limit of 2 per s");
//! ```

use crate::Rejection;
use crate::chain::Chain;
use crate::columns::Columns;
use crate::ik::IkOptions;
use crate::safety::{JointPath, check_path};
use crate::tool_path::check_tool_path;

/// Position and speed limits of one column.
#[derive(Debug, Clone, PartialEq)]
pub struct ColumnLimit {
    /// The column's name.
    pub name: String,
    /// Lowest value.
    pub min: f64,
    /// Highest value.
    pub max: f64,
    /// Fastest change per second (> 0).
    pub max_speed: f64,
}

/// A box three position columns (a point) stay in.
#[derive(Debug, Clone, PartialEq)]
pub struct WorkspaceBox {
    /// The point's columns, `x`, `y`, `z` in this order.
    pub columns: [String; 3],
    /// Lower corner.
    pub min: [f64; 3],
    /// Upper corner.
    pub max: [f64; 3],
    /// Fastest the point moves, per second (> 0).
    pub max_speed: f64,
}

/// Per-column limits: every column of a trajectory has one.
#[derive(Debug, Clone, PartialEq)]
pub struct Envelope {
    /// One per column, any order.
    pub columns: Vec<ColumnLimit>,
    /// The workspace of a point, if the columns hold one.
    pub workspace: Option<WorkspaceBox>,
}

/// A robot's limits: its chain's joint limits, and an acceleration bound.
#[derive(Debug, Clone, PartialEq)]
pub struct RobotLimits {
    /// The robot, with its joints' limits.
    pub chain: Chain,
    /// Every joint's fastest acceleration (rad/s² or m/s²), if bounded.
    pub max_acceleration: Option<f64>,
    /// The posture a tool trajectory starts from (one position per joint,
    /// the chain's order, within its limits: [`Chain::posture`]): its
    /// first pose is solved from there, so to the robot's own elbow.
    /// Without it, from the middle of the joints' ranges.
    pub start: Option<Vec<f64>>,
}

/// The limits a task's trajectories pass.
#[derive(Debug, Clone, PartialEq)]
pub enum Limits {
    /// A robot's: the columns are its joints by name ([`Chain::index`]) or
    /// its tool's pose ([`Columns`]).
    Robot(RobotLimits),
    /// Per-column limits.
    Envelope(Envelope),
}

/// A trajectory that passed its [`Limits`]: times strictly increasing,
/// every value finite and within them.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    names: Vec<String>,
    times: Vec<f64>,
    rows: Vec<f64>,
    /// For a robot's limits: the joint path, and whether it was solved
    /// from tool poses.
    joints: Option<(JointPath, bool)>,
}

impl Checked {
    /// The column names.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Sample times, s.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// The samples, row-major, one value per column.
    pub fn rows(&self) -> &[f64] {
        &self.rows
    }

    /// For a robot's limits, the joint path that was checked (a tool
    /// trajectory's, by inverse kinematics): what a robot executes.
    pub fn path(&self) -> Option<&JointPath> {
        self.joints.as_ref().map(|(path, _)| path)
    }

    /// The trajectory as a table for whoever executes it: its own columns
    /// and rows, then, for a tool trajectory on a robot, the joint
    /// positions its poses were solved to.
    pub fn table(&self) -> (Vec<String>, Vec<f64>) {
        let Some((path, true)) = &self.joints else {
            return (self.names.clone(), self.rows.clone());
        };
        let joints = path.chain().names();
        let names = (self.names.iter().cloned())
            .chain(joints.iter().map(|n| n.to_string()))
            .collect();
        let rows = self
            .rows
            .chunks_exact(self.names.len())
            .zip(path.rows())
            .flat_map(|(own, q)| own.iter().chain(q).copied())
            .collect();
        (names, rows)
    }
}

impl Limits {
    /// Checks that the columns `names` can be limited at all: a robot's
    /// joints or its tool's pose, or a limit for every column (and the
    /// workspace's columns among them). The message names the column.
    pub fn covers(&self, names: &[String]) -> Result<(), String> {
        match self {
            Limits::Robot(r) => r.columns(names).map(drop),
            Limits::Envelope(e) => {
                for n in names {
                    if !e.columns.iter().any(|c| &c.name == n) {
                        return Err(format!("column `{n}` has no limits"));
                    }
                }
                for c in e.workspace.iter().flat_map(|w| &w.columns) {
                    if !names.contains(c) {
                        return Err(format!("the workspace's column `{c}` is not a column"));
                    }
                }
                Ok(())
            }
        }
    }

    /// Checks a trajectory: `times[i]` and row `i` of `rows` (one value
    /// per column of `names`, row-major). The rejection names the sample
    /// and the column.
    pub fn check(
        &self,
        names: &[String],
        times: Vec<f64>,
        rows: &[f64],
    ) -> Result<Checked, Rejection> {
        let width = names.len();
        if width == 0 || times.is_empty() || rows.len() != times.len() * width {
            return Err(Rejection::Shape {
                times: times.len(),
                samples: rows.len() / width.max(1),
            });
        }
        let joints = match self {
            // Its columns are mapped (and refused) as they are checked.
            Limits::Robot(r) => Some(r.check(names, &times, rows)?),
            Limits::Envelope(e) => {
                self.covers(names).map_err(Rejection::Columns)?;
                e.check(names, &times, rows)?;
                None
            }
        };
        Ok(Checked {
            names: names.to_vec(),
            times,
            rows: rows.to_vec(),
            joints,
        })
    }
}

impl RobotLimits {
    /// What the columns `names` are to the robot: its joints, or its
    /// tool's pose (the only trajectory a start posture is for).
    fn columns(&self, names: &[String]) -> Result<Columns, String> {
        match Columns::of(&self.chain, names) {
            Ok(Columns::Joints(_)) if self.start.is_some() => Err(
                "a start posture is for a tool trajectory: a joint trajectory starts at its first \
                 sample"
                    .into(),
            ),
            mapped => mapped.map_err(|e| e.to_string()),
        }
    }

    /// The joint path of a trajectory of joints or tool poses, checked;
    /// whether it was solved from poses.
    fn check(
        &self,
        names: &[String],
        times: &[f64],
        rows: &[f64],
    ) -> Result<(JointPath, bool), Rejection> {
        let columns = self.columns(names).map_err(Rejection::Columns)?;
        let ordered = columns.reorder(rows);
        if let Columns::Joints(_) = columns {
            let path = check_path(&self.chain, times.to_vec(), ordered, self.max_acceleration)?;
            return Ok((path, false));
        }
        let q = check_tool_path(
            &self.chain,
            times,
            &Columns::poses(&ordered),
            self.start.as_deref(),
            self.max_acceleration,
            &IkOptions::default(),
        )?;
        // `check_tool_path` has checked the joints it solved.
        Ok((JointPath::solved(&self.chain, times.to_vec(), q), true))
    }
}

impl Envelope {
    /// Positions, speeds and the workspace, sample by sample.
    fn check(&self, names: &[String], times: &[f64], rows: &[f64]) -> Result<(), Rejection> {
        let width = names.len();
        let limits: Vec<&ColumnLimit> = names
            .iter()
            .filter_map(|n| self.columns.iter().find(|c| &c.name == n))
            .collect();
        let point: Option<[usize; 3]> = self.workspace.as_ref().and_then(|w| {
            let at = |c: &String| names.iter().position(|n| n == c);
            Some([at(&w.columns[0])?, at(&w.columns[1])?, at(&w.columns[2])?])
        });
        let mut last: Option<(f64, &[f64])> = None;
        for (sample, (&t, row)) in times.iter().zip(rows.chunks_exact(width)).enumerate() {
            if !t.is_finite() || row.iter().any(|v| !v.is_finite()) {
                return Err(Rejection::NonFinite { sample });
            }
            if last.is_some_and(|(t0, _)| t <= t0) {
                return Err(Rejection::TimeOrder { sample, time: t });
            }
            for (j, (&v, c)) in row.iter().zip(&limits).enumerate() {
                if v < c.min || v > c.max {
                    return Err(Rejection::Column {
                        sample,
                        column: c.name.clone(),
                        value: v,
                        low: c.min,
                        high: c.max,
                    });
                }
                if let Some((t0, r0)) = last {
                    let speed = (v - r0.get(j).copied().unwrap_or(v)).abs() / (t - t0);
                    if speed > c.max_speed {
                        return Err(Rejection::ColumnSpeed {
                            sample,
                            column: c.name.clone(),
                            speed,
                            limit: c.max_speed,
                        });
                    }
                }
            }
            if let (Some(w), Some(idx)) = (&self.workspace, point) {
                let p = idx.map(|i| row.get(i).copied().unwrap_or(f64::NAN));
                for (k, v) in p.iter().enumerate() {
                    let (low, high) = (w.min[k], w.max[k]);
                    if !(low..=high).contains(v) {
                        return Err(Rejection::Column {
                            sample,
                            column: w.columns[k].clone(),
                            value: *v,
                            low,
                            high,
                        });
                    }
                }
                if let Some((t0, r0)) = last {
                    let d = idx.map(|i| {
                        row.get(i).copied().unwrap_or(0.0) - r0.get(i).copied().unwrap_or(0.0)
                    });
                    let speed = (d[0] * d[0] + d[1] * d[1] + d[2] * d[2]).sqrt() / (t - t0);
                    if speed > w.max_speed {
                        return Err(Rejection::PointSpeed {
                            sample,
                            columns: w.columns.join(", "),
                            speed,
                            limit: w.max_speed,
                        });
                    }
                }
            }
            last = Some((t, row));
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    fn reach() -> Limits {
        let c = |n: &str| ColumnLimit {
            name: n.into(),
            min: -1.0,
            max: 1.0,
            max_speed: 2.0,
        };
        Limits::Envelope(Envelope {
            columns: vec![c("x"), c("y"), c("z")],
            workspace: Some(WorkspaceBox {
                columns: ["x".into(), "y".into(), "z".into()],
                min: [-0.5, -0.5, 0.0],
                max: [0.5, 0.5, 0.5],
                max_speed: 1.0,
            }),
        })
    }

    fn lwr(max_acceleration: Option<f64>) -> Limits {
        Limits::Robot(RobotLimits {
            chain: crate::Robot::lwr4().chain(),
            max_acceleration,
            start: None,
        })
    }

    #[test]
    fn a_robot_checks_its_joints_by_name_in_any_order() {
        let cols = names(&["A1", "A2", "A3", "A4", "A5", "A6", "A7"]);
        let still = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
        let rows: Vec<f64> = [still, still].concat();
        let checked = lwr(None).check(&cols, vec![0.0, 0.01], &rows).unwrap();
        assert_eq!(checked.table(), (cols.clone(), rows.clone()));
        let swapped = names(&["a2", "a1", "a3", "a4", "a5", "a6", "a7"]);
        let checked = lwr(None).check(&swapped, vec![0.0, 0.01], &rows).unwrap();
        let path = checked.path().unwrap();
        assert_eq!(path.start()[..2], [0.5, 0.0]);
        let mut fast = still;
        fast[1] = 0.6;
        let rows: Vec<f64> = [still, fast].concat();
        let err = lwr(None).check(&cols, vec![0.0, 0.01], &rows).unwrap_err();
        assert!(err.to_string().contains("joint a2 at sample 1"), "{err}");
        // 0.01 rad in 10 ms from rest: 100 rad/s².
        fast[1] = 0.51;
        let rows: Vec<f64> = [still, still, fast].concat();
        let times = vec![0.0, 0.01, 0.02];
        assert!(lwr(Some(200.0)).check(&cols, times.clone(), &rows).is_ok());
        let err = lwr(Some(50.0)).check(&cols, times, &rows).unwrap_err();
        assert!(err.to_string().contains("acceleration"), "{err}");
    }

    #[test]
    fn a_robots_tool_trajectory_is_solved_and_kept_with_its_joints() {
        let chain = crate::Robot::lwr4().chain();
        let pose = |q: &[f64]| {
            let p = chain.forward(q);
            let (t, r) = (p.translation.vector, p.rotation);
            vec![r.w, r.i, r.j, r.k, t.x, t.y, t.z]
        };
        let cols = names(&["qw", "qx", "qy", "qz", "x", "y", "z"]);
        let (a, b) = (
            [0.1, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0],
            [0.12, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0],
        );
        let rows = [pose(&a), pose(&b)].concat();
        let checked = lwr(None).check(&cols, vec![0.0, 0.1], &rows).unwrap();
        let (header, table) = checked.table();
        assert_eq!(header.len(), 14);
        assert_eq!(header[7..], ["a1", "a2", "a3", "a4", "a5", "a6", "a7"]);
        assert_eq!(table[..7], rows[..7]);
        let solved = &table[7..14];
        let reached = pose(solved);
        assert!(
            reached
                .iter()
                .zip(&rows[..7])
                .all(|(u, v)| (u - v).abs() < 1e-6)
        );
        let mut far = rows.clone();
        far[11] = 2.0;
        let err = lwr(None).check(&cols, vec![0.0, 0.1], &far).unwrap_err();
        assert!(
            err.to_string()
                .starts_with("sample 1 (t = 0.100 s): tool pose"),
            "{err}"
        );
    }

    #[test]
    fn a_tool_trajectory_is_solved_from_the_start_posture_to_the_robots_own_joints() {
        let chain = crate::Robot::lwr4().chain();
        let pose = |q: &[f64]| {
            let p = chain.forward(q);
            let (t, r) = (p.translation.vector, p.rotation);
            vec![t.x, t.y, t.z, r.w, r.i, r.j, r.k]
        };
        let cols = names(&["x", "y", "z", "qw", "qx", "qy", "qz"]);
        // Recorded on the redundant arm with its elbow turned well out of
        // the plane; from the middle of the ranges the same poses are
        // reached with the elbow elsewhere on its self-motion.
        let recorded = |k: f64| [0.4, 0.6, 1.0, 1.2 + 0.01 * k, -0.4, -0.5, 0.3];
        let times = vec![0.0, 0.1, 0.2];
        let rows: Vec<f64> = (0..3).flat_map(|k| pose(&recorded(f64::from(k)))).collect();
        let gap = |start: Option<Vec<f64>>| {
            let limits = Limits::Robot(RobotLimits {
                chain: chain.clone(),
                max_acceleration: None,
                start,
            });
            let checked = limits.check(&cols, times.clone(), &rows).unwrap();
            let path = checked.path().unwrap();
            (path.rows().enumerate())
                .flat_map(|(k, q)| q.iter().zip(recorded(k as f64)).map(|(a, b)| (a - b).abs()))
                .fold(0.0, f64::max)
        };
        let elsewhere = gap(None);
        assert!(elsewhere > 0.3, "{elsewhere}");
        let own = gap(Some(recorded(0.0).to_vec()));
        assert!(own < 1e-6, "{own}");
        // A start posture does not belong to a joint trajectory.
        let limits = Limits::Robot(RobotLimits {
            chain,
            max_acceleration: None,
            start: Some(recorded(0.0).to_vec()),
        });
        let joints = names(&["a1", "a2", "a3", "a4", "a5", "a6", "a7"]);
        let err = limits.covers(&joints).unwrap_err();
        assert!(
            err.starts_with("a start posture is for a tool trajectory"),
            "{err}"
        );
    }

    #[test]
    fn columns_and_the_workspace_are_checked_sample_by_sample() {
        let l = reach();
        let cols = names(&["x", "y", "z"]);
        assert!(
            l.check(&cols, vec![0.0, 1.0], &[0.0, 0.0, 0.1, 0.1, 0.0, 0.1])
                .is_ok()
        );
        let err = l
            .check(&cols, vec![0.0, 1.0], &[0.0, 0.0, 0.1, 0.0, 0.0, 0.7])
            .unwrap_err();
        assert_eq!(
            err.to_string(),
            "column `z` at sample 1: 0.7000 outside [0, 0.5]"
        );
        let err = l
            .check(&cols, vec![0.0, 0.1], &[0.0, 0.0, 0.1, 0.15, 0.0, 0.1])
            .unwrap_err();
        assert!(
            err.to_string()
                .contains("the point (x, y, z) moves at 1.5000 per s, beyond 1 per s"),
            "{err}"
        );
        let err = l
            .check(&names(&["x", "w"]), vec![0.0], &[0.0, 0.0])
            .unwrap_err();
        assert!(err.to_string().contains("`w` has no limits"), "{err}");
        let err = l.check(&cols, vec![0.0, 0.0], &[0.0; 6]).unwrap_err();
        assert!(
            matches!(err, Rejection::TimeOrder { sample: 1, .. }),
            "{err}"
        );
        let err = l
            .check(&cols, vec![0.0], &[0.0, f64::NAN, 0.0])
            .unwrap_err();
        assert!(matches!(err, Rejection::NonFinite { sample: 0 }), "{err}");
        let err = l.check(&cols, vec![0.0], &[0.0, 0.0]).unwrap_err();
        assert!(matches!(err, Rejection::Shape { .. }), "{err}");
    }
}
