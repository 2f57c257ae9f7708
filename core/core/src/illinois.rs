//! A bracketed error learner that also uses the error's magnitude: the
//! Illinois variant of regula falsi, with secant steps before a bracket is
//! known and the paper's golden step as the fallback.
//!
//! Same interface, sign convention and stop rules as
//! [`GoldenSection`](crate::golden::GoldenSection) (see [`crate::golden`]):
//!
//! 1. The first query is the desired one.
//! 2. While every error so far has the same sign, the root lies between the
//!    last query and one search limit. With two queries on that side, the
//!    secant through them predicts the root; the prediction is used if it
//!    falls strictly inside the open side, otherwise the golden step is taken.
//! 3. Once errors of both signs are known, the root is bracketed and each
//!    query is the regula-falsi point of the bracket. When the same end is
//!    replaced twice in a row, the error kept at the other end is halved
//!    (Illinois), which gives superlinear convergence instead of regula
//!    falsi's one-sided crawl.
//!
//! Every query lies strictly inside the current bracket, so the bracket
//! shrinks at every roll-out, exactly as in golden-section search; no
//! parameter needs tuning.
//!
//! ```
//! use primo_core::golden::{ErrorLearner, SearchConfig, Status};
//! use primo_core::illinois::Illinois;
//! let cfg = SearchConfig { low: 0.0, high: 2.0, desired: 0.5, precision: 1e-3, max_rollouts: 40 };
//! let mut learner = Illinois::new(cfg)?;
//! while let Some(q) = learner.ask() {
//!     learner.tell(0.5 - q * q)?;
//! }
//! assert_eq!(learner.status(), Status::Converged);
//! assert!(learner.rollouts() <= 6);
//! # Ok::<(), primo_core::Error>(())
//! ```

use serde::Serialize;

use crate::Error;
use crate::golden::{End, ErrorLearner, SearchConfig, SearchState, Status};

/// A known point `(q, ε)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
struct Point {
    q: f32,
    e: f32,
}

/// The Illinois error learner.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Illinois {
    state: SearchState,
    /// Error at the bracket's low end (positive), once a roll-out has been
    /// there; halved by the Illinois rule.
    low_error: Option<f32>,
    /// Error at the high end (negative), likewise.
    high_error: Option<f32>,
    /// The point before the last one on the same side, for the secant.
    previous: Option<Point>,
    /// Which end of the bracket the last roll-out replaced.
    last_side: Option<End>,
}

impl Illinois {
    /// A new search starting at the desired query.
    pub fn new(cfg: SearchConfig) -> Result<Self, Error> {
        Ok(Self {
            state: SearchState::new(cfg)?,
            low_error: None,
            high_error: None,
            previous: None,
            last_side: None,
        })
    }

    fn next_query(&self, current: Point) -> f32 {
        let (a, b) = self.state.bracket();
        let proposal = match (self.low_error, self.high_error) {
            // Bracketed: regula falsi between the ends.
            (Some(fa), Some(fb)) => (a * fb - b * fa) / (fb - fa),
            // One-sided: secant through the last two points on this side.
            _ => match self.previous {
                Some(p) if p.e != current.e => {
                    current.q - current.e * (current.q - p.q) / (current.e - p.e)
                }
                _ => f32::NAN,
            },
        };
        if proposal > a && proposal < b {
            proposal
        } else {
            self.state.golden_step(current.e)
        }
    }
}

impl ErrorLearner for Illinois {
    fn state(&self) -> &SearchState {
        &self.state
    }

    fn tell(&mut self, error: f32) -> Result<Status, Error> {
        let (low, high) = self.state.bracket();
        let Some(query) = self.state.record(error)? else {
            return Ok(self.status());
        };
        let current = Point { q: query, e: error };
        let side = End::of(error);
        // The secant needs the previous point on the same side.
        let repeated = self.last_side == Some(side);
        self.previous = match side {
            End::Low => self.low_error.map(|e| Point { q: low, e }),
            End::High => self.high_error.map(|e| Point { q: high, e }),
        };
        let (kept, moved) = match side {
            End::Low => (&mut self.high_error, &mut self.low_error),
            End::High => (&mut self.low_error, &mut self.high_error),
        };
        *moved = Some(error);
        if repeated {
            *kept = kept.map(|e| 0.5 * e);
        }
        self.last_side = Some(side);
        self.state.shrink(query, error);
        let next = self.next_query(current);
        Ok(self.state.propose(next))
    }

    fn tell_infeasible(&mut self) -> Result<Status, Error> {
        let Some(end) = self.state.record_infeasible()? else {
            return Ok(self.status());
        };
        // No error is known at the moved end: regula falsi waits for one,
        // and the step is the golden section's.
        match end {
            End::Low => self.low_error = None,
            End::High => self.high_error = None,
        }
        self.previous = None;
        self.last_side = None;
        Ok(self.state.propose(self.state.golden_from(end)))
    }
}
