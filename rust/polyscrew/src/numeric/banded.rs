//! Symmetric banded matrices and their Cholesky factorisation, for the normal equations of
//! spline fits: a Hermite spline couples only neighbouring control points, so `J^T J` is
//! block tridiagonal and factorises in `O(n b^2)` instead of `O(n^3)`.

// Index loops mirror the textbook band algorithms; iterator forms would hide the band.
#![allow(clippy::needless_range_loop)]

/// A symmetric `n x n` matrix with half-bandwidth `b` (`a[i][j] = 0` for `|i - j| > b`),
/// stored as its lower band: row `i` holds `a[i][i - b ..= i]`.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct SymBand {
    n: usize,
    b: usize,
    data: Vec<f64>,
}

impl SymBand {
    /// The zero matrix.
    pub(crate) fn zeros(n: usize, b: usize) -> Self {
        Self {
            n,
            b,
            data: vec![0.0; n * (b + 1)],
        }
    }

    /// Size `n`.
    pub(crate) fn len(&self) -> usize {
        self.n
    }

    #[inline]
    fn idx(&self, i: usize, j: usize) -> usize {
        debug_assert!(j <= i && i - j <= self.b && i < self.n);
        i * (self.b + 1) + (self.b - (i - j))
    }

    /// `a[i][j]` for `j <= i` within the band.
    #[inline]
    pub(crate) fn get(&self, i: usize, j: usize) -> f64 {
        self.data[self.idx(i, j)]
    }

    /// `a[i][j] += v` for `j <= i` within the band (the symmetric entry is implied).
    #[inline]
    pub(crate) fn add(&mut self, i: usize, j: usize, v: f64) {
        let k = self.idx(i, j);
        self.data[k] += v;
    }

    /// `a x`, from the lower band and its mirror image.
    pub(crate) fn mul(&self, x: &[f64]) -> Vec<f64> {
        debug_assert_eq!(x.len(), self.n);
        let mut y = vec![0.0; self.n];
        for i in 0..self.n {
            y[i] += self.get(i, i) * x[i];
            for j in i.saturating_sub(self.b)..i {
                let v = self.get(i, j);
                y[i] += v * x[j];
                y[j] += v * x[i];
            }
        }
        y
    }

    /// Solves `a x = rhs` by Cholesky factorisation `a = L L^T` within the band.
    ///
    /// Returns `None` when `a` is not (numerically) positive definite.
    pub(crate) fn solve(&self, rhs: &[f64]) -> Option<Vec<f64>> {
        let (n, b) = (self.n, self.b);
        debug_assert_eq!(rhs.len(), n);
        let mut l = self.clone();
        for j in 0..n {
            let lo = j.saturating_sub(b);
            let mut d = l.get(j, j);
            for k in lo..j {
                let v = l.get(j, k);
                d -= v * v;
            }
            if d.is_nan() || d <= 0.0 {
                return None;
            }
            let d = d.sqrt();
            let k = l.idx(j, j);
            l.data[k] = d;
            for i in j + 1..(j + b + 1).min(n) {
                let lo_i = i.saturating_sub(b).max(lo);
                let mut s = l.get(i, j);
                for k in lo_i..j {
                    s -= l.get(i, k) * l.get(j, k);
                }
                let k = l.idx(i, j);
                l.data[k] = s / d;
            }
        }
        // L y = rhs
        let mut x = rhs.to_vec();
        for i in 0..n {
            let mut s = x[i];
            for k in i.saturating_sub(b)..i {
                s -= l.get(i, k) * x[k];
            }
            x[i] = s / l.get(i, i);
        }
        // L^T x = y
        for i in (0..n).rev() {
            let mut s = x[i];
            for k in i + 1..(i + b + 1).min(n) {
                s -= l.get(k, i) * x[k];
            }
            x[i] = s / l.get(i, i);
        }
        if x.iter().all(|v| v.is_finite()) {
            Some(x)
        } else {
            None
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_a_banded_system_like_a_dense_solver() {
        let (n, b) = (9, 3);
        let mut a = SymBand::zeros(n, b);
        let mut dense = nalgebra::DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            for j in i.saturating_sub(b)..=i {
                let v = if i == j {
                    10.0 + i as f64
                } else {
                    ((i * 7 + j * 3) % 5) as f64 - 2.0
                };
                a.add(i, j, v);
                dense[(i, j)] = v;
                dense[(j, i)] = v;
            }
        }
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let x = a.solve(&rhs).unwrap();
        // the product of the band and its mirror is the dense product
        let back = a.mul(&x);
        let dense_back = &dense * nalgebra::DVector::from_vec(x.clone());
        for i in 0..n {
            assert!(
                (back[i] - dense_back[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                back[i],
                dense_back[i]
            );
        }
        let expected = dense
            .cholesky()
            .unwrap()
            .solve(&nalgebra::DVector::from_vec(rhs.clone()));
        for i in 0..n {
            assert!(
                (x[i] - expected[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                x[i],
                expected[i]
            );
        }
        assert_eq!(a.len(), n);
    }

    #[test]
    fn refuses_an_indefinite_matrix() {
        let mut a = SymBand::zeros(2, 1);
        a.add(0, 0, 1.0);
        a.add(1, 0, 2.0);
        a.add(1, 1, 1.0);
        assert!(a.solve(&[1.0, 1.0]).is_none());
    }
}
