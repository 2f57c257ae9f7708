//! Obstacle avoidance by Park et al.'s dynamic potential field.
//!
//! D.-H. Park, H. Hoffmann, P. Pastor, S. Schaal, "Movement reproduction
//! and obstacle avoidance with dynamic movement primitives and potential
//! fields", Humanoids 2008. With `p` the distance from the position `x`
//! to the obstacle's surface, `v` the velocity and `θ` the angle between
//! `v` and the direction from the obstacle's centre to `x`:
//!
//! ```text
//! U(x, v) = λ (−cos θ)^β ‖v‖ / p   while moving towards it (θ > π/2), else 0
//! c = −∇ₓU = λ (−cos θ)^(β−1) (‖v‖/p) [β (v̂ − cos θ n)/d − cos θ n/p]
//! ```
//!
//! `n` the unit vector from the centre to `x` and `d` their distance
//! (`p = d − r`). The first bracketed part turns the velocity aside, the
//! second brakes along `n`; both vanish when moving away or alongside.
//!
//! Why this term and not Hoffmann et al.'s steering angle (2009, the one
//! movement_primitives ships): that term depends on the angle between the
//! velocity and the obstacle only, not on its distance, so a point two
//! metres ahead turns the movement as hard as one two centimetres ahead,
//! and it has no notion of a size. Park's term grows as the surface comes
//! nearer (as `1/p²`), takes a sphere's radius as it is, and is zero for a
//! movement heading away from the obstacle. Measured against
//! movement_primitives on the same scenes
//! (`bench/results/2026-12-04-obstacles-vs-movement-primitives.md`), it
//! bends a path half as much for an obstacle 10 to 30 cm off it, keeps
//! less clearance from a point or a small ball right on the path (3.4 cm
//! against 6 cm from a point 1 mm off), more from a 5 cm ball there.
//! Its known limit, shared by every local potential: a movement aimed
//! exactly at a sphere's centre is only braked (the turning part is zero)
//! and stops short of the obstacle rather than going round.

use heapless::Vec;

use super::{Coupling, clamp_norm};
use crate::vec3::{dot, mix, norm};
use crate::{Error, check_len};

/// A ball to keep out of: its centre and radius (≥ 0; 0 is a point), in
/// the units of the DMP's position DoFs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sphere {
    /// Centre `[x, y, z]`.
    pub center: [f32; 3],
    /// Radius, ≥ 0.
    pub radius: f32,
}

impl Sphere {
    /// Distance from `point` to the surface: negative inside.
    pub fn distance(&self, point: [f32; 3]) -> f32 {
        norm(&mix(1.0, &point, -1.0, &self.center)) - self.radius
    }
}

/// Up to `N` spheres avoided by the DoFs `axes` (which hold `x`, `y`, `z`).
#[derive(Debug, Clone, PartialEq)]
pub struct Obstacles<const N: usize> {
    spheres: Vec<Sphere, N>,
    axes: [usize; 3],
    gain: f32,
    power: f32,
    max_acceleration: f32,
}

/// λ: the potential's strength, m²/s for positions in metres. Chosen on a
/// 0.6 m, one-second reach passing 1 mm from a 5 cm ball's centre: the
/// least of 0.01, 0.03, 0.1 and 1 that kept 1 cm clear of it (1.4 cm),
/// while a ball 15 cm off the path bends it by 9 mm.
pub const DEFAULT_GAIN: f32 = 0.1;
/// β: how sharply the term narrows to movements aimed at the obstacle.
pub const DEFAULT_POWER: f32 = 2.0;
/// The largest acceleration one obstacle adds, units/s².
pub const DEFAULT_MAX_ACCELERATION: f32 = 1.0e4;

impl<const N: usize> Obstacles<N> {
    /// The spheres avoided by the DoFs `axes`, with the default gain
    /// ([`DEFAULT_GAIN`]), power and bound. Refused: more than `N`
    /// spheres, a negative or non-finite radius or centre, an axis listed
    /// twice or beyond `start`'s length, and a sphere holding the
    /// movement's `start` or `goal` (the DMP's, one value per DoF): that
    /// movement could not begin or end outside it.
    pub fn new(
        axes: [usize; 3],
        spheres: &[Sphere],
        start: &[f32],
        goal: &[f32],
    ) -> Result<Self, Error> {
        check_len("goal", start.len(), goal.len())?;
        let [a, b, c] = axes;
        if a == b || b == c || a == c {
            return Err(Error::OutOfRange(
                "obstacle axes must be three different DoFs",
            ));
        }
        let pick = |y: &[f32]| -> Result<[f32; 3], Error> {
            match (y.get(a), y.get(b), y.get(c)) {
                (Some(&x), Some(&y), Some(&z)) => Ok([x, y, z]),
                _ => Err(Error::OutOfRange(
                    "an obstacle axis is beyond the DMP's DoF",
                )),
            }
        };
        let (start, goal) = (pick(start)?, pick(goal)?);
        let mut kept = Vec::new();
        for s in spheres {
            if !(s.center.iter().all(|v| v.is_finite()) && s.radius.is_finite()) {
                return Err(Error::NotFinite("obstacle centre and radius"));
            }
            if s.radius < 0.0 {
                return Err(Error::OutOfRange("an obstacle's radius must be ≥ 0"));
            }
            if !(s.distance(start) > 0.0) {
                return Err(Error::OutOfRange("an obstacle holds the movement's start"));
            }
            if !(s.distance(goal) > 0.0) {
                return Err(Error::OutOfRange("an obstacle holds the movement's goal"));
            }
            kept.push(*s).map_err(|_| Error::Capacity {
                what: "obstacles",
                requested: spheres.len(),
                capacity: N,
            })?;
        }
        Ok(Self {
            spheres: kept,
            axes,
            gain: DEFAULT_GAIN,
            power: DEFAULT_POWER,
            max_acceleration: DEFAULT_MAX_ACCELERATION,
        })
    }

    /// The same with λ `gain` (> 0), β `power` (≥ 1) and the largest
    /// acceleration one obstacle adds (> 0).
    pub fn with_gains(
        mut self,
        gain: f32,
        power: f32,
        max_acceleration: f32,
    ) -> Result<Self, Error> {
        if !(gain.is_finite() && gain > 0.0) {
            return Err(Error::OutOfRange("obstacle gain must be finite and > 0"));
        }
        if !(power.is_finite() && (1.0..=16.0).contains(&power)) {
            return Err(Error::OutOfRange("obstacle power must be within 1..=16"));
        }
        if !(max_acceleration.is_finite() && max_acceleration > 0.0) {
            return Err(Error::OutOfRange(
                "obstacle acceleration bound must be finite and > 0",
            ));
        }
        (self.gain, self.power, self.max_acceleration) = (gain, power, max_acceleration);
        Ok(self)
    }

    /// The spheres.
    pub fn spheres(&self) -> &[Sphere] {
        &self.spheres
    }

    /// The DoFs holding `x`, `y`, `z`.
    pub fn axes(&self) -> [usize; 3] {
        self.axes
    }

    /// The acceleration one sphere adds at `x` moving at `v`.
    fn acceleration(&self, s: &Sphere, x: [f32; 3], v: [f32; 3]) -> [f32; 3] {
        let offset = mix(1.0, &x, -1.0, &s.center);
        let (d, speed) = (norm(&offset), norm(&v));
        // No direction to steer by: at the centre, or at rest.
        if !(d > 0.0 && speed > 0.0) {
            return [0.0; 3];
        }
        let n = mix(1.0 / d, &offset, 0.0, &offset);
        let v_hat = mix(1.0 / speed, &v, 0.0, &v);
        let cos = dot(&v_hat, &n);
        if !(cos < 0.0) {
            return [0.0; 3];
        }
        // Inside or on the surface (only after a run was pushed in): the
        // strongest push the bound allows, straight out.
        let p = d - s.radius;
        if !(p > 0.0) {
            return mix(self.max_acceleration, &n, 0.0, &n);
        }
        let k = self.gain * libm::powf(-cos, self.power - 1.0) * speed / p;
        let mut a = [0.0f32; 3];
        for ((a, vh), n) in a.iter_mut().zip(v_hat).zip(n) {
            *a = k * (self.power * (vh - cos * n) / d - cos * n / p);
        }
        clamp_norm(&mut a, self.max_acceleration);
        a
    }
}

impl<const N: usize> Coupling for Obstacles<N> {
    fn add_to(
        &self,
        position: &[f32],
        velocity: &[f32],
        acceleration: &mut [f32],
    ) -> Result<(), Error> {
        check_len("velocity", position.len(), velocity.len())?;
        check_len("acceleration", position.len(), acceleration.len())?;
        let [a, b, c] = self.axes;
        let pick = |y: &[f32]| match (y.get(a), y.get(b), y.get(c)) {
            (Some(&x), Some(&y), Some(&z)) => Ok([x, y, z]),
            _ => Err(Error::Length {
                what: "position (the obstacles' axes)",
                expected: a.max(b).max(c) + 1,
                found: y.len(),
            }),
        };
        let (x, v) = (pick(position)?, pick(velocity)?);
        if !(x.iter().chain(&v).all(|v| v.is_finite())) {
            return Err(Error::NotFinite("position and velocity"));
        }
        for s in &self.spheres {
            let push = self.acceleration(s, x, v);
            for (axis, p) in self.axes.iter().zip(push) {
                if let Some(out) = acceleration.get_mut(*axis) {
                    *out += p;
                }
            }
        }
        Ok(())
    }
}
