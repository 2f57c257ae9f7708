//! The TI ADS1232: SCLK and PDWN (ours), DRDY/DOUT (the chip's), and the
//! gain and speed pins GAIN0, GAIN1 and SPEED (ours, or strapped on the
//! board: [`crate::Strapped`]).
//!
//! DRDY/DOUT low: a conversion is ready. 24 SCLK pulses shift it out MSB
//! first on the rising edges; a 25th forces DRDY/DOUT high until the next
//! conversion, and a 26th starts an offset calibration, after which
//! DRDY/DOUT falls when the first calibrated conversion is ready (801 ms
//! at 10 samples per second, 101 ms at 80). SCLK high and low at least
//! 100 ns a pulse (1 µs each here), and low between reads: held high it
//! puts the chip in standby. PDWN low powers it down; back high, the chip
//! holds DRDY/DOUT high until its filter has settled, so no conversion is
//! dropped. The gain and speed pins are set while the chip is powered
//! down.

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{InputPin, OutputPin, PinState};

use crate::{Error, LoadCell, pin};

/// SCLK's high and low time of a pulse, ns.
const PULSE_NS: u32 = 1_000;
/// PDWN held low this long when the driver cycles the power, µs.
const POWER_DOWN_US: u32 = 100;
/// How often a blocking wait looks at DRDY/DOUT, µs.
const POLL_US: u32 = 100;

/// The PGA's gain (GAIN1, GAIN0).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Gain {
    /// 1 (low, low).
    X1,
    /// 2 (low, high).
    X2,
    /// 64 (high, low).
    X64,
    /// 128 (high, high): a load cell's usual.
    X128,
}

/// The data rate (SPEED) on the internal oscillator.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Speed {
    /// 10 samples per second (low): the least noise, 50 and 60 Hz
    /// rejected.
    Sps10,
    /// 80 samples per second (high).
    Sps80,
}

/// An ADS1232's pins: `sclk`, `pdwn`, `gain0`, `gain1` and `speed`
/// outputs, `dout` (DRDY/DOUT) an input.
pub struct Pins<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED> {
    /// SCLK.
    pub sclk: SCLK,
    /// DRDY/DOUT.
    pub dout: DOUT,
    /// PDWN (low: powered down).
    pub pdwn: PDWN,
    /// GAIN0.
    pub gain0: GAIN0,
    /// GAIN1.
    pub gain1: GAIN1,
    /// SPEED.
    pub speed: SPEED,
}

/// An ADS1232 on `pins`, timed by `delay`.
pub struct Ads1232<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED, D> {
    pins: Pins<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED>,
    delay: D,
}

impl<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED, D> Ads1232<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED, D>
where
    SCLK: OutputPin,
    DOUT: InputPin,
    PDWN: OutputPin,
    GAIN0: OutputPin,
    GAIN1: OutputPin,
    SPEED: OutputPin,
    D: DelayNs,
{
    /// The chip powered up at `gain` and `speed`, from a power-down (so
    /// its state is known).
    pub fn new(
        pins: Pins<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED>,
        delay: D,
        gain: Gain,
        speed: Speed,
    ) -> Result<Self, Error> {
        let mut chip = Ads1232 { pins, delay };
        chip.pins.sclk.set_low().map_err(pin)?;
        chip.set_mode(gain, speed)?;
        Ok(chip)
    }

    /// Powers down, sets `gain` and `speed`, and powers up: the next
    /// conversion is the first settled one at them.
    pub fn set_mode(&mut self, gain: Gain, speed: Speed) -> Result<(), Error> {
        self.power_down()?;
        let (g1, g0) = match gain {
            Gain::X1 => (false, false),
            Gain::X2 => (false, true),
            Gain::X64 => (true, false),
            Gain::X128 => (true, true),
        };
        let p = &mut self.pins;
        p.gain1.set_state(PinState::from(g1)).map_err(pin)?;
        p.gain0.set_state(PinState::from(g0)).map_err(pin)?;
        let fast = PinState::from(speed == Speed::Sps80);
        p.speed.set_state(fast).map_err(pin)?;
        self.delay.delay_us(POWER_DOWN_US);
        self.power_up()
    }

    /// Powers the chip down (PDWN low).
    pub fn power_down(&mut self) -> Result<(), Error> {
        self.pins.pdwn.set_low().map_err(pin)
    }

    /// Powers the chip up (PDWN high); DRDY/DOUT falls once settled.
    pub fn power_up(&mut self) -> Result<(), Error> {
        self.pins.pdwn.set_high().map_err(pin)
    }

    /// A conversion is ready (DRDY/DOUT low).
    pub fn is_ready(&mut self) -> Result<bool, Error> {
        self.pins.dout.is_low().map_err(pin)
    }

    /// The next sample, waiting up to `timeout_us` (counted in the delay's
    /// waits, so at least that long) for a conversion.
    pub fn read(&mut self, timeout_us: u32) -> Result<i32, Error> {
        self.wait(timeout_us)?;
        let bits = self.shift_out(25)?;
        crate::counts(bits)
    }

    /// An offset calibration: waits up to `timeout_us` for a conversion,
    /// reads it with the 26 pulses that start the calibration (dropping
    /// it), then waits up to `timeout_us` again for the calibration's end
    /// (DRDY/DOUT low: the first calibrated conversion is ready).
    pub fn calibrate(&mut self, timeout_us: u32) -> Result<(), Error> {
        self.wait(timeout_us)?;
        self.shift_out(26)?;
        self.wait(timeout_us)
    }

    /// Gives the pins and the delay back.
    pub fn release(self) -> (Pins<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED>, D) {
        (self.pins, self.delay)
    }

    /// Waits up to `timeout_us` for DRDY/DOUT low.
    fn wait(&mut self, timeout_us: u32) -> Result<(), Error> {
        let mut waited = 0;
        while !self.is_ready()? {
            if waited >= timeout_us {
                return Err(Error::NotReady);
            }
            self.delay.delay_us(POLL_US);
            waited += POLL_US;
        }
        Ok(())
    }

    /// The 24 data bits of a ready conversion, clocked out with `pulses`
    /// pulses in all (25: DRDY/DOUT forced high; 26: and a calibration).
    fn shift_out(&mut self, pulses: u8) -> Result<u32, Error> {
        let (p, delay) = (&mut self.pins, &mut self.delay);
        let extra = pulses.saturating_sub(24);
        crate::transfer(&mut p.sclk, &mut p.dout, delay, extra, PULSE_NS)
    }
}

impl<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED, D> LoadCell
    for Ads1232<SCLK, DOUT, PDWN, GAIN0, GAIN1, SPEED, D>
where
    SCLK: OutputPin,
    DOUT: InputPin,
    PDWN: OutputPin,
    GAIN0: OutputPin,
    GAIN1: OutputPin,
    SPEED: OutputPin,
    D: DelayNs,
{
    type Error = Error;

    fn sample(&mut self) -> Result<Option<i32>, Error> {
        if !self.is_ready()? {
            return Ok(None);
        }
        self.read(0).map(Some)
    }
}
