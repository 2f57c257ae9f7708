//! Via-points: a DMP changed to pass given positions at given times,
//! without refitting it to data.
//!
//! With the start, goal and `τ` of an execution fixed, a run's position at
//! any time is an affine function of the kernel weights: the spring is
//! linear and the forcing term is linear in them (scaled by the
//! amplitude, turned globally or not). So the positions at the via-points'
//! times are `y = y₀ + J Δw`, with `J`'s columns measured by runs with one
//! weight moved, and the smallest weight change (in the sum of squares)
//! that puts them on the via-points is `Δw = Jᵀ (J Jᵀ)⁻¹ (y* − y₀)`. The
//! rest of the movement changes as little as that allows: most near the
//! via-points' times, nothing before the first kernel that reaches them.
//! Each DoF with a via-point also keeps its position at `τ` (a row of `J`
//! more): without that, the bend's tail left the run up to millimetres
//! short of its goal at `τ`, settling there only later.

use super::model::{Dmp, Execution};
use super::options::{MAX_ABS_POSITION, MAX_ABS_WEIGHT};
use crate::Error;
use crate::error::{check_capacity, check_positive};
use crate::linalg::{cholesky, cholesky_solve};

/// The most via-points one call takes.
pub const MAX_VIA_POINTS: usize = 8;

/// Rows of `J`: the via-points and the end of each DoF they bend.
const ROWS: usize = 2 * MAX_VIA_POINTS;

/// How far one weight is moved to measure its effect: the effect is
/// linear, so any size gives it; a large one keeps `f32` rounding small
/// against it.
const PROBE: f32 = 100.0;

/// A position one DoF passes at a time.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ViaPoint {
    /// Seconds from the start, strictly between 0 and the execution's `τ`.
    pub time: f32,
    /// The DoF.
    pub dof: usize,
    /// Where the DoF is at `time`.
    pub position: f32,
}

impl<const D: usize, const K: usize> Dmp<D, K> {
    /// This DMP with its weights changed least so that `exec`'s run,
    /// stepped at `dt` from 0, passes every via-point (between two steps,
    /// the straight line between them does): up to [`MAX_VIA_POINTS`],
    /// each on one DoF, at a time strictly inside the movement. Its start,
    /// goal and `τ` are unchanged, and so are the run before the first
    /// kernel that reaches a via-point's time, the position at `τ` and
    /// every DoF without a via-point.
    ///
    /// Refused: a via-point's DoF beyond the DMP's, a time outside the
    /// movement, a position beyond ±[`MAX_ABS_POSITION`], two that ask one
    /// DoF for two places at once or one that no weight can move (a DoF
    /// whose amplitude is 0, a time before the kernels reach), and weights
    /// it would take beyond ±[`MAX_ABS_WEIGHT`].
    ///
    /// ```
    /// use primo_core::dmp::{Dmp, FitOptions, ViaPoint};
    /// let t: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
    /// let y: Vec<f32> = t.iter().map(|&t| t * t * (3.0 - 2.0 * t)).collect();
    /// let dmp = Dmp::<1, 20>::fit(&t, &y, 1, 20, &FitOptions::default())?;
    /// let exec = dmp.execution();
    /// let via = ViaPoint { time: 0.5, dof: 0, position: 0.8 };
    /// let bent = dmp.through(&exec, 0.01, &[via])?;
    /// let at = bent.trajectory(&exec, 0.01)?.nth(50).unwrap();
    /// assert!((at.time - 0.5).abs() < 1e-6 && (at.position[0] - 0.8).abs() < 1e-4);
    /// # Ok::<(), primo_core::Error>(())
    /// ```
    pub fn through(
        &self,
        exec: &Execution<D>,
        dt: f32,
        points: &[ViaPoint],
    ) -> Result<Self, Error> {
        check_positive(dt, "dt must be finite and > 0")?;
        check_capacity("via-points", points.len(), MAX_VIA_POINTS)?;
        for p in points {
            if p.dof >= self.dof() {
                return Err(Error::OutOfRange("a via-point's DoF is beyond the DMP's"));
            }
            if !(p.time > 0.0 && p.time < exec.tau) {
                return Err(Error::OutOfRange(
                    "a via-point's time must lie within the movement, after its start and before τ",
                ));
            }
            if !(p.position.is_finite() && libm::fabsf(p.position) <= MAX_ABS_POSITION) {
                return Err(Error::OutOfRange(
                    "a via-point's position must be finite and within ±1e6",
                ));
            }
        }
        if !(exec.tau / dt < 1e7) {
            return Err(Error::OutOfRange(
                "tau / dt must be below 1e7 steps for via-points",
            ));
        }
        if points.is_empty() {
            return Ok(self.clone());
        }
        // The via-points, then each bent DoF's position at τ, kept.
        let mut rows = [ViaPoint {
            time: exec.tau,
            dof: 0,
            position: 0.0,
        }; ROWS];
        // At most MAX_VIA_POINTS (checked above): every one has its row.
        for (row, p) in rows.iter_mut().zip(points) {
            *row = *p;
        }
        let vias = points.len();
        let mut m = vias;
        let mut bent = [false; D];
        for p in points {
            if let Some(b) = bent.get_mut(p.dof)
                && !*b
            {
                *b = true;
                if let Some(row) = rows.get_mut(m) {
                    row.dof = p.dof;
                    m += 1;
                }
            }
        }
        let ends = self.positions_at(exec, dt, rows.get(vias..m).unwrap_or(&[]))?;
        for (row, end) in rows.iter_mut().skip(vias).take(m - vias).zip(ends) {
            row.position = end;
        }
        let rows = rows.get(..m).unwrap_or(&[]);
        let base = self.positions_at(exec, dt, rows)?;
        // J, column by column: the rows' positions per unit of one weight
        // (zero off the bent DoFs: a DoF's run has its own weights only).
        let mut jacobian = [[[0.0f32; ROWS]; K]; D];
        for (d, row) in jacobian.iter_mut().enumerate().take(self.dof()) {
            if !bent.get(d).copied().unwrap_or(false) {
                continue;
            }
            for (k, column) in row.iter_mut().enumerate().take(self.kernels()) {
                let mut probe = self.clone();
                if let Some(w) = probe.weight_mut(d, k) {
                    *w += PROBE;
                }
                let moved = probe.positions_at(exec, dt, rows)?;
                for ((j, y), y0) in column.iter_mut().zip(moved).zip(base) {
                    *j = (y - y0) / PROBE;
                }
            }
        }
        // J Jᵀ, in f64: its entries are sums of many small products.
        let mut gram = [[0.0f64; ROWS]; ROWS];
        for column in jacobian.iter().flatten() {
            for (row, &a) in gram.iter_mut().zip(column.iter()) {
                for (g, &b) in row.iter_mut().zip(column.iter()) {
                    *g += f64::from(a) * f64::from(b);
                }
            }
        }
        let diagonal: [f64; ROWS] = core::array::from_fn(|i| {
            gram.get(i)
                .and_then(|row| row.get(i))
                .copied()
                .unwrap_or(0.0)
        });
        let contradictory = "no weight change passes these via-points: two ask one DoF for two \
             places at once (or one is too close to τ, where the DoF keeps its end), or a DoF \
             cannot move there (its amplitude is 0, or the time is before its kernels reach)";
        cholesky(&mut gram, m, contradictory)?;
        // Rows that rounding alone keeps apart (the same DoF and time twice)
        // leave a pivot that is rounding: as singular as they are.
        for (i, (row, d)) in gram.iter().zip(diagonal).enumerate().take(m) {
            let pivot = row.get(i).copied().unwrap_or(0.0);
            if !(pivot * pivot > 1e-8 * d) {
                return Err(Error::Singular(contradictory));
            }
        }
        let mut out = self.clone();
        // Two rounds: the second takes up what rounding left of the first.
        for _ in 0..2 {
            let now = out.positions_at(exec, dt, rows)?;
            let mut residual = [0.0f64; ROWS];
            for ((r, p), y) in residual.iter_mut().zip(rows).zip(now) {
                *r = f64::from(p.position) - f64::from(y);
            }
            cholesky_solve(&gram, m, &mut residual);
            for (d, row) in jacobian.iter().enumerate().take(self.dof()) {
                for (k, column) in row.iter().enumerate().take(self.kernels()) {
                    let change: f64 = column
                        .iter()
                        .zip(residual)
                        .map(|(&j, r)| f64::from(j) * r)
                        .sum();
                    if let Some(w) = out.weight_mut(d, k) {
                        *w += change as f32;
                        if !(libm::fabsf(*w) <= MAX_ABS_WEIGHT) {
                            return Err(Error::OutOfRange(
                                "the via-points need weights beyond ±1e9: one lies too far \
                                 from the movement",
                            ));
                        }
                    }
                }
            }
        }
        Ok(out)
    }

    /// The positions of `exec`'s run stepped at `dt` at each row's time
    /// and DoF, linear between the steps around it.
    fn positions_at(
        &self,
        exec: &Execution<D>,
        dt: f32,
        points: &[ViaPoint],
    ) -> Result<[f32; ROWS], Error> {
        let last = points.iter().fold(0.0f32, |t, p| t.max(p.time));
        let mut out = [0.0; ROWS];
        let mut run = self.start(exec)?;
        let mut before = run.position().get(..self.dof()).map(|p| {
            let mut a = [0.0f32; D];
            a.iter_mut().zip(p).for_each(|(a, p)| *a = *p);
            a
        });
        let mut i = 0u32;
        loop {
            let (t0, t1) = (i as f32 * dt, (i + 1) as f32 * dt);
            run.step(self, dt)?;
            let after = run.position();
            for (o, p) in out.iter_mut().zip(points) {
                if p.time > t0 && p.time <= t1 {
                    let y0 = before.and_then(|b| b.get(p.dof).copied()).unwrap_or(0.0);
                    let y1 = after.get(p.dof).copied().unwrap_or(0.0);
                    *o = y0 + (y1 - y0) * ((p.time - t0) / dt);
                }
            }
            if t1 >= last {
                return Ok(out);
            }
            if let Some(b) = before.as_mut() {
                b.iter_mut().zip(after).for_each(|(b, a)| *b = *a);
            }
            i += 1;
        }
    }
}
