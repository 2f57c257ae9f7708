//! A DMP file's run shaped at execution time, by column name: a velocity
//! at the goal (a hit, a throw), via-points passed at given times
//! ([`primo_core::dmp::Dmp::through`]), without refitting, and coupling
//! terms: obstacles steered round, limits kept away from
//! ([`crate::coupled`]).

use primo_core::dmp::{MAX_VIA_POINTS, ViaPoint};

use crate::coupled::Coupled;
use crate::dmpfile::{DmpFile, Prepared};
use crate::{Error, HOST_MAX_DOF};

/// A column's value at a time: a via-point.
#[derive(Debug, Clone, PartialEq)]
pub struct Via {
    /// Seconds from the start.
    pub time: f32,
    /// The column, by name.
    pub column: String,
    /// Its value at `time`.
    pub value: f32,
}

/// How a run is shaped beyond its start, goal and `τ`: all optional.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Shaping {
    /// The velocity at the goal, one value per column (per second).
    pub goal_velocity: Option<Vec<f32>>,
    /// Via-points to pass.
    pub vias: Vec<Via>,
    /// Obstacles to steer round, limits to keep away from.
    pub coupled: Coupled,
}

impl Shaping {
    /// Whether it changes nothing.
    pub fn is_plain(&self) -> bool {
        self.goal_velocity.is_none() && self.vias.is_empty() && self.coupled.is_none()
    }
}

impl DmpFile {
    /// The run of `prepared` at steps of `dt` shaped by `shaping`: its
    /// rows (time, one value per column), from 0 to `τ`, or until it
    /// reaches its goal when it has coupling terms.
    pub fn run_shaped(
        &self,
        mut prepared: Prepared,
        dt: f32,
        shaping: &Shaping,
    ) -> Result<Vec<(f32, Vec<f32>)>, Error> {
        if let Some(v) = &shaping.goal_velocity {
            self.set_goal_velocity(&mut prepared, v)?;
        }
        let bent;
        let file = match shaping.vias.is_empty() {
            true => self,
            false => {
                bent = self.through(&prepared, dt, &shaping.vias)?;
                &bent
            }
        };
        if shaping.coupled.is_none() {
            Ok(file.run_prepared(&prepared, dt)?.collect())
        } else {
            file.run_coupled(&prepared, dt, &shaping.coupled)
        }
    }

    /// Sets `prepared`'s velocity at the goal from one value per column
    /// (per second). Orientation columns take none yet: a file with
    /// orientations is refused.
    pub fn set_goal_velocity(&self, prepared: &mut Prepared, values: &[f32]) -> Result<(), Error> {
        if !self.orientations.is_empty() {
            return Err(Error::Movement(
                "a velocity at the goal is for position columns only: this DMP has an \
                 orientation"
                    .into(),
            ));
        }
        if values.len() != self.names.len() {
            return Err(Error::Movement(format!(
                "goal velocity: {} values, expected one per column ({})",
                values.len(),
                self.names.join(",")
            )));
        }
        for (name, v) in self.names.iter().zip(values) {
            if !v.is_finite() {
                return Err(Error::Movement(format!(
                    "goal velocity of `{name}`: {v} is not a number"
                )));
            }
        }
        let velocity = &mut prepared.execution.goal_velocity;
        velocity.clear();
        for v in values {
            velocity.push(*v).map_err(|_| {
                Error::Movement(format!("goal velocity: more than {HOST_MAX_DOF} values"))
            })?;
        }
        Ok(())
    }

    /// This file with its DMP bent through `vias` for `prepared`'s start,
    /// goal and `τ`, run at steps of `dt` (see
    /// [`Dmp::through`](primo_core::dmp::Dmp::through)).
    pub fn through(&self, prepared: &Prepared, dt: f32, vias: &[Via]) -> Result<DmpFile, Error> {
        if vias.len() > MAX_VIA_POINTS {
            return Err(Error::Movement(format!(
                "{} via-points, at most {MAX_VIA_POINTS}",
                vias.len()
            )));
        }
        let mut points = Vec::with_capacity(vias.len());
        for v in vias {
            let dof = self.scalar_dof(&v.column).ok_or_else(|| {
                Error::Movement(format!(
                    "via-point at {} s: no position column `{}` among {}",
                    v.time,
                    v.column,
                    self.names.join(",")
                ))
            })?;
            points.push(ViaPoint {
                time: v.time,
                dof,
                position: v.value,
            });
        }
        let dmp = self
            .dmp
            .through(&prepared.execution, dt, &points)
            .map_err(|e| Error::Movement(format!("via-points: {e}")))?;
        Ok(DmpFile {
            dmp,
            ..self.clone()
        })
    }
}
