//! What a fit may be asked for and the ranges a DMP keeps to: the gains,
//! the kernels' overlap and margin, the amplitude scaling, and the bounds
//! of positions, weights, `τ` and `α` (why they hold: [`crate::dmp`],
//! "Bounds, and reaching the goal").

use serde::{Deserialize, Serialize};

use crate::Error;

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
    /// The DoFs whose bit is set (positions: not an orientation's log
    /// coordinates) scaled together, as Koutras & Doulgeri (2020) scale
    /// them: their forcing term, as demonstrated, turned by the smallest
    /// rotation that takes the demonstrated `g − y0` onto the executed
    /// one and stretched by the ratio of their lengths; the others
    /// unscaled. A coordinate whose goal meets its start keeps its shape,
    /// turned. Needs the demonstrated `g ≠ y0` on those DoFs. With the
    /// `global-scaling` feature (a default one).
    #[cfg(feature = "global-scaling")]
    Global(u32),
}

impl Scaling {
    /// Whether the DoFs are scaled globally.
    pub(super) fn is_global(&self) -> bool {
        #[cfg(feature = "global-scaling")]
        if let Scaling::Global(_) = self {
            return true;
        }
        false
    }
}

/// Options for [`Dmp::fit`](super::Dmp::fit).
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
    /// The velocity the DMP reaches its goal with.
    pub final_velocity: FinalVelocity,
}

/// The velocity a fitted DMP reaches its goal with, at `τ`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum FinalVelocity {
    /// At rest, whatever the demonstration's end: the classic DMP.
    #[default]
    AtRest,
    /// The demonstration's: the slope of a straight line fitted to its
    /// last [`FINAL_VELOCITY_WINDOW`] of the duration (at least its last
    /// two samples). The goal moves at that velocity until `τ` (Kober et
    /// al. 2010's hitting DMP), so a throw or a strike replays as
    /// demonstrated, and a new velocity ([`Execution::goal_velocity`](super::Execution::goal_velocity))
    /// changes the end's speed and nothing that does not need to change.
    Demonstrated,
}

/// The end of a demonstration whose slope is its final velocity, as a
/// fraction of its duration: 2 %, 20 ms of a one-second throw.
pub const FINAL_VELOCITY_WINDOW: f32 = 0.02;

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
        final_velocity: FinalVelocity::AtRest,
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
            final_velocity: FinalVelocity::AtRest,
        }
    }
}

/// The widest margin `kernels` kernels allow: `(K − 2)/2` spacings leave
/// `K − 1 − 2m = 1` spacing between the ends.
pub fn max_margin(kernels: usize) -> f32 {
    (kernels as f32 - 2.0) / 2.0
}

/// A margin in `[0, max_margin]` (NaN and infinities are not).
pub(super) fn check_margin(m: f32, kernels: usize) -> Result<(), Error> {
    if (0.0..=max_margin(kernels)).contains(&m) {
        Ok(())
    } else {
        Err(Error::OutOfRange(
            "margin must be finite, >= 0 and leave one kernel spacing between the ends",
        ))
    }
}

pub(super) fn check_tau(tau: f32, what: &'static str) -> Result<(), Error> {
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
        Err(Error::OutOfRange("alpha must be in [0.01, 10000]"))
    }
}
