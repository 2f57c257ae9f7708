//! Arbitrary demonstration files: the CSV parser gives a demonstration or
//! an error naming the file, never a panic, and what it accepts is what a
//! DMP fit needs: named, distinct DoF columns, at least MIN_ROWS rows,
//! finite values, strictly increasing times.
#![no_main]

use libfuzzer_sys::fuzz_target;
use primo_skill::csv::{MIN_ROWS, parse_demo};

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    match parse_demo("demo.csv", &text) {
        Ok(demo) => {
            let n = demo.names.len();
            assert!(n >= 1);
            assert!(demo.names.iter().all(|s| !s.is_empty() && s.trim() == s));
            for (i, a) in demo.names.iter().enumerate() {
                assert!(!demo.names[..i].contains(a));
            }
            assert!(demo.times.len() >= MIN_ROWS);
            assert_eq!(demo.positions.len(), demo.times.len() * n);
            assert!(
                demo.times
                    .iter()
                    .chain(&demo.positions)
                    .all(|v| v.is_finite())
            );
            assert!(demo.times.windows(2).all(|w| w[0] < w[1]));
        }
        Err(e) => assert!(e.to_string().contains("demo.csv"), "{e}"),
    }
});
