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
