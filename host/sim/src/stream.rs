//! The stream from the bottle's mouth to the glass:
//! it leaves along the bottle axis at the mean speed `Q / A_wet`, falls
//! ballistically, and at the rim's height has the radius `√(Q / (π v))`.
//! The part of that disk over the glass opening (a circle–circle lens) is
//! captured, the rest is spilled.
//!
//! ```
//! use primo_sim::stream::{Glass, land};
//! let glass = Glass::normal([0.6, 0.0]);
//! // A thin stream released 5 cm straight above the glass's centre.
//! let at = land([0.6, 0.0, glass.rim() + 0.05], [0.0; 3], 1e-5, &glass, 0.0);
//! assert_eq!(at.captured, 1.0);
//! ```

use std::f64::consts::PI;

use super::bottle::G;

/// Area of the intersection of two disks with radii `a`, `b` and centres
/// `d` apart (the lens).
pub fn lens_area(a: f64, b: f64, d: f64) -> f64 {
    let (small, large) = (a.min(b), a.max(b));
    if small <= 0.0 || d >= a + b {
        return 0.0;
    }
    if d <= large - small {
        return PI * small * small;
    }
    // Each disk contributes the segment cut off by the common chord.
    let part = |r: f64, other: f64| {
        let x = ((d * d + r * r - other * other) / (2.0 * d * r)).clamp(-1.0, 1.0);
        r * r * x.acos() - r * r * x * (1.0 - x * x).max(0.0).sqrt()
    };
    (part(a, b) + part(b, a)).clamp(0.0, PI * small * small)
}

/// A glass standing on the scale: a cylinder of radius `body` with an
/// opening of radius `opening` at the rim (a narrower opening is a glass
/// that closes in towards the top, as the paper's second one).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Glass {
    /// Centre of the glass, x and y in the robot's base frame, m.
    pub centre: [f64; 2],
    /// Height of the glass's inner bottom, m.
    pub bottom: f64,
    /// Inner height from bottom to rim, m.
    pub height: f64,
    /// Inner radius of the body, m.
    pub body: f64,
    /// Radius of the opening at the rim, m.
    pub opening: f64,
}

impl Glass {
    /// The cell's glass standing on the scale at `centre`: 7 cm wide,
    /// 11 cm tall (0.42 l).
    pub fn normal(centre: [f64; 2]) -> Self {
        Glass {
            centre,
            bottom: 0.26,
            height: 0.11,
            body: 0.035,
            opening: 0.035,
        }
    }

    /// The same glass with an opening of half the diameter (the paper's
    /// second experiment).
    pub fn small(centre: [f64; 2]) -> Self {
        Glass {
            opening: 0.0175,
            ..Glass::normal(centre)
        }
    }

    /// Height of the rim, m.
    pub fn rim(&self) -> f64 {
        self.bottom + self.height
    }

    /// Volume the glass holds before it overflows, m³.
    pub fn capacity(&self) -> f64 {
        PI * self.body * self.body * self.height
    }

    /// Height of the liquid's surface holding `volume` m³.
    pub fn level(&self, volume: f64) -> f64 {
        self.bottom + (volume / (PI * self.body * self.body)).clamp(0.0, self.height)
    }

    /// Checks the sizes.
    pub fn validate(&self) -> Result<(), &'static str> {
        let all = [
            self.centre[0],
            self.centre[1],
            self.bottom,
            self.height,
            self.body,
            self.opening,
        ];
        if all.iter().any(|v| !v.is_finite()) {
            return Err("glass sizes must be finite");
        }
        if !(self.height > 0.0 && self.body > 0.0 && self.opening > 0.0) {
            return Err("glass height and radii must be > 0");
        }
        if self.opening > self.body {
            return Err("the glass's opening cannot be wider than its body");
        }
        Ok(())
    }
}

/// Where and how a parcel of the stream arrives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Landing {
    /// Time from the mouth to the rim's height, s.
    pub time: f64,
    /// Fraction of the stream inside the opening there, in `[0, 1]`.
    pub captured: f64,
    /// Downward speed at the liquid's surface in the glass (m/s): the
    /// stream's impact pushes on the scale with `ṁ · speed`.
    pub impact_speed: f64,
    /// Centre of the stream at the rim's height (x, y), m.
    pub point: [f64; 2],
}

/// Follows a stream released at `origin` with `velocity` and volume flow
/// `flow` (m³/s) to the glass; `level` is the height of the liquid's
/// surface in the glass ([`Glass::level`]).
pub fn land(origin: [f64; 3], velocity: [f64; 3], flow: f64, glass: &Glass, level: f64) -> Landing {
    let rim = glass.rim();
    let offset = |p: [f64; 2]| (p[0] - glass.centre[0]).hypot(p[1] - glass.centre[1]);
    let drop = origin[2] - rim;
    if drop < 0.0 {
        // Released below the rim: inside the opening it falls into the
        // glass, outside it runs down the outside.
        let point = [origin[0], origin[1]];
        let inside = offset(point) < glass.opening;
        let fall = (origin[2] - level).max(0.0);
        let vz = velocity[2].min(0.0);
        return Landing {
            time: 0.0,
            captured: if inside { 1.0 } else { 0.0 },
            impact_speed: (vz * vz + 2.0 * G * fall).sqrt(),
            point,
        };
    }
    // z(t) = z0 + vz t − g t²/2 reaches the rim's height at the later root.
    let vz = velocity[2];
    let time = (vz + (vz * vz + 2.0 * G * drop).sqrt()) / G;
    let point = [
        origin[0] + velocity[0] * time,
        origin[1] + velocity[1] * time,
    ];
    let fall_speed = G * time - vz; // downward, at the rim
    let speed = (velocity[0].powi(2) + velocity[1].powi(2) + fall_speed.powi(2)).sqrt();
    let radius = if speed > 0.0 && flow > 0.0 {
        (flow / (PI * speed)).sqrt()
    } else {
        0.0
    };
    let d = offset(point);
    let captured = if radius > 0.0 {
        (lens_area(radius, glass.opening, d) / (PI * radius * radius)).clamp(0.0, 1.0)
    } else if d < glass.opening {
        1.0
    } else {
        0.0
    };
    let below_rim = (rim - level).max(0.0);
    Landing {
        time,
        captured,
        impact_speed: (fall_speed * fall_speed + 2.0 * G * below_rim).sqrt(),
        point,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lens_area_limits() {
        assert_eq!(lens_area(1.0, 2.0, 3.5), 0.0);
        assert!((lens_area(1.0, 2.0, 0.5) - PI).abs() < 1e-12);
        // Two unit disks one radius apart: 2π/3 − √3/2.
        let expected = 2.0 * PI / 3.0 - 3f64.sqrt() / 2.0;
        assert!((lens_area(1.0, 1.0, 1.0) - expected).abs() < 1e-12);
        // Continuous at the containment and touching limits.
        assert!((lens_area(1.0, 2.0, 1.0 + 1e-9) - PI).abs() < 1e-4);
        assert!(lens_area(1.0, 2.0, 3.0 - 1e-9) < 1e-6);
        // Monotone in the distance.
        let mut last = f64::INFINITY;
        for i in 0..=100 {
            let a = lens_area(0.3, 1.0, i as f64 * 0.014);
            assert!(a <= last + 1e-15);
            last = a;
        }
    }

    #[test]
    fn narrow_centred_stream_is_captured_and_a_far_one_spilled() {
        let glass = Glass::normal([0.6, 0.1]);
        let level = glass.level(0.0);
        let above = [0.6, 0.1, glass.rim() + 0.04];
        let at = land(above, [0.0, 0.0, -0.1], 2e-5, &glass, level);
        assert_eq!(at.captured, 1.0);
        let far = [0.9, 0.1, glass.rim() + 0.04];
        assert_eq!(
            land(far, [0.0, 0.0, -0.1], 2e-5, &glass, level).captured,
            0.0
        );
        // Half over the edge: about half captured.
        let edge = [0.6 + glass.opening, 0.1, glass.rim() + 0.04];
        let half = land(edge, [0.0; 3], 2e-5, &glass, level).captured;
        assert!((half - 0.5).abs() < 0.05, "{half}");
    }

    #[test]
    fn ballistics() {
        let glass = Glass::normal([0.0, 0.0]);
        let level = glass.level(0.0);
        // Horizontal throw from h: t = √(2h/g), x = v t.
        let h = 0.05;
        let at = land(
            [-0.03, 0.0, glass.rim() + h],
            [0.2, 0.0, 0.0],
            1e-5,
            &glass,
            level,
        );
        let t = (2.0 * h / G).sqrt();
        assert!((at.time - t).abs() < 1e-12);
        assert!((at.point[0] - (-0.03 + 0.2 * t)).abs() < 1e-12);
        // Impact speed from the energy: the fall to the liquid's surface.
        let fall = h + glass.height;
        assert!((at.impact_speed - (2.0 * G * fall).sqrt()).abs() < 1e-9);
        // Thrown upwards it takes longer and lands further.
        let up = land(
            [-0.03, 0.0, glass.rim() + h],
            [0.2, 0.0, 0.3],
            1e-5,
            &glass,
            level,
        );
        assert!(up.time > at.time && up.point[0] > at.point[0]);
    }

    #[test]
    fn released_inside_the_glass_below_the_rim() {
        let glass = Glass::normal([0.0, 0.0]);
        let at = land(
            [0.01, 0.0, glass.rim() - 0.02],
            [0.0; 3],
            1e-5,
            &glass,
            glass.bottom,
        );
        assert_eq!((at.time, at.captured), (0.0, 1.0));
        let outside = land(
            [0.1, 0.0, glass.rim() - 0.02],
            [0.0; 3],
            1e-5,
            &glass,
            glass.bottom,
        );
        assert_eq!(outside.captured, 0.0);
    }
}
