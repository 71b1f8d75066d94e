//! One keyframed F-curve, validated and prepared, evaluated as Blender's `evaluate_fcurve`
//! does (`fcurve_eval_keyframes` with its extrapolation and interpolation, inside the Cycles
//! modifier's time and value stages).

use super::bezier::{BezierSegment, SharedRoot};
use super::cycles::Cycles;
use super::easing::ease;
use super::key::{from_code, from_name, Interpolation, Key};
use crate::error::{At, Error, Expected, Result};
use crate::memory::try_vec;

/// Blender's key search threshold in `fcurve_eval_keyframes_interpolate` (`0.0001`): a time
/// within this of a key (in frames) takes that key's value.
pub const KEY_THRESHOLD: f32 = 0.0001;

/// A time closer than this to the key after it takes that key's value (Blender's `eps`,
/// `1e-8f`, after the search).
const KEY_EPS: f32 = 1.0e-8;

/// How the curve continues before its first and after its last key (`FCurve.extrapolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Extrapolation {
    /// `CONSTANT`: the end keys' values hold.
    Constant,
    /// `LINEAR`: straight lines, through the end key and its neighbour when the end key is
    /// LINEAR, along the end key's outer handle otherwise (CONSTANT end keys still hold).
    Linear,
}

impl Extrapolation {
    /// Both, in the order of [`Extrapolation::NAMES`] (the index is the packed code).
    pub const ALL: [Self; 2] = [Self::Constant, Self::Linear];

    /// The RNA identifiers, in the order of [`Extrapolation::ALL`].
    pub const NAMES: [&'static str; 2] = ["CONSTANT", "LINEAR"];

    /// The RNA identifier.
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The extrapolation named by its RNA identifier.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        from_name("extrapolation", name, &Self::NAMES, &Self::ALL)
    }

    /// The extrapolation with code `code` (its index in [`Extrapolation::ALL`]).
    ///
    /// # Errors
    /// [`Error::Index`] for a code outside `0..2`.
    pub fn from_code(code: i64) -> Result<Self> {
        from_code("extrapolation", code, &Self::ALL)
    }
}

/// A keyframed F-curve ready to evaluate: keys in time order, extrapolation, an optional
/// Cycles modifier, and each BEZIER segment's frame-independent part.
#[derive(Debug, Clone, PartialEq)]
pub struct FCurve {
    keys: Vec<Key>,
    extrapolation: Extrapolation,
    cycles: Option<Cycles>,
    /// `bezier[i]`: the segment from key `i` to key `i + 1` when key `i` is BEZIER.
    bezier: Vec<Option<BezierSegment>>,
}

impl FCurve {
    /// The curve through `keys` (at least one, frames non-decreasing: Blender keeps keys
    /// sorted; equal frames are allowed, as Blender evaluates them), with `extrapolation` and
    /// an optional Cycles modifier.
    ///
    /// # Errors
    /// [`Error::Count`] when `keys` is empty, [`Error::Value`] when a key has a non-finite
    /// number (naming the key and the field) or the modifier has one, [`Error::Spacing`] when
    /// a key's frame is before the previous key's; [`Error::Memory`] when the allocator refuses the Bezier segments.
    pub fn new(
        keys: Vec<Key>,
        extrapolation: Extrapolation,
        cycles: Option<Cycles>,
    ) -> Result<Self> {
        Self::labelled(keys, extrapolation, cycles, None)
    }

    /// [`FCurve::new`], with errors naming the curve's index `curve` in a batch.
    pub(crate) fn labelled(
        keys: Vec<Key>,
        extrapolation: Extrapolation,
        cycles: Option<Cycles>,
        curve: Option<usize>,
    ) -> Result<Self> {
        let at = |e: Error| match curve {
            Some(c) => e.within("curve", c),
            None => e,
        };
        if keys.is_empty() {
            // (Blender does not evaluate an empty curve.)
            return Err(at(Error::Count {
                what: "keys",
                got: 0,
                need: 1,
            }));
        }
        for (k, key) in keys.iter().enumerate() {
            if let Some((field, value)) = key.non_finite_field() {
                return Err(at(Error::Value {
                    what: "keys",
                    at: Some(At::new("key", k)),
                    value,
                    expected: Expected::FiniteInF32(field),
                }));
            }
            if k > 0 && key.co[0] < keys[k - 1].co[0] {
                return Err(at(Error::Spacing {
                    what: "key frames",
                    at: At::new("key", k),
                    gap: f64::from(key.co[0] - keys[k - 1].co[0]),
                    min: 0.0,
                }));
            }
        }
        if let Some(c) = &cycles {
            c.validate().map_err(at)?;
        }
        let mut bezier = try_vec(keys.len() - 1, "Bezier segments")?;
        bezier.extend(keys.windows(2).map(|w| {
            (w[0].interpolation == Interpolation::Bezier)
                .then(|| BezierSegment::new(w[0].co, w[0].handle_right, w[1].handle_left, w[1].co))
        }));
        Ok(Self {
            keys,
            extrapolation,
            cycles,
            bezier,
        })
    }

    /// The keys, in time order.
    pub fn keys(&self) -> &[Key] {
        &self.keys
    }

    /// The extrapolation.
    pub fn extrapolation(&self) -> Extrapolation {
        self.extrapolation
    }

    /// The Cycles modifier, if any.
    pub fn cycles(&self) -> Option<&Cycles> {
        self.cycles.as_ref()
    }

    /// The curve's value at `frame`, exactly as Blender's `FCurve.evaluate(frame)`: the frame
    /// rounded to `float32`, the Cycles modifier's time mapping, the keys' extrapolation or
    /// interpolation, the modifier's offset. The result is Blender's `float32` value.
    ///
    /// # Errors
    /// [`Error::NotFinite`] for a frame that is not finite in `float32`, [`Error::Evaluates`]
    /// when the value is not finite (Blender would return NaN or infinity: huge handles,
    /// values near the `float32` limit).
    pub fn evaluate(&self, frame: f64) -> Result<f64> {
        let t = frame as f32;
        if !t.is_finite() {
            return Err(Error::NotFinite {
                what: "frame",
                index: 0,
            });
        }
        let v = self.evaluate_f32(t);
        if !v.is_finite() {
            return Err(Error::Evaluates {
                curve: None,
                value: v.into(),
                time: None,
                frame: t.into(),
            });
        }
        Ok(v as f64)
    }

    /// `evaluate_fcurve` at a `float` time (may be non-finite for extreme curves).
    pub(crate) fn evaluate_f32(&self, time: f32) -> f32 {
        self.evaluate_f32_sharing(time, &mut None)
    }

    /// [`FCurve::evaluate_f32`], the root of a BEZIER segment taken from `shared` when the
    /// curve evaluated before at the same time had a segment with the same key and handle
    /// frames (curves keyed together), and kept there for the next: the same value, bit for
    /// bit, with one cubic solved for several curves.
    pub(crate) fn evaluate_f32_sharing(&self, time: f32, shared: &mut Option<SharedRoot>) -> f32 {
        let Some(cycles) = &self.cycles else {
            return self.eval_keys(time, shared);
        };
        let first = self.keys[0].co;
        let last = self.keys[self.keys.len() - 1].co;
        let (mapped, offset) = cycles.map_time(time, first, last);
        cycles.apply_value(self.eval_keys(mapped, shared), mapped, offset)
    }

    /// `fcurve_eval_keyframes`.
    fn eval_keys(&self, time: f32, shared: &mut Option<SharedRoot>) -> f32 {
        let n = self.keys.len();
        if time <= self.keys[0].co[0] {
            return self.extrapolate(time, true);
        }
        if self.keys[n - 1].co[0] <= time {
            return self.extrapolate(time, false);
        }
        self.interpolate(time, shared)
    }

    /// `fcurve_eval_keyframes_extrapolate` from the first key (`before`) or the last.
    fn extrapolate(&self, time: f32, before: bool) -> f32 {
        let n = self.keys.len();
        let (end, neighbor) = if before {
            (0, 1)
        } else {
            (n - 1, n.wrapping_sub(2))
        };
        let e = &self.keys[end];
        if e.interpolation == Interpolation::Constant
            || self.extrapolation == Extrapolation::Constant
        {
            return e.co[1];
        }
        if e.interpolation == Interpolation::Linear {
            let Some(nb) = self.keys.get(neighbor).filter(|_| n > 1) else {
                return e.co[1];
            };
            let dx = e.co[0] - time;
            let fac = nb.co[0] - e.co[0];
            if fac == 0.0 {
                return e.co[1];
            }
            let fac = (nb.co[1] - e.co[1]) / fac;
            return e.co[1] - (fac * dx);
        }
        // Bezier and the easings: along the outer handle.
        let handle = if before {
            e.handle_left
        } else {
            e.handle_right
        };
        let dx = e.co[0] - time;
        let fac = e.co[0] - handle[0];
        if fac == 0.0 {
            return e.co[1];
        }
        let fac = (e.co[1] - handle[1]) / fac;
        e.co[1] - (fac * dx)
    }

    /// `fcurve_eval_keyframes_interpolate`, for a time strictly inside the keys' range.
    fn interpolate(&self, time: f32, shared: &mut Option<SharedRoot>) -> f32 {
        let (a, exact) = binary_search(&self.keys, time);
        let Some(bezt) = self.keys.get(a) else {
            return 0.0;
        };
        if exact {
            return bezt.co[1];
        }
        let pi = a.saturating_sub(1);
        let prev = &self.keys[pi];
        if (bezt.co[0] - time).abs() < KEY_EPS {
            return bezt.co[1];
        }
        if time < prev.co[0] || bezt.co[0] < time {
            // Blender's "failed eval" (cannot happen for sorted keys).
            return 0.0;
        }
        let begin = prev.co[1];
        let change = bezt.co[1] - prev.co[1];
        let duration = bezt.co[0] - prev.co[0];
        let t = time - prev.co[0];
        if prev.interpolation == Interpolation::Constant || duration == 0.0 {
            return begin;
        }
        if prev.interpolation == Interpolation::Bezier {
            return match self.bezier.get(pi).copied().flatten() {
                Some(seg) if pi < a => seg.eval_sharing(time, shared),
                // a == 0: Blender's segment from a key to itself.
                _ => BezierSegment::new(prev.co, prev.handle_right, bezt.handle_left, bezt.co)
                    .eval(time),
            };
        }
        ease(
            prev.interpolation,
            prev.easing,
            t,
            begin,
            change,
            duration,
            prev.back,
            prev.amplitude,
            prev.period,
        )
    }
}

/// Blender's `BKE_fcurve_bezt_binarysearch_index_ex` with threshold [`KEY_THRESHOLD`]: the
/// index of the key within the threshold of `frame` and `true`, or the index where `frame`
/// would be inserted and `false`. Same probes in the same order, so keys closer together than
/// the threshold resolve as in Blender.
fn binary_search(keys: &[Key], frame: f32) -> (usize, bool) {
    let eqt = |a: f32, b: f32| {
        if a > b {
            a - b <= KEY_THRESHOLD
        } else {
            b - a <= KEY_THRESHOLD
        }
    };
    let n = keys.len();
    let first = keys[0].co[0];
    if eqt(frame, first) {
        return (0, true);
    }
    if frame < first {
        return (0, false);
    }
    let last = keys[n - 1].co[0];
    if eqt(frame, last) {
        return (n - 1, true);
    }
    if frame > last {
        return (n, false);
    }
    let (mut start, mut end) = (0i64, n as i64);
    let mut loops = 0;
    while start <= end && loops < 2 * n {
        let mid = start + (end - start) / 2;
        let Some(key) = keys.get(mid as usize) else {
            break;
        };
        let midfra = key.co[0];
        if eqt(frame, midfra) {
            return (mid as usize, true);
        }
        if frame > midfra {
            start = mid + 1;
        } else if frame < midfra {
            end = mid - 1;
        }
        loops += 1;
    }
    (start.max(0) as usize, false)
}
