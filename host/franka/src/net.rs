//! The session on the network: the TCP command channel on the calling
//! thread, the 1 kHz UDP stream on two real-time threads.
//!
//! As in `primo-fri`'s loop (and with its real-time helpers,
//! [`primo_fri::realtime`]), two threads pinned to two CPUs both wake for
//! every state and the first to take it answers: a virtual machine's CPU
//! may be taken away for milliseconds, and the other answers meanwhile.
//! The thread that takes the socket reads every state waiting and answers
//! the newest, as libfranka does; the ones passed over count as skipped.
//!
//! The UDP socket is bound to the local address of the TCP connection (a
//! robot on loopback is answered on loopback only), on a port the OS
//! picks, which the `Connect` request names.

use std::io::{ErrorKind, Read, Write};
use std::net::{SocketAddr, TcpStream, UdpSocket};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::mpsc::sync_channel;
use std::sync::{Mutex, MutexGuard};
use std::time::{Duration, Instant};

use primo_core::coupling::PhaseStop;
use primo_fri::realtime::{self, Realtime};
use primo_fri::udp::{readable, transient};
use primo_robot::JointPath;
use primo_robot::execute::{Executed, ExecutionFailed, Executor};

use crate::error::FrankaError;
use crate::session::{Event, Report, Session, SessionConfig};

/// How a run connects and schedules its loop.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PlayConfig {
    /// The session's motion and waits.
    pub session: SessionConfig,
    /// Longest wait for the TCP connection.
    pub connect_timeout: Duration,
    /// Ask for real-time scheduling and locked memory for the loop.
    pub realtime: bool,
}

impl Default for PlayConfig {
    fn default() -> Self {
        PlayConfig {
            session: SessionConfig::default(),
            connect_timeout: Duration::from_secs(5),
            realtime: true,
        }
    }
}

/// What a run is doing, for the caller's report.
#[derive(Debug, Clone, PartialEq)]
pub enum Progress {
    /// What the OS granted the loop.
    Realtime(Realtime),
    /// The session's event.
    Session(Event),
}

/// How often the channel and the timeouts are looked at without traffic.
const POLL: Duration = Duration::from_millis(2);

/// Runs `path` on the robot at `addr` (its command channel) until the
/// motion finishes or fails, or `stop` is set (then the motion is
/// stopped); `on_progress` hears what happens, on the calling thread.
pub fn play(
    addr: SocketAddr,
    path: &JointPath,
    cfg: &PlayConfig,
    stop: &AtomicBool,
    on_progress: &mut dyn FnMut(Progress),
) -> Result<Report, FrankaError> {
    let (report, outcome) = run(addr, path, cfg, stop, on_progress);
    outcome.map(|()| report)
}

/// As [`play`], and what the robot did whether it failed or not (the
/// positions it went through before a reflex, say).
pub fn run(
    addr: SocketAddr,
    path: &JointPath,
    cfg: &PlayConfig,
    stop: &AtomicBool,
    on_progress: &mut dyn FnMut(Progress),
) -> (Report, Result<(), FrankaError>) {
    match connected(addr, path, cfg, stop, on_progress) {
        Ok(parts) => parts,
        Err(e) => (Report::default(), Err(e)),
    }
}

fn connected(
    addr: SocketAddr,
    path: &JointPath,
    cfg: &PlayConfig,
    stop: &AtomicBool,
    on_progress: &mut dyn FnMut(Progress),
) -> Result<(Report, Result<(), FrankaError>), FrankaError> {
    let mut tcp = TcpStream::connect_timeout(&addr, cfg.connect_timeout)?;
    tcp.set_nodelay(true)?;
    tcp.set_read_timeout(Some(POLL))?;
    let udp = UdpSocket::bind(SocketAddr::new(tcp.local_addr()?.ip(), 0))?;
    udp.set_nonblocking(true)?;
    let session = Mutex::new(Session::new(
        path,
        udp.local_addr()?.port(),
        cfg.session,
        Instant::now(),
    ));
    let (progress, heard) = sync_channel(64);
    // One thread alone where the process may use one CPU.
    let cpus = realtime::cpus(2);
    let served: Result<(), FrankaError> = std::thread::scope(|scope| {
        let mut threads = Vec::new();
        for k in 0..cpus.len().max(1) {
            let cpu = cpus.get(k).copied();
            let (udp, session, progress) = (&udp, &session, progress.clone());
            let thread = std::thread::Builder::new()
                .name(format!("fci-{k}"))
                .spawn_scoped(scope, move || {
                    if let Some(cpu) = cpu {
                        let _ = realtime::pin(cpu);
                    }
                    let granted = match (cfg.realtime, k) {
                        (false, _) => None,
                        (true, 0) => Some(realtime::enter()),
                        (true, _) => {
                            let _ = realtime::schedule();
                            None
                        }
                    };
                    if let Some(g) = &granted {
                        let _ = progress.try_send(Progress::Realtime(g.clone()));
                    }
                    let served = serve(udp, session);
                    if let Some(g) = &granted {
                        realtime::leave(g);
                    }
                    served
                })?;
            threads.push(thread);
        }
        drop(progress);
        let channel = command_channel(&mut tcp, &session, stop, &heard, on_progress);
        if channel.is_err() {
            // The threads end with the session.
            if let Ok(mut s) = session.lock() {
                s.handle_closed();
            }
        }
        let mut joined = Ok(());
        for t in threads {
            let r = t.join().unwrap_or(Err(FrankaError::Thread));
            joined = joined.and(r);
        }
        heard.try_iter().for_each(&mut *on_progress);
        channel.and(joined)
    });
    let (report, outcome) = session
        .into_inner()
        .map_err(|_| FrankaError::Thread)?
        .into_parts();
    // A failed thread or socket outranks what the session concluded.
    Ok((report, served.and(outcome)))
}

/// A Franka at `addr` as a robot that executes checked paths, for a
/// learning run's roll-outs: each path is a run of its own (connect,
/// motion, disconnect); the positions executed are the measured ones
/// while the motion ran, on the robot's millisecond clock.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrankaRobot {
    /// The robot's command channel.
    pub addr: SocketAddr,
    /// How it connects and moves.
    pub cfg: PlayConfig,
}

impl Executor for FrankaRobot {
    fn execute(&mut self, path: &JointPath) -> Result<Executed, ExecutionFailed> {
        let (report, outcome) = run(
            self.addr,
            path,
            &self.cfg,
            &AtomicBool::new(false),
            &mut |_| {},
        );
        let executed = Executed {
            times: report.times,
            positions: report.positions,
        };
        match outcome {
            Ok(()) => Ok(executed),
            Err(e) => Err(ExecutionFailed {
                why: Box::new(e),
                executed,
            }),
        }
    }

    fn phase_stop(&mut self, gain: PhaseStop) -> bool {
        self.cfg.session.phase_stop = Some(gain);
        true
    }
}

fn lock(session: &Mutex<Session>) -> Result<MutexGuard<'_, Session>, FrankaError> {
    session.lock().map_err(|_| FrankaError::Thread)
}

/// The TCP side until the session is done and its last request sent.
fn command_channel(
    tcp: &mut TcpStream,
    session: &Mutex<Session>,
    stop: &AtomicBool,
    heard: &std::sync::mpsc::Receiver<Progress>,
    on_progress: &mut dyn FnMut(Progress),
) -> Result<(), FrankaError> {
    let mut buf = vec![0u8; 64 * 1024];
    let mut interrupted = false;
    loop {
        let (out, events, done) = {
            let mut s = lock(session)?;
            if stop.load(Ordering::Relaxed) && !interrupted {
                interrupted = true;
                s.interrupt();
            }
            s.handle_timeout(Instant::now());
            let out: Vec<Vec<u8>> = std::iter::from_fn(|| s.poll_transmit()).collect();
            let events: Vec<Event> = std::iter::from_fn(|| s.poll_event()).collect();
            (out, events, s.is_done())
        };
        for bytes in &out {
            tcp.write_all(bytes)?;
        }
        heard.try_iter().for_each(&mut *on_progress);
        events
            .into_iter()
            .for_each(|e| on_progress(Progress::Session(e)));
        if done {
            return Ok(());
        }
        match tcp.read(&mut buf) {
            Ok(0) => lock(session)?.handle_closed(),
            Ok(n) => lock(session)?.handle_tcp(Instant::now(), &buf[..n]),
            Err(e) if matches!(e.kind(), ErrorKind::WouldBlock | ErrorKind::TimedOut) => {}
            Err(e) if e.kind() == ErrorKind::Interrupted => {}
            Err(e) if e.kind() == ErrorKind::ConnectionReset => lock(session)?.handle_closed(),
            Err(e) => return Err(e.into()),
        }
    }
}

/// A UDP thread: waits for states, answers the newest, until the session
/// is done.
fn serve(udp: &UdpSocket, session: &Mutex<Session>) -> Result<(), FrankaError> {
    let mut buf = [0u8; 2048];
    let mut newest = [0u8; 2048];
    loop {
        readable(udp, POLL)?;
        let mut s = lock(session)?;
        if s.is_done() {
            return Ok(());
        }
        // Every state waiting; the newest is answered (the session counts
        // the ones passed over by the gap in their ids).
        let mut got: Option<(usize, SocketAddr)> = None;
        loop {
            match udp.recv_from(&mut buf) {
                Ok((n, from)) => {
                    newest[..n].copy_from_slice(&buf[..n]);
                    got = Some((n, from));
                }
                Err(e) if transient(&e) => break,
                Err(e) => return Err(e.into()),
            }
        }
        let now = Instant::now();
        if let Some((n, from)) = got
            && let Some(command) = s.handle_state(now, &newest[..n])
        {
            match udp.send_to(&command, from) {
                Ok(_) => {}
                Err(e) if transient(&e) => {}
                Err(e) => return Err(e.into()),
            }
        }
        s.handle_timeout(now);
    }
}
