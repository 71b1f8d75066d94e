//! Eigenvalues and eigenvectors of small symmetric matrices by cyclic Jacobi rotations.
//!
//! Registration needs the eigenvector of the largest eigenvalue of Horn's symmetric 4x4
//! matrix (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, section 2), and the inertia points need the
//! principal axes of a 3x3 inertia tensor (section 2.1, eq. 10). Jacobi's method is the
//! sturdy choice for such sizes: every rotation is orthogonal, so the eigenvectors come out
//! orthonormal to rounding and the eigenvalues accurate to about `eps ||A||`, whatever their
//! multiplicity (Golub-Van Loan, section 8.5).
//!
//! Each rotation `J(p, q, theta)` zeroes `a_pq`:
//!
//! ```text
//! theta = (a_qq - a_pp) / (2 a_pq),  t = sign(theta) / (|theta| + sqrt(theta^2 + 1))
//! c = 1 / sqrt(t^2 + 1),  s = t c,   A <- J^T A J,   V <- V J
//! ```

#![allow(clippy::needless_range_loop)] // index loops mirror the matrix formulas

/// Jacobi stops when the off-diagonal Frobenius norm is below this fraction of the matrix's
/// Frobenius norm (a few units of rounding).
pub const JACOBI_TOLERANCE: f64 = 1e-15;

/// Sweeps after which Jacobi gives up improving (quadratic convergence needs about 6 for
/// 4x4 matrices; the bound only guards against NaN input).
pub const JACOBI_MAX_SWEEPS: usize = 64;

/// Eigen-decomposition of a symmetric `N x N` matrix (only the upper triangle of `a` is
/// read): eigenvalues sorted from largest to smallest, and the matching unit eigenvectors
/// `vectors[k]` (`A vectors[k] = values[k] vectors[k]`), mutually orthonormal.
///
/// Repeated eigenvalues are fine here; which basis of their eigenspace is returned is then
/// arbitrary. Callers that need a unique vector check the gap themselves.
pub fn symmetric_eigen<const N: usize>(a: &[[f64; N]; N]) -> ([f64; N], [[f64; N]; N]) {
    let identity = std::array::from_fn(|k| std::array::from_fn(|i| f64::from(u8::from(i == k))));
    symmetric_eigen_from(a, &identity)
}

/// [`symmetric_eigen`] started from an orthonormal `basis` (`basis[k]` the `k`-th vector,
/// for example the eigenvectors of a nearby matrix): Jacobi runs on `B^T A B`, which is
/// nearly diagonal when the basis is nearly right, so one or two sweeps suffice. The result
/// does not depend on the basis beyond rounding (and the choice inside repeated eigenvalues).
pub fn symmetric_eigen_from<const N: usize>(
    a: &[[f64; N]; N],
    basis: &[[f64; N]; N],
) -> ([f64; N], [[f64; N]; N]) {
    let mut full = *a;
    for i in 0..N {
        for j in 0..i {
            full[i][j] = full[j][i];
        }
    }
    // v[i][k] = basis[k][i]; m = V^T A V.
    let mut v: [[f64; N]; N] = std::array::from_fn(|i| std::array::from_fn(|k| basis[k][i]));
    let av: [[f64; N]; N] = std::array::from_fn(|i| {
        std::array::from_fn(|k| (0..N).map(|j| full[i][j] * v[j][k]).sum())
    });
    let mut m: [[f64; N]; N] =
        std::array::from_fn(|k| std::array::from_fn(|l| (0..N).map(|i| v[i][k] * av[i][l]).sum()));
    for k in 0..N {
        for l in 0..k {
            let mean = 0.5 * (m[k][l] + m[l][k]);
            m[k][l] = mean;
            m[l][k] = mean;
        }
    }
    let norm2: f64 = full.iter().flatten().map(|x| x * x).sum();
    let limit = JACOBI_TOLERANCE * JACOBI_TOLERANCE * norm2;
    for _ in 0..JACOBI_MAX_SWEEPS {
        let mut off2 = 0.0;
        for i in 0..N {
            for j in i + 1..N {
                off2 += 2.0 * m[i][j] * m[i][j];
            }
        }
        if off2 <= limit || !off2.is_finite() {
            break;
        }
        for p in 0..N {
            for q in p + 1..N {
                let apq = m[p][q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (m[q][q] - m[p][p]) / (2.0 * apq);
                let t = if theta.is_finite() {
                    theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt())
                } else {
                    0.0
                };
                if t == 0.0 {
                    // a_pq negligible against the diagonal difference: drop it.
                    m[p][q] = 0.0;
                    m[q][p] = 0.0;
                    continue;
                }
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                // A <- J^T A J on rows/columns p and q.
                for k in 0..N {
                    let (mkp, mkq) = (m[k][p], m[k][q]);
                    m[k][p] = c * mkp - s * mkq;
                    m[k][q] = s * mkp + c * mkq;
                }
                for k in 0..N {
                    let (mpk, mqk) = (m[p][k], m[q][k]);
                    m[p][k] = c * mpk - s * mqk;
                    m[q][k] = s * mpk + c * mqk;
                }
                m[p][q] = 0.0;
                m[q][p] = 0.0;
                for row in v.iter_mut() {
                    let (vp, vq) = (row[p], row[q]);
                    row[p] = c * vp - s * vq;
                    row[q] = s * vp + c * vq;
                }
            }
        }
    }
    let mut order: [usize; N] = std::array::from_fn(|i| i);
    order.sort_by(|&i, &j| m[j][j].total_cmp(&m[i][i]));
    let values = std::array::from_fn(|k| m[order[k]][order[k]]);
    let vectors = std::array::from_fn(|k| std::array::from_fn(|i| v[i][order[k]]));
    (values, vectors)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn check<const N: usize>(a: &[[f64; N]; N], tol: f64) {
        let (values, vectors) = symmetric_eigen(a);
        for k in 0..N {
            if k > 0 {
                assert!(values[k] <= values[k - 1], "not sorted: {values:?}");
            }
            for i in 0..N {
                let av: f64 = (0..N).map(|j| a[i][j] * vectors[k][j]).sum();
                let err = (av - values[k] * vectors[k][i]).abs();
                assert!(err < tol, "A v != lambda v ({err:e}) for {a:?}");
            }
            for l in 0..N {
                let d: f64 = (0..N).map(|i| vectors[k][i] * vectors[l][i]).sum();
                let want = if k == l { 1.0 } else { 0.0 };
                assert!((d - want).abs() < tol, "not orthonormal: {d} for {a:?}");
            }
        }
    }

    #[test]
    fn random_and_degenerate_matrices() {
        check(
            &[
                [4.0, 1.0, -2.0, 0.5],
                [1.0, 3.0, 0.0, 1.0],
                [-2.0, 0.0, -1.0, 2.0],
                [0.5, 1.0, 2.0, 0.0],
            ],
            1e-13,
        );
        // Repeated eigenvalues, zero matrix, diagonal, huge dynamic range.
        check(&[[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]], 1e-15);
        check(&[[0.0; 4]; 4], 1e-15);
        check(
            &[[2.0, 1.0, 1.0], [1.0, 2.0, 1.0], [1.0, 1.0, 2.0]], // 4, 1, 1
            1e-14,
        );
        check(&[[1e8, 1e-3], [1e-3, 1e-8]], 1e-7);
    }

    #[test]
    fn known_spectrum() {
        // Q diag(5, 2, -1, -3) Q^T with Q from a unit quaternion's left-multiplication matrix.
        let (w, x, y, z) = (0.5f64, 0.5, -0.5, 0.5);
        let q = [[w, -x, -y, -z], [x, w, -z, y], [y, z, w, -x], [z, -y, x, w]];
        let d = [5.0, 2.0, -1.0, -3.0];
        let mut a = [[0.0; 4]; 4];
        for i in 0..4 {
            for j in 0..4 {
                a[i][j] = (0..4).map(|k| q[i][k] * d[k] * q[j][k]).sum();
            }
        }
        let (values, vectors) = symmetric_eigen(&a);
        for k in 0..4 {
            assert!((values[k] - d[k]).abs() < 1e-14, "{values:?}");
            let dot: f64 = (0..4).map(|i| vectors[k][i] * q[i][k]).sum();
            assert!(
                (dot.abs() - 1.0).abs() < 1e-14,
                "vector {k}: {:?}",
                vectors[k]
            );
        }
    }
}
