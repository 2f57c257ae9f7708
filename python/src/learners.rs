//! The core's ask/tell learners: golden section and Illinois (a scalar
//! query), secant (a query of 1 to 4 values), PoWER. Each keeps its
//! settings and what it was told, so it pickles as those and is rebuilt
//! by replaying them: the core's learners are deterministic, so the copy
//! is the original, bit for bit.

use heapless::Vec as HVec;
use pyo3::IntoPyObjectExt;
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use primo_core::golden::{ErrorLearner, SearchConfig, Status};
use primo_core::power::{Block, PowerConfig};
use primo_core::secant::{Rule, SecantConfig};
use primo_learn::algorithm::Algorithm;
use primo_learn::learner::{MAX_EXTENDED, QUERY_DECAY, power_blocks};
use primo_skill::MAX_QUERY;

use crate::arrays::{Array, out, out2, vector};
use crate::cell::Cell;
use crate::errors::{core, invalid, learn};
use crate::generalize::Generalizer;

/// Largest importance sampler a Python PoWER learner holds.
const MAX_SAMPLER: usize = 10;

/// A status as Python names it.
fn status(s: Status) -> &'static str {
    match s {
        Status::Running => "running",
        Status::Converged => "converged",
        Status::BudgetExhausted => "budget_exhausted",
        Status::BracketCollapsed => "bracket_collapsed",
        Status::Stalled => "stalled",
        Status::Infeasible => "infeasible",
    }
}

/// A finite f32 from a Python float (`what` names it).
fn scalar(what: &str, v: f64) -> PyResult<f32> {
    let x = v as f32;
    if x.is_finite() {
        Ok(x)
    } else {
        Err(invalid(format!("{what}: {v} is not a finite f32 number")))
    }
}

/// `(callable, args, state)` for `__reduce__`.
fn reduce<'py, A, S>(slf: &Bound<'py, PyAny>, args: A, state: S) -> PyResult<Bound<'py, PyTuple>>
where
    A: IntoPyObject<'py>,
    S: IntoPyObject<'py>,
{
    let py = slf.py();
    let args = args.into_bound_py_any(py)?;
    let state = state.into_bound_py_any(py)?;
    PyTuple::new(py, [slf.get_type().into_any(), args, state])
}

/// Golden section and Illinois: the same settings and interface.
macro_rules! scalar_learner {
    ($name:ident, $core:ty, $summary:literal, $example:literal) => {
        #[doc = concat!($summary, "
Args:
    low: the smallest query the search may ask.
    high: the largest query the search may ask (> low).
    desired: the first query, strictly between ``low`` and ``high``.
    precision: the search has converged when |error| < precision.
    max_rollouts: the budget of roll-outs (>= 1).

Raises:
    ValueError: a non-finite setting, not ``low < desired < high``, a
        precision or budget that is not positive.

", $example)]
        #[pyclass(module = "primo._primo")]
        pub struct $name {
            learner: $core,
            cfg: SearchConfig,
            /// What it was told, in order (None: an infeasible query).
            told: Vec<Option<f64>>,
        }

        #[pymethods]
        impl $name {
            #[new]
            #[pyo3(signature = (low, high, desired, precision=0.002, max_rollouts=30))]
            fn new(
                low: f64,
                high: f64,
                desired: f64,
                precision: f64,
                max_rollouts: u32,
            ) -> PyResult<Self> {
                let cfg = SearchConfig {
                    low: scalar("low", low)?,
                    high: scalar("high", high)?,
                    desired: scalar("desired", desired)?,
                    precision: scalar("precision", precision)?,
                    max_rollouts,
                };
                Ok(Self {
                    learner: <$core>::new(cfg).map_err(core)?,
                    cfg,
                    told: Vec::new(),
                })
            }

            /// The query to roll out next, or None once the search has finished.
            ///
            /// Returns:
            ///     float or None: the query, within ``[low, high]``; asking again
            ///     before telling gives the same query.
            ///
            /// >>> import primo
            /// >>> primo.GoldenSection(0.0, 2.0, desired=0.5).ask()
            /// 0.5
            fn ask(&self) -> Option<f64> {
                self.learner.ask().map(f64::from)
            }

            /// Tells the error of the asked query and moves the search on.
            ///
            /// Args:
            ///     error: the asked query's error, finite; > 0 means the query must
            ///         grow, < 0 that it must shrink.
            ///
            /// Returns:
            ///     str: the status after it (``"running"``, ``"converged"``,
            ///     ``"budget_exhausted"``, ``"bracket_collapsed"``, ``"infeasible"``).
            ///
            /// Raises:
            ///     ValueError: a non-finite error, or told after the search finished.
            ///
            /// >>> import primo
            /// >>> learner = primo.GoldenSection(0.0, 2.0, desired=0.5)
            /// >>> learner.tell(0.3 - learner.ask())
            /// 'running'
            fn tell(&mut self, error: f64) -> PyResult<&'static str> {
                let s = self.learner.tell(scalar("error", error)?).map_err(core)?;
                self.told.push(Some(error));
                Ok(status(s))
            }

            /// Tells that the asked query could not be rolled out or measured (it was
            /// rejected, or the trial failed): it bounds the search on its side, and
            /// counts against the budget. At the first query, ``desired``, the search
            /// ends as ``"infeasible"``.
            ///
            /// Returns:
            ///     str: the status after it.
            ///
            /// Raises:
            ///     ValueError: told after the search finished.
            ///
            /// >>> import primo
            /// >>> learner = primo.GoldenSection(0.0, 2.0, desired=0.5)
            /// >>> _ = learner.ask()
            /// >>> learner.tell_infeasible()
            /// 'infeasible'
            fn tell_infeasible(&mut self) -> PyResult<&'static str> {
                let s = self.learner.tell_infeasible().map_err(core)?;
                self.told.push(None);
                Ok(status(s))
            }

            /// The search's status: ``"running"``, ``"converged"`` (|error| <
            /// ``precision``), ``"budget_exhausted"`` (``max_rollouts`` told),
            /// ``"bracket_collapsed"`` (the bracket narrower than the query's float32
            /// resolution) or ``"infeasible"``.
            #[getter]
            fn status(&self) -> &'static str {
                status(self.learner.status())
            }

            /// True once the search has finished (``status`` is not ``"running"``).
            #[getter]
            fn done(&self) -> bool {
                self.learner.status() != Status::Running
            }

            /// The roll-outs told so far, feasible or not.
            #[getter]
            fn rollouts(&self) -> u32 {
                self.learner.rollouts()
            }

            /// ``(query, error)`` of the smallest |error| so far, or None before the
            /// first error.
            #[getter]
            fn best(&self) -> Option<(f64, f64)> {
                self.learner
                    .best()
                    .map(|b| (f64::from(b.query), f64::from(b.error)))
            }

            /// ``(low, high)``: the interval that still holds the answer.
            #[getter]
            fn bracket(&self) -> (f64, f64) {
                let (l, h) = self.learner.bracket();
                (f64::from(l), f64::from(h))
            }

            fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
                let this = slf.borrow();
                let c = this.cfg;
                let args = (c.low, c.high, c.desired, c.precision, c.max_rollouts);
                reduce(slf.as_any(), args, this.told.clone())
            }

            fn __setstate__(&mut self, told: Vec<Option<f64>>) -> PyResult<()> {
                for e in told {
                    match e {
                        Some(e) => self.tell(e)?,
                        None => self.tell_infeasible()?,
                    };
                }
                Ok(())
            }
        }
    };
}

scalar_learner!(
    GoldenSection,
    primo_core::golden::GoldenSection,
    "The paper's error learning: golden-section search on a scalar query
within ``[low, high]``, from ``desired``, until |error| < ``precision``.
``tell(error)`` takes the error of the asked query (> 0: the query must
grow); only its sign is used.
",
    ">>> import primo
>>> learner = primo.GoldenSection(0.0, 2.0, desired=0.5, precision=1e-3)
>>> while (q := learner.ask()) is not None:
...     _ = learner.tell(0.5 - q * q)
>>> learner.status, round(learner.best[0], 3)
('converged', 0.707)"
);
scalar_learner!(
    Illinois,
    primo_core::illinois::Illinois,
    "Bracketed error learning that also uses the error's magnitude (secant
steps, then Illinois regula falsi); golden section's settings and interface.
",
    ">>> import primo
>>> learner = primo.Illinois(0.0, 2.0, desired=0.5, precision=1e-3)
>>> while (q := learner.ask()) is not None:
...     _ = learner.tell(0.5 - q * q)
>>> learner.status, learner.rollouts <= 6
('converged', True)"
);

/// The paper's eq. 10, ``q ← q + K ε``, on a query of 1 to 4 values in the
/// box ``[low, high]``; the gain ``K`` starts at ``gain · I`` and is learned by
/// Broyden updates (``rule="broyden"``), or stays fixed (``"fixed"``: eq. 10;
/// ``"weighted"``: eq. 11, steps weighted by ``exp(−εᵀε)``). ``tell`` takes
/// ``ε = desired − measured``.
///
/// Args:
///     low: the smallest query the search may ask, 1 to 4 values.
///     high: the largest query, as many values, each > low's.
///     desired: the first query, within the box.
///     precision: the search has converged when every |error_i| < precision.
///     max_rollouts: the budget of roll-outs (>= 1).
///     gain: the initial gain's diagonal, ``K = gain · I`` (non-zero).
///     rule: ``"broyden"``, ``"fixed"`` or ``"weighted"``.
///
/// Raises:
///     ValueError: vectors of different lengths or more than 4 values, a
///         non-finite setting, an empty box, ``desired`` outside it, an
///         unknown rule.
///
/// >>> import numpy as np, primo
/// >>> a = np.array([[2.5, 0.5], [-0.4, 0.7]])
/// >>> learner = primo.Secant([-2, -2], [2, 2], desired=[0.5, 0.3], precision=1e-4)
/// >>> while (q := learner.ask()) is not None:
/// ...     _ = learner.tell(np.array([0.5, 0.3]) - a @ q)
/// >>> learner.status, learner.rollouts <= 6
/// ('converged', True)
#[pyclass(module = "primo._primo")]
pub struct Secant {
    learner: primo_core::secant::Secant<MAX_QUERY>,
    args: (Vec<f32>, Vec<f32>, Vec<f32>, f32, u32, f32, String),
    /// What it was told, in order (None: an infeasible query).
    told: Vec<Option<Vec<f32>>>,
}

/// A secant update rule by name.
fn rule(name: &str) -> PyResult<Rule> {
    match name {
        "broyden" => Ok(Rule::Broyden),
        "fixed" => Ok(Rule::Fixed),
        "weighted" => Ok(Rule::Weighted),
        other => Err(invalid(format!(
            "rule: `{other}`, expected \"broyden\", \"fixed\" or \"weighted\""
        ))),
    }
}

/// A query-sized vector (`what` names it).
fn query_vector(what: &str, a: &Array<'_>) -> PyResult<HVec<f32, MAX_QUERY>> {
    let v = vector(what, a, true)?;
    HVec::from_slice(&v).map_err(|_| {
        invalid(format!(
            "{what}: {} values, a query has 1 to {MAX_QUERY}",
            v.len()
        ))
    })
}

#[pymethods]
impl Secant {
    #[new]
    #[pyo3(signature = (low, high, desired, precision=0.002, max_rollouts=30, gain=1.0, rule="broyden"))]
    #[allow(clippy::too_many_arguments)]
    fn new(
        low: Array<'_>,
        high: Array<'_>,
        desired: Array<'_>,
        precision: f64,
        max_rollouts: u32,
        gain: f64,
        rule: &str,
    ) -> PyResult<Secant> {
        let cfg = SecantConfig {
            low: query_vector("low", &low)?,
            high: query_vector("high", &high)?,
            desired: query_vector("desired", &desired)?,
            precision: scalar("precision", precision)?,
            max_rollouts,
            gain: scalar("gain", gain)?,
            rule: self::rule(rule)?,
        };
        let args = (
            cfg.low.to_vec(),
            cfg.high.to_vec(),
            cfg.desired.to_vec(),
            cfg.precision,
            max_rollouts,
            cfg.gain,
            rule.to_string(),
        );
        Ok(Secant {
            learner: primo_core::secant::Secant::new(cfg).map_err(core)?,
            args,
            told: Vec::new(),
        })
    }

    /// The query to roll out next, or None once the search has finished.
    ///
    /// Returns:
    ///     numpy.ndarray or None: the query, ``dim`` values within
    ///     ``[low, high]``; asking again before telling gives the same query.
    ///
    /// >>> import primo
    /// >>> primo.Secant([-1, -1], [1, 1], desired=[0.5, 0.0]).ask()
    /// array([0.5, 0. ])
    fn ask<'py>(&self, py: Python<'py>) -> Option<Bound<'py, PyAny>> {
        self.learner.ask().map(|q| out(py, q).into_any())
    }

    /// Tells the error vector of the asked query and moves the search on.
    ///
    /// Args:
    ///     error: ``desired - measured`` of the asked query, ``dim`` finite
    ///         values.
    ///
    /// Returns:
    ///     str: the status after it (``"running"``, ``"converged"``,
    ///     ``"budget_exhausted"``, ``"stalled"``, ``"infeasible"``).
    ///
    /// Raises:
    ///     ValueError: a wrong length, a non-finite value, or told after the
    ///         search finished.
    ///
    /// >>> import primo
    /// >>> learner = primo.Secant([-1], [1], desired=[0.5], precision=1e-3)
    /// >>> learner.tell([0.5 - 0.5 * float(learner.ask()[0])])
    /// 'running'
    fn tell(&mut self, error: Array<'_>) -> PyResult<&'static str> {
        let e = vector("error", &error, true)?;
        if e.len() != self.learner.dim() {
            return Err(invalid(format!(
                "error: {} values, the query has {}",
                e.len(),
                self.learner.dim()
            )));
        }
        let s = self.learner.tell(&e).map_err(core)?;
        self.told.push(Some(e));
        Ok(status(s))
    }

    /// Tells that the asked query could not be rolled out or measured (it was
    /// rejected, or the trial failed): with ``"broyden"`` the trust region
    /// shrinks to half the step that reached it and the next step leaves from
    /// the best query; with the fixed gains the next query lies halfway back
    /// toward the one it stepped from, and the step's reach is halved until a
    /// query is feasible again. It counts against the budget; at the first
    /// query, ``desired``, the search ends as ``"infeasible"``.
    ///
    /// Returns:
    ///     str: the status after it.
    ///
    /// Raises:
    ///     ValueError: told after the search finished.
    ///
    /// >>> import primo
    /// >>> learner = primo.Secant([-1], [1], desired=[0.5])
    /// >>> _ = learner.ask()
    /// >>> learner.tell_infeasible()
    /// 'infeasible'
    fn tell_infeasible(&mut self) -> PyResult<&'static str> {
        let s = self.learner.tell_infeasible().map_err(core)?;
        self.told.push(None);
        Ok(status(s))
    }

    /// The search's status: ``"running"``, ``"converged"`` (every |error| <
    /// ``precision``), ``"budget_exhausted"``, ``"stalled"`` (the best query is
    /// on a bound and the error pushes out of the box: shown unreachable) or
    /// ``"infeasible"``.
    #[getter]
    fn status(&self) -> &'static str {
        status(self.learner.status())
    }

    /// True once the search has finished (``status`` is not ``"running"``).
    #[getter]
    fn done(&self) -> bool {
        self.learner.status() != Status::Running
    }

    /// The roll-outs told so far, feasible or not.
    #[getter]
    fn rollouts(&self) -> u32 {
        self.learner.rollouts()
    }

    /// The number of values in a query (1 to 4).
    #[getter]
    fn dim(&self) -> usize {
        self.learner.dim()
    }

    /// ``(query, error)`` of the smallest max |error_i| so far (ties broken by
    /// the sum of squares), or None before the first error.
    #[getter]
    fn best<'py>(&self, py: Python<'py>) -> Option<(Bound<'py, PyAny>, Bound<'py, PyAny>)> {
        self.learner
            .best()
            .map(|b| (out(py, b.query).into_any(), out(py, b.error).into_any()))
    }

    /// The present gain ``K`` (dim × dim): ``q ← q + K ε``.
    #[getter]
    fn gain<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let rows: Vec<f32> = self.learner.gain().flatten().copied().collect();
        Ok(out2(py, &rows, self.learner.dim())?.into_any())
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.borrow();
        reduce(slf.as_any(), this.args.clone(), this.told.clone())
    }

    fn __setstate__(&mut self, told: Vec<Option<Vec<f64>>>) -> PyResult<()> {
        for e in told {
            match e {
                Some(e) => {
                    let e: Vec<f32> = e.iter().map(|v| *v as f32).collect();
                    self.learner.tell(&e).map_err(core)?;
                    self.told.push(Some(e));
                }
                None => {
                    self.tell_infeasible()?;
                }
            }
        }
        Ok(())
    }
}

/// primo's importance sampler for a query gain: power-el's with one,
/// PoWER's (the paper's) without.
fn default_sampler(query_gain: f32) -> usize {
    match query_gain != 0.0 {
        true => Algorithm::PowerEl.default_sampler(),
        false => Algorithm::Power.default_sampler(),
    }
}

/// The core's PoWER at the host's capacity: a DMP's parameters and the
/// query.
type CorePower = primo_core::power::Power<MAX_EXTENDED, MAX_SAMPLER>;

/// PoWER's constructor arguments: initial, blocks `(len, variance,
/// decay)`, roll-outs per update, roll out the mean, sampler, seed, query
/// gain, query length.
type PowerArgs = (
    Vec<f32>,
    Vec<(usize, f32, f32)>,
    u16,
    bool,
    usize,
    u64,
    f32,
    usize,
);

/// What PoWER was told: each roll-out's reward and error, and whether a
/// roll-out was asked after them.
type PowerTold = (Vec<(f32, Vec<f32>)>, bool);

/// PoWER (Kober & Peters) as in the paper, with ``ask()`` and ``tell()``.
///
/// Exploration is Gaussian per contiguous block of parameters, each
/// ``(len, variance, decay)`` (the variance multiplied by ``decay`` at every
/// update); ``rollouts_per_update`` explorations make an update, the mean
/// rolled out once per update when ``roll_out_mean``; an importance sampler
/// keeps the best ``sampler`` roll-outs. Deterministic per ``seed``; it
/// pickles with what it was told. At most 2066 parameters (a 16-DoF,
/// 128-kernel DMP and its query).
///
/// The query: ``query`` = n says the first n parameters are a query (whole
/// blocks: n ends where a block ends), as in primo's extended vector
/// ``[q̂, Δθ]``. With ``query_gain`` K ≠ 0 it is learned from the error as
/// well: ``tell(reward, error)`` with n error values keeps each roll-out's
/// query as ``q + K·error`` (the paper's eq. 10 inside PoWER).
/// ``Power.defaults`` builds primo's exploration for a skill.
///
/// Args:
///     initial: the initial parameters (the mean), finite.
///     blocks: ``(len, variance, decay)`` per block, covering ``initial``
///         in order; variance >= 0, decay in (0, 1].
///     rollouts_per_update: explorations per update (>= 1).
///     roll_out_mean: roll out the mean once per update as well.
///     sampler: roll-outs the importance sampler keeps (1 to 10; default
///         the paper's 3, and 2 with a query gain, as ``primo pour
///         --method power-el``).
///     seed: the exploration's random seed (an integer in 0..2**64).
///     query_gain: K, the gain of the error on the query (0: the query is
///         explored like the rest).
///     query: the query's length n (0: none).
///
/// Raises:
///     ValueError: blocks that do not cover ``initial``, a ``query`` that
///         does not end on a block, a query gain without a query, a setting
///         out of range, too many parameters.
///
/// >>> import numpy as np, primo
/// >>> power = primo.Power([1.0, -1.0], blocks=[(2, 0.04, 1.0)], seed=42)
/// >>> for _ in range(200):
/// ...     theta = power.ask()
/// ...     _ = power.tell(1.0 / (1.0 + float(theta @ theta)))
/// >>> power.updates, bool(np.abs(power.mean).max() < 0.3)
/// (50, True)
/// >>> learned = primo.Power([0.5, 1.0, -1.0], blocks=[(1, 0.01, 0.9), (2, 0.04, 1.0)],
/// ...                       query=1, query_gain=1.0)
/// >>> theta = learned.ask()
/// >>> learned.tell(0.5, error=[0.1])
/// False
#[pyclass(module = "primo._primo")]
pub struct Power {
    learner: Box<CorePower>,
    args: PowerArgs,
    told: PowerTold,
}

/// `query` as a length that ends where one of `blocks` ends (0: none),
/// and needed when `query_gain` is not 0.
fn query_len(query: usize, blocks: &[Block], query_gain: f32) -> PyResult<usize> {
    if query == 0 {
        if query_gain != 0.0 {
            return Err(invalid(
                "query_gain: learns a query from the error, so name the query: query=n, the \
                 first n parameters (whole blocks)",
            ));
        }
        return Ok(0);
    }
    let ends: Vec<usize> = blocks
        .iter()
        .scan(0, |end, b| {
            *end += b.len;
            Some(*end)
        })
        .collect();
    if !ends.contains(&query) {
        return Err(invalid(format!(
            "query={query}: the query is the first blocks, whole; the blocks end at {ends:?}"
        )));
    }
    Ok(query)
}

impl Power {
    /// The core learner and this object for `args`, checked.
    fn build(args: PowerArgs) -> PyResult<Power> {
        let (initial, blocks, rollouts_per_update, roll_out_mean, sampler, seed, query_gain, query) =
            &args;
        let list: Vec<Block> = blocks
            .iter()
            .map(|&(len, variance, decay)| Block {
                len,
                variance,
                decay,
            })
            .collect();
        query_len(*query, &list, *query_gain)?;
        let cfg = PowerConfig {
            blocks: HVec::from_slice(&list).map_err(|_| {
                invalid(format!(
                    "blocks: {} blocks, at most {}",
                    list.len(),
                    primo_core::power::MAX_BLOCKS
                ))
            })?,
            rollouts_per_update: *rollouts_per_update,
            roll_out_mean: *roll_out_mean,
            sampler: *sampler,
            query_gain: *query_gain,
        };
        let mut learner = Box::new(CorePower::idle());
        learner.reset(initial, cfg, *seed).map_err(core)?;
        Ok(Power {
            learner,
            args,
            told: (Vec::new(), false),
        })
    }
}

#[pymethods]
impl Power {
    #[new]
    #[pyo3(signature = (initial, blocks, rollouts_per_update=3, roll_out_mean=true, sampler=None, seed=0, query_gain=0.0, query=0))]
    #[allow(clippy::too_many_arguments)] // Python's keyword arguments
    fn new(
        initial: Array<'_>,
        blocks: Vec<(usize, f64, f64)>,
        rollouts_per_update: u16,
        roll_out_mean: bool,
        sampler: Option<usize>,
        seed: u64,
        query_gain: f64,
        query: i64,
    ) -> PyResult<Power> {
        let query = usize::try_from(query).map_err(|_| {
            invalid(format!(
                "query={query}: the query's length, the first parameters (0: none)"
            ))
        })?;
        let query_gain = scalar("query_gain", query_gain)?;
        let sampler = sampler.unwrap_or_else(|| default_sampler(query_gain));
        let initial = vector("initial", &initial, false)?;
        let blocks = blocks
            .iter()
            .enumerate()
            .map(|(i, (len, variance, decay))| {
                Ok((
                    *len,
                    scalar(&format!("blocks[{i}] variance"), *variance)?,
                    scalar(&format!("blocks[{i}] decay"), *decay)?,
                ))
            })
            .collect::<PyResult<_>>()?;
        Power::build((
            initial,
            blocks,
            rollouts_per_update,
            roll_out_mean,
            sampler,
            seed,
            query_gain,
            query,
        ))
    }

    /// PoWER with primo's defaults on a skill, as `primo learn` and
    /// `primo pour --method power` build it: the extended vector `[q̂, Δθ]`
    /// starting at `[start, 0, …]`; one block for the query (its variance
    /// decaying by 0.9 per update), one for each DoF's kernel weights, one
    /// for the goals, one for τ, each exploring with the standard deviation
    /// `s · (the examples' widest distance over the block) / √len` (`s1` for
    /// the query, `s2` for the rest); 3 roll-outs per update plus the mean,
    /// a sampler of 3 (2 with a query gain). `primo pour --method power-el`
    /// is `s1=0.0, query_gain=1.0` (its `--gain`).
    ///
    /// Parameters: `skill` (a `Cell`, or a `Generalizer` over examples),
    /// `start` (the first query: default the cell's bottle, required for a
    /// Generalizer; one value per query entry), `seed` (the run's seed),
    /// `s1`, `s2` (exploration scales, >= 0), `query_gain` (K).
    /// Returns: a `Power` with `query` = the skill's query length.
    /// Raises: `TypeError` for another `skill`; `ValueError` for a missing or
    /// wrong-length start, or scales the examples cannot give a spread.
    ///
    /// >>> import primo
    /// >>> cell = primo.Cell(kernels=10)
    /// >>> power = primo.Power.defaults(cell, seed=1)
    /// >>> len(power.ask()) == len(cell), float(power.mean[0])
    /// (True, 0.5)
    #[staticmethod]
    #[pyo3(signature = (skill, start=None, seed=0, s1=0.2, s2=0.05, query_gain=0.0))]
    fn defaults(
        skill: &Bound<'_, PyAny>,
        start: Option<Array<'_>>,
        seed: u64,
        s1: f64,
        s2: f64,
        query_gain: f64,
    ) -> PyResult<Power> {
        let (skill, bottle) = if let Ok(cell) = skill.cast::<Cell>() {
            let (s, bottle) = cell.get().skill();
            (s.clone(), Some(bottle as f32))
        } else if let Ok(g) = skill.cast::<Generalizer>() {
            (g.borrow().skill.clone(), None)
        } else {
            return Err(PyTypeError::new_err(
                "skill: a primo.Cell or a primo.Generalizer, whose examples set the exploration",
            ));
        };
        let start = match (start, bottle) {
            (Some(s), _) => vector("start", &s, true)?,
            (None, Some(b)) => vec![b],
            (None, None) => {
                return Err(invalid(
                    "start: the first query, needed for a Generalizer (a Cell starts at its bottle)",
                ));
            }
        };
        if start.len() != skill.query_dim() {
            return Err(invalid(format!(
                "start: {} values, the skill's query has {}",
                start.len(),
                skill.query_dim()
            )));
        }
        let (s1, s2) = (scalar("s1", s1)?, scalar("s2", s2)?);
        let query_gain = scalar("query_gain", query_gain)?;
        let blocks = power_blocks(&skill, s1, s2, QUERY_DECAY).map_err(learn)?;
        let paper = PowerConfig::paper(&blocks).map_err(core)?;
        let mut initial = start;
        initial.resize(skill.query_dim() + skill.param_len(), 0.0);
        Power::build((
            initial,
            blocks
                .iter()
                .map(|b| (b.len, b.variance, b.decay))
                .collect(),
            paper.rollouts_per_update,
            paper.roll_out_mean,
            default_sampler(query_gain),
            seed,
            query_gain,
            skill.query_dim(),
        ))
    }

    /// The parameters to roll out next; the same until told.
    ///
    /// Returns:
    ///     numpy.ndarray: the parameters (the mean, or an exploration of it).
    ///
    /// >>> import primo
    /// >>> power = primo.Power([1.0, 2.0], blocks=[(2, 0.01, 1.0)])
    /// >>> power.ask()  # the mean first
    /// array([1., 2.])
    fn ask<'py>(&mut self, py: Python<'py>) -> Bound<'py, PyAny> {
        self.told.1 = true;
        out(py, self.learner.ask()).into_any()
    }

    /// Tells the asked roll-out's reward (and error, with a query).
    ///
    /// Args:
    ///     reward: the roll-out's reward, finite and >= 0 (larger is better).
    ///     error: the roll-out's error over the query, ``query`` values
    ///         (> 0 asks for a larger query): needed with a query gain,
    ///         refused without a query; else None.
    ///
    /// Returns:
    ///     bool: True when this roll-out completed an update.
    ///
    /// Raises:
    ///     ValueError: a negative or non-finite reward, an error of another
    ///         length than the query, or a missing one with a gain.
    ///
    /// >>> import primo
    /// >>> power = primo.Power([1.0], blocks=[(1, 0.01, 1.0)], rollouts_per_update=1)
    /// >>> _ = power.ask(); power.tell(0.5)
    /// False
    #[pyo3(signature = (reward, error=None))]
    fn tell(&mut self, reward: f64, error: Option<Array<'_>>) -> PyResult<bool> {
        let r = scalar("reward", reward)?;
        let query = self.args.7;
        let e = match &error {
            Some(e) => vector("error", e, true)?,
            None => Vec::new(),
        };
        if error.is_some() && e.len() != query {
            return Err(invalid(match query {
                0 => "error: this PoWER has no query (query=0) to correct".to_string(),
                n => format!(
                    "error: {} values, one per query entry: the query is the first {n} \
                     parameters (query={n})",
                    e.len()
                ),
            }));
        }
        if self.learner.query_gain() != 0.0 && e.is_empty() {
            return Err(invalid(
                "error: PoWER with a query gain needs each roll-out's error".to_string(),
            ));
        }
        let updated = self.learner.tell_outcome(r, &e).map_err(core)?;
        self.told.0.push((r, e));
        self.told.1 = false;
        Ok(updated)
    }

    /// The query's length: the first `query` parameters (0: none).
    #[getter]
    fn query(&self) -> usize {
        self.args.7
    }

    /// The present mean of the parameters.
    #[getter]
    fn mean<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        out(py, self.learner.mean()).into_any()
    }

    /// The updates made so far.
    #[getter]
    fn updates(&self) -> u32 {
        self.learner.updates()
    }

    /// The roll-outs told so far.
    #[getter]
    fn rollouts(&self) -> usize {
        self.told.0.len()
    }

    /// The present exploration variance, per parameter.
    #[getter]
    fn variances<'py>(&self, py: Python<'py>) -> Bound<'py, PyAny> {
        out(py, self.learner.variances()).into_any()
    }

    /// True when the next ``ask()`` gives the mean (rolled out once per update).
    #[getter]
    fn next_is_mean(&self) -> bool {
        self.learner.next_is_mean()
    }

    /// ``(parameters, reward)`` of the best roll-out so far, or None before the
    /// first.
    #[getter]
    fn best<'py>(&self, py: Python<'py>) -> Option<(Bound<'py, PyAny>, f64)> {
        self.learner
            .best()
            .map(|b| (out(py, b.params).into_any(), f64::from(b.reward)))
    }

    /// The importance sampler, best first: ``(parameters, reward)`` pairs.
    #[getter]
    fn sampler<'py>(&self, py: Python<'py>) -> Vec<(Bound<'py, PyAny>, f64)> {
        self.learner
            .sampler()
            .map(|(p, r)| (out(py, p).into_any(), f64::from(r)))
            .collect()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let this = slf.borrow();
        reduce(slf.as_any(), this.args.clone(), this.told.clone())
    }

    fn __setstate__(&mut self, told: PowerTold) -> PyResult<()> {
        for (r, e) in told.0 {
            self.learner.ask();
            self.learner.tell_outcome(r, &e).map_err(core)?;
            self.told.0.push((r, e));
        }
        if told.1 {
            self.learner.ask();
            self.told.1 = true;
        }
        Ok(())
    }
}
