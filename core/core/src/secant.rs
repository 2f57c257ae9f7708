//! Error learning on a query of any dimension: the paper's eq. 10,
//! `q ← q + K ε`, with the gain `K` learned from the roll-outs themselves
//! ([`Rule::Broyden`]); and, as baselines, the paper's eq. 10 and 11 with
//! `K` fixed ([`Rule::Fixed`], [`Rule::Weighted`]).
//!
//! `ε = desired − measured` is the error vector, with the sign convention
//! of [`crate::golden`]: `ε_i > 0` means component `i` of the query must
//! grow when `K = I`. The paper takes `K ≈ I`, right when generalization is
//! accurate (then `measured ≈ q`, so `ε ≈ desired − q`). Where it is not,
//! a fixed `K` converges slowly, or not at all. This learner starts from
//! `K = I` and corrects `K` after every roll-out:
//!
//! - With `J = ∂ε/∂q`, Newton's step is `q ← q − J⁻¹ ε`, so the ideal gain
//!   is `K = −J⁻¹`. A step `Δq` and the change `Δε ≈ J Δq` it made give
//!   `K Δε ≈ −Δq` (the secant condition).
//! - Broyden's ("good") update of the Jacobian, `J ← J + (Δε − J Δq) Δqᵀ /
//!   (Δqᵀ Δq)`, the smallest change that satisfies the secant condition,
//!   kept as its inverse by Sherman–Morrison so that no system is solved:
//!   `K ← K − (Δq + K Δε) (Δqᵀ K) / (Δqᵀ K Δε)`, with `Δq` measured in
//!   units of the box's span. On one dimension this is the secant method,
//!   `K = −Δq/Δε`; on a linear map of dimension `n`, undamped and
//!   unclamped, it reaches the root in at most `2n` steps (Gay 1979).
//!
//! An external task (issue 28) showed what one bad pair does unguarded: a
//! gain about 25 in size, queries bouncing between the box's corners, and a
//! stop after five roll-outs at a best query that was the first. So every
//! step is guarded, for errors measured on a robot:
//!
//! - **From the best roll-out** (smallest `max_i |ε_i|`, of those the
//!   smallest `Σ ε_i²`), never from a worse one, and **within a trust
//!   region**: no step is longer than `radius` times the box's span in any
//!   component. It starts at [`FIRST_RADIUS`]. A step that improved on the
//!   best grows it, when the region had held the step back: four times
//!   when the error fell by at least 3/4 of what the linear model
//!   predicted, else twice, up to the whole span. A step that did not
//!   improve shrinks it to half that step; not so the first step, made with
//!   the guessed `K = gain · I`, whose failure shows the guess wrong, not
//!   the model.
//! - **The first pair rescales the guess** as a whole to its least-squares
//!   fit `K = s · I` (Shanno and Phua's scaling), when `Δε` is nearly
//!   parallel to `Δq` ([`MIN_COSINE`]): a sign or size the guess got wrong
//!   is then wrong in no direction, not only along `Δq`.
//! - **Powell's damping**: the update scales `det J` by `1 − θ + θ γ`, with
//!   `θ = 1` Broyden's; when `|γ|` is below [`MIN_DETERMINANT`], `θ` is cut
//!   so that the ratio is `±MIN_DETERMINANT`, and one pair can no longer
//!   make `K` explode. The update is skipped when `Δε` is not finite or is
//!   below [`MIN_CHANGE`] of the error's size (rounding or noise, not
//!   slope), or `Δq = 0`; a `K` or a step `K ε` that is not finite resets
//!   `K = gain · I`.
//! - **A failed step refits `K`** (the model is inconsistent): by least
//!   squares, `K f_j ≈ −d_j` over the last [`MEMORY`] roll-outs' query and
//!   error differences from the best one, each pair scaled to unit size,
//!   pulled toward the current `K` by [`PRIOR`] so that directions no
//!   roll-out explored keep it.
//! - **The box**: every query is clamped into `[low, high]`. Where the best
//!   query sits on a limit and the step pushes out of it, that component is
//!   held, and the others take the step that solves their own equations
//!   (`s_F = (K_FF − K_FB K_BB⁻¹ K_BF) ε_F`, the free block of `J`
//!   inverted); repeated until the step pushes no other component out.
//! - A query that cannot be rolled out or measured is told as infeasible
//!   ([`Secant::tell_infeasible`]): the trust region shrinks to half the
//!   step that reached it and the next step leaves from the best query
//!   again. The first roll-out's, at the desired query, ends the search as
//!   [`Status::Infeasible`].
//!
//! **[`Status::Stalled`] means the target was shown unreachable**: the best
//! query sits on a limit, the model's step pushes out of it, and there is
//! nothing left to do inside the box (every component not held has its
//! error below the precision, or the last two roll-outs made no progress,
//! that is did not reduce the best error by the precision); then a probe is
//! rolled out half the trust radius back into the box along the held
//! components, and when it makes no progress either and the step from the
//! best query is still held, the search stops. It also stops so when the
//! trust region has shrunk until no step moves the query in `f32`, and a
//! probe along the step cannot either. A best query off the limits, or a
//! blocked step that the probe contradicts, keeps the search going; the
//! best roll-out is always the one recommended, whatever the status.
//!
//! It stops once `max_i |ε_i| < precision` or the budget is used up; the
//! first query is the desired one. Roll-outs to precision 1e-4 in a box of
//! ±4 (`core/tests/secant.rs`, `roll_out_counts`, about 10,000 maps each of
//! 1 / 2 / 3 / 4 dimensions, mean and worst): on diagonally dominant maps
//! `A` of one sign, linear 3.0 / 4.9 / 5.7 / 6.3 (at most 3 / 5 / 7 / 9),
//! mildly nonlinear 4.3 / 5.5 / 6.1 / 6.5 (at most 6 / 8 / 9 / 10); on
//! coupled maps with a sign per outcome, linear 3.0 / 5.3 / 7.3 / 8.9 (at
//! most 3 / 9 / 15 / 17), nonlinear 4.3 / 6.3 / 8.0 / 9.5 (at most 7 / 10 /
//! 17 / 24); every one converged within 30. With one component of the root
//! beyond the box, all 20,000 runs of each kind ended `Stalled` on that
//! bound, in a median of 6 (weakly coupled) or 7 (coupled) roll-outs, at
//! most 10 and 28. The state machine is ask/tell, as the
//! scalar learners' [`crate::golden::ErrorLearner`], on slices:
//!
//! ```
//! use heapless::Vec;
//! use primo_core::golden::Status;
//! use primo_core::secant::{Rule, Secant, SecantConfig};
//! let v = |s: &[f32]| Vec::from_slice(s).unwrap();
//! let cfg = SecantConfig {
//!     low: v(&[-2.0, -2.0]),
//!     high: v(&[2.0, 2.0]),
//!     desired: v(&[0.5, 0.3]),
//!     precision: 1e-4,
//!     max_rollouts: 20,
//!     gain: 1.0,
//!     rule: Rule::Broyden,
//! };
//! // A linear "cell", measured = A q + b, with A so far from I that the
//! // paper's K = I diverges (I − A has an eigenvalue −1.38); the learned
//! // gain converges.
//! let cell = |q: &[f32]| [2.5 * q[0] + 0.5 * q[1] + 0.1, -0.4 * q[0] + 0.7 * q[1] - 0.05];
//! let mut learner = Secant::<2>::new(cfg.clone())?;
//! while let Some(q) = learner.ask() {
//!     let m = cell(q);
//!     learner.tell(&[cfg.desired[0] - m[0], cfg.desired[1] - m[1]])?;
//! }
//! assert_eq!(learner.status(), Status::Converged);
//! assert!(learner.rollouts() <= 6);
//! # Ok::<(), primo_core::Error>(())
//! ```

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::error::{check_finite, check_len};
use crate::golden::{Status, check_span, check_stop_rules};
use crate::{Error, linalg};

/// A change of the error below this fraction of its size is rounding or
/// noise: no slope is learned from it.
pub const MIN_CHANGE: f32 = 1e-5;
/// Powell's safeguard on Broyden's update: it may scale the model's
/// Jacobian's determinant by no less than this in size (the update is
/// damped until it does), so that one secant pair cannot make the gain
/// explode or flip the sign it has learned.
pub const MIN_DETERMINANT: f32 = 0.1;
/// The first roll-outs' step and error change are fitted by a multiple of
/// the guessed gain unless the cosine of their angle is below this.
pub const MIN_COSINE: f32 = 0.9;
/// Roll-outs kept for the least-squares fit of the gain after a failed
/// step.
pub const MEMORY: usize = 8;
/// The fit's pull toward the gain it replaces, against pairs of unit size:
/// it keeps `K` in directions the roll-outs have not explored.
pub const PRIOR: f32 = 1e-2;
/// The trust region's first radius: steps of [`Rule::Broyden`] reach at
/// most this fraction of the box's span in each component, until a
/// roll-out improves on the best one (twice the radius, up to the whole
/// span) or does not (half the step it took).
pub const FIRST_RADIUS: f32 = 0.5;
/// Settings of the secant learner for a query of dimension `n = 1..=Q`:
/// `low`, `high` and `desired` all hold `n` values (postcard writes each
/// with its length, so the dimension travels with them).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SecantConfig<const Q: usize> {
    /// Lower limits of the query, per component.
    pub low: Vec<f32, Q>,
    /// Upper limits, each above its lower limit.
    pub high: Vec<f32, Q>,
    /// The desired query: the first one tried, within the limits.
    pub desired: Vec<f32, Q>,
    /// Stop when `max_i |ε_i| < precision` (> 0).
    pub precision: f32,
    /// Stop after this many roll-outs (≥ 1).
    pub max_rollouts: u32,
    /// The first gain, `K = gain · I` (finite, ≠ 0; the paper's `K ≈ I`
    /// is 1).
    pub gain: f32,
    /// How `K` is used.
    pub rule: Rule,
}

/// The update rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
pub enum Rule {
    /// `q ← q + K ε`, `K` corrected by Broyden's update after every
    /// roll-out (the module docs).
    Broyden,
    /// The paper's eq. 10, `q ← q + K ε` with `K` fixed.
    Fixed,
    /// The paper's eq. 11, `q ← q + e^{−εᵀε} K ε` with `K` fixed: smaller
    /// steps at large errors. (`εᵀε` is in the query's units: the weight
    /// depends on them.)
    Weighted,
}

impl<const Q: usize> SecantConfig<Q> {
    /// The query's dimension.
    pub fn dim(&self) -> usize {
        self.desired.len()
    }

    /// Checks the settings.
    pub fn validate(&self) -> Result<(), Error> {
        let n = self.dim();
        if n == 0 {
            return Err(Error::OutOfRange("the query needs at least one dimension"));
        }
        check_len("query lower limits", n, self.low.len())?;
        check_len("query upper limits", n, self.high.len())?;
        for v in [&self.low, &self.high, &self.desired] {
            check_finite(v, "search settings")?;
        }
        check_finite(&[self.precision, self.gain], "precision and gain")?;
        if self.gain == 0.0 {
            return Err(Error::OutOfRange("the gain must not be 0"));
        }
        for ((l, h), d) in self.low.iter().zip(&self.high).zip(&self.desired) {
            if !(l < h && l <= d && d <= h) {
                return Err(Error::OutOfRange(
                    "search limits must satisfy low <= desired <= high, low < high",
                ));
            }
            check_span(*l, *h)?;
        }
        check_stop_rules(self.precision, self.max_rollouts)
    }
}

/// A roll-out told: query, error and the error's size `max_i |ε_i|`.
#[derive(Debug, Clone, Copy, PartialEq)]
struct Point<const Q: usize> {
    query: [f32; Q],
    error: [f32; Q],
    size: f32,
}

impl<const Q: usize> Point<Q> {
    /// A smaller `max_i |ε_i|`, or the same and a smaller `Σ ε_i²` (when
    /// a component the box blocks holds the largest error, the others
    /// still count).
    fn better(&self, other: &Self) -> bool {
        let energy = |p: &Self| p.error.iter().map(|e| e * e).sum::<f32>();
        self.size < other.size || (self.size == other.size && energy(self) < energy(other))
    }
}

/// The best roll-out so far: smallest `max_i |ε_i|`, of those the
/// smallest `Σ ε_i²`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Best<'a> {
    /// Its query.
    pub query: &'a [f32],
    /// Its error.
    pub error: &'a [f32],
    /// `max_i |ε_i|`.
    pub size: f32,
}

/// The secant error learner (see the module docs) for queries of up to `Q`
/// dimensions.
#[derive(Debug, Clone, PartialEq)]
pub struct Secant<const Q: usize> {
    cfg: SecantConfig<Q>,
    n: usize,
    /// The query in flight.
    query: [f32; Q],
    /// The gain `K`, its leading `n × n` block.
    gain: [[f32; Q]; Q],
    best: Option<Point<Q>>,
    /// The longest step allowed, `max_i |Δq_i| / (high_i − low_i)`: for
    /// [`Rule::Broyden`] the trust region; for the paper's rules
    /// unbounded until a query is infeasible, then halved at each
    /// infeasible query and doubled at each feasible one.
    radius: f32,
    /// The roll-out the query in flight was stepped from (none for the
    /// first).
    from: Option<Point<Q>>,
    /// [`Rule::Broyden`]: the last [`MEMORY`] roll-outs, newest first.
    recent: [Option<Point<Q>>; MEMORY],
    /// [`Rule::Broyden`]: the error size the model predicts for the query
    /// in flight, if it predicts one (not for a probe, or a step the box
    /// bent).
    expected: Option<f32>,
    /// [`Rule::Broyden`]: roll-outs in a row that made no progress (did
    /// not reduce the best error by the precision).
    failures: u8,
    /// [`Rule::Broyden`]: the best query's step was blocked by the box and
    /// a probe back into it was asked; another block before any progress
    /// stalls.
    probed: bool,
    rollouts: u32,
    status: Status,
}

/// Solves `m x = r` by its normal equations (`m` is at most 4 × 4 and
/// well scaled: a block of the gain); `None` if singular.
fn solve<const Q: usize>(m: &[[f32; Q]; Q], r: &[f32; Q]) -> Option<[f32; Q]> {
    let mut a = [[0.0f32; Q]; Q];
    let mut b = [0.0f32; Q];
    let column = |row: &[f32; Q], i: usize| row.get(i).copied().unwrap_or(0.0);
    for (i, (row, bi)) in a.iter_mut().zip(&mut b).enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = m.iter().map(|mk| column(mk, i) * column(mk, j)).sum();
        }
        *bi = m.iter().zip(r).map(|(mk, rk)| column(mk, i) * rk).sum();
    }
    linalg::cholesky(&mut a, Q, "secant gain block").ok()?;
    linalg::cholesky_solve(&a, Q, &mut b);
    b.iter().all(|v| v.is_finite()).then_some(b)
}

/// The same query, bit for bit.
fn same<const Q: usize>(a: &[f32; Q], b: &[f32; Q]) -> bool {
    a.iter().zip(b).all(|(x, y)| x.to_bits() == y.to_bits())
}

/// `max_i |v_i|`.
fn size(v: &[f32]) -> f32 {
    v.iter().fold(0.0, |m, x| m.max(libm::fabsf(*x)))
}

impl<const Q: usize> Secant<Q> {
    /// A new search starting at the desired query with `K = I`.
    pub fn new(cfg: SecantConfig<Q>) -> Result<Self, Error> {
        cfg.validate()?;
        let cfg_rule = cfg.rule;
        let mut query = [0.0; Q];
        query
            .iter_mut()
            .zip(&cfg.desired)
            .for_each(|(q, d)| *q = *d);
        Ok(Self {
            gain: Self::identity(cfg.gain),
            n: cfg.dim(),
            cfg,
            query,
            best: None,
            radius: match cfg_rule {
                Rule::Broyden => FIRST_RADIUS,
                Rule::Fixed | Rule::Weighted => f32::INFINITY,
            },
            from: None,
            recent: [None; MEMORY],
            expected: None,
            failures: 0,
            probed: false,
            rollouts: 0,
            status: Status::Running,
        })
    }

    /// `gain · I`.
    fn identity(gain: f32) -> [[f32; Q]; Q] {
        core::array::from_fn(|i| core::array::from_fn(|j| if i == j { gain } else { 0.0 }))
    }

    /// The query to roll out next, or `None` once finished. Asking again
    /// before telling returns the same query.
    pub fn ask(&self) -> Option<&[f32]> {
        (self.status == Status::Running)
            .then(|| self.query.get(..self.n))
            .flatten()
    }

    /// Reports the error vector of the asked query. A wrong length, a
    /// non-finite value, or a call after the search finished is an error
    /// and changes nothing.
    pub fn tell(&mut self, error: &[f32]) -> Result<Status, Error> {
        if self.status != Status::Running {
            return Err(Error::BadState("the search has finished"));
        }
        check_len("error", self.n, error.len())?;
        check_finite(error, "error")?;
        let mut current = Point {
            query: self.query,
            error: [0.0; Q],
            size: size(error),
        };
        current
            .error
            .iter_mut()
            .zip(error)
            .for_each(|(e, v)| *e = *v);
        self.rollouts += 1;
        let improved = self.best.is_none_or(|b| current.better(&b));
        // Progress toward the precision: an error smaller by at least it.
        let progress = self
            .best
            .is_none_or(|b| b.size - current.size >= self.cfg.precision);
        let best = match self.best {
            Some(b) if !improved => b,
            _ => current,
        };
        self.best = Some(best);
        self.status = if current.size < self.cfg.precision {
            Status::Converged
        } else if self.rollouts >= self.cfg.max_rollouts {
            Status::BudgetExhausted
        } else {
            Status::Running
        };
        if self.status != Status::Running {
            return Ok(self.status);
        }
        if self.cfg.rule == Rule::Broyden {
            self.recent.rotate_right(1);
            if let Some(newest) = self.recent.first_mut() {
                *newest = Some(current);
            }
        }
        self.query = match (self.cfg.rule, self.from) {
            (Rule::Broyden, Some(from)) => {
                // A step of the guessed gain that failed shows the guess
                // wrong, not the learned model: the region keeps its size.
                let guessed = self.gain == Self::identity(self.cfg.gain);
                self.learn(&from, &current);
                let taken = self.length(&current.query);
                if current.better(&from) {
                    // A step the region held back that improved: four
                    // times the radius when the error fell by at least 3/4
                    // of what the model predicted, else twice.
                    let well = self
                        .expected
                        .is_some_and(|e| from.size - current.size >= 0.75 * (from.size - e));
                    if taken >= 0.999 * self.radius {
                        self.radius = (if well { 4.0 } else { 2.0 } * self.radius).min(1.0);
                    }
                } else if !guessed {
                    self.radius = self.radius.min(0.5 * taken);
                    self.refit(&best);
                }
                self.failures = if progress {
                    0
                } else {
                    self.failures.saturating_add(1)
                };
                if progress {
                    self.probed = false;
                }
                self.broyden_step(&best)
            }
            (Rule::Broyden, None) => self.broyden_step(&best),
            // The paper's rules step from the last roll-out, whatever it gave.
            (Rule::Fixed | Rule::Weighted, _) => {
                self.radius *= 2.0;
                let next = self.paper_step(&current);
                if same(&next, &current.query) {
                    self.status = Status::Stalled;
                }
                next
            }
        };
        Ok(self.status)
    }

    /// Reports that the asked query could not be rolled out or measured
    /// (module docs); it counts against the budget. A call after the
    /// search finished is an error and changes nothing.
    pub fn tell_infeasible(&mut self) -> Result<Status, Error> {
        if self.status != Status::Running {
            return Err(Error::BadState("the search has finished"));
        }
        self.rollouts += 1;
        let Some(best) = self.best else {
            self.status = Status::Infeasible;
            return Ok(self.status);
        };
        if self.rollouts >= self.cfg.max_rollouts {
            self.status = Status::BudgetExhausted;
            return Ok(self.status);
        }
        self.radius = self.radius.min(0.5 * self.length(&self.query));
        if self.cfg.rule == Rule::Broyden {
            // The same model from the best roll-out, at most half as far;
            // a probe that could not be made shows nothing.
            self.probed = false;
            self.query = self.broyden_step(&best);
            return Ok(self.status);
        }
        // Halfway back along the step, from where it was taken.
        let from = self.from.unwrap_or(best);
        let mut next = from.query;
        for (n, q) in next.iter_mut().zip(&self.query) {
            *n += 0.5 * (q - *n);
        }
        if same(&next, &from.query) || same(&next, &self.query) {
            self.status = Status::Stalled;
        }
        self.query = next;
        Ok(self.status)
    }

    /// The span of component `i` of the box (1 beyond the dimension).
    fn span(&self, i: usize) -> f32 {
        match (self.cfg.low.get(i), self.cfg.high.get(i)) {
            (Some(l), Some(h)) => h - l,
            _ => 1.0,
        }
    }

    /// `max_i |v_i| / span_i`: a step's length in the trust region's units.
    fn scaled(&self, v: &[f32; Q]) -> f32 {
        v.iter()
            .enumerate()
            .fold(0.0, |m, (i, x)| m.max(libm::fabsf(*x) / self.span(i)))
    }

    /// The length of the step to `query` from the roll-out it was stepped
    /// from.
    fn length(&self, query: &[f32; Q]) -> f32 {
        let Some(from) = self.from else { return 0.0 };
        let mut d = [0.0f32; Q];
        for ((d, q), o) in d.iter_mut().zip(query).zip(&from.query) {
            *d = q - o;
        }
        self.scaled(&d)
    }

    /// Broyden's update of `K` from the roll-out `current`, stepped from
    /// `from`, with Powell's damping (module docs). Every vector is zero
    /// beyond `n` and `K` the identity there, so the loops run over all
    /// `Q` values and leave that part as it is.
    fn learn(&mut self, from: &Point<Q>, current: &Point<Q>) {
        let mut dq = [0.0f32; Q];
        let mut de = [0.0f32; Q];
        let pairs = current.query.iter().zip(&from.query);
        let errors = current.error.iter().zip(&from.error);
        for ((q, e), ((q1, q0), (e1, e0))) in dq.iter_mut().zip(&mut de).zip(pairs.zip(errors)) {
            *q = q1 - q0;
            *e = e1 - e0;
        }
        // Δε scaled by max |Δε_i|, so that no product overflows.
        let scale = size(&de);
        if !scale.is_finite() || !(scale > MIN_CHANGE * current.size.max(from.size)) {
            return;
        }
        // The first pair rescales the guessed K = gain · I as a whole to its
        // least-squares fit, K Δε ≈ −Δq by a multiple of I (Shanno and
        // Phua's scaling): a sign or a size the guess got wrong is then
        // wrong in no direction, not only along Δq. Skipped when Δq and Δε
        // are nearly orthogonal (the fit says nothing).
        if self.gain == Self::identity(self.cfg.gain) {
            let e: [f32; Q] = de.map(|e| e / scale);
            let qe: f32 = dq.iter().zip(&e).map(|(q, e)| q * e).sum();
            let ee: f32 = e.iter().map(|e| e * e).sum();
            let qq: f32 = dq.iter().map(|q| q * q).sum();
            let fit = -qe / ee / scale;
            if libm::fabsf(qe) >= MIN_COSINE * libm::sqrtf(qq * ee) && fit.is_finite() && fit != 0.0
            {
                self.gain = Self::identity(fit);
            }
        }
        // In the box's units, u = D⁻¹ Δq with D = diag(span): v = K Δε /
        // scale, w = uᵀ D⁻¹ K, uu = uᵀ u, γ = uᵀ D⁻¹ K Δε / uu.
        let mut u = [0.0f32; Q];
        for (i, (ui, q)) in u.iter_mut().zip(&dq).enumerate() {
            *ui = q / self.span(i);
        }
        let uu: f32 = u.iter().map(|x| x * x).sum();
        if !(uu > 0.0) {
            return;
        }
        let mut v = [0.0f32; Q];
        let mut w = [0.0f32; Q];
        for (i, ((row, vi), ui)) in self.gain.iter().zip(&mut v).zip(&u).enumerate() {
            let weight = ui / self.span(i);
            for ((k, e), wj) in row.iter().zip(&de).zip(&mut w) {
                *vi += k * e / scale;
                *wj += weight * k;
            }
        }
        let gamma = scale * w.iter().zip(&de).map(|(w, e)| w * e / scale).sum::<f32>() / uu;
        // The update scales det J by 1 − θ + θ(−γ) (J = −K⁻¹): θ = 1 is
        // Broyden's; where that ratio is below MIN_DETERMINANT in size, θ
        // is cut so that it is ±MIN_DETERMINANT (Powell).
        let ratio = -gamma;
        let (theta, det) = if libm::fabsf(ratio) >= MIN_DETERMINANT {
            (1.0, ratio)
        } else {
            let det = if ratio < 0.0 {
                -MIN_DETERMINANT
            } else {
                MIN_DETERMINANT
            };
            ((1.0 - det) / (1.0 - ratio), det)
        };
        // K ← K + θ (Δq + K Δε) wᵀ / (uu · det), over `scale`.
        let factor = theta * scale / (uu * det);
        for ((row, vi), dqi) in self.gain.iter_mut().zip(v).zip(dq) {
            let r = dqi / scale + vi;
            for (k, wj) in row.iter_mut().zip(w) {
                *k += factor * r * wj;
            }
        }
        if !self.gain.iter().flatten().all(|k| k.is_finite()) {
            self.gain = Self::identity(self.cfg.gain);
        }
    }

    /// A failed step shows the model inconsistent: `K` refitted to the
    /// recent roll-outs around the best one, `K f_j ≈ −d_j` for `d_j` and
    /// `f_j` the query's and the error's differences from the best, by
    /// least squares with each pair scaled to `max|f_j| = 1` and a pull
    /// [`PRIOR`] toward the current `K`. Kept only if finite; needs two
    /// pairs (one is Broyden's update).
    fn refit(&mut self, best: &Point<Q>) {
        let mut g = [[0.0f32; Q]; Q];
        let mut r = [[0.0f32; Q]; Q];
        let mut pairs = 0;
        for p in self.recent.iter().flatten() {
            let mut d = [0.0f32; Q];
            let mut f = [0.0f32; Q];
            for ((d, f), ((q, q0), (e, e0))) in d.iter_mut().zip(&mut f).zip(
                p.query
                    .iter()
                    .zip(&best.query)
                    .zip(p.error.iter().zip(&best.error)),
            ) {
                *d = q - q0;
                *f = e - e0;
            }
            let scale = size(&f);
            if !scale.is_finite() || !(scale > MIN_CHANGE * p.size.max(best.size)) {
                continue;
            }
            pairs += 1;
            for ((gi, ri), (fi, di)) in g.iter_mut().zip(&mut r).zip(f.iter().zip(&d)) {
                for ((gij, rij), fj) in gi.iter_mut().zip(ri.iter_mut()).zip(&f) {
                    *gij += fi / scale * fj / scale;
                    *rij -= di / scale * fj / scale;
                }
            }
        }
        if pairs < 2 {
            return;
        }
        // K (G + λI) = R + λ K, row by row: (G + λI) k_i = r_i + λ k_i.
        for (i, gi) in g.iter_mut().enumerate() {
            if let Some(gii) = gi.get_mut(i) {
                *gii += PRIOR;
            }
        }
        let mut fitted = self.gain;
        for (row, ri) in fitted.iter_mut().zip(&r) {
            for (k, rij) in row.iter_mut().zip(ri) {
                *k = rij + PRIOR * *k;
            }
        }
        if linalg::cholesky(&mut g, Q, "secant fit").is_err() {
            return;
        }
        for row in &mut fitted {
            linalg::cholesky_solve(&g, Q, row);
        }
        if fitted.iter().flatten().all(|k| k.is_finite()) {
            self.gain = fitted;
        }
    }

    /// `K ε` at `from`, with `K` reset to the first gain if it is not
    /// finite.
    fn newton(&mut self, from: &Point<Q>) -> [f32; Q] {
        let mut step = [0.0f32; Q];
        for (s, row) in step.iter_mut().zip(&self.gain) {
            *s = row.iter().zip(&from.error).map(|(k, e)| k * e).sum::<f32>();
        }
        if !step.iter().all(|s| s.is_finite()) {
            self.gain = Self::identity(self.cfg.gain);
            step = from.error.map(|e| self.cfg.gain * e);
        }
        step
    }

    /// `from + t · step`, `t ≤ 1` so that the step stays within `radius`
    /// (scaled up to it if `exact`), clamped into the box.
    fn clip(&self, from: &[f32; Q], step: &[f32; Q], exact: bool) -> [f32; Q] {
        let ratio = self.radius / self.scaled(step);
        let t = if exact { ratio } else { ratio.min(1.0) };
        // A zero step (0/0, ∞·0) stays where it is.
        let t = if t.is_finite() { t } else { 0.0 };
        let mut next = *from;
        let limits = self.cfg.low.iter().zip(&self.cfg.high);
        for ((q, s), (low, high)) in next.iter_mut().zip(step).zip(limits) {
            // max/min rather than clamp: they never panic, and an
            // overflow to ±∞ lands on a limit.
            *q = (*q + t * s).max(*low).min(*high);
        }
        next
    }

    /// The Newton step `K ε` at `from`; the components the box blocks,
    /// with the sign of the step that pushed each out of it where `from`
    /// sits on a limit (grown until the step with them held pushes no other
    /// out); and that step ([`Self::within`]).
    fn held(&mut self, from: &Point<Q>) -> ([f32; Q], [f32; Q], [f32; Q]) {
        let newton = self.newton(from);
        let mut outward = [0.0f32; Q];
        let mut step = newton;
        for _ in 0..Q {
            let mut grew = false;
            let limits = self.cfg.low.iter().zip(&self.cfg.high);
            for ((o, (q, s)), (low, high)) in outward
                .iter_mut()
                .zip(from.query.iter().zip(&step))
                .zip(limits)
            {
                if *o == 0.0 && ((*q >= *high && *s > 0.0) || (*q <= *low && *s < 0.0)) {
                    *o = libm::copysignf(1.0, *s);
                    grew = true;
                }
            }
            if !grew {
                break;
            }
            step = self.within(&newton, &outward.map(|o| o != 0.0), &from.error);
        }
        (newton, outward, step)
    }

    /// The model's step from `from` within the trust region and the box,
    /// with the error it predicts; `None` if it leaves the query where it
    /// is.
    fn model_step(&mut self, from: &Point<Q>) -> Option<[f32; Q]> {
        let (newton, outward, step) = self.held(from);
        let blocked = outward.map(|o| o != 0.0);
        // Blocked, and nothing left to do inside the box: only blocked
        // components' errors above the precision, or the last two
        // roll-outs made no progress.
        let precision = self.cfg.precision;
        let errors = blocked.iter().zip(&from.error);
        let solved = errors
            .filter(|(b, _)| !**b)
            .all(|(_, e)| libm::fabsf(*e) < precision);
        if blocked.iter().any(|b| *b) && (solved || self.failures >= 2) {
            return None;
        }
        let next = self.clip(&from.query, &step, false);
        if same(&next, &from.query) {
            return None;
        }
        // Linear, a step of the fraction t of K ε leaves (1 − t) ε.
        let mut taken = [0.0f32; Q];
        for ((d, n), b) in taken.iter_mut().zip(&next).zip(&from.query) {
            *d = n - b;
        }
        let t = self.scaled(&taken) / self.scaled(&newton);
        // Held components, or the box's clamp (beyond rounding), bent it.
        let bent = blocked.iter().any(|b| *b)
            || taken
                .iter()
                .zip(&newton)
                .any(|(d, s)| libm::fabsf(d - t * s) > 1e-3 * libm::fabsf(*s));
        self.expected = (!bent && t <= 1.0).then_some((1.0 - t) * from.size);
        Some(next)
    }

    /// [`Rule::Broyden`]'s next query, from the best roll-out (module
    /// docs), or the best query with the status set to `Stalled`.
    fn broyden_step(&mut self, best: &Point<Q>) -> [f32; Q] {
        self.from = Some(*best);
        if let Some(next) = self.model_step(best) {
            return next;
        }
        self.expected = None;
        if self.probed {
            self.status = Status::Stalled;
            return best.query;
        }
        // Blocked: a probe half the trust radius back into the box along
        // the blocked components, whose error tests the gain that pushed
        // outward. Too short to move in f32: a probe the radius along the
        // step.
        self.probed = true;
        let (newton, outward, _) = self.held(best);
        let any_blocked = outward.iter().any(|o| *o != 0.0);
        let mut probe = newton;
        if any_blocked {
            for (i, (p, o)) in probe.iter_mut().zip(outward).enumerate() {
                *p = -0.5 * self.radius * self.span(i) * o;
            }
        }
        let next = self.clip(&best.query, &probe, !any_blocked);
        if same(&next, &best.query) || !next.iter().all(|q| q.is_finite()) {
            self.status = Status::Stalled;
            return best.query;
        }
        next
    }

    /// The step with the blocked components held: those of the Newton step
    /// `s = K ε` that solve the free components' equations alone, `s_F =
    /// (K_FF − K_FB K_BB⁻¹ K_BF) ε_F` (the free block of `J = −K⁻¹`,
    /// inverted), `s_B = 0`; if `K_BB` is singular, `s` with `s_B = 0`.
    fn within(&self, newton: &[f32; Q], blocked: &[bool; Q], error: &[f32; Q]) -> [f32; Q] {
        let mut step = *newton;
        if !blocked.iter().any(|b| *b) {
            return step;
        }
        // K_BB (the identity elsewhere) and K_BF ε_F.
        let mut kbb = [[0.0f32; Q]; Q];
        let mut rhs = [0.0f32; Q];
        let mut free_part = [0.0f32; Q];
        for (i, ((row, out), (bi, (r, fp)))) in kbb
            .iter_mut()
            .zip(&self.gain)
            .zip(blocked.iter().zip(rhs.iter_mut().zip(&mut free_part)))
            .enumerate()
        {
            for (j, ((m, k), (bj, e))) in row
                .iter_mut()
                .zip(out)
                .zip(blocked.iter().zip(error))
                .enumerate()
            {
                *m = match (*bi, *bj) {
                    (true, true) => *k,
                    _ if i == j => 1.0,
                    _ => 0.0,
                };
                if !*bj {
                    *fp += k * e;
                }
            }
            if *bi {
                *r = *fp;
            }
        }
        let held = solve(&kbb, &rhs);
        for (i, (s, (b, fp))) in step
            .iter_mut()
            .zip(blocked.iter().zip(&free_part))
            .enumerate()
        {
            *s = if *b {
                0.0
            } else if let Some(x) = held {
                let coupling: f32 = self
                    .gain
                    .get(i)
                    .map(|row| {
                        row.iter()
                            .zip(blocked.iter().zip(&x))
                            .filter(|(_, (bj, _))| **bj)
                            .map(|(k, (_, xj))| k * xj)
                            .sum()
                    })
                    .unwrap_or(0.0);
                fp - coupling
            } else {
                *s
            };
        }
        step
    }

    /// The paper's rules: `from.query + w · K ε` (`w = e^{−εᵀε}` for
    /// [`Rule::Weighted`], else 1) within the reach left by infeasible
    /// queries, clamped into the box.
    fn paper_step(&mut self, from: &Point<Q>) -> [f32; Q] {
        let weight = match self.cfg.rule {
            Rule::Weighted => libm::expf(-from.error.iter().map(|e| e * e).sum::<f32>()),
            _ => 1.0,
        };
        let step = self.newton(from).map(|s| weight * s);
        self.from = Some(*from);
        self.clip(&from.query, &step, false)
    }

    /// Current status.
    pub fn status(&self) -> Status {
        self.status
    }

    /// Roll-outs told so far.
    pub fn rollouts(&self) -> u32 {
        self.rollouts
    }

    /// The query's dimension.
    pub fn dim(&self) -> usize {
        self.n
    }

    /// The best roll-out so far.
    pub fn best(&self) -> Option<Best<'_>> {
        let b = self.best.as_ref()?;
        Some(Best {
            query: b.query.get(..self.n)?,
            error: b.error.get(..self.n)?,
            size: b.size,
        })
    }

    /// The learned gain `K`, row by row (the leading `n` values of each of
    /// the first `n` rows).
    pub fn gain(&self) -> impl Iterator<Item = &[f32]> {
        self.gain
            .iter()
            .take(self.n)
            .map(|row| row.get(..self.n).unwrap_or(&[]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cfg(low: &[f32], high: &[f32], desired: &[f32]) -> SecantConfig<4> {
        SecantConfig {
            low: Vec::from_slice(low).unwrap(),
            high: Vec::from_slice(high).unwrap(),
            desired: Vec::from_slice(desired).unwrap(),
            precision: 1e-4,
            max_rollouts: 30,
            gain: 1.0,
            rule: Rule::Broyden,
        }
    }

    /// Runs `error` to the end; returns the learner and the queries asked.
    fn run(
        mut l: Secant<4>,
        error: impl Fn(&[f32]) -> std::vec::Vec<f32>,
    ) -> (Secant<4>, std::vec::Vec<std::vec::Vec<f32>>) {
        let mut asked = std::vec::Vec::new();
        while let Some(q) = l.ask() {
            asked.push(q.to_vec());
            let e = error(q);
            l.tell(&e).unwrap();
        }
        (l, asked)
    }

    #[test]
    fn the_papers_fixed_gain_rules_converge_only_where_k_suits_the_map() {
        let fixed = |rule, gain| SecantConfig {
            rule,
            gain,
            ..cfg(&[-2.0], &[2.0], &[0.2])
        };
        // measured = a q: ε = 0.5 − a q. K = 1 converges for 0 < a < 2
        // (|1 − a K| < 1), geometrically; a = 0.5 halves the error per step.
        let cell = |a: f32| move |q: &[f32]| std::vec![0.5 - a * q[0]];
        let (l, asked) = run(Secant::new(fixed(Rule::Fixed, 1.0)).unwrap(), cell(0.5));
        assert_eq!(l.status(), Status::Converged);
        assert!((10..=16).contains(&asked.len()), "{}", asked.len());
        // The same map with K = 2 = 1/a: one step.
        let (_, asked) = run(Secant::new(fixed(Rule::Fixed, 2.0)).unwrap(), cell(0.5));
        assert_eq!(asked.len(), 2);
        // a = 3: K = 1 oscillates, growing, until the box holds it.
        let (l, _) = run(Secant::new(fixed(Rule::Fixed, 1.0)).unwrap(), cell(3.0));
        assert_ne!(l.status(), Status::Converged);
        let (l, asked) = run(Secant::new(fixed(Rule::Broyden, 1.0)).unwrap(), cell(3.0));
        assert_eq!(l.status(), Status::Converged, "{asked:?}");
        // Eq. 11 steps by e^{−εᵀε} K ε: at ε = 0.4 (from q = 0.2, a = 0.5)
        // the first step is e^{−0.16}·0.4.
        let l = Secant::new(fixed(Rule::Weighted, 1.0)).unwrap();
        let (_, asked) = run(l, cell(0.5));
        let step = asked[1][0] - asked[0][0];
        assert!((step - 0.4 * (-0.16f32).exp()).abs() < 1e-6, "{step}");
    }

    #[test]
    fn one_dimension_is_the_secant_method_and_learns_the_sign() {
        let root = 0.7f32;
        // ε = −0.5 (q − q*): K = I already moves the right way, K → 2.
        // ε = +0.5 (q − q*) (desired − measured with a decreasing measured
        // outcome, as in pouring): K = I moves away, K must become −2.
        for (slope, gain) in [(-0.5f32, 2.0f32), (0.5, -2.0)] {
            let l = Secant::new(cfg(&[-2.0], &[2.0], &[0.2])).unwrap();
            let (l, asked) = run(l, |q| std::vec![slope * (q[0] - root)]);
            assert_eq!(l.status(), Status::Converged, "slope {slope}: {asked:?}");
            assert!(asked.len() <= 4, "slope {slope}: {asked:?}");
            assert!((l.best().unwrap().query[0] - root).abs() < 1e-3);
            let k = l.gain().next().unwrap()[0];
            assert!((k - gain).abs() < 1e-3, "slope {slope}: K = {k}");
        }
    }

    #[test]
    fn queries_stay_in_the_box_and_a_target_outside_stalls() {
        // The root is at q = 5, beyond the upper limit 1.
        let l = Secant::new(cfg(&[0.0, 0.0], &[1.0, 1.0], &[0.5, 0.5])).unwrap();
        let (l, asked) = run(l, |q| std::vec![5.0 - q[0], 0.5 - q[1]]);
        assert!(asked.iter().flatten().all(|v| (0.0..=1.0).contains(v)));
        assert_eq!(l.status(), Status::Stalled, "{asked:?}");
        assert_eq!(l.best().unwrap().query, &[1.0, 0.5]);
    }

    #[test]
    fn bad_errors_are_refused_and_change_nothing() {
        let mut l = Secant::new(cfg(&[0.0, 0.0], &[1.0, 1.0], &[0.5, 0.5])).unwrap();
        l.tell(&[0.1, -0.1]).unwrap();
        let before = l.clone();
        for bad in [
            &[f32::NAN, 0.0][..],
            &[0.0, f32::INFINITY],
            &[0.1],
            &[0.1, 0.1, 0.1],
        ] {
            assert!(l.tell(bad).is_err(), "{bad:?}");
            assert_eq!(l, before);
        }
        l.tell(&[0.0, 0.0]).unwrap();
        assert_eq!(l.status(), Status::Converged);
        let done = l.clone();
        assert!(l.tell(&[0.0, 0.0]).is_err());
        assert_eq!(l, done);
    }

    #[test]
    fn invalid_settings_are_refused() {
        let ok = cfg(&[0.0], &[1.0], &[0.0]);
        assert!(
            Secant::new(ok.clone()).is_ok(),
            "desired on a limit is inside"
        );
        let bad = [
            cfg(&[], &[], &[]),
            cfg(&[0.0], &[1.0, 2.0], &[0.5]),
            cfg(&[1.0], &[0.0], &[0.5]),
            cfg(&[0.0], &[1.0], &[1.5]),
            cfg(&[0.0], &[f32::NAN], &[0.5]),
            cfg(&[-3e38], &[3e38], &[0.0]),
            SecantConfig {
                precision: 0.0,
                ..ok.clone()
            },
            SecantConfig {
                gain: 0.0,
                ..ok.clone()
            },
            SecantConfig {
                gain: f32::INFINITY,
                ..ok.clone()
            },
            SecantConfig {
                max_rollouts: 0,
                ..ok
            },
        ];
        for c in bad {
            assert!(Secant::new(c.clone()).is_err(), "{c:?}");
        }
    }

    #[test]
    fn a_huge_error_resets_the_gain_instead_of_overflowing() {
        let mut l = Secant::new(cfg(&[-1.0, -1.0], &[1.0, 1.0], &[0.0, 0.0])).unwrap();
        for e in [[3e38f32, -3e38], [-3e38, 3e38], [1e-30, 0.0], [3e38, 3e38]] {
            if l.ask().is_none() {
                break;
            }
            l.tell(&e).unwrap();
            assert!(l.gain().flatten().all(|k| k.is_finite()));
            assert!(l.ask().is_none_or(|q| q.iter().all(|v| v.abs() <= 1.0)));
        }
    }

    /// Issue 28: errors told on an external task. One Broyden update made
    /// the gain about 25 in size; the queries bounced between the box's
    /// corners and the learner stopped as `Stalled` after five roll-outs,
    /// the target inside the box as far as anything told shows.
    #[test]
    fn a_wild_gain_update_neither_bounces_between_corners_nor_stalls() {
        let mut c = cfg(&[-0.5, -0.5], &[0.5, 0.5], &[0.2279, -0.3578]);
        c.precision = 0.002;
        let mut l = Secant::new(c).unwrap();
        let told = [
            [0.3931f32, -0.0501],
            [0.3639, -0.264],
            [0.3199, -0.613],
            [0.3725, -0.5377],
            [0.3199, -0.613],
        ];
        let mut asked: std::vec::Vec<std::vec::Vec<f32>> = std::vec::Vec::new();
        for e in told {
            asked.push(l.ask().unwrap().to_vec());
            assert_eq!(l.tell(&e).unwrap(), Status::Running, "{asked:?}");
        }
        let best = l.best().unwrap();
        assert_eq!(best.size, 0.3639);
        // Every roll-out after the second was worse than the best: each
        // step from the best is at most half as long as the one before.
        let next = l.ask().unwrap().to_vec();
        asked.push(next);
        let from_best = |q: &[f32]| size(&[q[0] - best.query[0], q[1] - best.query[1]]);
        let lengths: std::vec::Vec<f32> = asked[2..].iter().map(|q| from_best(q)).collect();
        for w in lengths.windows(2) {
            assert!(w[1] <= 0.5 * w[0] * (1.0 + 1e-6), "{asked:?}");
        }
        // No query is asked twice (they went to (−0.5, 0.5) twice).
        for (i, q) in asked.iter().enumerate() {
            assert!(!asked[..i].contains(q), "{asked:?}");
        }
    }
}
