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

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::golden::{Best, ErrorLearner, GOLDEN, SearchConfig, Status, record};

/// A known point `(q, ε)`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
struct Point {
    q: f32,
    e: f32,
}

/// Which end of the bracket the last roll-out replaced.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
enum Side {
    Low,
    High,
}

/// The Illinois error learner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Illinois {
    cfg: SearchConfig,
    low: f32,
    high: f32,
    /// Error at `low` (positive), once a roll-out has been there; halved by
    /// the Illinois rule.
    low_error: Option<f32>,
    /// Error at `high` (negative), likewise.
    high_error: Option<f32>,
    /// The point before the last one on the same side, for the secant.
    previous: Option<Point>,
    last_side: Option<Side>,
    query: f32,
    rollouts: u32,
    best: Option<Best>,
    status: Status,
}

impl Illinois {
    /// A new search starting at the desired query.
    pub fn new(cfg: SearchConfig) -> Result<Self, Error> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            low: cfg.low,
            high: cfg.high,
            low_error: None,
            high_error: None,
            previous: None,
            last_side: None,
            query: cfg.desired,
            rollouts: 0,
            best: None,
            status: Status::Running,
        })
    }

    fn next_query(&self, side: Side, current: Point) -> f32 {
        let (a, b) = (self.low, self.high);
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
        } else if side == Side::Low {
            a + (b - a) * GOLDEN
        } else {
            a + (b - a) * (1.0 - GOLDEN)
        }
    }
}

impl ErrorLearner for Illinois {
    fn ask(&self) -> Option<f32> {
        (self.status == Status::Running).then_some(self.query)
    }

    fn tell(&mut self, error: f32) -> Result<Status, Error> {
        if self.status != Status::Running {
            return Err(Error::BadState("the search has finished"));
        }
        let status = record(
            &self.cfg,
            &mut self.best,
            &mut self.rollouts,
            self.query,
            error,
        )?;
        self.status = status;
        if status != Status::Running {
            return Ok(status);
        }
        let current = Point {
            q: self.query,
            e: error,
        };
        let side = if error > 0.0 { Side::Low } else { Side::High };
        // The secant needs the previous point on the same side.
        let same_side_point = match side {
            Side::Low => self.low_error.map(|e| Point { q: self.low, e }),
            Side::High => self.high_error.map(|e| Point { q: self.high, e }),
        };
        let repeated = self.last_side == Some(side);
        match side {
            Side::Low => {
                self.low = current.q;
                self.low_error = Some(error);
                if repeated {
                    self.high_error = self.high_error.map(|e| 0.5 * e);
                }
            }
            Side::High => {
                self.high = current.q;
                self.high_error = Some(error);
                if repeated {
                    self.low_error = self.low_error.map(|e| 0.5 * e);
                }
            }
        }
        self.previous = same_side_point;
        self.last_side = Some(side);
        let next = self.next_query(side, current);
        if next <= self.low || next >= self.high {
            self.status = Status::BracketCollapsed;
        }
        self.query = next;
        Ok(self.status)
    }

    fn status(&self) -> Status {
        self.status
    }

    fn best(&self) -> Option<Best> {
        self.best
    }

    fn rollouts(&self) -> u32 {
        self.rollouts
    }

    fn bracket(&self) -> (f32, f32) {
        (self.low, self.high)
    }
}
