//! Probabilistic movement primitives (ProMPs; Paraschos, Daniel, Peters,
//! Neumann, NeurIPS 2013): a distribution over movements learned from
//! several demonstrations.
//!
//! Each DoF is `y_d(z) = φ(z)ᵀ w_d + ε`, `z ∈ [0, 1]` the phase (each
//! demonstration's time over its duration), `φ` normalized Gaussian
//! kernels evenly spread over the phase, and the weights of all
//! DoFs one Gaussian `w ~ N(μ, Σ)` with the DoFs' correlations. The fit
//! takes each demonstration's weights by ridge regression, their mean and
//! sample covariance, plus a ridge `λ·(mean variance)·I` on the
//! covariance (few demonstrations give a covariance of low rank: the ridge
//! keeps it invertible and lets conditioning move every weight a little),
//! and `σ²`, the demonstrations' mean squared residual, as the
//! observation noise. Then:
//!
//! - the trajectory's mean `φᵀμ_d` and variance `φᵀΣ_ddφ + σ²` at any
//!   phase ([`ProMp::mean`], [`ProMp::variance`]), the mean's velocity
//!   ([`ProMp::velocity`]), and the mean's weights as the parameters a
//!   learner changes ([`ProMp::weights`], [`ProMp::set_weights`]);
//! - conditioning on observed positions of some DoFs at a phase (a
//!   via-point, the goal) with a variance: the Gaussian update
//!   `μ ← μ + ΣHᵀ(HΣHᵀ + R)⁻¹(y* − Hμ)`, `Σ ← Σ − ΣHᵀ(HΣHᵀ + R)⁻¹HΣ`
//!   ([`ProMp::condition`]);
//! - blending two ProMPs at a phase, each by an activation: the product of
//!   their trajectory distributions, precisions weighted by the
//!   activations ([`blend`]).
//!
//! Everything is `f64` on fixed-size buffers: `D·D·K·K` values of
//! covariance (7 DoF × 30 kernels: 353 KiB), a host's object; no
//! allocation, no panic.
//!
//! ```
//! use primo_core::promp::{Observation, ProMp};
//! // Three reaches to different heights.
//! let t: Vec<f32> = (0..=100).map(|i| i as f32 / 100.0).collect();
//! let demo = |h: f32| -> Vec<f32> { t.iter().map(|&t| h * t * t * (3.0 - 2.0 * t)).collect() };
//! let (a, b, c) = (demo(0.9), demo(1.0), demo(1.1));
//! let mut p = ProMp::<1, 20>::fit(&[(&t, &a), (&t, &b), (&t, &c)], 1, 20, 1e-6)?;
//! assert!((p.mean(1.0, 0) - 1.0).abs() < 1e-3);
//! // Through 1.05 at the end, exactly.
//! p.condition(1.0, &[Observation { dof: 0, position: 1.05 }], 0.0)?;
//! assert!((p.mean(1.0, 0) - 1.05).abs() < 1e-6);
//! # Ok::<(), primo_core::Error>(())
//! ```

use crate::Error;
use crate::linalg::{cholesky, cholesky_solve};

/// The most demonstrations a fit takes.
pub const MAX_DEMOS: usize = 32;

/// The kernels' overlap `h·Δc²`: neighbours cross at `exp(−overlap/4)`.
pub const OVERLAP: f64 = 0.5;

/// A position one DoF has, or is to have, at a phase.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Observation {
    /// The DoF.
    pub dof: usize,
    /// Its position.
    pub position: f32,
}

/// A ProMP of up to `D` DoFs and `K` kernels per DoF.
#[derive(Debug, Clone, PartialEq)]
pub struct ProMp<const D: usize, const K: usize> {
    dof: usize,
    kernels: usize,
    duration: f64,
    noise: f64,
    mean: [[f64; K]; D],
    /// `cov[a][b][i][j]`: the covariance of DoF `a`'s weight `i` and DoF
    /// `b`'s weight `j`.
    cov: [[[[f64; K]; K]; D]; D],
}

impl<const D: usize, const K: usize> ProMp<D, K> {
    /// Fits a ProMP of `dof` DoFs and `kernels` kernels to `demos`, each
    /// `(times, positions)` with `positions` row-major (`dof` per sample),
    /// with `ridge` (≥ 0, relative) on the covariance.
    ///
    /// Refused: fewer than two demonstrations (a distribution needs
    /// several) or more than [`MAX_DEMOS`], demonstrations of different
    /// sample counts, times that do not increase, positions that are not
    /// finite, fewer than 2 or more than `K` kernels, more samples'
    /// worth of kernels than a demonstration has.
    pub fn fit(
        demos: &[(&[f32], &[f32])],
        dof: usize,
        kernels: usize,
        ridge: f64,
    ) -> Result<Self, Error> {
        if demos.len() < 2 {
            return Err(Error::OutOfRange(
                "a ProMP needs at least two demonstrations: a distribution over movements is \
                 learned from several",
            ));
        }
        crate::check_capacity("demonstrations", demos.len(), MAX_DEMOS)?;
        crate::check_capacity("DoF", dof, D)?;
        crate::check_capacity("kernels", kernels, K)?;
        if dof == 0 || kernels < 2 {
            return Err(Error::OutOfRange(
                "a ProMP needs a DoF and at least two kernels",
            ));
        }
        if !(ridge.is_finite() && ridge >= 0.0) {
            return Err(Error::OutOfRange("ridge must be finite and >= 0"));
        }
        let samples = demos.first().map_or(0, |(t, _)| t.len());
        if samples < kernels {
            return Err(Error::OutOfRange(
                "a ProMP needs at least as many samples per demonstration as kernels",
            ));
        }
        let mut duration = 0.0;
        for (t, y) in demos {
            if t.len() != samples {
                return Err(Error::OutOfRange(
                    "demonstrations of different lengths: every one needs the same number of \
                     samples",
                ));
            }
            crate::check_len("positions (samples × DoF)", samples * dof, y.len())?;
            if !(t.iter().chain(y.iter()).all(|v| v.is_finite())) {
                return Err(Error::NotFinite("demonstration times and positions"));
            }
            if t.windows(2).any(|w| !matches!(w, [a, b] if b > a)) {
                return Err(Error::OutOfRange("times must be strictly increasing"));
            }
            if let (Some(a), Some(b)) = (t.first(), t.last()) {
                duration += f64::from(*b) - f64::from(*a);
            }
        }
        let mut p = ProMp {
            dof,
            kernels,
            duration: duration / demos.len() as f64,
            noise: 0.0,
            mean: [[0.0; K]; D],
            cov: [[[[0.0; K]; K]; D]; D],
        };
        // Each demonstration's weights: (ΦᵀΦ + εI)⁻¹Φᵀy per DoF, the
        // Gram matrix shared by the DoFs (the same phases).
        let mut weights = [[[0.0f64; K]; D]; MAX_DEMOS];
        let mut residual = 0.0;
        for ((t, y), w) in demos.iter().zip(weights.iter_mut()) {
            let (t0, t1) = match (t.first(), t.last()) {
                (Some(a), Some(b)) => (f64::from(*a), f64::from(*b)),
                _ => return Err(Error::OutOfRange("a demonstration needs samples")),
            };
            let mut gram = [[0.0f64; K]; K];
            let mut rhs = [[0.0f64; K]; D];
            let mut phi = [0.0f64; K];
            for (ti, row) in t.iter().zip(y.chunks_exact(dof)) {
                p.basis((f64::from(*ti) - t0) / (t1 - t0), &mut phi);
                for (g, a) in gram.iter_mut().zip(phi) {
                    for (g, b) in g.iter_mut().zip(phi) {
                        *g += a * b;
                    }
                }
                for (r, v) in rhs.iter_mut().zip(row) {
                    for (r, a) in r.iter_mut().zip(phi) {
                        *r += a * f64::from(*v);
                    }
                }
            }
            let scale = (0..kernels).map(|k| at2(&gram, k, k)).sum::<f64>() / kernels as f64;
            for (k, g) in gram.iter_mut().enumerate().take(kernels) {
                if let Some(g) = g.get_mut(k) {
                    *g += 1e-9 * scale;
                }
            }
            cholesky(
                &mut gram,
                kernels,
                "the kernels cannot be fitted to these samples",
            )?;
            for (r, w) in rhs.iter_mut().zip(w.iter_mut()).take(dof) {
                cholesky_solve(&gram, kernels, r);
                *w = *r;
            }
            for (ti, row) in t.iter().zip(y.chunks_exact(dof)) {
                p.basis((f64::from(*ti) - t0) / (t1 - t0), &mut phi);
                for (w, v) in w.iter().zip(row) {
                    let e = dot(&phi, w, kernels) - f64::from(*v);
                    residual += e * e;
                }
            }
        }
        let n = demos.len();
        p.noise = residual / (n * samples * dof) as f64;
        for w in weights.iter().take(n) {
            for (m, w) in p.mean.iter_mut().zip(w) {
                for (m, w) in m.iter_mut().zip(w) {
                    *m += w / n as f64;
                }
            }
        }
        for w in weights.iter().take(n) {
            for (a, block) in p.cov.iter_mut().enumerate().take(dof) {
                for (b, block) in block.iter_mut().enumerate().take(dof) {
                    for (i, row) in block.iter_mut().enumerate().take(kernels) {
                        let di = at2(w, a, i) - at2(&p.mean, a, i);
                        for (j, c) in row.iter_mut().enumerate().take(kernels) {
                            *c += di * (at2(w, b, j) - at2(&p.mean, b, j)) / (n - 1) as f64;
                        }
                    }
                }
            }
        }
        let variance = (0..dof)
            .flat_map(|d| (0..kernels).map(move |k| (d, k)))
            .map(|(d, k)| p.cov_at(d, d, k, k))
            .sum::<f64>()
            / (dof * kernels) as f64;
        // A floor for demonstrations that agree exactly.
        let floor = ridge * variance.max(1e-12);
        for (d, block) in p.cov.iter_mut().enumerate().take(dof) {
            if let Some(block) = block.get_mut(d) {
                for (k, row) in block.iter_mut().enumerate().take(kernels) {
                    if let Some(c) = row.get_mut(k) {
                        *c += floor;
                    }
                }
            }
        }
        Ok(p)
    }

    /// The whole ProMP as numbers, to keep it and rebuild it with
    /// [`ProMp::from_values`]: DoF, kernels, duration, noise, then the
    /// mean (DoF by DoF) and the covariance (`[a][i][b][j]` order) of the
    /// weights in use.
    pub fn values(&self) -> impl Iterator<Item = f64> + '_ {
        let (dof, kernels) = (self.dof, self.kernels);
        let head = [dof as f64, kernels as f64, self.duration, self.noise];
        let mean = (0..dof).flat_map(move |a| (0..kernels).map(move |i| at2(&self.mean, a, i)));
        let cov = (0..dof).flat_map(move |a| {
            (0..kernels).flat_map(move |i| {
                (0..dof).flat_map(move |b| (0..kernels).map(move |j| self.cov_at(a, b, i, j)))
            })
        });
        head.into_iter().chain(mean).chain(cov)
    }

    /// The ProMP [`ProMp::values`] gave. Checked: the sizes, finite
    /// values, a positive duration, a noise and a covariance diagonal
    /// `>= 0`, a symmetric covariance.
    pub fn from_values(values: &[f64]) -> Result<Self, Error> {
        let bad = Error::OutOfRange("not the values of a ProMP of this size");
        let (dof, kernels, duration, noise) = match values {
            [d, k, t, n, ..] => (*d as usize, *k as usize, *t, *n),
            _ => return Err(bad),
        };
        if dof == 0 || dof > D || kernels < 2 || kernels > K {
            return Err(bad);
        }
        let w = dof * kernels;
        crate::check_len("ProMP values", 4 + w + w * w, values.len())?;
        if !values.iter().all(|v| v.is_finite()) {
            return Err(Error::NotFinite("ProMP values"));
        }
        if !(duration > 0.0 && noise >= 0.0) {
            return Err(bad);
        }
        let mut p = ProMp {
            dof,
            kernels,
            duration,
            noise,
            mean: [[0.0; K]; D],
            cov: [[[[0.0; K]; K]; D]; D],
        };
        let rest = values.get(4..).unwrap_or(&[]);
        let (mean, cov) = rest.split_at(w.min(rest.len()));
        for (n, v) in mean.iter().enumerate() {
            if let Some(m) = p
                .mean
                .get_mut(n / kernels)
                .and_then(|r| r.get_mut(n % kernels))
            {
                *m = *v;
            }
        }
        for (n, v) in cov.iter().enumerate() {
            let (row, column) = (n / w, n % w);
            let (a, i, b, j) = (
                row / kernels,
                row % kernels,
                column / kernels,
                column % kernels,
            );
            if let Some(c) = p
                .cov
                .get_mut(a)
                .and_then(|r| r.get_mut(b))
                .and_then(|r| r.get_mut(i))
                .and_then(|r| r.get_mut(j))
            {
                *c = *v;
            }
        }
        for (row, column) in (0..w).flat_map(|r| (0..w).map(move |c| (r, c))) {
            let (a, i, b, j) = (
                row / kernels,
                row % kernels,
                column / kernels,
                column % kernels,
            );
            let (x, y) = (p.cov_at(a, b, i, j), p.cov_at(b, a, j, i));
            if (row == column && x < 0.0) || (x - y).abs() > 1e-9 * (x.abs() + y.abs()) {
                return Err(Error::OutOfRange(
                    "a ProMP's covariance must be symmetric with a diagonal >= 0",
                ));
            }
        }
        Ok(p)
    }

    /// The DoFs.
    pub fn dof(&self) -> usize {
        self.dof
    }

    /// Kernels per DoF.
    pub fn kernels(&self) -> usize {
        self.kernels
    }

    /// The demonstrations' mean duration, s: phase 1 at this time.
    pub fn duration(&self) -> f64 {
        self.duration
    }

    /// The observation noise `σ²`: the demonstrations' mean squared
    /// residual from their own weights.
    pub fn noise(&self) -> f64 {
        self.noise
    }

    /// The mean position of DoF `d` at phase `z` (clamped to [0, 1]; 0 for
    /// a DoF beyond the ProMP's).
    pub fn mean(&self, z: f64, d: usize) -> f64 {
        let mut phi = [0.0; K];
        self.basis(z, &mut phi);
        self.mean.get(d).map_or(0.0, |m| dot(&phi, m, self.kernels))
    }

    /// The mean velocity of DoF `d` at phase `z`, per second: `φ'(z)ᵀμ_d`
    /// over the duration. 0 outside [0, 1] (before and after the
    /// movement its mean holds still) and for a DoF beyond the ProMP's.
    pub fn velocity(&self, z: f64, d: usize) -> f64 {
        if !(0.0..=1.0).contains(&z) {
            return 0.0;
        }
        let mut slope = [0.0; K];
        self.basis_slope(z, &mut slope);
        self.mean
            .get(d)
            .map_or(0.0, |m| dot(&slope, m, self.kernels) / self.duration)
    }

    /// The mean's weights, DoF by DoF (`kernels` each): the parameters a
    /// learner changes.
    pub fn weights(&self) -> impl Iterator<Item = f64> + '_ {
        let kernels = self.kernels;
        self.mean
            .iter()
            .take(self.dof)
            .flat_map(move |m| m.iter().take(kernels).copied())
    }

    /// Replaces the mean's weights ([`ProMp::weights`]' order), keeping the
    /// covariance: the same spread around another mean movement. Refused:
    /// another count than `dof · kernels`, a value that is not finite.
    pub fn set_weights(&mut self, weights: &[f64]) -> Result<(), Error> {
        crate::check_len("ProMP weights", self.dof * self.kernels, weights.len())?;
        if !weights.iter().all(|w| w.is_finite()) {
            return Err(Error::NotFinite("ProMP weights"));
        }
        for (m, w) in self
            .mean
            .iter_mut()
            .zip(weights.chunks_exact(self.kernels.max(1)))
        {
            for (m, w) in m.iter_mut().zip(w) {
                *m = *w;
            }
        }
        Ok(())
    }

    /// The variance of DoF `d`'s position at phase `z`: `φᵀΣ_ddφ + σ²`.
    pub fn variance(&self, z: f64, d: usize) -> f64 {
        self.covariance(z, d, d) + self.noise
    }

    /// The covariance of DoFs `a` and `b` at phase `z`, without the
    /// observation noise.
    pub fn covariance(&self, z: f64, a: usize, b: usize) -> f64 {
        self.covariance_between(z, a, z, b)
    }

    /// The covariance of DoF `a`'s position at phase `za` and DoF `b`'s at
    /// phase `zb`, without the observation noise: `φ(za)ᵀ Σ_ab φ(zb)`.
    pub fn covariance_between(&self, za: f64, a: usize, zb: f64, b: usize) -> f64 {
        let (mut pa, mut pb) = ([0.0; K], [0.0; K]);
        self.basis(za, &mut pa);
        self.basis(zb, &mut pb);
        let block = match self.cov.get(a).and_then(|r| r.get(b)) {
            Some(block) => block,
            None => return 0.0,
        };
        block
            .iter()
            .zip(pa)
            .take(self.kernels)
            .map(|(row, p)| p * dot(&pb, row, self.kernels))
            .sum()
    }

    /// Conditions on `observed` positions at phase `z` (each of another
    /// DoF, at most `D`), each observed with `variance` (≥ 0; 0 is exact,
    /// up to the covariance's ridge): a via-point, the goal, a start.
    /// Refused: a DoF beyond the ProMP's or twice, a phase outside
    /// [0, 1], a negative or non-finite variance or position, and an
    /// observation the distribution cannot take (a singular system), each
    /// before anything changes; an update that leaves the distribution not
    /// finite (values near `f64`'s range) is refused after it, with the
    /// ProMP changed: condition a copy where the original must stay.
    pub fn condition(
        &mut self,
        z: f64,
        observed: &[Observation],
        variance: f64,
    ) -> Result<(), Error> {
        crate::check_capacity("observations", observed.len(), D)?;
        if !(0.0..=1.0).contains(&z) {
            return Err(Error::OutOfRange("a phase must lie in [0, 1]"));
        }
        if !(variance.is_finite() && variance >= 0.0) {
            return Err(Error::OutOfRange(
                "an observation's variance must be finite and >= 0",
            ));
        }
        for (i, o) in observed.iter().enumerate() {
            if o.dof >= self.dof || observed.iter().take(i).any(|p| p.dof == o.dof) {
                return Err(Error::OutOfRange(
                    "observations must be of different DoFs of the ProMP's",
                ));
            }
            if !o.position.is_finite() {
                return Err(Error::NotFinite("an observed position"));
            }
        }
        let m = observed.len();
        let (kernels, dof) = (self.kernels, self.dof);
        let mut phi = [0.0; K];
        self.basis(z, &mut phi);
        // ΣHᵀ: column o is Σ[·][d_o]·φ.
        let mut sh = [[[0.0f64; D]; K]; D];
        for (a, rows) in sh.iter_mut().enumerate().take(dof) {
            for (i, row) in rows.iter_mut().enumerate().take(kernels) {
                for (c, o) in row.iter_mut().zip(observed) {
                    *c = (0..kernels)
                        .map(|j| self.cov_at(a, o.dof, i, j) * at(&phi, j))
                        .sum();
                }
            }
        }
        // S = HΣHᵀ + R, and the innovation y* − Hμ.
        let mut s = [[0.0f64; D]; D];
        let mut innovation = [0.0f64; D];
        for (r, (o, e)) in observed.iter().zip(innovation.iter_mut()).enumerate() {
            *e = f64::from(o.position) - self.mean(z, o.dof);
            if let Some(row) = s.get_mut(r) {
                for (c, v) in row.iter_mut().enumerate().take(m) {
                    let column = sh.get(o.dof).map_or(0.0, |rows| {
                        rows.iter()
                            .zip(phi)
                            .take(kernels)
                            .map(|(x, p)| p * at(x, c))
                            .sum()
                    });
                    *v = column + if c == r { variance } else { 0.0 };
                }
            }
        }
        cholesky(&mut s, m, "the observations contradict the distribution")?;
        // μ += ΣHᵀ S⁻¹ (y* − Hμ).
        let mut gain = innovation;
        cholesky_solve(&s, m, &mut gain);
        for (a, rows) in sh.iter().enumerate().take(dof) {
            for (i, row) in rows.iter().enumerate().take(kernels) {
                let change: f64 = row.iter().zip(gain).take(m).map(|(x, g)| x * g).sum();
                if let Some(v) = self.mean.get_mut(a).and_then(|r| r.get_mut(i)) {
                    *v += change;
                }
            }
        }
        // Σ −= ΣHᵀ S⁻¹ HΣ, column by column of HΣ (= (ΣHᵀ)ᵀ).
        for b in 0..dof {
            for j in 0..kernels {
                let mut x = [0.0f64; D];
                let column = sh.get(b).and_then(|r| r.get(j));
                for (x, c) in x.iter_mut().zip(0..m) {
                    *x = column.map_or(0.0, |r| at(r, c));
                }
                cholesky_solve(&s, m, &mut x);
                for (a, rows) in sh.iter().enumerate().take(dof) {
                    for (i, row) in rows.iter().enumerate().take(kernels) {
                        let change: f64 = row.iter().zip(x).take(m).map(|(r, x)| r * x).sum();
                        if let Some(c) = self
                            .cov
                            .get_mut(a)
                            .and_then(|r| r.get_mut(b))
                            .and_then(|r| r.get_mut(i))
                            .and_then(|r| r.get_mut(j))
                        {
                            *c -= change;
                        }
                    }
                }
            }
        }
        if self
            .mean
            .iter()
            .flatten()
            .chain(self.cov.iter().flatten().flatten().flatten())
            .all(|v| v.is_finite())
        {
            Ok(())
        } else {
            Err(Error::NotFinite("the conditioned distribution"))
        }
    }

    /// The normalized kernels at phase `z` (clamped to [0, 1]).
    fn basis(&self, z: f64, phi: &mut [f64; K]) {
        let z = if z.is_nan() { 0.0 } else { z.clamp(0.0, 1.0) };
        let (spacing, width) = self.shape();
        let mut sum = 0.0;
        for (k, p) in phi.iter_mut().enumerate() {
            *p = match k < self.kernels {
                true => {
                    let d = z - k as f64 * spacing;
                    libm::exp(-width * d * d)
                }
                false => 0.0,
            };
            sum += *p;
        }
        if sum > 0.0 {
            phi.iter_mut().for_each(|p| *p /= sum);
        }
    }

    /// The normalized kernels' derivatives by the phase at `z` in [0, 1]:
    /// with `a_k = −2h (z − c_k)` each Gaussian's log-slope, `φ'_k = φ_k
    /// (a_k − Σ_j φ_j a_j)`.
    fn basis_slope(&self, z: f64, slope: &mut [f64; K]) {
        self.basis(z, slope);
        let (spacing, width) = self.shape();
        let log_slope = |k: usize| -2.0 * width * (z - k as f64 * spacing);
        let mean: f64 = slope
            .iter()
            .enumerate()
            .map(|(k, p)| p * log_slope(k))
            .sum();
        for (k, p) in slope.iter_mut().enumerate() {
            *p *= log_slope(k) - mean;
        }
    }

    /// The kernels' spacing on the phase and their width `h`, set by the
    /// kernel count and [`OVERLAP`].
    fn shape(&self) -> (f64, f64) {
        let spacing = 1.0 / (self.kernels - 1).max(1) as f64;
        (spacing, OVERLAP / (spacing * spacing))
    }

    fn cov_at(&self, a: usize, b: usize, i: usize, j: usize) -> f64 {
        self.cov
            .get(a)
            .and_then(|r| r.get(b))
            .and_then(|r| r.get(i))
            .and_then(|r| r.get(j))
            .copied()
            .unwrap_or(0.0)
    }
}

/// Blends two ProMPs at phase `z`, `a` with activation `alpha` and `b`
/// with `1 − alpha` (`alpha` in [0, 1]): the product of their
/// trajectory distributions at `z`, each DoF's precision weighted by its
/// activation: `σ⁻² = α σ_a⁻² + (1 − α) σ_b⁻²`, `μ = σ² (α σ_a⁻² μ_a + (1
/// − α) σ_b⁻² μ_b)`. Returns DoF `d`'s mean and variance. The DoFs are
/// blended one by one (their correlations are not). Refused: DoFs the
/// two do not share, an activation outside [0, 1].
pub fn blend<const D: usize, const K: usize>(
    a: &ProMp<D, K>,
    b: &ProMp<D, K>,
    alpha: f64,
    z: f64,
    d: usize,
) -> Result<(f64, f64), Error> {
    if !(0.0..=1.0).contains(&alpha) {
        return Err(Error::OutOfRange("an activation must lie in [0, 1]"));
    }
    if d >= a.dof || d >= b.dof {
        return Err(Error::OutOfRange("blending a DoF both ProMPs have"));
    }
    let (va, vb) = (a.variance(z, d), b.variance(z, d));
    if !(va > 0.0 && vb > 0.0) {
        return Err(Error::Singular(
            "a ProMP with no variance cannot be blended",
        ));
    }
    let precision = alpha / va + (1.0 - alpha) / vb;
    let variance = 1.0 / precision;
    Ok((
        variance * (alpha * a.mean(z, d) / va + (1.0 - alpha) * b.mean(z, d) / vb),
        variance,
    ))
}

fn dot<const K: usize>(a: &[f64; K], b: &[f64; K], n: usize) -> f64 {
    a.iter().zip(b).take(n).map(|(x, y)| x * y).sum()
}

fn at<const N: usize>(a: &[f64; N], i: usize) -> f64 {
    a.get(i).copied().unwrap_or(0.0)
}

fn at2<const N: usize, const M: usize>(a: &[[f64; N]; M], i: usize, j: usize) -> f64 {
    a.get(i).map_or(0.0, |r| at(r, j))
}
