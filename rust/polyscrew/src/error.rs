//! The one error type of the crate: every failure on user data is a variant that says
//! which input was wrong and why. Nothing in the crate panics on user data.

use std::fmt;

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
            Self::Invalid { what, reason } => write!(f, "{what}: {reason}"),
        }
    }
}

impl std::error::Error for Error {}

/// The crate's result type.
pub type Result<T, E = Error> = std::result::Result<T, E>;
