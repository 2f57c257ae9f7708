//! The critically damped spring-damper that discrete ([`crate::dmp`]) and
//! rhythmic ([`crate::rhythmic`]) DMPs share:
//!
//! ```text
//! τ ż = α (β (y* − y) − z),   τ ẏ = z,   β = α / 4
//! ```
//!
//! about an equilibrium `y*` (the goal or anchor, moved by the forcing
//! term held over a step). It is linear, so a step is its exact solution,
//! the matrix exponential `exp(A u)` for `u = dt/τ` ([`transition`]): any
//! `dt` is stable. At control rates a step moves the position by little,
//! so the runs take `Φ00 − 1` from its series ([`transition_step`]) and
//! sum the steps compensated ([`add_compensated`]): thousands of steps in
//! `f32` do not accumulate their rounding.
//!
//! The fits use the same spring in `f64`: the [`Responses`] to each kernel
//! alone, from rest, integrated with the runtime's scheme.

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

/// Sub-steps per kernel spacing when integrating the responses.
pub(crate) const SUBSTEPS_PER_SPACING: f64 = 64.0;

/// `exp(A h)` of the critically damped spring in phase units, `f64`.
fn transition_f64(alpha: f64, h: f64) -> [f64; 4] {
    let a = 0.5 * alpha;
    let ah = a * h;
    if !(ah < 700.0) {
        return [0.0; 4];
    }
    let e = libm::exp(-ah);
    [e * (1.0 + ah), e * h, -e * a * ah, e * (1.0 - ah)]
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
            let [p00, p01, ..] = transition_f64(self.alpha, rest);
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
        let [p00, p01, p10, p11] = transition_f64(self.alpha, h);
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

#[cfg(test)]
mod tests {
    use super::*;

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
}
