//! How primo writes a time: in seconds, to the microsecond.

/// A time in seconds to the microsecond, without trailing zeros: 9·0.1
/// prints as 0.9, not as f32's 0.90000004 or a sum of steps' 0.9000000000000001.
pub(crate) fn seconds(t: f64) -> String {
    let mut out = Vec::new();
    push_seconds(&mut out, t);
    String::from_utf8_lossy(&out).into_owned()
}

/// Appends [`seconds`]`(t)`.
pub(crate) fn push_seconds(out: &mut Vec<u8>, t: f64) {
    use std::io::Write as _;
    let start = out.len();
    let micros = t * 1e6;
    // Away from a half microsecond, the product's rounding (at most 1e-4 µs
    // below 1e12 µs) cannot change which whole microsecond is nearest, so
    // the digits come from integers, several times faster than formatting
    // the float; a time near a tie, or negative (whose sign the float
    // keeps), takes the float's.
    if t.is_sign_positive() && micros < 1e12 && (micros.fract() - 0.5).abs() > 1e-3 {
        let micros = micros.round() as u64;
        let _ = write!(out, "{}.{:06}", micros / 1_000_000, micros % 1_000_000);
    } else {
        let _ = write!(out, "{t:.6}");
    }
    if out[start..].contains(&b'.') {
        while out.last() == Some(&b'0') {
            out.pop();
        }
        if out.last() == Some(&b'.') {
            out.pop();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    proptest::proptest! {
        /// The integers' digits are the float's.
        #[test]
        fn whole_microseconds_print_as_the_float_does(k in 0..10_000_000_u64, t in -1e6..1e9_f64) {
            // Steps in f64 and in f32 (a run's times), and any time.
            let step = f64::from(k as f32 * 0.001_f32);
            for t in [k as f64 * 0.001, k as f64 * 1e-6, step, t] {
                let mut float = format!("{t:.6}").into_bytes();
                while float.last() == Some(&b'0') {
                    float.pop();
                }
                if float.last() == Some(&b'.') {
                    float.pop();
                }
                proptest::prop_assert_eq!(seconds(t).into_bytes(), float);
            }
        }
    }
}
