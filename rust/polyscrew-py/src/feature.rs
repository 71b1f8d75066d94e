//! Bindings of the feature-point motion design (Hofer-Pottmann-Ravani): registration, inertia
//! points, `feature_motion` and `sample_feature`. Conversion only; the math is in
//! `polyscrew::{registration, inertia, variational, feature_motion}`.

use glam::DVec3;
use numpy::ndarray::{ArrayViewD, Axis};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::prelude::*;

use polyscrew::feature::motion::{feature_footprint, FEATURE_HINT};
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::{
    feature_motion as core_feature_motion, register as core_register, CurveScheme, FeatureSpec,
    InertiaFrame, Parametrization, Pose, Stiffness, Timing,
};

use crate::args::{self, Choice, FeatureMotion, Function, SampleFeature};
use crate::args::{copy_of, float_array};
use crate::arrays::{
    key_count, poses_to_array, read_keys, read_rows3, read_vector, vec3s_to_array, vector_len,
};
use crate::errors::{check_budget, to_py_err};

/// Reads `(K, 3)` points; finiteness and range are checked by the core, which names the
/// point (no GIL needed).
fn read_points(function: &str, what: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Vec<DVec3>> {
    read_rows3(function, what, array, "(K, 3)")
}

/// The `feature_points` argument (None: not given) and how many points it gives (6, the
/// inertia points, when it is not given).
fn feature_points_arg<'py>(
    function: &'static str,
    feature_points: Option<&Bound<'py, PyAny>>,
) -> PyResult<(Option<crate::args::FloatArg<'py>>, usize)> {
    let points = args::optional_float_array(function, "feature_points", feature_points)?;
    let k = points
        .as_ref()
        .map_or(6, |p| p.shape().first().copied().unwrap_or(0));
    Ok((points, k))
}

/// Reads the `feature_points` view, if given, as `(K, 3)` points (no GIL needed).
fn read_feature_points(
    function: &str,
    points: Option<&ArrayViewD<'_, f64>>,
) -> PyResult<Option<Vec<DVec3>>> {
    points
        .map(|p| read_points(function, "feature_points", p))
        .transpose()
}

/// The `stiffness` argument, read but not yet one value per key (that copy waits for the
/// memory budget's check).
enum StiffnessArg<'py> {
    /// Not given.
    Absent,
    /// One value for every key.
    Scalar(f64),
    /// One value per key (its length is checked by the core).
    PerKey(crate::args::FloatArg<'py>),
}

impl StiffnessArg<'_> {
    /// The values the keys' stiffness will hold.
    fn len(&self, n: usize) -> usize {
        match self {
            Self::Absent => 0,
            Self::Scalar(_) => n,
            Self::PerKey(a) => a.len(),
        }
    }

    /// What reading it copies besides the values it holds.
    fn copy(&self) -> Footprint {
        match self {
            Self::PerKey(a) => a.copy(),
            _ => Footprint::ZERO,
        }
    }

    /// The keys' stiffness (`n` copies of a scalar), allocated fallibly: after the budget.
    fn keys(&self, function: &str, n: usize) -> PyResult<Option<Vec<f64>>> {
        match self {
            Self::Absent => Ok(None),
            Self::Scalar(v) => {
                let mut out = try_vec(n, "stiffness").map_err(|e| to_py_err(function, e))?;
                out.resize(n, *v);
                Ok(Some(out))
            }
            Self::PerKey(a) => read_vector(function, "stiffness", &a.read()?.as_array()).map(Some),
        }
    }
}

/// Parses the design options shared by `feature_motion` and `sample_feature`; the keys'
/// stiffness is left to [`StiffnessArg::keys`] (after the budget's check).
#[allow(clippy::too_many_arguments)]
fn read_feature_spec<'py>(
    function: &'static str,
    scheme: CurveScheme,
    levels: u32,
    closed: bool,
    parametrization: Parametrization,
    stiffness: Option<&Bound<'py, PyAny>>,
    inserted_stiffness: Option<&Bound<'py, PyAny>>,
) -> PyResult<(FeatureSpec, StiffnessArg<'py>)> {
    let keys = match stiffness.filter(|s| !s.is_none()) {
        None => StiffnessArg::Absent,
        Some(s) => {
            if s.is_instance_of::<pyo3::types::PyFloat>()
                || s.is_instance_of::<pyo3::types::PyInt>()
            {
                StiffnessArg::Scalar(args::float_scalar(function, "stiffness", s)?)
            } else {
                let a = float_array(function, "stiffness", s)?;
                if a.ndim() == 0 {
                    let value = a.read()?.as_array().iter().next().copied();
                    StiffnessArg::Scalar(value.unwrap_or(f64::NAN))
                } else {
                    if a.ndim() != 1 {
                        return Err(crate::errors::shape_err(
                            function,
                            "stiffness",
                            "(N,)",
                            a.shape(),
                        ));
                    }
                    StiffnessArg::PerKey(a)
                }
            }
        }
    };
    let inserted = args::optional_float(function, "inserted_stiffness", inserted_stiffness)?
        .unwrap_or(f64::INFINITY);
    Ok((
        FeatureSpec {
            scheme,
            levels,
            closed,
            parametrization,
            stiffness: Stiffness {
                keys: None,
                inserted,
            },
        },
        keys,
    ))
}

// stub:
// stub: CurveSchemeName = Literal["variational", "four_point", "bspline", "jarek"]
// stub: ParametrizationName = Literal["uniform", "centripetal"]
/// register_points(src: ArrayLike, dst: ArrayLike, weights: ArrayLike | None = None) -> FloatArray
///
/// The rigid pose (4, 4) minimising ``sum_k w_k |pose(src_k) - dst_k|^2`` (Horn's method).
///
/// ``src``, ``dst``: (K, 3) corresponding points, K >= 3; ``weights``: (K,) >= 0, default 1.
/// The rotation is the eigenvector of the largest eigenvalue of Horn's symmetric 4x4
/// matrix; when that eigenvalue is repeated (collinear points, or a target too distorted to
/// have a unique best fit) ValueError is raised instead of an arbitrary rotation.
#[pyfunction]
#[pyo3(signature = (src, dst, weights=None))]
fn register_points<'py>(
    py: Python<'py>,
    src: &Bound<'py, PyAny>,
    dst: &Bound<'py, PyAny>,
    weights: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "register_points";
    let src = float_array(F, "src", src)?;
    let dst = float_array(F, "dst", dst)?;
    let weights = args::optional_float_array(F, "weights", weights)?;
    let k = src.len() + dst.len();
    check_budget(
        F,
        src.copy()
            + dst.copy()
            + copy_of(weights.as_ref())
            + Footprint::of::<f64>(k).and::<f64>(weights.as_ref().map_or(0, |w| w.len())),
        "the point copies",
        "register fewer points",
    )?;
    let (src, dst) = (src.read()?, dst.read()?);
    let weights = weights.as_ref().map(|w| w.read()).transpose()?;
    let views = (
        src.as_array(),
        dst.as_array(),
        weights.as_ref().map(|w| w.as_array()),
    );
    let pose = py.detach(|| -> PyResult<Pose> {
        let (s, d, w) = &views;
        let src = read_points(F, "src", s)?;
        let dst = read_points(F, "dst", d)?;
        let weights = w
            .as_ref()
            .map(|w| read_vector(F, "weights", w))
            .transpose()?;
        core_register(&src, &dst, weights.as_deref()).map_err(|e| to_py_err(F, e))
    })?;
    let out = poses_to_array(&[pose]).map_err(|e| to_py_err(F, e))?;
    Ok(out.index_axis_move(Axis(0), 0).into_pyarray(py))
}

/// inertia_points(points: ArrayLike) -> FloatArray
///
/// The six inertia points (6, 3) of a cloud ``points`` (K, 3): barycentre
/// ``+- sqrt(lambda_j / 2) e_j`` along the principal axes of its inertia tensor.
///
/// They share the cloud's barycentre and inertia tensor, so they stand in for a whole mesh
/// as ``feature_points``. Raises ValueError for fewer than 3 or collinear points.
#[pyfunction]
fn inertia_points<'py>(
    py: Python<'py>,
    points: &Bound<'py, PyAny>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "inertia_points";
    let points = float_array(F, "points", points)?;
    check_budget(
        F,
        points.copy() + Footprint::of::<f64>(points.len()),
        "the point copy",
        "pass fewer points",
    )?;
    let points = points.read()?;
    let view = points.as_array();
    let six = py.detach(|| -> PyResult<[DVec3; 6]> {
        let points = read_points(F, "points", &view)?;
        let frame = InertiaFrame::of(&points).map_err(|e| to_py_err(F, e))?;
        Ok(frame.inertia_points())
    })?;
    let out = vec3s_to_array(&six).map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
}

/// feature_motion(
///     poses: ArrayLike,
///     scheme: CurveSchemeName = "variational",
///     levels: int = 5,
///     closed: bool = False,
///     feature_points: ArrayLike | None = None,
///     parametrization: ParametrizationName = "uniform",
///     stiffness: float | ArrayLike | None = None,
///     inserted_stiffness: float | None = None,
/// ) -> FloatArray
///
/// Feature-point motion design (Hofer-Pottmann-Ravani) of the keys ``poses`` (N, 4, 4).
///
/// The curve ``scheme`` runs on the homologous positions of ``feature_points`` (K, 3, in
/// the body frame; default the six unit points +-x, +-y, +-z, whose isotropic inertia makes
/// the result independent of how the local axes are turned), then the rigid body is
/// registered to the distorted points at every output pose. Returns (N * 2**levels, 4, 4)
/// closed, ((N - 1) * 2**levels + 1, 4, 4) open; pose ``i * 2**levels`` belongs to key i.
/// Rigid (unit quaternions) and independent of the world frame.
///
/// ``"variational"`` is Kobbelt's variational subdivision (C2), the only scheme that takes
/// ``parametrization`` (``"centripetal"``: spacing sqrt of the feature points' distance
/// between keys) and ``stiffness``: the spring lambda per key, a float for all keys or an
/// (N,) array; ``inf`` (or ``None``) hits that key exactly, a finite lambda >= 0 lets the
/// motion pass near it (smaller = smoother; an open motion needs two keys and a closed one
/// one key with lambda > 0). ``inserted_stiffness`` is lambda for the poses inserted at
/// earlier levels (``None`` = ``inf``: kept once inserted). ``"four_point"`` interpolates (C1),
/// ``"bspline"`` and ``"jarek"`` approximate (C2).
/// Raises ValueError naming the bad pose, key or sample and the reason.
#[pyfunction]
#[pyo3(signature = (poses, scheme=Choice::of(CurveScheme::Variational), levels=5, closed=false,
    feature_points=None, parametrization=Choice::of(Parametrization::Uniform), stiffness=None,
    inserted_stiffness=None))]
#[pyo3(
    text_signature = "(poses, scheme='variational', levels=5, closed=False, feature_points=None, parametrization='uniform', stiffness=None, inserted_stiffness=None)"
)]
#[allow(clippy::too_many_arguments)]
fn feature_motion<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    scheme: Choice<FeatureMotion, CurveScheme>,
    #[pyo3(from_py_with = args::levels::<FeatureMotion>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<FeatureMotion>)] closed: bool,
    feature_points: Option<&Bound<'py, PyAny>>,
    parametrization: Choice<FeatureMotion, Parametrization>,
    stiffness: Option<&Bound<'py, PyAny>>,
    inserted_stiffness: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = FeatureMotion::NAME;
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let (mut spec, stiffness) = read_feature_spec(
        F,
        scheme.0,
        levels,
        closed,
        parametrization.0,
        stiffness,
        inserted_stiffness,
    )?;
    let (points, k) = feature_points_arg(F, feature_points)?;
    let out_len = if n >= 2 {
        polyscrew::subdivided_len(n, levels, closed)
    } else {
        0
    };
    check_budget(
        F,
        poses.copy()
            + copy_of(points.as_ref())
            + stiffness.copy()
            + Footprint::of::<Pose>(n)
            + Footprint::of::<DVec3>(k)
            + Footprint::of::<f64>(stiffness.len(n))
            + feature_footprint(n, k, &spec)
            + Footprint::of::<[f64; 16]>(out_len),
        "the feature-point motion",
        FEATURE_HINT,
    )?;
    spec.stiffness.keys = stiffness.keys(F, n)?;
    let poses = poses.read()?;
    let points = points.as_ref().map(|p| p.read()).transpose()?;
    let views = (poses.as_array(), points.as_ref().map(|p| p.as_array()));
    let out = py.detach(|| -> PyResult<_> {
        let (v, p) = &views;
        let keys = read_keys(F, v)?;
        let points = read_feature_points(F, p.as_ref())?;
        core_feature_motion(&keys, points.as_deref(), &spec)
            .and_then(|d| poses_to_array(&d))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// sample_feature(
///     poses: ArrayLike,
///     key_times: ArrayLike,
///     times: ArrayLike,
///     scheme: CurveSchemeName = "variational",
///     levels: int = 5,
///     closed: bool = False,
///     feature_points: ArrayLike | None = None,
///     parametrization: ParametrizationName = "uniform",
///     stiffness: float | ArrayLike | None = None,
///     inserted_stiffness: float | None = None,
///     period: float | None = None,
///     timing: TimeMapName = "smooth",
/// ) -> FloatArray
///
/// ``feature_motion`` as a function of time, at ``times``: (len(times), 4, 4).
///
/// Key i sits at ``key_times[i]`` (finite, strictly increasing); ``period`` and ``timing``
/// as in ``sample``; between dense poses the motion is the screw joining them.
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, scheme=Choice::of(CurveScheme::Variational),
    levels=5, closed=false, feature_points=None,
    parametrization=Choice::of(Parametrization::Uniform), stiffness=None,
    inserted_stiffness=None, period=None, timing=Choice::of(Timing::Smooth)))]
#[pyo3(
    text_signature = "(poses, key_times, times, scheme='variational', levels=5, closed=False, feature_points=None, parametrization='uniform', stiffness=None, inserted_stiffness=None, period=None, timing='smooth')"
)]
#[allow(clippy::too_many_arguments)]
fn sample_feature<'py>(
    py: Python<'py>,
    poses: &Bound<'py, PyAny>,
    key_times: &Bound<'py, PyAny>,
    times: &Bound<'py, PyAny>,
    scheme: Choice<SampleFeature, CurveScheme>,
    #[pyo3(from_py_with = args::levels::<SampleFeature>)] levels: u32,
    #[pyo3(from_py_with = args::closed::<SampleFeature>)] closed: bool,
    feature_points: Option<&Bound<'py, PyAny>>,
    parametrization: Choice<SampleFeature, Parametrization>,
    stiffness: Option<&Bound<'py, PyAny>>,
    inserted_stiffness: Option<&Bound<'py, PyAny>>,
    period: Option<&Bound<'py, PyAny>>,
    timing: Choice<SampleFeature, Timing>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = SampleFeature::NAME;
    let poses = float_array(F, "poses", poses)?;
    let n = key_count(F, &poses)?;
    let (mut spec, stiffness) = read_feature_spec(
        F,
        scheme.0,
        levels,
        closed,
        parametrization.0,
        stiffness,
        inserted_stiffness,
    )?;
    let period = args::optional_float(F, "period", period)?;
    let timing = timing.0;
    let key_times = float_array(F, "key_times", key_times)?;
    let times = float_array(F, "times", times)?;
    let n_key_times = vector_len(F, "key_times", &key_times)?;
    let m = vector_len(F, "times", &times)?;
    let (points, k) = feature_points_arg(F, feature_points)?;
    check_budget(
        F,
        poses.copy()
            + key_times.copy()
            + times.copy()
            + copy_of(points.as_ref())
            + stiffness.copy()
            + Footprint::of::<Pose>(n)
            + Footprint::of::<f64>(n_key_times + m)
            + Footprint::of::<DVec3>(k)
            + Footprint::of::<f64>(stiffness.len(n))
            + feature_footprint(n, k, &spec)
            + Footprint::of::<f64>(n.saturating_add(1)).times(2)
            + Footprint::of::<Pose>(m)
            + Footprint::of::<[f64; 16]>(m),
        "the sampled feature-point motion",
        FEATURE_HINT,
    )?;
    spec.stiffness.keys = stiffness.keys(F, n)?;
    let (poses, key_times, times) = (poses.read()?, key_times.read()?, times.read()?);
    let points = points.as_ref().map(|p| p.read()).transpose()?;
    let views = (
        poses.as_array(),
        key_times.as_array(),
        times.as_array(),
        points.as_ref().map(|p| p.as_array()),
    );
    let out = py.detach(|| -> PyResult<_> {
        let (v, kt, tt, p) = &views;
        let keys = read_keys(F, v)?;
        let key_times = read_vector(F, "key_times", kt)?;
        let times = read_vector(F, "times", tt)?;
        let points = read_feature_points(F, p.as_ref())?;
        polyscrew::feature_motion_timed(&keys, &key_times, points.as_deref(), &spec, period, timing)
            .and_then(|m| m.sample(&times))
            .and_then(|p| poses_to_array(&p))
            .map_err(|e| to_py_err(F, e))
    })?;
    Ok(out.into_pyarray(py))
}

/// Adds the feature-point functions to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(register_points, m)?)?;
    m.add_function(wrap_pyfunction!(inertia_points, m)?)?;
    m.add_function(wrap_pyfunction!(feature_motion, m)?)?;
    m.add_function(wrap_pyfunction!(sample_feature, m)?)?;
    Ok(())
}
