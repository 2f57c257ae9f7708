//! Discrete, multi-DoF Dynamic Movement Primitives of fixed capacity.
//!
//! # Formulation
//!
//! Per degree of freedom, with `τ` the execution time in seconds (the
//! movement runs from `t = 0` to `t = τ`; there is no separate "execution
//! time" knob):
//!
//! ```text
//! τ ż = α (β (g − y) − z) + a · f(s),   τ ẏ = z,   β = α / 4
//! s   = min(t / τ, 1)                              (phase)
//! f(s) = Σ ψ_k(s) w_k / Σ ψ_k(s) for s < 1, 0 for s ≥ 1
//! ψ_k(s) = exp(−h (s − c_k)²),  c_k = (k − m) / (K − 1 − 2m)
//! a   = g − y0  (amplitude-scaled DoF)  or  1  (loop-like DoF)
//! ```
//!
//! Why this form, against the anchors' known failures:
//! - The forcing term is scaled by the new amplitude `g − y0`, so a goal moved
//!   close to the start shrinks the whole shape instead of overshooting
//!   (movement_primitives issue 70).
//! - A DoF whose demonstration starts and ends (almost) at the same place
//!   cannot be amplitude-scaled; it keeps an unscaled forcing term, so loops
//!   and shakes are reproduced (pydmps issue 5). [`Scaling::Auto`] decides per
//!   DoF; [`Scaling::Mask`] overrides.
//! - The phase reaches 1 exactly at `t = τ` and the forcing term is exactly zero
//!   afterwards: no Pastor-style `x(T) ≠ 0` residue pulling away from the goal.
//! - The kernels are uniform in `s`, so only the few within reach of the
//!   current phase are evaluated (see [`Dmp::forcing`]).
//! - The outer kernels may lie `m` spacings beyond the movement's ends
//!   ([`Margin`]). With `m = 0` the first and last kernels sit on the ends,
//!   where the normalized kernels can hardly bend: once a movement is
//!   resolved (enough kernels) that is where most of a fit's error is, and
//!   one spacing beyond each end reproduces it up to 30× better. With few
//!   kernels the interior's resolution counts more, so a fit tries both
//!   and keeps the better ([`Margin::Auto`]).
//! - The spring-damper is critically damped and linear, so a step with the
//!   forcing held at its mid-step value is integrated exactly (matrix
//!   exponential), not by Euler: any `dt` is stable and the error is
//!   second order in `dt` only through the forcing term.
//!
//! # Bounds, and reaching the goal
//!
//! A DMP takes values only in documented ranges, and within them every
//! sample it integrates is finite (the `dmp` fuzz target checks this on
//! arbitrary demonstrations, gains, goals and steps): weights within
//! ±[`MAX_ABS_WEIGHT`], starts and goals within ±[`MAX_ABS_POSITION`], `α`
//! in [[`MIN_ALPHA`], [`MAX_ALPHA`]], `τ ≥` [`MIN_TAU`], any `dt > 0`.
//!
//! It reaches its goal whatever the weights within those bounds: once the
//! phase is 1 (the first step past `τ`) the forcing term is exactly zero
//! and each step is the exact solution of the critically damped spring, so
//! `s·τ` seconds later
//!
//! ```text
//! |y − g| ≤ (1 + αs/2)·e^(−αs/2) · (|y − g| + 2τ|ẏ|/α at phase 1)
//! ```
//!
//! up to `f32` rounding: below 4e−10 of that deviation by `s = 50/α` (2τ
//! at the default `α` = 25). Property-tested in `core/tests/properties.rs`.
//!
//! # Parameter vector
//!
//! [`Dmp::params`] / [`Dmp::set_params`] expose `θ` for generalization and
//! learning, laid out as `[w_{0,0..K}, w_{1,0..K}, …, w_{D−1,0..K}, g_0, …,
//! g_{D−1}, τ]`: `D·K + D + 1` values (7 joints × 30 kernels → 218).
//!
//! ```
//! use primo_core::dmp::{Dmp, FitOptions};
//! let t: Vec<f32> = (0..=200).map(|i| i as f32 / 200.0).collect();
//! // Two DoF, row-major samples.
//! let y: Vec<f32> = t.iter().flat_map(|&t| [t, 1.0 - t * t]).collect();
//! let dmp = Dmp::<2, 15>::fit(&t, &y, 2, 15, &FitOptions::default())?;
//! let mut exec = dmp.execution();
//! exec.goal[0] = 2.0; // new goal for DoF 0
//! exec.tau = 2.0; // twice as slow
//! let last = dmp.trajectory(&exec, 0.01)?.last().unwrap();
//! assert_eq!(last.time, 2.0);
//! assert!((last.position[0] - 2.0).abs() < 1e-2);
//! # Ok::<(), primo_core::Error>(())
//! ```

pub(crate) mod fit;

use heapless::Vec;
use serde::{Deserialize, Serialize};

use crate::Error;
use crate::error::{check_bounded, check_capacity, check_finite, check_len};

/// Default spring gain `α` (with `β = α / 4`, critically damped).
pub const DEFAULT_ALPHA: f32 = 25.0;
/// Default kernel overlap `h·Δc²`: neighbouring kernels cross at
/// `exp(−overlap/4)` (0.84): of 0.5, 0.7, 1 and 2, the best or within 4 %
/// of the best reproduction with 30 kernels on `bench/compare_dmp.sh`'s
/// movements (2 was up to 10× worse), within 15 % with 10.
pub const DEFAULT_OVERLAP: f32 = 0.7;
/// Kernel overlap of the DMPs of skills that are learned (the pour, task
/// files): narrower kernels (neighbours cross at 0.61), so that PoWER's
/// exploration of one weight changes the movement locally. With
/// [`DEFAULT_OVERLAP`] the pour needed 85 instead of 25 roll-outs to a mean
/// reward of 0.95 (`primo experiment power`, median of 20 seeds).
pub const LEARNING_OVERLAP: f32 = 2.0;
/// Kernels with `h (s − c)² > KERNEL_CUTOFF` (ψ < 1.4e−11) are skipped.
pub const KERNEL_CUTOFF: f32 = 25.0;
/// Largest |start|, |goal| (any unit) a DMP accepts: far beyond any robot,
/// and small enough that no intermediate sum can overflow `f32`.
pub const MAX_ABS_POSITION: f32 = 1e6;
/// Largest |kernel weight| a DMP accepts.
pub const MAX_ABS_WEIGHT: f32 = 1e9;
/// Shortest duration `τ`, s (one cycle of a 1 kHz robot interface): the
/// acceleration `(…)/τ²` of any accepted DMP stays finite (a `τ` of 1e−35 s
/// made it ∞).
pub const MIN_TAU: f32 = 1e-3;
/// Smallest spring gain `α`: the equilibrium `g + f/(α²/4)` of a forcing
/// term of [`MAX_ABS_WEIGHT`] × the widest amplitude stays far inside
/// `f32` (a subnormal `α` made it ∞, and the movement NaN).
pub const MIN_ALPHA: f32 = 1e-2;
/// Largest spring gain `α`.
pub const MAX_ALPHA: f32 = 1e4;
/// [`Scaling::Auto`] scales a DoF only if `|g − y0|` is at least this
/// fraction of the demonstration's range on that DoF.
pub const AUTO_SCALING_MIN_FRACTION: f32 = 0.1;

/// Where a fit puts its outer kernels.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize, Default)]
pub enum Margin {
    /// Fits with [`AUTO_MARGIN`] spacings and with none, and keeps the one
    /// that reproduces the demonstration better (time-weighted squared
    /// error over all DoFs; judged on at least
    /// [`AUTO_SAMPLES_PER_SPACING`] samples per kernel of a denser
    /// recording). The fit takes 1.2 to 2 times as long.
    #[default]
    Auto,
    /// This many kernel spacings beyond each end (0: the first kernel on the
    /// start, the last on the end; at most `(K − 2)/2`).
    Spacings(f32),
}

/// The margin [`Margin::Auto`] tries besides none, in kernel spacings.
pub const AUTO_MARGIN: f32 = 1.0;
/// [`Margin::Auto`] chooses on every `s`-th sample, `s` the largest that
/// keeps this many samples per kernel (then fits all with its choice).
pub const AUTO_SAMPLES_PER_SPACING: usize = 32;

/// Which DoFs scale their forcing term by the amplitude `g − y0`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize, Default)]
pub enum Scaling {
    /// Per DoF: scaled unless `|g − y0|` is below
    /// [`AUTO_SCALING_MIN_FRACTION`] of the demonstrated range (a loop).
    #[default]
    Auto,
    /// Every DoF scaled.
    Always,
    /// No DoF scaled (Ijspeert 2002 behaviour).
    Never,
    /// Bit `d` set: DoF `d` scaled (DoFs ≥ 32 are unscaled).
    Mask(u32),
    /// [`Scaling::Auto`] for the DoFs whose bit is set, unscaled for the
    /// others (e.g. the log coordinates of an orientation).
    AutoWhere(u32),
}

/// Options for [`Dmp::fit`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct FitOptions {
    /// Spring gain `α` in [[`MIN_ALPHA`], [`MAX_ALPHA`]].
    pub alpha: f32,
    /// Kernel overlap `h·Δc² > 0`; larger means narrower kernels.
    pub overlap: f32,
    /// Ridge regularization, relative to the mean diagonal of the Gram
    /// matrix. The default 1e−9 only guards the `f64` solve: 1e−6 kept a
    /// margin's outer kernels from fitting (the helix of
    /// `bench/compare_dmp.sh` 10× worse) and cost up to 40 % without one.
    pub ridge: f32,
    /// Which DoFs are amplitude-scaled.
    pub scaling: Scaling,
    /// Where the outer kernels go.
    pub margin: Margin,
}

impl FitOptions {
    /// The fit of the DMPs of skills that are learned (the pour, task
    /// files): the narrower kernels of [`LEARNING_OVERLAP`], none beyond
    /// the ends and a ridge of 1e−6, the fit PoWER's roll-out counts were
    /// measured with. The margin is fixed because the examples of one
    /// skill must share their kernels to be generalized (an automatic
    /// choice may differ between them).
    pub const LEARNING: FitOptions = FitOptions {
        alpha: DEFAULT_ALPHA,
        overlap: LEARNING_OVERLAP,
        ridge: 1e-6,
        scaling: Scaling::Auto,
        margin: Margin::Spacings(0.0),
    };
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            alpha: DEFAULT_ALPHA,
            overlap: DEFAULT_OVERLAP,
            ridge: 1e-9,
            scaling: Scaling::Auto,
            margin: Margin::Auto,
        }
    }
}

/// A fitted DMP with capacity `D` DoF and `K` kernels per DoF; the actual
/// sizes are [`Dmp::dof`] ≤ `D` and [`Dmp::kernels`] ≤ `K`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DmpFields<D, K>")]
pub struct Dmp<const D: usize, const K: usize> {
    tau: f32,
    alpha: f32,
    width: f32,
    margin: f32,
    start: Vec<f32, D>,
    goal: Vec<f32, D>,
    scaled: Vec<bool, D>,
    weights: Vec<Vec<f32, K>, D>,
}

/// The serialized form, checked before it becomes a [`Dmp`].
#[derive(Deserialize)]
struct DmpFields<const D: usize, const K: usize> {
    tau: f32,
    alpha: f32,
    width: f32,
    /// Absent from DMPs saved before margins existed: none.
    #[serde(default)]
    margin: f32,
    start: Vec<f32, D>,
    goal: Vec<f32, D>,
    scaled: Vec<bool, D>,
    weights: Vec<Vec<f32, K>, D>,
}

impl<const D: usize, const K: usize> TryFrom<DmpFields<D, K>> for Dmp<D, K> {
    type Error = Error;
    fn try_from(f: DmpFields<D, K>) -> Result<Self, Error> {
        let n = f.start.len();
        if n == 0 {
            return Err(Error::OutOfRange("a DMP needs at least one DoF"));
        }
        check_len("goal", n, f.goal.len())?;
        check_len("scaled", n, f.scaled.len())?;
        check_len("weights (rows)", n, f.weights.len())?;
        let k = f.weights.first().map_or(0, |w| w.len());
        if k < 2 {
            return Err(Error::OutOfRange("a DMP needs at least two kernels"));
        }
        for row in &f.weights {
            check_len("weights (row)", k, row.len())?;
            check_bounded(row, MAX_ABS_WEIGHT, "weights beyond MAX_ABS_WEIGHT")?;
        }
        check_bounded(&f.start, MAX_ABS_POSITION, "start beyond MAX_ABS_POSITION")?;
        check_bounded(&f.goal, MAX_ABS_POSITION, "goal beyond MAX_ABS_POSITION")?;
        check_tau(f.tau, "tau must be finite and >= MIN_TAU")?;
        check_alpha(f.alpha)?;
        check_positive(f.width, "width must be finite and > 0")?;
        check_margin(f.margin, k)?;
        Ok(Dmp {
            tau: f.tau,
            alpha: f.alpha,
            width: f.width,
            margin: f.margin,
            start: f.start,
            goal: f.goal,
            scaled: f.scaled,
            weights: f.weights,
        })
    }
}

pub(crate) fn check_positive(v: f32, what: &'static str) -> Result<(), Error> {
    if v.is_finite() && v > 0.0 {
        Ok(())
    } else {
        Err(Error::OutOfRange(what))
    }
}

/// The widest margin `kernels` kernels allow: `(K − 2)/2` spacings leave
/// `K − 1 − 2m = 1` spacing between the ends.
pub fn max_margin(kernels: usize) -> f32 {
    (kernels as f32 - 2.0) / 2.0
}

/// A margin in `[0, max_margin]` (NaN and infinities are not).
fn check_margin(m: f32, kernels: usize) -> Result<(), Error> {
    if (0.0..=max_margin(kernels)).contains(&m) {
        Ok(())
    } else {
        Err(Error::OutOfRange(
            "margin must be finite, >= 0 and leave one kernel spacing between the ends",
        ))
    }
}

/// Kernel spacings between the movement's ends: `K − 1 − 2m`.
fn span(kernels: usize, margin: f32) -> f32 {
    kernels.saturating_sub(1) as f32 - 2.0 * margin
}

pub(crate) fn check_tau(tau: f32, what: &'static str) -> Result<(), Error> {
    if tau.is_finite() && tau >= MIN_TAU {
        Ok(())
    } else {
        Err(Error::OutOfRange(what))
    }
}

pub(crate) fn check_alpha(alpha: f32) -> Result<(), Error> {
    if (MIN_ALPHA..=MAX_ALPHA).contains(&alpha) {
        Ok(())
    } else {
        Err(Error::OutOfRange("alpha must be in [MIN_ALPHA, MAX_ALPHA]"))
    }
}

/// A demonstration's rows, visited in order: `rows(visit)` calls `visit`
/// with each row (`dof` positions) of the demonstration, first to last.
pub(crate) type Rows<'a> = dyn Fn(&mut dyn FnMut(&[f32])) + 'a;

/// A DMP's gains, kernel width and amplitude scaling: with θ and a start,
/// all that [`Dmp::from_shape`] needs, and small enough for one wire frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Shape {
    /// Spring gain `α`.
    pub alpha: f32,
    /// Kernel width `h`.
    pub width: f32,
    /// Kernels beyond each end, in spacings ([`Margin::Spacings`]).
    pub margin: f32,
    /// Bit `d` set: DoF `d`'s forcing term is scaled by its amplitude.
    pub scaled: u32,
}

/// Where and how fast to execute a DMP: start, goal and duration `τ`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Execution<const D: usize> {
    /// Execution time in seconds (≥ [`MIN_TAU`]).
    pub tau: f32,
    /// Start position, one value per DoF.
    pub start: Vec<f32, D>,
    /// Goal position, one value per DoF.
    pub goal: Vec<f32, D>,
}

/// Fits `demo`'s weights into `out` with the kernels `margin` spacings
/// beyond the ends at `overlap`, on every `stride`-th sample; returns the
/// residual and the kernel width. Never inlined: [`Margin::Auto`] calls it
/// up to three times, and on the M4F one frame must serve them all.
#[inline(never)]
fn fit_layout<const D: usize, const K: usize>(
    demo: &fit::Demonstration,
    overlap: f32,
    margin: f32,
    stride: usize,
    out: &mut [[f32; K]; D],
) -> Result<(f64, f32), Error> {
    let spacing = 1.0 / span(demo.kernels, margin);
    let width = overlap / (spacing * spacing);
    check_positive(width, "overlap too large for this many kernels")?;
    let residual = fit::weights(
        &fit::Demonstration {
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
            "fitted weights beyond MAX_ABS_WEIGHT (demo too short or too noisy for the kernels?)",
        )?;
    }
    Ok((residual, width))
}

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
        check_tau(tau, "demonstration duration must be finite and >= MIN_TAU")?;
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
            return Err(Error::OutOfRange("positions beyond MAX_ABS_POSITION"));
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
            };
            if on && amplitude == 0.0 {
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
        for (d, a) in amplitude.iter_mut().enumerate().take(dof) {
            if scaled.get(d) == Some(&true) {
                *a = goal.get(d).copied().unwrap_or(0.0) - start.get(d).copied().unwrap_or(0.0);
            }
        }
        let demo = fit::Demonstration {
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
            weights: weights
                .iter()
                .take(dof)
                .map(|w| w.iter().copied().take(kernels).collect())
                .collect(),
        })
    }

    /// Number of degrees of freedom.
    pub fn dof(&self) -> usize {
        self.start.len()
    }

    /// Number of kernels per DoF.
    pub fn kernels(&self) -> usize {
        self.weights.first().map_or(0, |w| w.len())
    }

    /// The demonstrated duration (default `τ`), in seconds.
    pub fn tau(&self) -> f32 {
        self.tau
    }

    /// The demonstrated start.
    pub fn start_position(&self) -> &[f32] {
        &self.start
    }

    /// The default goal (the demonstrated one unless changed by
    /// [`Dmp::set_params`]).
    pub fn goal(&self) -> &[f32] {
        &self.goal
    }

    /// Kernel spacings beyond each end of the movement ([`Margin`]).
    pub fn margin(&self) -> f32 {
        self.margin
    }

    /// Whether DoF `d`'s forcing term is scaled by its amplitude.
    pub fn is_scaled(&self, d: usize) -> bool {
        self.scaled.get(d).copied().unwrap_or(false)
    }

    /// The kernel weights of DoF `d`.
    pub fn weights(&self, d: usize) -> &[f32] {
        self.weights.get(d).map_or(&[], |w| w.as_slice())
    }

    /// Length of the parameter vector: `dof·kernels + dof + 1`.
    pub fn param_len(&self) -> usize {
        self.dof() * self.kernels() + self.dof() + 1
    }

    /// Writes `θ = [weights row by row, goals, τ]` into `out[..param_len()]`.
    pub fn params(&self, out: &mut [f32]) -> Result<(), Error> {
        let len = self.param_len();
        let found = out.len();
        let out = out.get_mut(..len).ok_or(Error::Length {
            what: "parameter buffer",
            expected: len,
            found,
        })?;
        let values = self
            .weights
            .iter()
            .flatten()
            .chain(self.goal.iter())
            .chain([&self.tau]);
        for (o, v) in out.iter_mut().zip(values) {
            *o = *v;
        }
        Ok(())
    }

    /// Sets weights, goals and `τ` from `θ` (exactly [`Dmp::param_len`] values).
    /// On error the DMP is unchanged.
    pub fn set_params(&mut self, theta: &[f32]) -> Result<(), Error> {
        check_len("parameter vector", self.param_len(), theta.len())?;
        let (k, n) = (self.kernels(), self.dof());
        let (weights, rest) = theta.split_at(n * k);
        check_bounded(weights, MAX_ABS_WEIGHT, "weights beyond MAX_ABS_WEIGHT")?;
        check_bounded(
            rest.get(..n).unwrap_or(&[]),
            MAX_ABS_POSITION,
            "goals beyond MAX_ABS_POSITION",
        )?;
        let tau = theta.last().copied().unwrap_or(0.0);
        check_tau(tau, "tau must be finite and >= MIN_TAU")?;
        for (row, chunk) in self.weights.iter_mut().zip(theta.chunks_exact(k)) {
            row.copy_from_slice(chunk);
        }
        let goals = theta.get(n * k..n * k + n).unwrap_or(&[]);
        self.goal.copy_from_slice(goals);
        self.tau = tau;
        Ok(())
    }

    /// Sets the default goal (one value per DoF).
    pub(crate) fn set_goal_vector(&mut self, goal: &[f32]) -> Result<(), Error> {
        check_len("goal", self.dof(), goal.len())?;
        check_bounded(goal, MAX_ABS_POSITION, "goals beyond MAX_ABS_POSITION")?;
        self.goal.copy_from_slice(goal);
        Ok(())
    }

    /// Everything but θ that defines the DMP's motion.
    pub fn shape(&self) -> Shape {
        let scaled = self
            .scaled
            .iter()
            .enumerate()
            .filter(|(d, s)| **s && *d < 32)
            .fold(0u32, |m, (d, _)| m | 1 << d);
        Shape {
            alpha: self.alpha,
            width: self.width,
            margin: self.margin,
            scaled,
        }
    }

    /// Rebuilds a DMP of `dof` DoF and `kernels` kernels from its shape, a
    /// start and `θ = [weights row by row, goals, τ]`, with the same checks
    /// as a deserialized one. `Dmp::from_shape(&d.shape(), …, θ of d)`
    /// moves exactly as `d`.
    pub fn from_shape(
        shape: &Shape,
        dof: usize,
        kernels: usize,
        start: &[f32],
        theta: &[f32],
    ) -> Result<Self, Error> {
        check_capacity("DoF", dof, D)?;
        check_capacity("kernels", kernels, K)?;
        check_len("start", dof, start.len())?;
        let zeros = |n| core::iter::repeat_n(0.0f32, n);
        let mut dmp = Self::try_from(DmpFields {
            tau: 1.0,
            alpha: shape.alpha,
            width: shape.width,
            margin: shape.margin,
            start: start.iter().copied().collect(),
            goal: zeros(dof).collect(),
            scaled: (0..dof)
                .map(|d| d < 32 && shape.scaled >> d & 1 == 1)
                .collect(),
            weights: (0..dof).map(|_| zeros(kernels).collect()).collect(),
        })?;
        dmp.set_params(theta)?;
        Ok(dmp)
    }

    /// The default execution: demonstrated start, current goal and `τ`.
    pub fn execution(&self) -> Execution<D> {
        Execution {
            tau: self.tau,
            start: self.start.clone(),
            goal: self.goal.clone(),
        }
    }

    /// The unscaled forcing term `Σψw/Σψ` of every DoF at phase `s`, written
    /// to `out[..dof]`; zero for `s ≥ 1`. Only kernels within
    /// `h (s − c)² ≤ KERNEL_CUTOFF` are summed (about 7 at the default
    /// overlap, whatever `K`).
    pub fn forcing(&self, s: f32, out: &mut [f32]) {
        for o in out.iter_mut() {
            *o = 0.0;
        }
        let kernels = self.kernels();
        if !(s < 1.0) || kernels < 2 {
            return;
        }
        let mut psi = [0.0f32; K];
        let layout = Layout::new(kernels, self.margin);
        let (lo, hi, sum) = activations(s.max(0.0), self.width, &layout, &mut psi);
        let Some(active) = psi.get(lo..=hi) else {
            return;
        };
        for (o, w) in out.iter_mut().zip(self.weights.iter()) {
            let dot: f32 = w
                .get(lo..=hi)
                .unwrap_or(&[])
                .iter()
                .zip(active)
                .map(|(w, p)| w * p)
                .sum();
            *o = dot / sum;
        }
    }

    fn check_execution(&self, exec: &Execution<D>) -> Result<(), Error> {
        check_len("execution start", self.dof(), exec.start.len())?;
        check_len("execution goal", self.dof(), exec.goal.len())?;
        check_bounded(
            &exec.start,
            MAX_ABS_POSITION,
            "execution start beyond MAX_ABS_POSITION",
        )?;
        check_bounded(
            &exec.goal,
            MAX_ABS_POSITION,
            "execution goal beyond MAX_ABS_POSITION",
        )?;
        check_tau(exec.tau, "execution tau must be finite and >= MIN_TAU")
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
        };
        for (dst, src) in run.start.iter_mut().zip(&exec.start) {
            *dst = *src;
        }
        run.y = run.start;
        run.set_goal(self, &exec.goal)?;
        // Forcing at s = 0 gives the initial acceleration.
        let mut force = [0.0; D];
        self.forcing(0.0, &mut force);
        for ((f, raw), a) in run.force.iter_mut().zip(force).zip(run.amplitude) {
            *f = a * raw;
        }
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

/// Where the kernels are: `c_k = (k − margin)·spacing` for `k` in
/// `0..=last`.
pub(crate) struct Layout {
    /// Kernel spacings between the movement's ends, `1/spacing`.
    span: f32,
    margin: f32,
    last: f32,
}

impl Layout {
    pub(crate) fn new(kernels: usize, margin: f32) -> Self {
        Layout {
            span: span(kernels, margin),
            margin,
            last: kernels.saturating_sub(1).max(1) as f32,
        }
    }

    /// The distance between neighbouring kernels, in phase.
    pub(crate) fn spacing(&self) -> f32 {
        1.0 / self.span
    }

    /// Kernel spacings between the movement's ends.
    pub(crate) fn span(&self) -> f32 {
        self.span
    }

    /// Kernel spacings beyond each end.
    pub(crate) fn margin(&self) -> f32 {
        self.margin
    }

    /// The kernel index range `[lo, hi]` within reach of phase `s`, and
    /// the nearest kernel, which it always contains.
    pub(crate) fn window(&self, s: f32, width: f32) -> (usize, usize, usize) {
        let last = self.last;
        let reach = libm::sqrtf(KERNEL_CUTOFF / width) * self.span;
        let centre = s * self.span + self.margin;
        // `as usize` saturates, and the clamp keeps both ends inside [0, last].
        let lo = libm::ceilf(centre - reach).clamp(0.0, last) as usize;
        let hi = libm::floorf(centre + reach).clamp(0.0, last) as usize;
        let nearest = libm::roundf(centre).clamp(0.0, last) as usize;
        (lo.min(nearest), hi.max(nearest), nearest)
    }
}

/// Activations of the kernels within reach of phase `s`, relative to the
/// nearest kernel (which gets exactly 1, so the sum is ≥ 1 however narrow the
/// kernels): written to `psi[lo..=hi]`, returned with `lo`, `hi` and the sum.
fn activations<const K: usize>(
    s: f32,
    width: f32,
    layout: &Layout,
    psi: &mut [f32; K],
) -> (usize, usize, f32) {
    let spacing = layout.spacing();
    let (lo, hi, nearest) = layout.window(s, width);
    // The phase from kernel 0's centre (s itself without a margin, so
    // those DMPs move bit for bit as before margins existed).
    let from_first = s + layout.margin * spacing;
    let d0 = from_first - nearest as f32 * spacing;
    let base = d0 * d0;
    let mut sum = 0.0;
    for (k, p) in (lo..=hi).zip(psi.iter_mut().skip(lo)) {
        let ds = from_first - k as f32 * spacing;
        *p = libm::expf(-width * (ds * ds - base));
        sum += *p;
    }
    (lo, hi, sum)
}

/// `exp(A u)` of the critically damped spring-damper for `u = dt/τ`, as
/// `[Φ00, Φ01, Φ10, Φ11]` acting on `(y − y*, z)`.
pub(crate) fn transition(alpha: f32, u: f32) -> [f32; 4] {
    let a = 0.5 * alpha;
    let au = a * u;
    // Past 80 time constants the spring has settled (e^−80 < 2e−35); the
    // closed form would compute 0·∞ there.
    if !(au < 80.0) {
        return [0.0; 4];
    }
    let e = libm::expf(-au);
    [e * (1.0 + au), e * u, -e * a * au, e * (1.0 - au)]
}

/// [`transition`] with `Φ00 − 1` in place of `Φ00`: at 1 kHz `Φ00` is
/// within 1e−4 of 1, so `Φ00 − 1` from `Φ00` in `f32` would keep only three
/// digits of the spring's pull per step.
pub(crate) fn transition_step(alpha: f32, u: f32) -> [f32; 4] {
    let mut p = transition(alpha, u);
    let x = 0.5 * alpha * u;
    if let Some(p00) = p.first_mut() {
        // e^−x (1 + x) − 1 = Σ_{n≥2} (−1)^n (1 − n) xⁿ/n!: the series for
        // small x (the next term is below 1e−9 of the first at x = 0.25),
        // the closed form, with little cancellation, beyond.
        *p00 = if x < 0.25 {
            let tail = 1.0 / 144.0 - x * (1.0 / 840.0 - x / 5760.0);
            -x * x * (0.5 - x * (1.0 / 3.0 - x * (0.125 - x * (1.0 / 30.0 - x * tail))))
        } else {
            *p00 - 1.0
        };
    }
    p
}

/// `sum += inc`, Kahan-compensated: `carry` holds what the sum lost.
pub(crate) fn add_compensated(sum: &mut f32, carry: &mut f32, inc: f32) {
    let inc = inc - *carry;
    let t = *sum + inc;
    *carry = (t - *sum) - inc;
    *sum = t;
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
        dmp.forcing(self.phase + 0.5 * u, &mut self.force);
        let stiffness = self.alpha * self.alpha / 4.0;
        for (((((y, carry), z), f), g), a) in self
            .y
            .iter_mut()
            .zip(self.y_carry.iter_mut())
            .zip(self.z.iter_mut())
            .zip(self.force.iter_mut())
            .zip(self.goal)
            .zip(self.amplitude)
            .take(self.dof)
        {
            *f *= a;
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

    /// Moves the current position to `y` (one value per DoF), keeping the
    /// velocity: the same motion seen from a new origin.
    pub(crate) fn rebase<const K: usize>(
        &mut self,
        dmp: &Dmp<D, K>,
        y: &[f32],
    ) -> Result<(), Error> {
        check_len("position", self.dof, y.len())?;
        check_len("DMP DoF", self.dof, dmp.dof())?;
        check_bounded(y, MAX_ABS_POSITION, "position beyond MAX_ABS_POSITION")?;
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
        check_bounded(goal, MAX_ABS_POSITION, "goal beyond MAX_ABS_POSITION")?;
        for (d, (dst, &g)) in self.goal.iter_mut().zip(goal).enumerate() {
            *dst = g;
            if let (Some(a), Some(&y0)) = (self.amplitude.get_mut(d), self.start.get(d)) {
                *a = if dmp.is_scaled(d) { g - y0 } else { 1.0 };
            }
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

#[cfg(test)]
mod tests {
    use super::*;

    /// The full kernel sum, every kernel, no window: the reference for the
    /// windowed [`Dmp::forcing`].
    fn forcing_full<const D: usize, const K: usize>(dmp: &Dmp<D, K>, s: f32, out: &mut [f32]) {
        let k = dmp.kernels();
        let spacing = 1.0 / ((k - 1) as f32 - 2.0 * dmp.margin);
        let psi: std::vec::Vec<f32> = (0..k)
            .map(|i| {
                let ds = s - (i as f32 - dmp.margin) * spacing;
                libm::expf(-dmp.width * ds * ds)
            })
            .collect();
        let sum: f32 = psi.iter().sum();
        for (d, o) in out.iter_mut().enumerate().take(dmp.dof()) {
            *o = dmp
                .weights(d)
                .iter()
                .zip(&psi)
                .map(|(w, p)| w * p)
                .sum::<f32>()
                / sum;
        }
    }

    #[test]
    fn windowed_forcing_matches_full_sum() {
        for margin in [0.0, AUTO_MARGIN, 2.5] {
            windowed_forcing_matches_full_sum_with(margin);
        }
    }

    fn windowed_forcing_matches_full_sum_with(margin: f32) {
        // Weights in [-1, 1]: the forcing term is a convex combination of
        // them, so an absolute tolerance of 1e-6 is a relative one too.
        let span = 29.0 - 2.0 * margin;
        let mut dmp: Dmp<7, 30> = Dmp {
            tau: 1.0,
            alpha: DEFAULT_ALPHA,
            width: DEFAULT_OVERLAP * span * span,
            margin,
            start: Vec::from_slice(&[0.0; 7]).unwrap(),
            goal: Vec::from_slice(&[1.0; 7]).unwrap(),
            scaled: Vec::from_slice(&[true; 7]).unwrap(),
            weights: Vec::new(),
        };
        let mut seed = 12345u32;
        for _ in 0..7 {
            let row: Vec<f32, 30> = (0..30)
                .map(|_| {
                    seed = seed.wrapping_mul(1_664_525).wrapping_add(1_013_904_223);
                    (seed >> 8) as f32 / 8_388_608.0 - 1.0
                })
                .collect();
            dmp.weights.push(row).unwrap();
        }
        let (mut a, mut b) = ([0.0f32; 7], [0.0f32; 7]);
        let mut worst = 0.0f32;
        for i in 0..=10_000 {
            let s = i as f32 / 10_000.0 * 0.9999;
            dmp.forcing(s, &mut a);
            forcing_full(&dmp, s, &mut b);
            for (x, y) in a.iter().zip(&b) {
                worst = worst.max((x - y).abs());
            }
        }
        assert!(
            worst <= 1e-6,
            "windowed forcing differs by {worst} (margin {margin})"
        );
    }

    #[test]
    fn the_springs_pull_per_step_keeps_f32_precision() {
        for u in [
            1e-7f32, 1e-5, 1e-3, 0.004, 0.02, 0.0199, 0.0201, 0.1, 1.0, 7.0,
        ] {
            let x = 0.5 * 25.0 * f64::from(u);
            // The series in f64 where the closed form would cancel.
            let exact = if x < 1.0 {
                let (mut sum, mut term) = (0.0, 1.0);
                for n in 1..30 {
                    term *= -x / f64::from(n);
                    sum += term * f64::from(1 - n);
                }
                sum
            } else {
                libm::exp(-x) * (1.0 + x) - 1.0
            };
            let got = f64::from(transition_step(25.0, u)[0]);
            assert!(
                ((got - exact) / exact).abs() < 1e-6,
                "u = {u}: {got} vs {exact}"
            );
        }
        assert_eq!(transition_step(25.0, 1e3)[0], -1.0);
    }

    #[test]
    fn window_is_small_and_covers_nearest() {
        // Within reach: |s − c| ≤ √(cutoff/overlap) spacings either side.
        for (overlap, margin, most) in [
            (DEFAULT_OVERLAP, 0.0, 13),
            (DEFAULT_OVERLAP, AUTO_MARGIN, 13),
            (LEARNING_OVERLAP, 0.0, 8),
        ] {
            let layout = Layout::new(30, margin);
            let width = overlap * layout.span() * layout.span();
            for i in 0..=1000 {
                let s = i as f32 / 1000.0;
                let (lo, hi, nearest) = layout.window(s, width);
                assert!(lo <= nearest && nearest <= hi);
                assert!(lo <= hi && hi < 30);
                assert!(hi - lo < most, "window {lo}..={hi} at overlap {overlap}");
            }
        }
    }
}
