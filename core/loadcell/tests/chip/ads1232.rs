//! The ADS1232 at its pins, as its datasheet gives it: DRDY/DOUT low when
//! a conversion is ready; SCLK's rising edges shift it out MSB first, a
//! 25th forces DRDY/DOUT high, a 26th starts an offset calibration (8
//! periods and a bit: 101 ms at 80 samples per second); SCLK high and low
//! at least 100 ns, never held high (standby); PDWN low powers down, and
//! after PDWN rises DRDY/DOUT stays high until the filter has settled (51
//! ms at 80 samples per second, 401 ms at 10), so every conversion
//! given is settled. The model latches GAIN0, GAIN1 and SPEED at power-up
//! and tags each conversion with them (`GAIN1 GAIN0 SPEED` as 3 bits).

use super::{Chip, Codes, Conversion, Line, Pin};

pub struct Ads1232 {
    pub codes: Codes,
    /// Every conversion shifted out whole, in order.
    pub read: Vec<Conversion>,
    /// The pulse count of every read.
    pub pulse_counts: Vec<u8>,
    pub calibrations: u32,
    pub powered: bool,
    /// GAIN1, GAIN0, SPEED as the board or the driver holds them.
    pub levels: [bool; 3],
    setting: u8,
    period: u64,
    sclk: bool,
    edge_at: u64,
    next_at: Option<u64>,
    ready: Option<Conversion>,
    shifting: Option<Conversion>,
    pulses: u8,
}

impl Ads1232 {
    /// A chip powered down, its gain and speed pins at `levels` (GAIN1,
    /// GAIN0, SPEED), that will convert `codes`.
    pub fn new(levels: [bool; 3], codes: impl IntoIterator<Item = u32>) -> Self {
        Ads1232 {
            codes: codes.into_iter().collect(),
            read: Vec::new(),
            pulse_counts: Vec::new(),
            calibrations: 0,
            powered: false,
            levels,
            setting: 0,
            period: 0,
            sclk: false,
            edge_at: 0,
            next_at: None,
            ready: None,
            shifting: None,
            pulses: 0,
        }
    }

    /// Ends the test: the last read's pulses count too.
    pub fn finish(&mut self) {
        self.end_read();
    }

    fn end_read(&mut self) {
        if self.pulses > 0 {
            self.pulse_counts.push(self.pulses);
        }
        self.pulses = 0;
        self.shifting = None;
    }
}

impl Chip for Ads1232 {
    fn drive(&mut self, pin: Pin, high: bool, now: u64, faults: &mut Vec<String>) {
        match pin {
            Pin::Clock => {}
            Pin::PowerDown => {
                if high && !self.powered {
                    let [g1, g0, fast] = self.levels;
                    self.setting = u8::from(g1) << 2 | u8::from(g0) << 1 | u8::from(fast);
                    self.period = if fast { 12_500_000 } else { 100_000_000 };
                    self.next_at = Some(now + 4 * self.period + 1_000_000);
                } else if !high {
                    self.next_at = None;
                    self.ready = None;
                    self.end_read();
                }
                self.powered = high;
                return;
            }
            Pin::Gain1 => self.levels[0] = high,
            Pin::Gain0 => self.levels[1] = high,
            Pin::Speed => self.levels[2] = high,
        }
        if pin != Pin::Clock || high == self.sclk {
            return;
        }
        let held = now - self.edge_at;
        self.sclk = high;
        self.edge_at = now;
        if high {
            if held < 100 {
                faults.push(format!("SCLK low {held} ns, under 100 ns"));
            }
            if self.pulses == 0 {
                match self.ready.take() {
                    Some(c) => self.shifting = Some(c),
                    None => faults.push("an SCLK pulse with no conversion ready".into()),
                }
            }
            self.pulses += 1;
            if self.pulses > 26 {
                faults.push(format!("{} SCLK pulses in a read", self.pulses));
            }
            return;
        }
        if held < 100 {
            faults.push(format!("SCLK high {held} ns, under 100 ns"));
        }
        if held > 10_000 {
            faults.push(format!("SCLK held high {held} ns: standby"));
        }
        if self.pulses == 24
            && let Some(c) = self.shifting
        {
            self.read.push(c);
        }
        if self.pulses == 26 {
            self.calibrations += 1;
            self.next_at = Some(now + 8 * self.period + 1_280_000);
        }
    }

    fn data(&mut self, now: u64, faults: &mut Vec<String>) -> bool {
        let line = Line {
            powered: self.powered,
            ready: self.ready.is_some(),
            pulses: self.pulses,
            shifting: self.shifting,
            since_rise: self.sclk.then(|| now - self.edge_at),
        };
        line.level(50, faults)
    }

    fn advance(&mut self, now: u64) {
        while let Some(at) = self.next_at.filter(|at| *at <= now && self.powered) {
            self.end_read();
            self.next_at = None;
            if let Some(code) = self.codes.pop_front() {
                self.ready = Some(Conversion {
                    code,
                    setting: self.setting,
                    settled: true,
                });
                self.next_at = Some(at + self.period);
            }
        }
    }
}
