//! The subdivided motion as a function of time: dense elements from [`subdivide`], the time
//! map of [`TimeMap`], and between two dense elements the screw (or straight line) joining
//! them ("between dense poses, the motion is the screw between them").

use crate::error::{Error, Result};
use crate::motion::subdivision::{subdivide, Interpolant, Scheme};
use crate::motion::timing::{TimeMap, Timing};

/// Everything that defines a smoothed motion besides its keys.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MotionSpec {
    /// The subdivision scheme.
    pub scheme: Scheme,
    /// Subdivision levels, `0..=MAX_LEVELS`.
    pub levels: u32,
    /// Whether the keys form a cycle.
    pub closed: bool,
    /// The cycle length of a closed motion (`None`: the mean key spacing closes it).
    pub period: Option<f64>,
    /// Smooth (C1) or linear timing between keys.
    pub timing: Timing,
}

impl Default for MotionSpec {
    fn default() -> Self {
        Self {
            scheme: Scheme::Jarek,
            levels: 4,
            closed: false,
            period: None,
            timing: Timing::Smooth,
        }
    }
}

/// A subdivided motion ready to be sampled at any time.
#[derive(Debug, Clone)]
pub struct Motion<T: Interpolant> {
    dense: Vec<T>,
    map: TimeMap,
    /// Dense elements per key span, `2^levels`.
    per_span: usize,
    closed: bool,
}

impl<T: Interpolant> Motion<T> {
    /// Subdivides `keys` (one per entry of `key_times`) and prepares the time map.
    ///
    /// # Errors
    /// [`Error::LengthMismatch`] when `keys` and `key_times` differ in length, then the errors
    /// of [`TimeMap::new`] and [`subdivide`].
    pub fn new(keys: &[T], key_times: &[f64], spec: &MotionSpec) -> Result<Self> {
        if keys.len() != key_times.len() {
            return Err(Error::LengthMismatch {
                what: "key times",
                expected: keys.len(),
                got: key_times.len(),
            });
        }
        let dense = subdivide(keys, spec.scheme, spec.levels, spec.closed)?;
        let map = TimeMap::new(key_times, spec.closed, spec.period, spec.timing)?;
        Ok(Self {
            dense,
            map,
            per_span: 1 << spec.levels,
            closed: spec.closed,
        })
    }

    /// A motion from dense elements computed elsewhere (for example by
    /// [`crate::feature_motion()`]): `dense` must hold `subdivided_len(n, levels, closed)`
    /// elements for the `n = key_times.len()` keys, element `i 2^levels` belonging to key `i`.
    ///
    /// # Errors
    /// [`Error::Levels`] for levels above [`crate::MAX_LEVELS`], [`Error::LengthMismatch`]
    /// when `dense` has the wrong length, then the errors of [`TimeMap::new`].
    pub fn from_dense(
        dense: Vec<T>,
        key_times: &[f64],
        levels: u32,
        closed: bool,
        period: Option<f64>,
        timing: Timing,
    ) -> Result<Self> {
        crate::motion::subdivision::check_subdivision(key_times.len(), levels)?;
        let expected = crate::motion::subdivision::subdivided_len(key_times.len(), levels, closed);
        if dense.len() != expected {
            return Err(Error::LengthMismatch {
                what: "dense poses",
                expected,
                got: dense.len(),
            });
        }
        let map = TimeMap::new(key_times, closed, period, timing)?;
        Ok(Self {
            dense,
            map,
            per_span: 1 << levels,
            closed,
        })
    }

    /// The dense (subdivided) elements.
    pub fn dense(&self) -> &[T] {
        &self.dense
    }

    /// The time map.
    pub fn time_map(&self) -> &TimeMap {
        &self.map
    }

    /// Dense span index and fraction at motion parameter `u`.
    fn locate(&self, u: f64) -> (usize, f64) {
        let x = u * self.per_span as f64;
        let spans = if self.closed {
            self.dense.len()
        } else {
            self.dense.len() - 1
        };
        let j = (x.floor().max(0.0) as usize).min(spans - 1);
        (j, x - j as f64)
    }

    /// The element at time `t`.
    pub fn at(&self, t: f64) -> T {
        let (j, f) = self.locate(self.map.parameter(t));
        let n = self.dense.len();
        T::s(&self.dense[j], f, &self.dense[(j + 1) % n])
    }

    /// The elements at many times, reusing each dense span's segment while consecutive
    /// times stay in it.
    ///
    /// # Errors
    /// [`Error::NotFinite`] for a NaN or infinite time.
    pub fn sample(&self, times: &[f64]) -> Result<Vec<T>> {
        let n = self.dense.len();
        let mut out = Vec::with_capacity(times.len());
        let mut cached: Option<(usize, T::Segment)> = None;
        for (i, &t) in times.iter().enumerate() {
            if !t.is_finite() {
                return Err(Error::NotFinite {
                    what: "time",
                    index: i,
                });
            }
            let (j, f) = self.locate(self.map.parameter(t));
            let seg = match cached {
                Some((cj, seg)) if cj == j => seg,
                _ => {
                    let seg = T::segment(&self.dense[j], &self.dense[(j + 1) % n]);
                    cached = Some((j, seg));
                    seg
                }
            };
            out.push(T::eval(&seg, f));
        }
        Ok(out)
    }
}

/// The subdivided motion of `keys` at `times` (see [`Motion`]).
///
/// # Errors
/// As [`Motion::new`] and [`Motion::sample`].
pub fn sample<T: Interpolant>(
    keys: &[T],
    key_times: &[f64],
    times: &[f64],
    spec: &MotionSpec,
) -> Result<Vec<T>> {
    Motion::new(keys, key_times, spec)?.sample(times)
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    #[test]
    fn four_point_hits_keys_at_their_times() {
        let keys = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(1.0, 2.0, 0.0),
            DVec3::new(0.0, 3.0, 1.0),
        ];
        let times = [0.0, 3.0, 10.0, 12.0];
        for closed in [false, true] {
            let spec = MotionSpec {
                scheme: Scheme::FourPoint,
                levels: 5,
                closed,
                period: closed.then_some(20.0),
                timing: Timing::Smooth,
            };
            let got = sample(&keys, &times, &times, &spec).unwrap();
            for (g, k) in got.iter().zip(&keys) {
                assert!(g.distance(*k) < 1e-14, "closed {closed}: {g} vs {k}");
            }
        }
    }

    #[test]
    fn open_motion_holds_outside_range() {
        let keys = [DVec3::ZERO, DVec3::X, DVec3::Y];
        let spec = MotionSpec::default();
        let got = sample(&keys, &[1.0, 2.0, 3.0], &[-5.0, 10.0], &spec).unwrap();
        assert_eq!(got[0], keys[0]);
        assert_eq!(got[1], keys[2]);
    }
}
