//! Flips and spins: which key spans that Blender's playback turns the long way round were
//! meant to (a spin the animator typed) and which were not (an Euler wrap, a quaternion sign
//! flip), and how [`Turns`] smooths each.
//!
//! Keys set from matrices (a script setting `matrix_basis`, an importer, a visual-keyed bake)
//! have Euler values inside `-180..180` degrees: where a channel wraps (111.5 -> -141.1),
//! Blender's playback of the channels turns the long way round (252.6 degrees on that axis)
//! between two poses 107.4 degrees apart about it. A spin typed by the animator (0 -> 270,
//! 0 / 360 / 720) has a value beyond that range, or a jump that no equivalent triple
//! explains. The rule, per span, on the key values:
//!
//! - **Euler wrap**: every value of both keys lies inside `[-pi, pi]` (within
//!   [`RANGE_TOLERANCE`]), and the nearest triple equivalent to the second key (each angle
//!   plus a multiple of `2 pi`, or the twin triple `(x + pi, pi - y, z + pi)` in the order's
//!   axes, likewise: Blender's `mat3_normalized_to_compatible_eulO`) is at least
//!   [`WRAP_MARGIN`] closer to the first key (sum of absolute differences) than the keyed one.
//! - **Quaternion sign flip**: the two keys' 4-vectors point into opposite half-spaces
//!   (`q0 . q1 < 0`): Blender interpolates the components and turns the long way.
//! - Axis-angle keys never flip (their angle is typed).

use glam::DVec3;

use crate::motion::channels::{euler_compatible, EulerOrder, Flip};
use crate::{Error, Result, RotationMode};

/// How far beyond `[-pi, pi]` an Euler key value may lie and still count as inside the range
/// (radians): float32 storage of `pi` is `3.1415927`, `8.7e-8` above it.
pub const RANGE_TOLERANCE: f64 = 1e-6;

/// An Euler span is a wrap when an equivalent triple of its second key is at least this much
/// closer (radians, 45 degrees, sum of absolute differences over the three angles) to its
/// first key than the keyed triple: a single-axis wrap of a true change up to 157.5 degrees
/// (`360 - 2 * change >= 45`), and every twin-triple flip near gimbal lock.
pub const WRAP_MARGIN: f64 = 45.0 * (std::f64::consts::PI / 180.0);

/// How the spans that Blender's playback turns further than the short screw between their key
/// poses are smoothed (the add-on's option *Turns*).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Turns {
    /// Typed spins turn as Blender plays them; flips (Euler wraps, quaternion sign flips) take
    /// the short screw.
    #[default]
    Auto,
    /// Every span turns as Blender plays it: spins, and flips too (quaternion sign flips
    /// included).
    AsPlayed,
    /// The short screw between every two key poses.
    Shortest,
}

impl Turns {
    /// Parses `"AUTO"`, `"BLENDER"` (as Blender plays) or `"SHORTEST"`.
    ///
    /// # Errors
    /// [`Error::Choice`] for anything else.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "AUTO" => Ok(Self::Auto),
            "BLENDER" => Ok(Self::AsPlayed),
            "SHORTEST" => Ok(Self::Shortest),
            _ => Err(Error::Choice {
                what: "turns",
                got: name.to_owned(),
                expected: &["AUTO", "BLENDER", "SHORTEST"],
            }),
        }
    }
}

/// Sum of absolute differences of two triples.
fn l1(a: DVec3, b: DVec3) -> f64 {
    (a - b).abs().element_sum()
}

/// Whether the Euler span from key values `a` to `b` (radians, in `order`) is a wrap (see the
/// module's rule): both inside `[-pi, pi]` and an equivalent triple of `b` at least
/// [`WRAP_MARGIN`] closer to `a`.
pub fn is_euler_wrap(order: EulerOrder, a: DVec3, b: DVec3) -> bool {
    let limit = std::f64::consts::PI + RANGE_TOLERANCE;
    let inside = |e: DVec3| e.abs().max_element() <= limit;
    if !(inside(a) && inside(b)) {
        return false;
    }
    let nearest = euler_compatible(&order.to_mat3(b), order, Some(a));
    l1(nearest, a) <= l1(b, a) - WRAP_MARGIN
}

/// Whether the quaternion span from key values `a` to `b` (`w, x, y, z`) is a sign flip:
/// `a . b < 0`.
pub fn is_sign_flip(a: &[f64], b: &[f64]) -> bool {
    a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>() < 0.0
}

/// Whether the span between the rotation channel values `a` and `b` of `mode` is a flip of
/// the mode's kind ([`RotationMode::flip`]): an Euler wrap or a quaternion sign flip (never
/// for axis-angle).
pub fn is_flip(mode: RotationMode, a: &[f64], b: &[f64]) -> bool {
    match mode.flip() {
        Flip::Wrap(order) => is_euler_wrap(
            order,
            DVec3::new(a[0], a[1], a[2]),
            DVec3::new(b[0], b[1], b[2]),
        ),
        Flip::Sign => is_sign_flip(a, b),
        Flip::Never => false,
    }
}
