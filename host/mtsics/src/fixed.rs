//! A number with fixed decimals as a person reads it: a value that rounds
//! to zero is `0.0`, never `-0.0` (a scale's noise about an empty pan, a
//! pour of a hair less than nothing). Shared by every weight and volume
//! primo prints.

use std::fmt;

/// `value` with `decimals` decimals; `{:6}` pads it (on the left, as a
/// number) and `{:+}` signs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fixed(pub f64, pub usize);

impl fmt::Display for Fixed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let Fixed(value, decimals) = *self;
        let text = format!("{value:.decimals$}");
        let text = match text.strip_prefix('-') {
            Some(abs) if abs.bytes().all(|b| b == b'0' || b == b'.') => abs.to_string(),
            _ => text,
        };
        let text = match f.sign_plus() && !text.starts_with('-') {
            true => format!("+{text}"),
            false => text,
        };
        // Right-aligned unless told otherwise, as numbers are.
        match (f.width(), f.align()) {
            (Some(width), None) => write!(f, "{text:>width$}"),
            _ => f.pad(&text),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Fixed;

    #[test]
    fn no_negative_zero() {
        assert_eq!(Fixed(-0.00001, 1).to_string(), "0.0");
        assert_eq!(Fixed(-0.0, 2).to_string(), "0.00");
        assert_eq!(Fixed(-0.06, 1).to_string(), "-0.1");
        assert_eq!(format!("{:6}", Fixed(-0.04, 1)), "   0.0");
        assert_eq!(format!("{:<6}|", Fixed(1.0, 1)), "1.0   |");
        assert_eq!(format!("{:+6}", Fixed(-0.04, 1)), "  +0.0");
        assert_eq!(format!("{:+6}", Fixed(-2.0, 1)), "  -2.0");
        assert_eq!(format!("{:+}", Fixed(f64::NAN, 1)), "+NaN");
    }
}
