//! Binding of what the animator meant between the keys (`polyscrew::intent`): conversion only.
//!
//! A `Playback` is built once per owner from the same packed curves `evaluate_fcurves` takes
//! (the add-on's `curves.Packed.arguments()`), the channel each curve drives and the owner's
//! own values; `analyse_spans` and `keys_parameters` take it.

use std::borrow::Cow;

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use polyscrew::intent::{
    analyse_turns as core_analyse_turns, departure as core_departure,
    measure_departure as core_measure_departure, measure_departures as core_measure_departures,
    pace_parameters as core_pace_parameters, rotation_matrices as core_rotation_matrices,
    timed_frames as core_timed_frames, Channel, DepartureLimits, DepartureOwner, PaceSource,
    Playback, Spans, Timed, Turns, HOLD_TOLERANCE, MAX_ANALYSIS_SAMPLES, MAX_SPAN_SAMPLES,
    PACE_SAMPLES, RANGE_TOLERANCE, SPAN_SAMPLES, WIND_LIMIT, WIND_STEP, WRAP_MARGIN,
};
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::{Error, MotionSpec, Pose, RotationMode, Scheme, Timing};

use crate::args::{
    self, float_array, AnalyseSpans, AnalyseTurns, Choice, Function, KeysParameters,
    MeasureDepartures, Most, PlaybackNew, RotationMatrices, TimedFrames,
};
use crate::arrays::{key_count, pose_count, read_keys, read_poses, read_vector, vector_len};
use crate::errors::{check_budget, shape_err, to_py_err};
use crate::fcurve::CurveInput;

/// How to ask these functions for less memory.
const HINT: &str = "pass fewer frames or keys in one call";

/// `values` (`n x width`, row-major) as an `(n, width)` array.
fn rows_array(values: Vec<f64>, width: usize) -> Array2<f64> {
    let n = values.len() / width;
    Array2::from_shape_vec((n, width), values).expect("n * width values")
}

/// The `Playback` argument `obj`, or a `TypeError` naming `function` and `what`.
pub(crate) fn playback_arg<'a, 'py>(
    function: &str,
    what: &str,
    obj: &'a Bound<'py, PyAny>,
) -> PyResult<&'a Bound<'py, PyPlayback>> {
    obj.cast::<PyPlayback>().map_err(|_| {
        crate::errors::wrong_type(format!("{function}: {what}: expected a polyscrew.Playback"))
    })
}

/// The values of `view` (any shape) row-major, allocated fallibly.
fn flat_values(function: &str, view: &numpy::ndarray::ArrayViewD<'_, f64>) -> PyResult<Vec<f64>> {
    let mut out = try_vec(view.len(), "input values").map_err(|e| to_py_err(function, e))?;
    out.extend(view.iter().copied());
    Ok(out)
}

/// A `ValueError` unless `shape` is `(t, width)`.
fn check_rows(function: &str, what: &str, shape: &[usize], t: usize, width: usize) -> PyResult<()> {
    if shape.len() != 2 || shape[1] != width || shape[0] != t {
        return Err(shape_err(function, what, &format!("({t}, {width})"), shape));
    }
    Ok(())
}

/// `played` of `keys_parameters`, a bool.
fn played_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg(KeysParameters::NAME, "played", obj)
}

/// `most` of `Playback.measure_departure`: frames measured per span, at least 2.
fn most_arg(obj: &Bound<'_, PyAny>) -> PyResult<usize> {
    let most = args::int_in("Playback.measure_departure", "most", obj, 2, i64::MAX)?;
    Ok(usize::try_from(most).unwrap_or(usize::MAX))
}

/// `located`, a bool.
fn located(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg("Playback", "located", obj)
}

/// An owner's transform channels as Blender plays them.
///
/// C keyframed curves, packed as ``evaluate_fcurves`` takes them (the same keyword
/// arguments, evaluated exactly as it does), curve ``c`` driving ``channels[c]``, a
/// ``(property, index)`` pair: ``"location"``, ``"scale"`` or the rotation property of
/// ``mode`` (``"rotation_euler"``, ``"rotation_quaternion"``, ``"rotation_axis_angle"``).
/// ``unkeyed``: the owner's own values of all channels, location (3), rotation (3 Euler
/// angles, or 4: quaternion w, x, y, z / axis-angle angle, x, y, z) and scale (3), used where
/// no curve drives a channel. ``located=False``: location is ignored (0), as Blender does
/// for a bone connected to its parent. Raises ValueError for bad curves (as
/// ``evaluate_fcurves``), an unknown property or mode, an index out of range, more channels
/// than the owner has (``6 + width``), two curves on one channel, or ``unkeyed`` of the
/// wrong length or not finite.
#[pyclass(frozen, module = "polyscrew", name = "Playback")]
pub struct PyPlayback {
    pub(crate) inner: Playback,
}

#[pymethods]
impl PyPlayback {
    /// __init__(
    ///     *,
    ///     channels: Sequence[tuple[str, int]],
    ///     unkeyed: ArrayLike,
    ///     mode: RotationModeName,
    ///     located: bool = True,
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
    /// ) -> None
    #[new]
    #[pyo3(signature = (*, channels, unkeyed, mode, located=true, offsets, co, handle_left, handle_right, interpolation, easing, extrapolation=None, back=None, amplitude=None, period=None, cycles=None))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        py: Python<'py>,
        channels: &Bound<'py, PyAny>,
        unkeyed: &Bound<'py, PyAny>,
        mode: Choice<PlaybackNew, RotationMode>,
        #[pyo3(from_py_with = located)] located: bool,
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
        const F: &str = "Playback";
        let mode = mode.0;
        // One curve per channel of the row at most (more drive a channel twice).
        let expected = "a sequence of (property, index) pairs";
        let items = args::sequence(
            F,
            "channels",
            channels,
            Most::AtMost(6 + mode.width()),
            expected,
        )?;
        let pairs = items
            .iter()
            .map(|item| {
                item.extract::<(String, i64)>().map_err(|_| {
                    crate::errors::wrong_type(format!("{F}: channels: expected {expected}"))
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let channels = pairs
            .iter()
            .enumerate()
            .map(|(c, (property, index))| {
                let index = usize::try_from(*index).map_err(|_| {
                    crate::errors::invalid(format!("{F}: channels[{c}]: index {index} is negative"))
                })?;
                Channel::from_property(property, index, mode)
                    .map_err(|e| crate::errors::to_py_err(&format!("{F}: channels[{c}]"), e))
            })
            .collect::<PyResult<Vec<_>>>()?;
        let unkeyed = float_array(F, "unkeyed", unkeyed)?;
        let width = vector_len(F, "unkeyed", &unkeyed)?;
        let input = CurveInput::read(
            F,
            0,
            unkeyed.copy() + Footprint::of::<f64>(width), // the owner's values and their copy
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
        let unkeyed = unkeyed.read()?;
        let (unkeyed, curves) = (unkeyed.as_array(), input.views());
        let inner = py.detach(|| -> PyResult<Playback> {
            let unkeyed = read_vector(F, "unkeyed", &unkeyed)?;
            let args = curves.to_args()?;
            let curves = args.packed().to_curves().map_err(|e| to_py_err(F, e))?;
            Playback::new(curves, &channels, unkeyed, mode, located).map_err(|e| to_py_err(F, e))
        })?;
        Ok(Self { inner })
    }

    /// channels(frames: ArrayLike) -> tuple[FloatArray, FloatArray, FloatArray]
    ///
    /// Location (T, 3), rotation (T, 3 or 4) and scale (T, 3) at ``frames`` (T,), any
    /// order, subframes allowed: keyed channels exactly Blender's float32 values, the
    /// others ``unkeyed``. GIL released.
    #[allow(clippy::type_complexity)]
    fn channels<'py>(
        &self,
        py: Python<'py>,
        frames: &Bound<'py, PyAny>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        const F: &str = "Playback.channels";
        let frames = float_array(F, "frames", frames)?;
        let t = vector_len(F, "frames", &frames)?;
        let inner = &self.inner;
        let width = inner.width();
        let w = inner.mode().width();
        // the frames, the rows, the three outputs
        check_budget(
            F,
            frames.copy() + Footprint::of::<f64>(t).and::<f64>(t.saturating_mul(2 * width)),
            "the channel values",
            HINT,
        )?;
        let frames = frames.read()?;
        let view = frames.as_array();
        let (location, rotation, scale) = py.detach(|| -> PyResult<_> {
            let frames = read_vector(F, "frames", &view)?;
            let split = || -> Result<(Vec<f64>, Vec<f64>, Vec<f64>), Error> {
                let rows = inner.channels(&frames)?;
                let (mut location, mut rotation, mut scale) = (
                    try_vec(3 * t, "locations")?,
                    try_vec(w * t, "rotations")?,
                    try_vec(3 * t, "scales")?,
                );
                for row in rows.chunks_exact(width) {
                    location.extend_from_slice(&row[..3]);
                    rotation.extend_from_slice(&row[3..3 + w]);
                    scale.extend_from_slice(&row[3 + w..]);
                }
                Ok((location, rotation, scale))
            };
            split().map_err(|e| to_py_err(F, e))
        })?;
        Ok((
            rows_array(location, 3).into_pyarray(py),
            rows_array(rotation, w).into_pyarray(py),
            rows_array(scale, 3).into_pyarray(py),
        ))
    }

    /// __len__() -> int
    ///
    /// The number of curves.
    fn __len__(&self) -> usize {
        self.inner.curves().len()
    }

    /// departure(
    ///     frames: ArrayLike, location: ArrayLike, rotation: ArrayLike
    /// ) -> tuple[FloatArray, FloatArray]
    ///
    /// How far a result's ``location`` (T, 3) and ``rotation`` (T, 3 or 4, in the owner's
    /// mode) at ``frames`` (T,) are from this playback: per frame the distance between the
    /// locations (0 when ``located`` is false) and the angle (radians, in [0, pi]) between
    /// the rotations, both (T,). GIL released. Raises ValueError for shapes that do not
    /// match or values that are not finite.
    #[allow(clippy::type_complexity)]
    fn departure<'py>(
        &self,
        py: Python<'py>,
        frames: &Bound<'py, PyAny>,
        location: &Bound<'py, PyAny>,
        rotation: &Bound<'py, PyAny>,
    ) -> PyResult<(Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>)> {
        const F: &str = "Playback.departure";
        let inner = &self.inner;
        let frames = float_array(F, "frames", frames)?;
        let t = vector_len(F, "frames", &frames)?;
        let w = inner.mode().width();
        let location = float_array(F, "location", location)?;
        let rotation = float_array(F, "rotation", rotation)?;
        for (array, what, width) in [(&location, "location", 3), (&rotation, "rotation", w)] {
            check_rows(F, what, array.shape(), t, width)?;
        }
        // the arguments' conversions, the values read, the playback's rows, the two outputs
        check_budget(
            F,
            frames.copy()
                + location.copy()
                + rotation.copy()
                + Footprint::of::<f64>(t.saturating_mul(3 + w + 3))
                    .and::<f64>(4096 * inner.width()),
            "the departure",
            HINT,
        )?;
        let (frames, location, rotation) = (frames.read()?, location.read()?, rotation.read()?);
        let (frames, location, rotation) =
            (frames.as_array(), location.as_array(), rotation.as_array());
        let out = py.detach(|| -> PyResult<_> {
            let frames = read_vector(F, "frames", &frames)?;
            // (shapes checked above) row-major values
            let flat = |view: &numpy::ndarray::ArrayViewD<'_, f64>| flat_values(F, view);
            let location = flat(&location)?;
            let rotation = flat(&rotation)?;
            core_departure(inner, &frames, &location, &rotation).map_err(|e| to_py_err(F, e))
        })?;
        Ok((out.distance.into_pyarray(py), out.angle.into_pyarray(py)))
    }

    /// measure_departure(
    ///     frames: ArrayLike,
    ///     location: ArrayLike,
    ///     rotation: ArrayLike,
    ///     *,
    ///     degrees: float,
    ///     distance: float,
    ///     played: ArrayLike | None = None,
    ///     key_frames: ArrayLike | None = None,
    ///     most: int = 64,
    /// ) -> tuple[float, float, npt.NDArray[np.bool_]]
    ///
    /// What a report needs of ``departure`` in one call: ``(largest angle in degrees,
    /// largest distance, over)`` of a result's ``location`` (T, 3) and ``rotation`` (T, 3 or
    /// 4) at ``frames`` (T,), sorted, ``over`` (T,) true where a frame departs by more than
    /// ``degrees`` or ``distance``. With ``key_frames``, a key span baked at more than
    /// ``most`` frames is measured at ``most`` of them, evenly spaced (its first and last
    /// included), and a frame not measured departs as its nearest measured frame. ``played``
    /// (T, 3 + 3 or 4): the playback's location and rotation per frame as
    /// ``keys_parameters(..., played=True)`` returns them, NaN where not known: those frames
    /// are compared without being played again (the same figures, bit for bit). GIL
    /// released. Raises ValueError for shapes that do not match, values that are not finite
    /// or ``most`` below 2.
    #[pyo3(signature = (frames, location, rotation, *, degrees, distance, played=None, key_frames=None, most=64))]
    #[allow(clippy::too_many_arguments, clippy::type_complexity)]
    fn measure_departure<'py>(
        &self,
        py: Python<'py>,
        frames: &Bound<'py, PyAny>,
        location: &Bound<'py, PyAny>,
        rotation: &Bound<'py, PyAny>,
        degrees: &Bound<'py, PyAny>,
        distance: &Bound<'py, PyAny>,
        played: Option<&Bound<'py, PyAny>>,
        key_frames: Option<&Bound<'py, PyAny>>,
        #[pyo3(from_py_with = most_arg)] most: usize,
    ) -> PyResult<(f64, f64, Bound<'py, PyArray1<bool>>)> {
        const F: &str = "Playback.measure_departure";
        let inner = &self.inner;
        let limits = DepartureLimits {
            degrees: args::float_scalar(F, "degrees", degrees)?,
            distance: args::float_scalar(F, "distance", distance)?,
        };
        let frames = float_array(F, "frames", frames)?;
        let t = vector_len(F, "frames", &frames)?;
        let w = inner.mode().width();
        let location = float_array(F, "location", location)?;
        let rotation = float_array(F, "rotation", rotation)?;
        let played = crate::args::optional_float_array(F, "played", played)?;
        let key_frames = crate::args::optional_float_array(F, "key_frames", key_frames)?;
        let k = key_frames
            .as_ref()
            .map(|a| vector_len(F, "key_frames", a))
            .transpose()?
            .unwrap_or(0);
        for (array, what, width) in [
            (Some(&location), "location", 3),
            (Some(&rotation), "rotation", w),
            (played.as_ref(), "played", 3 + w),
        ] {
            if let Some(array) = array {
                check_rows(F, what, array.shape(), t, width)?;
            }
        }
        // the arguments' conversions, the values read, the core's work (per measured frame
        // the result, a row and the figures; the playback's rows of one chunk), the output
        check_budget(
            F,
            departure_copies([
                Some(&frames),
                Some(&location),
                Some(&rotation),
                played.as_ref(),
                key_frames.as_ref(),
            ]) + Footprint::of::<f64>(t.saturating_mul(3 + w + 3 + w + 1).saturating_add(k))
                + Footprint::of::<f64>(t.saturating_mul(4 + 3 + w + 3))
                    .and::<f64>(4096 * inner.width())
                    .and::<bool>(t),
            "the departure",
            HINT,
        )?;
        let (frames, location, rotation) = (frames.read()?, location.read()?, rotation.read()?);
        let played = played.as_ref().map(|p| p.read()).transpose()?;
        let key_frames = key_frames.as_ref().map(|a| a.read()).transpose()?;
        let (frames, location, rotation) =
            (frames.as_array(), location.as_array(), rotation.as_array());
        let played = played.as_ref().map(|p| p.as_array());
        let key_frames = key_frames.as_ref().map(|a| a.as_array());
        let out = py.detach(|| -> PyResult<_> {
            let frames = read_vector(F, "frames", &frames)?;
            let key_frames = key_frames
                .as_ref()
                .map(|k| read_vector(F, "key_frames", k))
                .transpose()?;
            // (shapes checked above) row-major values
            let flat = |view: &numpy::ndarray::ArrayViewD<'_, f64>| flat_values(F, view);
            let location = flat(&location)?;
            let rotation = flat(&rotation)?;
            let played = played.as_ref().map(flat).transpose()?;
            core_measure_departure(
                inner,
                &frames,
                &location,
                &rotation,
                played.as_deref(),
                key_frames.as_deref().map(|k| (k, most)),
                limits,
            )
            .map_err(|e| to_py_err(F, e))
        })?;
        Ok((out.degrees, out.distance, out.over.into_pyarray(py)))
    }

    /// rows_evaluated -> int
    ///
    /// How many frames this playback has played (one channel row each) since it was made, by
    /// every function that plays it: how often a caller plays the same curves.
    #[getter]
    fn rows_evaluated(&self) -> u64 {
        self.inner.rows_evaluated()
    }
}

/// What converting the arguments of a departure measure costs (frames, location, rotation,
/// and the played rows and key frames when given).
fn departure_copies(arrays: [Option<&args::FloatArg<'_>>; 5]) -> Footprint {
    arrays.into_iter().flatten().map(|a| a.copy()).sum()
}

/// The `Playback`s of the sequence `obj` (at most [`crate::many::MAX_PARTS`]), or a
/// `TypeError` naming `function`.
pub(crate) fn playbacks_arg<'py>(
    function: &str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<Vec<Bound<'py, PyPlayback>>> {
    args::sequence(
        function,
        "playbacks",
        obj,
        Most::AtMost(crate::many::MAX_PARTS),
        "a sequence of polyscrew.Playback",
    )?
    .iter()
    .map(|p| playback_arg(function, "playbacks", p).cloned())
    .collect()
}

/// The values of `view` row-major: its own when contiguous, else a copy.
fn contiguous<'a>(
    function: &str,
    view: &'a numpy::ndarray::ArrayViewD<'_, f64>,
) -> PyResult<Cow<'a, [f64]>> {
    Ok(match view.as_slice() {
        Some(values) => Cow::Borrowed(values),
        None => Cow::Owned(flat_values(function, view)?),
    })
}

/// `counts` of `measure_departures` (one per owner, each at least `least`: -1 for "none").
fn owner_counts(
    what: &'static str,
    obj: &Bound<'_, PyAny>,
    o: usize,
    least: i64,
) -> PyResult<Vec<i64>> {
    let counts = args::int_list(MeasureDepartures::NAME, what, obj, Most::Exactly(o))?;
    if counts.len() != o {
        return Err(crate::errors::invalid(format!(
            "{}: {what}: {} counts for {o} playbacks",
            MeasureDepartures::NAME,
            counts.len()
        )));
    }
    if let Some(&bad) = counts.iter().find(|&&c| c < least) {
        return Err(crate::errors::invalid(format!(
            "{}: {what}: {bad} is below {least}",
            MeasureDepartures::NAME
        )));
    }
    Ok(counts)
}

/// measure_departures(
///     playbacks: Sequence[Playback],
///     frames: ArrayLike,
///     counts: ArrayLike,
///     location: ArrayLike,
///     rotation: ArrayLike,
///     *,
///     degrees: ArrayLike,
///     distances: ArrayLike,
///     played: ArrayLike | None = None,
///     key_frames: ArrayLike | None = None,
///     key_counts: ArrayLike | None = None,
///     most: int = 64,
/// ) -> tuple[FloatArray, FloatArray, npt.NDArray[np.bool_]]
///
/// ``Playback.measure_departure`` of many owners in one call, each owner's figures to the
/// bit what its own call gives. Owner ``i`` (of O) is ``playbacks[i]``, the next
/// ``counts[i]`` frames of ``frames`` (N,) and rows of ``location`` (N, 3), the next
/// ``counts[i] * w`` numbers of ``rotation`` (its rotation rows, ``w`` = 3 or 4 numbers each
/// in its playback's mode, row-major) and of ``played`` the next ``counts[i] * (3 + w)`` (its
/// played rows, row-major; NaN rows where not known, as an owner without played rows has),
/// with the limits ``degrees[i]`` and ``distances[i]`` (O,) and, with ``key_frames``, the
/// next ``key_counts[i]`` of them (-1: the owner measures every frame, as without
/// ``key_frames``). Returns the largest angle (degrees) and distance per owner (O,) and
/// ``over`` (N,), the owners' flags one after the other. GIL released.
/// Raises ValueError for what ``measure_departure`` refuses, naming the owner (``part
/// i``), and for counts or shapes that do not match.
#[pyfunction]
#[pyo3(signature = (playbacks, frames, counts, location, rotation, *, degrees, distances, played=None, key_frames=None, key_counts=None, most=64))]
#[allow(clippy::too_many_arguments, clippy::type_complexity)]
fn measure_departures<'py>(
    py: Python<'py>,
    playbacks: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    counts: &Bound<'py, PyAny>,
    location: &Bound<'py, PyAny>,
    rotation: &Bound<'py, PyAny>,
    degrees: &Bound<'py, PyAny>,
    distances: &Bound<'py, PyAny>,
    played: Option<&Bound<'py, PyAny>>,
    key_frames: Option<&Bound<'py, PyAny>>,
    key_counts: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = most_arg)] most: usize,
) -> PyResult<(
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
)> {
    const F: &str = MeasureDepartures::NAME;
    let bound = playbacks_arg(F, playbacks)?;
    let o = bound.len();
    let as_len = |c: i64| usize::try_from(c).unwrap_or(0);
    let counts: Vec<usize> = owner_counts("counts", counts, o, 0)?
        .into_iter()
        .map(as_len)
        .collect();
    let key_counts = match (
        key_frames.filter(|k| !k.is_none()),
        key_counts.filter(|k| !k.is_none()),
    ) {
        (Some(_), Some(k)) => Some(owner_counts("key_counts", k, o, -1)?),
        (None, None) => None,
        _ => {
            return Err(crate::errors::invalid(format!(
                "{F}: key_frames and key_counts go together"
            )))
        }
    };
    let frames = float_array(F, "frames", frames)?;
    let n = vector_len(F, "frames", &frames)?;
    if counts.iter().try_fold(0usize, |a, &c| a.checked_add(c)) != Some(n) {
        return Err(crate::errors::invalid(format!(
            "{F}: counts: they do not add up to the {n} frames"
        )));
    }
    let location = float_array(F, "location", location)?;
    let rotation = float_array(F, "rotation", rotation)?;
    let played = args::optional_float_array(F, "played", played)?;
    check_rows(F, "location", location.shape(), n, 3)?;
    // each owner's rotation rows (`w` numbers each) and played rows (`3 + w`) one after the other
    let w: Vec<usize> = bound.iter().map(|p| p.get().inner.mode().width()).collect();
    let rotations: usize = counts
        .iter()
        .zip(&w)
        .map(|(&c, &w)| c.saturating_mul(w))
        .sum();
    let rows = rotations.saturating_add(n.saturating_mul(3));
    for (array, what, len) in [
        (Some(&rotation), "rotation", rotations),
        (played.as_ref(), "played", rows),
    ] {
        if let Some(array) = array {
            if array.shape() != [len] {
                return Err(shape_err(F, what, &format!("({len},)"), array.shape()));
            }
        }
    }
    let degrees = float_array(F, "degrees", degrees)?;
    let distances = float_array(F, "distances", distances)?;
    for (what, limits) in [("degrees", &degrees), ("distances", &distances)] {
        if limits.shape() != [o] {
            return Err(shape_err(F, what, &format!("({o},)"), limits.shape()));
        }
    }
    let key_frames = args::optional_float_array(F, "key_frames", key_frames)?;
    let k = key_frames
        .as_ref()
        .map(|a| vector_len(F, "key_frames", a))
        .transpose()?
        .unwrap_or(0);
    if let Some(key_counts) = &key_counts {
        let given = key_counts
            .iter()
            .map(|&c| as_len(c))
            .try_fold(0usize, |a, c| a.checked_add(c));
        if given != Some(k) {
            return Err(crate::errors::invalid(format!(
                "{F}: key_counts: they do not add up to the {k} key frames"
            )));
        }
    }
    let widest = bound
        .iter()
        .map(|p| p.get().inner.width())
        .max()
        .unwrap_or(0);
    // the arguments' conversions, the values read, the core's work for one
    // owner at most (as `measure_departure`), the outputs
    check_budget(
        F,
        departure_copies([
            Some(&frames),
            Some(&location),
            Some(&rotation),
            played.as_ref(),
            key_frames.as_ref(),
        ]) + Footprint::of::<f64>(n.saturating_mul(1 + 3 + 4 + 7 + 4 + 7).saturating_add(k))
            + Footprint::of::<f64>(n.saturating_mul(4 + 7 + 3 + 4 + 7 + 1))
                .and::<f64>(4096 * widest)
                .and::<bool>(n.saturating_mul(2))
                .and::<f64>(o.saturating_mul(4)),
        "the departures",
        HINT,
    )?;
    let (frames, location, rotation) = (frames.read()?, location.read()?, rotation.read()?);
    let (degrees, distances) = (degrees.read()?, distances.read()?);
    let played = played.as_ref().map(|p| p.read()).transpose()?;
    let key_frames = key_frames.as_ref().map(|a| a.read()).transpose()?;
    let (frames, location, rotation) =
        (frames.as_array(), location.as_array(), rotation.as_array());
    let (degrees, distances) = (degrees.as_array(), distances.as_array());
    let played = played.as_ref().map(|p| p.as_array());
    let key_frames = key_frames.as_ref().map(|a| a.as_array());
    let inner: Vec<&Playback> = bound.iter().map(|p| &p.get().inner).collect();
    let out = py.detach(|| -> PyResult<_> {
        let degrees = read_vector(F, "degrees", &degrees)?;
        let distances = read_vector(F, "distances", &distances)?;
        // (shapes checked above) row-major values: the arrays' own when contiguous
        let flat = |view| contiguous(F, view);
        let frames = flat(&frames)?;
        let key_frames = key_frames.as_ref().map(flat).transpose()?;
        let location = flat(&location)?;
        let rotation = flat(&rotation)?;
        let played = played.as_ref().map(flat).transpose()?;
        let mut owners = Vec::with_capacity(o);
        let (mut row, mut rot, mut pl, mut key) = (0, 0, 0, 0);
        for i in 0..o {
            let c = counts[i];
            let spans = match (&key_frames, &key_counts) {
                (Some(all), Some(kc)) if kc[i] >= 0 => {
                    key += as_len(kc[i]);
                    Some((&all[key - as_len(kc[i])..key], most))
                }
                _ => None,
            };
            owners.push(DepartureOwner {
                playback: inner[i],
                frames: &frames[row..row + c],
                location: &location[3 * row..3 * (row + c)],
                rotation: &rotation[rot..rot + c * w[i]],
                played: played.as_ref().map(|p| &p[pl..pl + c * (3 + w[i])]),
                spans,
                limits: DepartureLimits {
                    degrees: degrees[i],
                    distance: distances[i],
                },
            });
            (row, rot, pl) = (row + c, rot + c * w[i], pl + c * (3 + w[i]));
        }
        core_measure_departures(&owners).map_err(|e| to_py_err(F, e))
    })?;
    let over: Vec<bool> = out.iter().flat_map(|d| d.over.iter().copied()).collect();
    let degrees: Vec<f64> = out.iter().map(|d| d.degrees).collect();
    let distances: Vec<f64> = out.iter().map(|d| d.distance).collect();
    Ok((
        degrees.into_pyarray(py),
        distances.into_pyarray(py),
        over.into_pyarray(py),
    ))
}

/// Reads the arguments of `analyse_spans` / `analyse_turns` and runs the core, GIL released.
fn spans_of(
    py: Python<'_>,
    function: &'static str,
    playback: &Bound<'_, PyAny>,
    frames: &Bound<'_, PyAny>,
    turns: Turns,
) -> PyResult<Spans> {
    let playback = playback_arg(function, "playback", playback)?;
    let frames = float_array(function, "frames", frames)?;
    let k = vector_len(function, "frames", &frames)?;
    let inner = &playback.get().inner;
    // the frames' copy, and the core's working memory (which it checks again on its own):
    // the key rows, four values per span (the results and the sample counts), and one span's
    // samples at most (frames, rows, steps); the inserted frames are checked when counted
    let width = inner.width();
    let work = Footprint::of::<f64>(k.saturating_mul(width + 4))
        .and::<f64>(MAX_SPAN_SAMPLES.saturating_mul(width + 2));
    check_budget(
        function,
        frames.copy() + Footprint::of::<f64>(k) + work,
        "the frames",
        HINT,
    )?;
    let frames = frames.read()?;
    let view = frames.as_array();
    py.detach(|| -> PyResult<_> {
        let frames = read_vector(function, "frames", &view)?;
        core_analyse_turns(inner, &frames, turns).map_err(|e| to_py_err(function, e))
    })
}

/// analyse_spans(
///     playback: Playback, frames: ArrayLike, turns: Literal["AUTO", "BLENDER", "SHORTEST"] = "AUTO"
/// ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], FloatArray, FloatArray]
///
/// What each key span of ``frames`` (K,) (strictly increasing, K >= 2) does along the
/// playback: ``(held, pops, turn, inserted)``.
///
/// Each span is sampled at ``SPAN_SAMPLES`` frames from its start (included) to its end
/// (excluded), more where the rotation channels change a lot between its keys (one per 10
/// degrees, at most ``MAX_SPAN_SAMPLES``). ``held`` (K - 1,): no channel of any sample moves
/// from the span's start by more than ``HOLD_TOLERANCE`` (relative to the value + 1);
/// ``pops`` (K - 1,): held, and a channel differs between its keys; ``turn`` (K - 1,):
/// radians the rotation turns through, the sum of the angles between consecutive samples
/// and the span's end. ``inserted`` (M,), ascending: the frames where poses of the playback
/// must be added: a span that ``turns`` follows (``analyse_turns``; by default Euler and
/// axis-angle spans that are not Euler wraps) turning more than ``WIND_LIMIT`` (not held),
/// and the runs of its followed neighbours turning more than ``WIND_STEP``, get
/// ``ceil(turn / WIND_STEP) - 1`` frames where the accumulated turn
/// reaches equal fractions of the span's (linear between samples). GIL released. Raises
/// ValueError for fewer than two frames, frames that do not increase, or spans that would
/// take more than ``MAX_ANALYSIS_SAMPLES`` samples in all (refused before any is taken).
#[pyfunction]
#[pyo3(signature = (playback, frames, turns=Choice::of(Turns::Auto)))]
#[pyo3(text_signature = "(playback, frames, turns='AUTO')")]
#[allow(clippy::type_complexity)]
fn analyse_spans<'py>(
    py: Python<'py>,
    playback: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    turns: Choice<AnalyseSpans, Turns>,
) -> PyResult<SpanArrays<'py>> {
    Ok(span_arrays(
        py,
        spans_of(py, AnalyseSpans::NAME, playback, frames, turns.0)?,
    )
    .0)
}

/// What ``analyse_spans`` returns: held, pops, turn, inserted.
type SpanArrays<'py> = (
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
);

/// The arrays of ``analyse_spans`` (held, pops, turn, inserted), and the flips.
fn span_arrays(py: Python<'_>, spans: Spans) -> (SpanArrays<'_>, Bound<'_, PyArray1<bool>>) {
    (
        (
            spans.held.into_pyarray(py),
            spans.pops.into_pyarray(py),
            spans.turn.into_pyarray(py),
            spans.inserted.into_pyarray(py),
        ),
        spans.flips.into_pyarray(py),
    )
}

/// analyse_turns(
///     playback: Playback, frames: ArrayLike, turns: Literal["AUTO", "BLENDER", "SHORTEST"] = "AUTO"
/// ) -> tuple[npt.NDArray[np.bool_], npt.NDArray[np.bool_], FloatArray, FloatArray, npt.NDArray[np.bool_]]
///
/// ``analyse_spans`` and, per span, ``flips`` (K - 1,): not held, and its key values are
/// an Euler wrap (every value of both keys inside -pi..pi, and an equivalent triple of the
/// second key, 2 pi added or the twin triple, at least ``WRAP_MARGIN`` closer to the first,
/// sum of absolute differences) or a quaternion sign flip (q0 . q1 < 0): what Blender plays
/// the long way round although the animator did not type a spin.
///
/// ``turns`` picks the spans whose playback is followed (poses added, the rule of
/// ``analyse_spans``): "AUTO", Euler and axis-angle spans that are not flips (typed spins
/// turn as Blender plays them; flips and quaternion keys take the short screw); "BLENDER",
/// every span (flips and quaternion sign flips too, as Blender plays them); "SHORTEST",
/// none (the short screw between every two key poses; nothing inserted).
#[pyfunction]
#[pyo3(signature = (playback, frames, turns=Choice::of(Turns::Auto)))]
#[pyo3(text_signature = "(playback, frames, turns='AUTO')")]
#[allow(clippy::type_complexity)]
fn analyse_turns<'py>(
    py: Python<'py>,
    playback: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    turns: Choice<AnalyseTurns, Turns>,
) -> PyResult<(
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<bool>>,
)> {
    let ((held, pops, turn, inserted), flips) = span_arrays(
        py,
        spans_of(py, AnalyseTurns::NAME, playback, frames, turns.0)?,
    );
    Ok((held, pops, turn, inserted, flips))
}

/// keys_parameters(
///     key_frames: ArrayLike,
///     frames: ArrayLike,
///     *,
///     size: float,
///     closed: bool = False,
///     period: float | None = None,
///     playback: Playback | None = None,
///     poses: ArrayLike | None = None,
///     scheme: SchemeName = "four_point",
///     levels: int = 4,
///     smooth: ArrayLike | None = None,
///     played: bool = False,
/// ) -> FloatArray | tuple[FloatArray, FloatArray]
///
/// Timing "Keys": the motion parameter (key i at i) of each of ``frames`` (T,).
///
/// Within span s (keys s, s + 1; for a ``closed`` cycle of ``period`` frames the last span
/// returns to the first key), a frame at the fraction ``tau`` of the span's time gets the
/// parameter at which the smoothed motion has travelled the same fraction of the span as
/// the ``playback`` has at that frame (the fraction of time without ``playback``, or where
/// it does not move). Travel is ``sqrt(|dt|^2 + size^2 / 3 |dR|_F^2)`` (the root mean square
/// displacement of six points at +-``size``), summed over ``PACE_SAMPLES`` steps per span
/// and the output frames inside it; the smoothed motion's travel is measured at
/// ``pace_parameters(spans)`` and inverted linearly. Frames at keys and outside the spans
/// keep ``s + tau``.
///
/// The smoothed motion: the screw motion of the key ``poses`` (K, 4, 4) by ``scheme`` and
/// ``levels`` (keys at parameters 0..K-1, linear timing), or ``smooth``, its poses at
/// ``pace_parameters(spans)`` computed by the caller (feature points).
///
/// ``played=True`` returns ``(parameters, rows)`` instead: ``rows`` (T, 3 + 3 or 4), the
/// playback's location and rotation at each frame where this call played it at exactly that
/// frame (the frames from the first key to the last, but those of a span with more than 256
/// frames, which is measured on a grid), NaN elsewhere (without ``playback``: (T, 0)): what
/// ``Playback.measure_departure`` takes as ``played``. GIL released.
/// Raises ValueError naming the argument: key frames that do not increase, a period not
/// beyond the keys, a size that is not positive, frames not finite, neither or both of
/// ``poses`` and ``smooth``, or ``smooth`` of the wrong length.
#[pyfunction]
#[pyo3(signature = (key_frames, frames, *, size, closed=false, period=None, playback=None, poses=None, scheme=Choice::of(Scheme::FourPoint), levels=4, smooth=None, played=false))]
#[pyo3(
    text_signature = "(key_frames, frames, *, size, closed=False, period=None, playback=None, poses=None, scheme='four_point', levels=4, smooth=None, played=False)"
)]
#[allow(clippy::too_many_arguments)]
fn keys_parameters<'py>(
    py: Python<'py>,
    key_frames: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    size: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::closed::<KeysParameters>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    playback: Option<&Bound<'py, PyAny>>,
    poses: Option<&Bound<'py, PyAny>>,
    scheme: Choice<KeysParameters, Scheme>,
    #[pyo3(from_py_with = args::levels::<KeysParameters>)] levels: u32,
    smooth: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = played_arg)] played: bool,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = KeysParameters::NAME;
    let size = args::float_scalar(F, "size", size)?;
    let (out, rows, _) = paced(
        py,
        F,
        key_frames,
        frames,
        size,
        closed,
        period,
        playback,
        (poses, smooth),
        (scheme.0, levels),
        played,
    )?;
    let out = out.into_any();
    match rows {
        Some(rows) => Ok((out, rows).into_pyobject(py)?.into_any()),
        None => Ok(out),
    }
}

/// What [`paced`] returns: the parameters, the played rows, the number of keys.
type Paced<'py> = (
    Bound<'py, PyArray1<f64>>,
    Option<Bound<'py, PyArray2<f64>>>,
    usize,
);

/// Timing Keys' parameters of `frames` (the core's `timed_frames`; the arguments as
/// `keys_parameters` takes them), with `played` the playback's rows at them ((T, 0) without
/// a playback), and the number of keys.
#[allow(clippy::too_many_arguments)]
fn paced<'py>(
    py: Python<'py>,
    f: &'static str,
    key_frames: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    size: f64,
    closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    playback: Option<&Bound<'py, PyAny>>,
    (poses, smooth): (Option<&Bound<'py, PyAny>>, Option<&Bound<'py, PyAny>>),
    (scheme, levels): (Scheme, u32),
    played: bool,
) -> PyResult<Paced<'py>> {
    let period = args::optional_float(f, "period", period)?;
    let period = match (closed, period) {
        (true, Some(p)) => Some(p),
        (true, None) => {
            return Err(crate::errors::invalid(format!(
                "{f}: period: a closed motion needs its period"
            )))
        }
        (false, _) => None,
    };
    let playback = playback
        .filter(|p| !p.is_none())
        .map(|p| playback_arg(f, "playback", p))
        .transpose()?;
    let key_frames = float_array(f, "key_frames", key_frames)?;
    let frames = float_array(f, "frames", frames)?;
    let k = vector_len(f, "key_frames", &key_frames)?;
    let t = vector_len(f, "frames", &frames)?;
    let (poses, smooth) = (
        poses.filter(|p| !p.is_none()),
        smooth.filter(|p| !p.is_none()),
    );
    let (array, is_keys) = match (poses, smooth) {
        (Some(p), None) => (float_array(f, "poses", p)?, true),
        (None, Some(s)) => (float_array(f, "smooth", s)?, false),
        _ => {
            return Err(crate::errors::invalid(format!(
                "{f}: give either poses (the key poses) or smooth (the smoothed motion's poses)"
            )))
        }
    };
    let n = if is_keys {
        key_count(f, &array)?
    } else {
        pose_count(f, "smooth", array.shape())?.0
    };
    // the copies of the input and the output, and the core's working memory (which it
    // checks again on its own): per frame four values, per pace sample five, per pose of
    // the pace grid two and (from the keys) the smoothed pose itself
    let grid = k.saturating_mul(PACE_SAMPLES + 1);
    // (and, played, a pose row per frame and per span end)
    let rows = if played {
        t.saturating_add(2 * k)
            .saturating_mul(3 + playback.map_or(0, |p| p.get().inner.mode().width()))
    } else {
        0
    };
    let work = Footprint::of::<f64>(t).times(4)
        + Footprint::of::<f64>(grid.saturating_add(t)).times(6)
        + Footprint::of::<f64>(grid).times(2)
        + Footprint::of::<f64>(rows)
        + Footprint::of::<Pose>(if is_keys { grid } else { 0 });
    check_budget(
        f,
        key_frames.copy()
            + frames.copy()
            + array.copy()
            + work
            + Footprint::of::<f64>(k.saturating_add(2 * t)).and::<Pose>(n),
        "timing Keys",
        HINT,
    )?;
    let (key_frames, frames, array) = (key_frames.read()?, frames.read()?, array.read()?);
    let inner = playback.map(|p| &p.get().inner);
    let (kv, fv, pv) = (key_frames.as_array(), frames.as_array(), array.as_array());
    let spec = MotionSpec {
        scheme,
        levels,
        closed,
        period,
        timing: Timing::Keys,
    };
    let (out, rows) = py.detach(|| -> PyResult<(Vec<f64>, Vec<f64>)> {
        let key_frames = read_vector(f, "key_frames", &kv)?;
        let frames = read_vector(f, "frames", &fv)?;
        let poses = if is_keys {
            read_keys(f, &pv)?
        } else {
            read_poses(f, "smooth", &pv)?
        };
        let source = if is_keys {
            PaceSource::Keys(&poses)
        } else {
            PaceSource::Given(&poses)
        };
        match core_timed_frames(
            &key_frames,
            &frames,
            &spec,
            Some(size),
            inner,
            source,
            played,
        ) {
            Ok(Timed::Parameters {
                parameters, played, ..
            }) => Ok((parameters, played)),
            Ok(Timed::Frames) => unreachable!("timing Keys is paced"),
            Err(e) => Err(to_py_err(f, e)),
        }
    })?;
    let out = out.into_pyarray(py);
    if !played {
        return Ok((out, None, k));
    }
    // (T, 0) without a playback: nothing played
    let width = inner.map_or(0, |p| 3 + p.mode().width());
    let rows = Array2::from_shape_vec((t, width), rows)
        .expect("a row per frame")
        .into_pyarray(py);
    Ok((out, Some(rows), k))
}

/// timed_frames(
///     key_frames: ArrayLike,
///     frames: ArrayLike,
///     timing: TimingName = "smooth",
///     *,
///     size: float | None = None,
///     closed: bool = False,
///     period: float | None = None,
///     playback: Playback | None = None,
///     poses: ArrayLike | None = None,
///     scheme: SchemeName = "four_point",
///     levels: int = 4,
///     smooth: ArrayLike | None = None,
///     played: bool = False,
/// ) -> tuple[Any, Any, Any, TimeMapName, FloatArray | None]
///
/// Where the motion of keys at ``key_frames`` is sampled for ``frames`` with ``timing``, in
/// one call for every timing: ``(key_times, times, period, timing, rows)`` to pass to
/// ``sample``, ``sample_channels``, ``sample_vectors`` or a feature-point sampler (with the
/// same ``closed``, ``scheme`` and ``levels``).
///
/// A map of time (``"smooth"``, ``"linear"``): ``key_frames``, ``frames``, ``period`` and
/// ``timing`` as given (the same objects), ``rows`` None. A timing that follows Blender's
/// pace (``PACED_TIMINGS``: ``"keys"``): key times ``0..K-1`` (float64), the parameters of
/// ``keys_parameters`` (which takes the same keyword arguments: ``size`` required, ``poses``
/// or ``smooth``, the ``playback``), period ``K`` for a closed motion (else None),
/// ``"linear"``, and with ``played`` the playback's rows of ``keys_parameters(...,
/// played=True)`` (else None). GIL released. Raises ValueError as ``keys_parameters``, and
/// for a paced timing without ``size``.
#[pyfunction]
#[pyo3(signature = (key_frames, frames, timing=Choice::of(Timing::Smooth), *, size=None, closed=false, period=None, playback=None, poses=None, scheme=Choice::of(Scheme::FourPoint), levels=4, smooth=None, played=false))]
#[pyo3(
    text_signature = "(key_frames, frames, timing='smooth', *, size=None, closed=False, period=None, playback=None, poses=None, scheme='four_point', levels=4, smooth=None, played=False)"
)]
#[allow(clippy::too_many_arguments)]
fn timed_frames<'py>(
    py: Python<'py>,
    key_frames: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
    timing: Choice<TimedFrames, Timing>,
    size: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = args::closed::<TimedFrames>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    playback: Option<&Bound<'py, PyAny>>,
    poses: Option<&Bound<'py, PyAny>>,
    scheme: Choice<TimedFrames, Scheme>,
    #[pyo3(from_py_with = args::levels::<TimedFrames>)] levels: u32,
    smooth: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = played_arg)] played: bool,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = TimedFrames::NAME;
    let timing = timing.0;
    if !timing.paced() {
        let none = py.None().into_bound(py);
        let period = period.cloned().unwrap_or_else(|| none.clone());
        return Ok((key_frames, frames, period, timing.name(), none)
            .into_pyobject(py)?
            .into_any());
    }
    let size = match size.filter(|s| !s.is_none()) {
        Some(size) => args::float_scalar(F, "size", size)?,
        None => {
            return Err(crate::errors::invalid(format!(
                "{F}: size: timing {} needs the body's size",
                timing.name()
            )))
        }
    };
    let (parameters, rows, k) = paced(
        py,
        F,
        key_frames,
        frames,
        size,
        closed,
        period,
        playback,
        (poses, smooth),
        (scheme.0, levels),
        played,
    )?;
    let key_times = (0..k)
        .map(|i| i as f64)
        .collect::<Vec<f64>>()
        .into_pyarray(py);
    let period = closed.then_some(k as f64);
    Ok((key_times, parameters, period, Timing::Linear.name(), rows)
        .into_pyobject(py)?
        .into_any())
}

/// pace_parameters(spans: int) -> FloatArray
///
/// ``s + j / PACE_SAMPLES`` for j in 0..PACE_SAMPLES of each span s in 0..spans, span
/// after span: where ``keys_parameters`` measures the smoothed motion.
#[pyfunction]
fn pace_parameters<'py>(
    py: Python<'py>,
    spans: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    const F: &str = "pace_parameters";
    let spans = args::int_in(F, "spans", spans, 0, i64::MAX)?;
    let spans = usize::try_from(spans).unwrap_or(usize::MAX);
    let out = py
        .detach(|| core_pace_parameters(spans))
        .map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
}

/// rotation_matrices(values: ArrayLike, mode: RotationModeName) -> FloatArray
///
/// (N, 3, 3) rotation matrices of (N, k) rotation channel values in Blender's ``mode``:
/// quaternions (w, x, y, z) normalised (zero: identity); axis-angle (angle, x, y, z) about
/// the normalised axis (zero axis: identity); Euler (x, y, z) radians, ``"XYZ"`` meaning X
/// applied first (``R = Rz Ry Rx``). GIL released. Raises ValueError for a wrong shape or a
/// row that is not finite.
#[pyfunction]
fn rotation_matrices<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    mode: Choice<RotationMatrices, RotationMode>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = RotationMatrices::NAME;
    let mode = mode.0;
    let values = float_array(F, "values", values)?;
    let width = mode.width();
    let shape = values.shape();
    if shape.len() != 2 || shape[1] != width {
        return Err(shape_err(F, "values", &format!("(N, {width})"), shape));
    }
    let n = shape[0];
    // the values read, the matrices, the output
    check_budget(
        F,
        values.copy()
            + Footprint::of::<f64>(n.saturating_mul(width)).and::<[f64; 9]>(n.saturating_mul(2)),
        "the rotation matrices",
        HINT,
    )?;
    let values = values.read()?;
    let view = values.as_array();
    let out = py.detach(|| -> PyResult<Array3<f64>> {
        let run = || -> Result<Array3<f64>, Error> {
            let mut values = try_vec(n.saturating_mul(width), "input values")?;
            values.extend(view.iter().copied());
            let matrices = core_rotation_matrices(&values, mode)?;
            let mut flat = try_vec(n.saturating_mul(9), "output matrices")?;
            for m in &matrices {
                for r in 0..3 {
                    flat.extend([m.x_axis[r], m.y_axis[r], m.z_axis[r]]);
                }
            }
            Ok(Array3::from_shape_vec((n, 3, 3), flat).expect("9 values per matrix"))
        };
        run().map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// Adds the intent functions, `Playback` and their constants to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPlayback>()?;
    m.add_function(wrap_pyfunction!(analyse_spans, m)?)?;
    m.add_function(wrap_pyfunction!(analyse_turns, m)?)?;
    m.add_function(wrap_pyfunction!(keys_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(timed_frames, m)?)?;
    m.add_function(wrap_pyfunction!(pace_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_matrices, m)?)?;
    m.add_function(wrap_pyfunction!(measure_departures, m)?)?;
    // stub:
    // stub: WIND_LIMIT: float
    // stub: """A span whose rotation channels turn further than this (radians, 150 degrees) is a spin."""
    m.add("WIND_LIMIT", WIND_LIMIT)?;
    // stub: WIND_STEP: float
    // stub: """The most a screw span of a spin turns once poses are added (radians, 45 degrees); the
    // stub: neighbouring spans of a spin turning more than this are cut too."""
    m.add("WIND_STEP", WIND_STEP)?;
    // stub: SPAN_SAMPLES: int
    // stub: """Samples of the playback per key span in ``analyse_spans`` (8; more for spinning spans)."""
    m.add("SPAN_SAMPLES", SPAN_SAMPLES)?;
    // stub: MAX_SPAN_SAMPLES: int
    // stub: """At most this many samples per span in ``analyse_spans`` (4096; one per 10 degrees)."""
    m.add("MAX_SPAN_SAMPLES", MAX_SPAN_SAMPLES)?;
    // stub: MAX_ANALYSIS_SAMPLES: int
    // stub: """At most this many samples in one ``analyse_spans`` call, all spans together (2,097,152):
    // stub: its work is not bounded by memory, this bounds its time (about 2 s of one core at the
    // stub: limit: 512 spans of 4,096 samples, each a spin)."""
    m.add("MAX_ANALYSIS_SAMPLES", MAX_ANALYSIS_SAMPLES)?;
    // stub: HOLD_TOLERANCE: float
    // stub: """A channel moving less than this times (its size + 1) over a span is still (1e-6)."""
    m.add("HOLD_TOLERANCE", HOLD_TOLERANCE)?;
    // stub: PACE_SAMPLES: int
    // stub: """Steps per span along which ``keys_parameters`` measures travel (16)."""
    m.add("PACE_SAMPLES", PACE_SAMPLES)?;
    // stub: WRAP_MARGIN: float
    // stub: """An Euler span is a wrap when an equivalent triple of its second key is at least this much
    // stub: closer (radians, 45 degrees, sum over the three angles) to its first key (``analyse_turns``)."""
    m.add("WRAP_MARGIN", WRAP_MARGIN)?;
    // stub: RANGE_TOLERANCE: float
    // stub: """How far beyond -pi..pi an Euler key may lie and still be inside the range (1e-6 radians)."""
    m.add("RANGE_TOLERANCE", RANGE_TOLERANCE)?;
    Ok(())
}
