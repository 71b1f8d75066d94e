//! Blender's F-curve evaluation, exact to Blender and in batches: what an animator's
//! keyframed curve does between its keys (holds, Bezier handles, easing, extrapolation and the
//! Cycles modifier) at any frame, for many curves at many frames in one call.
//!
//! Source: Blender's own evaluation (`source/blender/blenkernel/intern/fcurve.cc`,
//! `fmodifier.cc`, `source/blender/blenlib/intern/easing.cc`, the same in 4.2 and 5.x),
//! mirrored operation by operation:
//!
//! - keys are Blender's `BezTriple`s in `float32`: `co` (frame, value), the two handles, the
//!   interpolation of the segment that starts at the key, its easing and the `back`,
//!   `amplitude`, `period` parameters ([`Key`]);
//! - a time is rounded to `float32` (Blender evaluates at a `float` frame), mapped by the
//!   Cycles modifier ([`Cycles`], `fcm_cycles_time`), and then
//!   - at or before the first key / at or after the last key: extrapolation
//!     (`fcurve_eval_keyframes_extrapolate`): the end key's value for
//!     [`Extrapolation::Constant`] or when the end key is CONSTANT; for
//!     [`Extrapolation::Linear`] the straight line through the end key and its neighbour
//!     when the end key is LINEAR, otherwise along the end key's outer handle;
//!   - within `0.0001` frames of a key (Blender's binary search threshold): that key's value;
//!   - otherwise the segment's interpolation (`fcurve_eval_keyframes_interpolate`):
//!     CONSTANT holds the first key's value, LINEAR is `begin + change * time / duration`,
//!     BEZIER solves the cubic `x(u) = frame` in closed form (`findzero`, `solve_cubic`,
//!     in `double`) after clamping each handle to the segment's length
//!     (`BKE_fcurve_correct_bezpart`) and evaluates `y(u)` (`berekeny`), and the eleven
//!     Penner easings (`BLI_easing_*`) use their own formulas ([`Interpolation`],
//!     [`Easing`]; AUTO is ease-out for BACK, BOUNCE and ELASTIC and ease-in for the rest);
//! - the Cycles modifier adds its offset per cycle (REPEAT_OFFSET) and mixes both by its
//!   influence and restricted frame range, as `evaluate_time_fmodifiers` and
//!   `evaluate_value_fmodifiers` do.
//!
//! Every operation Blender does in `float` is done in `f32` here and every one it does in
//! `double` in `f64`, in the same order, with the same C library functions (`log`, `exp`,
//! `acos`, `cos`, `sinf`, `cosf`, `asinf`, `powf`, `fmodf`), so the results are Blender's
//! `float` values (widened to `f64`), not a more precise curve: bit-identical to
//! `FCurve.evaluate` in Blender 4.2.23 and 5.0.1 (`tests/blender/test_curves.py`). Where the
//! shipped binaries differ from a literal reading of the source, the binaries are followed:
//! the Cycles modifier's cycle number is a `double` from the unrounded time difference
//! (found by that test at whole cycles, confirmed in the disassembly of both versions).
//! The batch is one pass per curve over the times: `O(K + T log K)` for `K` keys and `T`
//! times, each time found by Blender's own binary search.
//!
//! Out of scope (the caller detects them, see the add-on's `curves.py`): every other modifier
//! (Generator, Built-in Function, Envelope, Noise, Limits, Stepped), drivers, sampled points,
//! muted curves, and the integer / discrete value rounding Blender applies to integer, boolean
//! and enum properties.
//!
//! All sizes that input can drive are checked in one place ([`limits`]) before anything is
//! allocated; bad input (non-finite numbers, keys out of order, unknown names or codes, wrong
//! lengths) is an [`Error`](crate::Error) naming the curve and the key, never a panic, and a
//! result that is not finite (Blender would give NaN or infinity) is an error too.

pub mod batch;
pub mod bezier;
pub mod curve;
pub mod cycles;
pub mod easing;
pub mod key;
pub mod limits;

#[cfg(test)]
mod tests;

pub use batch::{evaluate_fcurves, evaluate_packed, PackedCurves};
pub use curve::{Extrapolation, FCurve};
pub use cycles::{CycleMode, Cycles, FrameRange};
pub use key::{Easing, Interpolation, Key};
pub use limits::{
    batch_footprint, check_batch, check_batch_with, packed_footprint, MAX_KEYS, MAX_VALUES,
};
