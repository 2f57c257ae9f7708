//! # primo-device
//!
//! The scale as a primo device, sans I/O: the scale itself ([`scale`]:
//! filter, calibration, zero and tare, stability, faults: the handler of
//! the scale's messages), and the loop every scale image runs
//! ([`ScaleDevice`]: the frames of the scale's endpoint,
//! [`primo_protocol::endpoint::Scale`], from the host to the learner
//! service or the scale, the load cell's counts to the scale, its replies
//! and streamed readings back, a changed setting to the store), over three
//! thin adapters an image supplies:
//!
//! - a byte [`Port`] to the host (a UART, polled);
//! - a [`LoadCell`] (`primo_loadcell`'s HX711 or ADS1232 driver on a
//!   board, the counts on a second UART under QEMU);
//! - a [`SettingsStore`] for the calibration, zero and tare (a RAM page
//!   under QEMU, the flash page through [`stm32g4::FlashSettings`] on an
//!   STM32G4).
//!
//! The scale's algorithm lives here rather than in the protocol or a crate
//! of its own: only the scale device runs it (the host's tests run it
//! through this crate too), and the protocol stays what both ends agree
//! on.
//!
//! [`page`] is the settings page's bytes (one CRC-checked wire frame), the
//! same on every store; [`stm32g4`] the STM32G4 flash controller's erase
//! and program sequence, over a register trait so the host's tests run it
//! against a model of the controller.
#![no_std]
#![deny(missing_docs)]
// `!(x > 0.0)` is the idiom that also rejects NaN; keep it.
#![allow(clippy::neg_cmp_op_on_partial_ord)]
#![cfg_attr(
    not(test),
    deny(
        clippy::unwrap_used,
        clippy::expect_used,
        clippy::panic,
        clippy::indexing_slicing,
        clippy::unreachable,
        clippy::todo,
        clippy::unimplemented
    )
)]

#[cfg(test)]
extern crate std;

pub mod page;
pub mod scale;
pub mod stm32g4;

use core::convert::Infallible;

use primo_learner::Coprocessor as Service;
pub use primo_loadcell::LoadCell;
use primo_protocol::endpoint::Scale as ScaleEndpoint;
use primo_protocol::frame::{self, FrameError, FrameReader, MAX_FRAME};
use primo_protocol::replay::Replay;
use primo_protocol::scale::{Reply, Request, STREAM};

use crate::scale::{Scale, Settings};

/// The host's line, byte by byte, polled.
pub trait Port {
    /// The byte received, if one is waiting.
    fn try_read_byte(&mut self) -> Option<u8>;
    /// Sends `bytes`, waiting while the transmitter is full.
    fn write_all(&mut self, bytes: &[u8]);
}

/// Where the scale's settings survive a reset.
pub trait SettingsStore {
    /// Why a store failed.
    type Error;
    /// The settings kept, if the store holds an intact copy (else the
    /// scale starts from its factory settings: uncalibrated, no tare).
    fn load(&mut self) -> Option<Settings>;
    /// Keeps `settings`.
    fn store(&mut self, settings: &Settings) -> Result<(), Self::Error>;
}

/// A load cell's error that is a saturated ADC rather than no sample: the
/// loop weighs the full-scale counts (an overload or an underload to the
/// scale) instead of the last good reading.
pub trait Saturation {
    /// The full-scale counts the ADC stopped at, if saturated.
    fn saturated(&self) -> Option<i32>;
}

impl Saturation for Infallible {
    fn saturated(&self) -> Option<i32> {
        match *self {}
    }
}

impl Saturation for primo_loadcell::Error {
    fn saturated(&self) -> Option<i32> {
        match self {
            primo_loadcell::Error::OutOfRange { counts } => Some(*counts),
            _ => None,
        }
    }
}

/// Answers one frame off the line to the scale device (`raw` as
/// [`FrameReader::push`] gives it), through `replay`: a learner's request
/// to `service`, a scale's to `scale`. Returns the reply frame's length in
/// `out`: 0 for a weighing the scale defers, whose answer comes from
/// [`Scale::deferred`] and [`Replay::deferred`] after a sample (unless
/// another frame comes first).
pub fn answer(
    service: &mut Service,
    scale: &mut Scale,
    replay: &mut Replay,
    raw: Result<&[u8], FrameError>,
    out: &mut [u8; MAX_FRAME],
) -> usize {
    replay.serve::<ScaleEndpoint>(raw, out, |request| match request {
        Request::Learner(r) => Some(Reply::Learner(service.respond(r))),
        Request::Scale(r) => scale.respond(r),
    })
}

/// What one [`ScaleDevice::poll`] did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[must_use]
pub struct Pass<E> {
    /// Nothing came from the host or the load cell: the image may sleep
    /// until a byte or a sample can come.
    pub idle: bool,
    /// A changed setting was stored, and how that went (the last, if
    /// several changed).
    pub stored: Option<Result<(), E>>,
}

/// The scale and the learner service on one device: the loop of every
/// scale image. The service and the scale are large (16 KiB): the image
/// keeps them in statics and lends them here. The learner's and the
/// scale's requests share one [`Replay`] (one sequence of frames).
pub struct ScaleDevice<'a> {
    service: &'a mut Service,
    scale: &'a mut Scale,
    reader: &'a mut FrameReader,
    replay: Replay,
    out: [u8; MAX_FRAME],
}

impl<'a> ScaleDevice<'a> {
    /// The device on its parts.
    pub fn new(
        service: &'a mut Service,
        scale: &'a mut Scale,
        reader: &'a mut FrameReader,
    ) -> Self {
        ScaleDevice {
            service,
            scale,
            reader,
            replay: Replay::new(),
            out: [0; MAX_FRAME],
        }
    }

    /// Power-on: the scale takes the settings `store` keeps, if it keeps
    /// intact ones (true), else it keeps its factory settings (false).
    pub fn boot(&mut self, store: &mut impl SettingsStore) -> bool {
        let Some(kept) = store.load() else {
            return false;
        };
        self.scale.restore(kept);
        true
    }

    /// One pass: every byte waiting on `host` (each whole frame answered
    /// by the service or the scale, a changed setting stored), then every
    /// sample `cell` has ready (the deferred weighing's answer once due,
    /// and the streamed readings, sent to `host`).
    pub fn poll<H, C, S>(&mut self, host: &mut H, cell: &mut C, store: &mut S) -> Pass<S::Error>
    where
        H: Port,
        C: LoadCell,
        C::Error: Saturation,
        S: SettingsStore,
    {
        let mut idle = true;
        let mut stored = None;
        while let Some(byte) = host.try_read_byte() {
            idle = false;
            let Some(raw) = self.reader.push(byte) else {
                continue;
            };
            let len = answer(
                self.service,
                self.scale,
                &mut self.replay,
                raw,
                &mut self.out,
            );
            host.write_all(self.out.get(..len).unwrap_or(&[]));
            if let Some(changed) = self.scale.take_changed() {
                stored = Some(store.store(changed));
            }
        }
        loop {
            let counts = match cell.sample() {
                Ok(Some(counts)) => counts,
                Ok(None) => break,
                Err(e) => match e.saturated() {
                    Some(full_scale) => full_scale,
                    None => break,
                },
            };
            idle = false;
            self.scale.push(counts);
            if let Some(reply) = self.scale.deferred()
                && let Some(len) = self.replay.deferred(&reply, &mut self.out)
            {
                host.write_all(self.out.get(..len).unwrap_or(&[]));
            }
            if let Some(reading) = self.scale.streamed()
                && let Ok(frame) = frame::encode(STREAM, &reading, &mut self.out)
            {
                host.write_all(frame);
            }
        }
        Pass { idle, stored }
    }
}
