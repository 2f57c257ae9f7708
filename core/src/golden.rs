//! Error learning with golden-section search on the query (paper Sec. IV).
//!
//! The learner proposes a query `q`, the caller generalizes and executes the
//! movement for it and reports the error `ε`. Only the sign of `ε` is used, so
//! there is no gain to tune. Sign convention, as in the paper's pseudo-code:
//! **`ε > 0` means the query must increase** (e.g. `ε = q0 − q_m` when the
//! measured outcome grows with `q`; negate the error for a decreasing one).
//!
//! ```text
//! set search limits q_l and q_h; set desired query q0; set q = q0
//! repeat
//!   generalize and execute for q, measure ε
//!   if ε > 0 { q_l = q; q = q_l + (q_h − q_l)·0.618 }
//!   else     { q_h = q; q = q_l + (q_h − q_l)·0.382 }
//! until |ε| < precision
//! ```
//!
//! plus a roll-out budget, and a stop once the bracket can no longer shrink
//! in `f32`. The state machine is ask/tell:
//!
//! ```
//! use primo_core::golden::{ErrorLearner, GoldenSection, SearchConfig, Status};
//! let cfg = SearchConfig { low: 0.0, high: 2.0, desired: 0.5, precision: 1e-3, max_rollouts: 40 };
//! let mut learner = GoldenSection::new(cfg)?;
//! // The "cell": the outcome is q² and we want it to be 0.5.
//! while let Some(q) = learner.ask() {
//!     learner.tell(0.5 - q * q)?;
//! }
//! assert_eq!(learner.status(), Status::Converged);
//! assert!((learner.best().unwrap().query - 0.5f32.sqrt()).abs() < 1e-3);
//! # Ok::<(), primo_core::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::Error;

/// The golden ratio's conjugate, `(√5 − 1)/2`, as the paper's 0.618.
pub const GOLDEN: f32 = 0.618_034;

/// Settings shared by the error learners.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct SearchConfig {
    /// Lower search limit `q_l`.
    pub low: f32,
    /// Upper search limit `q_h`.
    pub high: f32,
    /// Desired query `q0`: the first query tried, strictly inside the limits.
    pub desired: f32,
    /// Stop when `|ε| < precision` (> 0).
    pub precision: f32,
    /// Stop after this many roll-outs (≥ 1).
    pub max_rollouts: u32,
}

impl SearchConfig {
    /// Checks the settings.
    pub fn validate(&self) -> Result<(), Error> {
        let finite = [self.low, self.high, self.desired, self.precision];
        crate::error::check_finite(&finite, "search settings")?;
        if !(self.low < self.desired && self.desired < self.high) {
            return Err(Error::OutOfRange(
                "search limits must satisfy low < desired < high",
            ));
        }
        if !(self.precision > 0.0) {
            return Err(Error::OutOfRange("precision must be > 0"));
        }
        if self.max_rollouts == 0 {
            return Err(Error::OutOfRange("max_rollouts must be >= 1"));
        }
        Ok(())
    }
}

/// Where a search stands.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Status {
    /// Waiting for the outcome of the query from [`ErrorLearner::ask`].
    Running,
    /// The last roll-out reached `|ε| < precision`.
    Converged,
    /// The roll-out budget is used up.
    BudgetExhausted,
    /// The bracket has shrunk to adjacent `f32` values without reaching the
    /// precision: the error is discontinuous or noisy at the root.
    BracketCollapsed,
}

/// The best roll-out so far: smallest `|ε|`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Best {
    /// Its query.
    pub query: f32,
    /// Its error.
    pub error: f32,
}

/// The ask/tell interface of the error learners.
pub trait ErrorLearner {
    /// The query to roll out next, or `None` once finished. Asking again
    /// before telling returns the same query.
    fn ask(&self) -> Option<f32>;
    /// Reports the error of the asked query. A non-finite error, or a call
    /// after the search finished, is an error and changes nothing.
    fn tell(&mut self, error: f32) -> Result<Status, Error>;
    /// Current status.
    fn status(&self) -> Status;
    /// The best roll-out so far.
    fn best(&self) -> Option<Best>;
    /// Roll-outs told so far.
    fn rollouts(&self) -> u32;
    /// The current bracket `[low, high]` known to contain the root.
    fn bracket(&self) -> (f32, f32);
}

/// Shared bookkeeping of one roll-out: best-so-far, count, stop conditions.
/// Returns the status after `error` at `query` has been recorded.
pub(crate) fn record(
    cfg: &SearchConfig,
    best: &mut Option<Best>,
    rollouts: &mut u32,
    query: f32,
    error: f32,
) -> Result<Status, Error> {
    if !error.is_finite() {
        return Err(Error::NotFinite("error"));
    }
    *rollouts += 1;
    if best.is_none_or(|b| libm::fabsf(error) < libm::fabsf(b.error)) {
        *best = Some(Best { query, error });
    }
    Ok(if libm::fabsf(error) < cfg.precision {
        Status::Converged
    } else if *rollouts >= cfg.max_rollouts {
        Status::BudgetExhausted
    } else {
        Status::Running
    })
}

/// The paper's golden-section error learner.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct GoldenSection {
    cfg: SearchConfig,
    low: f32,
    high: f32,
    query: f32,
    rollouts: u32,
    best: Option<Best>,
    status: Status,
}

impl GoldenSection {
    /// A new search starting at the desired query.
    pub fn new(cfg: SearchConfig) -> Result<Self, Error> {
        cfg.validate()?;
        Ok(Self {
            cfg,
            low: cfg.low,
            high: cfg.high,
            query: cfg.desired,
            rollouts: 0,
            best: None,
            status: Status::Running,
        })
    }
}

impl ErrorLearner for GoldenSection {
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
        let next = if error > 0.0 {
            self.low = self.query;
            self.low + (self.high - self.low) * GOLDEN
        } else {
            self.high = self.query;
            self.low + (self.high - self.low) * (1.0 - GOLDEN)
        };
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
