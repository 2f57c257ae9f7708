//! A push away from each DoF's limits.
//!
//! Within `margin` of a limit, at distance `d` from it, a DoF is pushed
//! back by `gain · (margin/d − 1)`: zero at the margin's edge, `gain` at
//! half the margin, growing without bound towards the limit (held to
//! `max_acceleration`). A smooth, local term: a movement that keeps
//! `margin` away from its limits runs as it would without it, bit for bit.
//! An infinite limit is none: a DoF may be limited on one side, or not
//! at all.

use super::Coupling;
use crate::{Error, check_len};

/// Lower and upper limits of up to `D` DoFs, and the push.
#[derive(Debug, Clone, PartialEq)]
pub struct JointLimits<const D: usize> {
    dof: usize,
    low: [f32; D],
    high: [f32; D],
    margin: f32,
    gain: f32,
    max_acceleration: f32,
}

impl<const D: usize> JointLimits<D> {
    /// Limits `low[i] < high[i]` for each DoF (`−∞`, `+∞`: none), the
    /// `margin` (> 0, at most half of every DoF's range) within which the
    /// term pushes, the push `gain` at half the margin (units/s², > 0) and
    /// the largest push (> `gain`). Refused too: a `start` outside its
    /// limits, and a `goal` (one value per DoF) outside them or within the
    /// margin, where the push would hold the movement off it.
    pub fn new(
        low: &[f32],
        high: &[f32],
        margin: f32,
        gain: f32,
        max_acceleration: f32,
        start: &[f32],
        goal: &[f32],
    ) -> Result<Self, Error> {
        let dof = low.len();
        crate::check_capacity("joint limits", dof, D)?;
        for (what, n) in [
            ("upper limits", high.len()),
            ("start", start.len()),
            ("goal", goal.len()),
        ] {
            check_len(what, dof, n)?;
        }
        if !(gain.is_finite() && gain > 0.0) {
            return Err(Error::OutOfRange("joint-limit gain must be finite and > 0"));
        }
        if !(max_acceleration.is_finite() && max_acceleration > gain) {
            return Err(Error::OutOfRange(
                "joint-limit acceleration bound must be finite and above the gain",
            ));
        }
        let mut limits = Self {
            dof,
            low: [0.0; D],
            high: [0.0; D],
            margin,
            gain,
            max_acceleration,
        };
        for (i, (&lo, &hi)) in low.iter().zip(high).enumerate() {
            if lo.is_nan() || hi.is_nan() {
                return Err(Error::NotFinite("joint limits"));
            }
            if !(lo < hi) {
                return Err(Error::OutOfRange(
                    "a lower joint limit must be below its upper",
                ));
            }
            if !(margin > 0.0 && 2.0 * margin <= hi - lo) {
                return Err(Error::OutOfRange(
                    "joint-limit margin must be > 0 and at most half of every joint's range",
                ));
            }
            let inside = |y: Option<&f32>| y.is_some_and(|y| (lo..=hi).contains(y));
            if !inside(start.get(i)) {
                return Err(Error::OutOfRange(
                    "the movement's start is outside its joint limits",
                ));
            }
            if !inside(goal.get(i)) {
                return Err(Error::OutOfRange(
                    "the movement's goal is outside its joint limits",
                ));
            }
            if goal
                .get(i)
                .is_some_and(|g| g - lo < margin || hi - g < margin)
            {
                return Err(Error::OutOfRange(
                    "the movement's goal is within the margin of a joint limit, where the push \
                     would hold it off its goal: give a smaller margin",
                ));
            }
            if let (Some(l), Some(h)) = (limits.low.get_mut(i), limits.high.get_mut(i)) {
                (*l, *h) = (lo, hi);
            }
        }
        Ok(limits)
    }

    /// The push at distance `d` from a limit (≥ 0; `max_acceleration` at or
    /// beyond it).
    fn push(&self, d: f32) -> f32 {
        if d >= self.margin {
            0.0
        } else if d > 0.0 {
            (self.gain * (self.margin / d - 1.0)).min(self.max_acceleration)
        } else {
            self.max_acceleration
        }
    }
}

impl<const D: usize> Coupling for JointLimits<D> {
    fn add_to(
        &self,
        position: &[f32],
        velocity: &[f32],
        acceleration: &mut [f32],
    ) -> Result<(), Error> {
        check_len("position (the joint limits' DoF)", self.dof, position.len())?;
        check_len("velocity", self.dof, velocity.len())?;
        check_len("acceleration", self.dof, acceleration.len())?;
        if !position.iter().all(|y| y.is_finite()) {
            return Err(Error::NotFinite("position"));
        }
        for (((a, y), lo), hi) in acceleration
            .iter_mut()
            .zip(position)
            .zip(self.low)
            .zip(self.high)
        {
            *a += self.push(y - lo) - self.push(hi - y);
        }
        Ok(())
    }
}
