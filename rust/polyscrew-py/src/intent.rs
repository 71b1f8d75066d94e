//! Binding of what the animator meant between the keys (`polyscrew::intent`): conversion only.
//!
//! A `Playback` is built once per owner from the same packed curves `evaluate_fcurves` takes
//! (the add-on's `curves.Packed.arguments()`), the channel each curve drives and the owner's
//! own values; `analyse_spans` and `keys_parameters` take it.

use numpy::ndarray::{Array2, Array3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::exceptions::{PyTypeError, PyValueError};
use pyo3::prelude::*;

use polyscrew::intent::{
    analyse_spans as core_analyse_spans, keys_parameters as core_keys_parameters,
    pace_parameters as core_pace_parameters, rotation_matrices as core_rotation_matrices,
    screw_pace_poses, Channel, KeysTiming, Playback, HOLD_TOLERANCE, MAX_SPAN_SAMPLES,
    PACE_SAMPLES, SPAN_SAMPLES, WIND_LIMIT, WIND_STEP,
};
use polyscrew::{Error, RotationMode, Scheme, MAX_LEVELS};

use crate::fcurve::{CurveArgs, IntArray};
use crate::{read_poses, read_vector, shape_err, to_py_err, FloatArray};

/// Reads `(N, width)` rows, flattened.
fn read_rows(
    function: &str,
    what: &str,
    array: &FloatArray<'_>,
    width: usize,
) -> PyResult<Vec<f64>> {
    let array = array.as_array();
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != width {
        return Err(shape_err(function, what, &format!("(N, {width})"), shape));
    }
    Ok(array.iter().copied().collect())
}

/// The rows of `values` (`n x width`, row-major) as an `(n, width)` array.
fn rows_array(values: Vec<f64>, width: usize) -> Array2<f64> {
    let n = values.len() / width;
    Array2::from_shape_vec((n, width), values).expect("n * width values")
}

/// Playback(*, channels, unkeyed, mode, located=True, offsets, co, handle_left, handle_right, interpolation, easing, extrapolation=None, back=None, amplitude=None, period=None, cycles=None)
///
/// An owner's transform channels as Blender plays them: C keyframed curves (packed as
/// `evaluate_fcurves` takes them), curve `c` driving channel `channels[c]`, a
/// `(property, index)` pair (`"location"`, `"scale"` or the rotation property of `mode`);
/// `unkeyed`: the owner's own values of every channel, location (3), rotation (3 Euler
/// angles, 4 for quaternion or axis-angle) and scale (3), used where no curve drives one;
/// `located=False`: location is ignored (a connected bone).
#[pyclass(frozen, module = "polyscrew", name = "Playback")]
pub struct PyPlayback {
    inner: Playback,
}

#[pymethods]
impl PyPlayback {
    #[new]
    #[pyo3(signature = (*, channels, unkeyed, mode, located=true, offsets, co, handle_left, handle_right, interpolation, easing, extrapolation=None, back=None, amplitude=None, period=None, cycles=None))]
    #[allow(clippy::too_many_arguments)]
    fn new<'py>(
        py: Python<'py>,
        channels: Bound<'py, PyAny>,
        unkeyed: FloatArray<'py>,
        mode: &str,
        located: bool,
        offsets: IntArray<'py>,
        co: FloatArray<'py>,
        handle_left: FloatArray<'py>,
        handle_right: FloatArray<'py>,
        interpolation: IntArray<'py>,
        easing: IntArray<'py>,
        extrapolation: Option<Bound<'py, PyAny>>,
        back: Option<FloatArray<'py>>,
        amplitude: Option<FloatArray<'py>>,
        period: Option<FloatArray<'py>>,
        cycles: Option<Bound<'py, PyAny>>,
    ) -> PyResult<Self> {
        const F: &str = "Playback";
        let mode = RotationMode::from_name(mode).map_err(|e| to_py_err(F, e))?;
        let pairs: Vec<(String, i64)> = channels.extract().map_err(|_| {
            PyTypeError::new_err(format!(
                "{F}: channels: expected a sequence of (property, index) pairs"
            ))
        })?;
        let channels = pairs
            .iter()
            .enumerate()
            .map(|(c, (property, index))| {
                let index = usize::try_from(*index).map_err(|_| {
                    PyValueError::new_err(format!("{F}: channels[{c}]: index {index} is negative"))
                })?;
                Channel::from_property(property, index, mode).map_err(|e| {
                    let reason = match e {
                        Error::Invalid { reason, .. } => reason,
                        e => e.to_string(),
                    };
                    PyValueError::new_err(format!("{F}: channels[{c}]: {reason}"))
                })
            })
            .collect::<PyResult<Vec<_>>>()?;
        let unkeyed = read_vector(F, "unkeyed", unkeyed.as_array())?;
        let args = CurveArgs::read(
            F,
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
        let packed = args.packed();
        let inner = py
            .detach(|| {
                let curves = packed.to_curves()?;
                Playback::new(curves, &channels, unkeyed, mode, located)
            })
            .map_err(|e| to_py_err(F, e))?;
        Ok(Self { inner })
    }

    /// channels(frames) -> (location, rotation, scale)
    ///
    /// The channels at `frames` (T,) (any order, subframes allowed) as Blender plays them:
    /// location (T, 3), rotation (T, 3 or 4) in the owner's mode, scale (T, 3); keyed
    /// channels are Blender's float32 values exactly. GIL released.
    #[allow(clippy::type_complexity)]
    fn channels<'py>(
        &self,
        py: Python<'py>,
        frames: FloatArray<'py>,
    ) -> PyResult<(
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
        Bound<'py, PyArray2<f64>>,
    )> {
        const F: &str = "Playback.channels";
        let frames = read_vector(F, "frames", frames.as_array())?;
        let inner = &self.inner;
        let width = inner.width();
        let w = inner.mode().width();
        let rows = py
            .detach(|| inner.channels(&frames))
            .map_err(|e| to_py_err(F, e))?;
        let n = frames.len();
        let (mut location, mut rotation, mut scale) = (
            Vec::with_capacity(3 * n),
            Vec::with_capacity(w * n),
            Vec::with_capacity(3 * n),
        );
        for row in rows.chunks_exact(width) {
            location.extend_from_slice(&row[..3]);
            rotation.extend_from_slice(&row[3..3 + w]);
            scale.extend_from_slice(&row[3 + w..]);
        }
        Ok((
            rows_array(location, 3).into_pyarray(py),
            rows_array(rotation, w).into_pyarray(py),
            rows_array(scale, 3).into_pyarray(py),
        ))
    }

    /// The number of curves.
    fn __len__(&self) -> usize {
        self.inner.curves().len()
    }
}

/// analyse_spans(playback, frames) -> (held, pops, turn, inserted)
///
/// Per key span of `frames` (K,) (strictly increasing, K >= 2): `held` (K - 1,) bool, every
/// channel still over the span; `pops` (K - 1,) bool, held and jumping at its end; `turn`
/// (K - 1,) radians the rotation turns through over the span (along Blender's playback);
/// `inserted` (M,) the frames (ascending) where poses of the playback must be added so that
/// no screw span of a spin turns more than `WIND_STEP` (Euler and axis-angle only). GIL
/// released.
#[pyfunction]
#[allow(clippy::type_complexity)]
fn analyse_spans<'py>(
    py: Python<'py>,
    playback: &Bound<'py, PyPlayback>,
    frames: FloatArray<'py>,
) -> PyResult<(
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<bool>>,
    Bound<'py, PyArray1<f64>>,
    Bound<'py, PyArray1<f64>>,
)> {
    const F: &str = "analyse_spans";
    let frames = read_vector(F, "frames", frames.as_array())?;
    let inner = &playback.get().inner;
    let spans = py
        .detach(|| core_analyse_spans(inner, &frames))
        .map_err(|e| to_py_err(F, e))?;
    Ok((
        spans.held.into_pyarray(py),
        spans.pops.into_pyarray(py),
        spans.turn.into_pyarray(py),
        spans.inserted.into_pyarray(py),
    ))
}

/// keys_parameters(key_frames, frames, *, size, closed=False, period=None, playback=None, poses=None, scheme="four_point", levels=4, smooth=None) -> ndarray
///
/// Timing "Keys": the motion parameter (key i at i) of each of `frames` (T,): within each
/// span, where the smoothed motion has travelled the same fraction of the span as Blender's
/// `playback` has at that frame (the fraction of time without playback). Travel:
/// `sqrt(|dt|^2 + size^2 / 3 |dR|_F^2)`. The smoothed motion is the screw motion of the key
/// `poses` (K, 4, 4) by `scheme` and `levels`, or `smooth`, its poses at
/// `pace_parameters(spans)`. `closed`: the keys are a cycle of `period` frames. GIL released.
#[pyfunction]
#[pyo3(signature = (key_frames, frames, *, size, closed=false, period=None, playback=None, poses=None, scheme="four_point", levels=4, smooth=None))]
#[allow(clippy::too_many_arguments)]
fn keys_parameters<'py>(
    py: Python<'py>,
    key_frames: FloatArray<'py>,
    frames: FloatArray<'py>,
    size: f64,
    closed: bool,
    period: Option<f64>,
    playback: Option<Bound<'py, PyPlayback>>,
    poses: Option<FloatArray<'py>>,
    scheme: &str,
    levels: i64,
    smooth: Option<FloatArray<'py>>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    const F: &str = "keys_parameters";
    let key_frames = read_vector(F, "key_frames", key_frames.as_array())?;
    let frames = read_vector(F, "frames", frames.as_array())?;
    let period = match (closed, period) {
        (true, Some(p)) => Some(p),
        (true, None) => {
            return Err(PyValueError::new_err(format!(
                "{F}: period: a closed motion needs its period"
            )))
        }
        (false, _) => None,
    };
    let scheme = Scheme::from_name(scheme).map_err(|e| to_py_err(F, e))?;
    let levels = u32::try_from(levels)
        .ok()
        .filter(|l| *l <= MAX_LEVELS)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "{F}: levels {levels} out of range 0..={MAX_LEVELS}"
            ))
        })?;
    /// Where the smoothed motion comes from.
    enum Smoothed {
        /// The key poses, smoothed here by `scheme` and `levels`.
        Keys(Vec<polyscrew::Pose>),
        /// The caller's poses at `pace_parameters(spans)`.
        Given(Vec<polyscrew::Pose>),
    }
    let smoothed = match (&poses, &smooth) {
        (Some(p), None) => Smoothed::Keys(read_poses(F, "poses", p.as_array())?.0),
        (None, Some(s)) => Smoothed::Given(read_poses(F, "smooth", s.as_array())?.0),
        _ => {
            return Err(PyValueError::new_err(format!(
                "{F}: give either poses (the key poses) or smooth (the smoothed motion's poses)"
            )))
        }
    };
    let playback = playback.as_ref().map(|p| &p.get().inner);
    let out = py
        .detach(|| {
            let timing = KeysTiming {
                key_frames: &key_frames,
                period,
                size,
                playback,
            };
            match &smoothed {
                Smoothed::Keys(keys) => {
                    let smooth = screw_pace_poses(keys, scheme, levels, closed)?;
                    core_keys_parameters(&timing, &frames, &smooth)
                }
                Smoothed::Given(smooth) => core_keys_parameters(&timing, &frames, smooth),
            }
        })
        .map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
}

/// pace_parameters(spans) -> ndarray
///
/// The motion parameters `s + j / PACE_SAMPLES` (j = 0..PACE_SAMPLES) of each span s, span
/// after span: where `keys_parameters` wants the smoothed motion (`smooth`).
#[pyfunction]
fn pace_parameters(py: Python<'_>, spans: usize) -> PyResult<Bound<'_, PyArray1<f64>>> {
    let out = core_pace_parameters(spans).map_err(|e| to_py_err("pace_parameters", e))?;
    Ok(out.into_pyarray(py))
}

/// rotation_matrices(values, mode) -> ndarray
///
/// (N, 3, 3) rotation matrices of (N, k) rotation channel values in Blender's `mode`:
/// quaternions (w, x, y, z) normalised (zero: identity), axis-angle (angle, x, y, z) about
/// the normalised axis (zero axis: identity), Euler (x, y, z) radians with "XYZ" meaning X
/// applied first (R = Rz Ry Rx). GIL released.
#[pyfunction]
fn rotation_matrices<'py>(
    py: Python<'py>,
    values: FloatArray<'py>,
    mode: &str,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = "rotation_matrices";
    let mode = RotationMode::from_name(mode).map_err(|e| to_py_err(F, e))?;
    let values = read_rows(F, "values", &values, mode.width())?;
    let out = py
        .detach(|| {
            core_rotation_matrices(&values, mode).map(|m| {
                let mut out = Array3::<f64>::zeros((m.len(), 3, 3));
                for (i, m) in m.iter().enumerate() {
                    for r in 0..3 {
                        for c in 0..3 {
                            out[[i, r, c]] = m.col(c)[r];
                        }
                    }
                }
                out
            })
        })
        .map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
}

/// Adds the intent functions, `Playback` and their constants to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyPlayback>()?;
    m.add_function(wrap_pyfunction!(analyse_spans, m)?)?;
    m.add_function(wrap_pyfunction!(keys_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(pace_parameters, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_matrices, m)?)?;
    m.add("WIND_LIMIT", WIND_LIMIT)?;
    m.add("WIND_STEP", WIND_STEP)?;
    m.add("SPAN_SAMPLES", SPAN_SAMPLES)?;
    m.add("MAX_SPAN_SAMPLES", MAX_SPAN_SAMPLES)?;
    m.add("HOLD_TOLERANCE", HOLD_TOLERANCE)?;
    m.add("PACE_SAMPLES", PACE_SAMPLES)?;
    Ok(())
}
