//! What the fuzz targets share: numbers drawn from the fuzzer's bytes.

use arbitrary::{Result, Unstructured};

/// A number: one time in eight any `f32` bit pattern (NaN, ±∞, subnormal,
/// huge), otherwise a "reasonable" value, `±scale` in 65536 steps, so that
/// most runs get past the input checks into the arithmetic.
pub fn num(u: &mut Unstructured, scale: f32) -> Result<f32> {
    if u.ratio(1, 8)? {
        Ok(f32::from_bits(u.arbitrary()?))
    } else {
        Ok(f32::from(u.arbitrary::<i16>()?) / 32768.0 * scale)
    }
}

/// A value strictly above 0 and at most `scale` (or, as in [`num`], one
/// time in eight any bit pattern).
pub fn positive(u: &mut Unstructured, scale: f32) -> Result<f32> {
    if u.ratio(1, 8)? {
        Ok(f32::from_bits(u.arbitrary()?))
    } else {
        Ok((f32::from(u.arbitrary::<u16>()?) + 1.0) / 65536.0 * scale)
    }
}

/// What every error learner must keep after a tell: `told` roll-outs
/// counted, within `max_rollouts`; its best error (`best`, as it reports
/// it) is `smallest` of those told; converged only below `precision`.
pub fn check_told(
    rollouts: u32,
    told: u32,
    max_rollouts: u32,
    best: Option<f32>,
    smallest: f32,
    converged: bool,
    precision: f32,
) {
    assert_eq!(rollouts, told);
    assert!(told <= max_rollouts);
    assert_eq!(best, Some(smallest));
    if converged {
        assert!(smallest < precision);
    }
}
