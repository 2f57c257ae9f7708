//! The UDP adapter of a [`Session`]: [`play`] binds nothing itself, reads
//! measurements from a socket, answers each with the session's command, and
//! watches the time (silence, start and hold timeouts).
//!
//! The loop runs on a thread of its own, with real-time scheduling and
//! locked memory where the OS allows them ([`crate::realtime`]); inside the
//! cycle nothing allocates (but the message of a malformed datagram) and
//! nothing blocks but the wait for the next datagram. What it does is
//! reported as [`Event`]s to the caller's thread.

use std::fmt;
use std::net::{SocketAddr, UdpSocket};
use std::sync::mpsc::{SyncSender, sync_channel};
use std::time::{Duration, Instant};

use primo_robot::JointPath;

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
/// One socket serves any number of runs: the measurements that queued up
/// while nobody answered (between runs, the KRC sends on) are discarded
/// first, as their state and quality are past. The KRC has meanwhile
/// counted its packets unanswered and, after its release time, fallen
/// back to monitor mode: the run starts with the handshake again.
pub fn play(
    socket: &UdpSocket,
    path: &JointPath,
    cfg: &PlayConfig,
    on_event: &mut dyn FnMut(Event),
) -> Result<PlayResult, SocketError> {
    let (events, heard) = sync_channel(EVENTS);
    std::thread::scope(|scope| {
        let fri = std::thread::Builder::new()
            .name("fri".into())
            .spawn_scoped(scope, move || {
                let granted = cfg.realtime.then(realtime::enter);
                if let Some(granted) = &granted {
                    let _ = events.try_send(Event::Realtime(granted.clone()));
                }
                let result = cycle(socket, path, cfg, &events);
                if let Some(granted) = &granted {
                    realtime::leave(granted);
                }
                result
            })?;
        // Until the loop ends and drops its sender.
        heard.iter().for_each(&mut *on_event);
        fri.join()
            .unwrap_or_else(|_| Err(std::io::Error::other("the FRI loop panicked").into()))
    })
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

/// The FRI loop proper, on its own thread.
fn cycle(
    socket: &UdpSocket,
    path: &JointPath,
    cfg: &PlayConfig,
    events: &SyncSender<Event>,
) -> Result<PlayResult, SocketError> {
    let poll = cfg.cycle_timeout.min(Duration::from_millis(50));
    socket.set_read_timeout(Some(poll.max(Duration::from_millis(1))))?;
    let mut session = Session::new(path, cfg.session);
    let mut result = PlayResult {
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
    };
    drain(socket, &mut result)?;
    let started = Instant::now();
    let mut last_packet = started;
    let mut last_seen: Option<(u16, State, Quality)> = None;
    let mut stopped_at: Option<Instant> = None;
    let mut stage = Stage::Waiting;
    let mut progress_at = started;
    let mut buf = [0u8; 2048];
    let ended = loop {
        let now = Instant::now();
        let next = Stage::of(&session);
        if next > stage && !session.is_finished() {
            stage = next;
            progress_at = now;
            if let Some(event) = stage.event(&session) {
                let _ = events.try_send(event);
            }
        } else if stage == Stage::Streaming && now - progress_at >= PROGRESS {
            progress_at = now;
            let _ = events.try_send(Event::Streaming {
                sent: session.sent(),
                planned: session.planned(),
            });
        }
        match session.phase() {
            Phase::Done => break Ended::Completed,
            Phase::Stopped { why, .. } => {
                let since = *stopped_at.get_or_insert(now);
                if now - since >= cfg.hold || now - last_packet > cfg.cycle_timeout {
                    break Ended::Stopped(why.clone());
                }
            }
            Phase::Waiting if now - started > cfg.start_timeout => {
                break Ended::NeverCommanded {
                    after: now - started,
                    last: last_seen.map(|(_, s, q)| (s, q)),
                };
            }
            Phase::Streaming if now - last_packet > cfg.cycle_timeout => {
                break Ended::Silent {
                    after: now - last_packet,
                };
            }
            _ => {}
        }
        let (n, from) = match socket.recv_from(&mut buf) {
            Ok(got) => got,
            Err(e) if transient(&e) => continue,
            Err(e) => return Err(e.into()),
        };
        if let Some(krc) = result.krc.filter(|k| *k != from) {
            result.reject(format!("datagram from {from} ignored: the KRC is {krc}"));
            continue;
        }
        let m = match buf.get(..n).map(Measurement::parse) {
            Some(Ok(m)) => m,
            Some(Err(e)) => {
                result.reject(format!("from {from}: {e}"));
                continue;
            }
            None => continue,
        };
        let command = session.answer(&m);
        socket.send_to(&command.encode(), from)?;
        if result.krc.is_none() {
            let _ = events.try_send(Event::Krc(from));
        }
        result.krc = Some(from);
        result.answered += 1;
        if let Some((seq, _, _)) = last_seen {
            // Forward steps only: a restarted or reordered sequence is no gap.
            let step = m.head.send_seq_count.wrapping_sub(seq);
            if (1..0x8000).contains(&step) {
                result.gaps += u64::from(step - 1);
            }
        }
        last_seen = Some((m.head.send_seq_count, m.intf.state, m.intf.quality));
        last_packet = Instant::now();
    };
    result.ended = ended;
    result.tracking = session.tracking();
    result.planned = session.planned();
    result.weighing = session.weigh_len();
    result.approach = session.approach_len();
    result.sent = session.sent();
    result.cycle = session.cycle();
    result.load = session.held_load();
    result.load_samples = session.held_samples();
    Ok(result)
}

/// Reads every datagram queued on `socket` without answering: the
/// measurements count as stale, anything else as rejected.
fn drain(socket: &UdpSocket, result: &mut PlayResult) -> std::io::Result<()> {
    socket.set_nonblocking(true)?;
    let mut buf = [0u8; 2048];
    let drained = loop {
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
    };
    socket.set_nonblocking(false)?;
    drained
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
