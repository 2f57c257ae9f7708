//! `Dmp`: a fitted DMP with its column names, discrete (with orientation
//! columns, if any) or rhythmic: the DMP file of `primo dmp`
//! (`primo_skill::dmpfile`), so a Python DMP and a file are one thing.

use std::collections::BTreeMap;

use numpy::{PyArray1, PyUntypedArrayMethods};
use pyo3::exceptions::PyTypeError;
use pyo3::prelude::*;
use pyo3::types::{PyString, PyTuple};

use primo_core::dmp::{
    DEFAULT_OVERLAP, FinalVelocity, FitOptions, MAX_ALPHA, MIN_ALPHA, Margin, max_margin,
};
use primo_skill::MAX_KERNELS;
use primo_skill::coupled::DEFAULT_LIMIT_GAIN;
use primo_skill::csv::Demo;
use primo_skill::dmpfile::{
    self, AmplitudeScaling, Change, DmpFile, Fitted, MAX_ROWS, RhythmicFile,
};

use crate::arrays::{Array, matrix, out, out2, per_column, positive, times, vector};
use crate::dmprun::{Begun, DmpRun};
use crate::errors::{core, invalid, io, skill};
use crate::shaping::shaping;

/// A fitted DMP with its column names, discrete or rhythmic.
///
/// A discrete DMP moves from a start to a goal (four columns
/// ``<p>qw, <p>qx, <p>qy, <p>qz`` are one orientation, a quaternion DMP); a
/// rhythmic one repeats a period. Its JSON is the DMP file of
/// ``primo dmp fit`` and ``primo dmp run``. Computed in float32 (the fit's
/// normal equations in float64); arrays come out as float64. Make one with
/// ``Dmp.fit``, ``Dmp.fit_rhythmic``, ``Dmp.load`` or ``Dmp.from_json``;
/// it pickles, copies and compares (``==``) by value.
///
/// >>> import numpy as np, primo
/// >>> t = np.linspace(0.0, 1.0, 101)
/// >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"], kernels=20)
/// >>> times, x, v = dmp.run(dt=0.01, goal=[2.0], tau=2.0, velocities=True)
/// >>> round(float(times[-1]), 6), round(float(x[-1, 0]), 2), x.shape
/// (2.0, 2.0, (201, 1))
/// >>> run = dmp.stepper()
/// >>> bool((run.step(0.01) == dmp.run(dt=0.01)[1][1]).all())
/// True
/// >>> dmp.params.shape  # [weights, goal, tau]
/// (22,)
#[pyclass(module = "primo._primo", from_py_object)]
#[derive(Clone)]
pub struct Dmp {
    pub(crate) fitted: Fitted,
}

/// `names` as column names: any sequence of strings, but not a string,
/// which PyO3 would refuse in its own words ("Can't extract `str` to `Vec`").
fn column_names(names: Option<Bound<'_, PyAny>>) -> PyResult<Option<Vec<String>>> {
    let Some(names) = names else {
        return Ok(None);
    };
    if let Ok(text) = names.cast::<PyString>() {
        return Err(PyTypeError::new_err(format!(
            "names: a sequence of column names such as ['x', 'z'], not the string {}",
            text.repr()?
        )));
    }
    names.extract::<Vec<String>>().map(Some).map_err(|_| {
        PyTypeError::new_err("names: a sequence of column names (strings), one per column of y")
    })
}

/// A recording as a demonstration: `t` (n), `y` (n × columns, or n for
/// one column) and the column names (default `y0, y1, …`).
pub(crate) fn demo(
    t: &Array<'_>,
    y: &Array<'_>,
    names: Option<Bound<'_, PyAny>>,
) -> PyResult<Demo> {
    let names = column_names(names)?;
    let times = times("t", t)?;
    let (rows, cols, positions) = match y.shape().len() {
        1 => {
            let v = vector("y", y, false)?;
            (v.len(), 1, v)
        }
        _ => matrix("y", y)?,
    };
    if rows != times.len() {
        return Err(invalid(format!(
            "y has {rows} rows, t has {} samples: one row per sample",
            times.len()
        )));
    }
    if cols == 0 {
        return Err(invalid("y has no column"));
    }
    let names = names.unwrap_or_else(|| (0..cols).map(|i| format!("y{i}")).collect());
    if names.len() != cols {
        return Err(invalid(format!(
            "{} names for {cols} columns of y",
            names.len()
        )));
    }
    for (i, n) in names.iter().enumerate() {
        if n.is_empty() || names[..i].contains(n) {
            return Err(invalid(format!(
                "names: `{n}` is empty or repeated; one distinct name per column"
            )));
        }
    }
    Ok(Demo {
        names,
        times,
        positions,
    })
}

/// `kernels` of a fit in Python's terms (a negative count included, which
/// PyO3 would refuse as an overflow): `fewest` to [`MAX_KERNELS`] per DoF.
pub(crate) fn kernel_count(kernels: i64, fewest: usize, kind: &str) -> PyResult<usize> {
    usize::try_from(kernels)
        .ok()
        .filter(|k| (fewest..=MAX_KERNELS).contains(k))
        .ok_or_else(|| {
            invalid(format!(
                "kernels={kernels}: a {kind}DMP needs {fewest} to {MAX_KERNELS} kernels per DoF"
            ))
        })
}

/// At most [`MAX_ROWS`] samples for `duration` at step `dt`.
fn check_rows(dt: f32, duration: f32) -> PyResult<()> {
    if duration / dt > MAX_ROWS as f32 {
        return Err(invalid(format!(
            "dt {dt} over {duration} s would make {:.0} samples, at most {MAX_ROWS}",
            duration / dt
        )));
    }
    Ok(())
}

impl Dmp {
    fn discrete(&self, what: &str) -> PyResult<&DmpFile> {
        match &self.fitted {
            Fitted::Discrete(d) => Ok(d),
            Fitted::Rhythmic(_) => Err(invalid(format!(
                "{what}: not for a rhythmic DMP (a discrete one's)"
            ))),
        }
    }

    fn names_ref(&self) -> &[String] {
        match &self.fitted {
            Fitted::Discrete(d) => &d.names,
            Fitted::Rhythmic(r) => &r.names,
        }
    }

    pub(crate) fn from_file(file: DmpFile) -> Dmp {
        Dmp {
            fitted: Fitted::Discrete(file),
        }
    }

    fn json(&self) -> PyResult<String> {
        match &self.fitted {
            Fitted::Discrete(d) => d.to_json(),
            Fitted::Rhythmic(r) => r.to_json(),
        }
        .map_err(|e| invalid(format!("cannot serialize the DMP: {e}")))
    }
}

/// The fit's options from `Dmp.fit`'s keyword arguments, each checked
/// with its name.
fn fit_options(
    kernels: usize,
    margin: Option<f32>,
    overlap: f64,
    ridge: f64,
    alpha: f64,
    final_velocity: &str,
) -> PyResult<FitOptions> {
    let final_velocity = match final_velocity {
        "rest" => FinalVelocity::AtRest,
        "demonstrated" => FinalVelocity::Demonstrated,
        other => {
            return Err(invalid(format!(
                "final_velocity: {other:?}, expected \"rest\" or \"demonstrated\""
            )));
        }
    };
    let margin = match margin {
        None => Margin::Auto,
        Some(m) if (0.0..=max_margin(kernels)).contains(&m) => Margin::Spacings(m),
        Some(m) => {
            return Err(invalid(format!(
                "margin: {m} is not a number of kernel spacings from 0 to {} (with \
                 kernels={kernels}, one spacing must stay between the ends)",
                max_margin(kernels)
            )));
        }
    };
    let overlap = positive("overlap", Some(overlap))?.unwrap_or(DEFAULT_OVERLAP);
    if !(ridge.is_finite() && ridge >= 0.0 && (ridge as f32).is_finite()) {
        return Err(invalid(format!(
            "ridge: {ridge} must be a finite number >= 0"
        )));
    }
    if !(f64::from(MIN_ALPHA)..=f64::from(MAX_ALPHA)).contains(&alpha) {
        return Err(invalid(format!(
            "alpha: {alpha} is outside {MIN_ALPHA} to {MAX_ALPHA} (the spring gain; β = α/4)"
        )));
    }
    Ok(FitOptions {
        alpha: alpha as f32,
        overlap,
        ridge: ridge as f32,
        margin,
        final_velocity,
        ..FitOptions::default()
    })
}

#[pymethods]
impl Dmp {
    /// Fits a discrete DMP to one demonstration: least squares on the
    /// positions, so that its run reproduces ``y`` (no derivative of the
    /// recording is taken; any sampling fits).
    ///
    /// Args:
    ///     t: the sample times, s: n values, strictly increasing, any
    ///         spacing and any origin (Unix time is fine: they are counted
    ///         from the first sample in float64 before they are rounded to
    ///         the float32 the fit computes in).
    ///     y: the positions, n × columns (or n for one column), any unit.
    ///         Four columns ``<p>qw, <p>qx, <p>qy, <p>qz`` are one
    ///         orientation, a quaternion DMP.
    ///     names: the columns' names (default ``y0, y1, …``).
    ///     kernels: kernels per DoF, 2 to 128.
    ///     margin: kernel spacings the outer kernels lie beyond the
    ///         movement's ends, 0 to (kernels − 2)/2; ``None`` tries 0 and
    ///         1 and keeps the one that reproduces ``y`` better. DMPs
    ///         generalized together need the same.
    ///     overlap: the kernels' overlap ``h·Δc²`` (> 0; larger is
    ///         narrower: neighbours cross at ``exp(−overlap/4)``).
    ///     ridge: the ridge regularization, relative to the mean diagonal
    ///         of the Gram matrix (>= 0).
    ///     alpha: the spring gain α, 0.01 to 10000 (β = α/4).
    ///     scaling: how the forcing term scales to a new start and goal:
    ///         ``"per-dof"`` (each column by its own (g − y0)/(g_d − y0_d);
    ///         a column that starts and ends together unscaled),
    ///         ``"none"`` (the shape as demonstrated) or ``"global"`` (the
    ///         position columns turned by the smallest rotation taking the
    ///         demonstrated g − y0 onto the new one and stretched by the
    ///         ratio of their lengths, Koutras & Doulgeri 2020).
    ///     final_velocity: the velocity at the goal: ``"rest"`` (the
    ///         classic DMP) or ``"demonstrated"`` (the recording's speed at
    ///         its end, for a hit or a throw: the goal moves at it until τ,
    ///         Kober et al. 2010; ``run(goal_velocity=)`` changes it).
    ///
    /// ``primo learn`` fits a task's demonstrations with ``margin=0,
    /// overlap=2.0, ridge=1e-6`` (``Generalizer.from_task`` builds that
    /// skill itself).
    ///
    /// Returns:
    ///     Dmp: the fitted DMP, as ``primo dmp fit`` writes it.
    ///
    /// Raises:
    ///     ValueError: an argument out of its range (named), times that do
    ///         not increase, fewer than 3 samples, or weights beyond the
    ///         DMP's bounds.
    ///     TypeError: ``names`` not a sequence of strings.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = 1.7e9 + np.linspace(0.0, 1.0, 101)  # stamped in Unix time
    /// >>> dmp = primo.Dmp.fit(t, np.sin(t - t[0]), names=["x"], kernels=20, overlap=2.0)
    /// >>> dmp.tau, dmp.names
    /// (1.0, ['x'])
    #[staticmethod]
    #[allow(clippy::too_many_arguments)] // the fit's options, as keywords
    #[pyo3(signature = (t, y, names=None, kernels=30, margin=None, overlap=0.7, ridge=1e-9,
                        alpha=25.0, scaling="per-dof", final_velocity="rest"))]
    fn fit(
        py: Python<'_>,
        t: Array<'_>,
        y: Array<'_>,
        names: Option<Bound<'_, PyAny>>,
        kernels: i64,
        margin: Option<f32>,
        overlap: f64,
        ridge: f64,
        alpha: f64,
        scaling: &str,
        final_velocity: &str,
    ) -> PyResult<Dmp> {
        let kernels = kernel_count(kernels, 2, "")?;
        let options = fit_options(kernels, margin, overlap, ridge, alpha, final_velocity)?;
        let scaling = AmplitudeScaling::parse(scaling).ok_or_else(|| {
            invalid(format!(
                "scaling: {scaling:?}, expected \"per-dof\", \"none\" or \"global\""
            ))
        })?;
        let demo = demo(&t, &y, names)?;
        // The fit runs without the GIL: other threads go on meanwhile.
        let file = py.detach(|| {
            DmpFile::fit_with(
                "the demonstration",
                &demo,
                kernels,
                (scaling, None),
                &options,
            )
        });
        Ok(Dmp::from_file(file.map_err(skill)?))
    }

    /// Fits a rhythmic DMP to one period of a recording.
    ///
    /// Args:
    ///     t: sample times, s, shape (n,), strictly increasing, n >= 3.
    ///     y: positions, shape (n, columns), or (n,) for one column (no
    ///         orientation columns).
    ///     names: the column names, one per column of ``y`` (default
    ///         ``y0, y1, ...``).
    ///     kernels: basis functions per DoF, 2 to 128.
    ///     period: the period, s, counted from the first sample; None takes
    ///         the whole recording as one period.
    ///
    /// Returns:
    ///     Dmp: the rhythmic DMP (``rhythmic`` is True).
    ///
    /// Raises:
    ///     ValueError: as ``fit``, or a period that is not positive or longer
    ///         than the recording.
    ///     TypeError: ``names`` a string, or holding something not a string.
    ///
    /// The fit runs with the GIL released.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 201)
    /// >>> dmp = primo.Dmp.fit_rhythmic(t, np.sin(2 * np.pi * t), names=["x"])
    /// >>> dmp.rhythmic, dmp.kernels, round(dmp.period, 3)
    /// (True, 30, 1.0)
    #[staticmethod]
    #[pyo3(signature = (t, y, names=None, kernels=30, period=None))]
    fn fit_rhythmic(
        py: Python<'_>,
        t: Array<'_>,
        y: Array<'_>,
        names: Option<Bound<'_, PyAny>>,
        kernels: i64,
        period: Option<f64>,
    ) -> PyResult<Dmp> {
        let kernels = kernel_count(kernels, 3, "rhythmic ")?;
        let demo = demo(&t, &y, names)?;
        let period = positive("period", period)?;
        let file = py
            .detach(|| RhythmicFile::fit("the demonstration", &demo, kernels, period))
            .map_err(skill)?;
        Ok(Dmp {
            fitted: Fitted::Rhythmic(file),
        })
    }

    /// The DMP whose file text is ``text`` (DMP file versions 1 to 5).
    ///
    /// Args:
    ///     text: a DMP file's JSON, as ``to_json`` or ``primo dmp fit`` write it.
    ///
    /// Returns:
    ///     Dmp: the DMP it describes.
    ///
    /// Raises:
    ///     ValueError: not JSON, or not a DMP file (the message says where).
    ///
    /// >>> import numpy as np, primo
    /// >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
    /// >>> primo.Dmp.from_json(dmp.to_json()) == dmp
    /// True
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<Dmp> {
        let fitted = dmpfile::parse("the DMP's JSON", text).map_err(skill)?;
        Ok(Dmp { fitted })
    }

    /// Reads a DMP file written by ``primo dmp fit`` or ``Dmp.save``.
    ///
    /// Args:
    ///     path: the file's path (str or path-like).
    ///
    /// Returns:
    ///     Dmp: the DMP in the file.
    ///
    /// Raises:
    ///     OSError: the file cannot be read.
    ///     ValueError: not a DMP file (the message names the file and where).
    ///
    /// >>> import numpy as np, os, primo, tempfile
    /// >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
    /// >>> path = os.path.join(tempfile.mkdtemp(), "dmp.json")
    /// >>> dmp.save(path)
    /// >>> primo.Dmp.load(path) == dmp
    /// True
    #[staticmethod]
    fn load(path: std::path::PathBuf) -> PyResult<Dmp> {
        let text = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
        let fitted = dmpfile::parse(&path.display().to_string(), &text).map_err(skill)?;
        Ok(Dmp { fitted })
    }

    /// The DMP file's text (JSON), as ``primo dmp fit`` writes it.
    ///
    /// Returns:
    ///     str: the JSON text (without a final newline).
    ///
    /// >>> import numpy as np, json, primo
    /// >>> dmp = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11))
    /// >>> json.loads(dmp.to_json())["names"]
    /// ['y0']
    fn to_json(&self) -> PyResult<String> {
        self.json()
    }

    /// Writes the DMP file to ``path``, atomically: a reader sees the old file
    /// or the new one, never half of it.
    ///
    /// Args:
    ///     path: the file's path (str or path-like); an existing file is replaced.
    ///
    /// Raises:
    ///     OSError: the file cannot be written (the old one is kept).
    ///
    /// >>> import numpy as np, os, primo, tempfile
    /// >>> path = os.path.join(tempfile.mkdtemp(), "dmp.json")
    /// >>> primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11)).save(path)
    /// >>> os.path.exists(path)
    /// True
    fn save(&self, path: std::path::PathBuf) -> PyResult<()> {
        let text = format!("{}\n", self.json()?);
        primo_learn::output::write_file(&path, text.as_bytes()).map_err(crate::errors::learn)
    }

    /// The column names, in the order of ``y``'s columns.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.names_ref().to_vec()
    }

    /// True for a rhythmic DMP, False for a discrete one.
    #[getter]
    fn rhythmic(&self) -> bool {
        matches!(self.fitted, Fitted::Rhythmic(_))
    }

    /// The basis functions per DoF.
    #[getter]
    fn kernels(&self) -> usize {
        match &self.fitted {
            Fitted::Discrete(d) => d.dmp.kernels(),
            Fitted::Rhythmic(r) => r.rhythmic.kernels(),
        }
    }

    /// The DMP's DoFs: one per column, an orientation (four columns) counting 3.
    #[getter]
    fn dof(&self) -> usize {
        match &self.fitted {
            Fitted::Discrete(d) => d.dmp.dof(),
            Fitted::Rhythmic(r) => r.rhythmic.dof(),
        }
    }

    /// The orientation groups, each its four column names
    /// ``[<p>qw, <p>qx, <p>qy, <p>qz]`` (empty for a rhythmic DMP).
    #[getter]
    fn orientations(&self) -> Vec<Vec<String>> {
        match &self.fitted {
            Fitted::Discrete(d) => d.orientations.iter().map(|o| o.columns.to_vec()).collect(),
            Fitted::Rhythmic(_) => Vec::new(),
        }
    }

    /// The demonstrated duration, s (discrete; ValueError for a rhythmic DMP).
    #[getter]
    fn tau(&self) -> PyResult<f64> {
        Ok(f64::from(self.discrete("tau")?.dmp.tau()))
    }

    /// The demonstrated period, s (rhythmic; ValueError for a discrete DMP).
    #[getter]
    fn period(&self) -> PyResult<f64> {
        match &self.fitted {
            Fitted::Rhythmic(r) => Ok(f64::from(r.rhythmic.period())),
            Fitted::Discrete(_) => Err(invalid("period: not for a discrete DMP")),
        }
    }

    /// The demonstrated start, per column (discrete; ValueError for a
    /// rhythmic DMP).
    #[getter]
    fn start<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let d = self.discrete("start")?;
        let prepared = d.prepare(None, None, None).map_err(skill)?;
        Ok(out(py, &prepared.columns(&prepared.execution.start)))
    }

    /// The goal, per column (discrete; ValueError for a rhythmic DMP).
    #[getter]
    fn goal<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let d = self.discrete("goal")?;
        let prepared = d.prepare(None, None, None).map_err(skill)?;
        Ok(out(py, &prepared.columns(&prepared.execution.goal)))
    }

    /// The parameter vector θ = [weights row by row, goals, τ] of the DMP's
    /// DoFs (discrete): ``dof * kernels + dof + 1`` values, an orientation's
    /// goal as its 3 DoFs. Assigning it sets the DMP's weights, goal and
    /// duration (ValueError for a wrong length or a non-finite value, or for a
    /// rhythmic DMP).
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let d = self.discrete("params")?;
        let mut theta = vec![0.0; d.dmp.param_len()];
        d.dmp.params(&mut theta).map_err(core)?;
        Ok(out(py, &theta))
    }

    #[setter]
    fn set_params(&mut self, theta: Array<'_>) -> PyResult<()> {
        let theta = vector("params", &theta, false)?;
        match &mut self.fitted {
            Fitted::Discrete(d) => d.dmp.set_params(&theta).map_err(core),
            Fitted::Rhythmic(_) => Err(invalid("params: not for a rhythmic DMP")),
        }
    }

    #[allow(clippy::too_many_arguments)] // the keyword arguments of `primo dmp run`
    #[pyo3(signature = (dt=0.001, tau=None, start=None, goal=None, velocities=false,
                        duration=None, frequency=None, amplitude=None, anchor=None,
                        goal_velocity=None, via=None, obstacles=None, obstacle_columns=None,
                        limits=None, limit_margin=None, limit_gain=DEFAULT_LIMIT_GAIN as f64))]
    /// Runs the DMP at a fixed step, from start to goal (discrete) or for a
    /// duration (rhythmic), with the GIL released.
    ///
    /// Args:
    ///     dt: the step, s (positive).
    ///     tau: the duration, s (discrete; default the demonstrated one).
    ///     start: the start, per column (discrete; default the demonstrated one).
    ///     goal: the goal, per column (discrete; default the demonstrated one).
    ///         A changed goal does not move the start.
    ///     velocities: also return the velocities (discrete, no orientation
    ///         columns).
    ///     duration: how long to run, s (rhythmic; default three periods).
    ///     frequency: the frequency, Hz (rhythmic; default the demonstrated one).
    ///     amplitude: the amplitude, per column (rhythmic; default 1 each:
    ///         as demonstrated).
    ///     anchor: the centre of the oscillation, per column (rhythmic; default
    ///         the demonstrated one).
    ///     goal_velocity: the velocity at the goal, per column, per second
    ///         (discrete, no orientation columns): reached at the goal at τ.
    ///     via: via-points, a list of ``(time, column, value)`` (discrete,
    ///         up to 8): the column passes ``value`` at ``time`` s, strictly
    ///         inside the movement; the weights change least to pass them.
    ///     obstacles: spheres to steer round, shape (n, 4) rows of ``x, y,
    ///         z, radius`` (discrete, n up to 16; Park et al.'s dynamic
    ///         potential); the run goes on past τ until it reaches its goal,
    ///         at most 3τ.
    ///     obstacle_columns: the three position columns of ``x, y, z``
    ///         (default ``["x", "y", "z"]``).
    ///     limits: limits to keep away from, ``{column: (low, high)}``
    ///         (discrete; ``-inf``, ``inf``: none that side): within
    ///         ``limit_margin`` of one the run is pushed back, and goes on
    ///         past τ until it reaches its goal, at most 3τ.
    ///     limit_margin: how near a limit the push starts, in the column's
    ///         units (needed with ``limits``; the goal must lie outside it).
    ///     limit_gain: the push at half the margin, units/s².
    ///
    /// Returns:
    ///     tuple: ``(times, positions)``, shapes (m,) and (m, columns), m the
    ///     number of samples from time 0; with ``velocities``, a third array
    ///     (m, columns) of velocities (not with goal_velocity, via or
    ///     obstacles).
    ///
    /// Raises:
    ///     ValueError: a setting of the other kind of DMP, a value out of range,
    ///         a per-column array of the wrong length, more than a million samples.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"])
    /// >>> times, x = dmp.run(dt=0.01, goal=[0.5])
    /// >>> times.shape, round(float(x[-1, 0]), 2)
    /// ((101,), 0.5)
    /// >>> times, x = dmp.run(dt=0.01, via=[(0.5, "x", 0.8)])
    /// >>> round(float(x[50, 0]), 3)
    /// 0.8
    fn run<'py>(
        &self,
        py: Python<'py>,
        dt: f64,
        tau: Option<f64>,
        start: Option<Array<'_>>,
        goal: Option<Array<'_>>,
        velocities: bool,
        duration: Option<f64>,
        frequency: Option<f64>,
        amplitude: Option<Array<'_>>,
        anchor: Option<Array<'_>>,
        goal_velocity: Option<Array<'_>>,
        via: Option<Vec<(f64, String, f64)>>,
        obstacles: Option<Array<'_>>,
        obstacle_columns: Option<Vec<String>>,
        limits: Option<BTreeMap<String, (f64, f64)>>,
        limit_margin: Option<f64>,
        limit_gain: f64,
    ) -> PyResult<Bound<'py, PyTuple>> {
        let dt = positive("dt", Some(dt))?.unwrap_or(0.001);
        let names = self.names_ref();
        let width = names.len();
        let shaped =
            goal_velocity.is_some() || via.is_some() || obstacles.is_some() || limits.is_some();
        if limits.is_none() && limit_margin.is_some() {
            return Err(invalid("limit_margin: given without limits"));
        }
        let limits = limits.map(|l| (l, limit_margin, limit_gain));
        let shape = shaping(
            names,
            goal_velocity,
            via,
            obstacles,
            obstacle_columns,
            limits,
        )?;
        match &self.fitted {
            Fitted::Discrete(d) if !shape.is_plain() => {
                if duration.is_some()
                    || frequency.is_some()
                    || amplitude.is_some()
                    || anchor.is_some()
                    || velocities
                {
                    return Err(invalid(
                        "duration, frequency, amplitude, anchor, velocities: not with \
                         goal_velocity, via, obstacles or limits",
                    ));
                }
                let tau = positive("tau", tau)?;
                let start = per_column("start", start, names)?;
                let goal = per_column("goal", goal, names)?;
                let duration = tau.unwrap_or(d.dmp.tau());
                check_rows(
                    dt,
                    if !shape.coupled.is_none() {
                        3.0 * duration
                    } else {
                        duration
                    },
                )?;
                let prepared = d
                    .prepare(tau, start.as_deref(), goal.as_deref())
                    .map_err(skill)?;
                let rows = py
                    .detach(|| d.run_shaped(prepared, dt, &shape))
                    .map_err(skill)?;
                let t: Vec<f32> = rows.iter().map(|(t, _)| *t).collect();
                let y: Vec<f32> = rows.into_iter().flat_map(|(_, row)| row).collect();
                PyTuple::new(
                    py,
                    [out(py, &t).into_any(), out2(py, &y, width)?.into_any()],
                )
            }
            Fitted::Discrete(d) => {
                if duration.is_some()
                    || frequency.is_some()
                    || amplitude.is_some()
                    || anchor.is_some()
                {
                    return Err(invalid(
                        "duration, frequency, amplitude, anchor: for a rhythmic DMP only",
                    ));
                }
                let tau = positive("tau", tau)?;
                let start = per_column("start", start, names)?;
                let goal = per_column("goal", goal, names)?;
                check_rows(dt, tau.unwrap_or(d.dmp.tau()))?;
                let prepared = d
                    .prepare(tau, start.as_deref(), goal.as_deref())
                    .map_err(skill)?;
                if velocities && !prepared.is_plain() {
                    return Err(invalid(
                        "velocities: given for DMPs without orientation columns only",
                    ));
                }
                let integrate = || {
                    let (mut t, mut y, mut v) = (Vec::new(), Vec::new(), Vec::new());
                    let dof = d.dmp.dof();
                    for s in d.dmp.trajectory(&prepared.execution, dt)? {
                        t.push(s.time);
                        y.extend(prepared.columns(&s.position));
                        if velocities {
                            v.extend_from_slice(&s.velocity[..dof]);
                        }
                    }
                    Ok((t, y, v))
                };
                let (t, y, v) = py.detach(integrate).map_err(core)?;
                let mut items = vec![out(py, &t).into_any(), out2(py, &y, width)?.into_any()];
                if velocities {
                    items.push(out2(py, &v, width)?.into_any());
                }
                PyTuple::new(py, items)
            }
            Fitted::Rhythmic(r) => {
                if tau.is_some() || start.is_some() || goal.is_some() || velocities || shaped {
                    return Err(invalid(
                        "tau, start, goal, velocities, goal_velocity, via, obstacles, limits: \
                         for a discrete DMP only",
                    ));
                }
                let duration = match duration {
                    None => 3.0 * r.rhythmic.period(),
                    Some(x) if x.is_finite() && x >= 0.0 => x as f32,
                    Some(x) => {
                        return Err(invalid(format!(
                            "duration: {x} must be a finite number of seconds >= 0"
                        )));
                    }
                };
                check_rows(dt, duration)?;
                let frequency = positive("frequency", frequency)?;
                let amplitude = per_column("amplitude", amplitude, names)?;
                let anchor = per_column("anchor", anchor, names)?;
                let from_start = Change {
                    at: 0.0,
                    frequency,
                    amplitude,
                    anchor,
                };
                let integrate = || {
                    let (mut t, mut y) = (Vec::new(), Vec::new());
                    for (time, row) in r.run(dt, duration, &[from_start])? {
                        t.push(time);
                        y.extend(row);
                    }
                    Ok((t, y))
                };
                let (t, y) = py.detach(integrate).map_err(skill)?;
                PyTuple::new(
                    py,
                    [out(py, &t).into_any(), out2(py, &y, width)?.into_any()],
                )
            }
        }
    }

    /// This DMP bent through via-points (discrete): its weights changed
    /// least so that its run at steps of ``dt`` passes each point, as
    /// ``run(via=...)`` does, with the start, goal and duration its own.
    /// Its ``params`` are a movement's with the via-points built in: a
    /// parameter vector for a learner or ``primo.gym.BlackBox``.
    ///
    /// Args:
    ///     via: via-points, a list of ``(time, column, value)`` (up to 8):
    ///         the column passes ``value`` at ``time`` s, strictly inside the
    ///         movement.
    ///     dt: the step the run is made at, s (positive).
    ///
    /// Returns:
    ///     Dmp: the bent DMP.
    ///
    /// Raises:
    ///     ValueError: a rhythmic DMP, a time outside the movement, an unknown
    ///         column, two values for one column at once, a point no weight
    ///         can reach or that needs weights beyond their bound.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"])
    /// >>> bent = dmp.through([(0.5, "x", 0.8)], dt=0.01)
    /// >>> round(float(bent.run(dt=0.01)[1][50, 0]), 3), bent.goal.tolist() == dmp.goal.tolist()
    /// (0.8, True)
    #[pyo3(signature = (via, dt=0.001))]
    fn through(&self, py: Python<'_>, via: Vec<(f64, String, f64)>, dt: f64) -> PyResult<Dmp> {
        let d = self.discrete("through")?;
        let dt = positive("dt", Some(dt))?.unwrap_or(0.001);
        let shape = shaping(&d.names, None, Some(via), None, None, None)?;
        let prepared = d.prepare(None, None, None).map_err(skill)?;
        let bent = py
            .detach(|| d.through(&prepared, dt, &shape.vias))
            .map_err(skill)?;
        Ok(Dmp::from_file(bent))
    }

    /// A step-by-step execution of the DMP (discrete): a ``DmpRun`` at time 0.
    ///
    /// Args:
    ///     tau: the duration, s (default the demonstrated one).
    ///     start: the start, per column (default the demonstrated one).
    ///     goal: the goal, per column (default the demonstrated one).
    ///
    /// Returns:
    ///     DmpRun: the execution, at its start.
    ///
    /// Raises:
    ///     ValueError: a rhythmic DMP, a value out of range, a per-column array
    ///         of the wrong length.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> run = primo.Dmp.fit(t, t, names=["x"]).stepper(tau=2.0)
    /// >>> run.step(0.001).shape, round(run.time, 6)
    /// ((1,), 0.001)
    #[pyo3(signature = (tau=None, start=None, goal=None))]
    fn stepper(
        &self,
        tau: Option<f64>,
        start: Option<Array<'_>>,
        goal: Option<Array<'_>>,
    ) -> PyResult<DmpRun> {
        let d = self.discrete("stepper")?;
        let tau = positive("tau", tau)?;
        let start = per_column("start", start, &d.names)?;
        let goal = per_column("goal", goal, &d.names)?;
        DmpRun::new(d.clone(), Begun { tau, start, goal })
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let from_json = py.get_type::<Dmp>().getattr("from_json")?;
        let json = slf.borrow().json()?;
        PyTuple::new(py, [from_json, PyTuple::new(py, [json])?.into_any()])
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Dmp>()
            .is_ok_and(|o| o.borrow().fitted == self.fitted)
    }

    fn __copy__(&self) -> Dmp {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> Dmp {
        self.clone()
    }

    fn __repr__(&self) -> String {
        let kind = if self.rhythmic() { "rhythmic, " } else { "" };
        format!(
            "Dmp({kind}columns={:?}, kernels={})",
            self.names_ref(),
            self.kernels()
        )
    }
}
