//! The load-cell scale, the handler of the scale's messages
//! ([`primo_protocol::scale`]): raw counts of a 24-bit ADC in, weights
//! out, with no I/O, so the scale firmware and the host's tests run the
//! same code. It lives with the scale device, not in the protocol: the
//! protocol says what a reading is, this is how one is made.
//!
//! - **Filter**: the mean of the last [`FILTER`] samples (integer sums, so
//!   every target computes the same bits).
//! - **Calibration**: two points `(counts, grams)` ([`CalibrationPoint`]),
//!   a straight line through them; **zero** and **tare** in grams. They
//!   are the [`Settings`] the firmware keeps in a flash page: every change
//!   is reported once by [`Scale::take_changed`].
//! - **Stability**, as a lab balance's: the displayed digits have held
//!   within one digit for the last [`WINDOW`] samples (a second at 80
//!   samples per second); the ADC's sample rate is the clock.
//! - **Weighing**: the current reading, the current one if stable, or the
//!   next stable one ([`WeighMode`]): the first stable reading made only of
//!   samples taken after the request (as MT-SICS `S` after a change), so a
//!   weighing just after a load change cannot give the old load. Its answer
//!   waits for the samples: [`Scale::respond`] defers it, and
//!   [`Scale::deferred`], polled after each [`Scale::push`], gives it.
//! - **Faults**: overload (beyond the capacity), underload (below the zero
//!   range), not settled, uncalibrated, as typed [`FaultKind`]s.
//!
//! The samples reach the firmware from the ADC, or under QEMU over a UART
//! as [`encode_sample`] writes them (a real board reads an HX711 or an
//! ADS1232 instead).
//!
//! ```
//! use primo_device::scale::{Scale, ScaleConfig};
//! use primo_protocol::scale::{CalibrationPoint, Reply, ScaleReply, ScaleRequest};
//! use primo_protocol::scale::{Unit, WeighMode, FILTER, FRESH, WINDOW};
//! let mut s = Scale::new(ScaleConfig::LAB);
//! let mut settle = |s: &mut Scale, counts: i32| (0..FILTER + WINDOW).for_each(|_| s.push(counts));
//! settle(&mut s, 12_000);
//! let low = ScaleRequest::Calibrate(CalibrationPoint::Low { grams: 0.0 });
//! assert_eq!(s.respond(&low), Some(Reply::OK));
//! settle(&mut s, 512_000); // 500 g at 1000 counts per gram
//! let high = ScaleRequest::Calibrate(CalibrationPoint::High { grams: 500.0 });
//! assert_eq!(s.respond(&high), Some(Reply::OK));
//! let weigh = |mode| ScaleRequest::Weigh { mode, unit: Unit::G };
//! let Some(Reply::Scale(ScaleReply::Reading(r))) = s.respond(&weigh(WeighMode::Stable))
//! else { panic!() };
//! assert_eq!((r.digits, r.exponent, r.stable), (50_000, -2, true));
//! // 100 g more: the next stable reading waits for samples of it alone.
//! assert_eq!(s.respond(&weigh(WeighMode::Next { within: 400 })), None);
//! let mut pushed = 0;
//! let r = loop {
//!     s.push(612_000);
//!     pushed += 1;
//!     if let Some(Reply::Scale(ScaleReply::Reading(r))) = s.deferred() {
//!         break r;
//!     }
//! };
//! assert_eq!((r.digits, pushed), (60_000, FRESH));
//! ```

use heapless::String;
use primo_protocol::fault::{Fault, FaultKind};
use primo_protocol::scale::{
    CalibrationPoint, FILTER, FRESH, Identity, Reading, Reply, ScaleReply, ScaleRequest, Unit,
    WINDOW, WeighMode,
};
use serde::{Deserialize, Serialize};

/// A scale's fixed properties.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleConfig {
    /// Serial number.
    pub serial: u32,
    /// Largest load, g.
    pub capacity: f32,
    /// Decimals of a gram shown.
    pub decimals: u8,
    /// ADC samples per second.
    pub rate: u16,
    /// Zero works within ± this of the calibrated zero, and below its
    /// negative the scale is underloaded, g.
    pub zero_range: f32,
}

impl ScaleConfig {
    /// A 0.01 g laboratory scale of 4.2 kg on an 80 samples per second
    /// ADC, zero range ±2 % of the capacity (the simulated cell's).
    pub const LAB: ScaleConfig = ScaleConfig {
        serial: 1,
        capacity: 4200.0,
        decimals: 2,
        rate: 80,
        zero_range: 84.0,
    };
}

/// A two-point calibration: `grams = grams_low + (counts − counts_low) ×
/// gain`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Calibration {
    /// Filtered counts at the lower mass.
    pub counts_low: i32,
    /// The lower mass, g.
    pub grams_low: f32,
    /// Grams per count.
    pub gain: f32,
}

/// What survives a reset (the firmware keeps it in a flash page, as a
/// [`primo_protocol::frame`]: CRC-checked; see [`crate::page`]).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub struct Settings {
    /// The calibration, once both points were taken.
    pub calibration: Option<Calibration>,
    /// The first point of a calibration in progress: counts and grams.
    pub low: Option<(i32, f32)>,
    /// Gross grams shown as zero.
    pub zero: f32,
    /// Tare, g.
    pub tare: f32,
}

/// The scale (see the module docs).
#[derive(Debug, Clone)]
pub struct Scale {
    config: ScaleConfig,
    settings: Settings,
    changed: bool,
    /// The last [`FILTER`] samples and their sum.
    recent: [i32; FILTER],
    sum: i64,
    /// The displayed digits of the last [`WINDOW`] samples.
    shown: [i32; WINDOW],
    /// Samples since power-on (wrapping).
    samples: u32,
    /// Samples so far, up to [`FILTER`] + [`WINDOW`].
    warm: usize,
    stream_every: u16,
    /// The [`WeighMode::Next`] weighing waiting for its reading.
    next: Option<Next>,
}

/// A deferred [`WeighMode::Next`] weighing.
#[derive(Debug, Clone, Copy)]
struct Next {
    unit: Unit,
    /// [`Scale::samples`] when it was asked.
    asked: u32,
    within: u16,
}

/// Counts per nominal digit while uncalibrated, so that a calibration
/// point waits for a stable load too.
const RAW_DIGIT: f32 = 16.0;

/// A fault reply.
fn fault(kind: FaultKind, detail: &str) -> Reply {
    Reply::from(Fault::new(kind, detail))
}

impl Scale {
    /// A scale of `config`, uncalibrated, with no samples yet.
    pub const fn new(config: ScaleConfig) -> Self {
        Scale {
            config,
            settings: Settings {
                calibration: None,
                low: None,
                zero: 0.0,
                tare: 0.0,
            },
            changed: false,
            recent: [0; FILTER],
            sum: 0,
            shown: [0; WINDOW],
            samples: 0,
            warm: 0,
            stream_every: 0,
            next: None,
        }
    }

    /// Takes the settings kept over a reset.
    pub fn restore(&mut self, settings: Settings) {
        self.settings = settings;
    }

    /// The settings, once after each change (for the flash page).
    pub fn take_changed(&mut self) -> Option<&Settings> {
        core::mem::take(&mut self.changed).then_some(&self.settings)
    }

    /// One ADC sample.
    pub fn push(&mut self, counts: i32) {
        let slot = self.samples as usize % FILTER;
        if let Some(old) = self.recent.get_mut(slot) {
            self.sum += i64::from(counts) - i64::from(*old);
            *old = counts;
        }
        self.samples = self.samples.wrapping_add(1);
        self.warm = (self.warm + 1).min(FILTER + WINDOW);
        let digits = self.shown_now();
        if let Some(d) = self.shown.get_mut(self.samples as usize % WINDOW) {
            *d = digits;
        }
    }

    /// What the display shows now, in digits (uncalibrated: in nominal
    /// digits of [`RAW_DIGIT`] counts).
    fn shown_now(&self) -> i32 {
        self.display(self.gross()).unwrap_or_else(|| {
            // `as` saturates.
            self.filtered()
                .map_or(0, |c| libm::roundf(c / RAW_DIGIT) as i32)
        })
    }

    /// After a change of the display's meaning: the load was stable, and
    /// the display stays so.
    fn refill(&mut self) {
        let now = self.shown_now();
        self.shown.fill(now);
    }

    /// The filtered counts; `None` until [`FILTER`] samples arrived.
    fn filtered(&self) -> Option<f32> {
        (self.warm >= FILTER).then(|| self.sum as f32 / FILTER as f32)
    }

    /// The gross load, g: `None` uncalibrated or without samples.
    fn gross(&self) -> Option<f32> {
        let c = self.settings.calibration?;
        Some(c.grams_low + (self.filtered()? - c.counts_low as f32) * c.gain)
    }

    /// Grams per displayed digit.
    fn digit(&self) -> f32 {
        libm::powf(10.0, -f32::from(self.config.decimals))
    }

    /// The net load of `gross` in displayed digits.
    fn display(&self, gross: Option<f32>) -> Option<i32> {
        let net = gross? - self.settings.zero - self.settings.tare;
        // `as` saturates: an absurd load is an overload, caught before.
        Some(libm::roundf(net / self.digit()) as i32)
    }

    /// The display has held within one digit for [`WINDOW`] samples.
    fn stable(&self) -> bool {
        let (lo, hi) = self
            .shown
            .iter()
            .fold((i32::MAX, i32::MIN), |(lo, hi), d| (lo.min(*d), hi.max(*d)));
        self.warm >= FILTER + WINDOW && hi.saturating_sub(lo) <= 1
    }

    /// The gross load within the scale's range, or the fault.
    fn load(&self) -> Result<f32, Reply> {
        if self.settings.calibration.is_none() {
            return Err(fault(FaultKind::Uncalibrated, "calibrate the scale"));
        }
        let gross = self
            .gross()
            .ok_or_else(|| fault(FaultKind::NotSettled, "no samples yet"))?;
        if !(gross <= self.config.capacity) {
            return Err(fault(FaultKind::Overload, "beyond the capacity"));
        }
        if gross - self.settings.zero < -self.config.zero_range {
            return Err(fault(FaultKind::Underload, "below the zero range"));
        }
        Ok(gross)
    }

    /// The current reading in `unit`.
    fn reading(&self, unit: Unit) -> Result<Reading, Reply> {
        let gross = self.load()?;
        let digits = self.display(Some(gross)).unwrap_or(0);
        Ok(Reading {
            digits,
            exponent: -unit.exponent() - self.config.decimals as i8,
            unit,
            stable: self.stable(),
            net: self.settings.tare != 0.0,
            sample: self.samples,
        })
    }

    /// The stable filtered counts, or why not.
    fn settled(&self) -> Result<f32, Reply> {
        match self.filtered() {
            Some(c) if self.stable() => Ok(c),
            _ => Err(fault(FaultKind::NotSettled, "not stable yet")),
        }
    }

    /// The stream's next reading, after a [`Scale::push`], when one is due.
    pub fn streamed(&self) -> Option<Reply> {
        let every = u32::from(self.stream_every);
        (every > 0 && self.samples.is_multiple_of(every)).then(|| {
            self.reading(Unit::G)
                .map_or_else(|e| e, |r| Reply::Scale(ScaleReply::Reading(r)))
        })
    }

    /// The answer to a deferred [`WeighMode::Next`] weighing, after a
    /// [`Scale::push`], once it is due (then no more).
    pub fn deferred(&mut self) -> Option<Reply> {
        let next = self.next?;
        let taken = self.samples.wrapping_sub(next.asked);
        let fresh = taken >= u32::from(FRESH);
        let answer = match self.reading(next.unit) {
            Ok(r) if fresh && r.stable => Some(Reply::Scale(ScaleReply::Reading(r))),
            Err(e) if fresh => Some(e),
            _ if taken >= u32::from(next.within) => Some(fault(
                FaultKind::NotSettled,
                "no stable reading within the samples given",
            )),
            _ => None,
        };
        if answer.is_some() {
            self.next = None;
        }
        answer
    }

    /// The scale's identity.
    pub fn identity(&self) -> Identity {
        let mut model = String::new();
        let _ = model.push_str("primo-scale");
        Identity {
            model,
            serial: self.config.serial,
            capacity: self.config.capacity,
            decimals: self.config.decimals,
            rate: self.config.rate,
            calibrated: self.settings.calibration.is_some(),
        }
    }

    /// Answers one request: `None` defers the answer to
    /// [`Scale::deferred`] (a [`WeighMode::Next`] weighing). Any request
    /// drops a deferred answer not given yet.
    pub fn respond(&mut self, request: &ScaleRequest) -> Option<Reply> {
        self.next = None;
        let done = match request {
            ScaleRequest::Identify => {
                return Some(Reply::Scale(ScaleReply::Identity(self.identity())));
            }
            ScaleRequest::Weigh { mode, unit } => return self.weigh(*mode, *unit),
            ScaleRequest::Stream { every } => {
                self.stream_every = *every;
                return Some(Reply::OK);
            }
            ScaleRequest::Zero => self.zero(),
            ScaleRequest::Tare => self.tare(),
            ScaleRequest::Calibrate(point) => self.calibrate(*point),
        };
        Some(match done {
            Ok(()) => {
                self.changed = true;
                self.refill();
                Reply::OK
            }
            Err(e) => e,
        })
    }

    fn weigh(&mut self, mode: WeighMode, unit: Unit) -> Option<Reply> {
        let within = match mode {
            WeighMode::Next { within } => within,
            WeighMode::Now | WeighMode::Stable => {
                return Some(match self.reading(unit) {
                    Ok(r) if mode == WeighMode::Stable && !r.stable => {
                        fault(FaultKind::NotSettled, "not stable yet")
                    }
                    Ok(r) => Reply::Scale(ScaleReply::Reading(r)),
                    Err(e) => e,
                });
            }
        };
        if self.settings.calibration.is_none() {
            return Some(fault(FaultKind::Uncalibrated, "calibrate the scale"));
        }
        if within < FRESH {
            return Some(Reply::from(Fault::new(
                FaultKind::Invalid,
                format_args!("wait at least {FRESH} samples for the next stable reading"),
            )));
        }
        self.next = Some(Next {
            unit,
            asked: self.samples,
            within,
        });
        None
    }

    fn zero(&mut self) -> Result<(), Reply> {
        let gross = self.load()?;
        self.settled()?;
        if gross > self.config.zero_range {
            return Err(fault(FaultKind::Overload, "beyond the zero range"));
        }
        self.settings.zero = gross;
        self.settings.tare = 0.0;
        Ok(())
    }

    fn tare(&mut self) -> Result<(), Reply> {
        let gross = self.load()?;
        self.settled()?;
        self.settings.tare = gross - self.settings.zero;
        Ok(())
    }

    fn calibrate(&mut self, point: CalibrationPoint) -> Result<(), Reply> {
        let counts = self.settled()?;
        let invalid = |why| Err(fault(FaultKind::Invalid, why));
        match point {
            CalibrationPoint::Low { grams } if grams.is_finite() && grams >= 0.0 => {
                self.settings.low = Some((libm::roundf(counts) as i32, grams));
                Ok(())
            }
            CalibrationPoint::High { grams } if grams.is_finite() && grams > 0.0 => {
                let Some((counts_low, grams_low)) = self.settings.low else {
                    return Err(fault(FaultKind::BadState, "take the low point first"));
                };
                let gain = (grams - grams_low) / (counts - counts_low as f32);
                if !(gain.is_finite() && gain > 0.0 && grams > grams_low) {
                    return invalid("the high point must weigh more than the low one");
                }
                self.settings = Settings {
                    calibration: Some(Calibration {
                        counts_low,
                        grams_low,
                        gain,
                    }),
                    ..Settings::default()
                };
                Ok(())
            }
            _ => invalid("a calibration mass must be finite and >= 0 g (the high one > 0 g)"),
        }
    }
}

/// Bytes of one sample on the ADC line.
pub const SAMPLE_BYTES: usize = 4;

/// One 24-bit sample as the ADC line carries it: 24 bits of two's
/// complement and a 4-bit check in 28 bits, 7 to a byte, the first byte
/// marked by its top bit, so a reader resynchronizes after a lost byte.
pub fn encode_sample(counts: i32) -> [u8; SAMPLE_BYTES] {
    let v = (counts as u32) & 0x00FF_FFFF;
    [
        0x80 | (v >> 17) as u8 & 0x7F,
        (v >> 10) as u8 & 0x7F,
        (v >> 3) as u8 & 0x7F,
        ((v & 7) << 4) as u8 | check(v),
    ]
}

/// The xor of the six nibbles of a 24-bit value.
fn check(v: u32) -> u8 {
    (0..6).fold(0u8, |c, i| c ^ ((v >> (4 * i)) & 0xF) as u8)
}

/// Reads samples off the ADC line, byte by byte, dropping damaged ones.
#[derive(Debug, Clone, Default)]
pub struct SampleReader {
    bits: u32,
    len: u8,
}

impl SampleReader {
    /// A reader waiting for the first sample's start.
    pub const fn new() -> Self {
        SampleReader { bits: 0, len: 0 }
    }

    /// Feeds one byte; returns the sample it completes, if intact.
    pub fn push(&mut self, byte: u8) -> Option<i32> {
        if byte & 0x80 != 0 {
            self.bits = u32::from(byte & 0x7F);
            self.len = 1;
            return None;
        }
        if self.len == 0 {
            return None;
        }
        self.bits = self.bits << 7 | u32::from(byte);
        self.len += 1;
        if self.len < SAMPLE_BYTES as u8 {
            return None;
        }
        self.len = 0;
        let v = self.bits >> 4;
        // Sign-extend the 24 bits.
        (check(v) == (self.bits & 0xF) as u8).then_some(((v << 8) as i32) >> 8)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use primo_protocol::frame::{self, MAX_FRAME};
    use primo_protocol::learner::Reply as LearnerReply;
    use std::vec::Vec;

    fn settle(s: &mut Scale, counts: i32) {
        (0..FILTER + WINDOW).for_each(|_| s.push(counts));
    }

    fn calibrated() -> Scale {
        let mut s = Scale::new(ScaleConfig::LAB);
        settle(&mut s, 10_000);
        s.respond(&ScaleRequest::Calibrate(CalibrationPoint::Low {
            grams: 0.0,
        }));
        settle(&mut s, 1_010_000);
        let high = ScaleRequest::Calibrate(CalibrationPoint::High { grams: 1000.0 });
        assert_eq!(s.respond(&high), Some(Reply::OK));
        s
    }

    fn weigh(s: &mut Scale, stable: bool) -> Result<Reading, FaultKind> {
        let mode = if stable {
            WeighMode::Stable
        } else {
            WeighMode::Now
        };
        match s.respond(&ScaleRequest::Weigh {
            mode,
            unit: Unit::G,
        }) {
            Some(Reply::Scale(ScaleReply::Reading(r))) => Ok(r),
            Some(Reply::Learner(LearnerReply::Error(f))) => Err(f.kind),
            other => panic!("{other:?}"),
        }
    }

    #[test]
    fn samples_round_trip_and_damage_is_dropped() {
        for v in [0, 1, -1, 8_388_607, -8_388_608, 123_456, -654_321] {
            let mut r = SampleReader::new();
            let bytes = encode_sample(v);
            let got: Vec<_> = bytes.iter().filter_map(|b| r.push(*b)).collect();
            assert_eq!(got, [v]);
            for i in 0..SAMPLE_BYTES {
                for bit in 0..7 {
                    let mut bad = bytes;
                    bad[i] ^= 1 << bit;
                    let mut r = SampleReader::new();
                    let got: Vec<_> = bad.iter().filter_map(|b| r.push(*b)).collect();
                    assert!(got.is_empty(), "{v} byte {i} bit {bit}: {got:?}");
                }
            }
        }
        // A lost byte costs its sample only.
        let mut line: Vec<u8> = encode_sample(5)[1..].to_vec();
        line.extend(encode_sample(-7));
        let mut r = SampleReader::new();
        assert_eq!(
            line.iter().filter_map(|b| r.push(*b)).collect::<Vec<_>>(),
            [-7]
        );
    }

    #[test]
    fn uncalibrated_and_unsettled_are_faults() {
        let mut s = Scale::new(ScaleConfig::LAB);
        assert_eq!(weigh(&mut s, false), Err(FaultKind::Uncalibrated));
        let mut s = calibrated();
        s.push(2_000_000);
        assert_eq!(weigh(&mut s, true), Err(FaultKind::NotSettled));
        assert!(!weigh(&mut s, false).unwrap().stable);
        assert_eq!(
            s.respond(&ScaleRequest::Tare),
            Some(fault(FaultKind::NotSettled, "not stable yet"))
        );
    }

    #[test]
    fn weighs_tares_and_zeroes_in_digits() {
        let mut s = calibrated();
        assert!(s.take_changed().is_some());
        assert!(s.take_changed().is_none());
        settle(&mut s, 260_000); // 250 g
        let r = weigh(&mut s, true).unwrap();
        assert_eq!((r.digits, r.grams(), r.net), (25_000, 250.0, false));
        assert_eq!(s.respond(&ScaleRequest::Tare), Some(Reply::OK));
        settle(&mut s, 270_000);
        let r = weigh(&mut s, true).unwrap();
        assert_eq!((r.digits, r.net), (1_000, true));
        let Some(Reply::Scale(ScaleReply::Reading(kg))) = s.respond(&ScaleRequest::Weigh {
            mode: WeighMode::Stable,
            unit: Unit::Kg,
        }) else {
            panic!()
        };
        assert_eq!((kg.digits, kg.exponent), (1_000, -5));
        // Zero only near the calibrated zero.
        assert_eq!(
            s.respond(&ScaleRequest::Zero),
            Some(fault(FaultKind::Overload, "beyond the zero range"))
        );
        settle(&mut s, 15_000); // 5 g
        assert_eq!(s.respond(&ScaleRequest::Zero), Some(Reply::OK));
        assert_eq!(weigh(&mut s, true).unwrap().digits, 0);
        assert_eq!(s.take_changed().unwrap().zero, 5.0);
    }

    #[test]
    fn stability_is_one_digit_for_the_window() {
        let mut s = calibrated();
        // ±1 count (0.001 g) of noise: one digit at most.
        for i in 0..200 {
            s.push(110_000 + i % 3 - 1);
        }
        assert!(weigh(&mut s, true).is_ok());
        // A 0.03 g step is three digits: unstable until the window has
        // passed since the filter took it in.
        let mut stable_after = None;
        for i in 0..2 * (WINDOW + FILTER) {
            s.push(110_030);
            let stable = weigh(&mut s, false).unwrap().stable;
            if !stable {
                stable_after = None;
            } else if stable_after.is_none() {
                stable_after = Some(i);
            }
        }
        let at = stable_after.unwrap();
        assert!((WINDOW..WINDOW + FILTER).contains(&at), "{at}");
        assert_eq!(weigh(&mut s, true).unwrap().digits, 10_003);
    }

    #[test]
    fn overload_and_underload() {
        let mut s = calibrated();
        settle(&mut s, 4_300_000);
        assert_eq!(weigh(&mut s, false), Err(FaultKind::Overload));
        settle(&mut s, -90_000);
        assert_eq!(weigh(&mut s, false), Err(FaultKind::Underload));
    }

    #[test]
    fn settings_survive_as_a_frame() {
        let mut s = calibrated();
        let saved = *s.take_changed().unwrap();
        let mut buf = [0u8; MAX_FRAME];
        let frame = frame::encode(0, &saved, &mut buf).unwrap();
        let back = frame::decode::<Settings>(&frame[..frame.len() - 1]).unwrap();
        let mut fresh = Scale::new(ScaleConfig::LAB);
        fresh.restore(back.body);
        settle(&mut fresh, 510_000);
        assert_eq!(weigh(&mut fresh, true).unwrap().digits, 50_000);
    }

    #[test]
    fn streams_every_n_samples() {
        let mut s = calibrated();
        assert_eq!(
            s.respond(&ScaleRequest::Stream { every: 8 }),
            Some(Reply::OK)
        );
        let n = (0..80)
            .filter(|_| {
                s.push(10_000);
                s.streamed().is_some()
            })
            .count();
        assert_eq!(n, 10);
    }

    /// A [`WeighMode::Next`] weighing of `within` samples, pushing
    /// `counts(i)` for the i-th sample after it: the answer and the
    /// samples it took.
    fn next(s: &mut Scale, within: u16, counts: impl Fn(u32) -> i32) -> (Reply, u32) {
        let request = ScaleRequest::Weigh {
            mode: WeighMode::Next { within },
            unit: Unit::G,
        };
        assert_eq!(s.respond(&request), None);
        for i in 1..=u32::from(u16::MAX) {
            s.push(counts(i));
            if let Some(answer) = s.deferred() {
                assert_eq!(s.deferred(), None, "answered twice");
                return (answer, i);
            }
        }
        panic!("no answer")
    }

    #[test]
    fn the_next_stable_reading_is_of_the_new_load_only() {
        let mut s = calibrated();
        settle(&mut s, 260_000); // 250 g
        // 50 g more on the pan, but no sample of it yet (the ADC's
        // latency, a sample period): the stable reading is the old one.
        assert_eq!(weigh(&mut s, true).unwrap().digits, 25_000);
        let (answer, took) = next(&mut s, 400, |_| 310_000);
        let Reply::Scale(ScaleReply::Reading(r)) = answer else {
            panic!("{answer:?}")
        };
        assert_eq!((r.digits, r.stable, took), (30_000, true, u32::from(FRESH)));
        // A load still moving is not settled by the deadline, exactly.
        let (answer, took) = next(&mut s, 300, |i| 310_000 + 100 * i as i32);
        assert!(
            matches!(answer, Reply::Learner(LearnerReply::Error(f)) if f.kind == FaultKind::NotSettled)
        );
        assert_eq!(took, 300);
        // It settles once it stops: a window of displays later, once the
        // filter holds samples of the rest alone.
        let (answer, took) = next(&mut s, 1000, |i| 310_000 + 100 * i.min(200) as i32);
        assert!(matches!(answer, Reply::Scale(_)), "{answer:?}");
        let window = 200 + WINDOW as u32..=200 + u32::from(FRESH);
        assert!(window.contains(&took), "{took}");
    }

    #[test]
    fn the_next_stable_reading_faults() {
        let mut s = Scale::new(ScaleConfig::LAB);
        let request = |within| ScaleRequest::Weigh {
            mode: WeighMode::Next { within },
            unit: Unit::G,
        };
        let kind = |r: Option<Reply>| match r {
            Some(Reply::Learner(LearnerReply::Error(f))) => f.kind,
            other => panic!("{other:?}"),
        };
        assert_eq!(kind(s.respond(&request(400))), FaultKind::Uncalibrated);
        let mut s = calibrated();
        assert_eq!(kind(s.respond(&request(FRESH - 1))), FaultKind::Invalid);
        // An overload is answered once the samples are fresh.
        let (answer, took) = next(&mut s, 1000, |_| 4_300_000);
        assert!(
            matches!(answer, Reply::Learner(LearnerReply::Error(f)) if f.kind == FaultKind::Overload)
        );
        assert_eq!(took, u32::from(FRESH));
        // Another request drops the deferred answer.
        assert_eq!(s.respond(&request(400)), None);
        assert!(s.respond(&ScaleRequest::Identify).is_some());
        settle(&mut s, 10_000);
        assert_eq!(s.deferred(), None);
    }
}
