//! A scripted, slightly imperfect expert who pours demonstrations in the
//! simulated cell, as a person guiding the arm kinesthetically would.
//!
//! The expert brings the bottle over the glass while pre-tilting it to just
//! short of where the liquid would reach the lip (it knows how full the
//! bottle is), tilts on at a rate that holds a comfortable flow, keeps the
//! stream centred in the glass by moving the mouth, starts tilting back when
//! it judges the glass holds the target (anticipating what still flows while
//! it tilts back), and retreats. It is imperfect: it misjudges the volume in
//! the glass by a few per cent and its hand trembles by a millimetre and a
//! few milliradians. The movement is recorded at 100 Hz both as the bottle
//! pose (mouth position and orientation, a unit quaternion kept
//! sign-continuous from sample to sample) and as joint angles: the
//! robot's redundancy lets each demonstration hold the elbow differently,
//! as two people guiding the arm would.

use crate::Error;
use primo_robot::{JOINTS, Pose};

use crate::bottle::Bottle;
use crate::cell::{Cell, CellConfig};
use primo_core::rng::Xoshiro128PlusPlus;
use rand_core::{Rng, SeedableRng};

/// How one demonstration is given.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Style {
    /// Angle at which the demonstrator holds joint 3 (the elbow's swing), rad.
    pub elbow: f64,
    /// Seed of the imperfections (volume misjudgement, tremor).
    pub seed: u64,
}

/// A recorded demonstration.
#[derive(Debug, Clone, PartialEq)]
pub struct Recording {
    /// Sample times, s, from 0 at 100 Hz.
    pub t: Vec<f64>,
    /// Mouth position (m) and bottle orientation (a unit quaternion
    /// `[w, x, y, z]`, each sample's sign the one nearer the previous
    /// sample's) per sample.
    pub cartesian: Vec<[f64; 7]>,
    /// Joint angles (rad) per sample.
    pub joints: Vec<[f64; JOINTS]>,
    /// Volume in the glass at the end, l.
    pub poured: f64,
    /// Volume spilled, l.
    pub spilled: f64,
}

/// The two built-in demonstrations: 0.2 l from bottles holding 0.3 l and
/// 1.0 l, with the elbow held differently.
pub const BUILT_IN: [(f64, Style); 2] = [
    (
        0.3,
        Style {
            elbow: 0.4,
            seed: 1,
        },
    ),
    (
        1.0,
        Style {
            elbow: -0.4,
            seed: 2,
        },
    ),
];

/// Recording period, s.
const RECORD: f64 = 0.01;
/// Flow the expert aims for while pouring, m³/s.
const FLOW: f64 = 0.1e-3;
/// Largest tilt rate and acceleration of the expert's wrist.
const TILT_RATE: f64 = 0.6;
const TILT_ACCEL: f64 = 3.0;
/// How long the expert expects the flow to go on while it tilts back, s.
const LEAD: f64 = 0.3;

/// Minimum-jerk blend from 0 to 1.
fn min_jerk(s: f64) -> f64 {
    let s = s.clamp(0.0, 1.0);
    s * s * s * (10.0 - 15.0 * s + 6.0 * s * s)
}

/// The tilt at which liquid first reaches the lip of a bottle holding
/// `volume` m³ (the expert's feel for how full the bottle is).
fn lip_tilt(bottle: &Bottle, volume: f64) -> f64 {
    let (mut lo, mut hi) = (0.0, std::f64::consts::PI);
    for _ in 0..50 {
        let mid = 0.5 * (lo + hi);
        if bottle.reaches_lip(volume, mid) {
            hi = mid;
        } else {
            lo = mid;
        }
    }
    lo
}

/// A smooth tremor: three sines with random phases, amplitude `a`.
struct Tremor {
    phases: [[f64; 3]; 7],
}

impl Tremor {
    fn new(rng: &mut Xoshiro128PlusPlus) -> Self {
        let mut unit = || f64::from(rng.next_u32()) / f64::from(u32::MAX);
        Tremor {
            phases: std::array::from_fn(|_| {
                std::array::from_fn(|_| std::f64::consts::TAU * unit())
            }),
        }
    }

    /// Channel `k` at time `t`, in [−1, 1].
    fn at(&self, k: usize, t: f64) -> f64 {
        let p = self.phases.get(k).copied().unwrap_or_default();
        let f = [1.3, 2.9, 4.7];
        (0..3)
            .map(|i| (std::f64::consts::TAU * f[i] * t + p[i]).sin())
            .sum::<f64>()
            / 3.0
    }
}

#[derive(Debug, Clone, Copy, PartialEq)]
enum Phase {
    Approach,
    Pour,
    Back,
    Retreat {
        from: f64,
        mouth: [f64; 3],
        tilt: f64,
    },
}

/// Demonstrates pouring `target` litres from a bottle holding `volume`
/// litres in the cell `cfg`.
pub fn synthesize(
    cfg: &CellConfig,
    volume: f64,
    target: f64,
    style: &Style,
) -> Result<Recording, Error> {
    if !(target.is_finite() && target > 0.0 && target < volume) {
        return Err(Error::Invalid(format!(
            "pour {target} l from {volume} l: must be > 0 and less than the bottle holds"
        )));
    }
    let mut cell = Cell::new(cfg, volume, style.seed)?;
    let mut rng = Xoshiro128PlusPlus::seed_from_u64(style.seed);
    let misjudge = 1.0 + 0.08 * (f64::from(rng.next_u32()) / f64::from(u32::MAX) - 0.5);
    let tremor = Tremor::new(&mut rng);
    let g = cfg.glass;
    let start = [g.centre[0] - 0.15, g.centre[1] + 0.25, g.rim() + 0.2];
    let aim = [g.centre[0], g.centre[1] + 0.02, g.rim() + 0.025];
    let end = [g.centre[0] - 0.1, g.centre[1] + 0.25, g.rim() + 0.25];
    let pre_tilt = (lip_tilt(&cfg.bottle, volume * 1e-3) - 0.15).max(0.0);
    let (approach, retreat) = (2.5, 2.5);

    let arm = cfg.arm();
    let rest = rest_configuration(style.elbow);
    let mut q = rest;
    let mut demo = Recording {
        t: Vec::new(),
        cartesian: Vec::new(),
        joints: Vec::new(),
        poured: 0.0,
        spilled: 0.0,
    };
    let every = (RECORD / cfg.dt).round().max(1.0) as usize;
    let (mut tilt, mut rate) = (0.0f64, 0.0f64);
    let mut mouth = start;
    let mut phase = Phase::Approach;
    let mut step = 0usize;
    loop {
        let t = step as f64 * cfg.dt;
        // The expert's plan for this instant.
        let desired_rate = match phase {
            Phase::Approach => {
                let s = min_jerk(t / approach);
                mouth = std::array::from_fn(|i| start[i] + (aim[i] - start[i]) * s);
                tilt = pre_tilt * s;
                if t >= approach {
                    phase = Phase::Pour;
                }
                None
            }
            Phase::Pour => {
                let seen = cell.totals();
                let judged = misjudge * (seen.glass + seen.in_flight);
                if judged + cell.flow() * 1e3 * LEAD >= target {
                    phase = Phase::Back;
                }
                // Steer the stream's landing point onto the glass's centre.
                if let Some(p) = cell.landing() {
                    let miss = [p[0] - g.centre[0], p[1] - g.centre[1]];
                    for (m, e) in mouth.iter_mut().zip(miss) {
                        *m -= (2.0 * e).clamp(-0.03, 0.03) * cfg.dt;
                    }
                }
                Some(TILT_RATE * ((FLOW - cell.flow()) / FLOW).clamp(-1.0, 1.0))
            }
            Phase::Back => {
                if cell.flow() == 0.0 && rate <= 0.0 {
                    phase = Phase::Retreat {
                        from: t,
                        mouth,
                        tilt,
                    };
                }
                Some(-1.5 * TILT_RATE)
            }
            Phase::Retreat {
                from,
                mouth: m0,
                tilt: t0,
            } => {
                let s = min_jerk((t - from) / retreat);
                mouth = std::array::from_fn(|i| m0[i] + (end[i] - m0[i]) * s);
                tilt = t0 * (1.0 - s);
                if t - from >= retreat + 0.3 {
                    break;
                }
                None
            }
        };
        if let Some(want) = desired_rate {
            let dv = (want - rate).clamp(-TILT_ACCEL * cfg.dt, TILT_ACCEL * cfg.dt);
            rate += dv;
            tilt = (tilt + rate * cfg.dt).max(0.0);
        } else {
            rate = 0.0;
        }
        if t > 60.0 {
            return Err(Error::Invalid(format!(
                "the expert did not finish pouring {target} l from {volume} l within 60 s"
            )));
        }
        // What the hand actually does: the plan plus tremor, the tilt
        // about the base's x axis and the tremor's turn as a rotation
        // vector.
        let shake = |k: usize, a: f64| a * tremor.at(k, t);
        let actual = [
            mouth[0] + shake(0, 0.001),
            mouth[1] + shake(1, 0.001),
            mouth[2] + shake(2, 0.001),
        ];
        let turned = [tilt + shake(3, 0.004), shake(4, 0.003), shake(5, 0.003)];
        let mut orientation = Pose::from_rotation_vector([0.0; 3], turned).quaternion();
        if let Some(last) = demo.cartesian.last() {
            let dot: f64 = (0..4).map(|i| last[3 + i] * orientation[i]).sum();
            if dot < 0.0 {
                orientation = orientation.map(|v| -v);
            }
        }
        let pose = cfg.bottle_pose(actual, orientation);
        if step.is_multiple_of(every) {
            q = arm
                .inverse(&pose, &q, &rest)
                .map_err(|e| Error::Invalid(format!("demonstration at t = {t:.2} s: {e}")))?;
            demo.t.push(t);
            let [w, x, y, z] = orientation;
            demo.cartesian
                .push([actual[0], actual[1], actual[2], w, x, y, z]);
            demo.joints.push(q);
        }
        cell.step_pose(&pose);
        step += 1;
    }
    cfg.robot
        .chain()
        .check_samples(
            demo.t
                .iter()
                .copied()
                .zip(demo.joints.iter().map(|q| &q[..])),
        )
        .map_err(|v| Error::Invalid(format!("demonstration from {volume} l: {v}")))?;
    let out = cell.finish();
    demo.poured = out.totals.glass;
    demo.spilled = out.spilled;
    Ok(demo)
}

/// A comfortable configuration for pouring over the glass, with joint 3 at
/// `elbow`: the null-space target of the demonstrator.
pub fn rest_configuration(elbow: f64) -> [f64; JOINTS] {
    [0.0, -0.75, elbow, 1.7, 0.05, 0.9, 0.0]
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::cell::GlassKind;

    #[test]
    fn built_in_demonstrations_pour_about_the_target_without_spilling() {
        let cfg = CellConfig::standard(GlassKind::Normal);
        for (volume, style) in BUILT_IN {
            let started = std::time::Instant::now();
            let demo = synthesize(&cfg, volume, 0.2, &style).unwrap();
            // The tilt is the turn about x: 2·atan2(qx, qw).
            let tilt = demo
                .cartesian
                .iter()
                .map(|c| 2.0 * c[4].atan2(c[3]))
                .fold(0.0, f64::max);
            println!(
                "{volume} l: poured {:.4} l, spilled {:.5} l, {:.2} s, max tilt {:.1} deg, {:?}",
                demo.poured,
                demo.spilled,
                demo.t.last().unwrap(),
                tilt.to_degrees(),
                started.elapsed()
            );
            assert!((demo.poured - 0.2).abs() < 0.02, "{}", demo.poured);
            assert!(demo.spilled < 0.002);
            // The joint recording is the same movement.
            let arm = cfg.arm();
            for (c, q) in demo.cartesian.iter().zip(&demo.joints) {
                let (m, o) = cfg.mouth_and_orientation(&arm.forward(q));
                for i in 0..3 {
                    assert!((m[i] - c[i]).abs() < 1e-6);
                }
                // Unit, and the same orientation (of either sign).
                let norm = c[3..].iter().map(|v| v * v).sum::<f64>();
                let dot: f64 = (0..4).map(|i| o[i] * c[3 + i]).sum();
                assert!((norm - 1.0).abs() < 1e-12 && dot.abs() > 1.0 - 1e-12);
            }
            // Sign-continuous: neighbouring samples' quaternions agree.
            for pair in demo.cartesian.windows(2) {
                let dot: f64 = (3..7).map(|i| pair[0][i] * pair[1][i]).sum();
                assert!(dot > 0.99, "{pair:?}");
            }
        }
    }
}
