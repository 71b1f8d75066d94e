//! Symmetric positive definite block band matrices of 3x3 blocks, block half-bandwidth `M`,
//! factorised as `L D L^T` with unit block-lower-triangular `L` and block-diagonal `D`
//! (Golub and Van Loan, *Matrix computations*, section 4.5, by blocks). The rotation's
//! Gauss-Newton system couples each frame's rotation (a 3-vector) with the frames `M`
//! apart; working on whole 3x3 blocks keeps the loops short and free of index arithmetic.
//!
//! ```text
//! L_ij D_j = A_ij - sum_{k<j} (L_ik D_k) L_jk^T          (j = i - M .. i - 1)
//! D_i      = A_ii - sum_{k<i} (L_ik D_k) L_ik^T
//! ```

// Index loops mirror the band algorithms (several arrays indexed together).
#![allow(clippy::needless_range_loop)]

use glam::{DMat3, DVec3};

/// A block band matrix: block row `i` holds `A_ii` and `A_{i, i-M+p}` at `off[i][p]`.
#[derive(Debug, Clone, Default)]
pub(crate) struct BlockBand<const M: usize> {
    diag: Vec<DMat3>,
    off: Vec<[DMat3; M]>,
    /// `D_i^-1` after [`BlockBand::factor`].
    inv: Vec<DMat3>,
}

impl<const M: usize> BlockBand<M> {
    /// The zero matrix of `n` block rows, reusing the storage.
    pub(crate) fn reset(&mut self, n: usize) {
        self.diag.clear();
        self.diag.resize(n, DMat3::ZERO);
        self.off.clear();
        self.off.resize(n, [DMat3::ZERO; M]);
    }

    /// Block rows.
    pub(crate) fn len(&self) -> usize {
        self.diag.len()
    }

    /// `A_ii += b` (`b` symmetric).
    #[inline(always)]
    pub(crate) fn add_diag(&mut self, i: usize, b: DMat3) {
        self.diag[i] += b;
    }

    /// `A_ij += b` for `j < i <= j + M`.
    #[inline(always)]
    pub(crate) fn add_off(&mut self, i: usize, j: usize, b: DMat3) {
        debug_assert!(j < i && i - j <= M);
        self.off[i][M - (i - j)] += b;
    }

    /// Sets block row and column `i` to those of the identity (a held unknown).
    pub(crate) fn pin(&mut self, i: usize) {
        self.off[i] = [DMat3::ZERO; M];
        self.diag[i] = DMat3::IDENTITY;
        for r in i + 1..(i + M + 1).min(self.len()) {
            self.off[r][M - (r - i)] = DMat3::ZERO;
        }
    }

    /// Factorises in place. False when a diagonal block is not positive definite (checked
    /// by its leading minors) or not finite.
    pub(crate) fn factor(&mut self) -> bool {
        let n = self.len();
        self.inv.clear();
        self.inv.resize(n, DMat3::ZERO);
        let mut ld = [DMat3::ZERO; M];
        for i in 0..n {
            let first = M.saturating_sub(i);
            let mut row = self.off[i];
            for p in first..M {
                let j = i + p - M;
                let rj = &self.off[j];
                let mut s = row[p];
                for q in first..p {
                    // L_jk for k = i - M + q sits at position M - p + q of row j.
                    s -= ld[q] * rj[M - p + q].transpose();
                }
                ld[p] = s;
                row[p] = s * self.inv[j];
            }
            let mut d = self.diag[i];
            for p in first..M {
                d -= row[p] * ld[p].transpose();
            }
            // Symmetrise against rounding, then check positive definiteness.
            d = (d + d.transpose()) * 0.5;
            let m1 = d.x_axis.x;
            let m2 = m1 * d.y_axis.y - d.y_axis.x * d.x_axis.y;
            let m3 = d.determinant();
            if !(m1 > 0.0 && m2 > 0.0 && m3 > 0.0 && m3.is_finite()) {
                return false;
            }
            self.off[i] = row;
            self.diag[i] = d;
            self.inv[i] = d.inverse();
        }
        true
    }

    /// Solves `A x = b` in place after [`BlockBand::factor`].
    pub(crate) fn solve(&self, b: &mut [DVec3]) {
        let n = self.len();
        for i in 0..n {
            let row = &self.off[i];
            let mut s = b[i];
            for p in M.saturating_sub(i)..M {
                s -= row[p] * b[i + p - M];
            }
            b[i] = s;
        }
        for i in 0..n {
            b[i] = self.inv[i] * b[i];
        }
        for i in (0..n).rev() {
            let mut s = b[i];
            for t in 1..=M.min(n - 1 - i) {
                s -= self.off[i + t][M - t].transpose() * b[i + t];
            }
            b[i] = s;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn solves_like_a_dense_solver() {
        let n = 9;
        let mut a = BlockBand::<3>::default();
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
        let mut b = BlockBand::<1>::default();
        b.reset(2);
        b.add_diag(0, DMat3::IDENTITY);
        b.add_diag(1, DMat3::IDENTITY);
        b.add_off(1, 0, DMat3::IDENTITY * 2.0);
        assert!(!b.clone().factor());
        b.pin(1);
        assert!(b.factor());
    }
}
