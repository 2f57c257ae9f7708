//! `Generalizer`: DMPs at task queries, `G(q)` → a DMP for a new query
//! (`primo_skill::Skill::from_files`: LWR, GPR or a ProMP's conditioning
//! over the parameter vectors, the start generalized with the same coefficients; orientation
//! groups in the tangent space at their goals' mean, as the skill layer
//! and `primo learn` generalize them).

use numpy::PyArray1;
use pyo3::exceptions::PyOSError;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use primo_core::generalize::{Method, PROMP_RIDGE};
use primo_learn::task::Task;
use primo_skill::Skill;
use primo_skill::dmpfile::{DmpFile, Fitted};

use crate::arrays::{Array, out, vector};
use crate::dmp::Dmp;
use crate::errors::{invalid, skill};

/// ``G(q)``: a DMP for any task query, generalized from examples.
///
/// Examples are ``(query, dmp)`` pairs (a query is a float or 1 to 4 values);
/// a regression on the DMPs' parameter vectors gives the DMP for a new query,
/// the start generalized with the same coefficients. With two examples both
/// methods give the straight line through them; ``"promp"`` conditions a
/// ProMP over the parameters (Paraschos et al. 2013: the examples'
/// parameters and queries as one Gaussian) on the query, a global linear
/// model. Every example is a discrete
/// DMP with the first one's columns, in order. Orientation groups
/// (``<p>qw, <p>qx, <p>qy, <p>qz``) are generalized as ``primo learn`` does:
/// goals and starts as rotation vectors at the mean of the examples' goals,
/// weights as they are, so every ``generalize(q)`` is an orientation DMP
/// whose quaternions are unit-norm, equal to each example at its query where
/// the regression interpolates. It pickles with its examples.
///
/// Args:
///     examples: a sequence of ``(query, dmp)``: query a float or 1 to 4
///         values, the same count in every example; dmp a discrete ``Dmp``.
///     method: ``"lwr"`` (locally weighted regression), ``"gpr"``
///         (Gaussian process regression) or ``"promp"`` (a ProMP
///         conditioned on the query).
///     bandwidth: LWR's kernel bandwidth, or GPR's length scale, in query
///         units (positive; default from the examples' spacing).
///     noise: GPR's noise variance (>= 0; 0 interpolates the examples).
///     ridge: the ProMP's ridge on the query covariance, relative to its
///         mean variance (>= 0; default 1e-6).
///
/// Raises:
///     ValueError: no example, a rhythmic DMP, columns that differ from the
///         first example's, queries of different lengths, a setting out of
///         range.
///
/// >>> import numpy as np, primo
/// >>> t = np.linspace(0.0, 1.0, 101)
/// >>> low = primo.Dmp.fit(t, 0.2 * t, names=["x"])
/// >>> high = primo.Dmp.fit(t, 1.0 * t, names=["x"])
/// >>> g = primo.Generalizer([(0.2, low), (1.0, high)])
/// >>> round(float(g.generalize(0.6).goal[0]), 4)
/// 0.6
#[pyclass(module = "primo._primo")]
pub struct Generalizer {
    pub(crate) skill: Skill,
    /// The examples and settings, for pickling.
    examples: Vec<(Vec<f32>, Dmp)>,
    method: String,
    bandwidth: Option<f64>,
    noise: f64,
    ridge: Option<f64>,
}

/// The regression `method` ("lwr", "gpr" or "promp") with its bandwidth
/// (LWR) or length scale (GPR), noise (GPR) and ridge (ProMP).
fn method(name: &str, bandwidth: Option<f64>, noise: f64, ridge: Option<f64>) -> PyResult<Method> {
    if ridge.is_some() && name != "promp" {
        return Err(invalid(format!(
            "ridge: for method \"promp\", not \"{name}\""
        )));
    }
    let bandwidth = match bandwidth {
        Some(b) if !(b.is_finite() && b > 0.0 && (b as f32) > 0.0) => {
            return Err(invalid(format!(
                "bandwidth: {b} must be a positive, finite number"
            )));
        }
        b => b.map(|b| b as f32),
    };
    if !(noise.is_finite() && noise >= 0.0) {
        return Err(invalid(format!(
            "noise: {noise} must be a finite number >= 0"
        )));
    }
    match name {
        "lwr" => Ok(Method::Lwr { bandwidth }),
        "gpr" => Ok(Method::Gpr {
            length_scale: bandwidth,
            noise: noise as f32,
        }),
        "promp" => match ridge {
            None => Ok(Method::ProMp { ridge: PROMP_RIDGE }),
            Some(r) if r.is_finite() && r >= 0.0 => Ok(Method::ProMp { ridge: r as f32 }),
            Some(r) => Err(invalid(format!("ridge: {r} must be a finite number >= 0"))),
        },
        other => Err(invalid(format!(
            "method: `{other}`, expected \"lwr\", \"gpr\" or \"promp\""
        ))),
    }
}

/// A task's refusal: a file that would not open is an `OSError`, as
/// Python's own `open` raises, the rest as the learning library's.
fn task_error(e: primo_learn::Error) -> PyErr {
    match e {
        primo_learn::Error::Open { .. } => PyOSError::new_err(e.to_string()),
        e => crate::errors::learn(e),
    }
}

/// A DMP file's columns for a message, its orientation groups named.
fn columns(file: &DmpFile) -> String {
    let groups: Vec<String> = file
        .orientations
        .iter()
        .map(|o| o.columns.join(","))
        .collect();
    let orientations = match groups.as_slice() {
        [] => "no orientation".to_string(),
        [one] => format!("orientation {one}"),
        more => format!("orientations {}", more.join("; ")),
    };
    format!("[{}] ({orientations})", file.names.join(", "))
}

#[pymethods]
impl Generalizer {
    #[new]
    #[pyo3(signature = (examples, method="lwr", bandwidth=None, noise=0.0, ridge=None))]
    fn new(
        examples: Vec<(Array<'_>, Dmp)>,
        method: &str,
        bandwidth: Option<f64>,
        noise: f64,
        ridge: Option<f64>,
    ) -> PyResult<Generalizer> {
        let regression = self::method(method, bandwidth, noise, ridge)?;
        let mut kept: Vec<(Vec<f32>, Dmp)> = Vec::new();
        let mut files: Vec<&DmpFile> = Vec::new();
        for (i, (q, dmp)) in examples.iter().enumerate() {
            let query = vector(&format!("examples[{i}] query"), q, true)?;
            let Fitted::Discrete(file) = &dmp.fitted else {
                return Err(invalid(format!(
                    "examples[{i}]: a rhythmic DMP; generalization takes discrete DMPs"
                )));
            };
            if let Some(first) = files.first()
                && first.names != file.names
            {
                return Err(invalid(format!(
                    "examples[{i}]: columns {}, the first example's are {}: every example needs \
                     the same columns, in the same order",
                    columns(file),
                    columns(first)
                )));
            }
            files.push(file);
            kept.push((query, dmp.clone()));
        }
        if files.is_empty() {
            return Err(invalid("examples: give at least one (query, dmp) pair"));
        }
        let files: Vec<(&[f32], &DmpFile)> = kept
            .iter()
            .zip(files)
            .map(|((q, _), f)| (&q[..], f))
            .collect();
        let skill = Skill::from_files(&files, regression).map_err(skill)?;
        Ok(Generalizer {
            skill,
            examples: kept,
            method: method.to_string(),
            bandwidth,
            noise,
            ridge,
        })
    }

    /// The skill a task file builds, exactly as ``primo learn --task``
    /// builds it: the task's demonstrations read and checked (their
    /// columns and the task's limits), each fitted as ``primo learn``
    /// fits it (``margin=0, overlap=2.0, ridge=1e-6``, the task's
    /// ``kernels``, every example with the first one's amplitude scaling)
    /// and generalized by the task's ``generalization``.
    ///
    /// Args:
    ///     path: the task file (TOML, the book's task file reference); its
    ///         demonstrations are found beside it.
    ///
    /// Returns:
    ///     Generalizer: one example per ``[[demo]]``, in the file's order,
    ///     at its ``query``.
    ///
    /// Raises:
    ///     OSError: the task file cannot be read.
    ///     ValueError: the task file or a demonstration is refused or
    ///         missing (the message names the file, the line and the key),
    ///         or the task is the built-in pour (its cell builds its own
    ///         skill).
    ///
    /// >>> import primo
    /// >>> g = primo.Generalizer.from_task("examples/throw/throw.toml")  # doctest: +SKIP
    /// >>> len(g), g.names, g.query_dim  # doctest: +SKIP
    /// (2, ['shoulder', 'elbow'], 1)
    #[staticmethod]
    fn from_task(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Generalizer> {
        let task = Task::load(&path).map_err(task_error)?;
        let built = py.detach(|| task.build()).map_err(task_error)?;
        let (method, bandwidth, noise, ridge) = match task.regression {
            Method::Lwr { bandwidth } => ("lwr", bandwidth, 0.0, None),
            Method::Gpr {
                length_scale,
                noise,
            } => ("gpr", length_scale, noise, None),
            Method::ProMp { ridge } => ("promp", None, 0.0, Some(f64::from(ridge))),
        };
        let examples = (task.demos.iter().zip(built.fitted))
            .map(|(d, file)| (d.query.clone(), Dmp::from_file(file)))
            .collect();
        Ok(Generalizer {
            skill: built.skill,
            examples,
            method: method.to_string(),
            bandwidth: bandwidth.map(f64::from),
            noise: f64::from(noise),
            ridge,
        })
    }

    /// The DMP for query ``q``.
    ///
    /// Args:
    ///     q: the query: a float, or ``query_dim`` values.
    ///
    /// Returns:
    ///     Dmp: the generalized discrete DMP, with the examples' columns.
    ///
    /// Raises:
    ///     ValueError: a query of the wrong length or not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> g = primo.Generalizer([(q, primo.Dmp.fit(t, q * t)) for q in (0.5, 1.0)])
    /// >>> round(float(g.generalize(0.75).goal[0]), 4)
    /// 0.75
    fn generalize(&self, q: Array<'_>) -> PyResult<Dmp> {
        let query = vector("q", &q, true)?;
        Ok(Dmp::from_file(
            self.skill.movement(&query, &[]).map_err(skill)?,
        ))
    }

    /// ``G(q)``, the generalized parameter vector, laid out as ``Dmp.params``
    /// (an orientation group's three goal values: its goal's rotation vector
    /// from the examples' mean goal).
    ///
    /// Args:
    ///     q: the query: a float, or ``query_dim`` values.
    ///
    /// Returns:
    ///     numpy.ndarray: the parameter vector θ.
    ///
    /// Raises:
    ///     ValueError: a query of the wrong length or not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> g = primo.Generalizer([(q, primo.Dmp.fit(t, q * t)) for q in (0.5, 1.0)])
    /// >>> g.params(0.5).shape == g.generalize(0.5).params.shape
    /// True
    fn params<'py>(&self, py: Python<'py>, q: Array<'_>) -> PyResult<Bound<'py, PyAny>> {
        let query = vector("q", &q, true)?;
        Ok(out(py, &self.skill.generalize(&query).map_err(skill)?).into_any())
    }

    /// The examples ``(query, dmp)``, in order: the queries as float64
    /// arrays (1 to 4 values), the DMPs as given (or, from a task file, as
    /// ``primo learn`` fits them).
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> g = primo.Generalizer([(0.2, primo.Dmp.fit(t, 0.2 * t)), (1.0, primo.Dmp.fit(t, t))])
    /// >>> [float(q[0]) for q, _ in g.examples]
    /// [0.2, 1.0]
    #[getter]
    fn examples<'py>(&self, py: Python<'py>) -> Vec<(Bound<'py, PyArray1<f64>>, Dmp)> {
        (self.examples.iter())
            .map(|(q, dmp)| (out(py, q), dmp.clone()))
            .collect()
    }

    /// The number of values in a query (1 to 4).
    #[getter]
    fn query_dim(&self) -> usize {
        self.skill.query_dim()
    }

    /// The examples' column names.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.skill.names().to_vec()
    }

    fn __len__(&self) -> usize {
        self.examples.len()
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.borrow();
        let examples: Vec<(Vec<f32>, Dmp)> = this.examples.clone();
        let args = (
            examples,
            this.method.clone(),
            this.bandwidth,
            this.noise,
            this.ridge,
        );
        (py.get_type::<Generalizer>(), args).into_pyobject(py)
    }
}
