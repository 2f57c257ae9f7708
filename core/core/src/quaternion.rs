//! Unit quaternions `(w, x, y, z)` (Hamilton convention, `w` first) for
//! orientations, with the exponential and logarithmic maps between them and
//! rotation vectors.
//!
//! ```
//! use primo_core::quaternion::Quaternion;
//! let quarter = Quaternion::exp([0.0, 0.0, core::f32::consts::FRAC_PI_2]);
//! let back = quarter.log();
//! assert!((back[2] - core::f32::consts::FRAC_PI_2).abs() < 1e-6);
//! assert!((quarter.mul(&quarter.conj()).w - 1.0).abs() < 1e-6);
//! ```

use serde::{Deserialize, Serialize};

use crate::Error;

/// A quaternion; orientations are unit quaternions.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Quaternion {
    /// Scalar part.
    pub w: f32,
    /// Vector part, x.
    pub x: f32,
    /// Vector part, y.
    pub y: f32,
    /// Vector part, z.
    pub z: f32,
}

impl Quaternion {
    /// No rotation.
    pub const IDENTITY: Quaternion = Quaternion {
        w: 1.0,
        x: 0.0,
        y: 0.0,
        z: 0.0,
    };

    /// From `[w, x, y, z]`.
    pub fn from_array(q: [f32; 4]) -> Self {
        let [w, x, y, z] = q;
        Quaternion { w, x, y, z }
    }

    /// As `[w, x, y, z]`.
    pub fn to_array(self) -> [f32; 4] {
        [self.w, self.x, self.y, self.z]
    }

    /// The Hamilton product `self ⊗ other` (apply `other`, then `self`).
    pub fn mul(&self, o: &Quaternion) -> Quaternion {
        Quaternion {
            w: self.w * o.w - self.x * o.x - self.y * o.y - self.z * o.z,
            x: self.w * o.x + self.x * o.w + self.y * o.z - self.z * o.y,
            y: self.w * o.y - self.x * o.z + self.y * o.w + self.z * o.x,
            z: self.w * o.z + self.x * o.y - self.y * o.x + self.z * o.w,
        }
    }

    /// The conjugate: the inverse rotation of a unit quaternion.
    pub fn conj(&self) -> Quaternion {
        Quaternion {
            w: self.w,
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    /// The same rotation, the other sign.
    pub fn neg(&self) -> Quaternion {
        Quaternion {
            w: -self.w,
            x: -self.x,
            y: -self.y,
            z: -self.z,
        }
    }

    /// The 4-D dot product.
    pub fn dot(&self, o: &Quaternion) -> f32 {
        self.w * o.w + self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The Euclidean norm.
    pub fn norm(&self) -> f32 {
        libm::sqrtf(self.dot(self))
    }

    /// Scaled to unit norm; an error if not finite or (near) zero.
    pub fn normalized(&self) -> Result<Quaternion, Error> {
        let n = self.norm();
        if !(n.is_finite() && n > 1e-6) {
            return Err(Error::OutOfRange(
                "a quaternion must be finite and non-zero",
            ));
        }
        Ok(Quaternion {
            w: self.w / n,
            x: self.x / n,
            y: self.y / n,
            z: self.z / n,
        })
    }

    /// Back to unit norm after a little rounding (a product of unit
    /// quaternions): one Newton step `q (3 − |q|²)/2`, no square root.
    /// Not for arbitrary quaternions: see [`Quaternion::normalized`].
    pub fn renormalized(&self) -> Quaternion {
        let k = 0.5 * (3.0 - self.dot(self));
        Quaternion {
            w: k * self.w,
            x: k * self.x,
            y: k * self.y,
            z: k * self.z,
        }
    }

    /// The rotation by the rotation vector `r` (axis × angle, rad).
    pub fn exp(r: [f32; 3]) -> Quaternion {
        let angle = libm::sqrtf(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]);
        let (sin, cos) = sin_cos(0.5 * angle);
        // sin(θ/2)/θ, by its series where θ is tiny.
        let k = if angle > 1e-4 {
            sin / angle
        } else {
            0.5 - angle * angle / 48.0
        };
        Quaternion {
            w: cos,
            x: k * r[0],
            y: k * r[1],
            z: k * r[2],
        }
    }

    /// The rotation vector of a unit quaternion, angle in `[0, 2π]` (a
    /// negative `w` gives an angle beyond π: the sign of a quaternion
    /// sequence is kept, so its logarithm stays continuous).
    pub fn log(&self) -> [f32; 3] {
        let v = libm::sqrtf(self.x * self.x + self.y * self.y + self.z * self.z);
        // θ/|v|, by its limit 2/w where |v| is tiny.
        let k = if v > 1e-6 {
            2.0 * libm::atan2f(v, self.w) / v
        } else if self.w != 0.0 {
            2.0 / self.w
        } else {
            0.0
        };
        [k * self.x, k * self.y, k * self.z]
    }
}

/// `(sin x, cos x)` in `f32` arithmetic only (libm's `sinf` computes in
/// `f64`, which the Cortex-M4F emulates in software: this is what keeps an
/// orientation step within budget there). Reduction to `[−π/4, π/4]` with
/// a two-part `π/2` (exact for |x| up to 10⁵; libm beyond), then Taylor polynomials to `x⁹` and `x⁸`: error below
/// 3e−8 there, so `sin² + cos²` is 1 to about 1e−7.
fn sin_cos(x: f32) -> (f32, f32) {
    if !(libm::fabsf(x) < 1e5) {
        // Beyond the exact reduction (and NaN): libm's own.
        return libm::sincosf(x);
    }
    // π/2 in two parts; the first has 8 significant bits, so n·PIO2_HI is
    // exact for any quadrant count n below 2¹⁶.
    const PIO2_HI: f32 = 1.570_312_5;
    const PIO2_LO: f32 = 4.838_268e-4;
    let n = libm::roundf(x * core::f32::consts::FRAC_2_PI);
    let r = (x - n * PIO2_HI) - n * PIO2_LO;
    let r2 = r * r;
    let sin =
        r + r * r2 * (-1.0 / 6.0 + r2 * (1.0 / 120.0 + r2 * (-1.0 / 5040.0 + r2 / 362_880.0)));
    let cos = 1.0 + r2 * (-0.5 + r2 * (1.0 / 24.0 + r2 * (-1.0 / 720.0 + r2 / 40_320.0)));
    // `as` saturates (and maps NaN to 0): any input gives a quadrant.
    match (n as i64) & 3 {
        0 => (sin, cos),
        1 => (cos, -sin),
        2 => (-sin, -cos),
        _ => (-cos, sin),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn exp_and_log_are_inverse_up_to_two_pi() {
        for r in [
            [0.0, 0.0, 0.0],
            [1e-7, 0.0, 0.0],
            [0.3, -0.2, 0.1],
            [0.0, 3.0, 0.0],
            [2.0, 2.0, -2.0],
        ] {
            let q = Quaternion::exp(r);
            assert!((q.norm() - 1.0).abs() < 1e-6);
            let back = q.log();
            for k in 0..3 {
                assert!((back[k] - r[k]).abs() < 1e-5, "{r:?} -> {back:?}");
            }
        }
    }

    #[test]
    fn sin_cos_matches_libm() {
        let mut worst = 0.0f64;
        for i in -20_000..=20_000 {
            let x = i as f32 * 1e-3;
            let (s, c) = sin_cos(x);
            let (xs, xc) = (f64::from(x).sin(), f64::from(x).cos());
            worst = worst
                .max((f64::from(s) - xs).abs())
                .max((f64::from(c) - xc).abs());
        }
        assert!(worst < 2e-7, "{worst}");
        assert!(sin_cos(f32::NAN).0.is_nan() && sin_cos(1e30).0.is_finite());
    }

    #[test]
    fn products_compose_rotations() {
        let a = Quaternion::exp([0.0, 0.0, 0.4]);
        let b = Quaternion::exp([0.0, 0.0, 0.5]);
        let ab = a.mul(&b).log();
        assert!((ab[2] - 0.9).abs() < 1e-6 && ab[0].abs() < 1e-7);
        let inv = a.mul(&a.conj());
        assert!((inv.w - 1.0).abs() < 1e-7);
        assert!(Quaternion::from_array([0.0; 4]).normalized().is_err());
    }
}
