//! The weights of a fit: least squares on the demonstrated positions.
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
//! are ill-conditioned for `f32`). The responses are integrated with the
//! same scheme as [`super::Run`] (exact spring, forcing at mid-step), on
//! a fixed grid of 1/64 of the kernel spacing with one partial step to
//! each sample, so they do not depend on how densely or evenly the
//! demonstration is sampled. Memory: `2K`
//! response states, a `K × K` Gram matrix and `D × K` right-hand sides, on
//! the stack; no allocation.

use crate::Error;

/// Sub-steps per kernel spacing when integrating the responses.
pub(crate) const SUBSTEPS_PER_SPACING: f64 = 64.0;

/// Extra weight of the last sample, in kernel spacings of phase: it stands
/// for the goal the DMP holds afterwards. With only its share of the time
/// axis (half a sample period) a denser recording weighed the end less and
/// let it drift: at overlap 0.7 a 1 kHz fit's largest error, at `t = τ`,
/// was 45 % above a 100 Hz fit's; with this weight they agree within 1 %.
const END_WEIGHT: f64 = 0.5;

/// What the weights are fitted to.
#[derive(Clone, Copy)]
pub(super) struct Demonstration<'a> {
    pub times: &'a [f32],
    pub rows: &'a super::Rows<'a>,
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
}

/// `exp(A h)` of the critically damped spring in phase units, `f64`.
fn transition(alpha: f64, h: f64) -> [f64; 4] {
    let a = 0.5 * alpha;
    let ah = a * h;
    if !(ah < 700.0) {
        return [0.0; 4];
    }
    let e = libm::exp(-ah);
    [e * (1.0 + ah), e * h, -e * a * ah, e * (1.0 - ah)]
}

/// The normalized kernels `φ_k(u)` (zero for `u ≥ 1`), over the same
/// window of kernels as the execution's forcing term.
fn basis<const K: usize>(u: f64, width: f32, layout: &super::Layout, phi: &mut [f64; K]) {
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

/// The responses `r_k(u)` of the spring, from rest at phase 0, to each
/// kernel of a basis alone, and their phase derivatives: integrated with
/// the runtime's scheme on sub-steps of at most `h_max`.
pub(crate) struct Responses<const K: usize> {
    /// The responses at the current phase.
    pub r: [f64; K],
    /// Their phase derivatives.
    pub v: [f64; K],
    phase: f64,
    phi: [f64; K],
    /// The responses at the last [`Responses::sample`]d phase.
    at: [f64; K],
    alpha: f64,
    kernels: usize,
    h_max: f64,
}

impl<const K: usize> Responses<K> {
    /// At rest at phase 0.
    pub fn new(alpha: f64, kernels: usize, h_max: f64) -> Self {
        Responses {
            r: [0.0; K],
            v: [0.0; K],
            phase: 0.0,
            phi: [0.0; K],
            at: [0.0; K],
            alpha,
            kernels,
            h_max,
        }
    }

    /// Integrates on to phase `to` (nothing if it is not ahead);
    /// `basis(u, φ)` writes the kernels at phase `u`.
    pub fn advance(&mut self, to: f64, basis: &mut impl FnMut(f64, &mut [f64; K])) {
        let span = to - self.phase;
        if !(span > 0.0) {
            return;
        }
        let steps = libm::ceil(span / self.h_max).max(1.0);
        self.steps(steps as u32, span / steps, basis);
        self.phase = to;
    }

    /// The responses at phase `to` (not behind the last call) on a grid
    /// that does not depend on the samples: whole sub-steps of `h_max` from
    /// phase 0 up to `to`, then one partial step to `to` that is not kept.
    /// So every sampling rate fits the same model of the runtime (with
    /// [`Responses::advance`] a denser recording integrated on finer steps,
    /// further from a 1 ms replay's, and fitted it up to 8 % worse).
    pub fn sample(&mut self, to: f64, basis: &mut impl FnMut(f64, &mut [f64; K])) -> &[f64; K] {
        let done = libm::round(self.phase / self.h_max);
        let whole = libm::floor(to / self.h_max).max(done);
        self.steps((whole - done) as u32, self.h_max, basis);
        self.phase = whole * self.h_max;
        let rest = to - self.phase;
        self.at = self.r;
        if rest > 0.0 {
            let stiffness = self.alpha * self.alpha / 4.0;
            let [p00, p01, ..] = transition(self.alpha, rest);
            basis(self.phase + 0.5 * rest, &mut self.phi);
            for (((ak, rk), vk), pk) in self
                .at
                .iter_mut()
                .zip(&self.r)
                .zip(&self.v)
                .zip(&self.phi)
                .take(self.kernels)
            {
                let equilibrium = pk / stiffness;
                *ak = equilibrium + p00 * (rk - equilibrium) + p01 * vk;
            }
        }
        &self.at
    }

    /// `n` steps of `h` from the current phase (which it does not update).
    fn steps(&mut self, n: u32, h: f64, basis: &mut impl FnMut(f64, &mut [f64; K])) {
        let stiffness = self.alpha * self.alpha / 4.0;
        let [p00, p01, p10, p11] = transition(self.alpha, h);
        for s in 0..n {
            basis(self.phase + (f64::from(s) + 0.5) * h, &mut self.phi);
            for ((rk, vk), pk) in self
                .r
                .iter_mut()
                .zip(self.v.iter_mut())
                .zip(&self.phi)
                .take(self.kernels)
            {
                let equilibrium = pk / stiffness;
                let e = *rk - equilibrium;
                *rk = equilibrium + p00 * e + p01 * *vk;
                *vk = p10 * e + p11 * *vk;
            }
        }
    }
}

/// The normal equations of a least-squares fit on the responses: the Gram
/// matrix's lower triangle and one right-hand side per DoF, in the
/// caller's buffers (a few KiB: on the M4F's stack they must not be
/// copied).
pub(crate) struct Normal<'a, const D: usize, const K: usize> {
    gram: &'a mut [[f64; K]; K],
    rhs: &'a mut [[f64; K]; D],
    /// Per DoF, `Σ q·target²`: with the solution, the fit's residual.
    energy: [f64; D],
    kernels: usize,
    dof: usize,
}

impl<'a, const D: usize, const K: usize> Normal<'a, D, K> {
    /// Empty: `gram` and `rhs` must be all zeros.
    pub fn new(
        gram: &'a mut [[f64; K]; K],
        rhs: &'a mut [[f64; K]; D],
        kernels: usize,
        dof: usize,
    ) -> Self {
        Normal {
            gram,
            rhs,
            energy: [0.0; D],
            kernels,
            dof,
        }
    }

    /// Adds a sample of weight `q` with responses `r`; `target(d)` is the
    /// value DoF `d`'s weighted responses should reach there.
    pub fn add(&mut self, q: f64, r: &[f64; K], target: impl Fn(usize) -> f64) {
        // The kernels the phase has not reached yet have not moved the
        // spring: their responses are exactly zero, and so are their terms
        // (early in a discrete movement that is most of them).
        let reached = r
            .iter()
            .take(self.kernels)
            .rposition(|x| *x != 0.0)
            .map_or(0, |k| k + 1);
        for (a, gram_row) in self.gram.iter_mut().enumerate().take(reached) {
            let qa = q * r.get(a).copied().unwrap_or(0.0);
            for (g, rb) in gram_row.iter_mut().zip(r).take(a + 1) {
                *g += qa * rb;
            }
        }
        for ((b, e), d) in self.rhs.iter_mut().zip(&mut self.energy).zip(0..self.dof) {
            let forced = target(d);
            *e += q * forced * forced;
            for (bk, rk) in b.iter_mut().zip(r).take(reached) {
                *bk += q * rk * forced;
            }
        }
    }

    /// Solves with a ridge of `ridge` times the Gram matrix's mean
    /// diagonal; the weights go to `out[d][..kernels]`.
    pub fn solve(&mut self, ridge: f32, out: &mut [[f32; K]; D]) -> Result<(), Error> {
        solve(self.gram, self.rhs, self.kernels, self.dof, ridge, out).map(|_| ())
    }

    /// [`Normal::solve`], returning each DoF's residual: the weighted sum
    /// of squared misfits `Σ q (target − r·w)²` at the solution.
    pub fn solve_with_residual(
        &mut self,
        ridge: f32,
        out: &mut [[f32; K]; D],
    ) -> Result<[f64; D], Error> {
        let explained = solve(self.gram, self.rhs, self.kernels, self.dof, ridge, out)?;
        let mut residual = self.energy;
        for (r, e) in residual.iter_mut().zip(explained) {
            *r = (*r - e).max(0.0);
        }
        Ok(residual)
    }
}

/// Fits the weights of every DoF into `out[d][..kernels]`.
/// Returns the residual: the time-weighted sum of squared position errors
/// at the samples, over all DoFs (in the demonstration's units).
pub(super) fn weights<const D: usize, const K: usize>(
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
    let layout = super::Layout::new(kernels, demo.margin);
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
        let decay = (1.0 + 0.5 * alpha * u) * libm::exp(-0.5 * alpha * u);
        normal.add(q, r, |d| {
            let at = |v: &[f32]| v.get(d).map_or(0.0, |x| f64::from(*x));
            let (y0, g, a) = (at(demo.start), at(demo.goal), at(demo.amplitude));
            (at(row) - (g + (y0 - g) * decay)) / a
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

/// Solves the normal equations `G w_d = b_d` of every DoF, `G` given by its
/// lower triangle, with a ridge `λ` of `ridge` times `G`'s mean diagonal;
/// the weights go to `out[d][..kernels]`. Returns per DoF what the fit
/// explains, `b·w + λ|w|²`: at the solution of `(G + λ)w = b` the residual
/// `Σq(t − r·w)² = Σqt² − 2b·w + w·Gw` is `Σqt²` minus that.
fn solve<const D: usize, const K: usize>(
    gram: &mut [[f64; K]; K],
    rhs: &mut [[f64; K]; D],
    kernels: usize,
    dof: usize,
    ridge: f32,
    out: &mut [[f32; K]; D],
) -> Result<[f64; D], Error> {
    for a in 0..kernels {
        for b in 0..a {
            let lower = gram
                .get(a)
                .and_then(|row| row.get(b))
                .copied()
                .unwrap_or(0.0);
            if let Some(upper) = gram.get_mut(b).and_then(|row| row.get_mut(a)) {
                *upper = lower;
            }
        }
    }
    let trace: f64 = (0..kernels)
        .filter_map(|k| gram.get(k).and_then(|row| row.get(k)))
        .sum();
    let lambda = f64::from(ridge) * trace / kernels as f64;
    for (k, row) in gram.iter_mut().enumerate().take(kernels) {
        if let Some(g) = row.get_mut(k) {
            *g += lambda;
        }
    }
    crate::linalg::cholesky(gram, kernels, "DMP fit (too few samples for the kernels?)")?;
    let mut explained = [0.0; D];
    for ((b, w), e) in rhs
        .iter_mut()
        .zip(out.iter_mut())
        .zip(&mut explained)
        .take(dof)
    {
        let given = *b;
        crate::linalg::cholesky_solve(gram, kernels, b);
        for ((wk, bk), gk) in w.iter_mut().zip(b.iter()).zip(&given).take(kernels) {
            *wk = *bk as f32;
            *e += bk * (gk + lambda * bk);
        }
    }
    Ok(explained)
}
