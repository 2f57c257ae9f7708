//! Rhythmic (periodic) DMPs: one period of a periodic demonstration,
//! replayed at any frequency and amplitude, both changeable online.
//!
//! # Formulation
//!
//! Per DoF, with the phase angle `φ` advancing at `Ω = 2π·frequency` and
//! `τ = 1/Ω` (Ijspeert et al. 2013, rhythmic form):
//!
//! ```text
//! τ ż = α (β (g − y) − z) + a · f(φ),   τ ẏ = z,   β = α / 4,   φ̇ = Ω
//! f(φ) = Σ ψ_k(φ) w_k / Σ ψ_k(φ),   ψ_k(φ) = exp(h (cos(φ − c_k) − 1)),   c_k = 2πk/K
//! ```
//!
//! `g` is the oscillation's anchor (the demonstrated period's mean), `a`
//! the amplitude relative to the demonstrated one (1 replays it). The
//! same linear, critically damped spring as [`crate::dmp`], integrated
//! exactly with the forcing at mid-step, so any `dt` is stable; as there,
//! the position's steps are summed compensated (Kahan) with `Φ00 − 1` from
//! its series, and the phase is kept in periods, compensated, so its
//! wrap-around is exact: a 1 kHz run in `f32` does not drift over many
//! periods (plain sums were 1.3e-3 off after 20). A new
//! frequency takes effect at the next step (the velocity is kept); a new
//! amplitude or anchor is approached through a first-order filter with a
//! time constant of a quarter period (Ijspeert's goal filter), so the
//! motion glides onto the new cycle within about a period, with no jump in
//! velocity or in the forcing.
//!
//! The fit is the least-squares fit of [`crate::dmp`] on positions: the
//! responses to each kernel are the system's periodic steady state (its
//! transient decays by `e^(−απ)` per period, below 1e−34), so the
//! weights are those whose limit cycle best reproduces the period. The
//! responses are integrated on a fixed phase grid (whole sub-steps, one
//! partial step to each sample, as [`crate::dmp`]'s fit), so they do not
//! depend on how densely or evenly the period is sampled: 100 Hz, 1 kHz
//! and 10 kHz, even or jittered, fit alike. A run starts on that cycle (at
//! the period's first point, moving), not at rest.
//!
//! ```
//! use primo_core::dmp::FitOptions;
//! use primo_core::rhythmic::RhythmicDmp;
//! // Two periods of a wiping motion, 1 s each; fit the first.
//! let t: Vec<f32> = (0..=400).map(|i| i as f32 / 200.0).collect();
//! let y: Vec<f32> = t
//!     .iter()
//!     .map(|&t| 0.1 * (6.2832 * t).sin() + 0.02 * (12.566 * t).cos())
//!     .collect();
//! let dmp = RhythmicDmp::<1, 20>::fit(&t, &y, 1, 20, Some(1.0), &FitOptions::default())?;
//! let mut run = dmp.start()?;
//! run.set_frequency(2.0)?; // twice as fast
//! run.set_amplitude(&[2.0])?; // twice as wide
//! for _ in 0..2000 {
//!     run.step(&dmp, 0.001)?;
//! }
//! // After 2 s, 4 periods at 2 Hz: back where a period starts.
//! assert!((run.position()[0] - 2.0 * 0.02).abs() < 1e-3);
//! # Ok::<(), primo_core::Error>(())
//! ```

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::dmp::{FitOptions, MAX_ABS_POSITION, MAX_ABS_WEIGHT, check_alpha};
use crate::error::{check_bounded, check_capacity, check_finite, check_len, check_positive};
use crate::linalg::Normal;
use crate::spring::{Responses, SUBSTEPS_PER_SPACING, add_compensated, transition_step};

const TAU: f64 = core::f64::consts::TAU;
/// Lowest and highest frequency a run accepts, Hz.
pub const FREQUENCY_RANGE: [f32; 2] = [1e-3, 1e3];

/// A fitted rhythmic DMP with capacity `D` DoF and `K` kernels per DoF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct RhythmicDmp<const D: usize, const K: usize> {
    period: f32,
    alpha: f32,
    width: f32,
    anchor: Vec<f32, D>,
    weights: Vec<Vec<f32, K>, D>,
    /// The limit cycle's state at `φ = 0` (position, `z`), to start on it.
    cycle: Vec<[f32; 2], D>,
}

/// `ψ_k(φ)/Σψ` for every kernel (von Mises kernels, uniform in `φ`).
fn basis<const K: usize>(phi: f64, width: f64, kernels: usize, out: &mut [f64; K]) {
    let mut sum = 0.0;
    for (k, o) in out.iter_mut().enumerate().take(kernels) {
        let c = TAU * k as f64 / kernels as f64;
        *o = libm::exp(width * (libm::cos(phi - c) - 1.0));
        sum += *o;
    }
    if sum > 0.0 {
        for o in out.iter_mut().take(kernels) {
            *o /= sum;
        }
    }
}

impl<const D: usize, const K: usize> RhythmicDmp<D, K> {
    /// Fits one period: `times` strictly increasing, `positions` row-major
    /// (`times.len() × dof`); the period is `period` seconds from the first
    /// sample (the samples beyond it are ignored), or the whole recording.
    /// The kernels are `K`-uniform on the circle, their width from
    /// `options.overlap` as for [`crate::dmp::Dmp::fit`].
    pub fn fit(
        times: &[f32],
        positions: &[f32],
        dof: usize,
        kernels: usize,
        period: Option<f32>,
        options: &FitOptions,
    ) -> Result<Self, Error> {
        if dof == 0 {
            return Err(Error::OutOfRange("a DMP needs at least one DoF"));
        }
        check_capacity("DoF", dof, D)?;
        if kernels < 3 {
            return Err(Error::OutOfRange(
                "a rhythmic DMP needs at least three kernels",
            ));
        }
        check_capacity("kernels", kernels, K)?;
        check_len(
            "positions",
            times.len().saturating_mul(dof),
            positions.len(),
        )?;
        check_finite(times, "times")?;
        check_bounded(
            positions,
            MAX_ABS_POSITION,
            "positions beyond ±1e6, the bound on any position",
        )?;
        if times.windows(2).any(|w| !matches!(w, [a, b] if b > a)) {
            return Err(Error::OutOfRange("times must be strictly increasing"));
        }
        check_alpha(options.alpha)?;
        check_positive(options.overlap, "overlap must be finite and > 0")?;
        let t0 = times.first().copied().unwrap_or(0.0);
        let period = match period {
            Some(p) => p,
            None => times.last().copied().unwrap_or(0.0) - t0,
        };
        check_positive(period, "the period must be finite and > 0")?;
        // The samples of one period: within it, to rounding.
        let n = times
            .iter()
            .take_while(|t| f64::from(**t - t0) <= f64::from(period) * (1.0 + 1e-6))
            .count();
        if n < 3
            || times
                .get(n.saturating_sub(1))
                .is_none_or(|t| *t - t0 < 0.5 * period)
        {
            return Err(Error::OutOfRange(
                "the recording must cover the period with at least 3 samples",
            ));
        }
        let spacing = TAU / kernels as f64;
        // The same overlap as the discrete kernels: h·(Δc)² in phase units.
        let width = f64::from(options.overlap) / (spacing * spacing);
        let alpha = f64::from(options.alpha);
        // Each sample's share of the period, wrapping around.
        let phase = |i: usize| {
            times
                .get(i)
                .map(|t| TAU * f64::from(*t - t0) / f64::from(period))
        };
        let share = |i: usize| {
            let here = phase(i).unwrap_or(0.0);
            let prev = if i == 0 { None } else { phase(i - 1) };
            let next = if i + 1 < n { phase(i + 1) } else { None };
            let before = prev.map_or(0.0, |p| here - p);
            let after = next.map_or(TAU - here, |p| p - here);
            0.5 * (before + after) / TAU
        };
        // The anchor: each DoF's mean over the period.
        let mut anchor = [0.0f64; D];
        for i in 0..n {
            let q = share(i);
            for (d, a) in anchor.iter_mut().enumerate().take(dof) {
                *a += q * f64::from(positions.get(i * dof + d).copied().unwrap_or(0.0));
            }
        }
        // Responses to each kernel from rest: one period for the transient,
        // the second sampled on the fixed grid.
        let mut responses = Responses::<K>::new(alpha, kernels, spacing / SUBSTEPS_PER_SPACING);
        let mut kernels_at = |u: f64, psi: &mut [f64; K]| basis(u, width, kernels, psi);
        let (mut gram, mut rhs) = ([[0.0f64; K]; K], [[0.0f64; K]; D]);
        let mut normal = Normal::new(&mut gram, &mut rhs, kernels, dof);
        responses.advance(TAU, &mut kernels_at);
        let start = (responses.r, responses.v);
        for i in 0..n {
            let r = responses.sample(TAU + phase(i).unwrap_or(0.0), &mut kernels_at);
            normal.add(share(i), r, |d| {
                let y = f64::from(positions.get(i * dof + d).copied().unwrap_or(0.0));
                y - anchor.get(d).copied().unwrap_or(0.0)
            });
        }
        let mut fitted = [[0.0f32; K]; D];
        normal.solve(options.ridge, &mut fitted)?;
        let mut weights: Vec<Vec<f32, K>, D> = Vec::new();
        let mut cycle: Vec<[f32; 2], D> = Vec::new();
        for (d, w) in fitted.iter().enumerate().take(dof) {
            let row: Vec<f32, K> = w.iter().copied().take(kernels).collect();
            check_bounded(
                &row,
                MAX_ABS_WEIGHT,
                "fitted weights beyond ±1e9, the bound on kernel weights",
            )?;
            // The cycle at φ = 0: anchor plus the responses' weighted sum.
            let dot = |s: &[f64; K]| -> f64 {
                s.iter()
                    .zip(w)
                    .take(kernels)
                    .map(|(x, w)| x * f64::from(*w))
                    .sum()
            };
            let y0 = anchor.get(d).copied().unwrap_or(0.0) + dot(&start.0);
            let state = [y0 as f32, dot(&start.1) as f32];
            let capacity = Error::Capacity {
                what: "DoF",
                requested: dof,
                capacity: D,
            };
            weights.push(row).map_err(|_| capacity)?;
            cycle.push(state).map_err(|_| capacity)?;
        }
        Ok(RhythmicDmp {
            period,
            alpha: options.alpha,
            width: width as f32,
            anchor: anchor.iter().take(dof).map(|a| *a as f32).collect(),
            weights,
            cycle,
        })
    }

    /// Number of degrees of freedom.
    pub fn dof(&self) -> usize {
        self.weights.len()
    }

    /// Kernels per DoF.
    pub fn kernels(&self) -> usize {
        self.weights.first().map_or(0, |w| w.len())
    }

    /// The demonstrated period, s.
    pub fn period(&self) -> f32 {
        self.period
    }

    /// The oscillation's demonstrated anchor (the period's mean).
    pub fn anchor(&self) -> &[f32] {
        &self.anchor
    }

    /// Weights of DoF `d`.
    pub fn weights(&self, d: usize) -> &[f32] {
        self.weights.get(d).map_or(&[], |w| w.as_slice())
    }

    /// The unscaled forcing term of every DoF at phase angle `phi`.
    pub fn forcing(&self, phi: f32, out: &mut [f32]) {
        let kernels = self.kernels();
        let mut psi = [0.0f32; K];
        let mut sum = 0.0;
        for (k, p) in psi.iter_mut().enumerate().take(kernels) {
            let c = core::f32::consts::TAU * k as f32 / kernels as f32;
            *p = libm::expf(self.width * (libm::cosf(phi - c) - 1.0));
            sum += *p;
        }
        for (o, w) in out.iter_mut().zip(&self.weights) {
            let dot: f32 = w.iter().zip(&psi).map(|(w, p)| w * p).sum();
            *o = if sum > 0.0 { dot / sum } else { 0.0 };
        }
    }

    /// Starts on the demonstrated cycle: at its first point, at the
    /// demonstrated frequency, amplitude and anchor.
    pub fn start(&self) -> Result<RhythmicRun<D>, Error> {
        let mut run = RhythmicRun {
            dof: self.dof(),
            alpha: self.alpha,
            hz: 0.0,
            omega: 0.0,
            cycle: 0.0,
            cycle_carry: 0.0,
            time: 0.0,
            time_carry: 0.0,
            anchor: [0.0; D],
            amplitude: [1.0; D],
            anchor_target: [0.0; D],
            amplitude_target: [1.0; D],
            y: [0.0; D],
            y_carry: [0.0; D],
            z: [0.0; D],
            // A step of 0, the identity (so a fresh run equals its clone).
            step_u: 0.0,
            transition: [0.0, 0.0, 0.0, 1.0],
        };
        run.set_frequency(1.0 / self.period)?;
        for (d, state) in self.cycle.iter().enumerate() {
            if let (Some(y), Some(z), Some(a), Some(t), Some(&g)) = (
                run.y.get_mut(d),
                run.z.get_mut(d),
                run.anchor.get_mut(d),
                run.anchor_target.get_mut(d),
                self.anchor.get(d),
            ) {
                *y = state[0];
                *z = state[1];
                *a = g;
                *t = g;
            }
        }
        Ok(run)
    }
}

/// A rhythmic execution in progress.
#[derive(Debug, Clone, PartialEq)]
pub struct RhythmicRun<const D: usize> {
    dof: usize,
    alpha: f32,
    /// The frequency, Hz, and as `Ω = 2π·frequency`.
    hz: f32,
    omega: f32,
    /// The phase in periods, in `[0, 1)`, and its compensation (Kahan):
    /// in periods the wrap-around is exact (2π is not an `f32`).
    cycle: f32,
    cycle_carry: f32,
    time: f32,
    time_carry: f32,
    anchor: [f32; D],
    amplitude: [f32; D],
    /// Where the filters take `anchor` and `amplitude`.
    anchor_target: [f32; D],
    amplitude_target: [f32; D],
    y: [f32; D],
    /// Compensation of `y` (Kahan): what its sums lost to rounding.
    y_carry: [f32; D],
    z: [f32; D],
    /// The step `u` (phase angle) the transition below is for.
    step_u: f32,
    transition: [f32; 4],
}

impl<const D: usize> RhythmicRun<D> {
    /// Advances by `dt` seconds (> 0).
    pub fn step<const K: usize>(&mut self, dmp: &RhythmicDmp<D, K>, dt: f32) -> Result<(), Error> {
        check_positive(dt, "dt must be finite and > 0")?;
        check_len("DMP DoF", self.dof, dmp.dof())?;
        if !(self.time + dt).is_finite() {
            return Err(Error::OutOfRange("time would overflow"));
        }
        // The step in periods and in phase angle (`dt/τ`).
        let periods = dt * self.hz;
        let u = dt * self.omega;
        if u != self.step_u {
            self.transition = transition_step(self.alpha, u);
            self.step_u = u;
        }
        let [d00, p01, p10, p11] = self.transition;
        // The filters: a quarter period, π/2 in phase.
        let follow = 1.0 - libm::expf(-u / core::f32::consts::FRAC_PI_2);
        for (a, t) in self.anchor.iter_mut().zip(self.anchor_target) {
            *a += follow * (t - *a);
        }
        for (a, t) in self.amplitude.iter_mut().zip(self.amplitude_target) {
            *a += follow * (t - *a);
        }
        let mut force = [0.0f32; D];
        dmp.forcing(
            core::f32::consts::TAU * (self.cycle + 0.5 * periods),
            &mut force,
        );
        let stiffness = self.alpha * self.alpha / 4.0;
        for (((((y, carry), z), f), g), a) in self
            .y
            .iter_mut()
            .zip(self.y_carry.iter_mut())
            .zip(self.z.iter_mut())
            .zip(force)
            .zip(self.anchor)
            .zip(self.amplitude)
            .take(self.dof)
        {
            let equilibrium = g + a * f / stiffness;
            let e = (*y - equilibrium) - *carry;
            // A small step each cycle, added compensated: over many periods
            // plain f32 sums would accumulate their rounding.
            add_compensated(y, carry, d00 * e + p01 * *z);
            *z = p10 * e + p11 * *z;
        }
        add_compensated(&mut self.cycle, &mut self.cycle_carry, periods);
        if !(self.cycle < 1.0) {
            // Exact (`fmod` is); after a step of half a period or more (far
            // from any control rate) the compensation is dropped.
            self.cycle = libm::fmodf(self.cycle, 1.0);
            if !(self.cycle >= 0.0 && periods < 0.5) {
                self.cycle_carry = 0.0;
            }
            if !(0.0..1.0).contains(&self.cycle) {
                self.cycle = 0.0;
            }
        }
        add_compensated(&mut self.time, &mut self.time_carry, dt);
        Ok(())
    }

    /// Sets the frequency, Hz (within [`FREQUENCY_RANGE`]), from the next
    /// step on; the phase goes on from where it is.
    pub fn set_frequency(&mut self, hz: f32) -> Result<(), Error> {
        if !(FREQUENCY_RANGE[0]..=FREQUENCY_RANGE[1]).contains(&hz) {
            return Err(Error::OutOfRange("frequency outside 0.001 to 1000 Hz"));
        }
        // `z` is `τ ẏ`: keep the velocity across the change of `τ`.
        let omega = core::f32::consts::TAU * hz;
        if self.omega > 0.0 {
            for z in self.z.iter_mut() {
                *z *= self.omega / omega;
            }
        }
        self.hz = hz;
        self.omega = omega;
        Ok(())
    }

    /// Sets each DoF's amplitude relative to the demonstrated one (1
    /// replays it); the run glides onto it (see the module docs).
    pub fn set_amplitude(&mut self, relative: &[f32]) -> Result<(), Error> {
        check_len("amplitude", self.dof, relative.len())?;
        check_bounded(relative, 1e3, "amplitude beyond ±1e3")?;
        for (a, r) in self.amplitude_target.iter_mut().zip(relative) {
            *a = *r;
        }
        Ok(())
    }

    /// Moves the oscillation's anchor (one value per DoF); the run glides
    /// onto it (see the module docs).
    pub fn set_anchor(&mut self, anchor: &[f32]) -> Result<(), Error> {
        check_len("anchor", self.dof, anchor.len())?;
        check_bounded(
            anchor,
            MAX_ABS_POSITION,
            "anchor beyond ±1e6, the bound on any position",
        )?;
        for (a, g) in self.anchor_target.iter_mut().zip(anchor) {
            *a = *g;
        }
        Ok(())
    }

    /// Current position (`dof` values).
    pub fn position(&self) -> &[f32] {
        self.y.get(..self.dof).unwrap_or(&[])
    }

    /// Seconds since the start.
    pub fn time(&self) -> f32 {
        self.time
    }

    /// Phase angle, rad, in `[0, 2π)`.
    pub fn phase(&self) -> f32 {
        let phase = core::f32::consts::TAU * self.cycle;
        if (0.0..core::f32::consts::TAU).contains(&phase) {
            phase
        } else {
            0.0
        }
    }
}
