//! On the target: the scale gives the host's readings from the same
//! counts (`core/device/src/scale.rs`'s tests), and its calibration and tare
//! survive a reset in the settings page. The first boot calibrates, tares,
//! stores and resets the core; the second finds the settings in the page.
#![no_std]
#![no_main]

use cortex_m::peripheral::SCB;
use cortex_m_rt::entry;
use cortex_m_semihosting::hprintln;
use primo_device::scale::{Scale, ScaleConfig};
use primo_firmware::{exit, settings};
use primo_protocol::scale::{
    CalibrationPoint, FILTER, FRESH, Reading, Reply, ScaleReply, ScaleRequest, Unit, WINDOW,
    WeighMode,
};

fn settle(s: &mut Scale, counts: i32) {
    (0..FILTER + WINDOW).for_each(|_| s.push(counts));
}

fn weigh(s: &mut Scale) -> Option<Reading> {
    let weigh = ScaleRequest::Weigh {
        mode: WeighMode::Stable,
        unit: Unit::G,
    };
    match s.respond(&weigh) {
        Some(Reply::Scale(ScaleReply::Reading(r))) => Some(r),
        _ => None,
    }
}

fn check(what: &str, ok: bool) {
    if !ok {
        hprintln!("scale: {} failed", what);
        exit(false);
    }
}

/// Seconds of QEMU's CPU time: a reset that lost the page would reset
/// forever, and this ends it.
fn seconds() -> usize {
    // SAFETY: the semihosting CLOCK call takes no argument.
    unsafe { cortex_m_semihosting::syscall!(CLOCK) / 100 }
}

#[entry]
fn main() -> ! {
    let mut s = Scale::new(ScaleConfig::LAB);
    if let Some(kept) = settings::load() {
        s.restore(kept);
        settle(&mut s, 520_000); // 510 g gross, 110 g tared
        let r = weigh(&mut s);
        check(
            "the reading after the reset",
            r.map(|r| (r.digits, r.net)) == Some((40_000, true)),
        );
        hprintln!("scale: settings survived the reset, 400.00 g net");
        exit(true);
    }
    check("a single boot", seconds() < 30);
    settle(&mut s, 10_000);
    let low = ScaleRequest::Calibrate(CalibrationPoint::Low { grams: 0.0 });
    check("the low point", s.respond(&low) == Some(Reply::OK));
    settle(&mut s, 1_010_000);
    let high = ScaleRequest::Calibrate(CalibrationPoint::High { grams: 1000.0 });
    check("the high point", s.respond(&high) == Some(Reply::OK));
    settle(&mut s, 260_000);
    check("250 g", weigh(&mut s).map(|r| r.digits) == Some(25_000));
    // 50 g more, no sample of it yet: the next stable reading waits for
    // FRESH samples of the new load (the deadline ends the loop).
    let next = ScaleRequest::Weigh {
        mode: WeighMode::Next { within: 400 },
        unit: Unit::G,
    };
    check("a deferred weighing", s.respond(&next).is_none());
    let mut took = 0;
    let answer = loop {
        s.push(310_000);
        took += 1;
        if let Some(answer) = s.deferred() {
            break answer;
        }
    };
    let fresh = matches!(answer, Reply::Scale(ScaleReply::Reading(r)) if r.digits == 30_000);
    check("300 g, the next stable reading", fresh && took == FRESH);
    settle(&mut s, 120_000);
    check(
        "the tare",
        s.respond(&ScaleRequest::Tare) == Some(Reply::OK),
    );
    let Some(changed) = s.take_changed() else {
        check("a change to keep", false);
        exit(false)
    };
    settings::store(changed);
    SCB::sys_reset()
}
