//! The MT-SICS client: a precision scale on a serial port.

use std::fmt;
use std::io::{self, Read, Write};
use std::path::Path;
use std::time::{Duration, Instant};

use serialport::{ClearBuffer, DataBits, FlowControl, Parity, SerialPort, StopBits};

use crate::path::{Fault, Wanted};
use crate::protocol::{
    Lines, Reply, Response, ResponseError, Stability, Weight, parse_response, parse_tail, quote,
};

/// How to talk to the scale.
#[derive(Debug, Clone, PartialEq)]
pub struct ClientConfig {
    /// Baud rate (MT-SICS default 9600).
    pub baud: u32,
    /// Data bits (8).
    pub data_bits: DataBits,
    /// Parity (none).
    pub parity: Parity,
    /// Stop bits (1).
    pub stop_bits: StopBits,
    /// How long a command may go unanswered, its re-sends included, before
    /// the scale counts as silent. Lines of noise are no answer.
    pub timeout: Duration,
    /// Re-sends within `timeout` when nothing answers (a command lost to
    /// line noise), evenly spaced.
    pub retries: u32,
    /// How long `S`, `Z` and `T` are asked again while the scale answers
    /// `I` (still settling, or busy), from the first time they are sent.
    pub settle: Duration,
}

impl Default for ClientConfig {
    /// 9600 baud 8N1 (MT-SICS); silent after 10 s, re-sending twice within
    /// them; a minute to settle (a lab balance in a draft shield settles in
    /// seconds; a minute allows for a liquid still moving).
    fn default() -> Self {
        ClientConfig {
            baud: 9600,
            data_bits: DataBits::Eight,
            parity: Parity::None,
            stop_bits: StopBits::One,
            timeout: Duration::from_secs(10),
            retries: 2,
            settle: Duration::from_secs(60),
        }
    }
}

/// What went wrong in one exchange with the scale.
#[derive(Debug)]
pub enum ErrorKind {
    /// Opening, reading or writing the port failed.
    Port(io::Error),
    /// The port would not open: why ([`crate::path`]).
    Open(Fault),
    /// No MT-SICS answer within the timeout.
    Timeout {
        /// Times the command was sent.
        attempts: u32,
    },
    /// A valid line that does not answer the command sent.
    Unexpected(String),
    /// `I` until the settling time was over: busy, or could not settle.
    NotExecutable {
        /// Times the command was sent.
        attempts: u32,
        /// The last answer.
        line: String,
        /// From the first send to the last answer.
        waited: Duration,
    },
    /// `+`: the load is beyond the capacity (or the zero range).
    Overload(String),
    /// `-`: the load is below the zero range.
    Underload(String),
    /// `ES`, `ET`, `EL` or `L`: the scale refused the command.
    Rejected(String),
}

/// Lines that are not MT-SICS, skipped while waiting for an answer.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Noise {
    /// How many.
    pub lines: u32,
    /// The last one and what is wrong with it.
    pub last: ResponseError,
}

/// An exchange with the scale that failed: the port, the command sent and
/// what came back.
#[derive(Debug)]
pub struct ScaleError {
    /// The port's path.
    pub port: String,
    /// The command sent (empty while opening).
    pub sent: String,
    /// What happened.
    pub kind: ErrorKind,
    /// Noise skipped during the exchange, if any.
    pub noise: Option<Box<Noise>>,
    /// The timeout in force.
    timeout: Duration,
}

impl fmt::Display for ScaleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (port, sent) = (&self.port, &self.sent);
        let got = |f: &mut fmt::Formatter<'_>, line: &str, why: &str| {
            write!(f, "{port}: sent `{sent}`, received `{line}`: {why}")
        };
        match (&self.kind, &self.noise) {
            (ErrorKind::Open(fault), _) => write!(f, "{port}: {fault}"),
            (ErrorKind::Port(e), _) => write!(f, "{port}: sent `{sent}`: {e}"),
            (ErrorKind::Timeout { attempts }, None) => write!(
                f,
                "{port}: sent `{sent}` {attempts} time(s), no answer within {:.1} s: is the \
                 scale on and connected, at the right baud rate?",
                self.timeout.as_secs_f64()
            ),
            (ErrorKind::Timeout { attempts }, Some(noise)) => write!(
                f,
                "{port}: sent `{sent}` {attempts} time(s), no MT-SICS answer within {:.1} s, \
                 only {} line(s) of noise (the last `{}`: {}): is the baud rate right (8N1), \
                 and the cable?",
                self.timeout.as_secs_f64(),
                noise.lines,
                noise.last.line,
                noise.last.reason
            ),
            (ErrorKind::Unexpected(line), _) => got(f, line, &format!("not an answer to `{sent}`")),
            (
                ErrorKind::NotExecutable {
                    attempts,
                    line,
                    waited,
                },
                _,
            ) => got(
                f,
                line,
                &format!(
                    "the scale did not settle (or stayed busy): asked {attempts} time(s) over \
                     {:.1} s; is the load still moving, or the balance in a draft?",
                    waited.as_secs_f64()
                ),
            ),
            // `Z` and `T` answer `+`/`-` for their own ranges, not the
            // weighing range `S` answers it for.
            (ErrorKind::Overload(line), _) => got(
                f,
                line,
                match sent.as_str() {
                    "Z" => {
                        "the load is beyond the balance's zero-setting range (it zeroes only \
                        near its empty pan): empty the pan, or tare instead"
                    }
                    "T" => "the load is beyond the balance's taring range",
                    _ => "overload: the load is beyond the scale's weighing range",
                },
            ),
            (ErrorKind::Underload(line), _) => got(
                f,
                line,
                match sent.as_str() {
                    "Z" => {
                        "the load is below the balance's zero-setting range (it zeroes only \
                        near its empty pan)"
                    }
                    _ => "underload: the load is below the scale's zero range",
                },
            ),
            (ErrorKind::Rejected(line), _) => {
                let why = match line.as_str() {
                    "ES" => "syntax error: the scale does not know the command",
                    "ET" => "transmission error: the scale received garbled bytes",
                    "EL" => "logic error: the scale cannot execute the command",
                    _ => "the scale refused a parameter",
                };
                got(f, line, why)
            }
        }?;
        match (&self.kind, &self.noise) {
            (ErrorKind::Timeout { .. }, _) | (_, None) => Ok(()),
            (_, Some(noise)) => write!(
                f,
                " ({} line(s) of noise skipped before it, the last `{}`)",
                noise.lines, noise.last.line
            ),
        }
    }
}

impl std::error::Error for ScaleError {}

/// A precision scale speaking MT-SICS on a serial port.
///
/// A command is sent again, evenly within the timeout, while nothing
/// answers, and again (after [`ASK_AGAIN`]) while the scale answers `I`,
/// until the settling time is over. Lines that are not MT-SICS (line noise
/// at connect and after power-on is normal on RS-232) are skipped and
/// counted; a response at the end of a noisy line is taken. Lines the
/// scale sends unprompted at power-on (`I4 A "<serial>"`) are skipped
/// wherever they arrive. After a re-send or an unexpected line the answer
/// to an earlier send may still be on its way, so the next command first
/// resynchronizes: it asks `I4` and drops everything up to the answer
/// (`I4`, unlike `@`, leaves the tare alone).
pub struct Client {
    port: Box<dyn SerialPort>,
    name: String,
    config: ClientConfig,
    lines: Lines,
    serial: String,
    resync: bool,
    power_on_lines: u32,
    noise_lines: u32,
    /// Noise of the exchange under way.
    noise: Option<Box<Noise>>,
}

/// The pause before asking again after an `I`: a balance may answer `I`
/// at once, and asking at line speed would only flood it.
pub const ASK_AGAIN: Duration = Duration::from_millis(100);

/// Longest timeout or settling time the client accepts: a day (so that
/// deadlines cannot overflow).
const LONGEST: Duration = Duration::from_secs(86_400);

impl fmt::Debug for Client {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("Client")
            .field("port", &self.name)
            .field("serial", &self.serial)
            .finish_non_exhaustive()
    }
}

impl Client {
    /// Opens the scale on `path` (no flow control), drops whatever it sent
    /// before, and resets it with `@` (which also clears the tare).
    pub fn open(path: &str, config: ClientConfig) -> Result<Client, ScaleError> {
        let failed = |kind| ScaleError {
            port: path.to_string(),
            sent: String::new(),
            kind,
            noise: None,
            timeout: config.timeout,
        };
        let port = serialport::new(path, config.baud)
            .data_bits(config.data_bits)
            .parity(config.parity)
            .stop_bits(config.stop_bits)
            .flow_control(FlowControl::None)
            .timeout(config.timeout.min(LONGEST))
            .open()
            .map_err(|e| {
                failed(ErrorKind::Open(Fault::of(
                    Path::new(path),
                    Wanted::Port,
                    e.into(),
                )))
            })?;
        let mut scale = Client {
            port,
            name: path.to_string(),
            config,
            lines: Lines::default(),
            serial: String::new(),
            resync: false,
            power_on_lines: 0,
            noise_lines: 0,
            noise: None,
        };
        scale.reset()?;
        Ok(scale)
    }

    /// The serial number the scale gave on the last reset.
    pub fn serial(&self) -> &str {
        &self.serial
    }

    /// How many unprompted power-on lines were skipped so far.
    pub fn power_on_lines(&self) -> u32 {
        self.power_on_lines
    }

    /// How many lines that are not MT-SICS were skipped so far.
    pub fn noise_lines(&self) -> u32 {
        self.noise_lines
    }

    /// `@`: drops pending input, cancels what the scale was doing, clears
    /// its tare; waits for its `I4 A "<serial>"`.
    pub fn reset(&mut self) -> Result<(), ScaleError> {
        self.noise = None;
        self.port
            .clear(ClearBuffer::Input)
            .map_err(|e| self.error("@", ErrorKind::Port(e.into())))?;
        self.lines.clear();
        self.serial = self.until_serial("@")?;
        self.resync = false;
        Ok(())
    }

    /// `S`: the stable weight, asked again while the scale is settling.
    pub fn stable(&mut self) -> Result<Weight, ScaleError> {
        match self.transact("S", Reply::Weight)? {
            (Response::Weight(w, Stability::Stable), _) => Ok(w),
            (_, line) => Err(self.unexpected("S", line)),
        }
    }

    /// `SI`: the weight now, stable or still moving.
    pub fn immediate(&mut self) -> Result<(Weight, Stability), ScaleError> {
        match self.transact("SI", Reply::Weight)? {
            (Response::Weight(w, s), _) => Ok((w, s)),
            (_, line) => Err(self.unexpected("SI", line)),
        }
    }

    /// `Z`: zero on a stable reading (clears the tare).
    pub fn zero(&mut self) -> Result<(), ScaleError> {
        match self.transact("Z", Reply::Zero)? {
            (Response::Zeroed, _) => Ok(()),
            (_, line) => Err(self.unexpected("Z", line)),
        }
    }

    /// `T`: tare on a stable reading; returns the tare weight.
    pub fn tare(&mut self) -> Result<Weight, ScaleError> {
        match self.transact("T", Reply::Tare)? {
            (Response::Tared(w), _) => Ok(w),
            (_, line) => Err(self.unexpected("T", line)),
        }
    }

    /// `TAC`: clear the tare.
    pub fn clear_tare(&mut self) -> Result<(), ScaleError> {
        match self.transact("TAC", Reply::ClearTare)? {
            (Response::TareCleared, _) => Ok(()),
            (_, line) => Err(self.unexpected("TAC", line)),
        }
    }

    fn error(&self, sent: &str, kind: ErrorKind) -> ScaleError {
        ScaleError {
            port: self.name.clone(),
            sent: sent.to_string(),
            kind,
            noise: self.noise.clone(),
            timeout: self.config.timeout,
        }
    }

    /// A valid line that answers something else: a late answer, so resync.
    fn unexpected(&mut self, sent: &str, line: String) -> ScaleError {
        self.resync = true;
        self.error(sent, ErrorKind::Unexpected(line))
    }

    fn send(&mut self, command: &str) -> Result<(), ScaleError> {
        self.port
            .write_all(format!("{command}\r\n").as_bytes())
            .and_then(|()| self.port.flush())
            .map_err(|e| self.error(command, ErrorKind::Port(e)))
    }

    /// When send `attempt` (from 0) of a command first sent at `first`
    /// has waited long enough: the timeout split evenly among the sends.
    fn deadline(&self, first: Instant, attempt: u32) -> Instant {
        let sends = self.config.retries.saturating_add(1);
        let share = self.config.timeout.min(LONGEST) / sends;
        first + share * attempt.saturating_add(1)
    }

    /// The next line before `deadline`, `None` at the deadline.
    fn read_line(&mut self, sent: &str, deadline: Instant) -> Result<Option<Vec<u8>>, ScaleError> {
        let mut buf = [0u8; 256];
        loop {
            if let Some(line) = self.lines.next_line() {
                return Ok(Some(line));
            }
            let now = Instant::now();
            if now >= deadline {
                return Ok(None);
            }
            let wait = deadline - now;
            self.port
                .set_timeout(wait)
                .map_err(|e| self.error(sent, ErrorKind::Port(e.into())))?;
            match self.port.read(&mut buf) {
                Ok(0) => {
                    let closed =
                        io::Error::new(io::ErrorKind::UnexpectedEof, "the port was closed");
                    return Err(self.error(sent, ErrorKind::Port(closed)));
                }
                Ok(n) => self.lines.push(buf.get(..n).unwrap_or_default()),
                Err(e)
                    if matches!(
                        e.kind(),
                        io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
                    ) => {}
                Err(e) => return Err(self.error(sent, ErrorKind::Port(e))),
            }
        }
    }

    /// The next MT-SICS response before `deadline`: lines of noise skipped
    /// and counted (a response ending one taken), `None` at the deadline.
    fn read_response(
        &mut self,
        sent: &str,
        deadline: Instant,
    ) -> Result<Option<(Response, String)>, ScaleError> {
        while let Some(line) = self.read_line(sent, deadline)? {
            match parse_response(&line) {
                Ok(response) => return Ok(Some((response, quote(&line)))),
                Err(e) => {
                    self.noise_lines += 1;
                    let lines = self.noise.as_ref().map_or(0, |n| n.lines) + 1;
                    self.noise = Some(Box::new(Noise { lines, last: e }));
                    if let Some((at, response)) = parse_tail(&line) {
                        return Ok(Some((response, quote(line.get(at..).unwrap_or_default()))));
                    }
                }
            }
        }
        Ok(None)
    }

    /// Sends `command` (`@` or `I4`) and drops every line up to an
    /// `I4 A` answer; its serial number.
    fn until_serial(&mut self, command: &str) -> Result<String, ScaleError> {
        let first = Instant::now();
        for attempt in 0..=self.config.retries {
            self.send(command)?;
            let deadline = self.deadline(first, attempt);
            while let Some((response, _)) = self.read_response(command, deadline)? {
                if let Response::Serial(serial) = response {
                    return Ok(serial);
                }
            }
        }
        self.resync = true;
        let attempts = self.config.retries.saturating_add(1);
        Err(self.error(command, ErrorKind::Timeout { attempts }))
    }

    /// Sends `command` until it gets an answer other than `I` and sorts out
    /// the answers every command shares: `+`, `-`, `L`, `ES`, `ET`, `EL`,
    /// and answers to other commands. Returns the answer and its line.
    fn transact(&mut self, command: &str, reply: Reply) -> Result<(Response, String), ScaleError> {
        self.noise = None;
        if self.resync {
            self.until_serial("I4")?;
            self.resync = false;
        }
        let asked = Instant::now();
        let mut attempts = 0u32;
        loop {
            let (response, line) = self.ask(command, &mut attempts)?;
            let kind = match response {
                Response::NotExecutable(r) if r == reply => {
                    let waited = asked.elapsed();
                    if waited + ASK_AGAIN < self.config.settle.min(LONGEST) {
                        std::thread::sleep(ASK_AGAIN);
                        continue;
                    }
                    ErrorKind::NotExecutable {
                        attempts,
                        line,
                        waited,
                    }
                }
                Response::Overload(r) if r == reply => ErrorKind::Overload(line),
                Response::Underload(r) if r == reply => ErrorKind::Underload(line),
                Response::InvalidParameter(r) if r == reply => ErrorKind::Rejected(line),
                Response::SyntaxError | Response::TransmissionError | Response::LogicError => {
                    ErrorKind::Rejected(line)
                }
                Response::NotExecutable(_)
                | Response::Overload(_)
                | Response::Underload(_)
                | Response::InvalidParameter(_) => return Err(self.unexpected(command, line)),
                other => return Ok((other, line)),
            };
            return Err(self.error(command, kind));
        }
    }

    /// Sends `command` (again within the timeout while nothing answers)
    /// until a response other than a power-on line comes; counts the sends
    /// in `attempts`.
    fn ask(&mut self, command: &str, attempts: &mut u32) -> Result<(Response, String), ScaleError> {
        let first = Instant::now();
        for attempt in 0..=self.config.retries {
            if attempt > 0 {
                // The late answer may still come: whatever this exchange
                // ends in, the next command first resyncs.
                self.resync = true;
            }
            self.send(command)?;
            *attempts += 1;
            let deadline = self.deadline(first, attempt);
            while let Some((response, line)) = self.read_response(command, deadline)? {
                match response {
                    Response::Serial(_) => self.power_on_lines += 1,
                    response => return Ok((response, line)),
                }
            }
        }
        self.resync = true;
        let attempts = *attempts;
        Err(self.error(command, ErrorKind::Timeout { attempts }))
    }
}
