//! Arbitrary messages round-trip: any `Request` or `Reply`, the
//! coprocessor's or the scale device's (built from the input by postcard, so every variant and value is reachable, NaNs too)
//! either does not fit a frame or encodes to a frame that the reader cuts
//! out whole and the decoder gives back bit for bit.
#![no_main]

use core::fmt::Debug;

use libfuzzer_sys::fuzz_target;
use primo_protocol::frame::{self as wire, Frame, FrameError, FrameReader, MAX_FRAME};
use primo_protocol::learner::{Reply, Request};
use primo_protocol::scale;
use serde::Serialize;
use serde::de::DeserializeOwned;

fn round_trip<T: Serialize + DeserializeOwned + Debug>(seq: u32, body: &T) {
    let mut buf = [0u8; MAX_FRAME];
    let frame = match wire::encode(seq, body, &mut buf) {
        Ok(frame) => frame.to_vec(),
        Err(e) => {
            // Only a message too long for a frame: postcard ‖ CRC-32, one
            // COBS overhead byte (frames are under 254 bytes), 0x00.
            assert_eq!(e, FrameError::Overflow);
            const ROOM: usize = 4 * MAX_FRAME;
            let mut plain = [0u8; ROOM];
            let n = postcard::to_slice(&Frame { seq, body }, &mut plain).map_or(ROOM, |p| p.len());
            assert!(n + 6 > MAX_FRAME, "{n} bytes did not fit");
            return;
        }
    };
    let mut reader = FrameReader::new();
    let (last, bytes) = frame.split_last().expect("a frame is never empty");
    assert_eq!(*last, 0);
    assert!(bytes.iter().all(|b| *b != 0));
    assert!(bytes.iter().all(|b| reader.push(*b).is_none()));
    let raw = reader
        .push(0)
        .expect("the delimiter ends the frame")
        .expect("fits");
    let got = wire::decode::<T>(raw).expect("an encoded frame decodes");
    assert_eq!(got.seq, seq);
    // Bit for bit: Debug tells -0.0 from 0.0, the re-encoding NaN payloads.
    assert_eq!(format!("{:?}", got.body), format!("{body:?}"));
    let mut again = [0u8; MAX_FRAME];
    assert_eq!(wire::encode(seq, &got.body, &mut again), Ok(&frame[..]));
}

fuzz_target!(|data: &[u8]| {
    let Some((&which, rest)) = data.split_first() else {
        return;
    };
    let Ok((seq, rest)) = postcard::take_from_bytes::<u32>(rest) else {
        return;
    };
    match which & 3 {
        0 => {
            if let Ok((body, _)) = postcard::take_from_bytes::<Request>(rest) {
                round_trip(seq, &body);
            }
        }
        1 => {
            if let Ok((body, _)) = postcard::take_from_bytes::<Reply>(rest) {
                round_trip(seq, &body);
            }
        }
        2 => {
            if let Ok((body, _)) = postcard::take_from_bytes::<scale::Request>(rest) {
                round_trip(seq, &body);
            }
        }
        _ => {
            if let Ok((body, _)) = postcard::take_from_bytes::<scale::Reply>(rest) {
                round_trip(seq, &body);
            }
        }
    }
});
