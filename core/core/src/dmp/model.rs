//! The DMP itself: its gains, kernels, start, goal and weights, the
//! checks a deserialized or rebuilt one passes, its parameter vector `θ`
//! and its forcing term.

use heapless::Vec;
use serde::{Deserialize, Serialize};

use super::kernels::{Layout, activations};
use super::options::{MAX_ABS_POSITION, MAX_ABS_WEIGHT, check_alpha, check_margin, check_tau};
use crate::Error;
use crate::error::{check_bounded, check_capacity, check_len, check_positive};

/// A fitted DMP with capacity `D` DoF and `K` kernels per DoF; the actual
/// sizes are [`Dmp::dof`] ≤ `D` and [`Dmp::kernels`] ≤ `K`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(try_from = "DmpFields<D, K>")]
pub struct Dmp<const D: usize, const K: usize> {
    pub(super) tau: f32,
    pub(super) alpha: f32,
    pub(super) width: f32,
    pub(super) margin: f32,
    pub(super) start: Vec<f32, D>,
    pub(super) goal: Vec<f32, D>,
    pub(super) scaled: Vec<bool, D>,
    /// Global scaling ([`Scaling::Global`](super::Scaling::Global)): the
    /// demonstrated `g − y0` of the scaled DoFs (0 on the others). Empty:
    /// each scaled DoF by its own amplitude.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) reference: Vec<f32, D>,
    /// The velocity at the goal at `τ`, per DoF per second (a hit, a
    /// throw: [`FinalVelocity`](super::FinalVelocity)). Empty: at rest.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub(super) goal_velocity: Vec<f32, D>,
    pub(super) weights: Vec<Vec<f32, K>, D>,
}

/// Whether `reference` is a global scaling's (empty, or one value per
/// DoF, bounded, zero off the scaled DoFs and not all zero on them).
pub(super) fn check_reference(reference: &[f32], scaled: &[bool]) -> bool {
    if reference.is_empty() {
        return true;
    }
    reference.len() == scaled.len()
        && reference
            .iter()
            .zip(scaled)
            .all(|(r, s)| libm::fabsf(*r) <= 2.0 * MAX_ABS_POSITION && (*s || *r == 0.0))
        && reference.iter().any(|r| *r != 0.0)
}

/// A goal velocity: empty, or one finite value per DoF within ±1e6/s.
pub(super) fn check_goal_velocity(v: &[f32], dof: usize) -> Result<(), Error> {
    if !v.is_empty() {
        check_len("goal velocity", dof, v.len())?;
        check_bounded(v, MAX_ABS_POSITION, "goal velocity beyond ±1e6 per second")?;
    }
    Ok(())
}

/// A goal moving at `v` for `τ`: its travel `vτ` within ±1e6, the bound
/// on any position (the run moves the goal by it, so it must not overflow).
pub(super) fn check_goal_travel(v: &[f32], tau: f32) -> Result<(), Error> {
    match v.iter().all(|v| libm::fabsf(v * tau) <= MAX_ABS_POSITION) {
        true => Ok(()),
        false => Err(Error::OutOfRange(
            "goal velocity × τ beyond ±1e6: the goal would travel beyond the bound on any position",
        )),
    }
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
    /// Absent from DMPs saved before global scaling existed: per DoF.
    #[serde(default)]
    reference: Vec<f32, D>,
    /// Absent from DMPs that end at rest.
    #[serde(default)]
    goal_velocity: Vec<f32, D>,
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
            check_bounded(
                row,
                MAX_ABS_WEIGHT,
                "weights beyond ±1e9, the bound on kernel weights",
            )?;
        }
        check_bounded(
            &f.start,
            MAX_ABS_POSITION,
            "start beyond ±1e6, the bound on any position",
        )?;
        check_bounded(
            &f.goal,
            MAX_ABS_POSITION,
            "goal beyond ±1e6, the bound on any position",
        )?;
        check_tau(f.tau, "tau must be finite and at least 0.001 s")?;
        check_alpha(f.alpha)?;
        check_positive(f.width, "width must be finite and > 0")?;
        check_margin(f.margin, k)?;
        if !check_reference(&f.reference, &f.scaled) {
            return Err(Error::OutOfRange(
                "reference must be empty or one finite value per DoF, 0 off the scaled DoFs and \
                 not all 0",
            ));
        }
        check_goal_velocity(&f.goal_velocity, n)?;
        Ok(Dmp {
            tau: f.tau,
            alpha: f.alpha,
            width: f.width,
            margin: f.margin,
            start: f.start,
            goal: f.goal,
            scaled: f.scaled,
            reference: f.reference,
            goal_velocity: f.goal_velocity,
            weights: f.weights,
        })
    }
}

/// A DMP's gains, kernel width and amplitude scaling: with θ and a start,
/// all that [`Dmp::from_shape`] needs, and small enough for one wire frame.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Shape {
    /// Spring gain `α`.
    pub alpha: f32,
    /// Kernel width `h`.
    pub width: f32,
    /// Kernels beyond each end, in spacings ([`Margin::Spacings`](super::Margin::Spacings)).
    pub margin: f32,
    /// Bit `d` set: DoF `d`'s forcing term is scaled by its amplitude.
    pub scaled: u32,
}

/// Where and how fast to execute a DMP: start, goal and duration `τ`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Execution<const D: usize> {
    /// Execution time in seconds (≥ [`MIN_TAU`](super::MIN_TAU)).
    pub tau: f32,
    /// Start position, one value per DoF.
    pub start: Vec<f32, D>,
    /// Goal position, one value per DoF.
    pub goal: Vec<f32, D>,
    /// Velocity at the goal at `τ`, one value per DoF, per second: the
    /// goal moves at it until `τ` (Kober et al. 2010) and the run reaches
    /// it moving so; afterwards the goal holds still and the run brakes
    /// back onto it. Empty: at rest, as the plain DMP.
    #[serde(default)]
    pub goal_velocity: Vec<f32, D>,
}

impl<const D: usize, const K: usize> Dmp<D, K> {
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

    /// Kernel spacings beyond each end of the movement ([`Margin`](super::Margin)).
    pub fn margin(&self) -> f32 {
        self.margin
    }

    /// Whether DoF `d`'s forcing term is scaled by its amplitude.
    pub fn is_scaled(&self, d: usize) -> bool {
        self.scaled.get(d).copied().unwrap_or(false)
    }

    /// Global scaling's demonstrated `g − y0` (0 off the scaled DoFs), or
    /// `None`: each scaled DoF by its own amplitude.
    pub fn reference(&self) -> Option<&[f32]> {
        Some(self.reference.as_slice()).filter(|r| !r.is_empty())
    }

    /// Scales the scaled DoFs globally about `reference` (one value per
    /// DoF, 0 off the scaled DoFs; see [`Dmp::reference`]), or per DoF
    /// with `None`: a DMP rebuilt by [`Dmp::from_shape`] takes its
    /// template's. On error the DMP is unchanged.
    pub fn set_reference(&mut self, reference: Option<&[f32]>) -> Result<(), Error> {
        let reference = reference.unwrap_or(&[]);
        if !check_reference(reference, &self.scaled) {
            return Err(Error::OutOfRange(
                "reference must be empty or one finite value per DoF, 0 off the scaled DoFs and \
                 not all 0",
            ));
        }
        self.reference = reference.iter().copied().collect();
        Ok(())
    }

    /// The velocity at the goal at `τ`, per DoF per second; empty when the
    /// DMP ends at rest.
    pub fn goal_velocity(&self) -> &[f32] {
        &self.goal_velocity
    }

    /// Sets the velocity at the goal at `τ`, one value per DoF per second
    /// (empty: at rest), as [`FinalVelocity::Demonstrated`](super::FinalVelocity::Demonstrated)
    /// fits it: a DMP rebuilt by [`Dmp::from_shape`] (a generalized one)
    /// takes its examples' this way. On error the DMP is unchanged.
    pub fn set_goal_velocity(&mut self, velocity: &[f32]) -> Result<(), Error> {
        check_goal_velocity(velocity, self.dof())?;
        self.goal_velocity = velocity.iter().copied().collect();
        Ok(())
    }

    /// The kernel weights of DoF `d`.
    pub fn weights(&self, d: usize) -> &[f32] {
        self.weights.get(d).map_or(&[], |w| w.as_slice())
    }

    /// Kernel `k`'s weight of DoF `d`, to change in place (unchecked
    /// against [`MAX_ABS_WEIGHT`]: the caller checks).
    pub(crate) fn weight_mut(&mut self, d: usize, k: usize) -> Option<&mut f32> {
        self.weights.get_mut(d)?.get_mut(k)
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
        check_bounded(
            weights,
            MAX_ABS_WEIGHT,
            "weights beyond ±1e9, the bound on kernel weights",
        )?;
        check_bounded(
            rest.get(..n).unwrap_or(&[]),
            MAX_ABS_POSITION,
            "goals beyond ±1e6, the bound on any position",
        )?;
        let tau = theta.last().copied().unwrap_or(0.0);
        check_tau(tau, "tau must be finite and at least 0.001 s")?;
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
        check_bounded(
            goal,
            MAX_ABS_POSITION,
            "goals beyond ±1e6, the bound on any position",
        )?;
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
            reference: Vec::new(),
            goal_velocity: Vec::new(),
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
            goal_velocity: self.goal_velocity.clone(),
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
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::dmp::options::{AUTO_MARGIN, DEFAULT_ALPHA, DEFAULT_OVERLAP};

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
            reference: Vec::new(),
            goal_velocity: Vec::new(),
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
}
