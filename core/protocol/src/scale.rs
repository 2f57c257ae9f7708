//! The scale's messages: weighings in three modes, zero, tare, the
//! two-point calibration, a stream of readings, its identity; and what the
//! scale device accepts and answers, the learner's messages besides its
//! own ([`Request`], [`Reply`]).
//!
//! A scale that streams sends replies numbered [`STREAM`] unasked, and
//! answers a weighing of the next stable reading ([`WeighMode::Next`])
//! only once it has one (and not at all if another request comes first:
//! the host gave up on it).
//!
//! The scale's requests and replies continue the learner's numbering: the
//! learner's messages have the same bytes on the scale as on the learning
//! coprocessor, so the host speaks one language to both, and the
//! coprocessor, which has no scale messages at all, cannot read a scale's
//! request (it answers [`FaultKind::BadFrame`]).

use core::fmt;

use heapless::String;
use serde::{Deserialize, Deserializer, Serialize, Serializer};

use crate::extend;
use crate::fault::Fault;
#[cfg(doc)]
use crate::fault::FaultKind;
use crate::learner;

/// Samples averaged into one filtered value.
pub const FILTER: usize = 16;
/// Samples the display must hold within one digit to be stable.
pub const WINDOW: usize = 80;
/// The sequence number of streamed readings (hosts never send it).
pub const STREAM: u32 = u32::MAX;
/// Length of the model name.
pub const MODEL: usize = 16;
/// Samples after a request before the filter and the whole stability
/// window hold samples of that time alone: the soonest a
/// [`WeighMode::Next`] reading can be.
pub const FRESH: u16 = (FILTER + WINDOW - 1) as u16;

/// What the host asks the scale.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ScaleRequest {
    /// Who are you? Answered with [`ScaleReply::Identity`].
    Identify,
    /// The weight, as `mode` says.
    Weigh {
        /// Which reading.
        mode: WeighMode,
        /// The unit to give it in.
        unit: Unit,
    },
    /// Send a reading (immediate, in grams) every `every` samples,
    /// numbered [`STREAM`]; 0 stops.
    Stream {
        /// Samples between readings.
        every: u16,
    },
    /// Sets the zero to the current stable load (within the zero range)
    /// and clears the tare.
    Zero,
    /// Sets the tare to the current stable net load.
    Tare,
    /// Takes one point of the two-point calibration at the current stable
    /// load.
    Calibrate(CalibrationPoint),
}

/// Which reading a [`ScaleRequest::Weigh`] asks for.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum WeighMode {
    /// The current reading, stable or not.
    Now,
    /// The current reading if stable, else the fault
    /// [`FaultKind::NotSettled`] (ask again). Within a second of a load
    /// change it can still be the old load's.
    Stable,
    /// The first stable reading made only of samples taken after the
    /// request ([`FRESH`] at least): answered when there is one, or with
    /// the fault [`FaultKind::NotSettled`] once `within` samples passed
    /// without one. An overload or underload is answered once the
    /// samples are fresh; a later request drops this one's answer.
    Next {
        /// Samples to wait at most, at least [`FRESH`].
        within: u16,
    },
}

/// A point of the two-point calibration: the known mass on the pan now.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub enum CalibrationPoint {
    /// The lower mass (usually the empty pan, 0 g); first.
    Low {
        /// Its mass, g.
        grams: f32,
    },
    /// The upper mass (a reference weight); completes the calibration,
    /// clears zero and tare.
    High {
        /// Its mass, g.
        grams: f32,
    },
}

/// What the scale answers (besides the learner's [`learner::Reply::Ok`]
/// and [`learner::Reply::Error`]).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub enum ScaleReply {
    /// Its identity and settings.
    Identity(Identity),
    /// A weight.
    Reading(Reading),
}

/// Units of a reading (primo's scale's and an MT-SICS balance's).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Unit {
    /// Grams.
    G,
    /// Milligrams.
    Mg,
    /// Kilograms.
    Kg,
}

impl Unit {
    /// The unit as it is written (`g`, `mg`, `kg`; MT-SICS writes these).
    pub fn symbol(self) -> &'static str {
        match self {
            Unit::G => "g",
            Unit::Mg => "mg",
            Unit::Kg => "kg",
        }
    }

    /// The unit `symbol` names, if it is one of these.
    pub fn from_symbol(symbol: &str) -> Option<Unit> {
        [Unit::Mg, Unit::G, Unit::Kg]
            .into_iter()
            .find(|u| u.symbol() == symbol)
    }

    /// The unit as a power of ten of a gram (mg: −3).
    pub fn exponent(self) -> i8 {
        match self {
            Unit::Mg => -3,
            Unit::G => 0,
            Unit::Kg => 3,
        }
    }
}

/// A weight: `digits × 10^exponent` of `unit`, exactly as displayed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub struct Reading {
    /// The displayed value in units of `10^exponent`.
    pub digits: i32,
    /// Decimal exponent of a digit.
    pub exponent: i8,
    /// The unit.
    pub unit: Unit,
    /// The display has held within one digit for [`WINDOW`] samples.
    pub stable: bool,
    /// A tare is set: the value is net.
    pub net: bool,
    /// Samples taken since power-on, when this was read.
    pub sample: u32,
}

impl Reading {
    /// The value in its unit.
    pub fn value(&self) -> f64 {
        f64::from(self.digits) * libm::pow(10.0, f64::from(self.exponent))
    }

    /// The value in grams.
    pub fn grams(&self) -> f64 {
        let per_unit = match self.unit {
            Unit::G => 1.0,
            Unit::Mg => 1e-3,
            Unit::Kg => 1e3,
        };
        self.value() * per_unit
    }
}

/// Who the scale is.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Identity {
    /// Model name.
    pub model: String<MODEL>,
    /// Serial number.
    pub serial: u32,
    /// Largest load, g.
    pub capacity: f32,
    /// Decimals of a gram shown (2: 0.01 g digits).
    pub decimals: u8,
    /// ADC samples per second.
    pub rate: u16,
    /// A calibration is in force.
    pub calibrated: bool,
}

/// What the scale device accepts: the learner's requests (the same bytes
/// as on the learning coprocessor) and the scale's, numbered after them.
#[derive(Clone, PartialEq)]
#[allow(clippy::large_enum_variant)] // the learner's setup: one per frame, as on the coprocessor
pub enum Request {
    /// A request to the learner the scale serves too.
    Learner(learner::Request),
    /// A request to the scale.
    Scale(ScaleRequest),
}

/// What the scale device answers: the learner's replies (among them
/// [`learner::Reply::Ok`] and [`learner::Reply::Error`], which the scale
/// answers too) and the scale's, numbered after them.
#[derive(Clone, PartialEq)]
pub enum Reply {
    /// A reply of the learner, or the scale's "done" or fault.
    Learner(learner::Reply),
    /// The scale's answer.
    Scale(ScaleReply),
}

impl Reply {
    /// The scale's "done; nothing to report".
    pub const OK: Reply = Reply::Learner(learner::Reply::Ok);
}

impl From<Fault> for Reply {
    fn from(fault: Fault) -> Self {
        Reply::Learner(learner::Reply::Error(fault))
    }
}

impl From<learner::Reply> for Reply {
    fn from(reply: learner::Reply) -> Self {
        Reply::Learner(reply)
    }
}

impl From<learner::Request> for Request {
    fn from(request: learner::Request) -> Self {
        Request::Learner(request)
    }
}

/// As the message it holds: a learner's request reads the same on either
/// device, a scale's as `Scale(…)`.
impl fmt::Debug for Request {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Request::Learner(r) => r.fmt(f),
            Request::Scale(r) => f.debug_tuple("Scale").field(r).finish(),
        }
    }
}

/// As the message it holds, like [`Request`]'s.
impl fmt::Debug for Reply {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Reply::Learner(r) => r.fmt(f),
            Reply::Scale(r) => f.debug_tuple("Scale").field(r).finish(),
        }
    }
}

impl Serialize for Request {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Request::Learner(r) => r.serialize(serializer),
            Request::Scale(r) => {
                extend::serialize::<learner::Request, _, _>(serializer, "Scale", r)
            }
        }
    }
}

impl<'de> Deserialize<'de> for Request {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        extend::deserialize(deserializer, Request::Learner, Request::Scale)
    }
}

impl Serialize for Reply {
    fn serialize<S: Serializer>(&self, serializer: S) -> Result<S::Ok, S::Error> {
        match self {
            Reply::Learner(r) => r.serialize(serializer),
            Reply::Scale(r) => extend::serialize::<learner::Reply, _, _>(serializer, "Scale", r),
        }
    }
}

impl<'de> Deserialize<'de> for Reply {
    fn deserialize<D: Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        extend::deserialize(deserializer, Reply::Learner, Reply::Scale)
    }
}
