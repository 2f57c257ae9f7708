use core::fmt;

/// Everything that can go wrong in the core. Each variant says what was wrong;
/// the `&'static str` names the argument or quantity concerned.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub enum Error {
    /// More items than the compile-time capacity holds.
    Capacity {
        /// What overflowed.
        what: &'static str,
        /// How many were asked for.
        requested: usize,
        /// How many fit.
        capacity: usize,
    },
    /// Two sizes that must agree do not.
    Length {
        /// What has the wrong length.
        what: &'static str,
        /// The length required.
        expected: usize,
        /// The length given.
        found: usize,
    },
    /// A value is NaN or infinite where a finite one is required.
    NotFinite(&'static str),
    /// A value is outside its allowed range (the message says which range).
    OutOfRange(&'static str),
    /// A linear system is singular or not positive definite.
    Singular(&'static str),
    /// The call does not fit the object's current state.
    BadState(&'static str),
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Error::Capacity {
                what,
                requested,
                capacity,
            } => write!(
                f,
                "{what}: {requested} requested but capacity is {capacity}"
            ),
            Error::Length {
                what,
                expected,
                found,
            } => write!(f, "{what}: expected length {expected}, found {found}"),
            Error::NotFinite(what) => write!(f, "{what} must be finite"),
            Error::OutOfRange(what) => write!(f, "out of range: {what}"),
            Error::Singular(what) => write!(f, "singular system: {what}"),
            Error::BadState(what) => write!(f, "bad state: {what}"),
        }
    }
}

impl core::error::Error for Error {}

/// Checks that every value in `values` is finite.
pub(crate) fn check_finite(values: &[f32], what: &'static str) -> Result<(), Error> {
    if values.iter().all(|v| v.is_finite()) {
        Ok(())
    } else {
        Err(Error::NotFinite(what))
    }
}

/// Checks that every value in `values` is finite and within `±bound`.
pub(crate) fn check_bounded(values: &[f32], bound: f32, what: &'static str) -> Result<(), Error> {
    check_finite(values, what)?;
    if values.iter().all(|v| libm::fabsf(*v) <= bound) {
        Ok(())
    } else {
        Err(Error::OutOfRange(what))
    }
}

/// Checks that `v` is finite and positive.
pub(crate) fn check_positive(v: f32, what: &'static str) -> Result<(), Error> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::OutOfRange(what))
    }
}

/// Checks `n <= capacity`: [`Error::Capacity`] if not.
pub fn check_capacity(what: &'static str, n: usize, capacity: usize) -> Result<(), Error> {
    if n <= capacity {
        Ok(())
    } else {
        Err(Error::Capacity {
            what,
            requested: n,
            capacity,
        })
    }
}

/// Checks `found == expected`: [`Error::Length`] if not.
pub fn check_len(what: &'static str, expected: usize, found: usize) -> Result<(), Error> {
    if found == expected {
        Ok(())
    } else {
        Err(Error::Length {
            what,
            expected,
            found,
        })
    }
}
