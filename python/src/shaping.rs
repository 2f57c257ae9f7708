//! `Dmp.run`'s shaping keywords (goal velocity, via-points, obstacles) as
//! the skill's [`Shaping`], each checked with its name.

use pyo3::prelude::*;

use primo_core::coupling::Sphere;
use primo_skill::coupled::{Avoidance, MAX_OBSTACLES};
use primo_skill::shaping::{Shaping, Via};

use crate::arrays::{Array, matrix};
use crate::dmp::per_column;
use crate::errors::invalid;

/// The shaping from `Dmp.run`'s keywords for a DMP with columns `names`.
pub fn shaping(
    names: &[String],
    goal_velocity: Option<Array<'_>>,
    via: Option<Vec<(f64, String, f64)>>,
    obstacles: Option<Array<'_>>,
    obstacle_columns: Option<Vec<String>>,
) -> PyResult<Shaping> {
    let goal_velocity = per_column("goal_velocity", goal_velocity, names)?;
    let mut vias = Vec::new();
    for (i, (time, column, value)) in via.unwrap_or_default().into_iter().enumerate() {
        if !(time.is_finite() && value.is_finite()) {
            return Err(invalid(format!(
                "via[{i}]: ({time}, {column:?}, {value}) needs a finite time and value"
            )));
        }
        vias.push(Via {
            time: time as f32,
            column,
            value: value as f32,
        });
    }
    let avoid = match obstacles {
        None if obstacle_columns.is_some() => {
            return Err(invalid("obstacle_columns: given without obstacles"));
        }
        None => None,
        Some(a) => {
            let (rows, cols, values) = matrix("obstacles", &a)?;
            if cols != 4 || rows > MAX_OBSTACLES {
                return Err(invalid(format!(
                    "obstacles: shape ({rows}, {cols}), expected (n, 4) rows of x, y, z, \
                     radius with n at most {MAX_OBSTACLES}"
                )));
            }
            let mut spheres = Vec::with_capacity(rows);
            for (i, row) in values.chunks_exact(4).enumerate() {
                if let [x, y, z, r] = *row {
                    if r < 0.0 {
                        return Err(invalid(format!("obstacles[{i}]: radius {r} must be >= 0")));
                    }
                    spheres.push(Sphere {
                        center: [x, y, z],
                        radius: r,
                    });
                }
            }
            let names =
                obstacle_columns.unwrap_or_else(|| ["x", "y", "z"].map(String::from).to_vec());
            let columns: [String; 3] = names.try_into().map_err(|names: Vec<String>| {
                invalid(format!(
                    "obstacle_columns: {} names, expected three (the position columns of x, y, z)",
                    names.len()
                ))
            })?;
            Some(Avoidance { spheres, columns })
        }
    };
    Ok(Shaping {
        goal_velocity,
        vias,
        avoid,
    })
}
