//! Dense symmetric positive-definite solves on fixed-size square buffers.
//! Only the leading `n × n` block of an `N × N` buffer is used, so one buffer
//! serves every problem size up to its capacity.

use core::iter::Sum;
use core::ops::{Div, Mul, Sub};

use crate::Error;

/// The floating-point types the solves run in: `f32` for the learners,
/// `f64` for the DMP fit's ill-conditioned normal equations.
pub(crate) trait Real:
    Copy + PartialOrd + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self> + Sum
{
    const ZERO: Self;
    fn sqrt(self) -> Self;
    fn is_finite(self) -> bool;
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
pub(crate) fn cholesky<T: Real, const N: usize>(
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
pub(crate) fn cholesky_solve<T: Real, const N: usize>(l: &[[T; N]; N], n: usize, b: &mut [T]) {
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
