//! The fit: a DMP from one demonstration. [`Dmp::fit`] takes its start,
//! goal and duration from the demonstration, decides each DoF's amplitude
//! scaling and the kernels' margin, and fits the weights by least squares
//! on the demonstrated positions.
//!
//! Per DoF the transformation system is linear in the weights: with the
//! phase `u = t/τ`, `y'' + α y' + (α²/4)(y − g) = a Σ w_k φ_k(u)` where
//! `φ_k = ψ_k/Σψ`, started at rest at `y0`. So the DMP's own trajectory is
//! `y(u) = y_h(u) + a Σ w_k r_k(u)`: `y_h` is the unforced spring's closed
//! form and `r_k` the response, from rest, to the kernel `φ_k` alone.
//! The weights minimize `Σ_i q_i (y_i − y(u_i))²` over the samples (`q_i`
//! each sample's share of the time axis, the last one's raised by
//! [`END_WEIGHT`] whatever the rate) plus a small ridge: the fit is the
//! one that best reproduces the demonstration, by construction.
//!
//! Why not the usual regression of `τ²ÿ − α(β(g − y) − τẏ)` on the
//! kernels: it needs the demonstration's second derivative. Finite
//! differences divide rounding and noise by `dt²`, so the denser the
//! recording the worse the fit (at 10 kHz, f32 positions rounded at 4e−8
//! give accelerations wrong by units of m/s²). Here nothing is
//! differentiated: more samples only average the noise away.
//!
//! Numerics: everything in `f64` (the normal equations of smooth responses
//! are ill-conditioned for `f32`). The responses ([`crate::spring::Responses`])
//! are integrated with the same scheme as [`super::Run`] (exact spring,
//! forcing at mid-step), on
//! a fixed grid of 1/64 of the kernel spacing with one partial step to
//! each sample, so they do not depend on how densely or evenly the
//! demonstration is sampled. Memory: `2K`
//! response states, a `K × K` Gram matrix and `D × K` right-hand sides, on
//! the stack; no allocation.

use heapless::Vec;

use super::kernels::{Layout, span};
use super::model::Dmp;
use super::options::{
    AUTO_MARGIN, AUTO_SAMPLES_PER_SPACING, AUTO_SCALING_MIN_FRACTION, FINAL_VELOCITY_WINDOW,
    FinalVelocity, FitOptions, MAX_ABS_POSITION, MAX_ABS_WEIGHT, Margin, Scaling, check_alpha,
    check_margin, check_tau,
};
use crate::Error;
use crate::error::{check_bounded, check_capacity, check_finite, check_len, check_positive};
use crate::linalg::Normal;
use crate::spring::{Responses, SUBSTEPS_PER_SPACING};

/// A demonstration's rows, visited in order: `rows(visit)` calls `visit`
/// with each row (`dof` positions) of the demonstration, first to last.
pub(crate) type Rows<'a> = dyn Fn(&mut dyn FnMut(&[f32])) + 'a;

impl<const D: usize, const K: usize> Dmp<D, K> {
    /// Fits a DMP to one demonstration.
    ///
    /// `times` are strictly increasing (any spacing, at least 3 samples);
    /// `positions` holds `times.len() × dof` values, row-major (sample by
    /// sample). The demo's first sample is the start, its last the goal and
    /// its duration the default `τ`. The weights are those whose execution
    /// best reproduces the demonstrated positions (least squares, each
    /// sample weighted by its share of the time axis, a small ridge): no
    /// derivative of the demonstration is taken, so a denser or unevenly
    /// sampled recording fits as well or better (see `dmp/fit.rs` for the
    /// numerics). Positions must lie within
    /// [`MAX_ABS_POSITION`]; fitted weights beyond [`MAX_ABS_WEIGHT`] are an
    /// error.
    pub fn fit(
        times: &[f32],
        positions: &[f32],
        dof: usize,
        kernels: usize,
        options: &FitOptions,
    ) -> Result<Self, Error> {
        if dof == 0 {
            return Err(Error::OutOfRange("a DMP needs at least one DoF"));
        }
        check_len(
            "positions",
            times.len().saturating_mul(dof),
            positions.len(),
        )?;
        let rows = |visit: &mut dyn FnMut(&[f32])| positions.chunks_exact(dof).for_each(visit);
        Self::fit_rows(times, &rows, dof, kernels, options)
    }

    /// [`Dmp::fit`] with the demonstration's rows given by `rows`, which
    /// calls its argument with each row in order (and may be called more
    /// than once): a demonstration computed on the fly, without a buffer.
    pub(crate) fn fit_rows(
        times: &[f32],
        rows: &Rows,
        dof: usize,
        kernels: usize,
        options: &FitOptions,
    ) -> Result<Self, Error> {
        if dof == 0 {
            return Err(Error::OutOfRange("a DMP needs at least one DoF"));
        }
        check_capacity("DoF", dof, D)?;
        if kernels < 2 {
            return Err(Error::OutOfRange("a DMP needs at least two kernels"));
        }
        check_capacity("kernels", kernels, K)?;
        let n = times.len();
        if n < 3 {
            return Err(Error::OutOfRange(
                "a demonstration needs at least 3 samples",
            ));
        }
        check_finite(times, "times")?;
        if times.windows(2).any(|w| !matches!(w, [a, b] if b > a)) {
            return Err(Error::OutOfRange("times must be strictly increasing"));
        }
        check_alpha(options.alpha)?;
        check_positive(options.overlap, "overlap must be finite and > 0")?;
        if !(options.ridge >= 0.0 && options.ridge.is_finite()) {
            return Err(Error::OutOfRange("ridge must be finite and >= 0"));
        }

        let (t0, t_end) = match (times.first(), times.last()) {
            (Some(a), Some(b)) => (*a, *b),
            _ => {
                return Err(Error::OutOfRange(
                    "a demonstration needs at least 3 samples",
                ));
            }
        };
        let tau = t_end - t0;
        check_tau(
            tau,
            "demonstration duration must be finite and at least 0.001 s",
        )?;
        // One pass: the rows' count and bounds, start, goal and ranges.
        let mut count = 0usize;
        let mut bounded = true;
        let mut first = [0.0f32; D];
        let mut last = [0.0f32; D];
        let mut lo = [f32::INFINITY; D];
        let mut hi = [f32::NEG_INFINITY; D];
        rows(&mut |row: &[f32]| {
            bounded &= row.len() == dof
                && row
                    .iter()
                    .all(|v| v.is_finite() && libm::fabsf(*v) <= MAX_ABS_POSITION);
            for (d, &v) in row.iter().enumerate().take(D) {
                if count == 0
                    && let Some(f) = first.get_mut(d)
                {
                    *f = v;
                }
                if let (Some(l), Some(lo), Some(hi)) =
                    (last.get_mut(d), lo.get_mut(d), hi.get_mut(d))
                {
                    *l = v;
                    *lo = lo.min(v);
                    *hi = hi.max(v);
                }
            }
            count += 1;
        });
        check_len("positions", n, count)?;
        if !bounded {
            return Err(Error::OutOfRange(
                "positions beyond ±1e6, the bound on any position",
            ));
        }
        let start: Vec<f32, D> = first.iter().copied().take(dof).collect();
        let goal: Vec<f32, D> = last.iter().copied().take(dof).collect();

        let mut scaled: Vec<bool, D> = Vec::new();
        for d in 0..dof {
            let (lo, hi) = (
                lo.get(d).copied().unwrap_or(0.0),
                hi.get(d).copied().unwrap_or(0.0),
            );
            let amplitude =
                goal.get(d).copied().unwrap_or(0.0) - start.get(d).copied().unwrap_or(0.0);
            let on = match options.scaling {
                Scaling::Auto => {
                    amplitude != 0.0
                        && libm::fabsf(amplitude) >= AUTO_SCALING_MIN_FRACTION * (hi - lo)
                }
                Scaling::Always => true,
                Scaling::Never => false,
                Scaling::Mask(m) => d < 32 && (m >> d) & 1 == 1,
                Scaling::AutoWhere(m) => {
                    d < 32
                        && (m >> d) & 1 == 1
                        && amplitude != 0.0
                        && libm::fabsf(amplitude) >= AUTO_SCALING_MIN_FRACTION * (hi - lo)
                }
                // Marks the group scaled together.
                #[cfg(feature = "global-scaling")]
                Scaling::Global(m) => d < 32 && (m >> d) & 1 == 1,
            };
            if on && amplitude == 0.0 && !options.scaling.is_global() {
                return Err(Error::OutOfRange(
                    "an amplitude-scaled DoF needs its goal to differ from its start",
                ));
            }
            scaled.push(on).map_err(|_| Error::Capacity {
                what: "DoF",
                requested: dof,
                capacity: D,
            })?;
        }

        let alpha = options.alpha;
        let mut amplitude = [1.0f32; D];
        // Global scaling fits the forcing term as demonstrated (amplitude
        // 1) and keeps the group's demonstrated `g − y0` to turn it by.
        let mut reference: Vec<f32, D> = Vec::new();
        let global = options.scaling.is_global();
        for (d, a) in amplitude.iter_mut().enumerate().take(dof) {
            let span = goal.get(d).copied().unwrap_or(0.0) - start.get(d).copied().unwrap_or(0.0);
            let on = scaled.get(d) == Some(&true);
            match global {
                true => {
                    let _ = reference.push(if on { span } else { 0.0 });
                }
                false if on => *a = span,
                false => {}
            }
        }
        if global && !super::model::check_reference(&reference, &scaled) {
            return Err(Error::OutOfRange(
                "global scaling needs the demonstration's goal to differ from its start on the \
                 scaled DoFs",
            ));
        }
        let goal_velocity: Vec<f32, D> = match options.final_velocity {
            FinalVelocity::AtRest => Vec::new(),
            FinalVelocity::Demonstrated => final_velocity(times, rows, dof)?,
        };
        let demo = Demonstration {
            times,
            rows,
            dof,
            kernels,
            alpha,
            width: 0.0,
            margin: 0.0,
            stride: 1,
            ridge: options.ridge,
            start: &start,
            goal: &goal,
            amplitude: &amplitude,
            velocity: &goal_velocity,
        };
        let layout = |margin: f32, stride: usize, out: &mut [[f32; K]; D]| {
            fit_layout(&demo, options.overlap, margin, stride, out)
        };
        let mut weights = [[0.0f32; K]; D];
        let (width, margin) = match options.margin {
            Margin::Spacings(m) => {
                check_margin(m, kernels)?;
                (layout(m, 1, &mut weights)?.1, m)
            }
            Margin::Auto => {
                // Chosen on a sparser recording where it is dense (the
                // choice costs a fifth of the fit at 1 kHz, not a fit).
                let stride = (n / (AUTO_SAMPLES_PER_SPACING * kernels)).max(1);
                let (plain, plain_width) = layout(0.0, stride, &mut weights)?;
                // The wider layout only where it leaves a spacing between
                // the ends and fits at all; a tie keeps the plain one.
                let mut wider = [[0.0f32; K]; D];
                let wide = check_margin(AUTO_MARGIN, kernels)
                    .and_then(|()| layout(AUTO_MARGIN, stride, &mut wider))
                    .ok()
                    .filter(|(residual, _)| *residual < plain);
                match (wide, stride) {
                    (Some((_, width)), 1) => {
                        weights = wider;
                        (width, AUTO_MARGIN)
                    }
                    (Some(_), _) => (layout(AUTO_MARGIN, 1, &mut weights)?.1, AUTO_MARGIN),
                    (None, 1) => (plain_width, 0.0),
                    (None, _) => (layout(0.0, 1, &mut weights)?.1, 0.0),
                }
            }
        };
        Ok(Self {
            tau,
            alpha,
            width,
            margin,
            start,
            goal,
            scaled,
            reference,
            goal_velocity,
            weights: weights
                .iter()
                .take(dof)
                .map(|w| w.iter().copied().take(kernels).collect())
                .collect(),
        })
    }
}

/// The demonstration's velocity at its end, per DoF: the least-squares
/// slope over its last [`FINAL_VELOCITY_WINDOW`] of the duration, at
/// least its last two samples.
fn final_velocity<const D: usize>(
    times: &[f32],
    rows: &Rows,
    dof: usize,
) -> Result<Vec<f32, D>, Error> {
    let (Some(&t0), Some(&t_end)) = (times.first(), times.last()) else {
        return Err(Error::OutOfRange(
            "a demonstration needs at least 3 samples",
        ));
    };
    let from = t_end - FINAL_VELOCITY_WINDOW * (t_end - t0);
    let first = times
        .iter()
        .position(|&t| t >= from)
        .unwrap_or(0)
        .min(times.len().saturating_sub(2));
    // Sums about the last time, in f64: Σs, Σs², Σy, Σsy.
    let (mut n, mut st, mut stt) = (0.0f64, 0.0f64, 0.0f64);
    let (mut sy, mut sty) = ([0.0f64; D], [0.0f64; D]);
    let mut i = 0usize;
    rows(&mut |row: &[f32]| {
        if i >= first
            && let Some(&t) = times.get(i)
        {
            let s = f64::from(t) - f64::from(t_end);
            (n, st, stt) = (n + 1.0, st + s, stt + s * s);
            for ((y, sy), sty) in row.iter().zip(sy.iter_mut()).zip(sty.iter_mut()).take(dof) {
                *sy += f64::from(*y);
                *sty += s * f64::from(*y);
            }
        }
        i += 1;
    });
    let spread = n * stt - st * st;
    let velocity: Vec<f32, D> = sy
        .iter()
        .zip(sty)
        .take(dof)
        .map(|(sy, sty)| ((n * sty - st * sy) / spread) as f32)
        .collect();
    check_bounded(
        &velocity,
        MAX_ABS_POSITION,
        "the demonstration's final velocity beyond ±1e6 per second",
    )?;
    Ok(velocity)
}

/// Fits `demo`'s weights into `out` with the kernels `margin` spacings
/// beyond the ends at `overlap`, on every `stride`-th sample; returns the
/// residual and the kernel width. Never inlined: [`Margin::Auto`] calls it
/// up to three times, and on the M4F one frame must serve them all.
#[inline(never)]
fn fit_layout<const D: usize, const K: usize>(
    demo: &Demonstration,
    overlap: f32,
    margin: f32,
    stride: usize,
    out: &mut [[f32; K]; D],
) -> Result<(f64, f32), Error> {
    let spacing = 1.0 / span(demo.kernels, margin);
    let width = overlap / (spacing * spacing);
    check_positive(width, "overlap too large for this many kernels")?;
    let residual = weights(
        &Demonstration {
            width,
            margin,
            stride,
            ..*demo
        },
        out,
    )?;
    for row in out.iter().take(demo.dof) {
        check_bounded(
            row.get(..demo.kernels).unwrap_or(&[]),
            MAX_ABS_WEIGHT,
            "fitted weights beyond ±1e9, the bound on kernel weights (demo too short or too noisy for the kernels?)",
        )?;
    }
    Ok((residual, width))
}

/// Extra weight of the last sample, in kernel spacings of phase: it stands
/// for the goal the DMP holds afterwards. With only its share of the time
/// axis (half a sample period) a denser recording weighed the end less and
/// let it drift: at overlap 0.7 a 1 kHz fit's largest error, at `t = τ`,
/// was 45 % above a 100 Hz fit's; with this weight they agree within 1 %.
const END_WEIGHT: f64 = 0.5;

/// What the weights are fitted to.
#[derive(Clone, Copy)]
struct Demonstration<'a> {
    pub times: &'a [f32],
    pub rows: &'a Rows<'a>,
    pub dof: usize,
    pub kernels: usize,
    pub alpha: f32,
    pub width: f32,
    /// Kernel spacings beyond each end.
    pub margin: f32,
    /// Fit to every `stride`-th sample and the last (1: all).
    pub stride: usize,
    pub ridge: f32,
    /// Per DoF: start, goal, forcing amplitude (`g − y0` or 1).
    pub start: &'a [f32],
    pub goal: &'a [f32],
    pub amplitude: &'a [f32],
    /// Per DoF, the velocity at the goal (empty: at rest).
    pub velocity: &'a [f32],
}

/// The normalized kernels `φ_k(u)` (zero for `u ≥ 1`), over the same
/// window of kernels as the execution's forcing term.
fn basis<const K: usize>(u: f64, width: f32, layout: &Layout, phi: &mut [f64; K]) {
    for p in phi.iter_mut() {
        *p = 0.0;
    }
    if !(u < 1.0) {
        return;
    }
    let (lo, hi, nearest) = layout.window(u as f32, width);
    let spacing = 1.0 / f64::from(layout.span());
    let margin = f64::from(layout.margin());
    let d0 = u - (nearest as f64 - margin) * spacing;
    let base = d0 * d0;
    let width = f64::from(width);
    let mut sum = 0.0;
    for (k, p) in (lo..=hi).zip(phi.iter_mut().skip(lo)) {
        let ds = u - (k as f64 - margin) * spacing;
        *p = libm::exp(-width * (ds * ds - base));
        sum += *p;
    }
    if sum > 0.0 {
        for p in phi.iter_mut().take(hi + 1).skip(lo) {
            *p /= sum;
        }
    }
}

/// Fits the weights of every DoF into `out[d][..kernels]`.
/// Returns the residual: the time-weighted sum of squared position errors
/// at the samples, over all DoFs (in the demonstration's units).
fn weights<const D: usize, const K: usize>(
    demo: &Demonstration,
    out: &mut [[f32; K]; D],
) -> Result<f64, Error> {
    let kernels = demo.kernels.min(K);
    let dof = demo.dof.min(D);
    let (Some(&t0), Some(&t_end)) = (demo.times.first(), demo.times.last()) else {
        return Err(Error::OutOfRange(
            "a demonstration needs at least 3 samples",
        ));
    };
    let (t0, tau) = (f64::from(t0), f64::from(t_end) - f64::from(t0));
    let alpha = f64::from(demo.alpha);
    let layout = Layout::new(kernels, demo.margin);
    let spacing = 1.0 / f64::from(layout.span());
    let h_max = spacing / SUBSTEPS_PER_SPACING;
    let (mut gram, mut rhs) = ([[0.0f64; K]; K], [[0.0f64; K]; D]);
    let mut normal = Normal::new(&mut gram, &mut rhs, kernels, dof);
    let mut responses = Responses::<K>::new(alpha, kernels, h_max);
    let mut basis = |u: f64, phi: &mut [f64; K]| basis(u, demo.width, &layout, phi);
    let (n, stride) = (demo.times.len(), demo.stride.max(1));
    let mut i = 0usize;
    (demo.rows)(&mut |row: &[f32]| {
        let last = i + 1 == n;
        if !i.is_multiple_of(stride) && !last {
            i += 1;
            return;
        }
        let time = |j: usize| demo.times.get(j).map(|t| f64::from(*t));
        let ti = time(i).unwrap_or(t0);
        let u = (ti - t0) / tau;
        let r = responses.sample(u, &mut basis);
        // The sample's share of the time axis, between the kept neighbours.
        let prev = match i {
            0 => ti,
            _ => time((i - 1) / stride * stride).unwrap_or(ti),
        };
        let next = match last {
            true => ti,
            false => time((i + stride).min(n - 1)).unwrap_or(ti),
        };
        let mut q = 0.5 * (next - prev) / tau;
        if last {
            q += END_WEIGHT * spacing;
        }
        // The unforced spring from rest at y0: y_h = g + (y0 − g)(1 + αu/2)e^(−αu/2).
        // With a goal moving at ġ until τ and fed forward, the goal
        // itself, `g − c(1 − u)` (c = ġτ), is the particular solution,
        // and from rest y_h = g − c(1 − u) + ((y0 − g + c)(1 + αu/2) − cu)e^(−αu/2).
        let fade = libm::exp(-0.5 * alpha * u);
        let decay = (1.0 + 0.5 * alpha * u) * fade;
        normal.add(q, r, |d| {
            let at = |v: &[f32]| v.get(d).map_or(0.0, |x| f64::from(*x));
            let (y0, g, a) = (at(demo.start), at(demo.goal), at(demo.amplitude));
            let c = at(demo.velocity) * tau;
            let unforced = match c {
                0.0 => g + (y0 - g) * decay,
                c => g - c * (1.0 - u) + (y0 - g + c) * decay - c * u * fade,
            };
            (at(row) - unforced) / a
        });
        i += 1;
    });
    let residual = normal.solve_with_residual(demo.ridge, out)?;
    // The targets were divided by the amplitudes.
    Ok(residual
        .iter()
        .zip(demo.amplitude)
        .take(dof)
        .map(|(r, a)| r * f64::from(*a) * f64::from(*a))
        .sum())
}
