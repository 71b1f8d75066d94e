//! The swept region's boundary as one closed, consistently oriented, self-intersection-free
//! triangle mesh: the zero set of the region's signed distance, contoured by marching
//! tetrahedra (see `docs/sweep.md` for why this design and not a boolean of the soup).
//!
//! The region swept by a closed body `W` along poses `P(t)` is `{x : min_t d(P(t)^-1 x) <= 0}`
//! with `d` the body's signed distance (negative inside). Here:
//!
//! 1. `d` is sampled once, in the body frame, on a grid of spacing `h_b = cell /`
//!    [`BODY_SUBCELLS`] (exact point-to-triangle distances within a band of
//!    [`BAND_CELLS`] cells of the surface, signs by ray parity along the grid's columns) and
//!    read by trilinear interpolation, which is within `sqrt(3) h_b / 2` of `d` (`d` is
//!    1-Lipschitz, and a trilinear weight `w` puts its corners `sqrt(sum u (1 - u)) h_b` from
//!    the point on average);
//! 2. the motion is sampled densely (no body point moves more than a cell between two
//!    samples, each span on its own screw) and the region's field `g(x) = min_j d(P_j^-1 x)`
//!    is taken on a world grid of spacing `cell` around the region, only in the blocks of
//!    the grid that may hold the boundary (see `narrow_band`; elsewhere only its sign);
//! 3. the sign of every grid point whose value is within the grid's error of zero is settled
//!    by the exact minimum over every refined pose of the motion (`settle_signs`); each grid
//!    cube is cut into the six tetrahedra of Kuhn's triangulation (all sharing the main
//!    diagonal, so neighbouring cubes agree on their faces) and each tetrahedron where `g`
//!    changes sign gives one triangle or a quad (two triangles) with its vertices on the
//!    tetrahedron's edges; grid cubes where two sheets of the boundary face each other are read
//!    on a lattice four times finer, and those where a lattice point shows what the grid misses
//!    (outside where every corner is inside: a slab of outside space narrower than a cell; or a
//!    quarter cell across the grid's linear field) are cut into subcubes, their neighbours into
//!    tetrahedra that keep the whole conforming (`adaptive.rs`);
//! 4. each vertex is moved along its edge to the zero of `g` refined between the samples of
//!    the motion (the body at 8 poses per sample interval on each side of the sample that
//!    gave the minimum at the edge's ends), kept strictly inside the edge: regula falsi on
//!    trilinear reads, then secant steps on the body's exact signed distance (`exact.rs`),
//!    read only at the poses whose trilinear read can give the minimum; the value left is
//!    checked against every refined pose of the motion (an interval is skipped when a bound
//!    shows it above that value), and the steps are redone over all of them when a pose
//!    elsewhere is lower; a vertex still off by more than [`BRACKET_START`] cells is found by
//!    regula falsi between its edge's ends, whose exact signs differ (step 3);
//! 5. edges across creases are split at their midpoints moved onto the boundary
//!    (`crease.rs`), so that faces, not only vertices, lie on it.
//!
//! The reported bound is the largest exact `|g|` left at a vertex, plus the motion's gap
//! ([`motion_gap`]).
//!
//! Why it is closed and intersection-free (before step 5, which keeps both: `crease.rs`): the
//! surface pieces of a tetrahedron lie inside it and meet the pieces of its neighbours exactly
//! on their shared faces (a vertex is owned by
//! its grid edge, shared by every tetrahedron around the edge); every tetrahedron edge
//! crossed by the zero set holds one vertex, so every surface edge is in exactly two
//! triangles (two tetrahedra share a face, or two triangles of one quad share its diagonal),
//! and the orientation is taken from which end of a crossed edge is inside. The outer layer
//! of the grid is outside every instance, so the surface has no border.

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{DAffine3, DVec3};

use super::adaptive::{
    channel_cubes, coords, corner_offsets, cube_points, grid_key, grid_point, kuhn_value,
    offset_in, Key, Lattice, KUHN, SPLIT,
};
use super::exact::{closest_on_triangle, ExactField};
use super::hash::FastMap;
use super::{axis_distance, Body};
use crate::error::{Error, Expected, Result};
use crate::memory::{try_vec, Footprint};
use crate::motion::pose::Pose;
use crate::motion::screw::Screw;
use crate::progress::{Progress, Span};

/// The default cell of [`sweep_closed`] with neither a cell nor a tolerance given, before
/// issue 29 item 1 (kept for scripts that name it), as a fraction of the body's extent (the
/// diagonal of its bounding box): 1.5 %. [`sweep_closed`]'s default is now
/// [`DEFAULT_CLOSED_TOLERANCE_REL`].
pub const DEFAULT_CELL_REL: f64 = 0.015;

/// The default tolerance of [`sweep_closed`] as a fraction of the body's extent (the diagonal
/// of its bounding box, the "size" of `scripts/bench/sweep_measures.py`): 0.5 %, issue 29's
/// goal.
pub const DEFAULT_CLOSED_TOLERANCE_REL: f64 = 0.005;

/// The first cell tried for a tolerance, as a multiple of it. The reported bound (the exact
/// residual left at a vertex, capped at one cell, plus [`motion_gap`]: see [`guaranteed_cell`])
/// is, measured on issue 29's cases since stop 36's exact signs, `0.09` to `0.10` cells with
/// the gap's `0.0625` (cube, L-prism, torus, smoothed cube at 1 %, 2 % and 4 % of the extent).
/// Since stop 44 the bound covers every edge's midpoint too (`crease.rs` reads them all and
/// splits those more than a fortieth of a cell off; a split a neighbouring sheet blocks
/// leaves its edge up to about a third of a cell off): `0.26` to `0.41` cells with the gap on
/// `bench_sweep_closed.py`'s cube, torus and L-prism at a cell of 4 tolerances. A cell of `3`
/// tolerances meets the tolerance in one attempt on most; where the bound exceeds it, the grid
/// is contoured again at the cell [`RETRY_SPARE`] makes of the bound, and if that bound exceeds
/// it too, at [`guaranteed_cell`] (`attempts` 2 and 3). Up to stop 43: `2` tolerances, only
/// the midpoints of edges between triangles at an angle read, and none of them in the bound.
pub const CELL_PER_TOLERANCE: f64 = 3.0;

/// The second attempt's cell is this fraction of the cell at which the first attempt's bound
/// would have been the tolerance (the bound grows about as the cell does).
pub const RETRY_SPARE: f64 = 0.9;

/// The cell at which the vertices' part of the reported bound is within `tolerance` whatever
/// the body and the motion: the exact residual left at a vertex, at most one cell (a vertex
/// stays on its grid edge, and the residual is capped there), plus [`motion_gap`]; so
/// `tolerance / (1 + 1 / (2 REFINE_POSES))`. [`sweep_closed`] falls back on it when the second
/// cell's bound exceeds the tolerance. Since stop 44 the bound also covers the edges'
/// midpoints, which no cap holds (one cell plus half the edge at most): at this cell they are
/// within it on every case measured (`the_guaranteed_cell_meets_its_tolerance`), not by proof.
pub fn guaranteed_cell(tolerance: f64) -> f64 {
    tolerance / (1.0 + motion_gap(1.0))
}

/// How far below the minimum over the poses the refinement reads the minimum over the whole
/// continuous motion can be, at a cell of `cell`: `cell / (2 REFINE_POSES)` (see `contour`).
pub fn motion_gap(cell: f64) -> f64 {
    cell / (2.0 * REFINE_POSES as f64)
}

/// The body's distance grid is this many times finer than the world grid.
pub const BODY_SUBCELLS: f64 = 6.0;

/// Distances are exact within this many world cells of the body's surface (and clamped to
/// it beyond): enough for the trilinear reads of every grid point whose cube the surface
/// crosses (`sqrt(3)` cells from the surface at most, plus the body grid's own cube).
pub const BAND_CELLS: f64 = 2.5;

/// Side of a narrow-band block, in world grid points: the region's field is evaluated on the
/// fine grid only in the blocks whose coarse test cannot rule out the boundary.
pub const BLOCK_POINTS: usize = 4;

/// The coarse body field (spacing one world cell) behind the blocks' test holds exact
/// distances within this many cells of the surface. It must exceed the test's reach (the
/// ball about a block's centre, `sqrt(3) (BLOCK_POINTS + 1) / 2` cells, plus the fine field's
/// error and the nearest grid point's distance, `sqrt(3) / 2` cells: 5.6 cells): then a value
/// that decides a block is an unclamped distance, inside or outside (see `narrow_band` and
/// docs/sweep.md).
pub const COARSE_BAND_CELLS: f64 = 9.0;

/// Slack of the blocks' test, in cells: covers the float32 rounding of stored distances
/// (below `1e-6` cells at these bands) with a wide margin.
const BLOCK_SLACK_CELLS: f64 = 1e-4;

/// Round-off allowance of the distance bounds that skip work, relative to the largest
/// coordinate involved (the computed distances are within about `1e-15` of it).
const ROUNDOFF_REL: f64 = 1e-9;

/// Poses per sample interval at which a vertex's refinement evaluates the body.
pub const REFINE_POSES: usize = 8;

/// Regula falsi steps of a vertex's refinement along its edge (trilinear reads).
pub const REFINE_ITERATIONS: usize = 5;

/// Secant steps of a vertex's refinement on the body's exact distance, after the regula
/// falsi steps.
pub const EXACT_ITERATIONS: usize = 3;

/// A vertex whose secant steps leave it more than this many cells off the exact field's zero
/// is refined by regula falsi between its edge's ends (`bracketed`) ...
pub const BRACKET_START: f64 = 0.01;

/// ... until within this many cells of it ...
pub const BRACKET_STOP: f64 = 0.001;

/// ... or this many steps.
pub const BRACKET_ITERATIONS: usize = 30;

/// Creased edges are split until their midpoints are within this many cells of the boundary
/// (`crease.rs`).
pub const CREASE_TARGET: f64 = 0.025;

/// Flat parts are collapsed (`decimate.rs`) while the midpoint of every new edge is within this
/// many cells of the boundary.
pub const DECIMATE_TARGET: f64 = 0.05;

/// Collapses make no edge longer than this many cells.
pub const DECIMATE_LONGEST: f64 = 8.0;

/// The exact distance's triangle lists are kept per cube of side `cell /` this.
pub const EXACT_LISTS_PER_CELL: f64 = 2.0;

/// A vertex is kept at least this fraction of its edge from either end: where the zero set
/// passes through a grid point, the triangles around it stay far above round-off (and the
/// float32 copy Blender keeps) instead of shrinking into a fan of slivers that rounding can
/// fold through each other.
pub const EDGE_MARGIN: f64 = 0.02;

/// Vertices refined per part dealt to a thread (parts in turn, so uneven ones even out).
const REFINE_CHUNK: usize = 2048;

/// A cell below `extent / MAX_CELLS_PER_EXTENT` (the body's extent) is refused.
pub const MAX_CELLS_PER_EXTENT: f64 = 1000.0;

/// Most threads [`ClosedOptions::threads`] starts.
pub const MAX_THREADS: usize = 64;

/// Slabs of layers per thread in the body grid's parallel step (dealt in turn, so that the
/// threads' shares even out where the work is uneven along z).
const SLABS_PER_THREAD: usize = 4;

/// Most dense poses [`sweep_closed`] takes.
pub const MAX_POSES: usize = 1 << 20;

/// Where the stages of one contouring end, as fractions of its progress: the body's distance
/// grids, the region's narrow band, the signs settled; then the contouring (its shares of the
/// time on the L-prism at the defaults, one thread: 1.4, 2.0, 0.5 and 15 of 19 s).
const STAGE_ENDS: [f64; 3] = [0.07, 0.18, 0.21];

/// Within the contouring: where the walk over the grid, the vertices' refinement and the
/// creases end (0.2, 8.3 and 6.5 s of 15 on the L-prism at the defaults, one thread).
const CONTOUR_STAGE_ENDS: [f64; 3] = [0.013, 0.57, 1.0];

/// The same with the flat parts' collapses after the creases (`ClosedOptions::decimate`: 18 s
/// more there).
const DECIMATED_STAGE_ENDS: [f64; 3] = [0.006, 0.25, 0.45];

/// How to ask [`sweep_closed`] for less.
const CELL_HINT: &str = "use a larger tolerance (or cell)";

/// Bytes per world-grid point: its value (4) and the pose that gave it (4).
const WORLD_BYTES_PER_POINT: usize = 8;

/// The body grid's origin is shifted by these fractions of its spacing (irrational-looking,
/// unequal per axis), so that its columns do not run along the edges or diagonals of bodies
/// made of round numbers.
const GRID_JITTER: [f64; 3] = [0.313_725_49, 0.271_826_3, 0.141_4];

/// Options of [`sweep_closed`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ClosedOptions {
    /// The world grid's cell (body units, `> 0`), for scripts that fix it; `None`: derived
    /// from `tolerance`. Not both.
    pub cell: Option<f64>,
    /// The largest distance, reported as `error_bound`, of a vertex or an edge's midpoint from
    /// the swept boundary (body units, `> 0`); `None` (and no `cell`): [`DEFAULT_CLOSED_TOLERANCE_REL`] of the
    /// body's extent. The cell is [`CELL_PER_TOLERANCE`] times it, then finer while the bound
    /// exceeds it (`ClosedMesh::attempts`; see [`sweep_closed`]).
    pub tolerance: Option<f64>,
    /// Threads for the body's distance grids and the region's field (steps 1 and 2); `0`:
    /// [`std::thread::available_parallelism`]; at most [`MAX_THREADS`]. The mesh is the same,
    /// bit for bit, whatever the count.
    pub threads: usize,
    /// Fewer triangles: vertices removed where the boundary is flat and along its creases, by
    /// half-edge collapses that keep every new edge's midpoint within [`DECIMATE_TARGET`] cells
    /// of the boundary (`decimate.rs`: the new faces then within about twice that, plus the
    /// vertices' bound).
    /// The vertices left are some of those without it, bit for bit, so `error_bound` holds for
    /// them; it takes longer (1.6 to 2.1 times the CPU at the defaults). On by default since
    /// stop 44.
    pub decimate: bool,
}

impl Default for ClosedOptions {
    /// The default tolerance, every core, fewer triangles.
    fn default() -> Self {
        Self {
            cell: None,
            tolerance: None,
            threads: 0,
            decimate: true,
        }
    }
}

/// The closed boundary and what it took.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct ClosedMesh {
    /// Vertices, world frame.
    pub vertices: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from outside; every edge in exactly two of them.
    pub triangles: Vec<[u32; 3]>,
    /// The world grid's cell.
    pub cell: f64,
    /// A bound on the distance of every vertex, and of every edge's midpoint, from the exact
    /// swept boundary: the largest `|g|` left at a vertex or at the midpoint of an edge of the
    /// contoured mesh (since stop 44), `g` read with the body's exact distance at the motion
    /// refined [`REFINE_POSES`] times, plus the motion's gap ([`motion_gap`]). The collapses
    /// of `decimate` hold their new edges' midpoints within [`DECIMATE_TARGET`] cells on the
    /// poses read: covered when the largest `|g|` is at least that, as on every case measured
    /// (not by proof). Faces elsewhere are not bounded by it: they are measured
    /// (`closed_tests.rs`: within the bound on the contoured mesh, within the tolerance at the
    /// defaults).
    pub error_bound: f64,
    /// The part of `error_bound` that covers the vertices alone (as `error_bound` did up to
    /// stop 43): the largest `|g|` left at a vertex, plus the motion's gap.
    pub vertex_bound: f64,
    /// The tolerance asked for (0 when a cell was given): `error_bound` is within it, unless
    /// `finer_refused` says why not.
    pub tolerance: f64,
    /// Grids contoured: 1, or 2 and 3 when the first and the second cell's bound exceeded the
    /// tolerance.
    pub attempts: usize,
    /// Why the grid was not contoured again at a finer cell though `error_bound` exceeds the
    /// tolerance: the finer grids over the memory budget ([`Error::Memory`]) or past a limit
    /// ([`Error::Limit`]). The mesh is then the last attempt's, closed and within its bound,
    /// which is over the tolerance. `None` otherwise.
    pub finer_refused: Option<Error>,
    /// Dense poses sampled.
    pub poses: usize,
    /// Grid cubes cut finer because a feature of the boundary narrower than a cell was found
    /// in them: outside space among inside corners, or a quarter cell across the grid's linear
    /// field (`adaptive.rs`).
    pub refined_cubes: usize,
}

impl ClosedMesh {
    /// The volume it encloses ([`super::body::enclosed_volume`]).
    pub fn volume(&self) -> f64 {
        super::body::enclosed_volume(&self.vertices, &self.triangles)
    }
}

/// What [`sweep_closed`] will sample, known before it runs ([`closed_work`]): enough to
/// refuse a call that would run for minutes.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct ClosedWork {
    /// The cell of the first attempt.
    pub cell: f64,
    /// The tolerance (0 when a cell was given).
    pub tolerance: f64,
    /// Dense poses.
    pub poses: usize,
    /// Points of the world grid (the instances' boxes; the field is evaluated in its narrow
    /// band, every point is contoured).
    pub grid_points: usize,
    /// Points of the body's fine distance grid.
    pub body_points: usize,
    /// The bytes of the two grids, which the memory budget is checked against before either
    /// is sampled (saturated at `usize::MAX`).
    pub bytes: usize,
}

/// The points of the world grid `grid` and of the body's fine distance grid for `cell`, and
/// the bytes of the two (what the memory budget is checked against before either is sampled).
fn grid_sizes(body: &Body, grid: &Grid, cell: f64) -> (usize, usize, Footprint) {
    let count = |n: [usize; 3]| n[0].saturating_mul(n[1]).saturating_mul(n[2]);
    let grid_points = count(grid.n);
    let body_points = count(BodyField::dims(body, cell / BODY_SUBCELLS, BAND_CELLS * cell).1);
    let bytes = Footprint::bytes(WORLD_BYTES_PER_POINT).times(grid_points)
        + Footprint::of::<f32>(body_points);
    (grid_points, body_points, bytes)
}

/// The body's signed distance sampled on a grid (body frame), clamped to `+-band`.
pub(super) struct BodyField {
    origin: DVec3,
    h: f64,
    n: [usize; 3],
    values: Vec<f32>,
    /// Values are clamped to `+-band`.
    pub(super) band: f64,
}

impl BodyField {
    /// Trilinear read at `p` (body frame); `band` outside the grid.
    #[inline]
    fn at(&self, p: DVec3) -> f64 {
        let u = (p - self.origin) / self.h;
        let [nx, ny, nz] = self.n;
        if !(u.x >= 0.0 && u.y >= 0.0 && u.z >= 0.0) {
            return self.band;
        }
        let (i, j, k) = (u.x as usize, u.y as usize, u.z as usize);
        if i + 1 >= nx || j + 1 >= ny || k + 1 >= nz {
            return self.band;
        }
        let (fx, fy, fz) = (u.x - i as f64, u.y - j as f64, u.z - k as f64);
        let idx = |a: usize, b: usize, c: usize| (c * ny + b) * nx + a;
        let v = |a, b, c| self.values[idx(a, b, c)] as f64;
        let c00 = v(i, j, k) * (1.0 - fx) + v(i + 1, j, k) * fx;
        let c10 = v(i, j + 1, k) * (1.0 - fx) + v(i + 1, j + 1, k) * fx;
        let c01 = v(i, j, k + 1) * (1.0 - fx) + v(i + 1, j, k + 1) * fx;
        let c11 = v(i, j + 1, k + 1) * (1.0 - fx) + v(i + 1, j + 1, k + 1) * fx;
        let c0 = c00 * (1.0 - fy) + c10 * fy;
        let c1 = c01 * (1.0 - fy) + c11 * fy;
        c0 * (1.0 - fz) + c1 * fz
    }

    /// The value at the grid point nearest `p` and that point's distance from `p`: the
    /// distance at `p` is within that distance of the value (`d` is 1-Lipschitz) on the
    /// value's unclamped side. Outside the grid, `band` at distance 0 (the distance there is
    /// above the band).
    #[inline]
    fn nearest(&self, p: DVec3) -> (f64, f64) {
        let (v, node) = self.nearest_node(p);
        (v, node.distance(p))
    }

    /// The value at the grid point nearest `p`, and that point; outside the grid `band` and
    /// `p` itself (the distance there is above the band).
    #[inline]
    pub(super) fn nearest_node(&self, p: DVec3) -> (f64, DVec3) {
        let u = ((p - self.origin) / self.h).round();
        let [nx, ny, nz] = self.n;
        if !(u.x >= 0.0 && u.y >= 0.0 && u.z >= 0.0) {
            return (self.band, p);
        }
        let (i, j, k) = (u.x as usize, u.y as usize, u.z as usize);
        if i >= nx || j >= ny || k >= nz {
            return (self.band, p);
        }
        (
            self.values[(k * ny + j) * nx + i] as f64,
            self.origin + u * self.h,
        )
    }

    /// The grid's origin and points per axis for spacing `h` and band `band`: the body's box
    /// grown by the band and two spacings, its origin off any round position, so grid columns
    /// do not run along the body's edges (ray parity counts each face crossed once).
    fn dims(body: &Body, h: f64, band: f64) -> (DVec3, [usize; 3]) {
        let verts = body.vertices();
        let (lo, hi) = verts
            .iter()
            .fold((verts[0], verts[0]), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let jitter = DVec3::from_array(GRID_JITTER) * h;
        let origin = lo - DVec3::splat(band + 2.0 * h) - jitter;
        let size = hi + DVec3::splat(band + 2.0 * h) - origin;
        let n = [
            (size.x / h).ceil() as usize + 1,
            (size.y / h).ceil() as usize + 1,
            (size.z / h).ceil() as usize + 1,
        ];
        (origin, n)
    }

    /// Samples `body`'s signed distance (see the module documentation) on the grid of
    /// [`BodyField::dims`], the unsigned distances spread over `threads` threads by slabs of
    /// the grid along z (each point's value is the same whatever thread computes it: the
    /// least over the triangles).
    fn new(body: &Body, h: f64, band: f64, threads: usize, span: Span<'_>) -> Result<Self> {
        let verts = body.vertices();
        let (lo, hi) = verts
            .iter()
            .fold((verts[0], verts[0]), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let (origin, n) = Self::dims(body, h, band);
        let count = n[0].saturating_mul(n[1]).saturating_mul(n[2]);
        Footprint::of::<f32>(count).check("the body's distance grid", CLOSED_HINT)?;
        let mut values: Vec<f32> = try_vec(count, "the body's distance grid")?;
        values.resize(count, band as f32);
        let [nx, ny, nz] = n;
        let grid = Grid { origin, cell: h, n };
        let point = |i, j, k| grid.point(i, j, k);
        let range = |lo, hi, axis| grid.span(lo, hi, axis);
        let roundoff = ROUNDOFF_REL * (lo.abs().max(hi.abs()).max_element() + band + h);
        // Slabs of whole layers, a few per thread.
        let per = nz.div_ceil(thread_count(threads) * SLABS_PER_THREAD);
        let slabs: Vec<(usize, &mut [f32])> = values
            .chunks_mut(per * nx * ny)
            .enumerate()
            .map(|(s, slab)| (s * per, slab))
            .collect();
        in_parts(
            slabs,
            threads,
            "the body's distance grid",
            span,
            |(k0, slab)| {
                unsigned_distances(body, grid, band, roundoff, k0, slab);
            },
        )?;
        // Signs: crossings of each column (x_i, y_j) along z.
        let mut crossings: Vec<(usize, f64)> = Vec::new();
        for t in body.triangles() {
            let [a, b, c] = t.map(|i| verts[i as usize]);
            let tlo = a.min(b).min(c);
            let thi = a.max(b).max(c);
            let (i0, i1) = range(tlo.x, thi.x, 0);
            let (j0, j1) = range(tlo.y, thi.y, 1);
            let det = (b.x - a.x) * (c.y - a.y) - (c.x - a.x) * (b.y - a.y);
            if det == 0.0 {
                continue;
            }
            for j in j0..=j1 {
                for i in i0..=i1 {
                    let p = point(i, j, 0);
                    let (px, py) = (p.x - a.x, p.y - a.y);
                    let s = (px * (c.y - a.y) - (c.x - a.x) * py) / det;
                    let r = ((b.x - a.x) * py - px * (b.y - a.y)) / det;
                    if s >= 0.0 && r >= 0.0 && s + r < 1.0 && s < 1.0 && r < 1.0 {
                        let z = a.z + s * (b.z - a.z) + r * (c.z - a.z);
                        crossings.push((j * nx + i, z));
                    }
                }
            }
        }
        crossings.sort_unstable_by(|p, q| p.0.cmp(&q.0).then(p.1.total_cmp(&q.1)));
        let mut start = 0;
        while start < crossings.len() {
            let column = crossings[start].0;
            let mut end = start;
            while end < crossings.len() && crossings[end].0 == column {
                end += 1;
            }
            let zs = &crossings[start..end];
            let (i, j) = (column % nx, column / nx);
            let mut below = 0;
            for k in 0..nz {
                let z = origin.z + k as f64 * h;
                while below < zs.len() && zs[below].1 <= z {
                    below += 1;
                }
                if below % 2 == 1 {
                    let slot = &mut values[(k * ny + j) * nx + i];
                    *slot = -*slot;
                }
            }
            start = end;
        }
        Ok(Self {
            origin,
            h,
            n,
            values,
            band,
        })
    }
}

/// The body's unsigned distances within `band` at the grid points of the layers `k0..` held
/// by `slab` (whole layers of `grid`, initialised to `band`).
///
/// A point keeps the least distance, rounded once to f32 (rounding is monotone), so the order
/// of the triangles does not matter, and a triangle is skipped at a point where a lower bound
/// of its distance (to its plane, to its bounding sphere) is already above the point's least
/// distance by more than `roundoff`: it could not lower it. The values are those of testing
/// every triangle.
fn unsigned_distances(
    body: &Body,
    grid: Grid,
    band: f64,
    roundoff: f64,
    k0: usize,
    slab: &mut [f32],
) {
    let n = grid.n;
    let [nx, ny, nz] = n;
    let layers = slab.len() / (nx * ny);
    if layers == 0 {
        return;
    }
    let (ka, kb) = (k0, (k0 + layers - 1).min(nz - 1));
    let verts = body.vertices();
    let point = |i, j, k| grid.point(i, j, k);
    let range = |lo, hi, axis| grid.span(lo, hi, axis);
    for t in body.triangles() {
        let [a, b, c] = t.map(|i| verts[i as usize]);
        let tlo = a.min(b).min(c) - DVec3::splat(band);
        let thi = a.max(b).max(c) + DVec3::splat(band);
        let (k0, k1) = range(tlo.z, thi.z, 2);
        let (k0, k1) = (k0.max(ka), k1.min(kb));
        if k0 > k1 {
            continue;
        }
        let (i0, i1) = range(tlo.x, thi.x, 0);
        let (j0, j1) = range(tlo.y, thi.y, 1);
        let normal = (b - a).cross(c - a).normalize_or_zero();
        let centre = (a + b + c) / 3.0;
        let radius = centre
            .distance(a)
            .max(centre.distance(b))
            .max(centre.distance(c));
        // Along a row, the points within `band` of the plane and of the sphere (both
        // bounds a point's test below would also reject beyond) are an interval.
        let far = band + roundoff;
        for k in k0..=k1 {
            for j in j0..=j1 {
                let p0 = point(0, j, k);
                let (dy, dz) = (p0.y - centre.y, p0.z - centre.z);
                let rest = (radius + far).powi(2) - dy * dy - dz * dz;
                if rest < 0.0 {
                    continue;
                }
                let half = rest.sqrt();
                let (mut xlo, mut xhi) = (centre.x - half, centre.x + half);
                if normal.x != 0.0 {
                    let off = normal.dot(p0 - a) - normal.x * p0.x;
                    let (u, w) = ((-far - off) / normal.x, (far - off) / normal.x);
                    xlo = xlo.max(u.min(w));
                    xhi = xhi.min(u.max(w));
                }
                if xlo > xhi {
                    continue;
                }
                let (a0, a1) = range(xlo, xhi, 0);
                for i in a0.max(i0)..=a1.min(i1) {
                    let p = point(i, j, k);
                    let slot = &mut slab[((k - ka) * ny + j) * nx + i];
                    let least = *slot as f64 + roundoff;
                    let reach = least + radius;
                    if normal.dot(p - a).abs() > least || p.distance_squared(centre) > reach * reach
                    {
                        continue;
                    }
                    let d = point_triangle_distance(p, a, b, c);
                    if d < *slot as f64 {
                        *slot = d as f32;
                    }
                }
            }
        }
    }
}

/// The threads to use for `threads`: 0, the machine's ([`std::thread::available_parallelism`]);
/// otherwise that many, at most [`MAX_THREADS`] (more than the machine has gains nothing, but
/// gives the tests uneven shares to check on any machine).
fn thread_count(threads: usize) -> usize {
    if threads == 0 {
        std::thread::available_parallelism().map_or(1, |p| p.get())
    } else {
        threads.min(MAX_THREADS)
    }
}

/// Runs `work(part)` on every part of `parts`, spread over [`thread_count`]`(threads)`
/// threads, the parts dealt in turn (so that uneven parts even out). Each part is its own
/// slice of the output, so the result does not depend on the count. `span` follows the parts
/// done; once the computation is asked to stop, the parts not started are left.
///
/// # Errors
/// [`Error::Worker`] (`what`) if a thread failed (a bug: the work does not panic on data);
/// [`Error::Cancelled`] if the computation was asked to stop.
fn in_parts<P: Send>(
    parts: Vec<P>,
    threads: usize,
    what: &'static str,
    span: Span<'_>,
    work: impl Fn(P) + Sync,
) -> Result<()> {
    let total = parts.len().max(1) as f64;
    let done = AtomicUsize::new(0);
    let work = |part: P| {
        if !span.is_cancelled() {
            work(part);
            span.advance((done.fetch_add(1, Ordering::Relaxed) + 1) as f64 / total);
        }
    };
    let threads = thread_count(threads).min(parts.len());
    if threads <= 1 {
        parts.into_iter().for_each(work);
        return span.check();
    }
    let mut dealt: Vec<Vec<P>> = (0..threads).map(|_| Vec::new()).collect();
    for (s, part) in parts.into_iter().enumerate() {
        dealt[s % threads].push(part);
    }
    let work = &work;
    let joined = std::thread::scope(|scope| {
        let handles: Vec<_> = dealt
            .into_iter()
            .map(|mine| scope.spawn(move || mine.into_iter().for_each(work)))
            .collect();
        handles.into_iter().map(|h| h.join()).collect::<Vec<_>>()
    });
    joined
        .into_iter()
        .try_for_each(|r| r.map_err(|_| Error::Worker { what }))?;
    span.check()
}

/// The body's distance grid of spacing `h` and band `band`: its origin, points per axis and
/// values (for the tests).
#[cfg(test)]
pub(super) fn body_distance_grid(
    body: &Body,
    h: f64,
    band: f64,
) -> Result<(DVec3, [usize; 3], Vec<f32>)> {
    let field = BodyField::new(body, h, band, 0, Progress::new().span(0.0, 1.0))?;
    Ok((field.origin, field.n, field.values))
}

/// The body's exact distance as the closed sweep builds it for a cell (`band`, spacings as
/// [`sweep_closed`] takes them), its lists made on `threads` threads (for the tests).
#[cfg(test)]
fn exact_for_tests(body: &Body, cell: f64, threads: usize) -> Result<ExactField<'_>> {
    let field = BodyField::new(
        body,
        cell / BODY_SUBCELLS,
        BAND_CELLS * cell,
        0,
        Progress::new().span(0.0, 1.0),
    )?;
    exact_field(body, &field, cell, threads)
}

/// The body's exact signed distance as the closed sweep builds it for a cell: a reader of
/// `(distance, gradient)` (for the tests).
#[cfg(test)]
pub(super) fn exact_distance(
    body: &Body,
    cell: f64,
) -> Result<impl Fn(DVec3) -> (f64, Option<DVec3>) + '_> {
    let exact = exact_for_tests(body, cell, 0)?;
    Ok(move |p| exact.at(p))
}

/// The exact distance's lists for `body` at `cell`, made on `threads` threads: each list
/// cell's start, and the triangles (for the tests).
#[cfg(test)]
pub(super) fn exact_lists(body: &Body, cell: f64, threads: usize) -> Result<(Vec<u32>, Vec<u32>)> {
    let exact = exact_for_tests(body, cell, threads)?;
    let (start, items) = exact.lists();
    Ok((start.to_vec(), items.to_vec()))
}

/// The refinement's minima at `points` over the motion sampled for `cell` (for the tests): per
/// point, with `least` every refined pose's least exact distance there, `upper` that plus the
/// point's entry of `lifts` and `j` the sample nearest the pose of `least` moved by the
/// point's entry of `shifts` (within the motion), `[least, exact_all(upper), exact_near at j,
/// the least exact distance over the poses exact_near reads at j, exact_all(that, known j)]`.
#[cfg(test)]
pub(super) fn motion_minima(
    body: &Body,
    poses: &[Pose],
    cell: f64,
    points: &[DVec3],
    lifts: &[f64],
    shifts: &[i64],
) -> Result<Vec<[f64; 5]>> {
    let motion = DenseMotion::new(body, poses, cell)?;
    let progress = Progress::new();
    let (h, band) = (cell / BODY_SUBCELLS, BAND_CELLS * cell);
    let field = BodyField::new(body, h, band, 0, progress.span(0.0, 1.0))?;
    let coarse_band = COARSE_BAND_CELLS * cell;
    let coarse = BodyField::new(body, cell, coarse_band, 0, progress.span(0.0, 1.0))?;
    let exact = exact_field(body, &field, cell, 0)?;
    let refine = Refiner::new(&field, &coarse, exact, &motion, body, cell)?;
    let read = |x: DVec3, i: usize| refine.exact.at(refine.fine[i].transform_point3(x)).0;
    Ok(points
        .iter()
        .zip(lifts.iter().zip(shifts))
        .map(|(&x, (&lift, &shift))| {
            let (least, at) = (0..refine.fine.len())
                .map(|i| (read(x, i), i))
                .fold((f64::INFINITY, 0), |a, b| if b.0 < a.0 { b } else { a });
            let nearest = ((at + REFINE_POSES / 2) / REFINE_POSES) as i64;
            let j = (nearest + shift).clamp(0, motion.steps.len() as i64) as u32;
            let js = [j, u32::MAX];
            let near = refine.exact_near(x, js);
            let near_least = refine
                .span(j)
                .map(|i| read(x, i))
                .fold(f64::INFINITY, f64::min);
            [
                least,
                refine.exact_all(x, least + lift, NONE),
                near,
                near_least,
                refine.exact_all(x, near, js),
            ]
        })
        .collect())
}

/// The exact distance's lists over the body grid's box, made on [`thread_count`]`(threads)`
/// threads (the same lists whatever the count).
fn exact_field<'a>(
    body: &'a Body,
    field: &BodyField,
    cell: f64,
    threads: usize,
) -> Result<ExactField<'a>> {
    let last = DVec3::new(field.n[0] as f64, field.n[1] as f64, field.n[2] as f64) - 1.0;
    ExactField::new(
        body,
        field,
        field.origin,
        field.origin + last * field.h,
        cell / EXACT_LISTS_PER_CELL,
        thread_count(threads),
    )
}

/// How to ask the closed sweep for less memory.
pub const CLOSED_HINT: &str = "use a larger tolerance (or cell), fewer poses or a smaller motion";

/// Distance from `p` to the triangle `(a, b, c)`: to its point nearest `p`
/// (Ericson, *Real-Time Collision Detection*, 5.1.5: the closest point by Voronoi regions).
pub fn point_triangle_distance(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    (p - closest_on_triangle(p, a, b, c).0).length()
}

/// The dense motion: every pose (body -> world) and, for each interval between two, the
/// screw that joins them (relative to the first).
struct DenseMotion {
    poses: Vec<Pose>,
    steps: Vec<Screw>,
}

impl DenseMotion {
    /// Each span in the fewest steps that move no body vertex more than `step` (the arc of
    /// the farthest vertex from the axis and the slide).
    fn new(body: &Body, poses: &[Pose], step: f64) -> Result<Self> {
        let mut out = Self {
            poses: vec![poses[0]],
            steps: Vec::new(),
        };
        for pair in poses.windows(2) {
            let (a, b) = (&pair[0], &pair[1]);
            let screw = Screw::between(&Pose::IDENTITY, &a.inverse().mul_pose(b));
            let (axis, point) = (screw.axis(), screw.point());
            let rho = body
                .vertices()
                .iter()
                .map(|&q| axis_distance(q, point, axis))
                .fold(0.0, f64::max);
            let travel = (screw.angle() * rho).hypot(screw.slide());
            let k = (travel / step).ceil().max(1.0);
            if out.poses.len() as f64 + k > MAX_POSES as f64 {
                return Err(Error::Limit {
                    what: "cell",
                    counted: "poses",
                    count: (out.poses.len() as f64 + k).min(usize::MAX as f64) as usize,
                    limit: MAX_POSES,
                    hint: CELL_HINT,
                });
            }
            let k = k as u32;
            let one = Screw::between(&Pose::IDENTITY, &screw.motion(1.0 / k as f64));
            for j in 1..=k {
                out.poses
                    .push(a.mul_pose(&screw.motion(j as f64 / k as f64)));
                out.steps.push(one);
            }
        }
        Ok(out)
    }
}

impl DenseMotion {
    /// The body's bounding sphere (about its box's centre) through every pose: the centres
    /// (world) and the radius.
    fn spheres(&self, body: &Body) -> (Vec<DVec3>, f64) {
        let verts = body.vertices();
        let (lo, hi) = verts
            .iter()
            .fold((verts[0], verts[0]), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let centre = 0.5 * (lo + hi);
        let radius = verts
            .iter()
            .map(|&v| v.distance(centre))
            .fold(0.0, f64::max);
        let centres = self
            .poses
            .iter()
            .map(|p| p.transform_point3(centre))
            .collect();
        (centres, radius)
    }
}

/// The boundary of the region swept by the closed `body` along the polyscrew through `poses`
/// as a closed, consistently oriented, self-intersection-free triangle mesh (see the module
/// documentation), every vertex within `error_bound` of the swept boundary.
///
/// With a tolerance (`options.tolerance`, by default [`DEFAULT_CLOSED_TOLERANCE_REL`] of the
/// body's extent) the cell is [`CELL_PER_TOLERANCE`] times it; if the bound reported there
/// exceeds the tolerance, the grid is contoured again at the cell [`RETRY_SPARE`] makes of that
/// bound (`attempts` 2), then at [`guaranteed_cell`] (`attempts` 3), where the vertices' part
/// of the bound cannot exceed it and the midpoints' has not on any case measured; a bound still
/// over the tolerance is returned as it is.
/// A finer grid over the memory budget or past a limit is not an error: the last attempt's
/// mesh is returned, its bound over the tolerance, with the reason (`finer_refused`).
/// With `options.cell`, that cell, once.
///
/// # Errors
/// - [`Error::TooFew`] for fewer than 2 poses; [`Error::BadPose`] for a pose out of range;
/// - [`Error::Value`] (`"body"`) for a body that is not closed (no inside);
/// - [`Error::Value`] (`"cell"`, `"tolerance"`) for a cell or tolerance that is not finite
///   and positive, a cell below `extent /` [`MAX_CELLS_PER_EXTENT`] (a tolerance whose
///   [`guaranteed_cell`] is), or a motion needing more than [`MAX_POSES`] poses;
/// - [`Error::Conflict`] (`"cell"`) for both a cell and a tolerance;
/// - [`Error::Memory`] for grids or a mesh over the memory budget.
pub fn sweep_closed(body: &Body, poses: &[Pose], options: &ClosedOptions) -> Result<ClosedMesh> {
    sweep_closed_watched(body, poses, options, &Progress::new())
}

/// [`sweep_closed`], reporting its fraction done to `progress` (from 0 again for a second
/// grid, `attempts` 2) and stopping with [`Error::Cancelled`] once it is asked to, within a
/// part of its work (a few thousand vertices, a layer of grid blocks, a round of crease
/// splits): for a caller on another thread to show the one and offer the other.
///
/// # Errors
/// Those of [`sweep_closed`], and [`Error::Cancelled`].
pub fn sweep_closed_watched(
    body: &Body,
    poses: &[Pose],
    options: &ClosedOptions,
    progress: &Progress,
) -> Result<ClosedMesh> {
    sweep_closed_with(body, poses, options, Evaluation::NarrowBand, progress)
}

/// What [`sweep_closed`] will sample (its first attempt), without sampling it: the checks of
/// [`sweep_closed`] on the arguments, the cell, the dense poses and the grids' sizes.
///
/// # Errors
/// Those of [`sweep_closed`] but the memory budget's.
pub fn closed_work(body: &Body, poses: &[Pose], options: &ClosedOptions) -> Result<ClosedWork> {
    let (cell, tolerance) = first_cell(body, poses, options)?;
    let plan = Plan::new(body, poses, cell)?;
    let (grid_points, body_points, bytes) = grid_sizes(body, &plan.grid, cell);
    Ok(ClosedWork {
        cell,
        tolerance,
        poses: plan.motion.poses.len(),
        grid_points,
        body_points,
        bytes: bytes.get(),
    })
}

/// Where the region's field is evaluated on the world grid.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(super) enum Evaluation {
    /// Only in the blocks that may hold the boundary (see [`narrow_band`]).
    NarrowBand,
    /// At every grid point of every instance's box (the reference the band must reproduce).
    #[cfg_attr(not(test), allow(dead_code))]
    Dense,
}

/// The checks of [`sweep_closed`] and its first cell, with the tolerance (0 for a given cell).
fn first_cell(body: &Body, poses: &[Pose], options: &ClosedOptions) -> Result<(f64, f64)> {
    if poses.len() < 2 {
        return Err(Error::TooFew {
            got: poses.len(),
            need: 2,
        });
    }
    poses
        .iter()
        .enumerate()
        .try_for_each(|(index, p)| p.check_range(index))?;
    if !body.is_closed() {
        return Err(Error::Degenerate {
            what: "body",
            at: None,
            reason: "the mesh is not closed (every edge in two faces): it has no inside to sweep",
        });
    }
    let extent = body.extent();
    let smallest = extent / MAX_CELLS_PER_EXTENT;
    let at_least = |what: &'static str, value: f64, min: f64| Error::Value {
        what,
        at: None,
        value,
        expected: Expected::AtLeast {
            min,
            limit: MAX_CELLS_PER_EXTENT as usize,
            counted: "cells across the body's extent",
        },
    };
    match (options.cell, options.tolerance) {
        (Some(_), Some(_)) => Err(Error::Conflict {
            what: "cell",
            reason: "give a cell or a tolerance, not both".to_string(),
        }),
        (Some(cell), None) => {
            if !(cell.is_finite() && cell > 0.0 && cell * MAX_CELLS_PER_EXTENT >= extent) {
                return Err(at_least("cell", cell, smallest));
            }
            Ok((cell, 0.0))
        }
        (None, tolerance) => {
            let tolerance = tolerance.unwrap_or(DEFAULT_CLOSED_TOLERANCE_REL * extent);
            let least = smallest / guaranteed_cell(1.0);
            if !(tolerance.is_finite() && tolerance > 0.0 && tolerance >= least) {
                return Err(at_least("tolerance", tolerance, least));
            }
            Ok((CELL_PER_TOLERANCE * tolerance, tolerance))
        }
    }
}

/// [`sweep_closed`] with the world grid's evaluation chosen.
pub(super) fn sweep_closed_with(
    body: &Body,
    poses: &[Pose],
    options: &ClosedOptions,
    evaluation: Evaluation,
    progress: &Progress,
) -> Result<ClosedMesh> {
    let (cell, tolerance) = first_cell(body, poses, options)?;
    let whole = progress.span(0.0, 1.0);
    let mut out = contoured(body, poses, cell, options, evaluation, whole)?;
    let mut attempts = 1;
    while tolerance > 0.0 && out.error_bound > tolerance && attempts < 3 {
        // The bound grows about as the cell does: the second cell is the one that would meet
        // the tolerance with a tenth to spare; the third, the one whose vertices cannot miss it.
        let least = guaranteed_cell(tolerance);
        let retry = if attempts == 1 {
            (RETRY_SPARE * out.cell * tolerance / out.error_bound).max(least)
        } else {
            least
        };
        progress.restart();
        match contoured(body, poses, retry, options, evaluation, whole) {
            Ok(finer) => out = finer,
            // A finer grid the budget or a limit refuses (the grids' budget and the grid-point
            // and pose limits are checked before its sampling starts): the mesh so far is kept,
            // its bound over the tolerance and the reason told, rather than the work done lost
            // to an error.
            Err(refused @ (Error::Memory { .. } | Error::Limit { .. })) => {
                out.finer_refused = Some(refused);
                break;
            }
            Err(e) => return Err(e),
        }
        attempts += 1;
    }
    out.attempts = attempts;
    out.tolerance = tolerance;
    Ok(out)
}

/// The dense motion and the world grid of one cell.
struct Plan {
    motion: DenseMotion,
    /// Each instance's box (the body's box grown by the band), world frame.
    boxes: Vec<(DVec3, DVec3)>,
    grid: Grid,
}

impl Plan {
    /// The motion sampled for `cell`, and the world grid: the union of the instances' boxes
    /// (the body's box grown by the band), plus two cells, so the outer layer is outside
    /// every instance.
    fn new(body: &Body, poses: &[Pose], cell: f64) -> Result<Self> {
        let band = BAND_CELLS * cell;
        let motion = DenseMotion::new(body, poses, cell)?;
        let verts = body.vertices();
        let (blo, bhi) = verts
            .iter()
            .fold((verts[0], verts[0]), |(lo, hi), &v| (lo.min(v), hi.max(v)));
        let (blo, bhi) = (blo - DVec3::splat(band), bhi + DVec3::splat(band));
        let boxes: Vec<(DVec3, DVec3)> = motion
            .poses
            .iter()
            .map(|p| {
                (0..8).fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), c| {
                    let q = p.transform_point3(DVec3::new(
                        if c & 1 == 0 { blo.x } else { bhi.x },
                        if c & 2 == 0 { blo.y } else { bhi.y },
                        if c & 4 == 0 { blo.z } else { bhi.z },
                    ));
                    (lo.min(q), hi.max(q))
                })
            })
            .collect();
        let (wlo, whi) = boxes.iter().fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)),
        );
        let origin = wlo - DVec3::splat(2.0 * cell);
        let size = whi + DVec3::splat(2.0 * cell) - origin;
        let dims = [
            (size.x / cell).ceil() + 1.0,
            (size.y / cell).ceil() + 1.0,
            (size.z / cell).ceil() + 1.0,
        ];
        let total = dims[0] * dims[1] * dims[2];
        if total > (usize::MAX / WORLD_BYTES_PER_POINT) as f64 {
            return Err(Error::Limit {
                what: "cell",
                counted: "grid points",
                count: total.min(usize::MAX as f64) as usize,
                limit: usize::MAX / WORLD_BYTES_PER_POINT,
                hint: CELL_HINT,
            });
        }
        let n = dims.map(|d| d as usize);
        Ok(Self {
            motion,
            boxes,
            grid: Grid { origin, cell, n },
        })
    }
}

/// The region's boundary contoured at `cell` (steps 1 to 4 of the module documentation).
fn contoured(
    body: &Body,
    poses: &[Pose],
    cell: f64,
    options: &ClosedOptions,
    evaluation: Evaluation,
    span: Span<'_>,
) -> Result<ClosedMesh> {
    let threads = options.threads;
    let [grids, band_end, signs_end] = STAGE_ENDS;
    let band = BAND_CELLS * cell;
    let Plan {
        motion,
        boxes,
        grid,
    } = Plan::new(body, poses, cell)?;
    // Both grids checked before either is sampled: an oversized request costs no work.
    let (count, _, bytes) = grid_sizes(body, &grid, cell);
    bytes.check("the region's distance grid", CLOSED_HINT)?;
    let field = BodyField::new(
        body,
        cell / BODY_SUBCELLS,
        band,
        threads,
        span.part(0.0, grids),
    )?;
    let to_body: Vec<DAffine3> = motion
        .poses
        .iter()
        .map(|p| p.inverse().to_affine())
        .collect();
    let mut g: Vec<f32> = try_vec(count, "the region's distance grid")?;
    g.resize(count, band as f32);
    let mut arg: Vec<u32> = try_vec(count, "the region's distance grid")?;
    arg.resize(count, u32::MAX);
    // (The coarse grid is a small part of the grids' time.)
    let coarse = BodyField::new(
        body,
        cell,
        COARSE_BAND_CELLS * cell,
        threads,
        span.part(grids, grids),
    )?;
    match evaluation {
        Evaluation::NarrowBand => {
            narrow_band(
                &field,
                &coarse,
                body,
                &motion,
                &to_body,
                grid,
                (&mut g, &mut arg),
                threads,
                span.part(grids, band_end),
            )?;
        }
        Evaluation::Dense => dense(&field, &to_body, &boxes, grid, &mut g, &mut arg),
    }
    let exact = exact_field(body, &field, cell, threads)?;
    let refine = Refiner::new(&field, &coarse, exact, &motion, body, cell)?;
    settle_signs(
        &mut g,
        grid,
        &refine,
        threads,
        span.part(band_end, signs_end),
    )?;
    let mut out = ClosedMesh {
        cell,
        poses: motion.poses.len(),
        ..ClosedMesh::default()
    };
    contour(
        &g,
        &arg,
        grid,
        &refine,
        (threads, options.decimate),
        span.part(signs_end, 1.0),
        &mut out,
    )?;
    Ok(out)
}

/// The world grid: `n` points per axis from `origin`, `cell` apart (point `(i, j, k)` at slot
/// `(k * ny + j) * nx + i`).
#[derive(Debug, Clone, Copy)]
struct Grid {
    origin: DVec3,
    cell: f64,
    n: [usize; 3],
}

impl Grid {
    /// Point `(i, j, k)`.
    #[inline]
    fn point(&self, i: usize, j: usize, k: usize) -> DVec3 {
        self.origin + DVec3::new(i as f64, j as f64, k as f64) * self.cell
    }

    /// The indices along `axis` of the points from the last at or below `lo` to the first at
    /// or above `hi`, clamped to the grid.
    #[inline]
    fn span(&self, lo: f64, hi: f64, axis: usize) -> (usize, usize) {
        let (o, m) = (self.origin[axis], self.n[axis]);
        let a = ((lo - o) / self.cell).floor().max(0.0) as usize;
        let b = (((hi - o) / self.cell).ceil().max(0.0) as usize).min(m - 1);
        (a, b)
    }
}

/// Lowers `g` (and records the pose in `arg`) at the grid points `i0..=i1` of row `(jj, k)`
/// by the body's field read through `inv` (world -> body), as long as a point is not already
/// at the field's floor, at the points `i` that `read(i)` allows. `g` and `arg` hold the grid
/// from its point `base` on.
#[allow(clippy::too_many_arguments)]
#[inline]
fn lower_row(
    field: &BodyField,
    inv: &DAffine3,
    pose: u32,
    grid: Grid,
    [i0, i1, jj, k]: [usize; 4],
    (g, arg, base): (&mut [f32], &mut [u32], usize),
    read: impl Fn(usize) -> bool,
) {
    let Grid { origin, cell, n } = grid;
    let deep = -(field.band as f32);
    let row = (k * n[1] + jj) * n[0] - base;
    let dx = inv.matrix3.x_axis * cell;
    let mut p = inv.transform_point3(origin + DVec3::new(i0 as f64, jj as f64, k as f64) * cell);
    for i in i0..=i1 {
        let slot = row + i;
        if g[slot] > deep && read(i) {
            let v = field.at(p) as f32;
            if v < g[slot] {
                g[slot] = v;
                arg[slot] = pose;
            }
        }
        p += dx;
    }
}

/// The region's field at every grid point of every instance's box (`boxes`, world frame).
fn dense(
    field: &BodyField,
    to_body: &[DAffine3],
    boxes: &[(DVec3, DVec3)],
    grid: Grid,
    g: &mut [f32],
    arg: &mut [u32],
) {
    let Grid { origin, cell, n } = grid;
    let [nx, ny, nz] = n;
    for (j, (inv, (lo, hi))) in to_body.iter().zip(boxes).enumerate() {
        let i0 = ((lo.x - origin.x) / cell).floor().max(0.0) as usize;
        let i1 = (((hi.x - origin.x) / cell).ceil() as usize).min(nx - 1);
        let j0 = ((lo.y - origin.y) / cell).floor().max(0.0) as usize;
        let j1 = (((hi.y - origin.y) / cell).ceil() as usize).min(ny - 1);
        let k0 = ((lo.z - origin.z) / cell).floor().max(0.0) as usize;
        let k1 = (((hi.z - origin.z) / cell).ceil() as usize).min(nz - 1);
        for k in k0..=k1 {
            for jj in j0..=j1 {
                let at = (&mut *g, &mut *arg, 0);
                lower_row(field, inv, j as u32, grid, [i0, i1, jj, k], at, |_| true);
            }
        }
    }
}

/// The region's field `g = min_j f_j` (`f_j` the fine body field read through pose `j`) only
/// where the boundary can be; elsewhere `g` is left at `+band` (outside) or set to `-band`
/// (inside), with the same sign as the field there.
///
/// The grid is cut into blocks of [`BLOCK_POINTS`]^3 points. Every grid cube touching a
/// block's points lies in the ball of radius `rho = sqrt(3) (BLOCK_POINTS + 1) / 2` cells
/// about the block's centre `c`. The coarse field (spacing one cell, band `B_c`) is read at
/// its grid point nearest `c_j = P_j^-1 c`: a value `v_j` at a distance `delta_j` from `c_j`
/// (at most `sqrt(3) / 2` cells). The body's distance `d_j` through pose `j` is 1-Lipschitz,
/// so at any `y` a distance `r` from `c`:
///
/// `d_j(y) >= v_j - delta_j - r` unless `v_j` is the clamp `-B_c`, and
/// `d_j(y) <= v_j + delta_j + r` unless it is the clamp `+B_c`; the fine field `f_j`
/// (spacing `h`, band `b`, trilinear error `e = sqrt(3) h`) has
/// `min(d_j, b) - e <= f_j <= max(d_j, -b) + e`.
///
/// With `lo = min_j (v_j - delta_j)` and `up = min_j (v_j + delta_j)`: if `lo > rho + e`,
/// every `f_j > 0` on the ball; if `up < -(rho + e)`, the pose reaching `up` has `f_j < 0` on
/// the ball (the deciding values are far inside `B_c`, so never clamps). Either way no grid
/// cube touching the block changes sign, so marching tetrahedra sees exactly the cubes it saw
/// on the dense grid (the same values and poses there: below). Otherwise the block's points
/// are evaluated, each `y` (at `r` from `c`) only with the poses that can reach its minimum:
/// `g(y) <= U(y) = min(max(up + r, -b), b) + e` (the pose reaching `up`; `b` is also where
/// `g` starts), and pose `j` is above that if `min(v_j - delta_j - r, b) - e > U(y)`, by more
/// than the float32 rounding of the stored values (the slack in `e`): it would neither lower
/// `g(y)` nor be the first pose reaching it. A pose whose bounding sphere stays `B_c + sqrt(3)`
/// cells off `c` is not read at all (its `f_j` is the clamp `b` there, which never lowers
/// `g`). The poses kept are read in the dense order, so the minimum and the pose giving it are
/// those of the dense grid. The layers of blocks are dealt to `threads` threads.
#[allow(clippy::too_many_arguments)]
fn narrow_band(
    field: &BodyField,
    coarse: &BodyField,
    body: &Body,
    motion: &DenseMotion,
    to_body: &[DAffine3],
    grid: Grid,
    (g, arg): (&mut [f32], &mut [u32]),
    threads: usize,
    span: Span<'_>,
) -> Result<()> {
    let n = grid.n;
    let root3 = 3f64.sqrt();
    let (centres, radius) = motion.spheres(body);
    let band = Band {
        field,
        coarse,
        to_body,
        centres,
        sphere: radius + coarse.band + root3 * coarse.h,
        grid,
    };
    // Layers of blocks (`BLOCK_POINTS` grid layers each) dealt to the threads: a block
    // writes only its own points, each the same whatever thread computes it.
    let layer = BLOCK_POINTS * n[0] * n[1];
    let parts: Vec<_> = g
        .chunks_mut(layer)
        .zip(arg.chunks_mut(layer))
        .enumerate()
        .collect();
    in_parts(
        parts,
        threads,
        "the region's distance grid",
        span,
        |(bk, (g, arg))| {
            band.layer(bk, g, arg);
        },
    )
}

/// What the narrow band's blocks read (see [`narrow_band`]).
struct Band<'a> {
    field: &'a BodyField,
    coarse: &'a BodyField,
    to_body: &'a [DAffine3],
    /// The centre of the body's box at every pose (world frame).
    centres: Vec<DVec3>,
    /// A pose whose instance's centre is farther than this from a block's centre is not read.
    sphere: f64,
    grid: Grid,
}

impl Band<'_> {
    /// The blocks of layer `bk` (grid layers `bk * BLOCK_POINTS..`), `g` and `arg` holding
    /// that layer's points.
    fn layer(&self, bk: usize, g: &mut [f32], arg: &mut [u32]) {
        let Self {
            field,
            coarse,
            to_body,
            sphere,
            grid,
            ..
        } = *self;
        let Grid { origin, cell, n } = grid;
        let [nx, ny, nz] = n;
        let base = bk * BLOCK_POINTS * nx * ny;
        let root3 = 3f64.sqrt();
        let rho = root3 * (BLOCK_POINTS as f64 + 1.0) / 2.0 * cell;
        // The farthest a block's own point is from its centre.
        let r_max = root3 * (BLOCK_POINTS as f64 - 1.0) / 2.0 * cell;
        let fine_err = root3 * field.h + BLOCK_SLACK_CELLS * cell;
        let reach = rho + fine_err;
        let b = field.band;
        let deep = -(b as f32);
        let blocks = n.map(|m| m.div_ceil(BLOCK_POINTS));
        // The least value of `f_j` at a block point `r` from the centre (`low` = `v_j - delta_j`),
        // and the most `g` can be there (`up` = `min_j (v_j + delta_j)`).
        let floor = |low: f64, r: f64| (low - r).min(b) - fine_err;
        let ceiling = |up: f64, r: f64| (up + r).max(-b).min(b) + fine_err;
        let mut near: Vec<(u32, f64)> = Vec::new();
        let mut dist = [0.0f64; BLOCK_POINTS * BLOCK_POINTS * BLOCK_POINTS];
        let (k0, k1) = (bk * BLOCK_POINTS, ((bk + 1) * BLOCK_POINTS).min(nz) - 1);
        for bj in 0..blocks[1] {
            let (j0, j1) = (bj * BLOCK_POINTS, ((bj + 1) * BLOCK_POINTS).min(ny) - 1);
            for bi in 0..blocks[0] {
                let (i0, i1) = (bi * BLOCK_POINTS, ((bi + 1) * BLOCK_POINTS).min(nx) - 1);
                let twice = DVec3::new((i0 + i1) as f64, (j0 + j1) as f64, (k0 + k1) as f64);
                let c = origin + 0.5 * twice * cell;
                near.clear();
                let (mut low, mut up) = (coarse.band, coarse.band);
                for (j, (w, inv)) in self.centres.iter().zip(to_body).enumerate() {
                    if c.distance_squared(*w) > sphere * sphere {
                        continue;
                    }
                    let (v, delta) = coarse.nearest(inv.transform_point3(c));
                    low = low.min(v - delta);
                    up = up.min(v + delta);
                    near.push((j as u32, v - delta));
                }
                if low > reach {
                    continue;
                }
                if up < -reach {
                    for k in k0..=k1 {
                        for jj in j0..=j1 {
                            let row = (k * ny + jj) * nx - base;
                            g[row + i0..=row + i1].fill(deep);
                        }
                    }
                    continue;
                }
                // Each point's distance from the centre, by its offsets in the block.
                let slot = |i: usize, jj: usize, k: usize| {
                    ((k - k0) * BLOCK_POINTS + (jj - j0)) * BLOCK_POINTS + (i - i0)
                };
                for k in k0..=k1 {
                    for jj in j0..=j1 {
                        for i in i0..=i1 {
                            let q = DVec3::new(i as f64, jj as f64, k as f64) - 0.5 * twice;
                            dist[slot(i, jj, k)] = q.length() * cell;
                        }
                    }
                }
                let upper = ceiling(up, r_max);
                for &(j, v) in &near {
                    if floor(v, r_max) > upper {
                        continue;
                    }
                    let inv = &to_body[j as usize];
                    for k in k0..=k1 {
                        for jj in j0..=j1 {
                            let read = |i: usize| {
                                let r = dist[slot(i, jj, k)];
                                floor(v, r) <= ceiling(up, r)
                            };
                            let at = (&mut *g, &mut *arg, base);
                            lower_row(field, inv, j, grid, [i0, i1, jj, k], at, read);
                        }
                    }
                }
            }
        }
    }
}

/// No samples, for [`Refiner::exact_all`]'s `known`.
const NONE: [u32; 2] = [u32::MAX; 2];

/// Samples of the motion per run [`Refiner::exact_all`] can pass over at once.
const SAMPLE_RUN: usize = 16;

/// Evaluates the region's field between the motion's samples: by the body grid's trilinear
/// reads, and by the body's exact distance for a vertex's last steps.
struct Refiner<'a> {
    field: &'a BodyField,
    /// The body's distance a world cell apart (small enough to stay in cache): its reads
    /// rule out most samples of the motion before the fine grid is read there.
    coarse: &'a BodyField,
    /// The coarse read's error bound (as half of [`Refiner::spread`] for the fine one).
    coarse_error: f64,
    exact: ExactField<'a>,
    /// World -> body at [`REFINE_POSES`] poses per sample interval (sample `j` at
    /// `j * REFINE_POSES`).
    fine: Vec<DAffine3>,
    /// Twice the trilinear read's error bound and the float32 rounding of the grid's values:
    /// a pose whose read is above the least read by more cannot give the exact minimum.
    spread: f64,
    /// The centre of the body's bounding sphere through each sample of the motion (world).
    centres: Vec<DVec3>,
    /// That sphere's radius.
    radius: f64,
    /// Per run of [`SAMPLE_RUN`] samples: a ball holding their spheres' centres (its radius
    /// rounded up), whose distance less the two radii bounds the run's distances from below.
    runs: Vec<(DVec3, f64)>,
    /// The most a body point moves between a sample and a refined pose of its intervals.
    travel: f64,
    /// Round-off allowance of the bounds between samples.
    slack: f64,
}

impl<'a> Refiner<'a> {
    fn new(
        field: &'a BodyField,
        coarse: &'a BodyField,
        exact: ExactField<'a>,
        motion: &DenseMotion,
        body: &Body,
        travel: f64,
    ) -> Result<Self> {
        let count = motion.steps.len() * REFINE_POSES + 1;
        Footprint::of::<DAffine3>(count).check("the refined motion", CLOSED_HINT)?;
        let mut fine = try_vec(count, "the refined motion")?;
        for (pose, screw) in motion.poses.iter().zip(&motion.steps) {
            for s in 0..REFINE_POSES {
                let p = pose.mul_pose(&screw.motion(s as f64 / REFINE_POSES as f64));
                fine.push(p.inverse().to_affine());
            }
        }
        fine.push(motion.poses[motion.poses.len() - 1].inverse().to_affine());
        let error = |f: &BodyField| 0.5 * 3f64.sqrt() * f.h + f.band * f32::EPSILON as f64;
        let spread = 2.0 * error(field) + ROUNDOFF_REL * field.band;
        let coarse_error = error(coarse) + ROUNDOFF_REL * coarse.band;
        let (centres, radius) = motion.spheres(body);
        let runs = centres
            .chunks(SAMPLE_RUN)
            .map(|run| {
                let (lo, hi) = run
                    .iter()
                    .fold((run[0], run[0]), |(lo, hi), &c| (lo.min(c), hi.max(c)));
                let centre = 0.5 * (lo + hi);
                let reach = run.iter().map(|c| c.distance(centre)).fold(0.0, f64::max);
                let scale = centre.abs().max_element() + reach + radius;
                (centre, reach + ROUNDOFF_REL * scale)
            })
            .collect();
        Ok(Self {
            field,
            coarse,
            coarse_error,
            exact,
            fine,
            spread,
            centres,
            radius,
            runs,
            travel,
            slack: ROUNDOFF_REL * (field.band + travel),
        })
    }

    /// The refined poses within one sample interval of sample `j`.
    fn span(&self, j: u32) -> std::ops::RangeInclusive<usize> {
        let j = j as usize;
        let lo = j.saturating_sub(1) * REFINE_POSES;
        let hi = ((j + 1) * REFINE_POSES).min(self.fine.len() - 1);
        lo..=hi
    }

    /// `min d(P(s)^-1 x)` over the poses `P(s)` within one sample interval of sample `j`
    /// (trilinear reads).
    fn at(&self, x: DVec3, j: u32) -> f64 {
        self.fine[self.span(j)]
            .iter()
            .map(|a| self.field.at(a.transform_point3(x)))
            .fold(f64::INFINITY, f64::min)
    }

    /// The region's field at `x` near the samples `js` (`u32::MAX`: none), trilinear reads.
    fn near(&self, x: DVec3, js: [u32; 2]) -> f64 {
        let a = if js[0] == u32::MAX {
            f64::INFINITY
        } else {
            self.at(x, js[0])
        };
        if js[1] == js[0] || js[1] == u32::MAX {
            return a;
        }
        a.min(self.at(x, js[1]))
    }

    /// The poses [`Refiner::near`] reads at `js`, each once.
    fn poses(&self, js: [u32; 2]) -> impl Iterator<Item = &DAffine3> {
        let first = (js[0] != u32::MAX).then(|| self.span(js[0]));
        let second = (js[1] != u32::MAX && js[1] != js[0]).then(|| self.span(js[1]));
        let skip = first.clone();
        first
            .into_iter()
            .flatten()
            .chain(
                second
                    .into_iter()
                    .flatten()
                    .filter(move |i| !skip.as_ref().is_some_and(|r| r.contains(i))),
            )
            .map(|i| &self.fine[i])
    }

    /// The same minimum with the body's exact distance. Each trilinear read is within half
    /// of [`Refiner::spread`] of the exact distance, so a pose whose read, less that, is
    /// above an exact value already found cannot give the minimum and is not read exactly.
    fn exact_near(&self, x: DVec3, js: [u32; 2]) -> f64 {
        const MOST: usize = 2 * (2 * REFINE_POSES + 1);
        let mut reads = [(0.0f64, DVec3::ZERO); MOST];
        let mut count = 0;
        let mut first = 0;
        for a in self.poses(js) {
            let y = a.transform_point3(x);
            reads[count] = (self.field.at(y), y);
            if reads[count].0 < reads[first].0 {
                first = count;
            }
            count += 1;
        }
        if count == 0 {
            return f64::INFINITY;
        }
        // The pose read least first: its exact value then rules out every pose whose read,
        // less the read's error, is above it.
        let half = 0.5 * self.spread;
        let mut best = self.exact.at(reads[first].1).0;
        for (k, &(read, y)) in reads[..count].iter().enumerate() {
            if k != first && read - half <= best {
                best = best.min(self.exact.at(y).0);
            }
        }
        best
    }
}

impl Refiner<'_> {
    /// At most the distance at every pose of a sample interval whose ends' distances are at
    /// least `a` and `b`: a pose a fraction `s` of the way is within `s travel` of the first
    /// end and `(1 - s) travel` of the other (the helix arc is linear in the screw's parameter),
    /// so its distance is at least `max(a - s travel, b - (1 - s) travel)`, least where the two
    /// meet (or at the nearer end).
    fn between(&self, a: f64, b: f64) -> f64 {
        let t = self.travel;
        let low = if (a - b).abs() <= t {
            0.5 * (a + b - t)
        } else {
            a.max(b) - t
        };
        low - self.slack
    }

    /// Whether sample interval `m` (its poses from sample `m` to sample `m + 1`) is among the
    /// poses [`Refiner::near`] reads at the samples `js`: within one interval of one.
    fn within(m: usize, js: [u32; 2]) -> bool {
        js.iter()
            .any(|&j| j != u32::MAX && (m == j as usize || m + 1 == j as usize))
    }

    /// The exact minimum at `x` over every refined pose of the motion; `upper` is at least
    /// that minimum (a value already found). An interval between two samples is skipped when
    /// every pose in it is above `upper` ([`Refiner::between`] bounds them from its ends), and
    /// so is a pose its ends' bounds show above it; the distance at a sample is at least its
    /// distance to the body's bounding sphere (to the ball of a run of samples' spheres), at
    /// least its coarse or trilinear read less the read's error (the coarse grid read first),
    /// and at least the last sample read's bound less `travel` per interval since (so a sample
    /// far off lets the next ones go unread). The intervals left are read least bounded first,
    /// and a pose is read exactly only when its trilinear read, less its error, is not above
    /// `upper` (the least reads first): the minimum found early bounds out the rest. Which
    /// poses are read exactly changes nothing but the time: each one skipped is above the
    /// minimum.
    ///
    /// Where that minimum is above `upper`, the value returned is too (and may not be the
    /// minimum). The intervals [`Refiner::exact_near`] reads at the samples `known` ([`NONE`]:
    /// none) are left out: a caller passes them when `upper` is their minimum already.
    fn exact_all(&self, x: DVec3, upper: f64, known: [u32; 2]) -> f64 {
        self.least(x, upper, known).0
    }

    /// [`Refiner::exact_all`] with the refined pose giving it (its index in
    /// [`Refiner::fine`]; `usize::MAX` when no pose is below `upper`).
    fn least(&self, x: DVec3, mut upper: f64, known: [u32; 2]) -> (f64, usize) {
        let half = 0.5 * self.spread;
        let floor = -self.field.band;
        let mut best = (f64::INFINITY, usize::MAX);
        // The sample before: at most its distance (its read less the read's error, or a bound).
        let mut before = f64::INFINITY;
        // The last sample read and at most its distance (none: minus infinity).
        let mut last = (0usize, f64::NEG_INFINITY);
        // The sample intervals (by their first sample) that may hold a pose below `upper`,
        // each with at most its poses' distances.
        let mut intervals: Vec<(f64, usize, [f64; 2])> = Vec::new();
        // A sample is far when at most its distance, less half an interval's travel, is above
        // `upper`: no pose between two far samples can be below `upper`. Any bound of a far
        // sample's distance serves its intervals' bounds (`between`), so a run of far samples
        // is passed over once its ball shows them all far, and a sample is far without its
        // sphere once the last read shows it.
        let far = |bound: f64| bound - 0.5 * self.travel > upper;
        let mut i = 0;
        while i < self.centres.len() {
            if i % SAMPLE_RUN == 0 {
                let (centre, reach) = self.runs[i / SAMPLE_RUN];
                let bound = centre.distance(x) - reach - self.radius;
                if far(bound) {
                    // Only the interval before the run may be read (by the sample before it).
                    let low = self.between(before, bound);
                    if i > 0 && low <= upper && !Self::within(i - 1, known) {
                        intervals.push((low, i - 1, [before, bound]));
                    }
                    before = bound;
                    i += SAMPLE_RUN;
                    continue;
                }
            }
            // At most the distance at sample `i`: from the last read (a body point moves at
            // most `travel` per sample interval), and from the body's bounding sphere.
            let chain = last.1 - (i - last.0) as f64 * self.travel;
            let bound = if far(chain) {
                chain
            } else {
                (self.centres[i].distance(x) - self.radius).max(chain)
            };
            let here = if far(bound) {
                bound
            } else {
                let y = self.fine[i * REFINE_POSES].transform_point3(x);
                // The coarse grid's read first (it stays in cache); the fine grid's only where
                // that leaves the sample's interval able to hold a pose below `upper`. A read
                // clamped below (deep inside) bounds nothing from below.
                let coarse = self.coarse.at(y);
                let low = if coarse > -self.coarse.band {
                    (coarse - self.coarse_error).max(bound)
                } else {
                    bound
                };
                if far(low) {
                    last = (i, low);
                    low
                } else {
                    let read = self.field.at(y);
                    last = (
                        i,
                        if read > floor {
                            read - half
                        } else {
                            f64::NEG_INFINITY
                        },
                    );
                    read - half
                }
            };
            let low = self.between(before, here);
            if i > 0 && low <= upper && !Self::within(i - 1, known) {
                intervals.push((low, i - 1, [before, here]));
            }
            before = here;
            i += 1;
        }
        // The intervals least bounded first, and in each the poses read least first: the
        // minimum is found early and bounds out the rest.
        intervals.sort_unstable_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        let mut reads = [(0.0f64, DVec3::ZERO, 0usize); REFINE_POSES + 1];
        for &(low, i, [a, b]) in &intervals {
            if low > upper {
                break;
            }
            let first = i * REFINE_POSES;
            for (k, (slot, pose)) in reads
                .iter_mut()
                .zip(&self.fine[first..=first + REFINE_POSES])
                .enumerate()
            {
                // At most the pose's distance, from the interval's ends: one above `upper` is
                // not read (and sorts last).
                let s = k as f64 / REFINE_POSES as f64;
                let bound = (a - s * self.travel).max(b - (1.0 - s) * self.travel) - self.slack;
                *slot = if bound > upper {
                    (f64::INFINITY, DVec3::ZERO, first + k)
                } else {
                    let y = pose.transform_point3(x);
                    (self.field.at(y), y, first + k)
                };
            }
            reads.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
            for &(read, y, pose) in &reads {
                if read - half > upper {
                    break;
                }
                let d = self.exact.at(y).0;
                if d < best.0 {
                    best = (d, pose);
                }
                upper = upper.min(d);
            }
        }
        best
    }
}

impl Refiner<'_> {
    /// Whether a slab of outside space narrower than a cell may pass through the grid cube centred at `x`
    /// (`reach` half its diagonal) whose corners' minima come from the samples `samples`: the
    /// body's surfaces through two of them more than [`CHANNEL_GAP`] apart face each other
    /// there (their outward normals at `x` more than 120 degrees apart: [`FACING_COSINE`]) and,
    /// taken as the planes at `x`, leave outside space within the cube; and no one of them holds
    /// the whole cube inside.
    fn facing(&self, x: DVec3, reach: f64, mut samples: [u32; 8]) -> bool {
        samples.sort_unstable();
        // Each sample's outward normal and distance at `x`.
        let mut sheets = [(0u32, DVec3::ZERO, 0.0f64); 8];
        let mut count = 0;
        for (m, &j) in samples.iter().enumerate() {
            if (m > 0 && samples[m - 1] == j) || j == u32::MAX {
                continue;
            }
            let a = &self.fine[j as usize * REFINE_POSES];
            let (d, normal) = self.exact.at(a.transform_point3(x));
            if d + reach + self.slack < 0.0 {
                return false;
            }
            if let Some(n) = normal {
                sheets[count] = (j, a.matrix3.transpose() * n, d);
                count += 1;
            }
        }
        let sheets = &sheets[..count];
        // Two planes facing each other leave outside space within `reach` of `x` where
        // `d + e + |n + o| reach` (the most their distances' sum reaches there) is not negative.
        sheets.iter().enumerate().any(|(m, &(j, n, d))| {
            sheets[m + 1..].iter().any(|&(k, o, e)| {
                k - j > CHANNEL_GAP
                    && n.dot(o) < FACING_COSINE
                    && d + e + (n + o).length() * reach >= 0.0
            })
        })
    }
}

/// Regula falsi (Illinois) for a zero of `f` on `[0, 1]` from its values `ends` at 0 and 1 (of
/// opposite signs), each step kept within [`EDGE_MARGIN`] of the ends, until a value within
/// `stop` of zero, [`BRACKET_ITERATIONS`] steps or a bracket of no width: the step with the
/// least `|f|` (or `start`, a step already taken, if less).
fn bracketed(ends: [f64; 2], start: (f64, f64), stop: f64, f: &dyn Fn(f64) -> f64) -> (f64, f64) {
    let ([mut ga, mut gb], [mut ta, mut tb]) = (ends, [0.0, 1.0]);
    let mut best = start;
    if (ga < 0.0) == (gb < 0.0) {
        return best;
    }
    // The end kept last (-1: a, 1: b), whose value Illinois halves when it is kept again.
    let mut kept = 0;
    for _ in 0..BRACKET_ITERATIONS {
        let t = (ta + (tb - ta) * ga / (ga - gb)).clamp(EDGE_MARGIN, 1.0 - EDGE_MARGIN);
        let gt = f(t);
        if gt.abs() < best.0.abs() {
            best = (gt, t);
        }
        if gt.abs() <= stop || !(ta < t && t < tb) {
            break;
        }
        if (gt < 0.0) == (ga < 0.0) {
            (ta, ga) = (t, gt);
            if kept == -1 {
                gb *= 0.5;
            }
            kept = -1;
        } else {
            (tb, gb) = (t, gt);
            if kept == 1 {
                ga *= 0.5;
            }
            kept = 1;
        }
    }
    best
}

/// Settles the sign of every grid point whose value is within the grid's error of zero: the
/// exact minimum over every refined pose of the motion ([`Refiner::exact_all`]) is written in
/// its place. The grid's value is the least trilinear read over the samples of the motion: the
/// exact minimum is at most half the read's [`Refiner::spread`] above it (the exact value at the
/// sample that gave it) and at most that plus half a sample interval's travel below it (a
/// refined pose is within half of it from a sample). A point whose value is further from zero
/// keeps its sign, which is then the exact one.
///
/// So every grid edge the contouring crosses has ends of opposite exact signs and holds a zero
/// of the exact field, which its vertex is refined to: without this, an edge whose ends the
/// trilinear reads got on the wrong side of zero kept its vertex off the boundary by up to
/// their error (most of the reported bound).
fn settle_signs(
    g: &mut [f32],
    grid: Grid,
    refine: &Refiner<'_>,
    threads: usize,
    span: Span<'_>,
) -> Result<()> {
    let half = 0.5 * refine.spread;
    let below = half + 0.5 * refine.travel;
    let band = refine.field.band;
    let [nx, ny, _] = grid.n;
    let parts: Vec<_> = g.chunks_mut(nx * ny).enumerate().collect();
    in_parts(parts, threads, "the region's signs", span, |(k, layer)| {
        for (s, v) in layer.iter_mut().enumerate() {
            let value = f64::from(*v);
            if value + half < 0.0 || value - below > 0.0 {
                continue;
            }
            let exact = refine.exact_all(grid.point(s % nx, s / nx, k), value + half, NONE);
            *v = if exact < 0.0 {
                (exact.max(-band) as f32).min(-f32::MIN_POSITIVE)
            } else {
                (exact.min(band) as f32).max(0.0)
            };
        }
    })
}

/// A grid edge the contouring crosses: its ends, the region's field there and the motion
/// samples that gave it.
struct GridEdge {
    ends: [DVec3; 2],
    values: [f64; 2],
    samples: [u32; 2],
}

impl GridEdge {
    /// The point of the edge where the region's field is zero, with the exact field there
    /// (module documentation, step 4): regula falsi on the refined field, secant steps on the
    /// exact field near the edge's samples (over every pose where one elsewhere is lower),
    /// and, where those stall on a kink of the minimum, regula falsi (Illinois) on the exact
    /// field over every pose between the edge's ends, whose signs are exact
    /// ([`settle_signs`]), so that the edge holds a zero.
    fn refined(&self, refine: &Refiner<'_>, cell: f64) -> (DVec3, f64) {
        let [a, b] = self.ends;
        let [fa, fb] = self.values;
        let js = self.samples;
        let lerp = |t: f64| a.lerp(b, t.clamp(EDGE_MARGIN, 1.0 - EDGE_MARGIN));
        let mut t = fa / (fa - fb);
        // Regula falsi on the refined field, when it still brackets the edge.
        let (mut ta, mut tb) = (0.0, 1.0);
        let (mut ga, mut gb) = (refine.near(a, js), refine.near(b, js));
        if (ga < 0.0) != (gb < 0.0) {
            for _ in 0..REFINE_ITERATIONS {
                t = (ta + (tb - ta) * ga / (ga - gb)).clamp(EDGE_MARGIN, 1.0 - EDGE_MARGIN);
                let gt = refine.near(lerp(t), js);
                if gt == 0.0 {
                    break;
                }
                if (gt < 0.0) == (ga < 0.0) {
                    ta = t;
                    ga = gt;
                } else {
                    tb = t;
                    gb = gt;
                }
            }
        }
        // Secant steps on the exact field from the trilinear root (the first along the
        // trilinear bracket's slope), keeping the point where it is least: first near the
        // samples `js`, then, if a pose elsewhere in the motion is lower there, over all.
        let secant = |t: f64, slope: f64, exact: &dyn Fn(DVec3) -> f64| {
            let (mut t0, mut g0) = (t, exact(lerp(t)));
            let mut best = (g0, t0);
            let mut slope = slope;
            for _ in 0..EXACT_ITERATIONS {
                if g0 == 0.0 || !(slope.is_finite() && slope != 0.0) {
                    break;
                }
                let t1 = (t0 - g0 / slope).clamp(EDGE_MARGIN, 1.0 - EDGE_MARGIN);
                if t1 == t0 {
                    break;
                }
                let g1 = exact(lerp(t1));
                if g1.abs() < best.0.abs() {
                    best = (g1, t1);
                }
                slope = (g1 - g0) / (t1 - t0);
                (t0, g0) = (t1, g1);
            }
            (best, slope)
        };
        let ((local, t), slope) = secant(t, (gb - ga) / (tb - ta), &|x| refine.exact_near(x, js));
        let all = |x: DVec3| refine.exact_all(x, refine.near(x, js) + refine.spread, NONE);
        let (g, t) = if refine.exact_all(lerp(t), local, js) < local {
            secant(t, slope, &all).0
        } else {
            (local, t)
        };
        let (g, t) = if g.abs() > BRACKET_START * cell {
            let half = 0.5 * refine.spread;
            let ends = [
                refine.exact_all(a, fa + half, NONE),
                refine.exact_all(b, fb + half, NONE),
            ];
            bracketed(ends, (g, t), BRACKET_STOP * cell, &|t| all(lerp(t)))
        } else {
            (g, t)
        };
        (lerp(t), g)
    }
}

/// The smallest gap, in samples of the motion, between the samples giving a cube's corners
/// their minima for the cube to be read finer (`adaptive.rs`'s `channel_cubes`): two sheets
/// of the boundary, from parts of the motion apart, meet there.
pub const CHANNEL_GAP: u32 = 16;

/// The most the cosine between two sheets' outward normals may be for a cube between them to
/// be read finer (`Refiner::facing`): more than 120 degrees apart. A slab of outside space
/// narrower than a cell lies between nearly opposed sheets; sheets less opposed meet in a
/// wedge, whose tip the faces across the crease already cut (`crease.rs`).
pub const FACING_COSINE: f64 = -0.5;

/// How far, in cells, a lattice point of a suspect cube with a corner outside must be on the
/// other side of the grid's linear field for the cube to be refined: the plain grid's surface is
/// then that far off the boundary there (a slab's mouth, a thin fin). Smaller margins refine the
/// crease's own chords (on the cube at a 0.1 cell margin, 4 cubes; at this one, none).
pub const FEATURE_MARGIN: f64 = 0.25;

/// The value and sample at an added lattice point `key` (as the grid's: `f32`, negative
/// inside). Each grid point's value plus the read's error plus its distance is at least the
/// region's exact minimum at `key` (the minimum over the poses is 1-Lipschitz): where the least
/// of those is below zero, `key` is inside and takes it (with that grid point's sample); else
/// the exact minimum over every refined pose is found below it (and its sample).
fn added_value(
    lattice: &Lattice,
    key: Key,
    g: &[f32],
    arg: &[u32],
    refine: &Refiner<'_>,
) -> (f32, u32) {
    let x = lattice.point(key);
    let half = 0.5 * refine.spread;
    let band = refine.field.band;
    let (upper, near) = lattice
        .corners(key)
        .into_iter()
        .map(|p| {
            let at = lattice.point(grid_key(p));
            (
                f64::from(g[p]) + half + at.distance(x) + refine.slack,
                arg[p],
            )
        })
        .fold(
            (f64::INFINITY, u32::MAX),
            |a, b| if b.0 < a.0 { b } else { a },
        );
    if upper < 0.0 {
        return ((upper.max(-band) as f32).min(-f32::MIN_POSITIVE), near);
    }
    let (least, pose) = refine.least(x, upper, NONE);
    if pose == usize::MAX {
        // Every pose is above `upper`, itself not below zero: outside.
        return ((upper.min(band) as f32).max(0.0), near);
    }
    let samples = refine.centres.len();
    let sample = ((pose + REFINE_POSES / 2) / REFINE_POSES).min(samples - 1) as u32;
    let value = if least < 0.0 {
        (least.max(-band) as f32).min(-f32::MIN_POSITIVE)
    } else {
        (least.min(band) as f32).max(0.0)
    };
    (value, sample)
}

/// [`added_value`] at every point of `keys`, on every core.
fn lattice_values(
    lattice: &Lattice,
    keys: &[Key],
    (g, arg): (&[f32], &[u32]),
    refine: &Refiner<'_>,
    threads: usize,
    span: Span<'_>,
) -> Result<Vec<(f32, u32)>> {
    let mut values = vec![(0.0f32, 0u32); keys.len()];
    let parts: Vec<_> = keys
        .chunks(REFINE_CHUNK)
        .zip(values.chunks_mut(REFINE_CHUNK))
        .collect();
    in_parts(parts, threads, "the refined cubes", span, |(keys, vs)| {
        for (&key, v) in keys.iter().zip(vs) {
            *v = added_value(lattice, key, g, arg, refine);
        }
    })?;
    Ok(values)
}

/// Marching tetrahedra's state: the vertex on each crossed tetrahedron edge, made once.
#[derive(Default)]
struct Walk {
    edges: FastMap<(Key, Key), u32>,
    /// Each vertex's edge (its ends, lower first), refined once the mesh is walked.
    ends: Vec<(Key, Key)>,
}

impl Walk {
    /// The vertex on the edge from `p` to `q` (`p < q`), made once, at the edge's midpoint
    /// for now: a triangle's orientation along a crossed edge is the same wherever its
    /// vertices lie inside their edges.
    fn vertex(
        &mut self,
        (p, q): (Key, Key),
        position: &impl Fn(Key) -> DVec3,
        out: &mut ClosedMesh,
    ) -> Result<u32> {
        if let Some(&v) = self.edges.get(&(p, q)) {
            return Ok(v);
        }
        let v = out.vertices.len();
        if v >= u32::MAX as usize {
            return Err(Error::Limit {
                what: "cell",
                counted: "vertices",
                count: v + 1,
                limit: u32::MAX as usize,
                hint: CELL_HINT,
            });
        }
        out.vertices.push(position(p).lerp(position(q), 0.5));
        self.ends.push((p, q));
        self.edges.insert((p, q), v as u32);
        Ok(v as u32)
    }

    /// The triangle or quad (two triangles) of tetrahedron `pts` where the field changes sign,
    /// facing out.
    fn march(
        &mut self,
        pts: [Key; 4],
        inside: &impl Fn(Key) -> bool,
        position: &impl Fn(Key) -> DVec3,
        out: &mut ClosedMesh,
    ) -> Result<()> {
        let mut ins = [0; 4];
        let mut outs = [0; 4];
        let (mut ni, mut no) = (0, 0);
        for &p in &pts {
            if inside(p) {
                ins[ni] = p;
                ni += 1;
            } else {
                outs[no] = p;
                no += 1;
            }
        }
        // An edge by its ends, lower first.
        let edge = |a: Key, b: Key| if a < b { (a, b) } else { (b, a) };
        match ni {
            1 | 3 => {
                // One apex apart from the three others.
                let (apex, rest, apex_in) = if ni == 1 {
                    (ins[0], [outs[0], outs[1], outs[2]], true)
                } else {
                    (outs[0], [ins[0], ins[1], ins[2]], false)
                };
                let mut tri = [0u32; 3];
                for (slot, &r) in tri.iter_mut().zip(&rest) {
                    *slot = self.vertex(edge(apex, r), position, out)?;
                }
                // Outward: from the inside end of a crossed edge to its outside end.
                let (from, to) = if apex_in {
                    (apex, rest[0])
                } else {
                    (rest[0], apex)
                };
                push_oriented(out, tri, position(to) - position(from));
            }
            2 => {
                let (a, b, c, d) = (ins[0], ins[1], outs[0], outs[1]);
                let ac = self.vertex(edge(a, c), position, out)?;
                let ad = self.vertex(edge(a, d), position, out)?;
                let bd = self.vertex(edge(b, d), position, out)?;
                let bc = self.vertex(edge(b, c), position, out)?;
                // Both triangles hold the crossing of the edge a -> c.
                let outward = position(c) - position(a);
                let flip = orientation(out, [ac, ad, bd], outward);
                let (t0, t1) = ([ac, ad, bd], [ac, bd, bc]);
                if flip {
                    out.triangles.push([t0[0], t0[2], t0[1]]);
                    out.triangles.push([t1[0], t1[2], t1[1]]);
                } else {
                    out.triangles.push(t0);
                    out.triangles.push(t1);
                }
            }
            _ => {}
        }
        Ok(())
    }
}

/// The lattice refining the grid cubes where the boundary has a feature narrower than a cell
/// (`adaptive.rs`), with the values at every point it adds: the cubes with a corner inside,
/// none deep, and far-apart samples ([`channel_cubes`]) whose sheets face each other
/// ([`Refiner::facing`]) are read at their lattice points, and refined where one shows what the
/// grid misses (where none does, their subcubes would give about the grid's own surface).
fn channel_lattice(
    (g, arg): (&[f32], &[u32]),
    grid: Grid,
    refine: &Refiner<'_>,
    threads: usize,
    span: Span<'_>,
) -> Result<Lattice> {
    let Grid { origin, cell, n } = grid;
    let half = 0.5 * refine.spread;
    let deep = (3f64.sqrt() * cell + half) as f32;
    let offsets = corner_offsets(n);
    let reach = 0.5 * 3f64.sqrt() * cell;
    let candidates = channel_cubes(g, arg, n, deep, CHANNEL_GAP);
    let mut facing = vec![false; candidates.len()];
    let parts: Vec<_> = candidates
        .chunks(REFINE_CHUNK)
        .zip(facing.chunks_mut(REFINE_CHUNK))
        .collect();
    in_parts(
        parts,
        threads,
        "the refined cubes",
        span,
        |(cubes, flags)| {
            for (&c, flag) in cubes.iter().zip(flags) {
                let [i, j, k] = coords(n, c);
                let centre = grid.point(i, j, k) + DVec3::splat(0.5 * cell);
                *flag = refine.facing(centre, reach, offsets.map(|o| arg[c + o]));
            }
        },
    )?;
    let suspects: Vec<usize> = candidates
        .iter()
        .zip(&facing)
        .filter_map(|(&c, &f)| f.then_some(c))
        .collect();
    // Each suspect adds at most `PER_CUBE_POINTS` points; a refined cube's neighbours add fewer.
    Footprint::of::<LatticeEntry>(suspects.len().saturating_mul(3 * PER_CUBE_POINTS))
        .check("the refined cubes' points", CLOSED_HINT)?;
    let mut lattice = Lattice::new(origin, cell, n);
    let mut points: Vec<Key> = suspects.iter().flat_map(|&c| cube_points(n, c)).collect();
    points.sort_unstable();
    points.dedup();
    let values = lattice_values(&lattice, &points, (g, arg), refine, threads, span)?;
    lattice.set_values(&points, &values);
    // Refined where a lattice point shows what the grid misses: outside where every corner is
    // inside (a slab), or on the other side of the grid's linear field by more than
    // `FEATURE_MARGIN` cells.
    let margin = FEATURE_MARGIN * cell;
    let channels: Vec<usize> = suspects
        .into_iter()
        .filter(|&c| {
            let corner = offsets.map(|o| f64::from(g[c + o]));
            let inside = corner.iter().all(|&v| v < 0.0);
            cube_points(n, c).any(|k| {
                let v = f64::from(lattice.value(k).0);
                let linear = kuhn_value(corner, offset_in(n, c, k));
                (inside && v >= 0.0)
                    || (linear < 0.0 && v >= margin)
                    || (linear >= 0.0 && v < -margin)
            })
        })
        .collect();
    lattice.refine(&channels);
    let added: Vec<Key> = lattice
        .added_points()
        .into_iter()
        .filter(|&k| !lattice.has_value(k))
        .collect();
    let values = lattice_values(&lattice, &added, (g, arg), refine, threads, span)?;
    lattice.set_values(&added, &values);
    Ok(lattice)
}

/// What one added lattice point holds: its key, value and sample, and about as much again in
/// the map's and the lists' overhead (for the memory check).
type LatticeEntry = [u64; 4];

/// The lattice points a suspect cube adds at most: `(SPLIT + 1)^3` less its corners.
const PER_CUBE_POINTS: usize = (SPLIT + 1) * (SPLIT + 1) * (SPLIT + 1) - 8;

/// Marching tetrahedra over the world grid (see the module documentation).
fn contour(
    g: &[f32],
    arg: &[u32],
    grid: Grid,
    refine: &Refiner<'_>,
    (threads, decimate): (usize, bool),
    span: Span<'_>,
    out: &mut ClosedMesh,
) -> Result<()> {
    let [walked, refined, creased] = if decimate {
        DECIMATED_STAGE_ENDS
    } else {
        CONTOUR_STAGE_ENDS
    };
    let Grid { cell, n, .. } = grid;
    let [nx, ny, nz] = n;
    let index = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
    let grid_position = |p: usize| {
        let [i, j, k] = coords(n, p);
        grid.point(i, j, k)
    };
    // Cubes cut finer where a slab of outside space can hide (`adaptive.rs`), and the values
    // at the lattice points they add.
    let walk_span = span.part(0.0, walked);
    let lattice = channel_lattice((g, arg), grid, refine, threads, walk_span)?;
    out.refined_cubes = lattice.counts().0;
    let position = |key: Key| match grid_point(key) {
        Some(p) => grid_position(p),
        None => lattice.point(key),
    };
    let value = |key: Key| match grid_point(key) {
        Some(p) => g[p],
        None => lattice.value(key).0,
    };
    let sample = |key: Key| match grid_point(key) {
        Some(p) => arg[p],
        None => lattice.value(key).1,
    };
    let mut walk = Walk::default();
    let offsets = corner_offsets(n);
    let inside = |key: Key| value(key) < 0.0;
    let mut tets = Vec::new();
    for k in 0..nz - 1 {
        for j in 0..ny - 1 {
            for i in 0..nx - 1 {
                let base = index(i, j, k);
                if lattice.special(base) {
                    tets.clear();
                    lattice.tetrahedra(base, &mut tets);
                    for &tet in &tets {
                        walk.march(tet, &inside, &position, out)?;
                    }
                    continue;
                }
                let corner = |c: u8| grid_key(base + offsets[c as usize]);
                let first = inside(corner(0));
                if (1..8u8).all(|c| inside(corner(c)) == first) {
                    continue;
                }
                for tet in KUHN {
                    walk.march(tet.map(corner), &inside, &position, out)?;
                }
            }
        }
    }
    let Walk { edges, ends } = walk;
    drop(edges);
    // Every vertex moved onto the boundary along its edge, on every core: each is its own.
    let mut near: Vec<[u32; 2]> = ends.iter().map(|&(p, q)| [sample(p), sample(q)]).collect();
    let mut found = vec![0.0; ends.len()];
    let parts: Vec<_> = out
        .vertices
        .chunks_mut(REFINE_CHUNK)
        .zip(found.chunks_mut(REFINE_CHUNK))
        .zip(ends.chunks(REFINE_CHUNK).zip(near.chunks(REFINE_CHUNK)))
        .collect();
    walk_span.advance(1.0);
    let vertices = span.part(walked, refined);
    in_parts(
        parts,
        threads,
        "the vertices",
        vertices,
        |((xs, gs), (es, js))| {
            for (((x, g_at), &(p, q)), &samples) in xs.iter_mut().zip(gs.iter_mut()).zip(es).zip(js)
            {
                let edge = GridEdge {
                    ends: [position(p), position(q)],
                    values: [value(p) as f64, value(q) as f64],
                    samples,
                };
                (*x, *g_at) = edge.refined(refine, cell);
            }
        },
    )?;
    let mut residual = found.iter().fold(0.0f64, |r, g| r.max(g.abs().min(cell)));
    // Creases: their edges split until each midpoint is within CREASE_TARGET cells.
    let exact = |x: DVec3, js: [u32; 2]| {
        let near = refine.exact_near(x, js);
        near.min(refine.exact_all(x, near, js))
    };
    let onto = |from: DVec3, dir: DVec3, value: f64, js: [u32; 2]| {
        // The zero along `dir` (out from inside, in from outside), else the other way,
        // bracketed by steps of growing length (at most a cell).
        for way in [-value, value] {
            let mut reach = way;
            for _ in 0..4 {
                let there = exact(from + reach * dir, js);
                if (there < 0.0) != (value < 0.0) {
                    let (g, t) =
                        bracketed([value, there], (value, 0.0), BRACKET_STOP * cell, &|t| {
                            exact(from + t * reach * dir, js)
                        });
                    return Some((from + t * reach * dir, g));
                }
                reach = (1.5 * reach).clamp(-cell, cell);
            }
        }
        None
    };
    let moved = super::crease::split_creases(
        &mut out.vertices,
        &mut near,
        &mut out.triangles,
        CREASE_TARGET * cell,
        thread_count(threads),
        span.part(refined, creased),
        &exact,
        &onto,
    );
    span.check()?;
    // The bound covers the edges' midpoints too (each read exactly): where a split is refused
    // the face stays off, by up to a third of a cell (stop 44, the L-prism), more than a vertex.
    let vertices_residual = residual.max(moved.0);
    residual = vertices_residual.max(moved.1);
    // Flat parts: vertices removed (none moves, so the bound below holds for those left).
    if decimate {
        super::decimate::collapse_flat(
            &mut out.vertices,
            &near,
            &mut out.triangles,
            DECIMATE_TARGET * cell,
            DECIMATE_LONGEST * cell,
            super::crease::TOUCH * CREASE_TARGET * cell,
            thread_count(threads),
            span.part(creased, 1.0),
            &exact,
        );
        span.check()?;
    }
    // The refinement reads the body at REFINE_POSES poses per sample interval, over which no
    // body point travels more than a cell (`DenseMotion::new`: the helix arc, linear in the
    // screw's parameter), so every instant of the motion is within `cell / (2 REFINE_POSES)` of
    // travel from a pose read: the continuous motion's minimum is at most that below the one
    // found (the body's distance is 1-Lipschitz).
    out.error_bound = residual + motion_gap(cell);
    out.vertex_bound = vertices_residual + motion_gap(cell);
    Ok(())
}

/// Whether the triangle `t` must be reversed to face along `outward`.
fn orientation(out: &ClosedMesh, t: [u32; 3], outward: DVec3) -> bool {
    let [a, b, c] = t.map(|i| out.vertices[i as usize]);
    (b - a).cross(c - a).dot(outward) < 0.0
}

/// Adds `t`, reversed if needed to face along `outward`.
fn push_oriented(out: &mut ClosedMesh, t: [u32; 3], outward: DVec3) {
    if orientation(out, t, outward) {
        out.triangles.push([t[0], t[2], t[1]]);
    } else {
        out.triangles.push(t);
    }
}

/// The body of `vertices` and `triangles` for a motion through `poses` (two or more: checked
/// first, so that too few poses is that error whatever the mesh).
fn body_for(vertices: &[DVec3], triangles: &[[i64; 3]], poses: &[Pose]) -> Result<Body> {
    if poses.len() < 2 {
        return Err(Error::TooFew {
            got: poses.len(),
            need: 2,
        });
    }
    Body::new(vertices, triangles)
}

/// [`Body::new`] then [`closed_work`].
///
/// # Errors
/// Those of [`Body::new`] and [`closed_work`].
pub fn closed_work_mesh(
    vertices: &[DVec3],
    triangles: &[[i64; 3]],
    poses: &[Pose],
    options: &ClosedOptions,
) -> Result<ClosedWork> {
    closed_work(&body_for(vertices, triangles, poses)?, poses, options)
}

/// [`Body::new`] then [`sweep_closed_watched`].
///
/// # Errors
/// Those of [`Body::new`] and [`sweep_closed_watched`].
pub fn sweep_closed_mesh(
    vertices: &[DVec3],
    triangles: &[[i64; 3]],
    poses: &[Pose],
    options: &ClosedOptions,
    progress: &Progress,
) -> Result<ClosedMesh> {
    sweep_closed_watched(
        &body_for(vertices, triangles, poses)?,
        poses,
        options,
        progress,
    )
}
