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
//! in `f32`. A query that cannot be rolled out or measured (the robot's
//! limits reject its movement, the task failed) is told as infeasible
//! ([`ErrorLearner::tell_infeasible`]): it becomes the bracket's end on its
//! side of the best roll-out, and the search goes on inside. The state
//! machine is ask/tell:
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
        check_span(self.low, self.high)?;
        check_stop_rules(self.precision, self.max_rollouts)
    }
}

/// `high − low` must be finite in `f32` for the steps between them.
pub(crate) fn check_span(low: f32, high: f32) -> Result<(), Error> {
    if (high - low).is_finite() {
        Ok(())
    } else {
        Err(Error::OutOfRange("search limits too far apart for f32"))
    }
}

/// Every error learner's stop rules: `precision > 0`, `max_rollouts ≥ 1`.
pub(crate) fn check_stop_rules(precision: f32, max_rollouts: u32) -> Result<(), Error> {
    if !(precision > 0.0) {
        return Err(Error::OutOfRange("precision must be > 0"));
    }
    if max_rollouts == 0 {
        return Err(Error::OutOfRange("max_rollouts must be >= 1"));
    }
    Ok(())
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
    /// [`crate::secant`], without reaching the precision: the target was
    /// shown to lie beyond the search limits (the best query sits on a
    /// limit, every step left pushes out of it, and a probe back inside
    /// made no progress), or no step within the trust region moves the
    /// query in `f32` (module docs). The paper's fixed-gain rules: the next
    /// step would leave the query where it is.
    Stalled,
    /// The first roll-out, at the desired query, was infeasible: there is
    /// no feasible roll-out to narrow the search toward.
    Infeasible,
}

/// An end of the search bracket.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
pub(crate) enum End {
    /// The low end: the root is above it (`ε > 0` there).
    Low,
    /// The high end: the root is below it (`ε ≤ 0` there).
    High,
}

/// The best roll-out so far: smallest `|ε|`.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Best {
    /// Its query.
    pub query: f32,
    /// Its error.
    pub error: f32,
}

/// The ask/tell interface of the error learners. Implementors hold a
/// [`SearchState`] and decide only where the next query goes.
pub trait ErrorLearner {
    /// The shared search state.
    fn state(&self) -> &SearchState;
    /// Reports the error of the asked query. A non-finite error, or a call
    /// after the search finished, is an error and changes nothing.
    fn tell(&mut self, error: f32) -> Result<Status, Error>;
    /// Reports that the asked query could not be rolled out or measured:
    /// it bounds the search on its side of the best roll-out (the root is
    /// taken to lie among the feasible queries), and counts against the
    /// budget. The first roll-out's, at the desired query, ends the search
    /// as [`Status::Infeasible`]. A call after the search finished is an
    /// error and changes nothing.
    fn tell_infeasible(&mut self) -> Result<Status, Error>;
    /// The query to roll out next, or `None` once finished. Asking again
    /// before telling returns the same query.
    fn ask(&self) -> Option<f32> {
        let s = self.state();
        (s.status == Status::Running).then_some(s.query)
    }
    /// Current status.
    fn status(&self) -> Status {
        self.state().status
    }
    /// The best roll-out so far.
    fn best(&self) -> Option<Best> {
        self.state().best
    }
    /// Roll-outs told so far.
    fn rollouts(&self) -> u32 {
        self.state().rollouts
    }
    /// The current bracket `[low, high]` known to contain the root.
    fn bracket(&self) -> (f32, f32) {
        (self.state().low, self.state().high)
    }
}

/// What every bracketed error learner tracks: settings, bracket, the query
/// in flight, roll-out count, best so far and status.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SearchState {
    cfg: SearchConfig,
    low: f32,
    high: f32,
    query: f32,
    rollouts: u32,
    best: Option<Best>,
    status: Status,
}

impl SearchState {
    /// A search starting at the desired query over the configured limits.
    pub(crate) fn new(cfg: SearchConfig) -> Result<Self, Error> {
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

    /// Records `error` for the query in flight: best-so-far, count, stop
    /// conditions. Returns the query it belonged to and whether the search
    /// goes on; on an error nothing changes.
    pub(crate) fn record(&mut self, error: f32) -> Result<Option<f32>, Error> {
        if self.status != Status::Running {
            return Err(Error::BadState("the search has finished"));
        }
        if !error.is_finite() {
            return Err(Error::NotFinite("error"));
        }
        self.rollouts += 1;
        let query = self.query;
        if self
            .best
            .is_none_or(|b| libm::fabsf(error) < libm::fabsf(b.error))
        {
            self.best = Some(Best { query, error });
        }
        self.status = if libm::fabsf(error) < self.cfg.precision {
            Status::Converged
        } else if self.rollouts >= self.cfg.max_rollouts {
            Status::BudgetExhausted
        } else {
            Status::Running
        };
        Ok((self.status == Status::Running).then_some(query))
    }

    /// Moves the end on `error`'s side of the bracket to `query`: the root is
    /// above a query with `ε > 0` and below one with `ε ≤ 0`.
    pub(crate) fn shrink(&mut self, query: f32, error: f32) {
        self.move_end(End::of(error), query);
    }

    fn move_end(&mut self, end: End, query: f32) {
        match end {
            End::Low => self.low = query,
            End::High => self.high = query,
        }
    }

    /// Records that the query in flight is infeasible and moves the end on
    /// its side of the best roll-out to it; returns that end if the search
    /// goes on. Without a best roll-out (the first, desired query) the
    /// search stops as [`Status::Infeasible`].
    pub(crate) fn record_infeasible(&mut self) -> Result<Option<End>, Error> {
        if self.status != Status::Running {
            return Err(Error::BadState("the search has finished"));
        }
        self.rollouts += 1;
        let query = self.query;
        let end = match self.best {
            None => {
                self.status = Status::Infeasible;
                return Ok(None);
            }
            Some(b) if query > b.query => End::High,
            Some(_) => End::Low,
        };
        self.move_end(end, query);
        if self.rollouts >= self.cfg.max_rollouts {
            self.status = Status::BudgetExhausted;
            return Ok(None);
        }
        Ok(Some(end))
    }

    /// The bracket `(low, high)`.
    pub(crate) fn bracket(&self) -> (f32, f32) {
        (self.low, self.high)
    }

    /// The paper's step in the current bracket: 0.618 of the way up after
    /// `ε > 0`, 0.382 after `ε ≤ 0`.
    pub(crate) fn golden_step(&self, error: f32) -> f32 {
        self.golden_from(End::of(error))
    }

    /// The paper's step after the `end` of the bracket moved: 0.618 of the
    /// way up after the low end, 0.382 after the high one.
    pub(crate) fn golden_from(&self, end: End) -> f32 {
        let fraction = match end {
            End::Low => GOLDEN,
            End::High => 1.0 - GOLDEN,
        };
        self.low + (self.high - self.low) * fraction
    }

    /// Sets the next query; stops with [`Status::BracketCollapsed`] if it is
    /// not strictly inside the bracket (adjacent `f32` ends).
    pub(crate) fn propose(&mut self, next: f32) -> Status {
        if !(next > self.low && next < self.high) {
            self.status = Status::BracketCollapsed;
        }
        self.query = next;
        self.status
    }
}

impl End {
    /// The end a roll-out of error `error` replaces.
    pub(crate) fn of(error: f32) -> End {
        if error > 0.0 { End::Low } else { End::High }
    }
}

/// The paper's golden-section error learner.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct GoldenSection {
    state: SearchState,
}

impl GoldenSection {
    /// A new search starting at the desired query.
    pub fn new(cfg: SearchConfig) -> Result<Self, Error> {
        Ok(Self {
            state: SearchState::new(cfg)?,
        })
    }
}

impl ErrorLearner for GoldenSection {
    fn state(&self) -> &SearchState {
        &self.state
    }

    fn tell(&mut self, error: f32) -> Result<Status, Error> {
        let Some(query) = self.state.record(error)? else {
            return Ok(self.state.status);
        };
        self.state.shrink(query, error);
        Ok(self.state.propose(self.state.golden_step(error)))
    }

    fn tell_infeasible(&mut self) -> Result<Status, Error> {
        let Some(end) = self.state.record_infeasible()? else {
            return Ok(self.state.status);
        };
        Ok(self.state.propose(self.state.golden_from(end)))
    }
}
