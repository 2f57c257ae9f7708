//! The pouring cell: the LWR4 holds the bottle over a glass on the scale.
//! Each control step moves the bottle, lets the liquid find its level
//! (quasi-statically: no sloshing), pours over the lip, sends the poured
//! parcel on its ballistic way, lands the parcels whose time has come in the
//! glass or on the table, and weighs the glass.
//!
//! Volume is conserved exactly: what leaves the bottle is in flight until it
//! lands, then in the glass (up to its brim; the rest overflows) or spilled.
//!
//! Not modelled, on purpose: the bottle or the stream touching the glass's
//! outside, drops left on the lip, sloshing, evaporation.
//!
//! ```no_run
//! use primo_sim::cell::{Cell, CellConfig, GlassKind};
//! let cfg = CellConfig::standard(GlassKind::Normal);
//! let mut cell = Cell::new(&cfg, 0.5, 1)?;
//! // ... cell.step_joints(&q) once per control step, then:
//! let outcome = cell.finish();
//! println!("poured {} l, spilled {} l", outcome.poured, outcome.spilled);
//! # Ok::<(), primo_sim::Error>(())
//! ```

use crate::Error;
use primo_robot::{Arm, JOINTS, Pose, Robot};

use crate::bottle::{Bottle, G, Tilt};
use crate::scale::{Scale, ScaleModel};
use crate::stream::{Glass, land};

/// Litres per cubic metre.
const LITRE: f64 = 1e3;

/// Which glass stands on the scale.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum GlassKind {
    /// 7 cm opening.
    Normal,
    /// Half the diameter, as in the paper's second experiment.
    Small,
}

/// Everything fixed about the cell.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CellConfig {
    /// The arm.
    pub robot: Robot,
    /// The bottle's geometry.
    pub bottle: Bottle,
    /// The glass on the scale.
    pub glass: Glass,
    /// The scale.
    pub scale: ScaleModel,
    /// Flange → bottle frame (origin at the base centre, z along the axis
    /// to the mouth): the hand's grasp.
    pub grasp: Pose,
    /// Liquid density, kg/m³.
    pub density: f64,
    /// Control step, s (at most 2 ms).
    pub dt: f64,
    /// Longest wait for the scale to settle after the movement, s.
    pub settle_limit: f64,
    /// Keep every n-th step in the time series (0: keep none).
    pub record_every: usize,
}

/// Largest control step the cell accepts, s.
pub const MAX_DT: f64 = 0.002;

impl CellConfig {
    /// The built-in cell: a 1 l bottle (R 4 cm, 21 cm long, 11 mm mouth)
    /// held crosswise in the hand 16 cm from the flange, a glass 75 cm in
    /// front of the robot, water, a 2 ms control step.
    pub fn standard(glass: GlassKind) -> Self {
        let bottle = Bottle {
            radius: 0.04,
            length: 0.21,
            mouth: 0.011,
        };
        let centre = [0.75, 0.0];
        CellConfig {
            robot: Robot::lwr4(),
            bottle,
            glass: match glass {
                GlassKind::Normal => Glass::normal(centre),
                GlassKind::Small => Glass::small(centre),
            },
            scale: ScaleModel::default(),
            // Bottle axis along the flange's −x axis, grasped at half length;
            // the bottle frame's x is the flange's z, so with the hand
            // reaching forward (+x) and the bottle upright the bottle frame
            // is the base frame's orientation, and tilting about x pours
            // sideways (towards −y) by turning the wrist (joint 7).
            grasp: Pose {
                rotation: [[0.0, 0.0, -1.0], [0.0, 1.0, 0.0], [1.0, 0.0, 0.0]],
                position: [0.5 * bottle.length, 0.0, 0.12 + bottle.radius],
            },
            density: 998.0,
            dt: MAX_DT,
            settle_limit: 20.0,
            record_every: 0,
        }
    }

    /// Checks the settings.
    pub fn validate(&self) -> Result<(), Error> {
        Bottle::new(self.bottle.radius, self.bottle.length, self.bottle.mouth)?;
        self.glass.validate()?;
        self.scale.validate()?;
        if !(self.dt > 0.0 && self.dt <= MAX_DT) {
            return Err(Error::Invalid(format!(
                "control step {} s: must be in (0, {MAX_DT}]",
                self.dt
            )));
        }
        if !(self.density.is_finite() && self.density > 0.0) {
            return Err(Error::Invalid("density must be finite and > 0".into()));
        }
        if !(self.settle_limit.is_finite() && self.settle_limit >= 0.0) {
            return Err(Error::Invalid(
                "settle limit must be finite and >= 0".into(),
            ));
        }
        Ok(())
    }

    /// What the bottle holds, l.
    pub fn bottle_litres(&self) -> f64 {
        self.bottle.capacity() * LITRE
    }

    /// What the glass holds to its rim, l.
    pub fn glass_litres(&self) -> f64 {
        self.glass.capacity() * LITRE
    }

    /// The arm with this grasp as its tool: `forward` gives the bottle frame.
    pub fn arm(&self) -> Arm {
        Arm::with_tool(self.robot, &self.grasp)
    }

    /// The bottle frame's pose for a mouth position and an orientation, a
    /// unit quaternion `[w, x, y, z]` (the Cartesian trajectory's
    /// coordinates).
    pub fn bottle_pose(&self, mouth: [f64; 3], q: [f64; 4]) -> Pose {
        Pose::tool_at(mouth, q, self.bottle.length)
    }

    /// The mouth position and the bottle's orientation (`w ≥ 0`) of a
    /// bottle pose.
    pub fn mouth_and_orientation(&self, pose: &Pose) -> ([f64; 3], [f64; 4]) {
        (pose.point_along_z(self.bottle.length), pose.quaternion())
    }
}

/// Where the liquid is, litres.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Totals {
    /// Still in the bottle.
    pub bottle: f64,
    /// In the glass.
    pub glass: f64,
    /// On the table (missed the glass or overflowed it).
    pub spilled: f64,
    /// Between the mouth and the glass.
    pub in_flight: f64,
}

/// One row of the time series.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample {
    /// Time, s.
    pub t: f64,
    /// Tilt of the bottle from vertical, rad.
    pub tilt: f64,
    /// Mouth position, m.
    pub mouth: [f64; 3],
    /// Flow out of the mouth, l/s.
    pub flow: f64,
    /// Where the liquid is.
    pub totals: Totals,
    /// Scale display, g.
    pub scale: f64,
    /// Scale reports stable.
    pub stable: bool,
}

/// The result of one roll-out.
#[derive(Debug, Clone, PartialEq)]
pub struct Outcome {
    /// Poured volume as the settled scale reads it, l.
    pub poured: f64,
    /// Spilled volume, l (the simulation knows it exactly).
    pub spilled: f64,
    /// Final whereabouts of the liquid, l.
    pub totals: Totals,
    /// The scale became stable before the settle limit.
    pub settled: bool,
    /// Simulated time, movement and settling, s.
    pub duration: f64,
    /// Every `record_every`-th step.
    pub series: Vec<Sample>,
}

/// A parcel of liquid between the mouth and the glass.
#[derive(Debug, Clone, Copy)]
struct Parcel {
    arrives: f64,
    volume: f64,
    captured: f64,
    impact_speed: f64,
}

/// The simulated cell during one roll-out.
#[derive(Debug, Clone)]
pub struct Cell {
    cfg: CellConfig,
    arm: Arm,
    time: f64,
    steps: usize,
    /// Volumes in m³.
    bottle: f64,
    glass: f64,
    spilled: f64,
    flight: Vec<Parcel>,
    surface: Option<f64>,
    pose: Option<Pose>,
    flow: f64,
    landing: Option<[f64; 2]>,
    /// What the scale's pan carries, g.
    load: f64,
    scale: Scale,
    series: Vec<Sample>,
}

impl Cell {
    /// A cell with `volume` litres in the bottle, an empty glass on a tared
    /// scale whose noise comes from `seed`.
    pub fn new(cfg: &CellConfig, volume: f64, seed: u64) -> Result<Cell, Error> {
        cfg.validate()?;
        let capacity = cfg.bottle_litres();
        if !(volume.is_finite() && volume >= 0.0 && volume <= capacity) {
            return Err(Error::Invalid(format!(
                "bottle volume {volume} l: must be in [0, {capacity:.3}] l"
            )));
        }
        Ok(Cell {
            cfg: *cfg,
            arm: cfg.arm(),
            time: 0.0,
            steps: 0,
            bottle: volume / LITRE,
            glass: 0.0,
            spilled: 0.0,
            flight: Vec::new(),
            surface: None,
            pose: None,
            flow: 0.0,
            landing: None,
            load: 0.0,
            scale: Scale::new(cfg.scale, seed),
            series: Vec::new(),
        })
    }

    /// Where the liquid is now, litres.
    pub fn totals(&self) -> Totals {
        Totals {
            bottle: self.bottle * LITRE,
            glass: self.glass * LITRE,
            spilled: self.spilled * LITRE,
            in_flight: self.flight.iter().map(|p| p.volume).sum::<f64>() * LITRE,
        }
    }

    /// Flow out of the mouth in the last step, m³/s.
    pub fn flow(&self) -> f64 {
        self.flow
    }

    /// Where the stream poured in the last step crosses the rim's height
    /// (x, y), if anything poured.
    pub fn landing(&self) -> Option<[f64; 2]> {
        self.landing
    }

    /// The load on the scale's pan after the last step, g: the liquid in
    /// the (tared) glass plus the stream's impact force. What another
    /// simulated scale on the same pan weighs.
    pub fn load_on_pan(&self) -> f64 {
        self.load
    }

    /// One control step with the arm at joint angles `q` (radians).
    pub fn step_joints(&mut self, q: &[f64; JOINTS]) {
        let pose = self.arm.forward(q);
        self.step_pose(&pose);
    }

    /// One control step with the bottle frame at `pose`.
    pub fn step_pose(&mut self, pose: &Pose) {
        self.pose = Some(*pose);
        let dt = self.cfg.dt;
        self.pour(pose, dt);
        self.time += dt;
        self.land();
        self.steps += 1;
        if self.cfg.record_every > 0 && self.steps.is_multiple_of(self.cfg.record_every) {
            self.record(pose);
        }
    }

    /// Lets the liquid out of the bottle at `pose` for `dt`.
    fn pour(&mut self, pose: &Pose, dt: f64) {
        let b = self.cfg.bottle;
        let axis = pose.z_axis();
        let cos = axis[2].clamp(-1.0, 1.0);
        let tilt = cos.acos();
        let sin = tilt.sin();
        self.flow = 0.0;
        self.landing = None;
        let folded = Tilt::from(tilt);
        // Cheap test first (one closed-form volume, no surface solve).
        if !b.reaches_lip(self.bottle, folded) {
            self.surface = None;
            return;
        }
        let z_s = b.surface_height(self.bottle, folded, self.surface);
        self.surface = Some(z_s);
        let out = b.outflow(z_s, folded);
        let volume = (out.flow * dt).min(self.bottle);
        if !(volume > 0.0 && out.area > 0.0) {
            return;
        }
        self.bottle -= volume;
        self.flow = volume / dt;
        // The stream leaves from the wetted part's centroid, towards the
        // low side of the mouth, along the axis at the mean speed.
        let down: [f64; 3] = if sin > 1e-12 {
            std::array::from_fn(|i| (cos * axis[i] - if i == 2 { 1.0 } else { 0.0 }) / sin)
        } else {
            [0.0; 3]
        };
        let origin =
            std::array::from_fn(|i| pose.position[i] + b.length * axis[i] + out.centroid * down[i]);
        let speed = out.flow / out.area;
        let velocity = axis.map(|a| speed * a);
        let at = land(
            origin,
            velocity,
            out.flow,
            &self.cfg.glass,
            self.cfg.glass.level(self.glass),
        );
        self.landing = Some(at.point);
        self.flight.push(Parcel {
            arrives: self.time + dt + at.time,
            volume,
            captured: at.captured,
            impact_speed: at.impact_speed,
        });
    }

    /// Lands the parcels that have arrived and weighs the glass.
    fn land(&mut self) {
        let capacity = self.cfg.glass.capacity();
        let mut momentum = 0.0;
        let now = self.time;
        let (glass, spilled) = (&mut self.glass, &mut self.spilled);
        self.flight.retain(|p| {
            if p.arrives > now + 1e-12 {
                return true;
            }
            let into = p.volume * p.captured;
            let room = (capacity - *glass).max(0.0);
            *glass += into.min(room);
            *spilled += p.volume - into.min(room);
            momentum += into * p.impact_speed;
            false
        });
        let rho = self.cfg.density;
        // The tared scale carries the liquid plus the stream's impact force.
        let load_kg = rho * self.glass + rho * momentum / self.cfg.dt / G;
        self.load = load_kg * 1e3;
        self.scale.step(self.cfg.dt, self.load);
    }

    fn record(&mut self, pose: &Pose) {
        let mouth = pose.point_along_z(self.cfg.bottle.length);
        let reading = self.scale.reading();
        self.series.push(Sample {
            t: self.time,
            tilt: pose.z_axis()[2].clamp(-1.0, 1.0).acos(),
            mouth,
            flow: self.flow * LITRE,
            totals: self.totals(),
            scale: reading.grams,
            stable: reading.stable,
        });
    }

    /// Holds the last pose until nothing flows or flies and the scale is
    /// stable (or the settle limit passes), then reports the outcome.
    pub fn finish(mut self) -> Outcome {
        let end = self.time + self.cfg.settle_limit;
        let mut settled = false;
        while self.time < end {
            let quiet = self.flow == 0.0 && self.flight.is_empty();
            if quiet && self.scale.reading().stable {
                settled = true;
                break;
            }
            match self.pose {
                Some(pose) => self.step_pose(&pose),
                None => {
                    // Never moved: only the scale has anything to do.
                    self.time += self.cfg.dt;
                    self.land();
                }
            }
        }
        let reading = self.scale.reading();
        let grams_per_litre = self.cfg.density;
        Outcome {
            poured: reading.grams / grams_per_litre,
            spilled: self.spilled * LITRE,
            totals: self.totals(),
            settled,
            duration: self.time,
            series: self.series,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::FRAC_PI_2;

    /// A bottle pose with the mouth at `mouth`, tilted by `tilt` about the
    /// y axis (mouth towards +x).
    fn tilted(cfg: &CellConfig, mouth: [f64; 3], tilt: f64) -> Pose {
        let half = 0.5 * tilt;
        cfg.bottle_pose(mouth, [half.cos(), 0.0, half.sin(), 0.0])
    }

    fn over_glass(cfg: &CellConfig) -> [f64; 3] {
        let g = cfg.glass;
        [g.centre[0] - 0.02, g.centre[1], g.rim() + 0.03]
    }

    fn conserved(cell: &Cell, initial: f64) {
        let t = cell.totals();
        let sum = t.bottle + t.glass + t.spilled + t.in_flight;
        assert!((sum - initial).abs() < 1e-9, "{t:?} vs {initial}");
    }

    #[test]
    fn upright_bottle_pours_nothing_and_the_scale_stays_at_zero() {
        let mut cfg = CellConfig::standard(GlassKind::Normal);
        cfg.record_every = 10;
        let mut cell = Cell::new(&cfg, 1.0, 1).unwrap();
        let pose = tilted(&cfg, over_glass(&cfg), 0.0);
        for _ in 0..500 {
            cell.step_pose(&pose);
        }
        let out = cell.finish();
        // The time series: every 10th step, movement and settling.
        let steps = (out.duration / cfg.dt).round() as usize;
        assert_eq!(out.series.len(), steps / 10);
        assert!(
            out.series
                .iter()
                .all(|s| s.flow == 0.0 && s.totals.bottle == 1.0)
        );
        assert_eq!(out.totals.bottle, 1.0);
        assert_eq!(out.poured, 0.0);
        assert!(out.settled);
    }

    #[test]
    fn pouring_over_the_glass_conserves_volume_and_the_scale_reads_the_glass() {
        let cfg = CellConfig::standard(GlassKind::Normal);
        let initial = 0.5;
        let mut cell = Cell::new(&cfg, initial, 2).unwrap();
        let mouth = over_glass(&cfg);
        // Tilt to 110° over 2 s, hold 1 s, tilt back over 1 s.
        let steps = |s: f64| (s / cfg.dt) as usize;
        let mut max_flight: f64 = 0.0;
        let mut impact: f64 = 0.0;
        for i in 0..steps(4.0) {
            let t = i as f64 * cfg.dt;
            let tilt = if t < 2.0 {
                110f64.to_radians() * t / 2.0
            } else if t < 3.0 {
                110f64.to_radians()
            } else {
                110f64.to_radians() * (4.0 - t)
            };
            cell.step_pose(&tilted(&cfg, mouth, tilt));
            conserved(&cell, initial);
            max_flight = max_flight.max(cell.totals().in_flight);
            // The pan carries the glass's contents plus the stream's impact.
            impact = impact.max(cell.load_on_pan() - cell.glass * cfg.density * 1e3);
        }
        assert!(max_flight > 1e-4, "a stream in flight: {max_flight}");
        assert!(impact > 0.1, "impact force {impact} g");
        for _ in 0..steps(1.0) {
            cell.step_pose(&tilted(&cfg, mouth, 0.0));
        }
        assert!(cell.flight.is_empty());
        assert!((cell.load_on_pan() - cell.glass * cfg.density * 1e3).abs() < 1e-9);
        let out = cell.finish();
        let t = out.totals;
        assert!((t.bottle + t.glass + t.spilled + t.in_flight - initial).abs() < 1e-9);
        assert_eq!(t.in_flight, 0.0);
        assert!(t.glass > 0.05, "poured something: {t:?}");
        assert!(t.spilled < 1e-3 * t.glass, "aimed at the glass: {t:?}");
        assert!(out.settled);
        // The settled scale shows the glass's contents to a few digits.
        assert!(
            (out.poured - t.glass).abs() < 0.03e-3,
            "{} vs {}",
            out.poured,
            t.glass
        );
    }

    #[test]
    fn pouring_beside_the_glass_spills_everything() {
        let cfg = CellConfig::standard(GlassKind::Normal);
        let mut cell = Cell::new(&cfg, 0.8, 3).unwrap();
        let mut mouth = over_glass(&cfg);
        mouth[1] += 0.2;
        for _ in 0..1000 {
            cell.step_pose(&tilted(&cfg, mouth, 1.8));
        }
        for _ in 0..500 {
            cell.step_pose(&tilted(&cfg, mouth, 0.0));
        }
        let out = cell.finish();
        assert!(out.spilled > 0.05 && out.totals.glass == 0.0, "{out:?}");
        assert!(out.poured.abs() < 1e-4);
        conserved_outcome(&out, 0.8);
    }

    fn conserved_outcome(out: &Outcome, initial: f64) {
        let t = out.totals;
        assert!((t.bottle + t.glass + t.spilled + t.in_flight - initial).abs() < 1e-9);
    }

    #[test]
    fn fuller_bottle_pours_at_a_smaller_tilt() {
        let cfg = CellConfig::standard(GlassKind::Normal);
        let first_flow = |volume: f64| {
            let mut cell = Cell::new(&cfg, volume, 4).unwrap();
            for i in 0..2000 {
                let tilt = FRAC_PI_2 * 1.5 * i as f64 / 2000.0;
                cell.step_pose(&tilted(&cfg, over_glass(&cfg), tilt));
                if cell.flow > 0.0 {
                    return tilt;
                }
            }
            f64::NAN
        };
        let (full, low) = (first_flow(1.0), first_flow(0.3));
        assert!(full < low, "{full} {low}");
    }

    #[test]
    fn overflow_is_spilled() {
        let mut cfg = CellConfig::standard(GlassKind::Normal);
        cfg.glass.height = 0.02; // holds 77 ml
        let mut cell = Cell::new(&cfg, 0.5, 5).unwrap();
        for _ in 0..3000 {
            cell.step_pose(&tilted(&cfg, over_glass(&cfg), 2.0));
        }
        let out = cell.finish();
        assert!((out.totals.glass - cfg.glass.capacity() * LITRE).abs() < 1e-12);
        assert!(out.spilled > 0.1);
        conserved_outcome(&out, 0.5);
    }

    #[test]
    fn bad_settings_are_refused() {
        let cfg = CellConfig::standard(GlassKind::Small);
        assert!(Cell::new(&cfg, 2.0, 0).is_err());
        assert!(Cell::new(&cfg, f64::NAN, 0).is_err());
        let mut slow = cfg;
        slow.dt = 0.01;
        assert!(Cell::new(&slow, 0.5, 0).is_err());
    }

    #[test]
    fn cartesian_coordinates_round_trip() {
        let cfg = CellConfig::standard(GlassKind::Normal);
        let mouth = [0.5, -0.1, 0.3];
        // Any sign and norm: the orientation comes back unit, w ≥ 0.
        let q = [-0.8, 0.1, -0.5, 0.3];
        let n = q.iter().map(|v: &f64| v * v).sum::<f64>().sqrt();
        let (m, q2) = cfg.mouth_and_orientation(&cfg.bottle_pose(mouth, q.map(|v| 2.0 * v)));
        for i in 0..3 {
            assert!((m[i] - mouth[i]).abs() < 1e-12);
        }
        for i in 0..4 {
            assert!((q2[i] + q[i] / n).abs() < 1e-12, "{q2:?}");
        }
    }
}
