//! Symmetric positive definite band matrices of a fixed half-bandwidth `W`, factorised as
//! `L D L^T` in place (`L` unit lower triangular within the band), with solves and the
//! diagonal of the inverse (Takahashi, Fagan, Chen, "Formation of a sparse bus impedance
//! matrix and its application to short circuit study", 1973: the inverse's entries inside the
//! band of `L` follow from `L` and `D` alone). Everything is `O(n W^2)`.

// Index loops mirror the textbook band algorithms; iterator forms would hide the band.
#![allow(clippy::needless_range_loop)]

use std::ops::{Mul, Sub};

/// An `n x n` symmetric band matrix, half-bandwidth `W`, stored as its diagonal and its
/// lower band: `off[i][W - (i - j)]` holds `a[i][j]` for `i - W <= j < i` (after
/// [`Band::factor`]: `L[i][j]` and `D[i]`).
#[derive(Debug, Clone, Default)]
pub(crate) struct Band<const W: usize> {
    diag: Vec<f64>,
    off: Vec<[f64; W]>,
    /// `1 / D[i]` after [`Band::factor`] (the solves multiply by it).
    dinv: Vec<f64>,
}

impl<const W: usize> Band<W> {
    /// The zero matrix of size `n`, reusing the storage.
    pub(crate) fn reset(&mut self, n: usize) {
        self.diag.clear();
        self.diag.resize(n, 0.0);
        self.off.clear();
        self.off.resize(n, [0.0; W]);
    }

    /// Size.
    pub(crate) fn len(&self) -> usize {
        self.diag.len()
    }

    /// `a[i][i] += v`.
    #[inline(always)]
    pub(crate) fn add_diag(&mut self, i: usize, v: f64) {
        self.diag[i] += v;
    }

    /// `a[i][j] += v` for `j < i <= j + W`.
    #[inline(always)]
    pub(crate) fn add_off(&mut self, i: usize, j: usize, v: f64) {
        debug_assert!(j < i && i - j <= W);
        self.off[i][W - (i - j)] += v;
    }

    /// `a[i][j] += v` for `j <= i <= j + W`.
    #[cfg(test)]
    pub(crate) fn add(&mut self, i: usize, j: usize, v: f64) {
        if i == j {
            self.add_diag(i, v);
        } else {
            self.add_off(i, j, v);
        }
    }

    /// `self = scale * other` (same size).
    pub(crate) fn scaled_from(&mut self, other: &Band<W>, scale: f64) {
        self.diag.clear();
        self.diag.extend(other.diag.iter().map(|v| v * scale));
        self.off.clear();
        self.off
            .extend(other.off.iter().map(|r| r.map(|v| v * scale)));
    }

    /// Sets row and column `i` to those of the identity (a held unknown).
    pub(crate) fn pin(&mut self, i: usize) {
        self.off[i] = [0.0; W];
        self.diag[i] = 1.0;
        for r in i + 1..(i + W + 1).min(self.len()) {
            self.off[r][W - (r - i)] = 0.0;
        }
    }

    /// Factorises in place into `L D L^T`. Returns false when a pivot is not positive and
    /// finite (the matrix is not numerically positive definite).
    pub(crate) fn factor(&mut self) -> bool {
        let n = self.len();
        self.dinv.clear();
        self.dinv.reserve(n);
        // ld[q] = L[i][k] D[k] for k = i - W + q, the row being factorised.
        let mut ld = [0.0; W];
        // inv[q] = 1 / D[k] for the same k (a window moving with i).
        let mut inv = [0.0; W];
        for i in 0..n {
            let first = W.saturating_sub(i);
            let mut row = self.off[i];
            for p in first..W {
                // j = i - W + p; L[j][k] for k = i - W + q sits at W - p + q in row j.
                let j = i + p - W;
                let rj = &self.off[j];
                let mut s = row[p];
                for q in first..p {
                    s -= ld[q] * rj[W - p + q];
                }
                ld[p] = s;
                row[p] = s * inv[p];
            }
            let mut d = self.diag[i];
            for p in first..W {
                d -= row[p] * ld[p];
            }
            if !(d > 0.0 && d.is_finite()) {
                return false;
            }
            self.off[i] = row;
            self.diag[i] = d;
            let r = 1.0 / d;
            self.dinv.push(r);
            if W > 0 {
                inv.copy_within(1.., 0);
                inv[W - 1] = r;
            }
        }
        true
    }

    /// Solves `a x = b` in place after [`Band::factor`], for scalars or vectors.
    pub(crate) fn solve<T>(&self, b: &mut [T])
    where
        T: Copy + Sub<Output = T> + Mul<f64, Output = T>,
    {
        let n = self.len();
        for i in 0..n {
            let row = &self.off[i];
            let mut s = b[i];
            for p in W.saturating_sub(i)..W {
                s = s - b[i + p - W] * row[p];
            }
            b[i] = s;
        }
        for i in (0..n).rev() {
            let mut s = b[i] * self.dinv[i];
            for t in 1..=W.min(n - 1 - i) {
                s = s - b[i + t] * self.off[i + t][W - t];
            }
            b[i] = s;
        }
    }

    /// The diagonal of `a^-1` after [`Band::factor`] (Takahashi's recurrence, from the last
    /// row up): with `Z = a^-1`, `Z[i][i+d] = -sum_{t=1..=W} L[i+t][i] Z[i+t][i+d]` for
    /// `d = W, ..., 1`, then `Z[i][i] = 1 / D[i] - sum_t L[i+t][i] Z[i][i+t]`. `z` is scratch
    /// (row `i` holds `Z[i][i..=i+W]`), reused between calls. For `W <= 3`.
    pub(crate) fn inverse_diagonal(&self, z: &mut Vec<[f64; 4]>, out: &mut [f64]) {
        self.inverse_diagonal_tail(self.len(), z, out);
    }

    /// [`Band::inverse_diagonal`] of the last `rows` rows only (the recurrence runs from the
    /// last row up): `out[i]` is set for `i >= n - rows`.
    pub(crate) fn inverse_diagonal_tail(
        &self,
        rows: usize,
        z: &mut Vec<[f64; 4]>,
        out: &mut [f64],
    ) {
        debug_assert!(W <= 3, "inverse_diagonal keeps rows of 4");
        let n = self.len();
        z.clear();
        z.resize(n, [0.0; 4]);
        for i in (n - rows.min(n)..n).rev() {
            let tmax = W.min(n - 1 - i);
            let mut l = [0.0; 4];
            for t in 1..=tmax {
                l[t] = self.off[i + t][W - t];
            }
            let mut zi = [0.0; 4];
            for d in (1..=tmax).rev() {
                let mut s = 0.0;
                // Z[i+t][i+d] = z[i + min(t, d)][|t - d|]
                for t in 1..=d {
                    s -= l[t] * z[i + t][d - t];
                }
                for t in d + 1..=tmax {
                    s -= l[t] * z[i + d][t - d];
                }
                zi[d] = s;
            }
            let mut s = self.dinv[i];
            for t in 1..=tmax {
                s -= l[t] * zi[t];
            }
            zi[0] = s;
            z[i] = zi;
            out[i] = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dense_of<const W: usize>(n: usize, seed: f64) -> (Band<W>, nalgebra::DMatrix<f64>) {
        let mut a = Band::<W>::default();
        a.reset(n);
        let mut d = nalgebra::DMatrix::<f64>::zeros(n, n);
        for i in 0..n {
            for j in i.saturating_sub(W)..=i {
                let v = if i == j {
                    4.0 * W as f64 + 1.0 + (i as f64 * seed).sin()
                } else {
                    ((i * 7 + j * 3) as f64 * seed).cos()
                };
                a.add(i, j, v);
                d[(i, j)] = v;
                d[(j, i)] = v;
            }
        }
        (a, d)
    }

    fn check<const W: usize>() {
        let n = 17;
        let (mut a, d) = dense_of::<W>(n, 0.37);
        assert_eq!(a.len(), n);
        assert!(a.factor());
        let inv = d.clone().try_inverse().unwrap();
        let rhs: Vec<f64> = (0..n).map(|i| (i as f64 * 1.3).sin()).collect();
        let mut x = rhs.clone();
        a.solve(&mut x);
        let want = &inv * nalgebra::DVector::from_vec(rhs);
        for i in 0..n {
            assert!(
                (x[i] - want[i]).abs() < 1e-12,
                "W {W} x[{i}] {} vs {}",
                x[i],
                want[i]
            );
        }
        if W <= 3 {
            let mut z = Vec::new();
            let mut diag = vec![0.0; n];
            a.inverse_diagonal(&mut z, &mut diag);
            for i in 0..n {
                assert!((diag[i] - inv[(i, i)]).abs() < 1e-12, "W {W} diag {i}");
                // The band of Z is the band of the inverse.
                for d in 0..=W.min(n - 1 - i) {
                    assert!(
                        (z[i][d] - inv[(i, i + d)]).abs() < 1e-12,
                        "W {W} z[{i}][+{d}]"
                    );
                }
            }
        }
    }

    #[test]
    fn solves_and_inverts_like_a_dense_solver() {
        check::<1>();
        check::<2>();
        check::<3>();
        check::<8>();
        check::<11>();
    }

    #[test]
    fn refuses_an_indefinite_matrix_and_pins() {
        let mut a = Band::<1>::default();
        a.reset(2);
        a.add(0, 0, 1.0);
        a.add(1, 0, 2.0);
        a.add(1, 1, 1.0);
        assert!(!a.clone().factor());
        a.pin(0);
        assert!(a.factor());
        let mut x = [3.0, 5.0];
        a.solve(&mut x);
        assert_eq!(x, [3.0, 5.0]);
    }
}
