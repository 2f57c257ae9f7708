//! The host's end of the learning coprocessor: a [`Link`] that speaks the
//! wire protocol ([`primo_core::wire`]) over a serial port, and [`Qemu`],
//! which boots the firmware on an emulated Cortex-M4F and exposes its UART
//! as a pseudo-terminal.
//!
//! Every request is retransmitted with the same sequence number until its
//! reply arrives: on a timeout, on a corrupted frame from the coprocessor,
//! or when the coprocessor reports that it could not read ours. The
//! coprocessor answers a repeated sequence number with the same reply and
//! no second state change, so a retransmission is always safe.

use std::io::{self, BufRead, BufReader, Read};
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::time::{Duration, Instant};

use primo_core::service::UNREAD;
use primo_core::wire::{self, FaultKind, FrameReader, MAX_FRAME, Reply, Request};
use serialport::SerialPort;

use crate::Error;

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

/// A connection to the coprocessor.
pub struct Link {
    port: Box<dyn SerialPort>,
    name: String,
    reader: FrameReader,
    seq: u32,
    timeout: Duration,
    stats: LinkStats,
}

impl Link {
    /// Opens the serial port at `path` (115200 8N1; a pseudo-terminal
    /// ignores the rate) and greets the coprocessor: it must speak
    /// [`wire::VERSION`].
    pub fn open(path: &str) -> Result<Link, Error> {
        let port = serialport::new(path, 115_200)
            .timeout(Duration::from_millis(20))
            .open()
            .map_err(|e| Error::Coprocessor(format!("coprocessor {path}: cannot open: {e}")))?;
        // Sequence numbers start somewhere new each time, so that a reply
        // cached from an earlier session is never taken for ours.
        let seq = std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(1, |d| d.subsec_nanos() | 1);
        let mut link = Link {
            port,
            name: path.to_string(),
            reader: FrameReader::new(),
            seq,
            timeout: REPLY_TIMEOUT,
            stats: LinkStats::default(),
        };
        link.hello()?;
        Ok(link)
    }

    fn hello(&mut self) -> Result<(), Error> {
        let hello = Request::Hello {
            version: wire::VERSION,
        };
        match self.call(&hello)? {
            Reply::Hello { .. } => Ok(()),
            Reply::Error(f) if f.kind == FaultKind::Version => Err(Error::Coprocessor(format!(
                "coprocessor {}: {f}; flash firmware of this primo version",
                self.name
            ))),
            other => Err(Error::Coprocessor(format!(
                "coprocessor {}: unexpected answer to hello: {other:?}",
                self.name
            ))),
        }
    }

    /// What went wrong on the line so far.
    pub fn stats(&self) -> LinkStats {
        self.stats
    }

    /// Sends `request` and returns its reply, retransmitting as needed.
    /// Errors: the port fails, or no intact reply after [`ATTEMPTS`] sends.
    pub fn call(&mut self, request: &Request) -> Result<Reply, Error> {
        self.seq = self.seq.wrapping_add(1);
        if self.seq == UNREAD {
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
        for attempt in 0..ATTEMPTS {
            if attempt > 0 {
                self.stats.retransmissions += 1;
            }
            self.port
                .write_all(&frame)
                .and_then(|()| self.port.flush())
                .map_err(|e| {
                    Error::Coprocessor(format!("coprocessor {}: write: {e}", self.name))
                })?;
            if let Some(reply) = self.await_reply()? {
                self.stats.requests += 1;
                return Ok(reply);
            }
        }
        Err(Error::Coprocessor(format!(
            "coprocessor {}: no intact reply to {request:?} after {ATTEMPTS} attempts",
            self.name
        )))
    }

    /// The reply to the current sequence number, or `None` when it is time
    /// to send the request again.
    fn await_reply(&mut self) -> Result<Option<Reply>, Error> {
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
                    Ok(f) if f.seq == self.seq => return Ok(Some(f.body)),
                    // It could not read our frame: send it again now.
                    Ok(f) if f.seq == UNREAD => return Ok(None),
                    Ok(_) => self.stats.stale += 1,
                    // Our reply was damaged on the way: ask again now.
                    Err(_) => {
                        self.stats.bad_frames += 1;
                        return Ok(None);
                    }
                }
            }
        }
        Ok(None)
    }
}

/// Where cargo puts the firmware's release ELF under a target directory.
const FIRMWARE_ELF: &str = "thumbv7em-none-eabihf/release/primo-firmware";

/// The firmware's sources, `firmware/` beside this crate.
fn firmware_source() -> PathBuf {
    let learn = Path::new(env!("CARGO_MANIFEST_DIR"));
    learn.parent().unwrap_or(learn).join("firmware")
}

/// The firmware running in QEMU's `mps2-an386` (a Cortex-M4F) with UART0
/// on a pseudo-terminal; QEMU is stopped when this is dropped.
pub struct Qemu {
    child: Child,
    pty: String,
}

impl Qemu {
    /// The firmware ELF, found at run time: `PRIMO_FIRMWARE` if set; else
    /// the first that exists of the firmware's release build under
    /// `CARGO_TARGET_DIR` (relative to `firmware/`, where cargo builds
    /// it), under `firmware/target`, under the target directory this
    /// executable was built in (`<target>/debug/primo`), and
    /// `primo-firmware` beside the executable. Not found: an error naming
    /// where it looked and the command that builds it. It is not built on
    /// demand: that needs the Cortex-M4F target installed and takes a
    /// minute, which a run should not start by surprise.
    pub fn find_firmware() -> Result<PathBuf, Error> {
        if let Some(path) = std::env::var_os("PRIMO_FIRMWARE") {
            return Ok(PathBuf::from(path));
        }
        let source = firmware_source();
        let exe = std::env::current_exe().ok();
        let exe_dir = exe.as_deref().and_then(Path::parent);
        let candidates: Vec<PathBuf> = [
            std::env::var_os("CARGO_TARGET_DIR").map(|dir| source.join(dir).join(FIRMWARE_ELF)),
            Some(source.join("target").join(FIRMWARE_ELF)),
            exe_dir
                .and_then(Path::parent)
                .map(|target| target.join(FIRMWARE_ELF)),
            exe_dir.map(|dir| dir.join("primo-firmware")),
        ]
        .into_iter()
        .flatten()
        .collect();
        if let Some(found) = candidates.iter().find(|p| p.is_file()) {
            return Ok(found.clone());
        }
        let looked: Vec<String> = candidates.iter().map(|p| p.display().to_string()).collect();
        Err(Error::Coprocessor(format!(
            "the coprocessor firmware is not built (looked at {}): build it with \
             `cd {} && cargo build --release` (needs `rustup target add \
             thumbv7em-none-eabihf`), or name it with --firmware or PRIMO_FIRMWARE",
            looked.join(", "),
            source.display()
        )))
    }

    /// Boots `firmware` and waits for QEMU to name the pseudo-terminal.
    pub fn start(firmware: &Path) -> Result<Qemu, Error> {
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
        Ok(Qemu { child, pty })
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
    }
}
