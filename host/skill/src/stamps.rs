//! Sample times as recorded, taken relative to the first sample. Recorders
//! stamp in Unix time (a ROS bag, most trackers): 1.7e9 s, where an `f32`
//! is 128 s coarse and even an `f64` 0.24 µs. The fits compute in `f32`,
//! so each stamp is read as `f64`, its first sample's subtracted (exactly,
//! for stamps of one recording), and only then rounded: a recording fits
//! as the same recording started at 0 would, bit for bit.

/// Why a stamp is refused; [`Refused::why`] says it after the stamp.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Refused {
    /// Not after the previous stamp.
    NotIncreasing {
        /// The previous stamp, as recorded.
        previous: f64,
    },
    /// So long after the first stamp that `f32` cannot hold the time.
    Beyond {
        /// Seconds since the first sample.
        since_first: f64,
    },
    /// After the previous stamp, but too close to it for the `f32` the
    /// fits compute in, this far into the recording: the two would be one.
    Indistinct {
        /// Seconds after the previous stamp.
        step: f64,
        /// Seconds since the first sample.
        since_first: f64,
    },
}

impl Refused {
    /// The reason, to follow the stamp in a message; `previous` names the
    /// previous sample ("the previous row", `t[2]`).
    pub fn why(&self, previous: &str) -> String {
        match *self {
            Refused::NotIncreasing { previous: p } => {
                format!("does not increase: {previous} is at t = {p}")
            }
            Refused::Beyond { since_first } => format!(
                "is {since_first:e} s after the first sample, more than float32, the precision \
                 the fit computes in, holds"
            ),
            Refused::Indistinct { step, since_first } => format!(
                "is {step:.3e} s after {previous}: {} s into the recording, stamps must be \
                 at least {:.3e} s apart to stay distinct in float32, the precision the fit \
                 computes in",
                crate::seconds::seconds(since_first),
                resolution(since_first)
            ),
        }
    }
}

/// The spacing of `f32` values at `seconds` (their unit in the last place).
fn resolution(seconds: f64) -> f64 {
    let x = seconds.abs() as f32;
    f64::from(f32::from_bits(x.to_bits() + 1) - x)
}

/// A recording's stamps, one after the other ([`Stamps::push`]).
#[derive(Debug, Clone, Default)]
pub struct Stamps {
    /// The first stamp, as recorded.
    first: Option<f64>,
    /// The previous stamp, as recorded and as returned.
    previous: Option<(f64, f32)>,
}

impl Stamps {
    /// No stamp yet.
    pub fn new() -> Stamps {
        Stamps::default()
    }

    /// The next stamp `t` (finite, s), as seconds since the first one in
    /// `f32`; refused where it is not after the previous stamp, or where
    /// rounding would make it equal to it.
    pub fn push(&mut self, t: f64) -> Result<f32, Refused> {
        let first = *self.first.get_or_insert(t);
        let since_first = t - first;
        let relative = since_first as f32;
        if !relative.is_finite() {
            return Err(Refused::Beyond { since_first });
        }
        if let Some((previous, previous_relative)) = self.previous {
            if t <= previous {
                return Err(Refused::NotIncreasing { previous });
            }
            if relative <= previous_relative {
                return Err(Refused::Indistinct {
                    step: t - previous,
                    since_first,
                });
            }
        }
        self.previous = Some((t, relative));
        Ok(relative)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn relative(stamps: &[f64]) -> Result<Vec<f32>, Refused> {
        let mut s = Stamps::new();
        stamps.iter().map(|t| s.push(*t)).collect()
    }

    #[test]
    fn unix_time_at_1_khz_is_the_recording_from_0() {
        // The instants a 1 kHz recorder stamps in Unix time, and the same
        // instants counted from the first.
        let unix: Vec<f64> = (0..5000).map(|i| 1.7e9 + f64::from(i) * 1e-3).collect();
        let from_zero: Vec<f64> = unix.iter().map(|t| t - 1.7e9).collect();
        let (a, b) = (relative(&unix).unwrap(), relative(&from_zero).unwrap());
        assert_eq!(a, b);
        // Each within f32's rounding of the true offset.
        for (i, t) in a.iter().enumerate() {
            let exact = i as f64 * 1e-3;
            assert!((f64::from(*t) - exact).abs() < 1e-6, "{i}: {t}");
        }
    }

    #[test]
    fn stamps_that_round_together_are_refused() {
        assert_eq!(
            relative(&[0.0, 1.0, 1.0]),
            Err(Refused::NotIncreasing { previous: 1.0 })
        );
        assert_eq!(
            relative(&[-1e300, 1e300]),
            Err(Refused::Beyond {
                since_first: 1e300 + 1e300
            })
        );
        // 1000 s in, f32 steps by 6.1e-5 s: 1e-5 s apart rounds to one.
        let e = relative(&[5.0, 1005.0, 1005.00001]).unwrap_err();
        let Refused::Indistinct { step, since_first } = e else {
            panic!("{e:?}")
        };
        assert!((step - 1e-5).abs() < 1e-9 && (since_first - 1000.00001).abs() < 1e-9);
        let why = e.why("the previous row");
        assert!(
            why.starts_with("is 1.000e-5 s after the previous row: 1000.00001"),
            "{why}"
        );
        assert!(why.contains("at least 6.104e-5 s apart"), "{why}");
    }
}
