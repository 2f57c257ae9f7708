//! The Avia HX711: two pins, PD_SCK (ours) and DOUT (the chip's).
//!
//! DOUT low: a conversion is ready. 24 PD_SCK pulses shift it out MSB
//! first, each bit valid 0.1 µs after the rising edge; 1 to 3 pulses more
//! (25 to 27 in all) pull DOUT high again and choose the next
//! conversion's input and gain ([`Gain`]). PD_SCK high 0.2 µs to 50 µs and
//! low at least 0.2 µs a pulse (1 µs each here); held high over 60 µs, it
//! powers the chip down, and back low it resets it to channel A, gain 128.
//! After a reset or a change of input or gain the output settles for 4
//! conversions (50 ms at 80 samples per second, 400 ms at 10): the driver
//! drops those, and the one converted before a change took effect.

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{InputPin, OutputPin};

use crate::{Error, LoadCell, pin};

/// PD_SCK's high and low time of a pulse, ns (the datasheet's typical).
const PULSE_NS: u32 = 1_000;
/// PD_SCK held high this long powers the chip down (over 60 µs).
const POWER_DOWN_US: u32 = 100;
/// Conversions dropped after a reset or a change of input or gain.
pub const SETTLE: u8 = 4;
/// How often a blocking read looks at DOUT, µs.
const POLL_US: u32 = 100;

/// The input and gain of the next conversion, chosen by the pulses after
/// the 24 data bits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gain {
    /// Channel A, gain 128 (±20 mV full scale at 5 V): 25 pulses; the
    /// chip's choice after a reset.
    A128,
    /// Channel B, gain 32 (±80 mV): 26 pulses.
    B32,
    /// Channel A, gain 64 (±40 mV): 27 pulses.
    A64,
}

impl Gain {
    /// Pulses after the 24 data bits that choose it.
    fn extra(self) -> u8 {
        match self {
            Gain::A128 => 1,
            Gain::B32 => 2,
            Gain::A64 => 3,
        }
    }
}

/// An HX711 on `sck` (PD_SCK, an output) and `dout` (an input), timed by
/// `delay`.
pub struct Hx711<SCK, DOUT, D> {
    sck: SCK,
    dout: DOUT,
    delay: D,
    gain: Gain,
    /// Conversions still to drop.
    skip: u8,
}

impl<SCK: OutputPin, DOUT: InputPin, D: DelayNs> Hx711<SCK, DOUT, D> {
    /// The chip reset (powered down and up, so its state is known) and
    /// set to convert at `gain`.
    pub fn new(sck: SCK, dout: DOUT, delay: D, gain: Gain) -> Result<Self, Error> {
        let mut chip = Hx711 {
            sck,
            dout,
            delay,
            gain,
            skip: 0,
        };
        chip.power_down()?;
        chip.power_up()?;
        Ok(chip)
    }

    /// The gain samples are read at.
    pub fn gain(&self) -> Gain {
        self.gain
    }

    /// Reads at `gain` from now on: the conversion under way and those
    /// settling after the change are dropped.
    pub fn set_gain(&mut self, gain: Gain) {
        if gain != self.gain {
            self.gain = gain;
            self.skip = SETTLE + 1;
        }
    }

    /// Powers the chip down (PD_SCK held high).
    pub fn power_down(&mut self) -> Result<(), Error> {
        self.sck.set_high().map_err(pin)?;
        self.delay.delay_us(POWER_DOWN_US);
        Ok(())
    }

    /// Powers the chip up (PD_SCK low): it resets to channel A, gain 128,
    /// and the driver drops what converts before its gain has settled.
    pub fn power_up(&mut self) -> Result<(), Error> {
        self.sck.set_low().map_err(pin)?;
        self.skip = SETTLE + u8::from(self.gain != Gain::A128);
        Ok(())
    }

    /// A conversion is ready (DOUT low).
    pub fn is_ready(&mut self) -> Result<bool, Error> {
        self.dout.is_low().map_err(pin)
    }

    /// The next sample, waiting up to `timeout_us` (counted in the delay's
    /// waits, so at least that long) for a conversion, settling included.
    pub fn read(&mut self, timeout_us: u32) -> Result<i32, Error> {
        let mut waited = 0;
        loop {
            if let Some(counts) = self.sample()? {
                return Ok(counts);
            }
            if waited >= timeout_us {
                return Err(Error::NotReady);
            }
            self.delay.delay_us(POLL_US);
            waited += POLL_US;
        }
    }

    /// Gives the pins and the delay back.
    pub fn release(self) -> (SCK, DOUT, D) {
        (self.sck, self.dout, self.delay)
    }
}

impl<SCK: OutputPin, DOUT: InputPin, D: DelayNs> LoadCell for Hx711<SCK, DOUT, D> {
    type Error = Error;

    fn sample(&mut self) -> Result<Option<i32>, Error> {
        if !self.is_ready()? {
            return Ok(None);
        }
        // DOUT fell at least 0.1 µs before the first rising edge.
        self.delay.delay_ns(PULSE_NS);
        let (sck, dout, delay) = (&mut self.sck, &mut self.dout, &mut self.delay);
        let bits = crate::transfer(sck, dout, delay, self.gain.extra(), PULSE_NS)?;
        if self.skip > 0 {
            self.skip -= 1;
            return Ok(None);
        }
        crate::counts(bits).map(Some)
    }
}
