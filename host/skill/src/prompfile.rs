//! A ProMP by column name and its file, `primo-promp` version 1: what
//! `primo promp fit` writes, `primo promp run` reads and Python's `ProMp`
//! reads and writes. The core's [`ProMp`] on the host's sizes, its numbers
//! ([`ProMp::values`]) under the columns' names.

use primo_core::promp::{Observation, ProMp};
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::csv::Demo;
use crate::dmpfile::orientation_groups;

/// The most columns a ProMP takes here.
pub const MAX_COLUMNS: usize = 8;
/// The most kernels per column a ProMP takes here.
pub const MAX_KERNELS: usize = 40;
/// The ridge on the weights' covariance when none is chosen, relative to
/// its mean variance.
pub const DEFAULT_RIDGE: f64 = 1e-6;
/// The `format` field's value.
pub const FORMAT: &str = "primo-promp";
/// The version this primo writes and reads.
pub const VERSION: u32 = 1;

/// The core's ProMP on the host's sizes (boxed: 820 KB).
pub type HostProMp = ProMp<MAX_COLUMNS, MAX_KERNELS>;

/// A ProMP and its columns' names.
#[derive(Debug, Clone)]
pub struct PrompFile {
    /// The columns, in order: the ProMP's DoFs.
    pub names: Vec<String>,
    /// The distribution.
    pub promp: Box<HostProMp>,
}

/// The file's JSON.
#[derive(Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
struct Stored {
    format: String,
    version: u32,
    names: Vec<String>,
    values: Vec<f64>,
}

impl PrompFile {
    /// Fits a ProMP to `demos` with `kernels` per column and the
    /// covariance's `ridge`: two or more demonstrations, each with the
    /// first one's columns by name and in order, each's duration its phase
    /// from 0 to 1. Orientation columns are refused: a ProMP takes each
    /// column as a number, which a quaternion's components are not. The
    /// core's fit refuses kernels beyond [`MAX_KERNELS`], a bad ridge and
    /// fewer than two demonstrations.
    pub fn fit(demos: &[(&str, &Demo)], kernels: usize, ridge: f64) -> Result<Self, Error> {
        let bad = |why: String| Error::Demonstrations(why);
        let Some((first_name, first)) = demos.first() else {
            return Err(bad("a ProMP needs at least two demonstrations".into()));
        };
        if first.names.len() > MAX_COLUMNS {
            return Err(bad(format!(
                "{first_name}: {} columns, a ProMP takes at most {MAX_COLUMNS}",
                first.names.len()
            )));
        }
        if let Some((group, _)) = orientation_groups(&first.names).first() {
            return Err(bad(format!(
                "{first_name}: {} is an orientation (a quaternion), which a ProMP does not \
                 take: fit its position columns",
                group.join(",")
            )));
        }
        for (name, demo) in demos {
            crate::skill::same_columns(&first.names, &demo.names)
                .map_err(|why| bad(format!("{name}: {why} (the columns of {first_name})")))?;
        }
        let refs: Vec<(&[f32], &[f32])> = demos
            .iter()
            .map(|(_, d)| (&d.times[..], &d.positions[..]))
            .collect();
        let promp = HostProMp::fit(&refs, first.names.len(), kernels, ridge)
            .map(Box::new)
            .map_err(|e| bad(format!("the ProMP's fit: {e}")))?;
        Ok(PrompFile {
            names: first.names.clone(),
            promp,
        })
    }

    /// The column `name`'s DoF.
    pub fn dof_of(&self, name: &str) -> Result<usize, Error> {
        self.names.iter().position(|n| n == name).ok_or_else(|| {
            Error::Movement(format!("no column `{name}` among {}", self.names.join(",")))
        })
    }

    /// Conditions on columns' `positions` at `time` s (phase `time` over
    /// the demonstrations' mean duration), each known to `variance`
    /// (0: exactly).
    pub fn condition(
        &mut self,
        time: f64,
        positions: &[(String, f32)],
        variance: f64,
    ) -> Result<(), Error> {
        let duration = self.promp.duration();
        if !(time.is_finite() && (0.0..=duration).contains(&time)) {
            return Err(Error::Movement(format!(
                "{time} s is outside the movement, 0 to {duration} s"
            )));
        }
        let observed = positions
            .iter()
            .map(|(name, position)| {
                Ok(Observation {
                    dof: self.dof_of(name)?,
                    position: *position,
                })
            })
            .collect::<Result<Vec<_>, Error>>()?;
        self.promp
            .condition(time / duration, &observed, variance)
            .map_err(|e| Error::Movement(format!("conditioning at {time} s: {e}")))
    }

    /// The mean movement every `dt` s from 0 to the demonstrations' mean
    /// duration (the last step shorter, to land on it): rows of the time,
    /// each column's mean and, with `spread`, each column's standard
    /// deviation after them.
    pub fn run(&self, dt: f64, spread: bool) -> Vec<(f32, Vec<f32>)> {
        let duration = self.promp.duration();
        // The duration is a mean of f32 times: a hair over k steps is k
        // steps, not k + 1 with a last one of 1e-8 s.
        let steps = (duration / dt - 1e-6).ceil().max(0.0) as usize;
        (0..=steps)
            .map(|i| {
                let t = (i as f64 * dt).min(duration);
                let z = t / duration;
                let dofs = 0..self.names.len();
                let mut row: Vec<f32> =
                    dofs.clone().map(|d| self.promp.mean(z, d) as f32).collect();
                if spread {
                    row.extend(dofs.map(|d| self.promp.variance(z, d).max(0.0).sqrt() as f32));
                }
                (t as f32, row)
            })
            .collect()
    }

    /// The file's JSON.
    pub fn to_json(&self) -> Result<String, serde_json::Error> {
        serde_json::to_string(&Stored {
            format: FORMAT.into(),
            version: VERSION,
            names: self.names.clone(),
            values: self.promp.values().collect(),
        })
    }

    /// Reads a ProMP file's `text` (`file` names it in messages).
    pub fn parse(file: &str, text: &str) -> Result<Self, Error> {
        let stored: Stored = serde_json::from_str(text)
            .map_err(|e| Error::File(format!("{file}:{}:{}: {e}", e.line(), e.column())))?;
        if stored.format != FORMAT || stored.version != VERSION {
            return Err(Error::File(format!(
                "{file}: a `{}` file of version {}, not a ProMP file ({FORMAT} version {VERSION})",
                stored.format, stored.version
            )));
        }
        let promp = HostProMp::from_values(&stored.values)
            .map(Box::new)
            .map_err(|e| Error::File(format!("{file}: {e}")))?;
        if stored.names.len() != promp.dof() {
            return Err(Error::File(format!(
                "{file}: {} names for a ProMP of {} columns",
                stored.names.len(),
                promp.dof()
            )));
        }
        Ok(PrompFile {
            names: stored.names,
            promp,
        })
    }
}
