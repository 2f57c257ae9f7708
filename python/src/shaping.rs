//! `Dmp.run`'s shaping keywords (goal velocity, via-points, obstacles,
//! joint limits) as the skill's [`Shaping`], each checked with its name.

use std::collections::BTreeMap;

use pyo3::prelude::*;

use primo_core::coupling::Sphere;
use primo_skill::coupled::{Avoidance, Coupled, MAX_OBSTACLES, Repulsion};
use primo_skill::shaping::{Shaping, Via};

use crate::arrays::{Array, matrix, per_column};
use crate::errors::invalid;

/// `Dmp.run`'s `limits`, `limit_margin` and `limit_gain`.
pub type LimitKeywords = (BTreeMap<String, (f64, f64)>, Option<f64>, f64);

/// The shaping from `Dmp.run`'s keywords for a DMP with columns `names`.
pub fn shaping(
    names: &[String],
    goal_velocity: Option<Array<'_>>,
    via: Option<Vec<(f64, String, f64)>>,
    obstacles: Option<Array<'_>>,
    obstacle_columns: Option<Vec<String>>,
    limits: Option<LimitKeywords>,
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
        coupled: Coupled {
            avoid,
            repel: limits.map(repulsion).transpose()?,
        },
    })
}

/// `limits`, `limit_margin` and `limit_gain`.
fn repulsion((limits, margin, gain): LimitKeywords) -> PyResult<Repulsion> {
    let Some(margin) = margin else {
        return Err(invalid(
            "limits: needs limit_margin, how near a limit the push starts",
        ));
    };
    if !(margin.is_finite() && margin > 0.0) {
        return Err(invalid(format!(
            "limit_margin: {margin} must be a positive number"
        )));
    }
    if !(gain.is_finite() && gain > 0.0) {
        return Err(invalid(format!(
            "limit_gain: {gain} must be a positive number"
        )));
    }
    let mut columns = Vec::with_capacity(limits.len());
    for (column, (low, high)) in limits {
        if low.is_nan() || high.is_nan() || low >= high {
            return Err(invalid(format!(
                "limits[{column:?}]: ({low}, {high}) needs low < high (-inf, inf: none)"
            )));
        }
        columns.push((column, low as f32, high as f32));
    }
    Ok(Repulsion {
        limits: columns,
        margin: margin as f32,
        gain: gain as f32,
    })
}
