//! Arbitrary lines from a scale: the MT-SICS parser gives a response or an
//! error, never a panic, and a response prints as a line that parses back
//! to itself.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_mtsics::{MAX_LINE, Response, parse_response, quote};

fuzz_target!(|data: &[u8]| {
    match parse_response(data) {
        Ok(response) => {
            let line = response.to_string();
            assert_eq!(
                parse_response(line.as_bytes()),
                Ok(response.clone()),
                "{line}"
            );
            if let Response::Weight(w, _) | Response::Tared(w) | Response::TareValue(w) = response {
                assert!(w.value.is_finite());
            }
        }
        Err(e) => {
            // The quoted line is printable ASCII, cut near MAX_LINE.
            assert!(e.line.bytes().all(|b| (b' '..=b'~').contains(&b)));
            assert!(e.line.len() <= 4 * MAX_LINE + 32, "{}", e.line.len());
            let _ = e.to_string();
        }
    }
    assert!(quote(data).is_ascii());
});
