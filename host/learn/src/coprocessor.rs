//! The host's end of primo's devices (the learning coprocessor, the
//! load-cell scale): a [`Link`] that speaks the wire protocol
//! ([`primo_protocol`]) over a serial port, and [`Qemu`], which boots a
//! firmware image on an emulated Cortex-M4F and exposes its UART as a
//! pseudo-terminal.
//!
//! Every request is retransmitted with the same sequence number until its
//! reply arrives: on a timeout, on a corrupted frame from the device, or
//! when the device reports that it could not read ours. The device answers
//! a repeated sequence number with the same reply and no second state
//! change, so a retransmission is always safe. A [`Link`] is a shared
//! handle: the scale's client and the learner on the scale use one line.

use std::collections::VecDeque;
use std::fmt;
use std::io::{self, BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex, MutexGuard};
use std::time::{Duration, Instant};

use primo_protocol::VERSION;
use primo_protocol::fault::FaultKind;
use primo_protocol::frame::{self as wire, FrameReader, MAX_FRAME};
use primo_protocol::learner::{self, Reply as LearnerReply};
use primo_protocol::replay::UNREAD;
use primo_protocol::scale::{Reply, Request, STREAM};
use serde::Serialize;
use serialport::SerialPort;

use crate::{Error, Setting};
use primo_mtsics::path::Wanted;

/// How long to wait for a reply before sending the request again.
pub const REPLY_TIMEOUT: Duration = Duration::from_millis(200);
/// Sends of one request before giving up.
pub const ATTEMPTS: u32 = 100;

/// Counts of what went wrong on the line, for the run's report.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct LinkStats {
    /// Requests answered.
    pub requests: u64,
    /// Requests sent again.
    pub retransmissions: u64,
    /// Frames from the coprocessor that failed to decode.
    pub bad_frames: u64,
    /// Replies to an earlier sequence number (answers to retransmissions).
    pub stale: u64,
}

/// Streamed replies kept until read; older ones are dropped.
const STREAMED: usize = 1024;

/// A connection to a device; clones share it.
#[derive(Clone)]
pub struct Link(Arc<Mutex<Line>>);

/// The line behind a [`Link`].
struct Line {
    port: Box<dyn SerialPort>,
    name: String,
    reader: FrameReader,
    seq: u32,
    timeout: Duration,
    stats: LinkStats,
    /// Replies the device sent unasked ([`STREAM`]), oldest first.
    streamed: VecDeque<Reply>,
}

impl Link {
    /// Opens the serial port at `path`, named by `setting` (115200 8N1; a
    /// pseudo-terminal ignores the rate), and greets the device: it must
    /// speak [`VERSION`].
    pub fn open(path: &str, setting: Setting) -> Result<Link, Error> {
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(20))
            .open()
            .map_err(|e| Error::open(setting, path, Wanted::Port)(e.into()))?;
        // Sequence numbers start somewhere new each time, so that a reply
        // cached from an earlier session is never taken for ours.
        let seq = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(1, |d| d.subsec_nanos() | 1);
        let link = Link(Arc::new(Mutex::new(Line {
            port,
            name: path.to_string(),
            reader: FrameReader::new(),
            seq,
            timeout: REPLY_TIMEOUT,
            stats: LinkStats::default(),
            streamed: VecDeque::new(),
        })));
        link.line().hello()?;
        Ok(link)
    }

    fn line(&self) -> MutexGuard<'_, Line> {
        // A panic while holding the line leaves it consistent: every
        // request either completed or will be sent again.
        self.0.lock().unwrap_or_else(|e| e.into_inner())
    }

    /// The port's name.
    pub fn name(&self) -> String {
        self.line().name.clone()
    }

    /// What went wrong on the line so far.
    pub fn stats(&self) -> LinkStats {
        self.line().stats
    }

    /// Sends `request` and returns its reply, retransmitting as needed.
    /// Errors: the port fails, or no intact reply after [`ATTEMPTS`] sends.
    pub fn call(&mut self, request: &Request) -> Result<Reply, Error> {
        self.line().call(request, Duration::ZERO)
    }

    /// [`Link::call`] of a learner's request, on either device (it has the
    /// same bytes on both).
    pub fn learn(&mut self, request: &learner::Request) -> Result<LearnerReply, Error> {
        let mut line = self.line();
        match line.call(request, Duration::ZERO)? {
            Reply::Learner(reply) => Ok(reply),
            other => Err(Error::Coprocessor(format!(
                "coprocessor {}: unexpected answer to {request:?}: {other:?}",
                line.name
            ))),
        }
    }

    /// [`Link::call`] of a request whose reply may take up to `patience`
    /// (a scale's next stable reading): sent again while unanswered, for
    /// [`ATTEMPTS`] sends or `patience`, whichever is longer.
    pub fn call_within(&mut self, request: &Request, patience: Duration) -> Result<Reply, Error> {
        self.line().call(request, patience)
    }

    /// The replies the device streamed, oldest first, waiting up to
    /// `within` for the first; intact ones only.
    pub fn streamed(&mut self, within: Duration) -> Result<Vec<Reply>, Error> {
        let mut line = self.line();
        let deadline = Instant::now() + within;
        while line.streamed.is_empty() && Instant::now() < deadline {
            line.receive(None)?;
        }
        Ok(line.streamed.drain(..).collect())
    }
}

impl Line {
    fn hello(&mut self) -> Result<(), Error> {
        let hello = learner::Request::Hello { version: VERSION };
        match self.call(&hello, Duration::ZERO)? {
            Reply::Learner(LearnerReply::Hello { .. }) => Ok(()),
            Reply::Learner(LearnerReply::Error(f)) if f.kind == FaultKind::Version => {
                Err(Error::Coprocessor(format!(
                    "coprocessor {}: {f}; flash firmware of this primo version",
                    self.name
                )))
            }
            other => Err(Error::Coprocessor(format!(
                "coprocessor {}: unexpected answer to hello: {other:?}",
                self.name
            ))),
        }
    }

    /// Sends `request` (the scale's, or the learner's: the same bytes on
    /// either device) and returns its reply, retransmitting as needed.
    fn call<Q: Serialize + fmt::Debug>(
        &mut self,
        request: &Q,
        patience: Duration,
    ) -> Result<Reply, Error> {
        let start = Instant::now();
        self.seq = self.seq.wrapping_add(1);
        if self.seq == UNREAD || self.seq == STREAM {
            self.seq = 1;
        }
        let mut buf = [0u8; MAX_FRAME];
        let frame = wire::encode(self.seq, request, &mut buf)
            .map_err(|e| {
                Error::Coprocessor(format!(
                    "coprocessor {}: encoding {request:?}: {e}",
                    self.name
                ))
            })?
            .to_vec();
        let mut attempts = 0;
        while attempts < ATTEMPTS || start.elapsed() < patience {
            if attempts > 0 {
                self.stats.retransmissions += 1;
            }
            attempts += 1;
            self.port
                .write_all(&frame)
                .and_then(|()| self.port.flush())
                .map_err(|e| {
                    Error::Coprocessor(format!("coprocessor {}: write: {e}", self.name))
                })?;
            if let Some(reply) = self.receive(Some(self.seq))? {
                self.stats.requests += 1;
                return Ok(reply);
            }
        }
        Err(Error::Coprocessor(format!(
            "coprocessor {}: no intact reply to {request:?} after {attempts} attempts",
            self.name
        )))
    }

    /// The reply to `seq`, or `None` when it is time to send the request
    /// again; streamed replies are kept on the way. With no `seq`, reads
    /// for one reply timeout.
    fn receive(&mut self, seq: Option<u32>) -> Result<Option<Reply>, Error> {
        let deadline = Instant::now() + self.timeout;
        let mut bytes = [0u8; 256];
        while Instant::now() < deadline {
            let n = match self.port.read(&mut bytes) {
                Ok(n) => n,
                Err(e) if e.kind() == io::ErrorKind::TimedOut => continue,
                Err(e) => {
                    return Err(Error::Coprocessor(format!(
                        "coprocessor {}: read: {e}",
                        self.name
                    )));
                }
            };
            for b in bytes.iter().take(n) {
                let Some(raw) = self.reader.push(*b) else {
                    continue;
                };
                match raw.and_then(wire::decode::<Reply>) {
                    Ok(f) if Some(f.seq) == seq => return Ok(Some(f.body)),
                    Ok(f) if f.seq == STREAM => {
                        if self.streamed.len() == STREAMED {
                            self.streamed.pop_front();
                        }
                        self.streamed.push_back(f.body);
                    }
                    // It could not read our frame: send it again now.
                    Ok(f) if f.seq == UNREAD => return Ok(None),
                    Ok(_) => self.stats.stale += 1,
                    // A damaged frame, maybe our reply: ask again now.
                    Err(_) => {
                        self.stats.bad_frames += 1;
                        if seq.is_some() {
                            return Ok(None);
                        }
                    }
                }
            }
        }
        Ok(None)
    }
}

/// Where cargo puts the firmware's release ELFs under a target directory.
const RELEASE: &str = "thumbv7em-none-eabihf/release";

/// A firmware image.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Image {
    /// The learning coprocessor, `primo-firmware` (`$PRIMO_FIRMWARE`).
    Coprocessor,
    /// The load-cell scale, which serves the learner too, `primo-scale`
    /// (`$PRIMO_SCALE_FIRMWARE`).
    Scale,
}

impl Image {
    /// Its ELF's name, and the environment variable that names it.
    fn names(self) -> (&'static str, &'static str) {
        match self {
            Image::Coprocessor => ("primo-firmware", "PRIMO_FIRMWARE"),
            Image::Scale => ("primo-scale", "PRIMO_SCALE_FIRMWARE"),
        }
    }
}

/// Where the scale image keeps its settings (`firmware/src/settings.rs`).
const SETTINGS_PAGE: u32 = 0x0001_F800;

/// The firmware's sources, `firmware/` at the top of the source tree
/// (this crate is `host/learn/`).
fn firmware_source() -> PathBuf {
    let learn = Path::new(env!("CARGO_MANIFEST_DIR"));
    learn.ancestors().nth(2).unwrap_or(learn).join("firmware")
}

/// A firmware image running in QEMU's `mps2-an386` (a Cortex-M4F) with
/// UART0 on a pseudo-terminal; QEMU is stopped when this is dropped.
pub struct Qemu {
    child: Child,
    pty: String,
    /// The scale's settings page loaded at boot, removed with QEMU.
    page: Option<PathBuf>,
}

impl Qemu {
    /// The ELF of `image`, found at run time: its environment variable
    /// if set; else the first that exists of the firmware's release build
    /// under `CARGO_TARGET_DIR` (relative to `firmware/`, where cargo
    /// builds it), under `firmware/target`, under the target directory
    /// this executable was built in (`<target>/debug/primo`), and the ELF
    /// beside the executable. Not found: an error naming where it looked
    /// and the command that builds it. It is not built on demand: that
    /// needs the Cortex-M4F target installed and takes a minute, which a
    /// run should not start by surprise.
    pub fn find(image: Image) -> Result<PathBuf, Error> {
        let (name, variable) = image.names();
        if let Some(path) = std::env::var_os(variable) {
            return Ok(PathBuf::from(path));
        }
        let elf = Path::new(RELEASE).join(name);
        let source = firmware_source();
        let exe = std::env::current_exe().ok();
        let exe_dir = exe.as_deref().and_then(Path::parent);
        let candidates: Vec<PathBuf> = [
            std::env::var_os("CARGO_TARGET_DIR").map(|dir| source.join(dir).join(&elf)),
            Some(source.join("target").join(&elf)),
            exe_dir
                .and_then(Path::parent)
                .map(|target| target.join(&elf)),
            exe_dir.map(|dir| dir.join(name)),
        ]
        .into_iter()
        .flatten()
        .collect();
        if let Some(found) = candidates.iter().find(|p| p.is_file()) {
            return Ok(found.clone());
        }
        Err(Error::NoFirmware {
            name,
            variable,
            looked: candidates,
            sources: source,
        })
    }

    /// Boots the coprocessor `firmware` and waits for QEMU to name the
    /// pseudo-terminal.
    pub fn start(firmware: &Path) -> Result<Qemu, Error> {
        Self::boot(firmware, &[])
    }

    /// Boots the scale `firmware` with its load cell's ADC line (UART1) on
    /// the serial device `load_cell` (a pseudo-terminal the simulated cell
    /// sends counts on) and its settings page holding `settings`, as a
    /// factory programs it (QEMU's flash does not outlive QEMU).
    pub fn start_scale(
        firmware: &Path,
        load_cell: &str,
        settings: &primo_device::scale::Settings,
    ) -> Result<Qemu, Error> {
        let mut buf = [0u8; primo_device::page::IMAGE];
        let image = primo_device::page::encode(settings, &mut buf)
            .map_err(|e| Error::Coprocessor(format!("the scale's settings page: {e}")))?;
        // One file per boot of this process.
        static BOOTS: AtomicU32 = AtomicU32::new(0);
        let page = std::env::temp_dir().join(format!(
            "primo-scale-page-{}-{}.bin",
            std::process::id(),
            BOOTS.fetch_add(1, Ordering::Relaxed)
        ));
        std::fs::write(&page, image).map_err(Error::io(&page))?;
        let loader = format!(
            "loader,file={},addr={SETTINGS_PAGE:#x},force-raw=on",
            page.display()
        );
        let booted = Self::boot(firmware, &["-serial", load_cell, "-device", &loader]);
        match booted {
            Ok(mut qemu) => {
                qemu.page = Some(page);
                Ok(qemu)
            }
            Err(e) => {
                let _ = std::fs::remove_file(&page);
                Err(e)
            }
        }
    }

    /// Boots `firmware` with UART0 on a new pseudo-terminal and `extra`
    /// arguments.
    fn boot(firmware: &Path, extra: &[&str]) -> Result<Qemu, Error> {
        if !firmware.is_file() {
            return Err(Error::Coprocessor(format!(
                "firmware {} not found: build it with `cd {} && cargo build --release`",
                firmware.display(),
                firmware_source().display()
            )));
        }
        let mut child = Command::new("qemu-system-arm")
            .args(["-cpu", "cortex-m4", "-machine", "mps2-an386", "-nographic"])
            .args(["-monitor", "none", "-serial", "pty"])
            .args(extra)
            .args(["-semihosting-config", "enable=on,target=native"])
            .arg("-kernel")
            .arg(firmware)
            .stdin(Stdio::null())
            .stdout(Stdio::piped())
            .stderr(Stdio::piped())
            .spawn()
            .map_err(|e| {
                Error::Coprocessor(format!(
                    "cannot start qemu-system-arm: {e} (Debian: apt-get install qemu-system-arm)"
                ))
            })?;
        let stdout = child
            .stdout
            .take()
            .ok_or_else(|| Error::Coprocessor("qemu-system-arm: no stdout".into()))?;
        // QEMU prints "char device redirected to /dev/pts/N (label serial0)".
        let mut lines = BufReader::new(stdout).lines();
        let pty = loop {
            match lines.next() {
                Some(Ok(line)) => {
                    if let Some(rest) = line.split("redirected to ").nth(1) {
                        break rest.split_whitespace().next().unwrap_or("").to_string();
                    }
                }
                _ => {
                    let mut err = String::new();
                    if let Some(mut e) = child.stderr.take() {
                        let _ = e.read_to_string(&mut err);
                    }
                    let _ = child.kill();
                    let _ = child.wait();
                    return Err(Error::Coprocessor(format!(
                        "qemu-system-arm exited without a serial pty: {}",
                        err.trim()
                    )));
                }
            }
        };
        // Keep draining QEMU's stdout (semihosting output) so it never blocks.
        std::thread::spawn(move || lines.for_each(drop));
        Ok(Qemu {
            child,
            pty,
            page: None,
        })
    }

    /// The pseudo-terminal of the firmware's UART0.
    pub fn pty(&self) -> &str {
        &self.pty
    }
}

impl Drop for Qemu {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
        if let Some(page) = &self.page {
            let _ = std::fs::remove_file(page);
        }
    }
}
