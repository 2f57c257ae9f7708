//! `ProMp`: a probabilistic movement primitive from several
//! demonstrations (the core's [`primo_core::promp`]), by column name: the
//! file of `primo promp` ([`primo_skill::prompfile`]), so a Python ProMP
//! and a file are one thing. It pickles as that file's JSON.

use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use primo_core::promp::{Observation, blend};
use primo_skill::prompfile::{HostProMp as Core, MAX_KERNELS, PrompFile};

use crate::arrays::{Array, out2, vector, vector64};
use crate::dmp::demo;
use crate::errors::{core, invalid, skill};

/// A probabilistic movement primitive (Paraschos et al. 2013): a Gaussian
/// over the weights of normalized Gaussian kernels on the phase (each
/// demonstration's time over its duration), fitted to several
/// demonstrations; the trajectory's mean and variance at any phase,
/// conditioned on positions (via-points, the goal) and blended with
/// another. Pickles and copies.
///
/// >>> import numpy as np, primo
/// >>> t = np.linspace(0.0, 1.0, 101)
/// >>> demos = [(t, h * t * t * (3 - 2 * t)) for h in (0.9, 1.0, 1.1)]
/// >>> p = primo.ProMp.fit(demos, names=["x"], kernels=20)
/// >>> round(float(p.mean([1.0])[0, 0]), 3)
/// 1.0
/// >>> q = p.condition(1.0, {"x": 1.05})
/// >>> round(float(q.mean([1.0])[0, 0]), 3), round(float(q.mean([0.5])[0, 0]), 3)
/// (1.05, 0.525)
#[pyclass(module = "primo._primo")]
#[derive(Clone)]
pub struct ProMp {
    file: PrompFile,
}

impl ProMp {
    fn dof_of(&self, name: &str) -> PyResult<usize> {
        self.file
            .names
            .iter()
            .position(|n| n == name)
            .ok_or_else(|| {
                invalid(format!(
                    "no column {name:?} among {}",
                    self.file.names.join(", ")
                ))
            })
    }

    /// `f(phase, dof)` for each phase in `z` and each column: (len(z), columns).
    fn per_phase<'py>(
        &self,
        py: Python<'py>,
        z: &Array<'_>,
        f: impl Fn(&Core, f64, usize) -> f64,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        let z = vector("z", z, true)?;
        if let Some(bad) = z.iter().find(|z| !(0.0..=1.0).contains(*z)) {
            return Err(invalid(format!("z: {bad} is not a phase in [0, 1]")));
        }
        let values: Vec<f32> = z
            .iter()
            .flat_map(|&z| (0..self.file.names.len()).map(move |d| (z, d)))
            .map(|(z, d)| f(&self.file.promp, f64::from(z), d) as f32)
            .collect();
        out2(py, &values, self.file.names.len())
    }
}

#[pymethods]
impl ProMp {
    /// Fits a ProMP to several demonstrations of the same columns and the
    /// same number of samples: each one's kernel weights by least squares,
    /// their mean and covariance (with a ridge), and the mean squared
    /// residual as the observation noise.
    ///
    /// Args:
    ///     demos: a sequence of ``(t, y)``: times, s (n, strictly
    ///         increasing; each demonstration's own duration is its phase
    ///         0 to 1) and positions (n, columns), or (n,) for one column.
    ///     names: the columns' names (default ``y0, y1, …``).
    ///     kernels: kernels per column, 2 to 40.
    ///     ridge: the covariance's ridge, relative to its mean variance
    ///         (>= 0): what keeps it invertible with few demonstrations.
    ///
    /// Returns:
    ///     ProMp: the fitted ProMP.
    ///
    /// Raises:
    ///     ValueError: fewer than two demonstrations, ones of different
    ///         lengths or columns, more than 8 columns, an orientation's
    ///         four columns, times that do not increase, a value that is
    ///         not finite, kernels or ridge out of range (as ``primo promp
    ///         fit``).
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 2 * t)], kernels=10)
    /// >>> p.names, p.kernels, round(p.duration, 6)
    /// (['y0'], 10, 1.0)
    #[staticmethod]
    #[pyo3(signature = (demos, names=None, kernels=20, ridge=1e-6))]
    fn fit(
        py: Python<'_>,
        demos: Vec<(Array<'_>, Array<'_>)>,
        names: Option<Bound<'_, PyAny>>,
        kernels: i64,
        ridge: f64,
    ) -> PyResult<ProMp> {
        if !(2..=MAX_KERNELS as i64).contains(&kernels) {
            return Err(invalid(format!(
                "kernels={kernels}: a ProMP takes 2 to {MAX_KERNELS} kernels per column"
            )));
        }
        if !(ridge.is_finite() && ridge >= 0.0) {
            return Err(invalid(format!(
                "ridge: {ridge} must be a finite number >= 0"
            )));
        }
        let parsed = (demos.iter().enumerate())
            .map(|(i, (t, y))| {
                let d =
                    demo(t, y, names.clone()).map_err(|e| invalid(format!("demos[{i}]: {e}")))?;
                Ok((format!("demos[{i}]"), d))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let named: Vec<(&str, &primo_skill::csv::Demo)> =
            parsed.iter().map(|(name, d)| (name.as_str(), d)).collect();
        // The file's fit: the same checks as `primo promp fit`'s.
        let file = py.detach(|| PrompFile::fit(&named, kernels as usize, ridge));
        Ok(ProMp {
            file: file.map_err(skill)?,
        })
    }

    /// The columns' names.
    #[getter]
    fn names(&self) -> Vec<String> {
        self.file.names.clone()
    }

    /// Kernels per column.
    #[getter]
    fn kernels(&self) -> usize {
        self.file.promp.kernels()
    }

    /// The demonstrations' mean duration, s (phase 1).
    #[getter]
    fn duration(&self) -> f64 {
        self.file.promp.duration()
    }

    /// The mean position at each phase.
    ///
    /// Args:
    ///     z: phases in [0, 1], shape (m,) (or one number).
    ///
    /// Returns:
    ///     numpy.ndarray: shape (m, columns).
    ///
    /// Raises:
    ///     ValueError: a phase outside [0, 1] or not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
    /// >>> p.mean([0.0, 1.0]).round(2).tolist()
    /// [[0.0], [2.0]]
    fn mean<'py>(
        &self,
        py: Python<'py>,
        z: Array<'_>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        self.per_phase(py, &z, |p, z, d| p.mean(z, d))
    }

    /// The mean velocity at each phase, per second.
    ///
    /// Args:
    ///     z: phases in [0, 1], shape (m,) (or one number).
    ///
    /// Returns:
    ///     numpy.ndarray: shape (m, columns).
    ///
    /// Raises:
    ///     ValueError: a phase outside [0, 1] or not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 2.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
    /// >>> p.velocity([0.5]).round(1).tolist()  # the mean 2 t: 2 per second
    /// [[2.0]]
    fn velocity<'py>(
        &self,
        py: Python<'py>,
        z: Array<'_>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        self.per_phase(py, &z, |p, z, d| p.velocity(z, d))
    }

    /// The mean's kernel weights, column by column (``kernels`` each): the
    /// parameters a learner changes (``primo.gym.BlackBox``'s ``theta``).
    /// Assigning them moves the mean and keeps the spread (ValueError for
    /// a wrong length or a value that is not finite).
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
    /// >>> p.params = p.params + 0.5  # the normalized kernels: every position + 0.5
    /// >>> p.mean([0.0, 1.0]).round(2).tolist()
    /// [[0.5], [2.5]]
    #[getter]
    fn params<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        numpy::PyArray1::from_iter(py, self.file.promp.weights())
    }

    #[setter]
    fn set_params(&mut self, weights: Array<'_>) -> PyResult<()> {
        let weights = vector64("params", &weights)?;
        self.file.promp.set_weights(&weights).map_err(core)
    }

    /// The variance of the position at each phase: the weights' spread and
    /// the observation noise.
    ///
    /// Args:
    ///     z: phases in [0, 1], shape (m,) (or one number).
    ///
    /// Returns:
    ///     numpy.ndarray: shape (m, columns).
    ///
    /// Raises:
    ///     ValueError: a phase outside [0, 1] or not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
    /// >>> round(float(p.variance(1.0)[0, 0]), 2)  # the ends 1 and 3
    /// 2.0
    fn variance<'py>(
        &self,
        py: Python<'py>,
        z: Array<'_>,
    ) -> PyResult<Bound<'py, numpy::PyArray2<f64>>> {
        self.per_phase(py, &z, |p, z, d| p.variance(z, d))
    }

    /// This ProMP conditioned on positions at a phase: the columns pass
    /// them (a via-point, the goal), the rest moves with its correlations.
    ///
    /// Args:
    ///     z: the phase, in [0, 1].
    ///     positions: ``{column: position}``.
    ///     variance: how sure the positions are (>= 0; 0 is exact).
    ///
    /// Returns:
    ///     ProMp: the conditioned ProMP (this one is unchanged).
    ///
    /// Raises:
    ///     ValueError: an unknown column, a phase outside [0, 1], a
    ///         negative variance, a position that is not finite, or one the
    ///         distribution cannot take (no spread there to move by).
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 3 * t)], kernels=10)
    /// >>> round(float(p.condition(0.5, {"y0": 1.25}).mean(1.0)[0, 0]), 2)
    /// 2.5
    #[pyo3(signature = (z, positions, variance=0.0))]
    fn condition(&self, z: f64, positions: Bound<'_, PyDict>, variance: f64) -> PyResult<ProMp> {
        let mut observed = Vec::new();
        for (name, value) in positions.iter() {
            let name: String = name.extract()?;
            let position: f64 = value.extract()?;
            observed.push(Observation {
                dof: self.dof_of(&name)?,
                position: position as f32,
            });
        }
        let mut next = self.clone();
        next.file
            .promp
            .condition(z, &observed, variance)
            .map_err(core)?;
        Ok(next)
    }

    /// Blends this ProMP (activation ``alpha``) with ``other`` (``1 −
    /// alpha``) at phases: per column, the product of the two positions'
    /// distributions with each precision weighted by its activation.
    ///
    /// Args:
    ///     other: a ProMP of the same columns.
    ///     alpha: this one's activation, in [0, 1]: one number, or one per
    ///         phase.
    ///     z: phases in [0, 1], shape (m,).
    ///
    /// Returns:
    ///     tuple: ``(mean, variance)``, each (m, columns).
    ///
    /// Raises:
    ///     ValueError: other columns, an activation or phase out of range.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> a = primo.ProMp.fit([(t, t), (t, 1.1 * t)], kernels=10)
    /// >>> b = primo.ProMp.fit([(t, -t), (t, -1.1 * t)], kernels=10)
    /// >>> mean, var = a.blend(b, [1.0, 0.5, 0.0], [1.0, 1.0, 1.0])
    /// >>> mean.round(2).ravel().tolist()
    /// [1.05, 0.0, -1.05]
    fn blend<'py>(
        &self,
        py: Python<'py>,
        other: &ProMp,
        alpha: Array<'_>,
        z: Array<'_>,
    ) -> PyResult<Bound<'py, PyTuple>> {
        if other.file.names != self.file.names {
            return Err(invalid(format!(
                "other: columns {} where this ProMP has {}",
                other.file.names.join(","),
                self.file.names.join(",")
            )));
        }
        let z = vector("z", &z, true)?;
        let alpha = vector("alpha", &alpha, true)?;
        if alpha.len() != 1 && alpha.len() != z.len() {
            return Err(invalid(format!(
                "alpha: {} values for {} phases (give one, or one per phase)",
                alpha.len(),
                z.len()
            )));
        }
        let (mut mean, mut var) = (Vec::new(), Vec::new());
        for (i, &zi) in z.iter().enumerate() {
            let a = alpha.get(i).or(alpha.first()).copied().unwrap_or(1.0);
            if !(0.0..=1.0).contains(&zi) {
                return Err(invalid(format!("z: {zi} is not a phase in [0, 1]")));
            }
            for d in 0..self.file.names.len() {
                let (m, v) = blend(
                    &self.file.promp,
                    &other.file.promp,
                    f64::from(a),
                    f64::from(zi),
                    d,
                )
                .map_err(core)?;
                mean.push(m as f32);
                var.push(v as f32);
            }
        }
        let width = self.file.names.len();
        PyTuple::new(
            py,
            [
                out2(py, &mean, width)?.into_any(),
                out2(py, &var, width)?.into_any(),
            ],
        )
    }

    /// The ProMP file's JSON, as ``primo promp fit`` writes it.
    ///
    /// >>> import numpy as np, json, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 2 * t)], names=["x"], kernels=10)
    /// >>> json.loads(p.to_json())["names"]
    /// ['x']
    fn to_json(&self) -> PyResult<String> {
        self.file
            .to_json()
            .map_err(|e| invalid(format!("cannot serialize the ProMP: {e}")))
    }

    /// The ProMP of a ProMP file's JSON (``primo promp fit``'s, or
    /// ``to_json``'s): ``primo promp run`` runs the same.
    ///
    /// Args:
    ///     text: the JSON.
    ///
    /// Raises:
    ///     ValueError: not a ProMP file, or one whose numbers are not a
    ///         ProMP's.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 51)
    /// >>> p = primo.ProMp.fit([(t, t), (t, 2 * t)], kernels=10)
    /// >>> primo.ProMp.from_json(p.to_json()).mean([1.0]).tolist() == p.mean([1.0]).tolist()
    /// True
    #[staticmethod]
    fn from_json(text: &str) -> PyResult<ProMp> {
        let file = PrompFile::parse("the ProMP's JSON", text).map_err(skill)?;
        Ok(ProMp { file })
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let from_json = py.get_type::<ProMp>().getattr("from_json")?;
        let json = slf.borrow().to_json()?;
        PyTuple::new(py, [from_json, PyTuple::new(py, [json])?.into_any()])
    }

    fn __copy__(&self) -> ProMp {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: Bound<'_, PyAny>) -> ProMp {
        self.clone()
    }
}
