//! The linear smoothing spline on samples of `R^3` (Whittaker's graduation, Reinsch's
//! spline, on uneven times): the translation of the pivot point, and the linear model of the
//! rotation that chooses its strength.
//!
//! ```text
//! minimise  sum_i h_i |x_i - y_i|^2 + lambda sum_k u_k |D_k x|^2
//! (H + lambda D^T U D) x = H y            (band of half-width m)
//! ```
//!
//! with `D` the rows of [`super::stencil`], `u_k` in `[0, 1]` the row weights (0 where a kink
//! is let through) and `lambda = tau^(2m)`. The strength is chosen by generalised
//! cross-validation (Craven and Wahba, "Smoothing noisy data with spline functions", 1979):
//!
//! ```text
//! A = (H + lambda M)^-1 H,   GCV(lambda) = (RSS / sum h) / (1 - tr(A) / n)^2
//! RSS = sum_i h_i |x_i - y_i|^2,   tr(A) = sum_i h_i [(H + lambda M)^-1]_ii
//! ```
//!
//! the trace from the band of the inverse ([`crate::numeric::band`]), so each evaluation is `O(n)`.
//! The strengths tried lie on a fixed log-spaced grid, and the factorised systems of the
//! grid strengths are kept (the matrix depends on the times and the strength only, not on
//! the data), so the rotation, the translation and the next clip at the same times solve
//! with them again instead of factorising anew.

// Index loops mirror the band algorithms (several arrays indexed together).
#![allow(clippy::needless_range_loop)]

use glam::DVec3;

use super::stencil::Stencils;
use crate::numeric::band::Band;

/// The fit at one strength: its GCV score, residual and effective degrees of freedom.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Gcv {
    /// `tau`, the strength (a time).
    pub(crate) tau: f64,
    /// The GCV score.
    pub(crate) score: f64,
    /// `sum_i h_i |x_i - y_i|^2`.
    pub(crate) rss: f64,
    /// `tr(A)`, the effective number of parameters (per component).
    pub(crate) trace: f64,
}

/// Spacings that differ by less than this fraction count as even.
const EVEN_SPACING: f64 = 1e-9;
/// The diagonal of the inverse is computed this many strengths from an end...
const TRACE_SPAN: f64 = 12.0;
/// ... plus this many rows; beyond, it is constant to within about `exp(-7)` of its size.
const TRACE_ROWS: usize = 24;
/// The strength grid's ratio between neighbours (`2^(1/6)`: 12 per cent).
const GRID_RATIO: f64 = 1.122_462_048_309_373;
/// Strengths of the search's first, coarse pass over the whole range.
const SEARCH_COARSE: usize = 6;
/// A search from a guess starts at the guess and this many grid steps to either side.
const SEARCH_LOCAL: usize = 4;
/// The most kept factorisations...
const CACHE_ENTRIES: usize = 96;
/// ... and the most values they may hold together (about 32 MB).
const CACHE_VALUES: usize = 1 << 22;

/// A factorised `H + lambda M` at one grid strength, with its trace `tr(A)`.
#[derive(Debug, Clone, Default)]
struct Factored<const W: usize> {
    index: usize,
    band: Band<f64, W>,
    trace: f64,
}

/// Scratch and results of the linear smoother of order `W` (2 or 3), reused between calls.
/// [`Whittaker::prepare`] sets the problem (stencils, row weights, data, the strengths'
/// range); the other methods solve it at given strengths.
#[derive(Debug, Clone, Default)]
pub(crate) struct Whittaker<const W: usize> {
    /// The penalty `D^T U D` (for `lambda = 1`).
    m: Band<f64, W>,
    /// What `m` and the cache were built from: rows, data weights, row weights, range.
    rows: Vec<[f64; 4]>,
    h: Vec<f64>,
    u: Vec<f64>,
    range: (f64, f64),
    /// Whether the problem reads the same backwards (even spacing, row weights symmetric):
    /// then the diagonal of the inverse is computed near one end only.
    symmetric: bool,
    /// The data and `M y`.
    y: Vec<DVec3>,
    my: Vec<DVec3>,
    cache: Vec<Factored<W>>,
    band: Band<f64, W>,
    zinv: Vec<[f64; 4]>,
    diag: Vec<f64>,
    /// The last correction `y - x`.
    pub(crate) z: Vec<DVec3>,
    /// The last fit.
    pub(crate) x: Vec<DVec3>,
    /// The fit of the best strength the last [`Whittaker::search`] evaluated.
    pub(crate) best: Vec<DVec3>,
}

impl<const W: usize> Whittaker<W> {
    /// Sets the problem: the penalty of stencils `st` (of order `W`) with row weights `u`,
    /// the data `y`, and the range `(lo, hi)` of strengths searched. Kept factorisations
    /// stay valid while the stencils, row weights and range are the same.
    pub(crate) fn prepare(&mut self, st: &Stencils, u: &[f64], y: &[DVec3], range: (f64, f64)) {
        debug_assert_eq!(st.order, W);
        let same =
            self.rows == st.rows && self.h == st.weights && self.u == u && self.range == range;
        if !same {
            self.rows.clone_from(&st.rows);
            self.h.clone_from(&st.weights);
            self.u.clear();
            self.u.extend_from_slice(u);
            self.range = range;
            self.cache.clear();
            let n = st.weights.len();
            self.m.reset(n);
            for (k, row) in st.rows.iter().enumerate() {
                let c = u[k];
                if c == 0.0 {
                    continue;
                }
                for a in 0..=W {
                    let ca = c * row[a];
                    self.m.add_diag(k + a, ca * row[a]);
                    for b in 0..a {
                        self.m.add_off(k + a, k + b, ca * row[b]);
                    }
                }
            }
            let h0 = self.h[0];
            let even = self.h.iter().all(|h| (h - h0).abs() <= EVEN_SPACING * h0);
            let k = u.len();
            self.symmetric = even && (0..k / 2).all(|i| u[i] == u[k - 1 - i]);
        }
        self.set_data(y);
    }

    /// Replaces the data, keeping the penalty.
    ///
    /// `M y` is formed as `D^T (U (D y))`, by the stencils, not by the assembled band: the
    /// rounding of `D y` (relative to `|y|`) then has no low frequencies left after `D^T`,
    /// where [`Whittaker::smooth`]'s `lambda (H + lambda M)^-1` would multiply it by up to
    /// `lambda` (measured: a change of body frame moved a path by 5e-10 that way, by 1e-12
    /// this way).
    pub(crate) fn set_data(&mut self, y: &[DVec3]) {
        self.y.clear();
        self.y.extend_from_slice(y);
        self.my.clear();
        self.my.resize(y.len(), DVec3::ZERO);
        for (k, row) in self.rows.iter().enumerate() {
            let c = self.u[k];
            if c == 0.0 {
                continue;
            }
            let mut dy = DVec3::ZERO;
            for a in 0..=W {
                dy += y[k + a] * row[a];
            }
            let dy = dy * c;
            for a in 0..=W {
                self.my[k + a] += dy * row[a];
            }
        }
    }

    /// The number of grid strengths in the range.
    fn grid_len(&self) -> usize {
        let (lo, hi) = self.range;
        ((hi / lo).ln() / GRID_RATIO.ln()).floor().max(0.0) as usize + 1
    }

    /// Grid strength `k`.
    fn grid(&self, k: usize) -> f64 {
        self.range.0 * GRID_RATIO.powi(k as i32)
    }

    /// `H + lambda M` into `self.band`.
    fn assemble(&mut self, lambda: f64) {
        self.band.scaled_from(&self.m, lambda);
        for (i, h) in self.h.iter().enumerate() {
            self.band.add_diag(i, *h);
        }
    }

    /// `tr(A)` of the factorised `self.band` at strength `tau`.
    fn trace(&mut self, tau: f64) -> f64 {
        let n = self.h.len();
        self.diag.resize(n, 0.0);
        // On an even, symmetric problem the diagonal of the inverse is the same at both ends
        // and constant in between (to within exp(-7) once TRACE_SPAN strengths from an end):
        // only the last rows are computed.
        let edge = (TRACE_SPAN * tau / self.h[0]).ceil() as usize + TRACE_ROWS;
        if self.symmetric && 2 * edge < n {
            self.band
                .inverse_diagonal_tail(edge + 1, &mut self.zinv, &mut self.diag);
            let tail: f64 = self.diag[n - edge..].iter().sum();
            self.h[0] * (2.0 * tail + (n - 2 * edge) as f64 * self.diag[n - edge - 1])
        } else {
            self.band.inverse_diagonal(&mut self.zinv, &mut self.diag);
            self.h.iter().zip(&self.diag).map(|(h, z)| h * z).sum()
        }
    }

    /// Solves for the fit at `lambda`, with the samples flagged in `held` kept exactly.
    ///
    /// It solves for the correction `z = y - x`, `(H + lambda M) z = lambda M y`, rather than
    /// for `x`: the system is ill-conditioned for large `lambda` exactly where `M y` is
    /// small (data close to a polynomial of degree below `m`), so the correction stays
    /// accurate, and samples that need no correction get none. A held sample has `z_i = 0`.
    /// Returns false on overflow.
    pub(crate) fn smooth(&mut self, lambda: f64, held: Option<&[bool]>) -> bool {
        self.assemble(lambda);
        self.z.clear();
        self.z.extend(self.my.iter().map(|v| *v * lambda));
        if let Some(held) = held {
            for (i, h) in held.iter().enumerate() {
                if *h {
                    self.band.pin(i);
                    self.z[i] = DVec3::ZERO;
                }
            }
        }
        if !self.band.factor() {
            return false;
        }
        self.band.solve(&mut self.z);
        self.finish()
    }

    /// `x = y - z`; false if not finite.
    fn finish(&mut self) -> bool {
        self.x.clear();
        self.x
            .extend(self.y.iter().zip(&self.z).map(|(v, z)| *v - *z));
        self.z.iter().all(|v| v.is_finite())
    }

    /// The factorised system of grid strength `k` (kept, or made and kept), as an index
    /// into the cache; None on overflow.
    fn system(&mut self, k: usize) -> Option<usize> {
        if let Some(i) = self.cache.iter().position(|f| f.index == k) {
            return Some(i);
        }
        let tau = self.grid(k);
        self.assemble(tau.powi(2 * W as i32));
        if !self.band.factor() {
            return None;
        }
        let trace = self.trace(tau);
        let n = self.h.len();
        let cap = CACHE_ENTRIES
            .min(CACHE_VALUES / (n * (W + 1)).max(1))
            .max(1);
        if self.cache.len() >= cap {
            self.cache.remove(0);
        }
        let band = std::mem::take(&mut self.band);
        self.cache.push(Factored {
            index: k,
            band,
            trace,
        });
        Some(self.cache.len() - 1)
    }

    /// The corrections `z(v) = v - x(v)` of several inputs at grid strength `k` (no held
    /// samples): `out[j]` receives `z(inputs[j])`. False on overflow.
    ///
    /// Unlike [`Whittaker::smooth`] this solves for the fit, `x = (H + lambda M)^-1 H v`:
    /// `lambda M v` would carry the rounding of `M v` (relative to `|v|`) times `lambda`
    /// into `z` at low frequencies, while `x` is accurate relative to `|v|` there. The
    /// pivot's refinement needs that: its equations must change with the body frame
    /// exactly as the pivot does.
    pub(crate) fn corrections(
        &mut self,
        k: usize,
        inputs: &[&[DVec3]],
        out: &mut [Vec<DVec3>],
    ) -> bool {
        let Some(i) = self.system(k) else {
            return false;
        };
        for (v, z) in inputs.iter().zip(out.iter_mut()) {
            z.clear();
            z.extend(v.iter().zip(&self.h).map(|(p, h)| *p * *h));
            self.cache[i].band.solve(z);
            for (z, p) in z.iter_mut().zip(v.iter()) {
                *z = *p - *z;
            }
            if !z.iter().all(|p| p.is_finite()) {
                return false;
            }
        }
        true
    }

    /// The GCV statistics of the current `z`, with trace `trace` (the score infinite when
    /// the fit leaves no degree of freedom); None if they overflow.
    fn score(&self, tau: f64, trace: f64) -> Option<Gcv> {
        let n = self.y.len();
        let (mut rss, mut hsum) = (0.0, 0.0);
        for i in 0..n {
            let h = self.h[i];
            rss += h * self.z[i].length_squared();
            hsum += h;
        }
        if !(rss.is_finite() && trace.is_finite()) {
            return None;
        }
        // At a tiny strength the fit is the data (tr(A) = n to rounding): GCV cannot rank
        // it (an infinite score), but the fit itself is fine.
        let free = 1.0 - trace / n as f64;
        let score = if free > 0.0 {
            (rss / hsum) / (free * free)
        } else {
            f64::INFINITY
        };
        (!score.is_nan()).then_some(Gcv {
            tau,
            score,
            rss,
            trace,
        })
    }

    /// GCV at grid strength `k` (the correction in `z`; the fit is not formed). None on
    /// overflow.
    pub(crate) fn gcv_grid(&mut self, k: usize) -> Option<Gcv> {
        let tau = self.grid(k);
        let lambda = tau.powi(2 * W as i32);
        let i = self.system(k)?;
        self.z.clear();
        self.z.extend(self.my.iter().map(|v| *v * lambda));
        self.cache[i].band.solve(&mut self.z);
        if !self.z.iter().all(|v| v.is_finite()) {
            return None;
        }
        let trace = self.cache[i].trace;
        self.score(tau, trace)
    }

    /// GCV at any strength `tau` (the fit in `x`). None on overflow.
    pub(crate) fn gcv(&mut self, tau: f64) -> Option<Gcv> {
        if !self.smooth(tau.powi(2 * W as i32), None) {
            return None;
        }
        let trace = self.trace(tau);
        self.score(tau, trace)
    }

    /// The grid index of the grid strength nearest `tau`.
    pub(crate) fn grid_index(&self, tau: f64) -> usize {
        let k = ((tau / self.range.0).ln() / GRID_RATIO.ln()).round();
        (k.max(0.0) as usize).min(self.grid_len() - 1)
    }

    /// The grid strength of least GCV: the best of [`SEARCH_COARSE`] grid strengths spread
    /// over the range (or, from a `guess`, of three [`SEARCH_LOCAL`] steps apart around it,
    /// moving downhill while the best is at an end), then golden-section search on the grid
    /// between the best one's neighbours. GCV is smooth and flat near its minimum: the grid's
    /// 12 per cent change the fit by less. The fit at the best strength is kept in `best`.
    /// Returns the best strength's statistics and grid index; None when every evaluation
    /// overflows.
    pub(crate) fn search(&mut self, guess: Option<f64>) -> Option<(Gcv, usize)> {
        let last = self.grid_len() - 1;
        let mut seen: Vec<(usize, f64)> = Vec::with_capacity(24);
        let mut best: Option<(Gcv, usize)> = None;
        let mut eval = |wh: &mut Self, k: usize| -> f64 {
            if let Some((_, s)) = seen.iter().find(|(j, _)| *j == k) {
                return *s;
            }
            let s = match wh.gcv_grid(k) {
                Some(g) => {
                    if best.is_none_or(|(b, _)| g.score < b.score) {
                        best = Some((g, k));
                        wh.best.clear();
                        wh.best.extend(wh.y.iter().zip(&wh.z).map(|(y, z)| *y - *z));
                    }
                    g.score
                }
                None => f64::INFINITY,
            };
            seen.push((k, s));
            s
        };
        let (mut lo, mut hi);
        match guess {
            None => {
                let mut pts: Vec<(usize, f64)> = Vec::with_capacity(SEARCH_COARSE);
                for g in 0..SEARCH_COARSE {
                    let k = (g * last + (SEARCH_COARSE - 1) / 2) / (SEARCH_COARSE - 1);
                    pts.push((k, eval(self, k)));
                }
                pts.dedup_by_key(|p| p.0);
                let b = (0..pts.len()).min_by(|i, j| pts[*i].1.total_cmp(&pts[*j].1))?;
                lo = pts[b.saturating_sub(1)].0;
                hi = pts[(b + 1).min(pts.len() - 1)].0;
            }
            Some(t) => {
                let k0 = self.grid_index(t);
                let mut mid = k0;
                let (mut fl, mut fm, mut fh);
                fm = eval(self, mid);
                lo = mid.saturating_sub(SEARCH_LOCAL);
                hi = (mid + SEARCH_LOCAL).min(last);
                fl = eval(self, lo);
                fh = eval(self, hi);
                // Walk downhill until the middle is lowest (or an end of the range).
                loop {
                    if fl < fm && lo > 0 {
                        (hi, fh, mid, fm) = (mid, fm, lo, fl);
                        lo = mid.saturating_sub(SEARCH_LOCAL);
                        fl = eval(self, lo);
                    } else if fh < fm && hi < last {
                        (lo, fl, mid, fm) = (mid, fm, hi, fh);
                        hi = (mid + SEARCH_LOCAL).min(last);
                        fh = eval(self, hi);
                    } else {
                        break;
                    }
                }
                let _ = (fl, fh);
            }
        }
        // Golden-section search on the grid indices in [lo, hi].
        while hi - lo > 2 {
            let c = lo + ((hi - lo) as f64 * 0.381_966_011_250_105_1).round() as usize;
            let d = (lo + ((hi - lo) as f64 * 0.618_033_988_749_894_8).round() as usize).max(c + 1);
            if eval(self, c) < eval(self, d) {
                hi = d;
            } else {
                lo = c;
            }
        }
        if hi - lo == 2 {
            eval(self, lo + 1);
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Deterministic noise in [-1, 1] (a xorshift generator).
    pub(crate) fn noise(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn data(n: usize) -> (Vec<f64>, Vec<DVec3>, Vec<DVec3>) {
        let times: Vec<f64> = (0..n)
            .map(|i| i as f64 + 0.2 * (i as f64 * 2.1).sin())
            .collect();
        let truth: Vec<DVec3> = times
            .iter()
            .map(|t| DVec3::new((t * 0.1).sin(), (t * 0.07).cos(), 0.01 * t))
            .collect();
        // Deterministic "noise".
        let mut state = 0x9E37_79B9_7F4A_7C15;
        let y = truth
            .iter()
            .map(|v| {
                let mut f = || noise(&mut state) * 0.05;
                *v + DVec3::new(f(), f(), f())
            })
            .collect();
        (times, truth, y)
    }

    /// The fit equals the dense solution of the normal equations, holds are kept, and the
    /// trace equals the dense hat matrix's.
    #[test]
    fn matches_the_dense_normal_equations() {
        let (times, _, y) = data(30);
        for order in [2usize, 3] {
            let st = Stencils::new(&times, order).unwrap();
            let n = times.len();
            let u: Vec<f64> = (0..st.len())
                .map(|k| if k == 11 { 0.0 } else { 1.0 })
                .collect();
            let lambda = 7.5;
            let mut h = nalgebra::DMatrix::<f64>::zeros(n, n);
            let mut m = nalgebra::DMatrix::<f64>::zeros(n, n);
            for i in 0..n {
                h[(i, i)] = st.weights[i];
            }
            for (k, row) in st.rows.iter().enumerate() {
                for a in 0..=order {
                    for b in 0..=order {
                        m[(k + a, k + b)] += u[k] * row[a] * row[b];
                    }
                }
            }
            let k = &h + &m * lambda;
            let hat = k.clone().try_inverse().unwrap() * &h;
            let mut held = vec![false; n];
            held[0] = true;
            held[17] = true;
            let (fit, trace, kept) = if order == 2 {
                let mut w = Whittaker::<2>::default();
                w.prepare(&st, &u, &y, (0.25, 200.0));
                let g = w.gcv(lambda.powf(1.0 / 4.0)).unwrap();
                let fit = w.x.clone();
                assert!(w.smooth(lambda, Some(&held)));
                (fit, g.trace, w.x.clone())
            } else {
                let mut w = Whittaker::<3>::default();
                w.prepare(&st, &u, &y, (0.25, 200.0));
                let g = w.gcv(lambda.powf(1.0 / 6.0)).unwrap();
                let fit = w.x.clone();
                assert!(w.smooth(lambda, Some(&held)));
                (fit, g.trace, w.x.clone())
            };
            assert!(
                (trace - hat.trace()).abs() < 1e-9,
                "order {order}: {trace} vs {}",
                hat.trace()
            );
            for c in 0..3 {
                let yc = nalgebra::DVector::from_iterator(n, y.iter().map(|v| v[c]));
                let want = &hat * yc;
                for i in 0..n {
                    assert!((fit[i][c] - want[i]).abs() < 1e-10, "order {order} {i} {c}");
                }
            }
            // Held samples are kept exactly.
            assert_eq!(kept[0], y[0]);
            assert_eq!(kept[17], y[17]);
            assert!((kept[5] - fit[5]).length() > 0.0);
        }
    }

    /// The trace from the ends of an even problem equals the full recurrence's.
    #[test]
    fn the_trace_shortcut_matches_the_full_trace() {
        let n = 400;
        let times: Vec<f64> = (0..n).map(|i| 0.5 * i as f64).collect();
        let (_, _, y) = data(n);
        let st = Stencils::new(&times, 3).unwrap();
        let u = vec![1.0; st.len()];
        let mut w = Whittaker::<3>::default();
        w.prepare(&st, &u, &y, (0.25, 200.0));
        assert!(w.symmetric);
        for tau in [0.2, 1.0, 3.0, 7.0] {
            let fast = w.gcv(tau).unwrap().trace;
            let mut full = vec![0.0; n];
            w.band.inverse_diagonal(&mut w.zinv, &mut full);
            let want: f64 = full.iter().map(|z| 0.5 * z).sum();
            assert!(
                (fast - want).abs() < 1e-6 * want,
                "tau {tau}: {fast} vs {want}"
            );
        }
    }

    #[test]
    fn the_search_finds_the_grid_minimum() {
        let (times, truth, y) = data(200);
        let st = Stencils::new(&times, 3).unwrap();
        let u = vec![1.0; st.len()];
        let mut w = Whittaker::<3>::default();
        w.prepare(&st, &u, &y, (0.25, 200.0));
        let (found, index) = w.search(None).unwrap();
        let (local, _) = w.search(Some(1.0)).unwrap();
        assert!(
            (local.tau / found.tau).ln().abs() < 0.1,
            "{local:?} vs {found:?}"
        );
        assert_eq!(w.grid(index), found.tau);
        // The kept factorisations give the same scores as fresh ones.
        let again = w.gcv_grid(index).unwrap();
        let fresh = w.gcv(found.tau).unwrap();
        assert!(
            (again.score - fresh.score).abs() < 1e-12 * fresh.score
                && (again.trace - fresh.trace).abs() < 1e-9
        );
        // No strength scores much lower (the grid is 9 per cent apart).
        for g in 0..60 {
            let tau = 0.25 * (800.0f64).powf(g as f64 / 59.0);
            let v = w.gcv(tau).unwrap();
            assert!(
                v.score >= found.score * (1.0 - 1e-2),
                "tau {tau}: {} < {}",
                v.score,
                found.score
            );
        }
        // And smoothing helps: the fit is closer to the truth than the data.
        w.gcv(found.tau).unwrap();
        let err = |v: &[DVec3]| {
            v.iter()
                .zip(&truth)
                .map(|(a, b)| (*a - *b).length_squared())
                .sum::<f64>()
        };
        assert!(err(&w.x) < 0.5 * err(&y), "{} vs {}", err(&w.x), err(&y));
    }
}
