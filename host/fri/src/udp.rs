//! The UDP adapter of a [`Session`]: [`play`] binds nothing itself, reads
//! measurements from a socket, answers each with the session's command, and
//! watches the time (silence, start and hold timeouts).
//!
//! The loop runs on a thread of its own and a spare on another CPU, with
//! real-time scheduling and locked memory where the OS allows them
//! ([`crate::realtime`]); inside the cycle nothing allocates (but the
//! message of a malformed datagram, and the session's plan once, as
//! command mode starts) and nothing blocks but the wait for the next
//! datagram and the other thread's turn. What it does is reported as
//! [`Event`]s to the caller's thread.

use std::fmt;
use std::net::{SocketAddr, UdpSocket};
use std::sync::mpsc::{SyncSender, sync_channel};
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use crate::path::FriPath;

use crate::packet::{Measurement, Quality, State};
use crate::realtime::{self, Realtime};
use crate::session::{Phase, Session, SessionConfig, Stop, Tracking};

/// A socket failed.
#[derive(Debug, thiserror::Error)]
pub enum SocketError {
    /// Binding the local address failed.
    #[error("cannot bind UDP {addr}: {source}")]
    Bind {
        /// The address.
        addr: SocketAddr,
        /// Why.
        source: std::io::Error,
    },
    /// Reading or writing failed.
    #[error("FRI socket: {0}")]
    Io(#[from] std::io::Error),
}

/// How a [`play`] run ended.
#[derive(Debug, Clone, PartialEq)]
pub enum Ended {
    /// Every setpoint streamed and settled.
    Completed,
    /// The session stopped (it held position for a while before [`play`]
    /// returned).
    Stopped(Stop),
    /// No valid packet for longer than the cycle timeout while streaming.
    Silent {
        /// How long nothing came.
        after: Duration,
    },
    /// The robot never became commandable within the start timeout.
    NeverCommanded {
        /// How long primo waited.
        after: Duration,
        /// The last measurement's state and quality, if any came.
        last: Option<(State, Quality)>,
    },
}

impl fmt::Display for Ended {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Ended::Completed => f.write_str("completed"),
            Ended::Stopped(why) => write!(f, "stopped: {why}; held position"),
            Ended::Silent { after } => write!(
                f,
                "stopped: no packet from the KRC for {:.3} s; the robot holds its last commanded position",
                after.as_secs_f64()
            ),
            Ended::NeverCommanded {
                after,
                last: Some((state, quality)),
            } => write!(
                f,
                "the robot did not become commandable within {:.1} s (last: state {state:?}, \
                 quality {quality:?}, needs Command with quality >= Ok and all drives powered; \
                 friStart on the KRC?); nothing was moved",
                after.as_secs_f64()
            ),
            Ended::NeverCommanded { after, last: None } => write!(
                f,
                "no FRI packet from a KRC within {:.1} s (is the KRC sending to this address \
                 and port?); nothing was moved",
                after.as_secs_f64()
            ),
        }
    }
}

/// What a [`play`] run is doing, reported as it happens.
#[derive(Debug, Clone, PartialEq)]
pub enum Event {
    /// The loop's thread started with what the OS granted it; short of
    /// [`Realtime::is_full`], a busy machine may make answers late.
    Realtime(Realtime),
    /// The first measurement came from the KRC (waiting for command mode).
    Krc(SocketAddr),
    /// The robot is commandable: holding still, weighing what it holds.
    Weighing {
        /// Setpoints of the standstill.
        setpoints: usize,
    },
    /// Moving to the trajectory's start.
    Approaching {
        /// Setpoints of the approach.
        setpoints: usize,
    },
    /// Streaming: at the trajectory's start, then about every
    /// [`PROGRESS`] while streaming.
    Streaming {
        /// Setpoints sent so far (the standstill and approach included).
        sent: usize,
        /// Setpoints planned in all.
        planned: usize,
    },
    /// Every setpoint sent: holding the end, weighing again.
    Settling,
}

/// How often [`Event::Streaming`] reports progress.
pub const PROGRESS: Duration = Duration::from_secs(1);

/// Events that may wait for the caller's thread; more are dropped (only
/// progress could be, and only if the caller stalls).
const EVENTS: usize = 64;

/// Timeouts of [`play`], and its thread's scheduling.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlayConfig {
    /// How the session moves.
    pub session: SessionConfig,
    /// Longest silence while streaming before stopping.
    pub cycle_timeout: Duration,
    /// Longest wait for the robot to become commandable.
    pub start_timeout: Duration,
    /// How long to keep answering (holding) after a stop.
    pub hold: Duration,
    /// Ask for real-time scheduling and locked memory ([`realtime::enter`]).
    pub realtime: bool,
}

impl Default for PlayConfig {
    /// 0.2 s cycle timeout, 60 s start timeout, hold 0.5 s after a stop,
    /// real-time where allowed.
    fn default() -> Self {
        PlayConfig {
            session: SessionConfig::default(),
            cycle_timeout: Duration::from_millis(200),
            start_timeout: Duration::from_secs(60),
            hold: Duration::from_millis(500),
            realtime: true,
        }
    }
}

/// What a [`play`] run did.
#[derive(Debug, Clone, PartialEq)]
pub struct PlayResult {
    /// How it ended.
    pub ended: Ended,
    /// Measured minus commanded positions while streaming.
    pub tracking: Tracking,
    /// The KRC's address (where the first valid packet came from).
    pub krc: Option<SocketAddr>,
    /// Measurements answered.
    pub answered: u64,
    /// Measurements missing from the KRC's `sendSeqCount` sequence.
    pub gaps: u64,
    /// Setpoints planned: holding to weigh, the approach and the
    /// trajectory.
    pub planned: usize,
    /// Setpoints holding still to weigh before the approach.
    pub weighing: usize,
    /// Setpoints of the approach.
    pub approach: usize,
    /// Setpoints sent.
    pub sent: usize,
    /// The FRI cycle, s (0 if streaming never started).
    pub cycle: f64,
    /// Datagrams rejected (malformed, or not from the KRC).
    pub rejected: u64,
    /// Why the first few were rejected.
    pub rejections: Vec<String>,
    /// Measurements queued before the run started, discarded unanswered
    /// (malformed datagrams among them count as rejected).
    pub stale: u64,
    /// The load the robot held standing still before and after the
    /// movement, N ([`Session::held_load`]; `None` if a standstill had
    /// too few measurements, e.g. after a stop).
    pub load: Option<[f64; 2]>,
    /// Measurements averaged into `load`: before, after.
    pub load_samples: [usize; 2],
}

/// How many rejection messages a [`PlayResult`] keeps.
const KEEP_REJECTIONS: usize = 10;

impl PlayResult {
    /// Nothing done yet.
    fn new() -> Self {
        PlayResult {
            ended: Ended::Completed,
            tracking: Tracking::default(),
            krc: None,
            answered: 0,
            gaps: 0,
            planned: 0,
            weighing: 0,
            approach: 0,
            sent: 0,
            cycle: 0.0,
            rejected: 0,
            rejections: Vec::new(),
            stale: 0,
            load: None,
            load_samples: [0; 2],
        }
    }

    fn reject(&mut self, why: String) {
        self.rejected += 1;
        if self.rejections.len() < KEEP_REJECTIONS {
            self.rejections.push(why);
        }
    }
}

/// Binds the local FRI address (see [`crate::parse_robot`]).
pub fn bind(addr: SocketAddr) -> Result<UdpSocket, SocketError> {
    UdpSocket::bind(addr).map_err(|source| SocketError::Bind { addr, source })
}

/// Streams `path` to the KRC that sends to `socket`, answering every
/// measurement to its sender, until the session is done, stops, or a
/// timeout passes; `on_event` hears what it is doing, on the calling
/// thread. Errors are socket failures only.
///
/// The loop runs on a thread of its own and a spare, pinned to two CPUs
/// where the process may use two: both wake for every datagram, and the
/// first to take it answers. A virtual machine's CPU may be taken away
/// for milliseconds by its host, and no priority within the guest wins it
/// back; the other CPU answers meanwhile.
///
/// One socket serves any number of runs: the measurements that queued up
/// while nobody answered (between runs, the KRC sends on) are discarded
/// first, as their state and quality are past. The KRC has meanwhile
/// counted its packets unanswered and, after its release time, fallen
/// back to monitor mode: the run starts with the handshake again.
pub fn play(
    socket: &UdpSocket,
    path: &FriPath,
    cfg: &PlayConfig,
    on_event: &mut dyn FnMut(Event),
) -> Result<PlayResult, SocketError> {
    socket.set_nonblocking(true)?;
    let shared = Mutex::new(Loop::new(path, cfg.session));
    let served = serve_on_threads(socket, &shared, cfg, on_event);
    socket.set_nonblocking(false)?;
    served?;
    let state = shared.into_inner().map_err(|_| panicked())?;
    Ok(state.finish())
}

/// Runs the loop on its thread and the spare until both end.
fn serve_on_threads(
    socket: &UdpSocket,
    shared: &Mutex<Loop>,
    cfg: &PlayConfig,
    on_event: &mut dyn FnMut(Event),
) -> Result<(), SocketError> {
    let cpus = realtime::cpus(2);
    let (events, heard) = sync_channel(EVENTS);
    std::thread::scope(|scope| {
        let fri = std::thread::Builder::new()
            .name("fri".into())
            .spawn_scoped(scope, move || {
                if let Some(&cpu) = cpus.first() {
                    // Unpinned, it still answers: the pin only keeps the
                    // two threads apart.
                    let _ = realtime::pin(cpu);
                }
                let granted = cfg.realtime.then(realtime::enter);
                if let Some(granted) = &granted {
                    let _ = events.try_send(Event::Realtime(granted.clone()));
                }
                let served = lead(scope, socket, shared, cfg, events, cpus.get(1).copied());
                if let Some(granted) = &granted {
                    realtime::leave(granted);
                }
                served
            })?;
        // Until both threads end and drop their senders.
        heard.iter().for_each(&mut *on_event);
        joined(fri)
    })
}

/// The loop's first thread, set up: drops what queued up while nobody
/// answered (between runs, and while it was set up), starts the spare on
/// `spare_cpu` (if it cannot start, this thread serves alone) and serves.
fn lead<'scope>(
    scope: &'scope std::thread::Scope<'scope, '_>,
    socket: &'scope UdpSocket,
    shared: &'scope Mutex<Loop>,
    cfg: &'scope PlayConfig,
    events: SyncSender<Event>,
    spare_cpu: Option<usize>,
) -> Result<(), SocketError> {
    drain(socket, &mut lock(shared)?.result)?;
    let spare_events = events.clone();
    let spare = spare_cpu.and_then(|cpu| {
        std::thread::Builder::new()
            .name("fri-spare".into())
            .spawn_scoped(scope, move || {
                let _ = realtime::pin(cpu);
                // Granted as to the first thread (whose grant is reported);
                // the memory is locked already, for the whole process.
                if cfg.realtime {
                    let _ = realtime::schedule();
                }
                serve(socket, shared, cfg, &spare_events)
            })
            .ok()
    });
    let served = serve(socket, shared, cfg, &events);
    served.and(spare.map_or(Ok(()), joined))
}

/// A loop thread's outcome.
fn joined(
    thread: std::thread::ScopedJoinHandle<'_, Result<(), SocketError>>,
) -> Result<(), SocketError> {
    thread.join().unwrap_or_else(|_| Err(panicked()))
}

fn panicked() -> SocketError {
    std::io::Error::other("the FRI loop panicked").into()
}

/// Where a streaming session is, for its events.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
enum Stage {
    Waiting,
    Weighing,
    Approaching,
    Streaming,
    Settling,
}

impl Stage {
    fn of(session: &Session) -> Stage {
        let sent = session.sent();
        match session.phase() {
            Phase::Waiting => Stage::Waiting,
            _ if sent <= session.weigh_len() => Stage::Weighing,
            _ if sent <= session.weigh_len() + session.approach_len() => Stage::Approaching,
            _ if sent < session.planned() => Stage::Streaming,
            _ => Stage::Settling,
        }
    }

    /// The event on entering this stage.
    fn event(self, session: &Session) -> Option<Event> {
        match self {
            Stage::Waiting => None,
            Stage::Weighing => Some(Event::Weighing {
                setpoints: session.weigh_len(),
            }),
            Stage::Approaching => Some(Event::Approaching {
                setpoints: session.approach_len(),
            }),
            Stage::Streaming => Some(Event::Streaming {
                sent: session.sent(),
                planned: session.planned(),
            }),
            Stage::Settling => Some(Event::Settling),
        }
    }
}

/// The loop's state, shared by its threads.
struct Loop {
    session: Session,
    result: PlayResult,
    started: Instant,
    last_packet: Instant,
    last_seen: Option<(u16, State, Quality)>,
    stopped_at: Option<Instant>,
    stage: Stage,
    progress_at: Instant,
    /// The run ended (`result.ended` says how) or a thread failed: every
    /// thread stops.
    done: bool,
}

impl Loop {
    fn new(path: &FriPath, cfg: SessionConfig) -> Self {
        let started = Instant::now();
        Loop {
            session: Session::new(path, cfg),
            result: PlayResult::new(),
            started,
            last_packet: started,
            last_seen: None,
            stopped_at: None,
            stage: Stage::Waiting,
            progress_at: started,
            done: false,
        }
    }

    /// One turn: the events and timeouts due, then the datagram waiting,
    /// if no other thread took it.
    fn step(
        &mut self,
        socket: &UdpSocket,
        buf: &mut [u8],
        cfg: &PlayConfig,
        events: &SyncSender<Event>,
    ) -> Result<(), SocketError> {
        let now = Instant::now();
        self.report(now, events);
        if let Some(ended) = self.ended(now, cfg) {
            self.result.ended = ended;
            self.done = true;
            return Ok(());
        }
        match socket.recv_from(buf) {
            Ok((n, from)) => self.take(socket, buf.get(..n), from, events),
            Err(e) if transient(&e) => Ok(()),
            Err(e) => Err(e.into()),
        }
    }

    /// Sends the event of a new stage, or of progress while streaming.
    fn report(&mut self, now: Instant, events: &SyncSender<Event>) {
        let session = &self.session;
        let next = Stage::of(session);
        if next > self.stage && !session.is_finished() {
            self.stage = next;
            self.progress_at = now;
            if let Some(event) = next.event(session) {
                let _ = events.try_send(event);
            }
        } else if self.stage == Stage::Streaming && now - self.progress_at >= PROGRESS {
            self.progress_at = now;
            let _ = events.try_send(Event::Streaming {
                sent: session.sent(),
                planned: session.planned(),
            });
        }
    }

    /// How the run ended, if it has by `now`.
    fn ended(&mut self, now: Instant, cfg: &PlayConfig) -> Option<Ended> {
        let silent = now - self.last_packet;
        match self.session.phase() {
            Phase::Done => Some(Ended::Completed),
            Phase::Stopped { why, .. } => {
                let since = *self.stopped_at.get_or_insert(now);
                (now - since >= cfg.hold || silent > cfg.cycle_timeout)
                    .then(|| Ended::Stopped(why.clone()))
            }
            Phase::Waiting if now - self.started > cfg.start_timeout => {
                Some(Ended::NeverCommanded {
                    after: now - self.started,
                    last: self.last_seen.map(|(_, s, q)| (s, q)),
                })
            }
            Phase::Streaming if silent > cfg.cycle_timeout => Some(Ended::Silent { after: silent }),
            _ => None,
        }
    }

    /// Answers a datagram from `from` if it is the KRC's measurement.
    fn take(
        &mut self,
        socket: &UdpSocket,
        datagram: Option<&[u8]>,
        from: SocketAddr,
        events: &SyncSender<Event>,
    ) -> Result<(), SocketError> {
        let result = &mut self.result;
        if let Some(krc) = result.krc.filter(|k| *k != from) {
            result.reject(format!("datagram from {from} ignored: the KRC is {krc}"));
            return Ok(());
        }
        let m = match datagram.map(Measurement::parse) {
            Some(Ok(m)) => m,
            Some(Err(e)) => {
                result.reject(format!("from {from}: {e}"));
                return Ok(());
            }
            None => return Ok(()),
        };
        let command = self.session.answer(&m);
        socket.send_to(&command.encode(), from)?;
        if result.krc.is_none() {
            let _ = events.try_send(Event::Krc(from));
        }
        result.krc = Some(from);
        result.answered += 1;
        if let Some((seq, _, _)) = self.last_seen {
            // Forward steps only: a restarted or reordered sequence is no gap.
            let step = m.head.send_seq_count.wrapping_sub(seq);
            if (1..0x8000).contains(&step) {
                result.gaps += u64::from(step - 1);
            }
        }
        self.last_seen = Some((m.head.send_seq_count, m.intf.state, m.intf.quality));
        self.last_packet = Instant::now();
        Ok(())
    }

    /// The result of the ended run.
    fn finish(self) -> PlayResult {
        let (session, mut result) = (self.session, self.result);
        result.tracking = session.tracking();
        result.planned = session.planned();
        result.weighing = session.weigh_len();
        result.approach = session.approach_len();
        result.sent = session.sent();
        result.cycle = session.cycle();
        result.load = session.held_load();
        result.load_samples = session.held_samples();
        result
    }
}

/// The shared loop; if the other thread panicked in its turn, an error
/// (its state may be half-way): this thread stops too.
fn lock(shared: &Mutex<Loop>) -> Result<MutexGuard<'_, Loop>, SocketError> {
    shared.lock().map_err(|_| panicked())
}

/// One of the loop's threads: waits for a datagram and takes a turn, until
/// the run ends (or another thread fails).
fn serve(
    socket: &UdpSocket,
    shared: &Mutex<Loop>,
    cfg: &PlayConfig,
    events: &SyncSender<Event>,
) -> Result<(), SocketError> {
    // Wake now and then without datagrams, to see the timeouts.
    let wait = cfg
        .cycle_timeout
        .clamp(Duration::from_millis(1), Duration::from_millis(50));
    let mut buf = [0u8; 2048];
    loop {
        readable(socket, wait)?;
        let mut state = lock(shared)?;
        if state.done {
            return Ok(());
        }
        let turn = state.step(socket, &mut buf, cfg, events);
        if turn.is_err() {
            state.done = true;
        }
        turn?;
    }
}

/// Waits until a datagram is waiting on `socket` or `wait` passes. Every
/// thread waiting on it wakes (unlike in a blocking read, where the
/// kernel wakes one).
#[cfg(target_os = "linux")]
pub fn readable(socket: &UdpSocket, wait: Duration) -> std::io::Result<()> {
    use std::os::fd::AsRawFd;
    let mut fd = libc::pollfd {
        fd: socket.as_raw_fd(),
        events: libc::POLLIN,
        revents: 0,
    };
    let ms = libc::c_int::try_from(wait.as_millis()).unwrap_or(libc::c_int::MAX);
    // SAFETY: one valid pollfd for the duration of the call.
    match unsafe { libc::poll(&mut fd, 1, ms) } {
        -1 => match std::io::Error::last_os_error() {
            e if e.kind() == std::io::ErrorKind::Interrupted => Ok(()),
            e => Err(e),
        },
        _ => Ok(()),
    }
}

/// Reads every datagram queued on the non-blocking `socket` without
/// answering: the measurements count as stale, anything else as rejected.
fn drain(socket: &UdpSocket, result: &mut PlayResult) -> std::io::Result<()> {
    let mut buf = [0u8; 2048];
    loop {
        match socket.recv_from(&mut buf) {
            Ok((n, from)) => match buf.get(..n).map(Measurement::parse) {
                Some(Ok(_)) => result.stale += 1,
                Some(Err(e)) => result.reject(format!("from {from}: {e}")),
                None => {}
            },
            Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => break Ok(()),
            // A signal, or an ICMP error from an earlier answer: read on.
            Err(e) if transient(&e) => {}
            Err(e) => break Err(e),
        }
    }
}

/// Socket errors a UDP loop waits out: no datagram yet, a signal, or an
/// ICMP "port unreachable" from a peer that is not listening yet.
pub fn transient(e: &std::io::Error) -> bool {
    use std::io::ErrorKind::*;
    matches!(
        e.kind(),
        WouldBlock | TimedOut | Interrupted | ConnectionRefused
    )
}

/// Off Linux: a short sleep, then a look (as the simulated KRC polls).
#[cfg(not(target_os = "linux"))]
pub fn readable(_: &UdpSocket, _: Duration) -> std::io::Result<()> {
    std::thread::sleep(Duration::from_micros(100));
    Ok(())
}
