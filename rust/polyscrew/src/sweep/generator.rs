//! The generator of a screw sweep: the grazing points of the body's boundary, where the
//! velocity is tangent to the surface, as line segments in the body frame.
//!
//! Rossignac-Kim (*Computing and visualizing pose-interpolating 3D motions*, sections "Swept volumes" and "Computing the characteristic curves and
//! silhouette edges"): during a screw the velocity of a body point is constant in the body
//! frame,
//!
//! ```text
//! v(q) = d S + r S x (q - P)        (slide d, angle r, unit axis S through P)
//! ```
//!
//! so for a face of unit normal `n` the function `f(q) = n . v(q)` is affine in `q`. Its zero
//! set on the face's plane is the *characteristic line*; where it crosses the face it gives a
//! *characteristic segment*, ending at the characteristic points `Ch(F, E)` on the face's
//! edges. A convex edge is split at the characteristic points of its two faces into one, two
//! or three segments; a segment is a *silhouette edge* when `n_L . v` and `n_R . v` have
//! opposite signs at its midpoint. Concave edges of a closed mesh are not processed.
//!
//! Degenerate cases, all kept rather than dropped since any part of the body's surface swept
//! lies inside the swept region:
//! - a face with `f = 0` on all its corners sweeps into itself (for instance a face turning
//!   about its own normal): it has no characteristic segment and does not split its edges,
//!   and each of its edges whose other face is not tangent too is kept whole as a
//!   [`SegmentKind::Border`] segment; their sweeps cover the region the face sweeps in its
//!   own plane, together with the caps;
//! - border edges of an open mesh and non-manifold edges are kept whole as
//!   [`SegmentKind::Border`];
//! - an open mesh has no inside, so its concave edges are processed like convex ones.

use std::collections::HashMap;

use glam::DVec3;

use super::body::{Body, EdgeKind, NO_FACE};
use crate::motion::screw::Screw;

/// Below this fraction of the largest vertex speed, `n . v` counts as zero (the point is
/// grazing, the face tangent).
pub const TANGENT_REL: f64 = 1e-9;

/// A screw whose largest vertex speed is at most this fraction of the body's extent does not
/// move the body: it has an empty generator.
pub const MOTIONLESS_REL: f64 = 1e-12;

/// Face class: `n . v > tol` on every corner.
const POSITIVE: u8 = 1;
/// Face class: `n . v < -tol` on every corner.
const NEGATIVE: u8 = 2;
/// Face class: the zero set of `n . v` meets the face (a characteristic segment or point).
const MIXED: u8 = 3;
/// Face class: `|n . v| <= tol` on every corner: the face sweeps into itself.
const TANGENT: u8 = 4;

/// The body-frame velocity field of a screw, `v(q) = c + r S x q` with `c = d S - r S x P`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Velocity {
    /// `c = d S - r S x P`, the velocity of the body frame's origin.
    pub origin: DVec3,
    /// `omega = r S`, the angular velocity.
    pub omega: DVec3,
}

impl Velocity {
    /// The velocity field of the screw `screw` taken as a motion of the body frame from `t = 0`
    /// to `t = 1`: `screw` must start at the identity (`Screw::between(&Pose::IDENTITY, &rel)`
    /// with `rel = a^-1 b`, the body-frame screw from pose `a` to pose `b`).
    pub fn of_screw(screw: &Screw) -> Self {
        let s = screw.axis();
        let r = screw.angle();
        let omega = r * s;
        Self {
            origin: screw.slide() * s - omega.cross(screw.point()),
            omega,
        }
    }

    /// `v(q) = c + omega x q`.
    #[inline]
    pub fn at(&self, q: DVec3) -> DVec3 {
        self.origin + self.omega.cross(q)
    }
}

/// What a generator segment is.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SegmentKind {
    /// Part of a convex (or flat) edge where the two faces' `n . v` have opposite signs.
    Silhouette {
        /// The edge's index in [`Body::edges`].
        edge: u32,
    },
    /// Part of the characteristic line `n . v = 0` of a face, inside the face.
    Characteristic {
        /// The face's index.
        face: u32,
    },
    /// A whole edge kept because it borders an open mesh, is non-manifold, or borders a face
    /// that sweeps into itself.
    Border {
        /// The edge's index in [`Body::edges`].
        edge: u32,
    },
}

/// A segment of the generator between two of its points, oriented so that its sweep
/// `(a, b, b + v dt, a + v dt)` faces outward: `(b - a) x v . m > 0` with `m` the sum of the
/// normals of the faces it lies on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Segment {
    /// Indices of its ends in [`Generator::points`].
    pub ends: [u32; 2],
    /// Where it comes from.
    pub kind: SegmentKind,
}

/// The generator `G(W, A, B)` of one screw: points on the body's surface (body frame) and
/// segments between them. Points are shared by the segments that meet there.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Generator {
    /// The points, in the body frame.
    pub points: Vec<DVec3>,
    /// The segments.
    pub segments: Vec<Segment>,
}

/// Where a generator point sits, to share it between segments.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
enum PointKey {
    Vertex(u32),
    /// The characteristic point `Ch(face, edge)`.
    OnEdge(u32, u32),
}

/// Reusable buffers of [`Generator::build`], so that a polyscrew allocates once.
#[derive(Debug, Default)]
pub struct Scratch {
    speeds: Vec<DVec3>,
    face_values: Vec<[f64; 3]>,
    /// Per face: [`POSITIVE`], [`NEGATIVE`], [`MIXED`] or [`TANGENT`].
    face_sign: Vec<u8>,
    vertex_point: Vec<u32>,
    used_vertices: Vec<u32>,
    edge_points: HashMap<(u32, u32), u32>,
}

impl Scratch {
    /// `n . v` at the three corners of each face, from the last [`Generator::build`].
    pub fn face_values(&self) -> &[[f64; 3]] {
        &self.face_values
    }
}

impl Generator {
    /// The generator of `velocity` on `body` (see the module documentation); `scratch`
    /// keeps the buffers between calls and afterwards holds `n . v` at each face's corners.
    ///
    /// Returns the tolerance below which `|n . v|` counted as zero (0 for a motionless
    /// screw, which has an empty generator).
    pub fn build(&mut self, body: &Body, velocity: &Velocity, scratch: &mut Scratch) -> f64 {
        self.points.clear();
        self.segments.clear();
        let verts = body.vertices();
        let tris = body.triangles();
        let normals = body.normals();
        let edges = body.edges();
        let nf = tris.len();

        scratch.speeds.clear();
        scratch.speeds.extend(verts.iter().map(|&p| velocity.at(p)));
        let vmax2 = scratch
            .speeds
            .iter()
            .map(|v| v.length_squared())
            .fold(0.0, f64::max);
        let vmax = vmax2.sqrt();
        scratch.face_values.clear();
        scratch.face_sign.clear();
        if vmax <= MOTIONLESS_REL * body.extent() || vmax.is_nan() {
            scratch.face_values.resize(nf, [0.0; 3]);
            scratch.face_sign.resize(nf, TANGENT);
            return 0.0;
        }
        let tol = TANGENT_REL * vmax;
        let speeds = &scratch.speeds;
        scratch
            .face_values
            .extend(tris.iter().zip(normals).map(|(t, n)| {
                [
                    n.dot(speeds[t[0] as usize]),
                    n.dot(speeds[t[1] as usize]),
                    n.dot(speeds[t[2] as usize]),
                ]
            }));
        scratch
            .face_sign
            .extend(scratch.face_values.iter().map(|f| {
                let lo = f[0].min(f[1]).min(f[2]);
                let hi = f[0].max(f[1]).max(f[2]);
                if lo > tol {
                    POSITIVE
                } else if hi < -tol {
                    NEGATIVE
                } else if lo >= -tol && hi <= tol {
                    TANGENT
                } else {
                    MIXED
                }
            }));
        if scratch.vertex_point.len() != verts.len() {
            scratch.vertex_point.clear();
            scratch.vertex_point.resize(verts.len(), u32::MAX);
        }
        scratch.edge_points.clear();

        let mut b = Builder {
            gen: self,
            verts,
            velocity,
            vertex_point: &mut scratch.vertex_point,
            used_vertices: &mut scratch.used_vertices,
            edge_points: &mut scratch.edge_points,
        };
        let fv = &scratch.face_values;
        let sign = &scratch.face_sign;
        let corners = body.edge_corners();

        // Characteristic segments inside faces.
        for f in 0..nf {
            if sign[f] != MIXED {
                continue;
            }
            let vals = fv[f];
            let t = tris[f];
            let mut found: [(PointKey, DVec3); 3] = [(PointKey::Vertex(0), DVec3::ZERO); 3];
            let mut count = 0;
            let mut push = |key: PointKey, p: DVec3, count: &mut usize| {
                if found[..*count].iter().all(|(k, _)| *k != key) && *count < 3 {
                    found[*count] = (key, p);
                    *count += 1;
                }
            };
            for k in 0..3 {
                let (ia, ib) = (t[k], t[(k + 1) % 3]);
                let (fa, fb) = (vals[k], vals[(k + 1) % 3]);
                if fa.abs() <= tol {
                    push(PointKey::Vertex(ia), verts[ia as usize], &mut count);
                }
                if fb.abs() <= tol {
                    push(PointKey::Vertex(ib), verts[ib as usize], &mut count);
                }
                if (fa > tol && fb < -tol) || (fa < -tol && fb > tol) {
                    let e = body.face_edges()[f][k];
                    let [e0, e1] = edges[e as usize].vertices;
                    // Canonical direction e0 -> e1, so the point is the one the edge pass finds.
                    let (g0, g1) = if e0 == ia { (fa, fb) } else { (fb, fa) };
                    let u = g0 / (g0 - g1);
                    let p = verts[e0 as usize].lerp(verts[e1 as usize], u);
                    push(PointKey::OnEdge(e, f as u32), p, &mut count);
                }
            }
            if count < 2 {
                continue;
            }
            // Three points only through rounding: keep the two farthest apart.
            let (i, j) = if count == 3 {
                let d = |a: usize, b: usize| found[a].1.distance_squared(found[b].1);
                let pairs = [(0, 1), (1, 2), (0, 2)];
                *pairs
                    .iter()
                    .max_by(|x, y| d(x.0, x.1).total_cmp(&d(y.0, y.1)))
                    .unwrap_or(&(0, 1))
            } else {
                (0, 1)
            };
            b.segment(
                found[i],
                found[j],
                normals[f],
                SegmentKind::Characteristic { face: f as u32 },
            );
        }

        // Silhouette and border segments on edges.
        for (e, edge) in edges.iter().enumerate() {
            let e = e as u32;
            let [i0, i1] = edge.vertices;
            let (p0, p1) = (verts[i0 as usize], verts[i1 as usize]);
            let k0 = (PointKey::Vertex(i0), p0);
            let k1 = (PointKey::Vertex(i1), p1);
            let [fl, fr] = edge.faces;
            match edge.kind {
                EdgeKind::Border | EdgeKind::NonManifold => {
                    let mut m = normals[fl as usize];
                    if fr != NO_FACE {
                        m += normals[fr as usize];
                    }
                    b.segment(k0, k1, m, SegmentKind::Border { edge: e });
                }
                EdgeKind::Concave if body.is_closed() => {}
                _ => {
                    let (sl, sr) = (sign[fl as usize], sign[fr as usize]);
                    if sl == sr && sl != MIXED && sl != TANGENT {
                        continue; // both faces egress, or both ingress, everywhere
                    }
                    let (tl, tr) = (sl == TANGENT, sr == TANGENT);
                    let m = normals[fl as usize] + normals[fr as usize];
                    if tl || tr {
                        if !(tl && tr) {
                            b.segment(k0, k1, m, SegmentKind::Border { edge: e });
                        }
                        continue;
                    }
                    let c = corners[e as usize];
                    let (vl, vr) = (fv[fl as usize], fv[fr as usize]);
                    let gl = (vl[c[0] as usize], vl[c[1] as usize]);
                    let gr = (vr[c[2] as usize], vr[c[3] as usize]);
                    // Cheap rejection: same strict sign everywhere on the edge.
                    let sl = sign_on(gl, tol);
                    let sr = sign_on(gr, tol);
                    if sl != 0 && sl == sr {
                        continue;
                    }
                    // Split at the characteristic points of both faces.
                    let mut cuts: [(f64, PointKey); 4] = [(0.0, PointKey::Vertex(i0)); 4];
                    let mut nc = 1;
                    for (g, f) in [(gl, fl), (gr, fr)] {
                        if crosses(g, tol) {
                            cuts[nc] = (g.0 / (g.0 - g.1), PointKey::OnEdge(e, f));
                            nc += 1;
                        }
                    }
                    cuts[nc] = (1.0, PointKey::Vertex(i1));
                    nc += 1;
                    cuts[1..nc - 1].sort_by(|x, y| x.0.total_cmp(&y.0));
                    for w in 0..nc - 1 {
                        let (ua, ka) = cuts[w];
                        let (ub, kb) = cuts[w + 1];
                        if ub <= ua || ka == kb {
                            continue;
                        }
                        let um = 0.5 * (ua + ub);
                        let vl = gl.0 + um * (gl.1 - gl.0);
                        let vr = gr.0 + um * (gr.1 - gr.0);
                        if (vl > tol && vr < -tol) || (vl < -tol && vr > tol) {
                            b.segment(
                                (ka, p0.lerp(p1, ua)),
                                (kb, p0.lerp(p1, ub)),
                                m,
                                SegmentKind::Silhouette { edge: e },
                            );
                        }
                    }
                }
            }
        }
        // Reset the vertex map for the next call.
        for &i in &scratch.used_vertices {
            scratch.vertex_point[i as usize] = u32::MAX;
        }
        scratch.used_vertices.clear();
        tol
    }
}

/// Whether an affine function with these end values changes strict sign inside the edge.
#[inline]
fn crosses(g: (f64, f64), tol: f64) -> bool {
    (g.0 > tol && g.1 < -tol) || (g.0 < -tol && g.1 > tol)
}

/// `1` or `-1` when both end values are strictly of that sign, `0` otherwise.
#[inline]
fn sign_on(g: (f64, f64), tol: f64) -> i8 {
    if g.0 > tol && g.1 > tol {
        1
    } else if g.0 < -tol && g.1 < -tol {
        -1
    } else {
        0
    }
}

/// Adds points (shared by key) and oriented segments.
struct Builder<'a> {
    gen: &'a mut Generator,
    verts: &'a [DVec3],
    velocity: &'a Velocity,
    vertex_point: &'a mut [u32],
    used_vertices: &'a mut Vec<u32>,
    edge_points: &'a mut HashMap<(u32, u32), u32>,
}

impl Builder<'_> {
    fn point(&mut self, key: PointKey, p: DVec3) -> u32 {
        let points = &mut self.gen.points;
        match key {
            PointKey::Vertex(i) => {
                let slot = &mut self.vertex_point[i as usize];
                if *slot == u32::MAX {
                    *slot = points.len() as u32;
                    points.push(self.verts[i as usize]);
                    self.used_vertices.push(i);
                }
                *slot
            }
            PointKey::OnEdge(e, f) => *self.edge_points.entry((e, f)).or_insert_with(|| {
                points.push(p);
                (points.len() - 1) as u32
            }),
        }
    }

    /// Adds the segment between `a` and `b` oriented by `(b - a) x v . m > 0`.
    fn segment(&mut self, a: (PointKey, DVec3), b: (PointKey, DVec3), m: DVec3, kind: SegmentKind) {
        if a.1 == b.1 {
            return;
        }
        let v = self.velocity.at(0.5 * (a.1 + b.1));
        let (a, b) = if (b.1 - a.1).cross(v).dot(m) >= 0.0 {
            (a, b)
        } else {
            (b, a)
        };
        let ia = self.point(a.0, a.1);
        let ib = self.point(b.0, b.1);
        self.gen.segments.push(Segment {
            ends: [ia, ib],
            kind,
        });
    }
}
