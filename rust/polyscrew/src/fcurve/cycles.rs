//! The Cycles F-curve modifier (`fcm_cycles_time`, `fcm_cycles_evaluate` in Blender's
//! `fmodifier.cc`), with the influence and restricted frame range every modifier has
//! (`eval_fmodifier_influence`, `evaluate_time_fmodifiers`, `evaluate_value_fmodifiers`).
//!
//! Outside the keys' range `[x_first, x_last]` the time is folded into it: with
//! `dx = x_last - x_first` and the side's reference key `ofs` (the first key before, the last
//! key after), cycle number `n = side (t - ofs) / dx` (in `double`, from the exact
//! difference, as Blender's binaries compute it) and `fmodf(t - ofs, dx)` give the time in
//! the cycle, played backwards in odd cycles for MIRROR. REPEAT_OFFSET adds
//! `floor((t - ofs) / dx) * dy` before and `ceil((t - ofs) / dx) * dy` after
//! (`dy = y_last - y_first`) to the value. Beyond `cycles` cycles (0: no limit) the time is
//! left alone, so the curve's own extrapolation applies there (and no offset: Blender jumps
//! back to it). The modifier's influence mixes the folded time with the original one and the
//! offset value with the plain one (`interpf`), both 0 outside a restricted frame range and
//! ramped over its blend-in and blend-out.

use super::key::{from_code, from_name};
use crate::error::{Error, Expected, Result};

/// What a Cycles modifier does on one side of the keys (`FModifierCycles.mode_before`,
/// `mode_after`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CycleMode {
    /// `NONE`: no cycling on this side (the curve's extrapolation applies).
    None,
    /// `REPEAT`: the keys repeat.
    Repeat,
    /// `REPEAT_OFFSET`: the keys repeat, each cycle shifted by the last value minus the first.
    RepeatOffset,
    /// `MIRROR`: the keys repeat, every other cycle played backwards.
    Mirror,
}

impl CycleMode {
    /// Every mode, in the order of [`CycleMode::NAMES`] (the index is the packed code).
    pub const ALL: [Self; 4] = [Self::None, Self::Repeat, Self::RepeatOffset, Self::Mirror];

    /// The RNA identifiers, in the order of [`CycleMode::ALL`].
    pub const NAMES: [&'static str; 4] = ["NONE", "REPEAT", "REPEAT_OFFSET", "MIRROR"];

    /// The RNA identifier (`"REPEAT_OFFSET"`, ...).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The mode named by its RNA identifier.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        from_name("cycle mode", name, &Self::NAMES, &Self::ALL)
    }

    /// The mode with code `code` (its index in [`CycleMode::ALL`]).
    ///
    /// # Errors
    /// [`Error::Index`] for a code outside `0..4`.
    pub fn from_code(code: i64) -> Result<Self> {
        from_code("cycle mode", code, &Self::ALL)
    }
}

/// A modifier's restricted frame range (`FModifier.use_restricted_range` with `frame_start`,
/// `frame_end`, `blend_in`, `blend_out`): no effect outside `[start, end]`, influence ramped
/// from 0 over the first `blend_in` and back to 0 over the last `blend_out` frames.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FrameRange {
    /// First frame with an effect.
    pub start: f32,
    /// Last frame with an effect.
    pub end: f32,
    /// Frames over which the influence rises from 0 after `start` (0: none).
    pub blend_in: f32,
    /// Frames over which the influence falls to 0 before `end` (0: none).
    pub blend_out: f32,
}

/// A Cycles modifier (the first, and only supported, modifier of a curve).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cycles {
    /// Mode before the first key.
    pub before: CycleMode,
    /// Mode after the last key.
    pub after: CycleMode,
    /// Cycles before the first key (`cycles_before`; 0: unlimited).
    pub count_before: i32,
    /// Cycles after the last key (`cycles_after`; 0: unlimited).
    pub count_after: i32,
    /// The restricted frame range, if used.
    pub range: Option<FrameRange>,
    /// The influence, if used (`use_influence`); `None` is full influence.
    pub influence: Option<f32>,
}

impl Cycles {
    /// A Cycles modifier with modes `before` and `after`, unlimited, full influence, no
    /// restricted range (what Blender's "Add Modifier > Cycles" makes, with REPEAT on both
    /// sides).
    pub fn new(before: CycleMode, after: CycleMode) -> Self {
        Self {
            before,
            after,
            count_before: 0,
            count_after: 0,
            range: None,
            influence: None,
        }
    }

    /// Checks that every number is finite.
    ///
    /// # Errors
    /// [`Error::Value`] naming the field.
    pub fn validate(&self) -> Result<()> {
        let bad = |field, value| {
            Err(Error::Value {
                what: "cycles",
                at: None,
                value,
                expected: Expected::Finite(field),
            })
        };
        if let Some(r) = self.range {
            for (name, v) in [
                ("frame_start", r.start),
                ("frame_end", r.end),
                ("blend_in", r.blend_in),
                ("blend_out", r.blend_out),
            ] {
                if !v.is_finite() {
                    return bad(name, f64::from(v));
                }
            }
        }
        if let Some(i) = self.influence.filter(|i| !i.is_finite()) {
            return bad("influence", f64::from(i));
        }
        Ok(())
    }

    /// Whether the modifier acts at `time` at all (Blender skips a range-restricted modifier
    /// outside its range).
    fn in_range(&self, time: f32) -> bool {
        self.range.is_none_or(|r| r.start <= time && r.end >= time)
    }

    /// The modifier's influence at `time` (`eval_fmodifier_influence`).
    fn influence_at(&self, time: f32) -> f32 {
        let influence = self.influence.unwrap_or(1.0);
        let Some(r) = self.range else {
            return influence;
        };
        if time < r.start || time > r.end {
            return 0.0;
        }
        if r.blend_in != 0.0 && time >= r.start && time <= r.start + r.blend_in {
            let (a, b) = (r.start, r.start + r.blend_in);
            return influence * (time - a) / (b - a);
        }
        if r.blend_out != 0.0 && time <= r.end && time >= r.end - r.blend_out {
            let (a, b) = (r.end, r.end - r.blend_out);
            return influence * (time - a) / (b - a);
        }
        influence
    }

    /// The time at which the keys are evaluated for `time`, and the value offset to add
    /// afterwards (with [`Cycles::apply_value`]): `evaluate_time_fmodifiers` for a stack
    /// holding only this modifier. `first`, `last` are the `co` of the first and last key.
    pub(crate) fn map_time(&self, time: f32, first: [f32; 2], last: [f32; 2]) -> (f32, f32) {
        if !self.in_range(time) {
            return (time, 0.0);
        }
        let (mapped, offset) = self.cycle_time(time, first, last);
        (interpf(mapped, time, self.influence_at(time)), offset)
    }

    /// `value` with the offset added, weighted by the influence at the mapped time
    /// (`evaluate_value_fmodifiers`).
    pub(crate) fn apply_value(&self, value: f32, mapped_time: f32, offset: f32) -> f32 {
        if !self.in_range(mapped_time) {
            return value;
        }
        interpf(value + offset, value, self.influence_at(mapped_time))
    }

    /// `fcm_cycles_time`: the folded time and the REPEAT_OFFSET offset.
    fn cycle_time(&self, time: f32, first: [f32; 2], last: [f32; 2]) -> (f32, f32) {
        let (side, mode, cycles, ofs) = if time < first[0] {
            (-1i32, self.before, self.count_before, first[0])
        } else if time > last[0] {
            (1, self.after, self.count_after, last[0])
        } else {
            return (time, 0.0);
        };
        if mode == CycleMode::None {
            return (time, 0.0);
        }
        let cycdx = last[0] - first[0];
        let cycdy = last[1] - first[1];
        if cycdx == 0.0 {
            return (time, 0.0);
        }
        // The cycle number is a double, from the unrounded difference (what the 4.2.23 and
        // 5.0.1 binaries compute: `cvtss2sd`, `subsd`, `divsd`); the phase is `fmodf` of the
        // float difference. Both matter at whole cycles, where the float quotient rounds to
        // an integer the double one is not.
        let cycle = side as f64 * (time as f64 - ofs as f64) / cycdx as f64;
        let cyct = (time - ofs) % cycdx;
        if cycles != 0 && cycle > cycles as f64 {
            return (time, 0.0);
        }
        let mut offset = 0.0;
        if mode == CycleMode::RepeatOffset {
            let n = (time - ofs) / cycdx;
            offset = if side < 0 { n.floor() } else { n.ceil() };
            offset *= cycdy;
        }
        let mut t;
        if cyct == 0.0 {
            t = if side == 1 { last[0] } else { first[0] };
            if mode == CycleMode::Mirror && c_int(cycle) % 2 != 0 {
                t = if side == 1 { first[0] } else { last[0] };
            }
        } else if mode == CycleMode::Mirror && c_int(cycle + 1.0) % 2 != 0 {
            t = if side < 0 {
                first[0] - cyct
            } else {
                last[0] - cyct
            };
        } else {
            t = first[0] + cyct;
        }
        if t < first[0] {
            t += cycdx;
        }
        (t, offset)
    }
}

/// Blender's `interpf(target, origin, fac)`: `fac * target + (1 - fac) * origin`.
fn interpf(target: f32, origin: f32, fac: f32) -> f32 {
    (fac * target) + (1.0 - fac) * origin
}

/// C's `int(x)` for a `double` on x86-64 (`cvttsd2si`): truncation, and `INT_MIN` where the
/// value does not fit (Rust's `as` would saturate instead).
fn c_int(x: f64) -> i32 {
    if x.is_nan() || !(-2_147_483_648.0..2_147_483_648.0).contains(&x) {
        i32::MIN
    } else {
        x as i32
    }
}
