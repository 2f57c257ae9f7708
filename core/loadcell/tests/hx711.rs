//! The HX711 driver against the pin-level model (`chip/hx711.rs`): the
//! codes it converted, at the gain chosen and settled, come back as
//! counts, negative and saturated ones included, with every timing
//! minimum and pulse count kept; power-down and up, a gain change, a chip
//! that never gets ready, and a failing pin.
mod chip;

use chip::hx711::Hx711 as Model;
use chip::{Clock, In, Out, Pin, Shared, board, code};
use primo_loadcell::hx711::{Gain, Hx711, SETTLE};
use primo_loadcell::{Error, LoadCell, MAX, MIN};

type Driver = Hx711<Out<Model>, In<Model>, Clock<Model>>;

/// A second, µs: far longer than a conversion.
const SECOND: u32 = 1_000_000;

fn driver(codes: &[i32], gain: Gain) -> (Shared<Model>, Driver) {
    let b = board(Model::new(codes.iter().map(|c| code(*c))));
    let d = Hx711::new(
        Out(b.clone(), Pin::Clock),
        In(b.clone()),
        Clock(b.clone()),
        gain,
    );
    (b, d.unwrap())
}

/// The model's faults, after the last read.
fn faults(b: &Shared<Model>) -> Vec<String> {
    let mut b = b.borrow_mut();
    let mut faults = std::mem::take(&mut b.faults);
    b.chip.finish(&mut faults);
    faults
}

/// The counts of the conversions read that a sample may be: settled, at
/// pulse count `setting`.
fn expected(b: &Shared<Model>, setting: u8) -> Vec<Result<i32, Error>> {
    let b = b.borrow();
    let read = b.chip.read.iter();
    read.filter(|c| c.settled && c.setting == setting)
        .map(|c| primo_loadcell::counts(c.code))
        .collect()
}

const CODES: [i32; 12] = [
    0,
    1,
    -1,
    123_456,
    -654_321,
    MAX - 1,
    MIN + 1,
    42,
    -42,
    7,
    8,
    9,
];

#[test]
fn reads_the_settled_codes_at_each_gain() {
    for (gain, pulses) in [(Gain::A128, 25), (Gain::B32, 26), (Gain::A64, 27)] {
        // Dropped: 4 settling, and at another gain the first, at A 128.
        let dropped = SETTLE + u8::from(gain != Gain::A128);
        let mut codes = vec![999; usize::from(dropped)];
        codes.extend(CODES);
        let (b, mut d) = driver(&codes, gain);
        let got: Vec<_> = (0..CODES.len()).map(|_| d.read(SECOND)).collect();
        assert_eq!(got, CODES.map(Ok), "{gain:?}");
        assert_eq!(got, expected(&b, pulses), "{gain:?}");
        assert_eq!(faults(&b), Vec::<String>::new(), "{gain:?}");
        let counts = &b.borrow().chip.pulse_counts;
        // The first read after the reset chooses the gain; all do.
        assert!(counts.iter().all(|n| *n == pulses), "{gain:?}: {counts:?}");
    }
}

#[test]
fn saturated_codes_are_out_of_range_and_reading_goes_on() {
    let mut codes = vec![0; usize::from(SETTLE)];
    codes.extend([MAX, 5, MIN, -5]);
    let (b, mut d) = driver(&codes, Gain::A128);
    assert_eq!(d.read(SECOND), Err(Error::OutOfRange { counts: MAX }));
    assert_eq!(d.read(SECOND), Ok(5));
    assert_eq!(d.read(SECOND), Err(Error::OutOfRange { counts: MIN }));
    assert_eq!(d.read(SECOND), Ok(-5));
    assert_eq!(faults(&b), Vec::<String>::new());
}

#[test]
fn polling_never_clocks_a_chip_that_is_not_ready() {
    let mut codes = vec![0; usize::from(SETTLE)];
    codes.push(77);
    let (b, mut d) = driver(&codes, Gain::A128);
    let mut got = None;
    for _ in 0..200 {
        if let Some(c) = d.sample().unwrap() {
            got = Some(c);
            break;
        }
        embedded_hal::delay::DelayNs::delay_us(&mut Clock(b.clone()), 1_000);
    }
    assert_eq!(got, Some(77));
    assert_eq!(faults(&b), Vec::<String>::new());
}

#[test]
fn a_chip_that_never_gets_ready_times_out() {
    let (b, mut d) = driver(&[], Gain::A128);
    let start = b.borrow().now;
    assert_eq!(d.read(50_000), Err(Error::NotReady));
    assert!(b.borrow().now - start >= 50_000_000);
    assert_eq!(faults(&b), Vec::<String>::new());
}

#[test]
fn power_down_stops_it_and_power_up_resets_it() {
    let mut codes = vec![0; usize::from(SETTLE) + 1];
    codes.extend([10, 11, 12, 13, 14, 15, 16, 17, 18, 19, 20]);
    let (b, mut d) = driver(&codes, Gain::A64);
    assert_eq!(d.read(SECOND), Ok(10));
    d.power_down().unwrap();
    assert!(!b.borrow().chip.powered);
    assert_eq!(d.read(SECOND), Err(Error::NotReady));
    d.power_up().unwrap();
    assert_eq!(b.borrow().chip.resets, 2, "new() resets too");
    // After the reset: 11 at A 128 and 12 to 15 settling, dropped.
    assert_eq!(d.read(SECOND), Ok(16));
    assert_eq!(faults(&b), Vec::<String>::new());
    assert_eq!(vec![Ok(10), Ok(16)], expected(&b, 27));
}

#[test]
fn a_gain_change_drops_the_conversions_before_it_settles() {
    let codes: Vec<i32> = (0..20).collect();
    let (b, mut d) = driver(&codes, Gain::A128);
    assert_eq!(d.read(SECOND), Ok(4));
    d.set_gain(Gain::B32);
    assert_eq!(d.gain(), Gain::B32);
    // 5 converts at A 128 and chooses B 32; 6 to 9 settle.
    assert_eq!(d.read(SECOND), Ok(10));
    assert_eq!(faults(&b), Vec::<String>::new());
    assert_eq!(expected(&b, 26), vec![Ok(10)]);
}

#[test]
fn a_failing_pin_is_an_error() {
    let (b, mut d) = driver(&[1, 2, 3, 4, 5, 6], Gain::A128);
    b.borrow_mut().broken = true;
    assert!(matches!(d.read(SECOND), Err(Error::Pin(_))));
    assert!(matches!(d.power_down(), Err(Error::Pin(_))));
}
