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
    let _ = write!(out, "{t:.6}");
    if out[start..].contains(&b'.') {
        while out.last() == Some(&b'0') {
            out.pop();
        }
        if out.last() == Some(&b'.') {
            out.pop();
        }
    }
}
