//! Hardware in the loop: the learner on the emulated Cortex-M4F (the
//! release firmware in QEMU's mps2-an386), reached over a pseudo-terminal,
//! drives the simulated cell. The roll-outs must be bit for bit those of the
//! host-only run with the same seed, also through a line that drops and
//! corrupts bytes.

use std::io::{Read, Write};
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::thread::JoinHandle;
use std::time::Duration;

use primo_core::rng::Xoshiro128PlusPlus;
use primo_learn::coprocessor::{Link, Qemu};
use primo_learn::learning::{Algorithm as Method, Learner, Record, Settings, learn};
use primo_learn::pouring::built_in_skill;
use primo_sim::cell::{CellConfig, GlassKind};
use primo_skill::Space;
use rand_core::{Rng, SeedableRng};
use serialport::{SerialPort, TTYPort};

/// `TTYPort::pair` is not thread-safe.
static PTY: Mutex<()> = Mutex::new(());

/// Bytes the relay dropped and corrupted, both directions.
#[derive(Default)]
struct Damage {
    dropped: AtomicU64,
    corrupted: AtomicU64,
    passed: AtomicU64,
}

/// A line between the host and the coprocessor's pty that drops `rate / 2`
/// and corrupts `rate / 2` of the bytes in each direction.
struct Relay {
    path: String,
    /// The end the host opens by `path`; held so the pty stays up.
    _port: TTYPort,
    damage: Arc<Damage>,
    stop: Arc<AtomicBool>,
    threads: Vec<JoinHandle<()>>,
}

impl Relay {
    fn start(device: &str, rate: f64, seed: u64) -> Relay {
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

/// Parameters, query and reward bits of every roll-out.
fn bits(records: &[Record]) -> Vec<(u32, u32, u64, u64)> {
    records
        .iter()
        .map(|r| {
            (
                r.rollout,
                r.volume().to_bits(),
                r.trial.poured.to_bits(),
                r.trial.reward.to_bits(),
            )
        })
        .collect()
}

fn run(
    method: Method,
    space: Space,
    kernels: usize,
    rollouts: u32,
    learner: &mut Learner,
) -> Vec<Record> {
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, space, kernels).unwrap();
    let mut s = Settings::paper(method, 0.5, 0.2, 7);
    s.max_rollouts = rollouts;
    learn(&skill, &cell, &s, learner, |_| {}).unwrap()
}

fn coprocessor(qemu: &Qemu) -> Learner {
    Learner::Remote(Link::open(qemu.pty()).unwrap())
}

#[test]
fn golden_section_on_the_mcu_gives_the_host_only_roll_outs() {
    let qemu = Qemu::start(&Qemu::find_firmware().unwrap()).unwrap();
    let host = run(
        Method::Golden,
        Space::Cartesian,
        30,
        30,
        &mut Learner::local(),
    );
    let mcu = run(
        Method::Golden,
        Space::Cartesian,
        30,
        30,
        &mut coprocessor(&qemu),
    );
    assert!(host.len() >= 3);
    assert_eq!(bits(&mcu), bits(&host));
}

#[test]
fn power_on_the_mcu_gives_the_host_only_roll_outs() {
    // 219 parameters: 7 joints × 30 kernels + goals + τ + q̂; 3 updates.
    let qemu = Qemu::start(&Qemu::find_firmware().unwrap()).unwrap();
    let host = run(Method::Power, Space::Joint, 30, 12, &mut Learner::local());
    let mcu = run(Method::Power, Space::Joint, 30, 12, &mut coprocessor(&qemu));
    assert_eq!(host.len(), 12);
    assert_eq!(bits(&mcu), bits(&host));
}

#[test]
fn a_lossy_line_changes_nothing_but_the_time() {
    let qemu = Qemu::start(&Qemu::find_firmware().unwrap()).unwrap();
    let relay = Relay::start(qemu.pty(), 0.01, 5);
    let mut link = Learner::Remote(Link::open(&relay.path).unwrap());
    let host = run(Method::Power, Space::Joint, 10, 8, &mut Learner::local());
    let mcu = run(Method::Power, Space::Joint, 10, 8, &mut link);
    assert_eq!(bits(&mcu), bits(&host));
    let golden_host = run(
        Method::Golden,
        Space::Cartesian,
        30,
        30,
        &mut Learner::local(),
    );
    let golden_mcu = run(Method::Golden, Space::Cartesian, 30, 30, &mut link);
    assert_eq!(bits(&golden_mcu), bits(&golden_host));
    let Learner::Remote(link) = link else {
        unreachable!()
    };
    let (d, stats) = (&relay.damage, link.stats());
    let (dropped, corrupted) = (
        d.dropped.load(Ordering::Relaxed),
        d.corrupted.load(Ordering::Relaxed),
    );
    println!(
        "relay: {} bytes passed, {dropped} dropped, {corrupted} corrupted; link: {stats:?}",
        d.passed.load(Ordering::Relaxed)
    );
    assert!(dropped > 0 && corrupted > 0, "the line was not lossy");
    assert!(stats.retransmissions > 0);
}
