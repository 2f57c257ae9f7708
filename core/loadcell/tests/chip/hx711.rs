//! The HX711 at its pins, as its datasheet gives it: DOUT low when a
//! conversion is ready; 24 PD_SCK pulses shift it out MSB first (a bit
//! valid 0.1 µs after the rising edge, the first rising edge 0.1 µs after
//! DOUT fell); 25, 26 or 27 pulses in all choose the next conversion's
//! setting (channel A gain 128, B 32, A 64), any other count is a fault;
//! PD_SCK high 0.2 to 50 µs and low at least 0.2 µs a pulse; high over
//! 60 µs powers down, and back low resets to A 128; 4 conversions settle
//! after a reset or a change of setting.

use super::{Chip, Codes, Conversion, Line, Pin};

/// The chip's conversions settle after this many.
const SETTLE: u8 = 4;

pub struct Hx711 {
    /// Conversion period, ns.
    pub period: u64,
    pub codes: Codes,
    /// Every conversion shifted out whole, in order.
    pub read: Vec<Conversion>,
    /// The pulse count of every read (its setting choice).
    pub pulse_counts: Vec<u8>,
    /// Resets (power-ups after a power-down).
    pub resets: u32,
    /// Powered (PD_SCK not held high over 60 µs).
    pub powered: bool,
    sck: bool,
    edge_at: u64,
    next_at: Option<u64>,
    ready: Option<Conversion>,
    ready_at: u64,
    shifting: Option<Conversion>,
    pulses: u8,
    /// A pulse began with no conversion ready.
    idle_pulse: bool,
    /// The setting conversions are made at: its pulse count, 25 to 27.
    setting: u8,
    since_change: u8,
}

impl Hx711 {
    /// A chip powered on at 80 samples per second that will convert
    /// `codes`.
    pub fn new(codes: impl IntoIterator<Item = u32>) -> Self {
        let period = 12_500_000;
        Hx711 {
            period,
            codes: codes.into_iter().collect(),
            read: Vec::new(),
            pulse_counts: Vec::new(),
            resets: 0,
            powered: true,
            sck: false,
            edge_at: 0,
            next_at: Some(period),
            ready: None,
            ready_at: 0,
            shifting: None,
            pulses: 0,
            idle_pulse: false,
            setting: 25,
            since_change: 0,
        }
    }

    /// The read now over: its pulse count chooses the setting.
    fn end_read(&mut self, faults: &mut Vec<String>) {
        if self.pulses == 0 {
            return;
        }
        self.pulse_counts.push(self.pulses);
        if !(25..=27).contains(&self.pulses) {
            faults.push(format!(
                "{} PD_SCK pulses in a conversion period",
                self.pulses
            ));
        } else if self.pulses != self.setting {
            self.setting = self.pulses;
            self.since_change = 0;
        }
        self.pulses = 0;
        self.shifting = None;
    }

    /// Ends the test: the last read's pulses count too.
    pub fn finish(&mut self, faults: &mut Vec<String>) {
        self.end_read(faults);
    }
}

impl Chip for Hx711 {
    fn drive(&mut self, pin: Pin, high: bool, now: u64, faults: &mut Vec<String>) {
        assert_eq!(pin, Pin::Clock, "the HX711 has no other input");
        if high == self.sck {
            return;
        }
        let held = now - self.edge_at;
        self.sck = high;
        self.edge_at = now;
        if high {
            if held < 200 {
                faults.push(format!("PD_SCK low {held} ns, under 0.2 µs"));
            }
            self.idle_pulse = false;
            if self.pulses == 0 {
                match self.ready.take() {
                    Some(c) => {
                        if now - self.ready_at < 100 {
                            faults.push("PD_SCK rose within 0.1 µs of DOUT falling".into());
                        }
                        self.shifting = Some(c);
                        self.pulses = 1;
                    }
                    None => self.idle_pulse = true,
                }
            } else {
                self.pulses += 1;
            }
            return;
        }
        if held > 60_000 {
            // Powered down; back low, a reset to channel A, gain 128.
            self.resets += 1;
            self.powered = true;
            self.pulses = 0;
            self.shifting = None;
            self.ready = None;
            self.setting = 25;
            self.since_change = 0;
            self.next_at = Some(now + self.period);
            return;
        }
        if held > 50_000 {
            faults.push(format!("PD_SCK high {held} ns, over 50 µs"));
        }
        if held < 200 {
            faults.push(format!("PD_SCK high {held} ns, under 0.2 µs"));
        }
        if self.idle_pulse {
            faults.push("a PD_SCK pulse with no conversion ready".into());
        }
        if self.pulses == 24
            && let Some(c) = self.shifting
        {
            self.read.push(c);
        }
    }

    fn data(&mut self, now: u64, faults: &mut Vec<String>) -> bool {
        let line = Line {
            powered: self.powered,
            ready: self.ready.is_some(),
            pulses: self.pulses,
            shifting: self.shifting,
            since_rise: self.sck.then(|| now - self.edge_at),
        };
        line.level(100, faults)
    }

    fn advance(&mut self, now: u64) {
        if self.sck && now - self.edge_at > 60_000 {
            self.powered = false;
            self.next_at = None;
        }
        while let Some(at) = self.next_at.filter(|at| *at <= now && self.powered) {
            let mut faults = Vec::new();
            self.end_read(&mut faults);
            assert!(faults.is_empty(), "{faults:?}");
            self.next_at = None;
            if let Some(code) = self.codes.pop_front() {
                self.ready = Some(Conversion {
                    code,
                    setting: self.setting,
                    settled: self.since_change >= SETTLE,
                });
                self.since_change = self.since_change.saturating_add(1);
                self.ready_at = at;
                self.next_at = Some(at + self.period);
            }
        }
    }
}
