//! What a roll-out gives: what the rig measured ([`Measured`]), scored
//! once into a [`Trial`] with the paper's reward.

use serde::{Deserialize, Serialize};

use crate::rollouts::{Record, Scored};

use super::series::Series;

/// What a rig measured in one roll-out.
#[derive(Debug, Clone, PartialEq)]
pub struct Measured {
    /// Poured volume as the scale reads it, l.
    pub poured: f64,
    /// Spilled volume, l.
    pub spilled: f64,
    /// The time series, if the rig records one.
    pub series: Option<Series>,
    /// What the instruments read, on a real cell.
    pub readings: Option<Readings>,
}

/// What the instruments read around a roll-out on a real cell.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Readings {
    /// Stable scale weight before and after, g.
    pub scale: [f64; 2],
    /// The robot's estimated external force at the tool (the liquid in the
    /// bottle) standing still before and after, N; `None` if the robot
    /// reported too few still measurements.
    pub load: Option<[f64; 2]>,
}

/// The result of one roll-out.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Trial {
    /// Poured volume as the scale reads it, l.
    pub poured: f64,
    /// Spilled volume, l.
    pub spilled: f64,
    /// `poured − target`, l.
    pub error: f64,
    /// `max(0, 1 − 5 |target − poured| − 5 spilled)`.
    pub reward: f64,
    /// Why the trajectory never reached the cell, if it did not.
    pub rejected: Option<String>,
    /// The time series, if the rig recorded one.
    #[serde(skip)]
    pub series: Option<Series>,
    /// What the instruments read, on a real cell.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub readings: Option<Readings>,
}

impl Trial {
    /// Scores what was measured against the `target` volume.
    pub fn scored(target: f64, m: Measured) -> Trial {
        Trial {
            poured: m.poured,
            spilled: m.spilled,
            error: m.poured - target,
            reward: reward(target, m.poured, m.spilled),
            rejected: None,
            series: m.series,
            readings: m.readings,
        }
    }

    /// A roll-out the safety checks rejected (`why`): nothing moved, so
    /// nothing poured, and its reward is 0.
    pub fn rejected(target: f64, why: String) -> Trial {
        Trial {
            poured: 0.0,
            spilled: 0.0,
            error: -target,
            reward: 0.0,
            rejected: Some(why),
            series: None,
            readings: None,
        }
    }
}

impl Scored for Trial {
    fn error(&self) -> Vec<f32> {
        vec![self.error as f32]
    }

    fn reward(&self) -> f64 {
        self.reward
    }

    fn infeasible(&self) -> Option<&str> {
        self.rejected.as_deref()
    }

    fn worst_error(&self) -> Option<f64> {
        Some(self.error.abs())
    }

    fn lighten(&mut self) {
        self.series = None;
    }
}

impl Record<Trial> {
    /// The query's one value: the bottle's volume, l.
    pub fn volume(&self) -> f32 {
        self.query.first().copied().unwrap_or(f32::NAN)
    }
}

/// The paper's reward `r = 1 − 5|v_d − v_m| − 5 v_s` (litres), kept ≥ 0.
pub fn reward(target: f64, poured: f64, spilled: f64) -> f64 {
    (1.0 - 5.0 * (target - poured).abs() - 5.0 * spilled).max(0.0)
}
