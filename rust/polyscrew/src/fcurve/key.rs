//! One keyframe as Blender stores it (`BezTriple`, `float32`), and the names of its
//! interpolation and easing: the identifiers of Blender's RNA enums (`Keyframe.interpolation`,
//! `Keyframe.easing`), never Blender's internal integers.

use crate::error::{Error, Result};

/// How the segment that starts at a key is interpolated (`Keyframe.interpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Interpolation {
    /// `CONSTANT`: the key's value holds until the next key.
    Constant,
    /// `LINEAR`: a straight line to the next key.
    Linear,
    /// `BEZIER`: the cubic Bezier through the key, its right handle, the next key's left
    /// handle and the next key.
    Bezier,
    /// `SINE`: sinusoidal easing.
    Sine,
    /// `QUAD`: quadratic easing.
    Quad,
    /// `CUBIC`: cubic easing.
    Cubic,
    /// `QUART`: quartic easing.
    Quart,
    /// `QUINT`: quintic easing.
    Quint,
    /// `EXPO`: exponential easing.
    Expo,
    /// `CIRC`: circular easing.
    Circ,
    /// `BACK`: cubic easing that overshoots by the key's `back`.
    Back,
    /// `BOUNCE`: parabolic bounces.
    Bounce,
    /// `ELASTIC`: a damped sine with the key's `amplitude` and `period`.
    Elastic,
}

impl Interpolation {
    /// Every interpolation, in the order of [`Interpolation::NAMES`]: the index of one in this
    /// array is its code in packed input ([`PackedCurves`](super::PackedCurves)).
    pub const ALL: [Self; 13] = [
        Self::Constant,
        Self::Linear,
        Self::Bezier,
        Self::Sine,
        Self::Quad,
        Self::Cubic,
        Self::Quart,
        Self::Quint,
        Self::Expo,
        Self::Circ,
        Self::Back,
        Self::Bounce,
        Self::Elastic,
    ];

    /// The RNA identifiers, in the order of [`Interpolation::ALL`] (Blender's UI order).
    pub const NAMES: [&'static str; 13] = [
        "CONSTANT", "LINEAR", "BEZIER", "SINE", "QUAD", "CUBIC", "QUART", "QUINT", "EXPO", "CIRC",
        "BACK", "BOUNCE", "ELASTIC",
    ];

    /// The RNA identifier (`"BEZIER"`, ...).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The interpolation named by its RNA identifier.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        from_name("interpolation", name, &Self::NAMES, &Self::ALL)
    }

    /// The interpolation with code `code` (its index in [`Interpolation::ALL`]).
    ///
    /// # Errors
    /// [`Error::Index`] for a code outside `0..13`.
    pub fn from_code(code: i64) -> Result<Self> {
        from_code("interpolation", code, &Self::ALL)
    }

    /// Whether the interpolation is one of Penner's easings (everything but CONSTANT,
    /// LINEAR and BEZIER), the ones [`Easing`] applies to.
    pub fn is_easing(self) -> bool {
        !matches!(self, Self::Constant | Self::Linear | Self::Bezier)
    }
}

/// Which end of a segment an easing interpolation eases (`Keyframe.easing`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Easing {
    /// `AUTO`: ease-out for BACK, BOUNCE and ELASTIC, ease-in for the other easings (Blender's
    /// defaults).
    Auto,
    /// `EASE_IN`: slow at the first key.
    In,
    /// `EASE_OUT`: slow at the second key.
    Out,
    /// `EASE_IN_OUT`: slow at both.
    InOut,
}

impl Easing {
    /// Every easing, in the order of [`Easing::NAMES`] (the index is the packed code).
    pub const ALL: [Self; 4] = [Self::Auto, Self::In, Self::Out, Self::InOut];

    /// The RNA identifiers, in the order of [`Easing::ALL`].
    pub const NAMES: [&'static str; 4] = ["AUTO", "EASE_IN", "EASE_OUT", "EASE_IN_OUT"];

    /// The RNA identifier (`"EASE_IN"`, ...).
    pub fn name(self) -> &'static str {
        Self::NAMES[self as usize]
    }

    /// The easing named by its RNA identifier.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        from_name("easing", name, &Self::NAMES, &Self::ALL)
    }

    /// The easing with code `code` (its index in [`Easing::ALL`]).
    ///
    /// # Errors
    /// [`Error::Index`] for a code outside `0..4`.
    pub fn from_code(code: i64) -> Result<Self> {
        from_code("easing", code, &Self::ALL)
    }

    /// The easing `interpolation` actually uses: [`Easing::Auto`] resolved to Blender's
    /// default for it (ease-out for BACK, BOUNCE, ELASTIC; ease-in otherwise).
    pub fn resolve(self, interpolation: Interpolation) -> Self {
        match (self, interpolation) {
            (Self::Auto, Interpolation::Back | Interpolation::Bounce | Interpolation::Elastic) => {
                Self::Out
            }
            (Self::Auto, _) => Self::In,
            (e, _) => e,
        }
    }
}

/// Blender's default `back` of a new key (`Keyframe.back`).
pub const DEFAULT_BACK: f32 = 1.70158;
/// Blender's default `amplitude` of a new key (`Keyframe.amplitude`).
pub const DEFAULT_AMPLITUDE: f32 = 0.8;
/// Blender's default `period` of a new key (`Keyframe.period`).
pub const DEFAULT_PERIOD: f32 = 4.1;

/// One keyframe, in Blender's `float32` (`BezTriple`): position, handles, and how the segment
/// that starts here is interpolated.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Key {
    /// `(frame, value)` of the key.
    pub co: [f32; 2],
    /// `(frame, value)` of the left handle (used by a BEZIER segment ending here, and by
    /// linear extrapolation before a first key that is not LINEAR or CONSTANT).
    pub handle_left: [f32; 2],
    /// `(frame, value)` of the right handle (used by a BEZIER segment starting here, and by
    /// linear extrapolation after a last key that is not LINEAR or CONSTANT).
    pub handle_right: [f32; 2],
    /// Interpolation of the segment from this key to the next.
    pub interpolation: Interpolation,
    /// Easing of that segment (easing interpolations only).
    pub easing: Easing,
    /// Overshoot of BACK.
    pub back: f32,
    /// Amplitude of ELASTIC (0: Blender's default behaviour, the change itself).
    pub amplitude: f32,
    /// Period of ELASTIC in frames (0: Blender's default, 0.3 of the segment).
    pub period: f32,
}

impl Key {
    /// A BEZIER key at `(frame, value)` with flat handles one frame to each side, AUTO easing
    /// and Blender's default `back`, `amplitude` and `period`.
    pub fn new(frame: f32, value: f32) -> Self {
        Self {
            co: [frame, value],
            handle_left: [frame - 1.0, value],
            handle_right: [frame + 1.0, value],
            interpolation: Interpolation::Bezier,
            easing: Easing::Auto,
            back: DEFAULT_BACK,
            amplitude: DEFAULT_AMPLITUDE,
            period: DEFAULT_PERIOD,
        }
    }

    /// The same key with interpolation `interpolation`.
    pub fn with_interpolation(mut self, interpolation: Interpolation) -> Self {
        self.interpolation = interpolation;
        self
    }

    /// The same key with easing `easing`.
    pub fn with_easing(mut self, easing: Easing) -> Self {
        self.easing = easing;
        self
    }

    /// The same key with handles at `left` and `right` (`(frame, value)` each).
    pub fn with_handles(mut self, left: [f32; 2], right: [f32; 2]) -> Self {
        self.handle_left = left;
        self.handle_right = right;
        self
    }

    /// The first field that is not finite, by name (`None` when all are).
    pub(crate) fn non_finite_field(&self) -> Option<(&'static str, f64)> {
        let pair = |p: [f32; 2]| p.into_iter().find(|v| !v.is_finite());
        let one = |v: f32| (!v.is_finite()).then_some(v);
        [
            ("co", pair(self.co)),
            ("handle_left", pair(self.handle_left)),
            ("handle_right", pair(self.handle_right)),
            ("back", one(self.back)),
            ("amplitude", one(self.amplitude)),
            ("period", one(self.period)),
        ]
        .into_iter()
        .find_map(|(field, v)| v.map(|v| (field, f64::from(v))))
    }
}

/// Looks `name` up in `names` (an RNA enum's identifiers) and returns the matching value.
pub(crate) fn from_name<T: Copy>(
    what: &'static str,
    name: &str,
    names: &'static [&'static str],
    all: &[T],
) -> Result<T> {
    names
        .iter()
        .position(|n| *n == name)
        .map(|i| all[i])
        .ok_or_else(|| Error::Choice {
            what,
            got: name.to_owned(),
            expected: names,
        })
}

/// The value with index `code` in `all`.
pub(crate) fn from_code<T: Copy>(what: &'static str, code: i64, all: &[T]) -> Result<T> {
    usize::try_from(code)
        .ok()
        .and_then(|i| all.get(i).copied())
        .ok_or(Error::Index {
            what,
            at: None,
            item: "code",
            index: code,
            len: all.len(),
        })
}
