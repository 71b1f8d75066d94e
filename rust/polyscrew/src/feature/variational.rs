//! Kobbelt's variational subdivision of polygons, interpolating and approximating, uniform
//! and non-uniform (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, sections 4.1-4.2, after Kobbelt 1996 and
//! Kobbelt-Schroeder 1998).
//!
//! One level refines `v_0..v_{n-1}` into `w_0..w_{M-1}` (`M = 2n - 1` open, `2n` closed):
//! `w_{2i}` descends from `v_i`, `w_{2i+1} = q_i` is new, at the parameter midpoint. The new
//! polygon minimises
//!
//! ```text
//! F(w) = sum_j (D0 + D1) / 2 |2 c_2(w_{j-1}, w_j, w_{j+1})|^2  +  sum_i lambda_i |v_i - w_{2i}|^2
//!
//! 2 c_2 = 2 w_{j-1} / (D0 (D0 + D1)) - 2 w_j / (D0 D1) + 2 w_{j+1} / (D1 (D0 + D1))  (eq. 19)
//! ```
//!
//! over every inner triple `j` (all `j` cyclically when closed), with `D0`, `D1` the
//! parameter spacings either side of `w_j`. The weight `(D0 + D1) / 2` (1 for uniform
//! spacing) makes the sum a quadrature of `int |f''|^2 dt`; the paper writes the plain sum
//! `sum |c_2|^2` (eq. 21), which for unequal spacings weights the energy by `1 / spacing` and
//! lets the limit's second derivative jump at keys where the spacing changes (only C1 there;
//! the convergence test of this module sees it), so we weight it as Kobbelt-Schroeder's
//! discretisation of the integral does. A key with `lambda_i = inf` is kept
//! (`w_{2i} = v_i`, the interpolating scheme); finite `lambda_i` is the spring of section 4.2.
//! With unit spacings `2 c_2` is the second difference `w_{j-1} - 2 w_j + w_{j+1}` (eq. 20)
//! and `F` is exactly eq. 22 (open interpolating), eq. 24 (closed) and eq. 25 (open
//! approximating). Setting `grad F / 2 = 0` gives the paper's systems `A q = B f` (eq. 23,
//! tridiagonal; cyclic for eq. 24) and `A^a x = b` (eqs. 26-27), here assembled in the
//! interleaved order `w_0, w_1, ...`, where every system is (cyclic) pentadiagonal and is
//! solved by a band Cholesky factorisation (no dense inverse).
//!
//! Parameter spacings: uniform (all 1) or centripetal, `t_{i+1} - t_i = sqrt(|f_{i+1} - f_i|)`
//! (eq. 18; for several curves designed together, `|.|` is the Euclidean norm of all their
//! coordinates stacked, the metric of `A^12` in section 3.3.2). Each level halves every
//! spacing (new points at parameter midpoints); the spacings of each level are rescaled to
//! mean 1 so that the uniform case is eq. 22 exactly and `lambda` means the same in both.
//!
//! Stiffness across levels (section 4.2): the points descending from input key `i` keep the
//! key's `lambda_i` at every level; points inserted at an earlier level get
//! `inserted_stiffness` (default `inf`: once inserted, kept).

#![allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > 0.0)` also rejects NaN

use glam::DVec3;

use crate::error::{At, Error, Expected, Result};
use crate::motion::subdivision::{check_subdivision, subdivided_len};
use crate::numeric::cyclic_band::BandMatrix;

/// How parameter values are assigned to the input points.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Parametrization {
    /// `t_i = i` (eqs. 22-27).
    #[default]
    Uniform,
    /// `t_{i+1} - t_i = sqrt(|f_{i+1} - f_i|)` (eq. 18).
    Centripetal,
}

impl Parametrization {
    /// Parses `"uniform"` or `"centripetal"`.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "uniform" => Ok(Self::Uniform),
            "centripetal" => Ok(Self::Centripetal),
            _ => Err(Error::Choice {
                what: "parametrization",
                got: name.to_owned(),
                expected: &["uniform", "centripetal"],
            }),
        }
    }
}

/// The spring weights `lambda` of approximating variational subdivision (section 4.2).
#[derive(Debug, Clone, PartialEq)]
pub struct Stiffness {
    /// `lambda_i` per input key, `>= 0`, `inf` = interpolate that key; `None`: all `inf`
    /// (the interpolating scheme of section 4.1).
    pub keys: Option<Vec<f64>>,
    /// `lambda` of the points inserted at earlier levels, `> 0`; `inf` keeps them.
    pub inserted: f64,
}

impl Default for Stiffness {
    fn default() -> Self {
        Self {
            keys: None,
            inserted: f64::INFINITY,
        }
    }
}

impl Stiffness {
    /// Every key interpolated (the scheme of section 4.1).
    pub fn interpolating() -> Self {
        Self::default()
    }

    /// Per-key springs, inserted points kept.
    pub fn keys(lambda: Vec<f64>) -> Self {
        Self {
            keys: Some(lambda),
            inserted: f64::INFINITY,
        }
    }

    /// The stiffness of key `i`.
    pub fn key(&self, i: usize) -> f64 {
        self.keys.as_ref().map_or(f64::INFINITY, |k| k[i])
    }

    /// Whether every key is kept exactly (all key springs infinite).
    pub fn keeps_keys(&self) -> bool {
        self.keys
            .as_ref()
            .is_none_or(|k| k.iter().all(|l| *l == f64::INFINITY))
    }

    /// Checks the weights for `n` keys.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] for a wrong number of key springs; [`Error::Value`] or
    /// [`Error::Count`]
    /// (`what = "stiffness"`) for a NaN or negative spring, a non-positive inserted spring,
    /// or too few positive springs to pin the curve (an open curve needs two, a closed one
    /// one: otherwise the fairness term alone leaves a straight line or a point free to
    /// slide).
    pub fn check(&self, n: usize, closed: bool) -> Result<()> {
        let in_range = |l: f64| l == f64::INFINITY || l <= MAX_STIFFNESS;
        if !(self.inserted > 0.0) || !in_range(self.inserted) {
            return Err(Error::Value {
                what: "stiffness",
                at: Some(At::new("inserted point", 0)),
                value: self.inserted,
                expected: Expected::PositiveUpToOrInfinite(MAX_STIFFNESS),
            });
        }
        if let Some(k) = &self.keys {
            if k.len() != n {
                return Err(Error::LengthMismatch {
                    what: "stiffness",
                    expected: n,
                    got: k.len(),
                });
            }
            if let Some(i) = k.iter().position(|l| !(*l >= 0.0) || !in_range(*l)) {
                return Err(Error::Value {
                    what: "stiffness",
                    at: Some(At::new("key", i)),
                    value: k[i],
                    expected: Expected::WithinOrInfinite {
                        low: 0.0,
                        high: MAX_STIFFNESS,
                    },
                });
            }
            let need = if closed { 1 } else { 2 };
            let positive = k.iter().filter(|l| **l > 0.0).count();
            if positive < need {
                return Err(Error::Count {
                    what: "stiffness: keys with a positive spring (to pin the curve)",
                    got: positive,
                    need,
                });
            }
        }
        Ok(())
    }
}

/// The largest finite spring `lambda` (`inf` keeps the key exactly): the systems add
/// `lambda v` with `|v|` up to a few times [`crate::motion::pose::MAX_COORDINATE`], so a
/// finite `lambda` up to `1e100` keeps them finite (`1e8` already pins a key to
/// `1e-8` of its neighbours' spacing).
pub const MAX_STIFFNESS: f64 = 1e100;

/// Smallest parameter spacing (relative to the mean) accepted by the centripetal
/// parametrisation: consecutive keys closer than this are reported as coincident.
pub const MIN_RELATIVE_SPACING: f64 = 1e-9;

/// The parameter spacings of the input spans (`n - 1` open, `n` closed, the last closing
/// the cycle), for several curves designed together (`curves[k][i]` is point `i` of curve
/// `k`; all curves have the same length).
///
/// Centripetal: `D_i = (sum_k |f^k_{i+1} - f^k_i|^2)^(1/4)` (eq. 18 in the stacked metric).
///
/// # Errors
/// [`Error::Degenerate`] (`what = "keys"`) when two consecutive keys coincide (a zero
/// centripetal spacing), within [`MIN_RELATIVE_SPACING`] of the mean.
pub fn spans_spacing(
    curves: &[Vec<DVec3>],
    closed: bool,
    parametrization: Parametrization,
) -> Result<Vec<f64>> {
    let n = curves.first().map_or(0, Vec::len);
    if let Some(bad) = curves.iter().find(|c| c.len() != n) {
        return Err(Error::LengthMismatch {
            what: "curves",
            expected: n,
            got: bad.len(),
        });
    }
    let spans = if closed { n } else { n.saturating_sub(1) };
    match parametrization {
        Parametrization::Uniform => Ok(vec![1.0; spans]),
        Parametrization::Centripetal => {
            let d: Vec<f64> = (0..spans)
                .map(|i| {
                    let j = (i + 1) % n;
                    // Differences scaled by 4^-k (exact, and the fourth root of the sum
                    // scales back by exactly 2^k) so the sum of squares cannot overflow.
                    let big = curves
                        .iter()
                        .map(|c| (c[j] - c[i]).abs().max_element())
                        .fold(0.0, f64::max);
                    let k = if big > 1.0 && big.is_finite() {
                        (big.log2() / 2.0).ceil() as i32
                    } else {
                        0
                    };
                    let scale = 4f64.powi(-k);
                    let sq: f64 = curves
                        .iter()
                        .map(|c| ((c[j] - c[i]) * scale).length_squared())
                        .sum();
                    sq.sqrt().sqrt() * 2f64.powi(k)
                })
                .collect();
            let mean = d.iter().sum::<f64>() / spans.max(1) as f64;
            if let Some(i) = d.iter().position(|x| !(*x > MIN_RELATIVE_SPACING * mean)) {
                return Err(Error::Degenerate {
                    what: "keys",
                    at: Some(At::new("key", i)),
                    reason: "coincides with the next key: the centripetal parametrisation needs \
                             distinct consecutive keys",
                });
            }
            Ok(d)
        }
    }
}

/// Checks the span spacings of `n` points (`n - 1` spans open, `n` closed): one per span,
/// each finite and positive.
///
/// # Errors
/// [`Error::LengthMismatch`] for a wrong number of spacings, [`Error::Value`] (at the span)
/// for a spacing that is not finite and positive.
fn check_spacing(spacing: &[f64], n: usize, closed: bool) -> Result<()> {
    let spans = if closed { n } else { n - 1 };
    if spacing.len() != spans {
        return Err(Error::LengthMismatch {
            what: "spacing",
            expected: spans,
            got: spacing.len(),
        });
    }
    if let Some(i) = spacing.iter().position(|d| !(*d > 0.0 && d.is_finite())) {
        return Err(Error::Value {
            what: "spacing",
            at: Some(At::new("span", i)),
            value: spacing[i],
            expected: Expected::Positive("spacing"),
        });
    }
    Ok(())
}

/// One level's linear system, shared by all curves designed together.
#[derive(Debug, Clone)]
pub struct VariationalLevel {
    n: usize,
    /// Unknown index of each refined point, `None` for kept (fixed) old points.
    unknown: Vec<Option<usize>>,
    /// `(indices into w, 2 c_2 coefficients)` of every fairness triple.
    stencils: Vec<([usize; 3], [f64; 3])>,
    /// Spring weight of each unknown (0 for new points).
    springs: Vec<f64>,
    factor: crate::numeric::cyclic_band::BandFactor,
}

impl VariationalLevel {
    /// Assembles and factorises the system refining `n` points with the given span spacings
    /// (`n - 1` open, `n` closed, any positive scale) and per-point springs (`inf` = kept).
    ///
    /// # Errors
    /// [`Error::TooFew`] for fewer than 2 points, [`Error::LengthMismatch`] for a wrong
    /// number of spacings or springs, [`Error::Value`] for a spacing that is not finite and
    /// positive, and [`Error::Degenerate`] (`what = "stiffness"`) when the system is not positive
    /// definite (too few springs to pin the curve, or a NaN spring).
    pub fn new(n: usize, closed: bool, spacing: &[f64], lambda: &[f64]) -> Result<Self> {
        if n < 2 {
            return Err(Error::TooFew { got: n, need: 2 });
        }
        check_spacing(spacing, n, closed)?;
        if lambda.len() != n {
            return Err(Error::LengthMismatch {
                what: "stiffness",
                expected: n,
                got: lambda.len(),
            });
        }
        let m = if closed { 2 * n } else { 2 * n - 1 };
        // Refined spacings: each span halved, then rescaled to mean 1.
        let mean = spacing.iter().sum::<f64>() / spacing.len() as f64;
        let h = |j: usize| spacing[(j / 2) % spacing.len()] / mean;
        let mut unknown = vec![None; m];
        let mut springs = Vec::with_capacity(m);
        for (j, u) in unknown.iter_mut().enumerate() {
            let spring = if j % 2 == 1 { 0.0 } else { lambda[j / 2] };
            if spring.is_finite() {
                *u = Some(springs.len());
                springs.push(spring);
            }
        }
        let unknowns = springs.len();
        let mut matrix = BandMatrix::zeros(unknowns, closed);
        let mut stencils = Vec::with_capacity(m);
        let inner = if closed { 0..m } else { 1..m - 1 };
        for j in inner {
            let (jm, jp) = ((j + m - 1) % m, (j + 1) % m);
            let (d0, d1) = (h(jm), h(j));
            // sqrt of the quadrature weight (D0 + D1) / 2 times 2 c_2 (eq. 19).
            let r = ((d0 + d1) / 2.0).sqrt();
            let c = [
                2.0 * r / (d0 * (d0 + d1)),
                -2.0 * r / (d0 * d1),
                2.0 * r / (d1 * (d0 + d1)),
            ];
            let idx = [jm, j, jp];
            for a in 0..3 {
                let Some(ua) = unknown[idx[a]] else { continue };
                for b in a..3 {
                    let Some(ub) = unknown[idx[b]] else { continue };
                    debug_assert!(a == b || ua != ub, "a triple repeats an unknown");
                    matrix.add(ua, ub, c[a] * c[b]);
                }
            }
            stencils.push((idx, c));
        }
        for (u, l) in springs.iter().enumerate() {
            if *l > 0.0 {
                matrix.add(u, u, *l);
            }
        }
        let factor = matrix.factor().map_err(|_| Error::Degenerate {
            what: "stiffness",
            at: None,
            reason: "the variational system is singular: too few keys are pinned",
        })?;
        Ok(Self {
            n,
            unknown,
            stencils,
            springs,
            factor,
        })
    }

    /// The right-hand side `g` of `H x = g` (`H = grad^2 F / 2`) for one curve `v`.
    fn rhs(&self, v: &[DVec3]) -> Vec<DVec3> {
        let mut g = vec![DVec3::ZERO; self.springs.len()];
        for (idx, c) in &self.stencils {
            let mut fixed = DVec3::ZERO;
            for a in 0..3 {
                if self.unknown[idx[a]].is_none() {
                    fixed += c[a] * v[idx[a] / 2];
                }
            }
            if fixed != DVec3::ZERO {
                for a in 0..3 {
                    if let Some(u) = self.unknown[idx[a]] {
                        g[u] -= c[a] * fixed;
                    }
                }
            }
        }
        for (j, u) in self.unknown.iter().enumerate() {
            if let Some(u) = u {
                if j % 2 == 0 && self.springs[*u] > 0.0 {
                    g[*u] += self.springs[*u] * v[j / 2];
                }
            }
        }
        g
    }

    /// Refines one curve `v` (`n` points) into `2n - 1` (open) or `2n` (closed) points.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `v` does not have the system's `n` points.
    pub fn refine(&self, v: &[DVec3]) -> Result<Vec<DVec3>> {
        self.check_len(v.len())?;
        let mut x = self.rhs(v);
        self.factor.solve(&mut x);
        Ok(self
            .unknown
            .iter()
            .enumerate()
            .map(|(j, u)| match u {
                Some(u) => x[*u],
                None => v[j / 2],
            })
            .collect())
    }

    fn check_len(&self, got: usize) -> Result<()> {
        if got != self.n {
            return Err(Error::LengthMismatch {
                what: "points",
                expected: self.n,
                got,
            });
        }
        Ok(())
    }

    /// The scaled residual of the level's linear system `H x = g` (`H = grad^2 F / 2`) at a
    /// refined curve `w` of `v`: `max_u |(H x - g)_u| / H_uu`, row `u` divided by its
    /// diagonal so that stiff springs (`lambda ~ 1e8`) do not inflate it.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `v` or `w` has the wrong number of points.
    pub fn residual(&self, v: &[DVec3], w: &[DVec3]) -> Result<f64> {
        self.check_len(v.len())?;
        if w.len() != self.unknown.len() {
            return Err(Error::LengthMismatch {
                what: "refined points",
                expected: self.unknown.len(),
                got: w.len(),
            });
        }
        let x: Vec<DVec3> = self
            .unknown
            .iter()
            .enumerate()
            .filter_map(|(j, u)| u.map(|_| w[j]))
            .collect();
        let g = self.rhs(v);
        let hx = self.matrix_mul(&x);
        let mut diag = self.springs.clone();
        for (idx, c) in &self.stencils {
            for a in 0..3 {
                if let Some(u) = self.unknown[idx[a]] {
                    diag[u] += c[a] * c[a];
                }
            }
        }
        Ok(hx
            .iter()
            .zip(&g)
            .zip(&diag)
            .map(|((a, b), d)| (*a - *b).abs().max_element() / d)
            .fold(0.0, f64::max))
    }

    fn matrix_mul(&self, x: &[DVec3]) -> Vec<DVec3> {
        // H x = sum over stencils of c_u (c . w_unknown) + springs, without the fixed parts.
        let mut out = vec![DVec3::ZERO; x.len()];
        for (idx, c) in &self.stencils {
            let mut r = DVec3::ZERO;
            for a in 0..3 {
                if let Some(u) = self.unknown[idx[a]] {
                    r += c[a] * x[u];
                }
            }
            for a in 0..3 {
                if let Some(u) = self.unknown[idx[a]] {
                    out[u] += c[a] * r;
                }
            }
        }
        for (u, l) in self.springs.iter().enumerate() {
            out[u] += *l * x[u];
        }
        out
    }
}

/// Variational subdivision of several curves designed together (same parameter spacings
/// and springs), `levels` times: `curves[k]` is the `k`-th sequence of homologous points.
///
/// `spacing` has one entry per input span ([`spans_spacing`]). Closed output: `n 2^levels`
/// points per curve, point `i 2^levels` descending from key `i`; open: `(n - 1) 2^levels + 1`.
///
/// # Errors
/// [`Error::TooFew`] / [`Error::Levels`] as [`crate::subdivide`], [`Error::LengthMismatch`]
/// for curves of different lengths or a wrong number of spacings, [`Error::Value`] for
/// non-positive spacings, and the errors of [`Stiffness::check`].
pub fn variational_subdivide(
    curves: &[Vec<DVec3>],
    spacing: &[f64],
    levels: u32,
    closed: bool,
    stiffness: &Stiffness,
) -> Result<Vec<Vec<DVec3>>> {
    let n = curves.first().map_or(0, Vec::len);
    check_subdivision(n, levels)?;
    if let Some(bad) = curves.iter().find(|c| c.len() != n) {
        return Err(Error::LengthMismatch {
            what: "curves",
            expected: n,
            got: bad.len(),
        });
    }
    check_spacing(spacing, n, closed)?;
    stiffness.check(n, closed)?;
    let mut current: Vec<Vec<DVec3>> = curves.to_vec();
    let mut spacing = spacing.to_vec();
    for level in 0..levels {
        let len = current[0].len();
        // Points descending from key i sit at multiples of 2^level.
        let stride = 1usize << level;
        let lambda: Vec<f64> = (0..len)
            .map(|j| {
                if j % stride == 0 {
                    stiffness.key(j / stride)
                } else {
                    stiffness.inserted
                }
            })
            .collect();
        let system = VariationalLevel::new(len, closed, &spacing, &lambda)?;
        for c in current.iter_mut() {
            *c = system.refine(c)?;
        }
        spacing = spacing.iter().flat_map(|d| [0.5 * d, 0.5 * d]).collect();
    }
    debug_assert_eq!(current[0].len(), subdivided_len(n, levels, closed));
    Ok(current)
}

/// Variational subdivision of one polygon (see [`variational_subdivide`]); the
/// parametrisation is computed from the polygon itself.
///
/// # Errors
/// As [`spans_spacing`] and [`variational_subdivide`].
pub fn variational_curve(
    points: &[DVec3],
    levels: u32,
    closed: bool,
    parametrization: Parametrization,
    stiffness: &Stiffness,
) -> Result<Vec<DVec3>> {
    check_subdivision(points.len(), levels)?;
    let curves = vec![points.to_vec()];
    let spacing = spans_spacing(&curves, closed, parametrization)?;
    Ok(variational_subdivide(&curves, &spacing, levels, closed, stiffness)?.remove(0))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn polygon(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|i| {
                let x = i as f64;
                DVec3::new(
                    x * 1.5 + (x * 1.9).sin(),
                    (x * 0.8).cos() * 2.0,
                    (x * 0.5).sin(),
                )
            })
            .collect()
    }

    /// The paper's eq. 23 (open) or eq. 24 (closed) residual `|A q - B f|` for one level.
    fn paper_interpolating_residual(f: &[DVec3], w: &[DVec3], closed: bool) -> f64 {
        let n = f.len();
        let q: Vec<DVec3> = (0..if closed { n } else { n - 1 })
            .map(|i| w[2 * i + 1])
            .collect();
        let nq = q.len();
        let mut worst: f64 = 0.0;
        for i in 0..nq {
            let (aq, bf) = if closed {
                (
                    6.0 * q[i] + q[(i + nq - 1) % nq] + q[(i + 1) % nq],
                    4.0 * f[i] + 4.0 * f[(i + 1) % n],
                )
            } else if nq == 1 {
                (4.0 * q[0], 2.0 * f[0] + 2.0 * f[1])
            } else if i == 0 {
                (5.0 * q[0] + q[1], 2.0 * f[0] + 4.0 * f[1])
            } else if i == nq - 1 {
                (q[i - 1] + 5.0 * q[i], 4.0 * f[i] + 2.0 * f[i + 1])
            } else {
                (
                    q[i - 1] + 6.0 * q[i] + q[i + 1],
                    4.0 * f[i] + 4.0 * f[i + 1],
                )
            };
            worst = worst.max((aq - bf).abs().max_element());
        }
        worst
    }

    /// The paper's eqs. 26-27 residual `|A^a x - b|`, `x = (q, f^n)`, for one open level.
    fn paper_approximating_residual(f: &[DVec3], w: &[DVec3], lambda: &[f64]) -> f64 {
        let n = f.len();
        let q: Vec<DVec3> = (0..n - 1).map(|i| w[2 * i + 1]).collect();
        let fnew: Vec<DVec3> = (0..n).map(|i| w[2 * i]).collect();
        let mut worst: f64 = 0.0;
        // Rows of [A | -B] x = 0 (eq. 23's A and B).
        for i in 0..n - 1 {
            let aq = if n - 1 == 1 {
                4.0 * q[0]
            } else if i == 0 {
                5.0 * q[0] + q[1]
            } else if i == n - 2 {
                q[i - 1] + 5.0 * q[i]
            } else {
                q[i - 1] + 6.0 * q[i] + q[i + 1]
            };
            let (b0, b1) = (
                if i == 0 { 2.0 } else { 4.0 },
                if i == n - 2 { 2.0 } else { 4.0 },
            );
            let bf = b0 * fnew[i] + b1 * fnew[i + 1];
            worst = worst.max((aq - bf).abs().max_element());
        }
        // Rows of [-B^T | L] x = lambda f (eq. 27).
        for i in 0..n {
            let mut bt_q = DVec3::ZERO;
            if i > 0 {
                bt_q += (if i - 1 == n - 2 { 2.0 } else { 4.0 }) * q[i - 1];
            }
            if i < n - 1 {
                bt_q += (if i == 0 { 2.0 } else { 4.0 }) * q[i];
            }
            let diag = if i == 0 || i == n - 1 { 1.0 } else { 6.0 } + lambda[i];
            let mut lf = diag * fnew[i];
            if i > 0 {
                lf += fnew[i - 1];
            }
            if i < n - 1 {
                lf += fnew[i + 1];
            }
            let r = lf - bt_q - lambda[i] * f[i];
            worst = worst.max(r.abs().max_element() / (1.0 + lambda[i]));
        }
        worst
    }

    #[test]
    fn interpolating_keeps_points_and_solves_eqs_23_24() {
        for closed in [false, true] {
            for n in 2..9 {
                let f = polygon(n);
                let w = variational_curve(
                    &f,
                    1,
                    closed,
                    Parametrization::Uniform,
                    &Stiffness::default(),
                )
                .unwrap();
                let r = paper_interpolating_residual(&f, &w, closed);
                assert!(r < 1e-10, "closed {closed} n {n}: residual {r:e}");
                let fine = variational_curve(
                    &f,
                    5,
                    closed,
                    Parametrization::Uniform,
                    &Stiffness::default(),
                )
                .unwrap();
                for (i, p) in f.iter().enumerate() {
                    assert_eq!(fine[i << 5], *p, "key {i} moved");
                }
            }
        }
    }

    #[test]
    fn approximating_solves_eqs_26_27() {
        let f = polygon(7);
        let lambda = vec![1e8, 0.3, 2.0, 0.01, 5.0, 1.0, 1e8];
        let s = Stiffness::keys(lambda.clone());
        let w = variational_curve(&f, 1, false, Parametrization::Uniform, &s).unwrap();
        let r = paper_approximating_residual(&f, &w, &lambda);
        assert!(r < 1e-10, "residual {r:e}");
        // Approximated keys move, the stiff ones barely.
        assert!(w[2].distance(f[1]) > 1e-3);
        assert!(w[0].distance(f[0]) < 1e-6);
    }

    #[test]
    fn residual_of_every_variant_is_zero() {
        // Non-uniform, closed and approximating systems: the solution zeroes grad F,
        // checked against the assembled matrix and, independently, by central differences of
        // the energy F (exact for a quadratic up to rounding).
        let f = polygon(6);
        for closed in [false, true] {
            for param in [Parametrization::Uniform, Parametrization::Centripetal] {
                for lambda in [vec![f64::INFINITY; 6], vec![1e8, 0.5, 2.0, 0.01, 3.0, 1e8]] {
                    let curves = vec![f.clone()];
                    let spacing = spans_spacing(&curves, closed, param).unwrap();
                    let sys = VariationalLevel::new(6, closed, &spacing, &lambda).unwrap();
                    let w = sys.refine(&f).unwrap();
                    let r = sys.residual(&f, &w).unwrap();
                    assert!(r < 1e-10, "{closed} {param:?}: residual {r:e}");
                    let energy = |w: &[DVec3]| -> f64 {
                        let fair: f64 = sys
                            .stencils
                            .iter()
                            .map(|(i, c)| {
                                (c[0] * w[i[0]] + c[1] * w[i[1]] + c[2] * w[i[2]]).length_squared()
                            })
                            .sum();
                        let spring: f64 = (0..6)
                            .filter(|i| lambda[*i].is_finite())
                            .map(|i| lambda[i] * (w[2 * i] - f[i]).length_squared())
                            .sum();
                        fair + spring
                    };
                    for j in 0..w.len() {
                        if j % 2 == 0 && !lambda[j / 2].is_finite() {
                            continue;
                        }
                        for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                            let h = 1e-4;
                            let mut a = w.clone();
                            let mut b = w.clone();
                            a[j] += h * axis;
                            b[j] -= h * axis;
                            let scale = 1.0 + if j % 2 == 0 { lambda[j / 2] } else { 0.0 };
                            let g = (energy(&a) - energy(&b)) / (2.0 * h) / scale;
                            assert!(g.abs() < 1e-6, "{closed} {param:?} w{j}: dF = {g:e}");
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn stiffness_limits() {
        let f = polygon(6);
        let ends = |small: f64| {
            let mut l = vec![small; 6];
            l[0] = f64::INFINITY;
            l[5] = f64::INFINITY;
            l
        };
        // lambda -> 0 at interior keys: the straight line through the first and last key.
        let mut last_dev = f64::INFINITY;
        for small in [1e-2, 1e-4, 1e-6, 1e-8] {
            let w = variational_curve(
                &f,
                4,
                false,
                Parametrization::Uniform,
                &Stiffness::keys(ends(small)),
            )
            .unwrap();
            let dir = (f[5] - f[0]).normalize();
            let dev = w
                .iter()
                .map(|p| {
                    let d = *p - f[0];
                    (d - d.dot(dir) * dir).length()
                })
                .fold(0.0, f64::max);
            assert!(
                dev < last_dev,
                "deviation {dev:e} did not shrink at lambda {small:e}"
            );
            last_dev = dev;
        }
        assert!(last_dev < 1e-6, "deviation from the line {last_dev:e}");
        // lambda -> inf: the interpolating result.
        let interp = variational_curve(
            &f,
            4,
            false,
            Parametrization::Uniform,
            &Stiffness::default(),
        )
        .unwrap();
        let mut last = f64::INFINITY;
        for big in [1e2, 1e4, 1e6, 1e8] {
            let w = variational_curve(
                &f,
                4,
                false,
                Parametrization::Uniform,
                &Stiffness::keys(vec![big; 6]),
            )
            .unwrap();
            let d = w
                .iter()
                .zip(&interp)
                .map(|(a, b)| a.distance(*b))
                .fold(0.0, f64::max);
            assert!(d < last, "no convergence at {big:e}: {d:e}");
            last = d;
        }
        assert!(last < 1e-6, "lambda = 1e8 vs interpolating: {last:e}");
        let w = variational_curve(
            &f,
            4,
            false,
            Parametrization::Uniform,
            &Stiffness::keys(vec![f64::INFINITY; 6]),
        )
        .unwrap();
        assert_eq!(w, interp);
    }

    /// The second divided differences `2 c_2` (eq. 19) of the level-`level` polygon, with
    /// the parameter spacing of the input spans `spacing` (split in `2^level` equal steps):
    /// estimates of the second derivative, which converge for a C2 scheme.
    fn second_difference(w: &[DVec3], spacing: &[f64], level: u32, closed: bool) -> Vec<DVec3> {
        let m = w.len();
        let mean = spacing.iter().sum::<f64>() / spacing.len() as f64;
        let h = |j: usize| spacing[(j >> level) % spacing.len()] / mean / f64::from(1u32 << level);
        let range = if closed { 0..m } else { 1..m - 1 };
        range
            .map(|j| {
                let (d0, d1) = (h((j + m - 1) % m), h(j));
                2.0 * (w[(j + m - 1) % m] / (d0 * (d0 + d1)) - w[j] / (d0 * d1)
                    + w[(j + 1) % m] / (d1 * (d0 + d1)))
            })
            .collect()
    }

    #[test]
    fn second_differences_converge_c2() {
        // Fig. 9 style: the scaled second differences approximate the curve's second
        // derivative; they stay bounded and successive levels agree better and better at the
        // common parameters (C2). The C1 four-point scheme, for contrast, does not converge.
        let f = polygon(6);
        for closed in [false, true] {
            for param in [Parametrization::Uniform, Parametrization::Centripetal] {
                let spacing = spans_spacing(std::slice::from_ref(&f), closed, param).unwrap();
                let mut prev: Option<Vec<DVec3>> = None;
                let mut changes = Vec::new();
                for level in 3..=9 {
                    let w =
                        variational_curve(&f, level, closed, param, &Stiffness::default()).unwrap();
                    let d2 = second_difference(&w, &spacing, level, closed);
                    let bound = d2.iter().map(|v| v.length()).fold(0.0, f64::max);
                    assert!(bound < 100.0, "{closed} {param:?} level {level}: {bound}");
                    if let Some(p) = &prev {
                        // Level l point j sits where level l+1 point 2j does.
                        let off = usize::from(!closed);
                        let change = p
                            .iter()
                            .enumerate()
                            .map(|(j, v)| v.distance(d2[2 * (j + off) - off]))
                            .fold(0.0, f64::max);
                        changes.push(change);
                    }
                    prev = Some(d2);
                }
                for pair in changes.windows(2) {
                    assert!(
                        pair[1] < 0.75 * pair[0],
                        "{closed} {param:?}: changes {changes:?}"
                    );
                }
            }
        }
        // Contrast: the C1 four-point scheme's second differences do not settle (its
        // level-over-level changes stay of the same size).
        let mut prev: Option<Vec<DVec3>> = None;
        let mut changes = Vec::new();
        for level in 3..=9 {
            let w = crate::subdivide(&f, crate::Scheme::FourPoint, level, true).unwrap();
            let d2 = second_difference(&w, &[1.0], level, true);
            if let Some(p) = &prev {
                changes.push(
                    p.iter()
                        .enumerate()
                        .map(|(j, v)| v.distance(d2[2 * j]))
                        .fold(0.0, f64::max),
                );
            }
            prev = Some(d2);
        }
        for pair in changes.windows(2) {
            assert!(pair[1] > 0.75 * pair[0], "four-point changes {changes:?}");
        }
    }

    #[test]
    fn approximating_is_c2_too() {
        let f = polygon(7);
        let s = Stiffness::keys(vec![
            f64::INFINITY,
            0.5,
            0.2,
            f64::INFINITY,
            1.0,
            0.3,
            f64::INFINITY,
        ]);
        let mut prev: Option<Vec<DVec3>> = None;
        let mut changes = Vec::new();
        for level in 3..=9 {
            let w = variational_curve(&f, level, false, Parametrization::Uniform, &s).unwrap();
            let d2 = second_difference(&w, &[1.0], level, false);
            if let Some(p) = &prev {
                changes.push(
                    p.iter()
                        .enumerate()
                        .map(|(j, v)| v.distance(d2[2 * j + 1]))
                        .fold(0.0, f64::max),
                );
            }
            prev = Some(d2);
        }
        for pair in changes.windows(2) {
            assert!(pair[1] < 0.75 * pair[0], "changes {changes:?}");
        }
    }

    #[test]
    fn errors() {
        let f = polygon(4);
        let p = Parametrization::Uniform;
        assert!(matches!(
            variational_curve(&f, 2, false, p, &Stiffness::keys(vec![1.0; 3])),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(matches!(
            variational_curve(&f, 2, false, p, &Stiffness::keys(vec![0.0, 0.0, 0.0, 1.0])),
            Err(Error::Count {
                got: 1,
                need: 2,
                ..
            })
        ));
        assert!(matches!(
            variational_curve(
                &f,
                2,
                false,
                p,
                &Stiffness::keys(vec![1.0, f64::NAN, 0.0, 1.0])
            ),
            Err(Error::Value {
                what: "stiffness",
                at: Some(At { index: 1, .. }),
                ..
            })
        ));
        let dup = vec![f[0], f[1], f[1], f[2]];
        assert!(matches!(
            variational_curve(
                &dup,
                2,
                false,
                Parametrization::Centripetal,
                &Stiffness::default()
            ),
            Err(Error::Degenerate {
                what: "keys",
                at: Some(At { index: 1, .. }),
                ..
            })
        ));
        // Closed: one spring pins the cycle; zero springs elsewhere are fine.
        assert!(
            variational_curve(&f, 2, true, p, &Stiffness::keys(vec![0.0, 1.0, 0.0, 0.0])).is_ok()
        );
    }
}
