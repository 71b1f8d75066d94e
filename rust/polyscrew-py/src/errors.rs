//! The one place a Python exception is made: polyscrew's exception family and the mapping of
//! the core's errors onto it.
//!
//! Every error polyscrew judges is a `polyscrew.PolyscrewError`, of a subclass that is also
//! the builtin exception callers caught before the family existed (so `except ValueError`
//! keeps working):
//!
//! | class | bases | raised for |
//! | --- | --- | --- |
//! | `InvalidArgument` | `PolyscrewError`, `ValueError` | a wrong value, shape, range or count (every core error but memory) |
//! | `ArgumentTypeError` | `PolyscrewError`, `TypeError` | an argument of the wrong type |
//! | `BudgetExceeded` | `InvalidArgument`, `MemoryError` | a call over the memory budget (refused before allocating) |
//! | `OutOfMemory` | `PolyscrewError`, `MemoryError` | the allocator refused memory within the budget |
//! | `FitFailed` | `PolyscrewError`, `ValueError` | `fit_angular_velocity` did not converge (its `result` attribute holds the best fit) |
//!
//! Errors raised while numpy or the caller's own object converts an argument (numpy's
//! `MemoryError`, a ragged list, an `__array__` that raises) are not polyscrew's judgement:
//! [`named`] keeps their builtin type (`ValueError`, `TypeError`, `MemoryError`) and only
//! puts the function and the argument before the message.

use pyo3::exceptions::{PyException, PyMemoryError, PyTypeError};
use pyo3::prelude::*;
use pyo3::sync::PyOnceLock;
use pyo3::types::{PyDict, PyTuple, PyType};

use polyscrew::memory::Footprint;
use polyscrew::Error;

/// The kinds of error polyscrew raises, one Python class each.
#[derive(Debug, Clone, Copy)]
pub enum Kind {
    /// `InvalidArgument(PolyscrewError, ValueError)`.
    Invalid,
    /// `ArgumentTypeError(PolyscrewError, TypeError)`.
    WrongType,
    /// `BudgetExceeded(InvalidArgument, MemoryError)`.
    Budget,
    /// `OutOfMemory(PolyscrewError, MemoryError)`.
    OutOfMemory,
    /// `FitFailed(PolyscrewError, ValueError)`.
    FitFailed,
}

/// The classes: the base, then one per [`Kind`] (their Python names and docstrings).
const CLASSES: [(&str, &str); 6] = [
    (
        "PolyscrewError",
        "Base of every error polyscrew raises about its arguments or its work.",
    ),
    (
        "InvalidArgument",
        "An argument's value, shape, range or count is wrong (also a ValueError).",
    ),
    (
        "ArgumentTypeError",
        "An argument has the wrong type (also a TypeError).",
    ),
    (
        "BudgetExceeded",
        "The call would need more memory than memory_budget() allows; refused before anything \
         was allocated (an InvalidArgument, so a ValueError, and a MemoryError).",
    ),
    (
        "OutOfMemory",
        "The system refused memory within the budget (also a MemoryError).",
    ),
    (
        "FitFailed",
        "fit_angular_velocity did not converge or stays above delta; the best fit is the \
         exception's `result` attribute (also a ValueError).",
    ),
];

/// The family's classes, made once per interpreter.
struct Family([Py<PyType>; 6]);

static FAMILY: PyOnceLock<Family> = PyOnceLock::new();

/// Makes the classes (`type(name, bases, namespace)`, module `polyscrew`).
fn build(py: Python<'_>) -> PyResult<Family> {
    let make_type = py.import("builtins")?.getattr("type")?;
    let mut made: Vec<Py<PyType>> = Vec::with_capacity(CLASSES.len());
    for (i, (name, doc)) in CLASSES.iter().enumerate() {
        let bases: Vec<Bound<'_, PyAny>> = match i {
            0 => vec![py.get_type::<PyException>().into_any()],
            1 => vec![
                made[0].bind(py).clone().into_any(),
                py.get_type::<pyo3::exceptions::PyValueError>().into_any(),
            ],
            2 => vec![
                made[0].bind(py).clone().into_any(),
                py.get_type::<PyTypeError>().into_any(),
            ],
            3 => vec![
                made[1].bind(py).clone().into_any(),
                py.get_type::<PyMemoryError>().into_any(),
            ],
            4 => vec![
                made[0].bind(py).clone().into_any(),
                py.get_type::<PyMemoryError>().into_any(),
            ],
            _ => vec![
                made[0].bind(py).clone().into_any(),
                py.get_type::<pyo3::exceptions::PyValueError>().into_any(),
            ],
        };
        let namespace = PyDict::new(py);
        namespace.set_item("__module__", "polyscrew")?;
        namespace.set_item("__doc__", *doc)?;
        let class = make_type.call1((*name, PyTuple::new(py, bases)?, namespace))?;
        made.push(class.cast_into::<PyType>()?.unbind());
    }
    let made: [Py<PyType>; 6] = made.try_into().map_err(|_| {
        pyo3::exceptions::PyRuntimeError::new_err("polyscrew: the exception family")
    })?;
    Ok(Family(made))
}

/// The class of `kind`.
fn class(py: Python<'_>, kind: Kind) -> PyResult<Bound<'_, PyType>> {
    let family = FAMILY.get_or_try_init(py, || build(py))?;
    let i = match kind {
        Kind::Invalid => 1,
        Kind::WrongType => 2,
        Kind::Budget => 3,
        Kind::OutOfMemory => 4,
        Kind::FitFailed => 5,
    };
    Ok(family.0[i].bind(py).clone())
}

// stub:
// stub: # --- The exception family: every error polyscrew raises about its arguments or its work ---
// stub:
// stub: class PolyscrewError(Exception):
// stub:     """Base of every error polyscrew raises about its arguments or its work."""
// stub:
// stub: class InvalidArgument(PolyscrewError, ValueError):
// stub:     """An argument's value, shape, range or count is wrong (also a ValueError)."""
// stub:
// stub: class ArgumentTypeError(PolyscrewError, TypeError):
// stub:     """An argument has the wrong type (also a TypeError)."""
// stub:
// stub: class BudgetExceeded(InvalidArgument, MemoryError):
// stub:     """The call would need more memory than memory_budget() allows; refused before anything
// stub:     was allocated (an InvalidArgument, so a ValueError, and a MemoryError)."""
// stub:
// stub: class OutOfMemory(PolyscrewError, MemoryError):
// stub:     """The system refused memory within the budget (also a MemoryError)."""
// stub:
// stub: class FitFailed(PolyscrewError, ValueError):
// stub:     """fit_angular_velocity did not converge or stays above delta; the best fit is the
// stub:     exception's `result` attribute (also a ValueError)."""
// stub:
// stub:     result: AngularVelocityFit
/// Adds the family's classes to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    let py = m.py();
    let family = FAMILY.get_or_try_init(py, || build(py))?;
    for ((name, _), class) in CLASSES.iter().zip(&family.0) {
        m.add(*name, class.bind(py))?;
    }
    Ok(())
}

/// An exception of `kind` with `message` (made when raised: errors are the rare path, and may
/// be made while the GIL is released).
pub fn raise(kind: Kind, message: String) -> PyErr {
    Python::attach(|py| match class(py, kind) {
        Ok(class) => PyErr::from_type(class, message),
        Err(err) => err,
    })
}

/// `InvalidArgument` with `message`.
pub fn invalid(message: String) -> PyErr {
    raise(Kind::Invalid, message)
}

/// `ArgumentTypeError` with `message`.
pub fn wrong_type(message: String) -> PyErr {
    raise(Kind::WrongType, message)
}

/// The one place a core error becomes a Python exception, with the function's name: the
/// class from what went wrong (under any [`Error::In`] layers naming the entry), the message
/// the core's, after `"{function}: "`.
///
/// | core error | class |
/// | --- | --- |
/// | [`Error::Memory`] with no budget (the allocator refused within it) | `OutOfMemory` |
/// | [`Error::Memory`] over the budget | `BudgetExceeded` |
/// | [`Error::FitFailed`] | `FitFailed` |
/// | every other variant (a value, range, shape, count, choice, limit) | `InvalidArgument` |
pub fn to_py_err(function: &str, err: Error) -> PyErr {
    let kind = match err.innermost() {
        Error::Memory { budget: None, .. } => Kind::OutOfMemory,
        Error::Memory { .. } => Kind::Budget,
        Error::FitFailed { .. } => Kind::FitFailed,
        _ => Kind::Invalid,
    };
    raise(kind, format!("{function}: {err}"))
}

/// A core error about argument `what`: `"{function}: {what}: {err}"`.
pub fn arg_err(function: &str, what: &str, err: Error) -> PyErr {
    to_py_err(&format!("{function}: {what}"), err)
}

/// Checks a call's footprint against the memory budget (before anything input-sized is
/// allocated or copied).
pub fn check_budget(
    function: &str,
    footprint: Footprint,
    what: &'static str,
    hint: &'static str,
) -> PyResult<()> {
    footprint
        .check(what, hint)
        .map_err(|e| to_py_err(function, e))
}

/// A shape error naming the argument, what was expected and what came.
pub fn shape_err(function: &str, what: &str, expected: &str, got: &[usize]) -> PyErr {
    invalid(format!(
        "{function}: {what}: expected shape {expected}, got {got:?}"
    ))
}

/// `err` (raised by numpy or the caller's object while an argument was converted) with
/// `"{function}: {what}: "` before its message, as a `MemoryError` (numpy's own allocation
/// failure included), a `TypeError`, or a `ValueError` for any other exception (numpy's
/// exception classes cannot all be rebuilt from one message); the original is its
/// `__cause__`. A `BaseException` that is not an `Exception` (`KeyboardInterrupt`) passes
/// as it is, and so does an error of polyscrew's own family.
pub fn named(py: Python<'_>, function: &str, what: &str, err: PyErr) -> PyErr {
    let message = err.value(py).to_string();
    let prefix = format!("{function}: {what}: ");
    if message.starts_with(&prefix) {
        return err;
    }
    if let Ok(base) = FAMILY.get_or_try_init(py, || build(py)) {
        if err.matches(py, base.0[0].bind(py)).unwrap_or(false) {
            return err;
        }
    }
    let text = format!("{prefix}{message}");
    let renamed = if err.is_instance_of::<PyMemoryError>(py) {
        PyMemoryError::new_err(text)
    } else if err.is_instance_of::<PyTypeError>(py) {
        PyTypeError::new_err(text)
    } else if err.is_instance_of::<PyException>(py) {
        pyo3::exceptions::PyValueError::new_err(text)
    } else {
        return err;
    };
    renamed.set_cause(py, Some(err));
    renamed
}
