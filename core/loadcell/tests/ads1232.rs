//! The ADS1232 driver against the pin-level model (`chip/ads1232.rs`):
//! the codes it converted come back as counts, negative and saturated
//! ones included, at the gain and speed set, with every timing minimum
//! and pulse count kept; an offset calibration, power-down, strapped gain
//! and speed pins, a chip that never gets ready, and a failing pin.
mod chip;

use chip::ads1232::Ads1232 as Model;
use chip::{Clock, In, Out, Pin, Shared, board, code};
use primo_loadcell::ads1232::{Ads1232, Gain, Pins, Speed};
use primo_loadcell::{Error, LoadCell, MAX, MIN, Strapped};

type Driver =
    Ads1232<Out<Model>, In<Model>, Out<Model>, Out<Model>, Out<Model>, Out<Model>, Clock<Model>>;

/// A second, µs: longer than the settling at 80 samples per second.
const SECOND: u32 = 1_000_000;

fn driver(codes: &[i32], gain: Gain, speed: Speed) -> (Shared<Model>, Driver) {
    let b = board(Model::new([false; 3], codes.iter().map(|c| code(*c))));
    let pins = Pins {
        sclk: Out(b.clone(), Pin::Clock),
        dout: In(b.clone()),
        pdwn: Out(b.clone(), Pin::PowerDown),
        gain0: Out(b.clone(), Pin::Gain0),
        gain1: Out(b.clone(), Pin::Gain1),
        speed: Out(b.clone(), Pin::Speed),
    };
    let d = Ads1232::new(pins, Clock(b.clone()), gain, speed).unwrap();
    (b, d)
}

fn faults(b: &Shared<Model>) -> Vec<String> {
    let mut b = b.borrow_mut();
    b.chip.finish();
    std::mem::take(&mut b.faults)
}

const CODES: [i32; 8] = [0, 1, -1, 123_456, -654_321, MAX - 1, MIN + 1, -42];

#[test]
fn reads_every_code_at_the_gain_and_speed_set() {
    let gains = [
        (Gain::X1, 0),
        (Gain::X2, 2),
        (Gain::X64, 4),
        (Gain::X128, 6),
    ];
    for (gain, bits) in gains {
        for (speed, fast) in [(Speed::Sps10, 0), (Speed::Sps80, 1)] {
            let (b, mut d) = driver(&CODES, gain, speed);
            let got: Vec<_> = CODES.iter().map(|_| d.read(2 * SECOND)).collect();
            assert_eq!(got, CODES.map(Ok), "{gain:?} {speed:?}");
            assert_eq!(faults(&b), Vec::<String>::new());
            let b = b.borrow();
            assert!(b.chip.read.iter().all(|c| c.setting == bits | fast));
            assert!(b.chip.pulse_counts.iter().all(|n| *n == 25));
        }
    }
}

#[test]
fn saturated_codes_are_out_of_range_and_polling_waits() {
    let (b, mut d) = driver(&[MAX, 3, MIN], Gain::X128, Speed::Sps80);
    // Settling after power-up: nothing to read yet, and no clock for it.
    assert_eq!(d.sample(), Ok(None));
    assert_eq!(d.read(SECOND), Err(Error::OutOfRange { counts: MAX }));
    assert_eq!(d.sample(), Ok(None), "DRDY/DOUT forced high by the 25th");
    assert_eq!(d.read(SECOND), Ok(3));
    assert_eq!(d.read(SECOND), Err(Error::OutOfRange { counts: MIN }));
    assert_eq!(faults(&b), Vec::<String>::new());
}

#[test]
fn an_offset_calibration_takes_26_pulses_and_its_time() {
    let (b, mut d) = driver(&[5, 6, 7], Gain::X128, Speed::Sps80);
    d.calibrate(SECOND).unwrap();
    let took = b.borrow().now;
    assert_eq!(b.borrow().chip.calibrations, 1);
    // Settling (51 ms) and the calibration (101 ms), at the least.
    assert!(took >= 152_000_000, "{took}");
    assert_eq!(d.read(SECOND), Ok(6));
    assert_eq!(faults(&b), Vec::<String>::new());
    assert_eq!(b.borrow().chip.pulse_counts, [26, 25]);
}

#[test]
fn powered_down_or_out_of_codes_it_times_out() {
    let (b, mut d) = driver(&[1, 2], Gain::X128, Speed::Sps80);
    assert_eq!(d.read(SECOND), Ok(1));
    d.power_down().unwrap();
    assert_eq!(d.read(SECOND), Err(Error::NotReady));
    d.power_up().unwrap();
    assert_eq!(d.read(SECOND), Ok(2));
    let start = b.borrow().now;
    assert_eq!(d.read(SECOND), Err(Error::NotReady));
    assert!(b.borrow().now - start >= 1_000_000_000);
    assert_eq!(faults(&b), Vec::<String>::new());
}

#[test]
fn strapped_gain_and_speed_pins_are_the_boards() {
    // GAIN1, GAIN0 high (128) and SPEED low (10 per second) on the board.
    let b = board(Model::new([true, true, false], CODES.map(code)));
    let pins = Pins {
        sclk: Out(b.clone(), Pin::Clock),
        dout: In(b.clone()),
        pdwn: Out(b.clone(), Pin::PowerDown),
        gain0: Strapped,
        gain1: Strapped,
        speed: Strapped,
    };
    let mut d = Ads1232::new(pins, Clock(b.clone()), Gain::X128, Speed::Sps10).unwrap();
    assert_eq!(d.read(SECOND), Ok(0));
    assert_eq!(b.borrow().chip.read[0].setting, 0b110);
    assert_eq!(faults(&b), Vec::<String>::new());
}

#[test]
fn a_failing_pin_is_an_error() {
    let (b, mut d) = driver(&[1], Gain::X128, Speed::Sps80);
    b.borrow_mut().broken = true;
    assert!(matches!(d.read(SECOND), Err(Error::Pin(_))));
    assert!(matches!(d.sample(), Err(Error::Pin(_))));
}
