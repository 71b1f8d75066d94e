//! Rotations as Blender's animation channels, continuous from one frame to the next:
//! quaternions `(w, x, y, z)` without sign flips, axis-angle `(angle, x, y, z)` unwrapped, and
//! Euler angles in any of the six orders, each frame made compatible with the previous one
//! (no jump above 180 degrees on an axis).
//!
//! Euler conventions are Blender's: the angles are stored per axis `(x, y, z)` whatever the
//! order, and order `"XYZ"` means `R = Rz(z) Ry(y) Rx(x)` (X applied first). The extraction
//! and the compatibility rule follow Blender's `mat3_normalized_to_compatible_eulO`: of the
//! two Euler triples of a matrix, each wrapped by multiples of 2 pi towards the previous
//! frame, the one nearer to it (sum of absolute differences) is kept.

use std::f64::consts::{FRAC_PI_2, PI, TAU};

use glam::{DMat3, DQuat, DVec3};

use crate::error::{Error, Result};
use crate::memory::{try_vec, Footprint};
use crate::numeric::fastmath;

/// Below this `cos(middle angle)` an Euler triple is in gimbal lock: the first and last axes
/// coincide and the last angle is set to 0 (as Blender does, with its f32 threshold scaled).
pub const GIMBAL_LOCK_COS: f64 = 16.0 * f64::EPSILON;

/// A Blender rotation mode.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum RotationMode {
    /// `rotation_quaternion`, `(w, x, y, z)`.
    Quaternion,
    /// `rotation_axis_angle`, `(angle, x, y, z)`.
    AxisAngle,
    /// `rotation_euler` in the given order.
    Euler(EulerOrder),
}

/// The six Euler orders, named as in Blender (`"XYZ"`: X applied first).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum EulerOrder {
    /// `R = Rz Ry Rx`.
    Xyz,
    /// `R = Ry Rz Rx`.
    Xzy,
    /// `R = Rz Rx Ry`.
    Yxz,
    /// `R = Rx Rz Ry`.
    Yzx,
    /// `R = Ry Rx Rz`.
    Zxy,
    /// `R = Rx Ry Rz`.
    Zyx,
}

impl EulerOrder {
    /// The axes in the order they are applied, and whether that permutation is odd
    /// (Blender's `RotOrderInfo`).
    pub(crate) fn axes(self) -> ([usize; 3], bool) {
        match self {
            Self::Xyz => ([0, 1, 2], false),
            Self::Xzy => ([0, 2, 1], true),
            Self::Yxz => ([1, 0, 2], true),
            Self::Yzx => ([1, 2, 0], false),
            Self::Zxy => ([2, 0, 1], false),
            Self::Zyx => ([2, 1, 0], true),
        }
    }

    /// The rotation matrix of Euler angles `e = (x, y, z)` in this order.
    pub fn to_mat3(self, e: DVec3) -> DMat3 {
        let (axes, _) = self.axes();
        let about = |axis: usize| match axis {
            0 => DMat3::from_rotation_x(e.x),
            1 => DMat3::from_rotation_y(e.y),
            _ => DMat3::from_rotation_z(e.z),
        };
        about(axes[2]) * about(axes[1]) * about(axes[0])
    }

    /// Both Euler triples of a rotation matrix (equal in gimbal lock).
    fn two_triples(self, m: &DMat3) -> (DVec3, DVec3) {
        let m = m.to_cols_array();
        match self {
            Self::Xyz => two_triples_of::<0, 1, 2, false>(&m),
            Self::Xzy => two_triples_of::<0, 2, 1, true>(&m),
            Self::Yxz => two_triples_of::<1, 0, 2, true>(&m),
            Self::Yzx => two_triples_of::<1, 2, 0, false>(&m),
            Self::Zxy => two_triples_of::<2, 0, 1, false>(&m),
            Self::Zyx => two_triples_of::<2, 1, 0, true>(&m),
        }
    }
}

/// [`EulerOrder::two_triples`] of the column-major matrix `m` for the order whose axes are
/// applied `I, J, K` (`ODD`: an odd permutation), the indices known at compile time so that
/// a caller that builds `m` from a quaternion computes only the five entries read.
#[inline(always)]
fn two_triples_of<const I: usize, const J: usize, const K: usize, const ODD: bool>(
    m: &[f64; 9],
) -> (DVec3, DVec3) {
    // Blender's mat[a][b] is column a, row b.
    let at = |a: usize, b: usize| m[3 * a + b];
    // hypot without the library call: the entries of a rotation are at most 1.
    let cy = (at(I, I) * at(I, I) + at(I, J) * at(I, J)).sqrt();
    let mut e1 = [0.0; 3];
    let mut e2 = [0.0; 3];
    if cy > GIMBAL_LOCK_COS {
        e1[I] = atan2(at(J, K), at(K, K));
        e1[J] = atan2(-at(I, K), cy);
        e1[K] = atan2(at(I, J), at(I, I));
        // The second triple, atan2(-y, -x) and atan2(-s, -cy) in Blender, from the first:
        // three atan2 instead of six (Euler extraction is most of a bake's per-frame cost).
        e2[I] = half_turn_opposite(e1[I], at(J, K));
        e2[J] = reflected_middle(e1[J], -at(I, K));
        e2[K] = half_turn_opposite(e1[K], at(I, J));
    } else {
        e1[I] = atan2(-at(K, J), at(J, J));
        e1[J] = atan2(-at(I, K), cy);
        e1[K] = 0.0;
        e2 = e1;
    }
    let (mut a, mut b) = (DVec3::from_array(e1), DVec3::from_array(e2));
    if ODD {
        a = -a;
        b = -b;
    }
    (a, b)
}

impl RotationMode {
    /// Parses a Blender `rotation_mode` string: `"QUATERNION"`, `"AXIS_ANGLE"`, `"XYZ"`,
    /// `"XZY"`, `"YXZ"`, `"YZX"`, `"ZXY"`, `"ZYX"`.
    ///
    /// # Errors
    /// [`Error::Choice`] for anything else.
    pub fn from_name(name: &str) -> Result<Self> {
        Self::ALL
            .into_iter()
            .find(|mode| mode.name() == name)
            .ok_or_else(|| Error::Choice {
                what: "rotation mode",
                got: name.to_owned(),
                expected: &Self::NAMES,
            })
    }

    /// Every rotation mode, in Blender's order of the `rotation_mode` enum's values that
    /// [`RotationMode::from_name`] parses. Adding a mode: its variant, its entry here, its
    /// [`name`](Self::name), [`property`](Self::property) and [`width`](Self::width), its
    /// [`flip`](Self::flip) and [`channel_change`](Self::channel_change), and its
    /// conversions ([`rotation_matrix`], [`rotation_channels`], [`channels_near`]), all in
    /// this file.
    pub const ALL: [Self; 8] = [
        Self::Quaternion,
        Self::AxisAngle,
        Self::Euler(EulerOrder::Xyz),
        Self::Euler(EulerOrder::Xzy),
        Self::Euler(EulerOrder::Yxz),
        Self::Euler(EulerOrder::Yzx),
        Self::Euler(EulerOrder::Zxy),
        Self::Euler(EulerOrder::Zyx),
    ];

    /// [`name`](Self::name) of every mode of [`ALL`](Self::ALL), in its order.
    pub const NAMES: [&'static str; 8] = {
        let mut names = [""; 8];
        let mut i = 0;
        while i < names.len() {
            names[i] = Self::ALL[i].name();
            i += 1;
        }
        names
    };

    /// Blender's name of the mode (`"QUATERNION"`, `"AXIS_ANGLE"`, `"XYZ"`, ...).
    pub const fn name(self) -> &'static str {
        match self {
            Self::Quaternion => "QUATERNION",
            Self::AxisAngle => "AXIS_ANGLE",
            Self::Euler(EulerOrder::Xyz) => "XYZ",
            Self::Euler(EulerOrder::Xzy) => "XZY",
            Self::Euler(EulerOrder::Yxz) => "YXZ",
            Self::Euler(EulerOrder::Yzx) => "YZX",
            Self::Euler(EulerOrder::Zxy) => "ZXY",
            Self::Euler(EulerOrder::Zyx) => "ZYX",
        }
    }

    /// Blender's property holding the rotation in this mode: `"rotation_quaternion"`,
    /// `"rotation_axis_angle"` or `"rotation_euler"`.
    pub fn property(self) -> &'static str {
        match self {
            Self::Quaternion => "rotation_quaternion",
            Self::AxisAngle => "rotation_axis_angle",
            Self::Euler(_) => "rotation_euler",
        }
    }

    /// The transform properties of an owner in this mode: `"location"`, its
    /// [`property`](Self::property), `"scale"`.
    pub const fn transform_properties(self) -> &'static [&'static str] {
        match self {
            Self::Quaternion => &["location", "rotation_quaternion", "scale"],
            Self::AxisAngle => &["location", "rotation_axis_angle", "scale"],
            Self::Euler(_) => &["location", "rotation_euler", "scale"],
        }
    }

    /// How many of the channel values are angles (radians that wrap by whole turns): 0 for
    /// quaternions, the angle of axis-angle, the three Euler angles.
    const fn angles(self) -> usize {
        match self {
            Self::Quaternion => 0,
            Self::AxisAngle => 1,
            Self::Euler(_) => 3,
        }
    }

    /// The number of channels: 4 for quaternion and axis-angle, 3 for Euler.
    pub fn width(self) -> usize {
        match self {
            Self::Euler(_) => 3,
            _ => 4,
        }
    }

    /// Whether channel values written in this mode continue the values before them (a bake
    /// from the first key's values, one piece of a motion from the piece before: `previous`
    /// of [`rotation_channels`]): quaternions (their sign) and Euler angles (twin and whole
    /// turns). Axis-angle channels do not: each sequence starts from its own first rotation
    /// (the angle in `[0, pi]`, the axis the quaternion's), as the add-on has always
    /// written them.
    pub const fn continued(self) -> bool {
        !matches!(self, Self::AxisAngle)
    }

    /// The channels `start..end` Blender normalises before it uses them, so that scaling
    /// them together keeps the rotation: a quaternion's four, an axis-angle's axis (`1..4`);
    /// `None` for Euler angles.
    pub const fn normalised(self) -> Option<(usize, usize)> {
        match self {
            Self::Quaternion => Some((0, 4)),
            Self::AxisAngle => Some((1, 4)),
            Self::Euler(_) => None,
        }
    }

    /// Whether channel `channel` is an angle, radians that wrap by whole turns: the three
    /// Euler angles, the axis-angle angle (channel 0); no quaternion channel.
    pub fn is_angle(self, channel: usize) -> bool {
        channel < self.angles()
    }

    /// Whether two keys' values in this mode can say that the rotation turns more than half a
    /// turn between them (a spin the animator typed, `0 -> 270` degrees): the mode has an angle
    /// channel ([`is_angle`](Self::is_angle): Euler, axis-angle). A quaternion's values cannot
    /// (`q` and `-q` are one rotation: a sign is no turn).
    pub const fn holds_spins(self) -> bool {
        self.angles() > 0
    }

    /// How keys' values set from matrices (a script, an importer, a visual-keyed bake) in this
    /// mode can lie far apart for nearby rotations, so that Blender's playback, channel by
    /// channel, turns the long way between them: the mode's kind of [`Flip`].
    pub const fn flip(self) -> Flip {
        match self {
            Self::Quaternion => Flip::Sign,
            Self::AxisAngle => Flip::Never,
            Self::Euler(order) => Flip::Wrap(order),
        }
    }

    /// How far the channel values move from `a` to `b` (radians; rows of
    /// [`width`](Self::width) values), the measure of a span's change by its keys alone: the
    /// sum of the changes of the angle channels, `sum |b_i - a_i|` (Euler), `|b_0 - a_0|`
    /// (axis-angle); for a quaternion twice the angle between the 4-vectors,
    /// `2 acos(a . b / |a| |b|)` (up to 2 pi for a sign flip, which Blender plays the long
    /// way). `None` for a quaternion of zero length or NaN.
    #[inline]
    pub fn channel_change(self, a: &[f64], b: &[f64]) -> Option<f64> {
        match self {
            Self::Quaternion => {
                let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
                let norms = a.iter().map(|x| x * x).sum::<f64>().sqrt()
                    * b.iter().map(|x| x * x).sum::<f64>().sqrt();
                if norms <= 0.0 || norms.is_nan() {
                    return None;
                }
                Some(2.0 * (dot / norms).clamp(-1.0, 1.0).acos())
            }
            Self::AxisAngle => Some((b[0] - a[0]).abs()),
            Self::Euler(_) => Some(a.iter().zip(b).map(|(x, y)| (y - x).abs()).sum()),
        }
    }
}

/// How two neighbouring keys' values of a [`RotationMode`] can lie far apart for nearby
/// rotations when they were set from matrices ([`RotationMode::flip`]): what a flip between
/// them is, for the intent analysis to tell flips from typed spins (`intent::turns`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Flip {
    /// Angles that wrap by whole turns per channel (a matrix gives each inside `[-pi, pi]`),
    /// and the order's twin triple `(x + pi, pi - y, z + pi)` (Euler angles).
    Wrap(EulerOrder),
    /// A sign-symmetric unit quaternion: a matrix does not fix its sign (`q` and `-q` are one
    /// rotation).
    Sign,
    /// No flip: the values are typed (axis-angle's angle about its axis).
    Never,
}

/// `atan2(-y, -x)` given `a = atan2(y, x)`: the opposite direction, half a turn away, with
/// the sign `atan2` gives it (that of `-y`, signed zeros included).
#[inline]
fn half_turn_opposite(a: f64, y: f64) -> f64 {
    if y.is_sign_negative() {
        a + PI
    } else {
        a - PI
    }
}

/// `atan2(s, -c)` for `c > 0` given `a = atan2(s, c)`: the angle reflected about the
/// vertical axis, `pi - a` or `-pi - a` by the sign of `s` (signed zeros included).
#[inline]
fn reflected_middle(a: f64, s: f64) -> f64 {
    if s.is_sign_negative() {
        -PI - a
    } else {
        PI - a
    }
}

/// `x` plus the multiple of `2 pi` that brings it within `pi` of `reference`.
#[inline]
fn wrap_towards(x: f64, reference: f64) -> f64 {
    // Within 3 of the reference the multiple is 0 (the common case, continuous motion).
    if (x - reference).abs() < 3.0 {
        return x;
    }
    x - round_half_away((x - reference) / TAU) * TAU
}

/// `v.round()` (half away from zero) without the library call baseline x86-64 makes of it:
/// adding and subtracting `1.5 * 2^52` rounds half to even, a tie is moved away from zero
/// and the sign is `v`'s (`-0.2` rounds to `-0`); beyond `2^51` std.
#[inline(always)]
fn round_half_away(v: f64) -> f64 {
    if v.is_nan() || v.abs() >= 2_251_799_813_685_248.0 {
        return v.round();
    }
    let r = (v + fastmath::ROUNDING_SHIFT) - fastmath::ROUNDING_SHIFT;
    if (r - v).abs() == 0.5 {
        v + 0.5f64.copysign(v)
    } else {
        r.copysign(v)
    }
}

// fdlibm's `atan(0.5)` and `atan(1)` in two parts (`s_atan.c`, `atanhi`, `atanlo`; its
// `atanhi[1]` is `FRAC_PI_4`), digit for digit.
#[allow(clippy::excessive_precision)]
const ATAN_HALF_HI: f64 = 4.636_476_090_008_060_935_15e-1;
#[allow(clippy::excessive_precision)]
const ATAN_HALF_LO: f64 = 2.269_877_745_296_168_709_24e-17;
const ATAN_ONE_HI: f64 = std::f64::consts::FRAC_PI_4;
#[allow(clippy::excessive_precision)]
const ATAN_ONE_LO: f64 = 3.061_616_997_868_383_017_93e-17;
// The parts of pi / 2 and pi below their nearest doubles.
const FRAC_PI_2_LO: f64 = 6.123_233_995_736_766e-17;
const PI_LO: f64 = 1.224_646_799_147_353_2e-16;

/// `atan2(y, x)` within about one ulp of std's, without its library call: the ratio of the
/// smaller to the larger of `|x|`, `|y|` in `[0, 1]`, fdlibm's `atan` on it (`s_atan.c`: the
/// polynomial below `7/16`, `atan(1/2) + atan((2t - 1) / (2 + t))` below `11/16`,
/// `atan(1) + atan((t - 1) / (t + 1))` above), then the octant (`pi / 2 - a`, `pi - a` with
/// the low parts of `pi`) and the sign of `y` (signed zeros as std). Both zero, infinities
/// and NaN go to std.
#[inline(always)]
fn atan2(y: f64, x: f64) -> f64 {
    let (ax, ay) = (x.abs(), y.abs());
    let (small, large) = if ay > ax { (ax, ay) } else { (ay, ax) };
    if !(large > 0.0 && large < f64::INFINITY) {
        return y.atan2(x);
    }
    let t = small / large;
    let mut a = if t < 7.0 / 16.0 {
        t - fastmath::atan_poly(t)
    } else if t < 11.0 / 16.0 {
        let u = (2.0 * t - 1.0) / (2.0 + t);
        ATAN_HALF_HI - ((fastmath::atan_poly(u) - ATAN_HALF_LO) - u)
    } else {
        let u = (t - 1.0) / (t + 1.0);
        ATAN_ONE_HI - ((fastmath::atan_poly(u) - ATAN_ONE_LO) - u)
    };
    if ay > ax {
        a = (FRAC_PI_2 - a) + FRAC_PI_2_LO;
    }
    if x < 0.0 {
        a = (PI - a) + PI_LO;
    }
    a.copysign(y)
}

/// Of the two Euler triples `e1`, `e2` of one rotation: each wrapped towards `previous` and
/// the nearer kept (sum of absolute differences; `e1` on a tie); without `previous` the one
/// of smaller absolute sum.
#[inline(always)]
fn nearer_triple(e1: DVec3, e2: DVec3, previous: Option<DVec3>) -> DVec3 {
    match previous {
        None => {
            if e1.abs().element_sum() > e2.abs().element_sum() {
                e2
            } else {
                e1
            }
        }
        Some(p) => {
            let wrap = |e: DVec3| {
                DVec3::new(
                    wrap_towards(e.x, p.x),
                    wrap_towards(e.y, p.y),
                    wrap_towards(e.z, p.z),
                )
            };
            let (c1, c2) = (wrap(e1), wrap(e2));
            if (c1 - p).abs().element_sum() > (c2 - p).abs().element_sum() {
                c2
            } else {
                c1
            }
        }
    }
}

/// Euler angles of `m` in `order`, compatible with `previous` when given (Blender's
/// `mat3_normalized_to_compatible_eulO`), else the triple with the smaller absolute sum.
pub fn euler_compatible(m: &DMat3, order: EulerOrder, previous: Option<DVec3>) -> DVec3 {
    let (e1, e2) = order.two_triples(m);
    nearer_triple(e1, e2, previous)
}

/// [`euler_compatible`] of every rotation in turn, each compatible with the one before,
/// appended to `out` (3 values a row), the order's axes fixed at compile time.
fn euler_rows<const I: usize, const J: usize, const K: usize, const ODD: bool>(
    rotations: &[DQuat],
    mut previous: Option<DVec3>,
    out: &mut Vec<f64>,
) {
    for q in rotations {
        let (e1, e2) = two_triples_of::<I, J, K, ODD>(&DMat3::from_quat(*q).to_cols_array());
        let e = nearer_triple(e1, e2, previous);
        out.extend_from_slice(&e.to_array());
        previous = Some(e);
    }
}

/// The largest `previous` angle (radians, either sign) [`rotation_channels`] continues from:
/// Euler angles and the axis-angle angle. A continued angle is `previous` plus less than
/// half a turn; within this range a double holds it to about 1e-7 radians (its spacing at
/// 1e9 is 1.2e-7), beyond it the spacing grows until no double near `previous` stands for
/// the rotation at all (at 1e17 the doubles are 16 radians apart).
pub const MAX_PREVIOUS_ANGLE: f64 = 1e9;

/// The most rotations one [`rotation_channels`] call converts: 2**24 (16,777,216), the
/// most the default memory budget accepts for quaternion and axis-angle channels. Its work
/// is a few hundred nanoseconds per rotation, so this bounds its time (a few seconds of one
/// core) whatever the budget; more is refused before any is read ([`check_rotation_count`]).
pub const MAX_ROTATIONS: usize = 1 << 24;

/// Refuses more than [`MAX_ROTATIONS`] rotations in one call.
///
/// # Errors
/// [`Error::Limit`] (`rotations`) naming the count and the limit.
pub fn check_rotation_count(count: usize) -> Result<()> {
    if count > MAX_ROTATIONS {
        return Err(Error::Limit {
            what: "rotations",
            counted: "rotations",
            count,
            limit: MAX_ROTATIONS,
            hint: CHANNELS_HINT,
        });
    }
    Ok(())
}

/// How to ask [`rotation_channels`] for less memory.
pub const CHANNELS_HINT: &str = "convert fewer rotations at once";

/// Checks reference channel values (`previous`, or the rows of a reference): `expected`
/// numbers, finite, the angles of each row of `mode` within [`MAX_PREVIOUS_ANGLE`].
fn check_reference(
    values: &[f64],
    expected: usize,
    mode: RotationMode,
    what: &'static str,
    value: &'static str,
) -> Result<()> {
    if values.len() != expected {
        return Err(Error::LengthMismatch {
            what,
            expected,
            got: values.len(),
        });
    }
    if let Some(index) = values.iter().position(|v| !v.is_finite()) {
        return Err(Error::NotFinite { what: value, index });
    }
    let (width, angles) = (mode.width(), mode.angles());
    if let Some(index) = values
        .iter()
        .enumerate()
        .position(|(i, v)| i % width < angles && v.abs() > MAX_PREVIOUS_ANGLE)
    {
        return Err(Error::OutOfRange {
            what: value,
            index,
            value: values[index],
            limit: MAX_PREVIOUS_ANGLE,
        });
    }
    Ok(())
}

/// Channel values of a sequence of rotations in `mode`, continuous frame to frame.
///
/// `previous` (3 values for Euler, 4 otherwise) is the value just before the first frame;
/// the first frame is made compatible with it. Without it: quaternions start with `w >= 0`,
/// axis-angle with an angle in `[0, pi]`, Euler with the triple of smaller absolute sum.
/// Each output row has [`RotationMode::width`] values.
///
/// # Errors
/// [`Error::LengthMismatch`] when `previous` has the wrong width, [`Error::NotFinite`] when
/// it holds NaN or infinity, [`Error::OutOfRange`] when one of its angles (Euler, or the
/// axis-angle angle) is beyond [`MAX_PREVIOUS_ANGLE`], [`Error::Limit`] for more than
/// [`MAX_ROTATIONS`] rotations, [`Error::Memory`] when the channels exceed the memory budget.
pub fn rotation_channels(
    rotations: &[DQuat],
    mode: RotationMode,
    previous: Option<&[f64]>,
) -> Result<Vec<f64>> {
    let width = mode.width();
    if let Some(p) = previous {
        check_reference(p, width, mode, "previous", "previous value")?;
    }
    let values = rotations.len().saturating_mul(width);
    Footprint::of::<f64>(values).check("rotation channels", CHANNELS_HINT)?;
    check_rotation_count(rotations.len())?;
    let mut out = try_vec(values, "rotation channels")?;
    push_channels(rotations, mode, previous, &mut out);
    Ok(out)
}

/// Appends to `out` the channel values of `rotations` in `mode`, continuous frame to frame
/// from `previous` (checked already): the arithmetic of [`rotation_channels`], shared with
/// [`rotation_channels_each`] so the two agree to the bit.
fn push_channels(
    rotations: &[DQuat],
    mode: RotationMode,
    previous: Option<&[f64]>,
    out: &mut Vec<f64>,
) {
    match mode {
        RotationMode::Quaternion => {
            let mut prev = previous.map(|p| DQuat::from_xyzw(p[1], p[2], p[3], p[0]));
            for q in rotations {
                let mut q = q.normalize();
                let flip = match prev {
                    Some(p) => q.dot(p) < 0.0,
                    None => q.w < 0.0,
                };
                if flip {
                    q = -q;
                }
                out.extend_from_slice(&[q.w, q.x, q.y, q.z]);
                prev = Some(q);
            }
        }
        RotationMode::AxisAngle => {
            let mut prev: Option<(f64, DVec3)> =
                previous.map(|p| (p[0], DVec3::new(p[1], p[2], p[3])));
            let mut prev_q: Option<DQuat> = None;
            // An identity rotation has no axis: borrow the first defined one, so a motion that
            // starts at rest does not jump from an arbitrary axis on its second frame.
            let first_axis = rotations
                .iter()
                .find_map(|q| {
                    q.xyz()
                        .try_normalize()
                        .map(|a| if q.w < 0.0 { -a } else { a })
                })
                .unwrap_or(DVec3::Y);
            for q in rotations {
                // Sign-continuous quaternion, then angle in [0, 2 pi] and its axis.
                let mut q = q.normalize();
                if prev_q.map_or(q.w < 0.0, |p| q.dot(p) < 0.0) {
                    q = -q;
                }
                prev_q = Some(q);
                let (angle, axis) = axis_angle_near(q, prev, first_axis);
                out.extend_from_slice(&[angle, axis.x, axis.y, axis.z]);
                prev = Some((angle, axis));
            }
        }
        RotationMode::Euler(order) => {
            let prev = previous.map(|p| DVec3::new(p[0], p[1], p[2]));
            match order {
                EulerOrder::Xyz => euler_rows::<0, 1, 2, false>(rotations, prev, out),
                EulerOrder::Xzy => euler_rows::<0, 2, 1, true>(rotations, prev, out),
                EulerOrder::Yxz => euler_rows::<1, 0, 2, true>(rotations, prev, out),
                EulerOrder::Yzx => euler_rows::<1, 2, 0, false>(rotations, prev, out),
                EulerOrder::Zxy => euler_rows::<2, 0, 1, false>(rotations, prev, out),
                EulerOrder::Zyx => euler_rows::<2, 1, 0, true>(rotations, prev, out),
            }
        }
    }
}

/// The checks of a conversion of `n` rotations in `mode` each against its own row of
/// `reference` (named `what`, its values `value`): the rotation count, the reference's
/// length and values ([`check_reference`]), the memory budget; then the empty output.
fn per_row_channels(
    n: usize,
    mode: RotationMode,
    reference: &[f64],
    what: &'static str,
    value: &'static str,
) -> Result<Vec<f64>> {
    let values = n.saturating_mul(mode.width());
    check_rotation_count(n)?;
    check_reference(reference, values, mode, what, value)?;
    Footprint::of::<f64>(values).check("rotation channels", CHANNELS_HINT)?;
    try_vec(values, "rotation channels")
}

/// Channel values of each rotation in `mode` continued from its own row of `previous`
/// (`N x width` values: for example each owner's current channel values): row `i` is, to the
/// bit, `rotation_channels(&rotations[i..=i], mode, Some(previous row i))`. Many owners'
/// single keys converted in one call.
///
/// # Errors
/// [`Error::LengthMismatch`] when `previous` does not hold `N x width` values,
/// [`Error::NotFinite`] for NaN or infinity in it, [`Error::OutOfRange`] for one of its angles
/// beyond [`MAX_PREVIOUS_ANGLE`], [`Error::Limit`] for more than [`MAX_ROTATIONS`]
/// rotations, [`Error::Memory`] when the channels exceed the memory budget.
pub fn rotation_channels_each(
    rotations: &[DQuat],
    mode: RotationMode,
    previous: &[f64],
) -> Result<Vec<f64>> {
    let mut out = per_row_channels(
        rotations.len(),
        mode,
        previous,
        "previous",
        "previous value",
    )?;
    for (q, p) in rotations.iter().zip(previous.chunks_exact(mode.width())) {
        push_channels(std::slice::from_ref(q), mode, Some(p), &mut out);
    }
    Ok(out)
}

/// The axis-angle `(angle, axis)` of the unit quaternion `q` nearest `reference`:
/// `angle = 2 atan2(|v|, w)` about `v / |v|` (the reference's axis, else `fallback`, for no
/// rotation), then `(angle, axis)` or its twin `(-angle, -axis)`, whichever axis points the
/// reference's way, its angle wrapped by whole turns to within `pi` of the reference's.
fn axis_angle_near(q: DQuat, reference: Option<(f64, DVec3)>, fallback: DVec3) -> (f64, DVec3) {
    let v = q.xyz();
    let sin_h = v.length();
    let mut angle = 2.0 * sin_h.atan2(q.w);
    let mut axis = if sin_h > 0.0 {
        v / sin_h
    } else {
        reference.map_or(fallback, |(_, a)| a)
    };
    if let Some((ref_angle, ref_axis)) = reference {
        // (angle, axis) and (-angle, -axis) are the same rotation; so are angles
        // 2 pi apart: pick the representative nearest the reference.
        if axis.dot(ref_axis) < 0.0 {
            axis = -axis;
            angle = -angle;
        }
        angle = wrap_towards(angle, ref_angle);
    }
    (angle, axis)
}

/// Channel values of each rotation in `mode` written like its own row of `reference`
/// (`N x width` values, for example the keys an animator typed), not continued from the
/// rotation before: the representative of rotation `i` nearest `reference[i]`. Quaternions
/// take the reference's sign (`q . r >= 0`); axis-angle the axis that points the
/// reference's way and the angle within half a turn of its angle; Euler angles the one of
/// the two triples, each wrapped by whole turns towards the reference, that is nearer to
/// it (sum of absolute differences, [`euler_compatible`]). Spins and deliberate sign flips
/// of the reference are kept; a rotation equal to its reference's gives the reference back
/// (to rounding).
///
/// # Errors
/// [`Error::LengthMismatch`] when `reference` does not hold `N x width` values,
/// [`Error::NotFinite`] for NaN or infinity in it, [`Error::OutOfRange`] for one of its angles
/// beyond [`MAX_PREVIOUS_ANGLE`], [`Error::Limit`] for more than [`MAX_ROTATIONS`]
/// rotations, [`Error::Memory`] when the channels exceed the memory budget.
pub fn channels_near(
    rotations: &[DQuat],
    mode: RotationMode,
    reference: &[f64],
) -> Result<Vec<f64>> {
    let mut out = per_row_channels(
        rotations.len(),
        mode,
        reference,
        "reference",
        "reference value",
    )?;
    for (q, r) in rotations.iter().zip(reference.chunks_exact(mode.width())) {
        let q = q.normalize();
        match mode {
            RotationMode::Quaternion => {
                let q = if q.dot(DQuat::from_xyzw(r[1], r[2], r[3], r[0])) < 0.0 {
                    -q
                } else {
                    q
                };
                out.extend_from_slice(&[q.w, q.x, q.y, q.z]);
            }
            RotationMode::AxisAngle => {
                let q = if q.w < 0.0 { -q } else { q };
                let reference = (r[0], DVec3::new(r[1], r[2], r[3]));
                let (angle, axis) = axis_angle_near(q, Some(reference), DVec3::Y);
                out.extend_from_slice(&[angle, axis.x, axis.y, axis.z]);
            }
            RotationMode::Euler(order) => {
                let e = euler_compatible(&DMat3::from_quat(q), order, Some(DVec3::from_slice(r)));
                out.extend_from_slice(&e.to_array());
            }
        }
    }
    Ok(out)
}

/// Each of `values` of channel `channel` in `mode` moved by whole turns to within half a turn
/// of its entry of `reference` when the channel is an angle ([`RotationMode::is_angle`]:
/// `v - round((v - r) / 2 pi) 2 pi`, ties away from zero), unchanged otherwise: the same
/// rotation, written like the reference.
///
/// # Errors
/// [`Error::LengthMismatch`] when `reference` is not as long as `values`,
/// [`Error::Memory`] over the memory budget.
pub fn angles_near(
    values: &[f64],
    reference: &[f64],
    mode: RotationMode,
    channel: usize,
) -> Result<Vec<f64>> {
    if reference.len() != values.len() {
        return Err(Error::LengthMismatch {
            what: "reference",
            expected: values.len(),
            got: reference.len(),
        });
    }
    Footprint::of::<f64>(values.len()).check("angles", CHANNELS_HINT)?;
    let mut out = try_vec(values.len(), "angles")?;
    if mode.is_angle(channel) {
        out.extend(
            values
                .iter()
                .zip(reference)
                .map(|(&v, &r)| wrap_towards(v, r)),
        );
    } else {
        out.extend_from_slice(values);
    }
    Ok(out)
}

/// How far `a source + c` may stray from `target` (relative to the largest `|target|`, at
/// least 1) for [`same_rotation_map`] to accept the map `(a, c)`.
pub const SAME_ROTATION_TOLERANCE: f64 = 1e-5;

/// The per-channel affine map `(a, c)`, `a[i] source[i] + c[i] == target[i]` within
/// [`SAME_ROTATION_TOLERANCE`], that keeps every rotation channel values in `mode` can hold:
/// applied to any values (a curve's keys and handles), the rotation Blender plays from the
/// mapped values is the rotation it plays from the values. `None` when no such map takes
/// `source` to `target` (both [`RotationMode::width`] values; other lengths too).
///
/// - quaternion: a common scale `a = (target . source) / |source|^2` (the sign, and a length
///   Blender normalises away), `c = 0`;
/// - axis-angle: the angle `+-1` times the source's plus whole turns, the axis scaled by a
///   length of that same sign (`(angle, axis)` and `(-angle, -axis)` are one rotation);
/// - Euler: each angle plus whole turns (`a = 1`), or the twin triple `(x + pi, pi - y,
///   z + pi)` (the middle axis of the order negated) plus whole turns.
pub fn same_rotation_map(
    mode: RotationMode,
    source: &[f64],
    target: &[f64],
) -> Option<(Vec<f64>, Vec<f64>)> {
    let width = mode.width();
    if source.len() != width || target.len() != width {
        return None;
    }
    let largest = target.iter().fold(1.0f64, |m, v| m.max(v.abs()));
    let tol = SAME_ROTATION_TOLERANCE * largest;
    let turns = |d: f64| TAU * (d / TAU).round_ties_even();
    let dot = |a: &[f64], b: &[f64]| a.iter().zip(b).map(|(x, y)| x * y).sum::<f64>();
    let mut candidates: Vec<(Vec<f64>, Vec<f64>)> = Vec::with_capacity(2);
    match mode {
        RotationMode::Quaternion => {
            let norm = dot(source, source);
            if norm > 0.0 {
                candidates.push((vec![dot(target, source) / norm; width], vec![0.0; width]));
            }
        }
        RotationMode::AxisAngle => {
            let axis = dot(&source[1..], &source[1..]);
            for sign in [1.0, -1.0] {
                if axis > 0.0 {
                    // the axis: the sign times a positive length
                    let scale = dot(&target[1..], &source[1..]) / axis;
                    if scale * sign > 0.0 {
                        let c = turns(target[0] - sign * source[0]);
                        candidates.push((vec![sign, scale, scale, scale], vec![c, 0.0, 0.0, 0.0]));
                    }
                }
            }
        }
        RotationMode::Euler(order) => {
            candidates.push((
                vec![1.0; 3],
                source
                    .iter()
                    .zip(target)
                    .map(|(s, t)| turns(t - s))
                    .collect(),
            ));
            let middle = order.axes().0[1];
            let mut a = vec![1.0; 3];
            a[middle] = -1.0;
            let c = (0..3)
                .map(|i| PI + turns(target[i] - (a[i] * source[i] + PI)))
                .collect();
            candidates.push((a, c));
        }
    }
    candidates
        .into_iter()
        .find(|(a, c)| (0..width).all(|i| (a[i] * source[i] + c[i] - target[i]).abs() <= tol))
}

/// The rotation of `values` in `mode` as a quaternion of any non-zero length, as
/// [`rotation_matrix`] reads them (the departure's angle): a quaternion scaled by its largest component (the
/// identity for zero), Euler angles as the product of their axes' half-angle quaternions
/// (`q = q(a3) q(a2) q(a1)`, `R = R(a3) R(a2) R(a1)`); `None` for axis-angle.
pub(crate) fn rotation_quat(mode: RotationMode, values: &[f64]) -> Option<DQuat> {
    let v = |i: usize| values.get(i).copied().unwrap_or(0.0);
    match mode {
        RotationMode::Quaternion => {
            let q = DQuat::from_xyzw(v(1), v(2), v(3), v(0));
            let largest = q.to_array().into_iter().fold(0.0f64, |m, c| m.max(c.abs()));
            Some(if largest > 0.0 {
                q / largest
            } else {
                DQuat::IDENTITY
            })
        }
        RotationMode::AxisAngle => None,
        RotationMode::Euler(order) => {
            let about = |axis: usize| match axis {
                0 => DQuat::from_rotation_x(v(0)),
                1 => DQuat::from_rotation_y(v(1)),
                _ => DQuat::from_rotation_z(v(2)),
            };
            // (the axes in the order they apply, as `EulerOrder::to_mat3`)
            let [first, second, third] = order.axes().0;
            Some(about(third) * about(second) * about(first))
        }
    }
}

/// The rotation matrix of one set of rotation channels `values` in `mode`, as Blender builds
/// it:
///
/// - quaternion `(w, x, y, z)`, normalised (zero: the identity);
/// - axis-angle `(angle, x, y, z)`, a rotation by `angle` about the normalised axis
///   (Rodrigues, `I + sin(a) K + (1 - cos(a)) K^2`; a zero axis: the identity);
/// - Euler `(x, y, z)` radians, order `"XYZ"` meaning X applied first: `R = Rz Ry Rx`
///   ([`EulerOrder::to_mat3`]).
///
/// `values` has [`RotationMode::width`] numbers (extra ones are ignored, missing ones read
/// as 0); they are assumed finite.
pub fn rotation_matrix(mode: RotationMode, values: &[f64]) -> DMat3 {
    let v = |i: usize| values.get(i).copied().unwrap_or(0.0);
    match mode {
        RotationMode::Quaternion => {
            // scaled by its largest component first: no overflow for huge values
            let q = DQuat::from_xyzw(v(1), v(2), v(3), v(0));
            let largest = q.to_array().into_iter().fold(0.0f64, |m, c| m.max(c.abs()));
            if largest > 0.0 {
                let q = q / largest;
                DMat3::from_quat(q / q.length())
            } else {
                DMat3::IDENTITY
            }
        }
        RotationMode::AxisAngle => {
            let axis = DVec3::new(v(1), v(2), v(3));
            let largest = axis.abs().max_element();
            if largest > 0.0 {
                let axis = axis / largest;
                let k = axis / axis.length();
                let (s, c) = v(0).sin_cos();
                // K v = k x v, as columns of the skew matrix.
                let skew = DMat3::from_cols(
                    DVec3::new(0.0, k.z, -k.y),
                    DVec3::new(-k.z, 0.0, k.x),
                    DVec3::new(k.y, -k.x, 0.0),
                );
                DMat3::IDENTITY + skew * s + (skew * skew) * (1.0 - c)
            } else {
                DMat3::IDENTITY
            }
        }
        RotationMode::Euler(order) => order.to_mat3(DVec3::new(v(0), v(1), v(2))),
    }
}

/// The largest jump between consecutive rows on any channel (for tests and reports).
pub fn max_channel_jump(values: &[f64], width: usize) -> f64 {
    values
        .chunks_exact(width)
        .zip(values.chunks_exact(width).skip(1))
        .flat_map(|(a, b)| a.iter().zip(b).map(|(x, y)| (x - y).abs()))
        .fold(0.0, f64::max)
}

/// `pi`, re-exported for the bound of Euler jumps in tests.
pub const HALF_TURN: f64 = PI;

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    /// The six Euler orders (also used by the tests of `reduce/compose.rs`).
    pub(crate) const ORDERS: [EulerOrder; 6] = [
        EulerOrder::Xyz,
        EulerOrder::Xzy,
        EulerOrder::Yxz,
        EulerOrder::Yzx,
        EulerOrder::Zxy,
        EulerOrder::Zyx,
    ];

    /// The largest absolute difference between the entries of `a` and `b`.
    pub(crate) fn max_abs_diff(a: DMat3, b: DMat3) -> f64 {
        (a - b)
            .to_cols_array()
            .iter()
            .fold(0.0f64, |a, v| a.max(v.abs()))
    }

    #[test]
    fn atan2_matches_std() {
        // Every octant, ratios across fdlibm's ranges and their edges, tiny and huge values,
        // signed zeros and non-finite values.
        let mut worst: f64 = 0.0;
        let mut check = |y: f64, x: f64| {
            let (got, want) = (atan2(y, x), y.atan2(x));
            if want.is_nan() {
                assert!(got.is_nan(), "atan2({y}, {x}) = {got}, std NaN");
                return;
            }
            assert_eq!(
                got.is_sign_negative(),
                want.is_sign_negative(),
                "atan2({y}, {x}): {got} vs {want}"
            );
            let ulp = f64::EPSILON * want.abs().max(f64::MIN_POSITIVE);
            worst = worst.max((got - want).abs() / ulp);
        };
        for i in 0..=100_000 {
            let a = i as f64 / 100_000.0 * TAU - PI;
            let (s, c) = a.sin_cos();
            for r in [1.0, 1e-200, 3.7e150] {
                check(s * r, c * r);
            }
        }
        for t in [
            7.0 / 16.0,
            11.0 / 16.0,
            1.0,
            0.4375f64.next_down(),
            0.6875f64.next_up(),
        ] {
            for (y, x) in [(t, 1.0), (1.0, t), (-t, 1.0), (t, -1.0), (-1.0, -t)] {
                check(y, x);
            }
        }
        for (y, x) in [
            (0.0, 1.0),
            (-0.0, 1.0),
            (0.0, -1.0),
            (-0.0, -1.0),
            (1.0, 0.0),
            (1.0, -0.0),
            (-1.0, -0.0),
            (0.0, 0.0),
            (-0.0, -0.0),
            (0.0, -0.0),
            (1e-320, 1.0),
            (1.0, 1e-320),
            (f64::INFINITY, 1.0),
            (1.0, f64::NEG_INFINITY),
            (f64::INFINITY, f64::INFINITY),
            (f64::NAN, 1.0),
            (1.0, f64::NAN),
        ] {
            check(y, x);
        }
        assert!(worst <= 2.0, "worst {worst} ulps");
    }

    #[test]
    fn round_half_away_is_round() {
        for v in [
            0.5,
            -0.5,
            1.5,
            -2.5,
            2.4999999999999996,
            0.49999999999999994,
            3.0,
            -0.0,
            7e15,
            1e300,
            -4.5e9 + 0.5,
        ] {
            let (got, want) = (round_half_away(v), v.round());
            assert!(
                got == want && got.is_sign_negative() == want.is_sign_negative(),
                "{v}: {got} vs {want}"
            );
        }
    }

    #[test]
    fn euler_round_trip_every_order() {
        let e = DVec3::new(0.3, -1.1, 2.5);
        for order in ORDERS {
            let m = order.to_mat3(e);
            let got = euler_compatible(&m, order, None);
            let back = order.to_mat3(got);
            let err = max_abs_diff(back, m);
            assert!(err < 1e-14, "{order:?}: {got} -> error {err}");
        }
    }

    /// The second triple by the six-atan2 formulas of Blender's `mat3_normalized_to_eulO2`.
    fn second_triple_by_atan2(m: &DMat3, order: EulerOrder) -> DVec3 {
        let ([i, j, k], odd) = order.axes();
        let at = |a: usize, b: usize| m.col(a)[b];
        let cy = at(i, i).hypot(at(i, j));
        let mut e = [0.0; 3];
        e[i] = (-at(j, k)).atan2(-at(k, k));
        e[j] = (-at(i, k)).atan2(-cy);
        e[k] = (-at(i, j)).atan2(-at(i, i));
        let e = DVec3::from_array(e);
        if odd {
            -e
        } else {
            e
        }
    }

    #[test]
    fn second_triple_equals_the_atan2_formulas() {
        // Random rotations, and those whose entries are signed zeros (identity, half turns,
        // quarter turns), where atan2 turns on the sign of zero.
        let mut mats: Vec<DMat3> = (0..2000)
            .map(|n| {
                let f = n as f64;
                let axis = DVec3::new((1.3 * f).sin(), (2.1 * f).cos(), (0.7 * f).sin() + 0.1);
                DMat3::from_axis_angle(axis.normalize(), (f * 0.37) % TAU - PI)
            })
            .collect();
        for angle in [0.0, PI / 2.0, PI, -PI / 2.0] {
            for axis in [DVec3::X, DVec3::Y, DVec3::Z] {
                mats.push(DMat3::from_axis_angle(axis, angle));
            }
        }
        mats.push(DMat3::from_cols(-DVec3::X, -DVec3::Y, DVec3::Z));
        for m in &mats {
            for order in ORDERS {
                let ([i, j, _], _) = order.axes();
                if m.col(i)[i].hypot(m.col(i)[j]) <= GIMBAL_LOCK_COS {
                    continue; // gimbal lock: both triples are the same, no atan2 of the second
                }
                let (_, fast) = order.two_triples(m);
                let want = second_triple_by_atan2(m, order);
                for (a, b) in fast.to_array().iter().zip(want.to_array()) {
                    assert!((a - b).abs() <= 1e-15, "{order:?} {m}: {fast} vs {want}");
                }
            }
        }
    }

    #[test]
    fn spinning_several_turns_has_no_flips() {
        let axis = DVec3::new(0.2, 0.5, 1.0).normalize();
        let rots: Vec<DQuat> = (0..2000)
            .map(|i| DQuat::from_axis_angle(axis, i as f64 * 0.02))
            .collect();
        for order in ORDERS {
            let v = rotation_channels(&rots, RotationMode::Euler(order), None).unwrap();
            assert!(max_channel_jump(&v, 3) < 0.2, "{order:?}");
            for (row, q) in v.chunks_exact(3).zip(&rots) {
                let m = order.to_mat3(DVec3::from_slice(row));
                let want = DMat3::from_quat(*q);
                assert!((m - want).to_cols_array().iter().all(|d| d.abs() < 1e-12));
            }
        }
        let quats = rotation_channels(&rots, RotationMode::Quaternion, None).unwrap();
        assert!(max_channel_jump(&quats, 4) < 0.05);
        let aa = rotation_channels(&rots, RotationMode::AxisAngle, None).unwrap();
        assert!(max_channel_jump(&aa, 4) < 0.05);
        // The angle keeps growing past 2 pi.
        assert!(aa[aa.len() - 4] > 39.0, "final angle {}", aa[aa.len() - 4]);
    }

    #[test]
    fn previous_angles_beyond_the_range_are_refused() {
        let q = [DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2)];
        let euler = RotationMode::Euler(EulerOrder::Xyz);
        let err = rotation_channels(&q, euler, Some(&[0.0, 0.0, 1e17])).unwrap_err();
        assert_eq!(
            err.to_string(),
            "previous value 2 (1e17) is outside the working range +-1e9"
        );
        let err = rotation_channels(&q, RotationMode::AxisAngle, Some(&[-2e9, 0.0, 0.0, 1.0]));
        assert!(
            matches!(err, Err(Error::OutOfRange { index: 0, .. })),
            "{err:?}"
        );
        // quaternions only take the previous sign: any finite value
        assert!(
            rotation_channels(&q, RotationMode::Quaternion, Some(&[1e300, 0.0, 0.0, 0.0])).is_ok()
        );
    }

    #[test]
    fn previous_angles_at_the_edge_of_the_range_give_the_rotation() {
        let q = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2);
        for previous in [1e9, -1e9, 123_456_789.0, 7e8] {
            let e = rotation_channels(
                &[q],
                RotationMode::Euler(EulerOrder::Xyz),
                Some(&[previous; 3]),
            )
            .unwrap();
            assert!(
                e.iter().all(|v| (v - previous).abs() <= PI),
                "{e:?} from {previous}"
            );
            let m = EulerOrder::Xyz.to_mat3(DVec3::new(e[0], e[1], e[2]));
            let err = max_abs_diff(m, DMat3::from_quat(q));
            assert!(err < 1e-6, "previous {previous}: error {err}");
        }
    }

    #[test]
    fn more_than_max_rotations_are_refused() {
        assert!(check_rotation_count(MAX_ROTATIONS).is_ok());
        let err = check_rotation_count(MAX_ROTATIONS + 1).unwrap_err();
        assert_eq!(
            err,
            Error::Limit {
                what: "rotations",
                counted: "rotations",
                count: MAX_ROTATIONS + 1,
                limit: MAX_ROTATIONS,
                hint: CHANNELS_HINT,
            }
        );
        assert_eq!(
            err.to_string(),
            "rotations: 16777217 rotations exceed the limit of 16777216 in one call: convert fewer rotations at once"
        );
    }

    #[test]
    fn every_mode_parses_its_own_name() {
        for mode in RotationMode::ALL {
            assert_eq!(RotationMode::from_name(mode.name()).unwrap(), mode);
            assert!(mode.property().starts_with("rotation_"), "{mode:?}");
        }
        let err = RotationMode::from_name("xyz").unwrap_err();
        assert_eq!(
            err.to_string(),
            "rotation mode: \"xyz\" is not one of QUATERNION, AXIS_ANGLE, XYZ, XZY, YXZ, YZX, ZXY, ZYX"
        );
    }

    #[test]
    fn rotation_channels_each_is_one_call_per_row() {
        let rots: Vec<DQuat> = (0..40)
            .map(|i| {
                let axis = DVec3::new((i as f64).sin(), 0.3, (i as f64 * 0.7).cos()).normalize();
                let q = DQuat::from_axis_angle(axis, i as f64 * 0.37 - 6.0);
                if i % 3 == 0 {
                    -q
                } else {
                    q
                }
            })
            .collect();
        for mode in RotationMode::ALL {
            let w = mode.width();
            let previous: Vec<f64> = (0..rots.len() * w)
                .map(|k| 9.0 * ((k as f64) * 1.3).sin())
                .collect();
            let got = rotation_channels_each(&rots, mode, &previous).unwrap();
            let want: Vec<f64> = rots
                .iter()
                .zip(previous.chunks_exact(w))
                .flat_map(|(q, p)| {
                    rotation_channels(std::slice::from_ref(q), mode, Some(p)).unwrap()
                })
                .collect();
            assert_eq!(got, want, "{mode:?}: previous {previous:?}");
            assert!(matches!(
                rotation_channels_each(&rots, mode, &previous[1..]),
                Err(Error::LengthMismatch { .. })
            ));
            let mut bad = previous.clone();
            bad[w + 1] = f64::NAN;
            assert!(matches!(
                rotation_channels_each(&rots, mode, &bad),
                Err(Error::NotFinite { index, .. }) if index == w + 1
            ));
        }
    }

    #[test]
    fn channels_near_keep_the_reference_spins_and_signs() {
        let axis = DVec3::new(0.2, 0.5, 1.0).normalize();
        let rots: Vec<DQuat> = (0..400)
            .map(|i| DQuat::from_axis_angle(axis, i as f64 * 0.05))
            .collect();
        for mode in RotationMode::ALL {
            let w = mode.width();
            let continuous = rotation_channels(&rots, mode, None).unwrap();
            // the continuous channels are their own nearest representative
            let near = channels_near(&rots, mode, &continuous).unwrap();
            for (a, b) in near.iter().zip(&continuous) {
                assert!((a - b).abs() < 1e-12, "{mode:?}: {a} vs {b}");
            }
            // a reference a whole turn (or a sign) away is followed, rotation unchanged
            let shifted: Vec<f64> = continuous
                .chunks_exact(w)
                .flat_map(|row| {
                    let mut row = row.to_vec();
                    match mode {
                        RotationMode::Quaternion => row.iter_mut().for_each(|v| *v = -*v),
                        RotationMode::AxisAngle => row[0] += TAU,
                        RotationMode::Euler(_) => row[1] -= 2.0 * TAU,
                    }
                    row
                })
                .collect();
            let near = channels_near(&rots, mode, &shifted).unwrap();
            for (row, (want, q)) in near.chunks_exact(w).zip(shifted.chunks_exact(w).zip(&rots)) {
                for (a, b) in row.iter().zip(want) {
                    assert!((a - b).abs() < 1e-9, "{mode:?}: {row:?} vs {want:?}");
                }
                let m = rotation_matrix(mode, row);
                let err = max_abs_diff(m, DMat3::from_quat(*q));
                assert!(err < 1e-12, "{mode:?}: {row:?}");
            }
        }
        let err = channels_near(&rots[..1], RotationMode::AxisAngle, &[1.0, 0.0, 0.0]).unwrap_err();
        assert!(
            matches!(
                err,
                Error::LengthMismatch {
                    expected: 4,
                    got: 3,
                    ..
                }
            ),
            "{err:?}"
        );
    }

    /// The largest entry of `rotation_matrix(mode, a) - rotation_matrix(mode, b)`.
    fn rotation_gap(mode: RotationMode, a: &[f64], b: &[f64]) -> f64 {
        (rotation_matrix(mode, a) - rotation_matrix(mode, b))
            .to_cols_array()
            .iter()
            .fold(0.0f64, |m, v| m.max(v.abs()))
    }

    #[test]
    fn same_rotation_maps_keep_every_rotation_and_refuse_other_ones() {
        let rotations = [
            DQuat::from_euler(glam::EulerRot::XYZ, 0.4, -1.1, 2.2),
            DQuat::from_axis_angle(DVec3::new(0.2, -0.9, 0.4).normalize(), 2.9),
        ];
        let other = DQuat::from_euler(glam::EulerRot::ZXY, -2.0, 0.7, 0.3);
        for mode in RotationMode::ALL {
            let w = mode.width();
            let values = rotation_channels(&rotations, mode, None).unwrap();
            let probe = rotation_channels(&[other], mode, None).unwrap();
            for s in values.chunks_exact(w) {
                // the same rotation written otherwise: its sign and length, whole turns, the
                // other axis-angle, the twin Euler triple
                let targets: Vec<Vec<f64>> = match mode {
                    RotationMode::Quaternion => vec![
                        s.iter().map(|v| -2.5 * v).collect(),
                        s.iter().map(|v| 0.5 * v).collect(),
                    ],
                    RotationMode::AxisAngle => vec![
                        vec![-s[0] + 2.0 * TAU, -0.7 * s[1], -0.7 * s[2], -0.7 * s[3]],
                        vec![s[0] - TAU, 3.0 * s[1], 3.0 * s[2], 3.0 * s[3]],
                    ],
                    RotationMode::Euler(order) => {
                        let middle = order.axes().0[1];
                        let twin: Vec<f64> = (0..3)
                            .map(|i| if i == middle { PI - s[i] } else { s[i] + PI })
                            .map(|v| v - TAU)
                            .collect();
                        vec![vec![s[0] + TAU, s[1] - 2.0 * TAU, s[2]], twin]
                    }
                };
                for t in &targets {
                    assert!(rotation_gap(mode, s, t) < 1e-12, "{mode:?}: {s:?} vs {t:?}");
                    let (a, c) = same_rotation_map(mode, s, t)
                        .unwrap_or_else(|| panic!("{mode:?}: no map from {s:?} to {t:?}"));
                    for i in 0..w {
                        assert!((a[i] * s[i] + c[i] - t[i]).abs() < 1e-12, "{mode:?} {i}");
                    }
                    // and any other values keep their rotation under the map
                    let mapped: Vec<f64> = (0..w).map(|i| a[i] * probe[i] + c[i]).collect();
                    let gap = rotation_gap(mode, &probe, &mapped);
                    assert!(gap < 1e-12, "{mode:?}: {probe:?} -> {mapped:?}: {gap}");
                }
                // another rotation: no map
                let moved: Vec<f64> = s.iter().map(|v| v + 0.1).collect();
                assert_eq!(same_rotation_map(mode, s, &moved), None, "{mode:?}");
                assert_eq!(same_rotation_map(mode, s, &s[..w - 1]), None);
            }
        }
    }

    #[test]
    fn the_mode_says_its_flips_spins_and_change() {
        let e = [0.4, -1.1, 2.2];
        for mode in RotationMode::ALL {
            let w = mode.width();
            let values = rotation_channels(
                &[DQuat::from_euler(glam::EulerRot::XYZ, e[0], e[1], e[2])],
                mode,
                None,
            )
            .unwrap();
            // holds spins: a whole turn on some channel is the same rotation
            let turned = (0..w).any(|i| {
                let mut v = values.clone();
                v[i] += TAU;
                rotation_gap(mode, &values, &v) < 1e-12
            });
            assert_eq!(mode.holds_spins(), turned, "{mode:?}");
            match mode.flip() {
                Flip::Sign => {
                    let minus: Vec<f64> = values.iter().map(|v| -v).collect();
                    assert!(rotation_gap(mode, &values, &minus) < 1e-15, "{mode:?}");
                    assert!(!mode.holds_spins());
                }
                Flip::Wrap(order) => {
                    let m = order.to_mat3(DVec3::from_slice(&values));
                    assert_eq!(rotation_matrix(mode, &values), m, "{mode:?}");
                }
                Flip::Never => assert_eq!(mode, RotationMode::AxisAngle),
            }
        }
        // a quaternion's change is twice the angle between its 4-vectors: the turn between
        // the rotations (moves::turn_vector), or a full turn less it for opposite signs
        let quat = RotationMode::Quaternion;
        let a = DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 0.9).normalize(), 0.7);
        for (angle, scale) in [(0.0, 1.0), (0.4, 2.5), (2.9, 0.3), (3.1, -1.0), (1.2, -4.0)] {
            let b = DQuat::from_axis_angle(DVec3::new(-0.5, 0.8, 0.1).normalize(), angle) * a;
            let turn = crate::motion::moves::turn_vector(a, b).length();
            let (av, bv) = (
                [a.w, a.x, a.y, a.z],
                [b.w * scale, b.x * scale, b.y * scale, b.z * scale],
            );
            let got = quat.channel_change(&av, &bv).unwrap();
            let want = if a.dot(b) * scale >= 0.0 {
                turn
            } else {
                TAU - turn
            };
            assert!(
                (got - want).abs() < 1e-7,
                "{angle} {scale}: {got} vs {want}"
            );
        }
        assert_eq!(quat.channel_change(&[0.0; 4], &[1.0, 0.0, 0.0, 0.0]), None);
        let euler = RotationMode::Euler(EulerOrder::Zxy);
        assert_eq!(
            euler.channel_change(&[0.0, 1.0, -1.0], &[TAU, 0.5, 0.0]),
            Some(TAU + 1.5)
        );
        let aa = RotationMode::AxisAngle;
        assert_eq!(
            aa.channel_change(&[-1.0, 0.0, 0.0, 1.0], &[3.0, 1.0, 0.0, 0.0]),
            Some(4.0)
        );
    }

    #[test]
    fn angles_near_wrap_angles_only() {
        let values = [0.5, 7.0, -20.0];
        let reference = [0.0, 0.0, 0.0];
        let wrapped = [0.5, 7.0 - TAU, -20.0 + 3.0 * TAU];
        let euler = RotationMode::Euler(EulerOrder::Zxy);
        for channel in 0..3 {
            assert_eq!(
                angles_near(&values, &reference, euler, channel).unwrap(),
                wrapped
            );
        }
        let axis_angle = RotationMode::AxisAngle;
        assert_eq!(
            angles_near(&values, &reference, axis_angle, 0).unwrap(),
            wrapped
        );
        assert_eq!(
            angles_near(&values, &reference, axis_angle, 1).unwrap(),
            values
        );
        let quaternion = RotationMode::Quaternion;
        assert_eq!(
            angles_near(&values, &reference, quaternion, 0).unwrap(),
            values
        );
        assert!(matches!(
            angles_near(&values, &reference[..2], euler, 0),
            Err(Error::LengthMismatch { .. })
        ));
        assert!(RotationMode::Quaternion.continued() && !RotationMode::AxisAngle.continued());
        assert_eq!(RotationMode::AxisAngle.normalised(), Some((1, 4)));
        assert_eq!(RotationMode::Euler(EulerOrder::Xyz).normalised(), None);
        for mode in RotationMode::ALL {
            assert_eq!(mode.transform_properties()[1], mode.property());
        }
        assert!(RotationMode::Euler(EulerOrder::Yzx).continued());
    }
}
