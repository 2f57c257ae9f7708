//! The pour's skill: demonstrations of pouring (the files given, or the
//! expert's built-in pair) fitted and generalized over the bottle's
//! volume, and the pouring cell's safety gate.

use std::path::PathBuf;

use primo_core::generalize::Method as Regression;
use primo_robot::{CartesianLimits, Gate};
use primo_robot::{JOINT_COLUMNS, POSE_COLUMNS};
use primo_sim::cell::{CellConfig, GlassKind};
use primo_sim::expert::{BUILT_IN, Recording, rest_configuration, synthesize};
use primo_skill::csv::{Demo, parse_demo, rotation_vectors_as_quaternions};
use primo_skill::skill::same_columns;
use primo_skill::{MAX_KERNELS, Skill};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::algorithm::Algorithm;
use crate::error::Setting;

/// The coordinates a pour is learned in.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Space {
    /// The bottle's pose: its mouth's position (m) and orientation (unit
    /// quaternion).
    Cartesian,
    /// The arm's seven joint angles (rad).
    Joint,
}

impl Space {
    /// Column names of the space's trajectories.
    pub fn names(self) -> &'static [&'static str] {
        match self {
            Space::Cartesian => &POSE_COLUMNS,
            Space::Joint => &JOINT_COLUMNS,
        }
    }

    /// The space a pour learns in by default: joint space for PoWER (the
    /// paper's second experiment), Cartesian for error learning.
    pub fn default_for(method: Algorithm) -> Space {
        match method.is_power() {
            true => Space::Joint,
            false => Space::Cartesian,
        }
    }

    /// The space whose columns are `names`, if any.
    pub fn of(names: &[String]) -> Option<Space> {
        [Space::Joint, Space::Cartesian]
            .into_iter()
            .find(|s| s.names().iter().eq(names.iter()))
    }
}

/// A demonstration file and the query (bottle volume, l) it shows.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct DemoFile {
    /// The CSV file (absolute in a run log).
    pub file: PathBuf,
    /// Its query.
    pub volume: f32,
}

/// The skill a run learns: demonstrations fitted and generalized.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkillSpec {
    /// Coordinates of the movement.
    pub space: Space,
    /// The glass on the scale (the simulated cell's; on a real cell, the
    /// arm's model and the workspace are the same).
    pub glass: GlassKind,
    /// Kernels per DoF.
    pub kernels: usize,
    /// The demonstrations; empty for the built-in pair.
    pub demos: Vec<DemoFile>,
}

impl SkillSpec {
    /// Checks the settings without reading a file: the kernel count, and
    /// at least two demonstrations at distinct, positive volumes.
    pub fn validate(&self) -> Result<(), Error> {
        if !(2..=MAX_KERNELS).contains(&self.kernels) {
            return Err(Error::setting(
                Setting::Kernels,
                self.kernels,
                format!("must be in 2..={MAX_KERNELS}"),
            ));
        }
        if self.demos.len() == 1 {
            return Err(Error::setting(
                Setting::Demo,
                self.demos[0].file.display(),
                "one demonstration cannot be generalized; give at least two, at different \
                 volumes (or none for the built-in pair)",
            ));
        }
        for (i, d) in self.demos.iter().enumerate() {
            if !(d.volume.is_finite() && d.volume > 0.0) {
                return Err(Error::setting(
                    Setting::Demo,
                    format!("{}={}", d.file.display(), d.volume),
                    "the volume must be a positive number of litres",
                ));
            }
            if let Some(same) = self.demos[..i].iter().find(|e| e.volume == d.volume) {
                return Err(Error::setting(
                    Setting::Demo,
                    format!("{}={}", d.file.display(), d.volume),
                    format!(
                        "{} shows the same volume; the demonstrations must show different \
                         volumes to generalize over",
                        same.file.display()
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The simulated cell with this glass.
    pub fn cell(&self) -> CellConfig {
        CellConfig::standard(self.glass)
    }

    /// The cell and the fitted skill. A Cartesian demonstration in the
    /// rotation-vector columns of earlier versions is converted
    /// ([`upgrade`]) and said so in [`Built::converted`].
    pub fn build(&self) -> Result<Built, Error> {
        self.validate()?;
        let cell = self.cell();
        if self.demos.is_empty() {
            let skill = built_in_skill(&cell, self.space, self.kernels)?;
            return Ok(Built {
                cell,
                skill,
                converted: Vec::new(),
            });
        }
        let mut demos = Vec::new();
        let mut converted = Vec::new();
        for d in &self.demos {
            let text = Error::read(Setting::Demo, &d.file)?;
            let name = d.file.display().to_string();
            let mut demo = parse_demo(&name, &text)?;
            if self.space == Space::Cartesian
                && let Some((quaternions, wraps)) = upgrade(&demo)
            {
                demo = quaternions;
                converted.push(Converted {
                    file: d.file.clone(),
                    wraps,
                });
            }
            demos.push((name, d.volume, demo));
        }
        let skill = fit(self.space, &demos, self.kernels)?;
        Ok(Built {
            cell,
            skill,
            converted,
        })
    }
}

/// A skill built: the cell, the fitted skill, and the demonstrations
/// converted from rotation vectors.
#[derive(Debug, Clone)]
pub struct Built {
    /// The cell.
    pub cell: CellConfig,
    /// The skill.
    pub skill: Skill,
    /// The demonstration files read in the earlier Cartesian columns.
    pub converted: Vec<Converted>,
}

/// The Cartesian columns before the orientation was a quaternion: the
/// mouth's position and the bottle's rotation vector.
pub const ROTATION_VECTOR_NAMES: [&str; 6] = ["x", "y", "z", "rx", "ry", "rz"];

/// A Cartesian demonstration in [`ROTATION_VECTOR_NAMES`] as one in the
/// quaternion columns ([`rotation_vectors_as_quaternions`]: every row's
/// rotation exactly, the 2π wraps undone), and the rows where the vector
/// wrapped; `None` for any other columns.
pub fn upgrade(demo: &Demo) -> Option<(Demo, Vec<usize>)> {
    ROTATION_VECTOR_NAMES
        .iter()
        .eq(&demo.names)
        .then(|| rotation_vectors_as_quaternions(demo))
        .flatten()
}

/// A demonstration file read in [`ROTATION_VECTOR_NAMES`] and converted.
#[derive(Debug, Clone, PartialEq)]
pub struct Converted {
    /// The file.
    pub file: std::path::PathBuf,
    /// The data rows (from 1) where its rotation vector wrapped by 2π.
    pub wraps: Vec<usize>,
}

impl std::fmt::Display for Converted {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "{}: columns {} (a rotation vector) read as {} (its quaternion, sign-continuous)",
            self.file.display(),
            ROTATION_VECTOR_NAMES.join(","),
            Space::Cartesian.names().join(",")
        )?;
        match self.wraps.as_slice() {
            [] => Ok(()),
            [row] => write!(f, "; the 2π jump at row {row} unwrapped"),
            rows => write!(
                f,
                "; {} 2π jumps unwrapped (rows {})",
                rows.len(),
                rows.iter()
                    .map(|r| r.to_string())
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
        }
    }
}

/// The pouring cell's gate, the same for the simulated and the real cell:
/// the cell's arm holding the bottle (its grasp), the mouth as the
/// controlled point, the mouth's workspace and speed limits, and the rest
/// posture between the demonstrators' elbows.
pub fn gate(cell: &CellConfig) -> Gate {
    Gate {
        arm: cell.arm(),
        reach: cell.bottle.length,
        limits: CartesianLimits::default(),
        rest: rest_configuration(0.0),
    }
}

/// The demonstrations from the expert: 0.2 l from 0.3 l and 1.0 l bottles,
/// in `space` coordinates, as `(bottle volume, recording)`.
pub fn built_in_demos(cell: &CellConfig, space: Space) -> Result<Vec<(f32, Demo)>, Error> {
    BUILT_IN
        .iter()
        .map(|(volume, style)| {
            let demo = synthesize(cell, *volume, 0.2, style)?;
            Ok((*volume as f32, to_csv_demo(&demo, space)))
        })
        .collect()
}

/// A recording in the CSV layout of `space`.
pub fn to_csv_demo(demo: &Recording, space: Space) -> Demo {
    let positions = match space {
        Space::Cartesian => demo.cartesian.iter().flatten().map(|v| *v as f32).collect(),
        Space::Joint => demo.joints.iter().flatten().map(|v| *v as f32).collect(),
    };
    Demo {
        names: space.names().iter().map(|s| s.to_string()).collect(),
        times: demo.t.iter().map(|t| *t as f32).collect(),
        positions,
    }
}

/// The skill fitted to the built-in demonstrations (LWR over the volume,
/// which with two examples is the paper's linear interpolation).
pub fn built_in_skill(cell: &CellConfig, space: Space, kernels: usize) -> Result<Skill, Error> {
    let demos = built_in_demos(cell, space)?;
    let named: Vec<(String, f32, Demo)> = demos
        .into_iter()
        .map(|(q, d)| (format!("the built-in {q} l demonstration"), q, d))
        .collect();
    fit(space, &named, kernels)
}

/// The pouring skill in `space` fitted to `demos` (a name for messages,
/// the bottle volume, the recording), generalized by LWR over the volume.
/// Every demonstration's columns are the space's, by name and in order.
pub fn fit(space: Space, demos: &[(String, f32, Demo)], kernels: usize) -> Result<Skill, Error> {
    let expected: Vec<String> = space.names().iter().map(|n| n.to_string()).collect();
    for (name, _, demo) in demos {
        same_columns(&expected, &demo.names).map_err(|why| {
            Error::Invalid(format!(
                "{name}: {why}; {space:?} space's columns are t,{}",
                expected.join(",")
            ))
        })?;
    }
    let queries: Vec<[f32; 1]> = demos.iter().map(|(_, q, _)| [*q]).collect();
    let examples: Vec<(&[f32], &Demo)> = queries
        .iter()
        .zip(demos)
        .map(|(q, (_, _, d))| (&q[..], d))
        .collect();
    Ok(Skill::fit(
        &examples,
        kernels,
        Regression::Lwr { bandwidth: None },
    )?)
}
