//! Executing a DMP: a [`Run`] advanced one control step at a time, and
//! the [`Trajectory`] of a whole execution on a time grid. Each step is
//! the spring's exact solution with the forcing term held at its mid-step
//! value ([`crate::spring`]).

use super::model::{Dmp, Execution};
use super::options::{MAX_ABS_POSITION, check_tau};
#[cfg(feature = "global-scaling")]
use super::turn::Turn;
use crate::Error;
use crate::coupling::Coupling;
use crate::error::{check_bounded, check_finite, check_len, check_positive};
use crate::spring::{add_compensated, transition_step};

/// One point of an executed trajectory.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Sample<const D: usize> {
    /// Time since the start in seconds.
    pub time: f32,
    /// Position; the first [`Dmp::dof`] entries are valid.
    pub position: [f32; D],
    /// Velocity per second.
    pub velocity: [f32; D],
    /// Acceleration per second².
    pub acceleration: [f32; D],
}

impl<const D: usize, const K: usize> Dmp<D, K> {
    fn check_execution(&self, exec: &Execution<D>) -> Result<(), Error> {
        check_len("execution start", self.dof(), exec.start.len())?;
        check_len("execution goal", self.dof(), exec.goal.len())?;
        check_bounded(
            &exec.start,
            MAX_ABS_POSITION,
            "execution start beyond ±1e6, the bound on any position",
        )?;
        check_bounded(
            &exec.goal,
            MAX_ABS_POSITION,
            "execution goal beyond ±1e6, the bound on any position",
        )?;
        check_tau(
            exec.tau,
            "execution tau must be finite and at least 0.001 s",
        )?;
        super::model::check_goal_velocity(&exec.goal_velocity, self.dof())?;
        super::model::check_goal_travel(&exec.goal_velocity, exec.tau)
    }

    /// Starts an execution at rest at `exec.start`; advance it with
    /// [`Run::step`].
    pub fn start(&self, exec: &Execution<D>) -> Result<Run<D>, Error> {
        self.check_execution(exec)?;
        let mut run = Run {
            dof: self.dof(),
            tau: exec.tau,
            alpha: self.alpha,
            start: [0.0; D],
            goal: [0.0; D],
            amplitude: [1.0; D],
            #[cfg(feature = "global-scaling")]
            turn: None,
            y: [0.0; D],
            y_carry: [0.0; D],
            z: [0.0; D],
            force: [0.0; D],
            phase: 0.0,
            phase_carry: 0.0,
            time: 0.0,
            time_carry: 0.0,
            step_dt: f32::NAN,
            transition: [0.0; 4],
            goal_velocity: [0.0; D],
        };
        for (dst, src) in run.start.iter_mut().zip(&exec.start) {
            *dst = *src;
        }
        for (dst, src) in run.goal_velocity.iter_mut().zip(&exec.goal_velocity) {
            *dst = *src;
        }
        run.y = run.start;
        run.set_goal(self, &exec.goal)?;
        // Forcing at s = 0 gives the initial acceleration.
        self.forcing(0.0, &mut run.force);
        run.scale_force();
        Ok(run)
    }

    /// The whole trajectory from `t = 0` to `t = τ` inclusive at step `dt`:
    /// `round(τ/dt) + 1` samples when `τ` is a multiple of `dt`, otherwise a
    /// last, shorter step lands exactly on `τ`.
    pub fn trajectory(&self, exec: &Execution<D>, dt: f32) -> Result<Trajectory<'_, D, K>, Error> {
        check_positive(dt, "dt must be finite and > 0")?;
        let run = self.start(exec)?;
        let ratio = exec.tau / dt;
        let whole = libm::roundf(ratio);
        // A τ within 0.1% of one step (or f32's resolution of the ratio) of
        // a whole number of steps ends on the grid; otherwise (also when
        // τ < dt) a last, shorter step lands on τ.
        let tolerance = 1e-3f32.max(4.0 * f32::EPSILON * ratio);
        let (full_steps, last_dt) = if whole >= 1.0 && libm::fabsf(ratio - whole) <= tolerance {
            (whole as u32, 0.0)
        } else {
            let full = libm::floorf(ratio);
            (full as u32, exec.tau - full * dt)
        };
        if !(ratio < 1e9) || !(exec.tau + dt).is_finite() {
            return Err(Error::OutOfRange("tau / dt must be below 1e9 steps"));
        }
        Ok(Trajectory {
            dmp: self,
            run,
            dt,
            full_steps,
            last_dt,
            index: 0,
            done: false,
        })
    }
}

/// An execution in progress, advanced one control step at a time.
///
/// It does not borrow the DMP, so a control loop (or a coprocessor) can hold
/// both side by side; [`Run::step`] takes the DMP each time.
#[derive(Debug, Clone, PartialEq)]
pub struct Run<const D: usize> {
    dof: usize,
    tau: f32,
    alpha: f32,
    start: [f32; D],
    goal: [f32; D],
    amplitude: [f32; D],
    /// Global scaling's turn and stretch ([`Turn`]), if global.
    #[cfg(feature = "global-scaling")]
    turn: Option<Turn<D>>,
    y: [f32; D],
    /// Compensation of `y` (Kahan): what its sums lost to rounding.
    y_carry: [f32; D],
    z: [f32; D],
    force: [f32; D],
    phase: f32,
    phase_carry: f32,
    time: f32,
    time_carry: f32,
    step_dt: f32,
    transition: [f32; 4],
    /// The velocity at the goal at `τ` (all 0: at rest).
    goal_velocity: [f32; D],
}

impl<const D: usize> Run<D> {
    /// Advances by `dt` seconds (> 0).
    pub fn step<const K: usize>(&mut self, dmp: &Dmp<D, K>, dt: f32) -> Result<(), Error> {
        check_positive(dt, "dt must be finite and > 0")?;
        check_len("DMP DoF", self.dof, dmp.dof())?;
        if !(self.time + dt).is_finite() {
            return Err(Error::OutOfRange("time would overflow"));
        }
        self.advance(dmp, dt);
        Ok(())
    }

    fn advance<const K: usize>(&mut self, dmp: &Dmp<D, K>, dt: f32) {
        let u = dt / self.tau;
        if dt != self.step_dt {
            self.transition = transition_step(self.alpha, u);
            self.step_dt = dt;
        }
        let [d00, p01, p10, p11] = self.transition;
        let middle = self.phase + 0.5 * u;
        dmp.forcing(middle, &mut self.force);
        self.scale_force();
        let stiffness = self.alpha * self.alpha / 4.0;
        // A goal velocity moves the goal at it until τ, `g − ġτ(1 − s)`,
        // and feeds it forward (`ατġ` on the spring, `4τġ/α` on its rest
        // point): the run then reaches the goal at that velocity. After τ
        // the goal holds still. Both in units of τ: `ġτ` is bounded
        // (`check_goal_travel`), `τ` alone may be huge.
        let (lead, ahead) = match middle < 1.0 {
            true => (1.0 - middle, 4.0 / self.alpha),
            false => (0.0, 0.0),
        };
        for (((((y, carry), z), f), g), v) in self
            .y
            .iter_mut()
            .zip(self.y_carry.iter_mut())
            .zip(self.z.iter_mut())
            .zip(self.force.iter())
            .zip(self.goal)
            .zip(self.goal_velocity)
            .take(self.dof)
        {
            let g = match v {
                0.0 => g,
                v => g + v * self.tau * (ahead - lead),
            };
            let equilibrium = g + *f / stiffness;
            let e = (*y - equilibrium) - *carry;
            // The position moves by a small step each cycle: added as a
            // step, compensated, so thousands of cycles do not accumulate
            // f32 rounding (a random walk of ~1e-6 over 1000 steps).
            add_compensated(y, carry, d00 * e + p01 * *z);
            *z = p10 * e + p11 * *z;
        }
        if self.phase < 1.0 {
            add_compensated(&mut self.phase, &mut self.phase_carry, u);
            if self.phase >= 1.0 {
                (self.phase, self.phase_carry) = (1.0, 0.0);
            }
        }
        add_compensated(&mut self.time, &mut self.time_carry, dt);
    }

    /// [`Run::step`] with a coupling term: an additional acceleration per
    /// DoF (units per s², `dof` values) held over the step, as in
    /// `τ²ÿ = K(g − y) − ατẏ + f + τ²·coupling` (obstacle avoidance, joint
    /// limits, a controller's correction all enter this way). The step's
    /// exact spring solution takes it as its equilibrium moved by
    /// `τ²·coupling/K`; a DoF whose coupling is 0 steps as [`Run::step`]
    /// does, bit for bit.
    pub fn step_coupled<const K: usize>(
        &mut self,
        dmp: &Dmp<D, K>,
        dt: f32,
        coupling: &[f32],
    ) -> Result<(), Error> {
        check_len("coupling", self.dof, coupling.len())?;
        check_finite(coupling, "coupling")?;
        let shift = self.tau * self.tau / (self.alpha * self.alpha / 4.0);
        let goal = self.goal;
        for (g, &c) in self.goal.iter_mut().zip(coupling) {
            if c != 0.0 {
                *g += shift * c;
            }
        }
        // The goal itself is untouched: the shift lasts this step only.
        let stepped = check_bounded(
            self.goal.get(..self.dof).unwrap_or(&[]),
            MAX_ABS_POSITION,
            "coupling moves the rest point beyond ±1e6, the bound on any position",
        )
        .and_then(|()| self.step(dmp, dt));
        self.goal = goal;
        stepped
    }

    /// [`Run::step_coupled`] with the sum of `terms`, each computed from
    /// the run's position and velocity before the step.
    pub fn step_with<const K: usize>(
        &mut self,
        dmp: &Dmp<D, K>,
        dt: f32,
        terms: &[&dyn Coupling],
    ) -> Result<(), Error> {
        let now = self.sample();
        let dof = self.dof;
        let (position, velocity) = match (now.position.get(..dof), now.velocity.get(..dof)) {
            (Some(p), Some(v)) => (p, v),
            _ => return Err(Error::BadState("run DoF beyond its capacity")),
        };
        let mut coupling = [0.0f32; D];
        let acceleration = coupling.get_mut(..dof).unwrap_or(&mut []);
        for term in terms {
            term.add_to(position, velocity, acceleration)?;
        }
        self.step_coupled(dmp, dt, acceleration)
    }

    /// Feeds back a measured state, for closed-loop execution (as
    /// movement_primitives' `step(last_y, last_yd)`): the `position` and/or
    /// the `velocity` (per second), `dof` values each, replace the run's
    /// from here on. A value equal to the run's own ([`Run::position`],
    /// [`Run::sample`]'s velocity) changes nothing, its rounding
    /// compensation kept: feeding the run's own state back is the
    /// open-loop run, bit for bit. Nothing changes if either is refused.
    pub fn measured<const K: usize>(
        &mut self,
        dmp: &Dmp<D, K>,
        position: Option<&[f32]>,
        velocity: Option<&[f32]>,
    ) -> Result<(), Error> {
        check_len("DMP DoF", self.dof, dmp.dof())?;
        if let Some(y) = position {
            check_len("measured position", self.dof, y.len())?;
            check_bounded(
                y,
                MAX_ABS_POSITION,
                "measured position beyond ±1e6, the bound on any position",
            )?;
        }
        if let Some(v) = velocity {
            check_len("measured velocity", self.dof, v.len())?;
            check_finite(v, "measured velocity")?;
            if !v.iter().all(|v| (v * self.tau).is_finite()) {
                return Err(Error::OutOfRange("measured velocity × τ overflows"));
            }
        }
        for ((y, carry), &m) in self
            .y
            .iter_mut()
            .zip(self.y_carry.iter_mut())
            .zip(position.unwrap_or(&[]))
        {
            if *y != m {
                (*y, *carry) = (m, 0.0);
            }
        }
        for (z, &m) in self.z.iter_mut().zip(velocity.unwrap_or(&[])) {
            // `sample` reports z/τ: a velocity equal to it keeps z's bits.
            if *z / self.tau != m {
                *z = m * self.tau;
            }
        }
        Ok(())
    }

    /// Length of [`Run::state`].
    pub const STATE_LEN: usize = 12 + 8 * D;

    /// The whole state as [`Run::STATE_LEN`] numbers, to keep it and go on
    /// later with [`Run::from_state`], bit for bit. Its layout is not an
    /// interface: read it back with the same primo.
    pub fn state(&self) -> impl Iterator<Item = f32> + '_ {
        let scalars = [
            self.dof as f32,
            self.tau,
            self.alpha,
            self.phase,
            self.phase_carry,
            self.time,
            self.time_carry,
            self.step_dt,
        ];
        scalars
            .into_iter()
            .chain(self.transition)
            .chain(self.start)
            .chain(self.goal)
            .chain(self.amplitude)
            .chain(self.y)
            .chain(self.y_carry)
            .chain(self.z)
            .chain(self.force)
            .chain(self.goal_velocity)
    }

    /// The run [`Run::state`] gave, of `dmp`. Checked so that no state
    /// makes a later step panic or overflow: its length, its DoF (the
    /// DMP's), finite values (the step size remembered may be NaN: none
    /// yet) and `τ`.
    pub fn from_state<const K: usize>(dmp: &Dmp<D, K>, state: &[f32]) -> Result<Run<D>, Error> {
        check_len("run state", Self::STATE_LEN, state.len())?;
        let (head, arrays) = state.split_at_checked(12).ok_or(Error::Length {
            what: "run state",
            expected: Self::STATE_LEN,
            found: state.len(),
        })?;
        let [
            dof,
            tau,
            alpha,
            phase,
            phase_carry,
            time,
            time_carry,
            step_dt,
            t0,
            t1,
            t2,
            t3,
        ] = <[f32; 12]>::try_from(head).map_err(|_| Error::OutOfRange("run state"))?;
        if dof != dmp.dof() as f32 {
            return Err(Error::OutOfRange("run state: of a DMP of another DoF"));
        }
        let scalars = [alpha, phase, phase_carry, time, time_carry, t0, t1, t2, t3];
        check_finite(&scalars, "run state")?;
        check_finite(arrays, "run state")?;
        check_tau(tau, "run state: τ must be finite and at least 0.001 s")?;
        let mut chunks = arrays.chunks_exact(D.max(1)).map(<[f32; D]>::try_from);
        let mut next = || match chunks.next() {
            Some(Ok(a)) => Ok(a),
            _ => Err(Error::OutOfRange("run state")),
        };
        let mut run = Run {
            dof: dmp.dof(),
            tau,
            alpha,
            step_dt,
            transition: [t0, t1, t2, t3],
            phase,
            phase_carry,
            time,
            time_carry,
            start: next()?,
            goal: next()?,
            amplitude: next()?,
            y: next()?,
            y_carry: next()?,
            z: next()?,
            force: next()?,
            goal_velocity: next()?,
            #[cfg(feature = "global-scaling")]
            turn: None,
        };
        // Global scaling's turn follows from the DMP, start and goal, as
        // the amplitudes do: set again, both come back bit for bit.
        super::model::check_goal_travel(&run.goal_velocity, tau)?;
        let goal = run.goal;
        run.set_goal(dmp, goal.get(..run.dof).unwrap_or(&[]))?;
        Ok(run)
    }

    /// The forcing term as executed: per DoF by its amplitude, then
    /// globally turned and stretched (identity unless global).
    fn scale_force(&mut self) {
        for (f, a) in self.force.iter_mut().zip(self.amplitude) {
            *f *= a;
        }
        #[cfg(feature = "global-scaling")]
        if let Some(turn) = &self.turn {
            turn.apply(&mut self.force);
        }
    }

    /// Moves the current position to `y` (one value per DoF), keeping the
    /// velocity: the same motion seen from a new origin.
    pub(crate) fn rebase<const K: usize>(
        &mut self,
        dmp: &Dmp<D, K>,
        y: &[f32],
    ) -> Result<(), Error> {
        check_len("position", self.dof, y.len())?;
        check_len("DMP DoF", self.dof, dmp.dof())?;
        check_bounded(
            y,
            MAX_ABS_POSITION,
            "position beyond ±1e6, the bound on any position",
        )?;
        for ((dst, carry), src) in self.y.iter_mut().zip(self.y_carry.iter_mut()).zip(y) {
            (*dst, *carry) = (*src, 0.0);
        }
        Ok(())
    }

    /// Changes the goal during execution; amplitude-scaled DoFs rescale their
    /// forcing term to the new `g − y0` from the next step on.
    pub fn set_goal<const K: usize>(&mut self, dmp: &Dmp<D, K>, goal: &[f32]) -> Result<(), Error> {
        check_len("goal", self.dof, goal.len())?;
        check_len("DMP DoF", self.dof, dmp.dof())?;
        check_bounded(
            goal,
            MAX_ABS_POSITION,
            "goal beyond ±1e6, the bound on any position",
        )?;
        let global = cfg!(feature = "global-scaling") && dmp.reference().is_some();
        for (d, (dst, &g)) in self.goal.iter_mut().zip(goal).enumerate() {
            *dst = g;
            if let (Some(a), Some(&y0)) = (self.amplitude.get_mut(d), self.start.get(d)) {
                *a = if dmp.is_scaled(d) && !global {
                    g - y0
                } else {
                    1.0
                };
            }
        }
        #[cfg(feature = "global-scaling")]
        if let Some(reference) = dmp.reference() {
            let (mut span, mut group) = ([0.0f32; D], [false; D]);
            for (d, (s, g)) in span.iter_mut().zip(group.iter_mut()).enumerate() {
                *g = d < self.dof && dmp.is_scaled(d);
                if *g {
                    *s = self.goal.get(d).copied().unwrap_or(0.0)
                        - self.start.get(d).copied().unwrap_or(0.0);
                }
            }
            self.turn = Some(Turn::between(&group, reference, &span));
        }
        Ok(())
    }

    /// Seconds since the start.
    pub fn time(&self) -> f32 {
        self.time
    }

    /// Phase `s = t/τ`, saturated at 1.
    pub fn phase(&self) -> f32 {
        self.phase
    }

    /// Current position (`dof` values).
    pub fn position(&self) -> &[f32] {
        self.y.get(..self.dof).unwrap_or(&[])
    }

    /// The current point: time, position, velocity and acceleration (the
    /// latter with the forcing term of the last step, held over the step).
    pub fn sample(&self) -> Sample<D> {
        let mut s = Sample {
            time: self.time,
            position: self.y,
            velocity: [0.0; D],
            acceleration: [0.0; D],
        };
        let stiffness = self.alpha * self.alpha / 4.0;
        let tau2 = self.tau * self.tau;
        for d in 0..self.dof.min(D) {
            if let (Some(v), Some(acc), Some(y), Some(z), Some(g), Some(f)) = (
                s.velocity.get_mut(d),
                s.acceleration.get_mut(d),
                self.y.get(d),
                self.z.get(d),
                self.goal.get(d),
                self.force.get(d),
            ) {
                *v = z / self.tau;
                *acc = (stiffness * (g - y) - self.alpha * z + f) / tau2;
            }
        }
        s
    }
}

/// Iterator over a whole execution; see [`Dmp::trajectory`].
#[derive(Debug, Clone)]
pub struct Trajectory<'a, const D: usize, const K: usize> {
    dmp: &'a Dmp<D, K>,
    run: Run<D>,
    dt: f32,
    full_steps: u32,
    last_dt: f32,
    index: u32,
    done: bool,
}

impl<const D: usize, const K: usize> Trajectory<'_, D, K> {
    /// The next sample's time and position (one value per DoF):
    /// [`Iterator::next`] without the velocity and acceleration, for a
    /// caller that only wants where the movement goes.
    pub fn next_position(&mut self) -> Option<(f32, &[f32])> {
        let time = self.step()?;
        Some((time, self.run.position()))
    }

    /// Advances to the next sample, if any; its time.
    fn step(&mut self) -> Option<f32> {
        if self.done {
            return None;
        }
        if self.index > 0 {
            let dt = if self.index <= self.full_steps {
                self.dt
            } else {
                self.last_dt
            };
            self.run.advance(self.dmp, dt);
        }
        // Report exact grid times rather than the accumulated clock.
        let mut time = if self.index <= self.full_steps {
            self.index as f32 * self.dt
        } else {
            self.run.tau
        };
        let at_end = if self.last_dt > 0.0 {
            self.index > self.full_steps
        } else {
            self.index == self.full_steps
        };
        if at_end {
            time = self.run.tau;
            self.done = true;
        }
        self.index += 1;
        Some(time)
    }
}

impl<const D: usize, const K: usize> Iterator for Trajectory<'_, D, K> {
    type Item = Sample<D>;
    fn next(&mut self) -> Option<Sample<D>> {
        let time = self.step()?;
        let mut sample = self.run.sample();
        sample.time = time;
        Some(sample)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        // Samples 0..=full_steps on the grid, then the shorter last step's.
        let total = u64::from(self.full_steps) + 1 + u64::from(self.last_dt > 0.0);
        let left = match self.done {
            true => 0,
            false => usize::try_from(total.saturating_sub(u64::from(self.index))).unwrap_or(0),
        };
        (left, Some(left))
    }
}
