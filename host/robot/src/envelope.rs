//! Limits of a trajectory of named coordinates, for skills that are not the
//! pouring cell's: a robot preset (its joint limits, the columns being its
//! joints) or per-column position and speed limits with an optional
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

use crate::{JOINTS, Rejection, Robot, check_joints};

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

/// The limits a task's trajectories pass.
#[derive(Debug, Clone, PartialEq)]
pub enum Limits {
    /// A robot's joint limits; the columns are its joints in order, named
    /// as robot users write them (see [`joint_index`]).
    Robot(Robot),
    /// Per-column limits.
    Envelope(Envelope),
}

/// The joint a column name stands for, from 0: `a1`…`a7`, KUKA's `A1`…`A7`,
/// `j1`…`j7`, `joint_1`…`joint_7`.
pub fn joint_index(name: &str) -> Option<usize> {
    let digits = ["joint_", "a", "A", "j"]
        .iter()
        .find_map(|p| name.strip_prefix(p))?;
    let n: usize = digits.parse().ok()?;
    (1..=JOINTS).contains(&n).then(|| n - 1)
}

/// A trajectory that passed its [`Limits`]: times strictly increasing,
/// every value finite and within them.
#[derive(Debug, Clone, PartialEq)]
pub struct Checked {
    names: Vec<String>,
    times: Vec<f64>,
    rows: Vec<f64>,
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
}

impl Limits {
    /// Checks that the columns `names` can be limited at all: a robot's
    /// joints in order, or a limit for every column (and the workspace's
    /// columns among them). The message names the column.
    pub fn covers(&self, names: &[String]) -> Result<(), String> {
        match self {
            Limits::Robot(_) => {
                if names.len() != JOINTS {
                    return Err(format!(
                        "the robot preset limits {JOINTS} joint columns (a1..a7), the \
                         trajectory has {}",
                        names.len()
                    ));
                }
                for (i, n) in names.iter().enumerate() {
                    if joint_index(n) != Some(i) {
                        return Err(format!(
                            "column {} `{n}` is not joint {} (a{0}, A{0}, j{0} or joint_{0})",
                            i + 1,
                            i + 1
                        ));
                    }
                }
                Ok(())
            }
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
        self.covers(names).map_err(Rejection::Columns)?;
        match self {
            Limits::Robot(robot) => {
                let joints: Vec<[f64; JOINTS]> = rows
                    .chunks_exact(JOINTS)
                    .map(|r| std::array::from_fn(|j| r.get(j).copied().unwrap_or(f64::NAN)))
                    .collect();
                check_joints(robot, times.clone(), joints)?;
            }
            Limits::Envelope(e) => e.check(names, &times, rows)?,
        }
        Ok(Checked {
            names: names.to_vec(),
            times,
            rows: rows.to_vec(),
        })
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

    #[test]
    fn joint_names_as_robot_users_write_them() {
        for (n, i) in [("a1", 0), ("A7", 6), ("j3", 2), ("joint_4", 3)] {
            assert_eq!(joint_index(n), Some(i), "{n}");
        }
        for n in ["a0", "a8", "x", "joint_", "a", "a1b", "J1", "joint5"] {
            assert_eq!(joint_index(n), None, "{n}");
        }
    }

    #[test]
    fn a_robot_preset_checks_its_joints_in_order() {
        let lwr = Limits::Robot(Robot::lwr4());
        let cols = names(&["A1", "A2", "A3", "A4", "A5", "A6", "A7"]);
        let still = [0.0, 0.5, 0.0, -1.0, 0.0, 0.5, 0.0];
        let rows: Vec<f64> = [still, still].concat();
        assert!(lwr.check(&cols, vec![0.0, 0.01], &rows).is_ok());
        let swapped = names(&["a2", "a1", "a3", "a4", "a5", "a6", "a7"]);
        let err = lwr.check(&swapped, vec![0.0, 0.01], &rows).unwrap_err();
        assert!(err.to_string().contains("`a2` is not joint 1"), "{err}");
        let mut fast = still;
        fast[1] = 0.6;
        let rows: Vec<f64> = [still, fast].concat();
        let err = lwr.check(&cols, vec![0.0, 0.01], &rows).unwrap_err();
        assert!(err.to_string().contains("joint a2 at sample 1"), "{err}");
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
