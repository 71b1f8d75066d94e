//! The region swept by a triangle mesh moving along a polyscrew, as one indexed triangle
//! mesh whose depth image from outside equals that of the union of all the body's instances.
//!
//! Rossignac-Kim (`003_*`, "Swept volumes" and "Sweeping and animating moving objects"):
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
//! A quad `(a_j, b_j, b_{j+1}, a_{j+1})` is twisted: its two triangles leave the ruled
//! surface swept by `(a, b)` by up to `|omega x (b - a)| / (4 k)` (`omega = r S`), first order
//! in the step. Long segments are therefore cut into `n` equal pieces with
//! `|omega x (b - a)| / (4 k n) <= TWIST_REL * extent` (at most [`MAX_PIECES`]).
//!
//! Triangles whose area is below [`DEGENERATE_REL`] (points on the axis of a rotation, which
//! do not move) are left out.

pub mod body;
pub mod generator;

use glam::DVec3;

pub use body::{
    body_footprint, Body, Edge, EdgeKind, FLAT_REL, MAX_VERTEX_COORDINATE, NO_FACE, SWEEP_HINT,
    ZERO_AREA_REL,
};
pub use generator::{
    Generator, Scratch, Segment, SegmentKind, Velocity, MOTIONLESS_REL, TANGENT_REL,
};

use crate::error::{Error, Result};
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

/// Options of [`sweep`].
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SweepOptions {
    /// Steps `k` per screw, `1..=MAX_STEPS`: the sweep of each generator segment along one
    /// screw is `k` quads.
    pub steps: u32,
    /// Whether to add the body at the first and the last pose.
    pub caps: bool,
}

impl Default for SweepOptions {
    fn default() -> Self {
        Self {
            steps: 8,
            caps: true,
        }
    }
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
}

/// Sweeps `body` along the polyscrew through `poses` (Rossignac-Kim, "Sweeping and
/// animating moving objects"; see the module documentation).
///
/// # Errors
/// - [`Error::TooFew`] for fewer than 2 poses;
/// - [`Error::BadPose`] (`NotFinite`) for a pose with a NaN or infinite entry;
/// - [`Error::Invalid`] (`"steps"`) for `steps` outside `1..=MAX_STEPS`, or an output of
///   more than `u32::MAX` vertices;
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
        return Err(Error::Invalid {
            what: "steps",
            reason: format!("{k} is outside 1..={MAX_STEPS}"),
        });
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
    let mut out = SweptMesh::default();
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
        // Cut long segments against twist: extra points after the generator's own.
        points.clear();
        points.extend_from_slice(&gen.points);
        segments.clear();
        let twist_max = 4.0 * k as f64 * TWIST_REL * body.extent();
        for s in &gen.segments {
            let [sa, sb] = s.ends;
            let (pa, pb) = (gen.points[sa as usize], gen.points[sb as usize]);
            let twist = velocity.omega.cross(pb - pa).length();
            let n = ((twist / twist_max).ceil() as u32).clamp(1, MAX_PIECES);
            let mut prev = sa;
            for piece in 1..n {
                let next = points.len() as u32;
                points.push(pa.lerp(pb, piece as f64 / n as f64));
                segments.push([prev, next]);
                prev = next;
            }
            segments.push([prev, sb]);
        }
        let g = points.len();
        let total = out.vertices.len() as u64 + (k as u64 + 1) * g as u64;
        if total > u32::MAX as u64 {
            return Err(Error::Invalid {
                what: "steps",
                reason: format!("the swept mesh would have {total} vertices, over 2^32 - 1"),
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
mod tests;
