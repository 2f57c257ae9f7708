//! Dense symmetric positive-definite solves on fixed-size square buffers,
//! and the normal equations of the weighted least-squares fits built on
//! them. Only the leading `n × n` block of an `N × N` buffer is used, so one
//! buffer serves every problem size up to its capacity.

use core::iter::Sum;
use core::ops::{Div, Mul, Sub};

use crate::Error;

/// The floating-point types the solves run in: `f32` for the learners,
/// `f64` for the DMP fit's ill-conditioned normal equations (and the
/// robot's inverse kinematics). Implemented for these two only.
pub trait Real:
    sealed::Sealed
    + Copy
    + PartialOrd
    + Sub<Output = Self>
    + Mul<Output = Self>
    + Div<Output = Self>
    + Sum
{
    /// Zero.
    const ZERO: Self;
    /// The square root (`libm`'s).
    fn sqrt(self) -> Self;
    /// Neither infinite nor NaN.
    fn is_finite(self) -> bool;
}

mod sealed {
    pub trait Sealed {}
    impl Sealed for f32 {}
    impl Sealed for f64 {}
}

impl Real for f32 {
    const ZERO: Self = 0.0;
    fn sqrt(self) -> Self {
        libm::sqrtf(self)
    }
    fn is_finite(self) -> bool {
        f32::is_finite(self)
    }
}

impl Real for f64 {
    const ZERO: Self = 0.0;
    fn sqrt(self) -> Self {
        libm::sqrt(self)
    }
    fn is_finite(self) -> bool {
        f64::is_finite(self)
    }
}

/// Factorizes the leading `n × n` block of the symmetric matrix `a` in place
/// into its lower Cholesky factor `L` (the strict upper part is left as is).
/// A pivot that is not finite and positive is [`Error::Singular`]`(what)`;
/// `n > N` is [`Error::Capacity`].
pub fn cholesky<T: Real, const N: usize>(
    a: &mut [[T; N]; N],
    n: usize,
    what: &'static str,
) -> Result<(), Error> {
    crate::error::check_capacity(what, n, N)?;
    for i in 0..n {
        let (done, rest) = a.split_at_mut(i);
        let row_i = rest.first_mut().ok_or(Error::Singular(what))?;
        for (j, row_j) in done.iter().enumerate() {
            let dot: T = row_i
                .iter()
                .zip(row_j.iter())
                .take(j)
                .map(|(x, y)| *x * *y)
                .sum();
            let ljj = *row_j.get(j).ok_or(Error::Singular(what))?;
            let lij = row_i.get_mut(j).ok_or(Error::Singular(what))?;
            *lij = (*lij - dot) / ljj;
        }
        let dot: T = row_i.iter().take(i).map(|x| *x * *x).sum();
        let d = row_i.get_mut(i).ok_or(Error::Singular(what))?;
        let pivot = *d - dot;
        // `!(pivot > 0)` also rejects NaN.
        if !(pivot > T::ZERO) || !pivot.is_finite() {
            return Err(Error::Singular(what));
        }
        *d = pivot.sqrt();
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place (`b` becomes `x`) with the factor from
/// [`cholesky`]. `b` must hold at least `n` values.
pub fn cholesky_solve<T: Real, const N: usize>(l: &[[T; N]; N], n: usize, b: &mut [T]) {
    // Forward substitution: L y = b.
    for (i, row) in l.iter().enumerate().take(n) {
        let (head, rest) = b.split_at_mut(i.min(b.len()));
        let dot: T = row.iter().zip(head.iter()).map(|(x, y)| *x * *y).sum();
        if let (Some(bi), Some(lii)) = (rest.first_mut(), row.get(i)) {
            *bi = (*bi - dot) / *lii;
        }
    }
    // Back substitution: Lᵀ x = y.
    for i in (0..n).rev() {
        let dot: T = l
            .iter()
            .enumerate()
            .take(n)
            .skip(i + 1)
            .map(|(k, row)| {
                row.get(i).copied().unwrap_or(T::ZERO) * b.get(k).copied().unwrap_or(T::ZERO)
            })
            .sum();
        if let (Some(bi), Some(lii)) = (b.get_mut(i), l.get(i).and_then(|r| r.get(i))) {
            *bi = (*bi - dot) / *lii;
        }
    }
}

/// The normal equations of a weighted least-squares fit of `kernels`
/// unknowns per DoF, one row of regressors per sample (the DMP fits': the
/// spring's responses to each kernel, [`crate::spring::Responses`]): the
/// Gram matrix's lower triangle and one right-hand side per DoF, in the
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
        ridge_solve(self.gram, self.rhs, self.kernels, self.dof, ridge, out).map(|_| ())
    }

    /// [`Normal::solve`], returning each DoF's residual: the weighted sum
    /// of squared misfits `Σ q (target − r·w)²` at the solution.
    pub fn solve_with_residual(
        &mut self,
        ridge: f32,
        out: &mut [[f32; K]; D],
    ) -> Result<[f64; D], Error> {
        let explained = ridge_solve(self.gram, self.rhs, self.kernels, self.dof, ridge, out)?;
        let mut residual = self.energy;
        for (r, e) in residual.iter_mut().zip(explained) {
            *r = (*r - e).max(0.0);
        }
        Ok(residual)
    }
}

/// Solves the normal equations `G w_d = b_d` of every DoF, `G` given by its
/// lower triangle, with a ridge `λ` of `ridge` times `G`'s mean diagonal;
/// the weights go to `out[d][..kernels]`. Returns per DoF what the fit
/// explains, `b·w + λ|w|²`: at the solution of `(G + λ)w = b` the residual
/// `Σq(t − r·w)² = Σqt² − 2b·w + w·Gw` is `Σqt²` minus that.
fn ridge_solve<const D: usize, const K: usize>(
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
    cholesky(gram, kernels, "DMP fit (too few samples for the kernels?)")?;
    let mut explained = [0.0; D];
    for ((b, w), e) in rhs
        .iter_mut()
        .zip(out.iter_mut())
        .zip(&mut explained)
        .take(dof)
    {
        let given = *b;
        cholesky_solve(gram, kernels, b);
        for ((wk, bk), gk) in w.iter_mut().zip(b.iter()).zip(&given).take(kernels) {
            *wk = *bk as f32;
            *e += bk * (gk + lambda * bk);
        }
    }
    Ok(explained)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_spd_system() {
        let mut a = [[4.0, 2.0, 0.6], [2.0, 5.0, 1.0], [0.6, 1.0, 3.0]];
        let orig = a;
        cholesky(&mut a, 3, "test").unwrap();
        let mut b = [1.0, -2.0, 0.5];
        let rhs = b;
        cholesky_solve(&a, 3, &mut b);
        for i in 0..3 {
            let r: f32 = (0..3).map(|j| orig[i][j] * b[j]).sum();
            assert!((r - rhs[i]).abs() < 1e-5);
        }
    }

    #[test]
    fn rejects_indefinite_and_nan() {
        let mut a = [[1.0, 2.0], [2.0, 1.0]];
        assert!(cholesky(&mut a, 2, "t").is_err());
        let mut a = [[f32::NAN, 0.0], [0.0, 1.0]];
        assert!(cholesky(&mut a, 2, "t").is_err());
        let mut a = [[1.0]];
        assert!(cholesky(&mut a, 2, "t").is_err());
    }
}
