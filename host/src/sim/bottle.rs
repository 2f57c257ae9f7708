//! A cylindrical bottle tilted by `θ` from vertical: the liquid's free
//! surface and the outflow over the mouth (DESIGN.md §3, points 1–2).
//!
//! Bottle frame: axial coordinate `u ∈ [0, L]` from the base to the mouth,
//! cross-section coordinate `v` in the tilt plane, positive towards the side
//! that goes down as the bottle tilts. A point sits at height
//! `z = u cos θ − v sin θ` above the base centre. The liquid fills
//! everything below the free surface `z_s`; each cross-section's wetted part
//! is the circular segment `v ≥ c(u) = (u cos θ − z_s)/sin θ`.
//!
//! ```
//! use primo_host::sim::bottle::Bottle;
//! let b = Bottle::new(0.035, 0.18, 0.011)?;
//! // Upright, V = π R² h.
//! let h = b.surface_height(0.5e-3, 0.0);
//! assert!((h - 0.5e-3 / (std::f64::consts::PI * 0.035 * 0.035)).abs() < 1e-9);
//! # Ok::<(), &'static str>(())
//! ```

use std::f64::consts::PI;

/// Standard gravity, m/s².
pub const G: f64 = 9.81;
/// Discharge coefficient of the mouth (sharp-edged orifice).
pub const DISCHARGE: f64 = 0.61;

/// Area of the part of a disk of radius `r` on the far side of a chord at
/// signed distance `c` from the centre: `r² acos(c/r) − c √(r² − c²)`.
pub fn segment_area(r: f64, c: f64) -> f64 {
    if c >= r {
        0.0
    } else if c <= -r {
        PI * r * r
    } else {
        r * r * (c / r).acos() - c * (r * r - c * c).sqrt()
    }
}

/// Geometry of a bottle: body radius, length, mouth radius (metres).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bottle {
    /// Body radius R.
    pub radius: f64,
    /// Length L from base to mouth.
    pub length: f64,
    /// Mouth radius r (≤ R), centred on the axis at `u = L`.
    pub mouth: f64,
}

/// Axial samples of the volume integral (composite Simpson, even).
const AXIAL: usize = 256;
/// Samples across the mouth for the outflow integral (per direction).
const MOUTH: usize = 48;

impl Bottle {
    /// A bottle; sizes must be finite and positive, the mouth no wider than
    /// the body.
    pub fn new(radius: f64, length: f64, mouth: f64) -> Result<Self, &'static str> {
        let ok = [radius, length, mouth]
            .iter()
            .all(|v| v.is_finite() && *v > 0.0);
        if !ok {
            return Err("bottle sizes must be finite and > 0");
        }
        if mouth > radius {
            return Err("the bottle's mouth cannot be wider than its body");
        }
        Ok(Bottle {
            radius,
            length,
            mouth,
        })
    }

    /// Full volume `π R² L`, m³.
    pub fn capacity(&self) -> f64 {
        PI * self.radius * self.radius * self.length
    }

    /// Lowest and highest height of the bottle's interior at tilt `θ`.
    fn height_range(&self, tilt: f64) -> (f64, f64) {
        let (s, c) = tilt.sin_cos();
        let ends = [0.0, self.length * c];
        let lo = ends[0].min(ends[1]) - self.radius * s.abs();
        let hi = ends[0].max(ends[1]) + self.radius * s.abs();
        (lo, hi)
    }

    /// Liquid volume (m³) below the free surface at height `z_s` (metres
    /// above the base centre) when tilted by `θ` (radians from vertical).
    pub fn volume_below(&self, z_s: f64, tilt: f64) -> f64 {
        let (s, c) = tilt.sin_cos();
        if s.abs() < 1e-12 {
            // Upright (or upside down): flat layers.
            let h = if c > 0.0 { z_s } else { z_s + self.length };
            return PI * self.radius * self.radius * h.clamp(0.0, self.length);
        }
        let full = PI * self.radius * self.radius;
        let area = |u: f64| segment_area(self.radius, (u * c - z_s) / s);
        if c.abs() < 1e-12 {
            // Lying flat: every cross-section alike.
            return self.length * area(0.0);
        }
        // c(u) is linear in u: sections are completely full or empty outside
        // the interval where the surface crosses them, so integrate those
        // parts exactly and only the crossing interval numerically.
        let (u1, u2) = {
            let (a, b) = ((z_s - self.radius * s) / c, (z_s + self.radius * s) / c);
            (
                a.min(b).clamp(0.0, self.length),
                a.max(b).clamp(0.0, self.length),
            )
        };
        let outside = u1 * area(0.5 * u1) + (self.length - u2) * area(0.5 * (u2 + self.length));
        let step = (u2 - u1) / AXIAL as f64;
        let mut sum = area(u1) + area(u2);
        for i in 1..AXIAL {
            sum += area(u1 + i as f64 * step) * if i % 2 == 1 { 4.0 } else { 2.0 };
        }
        (outside + sum * step / 3.0).clamp(0.0, full * self.length)
    }

    /// The free-surface height holding `volume` (m³) at tilt `θ`, by
    /// bisection on the monotone [`Bottle::volume_below`].
    pub fn surface_height(&self, volume: f64, tilt: f64) -> f64 {
        let (mut lo, mut hi) = self.height_range(tilt);
        let target = volume.clamp(0.0, self.capacity());
        for _ in 0..60 {
            let mid = 0.5 * (lo + hi);
            if self.volume_below(mid, tilt) < target {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        0.5 * (lo + hi)
    }

    /// Volume flow (m³/s) out of the mouth with the free surface at `z_s`:
    /// `C_d ∬ √(2 g (z_s − z)) dA` over the part of the mouth disk below the
    /// surface. Returns the flow and the wetted mouth area (m²).
    pub fn outflow(&self, z_s: f64, tilt: f64) -> (f64, f64) {
        let (s, c) = tilt.sin_cos();
        let centre = self.length * c;
        // Midpoint rule on a square grid over the mouth disk.
        let h = 2.0 * self.mouth / MOUTH as f64;
        let (mut flow, mut area) = (0.0, 0.0);
        for i in 0..MOUTH {
            let v = -self.mouth + (i as f64 + 0.5) * h;
            for j in 0..MOUTH {
                let w = -self.mouth + (j as f64 + 0.5) * h;
                if v * v + w * w > self.mouth * self.mouth {
                    continue;
                }
                let head = z_s - (centre - v * s);
                if head > 0.0 {
                    flow += (2.0 * G * head).sqrt() * h * h;
                    area += h * h;
                }
            }
        }
        (DISCHARGE * flow, area)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn bottle() -> Bottle {
        Bottle::new(0.035, 0.18, 0.011).unwrap()
    }

    #[test]
    fn invalid_geometry_is_an_error() {
        assert!(Bottle::new(0.0, 0.18, 0.01).is_err());
        assert!(Bottle::new(0.03, f64::NAN, 0.01).is_err());
        assert!(Bottle::new(0.03, 0.18, 0.04).is_err());
    }

    #[test]
    fn upright_volume_is_pi_r2_h() {
        let b = bottle();
        for h in [0.0, 0.01, 0.09, 0.18] {
            let v = PI * 0.035 * 0.035 * h;
            assert!((b.volume_below(h, 0.0) - v).abs() < 1e-12);
            // A hair off vertical goes through the segment integral.
            assert!((b.volume_below(h, 1e-6) - v).abs() < 1e-9, "h={h}");
        }
    }

    #[test]
    fn volume_is_monotone_and_bounded_at_every_tilt() {
        let b = bottle();
        for k in 0..=18 {
            let tilt = k as f64 * PI / 18.0;
            let (lo, hi) = b.height_range(tilt);
            assert!(b.volume_below(lo - 0.01, tilt).abs() < 1e-12);
            assert!(
                (b.volume_below(hi + 0.01, tilt) - b.capacity()).abs()
                    < 1e-9 * b.capacity().max(1.0)
            );
            let mut last = 0.0;
            for i in 0..=100 {
                let v = b.volume_below(lo + (hi - lo) * i as f64 / 100.0, tilt);
                assert!(v >= last - 1e-15, "tilt {tilt}: not monotone");
                last = v;
            }
        }
    }

    #[test]
    fn horizontal_half_full_surface_is_on_the_axis() {
        // Lying flat, half the capacity fills exactly to the axis.
        let b = bottle();
        let z = b.surface_height(0.5 * b.capacity(), PI / 2.0);
        assert!(z.abs() < 1e-9, "{z}");
    }

    #[test]
    fn surface_height_inverts_volume() {
        let b = bottle();
        for tilt in [0.0, 0.4, 1.2, 1.9, 2.8] {
            for frac in [0.05, 0.3, 0.7, 0.95] {
                let v = frac * b.capacity();
                let z = b.surface_height(v, tilt);
                assert!(
                    (b.volume_below(z, tilt) - v).abs() < 1e-12,
                    "tilt {tilt} frac {frac}"
                );
            }
        }
    }

    #[test]
    fn outflow_is_zero_below_the_lip_and_torricelli_when_submerged() {
        let b = bottle();
        let tilt = 2.0; // mouth pointing down-ish
        let (s, c) = f64::sin_cos(tilt);
        let lowest = b.length * c - b.mouth * s;
        assert_eq!(b.outflow(lowest - 1e-6, tilt), (0.0, 0.0));
        // Deeply submerged mouth: Q → C_d π r² √(2 g h), h over the centre.
        let head = 0.5;
        let (q, area) = b.outflow(b.length * c + head, tilt);
        let torricelli = DISCHARGE * PI * b.mouth * b.mouth * (2.0 * G * head).sqrt();
        assert!(
            (area / (PI * b.mouth * b.mouth) - 1.0).abs() < 0.01,
            "area {area}"
        );
        assert!((q / torricelli - 1.0).abs() < 0.01, "{q} vs {torricelli}");
    }
}
