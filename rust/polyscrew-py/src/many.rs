//! Binding of `polyscrew::intent::many`: Remove Noise's and Reduce Keys' per-owner steps for
//! many owners in one call (each the single-owner function on each part, to the bit).
//! Conversion only.

use numpy::ndarray::Array2;
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use pyo3::prelude::*;

use polyscrew::intent::{
    angles_near_many as core_angles_near_many, channels_many as core_channels_many,
    partial_moves_many as core_partial_moves_many, sample_many as core_sample_many, AngleRun,
    MoveRun, Playback,
};
use polyscrew::memory::Footprint;
use polyscrew::{MoveBounds, Pose, RotationMode, Scheme, Timing};

use crate::args::{
    self, float_array, int_list, sequence, str_arg, AnglesNearMany, ChannelsMany, Choice, Function,
    Most, PartialMovesMany, SampleMany,
};
use crate::arrays::{poses_to_array, read_keys, read_spec, read_vec3s, read_vector, vector_len};
use crate::errors::{check_budget, invalid, shape_err, to_py_err};
use crate::intent::playbacks_arg;
use crate::motion::{moved_poses, wrapped_angles, MovedPoses};

/// The most parts one call takes (a list of that many entries is refused before it is read).
pub(crate) const MAX_PARTS: usize = 1 << 32;

/// `counts` (S,) as lengths, each at least 0.
fn lengths(
    function: &'static str,
    what: &'static str,
    obj: &Bound<'_, PyAny>,
) -> PyResult<Vec<usize>> {
    int_list(function, what, obj, Most::AtMost(MAX_PARTS))?
        .into_iter()
        .map(|v| {
            usize::try_from(v).map_err(|_| invalid(format!("{function}: {what}: {v} is negative")))
        })
        .collect()
}

/// angles_near_many(
///     values: ArrayLike, reference: ArrayLike, modes: Sequence[RotationModeName],
///     channels: ArrayLike, counts: ArrayLike
/// ) -> FloatArray
///
/// ``angles_near`` of many curves in one call: ``values`` and ``reference`` (N,) are the
/// curves' values one after the other, curve ``i`` the next ``counts[i]`` of them, of rotation
/// channel ``channels[i]`` in ``modes[i]``; the result is, to the bit, each curve's
/// ``angles_near(values_i, reference_i, modes[i], channels[i])`` one after the other.
#[pyfunction]
fn angles_near_many<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    modes: &Bound<'py, PyAny>,
    channels: &Bound<'py, PyAny>,
    counts: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    const F: &str = AnglesNearMany::NAME;
    let counts = lengths(F, "counts", counts)?;
    let channels = lengths(F, "channels", channels)?;
    let modes = sequence(
        F,
        "modes",
        modes,
        Most::Exactly(counts.len()),
        "a sequence of mode names",
    )?;
    if modes.len() != counts.len() || channels.len() != counts.len() {
        return Err(invalid(format!(
            "{F}: modes, channels and counts differ in length ({}, {}, {})",
            modes.len(),
            channels.len(),
            counts.len()
        )));
    }
    let runs = modes
        .iter()
        .zip(channels.iter().zip(&counts))
        .enumerate()
        .map(|(i, (mode, (&channel, &len)))| {
            let mode = RotationMode::from_name(str_arg(F, "modes", mode)?)
                .map_err(|e| invalid(format!("{F}: modes: part {i}: {e}")))?;
            Ok(AngleRun { mode, channel, len })
        })
        .collect::<PyResult<Vec<_>>>()?;
    wrapped_angles(py, F, values, reference, move |values, reference| {
        core_angles_near_many(values, reference, &runs)
    })
}

/// partial_moves_many(
///     source: ArrayLike, target: ArrayLike, counts: ArrayLike, pivots: ArrayLike,
///     max_angles: ArrayLike, max_distances: ArrayLike
/// ) -> tuple[FloatArray, npt.NDArray[np.bool_]]
///
/// ``partial_moves`` of many owners in one call: ``source`` and ``target`` (N, 4, 4) are the
/// owners' poses one after the other, owner ``i`` the next ``counts[i]`` of them, with its
/// pivot ``pivots[i]`` ((S, 3)) and bounds ``max_angles[i]``, ``max_distances[i]`` ((S,));
/// the result is, to the bit, each owner's ``partial_moves`` one after the other.
#[pyfunction]
fn partial_moves_many<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    counts: &Bound<'py, PyAny>,
    pivots: &Bound<'py, PyAny>,
    max_angles: &Bound<'py, PyAny>,
    max_distances: &Bound<'py, PyAny>,
) -> PyResult<MovedPoses<'py>> {
    const F: &str = PartialMovesMany::NAME;
    let counts = lengths(F, "counts", counts)?;
    let s = counts.len();
    let pivots = float_array(F, "pivots", pivots)?;
    if pivots.shape() != [s, 3] {
        return Err(shape_err(F, "pivots", &format!("({s}, 3)"), pivots.shape()));
    }
    let max_angles = float_array(F, "max_angles", max_angles)?;
    let max_distances = float_array(F, "max_distances", max_distances)?;
    for (what, bounds) in [
        ("max_angles", &max_angles),
        ("max_distances", &max_distances),
    ] {
        if bounds.shape() != [s] {
            return Err(shape_err(F, what, &format!("({s},)"), bounds.shape()));
        }
    }
    let extra = pivots.copy() + max_angles.copy() + max_distances.copy();
    let (pivots, max_angles, max_distances) =
        (pivots.read()?, max_angles.read()?, max_distances.read()?);
    let pivots = read_vec3s(F, "pivots", &pivots.as_array())?;
    let angles = read_vector(F, "max_angles", &max_angles.as_array())?;
    let distances = read_vector(F, "max_distances", &max_distances.as_array())?;
    let runs: Vec<MoveRun> = counts
        .iter()
        .zip(pivots.iter().zip(angles.iter().zip(&distances)))
        .map(|(&len, (&pivot, (&angle, &distance)))| MoveRun {
            len,
            pivot,
            bounds: MoveBounds { angle, distance },
        })
        .collect();
    moved_poses(py, F, source, target, extra, move |source, target| {
        core_partial_moves_many(source, target, &runs)
    })
}

/// sample_many(
///     poses: ArrayLike, key_times: ArrayLike, times: ArrayLike, scheme: SchemeName = "jarek",
///     levels: int = 4, timing: TimeMapName = "smooth"
/// ) -> FloatArray
///
/// ``sample`` of many owners keyed at the same ``key_times`` (K,), at the same ``times``
/// (T,), in one call: ``poses`` (O * K, 4, 4) are the owners' keys one after the other; the
/// result (O * T, 4, 4) is, to the bit, each owner's ``sample(poses_i, key_times, times,
/// scheme, levels, timing=timing)`` one after the other (open motions).
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, scheme=Choice::of(Scheme::Jarek), levels=4, timing=Choice::of(Timing::Smooth)))]
#[pyo3(text_signature = "(poses, key_times, times, scheme='jarek', levels=4, timing='smooth')")]
fn sample_many<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    scheme: Choice<SampleMany, Scheme>,
    #[pyo3(from_py_with = args::levels::<SampleMany>)] levels: u32,
    timing: Choice<SampleMany, Timing>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = SampleMany::NAME;
    let spec = read_spec(scheme.0, levels, false, None, timing.0);
    let poses = float_array(F, "poses", poses)?;
    let key_times = float_array(F, "key_times", key_times)?;
    let times = float_array(F, "times", times)?;
    let n = match poses.shape() {
        [n, 4, 4] => *n,
        shape => return Err(shape_err(F, "poses", "(O * K, 4, 4)", shape)),
    };
    let k = vector_len(F, "key_times", &key_times)?;
    let t = vector_len(F, "times", &times)?;
    if k == 0 || n % k != 0 {
        return Err(invalid(format!(
            "{F}: poses: {n} poses are not whole owners of {k} keys"
        )));
    }
    let owners = n / k;
    check_budget(
        F,
        poses.copy()
            + key_times.copy()
            + times.copy()
            + Footprint::of::<Pose>(n)
            + polyscrew::motion::sample::sample_footprint::<Pose>(k, t, &spec)
            + Footprint::of::<Pose>(owners.saturating_mul(t))
            + Footprint::of::<[f64; 16]>(owners.saturating_mul(t)),
        "the sampled poses",
        polyscrew::motion::sample::SAMPLE_HINT,
    )?;
    let (poses, key_times, times) = (poses.read()?, key_times.read()?, times.read()?);
    let (pv, kv, tv) = (poses.as_array(), key_times.as_array(), times.as_array());
    let out = py.detach(|| -> PyResult<numpy::ndarray::Array3<f64>> {
        let keys = read_keys(F, &pv)?;
        let key_times = read_vector(F, "key_times", &kv)?;
        let times = read_vector(F, "times", &tv)?;
        core_sample_many(&keys, &key_times, &times, owners, &spec)
            .and_then(|p| poses_to_array(&p))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// One playback's location, rotation and scale rows.
type Channels<'py> = (
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
    Bound<'py, PyArray2<f64>>,
);

/// channels_many(
///     playbacks: Sequence[Playback], frames: ArrayLike
/// ) -> list[tuple[FloatArray, FloatArray, FloatArray]]
///
/// ``Playback.channels`` of many playbacks at the same ``frames`` (T,) in one call: per
/// playback, to the bit, its location (T, 3), rotation (T, 3 or 4) and scale (T, 3).
#[pyfunction]
fn channels_many<'py>(
    py: Python<'py>,
    playbacks: &Bound<'py, PyAny>,
    frames: &Bound<'py, PyAny>,
) -> PyResult<Vec<Channels<'py>>> {
    const F: &str = ChannelsMany::NAME;
    let bound = playbacks_arg(F, playbacks)?;
    let frames = float_array(F, "frames", frames)?;
    let t = vector_len(F, "frames", &frames)?;
    let values: usize = bound.iter().map(|p| p.get().inner.width()).sum();
    check_budget(
        F,
        frames.copy() + Footprint::of::<f64>(t).and::<f64>(t.saturating_mul(2 * values)),
        "the channel values",
        "play fewer owners or frames at once",
    )?;
    let frames = frames.read()?;
    let view = frames.as_array();
    let inner: Vec<&Playback> = bound.iter().map(|p| &p.get().inner).collect();
    let rows = py.detach(|| -> PyResult<Vec<Vec<f64>>> {
        let frames = read_vector(F, "frames", &view)?;
        core_channels_many(&inner, &frames).map_err(|e| to_py_err(F, e))
    })?;
    let mut out = Vec::with_capacity(rows.len());
    for (playback, rows) in inner.iter().zip(rows) {
        let (width, w) = (playback.width(), playback.mode().width());
        let column = |lo: usize, hi: usize| -> PyResult<Bound<'py, PyArray2<f64>>> {
            let values: Vec<f64> = rows
                .chunks_exact(width)
                .flat_map(|r| r[lo..hi].iter().copied())
                .collect();
            Array2::from_shape_vec((t, hi - lo), values)
                .map(|a| a.into_pyarray(py))
                .map_err(|e| invalid(format!("{F}: {e}")))
        };
        out.push((column(0, 3)?, column(3, 3 + w)?, column(3 + w, width)?));
    }
    Ok(out)
}

/// Registers the functions.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(angles_near_many, m)?)?;
    m.add_function(wrap_pyfunction!(partial_moves_many, m)?)?;
    m.add_function(wrap_pyfunction!(sample_many, m)?)?;
    m.add_function(wrap_pyfunction!(channels_many, m)?)?;
    Ok(())
}
