//! Arbitrary datagrams at the FRI port: the measurement (and command)
//! parsers give a packet or an error, never a panic, and what parses
//! encodes back to the same bytes. Besides the raw input, the input is
//! also tried with the right length, size and id (and a valid state and
//! quality) patched in, so most runs reach the field checks.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_fri::packet::{
    COMMAND_ID, COMMAND_SIZE, Command, MEASUREMENT_ID, MEASUREMENT_SIZE, Measurement,
};

/// `data` cut or zero-padded to `size`, with the header's size and id set.
fn framed(data: &[u8], size: usize, id: u16) -> Vec<u8> {
    let mut bytes = data.to_vec();
    bytes.resize(size, 0);
    bytes[4..6].copy_from_slice(&(size as u16).to_le_bytes());
    bytes[6..8].copy_from_slice(&id.to_le_bytes());
    bytes
}

fn check(bytes: &[u8]) {
    if let Ok(m) = Measurement::parse(bytes) {
        assert_eq!(m.encode(), bytes);
        assert!(
            m.measured()
                .iter()
                .chain(&m.commanded())
                .all(|v| v.is_finite())
        );
    }
    if let Ok(c) = Command::parse(bytes) {
        assert_eq!(c.encode(), bytes);
    }
}

fuzz_target!(|data: &[u8]| {
    check(data);
    let mut m = framed(data, MEASUREMENT_SIZE, MEASUREMENT_ID);
    // state (offset 144) and quality (146) in their ranges half the time.
    if data.first().is_some_and(|b| b & 1 == 1) {
        let (state, quality) = (u16::from(m[144] % 3), u16::from(m[146] % 4));
        m[144..146].copy_from_slice(&state.to_le_bytes());
        m[146..148].copy_from_slice(&quality.to_le_bytes());
    }
    check(&m);
    check(&framed(data, COMMAND_SIZE, COMMAND_ID));
});
