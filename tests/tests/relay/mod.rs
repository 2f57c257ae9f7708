//! A lossy line for the hardware-in-the-loop tests: a relay between the
//! host and a device's pty that drops and corrupts bytes.

use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use primo_core::rng::Xoshiro128PlusPlus;
use rand_core::{Rng, SeedableRng};
use serialport::{SerialPort, TTYPort};

/// `TTYPort::pair` is not thread-safe.
pub static PTY: Mutex<()> = Mutex::new(());

/// Bytes the relay dropped and corrupted, both directions.
#[derive(Default)]
pub struct Damage {
    pub dropped: AtomicU64,
    pub corrupted: AtomicU64,
    pub passed: AtomicU64,
}

/// A line between the host and the coprocessor's pty that drops `rate / 2`
/// and corrupts `rate / 2` of the bytes in each direction.
pub struct Relay {
    pub path: String,
    /// The end the host opens by `path`; held so the pty stays up.
    _port: TTYPort,
    pub damage: Arc<Damage>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

impl Relay {
    pub fn start(device: &str, rate: f64, seed: u64) -> Relay {
        let (host_side, port) = {
            let _guard = PTY.lock().unwrap_or_else(|e| e.into_inner());
            TTYPort::pair().unwrap()
        };
        let path = port.name().unwrap();
        let device: Box<dyn SerialPort> = serialport::new(device, 115_200)
            .timeout(Duration::from_millis(10))
            .open()
            .unwrap();
        let (damage, stop) = (
            Arc::new(Damage::default()),
            Arc::new(AtomicBool::new(false)),
        );
        let mut host_side = host_side;
        host_side.set_timeout(Duration::from_millis(10)).unwrap();
        let pipes: [(Box<dyn SerialPort>, Box<dyn SerialPort>); 2] = [
            (
                Box::new(host_side.try_clone_native().unwrap()),
                device.try_clone().unwrap(),
            ),
            (device, Box::new(host_side)),
        ];
        let threads = pipes
            .into_iter()
            .enumerate()
            .map(|(i, (mut from, mut to))| {
                let (damage, stop) = (damage.clone(), stop.clone());
                let mut rng = Xoshiro128PlusPlus::seed_from_u64(seed + i as u64);
                std::thread::spawn(move || {
                    let mut buf = [0u8; 256];
                    while !stop.load(Ordering::Relaxed) {
                        let n = match from.read(&mut buf) {
                            Ok(n) => n,
                            Err(_) => continue,
                        };
                        let mut out = Vec::with_capacity(n);
                        for &b in &buf[..n] {
                            let u = rng.next_u32() as f64 / u32::MAX as f64;
                            if u < rate / 2.0 {
                                damage.dropped.fetch_add(1, Ordering::Relaxed);
                            } else if u < rate {
                                damage.corrupted.fetch_add(1, Ordering::Relaxed);
                                out.push(b ^ (1 + (rng.next_u32() % 255) as u8));
                            } else {
                                damage.passed.fetch_add(1, Ordering::Relaxed);
                                out.push(b);
                            }
                        }
                        if to.write_all(&out).is_err() {
                            return;
                        }
                    }
                })
            })
            .collect();
        Relay {
            path,
            _port: port,
            damage,
            stop,
            threads,
        }
    }
}

impl Drop for Relay {
    fn drop(&mut self) {
        self.stop.store(true, Ordering::Relaxed);
        for t in self.threads.drain(..) {
            let _ = t.join();
        }
    }
}
