//! Faults: how a device says a request failed and changed nothing, the
//! same on every device and endpoint.

use core::fmt;

use heapless::String;
use serde::{Deserialize, Serialize};

/// Length of the detail text of a fault.
pub const DETAIL: usize = 64;

/// A failed request: the kind, and a text saying what was wrong.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
pub struct Fault {
    /// What kind of failure.
    pub kind: FaultKind,
    /// What was wrong, in words (cut at [`DETAIL`] bytes).
    pub detail: String<DETAIL>,
}

/// Kinds of [`Fault`].
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum FaultKind {
    /// The host speaks another protocol version.
    Version,
    /// More than the coprocessor holds.
    Capacity,
    /// The request does not fit the learning state (e.g. tell before ask).
    BadState,
    /// The frame was corrupt or oversized and was dropped.
    BadFrame,
    /// The values were rejected (not finite, out of range, …).
    Invalid,
    /// The scale's load is beyond its capacity (or its zero range).
    Overload,
    /// The scale's load is below its zero range.
    Underload,
    /// The scale's reading is not stable yet: ask again.
    NotSettled,
    /// The scale has no calibration.
    Uncalibrated,
}

impl Fault {
    /// A fault whose detail is `detail`, cut to [`DETAIL`] bytes.
    pub fn new(kind: FaultKind, detail: impl fmt::Display) -> Self {
        let mut text = Truncating(String::new());
        let _ = fmt::write(&mut text, format_args!("{detail}"));
        Fault {
            kind,
            detail: text.0,
        }
    }
}

impl fmt::Display for Fault {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let kind = match self.kind {
            FaultKind::Version => "version mismatch",
            FaultKind::Capacity => "over capacity",
            FaultKind::BadState => "bad state",
            FaultKind::BadFrame => "bad frame",
            FaultKind::Invalid => "invalid",
            FaultKind::Overload => "overload",
            FaultKind::Underload => "underload",
            FaultKind::NotSettled => "not settled",
            FaultKind::Uncalibrated => "uncalibrated",
        };
        write!(f, "{kind}: {}", self.detail)
    }
}

/// Writes what fits and drops the rest, on a character boundary.
struct Truncating(String<DETAIL>);

impl fmt::Write for Truncating {
    fn write_str(&mut self, s: &str) -> fmt::Result {
        for c in s.chars() {
            if self.0.push(c).is_err() {
                break;
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::string::ToString;

    #[test]
    fn fault_details_are_cut_on_a_character_boundary() {
        let f = Fault::new(FaultKind::Invalid, "ü".repeat(DETAIL));
        assert_eq!(f.detail.len(), DETAIL);
        assert!(f.to_string().starts_with("invalid: ü"));
    }
}
