//! The one error type of the crate: every failure on user data is a variant that says
//! which input was wrong and why. Nothing in the crate panics on user data.

use std::fmt;

use crate::memory::human_bytes;

/// Why a pose matrix was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum PoseDefect {
    /// An entry is NaN or infinite.
    NotFinite,
    /// The bottom row is not `(0, 0, 0, 1)`.
    NotAffine,
    /// A column of the 3x3 part does not have unit length (`length` is the worst one).
    Scale {
        /// The column's index (0, 1 or 2).
        column: usize,
        /// Its length.
        length: f64,
    },
    /// Two columns of the 3x3 part are not perpendicular (`dot` is their dot product).
    Shear {
        /// The first column's index.
        a: usize,
        /// The second column's index.
        b: usize,
        /// Their dot product.
        dot: f64,
    },
    /// The 3x3 part has a negative determinant.
    Mirror,
    /// A translation entry lies outside the working range `+-limit` (see
    /// [`crate::motion::pose::MAX_COORDINATE`]).
    OutOfRange {
        /// The entry.
        value: f64,
        /// The working range's bound.
        limit: f64,
    },
}

impl fmt::Display for PoseDefect {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::NotFinite => write!(f, "contains NaN or infinity"),
            Self::NotAffine => write!(f, "bottom row is not (0, 0, 0, 1)"),
            Self::Scale { column, length } => {
                write!(f, "not rigid: scale (column {column} has length {length})")
            }
            Self::Shear { a, b, dot } => {
                write!(
                    f,
                    "not rigid: shear (columns {a} and {b} have dot product {dot:.3e})"
                )
            }
            Self::Mirror => write!(f, "not rigid: mirror (negative determinant)"),
            Self::OutOfRange { value, limit } => write!(
                f,
                "translation {value:e} is outside the working range +-{limit:e}"
            ),
        }
    }
}

/// Every error the crate reports. Messages are short and lowercase; the binding adds context.
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub enum Error {
    /// Pose `index` is not a rigid transform.
    BadPose {
        /// Index of the pose in its sequence.
        index: usize,
        /// What is wrong with it.
        defect: PoseDefect,
    },
    /// Fewer poses (or points) than the operation needs.
    TooFew {
        /// How many were given.
        got: usize,
        /// How many are needed.
        need: usize,
    },
    /// Subdivision levels outside `0..=MAX_LEVELS`.
    Levels {
        /// The requested levels.
        got: u32,
        /// The largest accepted value.
        max: u32,
    },
    /// Key times are not finite and strictly increasing: `times[index] <= times[index - 1]`.
    KeyTimes {
        /// Index of the first offending key time.
        index: usize,
    },
    /// A value that must be finite is NaN or infinite.
    NotFinite {
        /// What the value is (for example `"time"`).
        what: &'static str,
        /// Its index.
        index: usize,
    },
    /// Two arrays that must have the same length do not.
    LengthMismatch {
        /// What the arrays are.
        what: &'static str,
        /// Expected length.
        expected: usize,
        /// Given length.
        got: usize,
    },
    /// The cycle length of a closed motion does not exceed the span of its key times.
    Period {
        /// The given period.
        period: f64,
        /// The span `times[n - 1] - times[0]` it must exceed.
        span: f64,
    },
    /// A value outside the working range in which the formulas stay finite (`|value| <= limit`).
    OutOfRange {
        /// What the value is (for example `"key time"`).
        what: &'static str,
        /// Its index.
        index: usize,
        /// The value.
        value: f64,
        /// The working range's bound: `|value| <= limit` (for example
        /// [`crate::motion::timing::MAX_TIME`]).
        limit: f64,
    },
    /// A call would need more memory than it may use (see [`crate::memory`]).
    Memory {
        /// What would be allocated.
        what: &'static str,
        /// The bytes it would need (saturated at `usize::MAX`).
        bytes: usize,
        /// The budget it exceeds ([`crate::memory::memory_budget`]), or `None` when the
        /// allocator refused within the budget.
        budget: Option<usize>,
        /// How to ask for less.
        hint: &'static str,
    },
    /// A name that is not one of those the argument accepts (a scheme, a timing, a rotation
    /// mode, an interpolation).
    Choice {
        /// The argument.
        what: &'static str,
        /// The name given.
        got: String,
        /// The names accepted.
        expected: &'static [&'static str],
    },
    /// Fewer entries than an argument needs.
    Count {
        /// The argument (or what is counted in it, for example `"keys with positive
        /// stiffness"`).
        what: &'static str,
        /// How many were given.
        got: usize,
        /// How many are needed.
        need: usize,
    },
    /// A number outside the values its argument accepts.
    Value {
        /// The argument.
        what: &'static str,
        /// The entry, when the argument has several (for example `("key", 3)`).
        at: Option<At>,
        /// The value given.
        value: f64,
        /// What it must be.
        expected: Expected,
    },
    /// An entry that refers to an index outside its range `0..len`.
    Index {
        /// The argument.
        what: &'static str,
        /// The entry that refers (for example `("triangle", 12)`), when there are several.
        at: Option<At>,
        /// What the index refers to (`"vertex"`, `"owner"`, `"code"`).
        item: &'static str,
        /// The index it refers to.
        index: i64,
        /// The number of things it may refer to.
        len: usize,
    },
    /// Two consecutive values (times, frames, offsets) closer than `min` or out of order:
    /// entry `at` comes `gap` after the one before it.
    Spacing {
        /// The argument.
        what: &'static str,
        /// The later entry (for example `("key time", 3)`).
        at: At,
        /// `value[index] - value[index - 1]` (negative: out of order).
        gap: f64,
        /// The smallest gap accepted.
        min: f64,
    },
    /// More work than one call may do (a cap that bounds time, not memory; see
    /// [`Error::Memory`] for the memory budget).
    Limit {
        /// The argument that asks for the work.
        what: &'static str,
        /// What is counted (for example `"keys"`).
        counted: &'static str,
        /// How many the call asks for (saturated at `usize::MAX`).
        count: usize,
        /// The most one call accepts.
        limit: usize,
        /// How to ask for less (may be empty).
        hint: &'static str,
    },
    /// [`Error::Limit`] for work summed over parts (the samples of all key spans), with how
    /// many parts ask for it.
    LimitOver {
        /// The argument that asks for the work.
        what: &'static str,
        /// How many parts ask for the work.
        parts: usize,
        /// What the parts are (for example `"key spans"`).
        of: &'static str,
        /// What is counted (for example `"samples"`).
        counted: &'static str,
        /// How many the parts ask for together (saturated at `usize::MAX`).
        count: usize,
        /// The most one call accepts.
        limit: usize,
        /// How to ask for less (may be empty).
        hint: &'static str,
    },
    /// Input of the right form that has no unique answer: points on a line, coincident keys,
    /// a singular system, an empty mesh.
    Degenerate {
        /// The argument.
        what: &'static str,
        /// The entry, when one is to blame.
        at: Option<At>,
        /// Why there is no unique answer.
        reason: &'static str,
    },
    /// A rotation fitted to points that is not unique: the largest eigenvalue of Horn's
    /// matrix is repeated (the points are collinear or the target too distorted).
    NotUnique {
        /// What was fitted.
        what: &'static str,
        /// The largest eigenvalue.
        largest: f64,
        /// The next one, too close to it.
        next: f64,
    },
    /// Arguments that do not go together (a setting the chosen method does not take, two
    /// curves that drive one channel).
    Conflict {
        /// The argument.
        what: &'static str,
        /// What clashes with what.
        reason: String,
    },
    /// The computation left the range of `f64` (a result is NaN or infinite) although every
    /// input was in its working range.
    Overflow {
        /// What overflowed.
        what: &'static str,
        /// Where, when one entry is to blame (for example `("frame", 12)`).
        at: Option<At>,
        /// How to avoid it (may be empty).
        hint: &'static str,
    },
    /// An F-curve that evaluates to NaN or infinity (as Blender would) at a time.
    Evaluates {
        /// The curve's index, in a batch.
        curve: Option<usize>,
        /// The value.
        value: f64,
        /// The time's index, in a batch.
        time: Option<usize>,
        /// The frame.
        frame: f64,
    },
    /// A worker thread of a parallel computation failed (a bug, reported rather than
    /// propagated as a panic).
    Worker {
        /// The computation.
        what: &'static str,
    },
    /// The computation was asked to stop ([`Progress::cancel`](crate::Progress::cancel)).
    Cancelled,
    /// An error about one entry of a batch (a curve, a channel, an owner, a sample), with
    /// the entry.
    In {
        /// The argument the entry belongs to, or `""` when the entry is the whole call's
        /// (a curve of a batch of curves).
        what: &'static str,
        /// The entry.
        at: At,
        /// The error.
        source: Box<Error>,
    },
    /// An angular-velocity fit that did not converge in `max_iterations` or stays above
    /// `delta` (infeasible): the best result found, with its [`FitStatus`](crate::FitStatus).
    FitFailed {
        /// The best spline found and its figures.
        best: Box<crate::angular_velocity::AngularVelocityFit>,
    },
}

/// Which entry of an argument an error is about: `"curve"` and `3` read "curve 3".
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct At {
    /// What the entries are (singular: `"key"`, `"curve"`, `"owner"`).
    pub item: &'static str,
    /// The entry's index.
    pub index: usize,
}

impl At {
    /// Entry `index` of the `item`s.
    pub const fn new(item: &'static str, index: usize) -> Self {
        Self { item, index }
    }
}

impl fmt::Display for At {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{} {}", self.item, self.index)
    }
}

/// What a number must be: the accepted range of an [`Error::Value`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[non_exhaustive]
pub enum Expected {
    /// Finite and `> 0` (`noun` names the quantity: `"length"`).
    Positive(&'static str),
    /// Finite and `>= 0` (`noun` names the quantity: `"time"`).
    NonNegative(&'static str),
    /// In the key range `[low, high]` (a time the result is defined at).
    KeyRange {
        /// The first key's time.
        low: f64,
        /// The last key's time.
        high: f64,
    },
    /// In `low..=high`.
    Within {
        /// The smallest accepted value.
        low: f64,
        /// The largest accepted value.
        high: f64,
    },
    /// In `(0, high]`: positive and at most `high`.
    PositiveUpTo(f64),
    /// In `low..=high`, or `+inf`.
    WithinOrInfinite {
        /// The smallest accepted value.
        low: f64,
        /// The largest finite value accepted.
        high: f64,
    },
    /// In `(0, high]`, or `+inf`.
    PositiveUpToOrInfinite(f64),
    /// One of these values.
    OneOf(&'static [f64]),
    /// A vector or quaternion of length at least this, so it can be normalised.
    Normalisable(f64),
    /// Finite (the field of the argument named).
    Finite(&'static str),
    /// At least `min`, so that the call makes at most `limit` of `counted` (a length that
    /// cuts a range into pieces).
    AtLeast {
        /// The smallest value accepted.
        min: f64,
        /// The most pieces a call makes.
        limit: usize,
        /// What the pieces are.
        counted: &'static str,
    },
    /// Finite once rounded to `float32`, as Blender stores it (the field named).
    FiniteInF32(&'static str),
    /// [`Expected::AtLeast`] for a length cutting a range of known length: at least `min`, so
    /// that cutting `range` makes at most `limit` of `counted`.
    AtLeastCutting {
        /// The smallest value accepted.
        min: f64,
        /// The length of the range cut (for example the key range's).
        range: f64,
        /// The most pieces a call makes.
        limit: usize,
        /// What the pieces are.
        counted: &'static str,
    },
}

/// `x` as messages show it: plain for moderate sizes, `1e30` for large or tiny ones.
fn number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-4..1e6).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

impl fmt::Display for Expected {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::Positive(noun) => write!(f, "a positive {noun}"),
            Self::NonNegative(noun) => write!(f, "a finite {noun} >= 0"),
            Self::Within { low, high } => {
                write!(
                    f,
                    "in the working range {}..={}",
                    number(*low),
                    number(*high)
                )
            }
            Self::KeyRange { low, high } => write!(f, "inside the key range [{low}, {high}]"),
            Self::PositiveUpTo(high) => write!(f, "in the working range (0, {}]", number(*high)),
            Self::WithinOrInfinite { low, high } => {
                write!(f, "in {}..={} or inf", number(*low), number(*high))
            }
            Self::PositiveUpToOrInfinite(high) => write!(f, "in (0, {}] or inf", number(*high)),
            Self::OneOf(values) => {
                let names: Vec<String> = values.iter().map(|v| number(*v)).collect();
                match names.split_last() {
                    Some((last, [])) => write!(f, "{last}"),
                    Some((last, rest)) => write!(f, "{} or {last}", rest.join(", ")),
                    None => write!(f, "nothing"),
                }
            }
            Self::Normalisable(min) => {
                write!(f, "of length at least {} (to be normalised)", number(*min))
            }
            Self::Finite(field) => write!(f, "finite ({field})"),
            Self::AtLeast {
                min,
                limit,
                counted,
            } => write!(f, "at least {} (at most {limit} {counted})", number(*min)),
            Self::FiniteInF32(field) => write!(f, "finite in float32 ({field})"),
            Self::AtLeastCutting {
                min,
                range,
                limit,
                counted,
            } => write!(
                f,
                "at least {} (at most {limit} {counted}, {} long)",
                number(*min),
                number(*range)
            ),
        }
    }
}

impl Error {
    /// `self` about entry `index` of the `item`s of a batch ([`Error::In`]).
    pub fn within(self, item: &'static str, index: usize) -> Self {
        self.within_argument("", item, index)
    }

    /// `self` about entry `index` of the `item`s of argument `what` ([`Error::In`]).
    pub fn within_argument(self, what: &'static str, item: &'static str, index: usize) -> Self {
        Self::In {
            what,
            at: At::new(item, index),
            source: Box::new(self),
        }
    }

    /// The error under any [`Error::In`] layers: what went wrong, whichever entry it was.
    pub fn innermost(&self) -> &Self {
        match self {
            Self::In { source, .. } => source.innermost(),
            other => other,
        }
    }

    /// The argument the error is about, when it names one.
    pub fn what(&self) -> Option<&'static str> {
        if let Self::In { what, .. } = self {
            if !what.is_empty() {
                return Some(what);
            }
        }
        match self.innermost() {
            Self::NotFinite { what, .. }
            | Self::LengthMismatch { what, .. }
            | Self::OutOfRange { what, .. }
            | Self::Memory { what, .. }
            | Self::Choice { what, .. }
            | Self::Count { what, .. }
            | Self::Value { what, .. }
            | Self::Index { what, .. }
            | Self::Spacing { what, .. }
            | Self::Limit { what, .. }
            | Self::LimitOver { what, .. }
            | Self::Degenerate { what, .. }
            | Self::NotUnique { what, .. }
            | Self::Conflict { what, .. }
            | Self::Overflow { what, .. }
            | Self::Worker { what } => Some(what),
            _ => None,
        }
    }
}

/// `": {hint}"`, or nothing for an empty hint (the end of a limit's message).
fn write_hint(f: &mut fmt::Formatter<'_>, hint: &str) -> fmt::Result {
    if hint.is_empty() {
        Ok(())
    } else {
        write!(f, ": {hint}")
    }
}

/// A list of names as messages show them: Blender's identifiers bare (`QUATERNION, XYZ`),
/// lowercase option names quoted (`"smooth", "linear"`).
fn names(expected: &[&str]) -> String {
    let quoted = expected
        .iter()
        .any(|n| n.chars().any(|c| c.is_ascii_lowercase()));
    let shown: Vec<String> = expected
        .iter()
        .map(|n| {
            if quoted {
                format!("{n:?}")
            } else {
                (*n).to_owned()
            }
        })
        .collect();
    shown.join(", ")
}

/// `"{at}: "` or nothing.
fn prefix(at: &Option<At>) -> String {
    at.map(|a| format!("{a}: ")).unwrap_or_default()
}

impl fmt::Display for Error {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Self::BadPose { index, defect } => write!(f, "pose {index}: {defect}"),
            Self::TooFew { got, need } => write!(f, "{got} poses given, at least {need} needed"),
            Self::Levels { got, max } => write!(f, "levels {got} out of range 0..={max}"),
            Self::KeyTimes { index } => write!(
                f,
                "key time {index} is not finite or not greater than key time {}",
                index.saturating_sub(1)
            ),
            Self::NotFinite { what, index } => write!(f, "{what} {index} is NaN or infinite"),
            Self::LengthMismatch {
                what,
                expected,
                got,
            } => {
                write!(f, "{what}: expected {expected} entries, got {got}")
            }
            Self::Period { period, span } => write!(
                f,
                "period {period} must be finite and exceed the key times' span {span}"
            ),
            Self::OutOfRange {
                what,
                index,
                value,
                limit,
            } => write!(
                f,
                "{what} {index} ({value:e}) is outside the working range +-{limit:e}"
            ),
            Self::Memory {
                what,
                bytes,
                budget: Some(budget),
                hint,
            } => write!(
                f,
                "{what} would need {}, over the memory budget of {}: {hint} \
                 (or raise the budget with set_memory_budget)",
                human_bytes(*bytes),
                human_bytes(*budget)
            ),
            Self::Memory {
                what,
                bytes,
                budget: None,
                hint,
            } => write!(
                f,
                "could not allocate {} for {what}: {hint}",
                human_bytes(*bytes)
            ),
            Self::Choice {
                what,
                got,
                expected,
            } => write!(f, "{what}: {got:?} is not one of {}", names(expected)),
            Self::Count { what, got, need } => {
                write!(f, "{what}: {got} given, at least {need} needed")
            }
            Self::Value {
                what,
                at,
                value,
                expected,
            } => match (at, expected) {
                (None, Expected::AtLeast { .. }) if *value > 0.0 => {
                    write!(f, "{what}: {} is not {expected}", number(*value))
                }
                (Some(at), Expected::NonNegative(_)) if *value < 0.0 => {
                    write!(f, "{what}: {at} is negative ({value})")
                }
                (None, Expected::Finite(field)) => {
                    write!(f, "{what}: {field} is not finite ({value})")
                }
                (at, Expected::FiniteInF32(field)) => write!(
                    f,
                    "{what}: {}{field} is not finite in float32 ({value})",
                    prefix(at)
                ),
                (Some(at), Expected::KeyRange { low, high }) => write!(
                    f,
                    "{what}: {at} ({value}) is outside the key range [{low}, {high}]"
                ),
                (Some(at), Expected::Normalisable(min)) => write!(
                    f,
                    "{what}: {at} has length {value:e}, shorter than {min:e}: it cannot be \
                     normalised"
                ),
                (Some(at), _) => write!(f, "{what}: {at} has {what} {value}, not {expected}"),
                (None, _) => write!(f, "{what}: {} is not {expected}", number(*value)),
            },
            Self::Index {
                what,
                at,
                item,
                index,
                len,
            } => write!(
                f,
                "{what}: {}{item} {index} is outside 0..{len}",
                prefix(at)
            ),
            Self::Spacing { what, at, gap, min } => {
                if *gap < 0.0 || gap.is_nan() {
                    let order = if *min > 0.0 {
                        "increase strictly"
                    } else {
                        "be in increasing order"
                    };
                    write!(
                        f,
                        "{what}: {at} is less than the one before (by {}): they must {order}",
                        -gap
                    )
                } else if *gap == 0.0 {
                    write!(
                        f,
                        "{what}: {at} equals the one before: they must increase strictly"
                    )
                } else {
                    write!(
                        f,
                        "{what}: {at} is {gap:e} after the one before, closer than {min:e}"
                    )
                }
            }
            Self::Limit {
                what,
                counted,
                count,
                limit,
                hint,
            } => {
                write!(
                    f,
                    "{what}: {count} {counted} exceed the limit of {limit} in one call"
                )?;
                write_hint(f, hint)
            }
            Self::LimitOver {
                what,
                parts,
                of,
                counted,
                count,
                limit,
                hint,
            } => {
                write!(
                    f,
                    "{what}: the {parts} {of} would take {count} {counted}, over the limit of \
                     {limit} in one call"
                )?;
                write_hint(f, hint)
            }
            Self::Degenerate { what, at, reason } => {
                write!(f, "{what}: {}{reason}", prefix(at))
            }
            Self::NotUnique {
                what,
                largest,
                next,
            } => write!(
                f,
                "{what}: the best rotation is not unique (largest eigenvalue of Horn's matrix \
                 repeated: {largest:.6e} and {next:.6e}); the points are collinear or the target \
                 is too distorted"
            ),
            Self::Conflict { what, reason } => write!(f, "{what}: {reason}"),
            Self::Overflow { what, at, hint } => {
                write!(
                    f,
                    "{what}: {}values too large: the computation overflowed",
                    prefix(at)
                )?;
                if hint.is_empty() {
                    Ok(())
                } else {
                    write!(f, "; {hint}")
                }
            }
            Self::Evaluates {
                curve,
                value,
                time,
                frame,
            } => {
                match curve {
                    Some(c) => write!(f, "value: curve {c} evaluates to {value}")?,
                    None => write!(f, "value: the curve evaluates to {value}")?,
                }
                match time {
                    Some(i) => write!(f, " at time {i} (frame {frame}), as Blender would"),
                    None => write!(f, " at frame {frame}, as Blender would"),
                }
            }
            Self::Worker { what } => write!(f, "{what}: a worker thread failed"),
            Self::Cancelled => write!(f, "stopped: the caller asked the computation to stop"),
            Self::In {
                what: "",
                at,
                source,
            } => write!(f, "{at}: {source}"),
            Self::In { what, at, source } => write!(f, "{what}: {at}: {source}"),
            Self::FitFailed { best } => match best.status {
                crate::FitStatus::IterationLimit => write!(
                    f,
                    "optimiser did not converge in {} iterations (fit error {:.4e}, delta {})",
                    best.iterations, best.fit_error, best.delta
                ),
                _ => write!(
                    f,
                    "target infeasible: fit error {:.4e} exceeds delta {} with {} variable frames",
                    best.fit_error,
                    best.delta,
                    best.frame_times.len()
                ),
            },
        }
    }
}

impl std::error::Error for Error {}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bad_name_lists_the_names_as_they_are_written() {
        let blender = Error::Choice {
            what: "turns",
            got: "LONGEST".into(),
            expected: &["AUTO", "BLENDER", "SHORTEST"],
        };
        assert_eq!(
            blender.to_string(),
            "turns: \"LONGEST\" is not one of AUTO, BLENDER, SHORTEST"
        );
        let option = Error::Choice {
            what: "timing",
            got: "cubic".into(),
            expected: &["smooth", "linear"],
        };
        assert_eq!(
            option.to_string(),
            "timing: \"cubic\" is not one of \"smooth\", \"linear\""
        );
        assert_eq!(option.what(), Some("timing"));
    }

    #[test]
    fn a_value_says_what_it_is_and_what_it_must_be() {
        let cases = [
            (
                None,
                -1.0,
                Expected::NonNegative("time"),
                "strength: -1 is not a finite time >= 0",
            ),
            (
                None,
                0.0,
                Expected::Positive("length"),
                "strength: 0 is not a positive length",
            ),
            (
                None,
                -1.0,
                Expected::PositiveUpTo(1e150),
                "strength: -1 is not in the working range (0, 1e150]",
            ),
            (
                None,
                4.0,
                Expected::OneOf(&[2.0, 3.0]),
                "strength: 4 is not 2 or 3",
            ),
            (
                None,
                1e-15,
                Expected::AtLeast {
                    min: 1e-6,
                    limit: 1_000_000,
                    counted: "fragments",
                },
                "strength: 1e-15 is not at least 1e-6 (at most 1000000 fragments)",
            ),
            (
                Some(At::new("key", 1)),
                -1.0,
                Expected::NonNegative("weight"),
                "strength: key 1 is negative (-1)",
            ),
            (
                Some(At::new("key", 1)),
                -1.0,
                Expected::WithinOrInfinite {
                    low: 0.0,
                    high: 1e100,
                },
                "strength: key 1 has strength -1, not in 0..=1e100 or inf",
            ),
            (
                Some(At::new("time", 0)),
                2.0,
                Expected::KeyRange {
                    low: 0.0,
                    high: 1.0,
                },
                "strength: time 0 (2) is outside the key range [0, 1]",
            ),
            (
                Some(At::new("key", 0)),
                0.0,
                Expected::Normalisable(1e-9),
                "strength: key 0 has length 0e0, shorter than 1e-9: it cannot be normalised",
            ),
            (
                Some(At::new("key", 2)),
                f64::INFINITY,
                Expected::FiniteInF32("back"),
                "strength: key 2: back is not finite in float32 (inf)",
            ),
            (
                None,
                f64::NAN,
                Expected::Finite("influence"),
                "strength: influence is not finite (NaN)",
            ),
        ];
        for (at, value, expected, message) in cases {
            let e = Error::Value {
                what: "strength",
                at,
                value,
                expected,
            };
            assert_eq!(e.to_string(), message, "{e:?}");
        }
    }

    #[test]
    fn spacing_tells_order_from_closeness() {
        let at = At::new("key time", 3);
        let e = |gap, min| {
            Error::Spacing {
                what: "key times",
                at,
                gap,
                min,
            }
            .to_string()
        };
        assert_eq!(
            e(-2.0, f64::MIN_POSITIVE),
            "key times: key time 3 is less than the one before (by 2): they must increase strictly"
        );
        assert_eq!(
            e(-2.0, 0.0),
            "key times: key time 3 is less than the one before (by 2): they must be in increasing order"
        );
        assert_eq!(
            e(0.0, f64::MIN_POSITIVE),
            "key times: key time 3 equals the one before: they must increase strictly"
        );
        assert_eq!(
            e(1e-301, 1e-300),
            "key times: key time 3 is 1e-301 after the one before, closer than 1e-300"
        );
    }

    #[test]
    fn an_entry_of_a_batch_wraps_the_error_and_keeps_its_kind() {
        let inner = Error::Memory {
            what: "the keys",
            bytes: 1 << 30,
            budget: Some(1 << 20),
            hint: "use fewer keys",
        };
        let e = inner
            .clone()
            .within("key", 4)
            .within_argument("poses", "owner", 2);
        assert_eq!(e.innermost(), &inner);
        assert_eq!(e.what(), Some("poses"));
        assert!(
            e.to_string()
                .starts_with("poses: owner 2: key 4: the keys would need 1.07 GB"),
            "{e}"
        );
        let limit = Error::Limit {
            what: "keys",
            counted: "keys",
            count: 5,
            limit: 4,
            hint: "",
        };
        assert_eq!(
            limit.to_string(),
            "keys: 5 keys exceed the limit of 4 in one call"
        );
        let index = Error::Index {
            what: "triangles",
            at: Some(At::new("triangle", 12)),
            item: "vertex",
            index: 9,
            len: 8,
        };
        assert_eq!(
            index.within("curve", 0).to_string(),
            "curve 0: triangles: triangle 12: vertex 9 is outside 0..8"
        );
        assert_eq!(
            Error::OutOfRange {
                what: "key time",
                index: 2,
                value: 2e300,
                limit: 1e300
            }
            .to_string(),
            "key time 2 (2e300) is outside the working range +-1e300"
        );
    }
}
