//! Statistical generalization `θ = G(q)` from example movements `(q_i, θ_i)`.
//!
//! Both methods are linear smoothers: `G(q) = Σ_i c_i(q) θ_i`, so
//! [`Generalizer::coefficients`] computes `E` numbers per query whatever the
//! size of `θ`, and [`Generalizer::generalize`] combines the stored examples.
//!
//! - [`Method::Lwr`]: locally weighted *linear* regression (Atkeson et al.;
//!   Ude et al. 2010): at `q`, a weighted least-squares fit of
//!   `θ ≈ a + B (q_i − q)` with Gaussian weights; `G(q) = a`.
//! - [`Method::Gpr`]: Gaussian process regression with a squared-exponential
//!   kernel and an explicit linear mean (Rasmussen & Williams §2.7), so
//!   predictions far from the examples follow their linear trend instead of
//!   falling to zero.
//! - [`Method::ProMp`]: a probabilistic movement primitive's conditioning on
//!   a context (Paraschos et al. 2013, §2.3) over the DMP parameters: the
//!   examples' `(θ_i, q_i)` as one Gaussian, whose mean given `q` is
//!   `θ̄ + Σ_θq (Σ_qq + λI)⁻¹ (q − q̄)`, a global linear model of `θ` in `q`
//!   that the ridge `λ` keeps defined with fewer examples than query
//!   dimensions.
//!
//! With two examples along one query dimension both reduce to the straight
//! line through them: linear interpolation and extrapolation, as the paper
//! uses. Both need `E ≥ m + 1` examples to fit the linear part over an
//! `m`-dimensional query; with fewer they fall back to a constant mean.
//!
//! Orientation and Cartesian DMPs are generalized with the same
//! coefficients, their orientations as tangent vectors: [`orientation`].
//!
//! ```
//! use primo_core::generalize::{Generalizer, Method};
//! // Examples: bottle volume 0.3 l → θ = [1, 10], 1.0 l → θ = [2, 3].
//! let mut g = Generalizer::<4, 1, 2>::new(1, 2, Method::Lwr { bandwidth: None });
//! g.add_example(&[0.3], &[1.0, 10.0])?;
//! g.add_example(&[1.0], &[2.0, 3.0])?;
//! g.build()?;
//! let mut theta = [0.0; 2];
//! g.generalize(&[0.65], &mut theta)?;
//! assert!((theta[0] - 1.5).abs() < 1e-4 && (theta[1] - 6.5).abs() < 1e-4);
//! # Ok::<(), primo_core::Error>(())
//! ```

use serde::{Deserialize, Serialize};

pub mod orientation;

use crate::error::{check_capacity, check_finite, check_len};
use crate::{Error, linalg};

/// The regression method and its hyper-parameters. `None` picks a default
/// per query dimension from the mean spacing of the examples along it,
/// `span/(n−1)` (1 where all examples share that coordinate): half the spacing
/// as LWR bandwidth (its bias grows with the bandwidth squared, so this makes
/// it close to piecewise-linear interpolation between neighbours), twice the
/// spacing as GPR length scale (smooth between examples; with very uneven
/// spacing the covariance becomes ill-conditioned in `f32` and exactness at
/// the examples degrades to about 1e-3 of the data's scale: give a length
/// scale near the smallest spacing there).
///
/// `repr(u8)` makes `Lwr { bandwidth: None }` all zero bytes, so a static
/// generalizer (the coprocessor's) sits in .bss with no flash image.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[repr(u8)]
pub enum Method {
    /// Locally weighted linear regression with Gaussian weights of this
    /// bandwidth (same for every query dimension).
    Lwr {
        /// Kernel bandwidth in query units.
        bandwidth: Option<f32>,
    },
    /// Gaussian process regression with a linear mean.
    Gpr {
        /// Squared-exponential length scale in query units.
        length_scale: Option<f32>,
        /// Observation noise variance relative to the signal variance; 0 for
        /// noise-free interpolation (a 1e−6 jitter is always added).
        noise: f32,
    },
    /// A ProMP's Gaussian over `(θ, q)` conditioned on the query.
    ProMp {
        /// Ridge on the query covariance, relative to its mean variance
        /// (the queries scaled per dimension by their spacing); ≥ 0.
        ridge: f32,
    },
}

/// [`Method::ProMp`]'s ridge when none is chosen: small enough that two or
/// more examples along each query dimension are interpolated exactly (to
/// `f32`), large enough to keep a query covariance of fewer examples than
/// dimensions invertible.
pub const PROMP_RIDGE: f32 = 1e-6;

/// Jitter added to the GP covariance diagonal for a stable factorization.
const GPR_JITTER: f32 = 1e-6;
/// LWR weights are floored at this fraction of the largest one, so that far
/// extrapolation keeps enough of every example in the fit to stay linear
/// (a smaller floor drowns the far example in `f32` rounding).
const LWR_MIN_WEIGHT: f32 = 1e-3;
/// Ridge on each LWR slope term, relative to its own diagonal entry (or to
/// the total weight where that is zero: no spread along that dimension).
const LWR_RIDGE: f32 = 1e-6;

/// Examples `(q_i, θ_i)` with capacity `E` examples, query dimension `Q` and
/// parameter dimension `P`, and the precomputed regression.
#[derive(Debug, Clone)]
pub struct Generalizer<const E: usize, const Q: usize, const P: usize> {
    method: Method,
    q_dim: usize,
    p_dim: usize,
    count: usize,
    queries: [[f32; Q]; E],
    params: [[f32; P]; E],
    /// Per-dimension length scale, fixed by [`Generalizer::build`].
    scale: [f32; Q],
    /// Mean query, the centre of the linear basis.
    centre: [f32; Q],
    /// Size of the linear basis: `1 + q_dim` or 1 (constant mean).
    basis: usize,
    /// GPR: Cholesky factor of the covariance.
    chol_k: [[f32; E]; E],
    /// GPR: `K⁻¹ Hᵀ`, `count × basis`.
    k_inv_h: [[f32; E]; E],
    /// GPR: Cholesky factor of `H K⁻¹ Hᵀ`. ProMP: of the scaled queries'
    /// scatter `Σ_i d_i d_iᵀ + λI`, `d_i = (q_i − q̄)/scale` (`q_dim` ×
    /// `q_dim`).
    chol_r: [[f32; E]; E],
    built: bool,
}

impl<const E: usize, const Q: usize, const P: usize> Generalizer<E, Q, P> {
    /// An empty generalizer for queries of dimension `q_dim` and parameter
    /// vectors of length `p_dim`. Sizes are checked by
    /// [`Generalizer::add_example`].
    pub const fn new(q_dim: usize, p_dim: usize, method: Method) -> Self {
        Self {
            method,
            q_dim,
            p_dim,
            count: 0,
            queries: [[0.0; Q]; E],
            params: [[0.0; P]; E],
            scale: [0.0; Q],
            centre: [0.0; Q],
            basis: 0,
            chol_k: [[0.0; E]; E],
            k_inv_h: [[0.0; E]; E],
            chol_r: [[0.0; E]; E],
            built: false,
        }
    }

    /// Forgets every example and starts over with new dimensions and
    /// method, in place: a coprocessor reuses its one static generalizer
    /// for each learning run.
    pub fn reset(&mut self, q_dim: usize, p_dim: usize, method: Method) {
        self.method = method;
        self.q_dim = q_dim;
        self.p_dim = p_dim;
        self.count = 0;
        self.built = false;
    }

    /// Adds an example; call [`Generalizer::build`] after the last one.
    pub fn add_example(&mut self, query: &[f32], params: &[f32]) -> Result<(), Error> {
        if self.q_dim == 0 {
            return Err(Error::OutOfRange("the query needs at least one dimension"));
        }
        check_capacity("query dimension", self.q_dim, Q)?;
        check_capacity("parameter dimension", self.p_dim, P)?;
        check_capacity("examples", self.count + 1, E)?;
        check_len("example query", self.q_dim, query.len())?;
        check_len("example parameters", self.p_dim, params.len())?;
        check_finite(query, "example query")?;
        check_finite(params, "example parameters")?;
        let (Some(q), Some(p)) = (
            self.queries.get_mut(self.count),
            self.params.get_mut(self.count),
        ) else {
            return Err(Error::Capacity {
                what: "examples",
                requested: self.count + 1,
                capacity: E,
            });
        };
        q.iter_mut().zip(query).for_each(|(d, s)| *d = *s);
        p.iter_mut().zip(params).for_each(|(d, s)| *d = *s);
        self.count += 1;
        self.built = false;
        Ok(())
    }

    /// How `G(q)` is computed.
    pub fn method(&self) -> Method {
        self.method
    }

    /// Number of examples.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when there are no examples.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }

    /// Query `i` and parameters `i`, if present.
    pub fn example(&self, i: usize) -> Option<(&[f32], &[f32])> {
        if i >= self.count {
            return None;
        }
        Some((
            self.queries.get(i)?.get(..self.q_dim)?,
            self.params.get(i)?.get(..self.p_dim)?,
        ))
    }

    /// Fixes the length scales and, for GPR, factorizes the covariance.
    pub fn build(&mut self) -> Result<(), Error> {
        if self.count == 0 {
            return Err(Error::BadState("generalization needs at least one example"));
        }
        let n = self.count;
        let (explicit, spacings) = match self.method {
            Method::Lwr { bandwidth } => (bandwidth, 0.5),
            Method::Gpr {
                length_scale,
                noise,
            } => {
                if !(noise >= 0.0 && noise.is_finite()) {
                    return Err(Error::OutOfRange("GPR noise must be finite and >= 0"));
                }
                (length_scale, 2.0)
            }
            Method::ProMp { ridge } => {
                if !(ridge >= 0.0 && ridge.is_finite()) {
                    return Err(Error::OutOfRange("ProMP ridge must be finite and >= 0"));
                }
                (None, 1.0)
            }
        };
        for j in 0..self.q_dim {
            let (lo, hi) = self
                .queries
                .iter()
                .take(n)
                .filter_map(|q| q.get(j))
                .fold((f32::INFINITY, f32::NEG_INFINITY), |(lo, hi), &v| {
                    (lo.min(v), hi.max(v))
                });
            let scale = match explicit {
                Some(l) if l.is_finite() && l > 0.0 => l,
                Some(_) => return Err(Error::OutOfRange("length scale must be finite and > 0")),
                None if hi > lo && n > 1 => spacings * (hi - lo) / (n - 1) as f32,
                None => 1.0,
            };
            let centre = self
                .queries
                .iter()
                .take(n)
                .filter_map(|q| q.get(j))
                .sum::<f32>()
                / n as f32;
            if let (Some(s), Some(c)) = (self.scale.get_mut(j), self.centre.get_mut(j)) {
                *s = scale;
                *c = centre;
            }
        }
        self.basis = if n > self.q_dim { self.q_dim + 1 } else { 1 };
        match self.method {
            Method::Gpr { noise, .. } => self.build_gpr(noise)?,
            Method::ProMp { ridge } => self.build_promp(ridge)?,
            Method::Lwr { .. } => {}
        }
        self.built = true;
        Ok(())
    }

    /// Linear basis `[1, (q − centre)/scale]` (first `basis` entries).
    fn basis_row(&self, q: &[f32], centre: &[f32]) -> [f32; E] {
        let mut h = [0.0; E];
        let mut it = h.iter_mut().take(self.basis);
        if let Some(first) = it.next() {
            *first = 1.0;
        }
        for (((hj, qj), c), s) in it.zip(q).zip(centre).zip(&self.scale) {
            *hj = (qj - c) / s;
        }
        h
    }

    /// The GP's linear mean basis, centred on the mean example query.
    fn basis_at(&self, q: &[f32]) -> [f32; E] {
        self.basis_row(q, &self.centre)
    }

    /// Squared scaled distance between two queries.
    fn distance2(&self, a: &[f32], b: &[f32]) -> f32 {
        a.iter()
            .zip(b)
            .zip(&self.scale)
            .take(self.q_dim)
            .map(|((x, y), s)| {
                let d = (x - y) / s;
                d * d
            })
            .sum()
    }

    fn build_gpr(&mut self, noise: f32) -> Result<(), Error> {
        let n = self.count;
        let mut k = [[0.0f32; E]; E];
        for (i, row) in k.iter_mut().enumerate().take(n) {
            for (j, v) in row.iter_mut().enumerate().take(n) {
                let (Some(qi), Some(qj)) = (self.queries.get(i), self.queries.get(j)) else {
                    continue;
                };
                *v = libm::expf(-0.5 * self.distance2(qi, qj));
                if i == j {
                    *v += noise + GPR_JITTER;
                }
            }
        }
        linalg::cholesky(&mut k, n, "GPR covariance (duplicate examples?)")?;
        // K⁻¹ Hᵀ, column by column (one column per basis function).
        let mut k_inv_h = [[0.0f32; E]; E];
        let rows: [[f32; E]; E] = core::array::from_fn(|i| match self.queries.get(i) {
            Some(q) if i < n => self.basis_at(q),
            _ => [0.0; E],
        });
        for b in 0..self.basis {
            let mut col: [f32; E] = core::array::from_fn(|i| {
                rows.get(i).and_then(|r| r.get(b)).copied().unwrap_or(0.0)
            });
            linalg::cholesky_solve(&k, n, &mut col);
            for (row, v) in k_inv_h.iter_mut().zip(col).take(n) {
                if let Some(dst) = row.get_mut(b) {
                    *dst = v;
                }
            }
        }
        // R = H K⁻¹ Hᵀ (basis × basis).
        let mut r = [[0.0f32; E]; E];
        for (a, r_row) in r.iter_mut().enumerate().take(self.basis) {
            for (b, v) in r_row.iter_mut().enumerate().take(self.basis) {
                *v = rows
                    .iter()
                    .zip(&k_inv_h)
                    .take(n)
                    .map(|(h, m)| {
                        h.get(a).copied().unwrap_or(0.0) * m.get(b).copied().unwrap_or(0.0)
                    })
                    .sum();
            }
        }
        linalg::cholesky(
            &mut r,
            self.basis,
            "GPR linear mean (examples on a lower-dimensional set?)",
        )?;
        self.chol_k = k;
        self.k_inv_h = k_inv_h;
        self.chol_r = r;
        Ok(())
    }

    /// The examples' scaled query deviations `d_i = (q_i − q̄)/scale`.
    fn deviations(&self) -> [[f32; Q]; E] {
        core::array::from_fn(|i| match self.queries.get(i) {
            Some(q) if i < self.count => {
                core::array::from_fn(
                    |j| match (q.get(j), self.centre.get(j), self.scale.get(j)) {
                        (Some(v), Some(c), Some(s)) if j < self.q_dim => (v - c) / s,
                        _ => 0.0,
                    },
                )
            }
            _ => [0.0; Q],
        })
    }

    /// Factorizes the ProMP's regularized query scatter.
    fn build_promp(&mut self, ridge: f32) -> Result<(), Error> {
        let d = self.deviations();
        let mut r = [[0.0f32; E]; E];
        for (a, row) in r.iter_mut().enumerate().take(self.q_dim) {
            for (b, v) in row.iter_mut().enumerate().take(self.q_dim) {
                *v = d
                    .iter()
                    .take(self.count)
                    .map(|di| di.get(a).copied().unwrap_or(0.0) * di.get(b).copied().unwrap_or(0.0))
                    .sum();
            }
        }
        let trace: f32 = (0..self.q_dim)
            .map(|j| r.get(j).and_then(|row| row.get(j)).copied().unwrap_or(0.0))
            .sum();
        // Relative to the mean variance; absolute where the queries do not
        // spread at all (one example, or all alike).
        let mean = if trace > 0.0 {
            trace / self.q_dim as f32
        } else {
            1.0
        };
        for j in 0..self.q_dim {
            if let Some(v) = r.get_mut(j).and_then(|row| row.get_mut(j)) {
                *v += (ridge * mean).max(f32::MIN_POSITIVE);
            }
        }
        linalg::cholesky(
            &mut r,
            self.q_dim,
            "ProMP query covariance (examples on a lower-dimensional set? give a ridge)",
        )?;
        self.chol_r = r;
        Ok(())
    }

    /// `c_i = 1/n + d_iᵀ (Σ d d ᵀ + λI)⁻¹ (q − q̄)/scale`: the conditional
    /// mean `θ̄ + Σ_θq Σ_qq⁻¹ (q − q̄)` as weights on the examples.
    fn promp(&self, query: &[f32], out: &mut [f32; E]) {
        let n = self.count;
        let mut u = [0.0f32; E];
        for (j, uj) in u.iter_mut().enumerate().take(self.q_dim) {
            if let (Some(q), Some(c), Some(s)) =
                (query.get(j), self.centre.get(j), self.scale.get(j))
            {
                *uj = (q - c) / s;
            }
        }
        linalg::cholesky_solve(&self.chol_r, self.q_dim, &mut u);
        for (c, di) in out.iter_mut().zip(self.deviations()).take(n) {
            *c = 1.0 / n as f32 + di.iter().zip(&u).map(|(a, b)| a * b).sum::<f32>();
        }
    }

    /// The weights `c_i(q)` with `G(q) = Σ c_i θ_i`, written to
    /// `out[..len()]`.
    pub fn coefficients(&self, query: &[f32], out: &mut [f32; E]) -> Result<(), Error> {
        if !self.built {
            return Err(Error::BadState("call build() after adding examples"));
        }
        check_len("query", self.q_dim, query.len())?;
        check_finite(query, "query")?;
        *out = [0.0; E];
        match self.method {
            Method::Lwr { .. } => self.lwr(query, out)?,
            Method::Gpr { .. } => self.gpr(query, out)?,
            Method::ProMp { .. } => self.promp(query, out),
        }
        check_finite(out, "generalization coefficients")
    }

    fn lwr(&self, query: &[f32], out: &mut [f32; E]) -> Result<(), Error> {
        let n = self.count;
        // Weights relative to the nearest example, floored: never all zero.
        let d2: [f32; E] = core::array::from_fn(|i| match self.queries.get(i) {
            Some(q) if i < n => self.distance2(q, query),
            _ => 0.0,
        });
        let nearest = d2.iter().take(n).fold(f32::INFINITY, |m, &v| m.min(v));
        let w: [f32; E] = core::array::from_fn(|i| match d2.get(i) {
            Some(&d) if i < n => libm::expf(-0.5 * (d - nearest)).max(LWR_MIN_WEIGHT),
            _ => 0.0,
        });
        let total: f32 = w.iter().sum();
        // Local linear model θ ≈ a + bᵀ(q − q̄)/ℓ, centred on the weighted mean
        // q̄ of the examples so the normal equations stay well conditioned
        // however far the query is.
        let mut centre = [0.0f32; Q];
        for (qi, wi) in self.queries.iter().zip(&w).take(n) {
            for (c, v) in centre.iter_mut().zip(qi).take(self.q_dim) {
                *c += wi * v / total;
            }
        }
        let regressors = |q: &[f32]| self.basis_row(q, &centre);
        let x: [[f32; E]; E] = core::array::from_fn(|i| match self.queries.get(i) {
            Some(q) if i < n => regressors(q),
            _ => [0.0; E],
        });
        let mut a = [[0.0f32; E]; E];
        for (j, a_row) in a.iter_mut().enumerate().take(self.basis) {
            for (k, v) in a_row.iter_mut().enumerate().take(self.basis) {
                *v = x
                    .iter()
                    .zip(&w)
                    .take(n)
                    .map(|(xi, wi)| {
                        wi * xi.get(j).copied().unwrap_or(0.0) * xi.get(k).copied().unwrap_or(0.0)
                    })
                    .sum();
                if j == k && j > 0 {
                    *v += LWR_RIDGE * if *v > 0.0 { *v } else { total };
                }
            }
        }
        linalg::cholesky(&mut a, self.basis, "LWR local fit")?;
        // G(q) = h(q)ᵀ A⁻¹ Σ w_i x_i θ_i, so c_i = w_i x_iᵀ (A⁻¹ h(q)).
        let mut h = regressors(query);
        linalg::cholesky_solve(&a, self.basis, &mut h);
        for ((c, xi), wi) in out.iter_mut().zip(&x).zip(&w).take(n) {
            *c = wi
                * xi.iter()
                    .zip(&h)
                    .take(self.basis)
                    .map(|(a, b)| a * b)
                    .sum::<f32>();
        }
        Ok(())
    }

    fn gpr(&self, query: &[f32], out: &mut [f32; E]) -> Result<(), Error> {
        let n = self.count;
        // c = K⁻¹ k* + K⁻¹Hᵀ R⁻¹ (h* − H K⁻¹ k*).
        let mut v: [f32; E] = core::array::from_fn(|i| match self.queries.get(i) {
            Some(q) if i < n => libm::expf(-0.5 * self.distance2(q, query)),
            _ => 0.0,
        });
        linalg::cholesky_solve(&self.chol_k, n, &mut v);
        let mut u = self.basis_at(query);
        for (b, ub) in u.iter_mut().enumerate().take(self.basis) {
            // (H K⁻¹ k*)_b = Σ_i (K⁻¹Hᵀ)_{ib} k*_i … equivalently Σ_i h_b(q_i) v_i.
            let hv: f32 = self
                .queries
                .iter()
                .zip(&v)
                .take(n)
                .map(|(q, vi)| self.basis_at(q).get(b).copied().unwrap_or(0.0) * vi)
                .sum();
            *ub -= hv;
        }
        linalg::cholesky_solve(&self.chol_r, self.basis, &mut u);
        for ((c, vi), m) in out.iter_mut().zip(&v).zip(&self.k_inv_h).take(n) {
            *c = vi
                + m.iter()
                    .zip(&u)
                    .take(self.basis)
                    .map(|(a, b)| a * b)
                    .sum::<f32>();
        }
        Ok(())
    }

    /// `θ = G(q)`, written to `out[..p_dim]`.
    pub fn generalize(&self, query: &[f32], out: &mut [f32]) -> Result<(), Error> {
        let found = out.len();
        let out = out.get_mut(..self.p_dim).ok_or(Error::Length {
            what: "parameter buffer",
            expected: self.p_dim,
            found,
        })?;
        let mut c = [0.0f32; E];
        self.coefficients(query, &mut c)?;
        out.iter_mut().for_each(|o| *o = 0.0);
        for (ci, theta) in c.iter().zip(&self.params).take(self.count) {
            for (o, t) in out.iter_mut().zip(theta) {
                *o += ci * t;
            }
        }
        check_finite(out, "generalized parameters")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn methods() -> [Method; 3] {
        [
            Method::Lwr { bandwidth: None },
            Method::Gpr {
                length_scale: None,
                noise: 0.0,
            },
            Method::ProMp { ridge: PROMP_RIDGE },
        ]
    }

    #[test]
    fn two_examples_interpolate_and_extrapolate_linearly() {
        for m in methods() {
            let mut g = Generalizer::<4, 1, 3>::new(1, 3, m);
            g.add_example(&[0.3], &[1.0, -2.0, 100.0]).unwrap();
            g.add_example(&[1.0], &[2.0, 5.0, -40.0]).unwrap();
            g.build().unwrap();
            for q in [0.0f32, 0.3, 0.5, 0.8, 1.0, 1.5, 3.0] {
                let mut out = [0.0; 3];
                g.generalize(&[q], &mut out).unwrap();
                let a = (q - 0.3) / 0.7;
                let expect = [1.0 + a, -2.0 + 7.0 * a, 100.0 - 140.0 * a];
                for (o, e) in out.iter().zip(expect) {
                    assert!(
                        (o - e).abs() < 1e-3 * (1.0 + e.abs()),
                        "{m:?} q={q}: {o} vs {e}"
                    );
                }
            }
        }
    }

    #[test]
    fn gpr_is_exact_at_examples_and_lwr_reproduces_linear_data() {
        let qs: [[f32; 2]; 6] = [
            [0.0, 0.0],
            [1.0, 0.2],
            [0.3, 1.0],
            [0.8, 0.9],
            [0.5, 0.5],
            [0.1, 0.6],
        ];
        let f = |q: &[f32; 2]| [libm::sinf(3.0 * q[0]) + q[1] * q[1], 2.0 * q[0] - q[1]];
        for m in methods() {
            let mut g = Generalizer::<8, 2, 2>::new(2, 2, m);
            for q in &qs {
                g.add_example(q, &f(q)).unwrap();
            }
            g.build().unwrap();
            for q in &qs {
                let mut out = [0.0; 2];
                g.generalize(q, &mut out).unwrap();
                let y = f(q);
                // Second output is linear: both methods reproduce it anywhere.
                assert!(
                    (out[1] - y[1]).abs() < 1e-3,
                    "{m:?} linear part {out:?} vs {y:?}"
                );
                if matches!(m, Method::Gpr { .. }) {
                    assert!(
                        (out[0] - y[0]).abs() < 1e-3,
                        "GPR not exact at {q:?}: {out:?} vs {y:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn recovers_a_smooth_function() {
        // sin on [0, π] from 9 examples; check between them. (The ProMP's
        // model is global and linear: not for this.)
        for m in methods().into_iter().take(2) {
            let mut g = Generalizer::<9, 1, 1>::new(1, 1, m);
            for i in 0..9 {
                let q = i as f32 * core::f32::consts::PI / 8.0;
                g.add_example(&[q], &[libm::sinf(q)]).unwrap();
            }
            g.build().unwrap();
            let mut worst = 0.0f32;
            for i in 0..=100 {
                let q = i as f32 * core::f32::consts::PI / 100.0;
                let mut out = [0.0];
                g.generalize(&[q], &mut out).unwrap();
                worst = worst.max((out[0] - libm::sinf(q)).abs());
            }
            let tol = if matches!(m, Method::Gpr { .. }) {
                2e-3
            } else {
                3e-2
            };
            assert!(worst < tol, "{m:?}: worst error {worst}");
        }
    }

    /// The ProMP's mean is the Gaussian conditional `θ̄ + Σ_θq Σ_qq⁻¹ (q −
    /// q̄)` of the examples' sample covariance, computed here directly on a
    /// 1-D query; with fewer examples than query dimensions the ridge keeps
    /// it defined, and it reproduces the examples' mean at their mean query.
    #[test]
    fn promp_is_the_gaussian_conditional_of_the_examples() {
        let qs = [0.1f32, 0.4, 0.5, 0.9];
        let theta = [[1.0f32, -3.0], [2.5, 0.0], [2.0, 1.0], [4.0, 2.0]];
        let mut g = Generalizer::<4, 1, 2>::new(1, 2, Method::ProMp { ridge: 0.0 });
        for (q, t) in qs.iter().zip(&theta) {
            g.add_example(&[*q], t).unwrap();
        }
        g.build().unwrap();
        let n = qs.len() as f32;
        let q_mean = qs.iter().sum::<f32>() / n;
        let s_qq: f32 = qs.iter().map(|q| (q - q_mean) * (q - q_mean)).sum();
        for q in [-1.0f32, 0.3, 0.475, 2.0] {
            let mut out = [0.0; 2];
            g.generalize(&[q], &mut out).unwrap();
            for (d, o) in out.iter().enumerate() {
                let t_mean = theta.iter().map(|t| t[d]).sum::<f32>() / n;
                let s_tq: f32 = (qs.iter().zip(&theta))
                    .map(|(qi, t)| (t[d] - t_mean) * (qi - q_mean))
                    .sum();
                let expect = t_mean + s_tq / s_qq * (q - q_mean);
                assert!((o - expect).abs() < 1e-4, "q={q} dof {d}: {o} vs {expect}");
            }
        }
        // Two examples on a 2-D query: only the ridge makes it solvable.
        let mut g = Generalizer::<4, 2, 1>::new(2, 1, Method::ProMp { ridge: PROMP_RIDGE });
        g.add_example(&[0.0, 0.0], &[1.0]).unwrap();
        g.add_example(&[1.0, 1.0], &[3.0]).unwrap();
        g.build().unwrap();
        let mut out = [0.0];
        g.generalize(&[0.5, 0.5], &mut out).unwrap();
        assert!((out[0] - 2.0).abs() < 1e-4, "{out:?}");
        g.generalize(&[1.0, 1.0], &mut out).unwrap();
        assert!((out[0] - 3.0).abs() < 1e-3, "{out:?}");
        let mut bad = Generalizer::<4, 1, 1>::new(1, 1, Method::ProMp { ridge: -1.0 });
        bad.add_example(&[0.0], &[1.0]).unwrap();
        assert_eq!(
            bad.build(),
            Err(Error::OutOfRange("ProMP ridge must be finite and >= 0"))
        );
    }

    #[test]
    fn bad_input_is_an_error() {
        let mut g = Generalizer::<2, 1, 1>::new(1, 1, Method::Lwr { bandwidth: None });
        assert!(g.coefficients(&[0.0], &mut [0.0; 2]).is_err());
        assert!(g.add_example(&[f32::NAN], &[0.0]).is_err());
        assert!(g.add_example(&[0.0, 1.0], &[0.0]).is_err());
        g.add_example(&[0.0], &[0.0]).unwrap();
        g.add_example(&[1.0], &[1.0]).unwrap();
        assert!(g.add_example(&[2.0], &[1.0]).is_err());
        g.build().unwrap();
        assert!(g.generalize(&[f32::INFINITY], &mut [0.0]).is_err());
        let mut gp = Generalizer::<2, 1, 1>::new(
            1,
            1,
            Method::Gpr {
                length_scale: None,
                noise: 0.0,
            },
        );
        gp.add_example(&[0.5], &[0.0]).unwrap();
        gp.add_example(&[0.5], &[1.0]).unwrap();
        // Duplicate queries with different values: singular up to the jitter,
        // which the factorization survives; both give a finite answer.
        if gp.build().is_ok() {
            let mut out = [0.0];
            let _ = gp.generalize(&[0.7], &mut out);
            assert!(out[0].is_finite());
        }
    }
}
