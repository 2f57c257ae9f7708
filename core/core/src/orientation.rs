//! Orientation DMPs on unit quaternions, and Cartesian DMPs: a position
//! and an orientation sharing one phase.
//!
//! # Formulation
//!
//! An orientation `q(t)` is expressed by its rotation vector relative to
//! the goal, `e = log(q ⊗ ḡ)` (axis × angle, rad), and `e` is a 3-DoF
//! [`Dmp`] whose goal is `0`; the executed orientation is `exp(e) ⊗ g`.
//! This is the logarithmic-space formulation of Koutras and Doulgeri
//! (2020) for the orientation DMP of Ude, Nemec, Petrič and Morimoto
//! (2014): the same transformation system on `log(q ⊗ ḡ)`, but linear in
//! the weights, so
//! - every sample is a unit quaternion by construction (renormalized
//!   against rounding), whatever the weights, `dt` or `τ`;
//! - it reaches the goal orientation whenever the 3-DoF DMP reaches `0`,
//!   which it does for any weights within the bounds (see [`crate::dmp`]);
//! - the fit is the position least-squares fit of [`Dmp::fit`], with
//!   nothing differentiated on the sphere.
//!
//! The forcing term is not amplitude-scaled ([`Scaling::Never`]): scaling
//! each axis of a rotation vector would not be a rotation.
//!
//! A recording's quaternions are normalized, and each sample's rotation
//! vector is the one of its equivalents (`n (θ + 2πk)` for any `k`, the
//! same for `q` and `−q`) that continues the previous sample's
//! ([`unwrapped`]), so `e` is continuous along the movement however far it
//! turns: a sweep through 180°, a screw of three turns, a sign flip of the
//! tracker are no discontinuity. Where `|e|` crosses a multiple of 2π the
//! rotation vector is singular (every axis gives the same orientation);
//! there the coordinate is followed by damped Gauss–Newton steps, which
//! keep it continuous but follow a tilt across the turn's axis made there
//! only approximately (a turn about one axis is exact).
//!
//! A recording that turns further than that ([`ROTATION_VECTOR_CHART_LIMIT`],
//! 270° from its goal: a screw, a wrist's spin) is therefore charted by
//! swing and twist about its axis `n` ([`chart_axis`], the direction of its
//! summed turn): `q = exp(s) ⊗ exp(ψ n) ⊗ g` with the coordinates
//! `e = s + ψ n` (`s ⊥ n`), the twist `ψ` counting every turn. This chart
//! is singular only where the swing reaches 180°, so a wobble of the axis
//! is followed at every turn; it is the rotation vector's wherever the
//! movement is a turn about `n` alone. Everything above holds in it: the
//! goal is `e = 0`, every sample is a unit quaternion, and the map back is
//! periodic in `ψ`. [`OrientationDmp::axis`] says which chart a DMP uses.
//!
//! ```
//! use primo_core::dmp::FitOptions;
//! use primo_core::orientation::OrientationDmp;
//! use primo_core::quaternion::Quaternion;
//! // A yaw sweep from 170° to 190° in one second, through ±180°.
//! let t: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
//! let q: Vec<f32> = t
//!     .iter()
//!     .flat_map(|&t| {
//!         let yaw = (170.0 + 20.0 * t * t * (3.0 - 2.0 * t)).to_radians();
//!         Quaternion::exp([0.0, 0.0, yaw]).to_array()
//!     })
//!     .collect();
//! let dmp = OrientationDmp::<20>::fit(&t, &q, 20, &FitOptions::default())?;
//! let goal = Quaternion::exp([0.0, 0.0, 190f32.to_radians()]);
//! for (time, q) in dmp.trajectory(&dmp.execution(), 0.01)? {
//!     assert!((q.norm() - 1.0).abs() < 1e-6);
//!     // Never further from the goal than the 20° it starts at.
//!     let angle = 2.0 * q.dot(&goal).abs().min(1.0).acos().to_degrees();
//!     assert!(angle < 20.01, "{angle}° at {time} s");
//! }
//! let (_, end) = dmp.trajectory(&dmp.execution(), 0.01)?.last().unwrap();
//! assert!(end.dot(&goal).abs() > 1.0 - 1e-6);
//! # Ok::<(), primo_core::Error>(())
//! ```

use serde::{Deserialize, Serialize};

use crate::Error;
use crate::dmp::{Dmp, Execution, FitOptions, Run, Scaling};
use crate::quaternion::Quaternion;
use crate::vec3::{cross, dot, mix, norm};

/// Normalized quaternions of a recording (`[w, x, y, z]` rows).
fn rows(quaternions: &[f32]) -> impl DoubleEndedIterator<Item = Result<Quaternion, Error>> + '_ {
    quaternions.chunks_exact(4).map(|row| {
        Quaternion::from_array(core::array::from_fn(|k| row.get(k).copied().unwrap_or(0.0)))
            .normalized()
    })
}

/// Unwrapped log coordinates `log(q_i ⊗ ḡ)` of a recording (`[w, x, y,
/// z]` rows, any sign, any non-zero norm) relative to its last
/// orientation `g`, visited in order: `visit(e_i)`; returns `g`.
///
/// The start's coordinates are found from the goal backwards (the goal's
/// are 0), then each sample continues the previous one, so
/// a turn of any number of revolutions keeps its count.
pub fn unwrapped(
    quaternions: &[f32],
    visit: &mut dyn FnMut(&[f32; 3]),
) -> Result<Quaternion, Error> {
    continued(quaternions, &follow, visit)
}

/// A sample's coordinates continuing its neighbour's: `(q, goal, previous)`.
type Continue<'a> = &'a dyn Fn(&Quaternion, &Quaternion, &[f32; 3]) -> [f32; 3];

/// The coordinates of a recording relative to its last orientation, each
/// sample's `next(q, goal, previous)` continuing its neighbour's: from the
/// goal (0) back to the start, then forwards from there, visited in
/// order; returns the goal.
fn continued(
    quaternions: &[f32],
    next: Continue<'_>,
    visit: &mut dyn FnMut(&[f32; 3]),
) -> Result<Quaternion, Error> {
    crate::error::check_finite(quaternions, "quaternions")?;
    let goal = rows(quaternions)
        .next_back()
        .unwrap_or(Ok(Quaternion::IDENTITY))?;
    let mut e = [0.0; 3];
    for q in rows(quaternions).rev() {
        e = next(&q?, &goal, &e);
    }
    for q in rows(quaternions) {
        e = next(&q?, &goal, &e);
        visit(&e);
    }
    Ok(goal)
}

/// The log coordinates of a recording written to `out` (three per row),
/// as [`unwrapped`] visits them, the last row exactly 0; returns the goal.
pub fn log_coordinates(quaternions: &[f32], out: &mut [f32]) -> Result<Quaternion, Error> {
    let rows = quaternions.len() / 4;
    crate::error::check_len("quaternions", rows * 4, quaternions.len())?;
    crate::error::check_len("log coordinates", rows * 3, out.len())?;
    let mut chunks = out.chunks_exact_mut(3);
    let goal = unwrapped(quaternions, &mut |e| {
        if let Some(c) = chunks.next() {
            c.copy_from_slice(e);
        }
    })?;
    if let Some(last) = out.rchunks_exact_mut(3).next() {
        last.copy_from_slice(&[0.0; 3]);
    }
    Ok(goal)
}

/// Tikhonov damping of [`follow`]'s steps where the rotation vector is
/// singular (`|e|` near a multiple of 2π, where sideways moves of `e`
/// barely turn): a sideways step is at most `1/(2·DAMPING)` times the
/// turn it follows.
const DAMPING: f32 = 0.15;

/// The log coordinates of `q` relative to `goal` that continue `previous`
/// (a neighbouring sample's): damped Gauss–Newton from `previous` on the
/// residual turn, then the exact equivalent nearest the result
/// ([`nearest_log`]) wherever that is within 1e-3 rad of it (everywhere
/// but near a singular sphere).
fn follow(q: &Quaternion, goal: &Quaternion, previous: &[f32; 3]) -> [f32; 3] {
    let target = q.mul(&goal.conj());
    let mut e = *previous;
    for _ in 0..8 {
        // The residual turn `target ⊗ exp(e)⁻¹`, the short way round.
        let mut r = target.mul(&Quaternion::exp(e).conj());
        if r.w < 0.0 {
            r = r.neg();
        }
        let residual = r.log();
        if norm(&residual) < 1e-6 {
            break;
        }
        let step = damped_step(&e, &residual);
        e = mix(1.0, &e, 1.0, &step);
    }
    let exact = nearest_log(q, goal, &e);
    let gap = mix(1.0, &exact, -1.0, &e);
    if norm(&gap) < 1e-3 { exact } else { e }
}

/// The step `δ` with `exp(e + δ) ≈ exp(residual) ⊗ exp(e)`: the damped
/// inverse of the left Jacobian of the exponential map at `e`. Along `e`
/// the Jacobian is 1; across it, `a I + b [u]×` with `a = sin θ / θ`,
/// `b = (1 − cos θ)/θ`, which vanishes at `θ = 2πk`.
fn damped_step(e: &[f32; 3], residual: &[f32; 3]) -> [f32; 3] {
    let theta = norm(e);
    if theta < 1e-4 {
        return *residual;
    }
    let u = mix(1.0 / theta, e, 0.0, e);
    let along = dot(&u, residual);
    let across = mix(1.0, residual, -along, &u);
    let (sin, cos) = (libm::sinf(theta), libm::cosf(theta));
    let (a, b) = ((sin / theta), (1.0 - cos) / theta);
    let scale = 1.0 / (a * a + b * b + DAMPING * DAMPING);
    let turned = cross(&u, &across);
    mix(
        1.0,
        &mix(along, &u, scale * a, &across),
        -scale * b,
        &turned,
    )
}

/// Where the rotation-vector chart is used as it is: a recording whose
/// unwrapped `|log(q ⊗ ḡ)|` stays below this (1.5π, 270°) keeps it; one
/// that turns further is charted by swing and twist about its axis
/// ([`chart_axis`]), since the rotation vector is singular where its norm
/// crosses a whole turn.
pub const ROTATION_VECTOR_CHART_LIMIT: f32 = 1.5 * core::f32::consts::PI;

/// The chart axis of a recording (`[w, x, y, z]` rows, any sign, any
/// non-zero norm): `[0, 0, 0]` (the plain rotation vector `log(q ⊗ ḡ)`)
/// where its unwrapped rotation vector stays within
/// [`ROTATION_VECTOR_CHART_LIMIT`], else the unit direction of its summed
/// turn (the world-frame steps `log(q_{i+1} ⊗ q̄_i)` added up): the axis
/// a screw or a wrist's spin turns about, that the swing–twist chart
/// ([`from_coordinates`]) unwinds without a singularity.
pub fn chart_axis(quaternions: &[f32]) -> Result<[f32; 3], Error> {
    let mut widest = 0.0f32;
    unwrapped(quaternions, &mut |e| widest = widest.max(norm(e)))?;
    if widest < ROTATION_VECTOR_CHART_LIMIT {
        return Ok([0.0; 3]);
    }
    let mut sum = [0.0f32; 3];
    let mut previous: Option<Quaternion> = None;
    for q in rows(quaternions) {
        let q = q?;
        if let Some(p) = previous {
            let mut step = q.mul(&p.conj());
            if step.w < 0.0 {
                step = step.neg();
            }
            sum = mix(1.0, &sum, 1.0, &step.log());
        }
        previous = Some(q);
    }
    let n = norm(&sum);
    // A recording that unwinds past 270° turns far on the whole; were it
    // to come back, any axis charts it.
    Ok(if n > 1e-6 {
        mix(1.0 / n, &sum, 0.0, &sum)
    } else {
        [0.0, 0.0, 1.0]
    })
}

/// The orientation of coordinates `e` relative to `goal` in the chart of
/// `axis` (unit, or `[0, 0, 0]`): with a zero axis `exp(e) ⊗ g`
/// ([`from_log`]); with an axis `n`, `exp(s) ⊗ exp(ψ n) ⊗ g` where
/// `ψ = e · n` is the twist about `n` (any number of turns) and
/// `s = e − ψ n` the swing across it. Renormalized against rounding.
pub fn from_coordinates(e: &[f32], goal: &Quaternion, axis: &[f32; 3]) -> Quaternion {
    if *axis == [0.0; 3] {
        return from_log(e, goal);
    }
    let e: [f32; 3] = core::array::from_fn(|k| e.get(k).copied().unwrap_or(0.0));
    let psi = dot(&e, axis);
    let swing = mix(1.0, &e, -psi, axis);
    let twist = mix(psi, axis, 0.0, axis);
    Quaternion::exp(swing)
        .mul(&Quaternion::exp(twist))
        .mul(goal)
        .renormalized()
}

/// Of the coordinates of `q` relative to `goal` in the chart of `axis`
/// ([`from_coordinates`]), the ones nearest `reference`: with a zero axis
/// [`nearest_log`]; with an axis, the twist `ψ + 2πk` nearest the
/// reference's and the swing's rotation vector (the same for `q` and
/// `−q`). Continuous wherever the swing stays short of 180°.
pub fn nearest_coordinates(
    q: &Quaternion,
    goal: &Quaternion,
    reference: &[f32],
    axis: &[f32; 3],
) -> [f32; 3] {
    if *axis == [0.0; 3] {
        return nearest_log(q, goal, reference);
    }
    let reference: [f32; 3] = core::array::from_fn(|k| reference.get(k).copied().unwrap_or(0.0));
    let r = q.mul(&goal.conj());
    let along = dot(&[r.x, r.y, r.z], axis);
    let wanted = dot(&reference, axis);
    let full = 2.0 * core::f32::consts::PI;
    // The twist, ±2π by the sign of `q`; undefined (any) at a half-turn
    // swing, where the reference's is kept.
    let psi = if along * along + r.w * r.w > 1e-12 {
        let psi = 2.0 * libm::atan2f(along, r.w);
        psi + full * libm::roundf((wanted - psi) / full)
    } else {
        wanted
    };
    let mut swing = r.mul(&Quaternion::exp(mix(psi, axis, 0.0, axis)).conj());
    if swing.w < 0.0 {
        swing = swing.neg();
    }
    let s = swing.log();
    // Across the axis by construction; rounding's part along it removed.
    let s = mix(1.0, &s, -dot(&s, axis), axis);
    mix(1.0, &s, psi, axis)
}

/// The coordinates of a recording in the chart of `axis`, visited in
/// order as [`unwrapped`] visits its log coordinates (each continuing the
/// previous one; the goal's are 0); returns the goal.
pub fn unwrapped_in(
    quaternions: &[f32],
    axis: &[f32; 3],
    visit: &mut dyn FnMut(&[f32; 3]),
) -> Result<Quaternion, Error> {
    if *axis == [0.0; 3] {
        return unwrapped(quaternions, visit);
    }
    let next =
        |q: &Quaternion, goal: &Quaternion, e: &[f32; 3]| nearest_coordinates(q, goal, e, axis);
    continued(quaternions, &next, visit)
}

/// A recording's chart axis ([`chart_axis`]) and its coordinates in that
/// chart written to `out` (three per row, the last row exactly 0);
/// returns the goal and the axis.
pub fn chart_coordinates(
    quaternions: &[f32],
    out: &mut [f32],
) -> Result<(Quaternion, [f32; 3]), Error> {
    let rows = quaternions.len() / 4;
    crate::error::check_len("quaternions", rows * 4, quaternions.len())?;
    crate::error::check_len("log coordinates", rows * 3, out.len())?;
    let axis = chart_axis(quaternions)?;
    let mut chunks = out.chunks_exact_mut(3);
    let goal = unwrapped_in(quaternions, &axis, &mut |e| {
        if let Some(c) = chunks.next() {
            c.copy_from_slice(e);
        }
    })?;
    if let Some(last) = out.rchunks_exact_mut(3).next() {
        last.copy_from_slice(&[0.0; 3]);
    }
    Ok((goal, axis))
}

/// A chart axis as given (a file's, a generalizer's): `[0, 0, 0]` or a
/// finite vector, normalized (a unit one to within 1e-6 kept as it is).
pub fn checked_axis(axis: [f32; 3]) -> Result<[f32; 3], Error> {
    if axis == [0.0; 3] {
        return Ok(axis);
    }
    let n = norm(&axis);
    if !n.is_finite() || n < 1e-3 {
        return Err(Error::OutOfRange(
            "an orientation's chart axis is [0, 0, 0] or a finite direction",
        ));
    }
    if (n - 1.0).abs() < 1e-6 {
        // A unit axis stays bit for bit what it is (a file's, the first
        // demonstration's): equal axes compare equal.
        return Ok(axis);
    }
    Ok(mix(1.0 / n, &axis, 0.0, &axis))
}

/// An orientation DMP with `K` kernels per axis.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OrientationDmp<const K: usize> {
    /// The 3-DoF DMP of `log(q ⊗ ḡ)`.
    log: Dmp<3, K>,
    /// The demonstrated goal orientation.
    goal: Quaternion,
    /// The chart's axis ([`from_coordinates`]): `[0, 0, 0]` for the
    /// rotation vector `log(q ⊗ ḡ)` (every DMP fitted before charts had
    /// axes), a unit vector for swing and twist about it.
    #[serde(default)]
    axis: [f32; 3],
}

/// Where and how fast to execute an [`OrientationDmp`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct OrientationExecution {
    /// Execution time, s.
    pub tau: f32,
    /// Start orientation.
    pub start: Quaternion,
    /// Goal orientation.
    pub goal: Quaternion,
}

impl<const K: usize> OrientationDmp<K> {
    /// Fits an orientation DMP to a recording: `times` as for [`Dmp::fit`],
    /// `quaternions` `times.len()` rows of `[w, x, y, z]` (any non-zero
    /// norm; normalized, signs made continuous). The last sample is the
    /// goal, the first the start.
    pub fn fit(
        times: &[f32],
        quaternions: &[f32],
        kernels: usize,
        options: &FitOptions,
    ) -> Result<Self, Error> {
        crate::error::check_len(
            "quaternions",
            times.len().saturating_mul(4),
            quaternions.len(),
        )?;
        let axis = chart_axis(quaternions)?;
        let goal = unwrapped_in(quaternions, &axis, &mut |_| {})?;
        let rows = |visit: &mut dyn FnMut(&[f32])| {
            // Errors were found in the pass above; none can occur here.
            let _ = unwrapped_in(quaternions, &axis, &mut |e| visit(e));
        };
        let options = FitOptions {
            scaling: Scaling::Never,
            ..*options
        };
        let mut log = Dmp::fit_rows(times, &rows, 3, kernels, &options)?;
        // The goal of `e` is exactly 0 (the last sample's log is 0 up to
        // rounding).
        log.set_goal_vector(&[0.0; 3])?;
        Ok(OrientationDmp { log, goal, axis })
    }

    /// From the DMP of `log(q ⊗ ḡ)` and the goal orientation (as
    /// [`OrientationDmp::log_dmp`] and [`OrientationDmp::goal`] give them):
    /// the log DMP must have 3 DoF, a zero goal, no amplitude scaling.
    pub fn from_parts(log: Dmp<3, K>, goal: Quaternion) -> Result<Self, Error> {
        Self::from_chart(log, goal, [0.0; 3])
    }

    /// As [`OrientationDmp::from_parts`], with the log DMP's coordinates
    /// in the chart of `axis` ([`OrientationDmp::axis`]; `[0, 0, 0]` or a
    /// direction, normalized here).
    pub fn from_chart(log: Dmp<3, K>, goal: Quaternion, axis: [f32; 3]) -> Result<Self, Error> {
        let axis = checked_axis(axis)?;
        if log.dof() != 3
            || log.goal().iter().any(|g| *g != 0.0)
            || (0..3).any(|d| log.is_scaled(d))
        {
            return Err(Error::OutOfRange(
                "an orientation DMP's log DMP has 3 unscaled DoF and goal 0",
            ));
        }
        Ok(OrientationDmp {
            log,
            goal: goal.normalized()?,
            axis,
        })
    }

    /// The chart's axis: `[0, 0, 0]` where the log DMP's coordinates are
    /// the rotation vector `log(q ⊗ ḡ)`, else the unit axis of their
    /// swing–twist chart ([`from_coordinates`]).
    pub fn axis(&self) -> [f32; 3] {
        self.axis
    }

    /// The DMP of `log(q ⊗ ḡ)` (its parameters are what generalization and
    /// learning change).
    pub fn log_dmp(&self) -> &Dmp<3, K> {
        &self.log
    }

    /// The demonstrated goal orientation.
    pub fn goal(&self) -> Quaternion {
        self.goal
    }

    /// The demonstrated start orientation.
    pub fn start_orientation(&self) -> Quaternion {
        let e = self.log.start_position();
        from_coordinates(e, &self.goal, &self.axis)
    }

    /// The demonstrated duration, s.
    pub fn tau(&self) -> f32 {
        self.log.tau()
    }

    /// The default execution: demonstrated start, goal and `τ`.
    pub fn execution(&self) -> OrientationExecution {
        OrientationExecution {
            tau: self.tau(),
            start: self.start_orientation(),
            goal: self.goal,
        }
    }

    /// Starts an execution at rest at `exec.start`.
    ///
    /// `exec.start` is taken with the sign whose rotation vector to the
    /// goal is nearest the demonstrated one: the demonstrated turn (even
    /// beyond 180°) is kept when start and goal are the demonstrated ones,
    /// and the nearer way round is chosen for new ones.
    pub fn start(&self, exec: &OrientationExecution) -> Result<OrientationRun, Error> {
        let goal = exec.goal.normalized()?;
        let start = exec.start.normalized()?;
        let e = nearest_coordinates(&start, &goal, self.log.start_position(), &self.axis);
        let run = self.log.start(&Execution {
            tau: exec.tau,
            start: e.iter().copied().collect(),
            goal: [0.0; 3].iter().copied().collect(),
            goal_velocity: heapless::Vec::new(),
        })?;
        Ok(OrientationRun {
            run,
            goal,
            axis: self.axis,
        })
    }

    /// The whole execution from `t = 0` to `t = τ` at step `dt`, as
    /// `(time, orientation)` (see [`Dmp::trajectory`] for the time grid).
    pub fn trajectory(
        &self,
        exec: &OrientationExecution,
        dt: f32,
    ) -> Result<impl Iterator<Item = (f32, Quaternion)> + '_, Error> {
        let run = self.start(exec)?;
        let goal = run.goal;
        let log_exec = Execution {
            tau: exec.tau,
            start: run.run.position().iter().copied().collect(),
            goal: [0.0; 3].iter().copied().collect(),
            goal_velocity: heapless::Vec::new(),
        };
        let steps = self.log.trajectory(&log_exec, dt)?;
        let axis = self.axis;
        Ok(steps.map(move |s| (s.time, from_coordinates(&s.position, &goal, &axis))))
    }
}

/// `exp(e) ⊗ g` for a unit `g`, renormalized against rounding: the
/// orientation of log coordinates `e` relative to the goal `g`.
pub fn from_log(e: &[f32], goal: &Quaternion) -> Quaternion {
    let e = [
        e.first().copied().unwrap_or(0.0),
        e.get(1).copied().unwrap_or(0.0),
        e.get(2).copied().unwrap_or(0.0),
    ];
    Quaternion::exp(e).mul(goal).renormalized()
}

/// Of the rotation vectors of `q ⊗ ḡ` (`n (θ + 2πk)` for every whole
/// `k`, so `q` and `−q` alike), the one nearest `reference`: the log
/// coordinates of a new start kept on the demonstrated side and with the
/// demonstrated number of turns.
pub fn nearest_log(q: &Quaternion, goal: &Quaternion, reference: &[f32]) -> [f32; 3] {
    let reference: [f32; 3] = core::array::from_fn(|k| reference.get(k).copied().unwrap_or(0.0));
    let turn = q.mul(&goal.conj());
    let e = turn.log();
    let theta = norm(&e);
    let full = 2.0 * core::f32::consts::PI;
    if theta < 1e-6 {
        // No turn: whole turns about the reference's own axis.
        let r = norm(&reference);
        let k = libm::roundf(r / full);
        if k == 0.0 || r == 0.0 {
            return e;
        }
        return mix(k * full / r, &reference, 1.0, &e);
    }
    // Nearest along the axis n: θ + 2πk nearest n · reference.
    let k = libm::roundf((dot(&e, &reference) / theta - theta) / full);
    if k == 0.0 {
        e
    } else if k == -1.0 {
        // The other sign's logarithm: bit for bit what `−q` gives.
        turn.neg().log()
    } else {
        let scale = (theta + k * full) / theta;
        mix(scale, &e, 0.0, &e)
    }
}

/// An orientation execution in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct OrientationRun {
    run: Run<3>,
    goal: Quaternion,
    axis: [f32; 3],
}

impl OrientationRun {
    /// Advances by `dt` seconds (> 0).
    pub fn step<const K: usize>(&mut self, dmp: &OrientationDmp<K>, dt: f32) -> Result<(), Error> {
        self.run.step(&dmp.log, dt)
    }

    /// The current orientation, a unit quaternion.
    pub fn orientation(&self) -> Quaternion {
        from_coordinates(self.run.position(), &self.goal, &self.axis)
    }

    /// The current goal.
    pub fn goal(&self) -> Quaternion {
        self.goal
    }

    /// Changes the goal during execution: the current orientation is
    /// re-expressed relative to the new goal (with the turns still to go:
    /// the equivalent nearest its present coordinates), the log
    /// coordinates' velocity is kept.
    pub fn set_goal<const K: usize>(
        &mut self,
        dmp: &OrientationDmp<K>,
        goal: Quaternion,
    ) -> Result<(), Error> {
        let goal = goal.normalized()?;
        let now = self.orientation();
        let e = nearest_coordinates(&now, &goal, self.run.position(), &self.axis);
        self.run.rebase(&dmp.log, &e)?;
        self.goal = goal;
        Ok(())
    }

    /// Seconds since the start.
    pub fn time(&self) -> f32 {
        self.run.time()
    }

    /// Phase `s = t/τ`, saturated at 1.
    pub fn phase(&self) -> f32 {
        self.run.phase()
    }
}

/// A Cartesian DMP: a 3-D position DMP and an orientation DMP fitted to the
/// same recording, executed with one phase.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CartesianDmp<const K: usize> {
    /// The position.
    pub position: Dmp<3, K>,
    /// The orientation.
    pub orientation: OrientationDmp<K>,
}

/// Where and how fast to execute a [`CartesianDmp`].
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianExecution {
    /// Execution time, s.
    pub tau: f32,
    /// The position's start and goal.
    pub position: Execution<3>,
    /// The orientation's start and goal.
    pub orientation: OrientationExecution,
}

impl<const K: usize> CartesianDmp<K> {
    /// Fits both parts to one recording: `positions` rows of `[x, y, z]`,
    /// `quaternions` rows of `[w, x, y, z]`, both `times.len()` rows.
    pub fn fit(
        times: &[f32],
        positions: &[f32],
        quaternions: &[f32],
        kernels: usize,
        options: &FitOptions,
    ) -> Result<Self, Error> {
        Ok(CartesianDmp {
            position: Dmp::fit(times, positions, 3, kernels, options)?,
            orientation: OrientationDmp::fit(times, quaternions, kernels, options)?,
        })
    }

    /// The demonstrated start, goal and duration.
    pub fn execution(&self) -> CartesianExecution {
        CartesianExecution {
            tau: self.position.tau(),
            position: self.position.execution(),
            orientation: self.orientation.execution(),
        }
    }

    /// Starts both parts at rest with one `τ` (so one phase).
    pub fn start(&self, exec: &CartesianExecution) -> Result<CartesianRun, Error> {
        let mut position = exec.position.clone();
        position.tau = exec.tau;
        let mut orientation = exec.orientation;
        orientation.tau = exec.tau;
        Ok(CartesianRun {
            position: self.position.start(&position)?,
            orientation: self.orientation.start(&orientation)?,
        })
    }
}

/// A Cartesian execution in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct CartesianRun {
    position: Run<3>,
    orientation: OrientationRun,
}

impl CartesianRun {
    /// Advances both parts by `dt` seconds.
    pub fn step<const K: usize>(&mut self, dmp: &CartesianDmp<K>, dt: f32) -> Result<(), Error> {
        self.position.step(&dmp.position, dt)?;
        self.orientation.step(&dmp.orientation, dt)
    }

    /// The current pose: position and orientation.
    pub fn pose(&self) -> ([f32; 3], Quaternion) {
        let p = self.position.position();
        (
            [
                p.first().copied().unwrap_or(0.0),
                p.get(1).copied().unwrap_or(0.0),
                p.get(2).copied().unwrap_or(0.0),
            ],
            self.orientation.orientation(),
        )
    }

    /// Changes both goals during execution.
    pub fn set_goal<const K: usize>(
        &mut self,
        dmp: &CartesianDmp<K>,
        position: &[f32],
        orientation: Quaternion,
    ) -> Result<(), Error> {
        self.position.set_goal(&dmp.position, position)?;
        self.orientation.set_goal(&dmp.orientation, orientation)
    }

    /// Seconds since the start.
    pub fn time(&self) -> f32 {
        self.position.time()
    }
}
