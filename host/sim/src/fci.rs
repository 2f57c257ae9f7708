//! A simulated Franka controller: the robot side of the FCI (protocol
//! version 10, [`primo_franka::wire`]) on 127.0.0.1, for tests and for
//! trying primo without a robot; libfranka's own client drives it too.
//!
//! It listens on a TCP port for the command channel, one client at a
//! time. After `Connect` it sends a [`RobotState`] every millisecond from
//! its own UDP socket to the client's port; it serves the robot's URDF
//! for `GetRobotModel`, starts a joint-position motion on `Move`
//! (answering "motion started"), takes each command's `q_c` as the
//! arm's position the next cycle (perfect tracking, clamped to the joint
//! limits of the URDF's chain), and ends the motion with "finished" on
//! the command flagged `motion_generation_finished`. `StopMove` ends a
//! motion (it answers the `Move` "preempted"), `AutomaticErrorRecovery`
//! clears a reflex, every setter succeeds.
//!
//! Faults for the tests ([`Fault`]): a reflex after a number of motion
//! cycles (robot mode reflex, the flag in `reflex_reason`, the `Move`
//! answered "aborted by a reflex"), falling silent (no more states), or
//! hanging up the command channel.
//!
//! While a motion runs it counts each state answered before the next
//! state is due as on time, and the others late or missed: the
//! late-cycle rate of the client (and its own sends later than half a
//! cycle, its own lateness), in the [`FciReport`].

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpListener, TcpStream, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, PoisonError};
use std::time::{Duration, Instant};

use primo_franka::wire::{
    Command, ConnectStatus, Flags, Message, MoveRequest, MoveStatus, RecoveryStatus, RobotCommand,
    RobotState, StopMoveStatus, VERSION, connect_response, motion_generator_mode,
    parse_connect_request, robot_mode,
};
use primo_fri::realtime;
use primo_robot::JOINTS;
use primo_robot::chain::Chain;
use primo_robot::urdf::Urdf;

use crate::Error;

/// The FCI's cycle.
pub const CYCLE: Duration = Duration::from_millis(1);

/// A fault the controller injects while a motion runs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Fault {
    /// A reflex after this many motion cycles, with this flag (an index
    /// of [`primo_franka::wire::FLAG_NAMES`]).
    Reflex {
        /// Motion cycles before it.
        after: u64,
        /// The flag set in `reflex_reason`.
        flag: usize,
    },
    /// No more states after this many motion cycles.
    Silent {
        /// Motion cycles before it.
        after: u64,
    },
    /// The command channel closed after this many motion cycles.
    Hangup {
        /// Motion cycles before it.
        after: u64,
    },
    /// The arm held still (a person, a contact) for `cycles` motion
    /// cycles after `after`: it reports where it stopped while the
    /// commands go on, then follows them again.
    Hold {
        /// Motion cycles before it.
        after: u64,
        /// Motion cycles it lasts.
        cycles: u64,
    },
}

/// The simulated controller's settings.
#[derive(Debug, Clone)]
pub struct FciConfig {
    /// The TCP address to listen on (loopback).
    pub addr: SocketAddr,
    /// The robot's URDF, served for `GetRobotModel`; its chain's joint
    /// limits clamp the arm.
    pub urdf: String,
    /// Joint angles at power-on, rad.
    pub start: [f64; JOINTS],
    /// A fault to inject in every motion.
    pub fault: Option<Fault>,
    /// Return after the first client leaves.
    pub once: bool,
    /// Run the state stream at real-time priority where allowed.
    pub realtime: bool,
}

impl FciConfig {
    /// On 127.0.0.1:`port`, the FR3 at its usual start, no fault.
    pub fn new(port: u16) -> FciConfig {
        FciConfig {
            addr: SocketAddr::from(([127, 0, 0, 1], port)),
            urdf: primo_franka::plan::FR3_URDF.to_string(),
            start: [0.0, 0.0, 0.0, -1.57, 0.0, 1.57, 0.785],
            fault: None,
            once: false,
            realtime: true,
        }
    }
}

/// What the controller saw.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct FciReport {
    /// Clients served.
    pub clients: u64,
    /// Motions started.
    pub motions: u64,
    /// Motions that ended with the client's last command.
    pub finished: u64,
    /// Reflexes injected.
    pub reflexes: u64,
    /// States sent while a motion ran.
    pub motion_cycles: u64,
    /// Of those, answered before the next state.
    pub on_time: u64,
    /// Answered, but after the next state was sent.
    pub late: u64,
    /// Never answered.
    pub missed: u64,
    /// States this controller sent more than half a cycle late.
    pub late_sends: u64,
    /// Its latest send, s after its due time.
    pub max_send_delay: f64,
    /// Commands that were no command datagram.
    pub malformed: u64,
}

impl FciReport {
    /// Late and missed answers per motion cycle.
    pub fn late_rate(&self) -> f64 {
        (self.late + self.missed) as f64 / self.motion_cycles.max(1) as f64
    }
}

/// The robot as the stream and the command channel share it.
#[derive(Debug)]
struct Robot {
    state: RobotState,
    q: [f64; JOINTS],
    lower: [f64; JOINTS],
    upper: [f64; JOINTS],
    /// The running `Move`'s id.
    motion: Option<u32>,
    motion_cycles: u64,
    /// The last state sent while moving, awaiting its answer.
    awaiting: Option<u64>,
    silent: bool,
    hangup: bool,
    held: bool,
    report: FciReport,
}

/// The simulated controller, listening.
#[derive(Debug)]
pub struct SimFci {
    listener: TcpListener,
    cfg: FciConfig,
    lower: [f64; JOINTS],
    upper: [f64; JOINTS],
}

impl SimFci {
    /// Checks the URDF and listens on `cfg.addr`.
    pub fn new(cfg: FciConfig) -> Result<SimFci, Error> {
        let chain = Urdf::parse("the robot's URDF", &cfg.urdf)
            .map_err(|e| Error::Invalid(e.to_string()))
            .and_then(|u| {
                Chain::from_urdf(&u, &Default::default()).map_err(|e| Error::Invalid(e.to_string()))
            })?;
        if chain.dof() != JOINTS {
            return Err(Error::Invalid(format!(
                "a Franka arm has seven joints; the URDF's chain has {}",
                chain.dof()
            )));
        }
        let lower = std::array::from_fn(|j| chain.joints()[j].limits.lower);
        let upper = std::array::from_fn(|j| chain.joints()[j].limits.upper);
        let listener = TcpListener::bind(cfg.addr)
            .map_err(|e| Error::Io(format!("cannot listen on TCP {}: {e}", cfg.addr)))?;
        listener.set_nonblocking(true).map_err(io)?;
        Ok(SimFci {
            listener,
            cfg,
            lower,
            upper,
        })
    }

    /// The TCP address it listens on.
    pub fn local_addr(&self) -> Result<SocketAddr, Error> {
        self.listener.local_addr().map_err(io)
    }

    /// Serves clients one at a time until `stop` is set (or the first
    /// leaves, with `once`).
    pub fn run(&self, stop: &AtomicBool) -> Result<FciReport, Error> {
        let mut total = FciReport::default();
        let mut q = self.cfg.start;
        while !stop.load(Ordering::Relaxed) {
            let tcp = match self.listener.accept() {
                Ok((tcp, _)) => tcp,
                Err(e) if e.kind() == ErrorKind::WouldBlock => {
                    std::thread::sleep(Duration::from_millis(5));
                    continue;
                }
                Err(e) => return Err(io(e)),
            };
            let report = self.serve(tcp, stop, &mut q)?;
            for (sum, x) in [
                (&mut total.clients, 1),
                (&mut total.motions, report.motions),
                (&mut total.finished, report.finished),
                (&mut total.reflexes, report.reflexes),
                (&mut total.motion_cycles, report.motion_cycles),
                (&mut total.on_time, report.on_time),
                (&mut total.late, report.late),
                (&mut total.missed, report.missed),
                (&mut total.late_sends, report.late_sends),
                (&mut total.malformed, report.malformed),
            ] {
                *sum += x;
            }
            total.max_send_delay = total.max_send_delay.max(report.max_send_delay);
            if self.cfg.once {
                break;
            }
        }
        Ok(total)
    }

    /// One client, from `Connect` until it leaves.
    fn serve(
        &self,
        mut tcp: TcpStream,
        stop: &AtomicBool,
        q: &mut [f64; JOINTS],
    ) -> Result<FciReport, Error> {
        tcp.set_nonblocking(false).map_err(io)?;
        tcp.set_nodelay(true).map_err(io)?;
        tcp.set_read_timeout(Some(Duration::from_millis(20)))
            .map_err(io)?;
        let mut inbox = Vec::new();
        let Some(connect) = read_message(&mut tcp, &mut inbox, stop)? else {
            return Ok(FciReport::default());
        };
        let (version, port) = parse_connect_request(&connect.payload).map_err(invalid)?;
        if connect.header.command != Command::Connect || version != VERSION {
            let answer = connect_response(ConnectStatus::IncompatibleLibraryVersion, VERSION);
            let _ =
                tcp.write_all(&Message::new(Command::Connect, connect.header.id, answer).encode());
            return Ok(FciReport::default());
        }
        let peer = SocketAddr::new(tcp.peer_addr().map_err(io)?.ip(), port);
        let udp = UdpSocket::bind(SocketAddr::new(self.cfg.addr.ip(), 0)).map_err(io)?;
        udp.set_nonblocking(true).map_err(io)?;
        let answer = connect_response(ConnectStatus::Success, VERSION);
        match tcp.write_all(&Message::new(Command::Connect, connect.header.id, answer).encode()) {
            Ok(()) => {}
            Err(e) if gone(&e) => return Ok(FciReport::default()),
            Err(e) => return Err(io(e)),
        }
        let robot = Arc::new(Mutex::new(Robot {
            state: RobotState {
                robot_mode: robot_mode::IDLE,
                q_d: q.map(|x| x as f32),
                control_command_success_rate: 1.0,
                ..RobotState::default()
            },
            q: *q,
            lower: self.lower,
            upper: self.upper,
            motion: None,
            motion_cycles: 0,
            awaiting: None,
            silent: false,
            hangup: false,
            held: false,
            report: FciReport::default(),
        }));
        let writer = Mutex::new(tcp.try_clone().map_err(io)?);
        let leave = AtomicBool::new(false);
        let served = std::thread::scope(|scope| {
            let stream = std::thread::Builder::new()
                .name("sim-fci-stream".into())
                .spawn_scoped(scope, || {
                    self.stream(&udp, peer, &robot, &writer, &leave, stop)
                })
                .map_err(io)?;
            let channel = self.channel(&mut tcp, &mut inbox, &robot, &writer, stop);
            leave.store(true, Ordering::Relaxed);
            let streamed = stream
                .join()
                .unwrap_or_else(|_| Err(Error::Io("the state stream panicked".into())));
            channel.and(streamed)
        });
        let robot = robot.lock().unwrap_or_else(PoisonError::into_inner);
        *q = robot.q;
        served.map(|()| robot.report)
    }

    /// The command channel until the client leaves.
    fn channel(
        &self,
        tcp: &mut TcpStream,
        inbox: &mut Vec<u8>,
        robot: &Mutex<Robot>,
        writer: &Mutex<TcpStream>,
        stop: &AtomicBool,
    ) -> Result<(), Error> {
        while let Some(m) = read_message(tcp, inbox, stop)? {
            let id = m.header.id;
            let mut r = robot.lock().unwrap_or_else(PoisonError::into_inner);
            if r.hangup {
                break;
            }
            let reply = |status: u8| Message::new(m.header.command, id, vec![status]);
            let answers = match m.header.command {
                Command::GetRobotModel => {
                    let mut p = vec![0];
                    p.extend_from_slice(self.cfg.urdf.as_bytes());
                    vec![Message::new(Command::GetRobotModel, id, p)]
                }
                Command::Move => match MoveRequest::decode(&m.payload) {
                    Ok(req)
                        if req.motion_generator_mode == 0
                            && r.motion.is_none()
                            && r.state.robot_mode == robot_mode::IDLE =>
                    {
                        r.motion = Some(id);
                        r.motion_cycles = 0;
                        r.awaiting = None;
                        r.report.motions += 1;
                        r.state.robot_mode = robot_mode::MOVE;
                        r.state.motion_generator_mode = motion_generator_mode::JOINT_POSITION;
                        r.state.controller_mode = req.controller_mode as u8;
                        vec![reply(MoveStatus::MotionStarted as u8)]
                    }
                    Ok(_) => vec![reply(MoveStatus::CommandNotPossibleRejected as u8)],
                    Err(_) => vec![reply(MoveStatus::InvalidArgumentRejected as u8)],
                },
                Command::StopMove => {
                    let mut out = Vec::new();
                    if let Some(motion) = r.motion.take() {
                        r.end_motion();
                        out.push(Message::new(
                            Command::Move,
                            motion,
                            vec![MoveStatus::Preempted as u8],
                        ));
                    }
                    out.push(reply(StopMoveStatus::Success as u8));
                    out
                }
                Command::AutomaticErrorRecovery => {
                    if r.motion.is_none() {
                        r.state.errors = Flags::default();
                        r.state.robot_mode = robot_mode::IDLE;
                        vec![reply(RecoveryStatus::Success as u8)]
                    } else {
                        vec![reply(RecoveryStatus::CommandNotPossibleRejected as u8)]
                    }
                }
                Command::Connect => vec![reply(1)],
                _ => vec![reply(0)],
            };
            drop(r);
            let mut w = writer.lock().unwrap_or_else(PoisonError::into_inner);
            for a in answers {
                match w.write_all(&a.encode()) {
                    Ok(()) => {}
                    // The client left: its session ends.
                    Err(e) if gone(&e) => return Ok(()),
                    Err(e) => return Err(io(e)),
                }
            }
        }
        Ok(())
    }

    /// The state stream: a state every cycle, the commands in between.
    fn stream(
        &self,
        udp: &UdpSocket,
        peer: SocketAddr,
        robot: &Mutex<Robot>,
        writer: &Mutex<TcpStream>,
        leave: &AtomicBool,
        stop: &AtomicBool,
    ) -> Result<(), Error> {
        let granted = self.cfg.realtime.then(realtime::enter);
        let mut due = Instant::now();
        let mut id = 0u64;
        let mut buf = [0u8; 2048];
        let result = loop {
            if leave.load(Ordering::Relaxed) || stop.load(Ordering::Relaxed) {
                break Ok(());
            }
            // The commands that came in this cycle.
            let mut finished = None;
            let mut failed = None;
            loop {
                match udp.recv_from(&mut buf) {
                    Ok((n, _)) => {
                        let mut r = robot.lock().unwrap_or_else(PoisonError::into_inner);
                        match RobotCommand::decode(&buf[..n]) {
                            Ok(c) => finished = finished.or(r.take(&c)),
                            Err(_) => r.report.malformed += 1,
                        }
                    }
                    Err(e) if primo_fri::udp::transient(&e) => break,
                    Err(e) => {
                        failed = Some(io(e));
                        break;
                    }
                }
            }
            if let Some(e) = failed {
                break Err(e);
            }
            if let Some((motion, status)) = finished {
                let m = Message::new(Command::Move, motion, vec![status as u8]);
                let mut w = writer.lock().unwrap_or_else(PoisonError::into_inner);
                // A client gone is seen by the command channel.
                let _ = w.write_all(&m.encode());
            }
            // Until the cycle's end.
            let now = Instant::now();
            if now < due {
                std::thread::sleep(due - now);
                continue;
            }
            id += 1;
            let state = {
                let mut r = robot.lock().unwrap_or_else(PoisonError::into_inner);
                let delay = now.duration_since(due).as_secs_f64();
                r.report.max_send_delay = r.report.max_send_delay.max(delay);
                if delay > CYCLE.as_secs_f64() / 2.0 {
                    r.report.late_sends += 1;
                }
                if r.motion.is_some() {
                    if r.awaiting.is_some() {
                        r.report.missed += 1;
                    }
                    r.report.motion_cycles += 1;
                    r.motion_cycles += 1;
                    r.awaiting = Some(id);
                    if let Some(m) = self.inject(&mut r) {
                        let mut w = writer.lock().unwrap_or_else(PoisonError::into_inner);
                        let _ = w.write_all(&m.encode());
                    }
                }
                if r.hangup {
                    let w = writer.lock().unwrap_or_else(PoisonError::into_inner);
                    let _ = w.shutdown(std::net::Shutdown::Both);
                }
                r.state.message_id = id;
                r.state.q = r.q.map(|x| x as f32);
                (!r.silent).then_some(r.state)
            };
            if let Some(state) = state {
                match udp.send_to(&state.encode(), peer) {
                    Ok(_) => {}
                    Err(e) if primo_fri::udp::transient(&e) => {}
                    Err(e) => break Err(io(e)),
                }
            }
            due += CYCLE;
            // Far behind (the process was stopped): catch up, not burst.
            if Instant::now().saturating_duration_since(due) > 20 * CYCLE {
                due = Instant::now();
            }
        };
        if let Some(g) = &granted {
            realtime::leave(g);
        }
        result
    }

    /// The fault due this motion cycle, if any: a reflex answers the
    /// motion.
    fn inject(&self, r: &mut Robot) -> Option<Message> {
        match self.cfg.fault? {
            Fault::Reflex { after, flag } if r.motion_cycles > after => {
                let motion = r.motion.take()?;
                r.end_motion();
                r.state.robot_mode = robot_mode::REFLEX;
                r.state.reflex_reason = Flags::default().with(flag);
                r.report.reflexes += 1;
                Some(Message::new(
                    Command::Move,
                    motion,
                    vec![MoveStatus::ReflexAborted as u8],
                ))
            }
            Fault::Silent { after } if r.motion_cycles > after => {
                r.silent = true;
                None
            }
            Fault::Hangup { after } if r.motion_cycles > after => {
                r.hangup = true;
                None
            }
            Fault::Hold { after, cycles } => {
                r.held = r.motion_cycles > after && r.motion_cycles <= after.saturating_add(cycles);
                None
            }
            _ => None,
        }
    }
}

impl Robot {
    /// A command: counted, its position taken while a motion runs; the
    /// motion and its final status if it was the last.
    fn take(&mut self, c: &RobotCommand) -> Option<(u32, MoveStatus)> {
        let motion = self.motion?;
        match self.awaiting {
            Some(id) if c.message_id == id => {
                self.report.on_time += 1;
                self.awaiting = None;
            }
            _ => self.report.late += 1,
        }
        let q_d: [f64; JOINTS] =
            std::array::from_fn(|j| c.q_c[j].clamp(self.lower[j], self.upper[j]));
        if !self.held {
            self.q = q_d;
        }
        self.state.q_d = q_d.map(|x| x as f32);
        if c.motion_generation_finished {
            self.motion = None;
            self.end_motion();
            self.report.finished += 1;
            return Some((motion, MoveStatus::Success));
        }
        None
    }

    fn end_motion(&mut self) {
        self.awaiting = None;
        self.held = false;
        self.state.robot_mode = robot_mode::IDLE;
        self.state.motion_generator_mode = motion_generator_mode::IDLE;
    }
}

/// The next message from the client; `None` when it left or `stop` is set.
fn read_message(
    tcp: &mut TcpStream,
    inbox: &mut Vec<u8>,
    stop: &AtomicBool,
) -> Result<Option<Message>, Error> {
    let mut buf = [0u8; 4096];
    loop {
        if let Some(m) = Message::take(inbox).map_err(invalid)? {
            return Ok(Some(m));
        }
        if stop.load(Ordering::Relaxed) {
            return Ok(None);
        }
        match tcp.read(&mut buf) {
            Ok(0) => return Ok(None),
            Ok(n) => inbox.extend_from_slice(&buf[..n]),
            Err(e)
                if matches!(
                    e.kind(),
                    ErrorKind::WouldBlock | ErrorKind::TimedOut | ErrorKind::Interrupted
                ) => {}
            Err(e) if gone(&e) => return Ok(None),
            Err(e) => return Err(io(e)),
        }
    }
}

/// A write error that means the client has gone.
fn gone(e: &std::io::Error) -> bool {
    matches!(
        e.kind(),
        ErrorKind::BrokenPipe | ErrorKind::ConnectionReset | ErrorKind::NotConnected
    )
}

fn io(e: std::io::Error) -> Error {
    Error::Io(e.to_string())
}

fn invalid(e: primo_franka::wire::WireError) -> Error {
    Error::Invalid(format!("from the client: {e}"))
}
