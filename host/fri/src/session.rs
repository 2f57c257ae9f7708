//! primo's side of FRI, sans I/O: a [`Session`] takes one measurement in
//! and gives exactly one command out ([`crate::udp::play`] is the UDP loop
//! around it).
//!
//! The session streams a [`FriPath`], a seven-joint
//! [`primo_robot::JointPath`] (so only trajectories that passed
//! [`primo_robot::safety`] can reach the robot, within its limits):
//!
//! 1. In monitor mode, or before the robot is powered and in command mode
//!    with quality ≥ OK, it echoes `cmdJntPos + cmdJntPosFriOffset`: the
//!    robot stays where it is commanded.
//! 2. At the first commandable cycle it holds the measured position for a
//!    while (`weigh`), averaging the force the robot holds
//!    (`estExtTcpFT`); then a minimum-jerk approach at a bounded fraction
//!    of the velocity limits brings the robot to the trajectory's start.
//! 3. The trajectory, resampled at the FRI cycle (`desiredCmdSampleTime`),
//!    one setpoint per cycle in which the robot reports the previous one as
//!    commanded (`cmdJntPos + cmdJntPosFriOffset`): a lost measurement or a
//!    lost or late answer delays the rest by a cycle instead of making the
//!    robot jump two steps.
//! 4. It holds the last setpoint for a settling time, averaging the held
//!    force again, then is done.
//!
//! The two averages ([`Session::held_load`]) weigh what the robot holds
//! before and after the movement: with a bottle, the drop is the liquid
//! that left it.
//!
//! It stops for good, holding the last setpoint (or echoing once the robot
//! is back in monitor mode or unpowered), when the quality drops below OK, the robot
//! leaves command mode or loses power, does not take the setpoints for a
//! quarter of a second, or the next setpoint would cross a joint position
//! or velocity limit of the path's robot.
//!
//! ```
//! use primo_fri::session::{Phase, Session, SessionConfig};
//! use primo_fri::packet::{Measurement, Quality, State};
//! use primo_robot::{Robot, safety::check_joints};
//! let path = check_joints(&Robot::lwr4(), vec![0.0, 1.0], vec![[0.1; 7], [0.2; 7]]).unwrap();
//! let path = primo_fri::path::FriPath::try_from(&path).unwrap();
//! let mut session = Session::new(&path, SessionConfig::default());
//! let mut m = Measurement::default();
//! m.intf.desired_cmd_sample_time = 0.002;
//! m.robot.power = 0x7f;
//! m.intf.state = State::Monitor;
//! m.data.cmd_jnt_pos = [0.5; 7];
//! let c = session.answer(&m);
//! assert_eq!(c.cmd.jnt_pos, [0.5; 7]); // monitor mode: echo
//! m.intf.state = State::Command;
//! m.intf.quality = Quality::Perfect;
//! m.head.send_seq_count = 1;
//! let c = session.answer(&m);
//! assert_eq!(c.head.refl_seq_count, 1);
//! assert_eq!(c.cmd.jnt_pos, m.data.msr_jnt_pos); // first setpoint: where it is
//! assert_eq!(session.phase(), &Phase::Streaming);
//! ```

use std::fmt;

use primo_robot::JOINTS;
use primo_robot::limits::{min_jerk, min_jerk_duration};

use crate::packet::{Command, Measurement, Quality, State};
use crate::path::FriPath;

/// Shortest and longest FRI cycle the session accepts, s.
pub const CYCLE_RANGE: [f64; 2] = [0.0005, 0.1];

/// How far the robot's commanded position (`cmdJntPos +
/// cmdJntPosFriOffset`, two f32 summed) may be from the last setpoint for
/// it to count as taken, rad.
const TAKEN_TOLERANCE: f64 = 1e-5;
/// How long the robot may go on not taking the setpoints before the
/// session stops (at least 10 cycles), s.
const UNACKNOWLEDGED_TIME: f64 = 0.25;

/// Fewest measurements a standstill's mean force
/// ([`Session::held_load`]) is taken from.
pub const MIN_HELD_SAMPLES: usize = 10;

/// How the session moves.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionConfig {
    /// Peak speed of the approach to the trajectory's start, as a fraction
    /// of each joint's velocity limit.
    pub approach_speed: f64,
    /// How long to hold the measured position in command mode before the
    /// approach, weighing what the robot holds, s.
    pub weigh: f64,
    /// How long to hold the final setpoint after the trajectory (weighing
    /// again), s.
    pub settle: f64,
}

impl Default for SessionConfig {
    /// Approach at up to 20 % of the velocity limits; weigh 0.3 s before
    /// it; settle 0.3 s.
    fn default() -> Self {
        SessionConfig {
            approach_speed: 0.2,
            weigh: 0.3,
            settle: 0.3,
        }
    }
}

/// The sum of the forces measured during a standstill.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
struct HeldForce {
    sum: [f64; 3],
    samples: usize,
}

impl HeldForce {
    fn add(&mut self, m: &Measurement) {
        for (s, f) in self.sum.iter_mut().zip(m.data.est_ext_tcp_ft) {
            *s += f64::from(f);
        }
        self.samples += 1;
    }

    /// |mean force|, N.
    fn magnitude(&self) -> f64 {
        self.sum.iter().map(|s| s * s).sum::<f64>().sqrt() / self.samples as f64
    }
}

/// Why the session stopped before the end.
#[derive(Debug, Clone, PartialEq)]
pub enum Stop {
    /// The communication quality fell below OK.
    Quality(Quality),
    /// The robot left command mode.
    LeftCommandMode(State),
    /// A drive lost power (the `power` bits).
    Unpowered(u16),
    /// The next setpoint would cross a joint limit.
    Limit(String),
    /// `desiredCmdSampleTime` outside [`CYCLE_RANGE`].
    SampleTime(f32),
    /// The robot's commanded position stayed off the last setpoint for
    /// this many cycles.
    NotFollowing(usize),
}

impl fmt::Display for Stop {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Stop::Quality(q) => write!(f, "the communication quality dropped to {q:?}"),
            Stop::LeftCommandMode(s) => write!(f, "the robot left command mode (now {s:?})"),
            Stop::Unpowered(p) => write!(f, "drives lost power (power bits {p:#04x})"),
            Stop::Limit(why) => write!(f, "the next setpoint would cross a limit: {why}"),
            Stop::NotFollowing(n) => write!(
                f,
                "the robot did not take the commanded position for {n} cycles"
            ),
            Stop::SampleTime(t) => write!(
                f,
                "desiredCmdSampleTime {t} s is outside [{}, {}] s",
                CYCLE_RANGE[0], CYCLE_RANGE[1]
            ),
        }
    }
}

/// Where the session is.
#[derive(Debug, Clone, PartialEq)]
pub enum Phase {
    /// Echoing, waiting for command mode with quality ≥ OK and power.
    Waiting,
    /// Streaming setpoints (approach, trajectory, settling).
    Streaming,
    /// Every setpoint sent and settled; holding the last.
    Done,
    /// Stopped early; holding (see [`Stop`]).
    Stopped {
        /// Why.
        why: Stop,
        /// Setpoints sent before the stop.
        at: usize,
    },
}

/// Measured minus commanded joint positions while streaming, rad.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct Tracking {
    /// Largest |error| per joint.
    pub max: [f64; JOINTS],
    /// Root mean square per joint.
    pub rms: [f64; JOINTS],
    /// Measurements compared.
    pub samples: usize,
    /// The last measured minus the last commanded position.
    pub last: [f64; JOINTS],
}

/// The remote side of one FRI trajectory run, sans I/O.
#[derive(Debug, Clone)]
pub struct Session {
    cfg: SessionConfig,
    path: FriPath,
    phase: Phase,
    seq: u16,
    setpoints: Vec<[f64; JOINTS]>,
    weighing: usize,
    approach: usize,
    next: usize,
    dt: f64,
    last: Option<[f64; JOINTS]>,
    settle_cycles: usize,
    unacknowledged: usize,
    sum_sq: [f64; JOINTS],
    tracking: Tracking,
    /// Before the approach, after the trajectory.
    held: [HeldForce; 2],
}

impl Session {
    /// A session that will stream `path`.
    pub fn new(path: &FriPath, cfg: SessionConfig) -> Self {
        Session {
            cfg,
            path: path.clone(),
            phase: Phase::Waiting,
            seq: 0,
            setpoints: Vec::new(),
            weighing: 0,
            approach: 0,
            next: 0,
            dt: 0.0,
            last: None,
            settle_cycles: 0,
            unacknowledged: 0,
            sum_sq: [0.0; JOINTS],
            tracking: Tracking::default(),
            held: [HeldForce::default(); 2],
        }
    }

    /// Where the session is.
    pub fn phase(&self) -> &Phase {
        &self.phase
    }

    /// The tracking error so far.
    pub fn tracking(&self) -> Tracking {
        self.tracking
    }

    /// Setpoints planned (holding to weigh, approach and trajectory; 0
    /// before streaming).
    pub fn planned(&self) -> usize {
        self.setpoints.len()
    }

    /// Setpoints holding the measured position to weigh before the
    /// approach (0 before streaming).
    pub fn weigh_len(&self) -> usize {
        self.weighing
    }

    /// Setpoints of the approach (0 before streaming).
    pub fn approach_len(&self) -> usize {
        self.approach
    }

    /// Setpoints sent so far.
    pub fn sent(&self) -> usize {
        self.next
    }

    /// The FRI cycle the setpoints were planned for, s (0 before streaming).
    pub fn cycle(&self) -> f64 {
        self.dt
    }

    /// The load the robot held standing still before the approach and
    /// while settling after the trajectory, N, from the estimated external
    /// force at the TCP (`estExtTcpFT`); once each standstill had at least
    /// [`MIN_HELD_SAMPLES`] measurements.
    ///
    /// Each is the magnitude of the mean force vector: the TCP frame does
    /// not turn during a standstill, and averaging the vector first keeps
    /// the noise out of the magnitude (the mean of the magnitudes would be
    /// biased up by about σ²/|F|).
    pub fn held_load(&self) -> Option<[f64; 2]> {
        let [before, after] = self.held;
        (before.samples >= MIN_HELD_SAMPLES && after.samples >= MIN_HELD_SAMPLES)
            .then(|| [before.magnitude(), after.magnitude()])
    }

    /// Measurements averaged into [`Session::held_load`] so far: before,
    /// after.
    pub fn held_samples(&self) -> [usize; 2] {
        self.held.map(|h| h.samples)
    }

    /// Done or stopped: no more setpoints will move the robot.
    pub fn is_finished(&self) -> bool {
        matches!(self.phase, Phase::Done | Phase::Stopped { .. })
    }

    /// The one answer to `m`: `reflSeqCount` is its `sendSeqCount`.
    pub fn answer(&mut self, m: &Measurement) -> Command {
        let seq = self.seq;
        self.seq = seq.wrapping_add(1);
        let q = self.setpoint(m);
        Command::joint_position(seq, m, &q)
    }

    /// Why `m` does not allow commanding motion, if it does not.
    fn not_commandable(m: &Measurement) -> Option<Stop> {
        if m.intf.state != State::Command {
            Some(Stop::LeftCommandMode(m.intf.state))
        } else if !m.robot.powered() {
            Some(Stop::Unpowered(m.robot.power))
        } else if m.intf.quality < Quality::Ok {
            Some(Stop::Quality(m.intf.quality))
        } else {
            None
        }
    }

    /// The position to command in answer to `m`.
    fn setpoint(&mut self, m: &Measurement) -> [f64; JOINTS] {
        // Monitor mode or unpowered: echo; in command mode: the last setpoint.
        let hold = |last: Option<[f64; JOINTS]>| match last {
            Some(q) if m.intf.state == State::Command && m.robot.powered() => q,
            _ => m.commanded(),
        };
        match self.phase {
            Phase::Done | Phase::Stopped { .. } => hold(self.last),
            Phase::Waiting => {
                if Self::not_commandable(m).is_some() {
                    return m.commanded();
                }
                // An f32 on the wire: 0.002 arrives as 0.0020000000949949.
                let dt = (f64::from(m.intf.desired_cmd_sample_time) * 1e6).round() / 1e6;
                if !(CYCLE_RANGE[0]..=CYCLE_RANGE[1]).contains(&dt) {
                    self.stop(Stop::SampleTime(m.intf.desired_cmd_sample_time));
                    return m.commanded();
                }
                self.start(m.measured(), dt);
                self.advance(m)
            }
            Phase::Streaming => {
                self.track(m);
                if let Some(why) = Self::not_commandable(m) {
                    self.stop(why);
                    return hold(self.last);
                }
                self.advance(m)
            }
        }
    }

    /// Plans the standstill at `measured`, the approach from there and the
    /// resampled trajectory.
    fn start(&mut self, measured: [f64; JOINTS], dt: f64) {
        self.dt = dt;
        // A negative or NaN time saturates to no standstill.
        self.weighing = (self.cfg.weigh / dt).ceil() as usize;
        let approach = approach(
            measured,
            self.path.start(),
            dt,
            self.cfg.approach_speed,
            self.path.velocity_limits(),
        );
        self.approach = approach.len();
        let trajectory = resample(&self.path, dt);
        // One allocation, filled in place: this runs inside a cycle.
        let mut setpoints = Vec::with_capacity(self.weighing + self.approach + trajectory.len());
        setpoints.resize(self.weighing, measured);
        setpoints.extend(approach);
        setpoints.extend(trajectory.skip(1));
        self.setpoints = setpoints;
        self.phase = Phase::Streaming;
    }

    /// The next setpoint, checked against the limits, once the robot
    /// reports the last one as commanded; after the last setpoint, holds it
    /// for the settling time.
    fn advance(&mut self, m: &Measurement) -> [f64; JOINTS] {
        if self.next <= self.weighing {
            // Every setpoint so far held the robot where it stood.
            self.held[0].add(m);
        }
        if let Some(last) = self.last {
            // A lost or late answer: send it again rather than the next,
            // which would be two steps away from what the robot follows.
            let taken = m.commanded();
            if (0..JOINTS).any(|j| (taken[j] - last[j]).abs() > TAKEN_TOLERANCE) {
                self.unacknowledged += 1;
                let patience = (UNACKNOWLEDGED_TIME / self.dt).ceil().max(10.0) as usize;
                if self.unacknowledged >= patience {
                    self.stop(Stop::NotFollowing(self.unacknowledged));
                }
                return last;
            }
        }
        self.unacknowledged = 0;
        let Some(&next) = self.setpoints.get(self.next) else {
            let last = self.last.unwrap_or_else(|| m.commanded());
            self.held[1].add(m);
            self.settle_cycles += 1;
            if self.settle_cycles as f64 * self.dt >= self.cfg.settle {
                self.phase = Phase::Done;
            }
            return last;
        };
        let chain = self.path.path().chain();
        let step = match self.last {
            Some(last) => chain.check_samples([(0.0, &last[..]), (self.dt, &next[..])]),
            None => chain.check_samples([(0.0, &next[..])]),
        };
        if let Err(v) = step {
            let why = format!("setpoint {}: {v}", self.next);
            self.stop(Stop::Limit(why));
            return self.last.unwrap_or_else(|| m.commanded());
        }
        self.next += 1;
        self.last = Some(next);
        next
    }

    fn stop(&mut self, why: Stop) {
        self.phase = Phase::Stopped { why, at: self.next };
    }

    /// Compares the measured position with the setpoint in force.
    fn track(&mut self, m: &Measurement) {
        let Some(commanded) = self.last else {
            return;
        };
        let t = &mut self.tracking;
        t.samples += 1;
        let measured = m.measured();
        t.last = std::array::from_fn(|j| measured[j] - commanded[j]);
        for (j, e) in t.last.iter().enumerate() {
            t.max[j] = t.max[j].max(e.abs());
            self.sum_sq[j] += e * e;
            t.rms[j] = (self.sum_sq[j] / t.samples as f64).sqrt();
        }
    }
}

/// Minimum-jerk setpoints every `dt` from `from` (the first) to `to` (the
/// last), with each joint's peak speed at most `speed` times its limit
/// (`limits`, rad/s).
fn approach(
    from: [f64; JOINTS],
    to: [f64; JOINTS],
    dt: f64,
    speed: f64,
    limits: &[f64; JOINTS],
) -> impl ExactSizeIterator<Item = [f64; JOINTS]> {
    let duration = min_jerk_duration(&from, &to, speed, limits);
    let steps = (duration / dt).ceil().max(1.0) as usize;
    (0..steps + 1).map(move |k| {
        let blend = min_jerk(k as f64 / steps as f64);
        std::array::from_fn(|j| from[j] + (to[j] - from[j]) * blend)
    })
}

/// The path linearly interpolated every `dt` from its first sample, ending
/// exactly on its last.
fn resample(path: &FriPath, dt: f64) -> impl ExactSizeIterator<Item = [f64; JOINTS]> {
    let (times, q) = (path.path().times(), path.rows());
    let t0 = times.first().copied().unwrap_or(0.0);
    // A checked path has a sample at least.
    let last = q.last().copied().unwrap_or([0.0; JOINTS]);
    // Grid points strictly before the end (to rounding), then the end.
    let steps = (path.path().duration() / dt - 1e-9).ceil().max(0.0) as usize;
    let mut i = 0;
    (0..steps + 1).map(move |n| {
        let t = t0 + n as f64 * dt;
        while times.get(i + 1).is_some_and(|&next| next <= t) {
            i += 1;
        }
        match (
            n < steps,
            times.get(i),
            times.get(i + 1),
            q.get(i),
            q.get(i + 1),
        ) {
            (true, Some(&ta), Some(&tb), Some(a), Some(b)) => {
                let s = (t - ta) / (tb - ta);
                std::array::from_fn(|j| a[j] + (b[j] - a[j]) * s)
            }
            (true, _, _, Some(a), _) => *a,
            _ => last,
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::packet::{COMMAND_ID, flags};
    use primo_robot::Robot;

    fn check_joints(t: Vec<f64>, q: Vec<[f64; JOINTS]>) -> Result<FriPath, String> {
        let path =
            primo_robot::safety::check_joints(&Robot::lwr4(), t, q).map_err(|e| e.to_string())?;
        FriPath::try_from(&path).map_err(|e| e.to_string())
    }

    fn measurement(state: State, quality: Quality, q: [f32; JOINTS]) -> Measurement {
        let mut m = Measurement::default();
        m.intf.state = state;
        m.intf.quality = quality;
        m.intf.desired_cmd_sample_time = 0.01;
        m.robot.power = 0x7f;
        m.data.msr_jnt_pos = q;
        m.data.cmd_jnt_pos = q;
        m
    }

    fn path() -> FriPath {
        // 0.2 rad on joint 1 in 1 s, then back in 1 s.
        let t = vec![0.0, 1.0, 2.0];
        let mut a = [0.0; JOINTS];
        a[0] = 0.2;
        check_joints(t, vec![[0.0; JOINTS], a, [0.0; JOINTS]]).unwrap()
    }

    #[test]
    fn echoes_in_monitor_mode_and_reflects_the_sequence() {
        let mut s = Session::new(&path(), SessionConfig::default());
        for (i, state) in [State::Off, State::Monitor, State::Monitor]
            .into_iter()
            .enumerate()
        {
            let mut m = measurement(state, Quality::Perfect, [0.3; JOINTS]);
            m.head.send_seq_count = 100 + i as u16;
            m.data.cmd_jnt_pos_fri_offset[2] = 0.5;
            let c = s.answer(&m);
            assert_eq!(c.head.refl_seq_count, 100 + i as u16);
            assert_eq!(c.head.send_seq_count, i as u16);
            assert_eq!(c.head.datagram_id, COMMAND_ID);
            assert_eq!(c.cmd.cmd_flags, flags::JNTPOS);
            assert_eq!(c.cmd.jnt_pos[2], 0.8);
            assert_eq!(c.cmd.jnt_pos[0], 0.3);
        }
        // Command mode but quality BAD, or unpowered: still echo.
        let m = measurement(State::Command, Quality::Bad, [0.3; JOINTS]);
        assert_eq!(s.answer(&m).cmd.jnt_pos, [0.3; JOINTS]);
        let mut m = measurement(State::Command, Quality::Perfect, [0.3; JOINTS]);
        m.robot.power = 0x3f;
        assert_eq!(s.answer(&m).cmd.jnt_pos, [0.3; JOINTS]);
        assert_eq!(s.phase(), &Phase::Waiting);
    }

    /// Runs a session against an ideal robot (measured = last command).
    fn run(s: &mut Session, start: [f32; JOINTS], cycles: usize) -> Vec<[f32; JOINTS]> {
        let mut q = start;
        let mut sent = Vec::new();
        for _ in 0..cycles {
            let m = measurement(State::Command, Quality::Ok, q);
            q = s.answer(&m).cmd.jnt_pos;
            sent.push(q);
        }
        sent
    }

    #[test]
    fn weighs_approaches_then_streams_the_resampled_trajectory_then_settles() {
        let mut s = Session::new(&path(), SessionConfig::default());
        let start = [0.1, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let sent = run(&mut s, start, 1000);
        // Holding still for 0.3 s (30 cycles of 10 ms) where it stood, then
        // the approach from there.
        let weigh = s.weigh_len();
        assert_eq!(weigh, 30);
        assert!(
            sent[..=weigh].iter().all(|q| *q == start),
            "the first setpoints are the measured position"
        );
        // Approach: 0.1 rad on joint 1 at ≤ 20 % of 110 °/s.
        let approach = s.approach_len();
        let expected = (1.875 * 0.1 / (0.2 * 110f64.to_radians()) / 0.01).ceil() as usize + 1;
        assert_eq!(approach, expected);
        let speeds: Vec<f64> = sent
            .windows(2)
            .map(|w| f64::from(w[1][0] - w[0][0]).abs() / 0.01)
            .collect();
        assert!(
            speeds[..weigh + approach - 1]
                .iter()
                .all(|v| *v <= 0.2 * 110f64.to_radians() + 1e-6)
        );
        let at_start = weigh + approach - 1;
        assert_eq!(sent[at_start], [0.0; JOINTS]);
        // Then the trajectory at 10 ms: 0.2 rad/s up, 0.2 rad/s down.
        assert_eq!(s.planned(), weigh + approach + 200);
        assert!((sent[at_start + 100][0] - 0.2).abs() < 1e-6);
        assert!((sent[at_start + 50][0] - 0.1).abs() < 1e-6);
        assert_eq!(sent[at_start + 200], [0.0; JOINTS]);
        // Settling: holds the end for 0.3 s (30 cycles), then done.
        assert_eq!(s.phase(), &Phase::Done);
        assert!(sent[at_start + 200..].iter().all(|q| *q == [0.0; JOINTS]));
        // The ideal robot is always where it was commanded (to f32).
        let t = s.tracking();
        assert!(t.samples > 200);
        assert!(t.max.iter().all(|e| *e < 1e-7), "{t:?}");
    }

    #[test]
    fn lost_answers_are_sent_again_never_skipped() {
        let mut s = Session::new(&path(), SessionConfig::default());
        // A robot that loses every third answer: it keeps what it had.
        let mut taken = [0.0f32; JOINTS];
        let mut accepted = vec![taken];
        for cycle in 0..1000 {
            let c = s.answer(&measurement(State::Command, Quality::Ok, taken));
            if cycle % 3 != 2 {
                taken = c.cmd.jnt_pos;
                if accepted.last() != Some(&taken) {
                    accepted.push(taken);
                }
            }
        }
        assert_eq!(s.phase(), &Phase::Done);
        // Every setpoint reached the robot, in order, one step at a time.
        let planned = s.planned();
        let mut ideal = Session::new(&path(), SessionConfig::default());
        let mut every = run(&mut ideal, [0.0; JOINTS], 1000);
        every.dedup();
        assert_eq!(accepted, every);
        // The holds and the approach's first setpoint are one position.
        let distinct = planned - s.weigh_len();
        assert!(
            accepted.len() >= distinct - 1,
            "{} of {distinct}",
            accepted.len()
        );
        // A robot that never takes a command: stop after 0.25 s.
        let mut s = Session::new(&path(), SessionConfig::default());
        let mut m = measurement(State::Command, Quality::Ok, [0.1; JOINTS]);
        s.answer(&m);
        m.data.msr_jnt_pos = [0.0; JOINTS];
        m.data.cmd_jnt_pos = [0.0; JOINTS];
        for _ in 0..25 {
            s.answer(&m);
        }
        assert_eq!(
            s.phase(),
            &Phase::Stopped {
                why: Stop::NotFollowing(25),
                at: 1
            }
        );
    }

    /// A measurement that holds `newtons` along x at the TCP.
    fn holding(q: [f32; JOINTS], newtons: f32) -> Measurement {
        let mut m = measurement(State::Command, Quality::Ok, q);
        m.data.est_ext_tcp_ft = [newtons, 0.0, 0.0, 0.0, 0.0, 0.0];
        m
    }

    #[test]
    fn the_held_load_is_weighed_standing_still_before_and_after() {
        let cfg = SessionConfig {
            weigh: 0.2,
            ..SessionConfig::default()
        };
        let mut s = Session::new(&path(), cfg);
        // Waiting in monitor mode: not weighed.
        let mut m = holding([0.0; JOINTS], 99.0);
        m.intf.state = State::Monitor;
        s.answer(&m);
        // An ideal robot: 4.9 N while standing still before the approach,
        // 5 N while moving, 3 N once back (the bottle poured).
        let mut q = [0.1f32; JOINTS];
        let mut forces = Vec::new();
        while !s.is_finished() {
            let moving = s.sent() > s.weigh_len() && s.sent() < s.planned();
            let newtons = match (s.sent() <= s.weigh_len(), moving) {
                (true, _) => 4.9,
                (false, true) => 5.0,
                (false, false) => 3.0,
            };
            forces.push(newtons);
            q = s.answer(&holding(q, newtons)).cmd.jnt_pos;
        }
        assert_eq!(s.phase(), &Phase::Done);
        // 20 holds: 21 measurements standing still (the first included),
        // 30 settling (0.3 s).
        assert_eq!(s.weigh_len(), 20);
        assert_eq!(s.held_samples(), [21, 30]);
        let [before, after] = s.held_load().unwrap();
        assert!((before - 4.9).abs() < 1e-6 && (after - 3.0).abs() < 1e-6);
        // Noise along the force averages out of the magnitude: ±1 N across
        // it alternately leaves |mean| at 3 N, where the mean of the
        // magnitudes would say 3.16 N.
        let mut s = Session::new(&path(), cfg);
        let mut q = [0.1f32; JOINTS];
        for k in 0.. {
            if s.is_finished() {
                break;
            }
            let mut m = holding(q, 3.0);
            m.data.est_ext_tcp_ft[1] = if k % 2 == 0 { 1.0 } else { -1.0 };
            q = s.answer(&m).cmd.jnt_pos;
        }
        let load = s.held_load().unwrap();
        assert!(load.iter().all(|f| (f - 3.0).abs() < 0.1), "{load:?}");
    }

    #[test]
    fn a_short_standstill_weighs_nothing() {
        // No settling, no weighing: one measurement each is not a weight.
        let cfg = SessionConfig {
            weigh: 0.0,
            settle: 0.0,
            ..SessionConfig::default()
        };
        let mut s = Session::new(&path(), cfg);
        run(&mut s, [0.0; JOINTS], 1000);
        assert_eq!(s.phase(), &Phase::Done);
        assert_eq!(s.held_load(), None);
        // Stopped mid-trajectory: weighed before, never after.
        let mut s = Session::new(&path(), SessionConfig::default());
        let sent = run(&mut s, [0.0; JOINTS], 100);
        s.answer(&measurement(State::Command, Quality::Bad, sent[99]));
        for _ in 0..100 {
            s.answer(&measurement(State::Command, Quality::Ok, sent[99]));
        }
        assert!(matches!(s.phase(), Phase::Stopped { .. }));
        assert_eq!(s.held_load(), None);
    }

    #[test]
    fn quality_drop_holds_position_for_good() {
        let mut s = Session::new(&path(), SessionConfig::default());
        let sent = run(&mut s, [0.0; JOINTS], 60);
        let held = sent[59];
        assert!(held[0] > 0.0);
        let bad = measurement(State::Command, Quality::Bad, held);
        for _ in 0..5 {
            assert_eq!(s.answer(&bad).cmd.jnt_pos, held);
        }
        assert!(matches!(
            s.phase(),
            Phase::Stopped {
                why: Stop::Quality(Quality::Bad),
                ..
            }
        ));
        // Quality back: still holding, nothing moves.
        let good = measurement(State::Command, Quality::Perfect, held);
        assert_eq!(s.answer(&good).cmd.jnt_pos, held);
        // Back in monitor mode: echo.
        let mut mon = measurement(State::Monitor, Quality::Perfect, held);
        mon.data.cmd_jnt_pos = [0.7; JOINTS];
        assert_eq!(s.answer(&mon).cmd.jnt_pos, [0.7; JOINTS]);
    }

    #[test]
    fn leaving_command_mode_or_power_stops() {
        for (state, power) in [(State::Monitor, 0x7f), (State::Command, 0x7e)] {
            let mut s = Session::new(&path(), SessionConfig::default());
            let sent = run(&mut s, [0.0; JOINTS], 60);
            let mut m = measurement(state, Quality::Perfect, sent[59]);
            m.robot.power = power;
            m.data.cmd_jnt_pos = [0.05; JOINTS];
            // Both echo the robot's commanded position.
            assert_eq!(s.answer(&m).cmd.jnt_pos, [0.05; JOINTS]);
            assert!(
                matches!(s.phase(), Phase::Stopped { at: 60, .. }),
                "{:?}",
                s.phase()
            );
        }
    }

    #[test]
    fn a_setpoint_beyond_a_limit_is_never_sent() {
        // Measured far away and a near-zero approach speed bound would be
        // fine; a measured position beyond the limit is not.
        let mut s = Session::new(&path(), SessionConfig::default());
        let beyond = [3.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0];
        let c = s.answer(&measurement(State::Command, Quality::Perfect, beyond));
        assert_eq!(c.cmd.jnt_pos, beyond, "held where commanded, not moved");
        match s.phase() {
            Phase::Stopped {
                why: Stop::Limit(why),
                at: 0,
            } => assert!(
                why.starts_with(
                    "setpoint 0: joint a1 at sample 0 (t = 0.000 s): 3.0000 rad (171.89 deg) \
                     beyond its upper limit"
                ),
                "{why}"
            ),
            p => panic!("{p:?}"),
        }
        // An approach speed above the limits is caught step by step.
        let cfg = SessionConfig {
            approach_speed: 3.0,
            weigh: 0.0,
            settle: 0.0,
        };
        let mut s = Session::new(&path(), cfg);
        run(&mut s, [1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0], 20);
        match s.phase() {
            Phase::Stopped {
                why: Stop::Limit(why),
                ..
            } => assert!(why.contains("velocity limit"), "{why}"),
            p => panic!("{p:?}"),
        }
    }

    #[test]
    fn resampling_hits_the_knots_and_ends_on_the_last_sample() {
        let t = vec![0.5, 0.52, 0.535];
        let p = check_joints(t, vec![[0.0; JOINTS], [0.02; JOINTS], [0.035; JOINTS]]).unwrap();
        let r = resample(&p, 0.01);
        assert_eq!(r.len(), 5);
        let first: Vec<f64> = r.map(|q| q[0]).collect();
        assert_eq!(first.len(), 5);
        for (a, b) in first.iter().zip([0.0, 0.01, 0.02, 0.03, 0.035]) {
            assert!((a - b).abs() < 1e-12, "{first:?}");
        }
    }
}
