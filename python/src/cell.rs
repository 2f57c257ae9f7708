//! `Cell`: the simulated pouring cell as an objective, the one
//! `primo rollout` uses (`primo_learn::objective`): a vector `[weights,
//! goals, τ, q̂]` in, what the cell measured out. Many roll-outs run on
//! every core with the GIL released.

use numpy::PyUntypedArrayMethods;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use primo_learn::experiment::parallel;
use primo_learn::pour::objective::{Objective, layout};
use primo_learn::pour::rig::rollout_seed;
use primo_learn::pour::series::{MEASURED, Series, measured};
use primo_learn::pour::skill::Space;
use primo_learn::pour::skill::{DemoFile, SkillSpec};
use primo_learn::pour::trial::Trial;
use primo_sim::cell::GlassKind;

use crate::arrays::{Array, out, vector};
use crate::dmp::kernel_count;
use crate::errors::{invalid, learn};

/// The simulated pouring cell as an objective, as ``primo rollout`` uses it.
///
/// A vector ``[weights (dof × kernels, row by row), goals, τ, q̂]`` is
/// executed as ``G(q̂) + θ − G(bottle)``: the skill generalized from the
/// demonstrations to the query ``q̂``, plus the offset ``θ`` from the
/// movement generalized to the bottle. The robot pours from the bottle into
/// the glass; the scale measures. ``start()`` gives the generalized start
/// and PoWER's exploration std. ``rollout_many`` runs rows on every core with
/// the GIL released. It pickles with its settings.
///
/// Args:
///     glass: ``"small"`` or ``"normal"``, the glass poured into.
///     space: ``"joint"`` (the arm's 7 joints) or ``"cartesian"`` (the
///         bottle's mouth and orientation).
///     bottle: the liquid in the bottle, l.
///     target: the volume to pour, l.
///     kernels: basis functions per DoF, 2 to 128.
///     seed: the scale's noise seed of ``rollout`` by default.
///     demos: ``(path, volume)`` pairs: demonstration CSVs and the volume
///         each was recorded for (default: the built-in demonstrations).
///
/// Raises:
///     ValueError: an unknown glass or space, a volume or setting out of
///         range, a demonstration that does not parse (naming its file and
///         line).
///     OSError: a demonstration file that cannot be read.
///
/// >>> import primo
/// >>> cell = primo.Cell(glass="small", kernels=10, bottle=0.5, target=0.2)
/// >>> start = cell.start()
/// >>> len(start["start"]) == len(cell) == 7 * 10 + 7 + 1 + 1
/// True
/// >>> result = cell.rollout(start["start"])
/// >>> sorted(result), result["safe"]
/// (['error', 'poured', 'rejected', 'reward', 'safe', 'spilled'], True)
#[pyclass(module = "primo._primo", frozen)]
pub struct Cell {
    objective: Objective,
    glass: String,
    space: String,
    kernels: usize,
    seed: u64,
    demos: Vec<(std::path::PathBuf, f32)>,
}

pub(crate) fn glass_kind(name: &str) -> PyResult<GlassKind> {
    match name {
        "normal" => Ok(GlassKind::Normal),
        "small" => Ok(GlassKind::Small),
        other => Err(invalid(format!(
            "glass: `{other}`, expected \"normal\" or \"small\""
        ))),
    }
}

fn space_kind(name: &str) -> PyResult<Space> {
    match name {
        "joint" => Ok(Space::Joint),
        "cartesian" => Ok(Space::Cartesian),
        other => Err(invalid(format!(
            "space: `{other}`, expected \"joint\" or \"cartesian\""
        ))),
    }
}

/// The time series as a dict of columns: `t`, the commanded coordinates,
/// then what the cell measured (the columns of `primo rollout --series`).
fn series_dict<'py>(py: Python<'py>, s: &Series) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    let t: Vec<f64> = s.samples.iter().map(|x| x.t).collect();
    dict.set_item("t", numpy::PyArray1::from_vec(py, t))?;
    let names = s.space.names();
    let dof = names.len();
    for (j, name) in names.iter().enumerate() {
        let column: Vec<f64> = s.commands.iter().skip(j).step_by(dof).copied().collect();
        dict.set_item(*name, numpy::PyArray1::from_vec(py, column))?;
    }
    let rows: Vec<[f64; 11]> = s.samples.iter().map(measured).collect();
    for (j, name) in MEASURED.split(',').enumerate() {
        let column: Vec<f64> = rows.iter().map(|r| r[j]).collect();
        dict.set_item(name, numpy::PyArray1::from_vec(py, column))?;
    }
    Ok(dict)
}

/// A trial as the dict Python sees.
fn trial_dict<'py>(py: Python<'py>, trial: &Trial) -> PyResult<Bound<'py, PyDict>> {
    let dict = PyDict::new(py);
    dict.set_item("poured", trial.poured)?;
    dict.set_item("spilled", trial.spilled)?;
    dict.set_item("error", trial.error)?;
    dict.set_item("reward", trial.reward)?;
    dict.set_item("safe", trial.rejected.is_none())?;
    dict.set_item("rejected", trial.rejected.as_deref())?;
    if let Some(s) = &trial.series {
        dict.set_item("series", series_dict(py, s)?)?;
    }
    Ok(dict)
}

impl Cell {
    /// The skill and the bottle: where PoWER starts on this cell.
    pub(crate) fn skill(&self) -> (&primo_skill::Skill, f64) {
        (self.objective.skill(), self.objective.bottle())
    }

    /// One row of numbers as the objective's vector (`what` names it).
    fn vector(&self, what: &str, values: &[f64]) -> PyResult<Vec<f32>> {
        self.objective
            .vector(values)
            .map_err(|e| invalid(format!("{what}: {e}")))
    }
}

/// A seed from Python: any integer that fits 64 bits.
pub(crate) fn seed_of(what: &str, seed: &Bound<'_, PyAny>) -> PyResult<u64> {
    seed.extract::<u64>()
        .map_err(|_| invalid(format!("{what}: a seed is an integer in 0..2**64")))
}

#[pymethods]
impl Cell {
    #[new]
    #[pyo3(signature = (glass="small", space="joint", bottle=0.5, target=0.2, kernels=30, seed=1, demos=None))]
    fn new(
        glass: &str,
        space: &str,
        bottle: f64,
        target: f64,
        kernels: i64,
        seed: u64,
        demos: Option<Vec<(std::path::PathBuf, f64)>>,
    ) -> PyResult<Cell> {
        let kernels = kernel_count(kernels, 2, "")?;
        let demos: Vec<(std::path::PathBuf, f32)> = demos
            .unwrap_or_default()
            .into_iter()
            .map(|(f, v)| (f, v as f32))
            .collect();
        let files = demos
            .iter()
            .map(|(file, volume)| {
                Ok(DemoFile {
                    file: std::path::absolute(file).map_err(|e| crate::errors::io(file, e))?,
                    volume: *volume,
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let spec = SkillSpec {
            space: space_kind(space)?,
            glass: glass_kind(glass)?,
            kernels,
            demos: files,
        };
        if !bottle.is_finite() {
            return Err(invalid(format!(
                "bottle: {bottle} is not a volume in litres"
            )));
        }
        let objective = Objective::new(&spec, bottle, target).map_err(learn)?;
        Ok(Cell {
            objective,
            glass: glass.to_string(),
            space: space.to_string(),
            kernels,
            seed,
            demos,
        })
    }

    /// The length of a vector the cell takes: ``dof * kernels + dof + 2``.
    #[getter]
    fn size(&self) -> usize {
        self.objective.len()
    }

    fn __len__(&self) -> usize {
        self.objective.len()
    }

    /// The glass: ``"small"`` or ``"normal"``.
    #[getter]
    fn glass(&self) -> &str {
        &self.glass
    }

    /// The space: ``"joint"`` or ``"cartesian"``.
    #[getter]
    fn space(&self) -> &str {
        &self.space
    }

    /// The liquid in the bottle, l.
    #[getter]
    fn bottle(&self) -> f64 {
        self.objective.bottle()
    }

    /// The volume to pour, l.
    #[getter]
    fn target(&self) -> f64 {
        self.objective.target()
    }

    /// The basis functions per DoF.
    #[getter]
    fn kernels(&self) -> usize {
        self.kernels
    }

    /// What the glass holds to its rim, litres: `primo pour`'s
    /// `glass_holds` in summary.json. Error learning searches only queries
    /// that let no more than this leave the bottle: from
    /// `max(0.1, bottle + target − glass_holds)` (in float32) to 1.5 l.
    ///
    /// >>> import primo
    /// >>> round(primo.Cell(glass="small", kernels=10).glass_holds, 3)
    /// 0.423
    #[getter]
    fn glass_holds(&self) -> f64 {
        self.objective.glass_litres()
    }

    /// The seed of the scale's noise that `primo pour --seed SEED` uses
    /// for roll-out `rollout` (numbered from 1, as rollouts.csv's); `seed`
    /// defaults to the cell's. `cell.rollout(theta, seed=cell.pour_seed(k))`
    /// is roll-out k of that run when `theta` is what it rolled out.
    ///
    /// Parameters: `rollout` (int >= 1), `seed` (int in 0..2**64, or None).
    /// Returns: the seed, an int in 0..2**64.
    /// Raises: `ValueError` for a roll-out below 1 or beyond 2**32 − 1, or a
    /// seed out of range.
    ///
    /// >>> import primo
    /// >>> cell = primo.Cell(kernels=10, seed=7)
    /// >>> cell.pour_seed(1) == cell.pour_seed(1, seed=7) != cell.pour_seed(2)
    /// True
    #[pyo3(signature = (rollout, seed=None))]
    fn pour_seed(&self, rollout: i64, seed: Option<Bound<'_, PyAny>>) -> PyResult<u64> {
        let rollout = u32::try_from(rollout)
            .ok()
            .filter(|r| *r >= 1)
            .ok_or_else(|| {
                invalid(format!(
                    "rollout={rollout}: roll-outs are numbered from 1 to 2**32 - 1, as in \
                     rollouts.csv"
                ))
            })?;
        let seed = match seed {
            Some(s) => seed_of("seed", &s)?,
            None => self.seed,
        };
        Ok(rollout_seed(seed, rollout))
    }

    /// The same cell (glass, space, kernels, seed, demonstrations) for
    /// another context: `bottle` litres in the bottle, `target` litres to
    /// pour (each by default this cell's). Its skill is generalized to the
    /// new bottle, so its `start()` differs.
    ///
    /// Raises: `ValueError` for a bottle or target the cell refuses (as
    /// the constructor).
    ///
    /// >>> import primo
    /// >>> cell = primo.Cell(kernels=10, bottle=0.5, target=0.2)
    /// >>> other = cell.with_context(bottle=0.8)
    /// >>> other.bottle, other.target, len(other) == len(cell)
    /// (0.8, 0.2, True)
    #[pyo3(signature = (bottle=None, target=None))]
    fn with_context(&self, bottle: Option<f64>, target: Option<f64>) -> PyResult<Cell> {
        let demos = self
            .demos
            .iter()
            .map(|(f, v)| (f.clone(), f64::from(*v)))
            .collect();
        Cell::new(
            &self.glass,
            &self.space,
            bottle.unwrap_or(self.objective.bottle()),
            target.unwrap_or(self.objective.target()),
            self.kernels as i64,
            self.seed,
            Some(demos),
        )
    }
    /// The scale's noise seed of ``rollout`` by default.
    #[getter]
    fn seed(&self) -> u64 {
        self.seed
    }

    /// The commanded columns: ``a1..a7``, or in Cartesian space the mouth and
    /// the bottle's orientation, ``x, y, z, qw, qx, qy, qz``.
    #[getter]
    fn names(&self) -> Vec<&'static str> {
        self.objective.space().names().to_vec()
    }

    /// What ``primo rollout --print-start`` prints, and the cell it is for.
    ///
    /// Returns:
    ///     dict: ``layout`` (the vector's blocks), ``space``, ``glass``,
    ///     ``bottle``, ``target``, ``dof``, ``kernels``, ``start`` (the vector
    ///     of the movement generalized to the bottle) and ``std`` (PoWER's
    ///     exploration std per entry).
    ///
    /// Raises:
    ///     ValueError: the skill cannot be generalized to the bottle.
    ///
    /// >>> import primo
    /// >>> start = primo.Cell(kernels=10).start()
    /// >>> start["dof"], start["kernels"], len(start["std"]) == len(start["start"])
    /// (7, 10, True)
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = self.objective.start().map_err(learn)?;
        let dict = PyDict::new(py);
        dict.set_item("layout", layout(self.objective.space()))?;
        dict.set_item("space", &self.space)?;
        dict.set_item("glass", &self.glass)?;
        dict.set_item("bottle", self.objective.bottle())?;
        dict.set_item("target", self.objective.target())?;
        dict.set_item("dof", self.objective.skill().dof())?;
        dict.set_item("kernels", self.objective.skill().kernels())?;
        dict.set_item("start", out(py, &s.start))?;
        dict.set_item("std", out(py, &s.std))?;
        Ok(dict)
    }

    /// One roll-out of ``theta`` on the cell.
    ///
    /// Args:
    ///     theta: the vector, ``size`` values (see the class).
    ///     seed: the scale's noise seed (an integer below 2**64; default the
    ///         cell's).
    ///     series: also return the roll-out's time series.
    ///
    /// Returns:
    ///     dict: ``poured`` and ``spilled`` (l), ``error`` (target − poured,
    ///     l), ``reward``, ``safe`` (bool) and ``rejected`` (None, or why the
    ///     safety gate refused the movement before it ran); with ``series``,
    ///     ``series``: a dict of arrays (time, the commanded columns, the
    ///     measured volume).
    ///
    /// Raises:
    ///     ValueError: a wrong shape or length, a non-finite value, a bad seed.
    ///
    /// >>> import primo
    /// >>> cell = primo.Cell(kernels=10)
    /// >>> result = cell.rollout(cell.start()["start"], seed=7)
    /// >>> result["rejected"] is None, result["poured"] > 0
    /// (True, True)
    #[pyo3(signature = (theta, seed=None, series=false))]
    fn rollout<'py>(
        &self,
        py: Python<'py>,
        theta: Array<'_>,
        seed: Option<Bound<'py, PyAny>>,
        series: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        if theta.ndim() != 1 {
            return Err(invalid(format!(
                "theta: expected a 1-D array of {} values, got shape {:?}",
                self.objective.len(),
                theta.shape()
            )));
        }
        let seed = match seed {
            Some(s) => seed_of("seed", &s)?,
            None => self.seed,
        };
        let values: Vec<f64> = theta.as_array().iter().copied().collect();
        let x = self.vector("theta", &values)?;
        let objective = &self.objective;
        let trial = py
            .detach(|| objective.roll_out(&x, seed, series))
            .map_err(learn)?;
        trial_dict(py, &trial)
    }

    /// One roll-out of `G(query) + delta`: PoWER's extended vector `[q̂,
    /// Δθ]` executed as `primo pour` and `primo learn` execute it (`rollout`
    /// takes `θ = G(bottle) + Δθ` instead, whose float32 sum rounds Δθ).
    /// With `Power.defaults(cell)` and `pour_seed` this repeats a PoWER run
    /// of `primo pour` roll-out by roll-out.
    ///
    /// Parameters: `query` (the skill's query, 1 value: litres in the
    /// bottle), `delta` (`len(cell) − 1` values, the layout of
    /// `start()["start"][:-1]`), `seed` (the scale's noise, default the
    /// cell's), `series` (add the time series).
    /// Returns: the dict of `rollout`.
    /// Raises: `ValueError` for wrong lengths or non-finite values.
    ///
    /// >>> import numpy as np, primo
    /// >>> cell = primo.Cell(kernels=10)
    /// >>> start = cell.start()["start"]
    /// >>> cell.rollout_delta([0.5], np.zeros(len(cell) - 1)) == cell.rollout(start)
    /// True
    #[pyo3(signature = (query, delta, seed=None, series=false))]
    fn rollout_delta<'py>(
        &self,
        py: Python<'py>,
        query: Array<'_>,
        delta: Array<'_>,
        seed: Option<Bound<'py, PyAny>>,
        series: bool,
    ) -> PyResult<Bound<'py, PyDict>> {
        let query = vector("query", &query, true)?;
        let delta = vector("delta", &delta, false)?;
        let seed = match seed {
            Some(s) => seed_of("seed", &s)?,
            None => self.seed,
        };
        let objective = &self.objective;
        let trial = py
            .detach(|| objective.roll_out_delta(&query, &delta, seed, series))
            .map_err(learn)?;
        trial_dict(py, &trial)
    }

    /// Roll-outs of every row of ``thetas`` on all cores, the GIL released.
    ///
    /// Args:
    ///     thetas: the vectors, one per row: shape (m, ``size``).
    ///     seeds: one noise seed per row (default: the cell's seed + i, as
    ///         ``primo rollout --serve`` numbers its lines).
    ///
    /// Returns:
    ///     list: one dict per row, as ``rollout`` returns (without series).
    ///
    /// Raises:
    ///     ValueError: a wrong shape, a row that is not a vector of the cell,
    ///         a seed count that does not match the rows.
    ///
    /// >>> import numpy as np, primo
    /// >>> cell = primo.Cell(kernels=10)
    /// >>> rows = np.tile(cell.start()["start"], (3, 1))
    /// >>> [r["safe"] for r in cell.rollout_many(rows)]
    /// [True, True, True]
    #[pyo3(signature = (thetas, seeds=None))]
    fn rollout_many<'py>(
        &self,
        py: Python<'py>,
        thetas: Array<'_>,
        seeds: Option<Vec<Bound<'py, PyAny>>>,
    ) -> PyResult<Vec<Bound<'py, PyDict>>> {
        let shape = thetas.shape().to_vec();
        let [rows, _] = shape[..] else {
            return Err(invalid(format!(
                "thetas: expected a 2-D array (one vector per row), got shape {shape:?}"
            )));
        };
        // The shapes first: a count mismatch is said before any row.
        let seeds: Vec<u64> = match seeds {
            None => (0..rows as u64)
                .map(|i| self.seed.wrapping_add(i))
                .collect(),
            Some(s) if s.len() == rows => s
                .iter()
                .enumerate()
                .map(|(i, s)| seed_of(&format!("seeds[{i}]"), s))
                .collect::<PyResult<_>>()?,
            Some(s) => {
                return Err(invalid(format!("seeds: {} seeds for {rows} rows", s.len())));
            }
        };
        let xs = thetas
            .as_array()
            .outer_iter()
            .enumerate()
            .map(|(r, row)| {
                let row: Vec<f64> = row.iter().copied().collect();
                self.vector(&format!("thetas[{r}]"), &row)
            })
            .collect::<PyResult<Vec<_>>>()?;
        let objective = &self.objective;
        let trials = py.detach(|| parallel(rows, |i| objective.roll_out(&xs[i], seeds[i], false)));
        trials
            .into_iter()
            .map(|t| trial_dict(py, &t.map_err(learn)?))
            .collect()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let c = slf.get();
        let demos: Vec<(std::path::PathBuf, f64)> = c
            .demos
            .iter()
            .map(|(f, v)| (f.clone(), f64::from(*v)))
            .collect();
        let args = (
            c.glass.clone(),
            c.space.clone(),
            c.objective.bottle(),
            c.objective.target(),
            c.kernels,
            c.seed,
            demos,
        );
        (py.get_type::<Cell>(), args).into_pyobject(py)
    }

    fn __repr__(&self) -> String {
        format!(
            "Cell(glass={:?}, space={:?}, bottle={}, target={}, kernels={}, seed={})",
            self.glass,
            self.space,
            self.objective.bottle(),
            self.objective.target(),
            self.kernels,
            self.seed
        )
    }
}
