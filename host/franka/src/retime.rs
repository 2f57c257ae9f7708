//! Phase stopping on the FCI (Ijspeert et al. 2013, eq. 2.19): a checked
//! plan's setpoints played at a rate that waits for a robot lagging its
//! command (a person holding the arm, a contact) instead of running away
//! from it.
//!
//! The rate, setpoints a cycle, heads for `1/(1 + k‖e‖²)` of the lag `e`
//! between the measured position and the last command (the core's
//! [`PhaseStop`]). It changes by a bounded step whose own change is
//! bounded, so a slowing adds little acceleration and jerk to the plan's;
//! the setpoint it reaches lies on the plan (a Catmull-Rom curve through
//! its setpoints), and before it is sent it passes the plan's own limit
//! check against the three setpoints sent before it. When the wanted
//! change fails that check, smaller ones are tried down to keeping the
//! last change; when all fail, the motion stops with the limit it would
//! break. At rate 1 (a robot that follows, or gain 0) the setpoints are
//! the plan's, bit for bit.

use primo_core::coupling::PhaseStop;
use primo_robot::JOINTS;
use primo_robot::chain::Chain;

use crate::error::{Exceeded, FrankaError};
use crate::plan::{ACCELERATION, DT, JERK, Plan, check_step};

/// The share of the FCI's acceleration and jerk a change of rate may add
/// at the plan's fastest.
const SHARE: f64 = 0.5;
/// Halvings of a refused change of rate before keeping the last one.
const HALVINGS: usize = 6;

/// A plan played at a rate that waits for the robot.
#[derive(Debug, Clone)]
pub struct Retimer {
    gain: PhaseStop,
    /// Where in the plan, in setpoints from its first.
    at: f64,
    /// Setpoints a cycle, in [0, 1].
    rate: f64,
    /// The rate's change last cycle.
    change: f64,
    /// The largest change of rate a cycle.
    max_change: f64,
    /// The largest change of that change a cycle.
    max_turn: f64,
    /// The last three setpoints sent, oldest first.
    sent: [[f64; JOINTS]; 3],
    slowest: f64,
}

impl Retimer {
    /// A retimer for `plan` with phase-stopping gain `gain`, its bounds on
    /// the change of rate from the FCI's acceleration and jerk at the
    /// plan's fastest setpoint.
    pub fn new(plan: &Plan, gain: PhaseStop) -> Retimer {
        let s = plan.setpoints();
        let fastest = s
            .windows(2)
            .flat_map(|w| w[0].iter().zip(&w[1]).map(|(a, b)| (b - a).abs()))
            .fold(0.0_f64, f64::max)
            // A resting plan allows any change.
            .max(1e-12);
        // At the plan's fastest (rad a cycle), a change c of the rate adds
        // about `fastest·c/DT²` to the acceleration, and a change of c by
        // t adds `fastest·t/DT³` to the jerk: each may take a share of the
        // FCI's limit, and the check refuses what the plan's own
        // acceleration and jerk leave no room for.
        let max_change = (SHARE * ACCELERATION * DT * DT / fastest).min(0.1);
        let max_turn = (SHARE * JERK * DT * DT * DT / fastest).min(max_change);
        let first = s.first().copied().unwrap_or_default();
        Retimer {
            gain,
            // The first cycle reaches the first setpoint, where the robot stands.
            at: -1.0,
            rate: 1.0,
            change: 0.0,
            max_change,
            max_turn,
            sent: [first; 3],
            slowest: 1.0,
        }
    }

    /// The setpoint to send when the robot is measured at `measured`, and
    /// whether it is the plan's last.
    pub fn next(
        &mut self,
        plan: &Plan,
        chain: &Chain,
        measured: [f64; JOINTS],
    ) -> Result<([f64; JOINTS], bool), FrankaError> {
        let wanted = self.wanted_rate(measured);
        // The change that heads for the wanted rate and can still stop at
        // it, one bounded turn from the last change.
        let gap = wanted - self.rate;
        let braking = (2.0 * self.max_turn * gap.abs())
            .sqrt()
            .min(self.max_change);
        let ideal = (gap.signum() * braking)
            .clamp(self.change - self.max_turn, self.change + self.max_turn);
        // Halving toward the last change, then keeping it.
        for h in 0..=HALVINGS {
            let c = self.change + (ideal - self.change) / f64::from(1u32 << h);
            if let Ok(sent) = self.advance(plan, chain, c) {
                return Ok(sent);
            }
        }
        self.advance(plan, chain, self.change)
            .map_err(FrankaError::Retimed)
    }

    /// Changes the rate by `change` and moves on, if the setpoint reached
    /// passes the limit check.
    fn advance(
        &mut self,
        plan: &Plan,
        chain: &Chain,
        change: f64,
    ) -> Result<([f64; JOINTS], bool), Exceeded> {
        let s = plan.setpoints();
        let last = s.len().saturating_sub(1) as f64;
        // The rate stays in [0, 1]: never backwards, never faster.
        let change = change.clamp(-self.rate, 1.0 - self.rate);
        let at = (self.at + self.rate + change).min(last);
        let q = on_plan(s, at);
        let time = (at - (plan.approach_len() as f64 - 1.0)) * DT;
        check_step(chain, self.sent, &q, at as usize, time)?;
        self.rate += change;
        self.change = change;
        self.at = at;
        self.sent = [self.sent[1], self.sent[2], q];
        self.slowest = self.slowest.min(self.rate);
        Ok((q, at >= last))
    }

    /// The slowest rate the plan ran at so far, setpoints a cycle.
    pub fn slowest(&self) -> f64 {
        self.slowest
    }

    /// `1/(1 + k‖e‖²)` of the lag behind the last command.
    fn wanted_rate(&self, measured: [f64; JOINTS]) -> f64 {
        let commanded = self.sent[2].map(|x| x as f32);
        let measured = measured.map(|x| x as f32);
        // Both have seven finite values (a state's joints; a checked plan):
        // a refusal leaves the rate as it is.
        self.gain
            .step(1.0, &commanded, &measured)
            .map_or(self.rate, f64::from)
    }
}

/// The plan at `at` setpoints from its first: the setpoint itself at a
/// whole number, else the Catmull-Rom curve through its neighbours.
fn on_plan(s: &[[f64; JOINTS]], at: f64) -> [f64; JOINTS] {
    let i = at.floor().max(0.0) as usize;
    let t = at - i as f64;
    let get = |k: usize| {
        s.get(k.min(s.len().saturating_sub(1)))
            .copied()
            .unwrap_or_default()
    };
    let p1 = get(i);
    if t == 0.0 {
        return p1;
    }
    let (p0, p2, p3) = (get(i.saturating_sub(1)), get(i + 1), get(i + 2));
    std::array::from_fn(|j| {
        let (a, b, c, d) = (p0[j], p1[j], p2[j], p3[j]);
        b + 0.5
            * t
            * ((c - a) + t * ((2.0 * a - 5.0 * b + 4.0 * c - d) + t * (3.0 * (b - c) + d - a)))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::fr3;
    use primo_robot::safety::check_path;

    const HOME: [f64; JOINTS] = [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785];

    /// Joints 1 and 4 moved by `amplitude` and half of it in `seconds`, if
    /// the FCI's rates allow it.
    fn plan_of(amplitude: f64, seconds: f64) -> Option<(Plan, Chain)> {
        let chain = fr3();
        let mut end = HOME;
        end[0] += amplitude;
        end[3] += amplitude / 2.0;
        let path = check_path(&chain, vec![0.0, seconds], [HOME, end].concat(), None).ok()?;
        Some((Plan::new(&path, HOME, 0.2).ok()?, chain))
    }

    fn plan() -> (Plan, Chain) {
        plan_of(0.8, 1.5).unwrap()
    }

    /// Plays `plan` to its end against a robot at `robot(cycle, measured,
    /// command)`.
    fn play_on(
        (plan, chain): (Plan, Chain),
        gain: f32,
        robot: impl Fn(usize, [f64; JOINTS], [f64; JOINTS]) -> [f64; JOINTS],
    ) -> (Vec<[f64; JOINTS]>, f64) {
        let mut r = Retimer::new(&plan, PhaseStop::new(gain).unwrap());
        let mut sent = vec![];
        let mut measured = HOME;
        // A lag of at most 0.05 rad slows to no less than 1/26 of the plan.
        for cycle in 0..30 * plan.setpoints().len() {
            let (q, last) = r.next(&plan, &chain, measured).unwrap();
            measured = robot(cycle, measured, q);
            sent.push(q);
            if last {
                return (sent, r.slowest());
            }
        }
        panic!("never finished");
    }

    fn play(
        gain: f32,
        robot: impl Fn(usize, [f64; JOINTS], [f64; JOINTS]) -> [f64; JOINTS],
    ) -> (Vec<[f64; JOINTS]>, f64) {
        play_on(plan(), gain, robot)
    }

    #[test]
    fn a_robot_that_follows_gets_the_plan_bit_for_bit() {
        let (plan, _) = plan();
        let (sent, slowest) = play(1e4, |_, _, q| q);
        assert!(sent == plan.setpoints(), "not the plan's setpoints");
        assert_eq!(slowest, 1.0);
    }

    #[test]
    fn a_held_robot_holds_the_command_within_the_fci_rates() {
        let (plan, chain) = plan();
        // Held still for 0.8 s from 0.2 s into the path.
        let start = plan.approach_len() + 200;
        let held = |cycle: usize| (start..start + 800).contains(&cycle);
        let (sent, slowest) = play(1e4, |cycle, m, q| if held(cycle) { m } else { q });
        // The command waited: it ran longer than the plan, and ran far
        // slower while the arm was held.
        assert!(sent.len() > plan.setpoints().len() + 500, "{}", sent.len());
        assert!(slowest < 0.05, "{slowest}");
        let lag = (sent[start + 799][0] - sent[start][0]).abs();
        let free = (plan.setpoints()[start + 799][0] - plan.setpoints()[start][0]).abs();
        assert!(lag < 0.2 * free, "{lag} of {free}");
        // Every setpoint sent passes the plan's check, from rest to rest.
        let first = sent[0];
        let last = *sent.last().unwrap();
        let padded: Vec<_> = [first; 3]
            .into_iter()
            .chain(sent.iter().copied())
            .chain([last; 3])
            .collect();
        for (k, w) in padded.windows(4).enumerate() {
            check_step(&chain, [w[0], w[1], w[2]], &w[3], k, 0.0).unwrap();
        }
        assert_eq!(last, *plan.setpoints().last().unwrap());
    }

    proptest::proptest! {
        #![proptest_config(proptest::prelude::ProptestConfig::with_cases(32))]
        /// Any plan the FCI's rates allow, and any lag, held or jumping
        /// from cycle to cycle, give setpoints within the limits (the
        /// retimer never fails) that reach the plan's end.
        #[test]
        fn any_lag_keeps_the_limits_and_reaches_the_end(
            amplitude in -1.0..1.0_f64,
            seconds in 0.2..3.0_f64,
            lags in proptest::collection::vec(0.0..0.05_f64, 1..40),
            seed in 0..1000_usize,
        ) {
            let Some(planned) = plan_of(amplitude, seconds) else {
                return Ok(());
            };
            let end = planned.0.setpoints().last().copied();
            let lag = |cycle: usize| lags[(cycle / 37 + seed) % lags.len()];
            let (sent, _) = play_on(planned, 1e4, |cycle, _, q| {
                let mut m = q;
                m[3] += lag(cycle);
                m
            });
            proptest::prop_assert_eq!(sent.last().copied(), end);
        }
    }

    #[test]
    fn the_curve_passes_the_setpoints() {
        let s: Vec<[f64; JOINTS]> = (0..5).map(|k| [k as f64 * k as f64; JOINTS]).collect();
        assert_eq!(on_plan(&s, 2.0), s[2]);
        // Catmull-Rom reproduces a parabola between its inner knots.
        assert!((on_plan(&s, 1.5)[0] - 2.25).abs() < 1e-12);
        assert_eq!(on_plan(&s, 9.0), s[4]);
    }
}
