//! Dense symmetric positive-definite solves on fixed-size square buffers.
//! Only the leading `n × n` block of an `N × N` buffer is used, so one buffer
//! serves every problem size up to its capacity.

use crate::Error;

/// Factorizes the leading `n × n` block of the symmetric matrix `a` in place
/// into its lower Cholesky factor `L` (the strict upper part is left as is).
pub(crate) fn cholesky<const N: usize>(
    a: &mut [[f32; N]; N],
    n: usize,
    what: &'static str,
) -> Result<(), Error> {
    crate::error::check_capacity(what, n, N)?;
    for i in 0..n {
        let (done, rest) = a.split_at_mut(i);
        let row_i = rest.first_mut().ok_or(Error::Singular(what))?;
        for (j, row_j) in done.iter().enumerate() {
            let dot: f32 = row_i
                .iter()
                .zip(row_j.iter())
                .take(j)
                .map(|(x, y)| x * y)
                .sum();
            let ljj = *row_j.get(j).ok_or(Error::Singular(what))?;
            let lij = row_i.get_mut(j).ok_or(Error::Singular(what))?;
            *lij = (*lij - dot) / ljj;
        }
        let dot: f32 = row_i.iter().take(i).map(|x| x * x).sum();
        let d = row_i.get_mut(i).ok_or(Error::Singular(what))?;
        let pivot = *d - dot;
        // `!(pivot > 0)` also rejects NaN.
        if !(pivot > 0.0) || !pivot.is_finite() {
            return Err(Error::Singular(what));
        }
        *d = libm::sqrtf(pivot);
    }
    Ok(())
}

/// Solves `L Lᵀ x = b` in place (`b` becomes `x`) with the factor from
/// [`cholesky`]. `b` must hold at least `n` values.
pub(crate) fn cholesky_solve<const N: usize>(l: &[[f32; N]; N], n: usize, b: &mut [f32]) {
    // Forward substitution: L y = b.
    for (i, row) in l.iter().enumerate().take(n) {
        let (head, rest) = b.split_at_mut(i.min(b.len()));
        let dot: f32 = row.iter().zip(head.iter()).map(|(x, y)| x * y).sum();
        if let (Some(bi), Some(lii)) = (rest.first_mut(), row.get(i)) {
            *bi = (*bi - dot) / lii;
        }
    }
    // Back substitution: Lᵀ x = y.
    for i in (0..n).rev() {
        let dot: f32 = l
            .iter()
            .enumerate()
            .take(n)
            .skip(i + 1)
            .map(|(k, row)| row.get(i).copied().unwrap_or(0.0) * b.get(k).copied().unwrap_or(0.0))
            .sum();
        if let (Some(bi), Some(lii)) = (b.get_mut(i), l.get(i).and_then(|r| r.get(i))) {
            *bi = (*bi - dot) / lii;
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
