//! The cell's scale as a bare load cell: the load on the pan (the glass's
//! contents, tared, and the stream's impact) through the pan's lag, with
//! noise, as the raw counts of a 24-bit ADC at its sample rate: what the
//! scale firmware (`primo-scale`) weighs from. [`LoadCellServer`] sends the
//! counts on a new pseudo-terminal in wall-clock time, framed as
//! [`primo_device::scale::encode_sample`] does, for QEMU's second UART.
//!
//! ```
//! use primo_sim::load_cell::{LoadCell, LoadCellModel};
//! let model = LoadCellModel::default();
//! let mut cell = LoadCell::new(model, 1);
//! let counts: Vec<i32> = (0..800).map(|_| cell.sample(100.0)).collect();
//! let grams = (counts[799] - model.offset) as f64 / model.counts_per_gram;
//! assert!((grams - 100.0).abs() < 0.01, "{grams}");
//! ```

use std::io::{self, Write};
use std::sync::Arc;
use std::sync::atomic::{AtomicBool, Ordering};
use std::thread::JoinHandle;
use std::time::{Duration, Instant};

use primo_core::normal::StandardNormal;
use primo_core::rng::Xoshiro128PlusPlus;
use primo_device::scale::{Calibration, SAMPLE_BYTES, Settings, encode_sample};
use rand_core::SeedableRng;
use serialport::{SerialPort, TTYPort};

use crate::scale::{Lag, ScaleModel};
use crate::scale_device::LoadSource;

/// The load cell and its ADC.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LoadCellModel {
    /// The pan's lag, the noise (g, per sample) and the capacity.
    pub scale: ScaleModel,
    /// ADC counts per gram.
    pub counts_per_gram: f64,
    /// Counts of the tared, empty pan.
    pub offset: i32,
    /// Samples per second.
    pub rate: f64,
}

impl Default for LoadCellModel {
    /// The cell's scale (0.5 s lag, 2 mg noise, 4.2 kg) on a 5 kg cell at
    /// 2 mV/V read by an HX711-like ADC at 80 samples per second, gain
    /// scaled to 1000 counts per gram, 150,000 counts at the empty pan.
    fn default() -> Self {
        LoadCellModel {
            scale: ScaleModel::default(),
            counts_per_gram: 1000.0,
            offset: 150_000,
            rate: 80.0,
        }
    }
}

impl LoadCellModel {
    /// The calibration a factory takes of this cell with 0 g and 1 kg on
    /// the pan (noise-free), as the scale keeps it in its settings page.
    pub fn factory_settings(&self) -> Settings {
        Settings {
            calibration: Some(Calibration {
                counts_low: self.offset,
                grams_low: 0.0,
                gain: (1.0 / self.counts_per_gram) as f32,
            }),
            ..Settings::default()
        }
    }
}

/// The simulated load cell.
#[derive(Debug, Clone)]
pub struct LoadCell {
    model: LoadCellModel,
    settled: f64,
    lag: Lag,
    rng: Xoshiro128PlusPlus,
    normal: StandardNormal,
}

impl LoadCell {
    /// A cell of `model`, its pan empty, its noise from `seed`.
    pub fn new(model: LoadCellModel, seed: u64) -> Self {
        LoadCell {
            model,
            settled: 0.0,
            lag: Lag::NEW,
            rng: Xoshiro128PlusPlus::seed_from_u64(seed),
            normal: StandardNormal::new(),
        }
    }

    /// The next sample, one sample period on, under `load` grams.
    pub fn sample(&mut self, load: f64) -> i32 {
        self.step(1.0 / self.model.rate, load);
        self.counts()
    }

    /// Advances the pan by `dt` seconds under `load` grams (a non-finite
    /// load changes nothing).
    pub fn step(&mut self, dt: f64, load: f64) {
        if load.is_finite() && dt.is_finite() && dt > 0.0 {
            self.settled = self.lag.step(self.settled, load, dt, self.model.scale.lag);
        }
    }

    /// A conversion now: the counts of 24 bits (saturating, as the ADC
    /// does).
    pub fn counts(&mut self) -> i32 {
        let m = self.model;
        let noisy = self.settled + m.scale.noise * f64::from(self.normal.sample(&mut self.rng));
        let counts = f64::from(m.offset) + noisy * m.counts_per_gram;
        counts.round().clamp(-8_388_608.0, 8_388_607.0) as i32
    }
}

/// A [`LoadCell`] sending its counts on a new pseudo-terminal, from its own
/// thread, at the model's rate in wall-clock time, under a load read from
/// a [`LoadSource`] at every sample.
#[derive(Debug)]
pub struct LoadCellServer {
    path: String,
    stop: Arc<AtomicBool>,
    thread: Option<JoinHandle<io::Result<()>>>,
}

impl LoadCellServer {
    /// Starts sending. `TTYPort::pair` is not thread-safe: do not start two
    /// at once (nor with a scale server).
    pub fn start<L: LoadSource + 'static>(
        model: LoadCellModel,
        seed: u64,
        load: L,
    ) -> io::Result<LoadCellServer> {
        let (master, slave) = TTYPort::pair()?;
        let path = slave
            .name()
            .ok_or_else(|| io::Error::other("the pseudo-terminal has no path"))?;
        let stop = Arc::new(AtomicBool::new(false));
        let flag = stop.clone();
        let cell = LoadCell::new(model, seed);
        let thread = std::thread::Builder::new()
            .name("load-cell".into())
            .spawn(move || send(cell, load, master, slave, &flag))?;
        Ok(LoadCellServer {
            path,
            stop,
            thread: Some(thread),
        })
    }

    /// The path the scale's ADC line opens (`/dev/pts/N`).
    pub fn path(&self) -> &str {
        &self.path
    }

    /// Stops sending; the sending loop's error, if it failed.
    pub fn stop(mut self) -> io::Result<()> {
        self.halt()
    }

    fn halt(&mut self) -> io::Result<()> {
        self.stop.store(true, Ordering::Relaxed);
        match self.thread.take().map(JoinHandle::join) {
            Some(Ok(result)) => result,
            Some(Err(_)) => Err(io::Error::other("the load cell thread panicked")),
            None => Ok(()),
        }
    }
}

impl Drop for LoadCellServer {
    fn drop(&mut self) {
        let _ = self.halt();
    }
}

/// Samples waiting unread on the line beyond which new ones are dropped:
/// a scale opening the line late reads fresh counts, not seconds of old
/// ones queued in the pty.
const BACKLOG: u32 = 8;

/// The sending loop: one sample per period, the pan stepped by the time
/// that really passed (a thread starved by a busy machine still sees the
/// pan settle in time). Behind by more than a second, it skips ahead
/// rather than send a burst. Keeps
/// `slave` open so the pty lives while the scale comes and goes, and
/// watches its input queue.
fn send<L: LoadSource>(
    mut cell: LoadCell,
    load: L,
    mut master: TTYPort,
    slave: TTYPort,
    stop: &AtomicBool,
) -> io::Result<()> {
    let period = Duration::from_secs_f64(1.0 / cell.model.rate);
    master.set_timeout(period)?;
    let mut next = Instant::now();
    let mut last = next;
    while !stop.load(Ordering::Relaxed) {
        let now = Instant::now();
        cell.step(now.duration_since(last).as_secs_f64(), load.grams());
        last = now;
        let bytes = encode_sample(cell.counts());
        // Nobody reading: the sample is lost, as on a line with nothing
        // attached.
        if slave.bytes_to_read()? < BACKLOG * SAMPLE_BYTES as u32 {
            match master.write_all(&bytes) {
                Err(e) if e.kind() == io::ErrorKind::TimedOut => {}
                other => other?,
            }
        }
        next += period;
        let now = Instant::now();
        if now > next + Duration::from_secs(1) {
            next = now;
        }
        std::thread::sleep(next.saturating_duration_since(now));
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use primo_device::scale::SampleReader;
    use std::io::Read;

    #[test]
    fn the_factory_calibration_reads_the_load() {
        let model = LoadCellModel::default();
        let c = model.factory_settings().calibration.unwrap();
        let mut cell = LoadCell::new(model, 3);
        let counts = (0..1000).map(|_| cell.sample(321.0)).last().unwrap();
        let grams = c.grams_low as f64 + (counts - c.counts_low) as f64 * c.gain as f64;
        assert!((grams - 321.0).abs() < 0.01, "{grams}");
    }

    #[test]
    fn serves_samples_at_its_rate() {
        let server = LoadCellServer::start(
            LoadCellModel::default(),
            1,
            crate::scale_device::LoadHandle::new(50.0),
        )
        .unwrap();
        let mut port = serialport::new(server.path(), 115_200)
            .timeout(Duration::from_millis(50))
            .open()
            .unwrap();
        let start = Instant::now();
        let (mut reader, mut samples, mut buf) = (SampleReader::new(), 0, [0u8; 64]);
        while start.elapsed() < Duration::from_secs(1) {
            if let Ok(n) = port.read(&mut buf) {
                samples += buf[..n].iter().filter_map(|b| reader.push(*b)).count();
            }
        }
        // 80 a second, and at most the backlog from before it was opened.
        assert!((60..=90 + BACKLOG as usize).contains(&samples), "{samples}");
        server.stop().unwrap();
    }
}
