//! Bindings of the feature-point motion design (Hofer-Pottmann-Ravani): registration, inertia
//! points, `feature_motion` and `sample_feature`. Conversion only; the math is in
//! `polyscrew::{registration, inertia, variational, feature_motion}`.

use glam::DVec3;
use numpy::ndarray::{ArrayViewD, Axis};
use numpy::{IntoPyArray, PyArray2, PyArray3};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use polyscrew::{
    feature_motion as core_feature_motion, register as core_register, CurveScheme, FeatureSpec,
    InertiaFrame, Parametrization, Stiffness, Timing, MAX_LEVELS,
};

use crate::{
    poses_to_array, read_keys, read_vector, shape_err, to_py_err, vec3s_to_array, FloatArray,
};

/// Reads `(K, 3)` points; finiteness is checked by the core, which names the point.
fn read_points(function: &str, what: &str, array: ArrayViewD<'_, f64>) -> PyResult<Vec<DVec3>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(shape_err(function, what, "(K, 3)", shape));
    }
    let flat: Vec<f64> = array.iter().copied().collect();
    Ok(flat.chunks_exact(3).map(DVec3::from_slice).collect())
}

/// Parses the design options shared by `feature_motion` and `sample_feature`.
#[allow(clippy::too_many_arguments)]
fn read_feature_spec(
    function: &str,
    n: usize,
    scheme: &str,
    levels: i64,
    closed: bool,
    parametrization: &str,
    stiffness: Option<&Bound<'_, PyAny>>,
    inserted_stiffness: f64,
) -> PyResult<FeatureSpec> {
    let scheme = CurveScheme::from_name(scheme).map_err(|e| to_py_err(function, e))?;
    let parametrization =
        Parametrization::from_name(parametrization).map_err(|e| to_py_err(function, e))?;
    let levels = u32::try_from(levels)
        .ok()
        .filter(|l| *l <= MAX_LEVELS)
        .ok_or_else(|| {
            PyValueError::new_err(format!(
                "{function}: levels {levels} out of range 0..={MAX_LEVELS}"
            ))
        })?;
    let keys = match stiffness {
        None => None,
        Some(s) => match s.extract::<f64>() {
            Ok(x) => Some(vec![x; n]),
            Err(_) => {
                let a: FloatArray<'_> = s.extract()?;
                Some(read_vector(function, "stiffness", a.as_array())?)
            }
        },
    };
    Ok(FeatureSpec {
        scheme,
        levels,
        closed,
        parametrization,
        stiffness: Stiffness {
            keys,
            inserted: inserted_stiffness,
        },
    })
}

/// register_points(src, dst, weights=None) -> ndarray
///
/// The rigid pose (4, 4) minimising sum_k w_k |pose(src_k) - dst_k|^2 by Horn's quaternion
/// method: `src`, `dst` (K, 3) corresponding points, K >= 3, `weights` (K,) >= 0.
/// Raises ValueError for mismatched shapes, NaN, negative weights, or collinear points
/// (the best rotation is then not unique).
#[pyfunction]
#[pyo3(signature = (src, dst, weights=None))]
fn register_points<'py>(
    py: Python<'py>,
    src: FloatArray<'py>,
    dst: FloatArray<'py>,
    weights: Option<FloatArray<'py>>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "register_points";
    let src = read_points(F, "src", src.as_array())?;
    let dst = read_points(F, "dst", dst.as_array())?;
    let weights = weights
        .map(|w| read_vector(F, "weights", w.as_array()))
        .transpose()?;
    let pose = py
        .detach(|| core_register(&src, &dst, weights.as_deref()))
        .map_err(|e| to_py_err(F, e))?;
    Ok(poses_to_array(&[pose])
        .index_axis_move(Axis(0), 0)
        .into_pyarray(py))
}

/// inertia_points(points) -> ndarray
///
/// The six inertia points (6, 3) of a point cloud (K, 3): barycentre +- sqrt(lambda_j / 2)
/// e_j along the principal axes of its inertia tensor. They have the cloud's barycentre and
/// inertia tensor, so registering them is registering the cloud (for affine distortions).
/// Raises ValueError for fewer than 3 or collinear points.
#[pyfunction]
fn inertia_points<'py>(
    py: Python<'py>,
    points: FloatArray<'py>,
) -> PyResult<Bound<'py, PyArray2<f64>>> {
    const F: &str = "inertia_points";
    let points = read_points(F, "points", points.as_array())?;
    let frame = InertiaFrame::of(&points).map_err(|e| to_py_err(F, e))?;
    Ok(vec3s_to_array(&frame.inertia_points()).into_pyarray(py))
}

/// feature_motion(poses, scheme="variational", levels=5, closed=False, feature_points=None, parametrization="uniform", stiffness=None, inserted_stiffness=None) -> ndarray
///
/// Feature-point motion design (Hofer-Pottmann-Ravani): the curve scheme runs on the
/// homologous positions of the feature points of the key poses (N, 4, 4), and the rigid
/// body is registered to the distorted points at every output pose. Returns
/// (N * 2**levels, 4, 4) closed, ((N - 1) * 2**levels + 1, 4, 4) open; pose i * 2**levels
/// belongs to key i.
#[pyfunction]
#[pyo3(signature = (poses, scheme="variational", levels=5, closed=false, feature_points=None,
    parametrization="uniform", stiffness=None, inserted_stiffness=None))]
#[allow(clippy::too_many_arguments)]
fn feature_motion<'py>(
    py: Python<'py>,
    poses: FloatArray<'py>,
    scheme: &str,
    levels: i64,
    closed: bool,
    feature_points: Option<FloatArray<'py>>,
    parametrization: &str,
    stiffness: Option<&Bound<'py, PyAny>>,
    inserted_stiffness: Option<f64>,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = "feature_motion";
    let keys = read_keys(F, &poses)?;
    let spec = read_feature_spec(
        F,
        keys.len(),
        scheme,
        levels,
        closed,
        parametrization,
        stiffness,
        inserted_stiffness.unwrap_or(f64::INFINITY),
    )?;
    let points = feature_points
        .map(|p| read_points(F, "feature_points", p.as_array()))
        .transpose()?;
    let out = py
        .detach(|| core_feature_motion(&keys, points.as_deref(), &spec).map(|d| poses_to_array(&d)))
        .map_err(|e| to_py_err(F, e))?;
    Ok(out.into_pyarray(py))
}

/// sample_feature(poses, key_times, times, scheme="variational", levels=5, closed=False, feature_points=None, parametrization="uniform", stiffness=None, inserted_stiffness=None, period=None, timing="smooth") -> ndarray
///
/// `feature_motion` as a function of time, evaluated at `times` (M,): (M, 4, 4). Key i
/// sits at `key_times[i]` (strictly increasing); `period`, `timing` and the screw between
/// dense poses as in `sample`.
#[pyfunction]
#[pyo3(signature = (poses, key_times, times, scheme="variational", levels=5, closed=false,
    feature_points=None, parametrization="uniform", stiffness=None,
    inserted_stiffness=None, period=None, timing="smooth"))]
#[allow(clippy::too_many_arguments)]
fn sample_feature<'py>(
    py: Python<'py>,
    poses: FloatArray<'py>,
    key_times: FloatArray<'py>,
    times: FloatArray<'py>,
    scheme: &str,
    levels: i64,
    closed: bool,
    feature_points: Option<FloatArray<'py>>,
    parametrization: &str,
    stiffness: Option<&Bound<'py, PyAny>>,
    inserted_stiffness: Option<f64>,
    period: Option<f64>,
    timing: &str,
) -> PyResult<Bound<'py, PyArray3<f64>>> {
    const F: &str = "sample_feature";
    let keys = read_keys(F, &poses)?;
    let spec = read_feature_spec(
        F,
        keys.len(),
        scheme,
        levels,
        closed,
        parametrization,
        stiffness,
        inserted_stiffness.unwrap_or(f64::INFINITY),
    )?;
    let timing = Timing::from_name(timing).map_err(|e| to_py_err(F, e))?;
    let key_times = read_vector(F, "key_times", key_times.as_array())?;
    let times = read_vector(F, "times", times.as_array())?;
    let points = feature_points
        .map(|p| read_points(F, "feature_points", p.as_array()))
        .transpose()?;
    let out = py
        .detach(|| {
            polyscrew::feature_motion_timed(
                &keys,
                &key_times,
                points.as_deref(),
                &spec,
                period,
                timing,
            )
            .and_then(|m| m.sample(&times))
            .map(|p| poses_to_array(&p))
        })
        .map_err(|e| to_py_err(F, e))?;
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
