//! The precision scale under the glass: the load
//! (the glass's contents, tared, plus the stream's impact force while
//! pouring) through a first-order lag, with noise, shown in 0.01 g digits
//! at the display rate, and "stable" once the display has not moved by more
//! than one digit for a second.
//!
//! ```
//! use primo_sim::scale::{Scale, ScaleModel};
//! let mut scale = Scale::new(ScaleModel::default(), 7);
//! for _ in 0..5000 {
//!     scale.step(0.002, 200.0); // 200 g settle in, 10 s
//! }
//! let r = scale.reading();
//! assert!(r.stable && (r.grams - 200.0).abs() <= 0.01);
//! ```

use std::collections::VecDeque;

use primo_core::normal::StandardNormal;
use primo_core::rng::Xoshiro128PlusPlus;
use rand_core::SeedableRng;

/// The scale's behaviour.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleModel {
    /// Time constant of the first-order lag, s.
    pub lag: f64,
    /// Display resolution (one digit), g.
    pub resolution: f64,
    /// Standard deviation of the noise before rounding, g.
    pub noise: f64,
    /// Display update interval, s.
    pub update: f64,
    /// How long the display must hold within one digit to be stable, s.
    pub stable_window: f64,
    /// Largest load shown; beyond it the scale reports overload, g.
    pub capacity: f64,
}

impl Default for ScaleModel {
    /// A 0.01 g laboratory balance: 0.5 s lag, 20 display updates per
    /// second, 2 mg noise, 4.2 kg capacity.
    fn default() -> Self {
        ScaleModel {
            lag: 0.5,
            resolution: 0.01,
            noise: 0.002,
            update: 0.05,
            stable_window: 1.0,
            capacity: 4200.0,
        }
    }
}

impl ScaleModel {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), &'static str> {
        let positive = [
            self.lag,
            self.resolution,
            self.update,
            self.stable_window,
            self.capacity,
        ];
        if positive.iter().any(|v| !(v.is_finite() && *v > 0.0)) {
            return Err(
                "scale lag, resolution, update, window and capacity must be finite and > 0",
            );
        }
        if !(self.noise.is_finite() && self.noise >= 0.0) {
            return Err("scale noise must be finite and >= 0");
        }
        Ok(())
    }
}

/// What the scale shows.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Reading {
    /// The displayed weight, g (a multiple of the resolution).
    pub grams: f64,
    /// The display has held within one digit for the stable window.
    pub stable: bool,
    /// The load is beyond the capacity (the value is then meaningless).
    pub overload: bool,
}

/// A first-order lag: the pan's and the liquid's settling, which the scale
/// and the bare load cell share. It keeps its step's factor: a control
/// loop steps by the same `dt` every time, and `exp_m1` is most of a step.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Lag {
    /// The `dt` and `tau` of the last step, and its factor `1 − e^{−dt/τ}`.
    last: (f64, f64, f64),
}

impl Lag {
    /// A lag that has not stepped yet.
    pub(crate) const NEW: Lag = Lag {
        last: (f64::NAN, f64::NAN, f64::NAN),
    };

    /// `value` after `dt` seconds of the lag of time constant `tau` toward
    /// `load`.
    pub(crate) fn step(&mut self, value: f64, load: f64, dt: f64, tau: f64) -> f64 {
        if (dt, tau) != (self.last.0, self.last.1) {
            self.last = (dt, tau, -(-dt / tau).exp_m1());
        }
        value + (load - value) * self.last.2
    }
}

/// The simulated scale.
#[derive(Debug, Clone)]
pub struct Scale {
    model: ScaleModel,
    time: f64,
    filtered: f64,
    lag: Lag,
    display: f64,
    next_update: f64,
    /// Recent display values with their times, oldest first.
    recent: VecDeque<(f64, f64)>,
    rng: Xoshiro128PlusPlus,
    normal: StandardNormal,
}

impl Scale {
    /// A tared scale (showing 0) whose noise comes from `seed`.
    pub fn new(model: ScaleModel, seed: u64) -> Self {
        Scale {
            model,
            time: 0.0,
            filtered: 0.0,
            lag: Lag::NEW,
            display: 0.0,
            next_update: model.update,
            recent: VecDeque::from([(0.0, 0.0)]),
            rng: Xoshiro128PlusPlus::seed_from_u64(seed),
            normal: StandardNormal::new(),
        }
    }

    /// Advances by `dt` seconds under `load` grams.
    pub fn step(&mut self, dt: f64, load: f64) {
        let m = self.model;
        self.filtered = self.lag.step(self.filtered, load, dt, m.lag);
        self.time += dt;
        while self.time >= self.next_update {
            let noisy = self.filtered + m.noise * f64::from(self.normal.sample(&mut self.rng));
            self.display = (noisy / m.resolution).round() * m.resolution;
            self.recent.push_back((self.next_update, self.display));
            // Keep just enough history to cover the window.
            while self
                .recent
                .get(1)
                .is_some_and(|(t, _)| *t <= self.next_update - m.stable_window)
            {
                self.recent.pop_front();
            }
            self.next_update += m.update;
        }
    }

    /// The current display.
    pub fn reading(&self) -> Reading {
        let m = self.model;
        let covered = self
            .recent
            .front()
            .is_some_and(|(t, _)| *t <= self.time - m.stable_window + 1e-9);
        let (lo, hi) = self
            .recent
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), (_, v)| {
                (lo.min(*v), hi.max(*v))
            });
        let overload = self.display > m.capacity;
        Reading {
            grams: self.display,
            stable: covered && hi - lo <= 1.5 * m.resolution && !overload,
            overload,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settles_to_the_load_and_reports_stable() {
        let mut scale = Scale::new(ScaleModel::default(), 1);
        let mut settled_at = None;
        for i in 1..=10_000 {
            scale.step(0.001, 123.456);
            if settled_at.is_none() && scale.reading().stable {
                settled_at = Some(i as f64 * 0.001);
            }
        }
        let r = scale.reading();
        assert!((r.grams - 123.46).abs() <= 0.011, "{r:?}");
        assert!(r.stable && !r.overload);
        // Needs the lag to bring 123 g within a digit, plus the window.
        let t = settled_at.unwrap();
        assert!(t > 4.0 && t < 8.0, "stable after {t} s");
    }

    #[test]
    fn moving_load_is_not_stable_and_lags() {
        let mut scale = Scale::new(ScaleModel::default(), 2);
        for i in 0..3000 {
            scale.step(0.001, 20.0 * i as f64 * 0.001); // 20 g/s
            assert!(!scale.reading().stable || i < 1000);
        }
        // After 3 s of a 20 g/s ramp, a 0.5 s lag shows about 10 g less.
        let r = scale.reading();
        assert!((r.grams - 50.0).abs() < 1.5, "{r:?}");
        assert!(!r.stable);
    }

    #[test]
    fn display_is_in_digits_and_overload_is_flagged() {
        let mut scale = Scale::new(ScaleModel::default(), 3);
        for _ in 0..100 {
            scale.step(0.01, 10.0);
            let g = scale.reading().grams;
            assert!(((g / 0.01).round() * 0.01 - g).abs() < 1e-9);
        }
        for _ in 0..2000 {
            scale.step(0.01, 5000.0);
        }
        let r = scale.reading();
        assert!(r.overload && !r.stable);
    }

    #[test]
    fn same_seed_same_readings() {
        let run = |seed| {
            let mut s = Scale::new(ScaleModel::default(), seed);
            (0..500)
                .map(|i| {
                    s.step(0.002, (i as f64 * 0.1).sin());
                    s.reading().grams
                })
                .collect::<Vec<_>>()
        };
        assert_eq!(run(5), run(5));
        assert_ne!(run(5), run(6));
    }
}
