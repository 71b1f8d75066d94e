//! Reading arguments with errors that name the function and the argument.
//!
//! Python's conventions are kept (a wrong type is a `TypeError`, a wrong value a
//! `ValueError`), but nothing reaches the caller as an `OverflowError` or with a message that
//! does not say which argument it is about. Array-likes are taken as `&Bound<PyAny>` and read
//! in the function body ([`float_array`], [`int_array`]); scalars with a default are read by
//! `#[pyo3(from_py_with = ...)]` converters generic over a [`Function`] marker (so the
//! message names the function too while the signature keeps its literal default).

use numpy::ndarray::Dimension;
use numpy::{
    Element, PyArrayDescrMethods, PyArrayDyn, PyArrayMethods, PyReadonlyArrayDyn, PyUntypedArray,
    PyUntypedArrayMethods,
};
use pyo3::exceptions::PyOverflowError;

use crate::errors::named;
use pyo3::prelude::*;
use pyo3::types::{PyFloat, PyString};

use polyscrew::memory::{try_vec, Footprint};
use polyscrew::sweep::MAX_STEPS;
use polyscrew::MAX_LEVELS;

/// An array-like argument read as float64 ([`Arg::read`]).
pub type FloatArray<'py> = PyReadonlyArrayDyn<'py, f64>;

/// An integer array-like argument read as int64 ([`Arg::read`]).
pub type IntArray<'py> = PyReadonlyArrayDyn<'py, i64>;

/// A float array-like argument ([`float_array`]), its type and shape known, not yet read.
pub type FloatArg<'py> = Arg<'py, f64>;

/// An integer array-like argument ([`int_array`]), its type and shape known, not yet read.
pub type IntArg<'py> = Arg<'py, i64>;

/// An array-like argument as numpy sees it (its shape and dtype), before any conversion.
///
/// Reading an argument takes two steps so that every byte it costs is in the budget: the
/// function first learns the shapes of its arguments and what converting them will allocate
/// ([`Arg::copy`]: nothing for an array of the right dtype, whatever its strides; a full
/// copy for any other, a broadcast one included), adds that to its footprint and checks the
/// budget; only then does it read them ([`Arg::read`]). A request over the budget is
/// refused before numpy allocates anything for it.
pub struct Arg<'py, T: Element> {
    function: &'static str,
    what: &'static str,
    array: Bound<'py, PyUntypedArray>,
    /// The array itself when numpy holds it as `T` already (read without a copy).
    native: Option<Bound<'py, PyArrayDyn<T>>>,
    copy: Footprint,
}

impl<'py, T: Element> Arg<'py, T> {
    /// Its shape.
    pub fn shape(&self) -> &[usize] {
        self.array.shape()
    }

    /// Its number of dimensions.
    pub fn ndim(&self) -> usize {
        self.array.ndim()
    }

    /// Its number of entries.
    pub fn len(&self) -> usize {
        self.array.len()
    }

    /// What reading it allocates: nothing for an array of the target dtype, numpy's
    /// converted copy otherwise (for integers given as non-float64 floats, the float64
    /// copy their entries are checked on as well).
    pub fn copy(&self) -> Footprint {
        self.copy
    }

    /// The copy made by reading, checked alone against the budget (the function checked it
    /// within its footprint already: this keeps a reader that forgot within the budget).
    fn check_copy(&self, what: &'static str, hint: &'static str) -> PyResult<()> {
        self.copy
            .check(what, hint)
            .map_err(|e| crate::errors::arg_err(self.function, self.what, e))
    }

    /// `err` named after the function and the argument.
    fn named(&self, err: PyErr) -> PyErr {
        named(self.array.py(), self.function, self.what, err)
    }

    /// The array converted by numpy to `dtype` (after the budget's check).
    fn converted(&self, dtype: &str) -> PyResult<Bound<'py, PyAny>> {
        self.array
            .call_method1("astype", (dtype,))
            .map_err(|e| self.named(e))
    }
}

/// The copies of an optional argument ([`Arg::copy`]; nothing when it is absent).
pub fn copy_of<T: Element>(arg: Option<&Arg<'_, T>>) -> Footprint {
    arg.map_or(Footprint::ZERO, Arg::copy)
}

impl<'py> Arg<'py, f64> {
    /// The argument as float64: as it is for a float64 array, converted by numpy otherwise.
    /// numpy's own failures (its `MemoryError` included) come out naming the function and
    /// the argument.
    pub fn read(&self) -> PyResult<FloatArray<'py>> {
        if let Some(array) = &self.native {
            return array.try_readonly().map_err(|e| self.named(e.into()));
        }
        self.check_copy("the float64 conversion", "pass fewer values")?;
        let converted = self.converted("float64")?;
        let array = converted
            .cast::<PyArrayDyn<f64>>()
            .map_err(|e| self.named(e.into()))?;
        array.try_readonly().map_err(|e| self.named(e.into()))
    }
}

impl<'py> Arg<'py, i64> {
    /// The argument as int64: as it is for an int64 array, other integers converted, floats
    /// only when every entry is a whole number (`2.0`, not `2.7`, which is a `ValueError`
    /// naming the entry). Failures named as [`Arg::read`] of a float array names them.
    pub fn read(&self) -> PyResult<IntArray<'py>> {
        if let Some(array) = &self.native {
            return array.try_readonly().map_err(|e| self.named(e.into()));
        }
        self.check_copy("the integer conversion", "pass fewer entries")?;
        if self.array.dtype().kind() == b'f' {
            let floats = match self.array.cast::<PyArrayDyn<f64>>() {
                Ok(a) => a.readonly(),
                Err(_) => self
                    .converted("float64")?
                    .cast_into::<PyArrayDyn<f64>>()
                    .map_err(|e| self.named(e.into()))?
                    .readonly(),
            };
            let view = floats.as_array();
            if let Some((index, value)) = view
                .indexed_iter()
                .find(|(_, v)| !(v.fract() == 0.0 && v.abs() < 9.2e18))
            {
                return Err(crate::errors::invalid(format!(
                    "{}: {}: entry {:?} is {value}, not an integer",
                    self.function,
                    self.what,
                    index.slice()
                )));
            }
        }
        let converted = self.converted("int64")?;
        let array = converted
            .cast::<PyArrayDyn<i64>>()
            .map_err(|e| self.named(e.into()))?;
        array.try_readonly().map_err(|e| self.named(e.into()))
    }
}

/// Takes `obj` as a numpy array: a numpy array as it is, anything else through
/// `numpy.asarray` (a Python sequence becomes an array no larger than the sequence itself).
fn untyped<'py>(
    function: &str,
    what: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyUntypedArray>> {
    if let Ok(array) = obj.cast::<PyUntypedArray>() {
        return Ok(array.clone());
    }
    as_numpy(function, what, obj)?
        .cast_into::<PyUntypedArray>()
        .map_err(|e| named(obj.py(), function, what, e.into()))
}

/// A Python function of the module, for the messages of the argument converters.
pub trait Function {
    /// Its Python name.
    const NAME: &'static str;
}

macro_rules! functions {
    ($($ty:ident = $name:literal),* $(,)?) => {
        $(
            #[doc = concat!("`", $name, "`.")]
            pub struct $ty;
            impl Function for $ty {
                const NAME: &'static str = $name;
            }
        )*
    };
}

functions!(
    Subdivide = "subdivide",
    Sample = "sample",
    SampleChannels = "sample_channels",
    SubdivideVectors = "subdivide_vectors",
    SampleVectors = "sample_vectors",
    FeatureMotion = "feature_motion",
    SampleFeature = "sample_feature",
    Sweep = "sweep",
    FitAngularVelocity = "fit_angular_velocity",
    KeysParameters = "keys_parameters",
    TimedFrames = "timed_frames",
    RotationChannels = "rotation_channels",
    RotationChannelsNear = "rotation_channels_near",
    RotationChannelsEach = "rotation_channels_each",
    TurnVectors = "turn_vectors",
    AnglesNear = "angles_near",
    SameRotationMap = "same_rotation_map",
    DirectionSteps = "direction_steps",
    PartialMoves = "partial_moves",
    RotationMatrices = "rotation_matrices",
    PlaybackNew = "Playback",
    AnalyseSpans = "analyse_spans",
    AnalyseTurns = "analyse_turns",
    ReduceKeys = "reduce_keys",
    SampleOwners = "sample_owners",
    AnglesNearMany = "angles_near_many",
    PartialMovesMany = "partial_moves_many",
    SampleMany = "sample_many",
    ChannelsMany = "channels_many",
    ReadOwners = "read_owners",
    MeasureDepartures = "measure_departures",
);

/// The name of `obj`'s type, for messages.
pub fn type_name(obj: &Bound<'_, PyAny>) -> String {
    obj.get_type()
        .name()
        .map_or_else(|_| "?".to_owned(), |n| n.to_string())
}

/// Takes a float array-like for reading ([`Arg::read`]): float64 arrays as they are, other
/// real numbers (ints, bools, float32, nested lists) to be converted; complex, strings and
/// objects refused with a `TypeError`, ragged lists with numpy's `ValueError`, each naming
/// the argument. Nothing is converted yet: [`Arg::copy`] says what the conversion will cost.
pub fn float_array<'py>(
    function: &'static str,
    what: &'static str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<FloatArg<'py>> {
    let array = untyped(function, what, obj)?;
    let native = array.cast::<PyArrayDyn<f64>>().ok().cloned();
    if native.is_none() && !matches!(array.dtype().kind(), b'b' | b'i' | b'u' | b'f') {
        return Err(crate::errors::wrong_type(format!(
            "{function}: {what}: expected real numbers, got {}",
            dtype_name(array.as_any())
        )));
    }
    let copy = if native.is_some() {
        Footprint::ZERO
    } else {
        Footprint::of::<f64>(array.len())
    };
    Ok(Arg {
        function,
        what,
        array,
        native,
        copy,
    })
}

/// Takes an integer array-like for reading ([`Arg::read`]): integer arrays, and float
/// arrays whose entries are whole numbers (checked when read; the int64 copy of floats is
/// checked against the budget here already); anything else a `TypeError`.
pub fn int_array<'py>(
    function: &'static str,
    what: &'static str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<IntArg<'py>> {
    let array = untyped(function, what, obj)?;
    let native = array.cast::<PyArrayDyn<i64>>().ok().cloned();
    let n = array.len();
    let copy = match array.dtype().kind() {
        _ if native.is_some() => Footprint::ZERO,
        b'i' | b'u' => Footprint::of::<i64>(n),
        b'f' => {
            // the int64 copy, checked before the entries are even scanned
            Footprint::of::<i64>(n)
                .check("the integer conversion", "pass fewer entries")
                .map_err(|e| crate::errors::arg_err(function, what, e))?;
            let floats = array.cast::<PyArrayDyn<f64>>().is_ok();
            Footprint::of::<i64>(n).and::<f64>(if floats { 0 } else { n })
        }
        _ => {
            return Err(crate::errors::wrong_type(format!(
                "{function}: {what}: expected integers, got {}",
                dtype_name(array.as_any())
            )))
        }
    };
    Ok(Arg {
        function,
        what,
        array,
        native,
        copy,
    })
}

/// Refuses a sequence (a numpy array: its first axis) of more than `max` entries before
/// anything reads it: converting or extracting it would reserve room for all of them
/// first (`range(2**62)`). Objects without a length pass (numpy or the reader judges them).
fn check_len(function: &str, what: &str, obj: &Bound<'_, PyAny>, max: Most) -> PyResult<()> {
    if obj.is_instance_of::<PyString>() {
        return Ok(());
    }
    let Ok(len) = obj.call_method0("__len__") else {
        return Ok(());
    };
    match len.extract::<usize>() {
        Ok(n) if n <= max.count() => Ok(()),
        _ => Err(too_long(
            function,
            what,
            max,
            len.str().map_or_else(|_| "?".to_owned(), |s| s.to_string()),
        )),
    }
}

/// How many entries a sequence argument may have.
#[derive(Debug, Clone, Copy)]
pub enum Most {
    /// Exactly this many (fewer are the caller's error).
    Exactly(usize),
    /// At most this many.
    AtMost(usize),
}

impl Most {
    fn count(self) -> usize {
        match self {
            Self::Exactly(n) | Self::AtMost(n) => n,
        }
    }
}

/// The `ValueError` of a sequence longer than `max`: `"{what}: expected (at most) {max}
/// entries, got {len}"`.
fn too_long(function: &str, what: &str, max: Most, len: String) -> PyErr {
    let expected = match max {
        Most::Exactly(n) => n.to_string(),
        Most::AtMost(n) => format!("at most {n}"),
    };
    crate::errors::invalid(format!(
        "{function}: {what}: expected {expected} entries, got {len}"
    ))
}

/// Reads a sequence of at most `max` Python objects (a `ValueError` for more, checked before
/// anything is reserved for them; a `TypeError` for a str or anything that is not a
/// sequence, the message saying it `expected` ...).
pub fn sequence<'py>(
    function: &str,
    what: &str,
    obj: &Bound<'py, PyAny>,
    max: Most,
    expected: &str,
) -> PyResult<Vec<Bound<'py, PyAny>>> {
    let not_a_sequence = || {
        crate::errors::wrong_type(format!(
            "{function}: {what}: expected {expected}, got {}",
            type_name(obj)
        ))
    };
    if obj.is_instance_of::<PyString>() {
        return Err(not_a_sequence());
    }
    let seq = obj
        .cast::<pyo3::types::PySequence>()
        .map_err(|_| not_a_sequence())?;
    check_len(function, what, obj, max)?;
    let n = seq.len().map_err(|e| named(obj.py(), function, what, e))?;
    let mut out =
        try_vec(n, "input sequence").map_err(|e| crate::errors::to_py_err(function, e))?;
    for i in 0..n {
        out.push(
            seq.get_item(i)
                .map_err(|e| named(obj.py(), function, what, e))?,
        );
    }
    Ok(out)
}

/// Reads a boolean array-like through numpy, copied within the memory budget: its shape and
/// its entries in row-major order, or `None` when its entries are not booleans (the caller
/// may read it as something else). A sequence of more than `max_len` entries is refused
/// before numpy reads it.
pub fn bool_array(
    function: &str,
    what: &str,
    obj: &Bound<'_, PyAny>,
    max_len: Most,
) -> PyResult<Option<(Vec<usize>, Vec<bool>)>> {
    check_len(function, what, obj, max_len)?;
    let array = as_numpy(function, what, obj)?;
    if dtype_kind(&array)? != 'b' {
        return Ok(None);
    }
    let array = array
        .cast_into::<PyArrayDyn<bool>>()
        .map_err(|e| named(obj.py(), function, what, e.into()))?;
    let shape = array.shape().to_vec();
    let total = array.len();
    Footprint::of::<bool>(total)
        .check("the boolean mask", "pass a smaller mask")
        .map_err(|e| crate::errors::to_py_err(function, e))?;
    let readonly = array.readonly();
    let mut out =
        try_vec(total, "boolean mask").map_err(|e| crate::errors::to_py_err(function, e))?;
    out.extend(readonly.as_array().iter().copied());
    Ok(Some((shape, out)))
}

/// Reads a 1-D integer array-like of at most `max_len` entries ([`int_array`]'s rules),
/// copied within the memory budget; the length is checked before numpy reads a sequence.
pub fn int_list(
    function: &'static str,
    what: &'static str,
    obj: &Bound<'_, PyAny>,
    max_len: Most,
) -> PyResult<Vec<i64>> {
    check_len(function, what, obj, max_len)?;
    let array = int_array(function, what, obj)?;
    if array.ndim() != 1 {
        return Err(crate::errors::shape_err(
            function,
            what,
            "(N,)",
            array.shape(),
        ));
    }
    if array.len() > max_len.count() {
        return Err(too_long(function, what, max_len, array.len().to_string()));
    }
    let array = array.read()?;
    let view = array.as_array();
    let mut out =
        try_vec(view.len(), "input integers").map_err(|e| crate::errors::to_py_err(function, e))?;
    out.extend(view.iter().copied());
    Ok(out)
}

fn as_numpy<'py>(
    function: &str,
    what: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    let py = obj.py();
    py.import("numpy")?
        .call_method1("asarray", (obj,))
        .map_err(|e| named(py, function, what, e))
}

fn dtype_kind(array: &Bound<'_, PyAny>) -> PyResult<char> {
    array.getattr("dtype")?.getattr("kind")?.extract::<char>()
}

fn dtype_name(array: &Bound<'_, PyAny>) -> String {
    array
        .getattr("dtype")
        .and_then(|d| d.str())
        .map_or_else(|_| "?".to_owned(), |s| s.to_string())
}

/// Reads a real number: ints (any size that fits a float), floats and numpy scalars; a
/// `ValueError` for an int too large for a float, a `TypeError` for anything else.
pub fn float_scalar(function: &str, what: &str, obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    obj.extract::<f64>().map_err(|e| {
        if e.is_instance_of::<PyOverflowError>(obj.py()) {
            crate::errors::invalid(format!(
                "{function}: {what}: {} is too large for a float",
                obj.str().map_or_else(|_| "?".to_owned(), |s| s.to_string())
            ))
        } else {
            crate::errors::wrong_type(format!(
                "{function}: {what}: expected a real number, got {}",
                type_name(obj)
            ))
        }
    })
}

/// An optional real number (`None` stays `None`).
pub fn optional_float(
    function: &str,
    what: &str,
    obj: Option<&Bound<'_, PyAny>>,
) -> PyResult<Option<f64>> {
    match obj {
        Some(o) if !o.is_none() => float_scalar(function, what, o).map(Some),
        _ => Ok(None),
    }
}

/// An optional float array-like ([`float_array`]): None (or Python's None) when not given.
pub fn optional_float_array<'py>(
    function: &'static str,
    what: &'static str,
    obj: Option<&Bound<'py, PyAny>>,
) -> PyResult<Option<FloatArg<'py>>> {
    obj.filter(|o| !o.is_none())
        .map(|o| float_array(function, what, o))
        .transpose()
}

/// An int in `lo..=hi`: a `ValueError` naming the argument, the value and the range for any
/// int outside it (huge ones included), a `TypeError` for a float or any other type.
pub fn int_in(
    function: &str,
    what: &str,
    obj: &Bound<'_, PyAny>,
    lo: i64,
    hi: i64,
) -> PyResult<i64> {
    let out_of_range = |shown: String| {
        crate::errors::invalid(format!(
            "{function}: {what} {shown} out of range {lo}..={hi}"
        ))
    };
    if obj.is_instance_of::<PyFloat>() {
        return Err(crate::errors::wrong_type(format!(
            "{function}: {what}: expected an int, got float {}",
            obj.str().map_or_else(|_| "?".to_owned(), |s| s.to_string())
        )));
    }
    match obj.extract::<i64>() {
        Ok(v) if (lo..=hi).contains(&v) => Ok(v),
        Ok(v) => Err(out_of_range(v.to_string())),
        Err(e) if e.is_instance_of::<PyOverflowError>(obj.py()) => Err(out_of_range(
            obj.str().map_or_else(|_| "?".to_owned(), |s| s.to_string()),
        )),
        Err(_) => Err(crate::errors::wrong_type(format!(
            "{function}: {what}: expected an int, got {}",
            type_name(obj)
        ))),
    }
}

/// `levels` in `0..=MAX_LEVELS`.
pub fn levels<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<u32> {
    int_in(F::NAME, "levels", obj, 0, i64::from(MAX_LEVELS)).map(|v| v as u32)
}

/// `steps` in `1..=MAX_STEPS`.
pub fn steps<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<u32> {
    int_in(F::NAME, "steps", obj, 1, i64::from(MAX_STEPS)).map(|v| v as u32)
}

/// `max_iterations` in `1..=MAX_ITERATIONS`.
pub fn max_iterations<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    let max = polyscrew::angular_velocity::MAX_ITERATIONS as i64;
    int_in(F::NAME, "max_iterations", obj, 1, max).map(|v| v as usize)
}

/// `max_frames` in `0..=MAX_ITERATIONS`.
pub fn max_frames<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    let max = polyscrew::angular_velocity::MAX_ITERATIONS as i64;
    int_in(F::NAME, "max_frames", obj, 0, max).map(|v| v as usize)
}

/// `alpha`, a real number (its range is checked by the core).
pub fn alpha<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    float_scalar(F::NAME, "alpha", obj)
}

/// `delta`, a real number (its range is checked by the core).
pub fn delta<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<f64> {
    float_scalar(F::NAME, "delta", obj)
}

/// A bool argument.
pub fn bool_arg(function: &str, what: &str, obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    obj.extract::<bool>().map_err(|_| {
        crate::errors::wrong_type(format!(
            "{function}: {what}: expected a bool, got {}",
            type_name(obj)
        ))
    })
}

/// `closed`, a bool.
pub fn closed<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    bool_arg(F::NAME, "closed", obj)
}

/// `caps`, a bool.
pub fn caps<F: Function>(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    bool_arg(F::NAME, "caps", obj)
}

/// A str argument, borrowed.
pub fn str_arg<'a>(function: &str, what: &str, obj: &'a Bound<'_, PyAny>) -> PyResult<&'a str> {
    obj.cast::<PyString>()
        .map_err(|_| {
            crate::errors::wrong_type(format!(
                "{function}: {what}: expected a str, got {}",
                type_name(obj)
            ))
        })?
        .to_str()
}

/// A core enumeration that a Python argument names by a str ([`Choice`]).
pub trait Named: Sized + Copy {
    /// The argument's name in messages (`"scheme"`).
    const ARG: &'static str;
    /// The value called `name` (the core's parser and its error).
    fn from_name(name: &str) -> Result<Self, polyscrew::Error>;
}

macro_rules! named {
    ($($ty:ty = $arg:literal),* $(,)?) => {
        $(
            impl Named for $ty {
                const ARG: &'static str = $arg;
                fn from_name(name: &str) -> Result<Self, polyscrew::Error> {
                    <$ty>::from_name(name)
                }
            }
        )*
    };
}

named!(
    polyscrew::Scheme = "scheme",
    polyscrew::Timing = "timing",
    polyscrew::RotationMode = "mode",
    polyscrew::CurveScheme = "scheme",
    polyscrew::Parametrization = "parametrization",
    polyscrew::intent::Turns = "turns",
    polyscrew::reduce::Between = "between",
);

/// An enumeration argument of function `F`, parsed when pyo3 extracts it: a str naming one
/// of the core's values (`"jarek"`), or an `ArgumentTypeError` (`"{function}: {arg}:
/// expected a str, got int"`) / `InvalidArgument` (`"{function}: {arg}: \"x\" is not one
/// of ..."`, the core's message) naming the function and the argument. One implementation
/// for every enumeration, so every one fails the same way.
pub struct Choice<F: Function, T: Named>(pub T, std::marker::PhantomData<F>);

impl<F: Function, T: Named> Choice<F, T> {
    /// The choice `value` (a default in a `#[pyo3(signature)]`).
    pub const fn of(value: T) -> Self {
        Self(value, std::marker::PhantomData)
    }
}

impl<'a, 'py, F: Function, T: Named> FromPyObject<'a, 'py> for Choice<F, T> {
    type Error = PyErr;

    fn extract(obj: Borrowed<'a, 'py, PyAny>) -> PyResult<Self> {
        let name = str_arg(F::NAME, T::ARG, &obj)?;
        T::from_name(name)
            .map(Self::of)
            .map_err(|e| crate::errors::to_py_err(F::NAME, e))
    }
}

/// An optional per-owner flag of `function` (nonzero: set), `owners` long, `default` for
/// every owner when not given (or None).
pub fn per_owner_flags(
    function: &'static str,
    what: &'static str,
    obj: Option<&Bound<'_, PyAny>>,
    owners: usize,
    default: bool,
) -> PyResult<Vec<bool>> {
    let Some(obj) = obj.filter(|o| !o.is_none()) else {
        return Ok(vec![default; owners]);
    };
    let arg = int_array(function, what, obj)?;
    if arg.shape() != [owners] {
        return Err(crate::errors::shape_err(
            function,
            what,
            &format!("({owners},)"),
            arg.shape(),
        ));
    }
    let array = arg.read()?;
    Ok(array.as_array().iter().map(|&v| v != 0).collect())
}
