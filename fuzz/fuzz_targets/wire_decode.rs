//! Arbitrary bytes off a device's line: the frame reader and the decoder
//! never panic, and a frame any decoder accepts (the coprocessor's
//! messages, the scale device's) is the exact canonical encoding of what
//! it decoded to.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_protocol::frame::{self as wire, FrameReader, MAX_FRAME};
use primo_protocol::learner::{Reply, Request};
use primo_protocol::scale;
use serde::Serialize;
use serde::de::DeserializeOwned;

/// Decodes `raw` as a `T` frame; if accepted, it must re-encode to `raw`.
fn check<T: Serialize + DeserializeOwned>(raw: &[u8]) {
    if let Ok(frame) = wire::decode::<T>(raw) {
        let mut buf = [0u8; MAX_FRAME];
        let again = wire::encode(frame.seq, &frame.body, &mut buf).expect("re-encodes");
        assert_eq!(again.split_last().map(|(_, b)| b), Some(raw));
    }
}

fuzz_target!(|data: &[u8]| {
    // As one frame, without the reader.
    check::<Request>(data);
    check::<Reply>(data);
    check::<scale::Request>(data);
    check::<scale::Reply>(data);
    // As a stream: every frame the reader cuts is short and 0x00-free.
    let mut reader = FrameReader::new();
    for &b in data {
        if let Some(Ok(raw)) = reader.push(b) {
            assert!(!raw.is_empty() && raw.len() < MAX_FRAME && !raw.contains(&0));
            check::<Request>(raw);
            check::<Reply>(raw);
            check::<scale::Request>(raw);
            check::<scale::Reply>(raw);
        }
    }
});
