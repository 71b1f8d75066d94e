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
    /// A value outside the working range in which the formulas stay finite.
    OutOfRange {
        /// What the value is (for example `"key time"`).
        what: &'static str,
        /// Its index.
        index: usize,
        /// The value.
        value: f64,
        /// The working range, for the message (for example `"+-1e300"`).
        range: &'static str,
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
    /// A free-form invalid argument, with the argument's name and the reason.
    Invalid {
        /// The argument.
        what: &'static str,
        /// Why it is invalid.
        reason: String,
    },
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
                range,
            } => write!(
                f,
                "{what} {index} ({value:e}) is outside the working range {range}"
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
            Self::Invalid { what, reason } => write!(f, "{what}: {reason}"),
        }
    }
}

impl std::error::Error for Error {}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
