//! Pin-level models of the load-cell ADCs, for the drivers' tests: the
//! driver's pins and delay are handles on one [`Board`], whose clock moves
//! only when the driver waits, so every timing minimum the datasheets give
//! is checked against what the driver really waits. What the driver does
//! wrong is written down in `faults`, for the test to assert empty.
#![allow(dead_code)] // each test binary uses one chip

pub mod ads1232;
pub mod hx711;

use std::cell::RefCell;
use std::collections::VecDeque;
use std::rc::Rc;

use embedded_hal::delay::DelayNs;
use embedded_hal::digital::{self, ErrorKind, ErrorType, InputPin, OutputPin};

/// A chip's side of the pins.
pub trait Chip {
    /// The driver set output `pin` to `high` at time `now`, ns.
    fn drive(&mut self, pin: Pin, high: bool, now: u64, faults: &mut Vec<String>);
    /// The chip's data line at `now`, as the driver reads it.
    fn data(&mut self, now: u64, faults: &mut Vec<String>) -> bool;
    /// Time moved on to `now`.
    fn advance(&mut self, now: u64);
}

/// The driver's outputs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Pin {
    Clock,
    PowerDown,
    Gain0,
    Gain1,
    Speed,
}

/// The chip, the clock and what went wrong.
pub struct Board<C> {
    pub chip: C,
    pub now: u64,
    pub faults: Vec<String>,
    /// Pins fail from now on.
    pub broken: bool,
}

pub type Shared<C> = Rc<RefCell<Board<C>>>;

/// A board whose clock starts at 1 ms, the pins held since 0.
pub fn board<C>(chip: C) -> Shared<C> {
    Rc::new(RefCell::new(Board {
        chip,
        now: 1_000_000,
        faults: Vec::new(),
        broken: false,
    }))
}

/// A pin's failure.
#[derive(Debug)]
pub struct Broken;

impl digital::Error for Broken {
    fn kind(&self) -> ErrorKind {
        ErrorKind::Other
    }
}

/// One of the driver's outputs.
pub struct Out<C>(pub Shared<C>, pub Pin);
/// The chip's data line.
pub struct In<C>(pub Shared<C>);
/// The driver's delay: the board's clock.
pub struct Clock<C>(pub Shared<C>);

impl<C> ErrorType for Out<C> {
    type Error = Broken;
}

impl<C> ErrorType for In<C> {
    type Error = Broken;
}

impl<C: Chip> Out<C> {
    fn set(&mut self, high: bool) -> Result<(), Broken> {
        let mut b = self.0.borrow_mut();
        if b.broken {
            return Err(Broken);
        }
        let Board {
            chip, now, faults, ..
        } = &mut *b;
        chip.drive(self.1, high, *now, faults);
        Ok(())
    }
}

impl<C: Chip> OutputPin for Out<C> {
    fn set_low(&mut self) -> Result<(), Broken> {
        self.set(false)
    }

    fn set_high(&mut self) -> Result<(), Broken> {
        self.set(true)
    }
}

impl<C: Chip> InputPin for In<C> {
    fn is_high(&mut self) -> Result<bool, Broken> {
        let mut b = self.0.borrow_mut();
        if b.broken {
            return Err(Broken);
        }
        let Board {
            chip, now, faults, ..
        } = &mut *b;
        Ok(chip.data(*now, faults))
    }

    fn is_low(&mut self) -> Result<bool, Broken> {
        self.is_high().map(|h| !h)
    }
}

impl<C: Chip> DelayNs for Clock<C> {
    fn delay_ns(&mut self, ns: u32) {
        let mut b = self.0.borrow_mut();
        b.now += u64::from(ns);
        let now = b.now;
        b.chip.advance(now);
    }
}

/// A conversion the chip made: its code (24 bits) and the setting it was
/// made at (the chip's own tag).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Conversion {
    pub code: u32,
    pub setting: u8,
    /// Settled: what a driver may give as a sample.
    pub settled: bool,
}

/// Codes to convert, in order; when none are left the chip stops
/// converting (DOUT stays high).
pub type Codes = VecDeque<u32>;

/// A 24-bit code of `counts`.
pub fn code(counts: i32) -> u32 {
    (counts as u32) & 0xFF_FFFF
}

/// What a chip's data line shows: high when powered down; before a read,
/// low when a conversion is ready; during one, bit `pulses` of the
/// conversion, MSB first, valid `valid_ns` after the rising edge; high
/// after the 24th.
pub struct Line {
    pub powered: bool,
    pub ready: bool,
    pub pulses: u8,
    pub shifting: Option<Conversion>,
    /// Time since the clock rose, while it is high.
    pub since_rise: Option<u64>,
}

impl Line {
    pub fn level(&self, valid_ns: u64, faults: &mut Vec<String>) -> bool {
        if !self.powered {
            return true;
        }
        match (self.pulses, self.shifting) {
            (0, _) => !self.ready,
            (n @ 1..=24, Some(c)) => {
                if self.since_rise.is_some_and(|t| t < valid_ns) {
                    faults.push(format!("data read within {valid_ns} ns of the rising edge"));
                }
                c.code >> (24 - n) & 1 == 1
            }
            _ => true,
        }
    }
}
