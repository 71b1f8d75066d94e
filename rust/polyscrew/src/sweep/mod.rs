//! The region swept by a triangle mesh moving along a polyscrew, as one indexed triangle
//! mesh whose depth image from outside equals that of the union of all the body's instances.
//!
//! Rossignac-Kim (*Computing and visualizing pose-interpolating 3D motions*, sections "Swept volumes" and "Sweeping and animating moving objects"):
//! instead of the boundary of the swept region `S(W, A, B)` display the superset
//! `b(W@A) u b(W@B) u E(W, A, B)`, where the extrusion surface `E` is the sweep of a
//! time-independent generator `G` (the grazing points, see [`generator`]) along the screw.
//! The excess lies inside the region, so a z-buffer hides it.
//!
//! For a polyscrew (poses `p_0 .. p_{N-1}`, one screw per span `p_i -> p_{i+1}`):
//!
//! - each span's generator is computed in the body frame for the relative screw
//!   `Screw::between(I, p_i^-1 p_{i+1})`, and swept in `k` steps: at step `j` the generator's
//!   points are placed at `p_i N^(j / k)` (`N` that screw), consecutive steps share vertices,
//!   and each generator segment `(a, b)` gives the quads `(a_j, b_j, b_{j+1}, a_{j+1})` as two
//!   triangles, wound so that their normal `(b - a) x v` points away from the body;
//! - the body at the first and the last pose is added whole as caps (optional);
//! - at an interior pose `p_i` the body can be on the region's boundary where it was moving
//!   outward at the end of span `i - 1` and moves inward at the start of span `i` (a
//!   reversal): the faces with `max n . v_{i-1} >= 0` and `min n . v_i <= 0` on their corners
//!   are added there (a superset of those points, a thin band along the silhouette for a
//!   smooth motion).
//!
//! ## Accuracy: steps chosen from a tolerance
//!
//! Two errors separate the triangles from the exact surface swept by a generator segment
//! `(a, b)` along a screw of angle `theta` (its slide adds none: it is linear in time, on the
//! chord as on the helix):
//!
//! - **chord**: a point at distance `rho` from the screw's axis moves on a helix; sampled in
//!   `k` steps, the chord between two samples leaves it by at most the sagitta
//!   `rho (1 - cos(theta / 2k))` (at the step's middle, in the plane across the axis);
//! - **twist**: a quad `(a_j, b_j, b_{j+1}, a_{j+1})` is not planar; its two triangles leave
//!   the bilinear patch through its corners by at most `|w| / 4` (at its centre, `w` the
//!   twist vector `(b_{j+1} - b_j) - (a_{j+1} - a_j)`), and `|w| = |(R - I)(b - a)| <=
//!   2 sin(theta / 2k) l` with `l` the length of `b - a` across the axis (`R` the step's
//!   rotation). A segment cut into `n` pieces: `sin(theta / 2k) l / (2 n)`.
//!
//! The bilinear patch is within the chord error of the exact ruled surface (each of its
//! points is an affine combination of two chord points at the same time), so every triangle
//! point is within `chord + twist` of the body's surface at the pose of its time. With a
//! tolerance `tol` ([`Accuracy::Tolerance`]), each span takes the fewest steps `k` (at least
//! `steps`) with `rho_max (1 - cos(theta / 2k)) <= tol / 2` (`rho_max`: the generator's
//! farthest point from the axis), then cuts each segment into the fewest pieces with
//! `sin(theta / 2k) l / (2 n) <= tol / 2`. [`MAX_STEPS`] and [`MAX_PIECES`] bound both; the
//! bound actually met is returned as [`SweptMesh::error_bound`].
//!
//! With [`Accuracy::Steps`] (`steps` exactly per span) long segments are cut into `n` equal
//! pieces with `|omega x (b - a)| / (4 k n) <= TWIST_REL * extent` (at most [`MAX_PIECES`]).
//!
//! Triangles whose area is below [`DEGENERATE_REL`] (points on the axis of a rotation, which
//! do not move) are left out.

mod adaptive;
pub mod body;
pub mod closed;
mod crease;
mod decimate;
mod exact;
pub mod generator;
mod hash;

use glam::DVec3;

pub use body::{
    body_footprint, enclosed_volume, Body, Edge, EdgeKind, FLAT_REL, MAX_VERTEX_COORDINATE,
    NO_FACE, SWEEP_HINT, ZERO_AREA_REL,
};
pub use closed::{
    closed_work, sweep_closed, sweep_closed_mesh, sweep_closed_watched, ClosedMesh, ClosedOptions,
    ClosedWork, DEFAULT_CELL_REL, DEFAULT_CLOSED_TOLERANCE_REL,
};
pub use generator::{
    Generator, Scratch, Segment, SegmentKind, Velocity, MOTIONLESS_REL, TANGENT_REL,
};

use crate::error::{Error, Expected, Result};
use crate::memory::{try_reserve, Footprint};
use crate::motion::pose::Pose;
use crate::motion::screw::Screw;

/// Most steps per screw accepted by [`sweep`].
pub const MAX_STEPS: u32 = 4096;

/// An output triangle whose `|(b - a) x (c - a)|` is at most `DEGENERATE_REL` times the
/// square of the body's extent is degenerate and left out.
pub const DEGENERATE_REL: f64 = 1e-12;

/// Largest twist of a swept quad, as a fraction of the body's extent, before the generator
/// segment is cut into pieces (see the module documentation).
pub const TWIST_REL: f64 = 5e-3;

/// Most pieces a generator segment is cut into against twist.
pub const MAX_PIECES: u32 = 256;

/// The default tolerance of [`Accuracy::Relative`]: a fraction of the body's bounding radius
/// (half the diagonal of its bounding box): 0.2 %.
pub const DEFAULT_TOLERANCE_REL: f64 = 2e-3;

/// Bytes the sweep counts per output vertex against the memory budget: its own (24) and
/// the float64 copy the Python module returns (24).
pub const BYTES_PER_OUTPUT_VERTEX: usize = 48;

/// Bytes the sweep counts per output triangle: its own (12) and the int64 copy (24).
pub const BYTES_PER_OUTPUT_TRIANGLE: usize = 36;

/// What a swept mesh of `vertices` and `triangles` holds, its Python copy included.
fn output_footprint(vertices: usize, triangles: usize) -> Footprint {
    Footprint::bytes(BYTES_PER_OUTPUT_VERTEX).times(vertices)
        + Footprint::bytes(BYTES_PER_OUTPUT_TRIANGLE).times(triangles)
}

/// How [`sweep`] chooses the steps of each screw (see the module documentation).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Accuracy {
    /// Exactly [`SweepOptions::steps`] per screw; long segments cut against
    /// [`TWIST_REL`].
    Steps,
    /// Per screw the fewest steps (at least [`SweepOptions::steps`]) that keep every swept
    /// triangle within this distance (body units, `> 0`) of the exact swept surface.
    Tolerance(f64),
    /// [`Accuracy::Tolerance`] of this fraction (`> 0`) of the body's bounding radius (half
    /// the diagonal of its bounding box, `Body::extent() / 2`).
    Relative(f64),
}

impl Default for Accuracy {
    fn default() -> Self {
        Self::Relative(DEFAULT_TOLERANCE_REL)
    }
}

/// Options of [`sweep`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SweepOptions {
    /// Steps `k` per screw, `1..=MAX_STEPS`: with [`Accuracy::Steps`] the sweep of each
    /// generator segment along one screw is `k` quads; otherwise the fewest steps per screw.
    pub steps: u32,
    /// Whether to add the body at the first and the last pose.
    pub caps: bool,
    /// How the steps of each screw are chosen.
    pub accuracy: Accuracy,
}

impl Default for SweepOptions {
    /// One step at least, caps, and the tolerance [`DEFAULT_TOLERANCE_REL`] of the body's
    /// bounding radius.
    fn default() -> Self {
        Self {
            steps: 1,
            caps: true,
            accuracy: Accuracy::default(),
        }
    }
}

/// The steps and pieces that keep one screw's sweep within `tol`, and the bound they meet:
/// `(k, bound)` for the chord error (see the module documentation), `rho_max` the farthest
/// generator point from the axis, `theta` the screw's angle, `min_steps` the least `k`.
fn chord_steps(theta: f64, rho_max: f64, tol: f64, min_steps: u32) -> (u32, f64) {
    let sagitta = |k: u32| rho_max * (1.0 - (0.5 * theta / k as f64).cos());
    if theta <= 0.0 || rho_max <= 0.0 {
        return (min_steps, 0.0);
    }
    let half = 0.5 * tol;
    // rho (1 - cos(theta / 2k)) <= half  <=>  theta / 2k <= acos(1 - half / rho).
    let step_angle = 2.0 * (1.0 - half / rho_max).max(-1.0).acos();
    let mut k = (theta / step_angle).ceil().clamp(1.0, MAX_STEPS as f64) as u32;
    k = k.max(min_steps);
    // Rounding: one more step where the closed form lands a hair above.
    if k < MAX_STEPS && sagitta(k) > half {
        k += 1;
    }
    (k, sagitta(k))
}

/// Distance of `q` from the line through `point` along the unit `axis`.
#[inline]
fn axis_distance(q: DVec3, point: DVec3, axis: DVec3) -> f64 {
    let d = q - point;
    (d - d.dot(axis) * axis).length()
}

/// The swept region's mesh (world frame) and what it is made of.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SweptMesh {
    /// Vertices, world frame.
    pub vertices: Vec<DVec3>,
    /// Triangles, counter-clockwise seen from outside the region.
    pub triangles: Vec<[u32; 3]>,
    /// Generator segments summed over the screws.
    pub generator_segments: usize,
    /// Triangles of the caps and of the interior poses' bands.
    pub cap_triangles: usize,
    /// The tolerance asked for (body units; 0 with [`Accuracy::Steps`]).
    pub tolerance: f64,
    /// A bound, met by construction, on the distance of every swept triangle's points from
    /// the exact surface swept by its generator segment: the largest chord plus twist error
    /// over the screws (see the module documentation). At most `tolerance` unless
    /// [`MAX_STEPS`] or [`MAX_PIECES`] capped a screw.
    pub error_bound: f64,
    /// The most steps taken by one screw.
    pub max_steps: u32,
}

/// Sweeps `body` along the polyscrew through `poses` (Rossignac-Kim, "Sweeping and
/// animating moving objects"; see the module documentation).
///
/// # Errors
/// - [`Error::TooFew`] for fewer than 2 poses;
/// - [`Error::BadPose`] (`NotFinite`) for a pose with a NaN or infinite entry;
/// - [`Error::Value`] (`"steps"`) for `steps` outside `1..=MAX_STEPS`, [`Error::Limit`] for
///   an output of more than `u32::MAX` vertices;
/// - [`Error::Value`] (`"tolerance"`) for a tolerance that is not finite and positive;
/// - [`Error::Memory`] before the span whose quads would take the mesh (with its Python
///   copy, [`BYTES_PER_OUTPUT_VERTEX`], [`BYTES_PER_OUTPUT_TRIANGLE`]) and the body's
///   buffers ([`body_footprint`]) over the memory budget.
pub fn sweep(body: &Body, poses: &[Pose], options: &SweepOptions) -> Result<SweptMesh> {
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
    let k = options.steps;
    if k == 0 || k > MAX_STEPS {
        return Err(Error::Value {
            what: "steps",
            at: None,
            value: k as f64,
            expected: Expected::Within {
                low: 1.0,
                high: MAX_STEPS as f64,
            },
        });
    }
    let tolerance = match options.accuracy {
        Accuracy::Steps => None,
        Accuracy::Tolerance(t) => Some(t),
        Accuracy::Relative(r) => Some(r * 0.5 * body.extent()),
    };
    if let Some(t) = tolerance {
        if !(t.is_finite() && t > 0.0) {
            return Err(Error::Value {
                what: "tolerance",
                at: None,
                value: t,
                expected: Expected::Positive("length"),
            });
        }
    }
    let nf = body.triangles().len();
    let min_cross = DEGENERATE_REL * body.extent() * body.extent();
    let fixed = body_footprint(body.vertices().len(), nf);
    // The mesh so far plus `vertices` and `triangles` more, checked before they are added.
    let reserve = |out: &mut SweptMesh, vertices: usize, triangles: usize| -> Result<()> {
        let total = fixed
            + output_footprint(
                out.vertices.len().saturating_add(vertices),
                out.triangles.len().saturating_add(triangles),
            );
        total.check("the swept mesh", SWEEP_HINT)?;
        try_reserve(&mut out.vertices, vertices, "the swept mesh")?;
        try_reserve(&mut out.triangles, triangles, "the swept mesh")
    };
    let mut out = SweptMesh {
        tolerance: tolerance.unwrap_or(0.0),
        ..SweptMesh::default()
    };
    let mut remap = vec![u32::MAX; body.vertices().len()];
    let all: Vec<u32> = (0..nf as u32).collect();
    if options.caps {
        reserve(&mut out, body.vertices().len(), nf)?;
        add_faces(&mut out, body, &poses[0], &all, &mut remap);
    }
    let mut gen = Generator::default();
    let mut scratch = Scratch::default();
    let mut keep: Vec<u32> = Vec::new();
    let mut prev_max = vec![0.0; nf];
    let mut prev_tol = 0.0;
    let mut points: Vec<DVec3> = Vec::new();
    let mut segments: Vec<[u32; 2]> = Vec::new();
    for (i, pair) in poses.windows(2).enumerate() {
        let (a, b) = (&pair[0], &pair[1]);
        let screw = Screw::between(&Pose::IDENTITY, &a.inverse().mul_pose(b));
        let velocity = Velocity::of_screw(&screw);
        let tol = gen.build(body, &velocity, &mut scratch);
        let fv = scratch.face_values();
        keep.clear();
        for (f, (vals, prev)) in fv.iter().zip(prev_max.iter_mut()).enumerate() {
            let lo = vals[0].min(vals[1]).min(vals[2]);
            if i > 0 && *prev >= -prev_tol && lo <= tol {
                keep.push(f as u32);
            }
            *prev = vals[0].max(vals[1]).max(vals[2]);
        }
        if i > 0 {
            reserve(&mut out, 3 * keep.len(), keep.len())?;
            add_faces(&mut out, body, a, &keep, &mut remap);
        }
        prev_tol = tol;
        out.generator_segments += gen.segments.len();
        if gen.segments.is_empty() {
            continue;
        }
        // Steps of this screw: `k` exactly, or the fewest within the tolerance.
        let (theta, axis, point) = (screw.angle(), screw.axis(), screw.point());
        let (k, chord) = match tolerance {
            None => (k, 0.0),
            Some(tol) => {
                let rho_max = gen
                    .points
                    .iter()
                    .map(|&q| axis_distance(q, point, axis))
                    .fold(0.0, f64::max);
                chord_steps(theta, rho_max, tol, k)
            }
        };
        out.max_steps = out.max_steps.max(k);
        let half_step = (0.5 * theta / k as f64).sin();
        // Cut long segments against twist: extra points after the generator's own.
        points.clear();
        points.extend_from_slice(&gen.points);
        segments.clear();
        let twist_max = 4.0 * k as f64 * TWIST_REL * body.extent();
        let mut twist_bound: f64 = 0.0;
        for s in &gen.segments {
            let [sa, sb] = s.ends;
            let (pa, pb) = (gen.points[sa as usize], gen.points[sb as usize]);
            let n = match tolerance {
                None => {
                    let twist = velocity.omega.cross(pb - pa).length();
                    ((twist / twist_max).ceil() as u32).clamp(1, MAX_PIECES)
                }
                Some(tol) => {
                    // The segment's length across the axis: sin(theta / 2k) l / (2 n) <= tol / 2.
                    let d = pb - pa;
                    let across = (d - d.dot(axis) * axis).length();
                    let n = ((half_step * across / tol).ceil() as u32).clamp(1, MAX_PIECES);
                    twist_bound = twist_bound.max(half_step * across / (2.0 * n as f64));
                    n
                }
            };
            let mut prev = sa;
            for piece in 1..n {
                let next = points.len() as u32;
                points.push(pa.lerp(pb, piece as f64 / n as f64));
                segments.push([prev, next]);
                prev = next;
            }
            segments.push([prev, sb]);
        }
        if tolerance.is_some() {
            out.error_bound = out.error_bound.max(chord + twist_bound);
        }
        let g = points.len();
        let total = out.vertices.len() as u64 + (k as u64 + 1) * g as u64;
        if total > u32::MAX as u64 {
            return Err(Error::Limit {
                what: "steps",
                counted: "vertices of the swept mesh",
                count: usize::try_from(total).unwrap_or(usize::MAX),
                limit: u32::MAX as usize,
                hint: "use fewer steps or a larger tolerance",
            });
        }
        reserve(
            &mut out,
            (k as usize + 1).saturating_mul(g),
            (2 * k as usize).saturating_mul(segments.len()),
        )?;
        let base = out.vertices.len() as u32;
        for j in 0..=k {
            let pose = a.mul_pose(&screw.motion(j as f64 / k as f64));
            out.vertices
                .extend(points.iter().map(|&p| pose.transform_point3(p)));
        }
        for &[sa, sb] in &segments {
            for j in 0..k {
                let a0 = base + j * g as u32 + sa;
                let b0 = base + j * g as u32 + sb;
                let a1 = a0 + g as u32;
                let b1 = b0 + g as u32;
                push_triangle(&mut out, [a0, b0, b1], min_cross);
                push_triangle(&mut out, [a0, b1, a1], min_cross);
            }
        }
    }
    if options.caps {
        reserve(&mut out, body.vertices().len(), nf)?;
        add_faces(&mut out, body, &poses[poses.len() - 1], &all, &mut remap);
    }
    Ok(out)
}

/// Adds the triangle unless its doubled area is at most `min_cross`.
#[inline]
fn push_triangle(out: &mut SweptMesh, t: [u32; 3], min_cross: f64) {
    let [a, b, c] = t.map(|i| out.vertices[i as usize]);
    if (b - a).cross(c - a).length_squared() > min_cross * min_cross {
        out.triangles.push(t);
    }
}

/// Adds the faces `faces` of `body` placed at `pose`, sharing their vertices.
fn add_faces(out: &mut SweptMesh, body: &Body, pose: &Pose, faces: &[u32], remap: &mut [u32]) {
    let verts = body.vertices();
    let tris = body.triangles();
    for &f in faces {
        let tri = tris[f as usize].map(|i| {
            let slot = &mut remap[i as usize];
            if *slot == u32::MAX {
                *slot = out.vertices.len() as u32;
                out.vertices.push(pose.transform_point3(verts[i as usize]));
            }
            *slot
        });
        out.triangles.push(tri);
    }
    out.cap_triangles += faces.len();
    for &f in faces {
        for i in tris[f as usize] {
            remap[i as usize] = u32::MAX;
        }
    }
}

/// [`Body::new`] then [`sweep`]: the swept region of the mesh `(vertices, triangles)` (body
/// frame) moving through `poses`.
///
/// # Errors
/// Those of [`Body::new`] and [`sweep`].
pub fn sweep_mesh(
    vertices: &[DVec3],
    triangles: &[[i64; 3]],
    poses: &[Pose],
    options: &SweepOptions,
) -> Result<SweptMesh> {
    if poses.len() < 2 {
        return Err(Error::TooFew {
            got: poses.len(),
            need: 2,
        });
    }
    let body = Body::new(vertices, triangles)?;
    sweep(&body, poses, options)
}

#[cfg(test)]
mod closed_tests;
#[cfg(test)]
mod closed_tolerance_tests;
#[cfg(test)]
mod tests;
#[cfg(test)]
mod tolerance_tests;
