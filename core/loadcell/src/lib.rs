//! # primo-loadcell
//!
//! Drivers of the 24-bit load-cell ADCs a scale board carries, on the
//! embedded-hal 1.0 pin and delay traits, behind one polled trait
//! ([`LoadCell`]) that the scale firmware reads its counts through:
//!
//! - [`hx711`]: the Avia HX711 (two pins: PD_SCK, DOUT).
//! - [`ads1232`]: the TI ADS1232 (SCLK, DRDY/DOUT, PDWN, and the GAIN0,
//!   GAIN1 and SPEED pins, which a board may strap instead: [`Strapped`]).
//!
//! Both shift out 24 bits of two's complement, MSB first, one bit a clock
//! pulse, once their data line goes low. A code at either end of the range
//! (0x7FFFFF, 0x800000) is the ADC saturated, not a weight: it is the error
//! [`Error::OutOfRange`]. No allocation, no panic; time is what the delay
//! waits, so the timing minima hold on any core, and the host's tests
//! check them against a pin-level model of each chip.
//!
//! A transfer is 24 to 27 clock pulses of 2 µs. The HX711 powers down when
//! PD_SCK stays high 60 µs: run a read where no interrupt can stretch a
//! pulse that long (a critical section, or the highest priority).
#![no_std]
#![deny(missing_docs)]
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

use core::convert::Infallible;

use embedded_hal::digital::{self, ErrorKind, ErrorType, InputPin, OutputPin};

pub mod ads1232;
pub mod hx711;

/// A 24-bit load-cell ADC, polled.
pub trait LoadCell {
    /// Why a sample could not be read.
    type Error;

    /// The next conversion's counts if one is ready, without waiting:
    /// `Ok(None)` when none is.
    fn sample(&mut self) -> Result<Option<i32>, Self::Error>;
}

/// Why a driver could not give a sample.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Error {
    /// No conversion was ready within the timeout: the chip is powered
    /// down, unwired, or not converting.
    NotReady,
    /// A saturated code: the input is beyond the ADC's range. `counts` is
    /// the full scale it stopped at, [`MAX`] or [`MIN`].
    OutOfRange {
        /// The saturated counts.
        counts: i32,
    },
    /// A pin failed (its HAL's error, as embedded-hal's kind: the pins'
    /// own error types differ, and a board can only report it).
    Pin(ErrorKind),
}

impl core::fmt::Display for Error {
    fn fmt(&self, f: &mut core::fmt::Formatter<'_>) -> core::fmt::Result {
        match self {
            Error::NotReady => f.write_str("no conversion ready within the timeout"),
            Error::OutOfRange { counts } => write!(f, "ADC saturated at {counts}"),
            Error::Pin(kind) => write!(f, "pin: {kind}"),
        }
    }
}

impl core::error::Error for Error {}

/// A pin's error as an [`Error`].
fn pin(e: impl digital::Error) -> Error {
    Error::Pin(e.kind())
}

/// The largest code: positive full scale, saturated.
pub const MAX: i32 = 0x7F_FFFF;
/// The smallest code: negative full scale, saturated.
pub const MIN: i32 = -0x80_0000;

/// The counts of 24 bits of two's complement, sign-extended, or
/// [`Error::OutOfRange`] for a saturated code.
pub fn counts(bits: u32) -> Result<i32, Error> {
    // The shift left then back drags the sign bit 23 through the top.
    let counts = ((bits << 8) as i32) >> 8;
    if counts == MAX || counts == MIN {
        return Err(Error::OutOfRange { counts });
    }
    Ok(counts)
}

/// Both chips' read: 24 pulses on `clock`, each `pulse_ns` high then
/// `pulse_ns` low, shifting in `data` after each rising edge, MSB first,
/// then `extra` more pulses (what they select is the chip's); the 24 bits.
fn transfer<C: OutputPin, D: InputPin, W: embedded_hal::delay::DelayNs>(
    clock: &mut C,
    data: &mut D,
    delay: &mut W,
    extra: u8,
    pulse_ns: u32,
) -> Result<u32, Error> {
    let mut bits = 0u32;
    for i in 0..24 + u32::from(extra) {
        clock.set_high().map_err(pin)?;
        delay.delay_ns(pulse_ns);
        let bit = data.is_high().map_err(pin)?;
        clock.set_low().map_err(pin)?;
        delay.delay_ns(pulse_ns);
        if i < 24 {
            bits = bits << 1 | u32::from(bit);
        }
    }
    Ok(bits)
}

/// An output a board ties to a fixed level instead of a GPIO (the
/// ADS1232's gain and speed pins, often): setting it does nothing.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Strapped;

impl ErrorType for Strapped {
    type Error = Infallible;
}

impl OutputPin for Strapped {
    fn set_low(&mut self) -> Result<(), Infallible> {
        Ok(())
    }

    fn set_high(&mut self) -> Result<(), Infallible> {
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn counts_sign_extend_and_saturated_codes_are_out_of_range() {
        assert_eq!(counts(0), Ok(0));
        assert_eq!(counts(1), Ok(1));
        assert_eq!(counts(0xFF_FFFF), Ok(-1));
        assert_eq!(counts(0x7F_FFFE), Ok(MAX - 1));
        assert_eq!(counts(0x80_0001), Ok(MIN + 1));
        assert_eq!(counts(0x7F_FFFF), Err(Error::OutOfRange { counts: MAX }));
        assert_eq!(counts(0x80_0000), Err(Error::OutOfRange { counts: MIN }));
        // Bits above the 24th are ignored.
        assert_eq!(counts(0xFF00_0005), Ok(5));
    }
}
