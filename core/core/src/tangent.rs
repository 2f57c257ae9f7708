//! Orientations as vectors: the tangent space of unit quaternions at a
//! reference orientation `r`, where an orientation `q` is the rotation
//! vector `v = log(q ⊗ r̄)` (world frame, rad) and back `q = exp(v) ⊗ r`.
//! Where orientations are combined linearly (generalization over a task
//! query), they are combined as these vectors, so any combination maps
//! back to a unit quaternion.
//!
//! - `q` and `−q` are one orientation and give one vector: the shorter
//!   way from `r`, an angle of at most π.
//! - The chart is one-to-one for orientations less than π from `r`, and
//!   continuous there: orientations on both sides of ±180° yaw from an
//!   origin are a few degrees apart here when `r` is near them.
//! - [`Tangent::mean`] takes as `r` the iterated (Karcher) mean of a set,
//!   the orientation whose tangent vectors to the set sum to zero: the
//!   farthest from the chart's edge, and the same whatever the signs and
//!   order of the set.
//!
//! ```
//! use primo_core::quaternion::Quaternion;
//! use primo_core::tangent::Tangent;
//! let yaw = |deg: f32| Quaternion::exp([0.0, 0.0, deg.to_radians()]);
//! // 170° and −170° yaw: 20° apart through 180°, not 340° through 0°.
//! let tangent = Tangent::mean(&[yaw(170.0), yaw(-170.0).neg()])?;
//! let (a, b) = (tangent.log(&yaw(170.0)), tangent.log(&yaw(-170.0)));
//! assert!(((a[2] - b[2]).abs().to_degrees() - 20.0).abs() < 1e-3);
//! let halfway = tangent.exp(&[0.0, 0.0, 0.5 * (a[2] + b[2])]);
//! assert!(halfway.dot(&yaw(180.0)).abs() > 1.0 - 1e-6);
//! # Ok::<(), primo_core::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::quaternion::Quaternion;

/// Most iterations of [`Tangent::mean`]; each one shrinks the distance to
/// the mean by a factor of order the set's spread squared, so a set within
/// 90° is there to `f32` precision in a handful.
const MEAN_ITERATIONS: usize = 32;
/// [`Tangent::mean`] stops once its step is below this, rad.
const MEAN_TOLERANCE: f32 = 1e-7;

/// The tangent space at a reference orientation.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Tangent {
    /// The reference, unit, its first non-zero component positive (so that
    /// `q` and `−q` give the same bits).
    reference: Quaternion,
}

impl Tangent {
    /// The tangent space at `reference` (any non-zero norm).
    pub fn at(reference: Quaternion) -> Result<Self, Error> {
        Ok(Tangent {
            reference: canonical(reference.normalized()?),
        })
    }

    /// The tangent space at the iterated mean of `orientations` (any
    /// non-zero norms, any signs): from the first, `r ← exp(mean_i log_r
    /// q_i) ⊗ r` until the step is below 1e−7 rad. A set within 180° of
    /// one orientation converges; any other ends after a bounded number of
    /// steps at an orientation that is still a valid reference.
    pub fn mean(orientations: &[Quaternion]) -> Result<Self, Error> {
        let first = orientations.first().ok_or(Error::OutOfRange(
            "the mean of orientations needs at least one",
        ))?;
        let mut tangent = Tangent::at(*first)?;
        for q in orientations {
            q.normalized()?;
        }
        let n = orientations.len() as f32;
        for _ in 0..MEAN_ITERATIONS {
            let mut step = [0.0f32; 3];
            for q in orientations {
                let v = tangent.log(&q.normalized()?);
                for (s, v) in step.iter_mut().zip(v) {
                    *s += v / n;
                }
            }
            tangent.reference = canonical(tangent.exp(&step));
            let size = libm::sqrtf(step.iter().map(|s| s * s).sum());
            if !(size >= MEAN_TOLERANCE) {
                break;
            }
        }
        Ok(tangent)
    }

    /// The reference orientation.
    pub fn reference(&self) -> Quaternion {
        self.reference
    }

    /// The tangent vector of a unit quaternion `q` (either sign): the
    /// rotation vector from the reference to `q`, angle in `[0, π]`.
    pub fn log(&self, q: &Quaternion) -> [f32; 3] {
        let relative = q.mul(&self.reference.conj());
        if relative.w < 0.0 {
            relative.neg().log()
        } else {
            relative.log()
        }
    }

    /// The orientation of tangent vector `v` (its first three values; any
    /// finite vector): `exp(v) ⊗ r`, a unit quaternion.
    pub fn exp(&self, v: &[f32]) -> Quaternion {
        crate::orientation::from_log(v, &self.reference)
    }
}

/// `q` or `−q`, whichever has its first non-zero component positive.
fn canonical(q: Quaternion) -> Quaternion {
    let first = q.to_array().into_iter().find(|v| *v != 0.0);
    if first.is_some_and(|v| v < 0.0) {
        q.neg()
    } else {
        q
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn yaw(deg: f32) -> Quaternion {
        Quaternion::exp([0.0, 0.0, deg.to_radians()])
    }

    #[test]
    fn the_mean_of_a_set_around_180_degrees_is_there_whatever_the_signs() {
        let set = [yaw(170.0), yaw(-175.0), yaw(185.0).neg()];
        let a = Tangent::mean(&set).unwrap();
        let b = Tangent::mean(&[set[1].neg(), set[2], set[0].neg()]).unwrap();
        let expect = yaw((170.0 + 185.0 + 185.0) / 3.0);
        for t in [a, b] {
            assert!(t.reference().dot(&expect).abs() > 1.0 - 1e-6, "{t:?}");
            let sum: f32 = set.iter().map(|q| t.log(q)[2]).sum();
            assert!(sum.abs() < 1e-5, "{sum}");
        }
        assert!(Tangent::mean(&[]).is_err());
        assert!(Tangent::mean(&[yaw(0.0), Quaternion::from_array([0.0; 4])]).is_err());
    }

    #[test]
    fn log_and_exp_are_inverse_within_180_degrees() {
        let t = Tangent::at(yaw(100.0).mul(&Quaternion::exp([0.3, 0.0, 0.0]))).unwrap();
        for q in [
            yaw(0.0),
            yaw(-60.0),
            yaw(250.0).neg(),
            Quaternion::exp([1.0, -2.0, 0.5]),
        ] {
            let v = t.log(&q);
            assert!(libm::sqrtf(v.iter().map(|x| x * x).sum()) <= core::f32::consts::PI);
            assert_eq!(t.log(&q.neg()), v);
            assert!(t.exp(&v).dot(&q).abs() > 1.0 - 1e-6, "{q:?}");
        }
    }
}
