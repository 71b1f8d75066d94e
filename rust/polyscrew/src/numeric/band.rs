//! Symmetric positive definite band matrices of a fixed half-bandwidth `W`, factorised as
//! `L D L^T` in place (`L` unit lower triangular within the band), over an [`Entry`]: a
//! scalar (`f64`, the smoothing splines of Remove Noise) or a 3x3 block (`DMat3`, the
//! rotation's Gauss-Newton system, where each frame's unknown is a 3-vector). One kernel
//! for both (Golub and Van Loan, *Matrix computations*, section 4.3.5, by blocks):
//!
//! ```text
//! L_ij D_j = A_ij - sum_{k<j} (L_ik D_k) L_jk^T          (j = i - W .. i - 1)
//! D_i      = A_ii - sum_{k<i} (L_ik D_k) L_ik^T
//! ```
//!
//! For scalars also the diagonal of the inverse (Takahashi, Fagan, Chen, "Formation of a
//! sparse bus impedance matrix and its application to short circuit study", 1973: the
//! inverse's entries inside the band of `L` follow from `L` and `D` alone). Everything is
//! `O(n W^2)`.

// Index loops mirror the textbook band algorithms; iterator forms would hide the band.
#![allow(clippy::needless_range_loop)]

use std::ops::{Add, Mul, Sub};

use glam::{DMat3, DVec3};

/// An entry of a band matrix: a scalar or a square block.
pub(crate) trait Entry:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self>
{
    /// The additive identity.
    const ZERO: Self;
    /// The multiplicative identity.
    const ONE: Self;
    /// `b^T` (a scalar is its own transpose).
    fn transpose(self) -> Self;
    /// The pivot `D_i` as stored and its inverse, or `None` when `d` is not (numerically)
    /// positive definite and finite.
    fn pivot(d: Self) -> Option<(Self, Self)>;
}

/// An entry acting on the values a system is solved for (`V` = `f64` or `DVec3` for a
/// scalar, `DVec3` for a 3x3 block).
pub(crate) trait Acts<V>: Entry {
    /// `self v`.
    fn apply(self, v: V) -> V;
}

impl Entry for f64 {
    const ZERO: Self = 0.0;
    const ONE: Self = 1.0;
    #[inline(always)]
    fn transpose(self) -> Self {
        self
    }
    #[inline(always)]
    fn pivot(d: Self) -> Option<(Self, Self)> {
        (d > 0.0 && d.is_finite()).then(|| (d, 1.0 / d))
    }
}

impl<V: Mul<f64, Output = V>> Acts<V> for f64 {
    #[inline(always)]
    fn apply(self, v: V) -> V {
        v * self
    }
}

impl Entry for DMat3 {
    const ZERO: Self = DMat3::ZERO;
    const ONE: Self = DMat3::IDENTITY;
    #[inline(always)]
    fn transpose(self) -> Self {
        DMat3::transpose(&self)
    }
    /// Symmetrised against rounding, then positive definite by its leading minors.
    #[inline(always)]
    fn pivot(d: Self) -> Option<(Self, Self)> {
        let d = (d + d.transpose()) * 0.5;
        let m1 = d.x_axis.x;
        let m2 = m1 * d.y_axis.y - d.y_axis.x * d.x_axis.y;
        let m3 = d.determinant();
        (m1 > 0.0 && m2 > 0.0 && m3 > 0.0 && m3.is_finite()).then(|| (d, d.inverse()))
    }
}

impl Acts<DVec3> for DMat3 {
    #[inline(always)]
    fn apply(self, v: DVec3) -> DVec3 {
        self * v
    }
}

/// An `n x n` symmetric band matrix of entries `E`, half-bandwidth `W`, stored as its
/// diagonal and its lower band: `off[i][W - (i - j)]` holds `a[i][j]` for
/// `i - W <= j < i` (after [`Band::factor`]: `L[i][j]` and `D[i]`).
#[derive(Debug, Clone, Default)]
pub(crate) struct Band<E, const W: usize> {
    diag: Vec<E>,
    off: Vec<[E; W]>,
    /// `D[i]^-1` after [`Band::factor`] (the solves multiply by it).
    inv: Vec<E>,
}

impl<E: Entry, const W: usize> Band<E, W> {
    /// The zero matrix of size `n`, reusing the storage.
    pub(crate) fn reset(&mut self, n: usize) {
        self.diag.clear();
        self.diag.resize(n, E::ZERO);
        self.off.clear();
        self.off.resize(n, [E::ZERO; W]);
    }

    /// Size (block rows for blocks).
    pub(crate) fn len(&self) -> usize {
        self.diag.len()
    }

    /// `a[i][i] += v` (`v` symmetric).
    #[inline(always)]
    pub(crate) fn add_diag(&mut self, i: usize, v: E) {
        self.diag[i] = self.diag[i] + v;
    }

    /// `a[i][j] += v` for `j < i <= j + W`.
    #[inline(always)]
    pub(crate) fn add_off(&mut self, i: usize, j: usize, v: E) {
        debug_assert!(j < i && i - j <= W);
        let e = &mut self.off[i][W - (i - j)];
        *e = *e + v;
    }

    /// Sets row and column `i` to those of the identity (a held unknown).
    pub(crate) fn pin(&mut self, i: usize) {
        self.off[i] = [E::ZERO; W];
        self.diag[i] = E::ONE;
        for r in i + 1..(i + W + 1).min(self.len()) {
            self.off[r][W - (r - i)] = E::ZERO;
        }
    }

    /// Factorises in place into `L D L^T`. Returns false when a pivot is not positive
    /// definite and finite ([`Entry::pivot`]).
    pub(crate) fn factor(&mut self) -> bool {
        self.factor_or_pivot().is_ok()
    }

    /// [`Band::factor`], telling which pivot failed.
    ///
    /// # Errors
    /// The index of the first pivot that is not positive definite and finite.
    pub(crate) fn factor_or_pivot(&mut self) -> Result<(), usize> {
        let n = self.len();
        self.inv.clear();
        self.inv.reserve(n);
        // The first W rows reach past the start; the others take the row inlined with
        // `first = 0`, loops of constant length (the same operations in the same order).
        for i in 0..W.min(n) {
            self.factor_row(i, W - i)?;
        }
        for i in W.min(n)..n {
            self.factor_row(i, 0)?;
        }
        Ok(())
    }

    /// Row `i` of [`Band::factor_or_pivot`], whose band starts at column `i - W + first`.
    #[inline(always)]
    fn factor_row(&mut self, i: usize, first: usize) -> Result<(), usize> {
        // ld[q] = L[i][k] D[k] for k = i - W + q, the row being factorised.
        let mut ld = [E::ZERO; W];
        let mut row = self.off[i];
        for p in first..W {
            // j = i - W + p; L[j][k] for k = i - W + q sits at W - p + q in row j.
            let j = i + p - W;
            let rj = &self.off[j];
            let mut s = row[p];
            for q in first..p {
                s = s - ld[q] * rj[W - p + q].transpose();
            }
            ld[p] = s;
            row[p] = s * self.inv[j];
        }
        let mut d = self.diag[i];
        for p in first..W {
            d = d - row[p] * ld[p].transpose();
        }
        let Some((d, inv)) = E::pivot(d) else {
            return Err(i);
        };
        self.off[i] = row;
        self.diag[i] = d;
        self.inv.push(inv);
        Ok(())
    }

    /// Solves `a x = b` in place after [`Band::factor`].
    pub(crate) fn solve<V>(&self, b: &mut [V])
    where
        V: Copy + Sub<Output = V>,
        E: Acts<V>,
    {
        let n = self.len();
        let (off, inv, b) = (&self.off[..n], &self.inv[..n], &mut b[..n]);
        // The first and last W rows reach past an end of the band; the rows between take
        // all W terms in a loop of constant length (the same operations in the same order).
        let head = W.min(n);
        for i in 0..head {
            let mut s = b[i];
            for p in W - i..W {
                s = s - off[i][p].apply(b[i + p - W]);
            }
            b[i] = s;
        }
        for i in head..n {
            let (done, rest) = b.split_at_mut(i);
            let (row, before) = (&off[i], &done[i - W..]);
            let mut s = rest[0];
            for p in 0..W {
                s = s - row[p].apply(before[p]);
            }
            rest[0] = s;
        }
        let tail = n.saturating_sub(W);
        for i in (tail..n).rev() {
            let mut s = inv[i].apply(b[i]);
            for t in 1..n - i {
                s = s - off[i + t][W - t].transpose().apply(b[i + t]);
            }
            b[i] = s;
        }
        for i in (0..tail).rev() {
            let (head, after) = b.split_at_mut(i + 1);
            let (rows, after) = (&off[i + 1..=i + W], &after[..W]);
            let mut s = inv[i].apply(head[i]);
            for t in 1..=W {
                s = s - rows[t - 1][W - t].transpose().apply(after[t - 1]);
            }
            head[i] = s;
        }
    }
}

impl<const W: usize> Band<f64, W> {
    /// The zero matrix of size `n`.
    pub(crate) fn zeros(n: usize) -> Self {
        let mut a = Self::default();
        a.reset(n);
        a
    }

    /// `a[i][j] += v` for `j <= i <= j + W`.
    #[inline(always)]
    pub(crate) fn add(&mut self, i: usize, j: usize, v: f64) {
        if i == j {
            self.add_diag(i, v);
        } else {
            self.add_off(i, j, v);
        }
    }

    /// `a[i][j]` for `j <= i <= j + W` (before [`Band::factor`]).
    #[inline(always)]
    pub(crate) fn get(&self, i: usize, j: usize) -> f64 {
        debug_assert!(j <= i && i - j <= W);
        if i == j {
            self.diag[i]
        } else {
            self.off[i][W - (i - j)]
        }
    }

    /// `a x`, from the lower band and its mirror image (before [`Band::factor`]).
    pub(crate) fn mul(&self, x: &[f64]) -> Vec<f64> {
        let n = self.len();
        debug_assert_eq!(x.len(), n);
        let mut y = vec![0.0; n];
        for i in 0..n {
            y[i] += self.diag[i] * x[i];
            let row = &self.off[i];
            for p in W.saturating_sub(i)..W {
                let j = i + p - W;
                y[i] += row[p] * x[j];
                y[j] += row[p] * x[i];
            }
        }
        y
    }

    /// `x` with `a x = rhs`, the matrix kept (factorised on a copy); `None` when `a` is not
    /// numerically positive definite or `x` is not finite.
    pub(crate) fn solved(&self, rhs: &[f64]) -> Option<Vec<f64>> {
        let mut f = self.clone();
        if !f.factor() {
            return None;
        }
        let mut x = rhs.to_vec();
        f.solve(&mut x);
        x.iter().all(|v| v.is_finite()).then_some(x)
    }

    /// `self = scale * other` (same size).
    pub(crate) fn scaled_from(&mut self, other: &Band<f64, W>, scale: f64) {
        self.diag.clear();
        self.diag.extend(other.diag.iter().map(|v| v * scale));
        self.off.clear();
        self.off
            .extend(other.off.iter().map(|r| r.map(|v| v * scale)));
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
            let mut s = self.inv[i];
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

    fn dense_of<const W: usize>(n: usize, seed: f64) -> (Band<f64, W>, nalgebra::DMatrix<f64>) {
        let mut a = Band::<f64, W>::default();
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
    fn multiplies_like_a_dense_matrix_and_solves_a_copy() {
        let n = 9;
        let (a, d) = dense_of::<3>(n, 0.71);
        let x: Vec<f64> = (0..n).map(|i| (i as f64).sin()).collect();
        let back = a.mul(&x);
        let want = &d * nalgebra::DVector::from_vec(x.clone());
        for i in 0..n {
            assert!(
                (back[i] - want[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                back[i],
                want[i]
            );
            assert_eq!(a.get(i, i), d[(i, i)]);
        }
        let solved = a.solved(&back).unwrap();
        for i in 0..n {
            assert!(
                (solved[i] - x[i]).abs() < 1e-12,
                "{i}: {} vs {}",
                solved[i],
                x[i]
            );
        }
    }

    #[test]
    fn refuses_to_solve_an_indefinite_matrix_and_names_its_pivot() {
        let mut bad = Band::<f64, 1>::zeros(2);
        bad.add(0, 0, 1.0);
        bad.add(1, 0, 2.0);
        bad.add(1, 1, 1.0);
        assert!(bad.solved(&[1.0, 1.0]).is_none());
        assert_eq!(bad.factor_or_pivot(), Err(1));
    }

    #[test]
    fn refuses_an_indefinite_matrix_and_pins() {
        let mut a = Band::<f64, 1>::default();
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

    #[test]
    fn solves_blocks_like_a_dense_solver() {
        let n = 9;
        let mut a = Band::<DMat3, 3>::default();
        a.reset(n);
        let mut d = nalgebra::DMatrix::<f64>::zeros(3 * n, 3 * n);
        let entry = |i: usize, j: usize| ((i * 13 + j * 7) as f64 * 0.37).sin();
        for i in 0..n {
            for j in i.saturating_sub(3)..=i {
                let mut b = DMat3::ZERO;
                for r in 0..3 {
                    for c in 0..3 {
                        let (gi, gj) = (3 * i + r, 3 * j + c);
                        let v = if i == j {
                            if r == c {
                                30.0
                            } else {
                                entry(gi.max(gj), gi.min(gj))
                            }
                        } else {
                            entry(gi, gj)
                        };
                        b.col_mut(c)[r] = v;
                        d[(gi, gj)] = v;
                        d[(gj, gi)] = v;
                    }
                }
                if i == j {
                    a.add_diag(i, b);
                } else {
                    a.add_off(i, j, b);
                }
            }
        }
        assert!(a.factor());
        let rhs: Vec<DVec3> = (0..n)
            .map(|i| DVec3::new(i as f64, 1.0, -(i as f64).sin()))
            .collect();
        let mut x = rhs.clone();
        a.solve(&mut x);
        let flat = nalgebra::DVector::from_iterator(3 * n, rhs.iter().flat_map(|v| v.to_array()));
        let want = d.lu().solve(&flat).unwrap();
        for i in 0..n {
            for c in 0..3 {
                assert!((x[i][c] - want[3 * i + c]).abs() < 1e-12, "{i} {c}");
            }
        }
        assert_eq!(a.len(), n);
        let mut b = Band::<DMat3, 1>::default();
        b.reset(2);
        b.add_diag(0, DMat3::IDENTITY);
        b.add_diag(1, DMat3::IDENTITY);
        b.add_off(1, 0, DMat3::IDENTITY * 2.0);
        assert!(!b.clone().factor());
        b.pin(1);
        assert!(b.factor());
    }
}
