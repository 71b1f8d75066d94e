//! Python bindings of `polyscrew`: conversion and nothing else.
//!
//! Every function has the same shape: take array-likes, check shapes, release the GIL, call
//! the core, map the error once (`to_py_err`), wrap the result as numpy arrays.

mod angular_velocity;
mod args;
mod denoise;
mod fcurve;
mod feature;
mod intent;
mod reduce;
mod sweep;

use glam::{DQuat, DVec3};
use numpy::ndarray::{Array2, Array3, ArrayViewD};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::motion::sample::sample_footprint;
use polyscrew::motion::screw::MAX_T;
use polyscrew::motion::subdivision::{subdivision_footprint, SUBDIVISION_HINT};
use polyscrew::{
    rotation_channels as core_rotation_channels, sample as core_sample,
    subdivide as core_subdivide, subdivided_len, Error, MotionSpec, Pose, RotationMode, Scheme,
    Screw, Timing, MAX_LEVELS,
};
use pyo3::exceptions::{PyMemoryError, PyValueError};
use pyo3::prelude::*;

pub use args::{float_array, FloatArray};
use args::{Function, Sample, SampleChannels, SampleVectors, Subdivide, SubdivideVectors};

/// The one place a core error becomes a Python exception, with the function's name:
/// `ValueError`, or `MemoryError` when the allocator refused memory within the budget.
pub fn to_py_err(function: &str, err: Error) -> PyErr {
    match err {
        Error::Memory { budget: None, .. } => PyMemoryError::new_err(format!("{function}: {err}")),
        _ => PyValueError::new_err(format!("{function}: {err}")),
    }
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
    PyValueError::new_err(format!(
        "{function}: {what}: expected shape {expected}, got {got:?}"
    ))
}

/// The number of `(4, 4)` matrices in a `(4, 4)` or `(N, 4, 4)` shape (and whether it is a
/// single matrix), or a shape error.
pub fn pose_count(function: &str, what: &str, shape: &[usize]) -> PyResult<(usize, bool)> {
    match shape {
        [4, 4] => Ok((1, true)),
        [n, 4, 4] => Ok((*n, false)),
        _ => Err(shape_err(function, what, "(4, 4) or (N, 4, 4)", shape)),
    }
}

/// Reads `(4, 4)` or `(N, 4, 4)` matrices into validated poses (no GIL needed). Errors name
/// the argument: `"{function}: {what}: pose 2: ..."` (`"{function}: {what}: ..."` for a
/// single matrix).
pub fn read_poses(function: &str, what: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Vec<Pose>> {
    let (n, single) = pose_count(function, what, array.shape())?;
    let mut poses = try_vec(n, "input poses").map_err(|e| to_py_err(function, e))?;
    let mut values = array.iter();
    for i in 0..n {
        let mut m = [0.0; 16];
        for (slot, v) in m.iter_mut().zip(&mut values) {
            *slot = *v;
        }
        let row = |r: usize| [m[4 * r], m[4 * r + 1], m[4 * r + 2], m[4 * r + 3]];
        let pose = Pose::from_rows(&[row(0), row(1), row(2), row(3)], i).map_err(|e| {
            if single {
                match e {
                    Error::BadPose { defect, .. } => {
                        PyValueError::new_err(format!("{function}: {what}: {defect}"))
                    }
                    other => to_py_err(function, other),
                }
            } else {
                PyValueError::new_err(format!("{function}: {what}: {e}"))
            }
        })?;
        poses.push(pose);
    }
    Ok(poses)
}

/// Reads `(N, 4, 4)` key poses (a single matrix is refused), no GIL needed.
pub fn read_keys(function: &str, poses: &ArrayViewD<'_, f64>) -> PyResult<Vec<Pose>> {
    let (_, single) = pose_count(function, "poses", poses.shape())?;
    if single {
        return Err(shape_err(function, "poses", "(N, 4, 4)", &[4, 4]));
    }
    read_poses(function, "poses", poses)
}

/// The key count of an `(N, 4, 4)` argument (checked again when read).
pub fn key_count(function: &str, poses: &FloatArray<'_>) -> PyResult<usize> {
    pose_count(function, "poses", poses.as_array().shape()).map(|(n, _)| n)
}

/// Poses as an `(N, 4, 4)` array in Blender's layout (allocated fallibly).
pub fn poses_to_array(poses: &[Pose]) -> Result<Array3<f64>, Error> {
    let mut flat = try_vec(poses.len().saturating_mul(16), "output poses")?;
    for p in poses {
        flat.extend(p.to_rows().iter().flatten());
    }
    Ok(Array3::from_shape_vec((poses.len(), 4, 4), flat).expect("16 values per pose"))
}

/// Reads a 1-D float array (no GIL needed).
pub fn read_vector(function: &str, what: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Vec<f64>> {
    if array.ndim() != 1 {
        return Err(shape_err(function, what, "(N,)", array.shape()));
    }
    let mut out = try_vec(array.len(), "input values").map_err(|e| to_py_err(function, e))?;
    out.extend(array.iter().copied());
    Ok(out)
}

/// The length of a 1-D array (checked again when read).
pub fn vector_len(function: &str, what: &str, array: &FloatArray<'_>) -> PyResult<usize> {
    let a = array.as_array();
    if a.ndim() != 1 {
        return Err(shape_err(function, what, "(N,)", a.shape()));
    }
    Ok(a.len())
}

/// Reads `(N, 3)` rows without judging their values (no GIL needed).
pub fn read_rows3(
    function: &str,
    what: &str,
    array: &ArrayViewD<'_, f64>,
    expected: &str,
) -> PyResult<Vec<DVec3>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(shape_err(function, what, expected, shape));
    }
    let mut out = try_vec(shape[0], "input vectors").map_err(|e| to_py_err(function, e))?;
    for row in array.rows() {
        out.push(DVec3::new(row[0], row[1], row[2]));
    }
    Ok(out)
}

/// The row count of an `(N, 3)` argument (checked again when read).
pub fn rows3_len(array: &FloatArray<'_>) -> usize {
    array.as_array().shape().first().copied().unwrap_or(0)
}

/// Reads `(N, 3)` vectors, finite and within the working range (no GIL needed).
pub fn read_vec3s(function: &str, what: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Vec<DVec3>> {
    let v = read_rows3(function, what, array, "(N, 3)")?;
    polyscrew::motion::subdivision::check_range(&v).map_err(|e| arg_err(function, what, e))?;
    Ok(v)
}

/// `(N, 3)` vectors as an array (allocated fallibly).
pub fn vec3s_to_array(v: &[DVec3]) -> Result<Array2<f64>, Error> {
    let mut flat = try_vec(v.len().saturating_mul(3), "output vectors")?;
    for p in v {
        flat.extend(p.to_array());
    }
    Ok(Array2::from_shape_vec((v.len(), 3), flat).expect("3 values per vector"))
}

/// Parses a scheme name and timing name shared by several functions.
pub fn read_spec(
    function: &str,
    scheme: &str,
    levels: u32,
    closed: bool,
    period: Option<f64>,
    timing: &str,
) -> PyResult<MotionSpec> {
    let scheme = Scheme::from_name(scheme).map_err(|e| to_py_err(function, e))?;
    let timing = Timing::from_name(timing).map_err(|e| to_py_err(function, e))?;
    Ok(MotionSpec {
        scheme,
        levels,
        closed,
        period,
        timing,
    })
}

/// How to ask a sampling call for less memory.
const SAMPLE_HINT: &str = polyscrew::motion::sample::SAMPLE_HINT;

/// The screw between two poses (Rossignac-Kim): axis, point on the axis, angle, slide.
#[pyclass(frozen, module = "polyscrew", name = "Screw")]
pub struct PyScrew {
    inner: Screw,
}

#[pymethods]
impl PyScrew {
    /// Unit direction of the screw axis, shape (3,).
    #[getter]
    fn axis<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        self.inner.axis().to_array().to_vec().into_pyarray(py)
    }
    /// The point of the axis nearest to the first pose's origin, shape (3,).
    #[getter]
    fn point<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        self.inner.point().to_array().to_vec().into_pyarray(py)
    }
    /// Rotation angle about the axis, radians in [0, pi].
    #[getter]
    fn angle(&self) -> f64 {
        self.inner.angle()
    }
    /// Translation along the axis.
    #[getter]
    fn slide(&self) -> f64 {
        self.inner.slide()
    }
    fn __repr__(&self) -> String {
        let (a, p) = (self.inner.axis(), self.inner.point());
        format!(
            "Screw(axis=[{:.6}, {:.6}, {:.6}], point=[{:.6}, {:.6}, {:.6}], angle={:.9}, slide={:.9})",
            a.x,
            a.y,
            a.z,
            p.x,
            p.y,
            p.z,
            self.inner.angle(),
            self.inner.slide()
        )
    }
}

/// Reads exactly one pose.
fn read_one_pose(function: &str, what: &str, obj: &Bound<'_, PyAny>) -> PyResult<Pose> {
    let array = float_array(function, what, obj)?;
    let view = array.as_array();
    let (_, single) = pose_count(function, what, view.shape())?;
    if !single {
        return Err(shape_err(function, what, "(4, 4)", view.shape()));
    }
    Ok(read_poses(function, what, &view)?[0])
}

/// screw(a, b) -> Screw
///
/// The minimal screw carrying pose `a` to pose `b` (Rossignac-Kim): `b = M a` with `M` a
/// rotation by `angle` in [0, pi] about the line through `point` along unit `axis`, plus
/// `slide` along it. A pure translation has angle 0 and its axis along the translation.
/// `a`, `b`: (4, 4) rigid matrices, translation in the last column.
/// Raises ValueError for a non-rigid matrix, NaN or a wrong shape.
#[pyfunction]
fn screw(a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<PyScrew> {
    let a = read_one_pose("screw", "a", a)?;
    let b = read_one_pose("screw", "b", b)?;
    Ok(PyScrew {
        inner: Screw::between(&a, &b),
    })
}

/// interpolate(a, b, t) -> ndarray
///
/// `s(a, t, b)`: the pose a fraction `t` along the screw from `a` to `b` (t = 0 gives a,
/// t = 1 gives b; any real t extrapolates). Returns (4, 4) for a float `t`, (len(t), 4, 4)
/// for an array. Raises ValueError for bad poses or non-finite t.
#[pyfunction]
fn interpolate<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = "interpolate";
    let a = read_one_pose(F, "a", a)?;
    let b = read_one_pose(F, "b", b)?;
    let sc = Screw::between(&a, &b);
    let check_t = |index: usize, t: f64| {
        if t.abs() <= MAX_T {
            Ok(())
        } else if t.is_finite() {
            Err(to_py_err(
                F,
                Error::OutOfRange {
                    what: "t",
                    index,
                    value: t,
                    range: "+-1e12",
                },
            ))
        } else {
            Err(to_py_err(F, Error::NotFinite { what: "t", index }))
        }
    };
    if t.is_instance_of::<pyo3::types::PyFloat>() || t.is_instance_of::<pyo3::types::PyInt>() {
        let t = args::float_scalar(F, "t", t)?;
        check_t(0, t)?;
        let out = poses_to_array(&[sc.eval(t)]).map_err(|e| to_py_err(F, e))?;
        return Ok(out
            .index_axis_move(numpy::ndarray::Axis(0), 0)
            .into_pyarray(py)
            .into_any());
    }
    let ts = float_array(F, "t", t)?;
    let view = ts.as_array();
    if view.ndim() == 0 {
        let t = view.iter().next().copied().unwrap_or(f64::NAN);
        check_t(0, t)?;
        let out = poses_to_array(&[sc.eval(t)]).map_err(|e| to_py_err(F, e))?;
        return Ok(out
            .index_axis_move(numpy::ndarray::Axis(0), 0)
            .into_pyarray(py)
            .into_any());
    }
    let m = vector_len(F, "t", &ts)?;
    check_budget(
        F,
        Footprint::of::<f64>(m).and::<Pose>(m).and::<[f64; 16]>(m),
        "the interpolated poses",
        "pass fewer t at once",
    )?;
    let out = py.detach(|| -> PyResult<Array3<f64>> {
        let ts = read_vector(F, "t", &view)?;
        for (index, t) in ts.iter().enumerate() {
            check_t(index, *t)?;
        }
        let mut poses = try_vec(ts.len(), "interpolated poses").map_err(|e| to_py_err(F, e))?;
        poses.extend(ts.iter().map(|t| sc.eval(*t)));
        poses_to_array(&poses).map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py).into_any())
}

/// The input keys' footprint: the poses read from them.
fn keys_footprint(n: usize) -> Footprint {
    Footprint::of::<Pose>(n)
}

/// subdivide(poses, scheme="jarek", levels=4, closed=False) -> ndarray
///
/// Split&Tweak subdivision of the polyscrew through `poses` (N, 4, 4) with scheme
/// "four_point" (interpolating, C1), "bspline" (C2) or "jarek" (C2), `levels` in 0..=12.
/// Returns (N * 2**levels, 4, 4) for a closed cycle, ((N - 1) * 2**levels + 1, 4, 4) for an
/// open sequence, whose first and last poses are kept exactly.
/// Raises ValueError naming the bad pose index and the reason.
#[pyfunction]
#[pyo3(signature = (poses, scheme="jarek", levels=4, closed=false))]
fn subdivide<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::scheme::<Subdivide>)] scheme: &str,
    #[pyo3(from_py_with = args::levels::<Subdivide>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<Subdivide>)] closed: bool,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = Subdivide::NAME;
    let spec = read_spec(F, scheme, levels, closed, None, "smooth")?;
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let out_len = if n >= 2 {
        subdivided_len(n, levels, closed)
    } else {
        0
    };
    check_budget(
        F,
        keys_footprint(n)
            + subdivision_footprint::<Pose>(n, levels, closed)
            + Footprint::of::<[f64; 16]>(out_len),
        "the subdivided poses",
        SUBDIVISION_HINT,
    )?;
    let view = poses.as_array();
    let out = py.detach(|| -> PyResult<Array3<f64>> {
        let keys = read_keys(F, &view)?;
        core_subdivide(&keys, spec.scheme, spec.levels, spec.closed)
            .and_then(|d| poses_to_array(&d))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// The inputs of the sampling functions: key count, key times and times arrays.
struct TimedInput<'py> {
    key_times: FloatArray<'py>,
    times: FloatArray<'py>,
    n_times: usize,
    n_key_times: usize,
}

fn read_timed<'py>(
    function: &str,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
) -> PyResult<TimedInput<'py>> {
    let key_times = float_array(function, "key_times", key_times)?;
    let times = float_array(function, "times", times)?;
    let n_key_times = vector_len(function, "key_times", &key_times)?;
    let n_times = vector_len(function, "times", &times)?;
    Ok(TimedInput {
        key_times,
        times,
        n_times,
        n_key_times,
    })
}

/// sample(poses, key_times, times, scheme="jarek", levels=4, closed=False, period=None, timing="smooth") -> ndarray
///
/// The subdivided motion of `poses` (N, 4, 4), keyed at `key_times` (N,) strictly
/// increasing, evaluated at `times` (M,) (frames, subframes): (M, 4, 4). `closed` makes the
/// keys a cycle of length `period` (default: closed after the mean key spacing);
/// `timing="smooth"` maps time to the motion by a monotone C1 cubic through the keys,
/// `"linear"` maps each key span linearly. Open motions hold their end poses outside the
/// keys' range. Between dense poses the motion is the screw joining them.
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, scheme="jarek", levels=4, closed=false, period=None, timing="smooth"))]
#[allow(clippy::too_many_arguments)]
fn sample<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::scheme::<Sample>)] scheme: &str,
    #[pyo3(from_py_with = args::levels::<Sample>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<Sample>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = args::timing::<Sample>)] timing: &str,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = Sample::NAME;
    let period = args::optional_float(F, "period", period)?;
    let spec = read_spec(F, scheme, levels, closed, period, timing)?;
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let input = read_timed(F, key_times, times)?;
    let m = input.n_times;
    check_budget(
        F,
        keys_footprint(n)
            + Footprint::of::<f64>(input.n_key_times + m)
            + sample_footprint::<Pose>(n, m, &spec)
            + Footprint::of::<[f64; 16]>(m),
        "the sampled poses",
        SAMPLE_HINT,
    )?;
    let (view, kt, tt) = (
        poses.as_array(),
        input.key_times.as_array(),
        input.times.as_array(),
    );
    let out = py.detach(|| -> PyResult<Array3<f64>> {
        let keys = read_keys(F, &view)?;
        let key_times = read_vector(F, "key_times", &kt)?;
        let times = read_vector(F, "times", &tt)?;
        core_sample(&keys, &key_times, &times, &spec)
            .and_then(|p| poses_to_array(&p))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// sample_channels(poses, key_times, times, mode, previous=None, scheme="jarek", levels=4, closed=False, period=None, timing="smooth") -> (ndarray, ndarray)
///
/// `sample` as Blender's channels: the locations (M, 3) and the rotation channels of
/// `rotation_channels(sample(...), mode, previous)`, without building and re-checking the
/// (M, 4, 4) matrices in between. What a bake writes.
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, mode, previous=None, scheme="jarek", levels=4, closed=false, period=None, timing="smooth"))]
#[allow(clippy::too_many_arguments)]
#[allow(clippy::type_complexity)]
fn sample_channels<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    mode: &Bound<'py, PyAny>,
    previous: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = args::scheme::<SampleChannels>)] scheme: &str,
    #[pyo3(from_py_with = args::levels::<SampleChannels>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SampleChannels>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = args::timing::<SampleChannels>)] timing: &str,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    const F: &str = SampleChannels::NAME;
    let mode =
        RotationMode::from_name(args::str_arg(F, "mode", mode)?).map_err(|e| to_py_err(F, e))?;
    let period = args::optional_float(F, "period", period)?;
    let spec = read_spec(F, scheme, levels, closed, period, timing)?;
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let input = read_timed(F, key_times, times)?;
    let previous = previous
        .filter(|p| !p.is_none())
        .map(|p| float_array(F, "previous", p))
        .transpose()?;
    let m = input.n_times;
    let width = mode.width();
    check_budget(
        F,
        keys_footprint(n)
            + Footprint::of::<f64>(input.n_key_times + m)
            + sample_footprint::<Pose>(n, m, &spec)
            + Footprint::of::<(DQuat, DVec3)>(m)
            + Footprint::of::<[f64; 3]>(m)
            + Footprint::of::<f64>(m.saturating_mul(width)),
        "the sampled channels",
        SAMPLE_HINT,
    )?;
    let (view, kt, tt) = (
        poses.as_array(),
        input.key_times.as_array(),
        input.times.as_array(),
    );
    let pv = previous.as_ref().map(|p| p.as_array());
    let (locations, rotations) = py.detach(|| -> PyResult<(Array2<f64>, Array2<f64>)> {
        let keys = read_keys(F, &view)?;
        let key_times = read_vector(F, "key_times", &kt)?;
        let times = read_vector(F, "times", &tt)?;
        let previous = pv
            .as_ref()
            .map(|p| read_vector(F, "previous", p))
            .transpose()?;
        let run = || -> Result<(Array2<f64>, Vec<f64>), Error> {
            let dense = core_sample(&keys, &key_times, &times, &spec)?;
            let mut quats = try_vec(dense.len(), "sampled rotations")?;
            quats.extend(dense.iter().map(|p| p.rotation));
            let mut locations = try_vec(dense.len(), "sampled locations")?;
            locations.extend(dense.iter().map(|p| p.translation));
            drop(dense);
            let rotations = core_rotation_channels(&quats, mode, previous.as_deref())?;
            Ok((vec3s_to_array(&locations)?, rotations))
        };
        let (locations, rotations) = run().map_err(|e| to_py_err(F, e))?;
        let rotations = Array2::from_shape_vec((times.len(), width), rotations)
            .map_err(|e| PyValueError::new_err(format!("{F}: {e}")))?;
        Ok((locations, rotations))
    })?;
    Ok((locations.into_pyarray(py), rotations.into_pyarray(py)))
}

/// subdivide_vectors(values, scheme="jarek", levels=4, closed=False) -> ndarray
///
/// The same schemes applied to plain vectors `values` (N, 3) (the linear masks of
/// ScrewBender section 2); the output count is as in `subdivide`.
#[pyfunction]
#[pyo3(signature = (values, scheme="jarek", levels=4, closed=false))]
fn subdivide_vectors<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::scheme::<SubdivideVectors>)] scheme: &str,
    #[pyo3(from_py_with = args::levels::<SubdivideVectors>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SubdivideVectors>)] closed: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = SubdivideVectors::NAME;
    let spec = read_spec(F, scheme, levels, closed, None, "smooth")?;
    let values = float_array(F, "values", values)?;
    let n = rows3_len(&values);
    let out_len = if n >= 2 {
        subdivided_len(n, levels, closed)
    } else {
        0
    };
    check_budget(
        F,
        Footprint::of::<DVec3>(n)
            + subdivision_footprint::<DVec3>(n, levels, closed)
            + Footprint::of::<[f64; 3]>(out_len),
        "the subdivided vectors",
        SUBDIVISION_HINT,
    )?;
    let view = values.as_array();
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let keys = read_vec3s(F, "values", &view)?;
        core_subdivide(&keys, spec.scheme, spec.levels, spec.closed)
            .and_then(|d| vec3s_to_array(&d))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// sample_vectors(values, key_times, times, scheme="jarek", levels=4, closed=False, period=None, timing="smooth") -> ndarray
///
/// `sample` for plain vectors `values` (N, 3): linear subdivision, the same timing,
/// straight lines between dense values. Used for log-scale smoothing. Returns (M, 3).
#[pyfunction]
#[pyo3(signature = (values, key_times, times, scheme="jarek", levels=4, closed=false, period=None, timing="smooth"))]
#[allow(clippy::too_many_arguments)]
fn sample_vectors<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::scheme::<SampleVectors>)] scheme: &str,
    #[pyo3(from_py_with = args::levels::<SampleVectors>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SampleVectors>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = args::timing::<SampleVectors>)] timing: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = SampleVectors::NAME;
    let period = args::optional_float(F, "period", period)?;
    let spec = read_spec(F, scheme, levels, closed, period, timing)?;
    let values = float_array(F, "values", values)?;
    let n = rows3_len(&values);
    let input = read_timed(F, key_times, times)?;
    let m = input.n_times;
    check_budget(
        F,
        Footprint::of::<DVec3>(n)
            + Footprint::of::<f64>(input.n_key_times + m)
            + sample_footprint::<DVec3>(n, m, &spec)
            + Footprint::of::<[f64; 3]>(m),
        "the sampled vectors",
        SAMPLE_HINT,
    )?;
    let (view, kt, tt) = (
        values.as_array(),
        input.key_times.as_array(),
        input.times.as_array(),
    );
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let keys = read_vec3s(F, "values", &view)?;
        let key_times = read_vector(F, "key_times", &kt)?;
        let times = read_vector(F, "times", &tt)?;
        core_sample(&keys, &key_times, &times, &spec)
            .and_then(|v| vec3s_to_array(&v))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// Reads `(N, 3, 3)` or `(N, 4, 4)` rotations as quaternions (no GIL needed).
fn read_rotations(function: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Vec<DQuat>> {
    let shape = array.shape();
    match shape {
        [_, 4, 4] => {
            let poses = read_poses(function, "rotations", array)?;
            let mut out = try_vec(poses.len(), "rotations").map_err(|e| to_py_err(function, e))?;
            out.extend(poses.iter().map(|p| p.rotation));
            Ok(out)
        }
        [n, 3, 3] => {
            let mut out = try_vec(*n, "rotations").map_err(|e| to_py_err(function, e))?;
            let mut values = array.iter();
            for i in 0..*n {
                let mut m = [0.0; 9];
                for (slot, v) in m.iter_mut().zip(&mut values) {
                    *slot = *v;
                }
                let rows = [
                    [m[0], m[1], m[2], 0.0],
                    [m[3], m[4], m[5], 0.0],
                    [m[6], m[7], m[8], 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ];
                let pose = Pose::from_rows(&rows, i)
                    .map_err(|e| PyValueError::new_err(format!("{function}: rotations: {e}")))?;
                out.push(pose.rotation);
            }
            Ok(out)
        }
        _ => Err(shape_err(
            function,
            "rotations",
            "(N, 3, 3) or (N, 4, 4)",
            shape,
        )),
    }
}

/// rotation_channels(rotations, mode, previous=None) -> ndarray
///
/// Blender rotation channels of `rotations` ((N, 3, 3) or (N, 4, 4), rigid), continuous
/// frame to frame. `mode`: "QUATERNION" -> (N, 4) w, x, y, z without sign flips;
/// "AXIS_ANGLE" -> (N, 4) angle, x, y, z, unwrapped; "XYZ", "XZY", "YXZ", "YZX", "ZXY",
/// "ZYX" -> (N, 3) Euler angles (radians, per axis x, y, z) each compatible with the
/// previous frame as `Euler.make_compatible` does. `previous`: the channel values just
/// before the first frame, to continue from.
#[pyfunction]
#[pyo3(signature = (rotations, mode, previous=None))]
fn rotation_channels<'py>(
    py: Python<'py>,
    rotations: &Bound<'py, PyAny>,
    mode: &Bound<'py, PyAny>,
    previous: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "rotation_channels";
    let mode =
        RotationMode::from_name(args::str_arg(F, "mode", mode)?).map_err(|e| to_py_err(F, e))?;
    let rotations = float_array(F, "rotations", rotations)?;
    let previous = previous
        .filter(|p| !p.is_none())
        .map(|p| float_array(F, "previous", p))
        .transpose()?;
    let view = rotations.as_array();
    let n = view.shape().first().copied().unwrap_or(0);
    let width = mode.width();
    check_budget(
        F,
        Footprint::of::<DQuat>(n) + Footprint::of::<f64>(n.saturating_mul(width)),
        "the rotation channels",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    let pv = previous.as_ref().map(|p| p.as_array());
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let quats = read_rotations(F, &view)?;
        let previous = pv
            .as_ref()
            .map(|p| read_vector(F, "previous", p))
            .transpose()?;
        let values = core_rotation_channels(&quats, mode, previous.as_deref())
            .map_err(|e| to_py_err(F, e))?;
        Array2::from_shape_vec((quats.len(), width), values)
            .map_err(|e| PyValueError::new_err(format!("{F}: {e}")))
    })?;
    Ok(out.into_pyarray(py))
}

/// memory_budget() -> int
///
/// The memory budget in bytes: the most one call may hold at its peak (output, working
/// memory, the copies it makes of its input). A call that would need more raises
/// ValueError up front, saying how much it asked for and how to ask for less.
#[pyfunction]
fn memory_budget() -> usize {
    polyscrew::memory_budget()
}

/// set_memory_budget(bytes) -> int
///
/// Sets the memory budget (bytes, >= 0) for every later call in the process and returns the
/// previous one. `DEFAULT_MEMORY_BUDGET` restores the default.
#[pyfunction]
fn set_memory_budget(bytes: &Bound<'_, PyAny>) -> PyResult<usize> {
    let bytes = args::int_in("set_memory_budget", "bytes", bytes, 0, i64::MAX)?;
    Ok(polyscrew::set_memory_budget(bytes as usize))
}

/// The extension module `polyscrew._polyscrew`; `polyscrew/__init__.py` re-exports it.
#[pymodule]
fn _polyscrew(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScrew>()?;
    m.add_function(wrap_pyfunction!(screw, m)?)?;
    m.add_function(wrap_pyfunction!(interpolate, m)?)?;
    m.add_function(wrap_pyfunction!(subdivide, m)?)?;
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(sample_channels, m)?)?;
    m.add_function(wrap_pyfunction!(subdivide_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(sample_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_channels, m)?)?;
    m.add_function(wrap_pyfunction!(memory_budget, m)?)?;
    m.add_function(wrap_pyfunction!(set_memory_budget, m)?)?;
    m.add("MAX_LEVELS", MAX_LEVELS)?;
    m.add("DEFAULT_MEMORY_BUDGET", polyscrew::DEFAULT_MEMORY_BUDGET)?;
    m.add("MAX_COORDINATE", polyscrew::motion::pose::MAX_COORDINATE)?;
    m.add("MAX_TIME", polyscrew::motion::timing::MAX_TIME)?;
    angular_velocity::register(m)?;
    sweep::register(m)?;
    feature::register(m)?;
    fcurve::register(m)?;
    intent::register(m)?;
    denoise::register(m)?;
    reduce::register(m)?;
    Ok(())
}
