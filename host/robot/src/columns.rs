//! What a trajectory's columns (after `t`) are to a [`Chain`]: its joints
//! by name, each once, in any order; or its tool's pose
//! [`POSE_COLUMNS`], each once, in any order.
//!
//! ```
//! use primo_robot::Robot;
//! use primo_robot::columns::Columns;
//! let lwr = Robot::lwr4().chain();
//! let names = |n: &[&str]| n.iter().map(|s| s.to_string()).collect::<Vec<_>>();
//! let c = Columns::of(&lwr, &names(&["A2", "A1", "A3", "A4", "A5", "A6", "A7"])).unwrap();
//! assert_eq!(c, Columns::Joints(vec![1, 0, 2, 3, 4, 5, 6]));
//! let err = Columns::of(&lwr, &names(&["a1", "x"])).unwrap_err();
//! assert!(err.to_string().starts_with("column 3 `x` names no joint"), "{err}");
//! ```

use crate::chain::Chain;
use crate::safety::POSE_COLUMNS;

/// How a trajectory's columns map onto a chain.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Columns {
    /// Column `c` is joint `joints[c]` of the chain.
    Joints(Vec<usize>),
    /// Column `c` is coordinate `coordinates[c]` of [`POSE_COLUMNS`].
    Pose(Vec<usize>),
}

/// Columns that are neither a chain's joints nor its tool's pose.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum ColumnsError {
    /// A column that names no joint (nor a pose coordinate).
    #[error(
        "column {column} `{name}` names no joint; the columns after t are the joints ({joints}) \
         or the tool pose ({})",
        POSE_COLUMNS.join(",")
    )]
    Unknown {
        /// Its place in the file, `t` being column 1.
        column: usize,
        /// Its name.
        name: String,
        /// The chain's joints, comma-separated.
        joints: String,
    },
    /// Two columns for one joint or coordinate.
    #[error("columns `{first}` and `{second}` both name {what}")]
    Twice {
        /// The first column's name.
        first: String,
        /// The second's.
        second: String,
        /// `joint NAME` or `coordinate NAME`.
        what: String,
    },
    /// A joint without a column.
    #[error(
        "no column for joint `{joint}`: a joint trajectory of {robot} has every joint ({joints})"
    )]
    MissingJoint {
        /// The joint.
        joint: String,
        /// The robot.
        robot: String,
        /// The chain's joints, comma-separated.
        joints: String,
    },
    /// A pose coordinate without a column.
    #[error("no column `{coordinate}`: a tool trajectory has the columns t,{}", POSE_COLUMNS.join(","))]
    MissingPose {
        /// The coordinate.
        coordinate: &'static str,
    },
}

impl Columns {
    /// The chain's joints or pose coordinates `names` stand for; a pose
    /// when no name is a joint's and one is a pose coordinate's.
    pub fn of(chain: &Chain, names: &[String]) -> Result<Columns, ColumnsError> {
        let joints = || chain.names().join(", ");
        let pose = names.iter().all(|n| chain.index(n).is_none())
            && names.iter().any(|n| POSE_COLUMNS.contains(&n.as_str()));
        let mut mapped: Vec<usize> = Vec::with_capacity(names.len());
        for (c, name) in names.iter().enumerate() {
            let found = match pose {
                true => POSE_COLUMNS.iter().position(|p| p == name),
                false => chain.index(name),
            };
            let Some(k) = found else {
                return Err(ColumnsError::Unknown {
                    column: c + 2,
                    name: name.clone(),
                    joints: joints(),
                });
            };
            if let Some(first) = mapped.iter().position(|&m| m == k) {
                let what = match pose {
                    true => format!("coordinate {}", POSE_COLUMNS[k]),
                    false => format!("joint {}", chain.joints()[k].name),
                };
                return Err(ColumnsError::Twice {
                    first: names[first].clone(),
                    second: name.clone(),
                    what,
                });
            }
            mapped.push(k);
        }
        if pose {
            if let Some(k) = (0..POSE_COLUMNS.len()).find(|k| !mapped.contains(k)) {
                return Err(ColumnsError::MissingPose {
                    coordinate: POSE_COLUMNS[k],
                });
            }
            return Ok(Columns::Pose(mapped));
        }
        if let Some(j) = (0..chain.dof()).find(|j| !mapped.contains(j)) {
            return Err(ColumnsError::MissingJoint {
                joint: chain.joints()[j].name.clone(),
                robot: chain.robot.clone(),
                joints: joints(),
            });
        }
        Ok(Columns::Joints(mapped))
    }

    /// Rows of these columns (row-major) reordered: the chain's joints in
    /// its order, `dof` per row (for [`Columns::Joints`]), or the poses
    /// `[x, y, z, qw, qx, qy, qz]` flattened (for [`Columns::Pose`]).
    pub fn reorder(&self, rows: &[f64]) -> Vec<f64> {
        let (Columns::Joints(to) | Columns::Pose(to)) = self;
        let width = to.len();
        let mut out = vec![0.0; rows.len()];
        for (from, into) in rows.chunks_exact(width).zip(out.chunks_exact_mut(width)) {
            for (&k, &v) in to.iter().zip(from) {
                if let Some(slot) = into.get_mut(k) {
                    *slot = v;
                }
            }
        }
        out
    }

    /// Rows [`Columns::reorder`]ed from pose columns as poses `[x, y, z,
    /// qw, qx, qy, qz]`.
    pub fn poses(ordered: &[f64]) -> Vec<[f64; 7]> {
        ordered
            .chunks_exact(7)
            .map(|p| std::array::from_fn(|k| p.get(k).copied().unwrap_or(f64::NAN)))
            .collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::Robot;

    fn names(n: &[&str]) -> Vec<String> {
        n.iter().map(|s| s.to_string()).collect()
    }

    #[test]
    fn joints_by_name_or_number_and_poses_in_any_order() {
        let lwr = Robot::lwr4().chain();
        for (n, i) in [("a1", 0), ("A7", 6), ("j3", 2), ("joint_4", 3)] {
            assert_eq!(lwr.index(n), Some(i), "{n}");
        }
        for n in ["a0", "a8", "x", "joint_", "a", "a1b", "J1", "joint5", "a+1"] {
            assert_eq!(lwr.index(n), None, "{n}");
        }
        let pose = names(&["qw", "qx", "qy", "qz", "x", "y", "z"]);
        let c = Columns::of(&lwr, &pose).unwrap();
        assert_eq!(c, Columns::Pose(vec![3, 4, 5, 6, 0, 1, 2]));
        let row = [1.0, 0.0, 0.0, 0.0, 0.5, 0.1, 0.7];
        assert_eq!(c.reorder(&row), [0.5, 0.1, 0.7, 1.0, 0.0, 0.0, 0.0]);
        let swapped = names(&["a2", "a1", "a3", "a4", "a5", "a6", "a7"]);
        let c = Columns::of(&lwr, &swapped).unwrap();
        assert_eq!(
            c.reorder(&[2.0, 1.0, 3.0, 4.0, 5.0, 6.0, 7.0])[..2],
            [1.0, 2.0]
        );
    }

    #[test]
    fn a_column_that_is_neither_is_named() {
        let lwr = Robot::lwr4().chain();
        let err = Columns::of(&lwr, &names(&["a1", "A1"])).unwrap_err();
        assert_eq!(err.to_string(), "columns `a1` and `A1` both name joint a1");
        let err = Columns::of(&lwr, &names(&["a1", "a2"])).unwrap_err();
        assert!(
            err.to_string().starts_with("no column for joint `a3`"),
            "{err}"
        );
        let err = Columns::of(&lwr, &names(&["x", "y", "z", "qw"])).unwrap_err();
        assert!(err.to_string().starts_with("no column `qx`"), "{err}");
        let err = Columns::of(&lwr, &names(&["x", "y", "x"])).unwrap_err();
        assert!(err.to_string().contains("both name coordinate x"), "{err}");
        let err = Columns::of(&lwr, &names(&["x", "a1"])).unwrap_err();
        assert!(
            err.to_string().starts_with("column 2 `x` names no joint"),
            "{err}"
        );
    }
}
