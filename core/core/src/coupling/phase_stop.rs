//! Phase stopping (Ijspeert, Nakanishi, Hoffmann, Pastor, Schaal,
//! "Dynamical movement primitives", Neural Computation 2013, eq. 2.19):
//! while the robot lags its command by `e`, the movement's clock runs at
//! `1/(1 + k‖e‖²)` of real time, so the command waits for the robot
//! instead of running away from it.
//!
//! Here the whole DMP (phase and spring) is stepped by the slowed time,
//! which is the same movement played slower: it reaches the same path and
//! goal, only later, and a robot held still holds the command nearly still.

use crate::{Error, check_len};

/// The phase-stopping gain `k`, per squared position unit.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PhaseStop {
    gain: f32,
}

impl PhaseStop {
    /// Phase stopping with gain `k` (≥ 0, finite; 0 never slows).
    pub fn new(gain: f32) -> Result<Self, Error> {
        if gain.is_finite() && gain >= 0.0 {
            Ok(Self { gain })
        } else {
            Err(Error::OutOfRange(
                "phase-stopping gain must be finite and ≥ 0",
            ))
        }
    }

    /// The step to take for `dt` seconds of real time when the robot is
    /// `measured` and the run commands `commanded` (one value per DoF each):
    /// `dt/(1 + k‖measured − commanded‖²)`, in (0, dt].
    pub fn step(&self, dt: f32, commanded: &[f32], measured: &[f32]) -> Result<f32, Error> {
        check_len("measured position", commanded.len(), measured.len())?;
        if !(dt.is_finite() && dt > 0.0) {
            return Err(Error::OutOfRange("dt must be finite and > 0"));
        }
        if !measured.iter().chain(commanded).all(|v| v.is_finite()) {
            return Err(Error::NotFinite("measured and commanded positions"));
        }
        if self.gain == 0.0 {
            return Ok(dt);
        }
        let lag: f32 = measured
            .iter()
            .zip(commanded)
            .map(|(m, c)| (m - c) * (m - c))
            .sum();
        let slowed = dt / (1.0 + self.gain * lag);
        // A lag so large the step underflows (or the slowing overflows)
        // would stop the clock for good; the smallest normal step (or `dt`
        // itself, if smaller) keeps the run a run.
        Ok(if slowed > 0.0 {
            slowed
        } else {
            dt.min(f32::MIN_POSITIVE)
        })
    }
}
