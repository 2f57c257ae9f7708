//! One `FollowJointTrajectory` execution, sans I/O: the adapter
//! ([`crate::dds`]) feeds it what arrives (joint states, the goal's
//! response, feedback, the result) and the time, and does what it asks
//! ([`Command`]): send the goal once, or cancel it.
//!
//! 1. It waits for a joint state, maps its joints to the path's chain by
//!    name (never by index) and refuses to start unless every joint is
//!    within [`ExecutionConfig::start_tolerance`] of the path's start; or,
//!    with [`ExecutionConfig::approach_speed`], puts a minimum-jerk
//!    approach from where the robot is before the path (as FRI does), the
//!    two checked against the chain's limits as one trajectory.
//! 2. It asks for the goal to be sent: the path's samples, joints in the
//!    chain's order, times from its start, stamp zero (start now), the
//!    controller's own tolerances.
//! 3. While the goal runs it records the joint states (the executed
//!    series, times from the goal's acceptance) and the feedback; it
//!    cancels the goal if the joint states fall silent, go back in time or
//!    repeat one stamp too long, or no result comes long after the
//!    trajectory's end.
//! 4. It ends with the result: success only for a succeeded goal with
//!    error code 0; a rejection, an abort, a cancellation or a non-zero
//!    error code are [`Ros2Error`]s.
//!
//! ```
//! use primo_robot::{Robot, safety::check_joints};
//! use primo_ros2::execution::{Command, Execution, ExecutionConfig};
//! use primo_ros2::msgs::{FjtResult, GoalStatus, JointState};
//! let path = check_joints(&Robot::lwr4(), vec![0.0, 1.0], vec![[0.1; 7], [0.2; 7]]).unwrap();
//! let mut run = Execution::new(&path, ExecutionConfig::default());
//! let at_start = JointState {
//!     name: (1..=7).map(|i| format!("a{i}")).collect(),
//!     position: vec![0.1; 7],
//!     ..Default::default()
//! };
//! assert!(matches!(run.joint_state(0.0, &at_start), Command::SendGoal(_)));
//! assert_eq!(run.goal_response(0.1, true), Command::Wait);
//! run.joint_state(0.2, &at_start);
//! run.result(1.2, GoalStatus::Succeeded, &FjtResult::default());
//! assert_eq!(run.outcome(), Some(&Ok(())));
//! assert_eq!(run.executed().times, [0.1]);
//! ```

use primo_robot::JointPath;
use primo_robot::execute::Executed;
use primo_robot::limits::{min_jerk, min_jerk_duration};
use primo_robot::safety::check_path;

use crate::msgs::{
    Feedback, FjtResult, Goal, GoalStatus, JointState, JointTrajectory, JointTrajectoryPoint, Stamp,
};
use crate::{ErrorCode, Ros2Error};

use std::time::Duration;

/// How patient and how strict an execution is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ExecutionConfig {
    /// How far each joint may be from the path's start, rad or m.
    pub start_tolerance: f64,
    /// A robot further from the start: `None` refuses it; `Some(f)`
    /// approaches the start first, each joint's peak speed at most `f`
    /// times its velocity limit.
    pub approach_speed: Option<f64>,
    /// Longest wait for the first joint state.
    pub first_state: Duration,
    /// Longest silence of the joint states (or one stamp repeated) while
    /// the goal runs.
    pub state_silence: Duration,
    /// Longest wait for the controller to accept or reject the goal.
    pub goal_response: Duration,
    /// How long after the trajectory's planned end a result may come.
    pub result_margin: Duration,
}

impl Default for ExecutionConfig {
    /// 0.01 rad from the start; 5 s for the first state; 1 s of silence;
    /// 5 s for the goal's response; 10 s after the end for the result; no
    /// approach.
    fn default() -> Self {
        ExecutionConfig {
            start_tolerance: 0.01,
            approach_speed: None,
            first_state: Duration::from_secs(5),
            state_silence: Duration::from_secs(1),
            goal_response: Duration::from_secs(5),
            result_margin: Duration::from_secs(10),
        }
    }
}

/// What the adapter must do.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Nothing now.
    Wait,
    /// Send this goal (asked once).
    SendGoal(Box<Goal>),
    /// Cancel the goal sent; the execution has ended with an error.
    Cancel,
}

/// Where the execution is.
#[derive(Debug, Clone, PartialEq)]
pub enum Phase {
    /// Waiting for the first joint state.
    WaitingForState,
    /// The goal was sent at this time; waiting for the controller's answer.
    Sent(f64),
    /// The controller accepted the goal at this time.
    Executing(f64),
    /// Ended: `Ok` for a goal that succeeded with error code 0.
    Ended(Result<(), Ros2Error>),
}

/// One execution of a checked path.
#[derive(Debug, Clone)]
pub struct Execution {
    cfg: ExecutionConfig,
    path: JointPath,
    /// What the goal holds: the path, after an approach if there is one.
    sent: Option<JointPath>,
    phase: Phase,
    /// Per joint of the chain, its place in the last state's names.
    order: Option<(Vec<String>, Vec<usize>)>,
    executed: Executed,
    feedback: usize,
    max_error: f64,
    /// Local time of the last state, and of its stamp's first arrival.
    last_state: f64,
    stamp_since: f64,
    stamp: Option<Stamp>,
}

/// `d` in seconds.
fn secs(d: Duration) -> f64 {
    d.as_secs_f64()
}

impl Execution {
    /// An execution of `path` (it passed the limits of its chain); the
    /// times given to it are the adapter's clock in seconds from this
    /// execution's start, 0.
    pub fn new(path: &JointPath, cfg: ExecutionConfig) -> Self {
        Execution {
            cfg,
            path: path.clone(),
            sent: None,
            phase: Phase::WaitingForState,
            order: None,
            executed: Executed::default(),
            feedback: 0,
            max_error: 0.0,
            last_state: 0.0,
            stamp_since: 0.0,
            stamp: None,
        }
    }

    /// What the goal holds (the path, after the approach if one was
    /// planned).
    pub fn goal_path(&self) -> &JointPath {
        self.sent.as_ref().unwrap_or(&self.path)
    }

    /// The goal: the samples of [`Execution::goal_path`], its chain's
    /// joint names.
    pub fn goal(&self) -> Goal {
        let path = self.goal_path();
        let t0 = path.times().first().copied().unwrap_or(0.0);
        let points = path
            .times()
            .iter()
            .zip(path.rows())
            .map(|(t, q)| JointTrajectoryPoint {
                positions: q.to_vec(),
                time_from_start: Stamp::from_seconds(t - t0),
                ..Default::default()
            })
            .collect();
        Goal {
            trajectory: JointTrajectory {
                joint_names: path.chain().names().iter().map(|n| n.to_string()).collect(),
                points,
                ..Default::default()
            },
            ..Default::default()
        }
    }

    /// Where it is.
    pub fn phase(&self) -> &Phase {
        &self.phase
    }

    /// How it ended, once it has.
    pub fn outcome(&self) -> Option<&Result<(), Ros2Error>> {
        match &self.phase {
            Phase::Ended(r) => Some(r),
            _ => None,
        }
    }

    /// The joint states since the goal was accepted, in the chain's joint
    /// order, times from the acceptance.
    pub fn executed(&self) -> &Executed {
        &self.executed
    }

    /// Feedback messages received.
    pub fn feedback_count(&self) -> usize {
        self.feedback
    }

    /// The largest |desired − actual| of any joint in the feedback, rad
    /// or m.
    pub fn max_feedback_error(&self) -> f64 {
        self.max_error
    }

    fn end(&mut self, r: Result<(), Ros2Error>) -> Command {
        let sent = matches!(self.phase, Phase::Sent(_) | Phase::Executing(_));
        let failed = r.is_err();
        self.phase = Phase::Ended(r);
        if sent && failed {
            Command::Cancel
        } else {
            Command::Wait
        }
    }

    /// The state's positions in the chain's order.
    fn positions(&mut self, msg: &JointState) -> Result<Vec<f64>, Ros2Error> {
        let chain = self.path.chain();
        let fresh = match &self.order {
            Some((names, _)) => names != &msg.name,
            None => true,
        };
        if fresh {
            let mut order = Vec::with_capacity(chain.dof());
            for joint in chain.names() {
                let found = msg
                    .name
                    .iter()
                    .position(|n| chain.index(n) == chain.index(joint))
                    .filter(|&i| i < msg.position.len());
                match found {
                    Some(i) => order.push(i),
                    None => {
                        return Err(Ros2Error::MissingJoint {
                            joint: joint.to_string(),
                            named: match msg.name.join(", ") {
                                n if n.is_empty() => "no joint".to_string(),
                                n => n,
                            },
                        });
                    }
                }
            }
            self.order = Some((msg.name.clone(), order));
        }
        let order = self
            .order
            .as_ref()
            .map(|(_, o)| o.as_slice())
            .unwrap_or(&[]);
        Ok(order
            .iter()
            .map(|&i| msg.position.get(i).copied().unwrap_or(f64::NAN))
            .collect())
    }

    /// A joint state arrived at `now`.
    pub fn joint_state(&mut self, now: f64, msg: &JointState) -> Command {
        if matches!(self.phase, Phase::Ended(_)) {
            return Command::Wait;
        }
        let q = match self.positions(msg) {
            Ok(q) => q,
            Err(e) => return self.end(Err(e)),
        };
        if let Some(e) = self.check_stamp(now, msg.header.stamp) {
            return self.end(Err(e));
        }
        self.last_state = now;
        match self.phase {
            Phase::WaitingForState => {
                let chain = self.path.chain();
                let start = self.path.start();
                let worst = (0..chain.dof()).map(|j| (j, (q[j] - start[j]).abs())).fold(
                    None,
                    |w: Option<(usize, f64)>, (j, d)| match w {
                        Some((_, wd)) if !(d > wd || d.is_nan()) => w,
                        _ => Some((j, d)),
                    },
                );
                let off = worst.filter(|(_, d)| *d > self.cfg.start_tolerance || d.is_nan());
                if let (Some(_), Some(speed)) = (off, self.cfg.approach_speed) {
                    match approach(&self.path, &q, speed) {
                        Ok(path) => self.sent = Some(path),
                        Err(why) => return self.end(Err(Ros2Error::Approach { why })),
                    }
                } else if let Some((j, _)) = off {
                    let joint = chain
                        .names()
                        .get(j)
                        .map_or(String::new(), |n| n.to_string());
                    return self.end(Err(Ros2Error::NotAtStart {
                        joint,
                        at: q[j],
                        start: start[j],
                        tolerance: self.cfg.start_tolerance,
                    }));
                }
                self.phase = Phase::Sent(now);
                Command::SendGoal(Box::new(self.goal()))
            }
            Phase::Executing(since) => {
                self.executed.times.push(now - since);
                self.executed.positions.extend(q);
                Command::Wait
            }
            Phase::Sent(_) | Phase::Ended(_) => Command::Wait,
        }
    }

    /// A stamp earlier than the last one, or one repeated too long.
    fn check_stamp(&mut self, now: f64, stamp: Stamp) -> Option<Ros2Error> {
        if stamp.is_zero() {
            // Not stamped: nothing to compare.
            return None;
        }
        match self.stamp {
            Some(previous) if stamp < previous => {
                return Some(Ros2Error::NonMonotonic { stamp, previous });
            }
            Some(previous) if stamp == previous => {
                let stale = now - self.stamp_since;
                if matches!(self.phase, Phase::Executing(_)) && stale > secs(self.cfg.state_silence)
                {
                    return Some(Ros2Error::Stale {
                        stamp,
                        stale: Duration::from_secs_f64(stale.max(0.0)),
                    });
                }
            }
            _ => {
                self.stamp = Some(stamp);
                self.stamp_since = now;
            }
        }
        None
    }

    /// The controller accepted (`true`) or rejected the goal.
    pub fn goal_response(&mut self, now: f64, accepted: bool) -> Command {
        match self.phase {
            Phase::Sent(_) if accepted => {
                self.phase = Phase::Executing(now);
                // Silence counts from the acceptance.
                self.last_state = self.last_state.max(now);
                Command::Wait
            }
            Phase::Sent(_) => {
                // Nothing runs: nothing to cancel.
                self.phase = Phase::Ended(Err(Ros2Error::Rejected));
                Command::Wait
            }
            _ => Command::Wait,
        }
    }

    /// A feedback message of the goal.
    pub fn feedback(&mut self, feedback: &Feedback) {
        if matches!(self.phase, Phase::Executing(_)) {
            self.feedback += 1;
            for e in &feedback.error.positions {
                if e.abs() > self.max_error {
                    self.max_error = e.abs();
                }
            }
        }
    }

    /// The goal's result: how it ended.
    pub fn result(&mut self, _now: f64, status: GoalStatus, result: &FjtResult) -> Command {
        if !matches!(self.phase, Phase::Sent(_) | Phase::Executing(_)) {
            return Command::Wait;
        }
        let message = result.error_string.clone();
        let outcome = match (status, ErrorCode::from_code(result.error_code)) {
            (GoalStatus::Succeeded, None) => Ok(()),
            (GoalStatus::Canceled, _) => Err(Ros2Error::Canceled { message }),
            (_, Some(code)) => Err(Ros2Error::Failed { code, message }),
            (GoalStatus::Aborted, None) => Err(Ros2Error::Aborted { message }),
            (GoalStatus::Other(status), None) => Err(Ros2Error::Ended { status, message }),
        };
        // The goal is over: nothing to cancel.
        self.phase = Phase::Ended(outcome);
        Command::Wait
    }

    /// The time is `now`: ends the execution on a timeout.
    pub fn tick(&mut self, now: f64) -> Command {
        let waited = |since: f64| Duration::from_secs_f64((now - since).max(0.0));
        match self.phase {
            Phase::WaitingForState if now > secs(self.cfg.first_state) => {
                self.end(Err(Ros2Error::NoJointStates {
                    waited: waited(0.0),
                }))
            }
            Phase::Sent(at) if now - at > secs(self.cfg.goal_response) => {
                self.end(Err(Ros2Error::NoGoalResponse { waited: waited(at) }))
            }
            Phase::Executing(_) if now - self.last_state > secs(self.cfg.state_silence) => self
                .end(Err(Ros2Error::StatesLost {
                    silent: waited(self.last_state),
                })),
            Phase::Executing(since)
                if now - since > self.goal_path().duration() + secs(self.cfg.result_margin) =>
            {
                let end = since + self.goal_path().duration();
                self.end(Err(Ros2Error::NoResult {
                    waited: waited(end),
                }))
            }
            _ => Command::Wait,
        }
    }
}

/// Time between an approach's samples, s.
const APPROACH_STEP: f64 = 0.02;

/// `path` after a minimum-jerk approach from `q` at `speed` of the
/// velocity limits, checked as one trajectory.
fn approach(path: &JointPath, q: &[f64], speed: f64) -> Result<JointPath, String> {
    let chain = path.chain();
    let start = path.start();
    let limits: Vec<f64> = chain.joints().iter().map(|j| j.limits.velocity).collect();
    let duration = min_jerk_duration(q, start, speed, &limits);
    if !duration.is_finite() {
        return Err(format!("no approach at {speed} of the velocity limits"));
    }
    let steps = (duration / APPROACH_STEP).ceil().max(1.0) as usize;
    let t0 = path.times().first().copied().unwrap_or(0.0);
    let mut times = Vec::with_capacity(steps + path.times().len());
    let mut positions = Vec::with_capacity(times.capacity() * chain.dof());
    // The approach's samples before the start, then the path's, shifted.
    for k in 0..steps {
        let s = k as f64 / steps as f64;
        times.push(duration * s);
        let blend = min_jerk(s);
        positions.extend(q.iter().zip(start).map(|(a, b)| a + (b - a) * blend));
    }
    times.extend(path.times().iter().map(|t| t - t0 + duration));
    positions.extend_from_slice(path.positions());
    check_path(chain, times, positions, None).map_err(|e| e.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;
    use primo_robot::{Robot, safety::check_joints};

    fn path() -> JointPath {
        check_joints(
            &Robot::lwr4(),
            vec![0.0, 0.5, 1.0],
            vec![[0.1; 7], [0.15; 7], [0.2; 7]],
        )
        .unwrap()
    }

    /// The LWR 4's joints, in the order given by `order` (1-based).
    fn state(order: &[usize], q: &[f64], stamp: f64) -> JointState {
        JointState {
            header: crate::msgs::Header {
                stamp: Stamp::from_seconds(stamp),
                frame_id: String::new(),
            },
            name: order.iter().map(|i| format!("a{i}")).collect(),
            position: q.to_vec(),
            ..Default::default()
        }
    }

    const ORDER: [usize; 7] = [1, 2, 3, 4, 5, 6, 7];

    /// 0.5 s of silence.
    fn config() -> ExecutionConfig {
        ExecutionConfig {
            state_silence: Duration::from_millis(500),
            ..ExecutionConfig::default()
        }
    }

    /// An execution whose goal was sent and accepted at 0.1 s.
    fn running() -> Execution {
        let mut run = Execution::new(&path(), config());
        assert!(matches!(
            run.joint_state(0.0, &state(&ORDER, &[0.1; 7], 1.0)),
            Command::SendGoal(_)
        ));
        assert_eq!(run.goal_response(0.1, true), Command::Wait);
        run
    }

    #[test]
    fn the_goal_names_the_chain_joints_and_times_from_the_start() {
        let g = Execution::new(&path(), ExecutionConfig::default()).goal();
        assert_eq!(
            g.trajectory.joint_names,
            ["a1", "a2", "a3", "a4", "a5", "a6", "a7"]
        );
        assert_eq!(g.trajectory.points.len(), 3);
        assert_eq!(
            g.trajectory.points[1].time_from_start,
            Stamp {
                sec: 0,
                nanosec: 500_000_000
            }
        );
        assert_eq!(g.trajectory.points[2].positions, vec![0.2; 7]);
        assert!(g.trajectory.header.stamp.is_zero());
    }

    #[test]
    fn states_are_mapped_by_name_and_recorded_in_the_chain_order() {
        let mut run = Execution::new(&path(), ExecutionConfig::default());
        // Reversed, with an extra joint (a gripper's) first.
        let mut s = state(&[7, 6, 5, 4, 3, 2, 1], &[0.1; 7], 1.0);
        s.name.insert(0, "gripper".into());
        s.position.insert(0, 5.0);
        assert!(matches!(run.joint_state(0.0, &s), Command::SendGoal(_)));
        run.goal_response(0.1, true);
        let q = [0.0, 0.17, 0.16, 0.15, 0.14, 0.13, 0.12, 0.11];
        let mut s = state(&[7, 6, 5, 4, 3, 2, 1], &q[1..], 1.5);
        s.name.insert(0, "gripper".into());
        s.position.insert(0, 5.0);
        run.joint_state(0.6, &s);
        run.feedback(&Feedback {
            error: JointTrajectoryPoint {
                positions: vec![0.0, -0.03, 0.01],
                ..Default::default()
            },
            ..Default::default()
        });
        run.result(1.2, GoalStatus::Succeeded, &FjtResult::default());
        assert_eq!(run.outcome(), Some(&Ok(())));
        assert_eq!(run.executed().times, [0.5]);
        assert_eq!(
            run.executed().positions,
            [0.11, 0.12, 0.13, 0.14, 0.15, 0.16, 0.17]
        );
        assert_eq!(run.feedback_count(), 1);
        assert_eq!(run.max_feedback_error(), 0.03);
    }

    #[test]
    fn a_robot_off_the_start_gets_no_goal() {
        let mut run = Execution::new(&path(), ExecutionConfig::default());
        let mut q = [0.1; 7];
        q[2] = 0.13;
        q[4] = 0.05;
        assert_eq!(run.joint_state(0.0, &state(&ORDER, &q, 1.0)), Command::Wait);
        let Some(Err(e)) = run.outcome() else {
            panic!("{:?}", run.phase())
        };
        assert_eq!(
            e.to_string(),
            "the robot is not at the trajectory's start: joint `a5` is at 0.0500, the start is \
             0.1000 (0.0500 away, more than the tolerance 0.01): nothing sent to the robot"
        );
    }

    #[test]
    fn an_approach_moves_a_robot_off_the_start_there_within_the_limits() {
        let cfg = ExecutionConfig {
            approach_speed: Some(0.2),
            ..ExecutionConfig::default()
        };
        let mut run = Execution::new(&path(), cfg);
        let Command::SendGoal(goal) = run.joint_state(0.0, &state(&ORDER, &[0.0; 7], 1.0)) else {
            panic!("{:?}", run.phase())
        };
        let points = &goal.trajectory.points;
        assert_eq!(points[0].positions, vec![0.0; 7]);
        // 0.1 rad at 20 % of the slowest joint's 1.9199 rad/s (a2):
        // 1.875 · 0.1 / 0.384 = 0.488 s, then the path's 1 s.
        let approach = 1.875 * 0.1 / (0.2 * 110f64.to_radians());
        let end = points.last().unwrap().time_from_start.seconds();
        assert!((end - approach - 1.0).abs() < 1e-6, "{end}");
        assert_eq!(points.last().unwrap().positions, vec![0.2; 7]);
        assert!(points.len() > 3 + 3);
        assert!((run.goal_path().duration() - end).abs() < 1e-8);
        // From beyond a limit, none.
        let mut run = Execution::new(&path(), cfg);
        let mut q = [0.0; 7];
        q[0] = 3.0;
        assert_eq!(run.joint_state(0.0, &state(&ORDER, &q, 1.0)), Command::Wait);
        let Some(Err(e)) = run.outcome() else {
            panic!("{:?}", run.phase())
        };
        assert!(
            e.to_string().starts_with(
                "the approach from where the robot is to the trajectory's start would cross a \
                 limit: joint a1 at sample 0"
            ),
            "{e}"
        );
    }

    #[test]
    fn a_missing_joint_is_named() {
        let mut run = Execution::new(&path(), ExecutionConfig::default());
        run.joint_state(0.0, &state(&[1, 2, 3], &[0.1; 3], 1.0));
        assert_eq!(
            run.outcome().cloned(),
            Some(Err(Ros2Error::MissingJoint {
                joint: "a4".into(),
                named: "a1, a2, a3".into()
            }))
        );
    }

    #[test]
    fn no_joint_states_no_goal() {
        let mut run = Execution::new(&path(), ExecutionConfig::default());
        assert_eq!(run.tick(4.0), Command::Wait);
        assert_eq!(run.outcome(), None);
        assert_eq!(run.tick(5.5), Command::Wait);
        assert!(matches!(
            run.outcome(),
            Some(Err(Ros2Error::NoJointStates { .. }))
        ));
    }

    #[test]
    fn rejection_and_no_answer() {
        let mut run = Execution::new(&path(), ExecutionConfig::default());
        run.joint_state(0.0, &state(&ORDER, &[0.1; 7], 1.0));
        assert_eq!(run.goal_response(0.1, false), Command::Wait);
        assert_eq!(run.outcome(), Some(&Err(Ros2Error::Rejected)));
        let mut run = Execution::new(&path(), ExecutionConfig::default());
        run.joint_state(0.0, &state(&ORDER, &[0.1; 7], 1.0));
        assert_eq!(run.tick(6.0), Command::Cancel);
        assert!(matches!(
            run.outcome(),
            Some(Err(Ros2Error::NoGoalResponse { .. }))
        ));
    }

    #[test]
    fn results_map_to_outcomes() {
        let end = |status, code: i32, text: &str| {
            let mut run = running();
            let r = FjtResult {
                error_code: code,
                error_string: text.into(),
            };
            assert_eq!(run.result(1.0, status, &r), Command::Wait);
            run.outcome().cloned()
        };
        assert_eq!(end(GoalStatus::Succeeded, 0, ""), Some(Ok(())));
        assert_eq!(
            end(GoalStatus::Aborted, -4, "a3 off"),
            Some(Err(Ros2Error::Failed {
                code: ErrorCode::PathToleranceViolated,
                message: "a3 off".into()
            }))
        );
        assert_eq!(
            end(GoalStatus::Succeeded, -5, ""),
            Some(Err(Ros2Error::Failed {
                code: ErrorCode::GoalToleranceViolated,
                message: String::new()
            }))
        );
        assert_eq!(
            end(GoalStatus::Aborted, 0, ""),
            Some(Err(Ros2Error::Aborted {
                message: String::new()
            }))
        );
        assert_eq!(
            end(GoalStatus::Canceled, 0, "stop"),
            Some(Err(Ros2Error::Canceled {
                message: "stop".into()
            }))
        );
        assert_eq!(
            end(GoalStatus::Other(2), 0, ""),
            Some(Err(Ros2Error::Ended {
                status: 2,
                message: String::new()
            }))
        );
        for (code, typed) in [
            (-1, ErrorCode::InvalidGoal),
            (-2, ErrorCode::InvalidJoints),
            (-3, ErrorCode::OldHeaderTimestamp),
        ] {
            assert!(matches!(
                end(GoalStatus::Aborted, code, ""),
                Some(Err(Ros2Error::Failed { code, .. })) if code == typed
            ));
        }
    }

    #[test]
    fn silent_backward_or_stale_states_cancel_the_goal() {
        let mut run = running();
        assert_eq!(run.tick(0.5), Command::Wait);
        assert_eq!(run.tick(0.7), Command::Cancel);
        assert!(matches!(
            run.outcome(),
            Some(Err(Ros2Error::StatesLost { .. }))
        ));

        let mut run = running();
        run.joint_state(0.2, &state(&ORDER, &[0.1; 7], 1.2));
        assert_eq!(
            run.joint_state(0.3, &state(&ORDER, &[0.1; 7], 1.1)),
            Command::Cancel
        );
        assert!(matches!(
            run.outcome(),
            Some(Err(Ros2Error::NonMonotonic { .. }))
        ));

        let mut run = running();
        for k in 0..6 {
            let now = 0.2 + 0.1 * f64::from(k);
            assert_eq!(
                run.joint_state(now, &state(&ORDER, &[0.1; 7], 1.2)),
                Command::Wait
            );
        }
        assert_eq!(
            run.joint_state(0.8, &state(&ORDER, &[0.1; 7], 1.2)),
            Command::Cancel
        );
        let Some(Err(e)) = run.outcome() else {
            panic!("{:?}", run.phase())
        };
        assert!(
            e.to_string()
                .starts_with("the joint states repeated the stamp 1.200000 s")
        );
        // Unstamped states are not compared.
        let mut run = running();
        for k in 0..10 {
            let now = 0.2 + 0.1 * f64::from(k);
            assert_eq!(
                run.joint_state(now, &state(&ORDER, &[0.1; 7], 0.0)),
                Command::Wait
            );
        }
    }

    #[test]
    fn no_result_long_after_the_end_cancels() {
        let mut run = running();
        for k in 0..=110 {
            let now = 0.1 + 0.1 * f64::from(k);
            run.joint_state(now, &state(&ORDER, &[0.2; 7], 1.0 + now));
            assert_eq!(run.tick(now), Command::Wait, "{now}");
        }
        run.joint_state(11.2, &state(&ORDER, &[0.2; 7], 12.2));
        assert_eq!(run.tick(11.2), Command::Cancel);
        assert!(matches!(
            run.outcome(),
            Some(Err(Ros2Error::NoResult { .. }))
        ));
    }
}
