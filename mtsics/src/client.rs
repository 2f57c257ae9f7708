//! The MT-SICS client: a precision scale on a serial port.

use std::fmt;
use std::io::{self, Read, Write};
use std::time::{Duration, Instant};

use serialport::{ClearBuffer, DataBits, FlowControl, Parity, SerialPort, StopBits};

use crate::protocol::{
    Lines, Reply, Response, ResponseError, Stability, Weight, parse_response, quote,
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
    /// How long to wait for each answer. Longer than the scale's own wait
    /// for a stable reading, so a slow `S` ends in `S I`, not a timeout.
    pub timeout: Duration,
    /// Retries after a timeout or an `I` (busy / could not settle) answer.
    pub retries: u32,
}

impl Default for ClientConfig {
    /// 9600 baud 8N1 (MT-SICS), 10 s per answer, 2 retries.
    fn default() -> Self {
        ClientConfig {
            baud: 9600,
            data_bits: DataBits::Eight,
            parity: Parity::None,
            stop_bits: StopBits::One,
            timeout: Duration::from_secs(10),
            retries: 2,
        }
    }
}

/// What went wrong in one exchange with the scale.
#[derive(Debug)]
pub enum ErrorKind {
    /// Opening, reading or writing the port failed.
    Port(io::Error),
    /// No answer within the timeout, on every attempt.
    Timeout {
        /// Times the command was sent.
        attempts: u32,
    },
    /// A line that is not MT-SICS.
    Malformed(ResponseError),
    /// A valid line that does not answer the command sent.
    Unexpected(String),
    /// `I` on every attempt: busy, or could not settle in time.
    NotExecutable {
        /// Times the command was sent.
        attempts: u32,
        /// The last answer.
        line: String,
    },
    /// `+`: the load is beyond the capacity (or the zero range).
    Overload(String),
    /// `-`: the load is below the zero range.
    Underload(String),
    /// `ES`, `ET`, `EL` or `L`: the scale refused the command.
    Rejected(String),
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
    /// The per-attempt timeout in force.
    timeout: Duration,
}

impl fmt::Display for ScaleError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let (port, sent) = (&self.port, &self.sent);
        let got = |f: &mut fmt::Formatter<'_>, line: &str, why: &str| {
            write!(f, "{port}: sent `{sent}`, received `{line}`: {why}")
        };
        match &self.kind {
            ErrorKind::Port(e) if sent.is_empty() => write!(f, "{port}: cannot open: {e}"),
            ErrorKind::Port(e) => write!(f, "{port}: sent `{sent}`: {e}"),
            ErrorKind::Timeout { attempts } => write!(
                f,
                "{port}: sent `{sent}` {attempts} time(s), no answer within {:.1} s each: is the scale on and connected, at the right baud rate?",
                self.timeout.as_secs_f64()
            ),
            ErrorKind::Malformed(e) => write!(
                f,
                "{port}: sent `{sent}`, received `{}`: not an MT-SICS response: {}",
                e.line, e.reason
            ),
            ErrorKind::Unexpected(line) => got(f, line, &format!("not an answer to `{sent}`")),
            ErrorKind::NotExecutable { attempts, line } => got(
                f,
                line,
                &format!("the scale is busy or could not settle, {attempts} time(s)"),
            ),
            ErrorKind::Overload(line) => {
                got(f, line, "overload: the load is beyond the scale's range")
            }
            ErrorKind::Underload(line) => got(
                f,
                line,
                "underload: the load is below the scale's zero range",
            ),
            ErrorKind::Rejected(line) => {
                let why = match line.as_str() {
                    "ES" => "syntax error: the scale does not know the command",
                    "ET" => "transmission error: the scale received garbled bytes",
                    "EL" => "logic error: the scale cannot execute the command",
                    _ => "the scale refused a parameter",
                };
                got(f, line, why)
            }
        }
    }
}

impl std::error::Error for ScaleError {}

/// A precision scale speaking MT-SICS on a serial port.
///
/// Every command is sent up to 1 + `retries` times: again after a timeout
/// or an `I` answer (busy, or no stable reading in the scale's own time).
/// Lines the scale sends unprompted at power-on (`I4 A "<serial>"`) are
/// skipped wherever they arrive. After a garbled or unexpected line the
/// answer to the command may still be on its way, so the next command
/// first resynchronizes: it asks `I4` and drops everything up to the
/// answer (`I4`, unlike `@`, leaves the tare alone).
pub struct Client {
    port: Box<dyn SerialPort>,
    name: String,
    config: ClientConfig,
    lines: Lines,
    serial: String,
    resync: bool,
    power_on_lines: u32,
}

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
        let port = serialport::new(path, config.baud)
            .data_bits(config.data_bits)
            .parity(config.parity)
            .stop_bits(config.stop_bits)
            .flow_control(FlowControl::None)
            .timeout(config.timeout)
            .open()
            .map_err(|e| ScaleError {
                port: path.to_string(),
                sent: String::new(),
                kind: ErrorKind::Port(e.into()),
                timeout: config.timeout,
            })?;
        let mut scale = Client {
            port,
            name: path.to_string(),
            config,
            lines: Lines::default(),
            serial: String::new(),
            resync: false,
            power_on_lines: 0,
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

    /// `@`: drops pending input, cancels what the scale was doing, clears
    /// its tare; waits for its `I4 A "<serial>"`.
    pub fn reset(&mut self) -> Result<(), ScaleError> {
        self.port
            .clear(ClearBuffer::Input)
            .map_err(|e| self.error("@", ErrorKind::Port(e.into())))?;
        self.lines.clear();
        self.serial = self.until_serial("@")?;
        self.resync = false;
        Ok(())
    }

    /// `S`: the stable weight.
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

    /// When the answer to a command sent now is late (the timeout capped
    /// at a day, so the sum cannot overflow).
    fn deadline(&self) -> Instant {
        Instant::now() + self.config.timeout.min(Duration::from_secs(86_400))
    }

    fn error(&self, sent: &str, kind: ErrorKind) -> ScaleError {
        ScaleError {
            port: self.name.clone(),
            sent: sent.to_string(),
            kind,
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

    /// Sends `command` (`@` or `I4`) and drops every line up to an
    /// `I4 A` answer; its serial number.
    fn until_serial(&mut self, command: &str) -> Result<String, ScaleError> {
        let mut attempts = 0;
        loop {
            attempts += 1;
            self.send(command)?;
            let deadline = self.deadline();
            while let Some(line) = self.read_line(command, deadline)? {
                if let Ok(Response::Serial(serial)) = parse_response(&line) {
                    return Ok(serial);
                }
            }
            if attempts > self.config.retries {
                self.resync = true;
                return Err(self.error(command, ErrorKind::Timeout { attempts }));
            }
        }
    }

    /// Sends `command` until it gets an answer other than `I` (at most
    /// 1 + retries times) and sorts out the answers every command shares:
    /// `+`, `-`, `L`, `ES`, `ET`, `EL`, and answers to other commands.
    /// Returns the answer and its line.
    fn transact(&mut self, command: &str, reply: Reply) -> Result<(Response, String), ScaleError> {
        if self.resync {
            self.until_serial("I4")?;
            self.resync = false;
        }
        let mut attempts = 0;
        loop {
            attempts += 1;
            self.send(command)?;
            let Some((response, line)) = self.answer(command)? else {
                // The late answer may still come: whatever this exchange
                // ends in, the next command first resyncs.
                self.resync = true;
                if attempts > self.config.retries {
                    return Err(self.error(command, ErrorKind::Timeout { attempts }));
                }
                continue;
            };
            let kind = match response {
                Response::NotExecutable(r) if r == reply => {
                    if attempts > self.config.retries {
                        ErrorKind::NotExecutable { attempts, line }
                    } else {
                        continue;
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

    /// The answer to `command`, skipping power-on lines; `None` on timeout.
    fn answer(&mut self, command: &str) -> Result<Option<(Response, String)>, ScaleError> {
        let deadline = self.deadline();
        while let Some(line) = self.read_line(command, deadline)? {
            match parse_response(&line) {
                Ok(Response::Serial(_)) => self.power_on_lines += 1,
                Ok(response) => return Ok(Some((response, quote(&line)))),
                Err(e) => {
                    self.resync = true;
                    return Err(self.error(command, ErrorKind::Malformed(e)));
                }
            }
        }
        Ok(None)
    }
}
