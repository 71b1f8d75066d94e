//! Binding of Blender's F-curve evaluation (`polyscrew::fcurve`): conversion only.
//!
//! Enumerations cross the boundary by name: per-curve settings as the RNA identifiers
//! (`"LINEAR"`, `"REPEAT_OFFSET"`), per-key ones as integer codes that index the name tuples
//! the module exports (`INTERPOLATIONS`, `EASINGS`), so that a whole array of keys is one
//! integer array and its meaning is still fixed by names, never by Blender's internal values.

use numpy::ndarray::{Array2, ArrayViewD};
use numpy::{IntoPyArray, PyArray2};
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyString, PyTuple};

use polyscrew::fcurve::{
    check_batch_with, evaluate_packed, key::DEFAULT_AMPLITUDE, key::DEFAULT_BACK,
    key::DEFAULT_PERIOD, packed_footprint, CycleMode, Cycles, Easing, Extrapolation, FrameRange,
    Interpolation, PackedCurves, MAX_KEYS, MAX_VALUES,
};
use polyscrew::memory::{try_vec, Footprint};

use crate::args::{self, copy_of, float_array, int_array, FloatArray, IntArray, Most};
use crate::arrays::{read_vector, vector_len};
use crate::errors::{shape_err, to_py_err};

const F: &str = "evaluate_fcurves";

/// Reads `(K, 2)` pairs, flattened (allocated fallibly: the caller checked the budget).
fn read_pairs(f: &str, what: &str, array: ArrayViewD<'_, f64>) -> PyResult<Vec<f64>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 2 {
        return Err(shape_err(f, what, "(K, 2)", shape));
    }
    let mut out = try_vec(array.len(), "input pairs").map_err(|e| to_py_err(f, e))?;
    out.extend(array.iter().copied());
    Ok(out)
}

/// Reads a 1-D integer array (allocated fallibly: the caller checked the budget).
fn read_ints(f: &str, what: &str, array: ArrayViewD<'_, i64>) -> PyResult<Vec<i64>> {
    if array.ndim() != 1 {
        return Err(shape_err(f, what, "(N,)", array.shape()));
    }
    let mut out = try_vec(array.len(), "input integers").map_err(|e| to_py_err(f, e))?;
    out.extend(array.iter().copied());
    Ok(out)
}

/// `n` copies of `value`, allocated fallibly.
fn filled<T: Clone>(f: &str, value: T, n: usize, what: &'static str) -> PyResult<Vec<T>> {
    let mut out = try_vec(n, what).map_err(|e| to_py_err(f, e))?;
    out.resize(n, value);
    Ok(out)
}

/// One extrapolation name for every curve, or a sequence of `c` names (more are refused
/// before anything is reserved for them).
fn read_extrapolation(f: &str, arg: &Bound<'_, PyAny>, c: usize) -> PyResult<Vec<Extrapolation>> {
    let parse = |name: &str| Extrapolation::from_name(name).map_err(|e| to_py_err(f, e));
    if let Ok(name) = arg.cast::<PyString>() {
        return filled(f, parse(name.to_str()?)?, c, "extrapolations");
    }
    let expected = "a name or a sequence of names";
    let items = args::sequence(f, "extrapolation", arg, Most::Exactly(c), expected)?;
    let mut out = try_vec(items.len(), "extrapolations").map_err(|e| to_py_err(f, e))?;
    for item in &items {
        let name = item.cast::<PyString>().map_err(|_| {
            crate::errors::wrong_type(format!("{f}: extrapolation: expected {expected}"))
        })?;
        out.push(parse(name.to_str()?)?);
    }
    Ok(out)
}

/// The keys a Cycles settings dict may hold: the RNA property names of `FModifierCycles`.
const CYCLES_KEYS: [&str; 11] = [
    "mode_before",
    "mode_after",
    "cycles_before",
    "cycles_after",
    "use_restricted_range",
    "frame_start",
    "frame_end",
    "blend_in",
    "blend_out",
    "use_influence",
    "influence",
];

/// Reads one Cycles settings dict (named as Blender's RNA properties; missing entries take
/// the defaults of a new modifier).
fn read_cycles(f: &str, c: usize, dict: &Bound<'_, PyDict>) -> PyResult<Cycles> {
    let err = |reason: String| crate::errors::invalid(format!("{f}: cycles[{c}]: {reason}"));
    for key in dict.keys() {
        let key: String = key.extract().map_err(|_| {
            crate::errors::wrong_type(format!(
                "{f}: cycles[{c}]: setting names must be str, got {}",
                key.get_type()
                    .name()
                    .map_or_else(|_| "?".to_owned(), |n| n.to_string())
            ))
        })?;
        if !CYCLES_KEYS.contains(&key.as_str()) {
            return Err(err(format!(
                "unknown setting {key:?} (expected some of {})",
                CYCLES_KEYS.join(", ")
            )));
        }
    }
    fn get<'py, T: FromPyObjectOwned<'py>>(
        dict: &Bound<'py, PyDict>,
        key: &str,
        default: T,
        err: &dyn Fn(String) -> PyErr,
    ) -> PyResult<T> {
        match dict.get_item(key)? {
            Some(v) => v
                .extract::<T>()
                .map_err(|e| err(format!("{key}: {}", Into::<PyErr>::into(e)))),
            None => Ok(default),
        }
    }
    let mode = |key: &str| -> PyResult<CycleMode> {
        let name: String = get(dict, key, "REPEAT".to_string(), &err)?;
        CycleMode::from_name(&name).map_err(|e| err(format!("{key}: {e}")))
    };
    let count = |key: &str| -> PyResult<i32> {
        let n: i64 = get(dict, key, 0, &err)?;
        i32::try_from(n).map_err(|_| err(format!("{key}: {n} is out of range")))
    };
    let num = |key: &str, default: f32| -> PyResult<f32> {
        Ok(get(dict, key, default as f64, &err)? as f32)
    };
    let range = if get(dict, "use_restricted_range", false, &err)? {
        Some(FrameRange {
            start: num("frame_start", 0.0)?,
            end: num("frame_end", 0.0)?,
            blend_in: num("blend_in", 0.0)?,
            blend_out: num("blend_out", 0.0)?,
        })
    } else {
        None
    };
    let influence = if get(dict, "use_influence", false, &err)? {
        Some(num("influence", 1.0)?)
    } else {
        None
    };
    let cycles = Cycles {
        before: mode("mode_before")?,
        after: mode("mode_after")?,
        count_before: count("cycles_before")?,
        count_after: count("cycles_after")?,
        range,
        influence,
    };
    cycles.validate().map_err(|e| err(e.to_string()))?;
    Ok(cycles)
}

/// `None`, or a sequence of `c` entries each a settings dict or `None`.
fn read_cycles_list(
    f: &str,
    arg: Option<&Bound<'_, PyAny>>,
    c: usize,
) -> PyResult<Vec<Option<Cycles>>> {
    let Some(arg) = arg.filter(|a| !a.is_none()) else {
        return Ok(Vec::new());
    };
    let items = args::sequence(
        f,
        "cycles",
        arg,
        Most::Exactly(c),
        "a sequence of dicts or None, one per curve",
    )?;
    if items.len() != c {
        return Err(crate::errors::invalid(format!(
            "{f}: cycles: expected {c} entries (one per curve), got {}",
            items.len()
        )));
    }
    items
        .iter()
        .enumerate()
        .map(|(i, item)| {
            if item.is_none() {
                return Ok(None);
            }
            let dict = item.cast::<PyDict>().map_err(|_| {
                crate::errors::wrong_type(format!("{f}: cycles[{i}]: expected a dict or None"))
            })?;
            read_cycles(f, i, dict).map(Some)
        })
        .collect()
}

/// The packed curves' arguments of `evaluate_fcurves`, checked against the budget and read
/// (numpy's conversions done, nothing copied yet): shared with the functions that take the
/// same curves (`Playback`). [`CurveInput::views`] and [`CurveViews::to_args`] copy them
/// with the GIL released.
pub(crate) struct CurveInput<'py> {
    function: &'static str,
    k: usize,
    offsets: IntArray<'py>,
    co: FloatArray<'py>,
    handle_left: FloatArray<'py>,
    handle_right: FloatArray<'py>,
    interpolation: IntArray<'py>,
    easing: IntArray<'py>,
    back: Option<FloatArray<'py>>,
    amplitude: Option<FloatArray<'py>>,
    period: Option<FloatArray<'py>>,
    extrapolation: Vec<Extrapolation>,
    cycles: Vec<Option<Cycles>>,
}

/// Views of a [`CurveInput`]'s arrays: what the copies read, without the GIL.
pub(crate) struct CurveViews<'a> {
    function: &'static str,
    k: usize,
    offsets: ArrayViewD<'a, i64>,
    co: ArrayViewD<'a, f64>,
    handle_left: ArrayViewD<'a, f64>,
    handle_right: ArrayViewD<'a, f64>,
    interpolation: ArrayViewD<'a, i64>,
    easing: ArrayViewD<'a, i64>,
    back: Option<ArrayViewD<'a, f64>>,
    amplitude: Option<ArrayViewD<'a, f64>>,
    period: Option<ArrayViewD<'a, f64>>,
    extrapolation: &'a [Extrapolation],
    cycles: &'a [Option<Cycles>],
}

/// The packed curves' arguments, copied: what [`CurveArgs::packed`] lends the core.
pub(crate) struct CurveArgs<'a> {
    offsets: Vec<i64>,
    co: Vec<f64>,
    handle_left: Vec<f64>,
    handle_right: Vec<f64>,
    interpolation: Vec<i64>,
    easing: Vec<i64>,
    back: Vec<f64>,
    amplitude: Vec<f64>,
    period: Vec<f64>,
    extrapolation: &'a [Extrapolation],
    cycles: &'a [Option<Cycles>],
}

impl<'py> CurveInput<'py> {
    /// Reads the arguments (errors name `function` and the argument): every array through
    /// the module's readers ([`float_array`], [`int_array`]: no silent casts), then the
    /// batch's sizes and everything the call will hold (the core's [`check_batch_with`]:
    /// the copies [`CurveViews::to_args`] makes, `extra` bytes more the caller holds and the
    /// evaluation at `times` times) checked before anything is converted or copied.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn read(
        function: &'static str,
        times: usize,
        extra: Footprint,
        offsets: &Bound<'py, PyAny>,
        co: &Bound<'py, PyAny>,
        handle_left: &Bound<'py, PyAny>,
        handle_right: &Bound<'py, PyAny>,
        interpolation: &Bound<'py, PyAny>,
        easing: &Bound<'py, PyAny>,
        extrapolation: Option<&Bound<'py, PyAny>>,
        back: Option<&Bound<'py, PyAny>>,
        amplitude: Option<&Bound<'py, PyAny>>,
        period: Option<&Bound<'py, PyAny>>,
        cycles: Option<&Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        let f = function;
        let offsets = int_array(f, "offsets", offsets)?;
        let co = float_array(f, "co", co)?;
        let handle_left = float_array(f, "handle_left", handle_left)?;
        let handle_right = float_array(f, "handle_right", handle_right)?;
        let interpolation = int_array(f, "interpolation", interpolation)?;
        let easing = int_array(f, "easing", easing)?;
        let back = args::optional_float_array(f, "back", back)?;
        let amplitude = args::optional_float_array(f, "amplitude", amplitude)?;
        let period = args::optional_float_array(f, "period", period)?;

        if offsets.ndim() != 1 {
            return Err(shape_err(f, "offsets", "(N,)", offsets.shape()));
        }
        let c = offsets.len().saturating_sub(1);
        let shape = co.shape();
        if shape.len() != 2 || shape[1] != 2 {
            return Err(shape_err(f, "co", "(K, 2)", shape));
        }
        let k = shape[0];
        // What is copied here: the packed arrays of `c` curves at the length of the longest
        // given (a wrong length is the core's error, found after the copy).
        let pairs = [&co, &handle_left, &handle_right]
            .into_iter()
            .map(|a| a.len().div_ceil(2));
        let singles = [&interpolation, &easing]
            .into_iter()
            .map(|a| a.len())
            .chain(
                [&back, &amplitude, &period]
                    .into_iter()
                    .map(|a| a.as_ref().map_or(0, |a| a.len())),
            );
        let rows = pairs.chain(singles).fold(k, usize::max);
        // ... and numpy's conversions of the arguments that are not of their dtype already
        let conversions = [&co, &handle_left, &handle_right]
            .into_iter()
            .map(|a| a.copy())
            .chain(
                [&offsets, &interpolation, &easing]
                    .into_iter()
                    .map(|a| a.copy()),
            )
            .chain(
                [&back, &amplitude, &period]
                    .into_iter()
                    .map(|a| copy_of(a.as_ref())),
            )
            .sum::<Footprint>();
        let copies = packed_footprint(c, rows) + conversions;
        check_batch_with(c, k, times, copies + extra).map_err(|e| to_py_err(f, e))?;

        Ok(Self {
            function,
            k,
            offsets: offsets.read()?,
            co: co.read()?,
            handle_left: handle_left.read()?,
            handle_right: handle_right.read()?,
            interpolation: interpolation.read()?,
            easing: easing.read()?,
            back: back.as_ref().map(|a| a.read()).transpose()?,
            amplitude: amplitude.as_ref().map(|a| a.read()).transpose()?,
            period: period.as_ref().map(|a| a.read()).transpose()?,
            extrapolation: match extrapolation.filter(|e| !e.is_none()) {
                Some(e) => read_extrapolation(f, e, c)?,
                None => filled(f, Extrapolation::Constant, c, "extrapolations")?,
            },
            cycles: read_cycles_list(f, cycles, c)?,
        })
    }

    /// Views of the arrays, to copy without the GIL.
    pub(crate) fn views(&self) -> CurveViews<'_> {
        CurveViews {
            function: self.function,
            k: self.k,
            offsets: self.offsets.as_array(),
            co: self.co.as_array(),
            handle_left: self.handle_left.as_array(),
            handle_right: self.handle_right.as_array(),
            interpolation: self.interpolation.as_array(),
            easing: self.easing.as_array(),
            back: self.back.as_ref().map(|a| a.as_array()),
            amplitude: self.amplitude.as_ref().map(|a| a.as_array()),
            period: self.period.as_ref().map(|a| a.as_array()),
            extrapolation: &self.extrapolation,
            cycles: &self.cycles,
        }
    }
}

impl<'a> CurveViews<'a> {
    /// The arrays copied (allocated fallibly, no GIL needed: the budget was checked by
    /// [`CurveInput::read`]); the per-key arrays not given are Blender's defaults.
    pub(crate) fn to_args(&self) -> PyResult<CurveArgs<'a>> {
        let (f, k) = (self.function, self.k);
        let per_key = |what, a: &Option<ArrayViewD<'_, f64>>, default: f32| match a {
            Some(a) => read_vector(f, what, a),
            None => filled(f, default as f64, k, "per-key values"),
        };
        Ok(CurveArgs {
            offsets: read_ints(f, "offsets", self.offsets.view())?,
            co: read_pairs(f, "co", self.co.view())?,
            handle_left: read_pairs(f, "handle_left", self.handle_left.view())?,
            handle_right: read_pairs(f, "handle_right", self.handle_right.view())?,
            interpolation: read_ints(f, "interpolation", self.interpolation.view())?,
            easing: read_ints(f, "easing", self.easing.view())?,
            back: per_key("back", &self.back, DEFAULT_BACK)?,
            amplitude: per_key("amplitude", &self.amplitude, DEFAULT_AMPLITUDE)?,
            period: per_key("period", &self.period, DEFAULT_PERIOD)?,
            extrapolation: self.extrapolation,
            cycles: self.cycles,
        })
    }
}

impl CurveArgs<'_> {
    /// The arguments as the core's packed curves.
    pub(crate) fn packed(&self) -> PackedCurves<'_> {
        PackedCurves {
            offsets: &self.offsets,
            co: &self.co,
            handle_left: &self.handle_left,
            handle_right: &self.handle_right,
            interpolation: &self.interpolation,
            easing: &self.easing,
            back: &self.back,
            amplitude: &self.amplitude,
            period: &self.period,
            extrapolation: self.extrapolation,
            cycles: self.cycles,
        }
    }
}

// stub:
// stub: InterpolationName = Literal[
// stub:     "CONSTANT", "LINEAR", "BEZIER", "SINE", "QUAD", "CUBIC", "QUART", "QUINT", "EXPO", "CIRC",
// stub:     "BACK", "BOUNCE", "ELASTIC",
// stub: ]
// stub: EasingName = Literal["AUTO", "EASE_IN", "EASE_OUT", "EASE_IN_OUT"]
// stub: ExtrapolationName = Literal["CONSTANT", "LINEAR"]
// stub: CycleModeName = Literal["NONE", "REPEAT", "REPEAT_OFFSET", "MIRROR"]
/// evaluate_fcurves(
///     times: ArrayLike,
///     *,
///     offsets: ArrayLike,
///     co: ArrayLike,
///     handle_left: ArrayLike,
///     handle_right: ArrayLike,
///     interpolation: ArrayLike,
///     easing: ArrayLike,
///     extrapolation: ExtrapolationName | Sequence[ExtrapolationName] | None = None,
///     back: ArrayLike | None = None,
///     amplitude: ArrayLike | None = None,
///     period: ArrayLike | None = None,
///     cycles: Sequence[Mapping[str, Any] | None] | None = None,
/// ) -> FloatArray
///
/// C keyframed F-curves at T ``times`` as Blender evaluates them: (C, T) float64.
///
/// Each value is exactly Blender's ``FCurve.evaluate(time)`` (4.2 and later): every step
/// is done in float32 (and float64 where Blender uses double) in Blender's order, so the
/// result is Blender's float32 value, widened. Times may be in any order and are rounded to
/// float32, as Blender's frame is.
///
/// Keys are packed one curve after the other (K keys in all); curve ``c`` owns keys
/// ``offsets[c]:offsets[c + 1]`` (``offsets`` (C + 1,), from 0 to K, non-decreasing; every
/// curve needs a key):
///
/// - ``co``, ``handle_left``, ``handle_right``: (K, 2) ``(frame, value)``; frames of a
///   curve's keys must not decrease;
/// - ``interpolation``: (K,) integer codes, indices into ``INTERPOLATIONS`` (the segment
///   from each key to the next); ``easing``: (K,) indices into ``EASINGS`` (AUTO is
///   ease-out for BACK, BOUNCE, ELASTIC and ease-in for the others, as in Blender);
/// - ``back``, ``amplitude``, ``period``: (K,), default Blender's 1.70158, 0.8, 4.1.
///
/// ``extrapolation``: one name of ``EXTRAPOLATIONS`` for every curve or one per curve
/// (default ``"CONSTANT"``). ``cycles``: None, or C entries, each None (no modifier) or a
/// dict of the Cycles modifier's RNA properties: ``mode_before``, ``mode_after`` (names
/// of ``CYCLE_MODES``, default ``"REPEAT"``), ``cycles_before``, ``cycles_after`` (0:
/// unlimited), ``use_restricted_range`` with ``frame_start``, ``frame_end``, ``blend_in``,
/// ``blend_out``, ``use_influence`` with ``influence``. Other modifiers, drivers and muted
/// curves are not evaluated (the add-on's ``curves.py`` refuses them).
///
/// The GIL is released. Raises ValueError naming the argument, curve and key: wrong shapes
/// or lengths, bad offsets, codes or names, integer codes or offsets that are not whole
/// numbers (``2.7``, NaN), numbers not finite in float32, keys out of time order, a curve
/// without keys, more than ``MAX_FCURVE_KEYS`` keys or ``MAX_FCURVE_VALUES`` values, more
/// memory than the budget (the prepared curves, the values and the copies of the input,
/// checked before anything is copied), or a value that is not finite (where Blender's
/// would be NaN or infinite); TypeError for complex, string or object arrays.
#[pyfunction]
#[pyo3(signature = (times, *, offsets, co, handle_left, handle_right, interpolation, easing, extrapolation=None, back=None, amplitude=None, period=None, cycles=None))]
#[allow(clippy::too_many_arguments)]
fn evaluate_fcurves<'py>(
    py: Python<'py>,
    times: &Bound<'py, PyAny>,
    offsets: &Bound<'py, PyAny>,
    co: &Bound<'py, PyAny>,
    handle_left: &Bound<'py, PyAny>,
    handle_right: &Bound<'py, PyAny>,
    interpolation: &Bound<'py, PyAny>,
    easing: &Bound<'py, PyAny>,
    extrapolation: Option<&Bound<'py, PyAny>>,
    back: Option<&Bound<'py, PyAny>>,
    amplitude: Option<&Bound<'py, PyAny>>,
    period: Option<&Bound<'py, PyAny>>,
    cycles: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let times = float_array(F, "times", times)?;
    let n = vector_len(F, "times", &times)?;
    let input = CurveInput::read(
        F,
        n,
        times.copy() + Footprint::of::<f64>(n), // the times' conversion and copy
        offsets,
        co,
        handle_left,
        handle_right,
        interpolation,
        easing,
        extrapolation,
        back,
        amplitude,
        period,
        cycles,
    )?;
    let times = times.read()?;
    let (times, curves) = (times.as_array(), input.views());
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let times = read_vector(F, "times", &times)?;
        let args = curves.to_args()?;
        let packed = args.packed();
        let values = evaluate_packed(&packed, &times).map_err(|e| to_py_err(F, e))?;
        Array2::from_shape_vec((packed.len(), n), values)
            .map_err(|e| crate::errors::invalid(format!("{F}: {e}")))
    })?;
    Ok(out.into_pyarray(py))
}

/// Adds `evaluate_fcurves` and its name tables to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(evaluate_fcurves, m)?)?;
    let py = m.py();
    // stub:
    // stub: INTERPOLATIONS: tuple[InterpolationName, ...]
    // stub: """Blender's ``Keyframe.interpolation`` identifiers; a key's code is its index here."""
    m.add("INTERPOLATIONS", PyTuple::new(py, Interpolation::NAMES)?)?;
    // stub: EASINGS: tuple[EasingName, ...]
    // stub: """Blender's ``Keyframe.easing`` identifiers; a key's code is its index here."""
    m.add("EASINGS", PyTuple::new(py, Easing::NAMES)?)?;
    // stub: EXTRAPOLATIONS: tuple[ExtrapolationName, ...]
    // stub: """Blender's ``FCurve.extrapolation`` identifiers."""
    m.add("EXTRAPOLATIONS", PyTuple::new(py, Extrapolation::NAMES)?)?;
    // stub: CYCLE_MODES: tuple[CycleModeName, ...]
    // stub: """Blender's ``FModifierCycles.mode_before`` / ``mode_after`` identifiers."""
    m.add("CYCLE_MODES", PyTuple::new(py, CycleMode::NAMES)?)?;
    // stub: CYCLES_PROPERTIES: tuple[str, ...]
    // stub: """The keys a Cycles settings dict of ``evaluate_fcurves`` may hold: the RNA property names of
    // stub: Blender's ``FModifierCycles`` it reads."""
    m.add("CYCLES_PROPERTIES", PyTuple::new(py, CYCLES_KEYS)?)?;
    // stub: MAX_FCURVE_KEYS: int
    // stub: """The most keys one ``evaluate_fcurves`` call accepts (2**26)."""
    m.add("MAX_FCURVE_KEYS", MAX_KEYS)?;
    // stub: MAX_FCURVE_VALUES: int
    // stub: """The most values (curves x times) one ``evaluate_fcurves`` call returns (2**27)."""
    m.add("MAX_FCURVE_VALUES", MAX_VALUES)?;
    Ok(())
}
