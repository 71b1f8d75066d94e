//! The subdivided motion as a function of time: dense elements from [`subdivide`], the time
//! map of [`TimeMap`], and between two dense elements the screw (or straight line) joining
//! them ("between dense poses, the motion is the screw between them").
//!
//! Large motions are sampled piece by piece ([`sample`]): subdivision is local (every new
//! element depends on four neighbours), so the dense elements of key spans `c0..c1` are
//! those of the keys `c0 - WINDOW_MARGIN ..= c1 + WINDOW_MARGIN` subdivided on their own,
//! to the bit. Proof of the margin: subdividing a window as an open sequence gives its first
//! element and the new element after it other values than the whole sequence would (the
//! end is kept, a phantom joins the rule); if the first `e_l` elements of level `l` are
//! wrong, level `l + 1` gets `2 e_l + 2` wrong ones (an old element reads one neighbour
//! each side, a new one two), so `e_L = 2^(L+1) - 2`: fewer than two key spans. Every
//! element computes from its neighbours alone, with the same operations in the same order,
//! so outside that reach the window's elements equal the whole sequence's exactly.

use crate::error::{Error, Result};
use crate::memory::{try_vec, Footprint};
use crate::motion::subdivision::{
    check_range, check_subdivision, subdivide, subdivide_checked, subdivided_len,
    subdivision_footprint, Interpolant, Scheme,
};
use crate::motion::timing::{check_time, TimeMap, Timing};

/// Key spans taken on each side of a window by [`sample`] beyond those it samples (two are
/// enough, see the module documentation; one more for good measure).
pub const WINDOW_MARGIN: usize = 3;

/// [`sample`] subdivides the whole motion at once up to this many dense elements, and in
/// windows of about a quarter as many beyond (same result, bounded memory).
pub const WINDOWED_ABOVE: usize = 1 << 21;

/// Dense elements per window of the windowed [`sample`], about.
const WINDOW_ELEMENTS: usize = WINDOWED_ABOVE / 4;

/// Whether [`sample`] subdivides `n` keys in windows.
fn windowed(n: usize, levels: u32, closed: bool) -> bool {
    subdivided_len(n, levels, closed) > WINDOWED_ABOVE
}

/// Key spans per window of the windowed [`sample`] at `levels` (a quarter of the key spans
/// or fewer whenever windows are used, so a window never wraps onto itself).
fn window_spans(levels: u32) -> usize {
    (WINDOW_ELEMENTS >> levels.min(63)).max(1)
}

/// How to ask [`sample`] for less memory.
pub const SAMPLE_HINT: &str = "sample fewer times at once, or use fewer levels or fewer keys";

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
    /// of [`TimeMap::new`] and [`subdivide`] (including [`Error::Memory`] when the dense
    /// elements exceed the memory budget: [`sample`] samples such motions in windows).
    pub fn new(keys: &[T], key_times: &[f64], spec: &MotionSpec) -> Result<Self> {
        if keys.len() != key_times.len() {
            return Err(Error::LengthMismatch {
                what: "key times",
                expected: keys.len(),
                got: key_times.len(),
            });
        }
        let map = TimeMap::new(key_times, spec.closed, spec.period, spec.timing)?;
        let dense = subdivide(keys, spec.scheme, spec.levels, spec.closed)?;
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
    /// when `dense` has the wrong length, an element outside the working range (as
    /// [`subdivide`] refuses its keys: [`Interpolant::check_range`], naming the element),
    /// then the errors of [`TimeMap::new`].
    pub fn from_dense(
        dense: Vec<T>,
        key_times: &[f64],
        levels: u32,
        closed: bool,
        period: Option<f64>,
        timing: Timing,
    ) -> Result<Self> {
        check_subdivision(key_times.len(), levels)?;
        let expected = subdivided_len(key_times.len(), levels, closed);
        if dense.len() != expected {
            return Err(Error::LengthMismatch {
                what: "dense poses",
                expected,
                got: dense.len(),
            });
        }
        check_range(&dense)?;
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
    /// [`Error::NotFinite`] for a NaN or infinite time, [`Error::OutOfRange`] for a time
    /// beyond [`crate::motion::timing::MAX_TIME`], [`Error::Memory`] when the output exceeds
    /// the memory budget.
    pub fn sample(&self, times: &[f64]) -> Result<Vec<T>> {
        let n = self.dense.len();
        Footprint::of::<T>(times.len()).check("sampled poses", SAMPLE_HINT)?;
        let mut out = try_vec(times.len(), "sampled poses")?;
        let mut cached: Option<(usize, T::Segment)> = None;
        for (i, &t) in times.iter().enumerate() {
            check_time("time", i, t)?;
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

/// What [`sample`] holds at its peak for `n` keys and `m` times: the time map, the dense
/// elements (all of them, or one window with the times' parameters and order when the
/// motion has more than [`WINDOWED_ABOVE`]), and the output.
pub fn sample_footprint<T>(n: usize, m: usize, spec: &MotionSpec) -> Footprint {
    let map = Footprint::of::<f64>(n.saturating_add(1)).times(2);
    let out = Footprint::of::<T>(m);
    if windowed(n, spec.levels, spec.closed) {
        let keys = window_spans(spec.levels) + 2 * WINDOW_MARGIN + 1;
        map + out
            + subdivision_footprint::<T>(keys, spec.levels, false)
            + Footprint::of::<T>(keys)
            + Footprint::of::<f64>(m)
            + Footprint::of::<usize>(m)
    } else {
        map + out + subdivision_footprint::<T>(n, spec.levels, spec.closed)
    }
}

/// The subdivided motion of `keys` at `times` (see [`Motion`]), equal to
/// `Motion::new(keys, key_times, spec)?.sample(times)` to the bit.
///
/// A motion of more than [`WINDOWED_ABOVE`] dense elements is subdivided in windows of key
/// spans (only those the times fall in), so its memory is bounded by the output and one
/// window however many keys and levels it has (see the module documentation).
///
/// # Errors
/// As [`Motion::new`] and [`Motion::sample`]; [`Error::Memory`] when
/// [`sample_footprint`] exceeds the memory budget.
pub fn sample<T: Interpolant>(
    keys: &[T],
    key_times: &[f64],
    times: &[f64],
    spec: &MotionSpec,
) -> Result<Vec<T>> {
    let n = keys.len();
    if n != key_times.len() {
        return Err(Error::LengthMismatch {
            what: "key times",
            expected: n,
            got: key_times.len(),
        });
    }
    check_subdivision(n, spec.levels)?;
    check_range(keys)?;
    sample_footprint::<T>(n, times.len(), spec).check("the sampled motion", SAMPLE_HINT)?;
    if !windowed(n, spec.levels, spec.closed) {
        return Motion::new(keys, key_times, spec)?.sample(times);
    }
    let map = TimeMap::new(key_times, spec.closed, spec.period, spec.timing)?;
    sample_windowed(keys, &map, times, spec, window_spans(spec.levels))
}

/// The windowed path of [`sample`]: the same arithmetic as [`Motion::locate`] and
/// [`Motion::sample`] on dense elements subdivided window by window.
fn sample_windowed<T: Interpolant>(
    keys: &[T],
    map: &TimeMap,
    times: &[f64],
    spec: &MotionSpec,
    chunk: usize,
) -> Result<Vec<T>> {
    let n = keys.len();
    let closed = spec.closed;
    let per_span = 1usize << spec.levels;
    let key_spans = if closed { n } else { n - 1 };
    let dense_spans = key_spans * per_span;
    let mut params: Vec<f64> = try_vec(times.len(), "sample parameters")?;
    for (i, &t) in times.iter().enumerate() {
        check_time("time", i, t)?;
        params.push(map.parameter(t) * per_span as f64);
    }
    // Dense span of each time, as Motion::locate.
    let span_of = |x: f64| (x.floor().max(0.0) as usize).min(dense_spans - 1);
    let mut order: Vec<usize> = try_vec(times.len(), "sample order")?;
    order.extend(0..times.len());
    order.sort_by_key(|&i| span_of(params[i]));
    let mut out: Vec<T> = try_vec(times.len(), "sampled poses")?;
    out.resize(times.len(), keys[0]);
    let mut window: Vec<T> = try_vec(chunk + 2 * WINDOW_MARGIN + 1, "sample window")?;
    let mut k = 0;
    while k < order.len() {
        // Key spans c0..c1, subdivided with WINDOW_MARGIN keys either side (open sequences
        // stop at their ends, where the window's own end rule is the sequence's).
        let c0 = span_of(params[order[k]]) / per_span;
        let c1 = (c0 + chunk).min(key_spans);
        let (first, last) = if closed {
            (c0 + n - WINDOW_MARGIN, c1 + n + WINDOW_MARGIN)
        } else {
            (
                c0.saturating_sub(WINDOW_MARGIN),
                (c1 + WINDOW_MARGIN).min(n - 1),
            )
        };
        window.clear();
        window.extend((first..=last).map(|i| keys[i % n]));
        let dense = subdivide_checked(&window, spec.scheme, spec.levels, false)?;
        // Key span c0 sits at window span WINDOW_MARGIN closed, c0 - first open.
        let offset = if closed { WINDOW_MARGIN } else { c0 - first };
        let mut cached: Option<(usize, T::Segment)> = None;
        while k < order.len() {
            let i = order[k];
            let x = params[i];
            let j = span_of(x);
            if j / per_span >= c1 {
                break;
            }
            let local = (j / per_span - c0 + offset) * per_span + j % per_span;
            let seg = match cached {
                Some((cj, seg)) if cj == local => seg,
                _ => {
                    let seg = T::segment(&dense[local], &dense[local + 1]);
                    cached = Some((local, seg));
                    seg
                }
            };
            out[i] = T::eval(&seg, x - j as f64);
            k += 1;
        }
    }
    Ok(out)
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

    /// The windowed path equals the whole subdivision to the bit, for every scheme, open and
    /// closed, times in any order, including both ends, spans at the seams of windows and
    /// times outside the keys' range.
    #[test]
    fn windows_equal_the_whole_motion_to_the_bit() {
        use crate::motion::pose::Pose;
        use glam::{DQuat, DVec3};
        let mut x = 0.3f64;
        let mut next = move || {
            x = (x * 3.7 + 0.123).fract();
            x
        };
        let n = 41;
        let keys: Vec<Pose> = (0..n)
            .map(|_| {
                let axis = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5 + 1e-3);
                Pose::from_rotation_translation(
                    DQuat::from_axis_angle(axis.normalize(), next() * 3.0),
                    DVec3::new(next(), next(), next()) * 4.0 - 2.0,
                )
            })
            .collect();
        let key_times: Vec<f64> = (0..n)
            .map(|i| i as f64 * 1.5 + (i * i) as f64 * 0.01)
            .collect();
        let mut times: Vec<f64> = (0..700).map(|_| next() * 75.0 - 6.0).collect();
        times.extend_from_slice(&key_times);
        times.extend([key_times[0], key_times[n - 1], -1e3, 1e3]);
        for scheme in [Scheme::Jarek, Scheme::FourPoint, Scheme::BSpline] {
            for closed in [false, true] {
                for levels in [0, 1, 3, 5] {
                    let spec = MotionSpec {
                        scheme,
                        levels,
                        closed,
                        period: None,
                        timing: Timing::Smooth,
                    };
                    let whole = Motion::new(&keys, &key_times, &spec)
                        .unwrap()
                        .sample(&times)
                        .unwrap();
                    let map = TimeMap::new(&key_times, closed, None, Timing::Smooth).unwrap();
                    for chunk in [1, 2, 5, 9] {
                        let windowed = sample_windowed(&keys, &map, &times, &spec, chunk).unwrap();
                        for (i, (w, m)) in windowed.iter().zip(&whole).enumerate() {
                            assert_eq!(
                                w, m,
                                "{scheme:?} closed {closed} levels {levels} chunk {chunk} time {}",
                                times[i]
                            );
                        }
                    }
                }
            }
        }
    }

    #[test]
    fn dense_poses_outside_the_working_range_are_refused() {
        use crate::error::PoseDefect;
        use crate::motion::pose::{Pose, MAX_COORDINATE};
        let key_times = [0.0, 1.0, 2.0];
        let good = vec![Pose::IDENTITY; subdivided_len(3, 2, false)];
        let motion = Motion::from_dense(good.clone(), &key_times, 2, false, None, Timing::Smooth);
        assert!(motion.is_ok());
        for (index, translation) in [
            (0, DVec3::new(2.0 * MAX_COORDINATE, 0.0, 0.0)),
            (5, DVec3::new(0.0, f64::NAN, 0.0)),
            (8, DVec3::new(0.0, 0.0, f64::NEG_INFINITY)),
        ] {
            let mut dense = good.clone();
            dense[index] = Pose::from_translation(translation);
            let got = Motion::from_dense(dense, &key_times, 2, false, None, Timing::Smooth);
            match got {
                Err(Error::BadPose { index: i, defect }) => {
                    assert_eq!(i, index);
                    assert!(
                        matches!(
                            defect,
                            PoseDefect::NotFinite | PoseDefect::OutOfRange { .. }
                        ),
                        "{defect:?}"
                    );
                }
                other => panic!("dense pose {index} at {translation}: {:?}", other.err()),
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
