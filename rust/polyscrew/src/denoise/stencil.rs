//! Divided differences on uneven times: the penalty rows of the smoothing spline.
//!
//! Row `k` of order `m` spans times `t_k ..= t_{k+m}` and is the `m`-th divided difference
//! times `m!` (an estimate of the `m`-th derivative), scaled by `sqrt(q_k)` with
//! `q_k = (t_{k+m} - t_k) / m` so that `sum_k (D_k x)^2` is a Riemann sum of
//! `integral (x^(m))^2 dt`:
//!
//! ```text
//! D_k x = sqrt(q_k) m! sum_j x_{k+j} / prod_{l != j} (t_{k+j} - t_{k+l})
//! ```
//!
//! The data weights `h_i` are the time each sample stands for (half the span to its two
//! neighbours; the spacing at the ends), so the data term is a Riemann sum too and the
//! strength `tau` (with `lambda = tau^(2m)`) is a time, in the units of the times, however
//! densely the motion is sampled: on even samples the smoother's frequency response is
//! `1 / (1 + (tau omega)^(2m))` at low frequencies.

use crate::{At, Error, Result};

/// The largest order of differences used (third differences: the quintic spline).
pub(crate) const MAX_ORDER: usize = 3;

/// Penalty rows of one order on given times, and the data weights.
#[derive(Debug, Clone, Default)]
pub(crate) struct Stencils {
    /// Order `m` (2 or 3).
    pub(crate) order: usize,
    /// Row `k`: the weights of `x_k ..= x_{k+m}` (entries past `m` are 0).
    pub(crate) rows: Vec<[f64; MAX_ORDER + 1]>,
    /// Data weights `h_i`.
    pub(crate) weights: Vec<f64>,
}

impl Stencils {
    /// Builds the rows of order `order` for `times` (finite, strictly increasing, at least
    /// `order + 1` of them: checked by the caller).
    ///
    /// # Errors
    /// [`Error::Overflow`] when a weight overflows (times so close or so far apart that their
    /// powers leave `f64`).
    #[cfg(test)]
    pub(crate) fn new(times: &[f64], order: usize) -> Result<Self> {
        let mut s = Self::default();
        s.rebuild(times, order)?;
        Ok(s)
    }

    /// As [`Stencils::new`], reusing the storage.
    pub(crate) fn rebuild(&mut self, times: &[f64], order: usize) -> Result<()> {
        let n = times.len();
        debug_assert!((1..=MAX_ORDER).contains(&order) && n > order);
        self.order = order;
        self.rows.clear();
        self.weights.clear();
        let fact = [1.0, 1.0, 2.0, 6.0][order];
        for k in 0..n - order {
            let t = &times[k..=k + order];
            let mut row = [0.0; MAX_ORDER + 1];
            let q = ((t[order] - t[0]) / order as f64).sqrt();
            for j in 0..=order {
                let mut p = 1.0;
                for l in 0..=order {
                    if l != j {
                        p *= t[j] - t[l];
                    }
                }
                row[j] = q * fact / p;
            }
            if row.iter().any(|v| !v.is_finite()) {
                return Err(Error::Overflow {
                    what: "times",
                    at: Some(At::new("time", k)),
                    hint: "the times from here are too close together or too far apart for f64",
                });
            }
            self.rows.push(row);
        }
        for i in 0..n {
            let w = if i == 0 {
                times[1] - times[0]
            } else if i == n - 1 {
                times[n - 1] - times[n - 2]
            } else {
                0.5 * (times[i + 1] - times[i - 1])
            };
            self.weights.push(w);
        }
        Ok(())
    }

    /// Number of rows.
    pub(crate) fn len(&self) -> usize {
        self.rows.len()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_annihilate_low_degree_and_measure_the_derivative() {
        let times: Vec<f64> = (0..12)
            .map(|i| i as f64 + 0.3 * (i as f64 * 1.7).sin())
            .collect();
        for order in 1..=3 {
            let s = Stencils::new(&times, order).unwrap();
            for (k, row) in s.rows.iter().enumerate() {
                let q = ((times[k + order] - times[k]) / order as f64).sqrt();
                for degree in 0..=order {
                    let v: f64 = (0..=order)
                        .map(|j| row[j] * times[k + j].powi(degree as i32))
                        .sum();
                    let want = if degree == order {
                        // d^m/dt^m t^m = m!
                        q * [1.0, 1.0, 2.0, 6.0][order]
                    } else {
                        0.0
                    };
                    assert!(
                        (v - want).abs() < 1e-9 * (1.0 + want.abs()),
                        "order {order} row {k} degree {degree}: {v}"
                    );
                }
            }
            assert!(
                (s.weights.iter().sum::<f64>()
                    - (times[11] - times[0])
                    - 0.5 * ((times[1] - times[0]) + (times[11] - times[10])))
                    .abs()
                    < 1e-12
            );
        }
    }

    #[test]
    fn overflow_is_an_error() {
        let times = [0.0, 1e-120, 2e-120, 3e-120];
        assert!(matches!(
            Stencils::new(&times, 3),
            Err(Error::Overflow { what: "times", .. })
        ));
    }
}
