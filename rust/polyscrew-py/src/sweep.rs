//! Binding of the swept region (`polyscrew::sweep`): conversion only.

use numpy::ndarray::{Array2, ArrayViewD};
use numpy::{AllowTypeChange, IntoPyArray, PyArray2, PyArrayLikeDyn};
use pyo3::exceptions::PyValueError;
use pyo3::prelude::*;

use glam::DVec3;
use polyscrew::sweep::{sweep_mesh, SweepOptions, MAX_STEPS};
use polyscrew::Error;

use crate::{read_poses, shape_err, to_py_err, FloatArray};

/// An integer array-like argument converted to int64 on the way in.
type IntArray<'py> = PyArrayLikeDyn<'py, i64, AllowTypeChange>;

/// Reads `(N, 3)` float coordinates without judging them (the core names a bad vertex).
fn read_points(function: &str, what: &str, array: ArrayViewD<'_, f64>) -> PyResult<Vec<DVec3>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(shape_err(function, what, "(N, 3)", shape));
    }
    let flat: Vec<f64> = array.iter().copied().collect();
    Ok(flat.chunks_exact(3).map(DVec3::from_slice).collect())
}

/// Reads `(T, 3)` integer triangles.
fn read_triangles(
    function: &str,
    what: &str,
    array: ArrayViewD<'_, i64>,
) -> PyResult<Vec<[i64; 3]>> {
    let shape = array.shape();
    if shape.len() != 2 || shape[1] != 3 {
        return Err(shape_err(function, what, "(T, 3)", shape));
    }
    let flat: Vec<i64> = array.iter().copied().collect();
    Ok(flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect())
}

/// sweep(vertices, triangles, poses, steps=8, caps=True) -> (ndarray, ndarray)
///
/// The region swept by the triangle mesh `vertices` (V, 3), `triangles` (T, 3) (the body in
/// its local frame) moving through `poses` (N >= 2, 4, 4), one screw per span
/// (Rossignac-Kim, "Swept volumes"): each screw's generator (silhouette edge segments and
/// characteristic segments, in the body frame) swept in `steps` quads, the body at the first
/// and last pose as caps when `caps`, and at interior poses the faces where the motion turns
/// back. Its depth image from outside equals that of the union of the body's instances.
/// Returns `(vertices (V', 3) float64, triangles (T', 3) int64)`, world frame, triangles
/// counter-clockwise seen from outside. Raises ValueError for an empty mesh, a NaN vertex, a
/// bad or zero-area triangle (with its index), fewer than 2 poses, a non-rigid pose, or
/// `steps` outside 1..=4096.
#[pyfunction]
#[pyo3(signature = (vertices, triangles, poses, steps = 8, caps = true))]
#[allow(clippy::type_complexity)]
fn sweep<'py>(
    py: Python<'py>,
    vertices: FloatArray<'py>,
    triangles: IntArray<'py>,
    poses: FloatArray<'py>,
    steps: i64,
    caps: bool,
) -> PyResult<(Bound<'py, PyArray2<f64>>, Bound<'py, PyArray2<i64>>)> {
    const F: &str = "sweep";
    let v = read_points(F, "vertices", vertices.as_array())?;
    let t = read_triangles(F, "triangles", triangles.as_array())?;
    let (p, single) = read_poses(F, "poses", poses.as_array())?;
    if single {
        return Err(to_py_err(F, Error::TooFew { got: 1, need: 2 }));
    }
    let steps = u32::try_from(steps)
        .ok()
        .filter(|s| (1..=MAX_STEPS).contains(s))
        .ok_or_else(|| {
            to_py_err(
                F,
                Error::Invalid {
                    what: "steps",
                    reason: format!("{steps} is outside 1..={MAX_STEPS}"),
                },
            )
        })?;
    let options = SweepOptions { steps, caps };
    let (vo, to) = py
        .detach(|| {
            sweep_mesh(&v, &t, &p, &options).map(|out| {
                let flat: Vec<f64> = out.vertices.iter().flat_map(|q| q.to_array()).collect();
                let vo = Array2::from_shape_vec((out.vertices.len(), 3), flat);
                let flat: Vec<i64> = out
                    .triangles
                    .iter()
                    .flat_map(|t| t.map(|i| i as i64))
                    .collect();
                let to = Array2::from_shape_vec((out.triangles.len(), 3), flat);
                (vo, to)
            })
        })
        .map_err(|e| to_py_err(F, e))?;
    let shape_bug = |e: numpy::ndarray::ShapeError| PyValueError::new_err(format!("{F}: {e}"));
    let (vo, to) = (vo.map_err(shape_bug)?, to.map_err(shape_bug)?);
    Ok((vo.into_pyarray(py), to.into_pyarray(py)))
}

/// Adds `sweep` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add("MAX_STEPS", MAX_STEPS)?;
    Ok(())
}
