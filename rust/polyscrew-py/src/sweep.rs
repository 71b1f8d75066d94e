//! Binding of the swept region (`polyscrew::sweep`): conversion only.

use numpy::ndarray::{Array2, ArrayViewD};
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyTuple};

use glam::DVec3;
use polyscrew::memory::{try_vec, Footprint};
use polyscrew::sweep::closed::{
    closed_work_mesh, sweep_closed_mesh, ClosedOptions, CELL_PER_TOLERANCE, CLOSED_HINT,
    DECIMATE_TARGET, MAX_THREADS,
};
use polyscrew::sweep::{
    body_footprint, sweep_mesh, Accuracy, SweepOptions, DEFAULT_CELL_REL,
    DEFAULT_CLOSED_TOLERANCE_REL, DEFAULT_TOLERANCE_REL, MAX_STEPS, SWEEP_HINT,
};
use polyscrew::{Error, Pose};

use crate::args::{self, Function, Sweep};
use crate::args::{float_array, FloatArg, IntArg};
use crate::arrays::{pose_count, read_poses, read_rows3};
use crate::errors::{check_budget, shape_err, to_py_err};
use crate::progress::watched;

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

// stub:
// stub: IntArray = npt.NDArray[np.int64]
// stub:
// stub: class SweepInfo(TypedDict):
// stub:     tolerance: float
// stub:     error_bound: float
// stub:     max_steps: int
// stub:     generator_segments: int
/// sweep(
///     vertices: ArrayLike,
///     triangles: ArrayLike,
///     poses: ArrayLike,
///     steps: int = 1,
///     caps: bool = True,
///     tolerance: float | None = None,
///     info: Literal[False] = False,
/// ) -> tuple[FloatArray, IntArray]
/// sweep(
///     vertices: ArrayLike,
///     triangles: ArrayLike,
///     poses: ArrayLike,
///     steps: int = 1,
///     caps: bool = True,
///     tolerance: float | None = None,
///     *,
///     info: Literal[True],
/// ) -> tuple[FloatArray, IntArray, SweepInfo]
///
/// The region swept by a triangle mesh moving through ``poses``, as one triangle mesh.
///
/// ``vertices`` (V, 3) and ``triangles`` (T, 3) are the body in its local frame; ``poses``
/// (N >= 2, 4, 4) its world poses, one screw per span (Rossignac-Kim, "Swept volumes").
/// Each screw's generator (silhouette edge segments and characteristic segments inside
/// faces, computed in the body frame) is swept in quads; ``caps`` adds the body at the first
/// and the last pose; at interior poses the faces where the motion turns back are added. The
/// result is a superset of the swept region's boundary whose excess lies inside the region:
/// its depth image from outside equals that of the union of the body's instances.
///
/// Accuracy: each screw takes the fewest steps (at least ``steps``) that keep every swept
/// triangle within ``tolerance`` (a length, the body's units) of the exact surface its
/// generator sweeps: the chord sagitta ``rho (1 - cos(theta / 2k))`` (``rho`` the farthest
/// generator point from the screw's axis, ``theta`` its angle, ``k`` steps) and the quads'
/// twist ``sin(theta / 2k) l / (2 n)`` (a segment of length ``l`` across the axis cut into
/// ``n`` pieces), each held to half the tolerance. ``tolerance=None``: ``DEFAULT_SWEEP_TOLERANCE``
/// (0.2 %) of the body's bounding radius (half its bounding box's diagonal);
/// ``tolerance=0``: no tolerance, exactly ``steps`` per screw.
///
/// Returns ``(vertices (V', 3) float64, triangles (T', 3) int64)`` in world coordinates,
/// triangles counter-clockwise seen from outside, none degenerate; with ``info=True`` also a
/// dict: ``tolerance`` (asked for; 0 without), ``error_bound`` (the bound met: at most
/// ``tolerance`` unless ``MAX_STEPS`` capped a screw), ``max_steps``, ``generator_segments``.
///
/// Raises ``ValueError`` for an empty mesh, a NaN or infinite vertex or one beyond +-1e75, a
/// triangle with an index out of range or zero area (naming the triangle), a fractional
/// index (``2.7``: float arrays are accepted only with whole numbers), fewer than 2 poses, a
/// non-rigid pose (naming it), ``steps`` outside ``1..=MAX_STEPS``, a negative or non-finite
/// ``tolerance``, or a swept mesh over the memory budget (checked before each screw's quads
/// are added: 48 bytes per vertex, 36 per triangle).
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
    // The inputs read and the body built; the core checks the output span by span.
    let (vertices, triangles, poses) = body_and_poses(F, vertices, triangles, poses, SWEEP_HINT)?;
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
        let (vo, to) = mesh_arrays(F, &out.vertices, &out.triangles)?;
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

/// `sweep_closed`'s result off the watched thread: the mesh, its figures (cell, bound,
/// tolerance, vertices' bound), counts (attempts, poses, refined cubes) and `finer_refused`.
type Closed = (
    Array2<f64>,
    Array2<i64>,
    [f64; 4],
    [usize; 3],
    Option<String>,
);

// stub:
// stub: class ClosedSweepInfo(TypedDict):
// stub:     cell: float
// stub:     error_bound: float
// stub:     vertex_bound: float
// stub:     tolerance: float
// stub:     attempts: int
// stub:     poses: int
// stub:     refined_cubes: int
// stub:     finer_refused: str | None
/// sweep_closed(
///     vertices: ArrayLike,
///     triangles: ArrayLike,
///     poses: ArrayLike,
///     cell: float | None = None,
///     info: Literal[False] = False,
///     *,
///     tolerance: float | None = None,
///     threads: int | None = None,
///     progress: Callable[[float], object] | None = None,
///     decimate: bool = True,
/// ) -> tuple[FloatArray, IntArray]
/// sweep_closed(
///     vertices: ArrayLike,
///     triangles: ArrayLike,
///     poses: ArrayLike,
///     cell: float | None = None,
///     *,
///     info: Literal[True],
///     tolerance: float | None = None,
///     threads: int | None = None,
///     progress: Callable[[float], object] | None = None,
///     decimate: bool = True,
/// ) -> tuple[FloatArray, IntArray, ClosedSweepInfo]
///
/// The boundary of the region swept by a closed triangle mesh moving through ``poses``, as
/// one closed, consistently oriented, self-intersection-free triangle mesh, every vertex within
/// ``tolerance`` of the swept boundary.
///
/// ``vertices`` (V, 3) and ``triangles`` (T, 3) are the body in its local frame (closed:
/// every edge in two faces); ``poses`` (N >= 2, 4, 4) its world poses, one screw per span.
/// The region's signed distance (the minimum over the motion of the body's, the body's
/// sampled on a grid six times finer than the cell, the motion sampled so that no point
/// moves more than a cell between samples) is contoured on a grid by marching tetrahedra, and
/// every vertex moved along its grid edge to the zero of the distance refined between the
/// samples. ``tolerance`` (a length; None: ``DEFAULT_CLOSED_TOLERANCE`` (0.5 %) of the body's
/// extent, its bounding box's diagonal) sets the cell: ``CLOSED_CELL_PER_TOLERANCE`` times
/// it, contoured again at a finer cell (from the bound found), then at one where the vertices'
/// part of the bound cannot exceed it, while the bound does.
/// ``cell`` (scripts) fixes the cell instead; not both. ``threads``: the body's distance
/// grid and the region's field are computed on this many threads (0: all the machine has;
/// at most 64);
/// the mesh is the same, bit for bit. Slower than ``sweep`` (seconds, not milliseconds) and
/// many more triangles: for meshes that must be closed (``sweep_closed_work`` tells the work
/// before).
///
/// ``progress``: a callable, called with the fraction done (0 to 1; from 0 again for a second
/// grid) about ten times a second, on the calling thread, while the sweep runs on a thread of
/// its own; whatever it raises stops the sweep within a part of its work (a few thousand
/// vertices, a round of crease splits) and is raised by ``sweep_closed``, as is a signal
/// (Ctrl-C: ``KeyboardInterrupt``). None: no calls, and the sweep runs on the calling thread.
///
/// ``decimate`` (on by default): fewer triangles (3.8 to 5.7 times fewer at the defaults),
/// vertices removed where the boundary is flat, and along its creases, by collapses that keep
/// every new edge's midpoint within ``CLOSED_DECIMATE_TARGET`` cells of the boundary (the new
/// faces then within about twice that, plus the bound); the vertices left are some of those
/// without it, so ``error_bound`` still holds for them. It takes 1.6 to 2.1 times the CPU;
/// ``decimate=False`` gives the contoured mesh as it is.
///
/// Returns ``(vertices (V', 3) float64, triangles (T', 3) int64)`` in world coordinates,
/// triangles counter-clockwise seen from outside, every edge in exactly two; with
/// ``info=True`` also a dict: ``cell``, ``error_bound`` (every vertex and every edge's
/// midpoint within it of the swept boundary: the largest distance left at one, read exactly,
/// plus the motion's gap between the poses read; at most ``tolerance`` unless
/// ``finer_refused``), ``vertex_bound``
/// (its part that covers the vertices alone), ``tolerance`` (0 with a ``cell``), ``attempts`` (grids contoured: 1 to 3),
/// ``poses`` (the dense poses sampled), ``refined_cubes`` (grid cubes cut four times finer
/// because the boundary has a feature narrower than a cell there, such as a slab of outside
/// space between two sheets, which the grid's points alone would have filled) and
/// ``finer_refused`` (None, or why no finer grid was contoured though ``error_bound`` exceeds
/// ``tolerance``: its grids over the memory budget or a limit; the mesh is then the last
/// attempt's, closed and within ``error_bound``).
///
/// Raises ``ValueError`` for the errors of ``sweep``, a body that is not closed, a ``cell``
/// or ``tolerance`` that is not positive or too fine (a cell below 1/1000 of the body's
/// extent), both of them, or grids over the memory budget.
#[pyfunction]
#[pyo3(signature = (vertices, triangles, poses, cell = None, info = false, *, tolerance = None, threads = None, progress = None, decimate = true))]
#[allow(clippy::too_many_arguments)]
fn sweep_closed<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    triangles: &Bound<'py, PyAny>,
    poses: &Bound<'py, PyAny>,
    cell: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = closed_info_arg)] info: bool,
    tolerance: Option<&Bound<'py, PyAny>>,
    threads: Option<&Bound<'py, PyAny>>,
    progress: Option<&Bound<'py, PyAny>>,
    #[pyo3(from_py_with = decimate_arg)] decimate: bool,
) -> PyResult<Bound<'py, PyTuple>> {
    const F: &str = "sweep_closed";
    let options = ClosedOptions {
        decimate,
        ..closed_options(F, cell, tolerance, threads)?
    };
    let (vertices, triangles, poses) = body_and_poses(F, vertices, triangles, poses, CLOSED_HINT)?;
    let (vertices, triangles, poses) = (vertices.read()?, triangles.read()?, poses.read()?);
    let views = (vertices.as_array(), triangles.as_array(), poses.as_array());
    let closed = watched(py, F, progress, |watch| -> PyResult<Closed> {
        let (va, ta, pa) = &views;
        let v: Vec<DVec3> = read_rows3(F, "vertices", va, "(N, 3)")?;
        let t = read_triangles(F, "triangles", ta)?;
        let p = read_poses(F, "poses", pa)?;
        let out = sweep_closed_mesh(&v, &t, &p, &options, watch).map_err(|e| to_py_err(F, e))?;
        drop((v, t, p));
        let (vo, to) = mesh_arrays(F, &out.vertices, &out.triangles)?;
        let figures = [out.cell, out.error_bound, out.tolerance, out.vertex_bound];
        Ok((
            vo,
            to,
            figures,
            [out.attempts, out.poses, out.refined_cubes],
            out.finer_refused.map(|e| e.to_string()),
        ))
    })?;
    let (vo, to, figures, counts, refused) = closed;
    let (vo, to) = (vo.into_pyarray(py), to.into_pyarray(py));
    if !info {
        return PyTuple::new(py, [vo.into_any(), to.into_any()]);
    }
    let dict = PyDict::new(py);
    dict.set_item("cell", figures[0])?;
    dict.set_item("error_bound", figures[1])?;
    dict.set_item("vertex_bound", figures[3])?;
    dict.set_item("tolerance", figures[2])?;
    dict.set_item("attempts", counts[0])?;
    dict.set_item("poses", counts[1])?;
    dict.set_item("refined_cubes", counts[2])?;
    dict.set_item("finer_refused", refused)?;
    PyTuple::new(py, [vo.into_any(), to.into_any(), dict.into_any()])
}

// stub:
// stub: class ClosedSweepWork(TypedDict):
// stub:     cell: float
// stub:     tolerance: float
// stub:     poses: int
// stub:     grid_points: int
// stub:     body_points: int
// stub:     bytes: int
/// sweep_closed_work(
///     vertices: ArrayLike,
///     triangles: ArrayLike,
///     poses: ArrayLike,
///     cell: float | None = None,
///     *,
///     tolerance: float | None = None,
/// ) -> ClosedSweepWork
///
/// What ``sweep_closed`` with the same arguments will sample, without sampling it (the
/// arguments checked as it checks them; the dense poses counted, milliseconds): ``cell`` and
/// ``tolerance`` (of its first attempt), ``poses`` (dense poses), ``grid_points`` (the world
/// grid over the instances' boxes), ``body_points`` (the body's fine distance grid) and
/// ``bytes`` (the two grids', which ``sweep_closed`` checks against ``memory_budget()`` before
/// sampling either). For a caller to refuse work that would run for minutes before it starts.
///
/// Raises ``ValueError`` as ``sweep_closed`` does (but for the memory budget of its grids).
#[pyfunction]
#[pyo3(signature = (vertices, triangles, poses, cell = None, *, tolerance = None))]
fn sweep_closed_work<'py>(
    py: Python<'py>,
    vertices: &Bound<'py, PyAny>,
    triangles: &Bound<'py, PyAny>,
    poses: &Bound<'py, PyAny>,
    cell: Option<&Bound<'py, PyAny>>,
    tolerance: Option<&Bound<'py, PyAny>>,
) -> PyResult<Bound<'py, PyDict>> {
    const F: &str = "sweep_closed_work";
    let options = closed_options(F, cell, tolerance, None)?;
    let (vertices, triangles, poses) = body_and_poses(F, vertices, triangles, poses, CLOSED_HINT)?;
    let (vertices, triangles, poses) = (vertices.read()?, triangles.read()?, poses.read()?);
    let views = (vertices.as_array(), triangles.as_array(), poses.as_array());
    let work = py.detach(|| -> PyResult<_> {
        let (va, ta, pa) = &views;
        let v: Vec<DVec3> = read_rows3(F, "vertices", va, "(N, 3)")?;
        let t = read_triangles(F, "triangles", ta)?;
        let p = read_poses(F, "poses", pa)?;
        closed_work_mesh(&v, &t, &p, &options).map_err(|e| to_py_err(F, e))
    })?;
    let dict = PyDict::new(py);
    dict.set_item("cell", work.cell)?;
    dict.set_item("tolerance", work.tolerance)?;
    dict.set_item("poses", work.poses)?;
    dict.set_item("grid_points", work.grid_points)?;
    dict.set_item("body_points", work.body_points)?;
    dict.set_item("bytes", work.bytes)?;
    Ok(dict)
}

/// The options of `sweep_closed` and `sweep_closed_work`.
fn closed_options(
    function: &'static str,
    cell: Option<&Bound<'_, PyAny>>,
    tolerance: Option<&Bound<'_, PyAny>>,
    threads: Option<&Bound<'_, PyAny>>,
) -> PyResult<ClosedOptions> {
    let threads = match threads {
        Some(t) if !t.is_none() => {
            args::int_in(function, "threads", t, 0, MAX_THREADS as i64)? as usize
        }
        _ => 0,
    };
    Ok(ClosedOptions {
        cell: args::optional_float(function, "cell", cell)?,
        tolerance: args::optional_float(function, "tolerance", tolerance)?,
        threads,
        decimate: false,
    })
}

/// The `vertices`, `triangles` and `poses` (two or more) of a sweep, their copies, the poses
/// and the body checked against the memory budget (`hint`: how to ask for less).
fn body_and_poses<'py>(
    function: &'static str,
    vertices: &Bound<'py, PyAny>,
    triangles: &Bound<'py, PyAny>,
    poses: &Bound<'py, PyAny>,
    hint: &'static str,
) -> PyResult<(FloatArg<'py>, IntArg<'py>, FloatArg<'py>)> {
    let vertices = float_array(function, "vertices", vertices)?;
    let triangles = args::int_array(function, "triangles", triangles)?;
    let poses = float_array(function, "poses", poses)?;
    let (n, single) = pose_count(function, "poses", poses.shape())?;
    if single {
        return Err(to_py_err(function, Error::TooFew { got: 1, need: 2 }));
    }
    let (nv, nt) = (
        vertices.shape().first().copied().unwrap_or(0),
        triangles.shape().first().copied().unwrap_or(0),
    );
    check_budget(
        function,
        vertices.copy()
            + triangles.copy()
            + poses.copy()
            + Footprint::of::<Pose>(n)
            + body_footprint(nv, nt),
        "the swept body",
        hint,
    )?;
    Ok((vertices, triangles, poses))
}

/// The `(V, 3)` float64 and `(T, 3)` int64 arrays of a mesh (no GIL needed).
fn mesh_arrays(
    function: &str,
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
) -> PyResult<(Array2<f64>, Array2<i64>)> {
    let mut flat =
        try_vec(vertices.len() * 3, "the swept mesh").map_err(|e| to_py_err(function, e))?;
    flat.extend(vertices.iter().flat_map(|q| q.to_array()));
    let vo = Array2::from_shape_vec((vertices.len(), 3), flat)
        .map_err(|e| crate::errors::invalid(format!("{function}: {e}")))?;
    let mut flat =
        try_vec(triangles.len() * 3, "the swept mesh").map_err(|e| to_py_err(function, e))?;
    flat.extend(triangles.iter().flat_map(|t| t.map(i64::from)));
    let to = Array2::from_shape_vec((triangles.len(), 3), flat)
        .map_err(|e| crate::errors::invalid(format!("{function}: {e}")))?;
    Ok((vo, to))
}

/// `info`: a bool.
fn info_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg(Sweep::NAME, "info", obj)
}

/// `sweep_closed`'s `info`, a bool.
fn closed_info_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg("sweep_closed", "info", obj)
}

/// `sweep_closed`'s `decimate`, a bool.
fn decimate_arg(obj: &Bound<'_, PyAny>) -> PyResult<bool> {
    args::bool_arg("sweep_closed", "decimate", obj)
}

/// Adds `sweep` to the module.
pub fn register(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(sweep, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_closed, m)?)?;
    m.add_function(wrap_pyfunction!(sweep_closed_work, m)?)?;
    // stub:
    // stub: MAX_STEPS: int
    // stub: """The largest accepted number of sweep steps per screw (4096)."""
    m.add("MAX_STEPS", MAX_STEPS)?;
    // stub:
    // stub: DEFAULT_SWEEP_TOLERANCE: float
    // stub: """The default tolerance of ``sweep``, as a fraction of the body's bounding radius (0.002)."""
    m.add("DEFAULT_SWEEP_TOLERANCE", DEFAULT_TOLERANCE_REL)?;
    // stub:
    // stub: DEFAULT_CLOSED_CELL: float
    // stub: """The cell of ``sweep_closed`` before it took a tolerance, as a fraction of the body's extent (0.015)."""
    m.add("DEFAULT_CLOSED_CELL", DEFAULT_CELL_REL)?;
    // stub:
    // stub: DEFAULT_CLOSED_TOLERANCE: float
    // stub: """The default tolerance of ``sweep_closed``, as a fraction of the body's extent, its bounding box's diagonal (0.005)."""
    m.add("DEFAULT_CLOSED_TOLERANCE", DEFAULT_CLOSED_TOLERANCE_REL)?;
    // stub:
    // stub: CLOSED_CELL_PER_TOLERANCE: float
    // stub: """The first cell of ``sweep_closed`` as a multiple of its tolerance (2)."""
    m.add("CLOSED_CELL_PER_TOLERANCE", CELL_PER_TOLERANCE)?;
    // stub:
    // stub: CLOSED_DECIMATE_TARGET: float
    // stub: """How near the boundary, in cells, ``sweep_closed(decimate=True)`` keeps every new edge's midpoint (0.05)."""
    m.add("CLOSED_DECIMATE_TARGET", DECIMATE_TARGET)?;
    Ok(())
}
