//! The simulated scale as an MT-SICS device: [`Device`] is the protocol
//! without I/O (command lines in, responses out, the simulated scale
//! stepped in between), [`PtyServer`] serves it on a new pseudo-terminal.
//!
//! A round trip over a real pseudo-terminal with the MT-SICS client:
//!
//! ```
//! use primo_mtsics::{Client, ClientConfig};
//! use primo_sim::scale::ScaleModel;
//! use primo_sim::scale_device::{Device, DeviceConfig, LoadHandle, PtyServer};
//! let model = ScaleModel::default();
//! let load = LoadHandle::new(250.0);
//! let mut device = Device::new(model, 1, load.clone(), DeviceConfig::for_model(&model)).unwrap();
//! device.advance(30.0); // the load has settled
//! let server = PtyServer::start(device).unwrap();
//! let mut scale = Client::open(server.path(), ClientConfig::default()).unwrap();
//! let grams = scale.stable().unwrap().grams();
//! assert!((grams - 250.0).abs() <= 0.02, "{grams}");
//! drop(scale);
//! server.stop().unwrap();
//! ```

use crate::Error;
use std::collections::VecDeque;
use std::io::{self, Read, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::mpsc;
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use serialport::{SerialPort, TTYPort};

use primo_mtsics::{Lines, MAX_LINE, Reply, Response, Stability, Unit, Weight, parse_value};

use crate::scale::{Scale, ScaleModel};

/// Where the served scale's load comes from: the grams on the pan now.
pub trait LoadSource: Send {
    /// The load on the pan, g (a non-finite value is ignored: the last
    /// finite one stays).
    fn grams(&self) -> f64;
}

/// A load shared between threads: whoever simulates what stands on the
/// pan sets it, the served scale reads it.
#[derive(Debug, Clone, Default)]
pub struct LoadHandle(Arc<AtomicU64>);

impl LoadHandle {
    /// A handle holding `grams`.
    pub fn new(grams: f64) -> Self {
        LoadHandle(Arc::new(AtomicU64::new(grams.to_bits())))
    }

    /// Puts `grams` on the pan.
    pub fn set(&self, grams: f64) {
        self.0.store(grams.to_bits(), Ordering::Relaxed);
    }
}

impl LoadSource for LoadHandle {
    fn grams(&self) -> f64 {
        f64::from_bits(self.0.load(Ordering::Relaxed))
    }
}

/// The device's settings beyond the scale model.
#[derive(Debug, Clone, PartialEq)]
pub struct DeviceConfig {
    /// Serial number, sent by `I4`, `@` and at power-on.
    pub serial: String,
    /// Balance type, sent by `I2` with the capacity.
    pub kind: String,
    /// How long `S`, `Z` and `T` wait for a stable reading before they
    /// answer `I`, s.
    pub stable_timeout: f64,
    /// `Z` works within ± this of the power-on zero; a reading below its
    /// negative is underload, g.
    pub zero_range: f64,
}

impl DeviceConfig {
    /// A scale of `model`: zero range ±2 % of the capacity, 8 s to settle.
    pub fn for_model(model: &ScaleModel) -> Self {
        DeviceConfig {
            serial: "0123456789".into(),
            kind: "primo-sim".into(),
            stable_timeout: 8.0,
            zero_range: 0.02 * model.capacity,
        }
    }

    fn validate(&self) -> Result<(), Error> {
        for (what, text) in [("serial", &self.serial), ("kind", &self.kind)] {
            if text.len() > 40 || text.chars().any(|c| c == '"' || !(' '..='~').contains(&c)) {
                return Err(Error::Invalid(format!(
                    "scale {what} `{text}` must be at most 40 printable ASCII characters without quotes"
                )));
            }
        }
        let positive = |v: f64| v.is_finite() && v > 0.0;
        if !(positive(self.stable_timeout) && positive(self.zero_range)) {
            return Err(Error::Invalid(format!(
                "scale stable timeout {} s and zero range {} g must be finite and > 0",
                self.stable_timeout, self.zero_range
            )));
        }
        Ok(())
    }
}

/// A command waiting for a stable reading.
#[derive(Debug, Clone, Copy, PartialEq)]
enum Waiting {
    Weight,
    Zero,
    Tare,
}

/// Commands received while one waits, at most this many, answered in turn.
const QUEUE: usize = 16;
/// The longest simulation step, s: well below the display interval.
const STEP: f64 = 0.005;

/// The simulated scale speaking MT-SICS, without I/O.
///
/// ```
/// use primo_sim::scale_device::{Device, DeviceConfig, LoadHandle}; use primo_mtsics::{Response, Stability};
/// use primo_sim::scale::ScaleModel;
/// let model = ScaleModel::default();
/// let load = LoadHandle::new(100.0);
/// let mut scale = Device::new(model, 1, load.clone(), DeviceConfig::for_model(&model)).unwrap();
/// scale.advance(30.0); // 100 g stood on the pan for half a minute
/// let answer = scale.command(b"S");
/// assert!(matches!(answer[..], [Response::Weight(w, Stability::Stable)] if (w.value - 100.0).abs() < 0.02));
/// load.set(150.0);
/// scale.advance(0.1);
/// assert!(scale.command(b"S").is_empty()); // waits for the display to settle
/// scale.advance(10.0);
/// assert!(matches!(scale.poll()[..], [Response::Weight(w, _)] if (w.value - 150.0).abs() < 0.02));
/// ```
#[derive(Debug)]
pub struct Device<L> {
    scale: Scale,
    model: ScaleModel,
    config: DeviceConfig,
    load: L,
    last_load: f64,
    time: f64,
    /// Not stable before this time: the load changed and the display has
    /// not shown it yet.
    moving_until: f64,
    decimals: u8,
    /// The zero point and the tare, g of the simulated display.
    zero: f64,
    tare: f64,
    waiting: Option<(Waiting, f64)>,
    queue: VecDeque<Vec<u8>>,
}

impl<L: LoadSource> Device<L> {
    /// A scale of `model` (noise from `seed`) under `load`, just powered
    /// on: showing zero, nothing on it yet.
    pub fn new(model: ScaleModel, seed: u64, load: L, config: DeviceConfig) -> Result<Self, Error> {
        model.validate()?;
        config.validate()?;
        let decimals = (0..=9u8)
            .find(|d| {
                let x = model.resolution * 10f64.powi(i32::from(*d));
                (x - x.round()).abs() < 1e-6
            })
            .unwrap_or(9);
        Ok(Device {
            scale: Scale::new(model, seed),
            model,
            config,
            load,
            last_load: 0.0,
            time: 0.0,
            moving_until: 0.0,
            decimals,
            zero: 0.0,
            tare: 0.0,
            waiting: None,
            queue: VecDeque::new(),
        })
    }

    /// Seconds simulated so far.
    pub fn time(&self) -> f64 {
        self.time
    }

    /// Advances the scale by `dt` seconds under the load's current value
    /// (at most a minute at once: the display has long settled by then).
    pub fn advance(&mut self, dt: f64) {
        if !(dt.is_finite() && dt > 0.0) {
            return;
        }
        let load = self.load.grams();
        if load.is_finite() {
            // The load cell feels a change at once, the display only at its
            // next update: a command in between must not see "stable".
            if (load - self.last_load).abs() >= self.model.resolution {
                self.moving_until = self.time + self.model.update;
            }
            self.last_load = load;
        }
        let dt = dt.min(60.0);
        let mut left = dt;
        while left > 0.0 {
            let h = left.min(STEP);
            self.scale.step(h, self.last_load);
            left -= h;
        }
        self.time += dt;
    }

    /// The line a scale sends unprompted when it is switched on.
    pub fn power_on_line(&self) -> Response {
        Response::Serial(self.config.serial.clone())
    }

    /// Handles one received command line (without CR LF). Returns what to
    /// send now: usually one response, none while an earlier command still
    /// waits for a stable reading (this one is answered after it) or when
    /// this one waits; `@` cancels the waiting ones.
    pub fn command(&mut self, line: &[u8]) -> Vec<Response> {
        if self.waiting.is_none() {
            return self.execute(line).into_iter().collect();
        }
        if line.trim_ascii() == b"@" {
            return vec![self.reset()];
        }
        if self.queue.len() >= QUEUE {
            return vec![Response::LogicError];
        }
        self.queue.push_back(line.to_vec());
        Vec::new()
    }

    /// Answers that are due now: a waiting command whose reading settled
    /// (or whose time ran out), then the commands queued behind it.
    pub fn poll(&mut self) -> Vec<Response> {
        let mut out = Vec::new();
        loop {
            if let Some((what, deadline)) = self.waiting {
                match self.settle(what, self.time >= deadline) {
                    Some(answer) => {
                        self.waiting = None;
                        out.push(answer);
                    }
                    None => return out,
                }
            }
            let Some(line) = self.queue.pop_front() else {
                return out;
            };
            out.extend(self.execute(&line));
        }
    }

    /// `@`: cancels waiting commands, clears the tare, keeps the zero.
    fn reset(&mut self) -> Response {
        self.waiting = None;
        self.queue.clear();
        self.tare = 0.0;
        self.power_on_line()
    }

    fn gross(&self) -> (f64, bool, bool) {
        let r = self.scale.reading();
        (
            r.grams,
            r.stable && self.time >= self.moving_until,
            r.overload,
        )
    }

    fn weight(&self, grams: f64) -> Weight {
        let res = self.model.resolution;
        Weight {
            value: (grams / res).round() * res,
            unit: Unit::G,
            decimals: self.decimals,
        }
    }

    /// The answer to a waiting command now, or `None` to keep waiting.
    fn settle(&mut self, what: Waiting, timed_out: bool) -> Option<Response> {
        let (gross, stable, overload) = self.gross();
        let reply = match what {
            Waiting::Weight => Reply::Weight,
            Waiting::Zero => Reply::Zero,
            Waiting::Tare => Reply::Tare,
        };
        let range = self.config.zero_range;
        if overload || (what == Waiting::Zero && gross > range) {
            return Some(Response::Overload(reply));
        }
        if gross < -range {
            return Some(Response::Underload(reply));
        }
        if !stable {
            return timed_out.then_some(Response::NotExecutable(reply));
        }
        Some(match what {
            Waiting::Weight => Response::Weight(
                self.weight(gross - self.zero - self.tare),
                Stability::Stable,
            ),
            Waiting::Zero => {
                self.zero = gross;
                self.tare = 0.0;
                Response::Zeroed
            }
            Waiting::Tare => {
                self.tare = gross - self.zero;
                Response::Tared(self.weight(self.tare))
            }
        })
    }

    fn wait(&mut self, what: Waiting) -> Option<Response> {
        let answer = self.settle(what, false);
        if answer.is_none() {
            self.waiting = Some((what, self.time + self.config.stable_timeout));
        }
        answer
    }

    /// One command, not behind a waiting one: its answer, or `None` when
    /// it now waits for a stable reading.
    fn execute(&mut self, line: &[u8]) -> Option<Response> {
        if line.len() > MAX_LINE || !line.iter().all(|b| (b' '..=b'~').contains(b)) {
            return Some(Response::TransmissionError);
        }
        let text = String::from_utf8_lossy(line);
        let fields: Vec<&str> = text.split_ascii_whitespace().collect();
        let (gross, stable, overload) = self.gross();
        let stability = if stable {
            Stability::Stable
        } else {
            Stability::Dynamic
        };
        let range = self.config.zero_range;
        Some(match fields[..] {
            ["S"] => return self.wait(Waiting::Weight),
            ["Z"] => return self.wait(Waiting::Zero),
            ["T"] => return self.wait(Waiting::Tare),
            ["SI"] if overload => Response::Overload(Reply::Weight),
            ["SI"] if gross < -range => Response::Underload(Reply::Weight),
            ["SI"] => Response::Weight(self.weight(gross - self.zero - self.tare), stability),
            ["ZI"] if overload || gross > range => Response::Overload(Reply::ZeroImmediately),
            ["ZI"] if gross < -range => Response::Underload(Reply::ZeroImmediately),
            ["ZI"] => {
                self.zero = gross;
                self.tare = 0.0;
                Response::ZeroedImmediately(stability)
            }
            ["TA"] => Response::TareValue(self.weight(self.tare)),
            ["TA", value, unit] => match (parse_value(value), Unit::from_symbol(unit)) {
                (Some((v, _)), Some(u)) => {
                    let grams = Weight {
                        value: v,
                        unit: u,
                        decimals: 0,
                    }
                    .grams();
                    if (0.0..=self.model.capacity).contains(&grams) {
                        self.tare = self.weight(grams).value;
                        Response::TareValue(self.weight(self.tare))
                    } else {
                        Response::InvalidParameter(Reply::TareValue)
                    }
                }
                _ => Response::InvalidParameter(Reply::TareValue),
            },
            ["TAC"] => {
                self.tare = 0.0;
                Response::TareCleared
            }
            ["@"] => self.reset(),
            ["I2"] => Response::BalanceData(vec![format!(
                "{} {}",
                self.config.kind,
                self.weight(self.model.capacity)
            )]),
            ["I4"] => self.power_on_line(),
            _ => Response::SyntaxError,
        })
    }
}

/// What an operator (or a test) can do to a served scale besides its load.
#[derive(Debug, Clone, PartialEq)]
pub enum Control {
    /// Send these bytes and CR LF, as if line noise had written them.
    Garbage(Vec<u8>),
    /// Neither read nor answer commands for this long (zero ends a
    /// silence): a cable pulled out.
    Silent(Duration),
    /// Send the power-on line, as a scale does when it is switched on (the
    /// simulated state is kept).
    PowerOn,
}

/// How often the serving loop looks at the port and the controls.
const POLL: Duration = Duration::from_millis(10);

type Request = (Control, mpsc::Sender<()>);

/// A [`Device`] served on a new pseudo-terminal from its own thread;
/// clients open [`PtyServer::path`] like a real serial port. The
/// simulated scale runs in wall-clock time.
#[derive(Debug)]
pub struct PtyServer {
    path: String,
    control: mpsc::Sender<Request>,
    thread: JoinHandle<io::Result<()>>,
}

impl PtyServer {
    /// Opens a pseudo-terminal, sends the power-on line and serves
    /// `device` until [`PtyServer::stop`]. `TTYPort::pair` is not
    /// thread-safe: do not start two at once.
    pub fn start<L: LoadSource + 'static>(device: Device<L>) -> io::Result<PtyServer> {
        let (mut master, slave) = TTYPort::pair()?;
        let path = slave
            .name()
            .ok_or_else(|| io::Error::other("the pseudo-terminal has no path"))?;
        send(&mut master, device.power_on_line().to_string().as_bytes())?;
        let (control, requests) = mpsc::channel();
        let thread = std::thread::Builder::new()
            .name("mtsics-server".into())
            .spawn(move || serve(device, master, slave, &requests))?;
        Ok(PtyServer {
            path,
            control,
            thread,
        })
    }

    /// The path clients open (`/dev/pts/N`).
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Applies `control`; returns once it is done.
    pub fn control(&self, control: Control) -> io::Result<()> {
        let stopped = || io::Error::other("the scale server has stopped");
        let (done, wait) = mpsc::channel();
        self.control.send((control, done)).map_err(|_| stopped())?;
        wait.recv().map_err(|_| stopped())
    }

    /// Serves on until the process ends: returns only the serving loop's
    /// error, if it fails.
    pub fn serve_on(self) -> io::Result<()> {
        let PtyServer {
            control, thread, ..
        } = self;
        let served = thread
            .join()
            .map_err(|_| io::Error::other("the scale server panicked"))?;
        drop(control);
        served
    }

    /// Stops serving and closes the pseudo-terminal; the serving loop's
    /// error, if it failed.
    pub fn stop(self) -> io::Result<()> {
        drop(self.control);
        self.thread
            .join()
            .map_err(|_| io::Error::other("the scale server panicked"))?
    }
}

/// Writes `line` and CR LF. A full pty (nobody reading) drops the line,
/// as a serial line with nothing attached would.
fn send(port: &mut TTYPort, line: &[u8]) -> io::Result<()> {
    let mut bytes = line.to_vec();
    bytes.extend_from_slice(b"\r\n");
    match port.write_all(&bytes) {
        Err(e) if e.kind() == io::ErrorKind::TimedOut => Ok(()),
        other => other,
    }
}

/// The serving loop. Keeps `_slave` open so the pty lives (and stays raw)
/// while clients come and go.
fn serve<L: LoadSource>(
    mut device: Device<L>,
    mut master: TTYPort,
    _slave: TTYPort,
    requests: &mpsc::Receiver<Request>,
) -> io::Result<()> {
    master.set_timeout(POLL)?;
    let mut lines = Lines::default();
    let mut silent_until: Option<Instant> = None;
    let mut last = Instant::now();
    let mut buf = [0u8; 256];
    loop {
        loop {
            match requests.try_recv() {
                Ok((control, done)) => {
                    match control {
                        Control::Garbage(bytes) => send(&mut master, &bytes)?,
                        Control::Silent(d) => {
                            // Capped at a year, so the sum cannot overflow.
                            let d = d.min(Duration::from_secs(365 * 86_400));
                            silent_until = Some(Instant::now() + d);
                        }
                        Control::PowerOn => {
                            send(&mut master, device.power_on_line().to_string().as_bytes())?
                        }
                    }
                    let _ = done.send(());
                }
                Err(mpsc::TryRecvError::Empty) => break,
                Err(mpsc::TryRecvError::Disconnected) => return Ok(()),
            }
        }
        let n = match master.read(&mut buf) {
            Ok(n) => n,
            Err(e)
                if matches!(
                    e.kind(),
                    io::ErrorKind::TimedOut | io::ErrorKind::Interrupted
                ) =>
            {
                0
            }
            Err(e) => return Err(e),
        };
        let now = Instant::now();
        device.advance(now.duration_since(last).as_secs_f64());
        last = now;
        let silent = silent_until.is_some_and(|t| now < t);
        lines.push(buf.get(..n).unwrap_or_default());
        let mut out = Vec::new();
        while let Some(line) = lines.next_line() {
            if !silent {
                out.extend(device.command(&line));
            }
        }
        out.extend(device.poll());
        if !silent {
            for response in out {
                send(&mut master, response.to_string().as_bytes())?;
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn device(load: f64) -> (Device<LoadHandle>, LoadHandle) {
        let model = ScaleModel::default();
        let handle = LoadHandle::new(load);
        let mut d = Device::new(model, 3, handle.clone(), DeviceConfig::for_model(&model)).unwrap();
        d.advance(30.0);
        (d, handle)
    }

    fn one(d: &mut Device<LoadHandle>, line: &str) -> Response {
        let out = d.command(line.as_bytes());
        assert_eq!(out.len(), 1, "{line}: {out:?}");
        out.into_iter().next().unwrap()
    }

    fn value(r: &Response) -> f64 {
        match r {
            Response::Weight(w, _) | Response::Tared(w) | Response::TareValue(w) => w.value,
            other => panic!("not a weight: {other:?}"),
        }
    }

    #[test]
    fn stable_weight_waits_for_the_display_then_answers() {
        let (mut d, load) = device(100.0);
        let r = one(&mut d, "S");
        assert!(matches!(r, Response::Weight(_, Stability::Stable)));
        assert!((value(&r) - 100.0).abs() <= 0.02);
        assert_eq!(r.to_string().len(), "S S     100.00 g".len());
        load.set(60.0);
        // A millisecond later the display has not moved yet, but the scale
        // knows it is not stable.
        d.advance(0.001);
        assert!(matches!(
            one(&mut d, "SI"),
            Response::Weight(_, Stability::Dynamic)
        ));
        assert!(d.command(b"S").is_empty());
        // A second command waits behind the first.
        assert!(d.command(b"I4").is_empty());
        let mut answers = Vec::new();
        while answers.is_empty() {
            d.advance(0.05);
            answers = d.poll();
            assert!(d.time() < 45.0, "never settled");
        }
        assert!((value(&answers[0]) - 60.0).abs() <= 0.02, "{answers:?}");
        assert_eq!(answers[1], Response::Serial("0123456789".into()));
    }

    #[test]
    fn immediate_weight_is_dynamic_while_moving() {
        let (mut d, load) = device(0.0);
        load.set(50.0);
        d.advance(0.3);
        let r = one(&mut d, "SI");
        assert!(
            matches!(r, Response::Weight(_, Stability::Dynamic)),
            "{r:?}"
        );
        assert!(value(&r) > 1.0 && value(&r) < 49.0, "{r:?}");
        d.advance(20.0);
        assert!(matches!(
            one(&mut d, "SI"),
            Response::Weight(_, Stability::Stable)
        ));
    }

    #[test]
    fn no_stable_reading_in_time_answers_busy() {
        let (mut d, load) = device(0.0);
        load.set(1.0);
        d.advance(0.1);
        assert!(d.command(b"S").is_empty());
        let asked = d.time();
        // Pouring: the load never stops moving.
        loop {
            load.set(1.0 + 10.0 * (d.time() - asked));
            d.advance(0.01);
            let out = d.poll();
            if !out.is_empty() {
                assert_eq!(out, vec![Response::NotExecutable(Reply::Weight)]);
                assert!(
                    (d.time() - asked - 8.0).abs() < 0.02,
                    "{}",
                    d.time() - asked
                );
                break;
            }
        }
    }

    #[test]
    fn zero_and_tare() {
        let (mut d, _) = device(100.0);
        let tared = one(&mut d, "T");
        assert!(matches!(tared, Response::Tared(_)) && (value(&tared) - 100.0).abs() <= 0.02);
        assert!(value(&one(&mut d, "S")).abs() <= 0.02);
        assert!((value(&one(&mut d, "TA")) - value(&tared)).abs() < 1e-9);
        assert_eq!(one(&mut d, "TAC"), Response::TareCleared);
        assert!((value(&one(&mut d, "SI")) - 100.0).abs() <= 0.02);
        // Preset tare in kg.
        assert!((value(&one(&mut d, "TA 0.025 kg")) - 25.0).abs() < 1e-9);
        assert!((value(&one(&mut d, "S")) - 75.0).abs() <= 0.02);
        assert_eq!(
            one(&mut d, "TA -1 g"),
            Response::InvalidParameter(Reply::TareValue)
        );
        assert_eq!(
            one(&mut d, "TA 1 lb"),
            Response::InvalidParameter(Reply::TareValue)
        );
        // 100 g is beyond the ±84 g zero range; 50 g is within it.
        assert_eq!(one(&mut d, "Z"), Response::Overload(Reply::Zero));
        assert_eq!(
            one(&mut d, "ZI"),
            Response::Overload(Reply::ZeroImmediately)
        );
        let (mut d, _) = device(50.0);
        assert_eq!(one(&mut d, "Z"), Response::Zeroed);
        assert!(value(&one(&mut d, "S")).abs() <= 0.02);
        assert_eq!(
            one(&mut d, "ZI"),
            Response::ZeroedImmediately(Stability::Stable)
        );
    }

    #[test]
    fn overload_underload_and_errors() {
        let (mut d, load) = device(5000.0);
        assert_eq!(one(&mut d, "S"), Response::Overload(Reply::Weight));
        assert_eq!(one(&mut d, "SI"), Response::Overload(Reply::Weight));
        assert_eq!(one(&mut d, "T"), Response::Overload(Reply::Tare));
        load.set(-200.0);
        d.advance(30.0);
        assert_eq!(one(&mut d, "S"), Response::Underload(Reply::Weight));
        assert_eq!(one(&mut d, "Z"), Response::Underload(Reply::Zero));
        for bad in ["s", "X", "S 1", "", "TA 1", "I4 now"] {
            assert_eq!(one(&mut d, bad), Response::SyntaxError, "{bad}");
        }
        assert_eq!(one(&mut d, "S\u{e9}"), Response::TransmissionError);
        assert_eq!(d.command(&[b'S'; 200]), vec![Response::TransmissionError]);
        assert_eq!(
            one(&mut d, "I2"),
            Response::BalanceData(vec!["primo-sim 4200.00 g".into()])
        );
    }

    #[test]
    fn reset_cancels_waiting_commands_and_clears_the_tare() {
        let (mut d, load) = device(30.0);
        assert!(matches!(one(&mut d, "T"), Response::Tared(_)));
        load.set(70.0);
        d.advance(0.1);
        assert!(d.command(b"S").is_empty());
        assert!(d.command(b"SI").is_empty());
        assert_eq!(one(&mut d, "@"), Response::Serial("0123456789".into()));
        d.advance(20.0);
        assert!(d.poll().is_empty(), "cancelled commands stay unanswered");
        assert!((value(&one(&mut d, "S")) - 70.0).abs() <= 0.02);
        // A full queue refuses more.
        load.set(10.0);
        d.advance(0.1);
        assert!(d.command(b"S").is_empty());
        for _ in 0..QUEUE {
            assert!(d.command(b"SI").is_empty());
        }
        assert_eq!(d.command(b"SI"), vec![Response::LogicError]);
    }

    #[test]
    fn bad_settings_are_refused() {
        let model = ScaleModel::default();
        let mut config = DeviceConfig::for_model(&model);
        config.serial = "a\"b".into();
        assert!(Device::new(model, 1, LoadHandle::new(0.0), config).is_err());
        let mut config = DeviceConfig::for_model(&model);
        config.stable_timeout = 0.0;
        assert!(Device::new(model, 1, LoadHandle::new(0.0), config).is_err());
    }
}
