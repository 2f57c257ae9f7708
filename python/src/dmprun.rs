//! `DmpRun`: a discrete DMP executed one control step at a time, open or
//! closed loop (a measured state fed back, coupling terms added). It
//! pickles as its DMP file, how it began and the core run's state
//! (`Run::state`), so the copy goes on as the original, bit for bit.

use numpy::PyArray1;
use pyo3::prelude::*;
use pyo3::types::PyTuple;

use primo_core::coupling::PhaseStop;
use primo_core::dmp::Run;
use primo_skill::HOST_MAX_DOF;
use primo_skill::dmpfile::{DmpFile, Prepared};

use crate::arrays::{Array, out, per_column, positive, vector};
use crate::errors::{core, invalid, skill};

/// How a run began: `Dmp.stepper`'s arguments, checked (per column).
#[derive(Clone)]
pub(crate) struct Begun {
    pub tau: Option<f32>,
    pub start: Option<Vec<f32>>,
    pub goal: Option<Vec<f32>>,
}

/// A discrete DMP executed one control step at a time (`Dmp.stepper()`):
/// open loop it gives the same samples as `Dmp.run`, bit for bit. Closed
/// loop, each `step` may take the robot's measured `position` and
/// `velocity` (the run goes on from them; its own values change nothing)
/// and a `coupling` acceleration for that step. Pickles and copies (the
/// copy continues bit for bit).
///
/// >>> import copy, numpy as np, primo
/// >>> t = np.linspace(0.0, 1.0, 101)
/// >>> dmp = primo.Dmp.fit(t, t * t * (3 - 2 * t), names=["x"], kernels=20)
/// >>> open_loop = dmp.run(dt=0.01)[1]
/// >>> run = dmp.stepper()
/// >>> fed_back = [run.step(0.01, position=run.position, velocity=run.velocity)
/// ...             for _ in range(100)]
/// >>> bool((np.array(fed_back) == open_loop[1:]).all())
/// True
/// >>> twin = copy.copy(run)
/// >>> bool((twin.step(0.01) == run.step(0.01)).all())
/// True
#[pyclass(module = "primo._primo")]
#[derive(Clone)]
pub struct DmpRun {
    file: DmpFile,
    begun: Begun,
    run: Run<HOST_MAX_DOF>,
    prepared: Prepared,
}

impl DmpRun {
    /// The run of `file` from the beginning `begun`.
    pub(crate) fn new(file: DmpFile, begun: Begun) -> PyResult<DmpRun> {
        let prepared = file
            .prepare(begun.tau, begun.start.as_deref(), begun.goal.as_deref())
            .map_err(skill)?;
        let run = file.dmp.start(&prepared.execution).map_err(core)?;
        Ok(DmpRun {
            file,
            begun,
            run,
            prepared,
        })
    }

    /// Refuses closed-loop values for DMPs with orientation columns,
    /// whose columns are not their DoFs.
    fn plain(&self, what: &str) -> PyResult<()> {
        if self.prepared.is_plain() {
            Ok(())
        } else {
            Err(invalid(format!(
                "{what}: for DMPs without orientation columns only"
            )))
        }
    }

    /// One step, closed loop if told a measured state or a coupling; all
    /// or nothing.
    fn advance(
        &mut self,
        dt: f32,
        position: Option<&[f32]>,
        velocity: Option<&[f32]>,
        coupling: Option<&[f32]>,
    ) -> PyResult<()> {
        let dmp = &self.file.dmp;
        let mut run = self.run.clone();
        run.measured(dmp, position, velocity).map_err(core)?;
        match coupling {
            Some(c) => run.step_coupled(dmp, dt, c),
            None => run.step(dmp, dt),
        }
        .map_err(core)?;
        self.run = run;
        Ok(())
    }
}

#[pymethods]
impl DmpRun {
    /// Advances by `dt` seconds and returns the position, per column.
    ///
    /// Closed loop (DMPs without orientation columns): `position` and
    /// `velocity` (per second), one value per column, are the robot's
    /// measured state now; the step starts from them instead of the run's
    /// own (movement_primitives' `step(last_y, last_yd)`; either may be
    /// left out, and the run's own values change nothing, bit for bit).
    /// `coupling`: an acceleration per column (units per s²) added over
    /// this step, `τ²ÿ = K(g − y) − ατẏ + f + τ²·coupling`, where
    /// obstacle-avoidance or joint-limit terms enter.
    ///
    /// Phase stopping (Ijspeert et al. 2013): with `phase_stop` (the gain
    /// `k` ≥ 0, per squared unit) and `measured`, the robot's position per
    /// column, the movement's clock advances by `dt/(1 + k‖measured −
    /// commanded‖²)` instead of `dt`, so the command waits while the robot
    /// lags it; `time` is the movement's clock.
    ///
    /// Returns: the position after the step, per column (float64).
    /// Raises: `ValueError` for a `dt` that is not positive and finite, a
    /// wrong length, a non-finite value, a position beyond ±1e6, or
    /// closed-loop values for a DMP with orientation columns; the run is
    /// then unchanged.
    ///
    /// >>> import numpy as np, primo
    /// >>> t = np.linspace(0.0, 1.0, 101)
    /// >>> run = primo.Dmp.fit(t, t, names=["x"], kernels=10).stepper()
    /// >>> x = run.step(0.01, position=[0.5], velocity=[0.0])  # on from the robot
    /// >>> bool(abs(x[0] - 0.5) < 0.01)
    /// True
    /// >>> _ = run.step(0.01, coupling=[2.0])
    /// >>> before = run.time
    /// >>> _ = run.step(0.01, measured=[0.0], phase_stop=100.0)  # the robot lags
    /// >>> bool(run.time - before < 0.01)
    /// True
    #[allow(clippy::too_many_arguments)] // keyword arguments
    #[pyo3(signature = (dt, position=None, velocity=None, coupling=None, measured=None,
                        phase_stop=None))]
    fn step<'py>(
        &mut self,
        py: Python<'py>,
        dt: f64,
        position: Option<Array<'_>>,
        velocity: Option<Array<'_>>,
        coupling: Option<Array<'_>>,
        measured: Option<Array<'_>>,
        phase_stop: Option<f64>,
    ) -> PyResult<Bound<'py, PyArray1<f64>>> {
        let mut dt = positive("dt", Some(dt))?.unwrap_or(0.001);
        if position.is_some() || velocity.is_some() || coupling.is_some() || measured.is_some() {
            self.plain("position, velocity, coupling, measured")?;
        }
        let names = &self.file.names;
        let position = per_column("position", position, names)?;
        let velocity = per_column("velocity", velocity, names)?;
        let coupling = per_column("coupling", coupling, names)?;
        let measured = per_column("measured", measured, names)?;
        match (phase_stop, measured) {
            (Some(k), Some(measured)) => {
                let stop = PhaseStop::new(k as f32)
                    .map_err(|e| invalid(format!("phase_stop: {k}: {e}")))?;
                dt = stop
                    .step(dt, self.run.position(), &measured)
                    .map_err(core)?;
            }
            (None, None) => {}
            _ => return Err(invalid("phase_stop and measured: give both or neither")),
        }
        self.advance(
            dt,
            position.as_deref(),
            velocity.as_deref(),
            coupling.as_deref(),
        )?;
        Ok(out(py, &self.prepared.columns(self.run.position())))
    }

    /// The current position, per column.
    #[getter]
    fn position<'py>(&self, py: Python<'py>) -> Bound<'py, PyArray1<f64>> {
        out(py, &self.prepared.columns(self.run.position()))
    }

    /// The current velocity per second, per column (DMPs without
    /// orientation columns).
    #[getter]
    fn velocity<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyArray1<f64>>> {
        self.plain("velocity")?;
        let s = self.run.sample();
        Ok(out(py, &s.velocity[..self.file.dmp.dof()]))
    }

    /// Seconds since the start.
    #[getter]
    fn time(&self) -> f64 {
        f64::from(self.run.time())
    }

    /// The phase `t/τ`, at most 1.
    #[getter]
    fn phase(&self) -> f64 {
        f64::from(self.run.phase())
    }

    /// A new goal from the next step on (DMPs without orientation columns).
    ///
    /// Args:
    ///     goal: the new goal, per column.
    ///
    /// Raises:
    ///     ValueError: a DMP with orientation columns, a wrong length or a
    ///         non-finite value.
    ///
    /// >>> import numpy as np, primo
    /// >>> run = primo.Dmp.fit(np.linspace(0, 1, 11), np.linspace(0, 1, 11)).stepper()
    /// >>> run.set_goal([2.0])
    /// >>> while run.time < 3.0:
    /// ...     x = run.step(0.01)
    /// >>> round(float(x[0]), 2)
    /// 2.0
    fn set_goal(&mut self, goal: Array<'_>) -> PyResult<()> {
        self.plain("set_goal")?;
        let goal = vector("goal", &goal, false)?;
        self.run.set_goal(&self.file.dmp, &goal).map_err(core)
    }

    fn __reduce__<'py>(slf: &Bound<'py, Self>) -> PyResult<Bound<'py, PyTuple>> {
        let py = slf.py();
        let this = slf.borrow();
        let json = this.file.to_json().map_err(|e| invalid(e.to_string()))?;
        let Begun { tau, start, goal } = this.begun.clone();
        let args = (json, tau, start, goal).into_pyobject(py)?;
        let state: Vec<f32> = this.run.state().collect();
        PyTuple::new(
            py,
            [
                py.get_type::<DmpRun>().getattr("_restore")?,
                args.into_any(),
                state.into_pyobject(py)?.into_any(),
            ],
        )
    }

    /// Unpickles: the run of the DMP file `json` from its beginning (the
    /// state follows by `__setstate__`).
    #[staticmethod]
    fn _restore(
        json: &str,
        tau: Option<f32>,
        start: Option<Vec<f32>>,
        goal: Option<Vec<f32>>,
    ) -> PyResult<DmpRun> {
        let file = DmpFile::parse("the pickled run's DMP", json).map_err(skill)?;
        DmpRun::new(file, Begun { tau, start, goal })
    }

    fn __setstate__(&mut self, state: Vec<f32>) -> PyResult<()> {
        self.run = Run::from_state(&self.file.dmp, &state)
            .map_err(|e| invalid(format!("DmpRun: not a state this run pickled: {e}")))?;
        Ok(())
    }

    fn __copy__(&self) -> DmpRun {
        self.clone()
    }

    fn __deepcopy__(&self, _memo: &Bound<'_, PyAny>) -> DmpRun {
        self.clone()
    }
}
