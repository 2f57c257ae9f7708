//! Hardware in the loop: the learner on the emulated Cortex-M4F (the
//! release firmware in QEMU's mps2-an386), reached over a pseudo-terminal,
//! drives the simulated cell. The roll-outs must be bit for bit those of the
//! host-only run with the same seed, also through a line that drops and
//! corrupts bytes; on the coprocessor, and on the scale firmware, which
//! weighs the simulated load cell's counts besides.
mod relay;

use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};

use primo_device::scale::Settings as ScaleSettings;
use primo_learn::Setting;
use primo_learn::algorithm::Algorithm as Method;
use primo_learn::coprocessor::{Image, Link, Qemu};
use primo_learn::learner::Learner;
use primo_learn::pour::settings::Settings;
use primo_learn::pour::simulate::learn;
use primo_learn::pour::skill::Space;
use primo_learn::pour::skill::built_in_skill;
use primo_learn::pour::trial::Trial;
use primo_learn::pour::weigh::PrimoScale;
use primo_learn::rollouts::Record;
use primo_protocol::scale::{CalibrationPoint, ScaleRequest, Unit, WeighMode};
use primo_sim::cell::{CellConfig, GlassKind};
use primo_sim::load_cell::{LoadCellModel, LoadCellServer};
use primo_sim::scale_device::LoadHandle;
use relay::{PTY, Relay};

/// Parameters, query and reward bits of every roll-out.
fn bits(records: &[Record<Trial>]) -> Vec<(u32, u32, u64, u64)> {
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
) -> Vec<Record<Trial>> {
    let cell = CellConfig::standard(GlassKind::Normal);
    let skill = built_in_skill(&cell, space, kernels).unwrap();
    let mut s = Settings::paper(method, 0.5, 0.2, 7);
    s.max_rollouts = rollouts;
    learn(&skill, &cell, &s, learner, |_| {}).unwrap()
}

/// The paper's golden-section search on the built-in pour.
fn golden(learner: &mut Learner) -> Vec<Record<Trial>> {
    run(Method::Golden, Space::Cartesian, 30, 30, learner)
}

fn coprocessor(qemu: &Qemu) -> Learner {
    Learner::Remote(Link::open(qemu.pty(), Setting::Coprocessor).unwrap())
}

#[test]
fn golden_section_on_the_mcu_gives_the_host_only_roll_outs() {
    let qemu = Qemu::start(&Qemu::find(Image::Coprocessor).unwrap()).unwrap();
    let host = golden(&mut Learner::local());
    let mcu = golden(&mut coprocessor(&qemu));
    assert!(host.len() >= 3);
    assert_eq!(bits(&mcu), bits(&host));
}

#[test]
fn power_on_the_mcu_gives_the_host_only_roll_outs() {
    // 219 parameters: 7 joints × 30 kernels + goals + τ + q̂; 3 updates.
    let qemu = Qemu::start(&Qemu::find(Image::Coprocessor).unwrap()).unwrap();
    let host = run(Method::Power, Space::Joint, 30, 12, &mut Learner::local());
    let mcu = run(Method::Power, Space::Joint, 30, 12, &mut coprocessor(&qemu));
    assert_eq!(host.len(), 12);
    assert_eq!(bits(&mcu), bits(&host));
}

#[test]
fn a_lossy_line_changes_nothing_but_the_time() {
    let qemu = Qemu::start(&Qemu::find(Image::Coprocessor).unwrap()).unwrap();
    let relay = Relay::start(qemu.pty(), 0.01, 5);
    let mut link = Learner::Remote(Link::open(&relay.path, Setting::Coprocessor).unwrap());
    let host = run(Method::Power, Space::Joint, 10, 8, &mut Learner::local());
    let mcu = run(Method::Power, Space::Joint, 10, 8, &mut link);
    assert_eq!(bits(&mcu), bits(&host));
    let golden_host = golden(&mut Learner::local());
    let golden_mcu = golden(&mut link);
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

/// The scale firmware in QEMU on a simulated load cell under `load`, its
/// settings page holding `page`.
fn scale_on(load: &LoadHandle, page: &ScaleSettings) -> (LoadCellServer, Qemu) {
    let cell = {
        let _guard = PTY.lock().unwrap_or_else(|e| e.into_inner());
        LoadCellServer::start(LoadCellModel::default(), 9, load.clone()).unwrap()
    };
    let qemu = Qemu::start_scale(&Qemu::find(Image::Scale).unwrap(), cell.path(), page).unwrap();
    (cell, qemu)
}

/// Puts `grams` on the pan and waits until the display has moved away
/// from the last stable reading (the pan's lag is 0.5 s).
fn put(load: &LoadHandle, grams: f64) {
    load.set(grams);
    std::thread::sleep(Duration::from_secs(1));
}

fn grams(scale: &mut PrimoScale) -> f64 {
    scale.weigh(WeighMode::Stable, Unit::G).unwrap().grams()
}

#[test]
fn the_scale_in_qemu_calibrates_weighs_tares_and_streams() {
    let load = LoadHandle::new(0.0);
    let (_cell, qemu) = scale_on(&load, &ScaleSettings::default());
    let mut scale = PrimoScale::open(qemu.pty(), Duration::from_secs(20)).unwrap();
    assert!(!scale.identity().calibrated);
    let err = scale
        .weigh(WeighMode::Now, Unit::G)
        .unwrap_err()
        .to_string();
    assert!(err.contains("uncalibrated"), "{err}");
    // Two points: the empty pan, then a 500 g reference.
    scale
        .calibrate(CalibrationPoint::Low { grams: 0.0 })
        .unwrap();
    put(&load, 500.0);
    scale
        .calibrate(CalibrationPoint::High { grams: 500.0 })
        .unwrap();
    put(&load, 123.45);
    let g = grams(&mut scale);
    assert!((g - 123.45).abs() <= 0.02, "{g}");
    scale.set(&ScaleRequest::Tare).unwrap();
    // The next stable reading is of the new load, asked at once.
    load.set(173.45);
    let net = scale.next_stable(Unit::G).unwrap();
    assert!(net.net && (net.grams() - 50.0).abs() <= 0.02, "{net:?}");
    // Streamed readings come at the ADC's rate.
    let start = Instant::now();
    let readings = scale.stream(8, 40).unwrap();
    let rate = 40.0 * 8.0 / start.elapsed().as_secs_f64();
    println!("streamed 40 readings, every 8th sample: {rate:.1} samples/s");
    let samples: Vec<u32> = readings
        .iter()
        .map(|r| r.as_ref().unwrap().sample)
        .collect();
    assert!(samples.windows(2).all(|w| w[1] == w[0] + 8), "{samples:?}");
    assert!(rate > 40.0, "{rate}");
    put(&load, 5000.0);
    let err = scale
        .weigh(WeighMode::Now, Unit::G)
        .unwrap_err()
        .to_string();
    assert!(err.contains("overload"), "{err}");
}

#[test]
fn the_learner_on_the_scale_through_a_lossy_line_gives_the_host_only_roll_outs() {
    let load = LoadHandle::new(250.0);
    let (_cell, qemu) = scale_on(&load, &LoadCellModel::default().factory_settings());
    let relay = Relay::start(qemu.pty(), 0.01, 11);
    let mut scale = PrimoScale::open(&relay.path, Duration::from_secs(20)).unwrap();
    let g = grams(&mut scale);
    assert!((g - 250.0).abs() <= 0.02, "{g}");
    let host = golden(&mut Learner::local());
    let on_scale = golden(&mut Learner::Remote(scale.link()));
    assert_eq!(bits(&on_scale), bits(&host));
    // The deferred answer through the lossy line, retransmissions and all.
    load.set(300.0);
    let g = scale.next_stable(Unit::G).unwrap().grams();
    assert!((g - 300.0).abs() <= 0.02, "{g}");
    let (d, stats) = (&relay.damage, scale.link().stats());
    println!(
        "relay: {} bytes passed, {} dropped, {} corrupted; link: {stats:?}",
        d.passed.load(Ordering::Relaxed),
        d.dropped.load(Ordering::Relaxed),
        d.corrupted.load(Ordering::Relaxed)
    );
    assert!(stats.retransmissions > 0);
}
