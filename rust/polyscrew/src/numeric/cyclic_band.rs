//! Symmetric positive definite systems with half-bandwidth 2, optionally cyclic (the
//! variational subdivision systems of Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, eqs. 23, 24, 26-27 and their closed and
//! non-uniform versions).
//!
//! Open: the band kernel [`Band`] (`H = L D L^T`) in `O(n)`. Cyclic: the last `b = 2`
//! unknowns form a border; with `H = [[H11, H12], [H21, H22]]` and `H11` banded (no
//! wrap-around entries, factorised by [`Band`]),
//!
//! ```text
//! Y = H11^-1 H12,   S = H22 - H21 Y          (b x b Schur complement)
//! z = H11^-1 g1,    x2 = S^-1 (g2 - H21 z),   x1 = z - Y x2
//! ```
//!
//! also `O(n)`; no dense inverse is ever formed.

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix formulas
#![allow(clippy::neg_cmp_op_on_partial_ord)] // `!(d > 0.0)` rejects NaN pivots too

use std::ops::{Mul, Sub};

use super::band::Band;

/// Values a system can be solved for: scalars and 3D points (one coordinate at a time, the
/// matrix being the same for all three).
pub(crate) trait Lin: Copy + Sub<Output = Self> + Mul<f64, Output = Self> {
    /// The additive identity.
    const ZERO: Self;
}

impl Lin for f64 {
    const ZERO: Self = 0.0;
}

impl Lin for glam::DVec3 {
    const ZERO: Self = glam::DVec3::ZERO;
}

/// Width of the cyclic border.
const BORDER: usize = 2;

/// An assembled symmetric matrix of half-bandwidth 2 (cyclic when it has a border).
#[derive(Debug, Clone)]
pub(crate) struct BandMatrix {
    /// Interior size `n1`.
    n1: usize,
    /// Border size `b` (0 open, 2 cyclic).
    b: usize,
    /// `H11`.
    band: Band<f64, 2>,
    /// `cross[i][k] = H[i][n1 + k]`.
    cross: Vec<[f64; BORDER]>,
    corner: [[f64; BORDER]; BORDER],
}

/// The factorisation of a [`BandMatrix`].
#[derive(Debug, Clone)]
pub(crate) struct BandFactor {
    n1: usize,
    b: usize,
    /// `H11 = L D L^T`.
    band: Band<f64, 2>,
    cross: Vec<[f64; BORDER]>,
    /// `Y = H11^-1 H12`, row by row.
    y: Vec<[f64; BORDER]>,
    /// Cholesky factor of the Schur complement (lower).
    schur: [[f64; BORDER]; BORDER],
}

impl BandMatrix {
    /// A zero matrix of size `n`; `cyclic` adds the border (needs `n >= 2`).
    pub(crate) fn zeros(n: usize, cyclic: bool) -> Self {
        let b = if cyclic { BORDER.min(n) } else { 0 };
        let n1 = n - b;
        Self {
            n1,
            b,
            band: Band::zeros(n1),
            cross: vec![[0.0; BORDER]; n1],
            corner: [[0.0; BORDER]; BORDER],
        }
    }

    /// `H[i][j] += v` and, for `i != j`, `H[j][i] += v`. The pair must be within the band
    /// (cyclically, for a bordered matrix).
    pub(crate) fn add(&mut self, i: usize, j: usize, v: f64) {
        let (i, j) = if i >= j { (i, j) } else { (j, i) };
        let n1 = self.n1;
        if i < n1 {
            debug_assert!(i - j <= 2, "entry ({i}, {j}) outside the band");
            self.band.add(i, j, v);
        } else if j < n1 {
            self.cross[j][i - n1] += v;
        } else {
            self.corner[i - n1][j - n1] += v;
            if i != j {
                self.corner[j - n1][i - n1] += v;
            }
        }
    }

    /// `H x` (for residual checks).
    #[cfg(test)]
    pub(crate) fn mul<T: Lin + std::ops::Add<Output = T>>(&self, x: &[T]) -> Vec<T> {
        let n1 = self.n1;
        let mut out = vec![T::ZERO; n1 + self.b];
        for i in 0..n1 {
            out[i] = out[i] + x[i] * self.band.get(i, i);
            for d in 1..=2.min(i) {
                let s = self.band.get(i, i - d);
                out[i] = out[i] + x[i - d] * s;
                out[i - d] = out[i - d] + x[i] * s;
            }
            for k in 0..self.b {
                out[i] = out[i] + x[n1 + k] * self.cross[i][k];
                out[n1 + k] = out[n1 + k] + x[i] * self.cross[i][k];
            }
        }
        for k in 0..self.b {
            for l in 0..self.b {
                out[n1 + k] = out[n1 + k] + x[n1 + l] * self.corner[k][l];
            }
        }
        out
    }

    /// Factorisation: `H11 = L D L^T` by [`Band`], then the border's Schur complement by
    /// Cholesky.
    ///
    /// # Errors
    /// The index of the first non-positive (or non-finite) pivot: the matrix is not
    /// positive definite.
    pub(crate) fn factor(&self) -> Result<BandFactor, usize> {
        let n1 = self.n1;
        let mut band = self.band.clone();
        band.factor_or_pivot()?;
        let mut f = BandFactor {
            n1,
            b: self.b,
            band,
            cross: self.cross.clone(),
            y: vec![[0.0; BORDER]; n1],
            schur: [[0.0; BORDER]; BORDER],
        };
        let b = self.b;
        let mut s = self.corner;
        for k in 0..b {
            let mut col: Vec<f64> = self.cross.iter().map(|r| r[k]).collect();
            f.band_solve(&mut col);
            for (row, v) in f.y.iter_mut().zip(&col) {
                row[k] = *v;
            }
        }
        for k in 0..b {
            for l in 0..b {
                s[k][l] -= (0..n1).map(|i| self.cross[i][k] * f.y[i][l]).sum::<f64>();
            }
        }
        // Cholesky of the b x b Schur complement.
        for k in 0..b {
            let mut d = s[k][k];
            for m in 0..k {
                d -= f.schur[k][m] * f.schur[k][m];
            }
            if !(d > 0.0) || !d.is_finite() {
                return Err(n1 + k);
            }
            f.schur[k][k] = d.sqrt();
            for r in k + 1..b {
                let mut v = s[r][k];
                for m in 0..k {
                    v -= f.schur[r][m] * f.schur[k][m];
                }
                f.schur[r][k] = v / f.schur[k][k];
            }
        }
        Ok(f)
    }
}

impl BandFactor {
    /// Solves `H11 x = g` in place.
    fn band_solve<T: Lin>(&self, g: &mut [T]) {
        self.band.solve(g);
    }

    /// Solves `H x = g` in place.
    pub(crate) fn solve<T: Lin>(&self, g: &mut [T]) {
        let (n1, b) = (self.n1, self.b);
        let (g1, g2) = g.split_at_mut(n1);
        self.band_solve(g1);
        if b == 0 {
            return;
        }
        // r2 = g2 - H21 z, then x2 = S^-1 r2 by the Schur Cholesky factor.
        let mut r = [T::ZERO; BORDER];
        for k in 0..b {
            let mut v = g2[k];
            for (i, z) in g1.iter().enumerate() {
                v = v - *z * self.cross[i][k];
            }
            r[k] = v;
        }
        for k in 0..b {
            let mut v = r[k];
            for m in 0..k {
                v = v - r[m] * self.schur[k][m];
            }
            r[k] = v * (1.0 / self.schur[k][k]);
        }
        for k in (0..b).rev() {
            let mut v = r[k];
            for m in k + 1..b {
                v = v - r[m] * self.schur[m][k];
            }
            r[k] = v * (1.0 / self.schur[k][k]);
        }
        for (i, z) in g1.iter_mut().enumerate() {
            let mut v = *z;
            for (k, rk) in r.iter().enumerate().take(b) {
                v = v - *rk * self.y[i][k];
            }
            *z = v;
        }
        g2[..b].copy_from_slice(&r[..b]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A random SPD cyclic pentadiagonal matrix solved and checked by multiplication.
    #[test]
    fn solves_band_and_cyclic() {
        for n in 2..12 {
            for cyclic in [false, true] {
                let mut m = BandMatrix::zeros(n, cyclic);
                let mut seed = 1.0f64 + n as f64;
                let mut next = || {
                    seed = (seed * 7.31 + 0.17).fract();
                    seed - 0.5
                };
                for i in 0..n {
                    m.add(i, i, 6.0);
                    for d in 1..=2 {
                        if cyclic || i + d < n {
                            m.add(i, (i + d) % n, next());
                        }
                    }
                }
                let f = m.factor().unwrap();
                let x: Vec<f64> = (0..n).map(|i| (i as f64 * 0.37).sin()).collect();
                let mut g = m.mul(&x);
                f.solve(&mut g);
                for (a, b) in g.iter().zip(&x) {
                    assert!(
                        (a - b).abs() < 1e-13,
                        "n {n} cyclic {cyclic}: {g:?} vs {x:?}"
                    );
                }
            }
        }
    }

    #[test]
    fn detects_indefinite() {
        let mut m = BandMatrix::zeros(4, false);
        for i in 0..4 {
            m.add(i, i, 1.0);
        }
        m.add(2, 1, 2.0);
        assert_eq!(m.factor().unwrap_err(), 2);
    }
}
