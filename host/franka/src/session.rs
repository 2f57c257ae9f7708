//! primo's side of the FCI, sans I/O: time, TCP bytes and state datagrams
//! in; TCP bytes, one command per state, events and the outcome out.
//!
//! A session connects (protocol version [`VERSION`], the UDP port states
//! go to), fetches the robot's model, waits for the first state, plans
//! the [`Plan`] from the position it reports (nothing moves if the plan
//! breaks a limit), asks for a motion (joint impedance, joint-position
//! motion generator) and, once the robot runs it, answers every state with
//! the next setpoint, the last one flagged as the motion's end; it is done
//! when the robot reports the motion finished.
//!
//! Everything else ends it with a [`FrankaError`]: a refused motion, a
//! reflex (the robot's answer or a state in reflex mode or with errors),
//! a state older than the newest seen (the newest again is ignored), a
//! stream silent for longer than [`SessionConfig::state_timeout`], a
//! response later than [`SessionConfig::answer_timeout`], a closed
//! connection. An error while
//! the robot moves also asks it to stop the motion.
//!
//! The adapter ([`crate::net`]) drives it: [`Session::poll_transmit`] for
//! the TCP channel, [`Session::handle_state`]'s answer for UDP,
//! [`Session::poll_timeout`] and [`Session::handle_timeout`] for time.

use std::collections::VecDeque;
use std::time::{Duration, Instant};

use primo_core::coupling::PhaseStop;
use primo_robot::{JOINTS, JointPath};

use crate::error::FrankaError;
use crate::plan::Plan;
use crate::retime::Retimer;
use crate::wire::{
    COMMAND_SIZE, Command, ConnectStatus, Message, MoveRequest, MoveStatus, RobotCommand,
    RobotState, StopMoveStatus, VERSION, motion_generator_mode, parse_connect_response, robot_mode,
};

/// With phase stopping, the most setpoints a motion may take, in times its
/// plan's: an arm held for longer is stopped rather than waited for
/// without end.
pub const MAX_STRETCH: usize = 3;

/// How a session moves and waits.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SessionConfig {
    /// Peak speed of the approach to the path's start, as a fraction of
    /// the joint velocity limits.
    pub approach_speed: f64,
    /// Longest wait for a response on the command channel, or for the
    /// first state.
    pub answer_timeout: Duration,
    /// Longest silence of the state stream while the robot moves.
    pub state_timeout: Duration,
    /// Phase stopping: the plan waits for a robot that lags its command
    /// ([`crate::retime`]); `None` streams it as planned.
    pub phase_stop: Option<PhaseStop>,
}

impl Default for SessionConfig {
    fn default() -> Self {
        SessionConfig {
            approach_speed: 0.2,
            answer_timeout: Duration::from_secs(5),
            state_timeout: Duration::from_millis(100),
            phase_stop: None,
        }
    }
}

/// What a session is doing, as it happens.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// The robot accepted the connection.
    Connected {
        /// Its protocol version.
        version: u16,
    },
    /// The robot served its model (URDF).
    Model {
        /// Its length, bytes.
        bytes: usize,
    },
    /// The setpoints are planned from the robot's position and passed the
    /// limits.
    Planned {
        /// Setpoints in all, one a millisecond.
        setpoints: usize,
        /// Of those, approaching the path's start.
        approach: usize,
    },
    /// The robot runs the motion.
    MotionStarted,
    /// The robot reports the motion finished.
    Finished,
}

/// What a run did.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Report {
    /// States received.
    pub states: u64,
    /// Commands sent.
    pub commands: u64,
    /// States the robot sent that never arrived or came too late to
    /// answer (gaps in their `message_id`s while moving).
    pub skipped: u64,
    /// States received again with the same `message_id` (ignored).
    pub duplicates: u64,
    /// Setpoints planned.
    pub planned: usize,
    /// Of those, approaching the start.
    pub approach: usize,
    /// Largest |measured − commanded| per joint, rad (the command a cycle
    /// before the measurement).
    pub max_error: [f64; JOINTS],
    /// Its root mean square per joint, rad.
    pub rms_error: [f64; JOINTS],
    /// The last measured position, rad.
    pub last_q: [f64; JOINTS],
    /// The lowest `control_command_success_rate` the robot reported while
    /// moving.
    pub min_success_rate: Option<f32>,
    /// With phase stopping, the slowest the plan ran, setpoints a cycle
    /// (1: as planned).
    pub slowest_rate: Option<f64>,
    /// The measured positions while the motion ran: when, s on the
    /// robot's clock since the first state of the motion...
    pub times: Vec<f64>,
    /// ...and where, row-major, seven joints a row.
    pub positions: Vec<f64>,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Phase {
    Connecting,
    Model,
    FirstState,
    MoveRequested,
    Moving,
    Finishing,
    /// The robot aborted the motion: the next state says why.
    Aborting(Option<MoveStatus>),
    Done,
}

/// A run of one path on one robot.
#[derive(Debug)]
pub struct Session {
    path: JointPath,
    cfg: SessionConfig,
    phase: Phase,
    udp_port: u16,
    next_id: u32,
    move_id: u32,
    inbox: Vec<u8>,
    out: VecDeque<Vec<u8>>,
    events: VecDeque<Event>,
    plan: Option<Plan>,
    retimer: Option<Retimer>,
    next: usize,
    last_state: Option<RobotState>,
    waiting_since: Instant,
    last_state_at: Instant,
    last_command: Option<[f64; JOINTS]>,
    sum_sq: [f64; JOINTS],
    tracked: u64,
    first_moving: Option<u64>,
    report: Report,
    outcome: Option<Result<(), FrankaError>>,
}

impl Session {
    /// A session for `path` whose states go to the local UDP port
    /// `udp_port`, starting at `now` with the `Connect` request.
    pub fn new(path: &JointPath, udp_port: u16, cfg: SessionConfig, now: Instant) -> Session {
        let mut s = Session {
            path: path.clone(),
            cfg,
            phase: Phase::Connecting,
            udp_port,
            next_id: 0,
            move_id: 0,
            inbox: Vec::new(),
            out: VecDeque::new(),
            events: VecDeque::new(),
            plan: None,
            retimer: None,
            next: 0,
            last_state: None,
            waiting_since: now,
            last_state_at: now,
            last_command: None,
            sum_sq: [0.0; JOINTS],
            tracked: 0,
            first_moving: None,
            report: Report::default(),
            outcome: None,
        };
        s.request(Command::Connect, crate::wire::connect_request(udp_port));
        s
    }

    /// The UDP port the session asked the robot to send states to.
    pub fn udp_port(&self) -> u16 {
        self.udp_port
    }

    /// The next bytes for the command channel.
    pub fn poll_transmit(&mut self) -> Option<Vec<u8>> {
        self.out.pop_front()
    }

    /// The next event.
    pub fn poll_event(&mut self) -> Option<Event> {
        self.events.pop_front()
    }

    /// When [`Session::handle_timeout`] is due, if waiting for anything.
    pub fn poll_timeout(&self) -> Option<Instant> {
        match self.phase {
            Phase::Done => None,
            Phase::Moving | Phase::Aborting(_) => Some(self.last_state_at + self.cfg.state_timeout),
            _ => Some(self.waiting_since + self.cfg.answer_timeout),
        }
    }

    /// Ends the session with an error if what it waits for is overdue.
    pub fn handle_timeout(&mut self, now: Instant) {
        let Some(due) = self.poll_timeout() else {
            return;
        };
        if now < due {
            return;
        }
        let last = self.last_state.unwrap_or_default();
        let error = match self.phase {
            Phase::Moving => FrankaError::Silent(now - self.last_state_at),
            Phase::Aborting(status) => FrankaError::Aborted {
                status,
                reflex: last.reflex_reason,
                errors: last.errors,
            },
            phase => FrankaError::NoAnswer {
                what: match phase {
                    Phase::Connecting => "Connect",
                    Phase::Model => "GetRobotModel",
                    Phase::FirstState => "the first state (is the UDP port reachable?)",
                    Phase::MoveRequested => "Move",
                    _ => "the motion's end",
                },
                after: self.cfg.answer_timeout,
            },
        };
        self.fail(error);
    }

    /// The command channel closed.
    pub fn handle_closed(&mut self) {
        if self.phase != Phase::Done {
            self.out.clear();
            self.fail(FrankaError::Closed);
        }
    }

    /// The operator interrupts: stops the motion if one runs.
    pub fn interrupt(&mut self) {
        if self.phase != Phase::Done {
            self.fail(FrankaError::Interrupted);
        }
    }

    /// Bytes from the command channel.
    pub fn handle_tcp(&mut self, now: Instant, bytes: &[u8]) {
        self.inbox.extend_from_slice(bytes);
        while self.phase != Phase::Done {
            match Message::take(&mut self.inbox) {
                Ok(Some(m)) => self.response(now, m),
                Ok(None) => return,
                Err(e) => return self.fail(e.into()),
            }
        }
    }

    /// A state datagram: the command answering it, if one is due.
    pub fn handle_state(&mut self, now: Instant, datagram: &[u8]) -> Option<[u8; COMMAND_SIZE]> {
        if self.phase == Phase::Done {
            return None;
        }
        let state = match RobotState::decode(datagram) {
            Ok(s) => s,
            Err(e) => {
                self.fail(e.into());
                return None;
            }
        };
        if let Some(last) = self.last_state.map(|s| s.message_id) {
            if state.message_id == last {
                // The same state again (franka-sim resends one at times):
                // answered already, nothing new.
                self.report.duplicates += 1;
                return None;
            }
            if state.message_id < last {
                self.fail(FrankaError::Stale {
                    got: state.message_id,
                    last,
                });
                return None;
            }
            if self.phase == Phase::Moving {
                self.report.skipped += state.message_id - last - 1;
            }
        }
        self.last_state = Some(state);
        self.last_state_at = now;
        self.report.states += 1;
        self.report.last_q = state.joints();
        match self.phase {
            Phase::FirstState => {
                self.start(now, &state);
                None
            }
            Phase::Aborting(status) => {
                self.fail(FrankaError::Aborted {
                    status,
                    reflex: state.reflex_reason,
                    errors: state.errors,
                });
                None
            }
            Phase::MoveRequested | Phase::Moving | Phase::Finishing => self.answer(&state),
            _ => None,
        }
    }

    /// Whether the session has ended (its outcome is known).
    pub fn is_done(&self) -> bool {
        self.phase == Phase::Done
    }

    /// What the run did so far.
    pub fn report(&self) -> &Report {
        &self.report
    }

    /// The outcome: the report, or why the run failed (an unfinished
    /// session has not failed yet but did not finish either: interrupted).
    pub fn finish(self) -> Result<Report, FrankaError> {
        let (report, outcome) = self.into_parts();
        outcome.map(|()| report)
    }

    /// What the run did, failed or not, and its outcome.
    pub fn into_parts(self) -> (Report, Result<(), FrankaError>) {
        let outcome = self.outcome.unwrap_or(Err(FrankaError::Interrupted));
        (self.report, outcome)
    }

    fn request(&mut self, command: Command, payload: Vec<u8>) -> u32 {
        let id = self.next_id;
        self.next_id = self.next_id.wrapping_add(1);
        self.out
            .push_back(Message::new(command, id, payload).encode());
        id
    }

    fn fail(&mut self, error: FrankaError) {
        if matches!(
            self.phase,
            Phase::MoveRequested | Phase::Moving | Phase::Finishing
        ) && !matches!(error, FrankaError::Aborted { .. } | FrankaError::Closed)
        {
            self.request(Command::StopMove, Vec::new());
        }
        self.phase = Phase::Done;
        self.outcome.get_or_insert(Err(error));
    }

    fn response(&mut self, now: Instant, m: Message) {
        let status = match m.status() {
            Ok(s) => s,
            Err(e) => return self.fail(e.into()),
        };
        let unexpected = |m: &Message| {
            FrankaError::Unexpected(format!(
                "{:?} response {} (status {}) while {:?}",
                m.header.command, m.header.id, status, self.phase
            ))
        };
        match (self.phase, m.header.command) {
            (Phase::Connecting, Command::Connect) => {
                let (status, version) = match parse_connect_response(&m.payload) {
                    Ok(r) => r,
                    Err(e) => return self.fail(e.into()),
                };
                if ConnectStatus::from_code(status) != Some(ConnectStatus::Success)
                    || version != VERSION
                {
                    return self.fail(FrankaError::Version {
                        robot: version,
                        ours: VERSION,
                    });
                }
                self.events.push_back(Event::Connected { version });
                self.request(Command::GetRobotModel, Vec::new());
                self.phase = Phase::Model;
                self.waiting_since = now;
            }
            (Phase::Model, Command::GetRobotModel) => {
                if status != 0 {
                    return self.fail(FrankaError::Model(status));
                }
                self.events.push_back(Event::Model {
                    bytes: m.payload.len() - 1,
                });
                self.phase = Phase::FirstState;
                self.waiting_since = now;
            }
            (Phase::MoveRequested | Phase::Moving | Phase::Finishing, Command::Move)
                if m.header.id == self.move_id =>
            {
                self.move_status(now, status)
            }
            (_, Command::StopMove) => match StopMoveStatus::from_code(status) {
                Some(StopMoveStatus::Success) => {}
                Some(s) => self.fail(FrankaError::Stop(s)),
                None => self.fail(unexpected(&m)),
            },
            _ => self.fail(unexpected(&m)),
        }
    }

    fn move_status(&mut self, now: Instant, status: u8) {
        match (self.phase, MoveStatus::from_code(status)) {
            (Phase::MoveRequested, Some(MoveStatus::MotionStarted)) => {
                self.events.push_back(Event::MotionStarted);
                self.phase = Phase::Moving;
                self.last_state_at = now;
            }
            // The stream showed the motion first.
            (Phase::Moving | Phase::Finishing, Some(MoveStatus::MotionStarted)) => {}
            (Phase::Finishing, Some(MoveStatus::Success)) => {
                self.events.push_back(Event::Finished);
                self.phase = Phase::Done;
                self.outcome = Some(Ok(()));
            }
            (
                Phase::MoveRequested,
                Some(
                    s @ (MoveStatus::CommandRejectedDueToActivatedSafetyFunctions
                    | MoveStatus::CommandNotPossibleRejected
                    | MoveStatus::StartAtSingularPoseRejected
                    | MoveStatus::InvalidArgumentRejected),
                ),
            ) => self.fail(FrankaError::Refused(s)),
            (_, Some(s)) if !matches!(s, MoveStatus::Success | MoveStatus::MotionStarted) => {
                // The next state carries the reflex's reasons.
                self.phase = Phase::Aborting(Some(s));
                self.last_state_at = now;
            }
            _ => self.fail(FrankaError::Unexpected(format!(
                "Move response status {status} while {:?}",
                self.phase
            ))),
        }
    }

    /// The first state: the robot ready, the plan from where it stands,
    /// the motion asked for.
    fn start(&mut self, now: Instant, state: &RobotState) {
        if !state.errors.is_empty() || state.robot_mode != robot_mode::IDLE {
            return self.fail(FrankaError::NotReady {
                errors: state.errors,
                mode: state.robot_mode,
            });
        }
        // A joint-position motion starts where the robot's desired
        // position stands (libfranka's motion generators start at q_d;
        // a start elsewhere is the reflex
        // joint_position_motion_generator_start_pose_invalid).
        let from = state.q_d.map(f64::from);
        let plan = match Plan::new(&self.path, from, self.cfg.approach_speed) {
            Ok(p) => p,
            Err(e) => return self.fail(e),
        };
        self.report.planned = plan.setpoints().len();
        // Room for the motion's states (stretched by phase stopping), a
        // second of late ones besides: nothing grows inside the cycle.
        let stretch = if self.cfg.phase_stop.is_some() {
            MAX_STRETCH
        } else {
            1
        };
        let states = plan.setpoints().len() * stretch + 1000;
        self.report.times.reserve(states);
        self.report.positions.reserve(states * JOINTS);
        self.report.approach = plan.approach_len();
        self.events.push_back(Event::Planned {
            setpoints: plan.setpoints().len(),
            approach: plan.approach_len(),
        });
        self.retimer = self.cfg.phase_stop.map(|k| Retimer::new(&plan, k));
        self.plan = Some(plan);
        self.move_id = self.request(Command::Move, MoveRequest::default().encode());
        self.phase = Phase::MoveRequested;
        self.waiting_since = now;
    }

    /// The next setpoint for a state, once the robot runs the motion.
    fn answer(&mut self, state: &RobotState) -> Option<[u8; COMMAND_SIZE]> {
        let running = state.motion_generator_mode == motion_generator_mode::JOINT_POSITION
            && state.robot_mode == robot_mode::MOVE;
        if self.phase == Phase::Moving
            && (state.robot_mode == robot_mode::REFLEX || !state.errors.is_empty())
        {
            self.fail(FrankaError::Aborted {
                status: None,
                reflex: state.reflex_reason,
                errors: state.errors,
            });
            return None;
        }
        if self.phase == Phase::MoveRequested && running {
            // The stream may show the motion before the channel says so.
            self.events.push_back(Event::MotionStarted);
            self.phase = Phase::Moving;
        }
        if self.phase != Phase::Moving || !running {
            return None;
        }
        let rate = state.control_command_success_rate;
        self.report.min_success_rate =
            Some(self.report.min_success_rate.map_or(rate, |r| r.min(rate)));
        self.track(state);
        self.record(state);
        let plan = self.plan.as_ref()?;
        let (q_c, finished) = match &mut self.retimer {
            Some(_) if self.next >= MAX_STRETCH * plan.setpoints().len() => {
                let planned = plan.setpoints().len() as f64 * crate::plan::DT;
                self.fail(FrankaError::Held {
                    planned,
                    stretch: MAX_STRETCH,
                });
                return None;
            }
            Some(r) => {
                let next = r.next(plan, self.path.chain(), state.joints());
                self.report.slowest_rate = Some(r.slowest());
                match next {
                    Ok(next) => next,
                    Err(e) => {
                        self.fail(e);
                        return None;
                    }
                }
            }
            None => {
                let setpoints = plan.setpoints();
                let q_c = setpoints.get(self.next).copied()?;
                (q_c, self.next + 1 >= setpoints.len())
            }
        };
        self.next += 1;
        self.last_command = Some(q_c);
        self.report.commands += 1;
        if finished {
            self.phase = Phase::Finishing;
            self.waiting_since = self.last_state_at;
        }
        Some(
            RobotCommand {
                message_id: state.message_id,
                q_c,
                motion_generation_finished: finished,
                ..RobotCommand::default()
            }
            .encode(),
        )
    }

    /// The state's position, on the robot's millisecond clock.
    fn record(&mut self, state: &RobotState) {
        let first = *self.first_moving.get_or_insert(state.message_id);
        let t = state.message_id.saturating_sub(first) as f64 * crate::plan::DT;
        self.report.times.push(t);
        self.report.positions.extend(state.joints());
    }

    fn track(&mut self, state: &RobotState) {
        let Some(commanded) = self.last_command else {
            return;
        };
        self.tracked += 1;
        let q = state.joints();
        for j in 0..JOINTS {
            let e = (q[j] - commanded[j]).abs();
            self.report.max_error[j] = self.report.max_error[j].max(e);
            self.sum_sq[j] += e * e;
            self.report.rms_error[j] = (self.sum_sq[j] / self.tracked as f64).sqrt();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::plan::fr3;
    use crate::wire::{ConnectStatus, Flags, connect_response};
    use primo_robot::safety::check_path;

    const HOME: [f64; JOINTS] = [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785];

    fn path() -> JointPath {
        let mut end = HOME;
        end[0] = 0.05;
        check_path(&fr3(), vec![0.0, 0.5], [HOME, end].concat(), None).unwrap()
    }

    fn reply(s: &mut Session, now: Instant, command: Command, payload: Vec<u8>) {
        let sent = s.poll_transmit().expect("a request");
        let mut buf = sent.clone();
        let request = Message::take(&mut buf).unwrap().unwrap();
        assert_eq!(request.header.command, command);
        s.handle_tcp(
            now,
            &Message::new(command, request.header.id, payload).encode(),
        );
    }

    fn state(id: u64, mode: u8, mg: u8) -> Vec<u8> {
        RobotState {
            message_id: id,
            q: HOME.map(|x| x as f32),
            q_d: HOME.map(|x| x as f32),
            robot_mode: mode,
            motion_generator_mode: mg,
            control_command_success_rate: 1.0,
            ..RobotState::default()
        }
        .encode()
        .to_vec()
    }

    /// A session the robot accepted.
    fn connected(now: Instant) -> Session {
        let mut s = Session::new(&path(), 4000, SessionConfig::default(), now);
        reply(
            &mut s,
            now,
            Command::Connect,
            connect_response(ConnectStatus::Success, VERSION),
        );
        s
    }

    /// A session up to the motion running, and the next state's id.
    fn moving(now: Instant) -> (Session, u64) {
        let mut s = connected(now);
        let mut model = vec![0];
        model.extend_from_slice(b"<robot/>");
        reply(&mut s, now, Command::GetRobotModel, model);
        assert!(
            s.handle_state(now, &state(1, robot_mode::IDLE, 0))
                .is_none()
        );
        reply(
            &mut s,
            now,
            Command::Move,
            vec![MoveStatus::MotionStarted as u8],
        );
        (s, 2)
    }

    #[test]
    fn streams_one_command_per_state_and_finishes() {
        let now = Instant::now();
        let (mut s, mut id) = moving(now);
        let events: Vec<_> = std::iter::from_fn(|| s.poll_event()).collect();
        assert_eq!(events[0], Event::Connected { version: 10 });
        assert!(
            matches!(events[2], Event::Planned { approach, setpoints } if setpoints == approach + 500),
            "{events:?}"
        );
        let mut last = None;
        while !s.is_done() && id < 2000 {
            if let Some(c) = s.handle_state(now, &state(id, robot_mode::MOVE, 1)) {
                let c = RobotCommand::decode(&c).unwrap();
                assert_eq!(c.message_id, id);
                last = Some(c);
            }
            id += 1;
            if last.is_some_and(|c| c.motion_generation_finished) && s.poll_transmit().is_none() {
                break;
            }
        }
        let last = last.unwrap();
        assert!(last.motion_generation_finished);
        assert_eq!(last.q_c[0], 0.05);
        s.handle_tcp(now, &Message::new(Command::Move, 2, vec![0]).encode());
        assert!(s.is_done());
        let report = s.finish().unwrap();
        assert_eq!(report.commands as usize, report.planned);
        assert_eq!(report.times.len(), report.planned);
        assert_eq!(report.positions.len(), 7 * report.planned);
        assert_eq!(report.times[1], 0.001);
    }

    #[test]
    fn a_reflex_is_a_typed_error_and_the_motion_is_stopped() {
        let now = Instant::now();
        let (mut s, id) = moving(now);
        assert!(
            s.handle_state(now, &state(id, robot_mode::MOVE, 1))
                .is_some()
        );
        let mut reflex = RobotState::decode(&state(id + 1, robot_mode::REFLEX, 0)).unwrap();
        reflex.reflex_reason = Flags::default().with(6);
        assert!(s.handle_state(now, &reflex.encode()).is_none());
        let err = s.finish().unwrap_err().to_string();
        assert_eq!(
            err,
            "the robot stopped the motion (a reflex): reflex joint_reflex; errors none"
        );
        let (mut s, _) = moving(now);
        s.handle_tcp(now, &Message::new(Command::Move, 2, vec![8]).encode());
        assert!(!s.is_done(), "waits for the state with the reasons");
        s.handle_state(now, &reflex.encode());
        assert!(
            s.finish()
                .unwrap_err()
                .to_string()
                .starts_with("the robot stopped the motion (aborted by a reflex)")
        );
    }

    #[test]
    fn stale_states_silence_and_a_closed_channel_are_errors() {
        let now = Instant::now();
        let (mut s, id) = moving(now);
        assert!(
            s.handle_state(now, &state(id, robot_mode::MOVE, 1))
                .is_some()
        );
        // The same state again is ignored; an older one ends the run.
        assert!(
            s.handle_state(now, &state(id, robot_mode::MOVE, 1))
                .is_none()
        );
        assert!(!s.is_done());
        assert_eq!(s.report().duplicates, 1);
        s.handle_state(now, &state(id - 1, robot_mode::MOVE, 1));
        assert!(s.poll_transmit().is_some(), "asks to stop");
        assert!(matches!(
            s.finish(),
            Err(FrankaError::Stale { got: 1, last: 2 })
        ));

        let (mut s, id) = moving(now);
        s.handle_state(now, &state(id, robot_mode::MOVE, 1));
        assert_eq!(s.poll_timeout(), Some(now + Duration::from_millis(100)));
        s.handle_timeout(now + Duration::from_millis(99));
        assert!(!s.is_done());
        s.handle_timeout(now + Duration::from_millis(150));
        assert_eq!(
            s.finish().unwrap_err().to_string(),
            "no state from the robot for 150ms"
        );

        let (mut s, _) = moving(now);
        s.handle_closed();
        assert!(matches!(s.finish(), Err(FrankaError::Closed)));
    }

    #[test]
    fn a_robot_in_error_or_another_version_is_refused_before_any_motion() {
        let now = Instant::now();
        let mut s = Session::new(&path(), 4000, SessionConfig::default(), now);
        reply(
            &mut s,
            now,
            Command::Connect,
            connect_response(ConnectStatus::IncompatibleLibraryVersion, 9),
        );
        assert!(matches!(
            s.finish(),
            Err(FrankaError::Version { robot: 9, ours: 10 })
        ));

        let mut s = connected(now);
        reply(&mut s, now, Command::GetRobotModel, vec![0]);
        s.handle_state(now, &state(1, robot_mode::REFLEX, 0));
        assert!(s.poll_transmit().is_none(), "no Move");
        assert!(matches!(s.finish(), Err(FrankaError::NotReady { .. })));
    }
}
