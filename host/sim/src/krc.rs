//! A simulated KRC: the robot side of FRI on UDP, driving the simulated
//! LWR4 and pouring cell, for tests and for trying primo without a robot.
//!
//! Every cycle (1–10 ms) it sends a measurement packet to the remote and
//! waits until the cycle's end for the answer; an answer with the wrong
//! `reflSeqCount` or after the cycle is stale and counts as a miss
//! (`answerRate`, `missRate`, `missCounter`, over the last
//! [`STAT_WINDOW`] cycles). As on a real KRC it opens in monitor mode; the
//! quality ramps BAD → OK → PERFECT as the remote answers (and falls with
//! the answer rate); once the quality is at least OK and the remote has
//! echoed the commanded position on time for [`HANDSHAKE`] cycles in a
//! row, it switches to command mode (`friStart`). In command mode the
//! commanded joint position is the remote's `jntPos`; if the remote falls
//! silent for `release_after` it falls back to monitor mode (`friStop`),
//! holding the last commanded position.
//!
//! The arm's measured position follows the commanded one through a
//! first-order lag of [`SERVO_LAG`] limited to the joint velocity limits;
//! commands beyond the position limits are clamped and counted, commands
//! faster than the velocity limits are counted. The pouring cell is
//! stepped with the measured joints (interpolated within the cycle at the
//! cell's ≤ 2 ms step), so the liquid pours; it is shared through a
//! [`CellHandle`] for other simulated instruments in the same process.
//!
//! It follows `jntPos` in command mode whatever the quality: checking the
//! quality is the remote's job, and the tests can see that it does it.
//!
//! The estimated external load (`estExtTcpFT`, and `estExtJntTrq`) is the
//! weight of the liquid still in the bottle: the tool's load data on a
//! real KRC cover the hand and the empty bottle, so what remains is the
//! liquid. The force (N) and its moment about the flange (N·m, the weight
//! taken at the bottle's centre: the liquid's centre of mass moving as it
//! tilts and empties is not modelled) are expressed in the flange frame,
//! the TCP of `msrCartPos`, as on a real LWR; each component carries
//! Gaussian noise ([`FORCE_NOISE`], [`MOMENT_NOISE`]) from the KRC's seed.
//! `estExtJntTrq` is `Jᵀ` times that noisy wrench. Inertial forces are not
//! modelled: the estimate is meant to be read while the arm stands still.
//!
//! [`SimKrc::serve_scale`] serves the cell's scale over MT-SICS, weighing
//! what lands on the cell's pan; [`SimKrc::serve_load_cell`] serves it as
//! a bare load cell's raw counts, for the scale firmware.

use crate::Error;
use std::collections::VecDeque;
use std::net::{SocketAddr, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use primo_core::normal::StandardNormal;
use primo_core::rng::Xoshiro128PlusPlus;
use rand_core::{Rng, SeedableRng};

use primo_fri::packet::{Command, Measurement, Quality, State, flags};
use primo_fri::udp::transient;
use primo_robot::{Arm, JOINTS, Pose};

use crate::bottle::G;
use crate::cell::{Cell, CellConfig, GlassKind, MAX_DT};
use crate::load_cell::{LoadCellModel, LoadCellServer};
use crate::scale_device::{Device, DeviceConfig, LoadSource, PtyServer};

/// Cycles the communication statistics and the quality are computed over.
pub const STAT_WINDOW: usize = 100;
/// On-time answers needed for OK; twice as many for PERFECT.
pub const RAMP: u64 = 10;
/// Consecutive on-time echoes in monitor mode before command mode.
pub const HANDSHAKE: usize = 20;
/// The fraction of a cycle after which a send counts as late
/// ([`KrcReport::late_sends`]).
pub const LATE_SEND: f64 = 0.25;
/// How often the KRC looks for the answer within a cycle.
const POLL: Duration = Duration::from_micros(100);
/// Time constant of the joint position servo, s.
pub const SERVO_LAG: f64 = 0.005;
/// Standard deviation of the noise on each force component of
/// `estExtTcpFT`, N: an LWR4's estimate from its joint torque sensors is
/// good to a few tenths of a newton at a standstill. Averaged over 0.3 s
/// of 2 ms cycles (150 samples) it is 0.025 N, the weight of 2.5 ml of
/// water.
pub const FORCE_NOISE: f64 = 0.3;
/// Standard deviation of the noise on each moment component of
/// `estExtTcpFT`, N·m (the force noise on a lever of about 16 cm).
pub const MOMENT_NOISE: f64 = 0.05;

/// What the simulated KRC does.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct KrcConfig {
    /// Where the remote listens (primo's `fri:ADDR:PORT`).
    pub remote: SocketAddr,
    /// The FRI cycle, 1–10 ms.
    pub cycle: Duration,
    /// The arm's joint angles at power-on, rad.
    pub start: [f64; JOINTS],
    /// Liquid in the bottle, l.
    pub bottle: f64,
    /// The glass on the scale.
    pub glass: GlassKind,
    /// Fraction of measurement packets lost on the way to the remote.
    pub drop: f64,
    /// Seed of the losses and of the scale's noise.
    pub seed: u64,
    /// From this time on the quality is BAD.
    pub quality_drop_at: Option<Duration>,
    /// Never switch to command mode.
    pub monitor_only: bool,
    /// Stop sending (and return) at this time.
    pub stop_after: Option<Duration>,
    /// Return when a command session ends (the remote fell silent).
    pub once: bool,
    /// Silence in command mode before falling back to monitor mode.
    pub release_after: Duration,
    /// Answer rates (over [`STAT_WINDOW`] cycles) for the qualities BAD,
    /// OK and PERFECT; below the first it is UNACCEPTABLE. A real KRC's
    /// thresholds are configured too.
    pub thresholds: [f64; 3],
    /// Keep a [`CycleRecord`] of every cycle in the report.
    pub record: bool,
}

impl KrcConfig {
    /// A 2 ms KRC sending to `remote`: the arm at the pouring rest
    /// posture, 0.5 l in the bottle, the normal glass, no faults, falling
    /// back to monitor mode after 0.5 s of silence, quality OK from 80 %
    /// answers on time, PERFECT from 98 %.
    pub fn new(remote: SocketAddr) -> Self {
        KrcConfig {
            remote,
            cycle: Duration::from_millis(2),
            start: crate::expert::rest_configuration(0.0),
            bottle: 0.5,
            glass: GlassKind::Normal,
            drop: 0.0,
            seed: 1,
            quality_drop_at: None,
            monitor_only: false,
            stop_after: None,
            once: false,
            release_after: Duration::from_millis(500),
            thresholds: [0.5, 0.8, 0.98],
            record: false,
        }
    }

    fn validate(&self) -> Result<(), Error> {
        let ms = self.cycle.as_secs_f64() * 1e3;
        if !(1.0..=10.0).contains(&ms) {
            return Err(Error::Invalid(format!(
                "FRI cycle {ms} ms: must be 1 to 10 ms"
            )));
        }
        if !(0.0..1.0).contains(&self.drop) {
            return Err(Error::Invalid(format!(
                "packet loss {}: must be a fraction in [0, 1)",
                self.drop
            )));
        }
        if let Err(v) = primo_robot::Robot::lwr4().check_limits([(0.0, &self.start)]) {
            return Err(Error::Invalid(format!("start position: {v}")));
        }
        let [bad, ok, perfect] = self.thresholds;
        if !(0.0 <= bad && bad <= ok && ok <= perfect && perfect <= 1.0) {
            return Err(Error::Invalid(format!(
                "quality thresholds {:?}: must rise within [0, 1]",
                self.thresholds
            )));
        }
        if self.release_after < self.cycle {
            return Err(Error::Invalid(
                "release time must be at least one cycle".into(),
            ));
        }
        Ok(())
    }

    /// The cell the arm pours in: the standard one with `glass`, stepped
    /// in equal steps of at most [`MAX_DT`] within each cycle.
    pub fn cell_config(&self) -> CellConfig {
        let cycle = self.cycle.as_secs_f64();
        let mut cell = CellConfig::standard(self.glass);
        cell.dt = cycle / (cycle / MAX_DT).ceil().max(1.0);
        cell
    }

    /// The cell at power-on, and after an operator's reset: `bottle`
    /// litres in the bottle, an empty glass on the tared scale, the
    /// scale's noise from `seed`.
    pub fn fresh_cell(&self) -> Result<Cell, Error> {
        Cell::new(&self.cell_config(), self.bottle, self.seed)
    }
}

/// The simulated cell, shared with other instruments of the process.
#[derive(Debug, Clone)]
pub struct CellHandle(Arc<Mutex<Cell>>);

impl CellHandle {
    /// The cell, for as long as the guard lives (the KRC waits for it).
    pub fn lock(&self) -> MutexGuard<'_, Cell> {
        // A panic elsewhere while holding the lock leaves a consistent
        // cell (every step completes before it returns): carry on.
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }
}

/// A scale under the cell's glass weighs what is on the pan.
impl LoadSource for CellHandle {
    fn grams(&self) -> f64 {
        self.lock().load_on_pan()
    }
}

/// One cycle as the KRC saw it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CycleRecord {
    /// Time since power-on, s.
    pub t: f64,
    /// Interface state sent.
    pub state: State,
    /// Quality sent.
    pub quality: Quality,
    /// The measurement was sent (not lost).
    pub sent: bool,
    /// An answer came back on time.
    pub answered: bool,
    /// The commanded joint position after the cycle.
    pub target: [f64; JOINTS],
    /// The measured joint position after the cycle.
    pub measured: [f64; JOINTS],
}

/// What happened while the KRC ran.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct KrcReport {
    /// Cycles run.
    pub cycles: u64,
    /// Measurement packets sent.
    pub sent: u64,
    /// Measurement packets lost on purpose.
    pub dropped: u64,
    /// Cycles answered on time.
    pub answered: u64,
    /// Cycles not answered on time (`missCounter`).
    pub missed: u64,
    /// Answers with the wrong `reflSeqCount` or after their cycle.
    pub stale: u64,
    /// Datagrams that are not command packets.
    pub malformed: u64,
    /// Measurements sent more than [`LATE_SEND`] of a cycle after they
    /// were due: the simulator's own lateness (a real KRC sends on a
    /// real-time clock), which leaves the remote less time to answer.
    pub late_sends: u64,
    /// The latest send after it was due, s.
    pub max_send_delay: f64,
    /// Commands in command mode faster than the velocity limits.
    pub too_fast: u64,
    /// Commands in command mode beyond the position limits (clamped).
    pub beyond_limits: u64,
    /// Cycles in command mode.
    pub command_cycles: u64,
    /// When command mode was first entered, s.
    pub entered_command: Option<f64>,
    /// When it was last left, s.
    pub left_command: Option<f64>,
    /// Largest distance of the measured position from the start, rad.
    pub max_excursion: f64,
    /// The measured joint position at the end.
    pub measured: [f64; JOINTS],
    /// Why the first few malformed datagrams were rejected.
    pub rejections: Vec<String>,
    /// Every cycle, if recording.
    pub log: Vec<CycleRecord>,
}

impl KrcReport {
    /// Notes a measurement sent `delay` after it was due.
    fn sent_after(&mut self, delay: Duration, cycle: Duration) {
        self.late_sends += u64::from(delay > cycle.mul_f64(LATE_SEND));
        self.max_send_delay = self.max_send_delay.max(delay.as_secs_f64());
    }
}

/// The simulated KRC, bound and ready to run.
#[derive(Debug)]
pub struct SimKrc {
    socket: UdpSocket,
    cfg: KrcConfig,
    cell_cfg: CellConfig,
    cell: CellHandle,
    cell_steps: usize,
}

/// The communication statistics over the last [`STAT_WINDOW`] cycles.
#[derive(Debug, Default)]
struct Window {
    /// Answer latency of each cycle, `None` if missed.
    cycles: VecDeque<Option<f64>>,
    /// On-time answers since power-on.
    answered: u64,
}

impl Window {
    fn push(&mut self, latency: Option<f64>) {
        if self.cycles.len() == STAT_WINDOW {
            self.cycles.pop_front();
        }
        self.cycles.push_back(latency);
        self.answered += u64::from(latency.is_some());
    }

    fn answer_rate(&self) -> f64 {
        let n = self.cycles.len();
        if n == 0 {
            return 0.0;
        }
        self.cycles.iter().filter(|c| c.is_some()).count() as f64 / n as f64
    }

    /// Mean and spread (max − min) of the latencies.
    fn latency(&self) -> (f64, f64) {
        let l: Vec<f64> = self.cycles.iter().flatten().copied().collect();
        if l.is_empty() {
            return (0.0, 0.0);
        }
        let mean = l.iter().sum::<f64>() / l.len() as f64;
        let (lo, hi) = l
            .iter()
            .fold((f64::INFINITY, f64::NEG_INFINITY), |(a, b), x| {
                (a.min(*x), b.max(*x))
            });
        (mean, hi - lo)
    }

    /// The quality: the answer rate against `[bad, ok, perfect]`, capped
    /// by the ramp after opening.
    fn quality(&self, [bad, ok, perfect]: [f64; 3]) -> Quality {
        let rate = self.answer_rate();
        let by_rate = if rate >= perfect {
            Quality::Perfect
        } else if rate >= ok {
            Quality::Ok
        } else if rate >= bad {
            Quality::Bad
        } else {
            Quality::Unacceptable
        };
        let ramp = if self.answered < RAMP {
            Quality::Bad
        } else if self.answered < 2 * RAMP {
            Quality::Ok
        } else {
            Quality::Perfect
        };
        by_rate.min(ramp)
    }
}

/// A pose as FRI's 3×4 row-major `[R | p]`.
fn pose_row_major(p: &Pose) -> [f32; 12] {
    std::array::from_fn(|k| {
        let (i, j) = (k / 4, k % 4);
        let v = if j == 3 {
            p.position[i]
        } else {
            p.rotation[i][j]
        };
        v as f32
    })
}

impl SimKrc {
    /// Checks `cfg`, fills the cell's bottle and binds an ephemeral UDP
    /// port (the KRC's own address; the remote answers to it).
    pub fn new(cfg: KrcConfig) -> Result<SimKrc, Error> {
        cfg.validate()?;
        let cell_cfg = cfg.cell_config();
        let cell_steps = (cfg.cycle.as_secs_f64() / cell_cfg.dt).round() as usize;
        let cell = cfg.fresh_cell()?;
        let any: SocketAddr = if cfg.remote.is_ipv4() {
            ([0, 0, 0, 0], 0).into()
        } else {
            ([0u16; 8], 0).into()
        };
        let socket =
            UdpSocket::bind(any).map_err(|e| Error::Io(format!("cannot bind UDP {any}: {e}")))?;
        Ok(SimKrc {
            socket,
            cfg,
            cell_cfg,
            cell: CellHandle(Arc::new(Mutex::new(cell))),
            cell_steps,
        })
    }

    /// The shared cell.
    pub fn cell(&self) -> CellHandle {
        self.cell.clone()
    }

    /// Serves the cell's scale as an MT-SICS device on a new
    /// pseudo-terminal ([`PtyServer`], not thread-safe to start): the
    /// cell's scale model with the noise from the KRC's seed, weighing the
    /// cell's pan in wall-clock time.
    pub fn serve_scale(&self) -> Result<PtyServer, Error> {
        let model = self.cell_cfg.scale;
        let device = Device::new(
            model,
            self.cfg.seed,
            self.cell(),
            DeviceConfig::for_model(&model),
        )?;
        PtyServer::start(device)
            .map_err(|e| Error::Io(format!("cannot serve the scale on a pseudo-terminal: {e}")))
    }

    /// Serves the cell's scale as a bare load cell ([`LoadCellServer`],
    /// not thread-safe to start): raw counts of the pan's load on a new
    /// pseudo-terminal, the noise from the KRC's seed.
    pub fn serve_load_cell(&self) -> Result<LoadCellServer, Error> {
        let model = LoadCellModel {
            scale: self.cell_cfg.scale,
            ..LoadCellModel::default()
        };
        LoadCellServer::start(model, self.cfg.seed, self.cell()).map_err(|e| {
            Error::Io(format!(
                "cannot serve the load cell on a pseudo-terminal: {e}"
            ))
        })
    }

    /// The KRC's own UDP address.
    pub fn local_addr(&self) -> Result<SocketAddr, Error> {
        self.socket
            .local_addr()
            .map_err(|e| Error::Io(format!("KRC socket: {e}")))
    }

    /// Runs until `stop` is set, `stop_after` passes, or (with `once`) a
    /// command session ends. Errors are socket failures.
    pub fn run(self, stop: &AtomicBool) -> Result<KrcReport, Error> {
        let cfg = self.cfg;
        let mut rng = Xoshiro128PlusPlus::seed_from_u64(cfg.seed);
        let drop_below = (cfg.drop * f64::from(u32::MAX)) as u32;
        let release = (cfg.release_after.as_secs_f64() / cfg.cycle.as_secs_f64()).ceil() as u64;
        let mut report = KrcReport::default();
        let mut window = Window::default();
        let mut normal = StandardNormal::new();
        // The bottle's centre in the flange frame: where its weight acts.
        let half = Pose::translation(0.0, 0.0, 0.5 * self.cell_cfg.bottle.length);
        let lever = self.cell_cfg.grasp.then(&half).position;
        let mut robot = Robot::new(cfg.start, cfg.cycle.as_secs_f64(), lever);
        let mut liquid = self.liquid(&self.cell.lock());
        self.socket.set_nonblocking(true).map_err(socket_error)?;
        let (mut anchor, mut anchor_k) = (Instant::now(), 0u64);
        for k in 0u64.. {
            let t = k as f64 * robot.cycle;
            let past = |d: Option<Duration>| d.is_some_and(|d| t >= d.as_secs_f64());
            if stop.load(Ordering::Relaxed) || past(cfg.stop_after) {
                break;
            }
            let quality = if past(cfg.quality_drop_at) {
                Quality::Bad
            } else {
                window.quality(cfg.thresholds)
            };
            match robot.state {
                State::Command if k.saturating_sub(robot.last_answer) > release => {
                    robot.switch(State::Monitor);
                    report.left_command = Some(t);
                    if cfg.once {
                        break;
                    }
                }
                State::Monitor
                    if !cfg.monitor_only && quality >= Quality::Ok && robot.echoes >= HANDSHAKE =>
                {
                    robot.switch(State::Command);
                    report.entered_command.get_or_insert(t);
                }
                _ => {}
            }
            let seq = k as u16;
            let mut m = robot.measurement(seq, t, quality, &window, report.missed);
            let noise = std::array::from_fn(|i| {
                let sigma = if i < 3 { FORCE_NOISE } else { MOMENT_NOISE };
                sigma * f64::from(normal.sample(&mut rng))
            });
            (m.data.est_ext_tcp_ft, m.data.est_ext_jnt_trq) = robot.external_load(liquid, noise);
            let sent = rng.next_u32() >= drop_below;
            let sent_at = Instant::now();
            let due = anchor + cfg.cycle.mul_f64((k - anchor_k) as f64);
            report.sent_after(sent_at.saturating_duration_since(due), cfg.cycle);
            if sent {
                self.socket
                    .send_to(&m.encode(), cfg.remote)
                    .map_err(socket_error)?;
                report.sent += 1;
            } else {
                report.dropped += 1;
            }
            let deadline = anchor + cfg.cycle.mul_f64((k - anchor_k + 1) as f64);
            let expected = sent.then_some(seq);
            let answer = self.answer(expected, sent_at, deadline, &mut report)?;
            window.push(answer.map(|(_, latency)| latency));
            match answer {
                Some((c, _)) => {
                    report.answered += 1;
                    robot.take(&c, k, &mut report);
                }
                None => {
                    report.missed += 1;
                    robot.echoes = 0;
                }
            }
            let before = robot.measured;
            robot.servo();
            liquid = self.step_cell(before, robot.measured);
            report.cycles += 1;
            report.command_cycles += u64::from(robot.state == State::Command);
            let excursion = (0..JOINTS)
                .map(|j| (robot.measured[j] - cfg.start[j]).abs())
                .fold(0.0, f64::max);
            report.max_excursion = report.max_excursion.max(excursion);
            if cfg.record {
                report.log.push(CycleRecord {
                    t,
                    state: robot.state,
                    quality,
                    sent,
                    answered: answer.is_some(),
                    target: robot.target,
                    measured: robot.measured,
                });
            }
            // Fell behind (a loaded machine): skip ahead rather than burst.
            let now = Instant::now();
            if now > deadline + cfg.cycle {
                anchor = now;
                anchor_k = k + 1;
            }
        }
        report.measured = robot.measured;
        Ok(report)
    }

    /// Reads datagrams until `deadline`; returns the answer to `expected`
    /// (the measurement's `sendSeqCount`, if it was sent) and its latency,
    /// counting stale answers and malformed datagrams in `report`.
    fn answer(
        &self,
        expected: Option<u16>,
        sent_at: Instant,
        deadline: Instant,
        report: &mut KrcReport,
    ) -> Result<Option<(Command, f64)>, Error> {
        let mut buf = [0u8; 2048];
        let mut answer = None;
        // Poll rather than block with a timeout: socket timeouts round up
        // to the kernel's tick (4 ms at 250 Hz), sleeps do not.
        loop {
            match self.socket.recv_from(&mut buf) {
                Ok((n, _)) => {
                    match buf.get(..n).map(Command::parse) {
                        Some(Ok(c))
                            if answer.is_none() && Some(c.head.refl_seq_count) == expected =>
                        {
                            answer = Some((c, sent_at.elapsed().as_secs_f64()));
                        }
                        Some(Ok(_)) => report.stale += 1,
                        Some(Err(e)) => {
                            report.malformed += 1;
                            if report.rejections.len() < 10 {
                                report.rejections.push(e.to_string());
                            }
                        }
                        None => {}
                    }
                    continue;
                }
                Err(e) if transient(&e) => {}
                Err(e) => return Err(socket_error(e)),
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(answer);
            }
            let left = deadline - now;
            std::thread::sleep(if answer.is_some() {
                left
            } else {
                left.min(POLL)
            });
        }
    }

    /// Steps the cell through the cycle, the joints interpolated from
    /// `from` to `to`; the liquid left in the bottle, kg.
    fn step_cell(&self, from: [f64; JOINTS], to: [f64; JOINTS]) -> f64 {
        let mut cell = self.cell.lock();
        for i in 1..=self.cell_steps {
            let s = i as f64 / self.cell_steps as f64;
            cell.step_joints(&std::array::from_fn(|j| from[j] + (to[j] - from[j]) * s));
        }
        self.liquid(&cell)
    }

    /// The liquid in the cell's bottle, kg.
    fn liquid(&self, cell: &Cell) -> f64 {
        cell.totals().bottle * 1e-3 * self.cell_cfg.density
    }
}

fn socket_error(e: std::io::Error) -> Error {
    Error::Io(format!("KRC socket: {e}"))
}

/// The robot side's state from cycle to cycle.
#[derive(Debug)]
struct Robot {
    arm: Arm,
    cycle: f64,
    state: State,
    /// Measured joint positions.
    measured: [f64; JOINTS],
    /// Commanded joint positions.
    target: [f64; JOINTS],
    /// The KRL program's part of the commanded position (`cmdJntPos`).
    krl: [f64; JOINTS],
    /// Consecutive on-time echoes in monitor mode.
    echoes: usize,
    /// The cycle of the last on-time answer.
    last_answer: u64,
    /// The last answer's `sendSeqCount`.
    refl: u16,
    /// Where the held load's weight acts, in the flange frame, m.
    lever: [f64; 3],
}

impl Robot {
    fn new(start: [f64; JOINTS], cycle: f64, lever: [f64; 3]) -> Self {
        Robot {
            arm: Arm::new(primo_robot::Robot::lwr4()),
            cycle,
            state: State::Monitor,
            measured: start,
            target: start,
            krl: start,
            echoes: 0,
            last_answer: 0,
            refl: 0,
            lever,
        }
    }

    /// `friStart` / `friStop`: the KRL program's position becomes the
    /// commanded one, the remote's offset zero.
    fn switch(&mut self, state: State) {
        self.state = state;
        self.krl = self.target;
    }

    fn measurement(
        &self,
        seq: u16,
        t: f64,
        quality: Quality,
        window: &Window,
        missed: u64,
    ) -> Measurement {
        let mut m = Measurement::default();
        m.head.send_seq_count = seq;
        m.head.refl_seq_count = self.refl;
        let (latency, jitter) = window.latency();
        let rate = window.answer_rate();
        m.intf.timestamp = t as f32;
        m.intf.state = self.state;
        m.intf.quality = quality;
        m.intf.desired_msr_sample_time = self.cycle as f32;
        m.intf.desired_cmd_sample_time = self.cycle as f32;
        m.intf.stat.answer_rate = rate as f32;
        m.intf.stat.miss_rate = (1.0 - rate) as f32;
        m.intf.stat.latency = latency as f32;
        m.intf.stat.jitter = jitter as f32;
        m.intf.stat.miss_counter = missed as u32;
        m.robot.power = 0x7f;
        m.robot.control = 1;
        m.robot.temperature = [30.0; JOINTS];
        let d = &mut m.data;
        d.msr_jnt_pos = self.measured.map(|v| v as f32);
        d.msr_cart_pos = pose_row_major(&self.arm.forward(&self.measured));
        d.cmd_jnt_pos = self.krl.map(|v| v as f32);
        d.cmd_jnt_pos_fri_offset = std::array::from_fn(|j| (self.target[j] - self.krl[j]) as f32);
        d.cmd_cart_pos = pose_row_major(&self.arm.forward(&self.target));
        let jacobian = self.arm.jacobian(&self.measured);
        d.jacobian = std::array::from_fn(|k| jacobian[k / JOINTS][k % JOINTS] as f32);
        m
    }

    /// `estExtTcpFT` and `estExtJntTrq` with `mass` kg hanging at the
    /// lever: its weight and moment about the flange in the flange frame
    /// plus `noise` (force N, moment N·m), and `Jᵀ` times that wrench.
    fn external_load(&self, mass: f64, noise: [f64; 6]) -> ([f32; 6], [f32; JOINTS]) {
        let pose = self.arm.forward(&self.measured);
        let r = pose.rotation;
        // The weight (0, 0, −mg) in the base frame, seen from the flange.
        let force: [f64; 3] = std::array::from_fn(|i| -mass * G * r[2][i]);
        let l = self.lever;
        let moment = [
            l[1] * force[2] - l[2] * force[1],
            l[2] * force[0] - l[0] * force[2],
            l[0] * force[1] - l[1] * force[0],
        ];
        let tcp: [f64; 6] =
            std::array::from_fn(|i| noise[i] + if i < 3 { force[i] } else { moment[i - 3] });
        // Back to the base frame, where the Jacobian is.
        let base: [f64; 6] = std::array::from_fn(|k| {
            let (v, i) = (&tcp[3 * (k / 3)..], k % 3);
            (0..3).map(|c| r[i][c] * v[c]).sum()
        });
        let jacobian = self.arm.jacobian(&self.measured);
        let torques =
            std::array::from_fn(|j| (0..6).map(|k| jacobian[k][j] * base[k]).sum::<f64>() as f32);
        (tcp.map(|v| v as f32), torques)
    }

    /// An on-time answer in cycle `k`: in command mode its `jntPos` is the
    /// new commanded position (clamped to the position limits; too fast or
    /// too far counted); in monitor mode it counts towards the handshake if
    /// it echoes the commanded position.
    fn take(&mut self, c: &Command, k: u64, report: &mut KrcReport) {
        self.last_answer = k;
        self.refl = c.head.send_seq_count;
        let wanted = c.cmd.jnt_pos.map(f64::from);
        let moves = c.cmd.cmd_flags & flags::JNTPOS != 0;
        let limits = self.arm.robot();
        let velocity = limits.velocity_limits_deg.map(f64::to_radians);
        let position = limits.position_limits_deg.map(f64::to_radians);
        match self.state {
            State::Command if moves => {
                let step = |j: usize| (wanted[j] - self.target[j]).abs();
                if (0..JOINTS).any(|j| step(j) > velocity[j] * self.cycle * 1.001) {
                    report.too_fast += 1;
                }
                if (0..JOINTS).any(|j| wanted[j].abs() > position[j]) {
                    report.beyond_limits += 1;
                }
                self.target = std::array::from_fn(|j| wanted[j].clamp(-position[j], position[j]));
            }
            State::Monitor => {
                let echo = moves && (0..JOINTS).all(|j| (wanted[j] - self.target[j]).abs() < 1e-4);
                self.echoes = if echo { self.echoes + 1 } else { 0 };
            }
            _ => {}
        }
    }

    /// One cycle of the joint servo: a first-order lag of [`SERVO_LAG`]
    /// toward the commanded position, no faster than the velocity limits.
    fn servo(&mut self) {
        let follow = 1.0 - (-self.cycle / SERVO_LAG).exp();
        for (j, limit) in self.arm.robot().velocity_limits_deg.iter().enumerate() {
            let max = limit.to_radians() * self.cycle;
            self.measured[j] += ((self.target[j] - self.measured[j]) * follow).clamp(-max, max);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const THRESHOLDS: [f64; 3] = [0.5, 0.8, 0.98];

    #[test]
    fn quality_ramps_up_with_answers_and_falls_with_misses() {
        let mut w = Window::default();
        assert_eq!(w.quality(THRESHOLDS), Quality::Unacceptable);
        let mut seen = Vec::new();
        for _ in 0..2 * RAMP {
            w.push(Some(1e-4));
            seen.push(w.quality(THRESHOLDS));
        }
        seen.dedup();
        assert_eq!(seen, [Quality::Bad, Quality::Ok, Quality::Perfect]);
        // One answer in 20 missing: OK, not PERFECT.
        for i in 0..STAT_WINDOW {
            w.push((i % 20 != 0).then_some(2e-4));
        }
        assert_eq!(w.quality(THRESHOLDS), Quality::Ok);
        assert!((w.answer_rate() - 0.95).abs() < 1e-12);
        let (latency, jitter) = w.latency();
        assert!((latency - 2e-4).abs() < 1e-15 && jitter == 0.0);
        // Silence: down to UNACCEPTABLE.
        for _ in 0..40 {
            w.push(None);
        }
        assert!((w.answer_rate() - 0.57).abs() < 1e-12);
        assert_eq!(w.quality(THRESHOLDS), Quality::Bad);
        for _ in 0..60 {
            w.push(None);
        }
        assert_eq!(w.quality(THRESHOLDS), Quality::Unacceptable);
    }

    #[test]
    fn sends_later_than_a_quarter_cycle_count_as_late() {
        let cycle = Duration::from_millis(2);
        let mut report = KrcReport::default();
        report.sent_after(Duration::from_micros(20), cycle);
        report.sent_after(Duration::from_micros(500), cycle);
        assert_eq!(report.late_sends, 0);
        report.sent_after(Duration::from_micros(1500), cycle);
        report.sent_after(Duration::from_micros(700), cycle);
        assert_eq!(report.late_sends, 2);
        assert!((report.max_send_delay - 1.5e-3).abs() < 1e-12);
    }

    #[test]
    fn the_servo_lags_and_respects_the_velocity_limits() {
        let mut robot = Robot::new([0.0; JOINTS], 0.002, [0.0; 3]);
        robot.target = [1.0, 1e-3, 0.0, 0.0, 0.0, 0.0, 0.0];
        robot.servo();
        // Joint 1 at its 110 °/s limit; joint 2 a third of the way (lag).
        assert!((robot.measured[0] - 110f64.to_radians() * 0.002).abs() < 1e-12);
        let follow = 1.0 - (-0.002f64 / SERVO_LAG).exp();
        assert!((robot.measured[1] - 1e-3 * follow).abs() < 1e-15);
        for _ in 0..1000 {
            robot.servo();
        }
        assert!((0..JOINTS).all(|j| (robot.measured[j] - robot.target[j]).abs() < 1e-12));
    }

    #[test]
    fn the_external_load_is_the_weight_at_the_lever() {
        let q = crate::expert::rest_configuration(0.3);
        let lever = [0.01, -0.02, 0.16];
        let mut robot = Robot::new(q, 0.002, lever);
        robot.measured = q;
        let mass = 0.4;
        let (ft, torques) = robot.external_load(mass, [0.0; 6]);
        // The force: mg straight down, in the flange frame.
        let down = robot.arm.forward(&q).rotation[2];
        for i in 0..3 {
            assert!(
                (f64::from(ft[i]) + mass * G * down[i]).abs() < 1e-5,
                "{ft:?}"
            );
        }
        // The joint torques are the weight's virtual work: τ_j = −mg ∂z/∂q_j
        // of the point where it acts.
        let height = |q: &[f64; JOINTS]| {
            let at = robot
                .arm
                .forward(q)
                .then(&Pose::translation(lever[0], lever[1], lever[2]));
            at.position[2]
        };
        let h = 1e-6;
        for j in 0..JOINTS {
            let (mut plus, mut minus) = (q, q);
            plus[j] += h;
            minus[j] -= h;
            let expected = -mass * G * (height(&plus) - height(&minus)) / (2.0 * h);
            assert!(
                (f64::from(torques[j]) - expected).abs() < 1e-4,
                "joint {}: {} vs {expected}",
                j + 1,
                torques[j]
            );
        }
        // Noise adds in the flange frame.
        let (noisy, _) = robot.external_load(mass, [0.1, 0.0, 0.0, 0.0, 0.0, -0.2]);
        assert!((noisy[0] - ft[0] - 0.1).abs() < 1e-6 && (noisy[5] - ft[5] + 0.2).abs() < 1e-6);
    }

    #[test]
    fn bad_settings_are_refused() {
        let remote = SocketAddr::from(([127, 0, 0, 1], 49938));
        let mut cfg = KrcConfig::new(remote);
        cfg.cycle = Duration::from_millis(20);
        assert_eq!(
            SimKrc::new(cfg).unwrap_err().to_string(),
            "FRI cycle 20 ms: must be 1 to 10 ms"
        );
        let mut cfg = KrcConfig::new(remote);
        cfg.drop = 1.0;
        assert!(
            SimKrc::new(cfg)
                .unwrap_err()
                .to_string()
                .starts_with("packet loss 1")
        );
        let mut cfg = KrcConfig::new(remote);
        cfg.start[1] = 2.2;
        assert!(
            SimKrc::new(cfg)
                .unwrap_err()
                .to_string()
                .starts_with("start position: joint 2")
        );
        let mut cfg = KrcConfig::new(remote);
        cfg.thresholds = [0.9, 0.8, 0.98];
        assert!(SimKrc::new(cfg).is_err());
    }
}
