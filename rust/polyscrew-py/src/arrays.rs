//! Array readers and writers shared by the domains: poses, vectors, rows, the motion spec.
//!
//! Each reader takes a view of an argument already read ([`crate::args::Arg::read`], after
//! the budget's check), needs no GIL, allocates fallibly and names the function and the
//! argument in its errors.

use glam::DVec3;
use numpy::ndarray::{Array2, Array3, ArrayViewD, Ix3};
use polyscrew::memory::try_vec;
use polyscrew::{Error, MotionSpec, Pose, Scheme, Timing};
use pyo3::prelude::*;

use crate::args::FloatArg;
use crate::errors::{arg_err, invalid, shape_err, to_py_err};

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
    // read through a view of fixed dimensions: ndarray iterates a broadcast or strided view
    // of dynamic dimensions about twice as slowly
    let mut push = |values: &mut dyn FnMut(&mut [f64; 16]), i: usize| -> PyResult<()> {
        let mut m = [0.0; 16];
        values(&mut m);
        let row = |r: usize| [m[4 * r], m[4 * r + 1], m[4 * r + 2], m[4 * r + 3]];
        let pose = Pose::from_rows(&[row(0), row(1), row(2), row(3)], i)
            .map_err(|e| pose_err(function, what, single, e))?;
        poses.push(pose);
        Ok(())
    };
    if let Ok(fixed) = array.view().into_dimensionality::<Ix3>() {
        for (i, matrix) in fixed.outer_iter().enumerate() {
            push(&mut |m| fill(m, matrix.iter()), i)?;
        }
    } else {
        push(&mut |m| fill(m, array.iter()), 0)?;
    }
    Ok(poses)
}

/// The error of a pose that is not rigid: `"{function}: {what}: pose 2: ..."`, or
/// `"{function}: {what}: ..."` for a `single` matrix.
fn pose_err(function: &str, what: &str, single: bool, e: Error) -> PyErr {
    match e {
        Error::BadPose { defect, .. } if single => invalid(format!("{function}: {what}: {defect}")),
        other if single => to_py_err(function, other),
        other => invalid(format!("{function}: {what}: {other}")),
    }
}

/// Reads the one pose of a `(4, 4)` array (its shape checked by the caller), without
/// allocating: what `read_poses` makes of a single matrix (no GIL needed).
pub fn read_one_pose(function: &str, what: &str, array: &ArrayViewD<'_, f64>) -> PyResult<Pose> {
    let mut m = [[0.0; 4]; 4];
    for (slot, v) in m.iter_mut().flatten().zip(array.iter()) {
        *slot = *v;
    }
    Pose::from_rows(&m, 0).map_err(|e| pose_err(function, what, true, e))
}

/// `m` filled from `values` (as many as it holds).
#[inline]
pub fn fill<'a, const K: usize>(m: &mut [f64; K], values: impl Iterator<Item = &'a f64>) {
    for (slot, v) in m.iter_mut().zip(values) {
        *slot = *v;
    }
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
pub fn key_count(function: &str, poses: &FloatArg<'_>) -> PyResult<usize> {
    pose_count(function, "poses", poses.shape()).map(|(n, _)| n)
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
pub fn vector_len(function: &str, what: &str, array: &FloatArg<'_>) -> PyResult<usize> {
    if array.ndim() != 1 {
        return Err(shape_err(function, what, "(N,)", array.shape()));
    }
    Ok(array.len())
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
pub fn rows3_len(array: &FloatArg<'_>) -> usize {
    array.shape().first().copied().unwrap_or(0)
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

/// The motion spec shared by the subdivision and sampling functions.
pub fn read_spec(
    scheme: Scheme,
    levels: u32,
    closed: bool,
    period: Option<f64>,
    timing: Timing,
) -> MotionSpec {
    MotionSpec {
        scheme,
        levels,
        closed,
        period,
        timing,
    }
}
