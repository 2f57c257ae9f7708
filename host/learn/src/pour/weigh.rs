//! The scales a real cell weighs with, behind one interface ([`Weigher`]):
//! an MT-SICS balance on a serial port, or primo's load-cell scale (the
//! `primo-scale` firmware) over the wire protocol, on a serial port
//! (`postcard:PORT`) or booted in QEMU with its ADC line on the simulated
//! cell's load cell (`qemu:LOAD_CELL`). primo's scale serves the learner
//! too: [`Weigher::link`] is the line to run it on.

use std::path::Path;
use std::time::{Duration, Instant};

use primo_mtsics::{Client, ClientConfig};
use primo_protocol::fault::{Fault, FaultKind};
use primo_protocol::learner::Reply as LearnerReply;
use primo_protocol::scale::{
    CalibrationPoint, FRESH, Identity, Reading, Reply, Request, ScaleReply, ScaleRequest, Unit,
    WeighMode,
};
use primo_sim::load_cell::LoadCellModel;

use crate::Error;
use crate::coprocessor::{Image, Link, Qemu};
use crate::error::Setting;

/// A liquid's density, used to turn a weight into a volume.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Density(f64);

impl Density {
    /// Water at about 21 °C: 0.998 g/ml. The pouring cell pours water, and
    /// the scale weighs it; the default for volumes.
    pub const WATER: Density = Density(0.998);

    /// A density of `g_per_ml` grams per millilitre (finite, > 0).
    pub fn new(g_per_ml: f64) -> Result<Density, String> {
        if g_per_ml.is_finite() && g_per_ml > 0.0 {
            Ok(Density(g_per_ml))
        } else {
            Err(format!(
                "density {g_per_ml} g/ml must be a finite number above 0"
            ))
        }
    }

    /// Grams per millilitre.
    pub fn g_per_ml(self) -> f64 {
        self.0
    }

    /// The volume of `grams` of the liquid, ml.
    pub fn millilitres(self, grams: f64) -> f64 {
        grams / self.0
    }
}

impl Default for Density {
    /// [`Density::WATER`].
    fn default() -> Self {
        Density::WATER
    }
}

/// Where a scale is.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ScaleSpec {
    /// An MT-SICS balance on this serial port.
    MtSics(String),
    /// primo's scale on this serial port.
    Postcard(String),
    /// primo's scale booted in QEMU, its ADC line on this serial device.
    Qemu(String),
}

impl ScaleSpec {
    /// `postcard:PORT`, `qemu:LOAD_CELL`, or an MT-SICS scale's port.
    pub fn parse(text: &str) -> Result<ScaleSpec, Error> {
        let named = |rest: &str, what: &str| {
            if rest.is_empty() {
                Err(Error::setting(Setting::Scale, text, what))
            } else {
                Ok(rest.to_string())
            }
        };
        Ok(match text.split_once(':') {
            Some(("postcard", port)) => ScaleSpec::Postcard(named(port, "name the serial port")?),
            Some(("qemu", cell)) => ScaleSpec::Qemu(named(cell, "name the load cell's port")?),
            _ if text == "qemu" => {
                return Err(Error::setting(
                    Setting::Scale,
                    text,
                    "name the load cell's port, qemu:PATH",
                ));
            }
            _ => ScaleSpec::MtSics(named(text, "name the serial port")?),
        })
    }
}

/// A scale that weighs.
pub enum Weigher {
    /// An MT-SICS balance.
    MtSics(Client),
    /// primo's scale.
    Primo(PrimoScale),
}

impl Weigher {
    /// Opens the scale of `spec`: `baud` for MT-SICS; a stable reading is
    /// waited for up to `settle`. A scale in QEMU boots with the
    /// simulated load cell's factory calibration.
    pub fn open(spec: &ScaleSpec, baud: u32, settle: Duration) -> Result<Weigher, Error> {
        Ok(match spec {
            ScaleSpec::MtSics(port) => Weigher::MtSics(Client::open(
                port,
                ClientConfig {
                    baud,
                    settle,
                    ..ClientConfig::default()
                },
            )?),
            ScaleSpec::Postcard(port) => Weigher::Primo(PrimoScale::open(port, settle)?),
            ScaleSpec::Qemu(cell) => {
                Weigher::Primo(PrimoScale::boot(&Qemu::find(Image::Scale)?, cell, settle)?)
            }
        })
    }

    /// The stable weight, g.
    pub fn stable_grams(&mut self) -> Result<f64, Error> {
        match self {
            Weigher::MtSics(client) => Ok(client.stable()?.grams()),
            Weigher::Primo(scale) => Ok(scale.weigh(WeighMode::Stable, Unit::G)?.grams()),
        }
    }

    /// The first stable weight made of samples taken after this call, g:
    /// never the load before it (after a pour, not the glass before the
    /// last drops). An MT-SICS balance's `S`, as [`Weigher::stable_grams`].
    pub fn next_stable_grams(&mut self) -> Result<f64, Error> {
        match self {
            Weigher::MtSics(client) => Ok(client.stable()?.grams()),
            Weigher::Primo(scale) => Ok(scale.next_stable(Unit::G)?.grams()),
        }
    }

    /// The scale's serial number.
    pub fn serial(&self) -> String {
        match self {
            Weigher::MtSics(client) => client.serial().to_string(),
            Weigher::Primo(scale) => scale.identity().serial.to_string(),
        }
    }

    /// The line to primo's scale, which serves the learner too.
    pub fn link(&self) -> Option<Link> {
        match self {
            Weigher::MtSics(_) => None,
            Weigher::Primo(scale) => Some(scale.link()),
        }
    }
}

/// How often a request is made again while the scale is not settled.
const SETTLE_POLL: Duration = Duration::from_millis(50);
/// How much longer than its samples take the host waits for the next
/// stable reading: the ADC's rate is nominal, and the line adds its delay.
const NEXT_MARGIN: Duration = Duration::from_secs(2);

/// primo's load-cell scale over the wire protocol.
pub struct PrimoScale {
    link: Link,
    identity: Identity,
    settle: Duration,
    /// QEMU, when the scale runs there: it lives as long as this.
    _qemu: Option<Qemu>,
}

impl PrimoScale {
    /// The scale on serial port `port`; stable readings are waited for up
    /// to `settle`.
    pub fn open(port: &str, settle: Duration) -> Result<PrimoScale, Error> {
        Self::with(Link::open(port, Setting::Scale)?, settle, None)
    }

    /// Boots the scale `firmware` in QEMU, its ADC line on `load_cell`,
    /// calibrated as the simulated load cell's factory would.
    pub fn boot(firmware: &Path, load_cell: &str, settle: Duration) -> Result<PrimoScale, Error> {
        let page = LoadCellModel::default().factory_settings();
        let qemu = Qemu::start_scale(firmware, load_cell, &page)?;
        Self::with(Link::open(qemu.pty(), Setting::Scale)?, settle, Some(qemu))
    }

    fn with(link: Link, settle: Duration, qemu: Option<Qemu>) -> Result<PrimoScale, Error> {
        let mut scale = PrimoScale {
            link,
            identity: Identity {
                model: Default::default(),
                serial: 0,
                capacity: 0.0,
                decimals: 0,
                rate: 0,
                calibrated: false,
            },
            settle,
            _qemu: qemu,
        };
        match scale.call(&ScaleRequest::Identify)? {
            Reply::Scale(ScaleReply::Identity(identity)) => scale.identity = identity,
            other => return Err(scale.unexpected("identify", &other)),
        }
        Ok(scale)
    }

    /// Who it is.
    pub fn identity(&self) -> &Identity {
        &self.identity
    }

    /// The line to it.
    pub fn link(&self) -> Link {
        self.link.clone()
    }

    /// A reading in `unit` as `mode` asks: a stable one is asked again
    /// while the scale is not settled, up to the settling time; the next
    /// stable one is waited for as long as its samples take.
    pub fn weigh(&mut self, mode: WeighMode, unit: Unit) -> Result<Reading, Error> {
        let patience = match mode {
            WeighMode::Next { within } => {
                let rate = f64::from(self.identity.rate.max(1));
                Duration::from_secs_f64(f64::from(within) / rate) + NEXT_MARGIN
            }
            WeighMode::Now | WeighMode::Stable => Duration::ZERO,
        };
        match self.settled(&ScaleRequest::Weigh { mode, unit }, patience)? {
            Reply::Scale(ScaleReply::Reading(r)) => Ok(r),
            other => Err(self.unexpected("weigh", &other)),
        }
    }

    /// The next stable reading in `unit` ([`WeighMode::Next`]): made of
    /// samples taken after this call alone, within the settling time (at
    /// least the [`FRESH`] samples it needs).
    pub fn next_stable(&mut self, unit: Unit) -> Result<Reading, Error> {
        let rate = f64::from(self.identity.rate);
        // `as` saturates: past u16::MAX samples, the scale is asked again.
        let within = ((self.settle.as_secs_f64() * rate) as u16).max(FRESH);
        self.weigh(WeighMode::Next { within }, unit)
    }

    /// Zero, tare or a calibration point, at a stable load (waited for).
    pub fn set(&mut self, request: &ScaleRequest) -> Result<(), Error> {
        match self.settled(request, Duration::ZERO)? {
            Reply::Learner(LearnerReply::Ok) => Ok(()),
            other => Err(self.unexpected("setting", &other)),
        }
    }

    /// Takes calibration point `point`.
    pub fn calibrate(&mut self, point: CalibrationPoint) -> Result<(), Error> {
        self.set(&ScaleRequest::Calibrate(point))
    }

    /// `count` readings streamed every `every` samples (then the stream
    /// stops), each waited for up to a second: a reading, or the fault
    /// the scale streamed instead (not settled, overload, …).
    pub fn stream(
        &mut self,
        every: u16,
        count: usize,
    ) -> Result<Vec<Result<Reading, Fault>>, Error> {
        self.call(&ScaleRequest::Stream { every })?;
        let mut readings = Vec::with_capacity(count);
        while readings.len() < count {
            let got = self.link.streamed(Duration::from_secs(1))?;
            if got.is_empty() {
                break;
            }
            for reply in got {
                match reply {
                    Reply::Scale(ScaleReply::Reading(r)) => readings.push(Ok(r)),
                    Reply::Learner(LearnerReply::Error(fault)) => readings.push(Err(fault)),
                    other => return Err(self.unexpected("stream", &other)),
                }
            }
        }
        self.call(&ScaleRequest::Stream { every: 0 })?;
        if readings.len() < count {
            return Err(Error::Instrument(format!(
                "scale {}: the stream stopped after {} of {count} readings",
                self.link.name(),
                readings.len()
            )));
        }
        readings.truncate(count);
        Ok(readings)
    }

    /// `request`, made again while the scale answers not settled, up to
    /// the settling time; its answer may take `patience`.
    fn settled(&mut self, request: &ScaleRequest, patience: Duration) -> Result<Reply, Error> {
        let start = Instant::now();
        loop {
            let request_frame = Request::Scale(request.clone());
            match self.link.call_within(&request_frame, patience)? {
                Reply::Learner(LearnerReply::Error(f))
                    if f.kind == FaultKind::NotSettled && start.elapsed() < self.settle =>
                {
                    std::thread::sleep(SETTLE_POLL)
                }
                reply => return self.fault(request, reply),
            }
        }
    }

    /// One request.
    fn call(&mut self, request: &ScaleRequest) -> Result<Reply, Error> {
        let reply = self.link.call(&Request::Scale(request.clone()))?;
        self.fault(request, reply)
    }

    /// A fault reply as an error naming the port and the request.
    fn fault(&self, request: &ScaleRequest, reply: Reply) -> Result<Reply, Error> {
        match reply {
            Reply::Learner(LearnerReply::Error(fault)) => Err(Error::Instrument(format!(
                "scale {}: {}: {fault}",
                self.link.name(),
                name(request)
            ))),
            reply => Ok(reply),
        }
    }

    fn unexpected(&self, what: &str, reply: &Reply) -> Error {
        Error::Instrument(format!(
            "scale {}: unexpected answer to {what}: {reply:?}",
            self.link.name()
        ))
    }
}

/// What `request` asks, in a word.
fn name(request: &ScaleRequest) -> &'static str {
    match request {
        ScaleRequest::Identify => "identify",
        ScaleRequest::Weigh { .. } => "weigh",
        ScaleRequest::Stream { .. } => "stream",
        ScaleRequest::Zero => "zero",
        ScaleRequest::Tare => "tare",
        ScaleRequest::Calibrate(_) => "calibrate",
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_volume_uses_the_density() {
        assert!((Density::WATER.millilitres(123.45) - 123.45 / 0.998).abs() < 1e-9);
        assert!((Density::new(1.25).unwrap().millilitres(123.45) - 98.76).abs() < 1e-9);
        assert!(Density::new(0.0).is_err() && Density::new(f64::NAN).is_err());
    }
}
