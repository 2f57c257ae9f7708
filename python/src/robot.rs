//! `Robot`: a serial arm's chain (`primo_robot::chain`), from a URDF or the
//! built-in KUKA LWR 4, with its forward kinematics, geometric Jacobian and
//! inverse kinematics (`primo_robot::ik`) on float64 arrays. A robot keeps
//! the URDF's text and the chain's settings, so it pickles and is rebuilt
//! as it was read.

use nalgebra::{Isometry3, Matrix3, Rotation3, Translation3, UnitQuaternion};
use numpy::{PyArray1, PyArrayMethods, PyUntypedArrayMethods};
use pyo3::exceptions::PyRuntimeError;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use primo_robot::chain::{Chain, JointLimits, Tip};
use primo_robot::ik::{IkOptions, inverse};
use primo_robot::urdf::Urdf;

use crate::arrays::Array;
use crate::errors::{invalid, io};

/// Most samples of `forward_many` and `inverse_path`: a path of an hour at
/// 1 kHz.
const MAX_SAMPLES: usize = 3_600_000;
/// How far a given rotation may be from orthonormal (each entry of
/// `RᵀR − I`).
const ORTHONORMAL: f64 = 1e-6;

/// A serial arm from its base link to a tip (a link, or a tool frame in
/// it), with its joints' limits: forward kinematics, the geometric
/// Jacobian and inverse kinematics, in float64 (metres, radians; poses are
/// 4 × 4 homogeneous matrices in the base frame). Read from a URDF
/// (``Robot.from_urdf``; xacro files and mimic joints in the chain are
/// refused) or the built-in KUKA LWR 4 (``Robot.lwr4()``, joints
/// ``a1``…``a7``). Bad input (a shape, a length, NaN) is a ``ValueError``,
/// an unreadable file an ``OSError``, an inverse kinematics that does not
/// converge a ``RuntimeError`` naming the errors reached. Pickles as its
/// URDF text and settings.
///
/// >>> import numpy as np, primo
/// >>> robot = primo.Robot.lwr4()
/// >>> robot.dof, robot.joint_names[:2], robot.tip
/// (7, ['a1', 'a2'], 'flange')
/// >>> q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5])
/// >>> pose = robot.forward(q)
/// >>> pose.shape, robot.jacobian(q).shape
/// ((4, 4), (6, 7))
/// >>> solved = robot.inverse(pose, seed=q + 0.05)
/// >>> bool(np.abs(robot.forward(solved) - pose).max() < 1e-9)
/// True
/// >>> import pickle
/// >>> pickle.loads(pickle.dumps(robot)) == robot
/// True
#[pyclass(module = "primo._primo", frozen)]
pub struct Robot {
    chain: Chain,
    source: Source,
}

/// What a robot was built from, to rebuild it.
#[derive(Clone)]
enum Source {
    Lwr4,
    Urdf {
        file: String,
        text: String,
        base: Option<String>,
        tip: Option<String>,
        /// The 4 × 4 tool matrix as given, row by row.
        tool: Option<Vec<f64>>,
        limits: Vec<Limit>,
    },
}

/// A joint's `(lower, upper, velocity)` given by name.
type Limit = (String, (f64, f64, f64));

/// A 1-D array of `n` finite float64 values (`what` names it).
fn joints(what: &str, a: &Array<'_>, n: usize) -> PyResult<Vec<f64>> {
    if a.ndim() != 1 || a.len() != n {
        return Err(invalid(format!(
            "{what}: expected {n} joint values (shape ({n},)), got shape {:?}",
            a.shape()
        )));
    }
    let v: Vec<f64> = a.as_array().iter().copied().collect();
    finite(what, &v, 1)?;
    Ok(v)
}

/// Every value finite; `width` values per row name the place of one that
/// is not.
fn finite(what: &str, v: &[f64], width: usize) -> PyResult<()> {
    match v.iter().position(|x| !x.is_finite()) {
        None => Ok(()),
        Some(i) if width == 1 => Err(invalid(format!(
            "{what}[{i}]: {} is not a finite number",
            v[i]
        ))),
        Some(i) => Err(invalid(format!(
            "{what}[{}, {}]: {} is not a finite number",
            i / width,
            i % width,
            v[i]
        ))),
    }
}

/// A homogeneous 4 × 4 transform, row by row, as an isometry: the last row
/// `0 0 0 1`, the rotation orthonormal (to 1e-6) and proper.
fn isometry(what: &str, m: &[f64]) -> PyResult<Isometry3<f64>> {
    finite(what, m, 4)?;
    if m[12..16] != [0.0, 0.0, 0.0, 1.0] {
        return Err(invalid(format!(
            "{what}: the last row is {:?}, a homogeneous transform's is [0, 0, 0, 1]",
            &m[12..16]
        )));
    }
    let r = Matrix3::new(m[0], m[1], m[2], m[4], m[5], m[6], m[8], m[9], m[10]);
    let off = (r.transpose() * r - Matrix3::identity()).amax();
    if off > ORTHONORMAL || r.determinant() <= 0.0 {
        return Err(invalid(format!(
            "{what}: its rotation is no rotation (RᵀR − I is off by {off:.3e}, det R = {:.6}); \
             give an orthonormal rotation with det 1",
            r.determinant()
        )));
    }
    let rotation = UnitQuaternion::from_rotation_matrix(&Rotation3::from_matrix_unchecked(r));
    let rotation = UnitQuaternion::new_normalize(rotation.into_inner());
    Ok(Isometry3::from_parts(
        Translation3::new(m[3], m[7], m[11]),
        rotation,
    ))
}

/// An array of 4 × 4 transforms (`lead` its leading shape), row by row.
fn transforms(what: &str, a: &Array<'_>, lead: usize) -> PyResult<Vec<f64>> {
    let shape = a.shape();
    if shape.len() != lead + 2 || shape[lead..] != [4, 4] {
        let expected = if lead == 0 { "(4, 4)" } else { "(m, 4, 4)" };
        return Err(invalid(format!(
            "{what}: expected shape {expected} (homogeneous transforms), got {shape:?}"
        )));
    }
    Ok(a.as_array().iter().copied().collect())
}

/// An isometry as a homogeneous 4 × 4 matrix, row by row.
fn rows(pose: &Isometry3<f64>, to: &mut Vec<f64>) {
    let h = pose.to_homogeneous();
    for r in 0..4 {
        for c in 0..4 {
            to.push(h[(r, c)]);
        }
    }
}

impl Robot {
    fn build(source: Source) -> PyResult<Robot> {
        let chain = match &source {
            Source::Lwr4 => primo_robot::Robot::lwr4().chain(),
            Source::Urdf {
                file,
                text,
                base,
                tip,
                tool,
                limits,
            } => {
                let urdf = Urdf::parse(file, text).map_err(invalid)?;
                let tool = tool.as_deref().map(|m| isometry("tool", m)).transpose()?;
                let limits = limits
                    .iter()
                    .map(|(name, (lower, upper, velocity))| {
                        (
                            name.clone(),
                            JointLimits {
                                lower: *lower,
                                upper: *upper,
                                velocity: *velocity,
                            },
                        )
                    })
                    .collect();
                let settings = Tip {
                    base: base.clone(),
                    tip: tip.clone(),
                    tool,
                    limits,
                };
                Chain::from_urdf(&urdf, &settings).map_err(invalid)?
            }
        };
        Ok(Robot { chain, source })
    }

    fn limit(&self, f: impl Fn(&JointLimits) -> f64) -> Vec<f64> {
        self.chain.joints().iter().map(|j| f(&j.limits)).collect()
    }

    /// The rest posture: given, or each joint's mid-range (0 when
    /// continuous).
    fn rest(&self, rest: Option<Array<'_>>) -> PyResult<Vec<f64>> {
        match rest {
            Some(r) => joints("rest", &r, self.chain.dof()),
            None => Ok(primo_robot::tool_path::mid_range(&self.chain)),
        }
    }
}

fn options(tolerance: f64, iterations: usize) -> PyResult<IkOptions> {
    if !(tolerance.is_finite() && tolerance > 0.0) {
        return Err(invalid(format!(
            "tolerance: {tolerance} must be a positive, finite number (metres and radians)"
        )));
    }
    if !(1..=100_000).contains(&iterations) {
        return Err(invalid(format!(
            "iterations: {iterations}, expected 1 to 100000"
        )));
    }
    Ok(IkOptions {
        tolerance,
        iterations,
    })
}

/// `(lower, upper, velocity)` of a joint in a `limits` dict.
fn limits_of(limits: Option<&Bound<'_, PyDict>>) -> PyResult<Vec<Limit>> {
    let Some(limits) = limits else {
        return Ok(Vec::new());
    };
    let mut all = Vec::new();
    for (name, value) in limits.iter() {
        let name: String = name
            .extract()
            .map_err(|_| invalid("limits: the keys are joint names (str)"))?;
        let triple: (f64, f64, f64) = value.extract().map_err(|_| {
            invalid(format!(
                "limits[{name:?}]: expected (lower, upper, velocity), three numbers"
            ))
        })?;
        all.push((name, triple));
    }
    Ok(all)
}

#[pymethods]
impl Robot {
    /// The chain of the URDF at ``path``, from ``base`` to ``tip``.
    ///
    /// Args:
    ///     path: the URDF file (str or path-like; plain URDF, not xacro).
    ///     base: the chain's base link (default: the URDF's root link).
    ///     tip: the chain's last link (default: the one leaf below the base;
    ///         name it when there are several).
    ///     tool: a 4 × 4 homogeneous transform from the tip link to the tool
    ///         frame (default: the identity).
    ///     limits: joint name → ``(lower, upper, velocity)`` (rad or m, rad/s
    ///         or m/s), for joints the URDF gives none or to narrow them.
    ///
    /// Returns:
    ///     Robot: the chain with its joints' limits.
    ///
    /// Raises:
    ///     OSError: the file cannot be read.
    ///     ValueError: a xacro file, a mimic, floating or planar joint in the
    ///         chain, a joint without limits, a malformed URDF (naming its line
    ///         and column), a bad tool or limit.
    ///
    /// >>> import os, primo, tempfile
    /// >>> urdf = '''<robot name="arm"><link name="base"/><link name="tip"/>
    /// ... <joint name="j1" type="revolute"><parent link="base"/><child link="tip"/>
    /// ... <origin xyz="0 0 0.5"/><axis xyz="0 0 1"/>
    /// ... <limit lower="-1" upper="1" velocity="2" effort="10"/></joint></robot>'''
    /// >>> path = os.path.join(tempfile.mkdtemp(), "arm.urdf")
    /// >>> with open(path, "w") as f:
    /// ...     _ = f.write(urdf)
    /// >>> robot = primo.Robot.from_urdf(path)
    /// >>> robot.name, robot.joint_names, robot.tip
    /// ('arm', ['j1'], 'tip')
    #[staticmethod]
    #[pyo3(signature = (path, base=None, tip=None, tool=None, limits=None))]
    fn from_urdf(
        path: std::path::PathBuf,
        base: Option<String>,
        tip: Option<String>,
        tool: Option<Array<'_>>,
        limits: Option<&Bound<'_, PyDict>>,
    ) -> PyResult<Robot> {
        let text = std::fs::read_to_string(&path).map_err(|e| io(&path, e))?;
        let file = path.display().to_string();
        Robot::from_urdf_text(text, base, tip, tool, limits, file)
    }

    /// ``from_urdf`` of a URDF's text.
    ///
    /// Args:
    ///     text: the URDF's XML text.
    ///     base: the chain's base link (default: the URDF's root link).
    ///     tip: the chain's last link (default: the one leaf below the base).
    ///     tool: a 4 × 4 transform from the tip link to the tool frame.
    ///     limits: joint name → ``(lower, upper, velocity)``.
    ///     file: the name errors give the text.
    ///
    /// Returns:
    ///     Robot: the chain with its joints' limits.
    ///
    /// Raises:
    ///     ValueError: as ``from_urdf``, the place named in ``file``.
    ///
    /// >>> import primo
    /// >>> primo.Robot.from_urdf_text("<robot>", file="arm.urdf")
    /// Traceback (most recent call last):
    /// ...
    /// ValueError: arm.urdf:1:8: ...
    #[staticmethod]
    #[pyo3(signature = (text, base=None, tip=None, tool=None, limits=None, file="<string>".to_string()))]
    fn from_urdf_text(
        text: String,
        base: Option<String>,
        tip: Option<String>,
        tool: Option<Array<'_>>,
        limits: Option<&Bound<'_, PyDict>>,
        file: String,
    ) -> PyResult<Robot> {
        let tool = tool.map(|t| transforms("tool", &t, 0)).transpose()?;
        Robot::build(Source::Urdf {
            file,
            text,
            base,
            tip,
            tool,
            limits: limits_of(limits)?,
        })
    }

    /// The built-in KUKA LWR 4 (its DH table, the flange as tip, joints
    /// ``a1`` to ``a7``).
    ///
    /// Returns:
    ///     Robot: the arm.
    ///
    /// >>> import primo
    /// >>> primo.Robot.lwr4().dof
    /// 7
    #[staticmethod]
    fn lwr4() -> PyResult<Robot> {
        Robot::build(Source::Lwr4)
    }

    /// The URDF's robot name.
    #[getter]
    fn name(&self) -> String {
        self.chain.robot.clone()
    }

    /// The chain's base link.
    #[getter]
    fn base(&self) -> String {
        self.chain.base.clone()
    }

    /// The chain's tip link.
    #[getter]
    fn tip(&self) -> String {
        self.chain.tip.clone()
    }

    /// The moving joints, base to tip: the order of every ``q``.
    #[getter]
    fn joint_names(&self) -> Vec<String> {
        self.chain.names().into_iter().map(String::from).collect()
    }

    /// The number of moving joints.
    #[getter]
    fn dof(&self) -> usize {
        self.chain.dof()
    }

    /// The lowest positions, rad or m (−inf for a continuous joint).
    #[getter]
    fn lower<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.limit(|l| l.lower))
    }

    /// The highest positions, rad or m (+inf for a continuous joint).
    #[getter]
    fn upper<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.limit(|l| l.upper))
    }

    /// The fastest speeds, rad/s or m/s.
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        PyArray1::from_vec(py, self.limit(|l| l.velocity))
    }

    /// The tool's pose at ``q``.
    ///
    /// Args:
    ///     q: the joint positions, ``dof`` values, rad or m.
    ///
    /// Returns:
    ///     numpy.ndarray: the pose, a 4 × 4 homogeneous matrix in the base frame.
    ///
    /// Raises:
    ///     ValueError: a wrong length or a value that is not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> primo.Robot.lwr4().forward(np.zeros(7))[:3, 3].round(3)
    /// array([0.   , 0.   , 1.178])
    fn forward<'py>(&self, py: Python<'py>, q: Array<'_>) -> PyResult<Bound<'py, PyAny>> {
        let q = joints("q", &q, self.chain.dof())?;
        let mut m = Vec::with_capacity(16);
        rows(&self.chain.forward(&q), &mut m);
        Ok(PyArray1::from_vec(py, m).reshape([4, 4])?.into_any())
    }

    /// The tool's poses at each row of ``qs``, with the GIL released.
    ///
    /// Args:
    ///     qs: joint positions, shape (m, dof).
    ///
    /// Returns:
    ///     numpy.ndarray: the poses, shape (m, 4, 4).
    ///
    /// Raises:
    ///     ValueError: a wrong shape, a value that is not finite, more than
    ///         3.6 million rows.
    ///
    /// >>> import numpy as np, primo
    /// >>> primo.Robot.lwr4().forward_many(np.zeros((5, 7))).shape
    /// (5, 4, 4)
    fn forward_many<'py>(&self, py: Python<'py>, qs: Array<'_>) -> PyResult<Bound<'py, PyAny>> {
        let dof = self.chain.dof();
        let shape = qs.shape().to_vec();
        if shape.len() != 2 || shape[1] != dof || shape[0] > MAX_SAMPLES {
            return Err(invalid(format!(
                "qs: expected shape (m, {dof}) with m <= {MAX_SAMPLES}, got {shape:?}"
            )));
        }
        let values: Vec<f64> = qs.as_array().iter().copied().collect();
        finite("qs", &values, dof)?;
        let m = shape[0];
        let chain = &self.chain;
        let out = py.detach(|| {
            let mut out = Vec::with_capacity(m * 16);
            for q in values.chunks(dof) {
                rows(&chain.forward(q), &mut out);
            }
            out
        });
        Ok(PyArray1::from_vec(py, out).reshape([m, 4, 4])?.into_any())
    }

    /// The geometric Jacobian at ``q``.
    ///
    /// Args:
    ///     q: the joint positions, ``dof`` values.
    ///
    /// Returns:
    ///     numpy.ndarray: 6 × dof; rows vx, vy, vz, wx, wy, wz of the tool
    ///     frame's origin, in the base frame.
    ///
    /// Raises:
    ///     ValueError: a wrong length or a value that is not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> primo.Robot.lwr4().jacobian(np.zeros(7)).shape
    /// (6, 7)
    fn jacobian<'py>(&self, py: Python<'py>, q: Array<'_>) -> PyResult<Bound<'py, PyAny>> {
        let dof = self.chain.dof();
        let q = joints("q", &q, dof)?;
        let j = self.chain.jacobian(&q);
        let values: Vec<f64> = (0..6)
            .flat_map(|r| (0..dof).map(move |c| (r, c)))
            .map(|(r, c)| j[(r, c)])
            .collect();
        Ok(PyArray1::from_vec(py, values).reshape([6, dof])?.into_any())
    }

    /// Joint positions within the limits that put the tool at ``target``.
    ///
    /// Damped least squares from ``seed``, pulled toward ``rest`` in the null
    /// space. A local search: seed it near the answer (a path's previous
    /// sample).
    ///
    /// Args:
    ///     target: the tool's pose, 4 × 4 homogeneous (an orthonormal, proper
    ///         rotation).
    ///     seed: the joint positions to start from, ``dof`` values.
    ///     rest: the posture the null space pulls toward (default: each joint's
    ///         mid-range, 0 if continuous).
    ///     tolerance: the position (m) and orientation (rad) error to reach.
    ///     iterations: the most iterations.
    ///
    /// Returns:
    ///     numpy.ndarray: the joint positions, ``dof`` values.
    ///
    /// Raises:
    ///     RuntimeError: no convergence within ``iterations``, naming the
    ///         smallest position and orientation errors reached.
    ///     ValueError: a wrong shape or length, a value that is not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> robot = primo.Robot.lwr4()
    /// >>> q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5])
    /// >>> solved = robot.inverse(robot.forward(q), seed=q + 0.05)
    /// >>> bool(np.abs(robot.forward(solved) - robot.forward(q)).max() < 1e-9)
    /// True
    #[pyo3(signature = (target, seed, rest=None, tolerance=1e-9, iterations=200))]
    fn inverse<'py>(
        &self,
        py: Python<'py>,
        target: Array<'_>,
        seed: Array<'_>,
        rest: Option<Array<'_>>,
        tolerance: f64,
        iterations: usize,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let target = isometry("target", &transforms("target", &target, 0)?)?;
        let seed = joints("seed", &seed, self.chain.dof())?;
        let rest = self.rest(rest)?;
        let options = options(tolerance, iterations)?;
        let chain = &self.chain;
        let solved = py
            .detach(|| inverse(chain, &target, &seed, &rest, &options))
            .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
        Ok(PyArray1::from_vec(py, solved))
    }

    /// Each of ``targets`` solved as ``inverse`` does, from the previous
    /// sample's solution (the first from ``seed``), with the GIL released.
    ///
    /// Args:
    ///     targets: the tool's poses, shape (m, 4, 4).
    ///     seed: the joint positions the first sample starts from.
    ///     rest: the posture the null space pulls toward.
    ///     tolerance: the position (m) and orientation (rad) error to reach.
    ///     iterations: the most iterations per sample.
    ///     on_failure: ``"raise"``: a sample that does not converge is a
    ///         ``RuntimeError`` naming it; ``"nan"``: its row is NaN and the
    ///         next sample starts from the last solution.
    ///
    /// Returns:
    ///     numpy.ndarray: the joint positions, shape (m, dof).
    ///
    /// Raises:
    ///     RuntimeError: a sample that does not converge (with ``"raise"``).
    ///     ValueError: a wrong shape or length, a value that is not finite.
    ///
    /// >>> import numpy as np, primo
    /// >>> robot = primo.Robot.lwr4()
    /// >>> q = np.array([0.3, 0.6, -0.2, -1.2, 0.4, 0.7, -0.5])
    /// >>> path = robot.forward_many(q + np.linspace(0, 0.1, 4)[:, None])
    /// >>> robot.inverse_path(path, seed=q).shape
    /// (4, 7)
    #[pyo3(signature = (targets, seed, rest=None, tolerance=1e-9, iterations=200, on_failure="raise"))]
    #[allow(clippy::too_many_arguments)] // inverse's keywords, and what to do on a failure
    fn inverse_path<'py>(
        &self,
        py: Python<'py>,
        targets: Array<'_>,
        seed: Array<'_>,
        rest: Option<Array<'_>>,
        tolerance: f64,
        iterations: usize,
        on_failure: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let dof = self.chain.dof();
        let values = transforms("targets", &targets, 1)?;
        let m = values.len() / 16;
        if m > MAX_SAMPLES {
            return Err(invalid(format!(
                "targets: {m} samples, at most {MAX_SAMPLES}"
            )));
        }
        let poses = values
            .chunks(16)
            .enumerate()
            .map(|(i, t)| isometry(&format!("targets[{i}]"), t))
            .collect::<PyResult<Vec<_>>>()?;
        let seed = joints("seed", &seed, dof)?;
        let rest = self.rest(rest)?;
        let options = options(tolerance, iterations)?;
        let nan = match on_failure {
            "raise" => false,
            "nan" => true,
            other => {
                return Err(invalid(format!(
                    "on_failure: `{other}`, expected \"raise\" or \"nan\""
                )));
            }
        };
        let chain = &self.chain;
        let solved = py.detach(|| {
            let mut out = Vec::with_capacity(m * dof);
            let mut from = seed;
            for (i, target) in poses.iter().enumerate() {
                match inverse(chain, target, &from, &rest, &options) {
                    Ok(q) => {
                        out.extend_from_slice(&q);
                        from = q;
                    }
                    Err(_) if nan => out.extend(std::iter::repeat_n(f64::NAN, dof)),
                    Err(e) => return Err(format!("targets[{i}] (of {m}): {e}")),
                }
            }
            Ok(out)
        });
        let solved = solved.map_err(PyRuntimeError::new_err)?;
        Ok(PyArray1::from_vec(py, solved).reshape([m, dof])?.into_any())
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let class = py.get_type::<Robot>();
        let robot = slf.get();
        match &robot.source {
            Source::Lwr4 => {
                PyTuple::new(py, [class.getattr("lwr4")?, PyTuple::empty(py).into_any()])
            }
            Source::Urdf {
                file,
                text,
                base,
                tip,
                tool,
                limits,
            } => {
                let tool = match tool {
                    Some(m) => Some(PyArray1::from_slice(py, m).reshape([4, 4])?),
                    None => None,
                };
                let dict = PyDict::new(py);
                for (name, triple) in limits {
                    dict.set_item(name, *triple)?;
                }
                let args = (
                    text.as_str(),
                    base.as_deref(),
                    tip.as_deref(),
                    tool,
                    dict,
                    file.as_str(),
                )
                    .into_pyobject(py)?;
                PyTuple::new(py, [class.getattr("from_urdf_text")?, args.into_any()])
            }
        }
    }

    fn __eq__(&self, other: &Bound<'_, PyAny>) -> bool {
        other
            .cast::<Robot>()
            .is_ok_and(|o| o.get().chain == self.chain)
    }

    fn __repr__(&self) -> String {
        format!(
            "Robot({:?}, base={:?}, tip={:?}, joints={:?})",
            self.chain.robot,
            self.chain.base,
            self.chain.tip,
            self.chain.names()
        )
    }
}
