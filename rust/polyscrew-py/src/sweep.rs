//! Binding of the swept region (`polyscrew::sweep`): conversion only.

use numpy::ndarray::{Array2, ArrayViewD};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use glam::DVec3;
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::sweep::{
    body_footprint, sweep_mesh, Accuracy, SweepOptions, DEFAULT_TOLERANCE_REL, MAX_STEPS,
    SWEEP_HINT,
};
use polyscrew::{Error, Pose};

use crate::args::float_array;
use crate::args::{self, Function, Sweep};
use crate::arrays::{pose_count, read_poses, read_rows3};
use crate::errors::{check_budget, shape_err, to_py_err};

/// Reads `(T, 3)` integer triangles (no GIL needed).
fn read_triangles(
    function: &str,
    what: &str,
    array: &ArrayViewD<'_, i64>,
) -> PyResult<Vec<[i64; 3]>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(shape_err(function, what, "(T, 3)", shape));
    }
    let mut out = try_vec(shape[0], "triangles").map_err(|e| to_py_err(function, e))?;
    for t in array.rows() {
        out.push([t[0], t[1], t[2]]);
    }
    Ok(out)
}

/// sweep(vertices, triangles, poses, steps=1, caps=True, tolerance=None, info=False) -> (ndarray, ndarray) | (ndarray, ndarray, dict)
///
/// The region swept by the triangle mesh `vertices` (V, 3), `triangles` (T, 3) (the body in
/// its local frame) moving through `poses` (N >= 2, 4, 4), one screw per span
/// (Rossignac-Kim, "Swept volumes"): each screw's generator (silhouette edge segments and
/// characteristic segments, in the body frame) swept in quads, the body at the first and last
/// pose as caps when `caps`, and at interior poses the faces where the motion turns back. Its
/// depth image from outside equals that of the union of the body's instances.
///
/// Accuracy: each screw takes the fewest steps (at least `steps`) that keep every swept
/// triangle within `tolerance` (a length in the body's units) of the exact surface its
/// generator sweeps (chord sagitta `rho (1 - cos(theta / 2k))` plus the quads' twist).
/// `tolerance=None`: 0.2 % of the body's bounding radius (half its bounding box's
/// diagonal); `tolerance=0`: no tolerance, exactly `steps` per screw.
/// Returns `(vertices (V', 3) float64, triangles (T', 3) int64)`, world frame, triangles
/// counter-clockwise seen from outside; with `info=True` also a dict: `tolerance` (the one
/// asked for, 0 without), `error_bound` (the bound met, at most `tolerance` unless
/// `MAX_STEPS` capped a screw), `max_steps` (most steps of one screw), `generator_segments`.
/// Raises ValueError for an empty mesh, a NaN vertex, a bad or zero-area triangle (with its
/// index), fewer than 2 poses, a non-rigid pose, `steps` outside 1..=4096, or a negative or
/// non-finite `tolerance`.
#[pyfunction]
#[pyo3(signature = (vertices, triangles, poses, steps = 1, caps = true, tolerance = None, info = false))]
#[allow(clippy::too_many_arguments)]
fn sweep<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    triangles: &Bound<'py, PyAny>,
    poses: &Bound<'py, PyAny>,
    #[pyo3(from_py_with = args::steps::<Sweep>)] steps: u32,
    #[pyo3(from_py_with = args::caps::<Sweep>)] caps: bool,
    tolerance: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = info_arg)] info: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    const F: &str = Sweep::NAME;
    let accuracy = match args::optional_float(F, "tolerance", tolerance)? {
        None => Accuracy::Relative(DEFAULT_TOLERANCE_REL),
        Some(0.0) => Accuracy::Steps,
        Some(t) if t.is_finite() && t > 0.0 => Accuracy::Tolerance(t),
        Some(t) => {
            return Err(crate::errors::invalid(format!(
                "{F}: tolerance: {t} is not a positive length (0: exactly `steps` per screw)"
            )))
        }
    };
    let vertices = float_array(F, "vertices", vertices)?;
    let triangles = args::int_array(F, "triangles", triangles)?;
    let poses = float_array(F, "poses", poses)?;
    let (n, single) = pose_count(F, "poses", poses.shape())?;
    if single {
        return Err(to_py_err(F, Error::TooFew { got: 1, need: 2 }));
    }
    let (nv, nt) = (
        vertices.shape().first().copied().unwrap_or(0),
        triangles.shape().first().copied().unwrap_or(0),
    );
    // The inputs read and the body built; the core checks the output span by span.
    check_budget(
        F,
        vertices.copy()
            + triangles.copy()
            + poses.copy()
            + Footprint::of::<Pose>(n)
            + body_footprint(nv, nt),
        "the swept body",
        SWEEP_HINT,
    )?;
    let (vertices, triangles, poses) = (vertices.read()?, triangles.read()?, poses.read()?);
    let options = SweepOptions {
        steps,
        caps,
        accuracy,
    };
    let views = (vertices.as_array(), triangles.as_array(), poses.as_array());
    type Swept = (Array2<f64>, Array2<i64>, [f64; 2], [usize; 2]);
    let (vo, to, bound, counts) = py.detach(|| -> PyResult<Swept> {
        let (va, ta, pa) = &views;
        let v: Vec<DVec3> = read_rows3(F, "vertices", va, "(N, 3)")?;
        let t = read_triangles(F, "triangles", ta)?;
        let p = read_poses(F, "poses", pa)?;
        let out = sweep_mesh(&v, &t, &p, &options).map_err(|e| to_py_err(F, e))?;
        drop((v, t, p));
        let mut flat =
            try_vec(out.vertices.len() * 3, "the swept mesh").map_err(|e| to_py_err(F, e))?;
        flat.extend(out.vertices.iter().flat_map(|q| q.to_array()));
        let vo = Array2::from_shape_vec((out.vertices.len(), 3), flat)
            .map_err(|e| crate::errors::invalid(format!("{F}: {e}")))?;
        let mut flat =
            try_vec(out.triangles.len() * 3, "the swept mesh").map_err(|e| to_py_err(F, e))?;
        flat.extend(out.triangles.iter().flat_map(|t| t.map(i64::from)));
        let to = Array2::from_shape_vec((out.triangles.len(), 3), flat)
            .map_err(|e| crate::errors::invalid(format!("{F}: {e}")))?;
        Ok((
            vo,
            to,
            [out.tolerance, out.error_bound],
            [out.max_steps as usize, out.generator_segments],
        ))
    })?;
    let (vo, to) = (vo.into_pyarray(py), to.into_pyarray(py));
    if !info {
        return PyTuple::new(py, [vo.into_any(), to.into_any()]);
    }
    let dict = PyDict::new(py);
    dict.set_item("tolerance", bound[0])?;
    dict.set_item("error_bound", bound[1])?;
    dict.set_item("max_steps", counts[0])?;
    dict.set_item("generator_segments", counts[1])?;
    PyTuple::new(py, [vo.into_any(), to.into_any(), dict.into_any()])
}

/// `info`: a bool.
fn info_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg(Sweep::NAME, "info", obj)
}

/// Adds `sweep` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add("MAX_STEPS", MAX_STEPS)?;
    m.add("DEFAULT_SWEEP_TOLERANCE", DEFAULT_TOLERANCE_REL)?;
    Ok(())
}
