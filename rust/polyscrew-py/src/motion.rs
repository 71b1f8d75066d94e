//! Binding of the motion functions (`polyscrew::motion`): screws, interpolation,
//! subdivision, sampling, rotation channels, and the memory budget. Conversion only.

use glam::{DQuat, DVec3};
use numpy::ndarray::{Array2, Array3, ArrayViewD, Ix3};
use numpy::{IntoPyArray, PyArray1, PyArray2, PyArray3};
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::motion::sample::sample_footprint;
use polyscrew::motion::screw::MAX_T;
use polyscrew::motion::subdivision::{subdivision_footprint, SUBDIVISION_HINT};
use polyscrew::{
    angles_near as core_angles_near, channels_near as core_channels_near,
    direction_steps as core_direction_steps, partial_moves as core_partial_moves,
    rotation_channels as core_rotation_channels,
    rotation_channels_each as core_rotation_channels_each,
    same_rotation_map as core_same_rotation_map, sample as core_sample,
    subdivide as core_subdivide, subdivided_len, turn_vectors as core_turn_vectors, Error,
    MoveBounds, Pose, RotationMode, Scheme, Screw, Timing, MAX_LEVELS,
};
use pyo3::prelude::*;

use crate::args::{
    self, copy_of, float_array, AnglesNear, Choice, DirectionSteps, FloatArg, FloatArray, Function,
    PartialMoves, RotationChannels, RotationChannelsEach, RotationChannelsNear, SameRotationMap,
    Sample, SampleChannels, SampleVectors, Subdivide, SubdivideVectors, TurnVectors,
};
use crate::arrays::{
    fill, key_count, pose_count, poses_to_array, read_keys, read_one_pose, read_poses, read_spec,
    read_vec3s, read_vector, rows3_len, vec3s_to_array, vector_len,
};
use crate::detach_unless_small;
use crate::errors::{check_budget, invalid, shape_err, to_py_err};

/// How to ask a sampling call for less memory.
const SAMPLE_HINT: &str = polyscrew::motion::sample::SAMPLE_HINT;

/// The screw between two poses (Rossignac-Kim): ``b = M a`` with ``M`` a rotation by
/// ``angle`` about the line through ``point`` along ``axis``, plus ``slide`` along it.
#[pyclass(frozen, module = "polyscrew", name = "Screw")]
pub struct PyScrew {
    inner: Screw,
}

#[pymethods]
impl PyScrew {
    /// axis -> FloatArray
    ///
    /// Unit direction of the axis, shape (3,). Along the translation for a pure translation.
    #[getter]
    fn axis<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        self.inner.axis().to_array().to_vec().into_pyarray(py)
    }
    /// point -> FloatArray
    ///
    /// The point of the axis nearest to the first pose's origin, shape (3,).
    #[getter]
    fn point<'py>(&self, py: Python<'py>) -> Bound<'py, numpy::PyArray1<f64>> {
        self.inner.point().to_array().to_vec().into_pyarray(py)
    }
    /// angle -> float
    ///
    /// Rotation angle, radians in [0, pi].
    #[getter]
    fn angle(&self) -> f64 {
        self.inner.angle()
    }
    /// slide -> float
    ///
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

/// A `(4, 4)` pose argument, its shape checked (read after the budget's check).
fn one_pose_arg<'py>(
    function: &'static str,
    what: &'static str,
    obj: &Bound<'py, PyAny>,
) -> PyResult<FloatArg<'py>> {
    let array = float_array(function, what, obj)?;
    let (_, single) = pose_count(function, what, array.shape())?;
    if !single {
        return Err(shape_err(function, what, "(4, 4)", array.shape()));
    }
    Ok(array)
}

/// How to ask `interpolate` for less memory (`screw` holds two poses whatever it is given).
const POSE_HINT: &str = "pass fewer t at once";

/// screw(a: ArrayLike, b: ArrayLike) -> Screw
///
/// The minimal screw carrying pose ``a`` (4, 4) to pose ``b`` (4, 4).
///
/// A relative rotation within round-off of the identity (``|q.xyz| <= 16 eps``, a turn
/// below 7e-15 rad) is a pure translation: axis along it, slide its length, angle 0.
/// Errors name the pose: ``"screw: b: not rigid: ..."``.
#[pyfunction]
fn screw(py: Python<'_>, a: &Bound<'_, PyAny>, b: &Bound<'_, PyAny>) -> PyResult<PyScrew> {
    const F: &str = "screw";
    let (a, b) = (one_pose_arg(F, "a", a)?, one_pose_arg(F, "b", b)?);
    check_budget(
        F,
        a.copy() + b.copy() + Footprint::of::<Pose>(2),
        "the poses",
        POSE_HINT,
    )?;
    let (a, b) = (a.read()?, b.read()?);
    let (a, b) = (a.as_array(), b.as_array());
    // two poses: constant work, done without leaving the GIL (`detach_unless_small`)
    let inner = detach_unless_small(py, true, || -> PyResult<Screw> {
        let (a, b) = (read_one_pose(F, "a", &a)?, read_one_pose(F, "b", &b)?);
        Ok(Screw::between(&a, &b))
    })?;
    Ok(PyScrew { inner })
}

/// `t` checked: within +-`MAX_T`, finite.
fn check_t(index: usize, t: f64) -> Result<(), Error> {
    if t.abs() <= MAX_T {
        Ok(())
    } else if t.is_finite() {
        Err(Error::OutOfRange {
            what: "t",
            index,
            value: t,
            limit: MAX_T,
        })
    } else {
        Err(Error::NotFinite { what: "t", index })
    }
}

/// The `t` of `interpolate`: a real number, or an array of them (0-d: one number).
enum TArg<'py> {
    Scalar(f64),
    Array(FloatArg<'py>),
}

/// interpolate(a: ArrayLike, b: ArrayLike, t: float) -> FloatArray
/// interpolate(a: ArrayLike, b: ArrayLike, t: ArrayLike) -> FloatArray
///
/// ``s(a, t, b)``: the pose a fraction ``t`` along the screw from ``a`` to ``b``.
///
/// ``t = 0`` gives ``a``, ``t = 1`` gives ``b``, other values move along or past the screw,
/// within +-1e12 (beyond, ``t**2`` times a coordinate could overflow).
/// Returns (4, 4) for a float ``t``, (len(t), 4, 4) for an array.
#[pyfunction]
fn interpolate<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
    t: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyAny>> {
    const F: &str = "interpolate";
    let (a, b) = (one_pose_arg(F, "a", a)?, one_pose_arg(F, "b", b)?);
    let t =
        if t.is_instance_of::<pyo3::types::PyFloat>() || t.is_instance_of::<pyo3::types::PyInt>() {
            TArg::Scalar(args::float_scalar(F, "t", t)?)
        } else {
            TArg::Array(float_array(F, "t", t)?)
        };
    let (m, single, t_copy) = match &t {
        TArg::Scalar(_) => (1, true, Footprint::ZERO),
        TArg::Array(ts) if ts.ndim() == 0 => (1, true, ts.copy()),
        TArg::Array(ts) => (vector_len(F, "t", ts)?, false, ts.copy()),
    };
    check_budget(
        F,
        a.copy()
            + b.copy()
            + t_copy
            + Footprint::of::<Pose>(2)
            + Footprint::of::<f64>(m).and::<Pose>(m).and::<[f64; 16]>(m),
        "the interpolated poses",
        POSE_HINT,
    )?;
    let (a, b) = (a.read()?, b.read()?);
    let ts = match &t {
        TArg::Array(ts) => Some(ts.read()?),
        TArg::Scalar(_) => None,
    };
    let scalar = match t {
        TArg::Scalar(t) => t,
        TArg::Array(_) => f64::NAN,
    };
    let (a, b, ts) = (
        a.as_array(),
        b.as_array(),
        ts.as_ref().map(|t| t.as_array()),
    );
    let out = detach_unless_small(py, single, || -> PyResult<Array3<f64>> {
        let (a, b) = (read_one_pose(F, "a", &a)?, read_one_pose(F, "b", &b)?);
        let sc = Screw::between(&a, &b);
        let many = match &ts {
            Some(ts) if !single => Some(read_vector(F, "t", ts)?),
            _ => None,
        };
        let run = || -> Result<Array3<f64>, Error> {
            let Some(ts) = &many else {
                let t = ts
                    .as_ref()
                    .map_or(scalar, |t| t.iter().next().copied().unwrap_or(f64::NAN));
                check_t(0, t)?;
                return poses_to_array(&[sc.eval(t)]);
            };
            for (index, t) in ts.iter().enumerate() {
                check_t(index, *t)?;
            }
            let mut poses = try_vec(ts.len(), "interpolated poses")?;
            poses.extend(ts.iter().map(|t| sc.eval(*t)));
            poses_to_array(&poses)
        };
        run().map_err(|e| to_py_err(F, e))
    })?;
    if single {
        return Ok(out
            .index_axis_move(numpy::ndarray::Axis(0), 0)
            .into_pyarray(py)
            .into_any());
    }
    Ok(out.into_pyarray(py).into_any())
}

/// The input keys' footprint: the poses read from them.
fn keys_footprint(n: usize) -> Footprint {
    Footprint::of::<Pose>(n)
}

/// subdivide(
///     poses: ArrayLike, scheme: SchemeName = "jarek", levels: int = 4, closed: bool = False
/// ) -> FloatArray
///
/// Split&Tweak subdivision of the polyscrew through ``poses`` (N, 4, 4).
///
/// Returns (N * 2**levels, 4, 4) closed, ((N - 1) * 2**levels + 1, 4, 4) open; an open
/// sequence keeps its first and last pose exactly; "four_point" keeps every key.
/// ``levels`` must be in 0..=12; at least 2 poses are needed.
#[pyfunction]
#[pyo3(signature = (poses, scheme=Choice::of(Scheme::Jarek), levels=4, closed=false))]
#[pyo3(text_signature = "(poses, scheme='jarek', levels=4, closed=False)")]
fn subdivide<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    scheme: Choice<Subdivide, Scheme>,
    #[pyo3(from_py_with = args::levels::<Subdivide>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<Subdivide>)] closed: bool,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = Subdivide::NAME;
    let spec = read_spec(scheme.0, levels, closed, None, Timing::Smooth);
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let out_len = if n >= 2 {
        subdivided_len(n, levels, closed)
    } else {
        0
    };
    check_budget(
        F,
        poses.copy()
            + keys_footprint(n)
            + subdivision_footprint::<Pose>(n, levels, closed)
            + Footprint::of::<[f64; 16]>(out_len),
        "the subdivided poses",
        SUBDIVISION_HINT,
    )?;
    let poses = poses.read()?;
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
    key_times: FloatArg<'py>,
    times: FloatArg<'py>,
    n_times: usize,
    n_key_times: usize,
}

fn read_timed<'py>(
    function: &'static str,
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

impl<'py> TimedInput<'py> {
    /// What reading the two arrays copies.
    fn copy(&self) -> Footprint {
        self.key_times.copy() + self.times.copy()
    }

    /// The two arrays read (after the budget's check).
    fn read(&self) -> PyResult<(FloatArray<'py>, FloatArray<'py>)> {
        Ok((self.key_times.read()?, self.times.read()?))
    }
}

/// sample(
///     poses: ArrayLike,
///     key_times: ArrayLike,
///     times: ArrayLike,
///     scheme: SchemeName = "jarek",
///     levels: int = 4,
///     closed: bool = False,
///     period: float | None = None,
///     timing: TimeMapName = "smooth",
/// ) -> FloatArray
///
/// The subdivided motion of ``poses`` keyed at ``key_times``, at ``times``: (len(times), 4, 4).
///
/// ``key_times`` must be strictly increasing, within +-1e300 and at least 1e-300 apart;
/// ``times`` within +-1e300. ``closed`` makes a cycle of length
/// ``period`` (default: closed after the mean key spacing). ``timing="smooth"`` is the
/// monotone C1 map from time to the motion parameter, ``"linear"`` maps each key span
/// linearly (the timings that map time, ``TimeMapName``: timing ``"keys"`` follows Blender's
/// playback, ``timed_frames`` turns it into times to sample at). Open motions hold their end
/// poses outside the keys' range.
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, scheme=Choice::of(Scheme::Jarek), levels=4, closed=false, period=None, timing=Choice::of(Timing::Smooth)))]
#[pyo3(
    text_signature = "(poses, key_times, times, scheme='jarek', levels=4, closed=False, period=None, timing='smooth')"
)]
#[allow(clippy::too_many_arguments)]
fn sample<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    scheme: Choice<Sample, Scheme>,
    #[pyo3(from_py_with = args::levels::<Sample>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<Sample>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    timing: Choice<Sample, Timing>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = Sample::NAME;
    let period = args::optional_float(F, "period", period)?;
    let spec = read_spec(scheme.0, levels, closed, period, timing.0);
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let input = read_timed(F, key_times, times)?;
    let m = input.n_times;
    check_budget(
        F,
        poses.copy()
            + input.copy()
            + keys_footprint(n)
            + Footprint::of::<f64>(input.n_key_times + m)
            + sample_footprint::<Pose>(n, m, &spec)
            + Footprint::of::<[f64; 16]>(m),
        "the sampled poses",
        SAMPLE_HINT,
    )?;
    let (poses, (key_times, times)) = (poses.read()?, input.read()?);
    let (view, kt, tt) = (poses.as_array(), key_times.as_array(), times.as_array());
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

/// sample_channels(
///     poses: ArrayLike,
///     key_times: ArrayLike,
///     times: ArrayLike,
///     mode: RotationModeName,
///     previous: ArrayLike | None = None,
///     scheme: SchemeName = "jarek",
///     levels: int = 4,
///     closed: bool = False,
///     period: float | None = None,
///     timing: TimeMapName = "smooth",
/// ) -> tuple[FloatArray, FloatArray]
///
/// ``sample`` as Blender channels: locations (len(times), 3) and the rotation channels
/// ``rotation_channels(sample(...), mode, previous)``, without the (len(times), 4, 4)
/// matrices in between (what a bake writes).
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, mode, previous=None, scheme=Choice::of(Scheme::Jarek), levels=4, closed=false, period=None, timing=Choice::of(Timing::Smooth)))]
#[pyo3(
    text_signature = "(poses, key_times, times, mode, previous=None, scheme='jarek', levels=4, closed=False, period=None, timing='smooth')"
)]
#[allow(clippy::too_many_arguments)]
#[allow(clippy::type_complexity)]
fn sample_channels<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    mode: Choice<SampleChannels, RotationMode>,
    previous: Option<&Bound<'py, PyAny>>,
    scheme: Choice<SampleChannels, Scheme>,
    #[pyo3(from_py_with = args::levels::<SampleChannels>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SampleChannels>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    timing: Choice<SampleChannels, Timing>,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<f64>>)> {
    const F: &str = SampleChannels::NAME;
    let mode = mode.0;
    let period = args::optional_float(F, "period", period)?;
    let spec = read_spec(scheme.0, levels, closed, period, timing.0);
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let input = read_timed(F, key_times, times)?;
    let previous = crate::args::optional_float_array(F, "previous", previous)?;
    let m = input.n_times;
    let width = mode.width();
    check_budget(
        F,
        poses.copy()
            + input.copy()
            + copy_of(previous.as_ref())
            + keys_footprint(n)
            + Footprint::of::<f64>(input.n_key_times + m)
            + sample_footprint::<Pose>(n, m, &spec)
            + Footprint::of::<(DQuat, DVec3)>(m)
            + Footprint::of::<[f64; 3]>(m)
            + Footprint::of::<f64>(m.saturating_mul(width)),
        "the sampled channels",
        SAMPLE_HINT,
    )?;
    let (poses, (key_times, times)) = (poses.read()?, input.read()?);
    let previous = previous.as_ref().map(|p| p.read()).transpose()?;
    let (view, kt, tt) = (poses.as_array(), key_times.as_array(), times.as_array());
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
            .map_err(|e| invalid(format!("{F}: {e}")))?;
        Ok((locations, rotations))
    })?;
    Ok((locations.into_pyarray(py), rotations.into_pyarray(py)))
}

/// subdivide_vectors(
///     values: ArrayLike, scheme: SchemeName = "jarek", levels: int = 4, closed: bool = False
/// ) -> FloatArray
///
/// The same schemes on plain vectors ``values`` (N, 3) (the linear masks).
#[pyfunction]
#[pyo3(signature = (values, scheme=Choice::of(Scheme::Jarek), levels=4, closed=false))]
#[pyo3(text_signature = "(values, scheme='jarek', levels=4, closed=False)")]
fn subdivide_vectors<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    scheme: Choice<SubdivideVectors, Scheme>,
    #[pyo3(from_py_with = args::levels::<SubdivideVectors>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SubdivideVectors>)] closed: bool,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = SubdivideVectors::NAME;
    let spec = read_spec(scheme.0, levels, closed, None, Timing::Smooth);
    let values = float_array(F, "values", values)?;
    let n = rows3_len(&values);
    let out_len = if n >= 2 {
        subdivided_len(n, levels, closed)
    } else {
        0
    };
    check_budget(
        F,
        values.copy()
            + Footprint::of::<DVec3>(n)
            + subdivision_footprint::<DVec3>(n, levels, closed)
            + Footprint::of::<[f64; 3]>(out_len),
        "the subdivided vectors",
        SUBDIVISION_HINT,
    )?;
    let values = values.read()?;
    let view = values.as_array();
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let keys = read_vec3s(F, "values", &view)?;
        core_subdivide(&keys, spec.scheme, spec.levels, spec.closed)
            .and_then(|d| vec3s_to_array(&d))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// sample_vectors(
///     values: ArrayLike,
///     key_times: ArrayLike,
///     times: ArrayLike,
///     scheme: SchemeName = "jarek",
///     levels: int = 4,
///     closed: bool = False,
///     period: float | None = None,
///     timing: TimeMapName = "smooth",
/// ) -> FloatArray
///
/// ``sample`` for plain vectors ``values`` (N, 3) (for example log-scale): (len(times), 3).
#[pyfunction]
#[pyo3(signature = (values, key_times, times, scheme=Choice::of(Scheme::Jarek), levels=4, closed=false, period=None, timing=Choice::of(Timing::Smooth)))]
#[pyo3(
    text_signature = "(values, key_times, times, scheme='jarek', levels=4, closed=False, period=None, timing='smooth')"
)]
#[allow(clippy::too_many_arguments)]
fn sample_vectors<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    scheme: Choice<SampleVectors, Scheme>,
    #[pyo3(from_py_with = args::levels::<SampleVectors>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SampleVectors>)] closed: bool,
    period: Option<&Bound<'py, PyAny>>,
    timing: Choice<SampleVectors, Timing>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = SampleVectors::NAME;
    let period = args::optional_float(F, "period", period)?;
    let spec = read_spec(scheme.0, levels, closed, period, timing.0);
    let values = float_array(F, "values", values)?;
    let n = rows3_len(&values);
    let input = read_timed(F, key_times, times)?;
    let m = input.n_times;
    check_budget(
        F,
        values.copy()
            + input.copy()
            + Footprint::of::<DVec3>(n)
            + Footprint::of::<f64>(input.n_key_times + m)
            + sample_footprint::<DVec3>(n, m, &spec)
            + Footprint::of::<[f64; 3]>(m),
        "the sampled vectors",
        SAMPLE_HINT,
    )?;
    let (values, (key_times, times)) = (values.read()?, input.read()?);
    let (view, kt, tt) = (values.as_array(), key_times.as_array(), times.as_array());
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
            let fixed = array
                .view()
                .into_dimensionality::<Ix3>()
                .map_err(|e| invalid(format!("{function}: rotations: {e}")))?;
            for (i, matrix) in fixed.outer_iter().enumerate() {
                let mut m = [0.0; 9];
                fill(&mut m, matrix.iter());
                let rows = [
                    [m[0], m[1], m[2], 0.0],
                    [m[3], m[4], m[5], 0.0],
                    [m[6], m[7], m[8], 0.0],
                    [0.0, 0.0, 0.0, 1.0],
                ];
                let pose = Pose::from_rows(&rows, i)
                    .map_err(|e| invalid(format!("{function}: rotations: {e}")))?;
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

/// rotation_channels(
///     rotations: ArrayLike, mode: RotationModeName, previous: ArrayLike | None = None
/// ) -> FloatArray
///
/// Blender rotation channels of ``rotations`` ((N, 3, 3) or (N, 4, 4)), continuous.
///
/// "QUATERNION": (N, 4) w, x, y, z without sign flips; "AXIS_ANGLE": (N, 4) angle, x, y, z
/// unwrapped; Euler orders: (N, 3) angles per axis (x, y, z), each frame compatible with the
/// previous one (no jump above 180 degrees). ``previous`` continues from earlier values;
/// its angles (Euler, the axis-angle angle) within ``+-MAX_PREVIOUS_ANGLE`` (1e9), else
/// ``ValueError``. At most ``MAX_ROTATIONS`` rotations per call.
#[pyfunction]
#[pyo3(signature = (rotations, mode, previous=None))]
fn rotation_channels<'py>(
    py: Python<'py>,
    rotations: &Bound<'py, PyAny>,
    mode: Choice<RotationChannels, RotationMode>,
    previous: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = RotationChannels::NAME;
    let mode = mode.0;
    let rotations = float_array(F, "rotations", rotations)?;
    let previous = crate::args::optional_float_array(F, "previous", previous)?;
    let n = rotations.shape().first().copied().unwrap_or(0);
    let width = mode.width();
    check_budget(
        F,
        rotations.copy()
            + copy_of(previous.as_ref())
            + Footprint::of::<DQuat>(n)
            + Footprint::of::<f64>(n.saturating_mul(width)),
        "the rotation channels",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    polyscrew::motion::channels::check_rotation_count(n).map_err(|e| to_py_err(F, e))?;
    let rotations = rotations.read()?;
    let view = rotations.as_array();
    let previous = previous.as_ref().map(|p| p.read()).transpose()?;
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
            .map_err(|e| invalid(format!("{F}: {e}")))
    })?;
    Ok(out.into_pyarray(py))
}

/// rotation_channels_each(
///     rotations: ArrayLike, mode: RotationModeName, previous: ArrayLike
/// ) -> FloatArray
///
/// Blender rotation channels of ``rotations`` ((N, 3, 3) or (N, 4, 4)), each continued from
/// its own row of ``previous`` ((N, 4) or (N, 3) values in ``mode``, for example each owner's
/// current values): row ``i`` is, to the bit, ``rotation_channels(rotations[i:i + 1], mode,
/// previous=previous[i])[0]``, so many owners' keys are converted in one call. ``previous``
/// angles within ``+-MAX_PREVIOUS_ANGLE``, else ``ValueError``.
#[pyfunction]
fn rotation_channels_each<'py>(
    py: Python<'py>,
    rotations: &Bound<'py, PyAny>,
    mode: Choice<RotationChannelsEach, RotationMode>,
    previous: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows = ("previous", previous);
    let core: PerRow = core_rotation_channels_each;
    per_row(
        py,
        RotationChannelsEach::NAME,
        rotations,
        mode.0,
        rows,
        core,
    )
}

/// rotation_channels_near(
///     rotations: ArrayLike, mode: RotationModeName, reference: ArrayLike
/// ) -> FloatArray
///
/// Blender rotation channels of ``rotations`` ((N, 3, 3) or (N, 4, 4)), each written like
/// its own row of ``reference`` ((N, 4) or (N, 3) values in ``mode``, for example the keys
/// an animator typed) rather than continued from the row before: quaternions take the
/// reference's sign; axis-angle the axis pointing the reference's way and the angle within
/// half a turn of its angle; Euler angles the one of the two triples of the rotation, each
/// wrapped by whole turns towards the reference, that is nearer to it. Spins and deliberate
/// sign flips of the reference are kept. Reference angles within ``+-MAX_PREVIOUS_ANGLE``.
#[pyfunction]
fn rotation_channels_near<'py>(
    py: Python<'py>,
    rotations: &Bound<'py, PyAny>,
    mode: Choice<RotationChannelsNear, RotationMode>,
    reference: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    let rows = ("reference", reference);
    per_row(
        py,
        RotationChannelsNear::NAME,
        rotations,
        mode.0,
        rows,
        core_channels_near,
    )
}

/// A core conversion of N rotations in a mode, each with its own row of N x width values.
type PerRow = fn(&[DQuat], RotationMode, &[f64]) -> Result<Vec<f64>, Error>;

/// The shared body of `rotation_channels_near` and `rotation_channels_each`: reads
/// `rotations` ((N, 3, 3) or (N, 4, 4)) and the rows `name` ((N, width) values in `mode`),
/// checks their shapes and the budget, and runs `core` on the N rotations and their rows
/// with the GIL released.
fn per_row<'py>(
    py: Python<'py>,
    function: &'static str,
    rotations: &Bound<'py, PyAny>,
    mode: RotationMode,
    (name, rows): (&'static str, &Bound<'py, PyAny>),
    core: PerRow,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const VALUES: &str = "row values";
    let f = function;
    let rotations = float_array(f, "rotations", rotations)?;
    let rows = float_array(f, name, rows)?;
    let n = rotations.shape().first().copied().unwrap_or(0);
    let width = mode.width();
    if rows.shape() != [n, width] {
        return Err(shape_err(f, name, &format!("({n}, {width})"), rows.shape()));
    }
    check_budget(
        f,
        rotations.copy()
            + rows.copy()
            + Footprint::of::<DQuat>(n)
            + Footprint::of::<f64>(n.saturating_mul(width).saturating_mul(2)),
        "the rotation channels",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    polyscrew::motion::channels::check_rotation_count(n).map_err(|e| to_py_err(f, e))?;
    let (rotations, rows) = (rotations.read()?, rows.read()?);
    let (view, rv) = (rotations.as_array(), rows.as_array());
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let quats = read_rotations(f, &view)?;
        let mut values = try_vec(n.saturating_mul(width), VALUES).map_err(|e| to_py_err(f, e))?;
        values.extend(rv.iter().copied());
        let channels = core(&quats, mode, &values).map_err(|e| to_py_err(f, e))?;
        Array2::from_shape_vec((n, width), channels).map_err(|e| invalid(format!("{f}: {e}")))
    })?;
    Ok(out.into_pyarray(py))
}

/// turn_vectors(a: ArrayLike, b: ArrayLike) -> FloatArray
///
/// The turn from each rotation of ``a`` to the same row of ``b`` ((N, 3, 3) or (N, 4, 4)
/// each), in the world frame: (N, 3) rotation vectors ``log(R_b R_a^T)``, axis times angle,
/// the angle (their length) in [0, pi], exact near 0 and near pi (``atan2`` of the relative
/// quaternion, not ``arccos`` of a trace). At most ``MAX_ROTATIONS`` rows.
#[pyfunction]
fn turn_vectors<'py>(
    py: Python<'py>,
    a: &Bound<'py, PyAny>,
    b: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = TurnVectors::NAME;
    let (a, b) = (float_array(F, "a", a)?, float_array(F, "b", b)?);
    let n = a.shape().first().copied().unwrap_or(0);
    check_budget(
        F,
        a.copy()
            + b.copy()
            + Footprint::of::<DQuat>(n.saturating_mul(2))
            + Footprint::of::<DVec3>(n.saturating_mul(2)),
        "the turn vectors",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    polyscrew::motion::channels::check_rotation_count(n).map_err(|e| to_py_err(F, e))?;
    let (a, b) = (a.read()?, b.read()?);
    let (av, bv) = (a.as_array(), b.as_array());
    let out = py.detach(|| -> PyResult<Array2<f64>> {
        let (qa, qb) = (read_rotations(F, &av)?, read_rotations(F, &bv)?);
        core_turn_vectors(&qa, &qb)
            .and_then(|v| vec3s_to_array(&v))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// angles_near(
///     values: ArrayLike, reference: ArrayLike, mode: RotationModeName, channel: int
/// ) -> FloatArray
///
/// Each of ``values`` (N,) of rotation channel ``channel`` in ``mode`` moved by whole turns to
/// within half a turn of the same entry of ``reference`` (N,) when that channel is an angle
/// (the three Euler angles, the axis-angle angle: channel 0), unchanged otherwise: the same
/// rotations, written like the reference (ties of half a turn rounded away from zero).
#[pyfunction]
fn angles_near<'py>(
    py: Python<'py>,
    values: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    mode: Choice<AnglesNear, RotationMode>,
    channel: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    const F: &str = AnglesNear::NAME;
    let (mode, channel) = (mode.0, args::int_in(F, "channel", channel, 0, 3)?);
    wrapped_angles(py, F, values, reference, move |values, reference| {
        core_angles_near(values, reference, mode, channel as usize)
    })
}

/// The shared body of `angles_near` and `angles_near_many`: reads `values` and `reference`
/// ((N,) each), checks the budget, and runs `near` on them with the GIL released.
pub(crate) fn wrapped_angles<'py>(
    py: Python<'py>,
    function: &'static str,
    values: &Bound<'py, PyAny>,
    reference: &Bound<'py, PyAny>,
    near: impl FnOnce(&[f64], &[f64]) -> Result<Vec<f64>, Error> + Send,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    let values = float_array(function, "values", values)?;
    let reference = float_array(function, "reference", reference)?;
    let n = vector_len(function, "values", &values)?;
    vector_len(function, "reference", &reference)?;
    check_budget(
        function,
        values.copy() + reference.copy() + Footprint::of::<f64>(n).times(3),
        "the angles",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    let (values, reference) = (values.read()?, reference.read()?);
    let (vv, rv) = (values.as_array(), reference.as_array());
    let out = py.detach(|| -> PyResult<Vec<f64>> {
        let values = read_vector(function, "values", &vv)?;
        let reference = read_vector(function, "reference", &rv)?;
        near(&values, &reference).map_err(|e| to_py_err(function, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// The `(a, c)` arrays of [`same_rotation_map`].
type ChannelMap<'py> = (Bound<'py, PyArray1<f64>>, Bound<'py, PyArray1<f64>>);

/// same_rotation_map(
///     source: ArrayLike, target: ArrayLike, mode: RotationModeName
/// ) -> tuple[FloatArray, FloatArray] | None
///
/// The per-channel map ``(a, c)`` with ``a * source + c == target`` (within 1e-5 of the
/// largest of 1 and ``|target|``) that keeps every rotation channel values in ``mode`` can
/// hold, so that mapping a curve's keys and handles by it keeps every pose Blender plays;
/// None when no such map takes ``source`` to ``target`` (one row of channel values each):
/// quaternions a common scale (the sign, and a length Blender normalises away); axis-angle
/// the angle's sign and whole turns, the axis scaled by a length of that sign; Euler whole
/// turns, or the twin triple ``(x + pi, pi - y, z + pi)`` (the order's middle axis negated)
/// and whole turns.
#[pyfunction]
fn same_rotation_map<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    mode: Choice<SameRotationMap, RotationMode>,
) -> PyResult<Option<ChannelMap<'py>>> {
    const F: &str = SameRotationMap::NAME;
    let mode = mode.0;
    let width = mode.width();
    let (source, target) = (
        float_array(F, "source", source)?,
        float_array(F, "target", target)?,
    );
    for (what, array) in [("source", &source), ("target", &target)] {
        if array.shape() != [width] {
            return Err(shape_err(F, what, &format!("({width},)"), array.shape()));
        }
    }
    let (source, target) = (source.read()?, target.read()?);
    let (sv, tv) = (source.as_array(), target.as_array());
    let (source, target) = (
        read_vector(F, "source", &sv)?,
        read_vector(F, "target", &tv)?,
    );
    // constant work (a few channels): no need to leave the GIL
    let found = detach_unless_small(py, true, || core_same_rotation_map(mode, &source, &target));
    Ok(found.map(|(a, c)| (a.into_pyarray(py), c.into_pyarray(py))))
}

/// direction_steps(directions: ArrayLike) -> FloatArray
///
/// The angle between each two consecutive rows of ``directions`` (N, 3) (any nonzero
/// lengths): (N - 1,) angles in [0, pi], ``atan2(|a x b|, a . b)``, exact near 0 and near
/// pi where ``arccos`` of a dot product loses digits; 0 where a row is zero.
#[pyfunction]
fn direction_steps<'py>(
    py: Python<'py>,
    directions: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray1<f64>>> {
    const F: &str = DirectionSteps::NAME;
    let directions = float_array(F, "directions", directions)?;
    let n = rows3_len(&directions);
    check_budget(
        F,
        directions.copy() + Footprint::of::<DVec3>(n) + Footprint::of::<f64>(n),
        "the direction steps",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    let directions = directions.read()?;
    let view = directions.as_array();
    let out = py.detach(|| -> PyResult<Vec<f64>> {
        let directions = read_vec3s(F, "directions", &view)?;
        core_direction_steps(&directions).map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// The poses of [`partial_moves`] and which were cut short.
pub(crate) type MovedPoses<'py> = (Bound<'py, PyArray3<f64>>, Bound<'py, PyArray1<bool>>);

/// The shared body of `partial_moves` and `partial_moves_many`: reads `source` and `target`
/// ((N, 4, 4) each), checks the budget (`extra`: the caller's other arguments read), and
/// runs `moves` on the poses with the GIL released.
pub(crate) fn moved_poses<'py>(
    py: Python<'py>,
    function: &'static str,
    source: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    extra: Footprint,
    moves: impl FnOnce(&[Pose], &[Pose]) -> Result<(Vec<Pose>, Vec<bool>), Error> + Send,
) -> PyResult<MovedPoses<'py>> {
    let source = float_array(function, "source", source)?;
    let target = float_array(function, "target", target)?;
    for (what, poses) in [("source", &source), ("target", &target)] {
        if !matches!(poses.shape(), [_, 4, 4]) {
            return Err(shape_err(function, what, "(N, 4, 4)", poses.shape()));
        }
    }
    let n = source.shape()[0];
    check_budget(
        function,
        source.copy()
            + target.copy()
            + extra
            + Footprint::of::<Pose>(n.saturating_mul(3))
            + Footprint::of::<bool>(n)
            + Footprint::of::<[f64; 16]>(n),
        "the partial moves",
        polyscrew::motion::channels::CHANNELS_HINT,
    )?;
    let (source, target) = (source.read()?, target.read()?);
    let (sv, tv) = (source.as_array(), target.as_array());
    let (poses, cut) = py.detach(|| -> PyResult<(Array3<f64>, Vec<bool>)> {
        let source = read_poses(function, "source", &sv)?;
        let target = read_poses(function, "target", &tv)?;
        let (poses, cut) = moves(&source, &target).map_err(|e| to_py_err(function, e))?;
        Ok((
            poses_to_array(&poses).map_err(|e| to_py_err(function, e))?,
            cut,
        ))
    })?;
    Ok((poses.into_pyarray(py), cut.into_pyarray(py)))
}

/// partial_moves(
///     source: ArrayLike, target: ArrayLike, pivot: ArrayLike, max_angle: float,
///     max_distance: float
/// ) -> tuple[FloatArray, npt.NDArray[np.bool_]]
///
/// Each pose of ``target`` ((N, 4, 4)), or where its straight move from the same row of
/// ``source`` turns by more than ``max_angle`` (radians) or carries the point ``pivot`` (3,
/// body coordinates) further than ``max_distance``, the pose the fraction ``a`` of the way
/// there that brings both within them: ``a = min(1, max_angle / angle, max_distance /
/// distance)``, the rotation ``a`` of the turn about the same axis, the pivot ``a`` of the
/// way along its straight move (not a screw's helix). Returns the poses and which were cut
/// short. Bounds at least 0 (``inf``: no bound).
#[pyfunction]
fn partial_moves<'py>(
    py: Python<'py>,
    source: &Bound<'py, PyAny>,
    target: &Bound<'py, PyAny>,
    pivot: &Bound<'py, PyAny>,
    max_angle: &Bound<'py, PyAny>,
    max_distance: &Bound<'py, PyAny>,
) -> PyResult<MovedPoses<'py>> {
    const F: &str = PartialMoves::NAME;
    let bounds = MoveBounds {
        angle: args::float_scalar(F, "max_angle", max_angle)?,
        distance: args::float_scalar(F, "max_distance", max_distance)?,
    };
    let pivot = float_array(F, "pivot", pivot)?;
    if pivot.shape() != [3] {
        return Err(shape_err(F, "pivot", "(3,)", pivot.shape()));
    }
    let extra = pivot.copy();
    let pivot = pivot.read()?;
    let pv = pivot.as_array();
    let p = DVec3::new(pv[0], pv[1], pv[2]);
    moved_poses(py, F, source, target, extra, move |source, target| {
        core_partial_moves(source, target, p, bounds)
    })
}

/// memory_budget() -> int
///
/// The memory budget in bytes: the most one call may hold at its peak (output, working
/// memory, copies of the input). A call that would need more raises ``ValueError`` up
/// front, naming the bytes asked for and how to ask for less.
#[pyfunction]
fn memory_budget() -> usize {
    polyscrew::memory_budget()
}

/// set_memory_budget(bytes: int) -> int
///
/// Sets the memory budget (bytes, >= 0) for every later call in the process; returns
/// the previous one. ``set_memory_budget(DEFAULT_MEMORY_BUDGET)`` restores the default.
/// Raise it on a machine that has the memory; lower it to keep a host application safe.
#[pyfunction]
fn set_memory_budget(bytes: &Bound<'_, PyAny>) -> PyResult<usize> {
    let bytes = args::int_in("set_memory_budget", "bytes", bytes, 0, i64::MAX)?;
    Ok(polyscrew::set_memory_budget(bytes as usize))
}

/// Adds the motion functions, `Screw`, the budget's functions and their constants.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<PyScrew>()?;
    m.add_function(wrap_pyfunction!(screw, m)?)?;
    m.add_function(wrap_pyfunction!(interpolate, m)?)?;
    m.add_function(wrap_pyfunction!(subdivide, m)?)?;
    m.add_function(wrap_pyfunction!(sample, m)?)?;
    m.add_function(wrap_pyfunction!(sample_channels, m)?)?;
    m.add_function(wrap_pyfunction!(subdivide_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(sample_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_channels, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_channels_near, m)?)?;
    m.add_function(wrap_pyfunction!(rotation_channels_each, m)?)?;
    m.add_function(wrap_pyfunction!(turn_vectors, m)?)?;
    m.add_function(wrap_pyfunction!(angles_near, m)?)?;
    m.add_function(wrap_pyfunction!(same_rotation_map, m)?)?;
    m.add_function(wrap_pyfunction!(direction_steps, m)?)?;
    m.add_function(wrap_pyfunction!(partial_moves, m)?)?;
    m.add_function(wrap_pyfunction!(memory_budget, m)?)?;
    m.add_function(wrap_pyfunction!(set_memory_budget, m)?)?;
    // stub:
    // stub: MAX_LEVELS: int
    // stub: """The largest accepted number of subdivision levels (12)."""
    m.add("MAX_LEVELS", MAX_LEVELS)?;
    // stub:
    // stub: DEFAULT_MEMORY_BUDGET: int
    // stub: """The default memory budget per call, 1 GiB (1073741824 bytes): about 5 times the largest
    // stub: legitimate use (the 10,000 keys x 8 levels subdivision benchmark in Rust, 215 MB by the
    // stub: estimate; through Python a 100,000-triangle sweep over 64 screws in 8 steps, 154 MB
    // stub: estimated, 118 MB measured)."""
    m.add("DEFAULT_MEMORY_BUDGET", polyscrew::DEFAULT_MEMORY_BUDGET)?;
    // stub:
    // stub: MAX_COORDINATE: float
    // stub: """The working range of coordinates: ``|x| <= 1e150`` (see the module documentation)."""
    m.add("MAX_COORDINATE", polyscrew::motion::pose::MAX_COORDINATE)?;
    // stub:
    // stub: MAX_TIME: float
    // stub: """The one working range of times: ``|t| <= 1e300`` (``fit_angular_velocity``, which
    // stub: multiplies times, works within its tenth root, ``|t| <= 1e30``)."""
    m.add("MAX_TIME", polyscrew::motion::timing::MAX_TIME)?;
    // stub:
    // stub: MAX_PREVIOUS_ANGLE: float
    // stub: """The largest ``previous`` angle (radians, either sign) the rotation channels continue
    // stub: from: 1e9 (see the module documentation); beyond it ``ValueError``."""
    m.add("MAX_PREVIOUS_ANGLE", polyscrew::MAX_PREVIOUS_ANGLE)?;
    // stub:
    // stub: MAX_ROTATIONS: int
    // stub: """The most rotations one ``rotation_channels`` call converts: 2**24 (16,777,216), the most
    // stub: the default memory budget accepts in quaternion and axis-angle modes. It bounds the call's
    // stub: time (a few seconds of one core) whatever the budget; more raise ``ValueError`` before any
    // stub: is read."""
    m.add("MAX_ROTATIONS", polyscrew::MAX_ROTATIONS)?;
    // stub:
    // stub: ROTATION_MODES: dict[str, tuple[str, int]]
    // stub: """Blender's rotation modes, the core's: name -> (the property holding the rotation, the
    // stub: number of its channels), in Blender's order: ``"QUATERNION"`` -> ``("rotation_quaternion",
    // stub: 4)``, ``"AXIS_ANGLE"`` -> ``("rotation_axis_angle", 4)``, each Euler order (``"XYZ"``, ...)
    // stub: -> ``("rotation_euler", 3)``."""
    let modes = pyo3::types::PyDict::new(m.py());
    for mode in RotationMode::ALL {
        modes.set_item(mode.name(), (mode.property(), mode.width()))?;
    }
    m.add("ROTATION_MODES", modes)?;
    // stub:
    // stub: CONTINUED_ROTATION_MODES: tuple[str, ...]
    // stub: """The rotation modes whose channels continue the values before them (``previous`` of
    // stub: ``rotation_channels`` and ``sample_channels``: a bake from its first key's values, a piece
    // stub: from the piece before): quaternion and the Euler orders. Axis-angle channels start from
    // stub: their own first rotation."""
    let continued: Vec<&str> = RotationMode::ALL
        .into_iter()
        .filter(|mode| mode.continued())
        .map(RotationMode::name)
        .collect();
    m.add(
        "CONTINUED_ROTATION_MODES",
        pyo3::types::PyTuple::new(m.py(), continued)?,
    )?;
    // stub:
    // stub: NORMALISED_CHANNELS: dict[str, tuple[int, int]]
    // stub: """The channels ``start:stop`` of a rotation mode that Blender normalises before it uses them
    // stub: (scaling them together keeps the rotation): ``"QUATERNION"`` -> ``(0, 4)``, ``"AXIS_ANGLE"``
    // stub: -> ``(1, 4)`` (the axis); Euler orders have none."""
    let normalised = pyo3::types::PyDict::new(m.py());
    for mode in RotationMode::ALL {
        if let Some(channels) = mode.normalised() {
            normalised.set_item(mode.name(), channels)?;
        }
    }
    m.add("NORMALISED_CHANNELS", normalised)?;
    // stub:
    // stub: TIMINGS: tuple[str, ...]
    // stub: """Every timing, the core's: ``("smooth", "linear", "keys")``."""
    m.add("TIMINGS", pyo3::types::PyTuple::new(m.py(), Timing::NAMES)?)?;
    // stub:
    // stub: PACED_TIMINGS: tuple[str, ...]
    // stub: """The timings that follow the pace of Blender's playback (``("keys",)``): not a map of time
    // stub: alone, they need the body's size and the playback (``timed_frames``); ``sample`` and its
    // stub: kin refuse them."""
    let paced: Vec<&str> = Timing::ALL
        .into_iter()
        .filter(|timing| timing.paced())
        .map(Timing::name)
        .collect();
    m.add("PACED_TIMINGS", pyo3::types::PyTuple::new(m.py(), paced)?)?;
    Ok(())
}
