//! Python bindings of `polyscrew`: conversion and nothing else.
//!
//! Every function has the same shape: take array-likes, check shapes, release the GIL, call
//! the core, map the error once (`to_py_err`), wrap the result as numpy arrays.

mod angular_velocity;
mod denoise;
mod feature;
mod sweep;

use glam::DVec3;
use numpy::ndarray::{Array2, Array3, ArrayViewD};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArray3, PyArrayLikeDyn};
use polyscrew::{
    rotation_channels as core_rotation_channels, subdivide as core_subdivide, Error, Motion,
    MotionSpec, Pose, RotationMode, Scheme, Screw, Timing, MAX_LEVELS,
};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

/// An array-like argument converted to float64 on the way in.
pub type FloatArray<'py> = PyArrayLikeDyn<'py, f64, AllowTypeChange>;

/// The one place a core error becomes a Python exception, with the function's name.
pub fn to_py_err(function: &str, err: Error) -> PyErr {
    PyValueError::new_err(format!("{function}: {err}"))
}

/// A shape error naming the argument, what was expected and what came.
pub fn shape_err(function: &str, what: &str, expected: &str, got: &[usize]) -> PyErr {
    PyValueError::new_err(format!(
        "{function}: {what}: expected shape {expected}, got {got:?}"
    ))
}

/// Reads `(4, 4)` or `(N, 4, 4)` matrices into validated poses. Returns the poses and
/// whether a single matrix was given.
pub fn read_poses(
    function: &str,
    what: &str,
    array: ArrayViewD<'_, f64>,
) -> PyResult<(Vec<Pose>, bool)> {
    let shape = array.shape().to_vec();
    let single = match shape.as_slice() {
        [4, 4] => true,
        [_, 4, 4] => false,
        _ => return Err(shape_err(function, what, "(4, 4) or (N, 4, 4)", &shape)),
    };
    let flat: Vec<f64> = array.iter().copied().collect();
    let poses = flat
        .chunks_exact(16)
        .enumerate()
        .map(|(i, m)| {
            let row = |r: usize| [m[4 * r], m[4 * r + 1], m[4 * r + 2], m[4 * r + 3]];
            Pose::from_rows(&[row(0), row(1), row(2), row(3)], i)
        })
        .collect::<Result<Vec<_>, _>>()
        .map_err(|e| to_py_err(function, e))?;
    Ok((poses, single))
}

/// Reads `(N, 4, 4)` key poses (a single matrix is refused).
pub fn read_keys(function: &str, poses: &FloatArray<'_>) -> PyResult<Vec<Pose>> {
    let (keys, single) = read_poses(function, "poses", poses.as_array())?;
    if single {
        return Err(shape_err(function, "poses", "(N, 4, 4)", &[4, 4]));
    }
    Ok(keys)
}

/// Poses as an `(N, 4, 4)` array in Blender's layout.
pub fn poses_to_array(poses: &[Pose]) -> Array3<f64> {
    let mut out = Array3::<f64>::zeros((poses.len(), 4, 4));
    for (i, p) in poses.iter().enumerate() {
        for (r, row) in p.to_rows().iter().enumerate() {
            for (c, v) in row.iter().enumerate() {
                out[[i, r, c]] = *v;
            }
        }
    }
    out
}

/// Reads a 1-D float array.
pub fn read_vector(function: &str, what: &str, array: ArrayViewD<'_, f64>) -> PyResult<Vec<f64>> {
    if array.ndim() != 1 {
        return Err(shape_err(function, what, "(N,)", array.shape()));
    }
    Ok(array.iter().copied().collect())
}

/// Reads `(N, 3)` vectors.
pub fn read_vec3s(function: &str, what: &str, array: ArrayViewD<'_, f64>) -> PyResult<Vec<DVec3>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(shape_err(function, what, "(N, 3)", shape));
    }
    let flat: Vec<f64> = array.iter().copied().collect();
    let v: Vec<DVec3> = flat.chunks_exact(3).map(DVec3::from_slice).collect();
    if let Some(index) = v.iter().position(|p| !p.is_finite()) {
        return Err(to_py_err(
            function,
            Error::NotFinite {
                what: "vector",
                index,
            },
        ));
    }
    Ok(v)
}

/// `(N, 3)` vectors as an array.
pub fn vec3s_to_array(v: &[DVec3]) -> Array2<f64> {
    let mut out = Array2::<f64>::zeros((v.len(), 3));
    for (i, p) in v.iter().enumerate() {
        out[[i, 0]] = p.x;
        out[[i, 1]] = p.y;
        out[[i, 2]] = p.z;
    }
    out
}

/// Parses a scheme name, levels and timing name shared by several functions.
pub fn read_spec(
    function: &str,
    scheme: &str,
    levels: i64,
    closed: bool,
    period: Option<f64>,
    timing: &str,
) -> PyResult<MotionSpec> {
    let scheme = Scheme::from_name(scheme).map_err(|e| to_py_err(function, e))?;
    let timing = Timing::from_name(timing).map_err(|e| to_py_err(function, e))?;
    let levels = u32::try_from(levels)
        .ok()
        .filter(|l| *l <= MAX_LEVELS)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "{function}: levels {levels} out of range 0..={MAX_LEVELS}"
            ))
        })?;
    Ok(MotionSpec {
        scheme,
        levels,
        closed,
        period,
        timing,
    })
}

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
fn read_one_pose(function: &str, what: &str, array: &FloatArray<'_>) -> PyResult<Pose> {
    let (poses, single) = read_poses(function, what, array.as_array())?;
    if !single {
        return Err(shape_err(
            function,
            what,
            "(4, 4)",
            array.as_array().shape(),
        ));
    }
    Ok(poses[0])
}

/// screw(a, b) -> Screw
///
/// The minimal screw carrying pose `a` to pose `b` (Rossignac-Kim): `b = M a` with `M` a
/// rotation by `angle` in [0, pi] about the line through `point` along unit `axis`, plus
/// `slide` along it. A pure translation has angle 0 and its axis along the translation.
/// `a`, `b`: (4, 4) rigid matrices, translation in the last column.
/// Raises ValueError for a non-rigid matrix, NaN or a wrong shape.
#[pyfunction]
fn screw(a: FloatArray<'_>, b: FloatArray<'_>) -> PyResult<PyScrew> {
    let a = read_one_pose("screw", "a", &a)?;
    let b = read_one_pose("screw", "b", &b)?;
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
    a: FloatArray<'py>,
    b: FloatArray<'py>,
    t: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = "interpolate";
    let a = read_one_pose(F, "a", &a)?;
    let b = read_one_pose(F, "b", &b)?;
    let sc = Screw::between(&a, &b);
    if let Ok(t) = t.extract::<f64>() {
        if !t.is_finite() {
            return Err(to_py_err(
                F,
                Error::NotFinite {
                    what: "t",
                    index: 0,
                },
            ));
        }
        let out = poses_to_array(&[sc.eval(t)]);
        return Ok(out
            .index_axis_move(numpy::ndarray::Axis(0), 0)
            .into_pyarray(py)
            .into_any());
    }
    let ts: FloatArray<'py> = t.extract()?;
    let ts = read_vector(F, "t", ts.as_array())?;
    if let Some(index) = ts.iter().position(|v| !v.is_finite()) {
        return Err(to_py_err(F, Error::NotFinite { what: "t", index }));
    }
    let out = py.detach(|| poses_to_array(&ts.iter().map(|t| sc.eval(*t)).collect::<Vec<_>>()));
    Ok(out.into_pyarray(py).into_any())
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
    poses: FloatArray<'py>,
    scheme: &str,
    levels: i64,
    closed: bool,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = "subdivide";
    let spec = read_spec(F, scheme, levels, closed, None, "smooth")?;
    let keys = read_keys(F, &poses)?;
    let out = py
        .detach(|| {
            core_subdivide(&keys, spec.scheme, spec.levels, spec.closed).map(|d| poses_to_array(&d))
        })
        .map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
}

/// Reads the key poses, key times and sample times shared by `sample` and `sample_vectors`.
fn read_times(
    function: &str,
    key_times: &FloatArray<'_>,
    times: &FloatArray<'_>,
) -> PyResult<(Vec<f64>, Vec<f64>)> {
    Ok((
        read_vector(function, "key_times", key_times.as_array())?,
        read_vector(function, "times", times.as_array())?,
    ))
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
    poses: FloatArray<'py>,
    key_times: FloatArray<'py>,
    times: FloatArray<'py>,
    scheme: &str,
    levels: i64,
    closed: bool,
    period: Option<f64>,
    timing: &str,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = "sample";
    let spec = read_spec(F, scheme, levels, closed, period, timing)?;
    let keys = read_keys(F, &poses)?;
    let (key_times, times) = read_times(F, &key_times, &times)?;
    let out = py
        .detach(|| {
            Motion::new(&keys, &key_times, &spec)
                .and_then(|m| m.sample(&times))
                .map(|p| poses_to_array(&p))
        })
        .map_err(|e| to_py_err(F, e))?;
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
    poses: FloatArray<'py>,
    key_times: FloatArray<'py>,
    times: FloatArray<'py>,
    mode: &str,
    previous: Option<FloatArray<'py>>,
    scheme: &str,
    levels: i64,
    closed: bool,
    period: Option<f64>,
    timing: &str,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    const F: &str = "sample_channels";
    let mode = RotationMode::from_name(mode).map_err(|e| to_py_err(F, e))?;
    let spec = read_spec(F, scheme, levels, closed, period, timing)?;
    let keys = read_keys(F, &poses)?;
    let (key_times, times) = read_times(F, &key_times, &times)?;
    let previous = previous
        .map(|p| read_vector(F, "previous", p.as_array()))
        .transpose()?;
    let (locations, rotations) = py
        .detach(|| {
            let dense = Motion::new(&keys, &key_times, &spec)?.sample(&times)?;
            let quats: Vec<_> = dense.iter().map(|p| p.rotation).collect();
            let locations: Vec<_> = dense.iter().map(|p| p.translation).collect();
            core_rotation_channels(&quats, mode, previous.as_deref())
                .map(|r| (vec3s_to_array(&locations), r))
        })
        .map_err(|e| to_py_err(F, e))?;
    let rotations =
        Array2::from_shape_vec((times.len(), mode.width()), rotations).expect("width * n values");
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
    values: FloatArray<'py>,
    scheme: &str,
    levels: i64,
    closed: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "subdivide_vectors";
    let spec = read_spec(F, scheme, levels, closed, None, "smooth")?;
    let keys = read_vec3s(F, "values", values.as_array())?;
    let out = py
        .detach(|| {
            core_subdivide(&keys, spec.scheme, spec.levels, spec.closed).map(|d| vec3s_to_array(&d))
        })
        .map_err(|e| to_py_err(F, e))?;
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
    values: FloatArray<'py>,
    key_times: FloatArray<'py>,
    times: FloatArray<'py>,
    scheme: &str,
    levels: i64,
    closed: bool,
    period: Option<f64>,
    timing: &str,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "sample_vectors";
    let spec = read_spec(F, scheme, levels, closed, period, timing)?;
    let keys = read_vec3s(F, "values", values.as_array())?;
    let (key_times, times) = read_times(F, &key_times, &times)?;
    let out = py
        .detach(|| {
            Motion::new(&keys, &key_times, &spec)
                .and_then(|m| m.sample(&times))
                .map(|v| vec3s_to_array(&v))
        })
        .map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
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
    rotations: FloatArray<'py>,
    mode: &str,
    previous: Option<FloatArray<'py>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "rotation_channels";
    let mode = RotationMode::from_name(mode).map_err(|e| to_py_err(F, e))?;
    let array = rotations.as_array();
    let shape = array.shape().to_vec();
    let quats = match shape.as_slice() {
        [_, 4, 4] => read_poses(F, "rotations", array)?
            .0
            .iter()
            .map(|p| p.rotation)
            .collect::<Vec<_>>(),
        [n, 3, 3] => {
            // Embed each 3x3 into a pose to share the validation.
            let mut m = numpy::ndarray::Array3::<f64>::zeros((*n, 4, 4));
            for i in 0..*n {
                for r in 0..3 {
                    for c in 0..3 {
                        m[[i, r, c]] = array[[i, r, c]];
                    }
                }
                m[[i, 3, 3]] = 1.0;
            }
            read_poses(F, "rotations", m.into_dyn().view())?
                .0
                .iter()
                .map(|p| p.rotation)
                .collect()
        }
        _ => return Err(shape_err(F, "rotations", "(N, 3, 3) or (N, 4, 4)", &shape)),
    };
    let previous = previous
        .map(|p| read_vector(F, "previous", p.as_array()))
        .transpose()?;
    let width = mode.width();
    let values = py
        .detach(|| core_rotation_channels(&quats, mode, previous.as_deref()))
        .map_err(|e| to_py_err(F, e))?;
    let out = Array2::from_shape_vec((quats.len(), width), values).expect("width * n values");
    Ok(out.into_pyarray(py))
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
    m.add("MAX_LEVELS", MAX_LEVELS)?;
    angular_velocity::register(m)?;
    sweep::register(m)?;
    feature::register(m)?;
    denoise::register(m)?;
    Ok(())
}
