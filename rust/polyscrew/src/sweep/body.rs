//! The moving body: a validated, consistently oriented triangle mesh in its local frame,
//! with unit face normals and edge adjacency (which faces meet at each edge, and whether the
//! edge is convex, flat or concave).
//!
//! Rossignac-Kim (*Computing and visualizing pose-interpolating 3D motions*, section "Computing the characteristic curves and silhouette edges"):
//! only convex edges can be silhouette edges; concave edges are not processed; a
//! non-manifold edge may be split into pseudo-manifold edges. Here an edge with one face
//! (the border of an open mesh) or with more than two faces or two faces of inconsistent
//! orientation is marked so that the generator keeps it whole: a superset of the generator
//! only adds faces inside the swept region.

use glam::DVec3;

use crate::error::{At, Error, Result};
use crate::memory::Footprint;

/// `sum a . (b x c) / 6` over the triangles, the corners taken from the first triangle's first
/// (less round-off far from the origin): the enclosed volume of a closed, consistently
/// oriented mesh, negative when it is inside out; 0 with no triangles.
pub fn enclosed_volume(vertices: &[DVec3], triangles: &[[u32; 3]]) -> f64 {
    let Some(first) = triangles.first() else {
        return 0.0;
    };
    let o = vertices[first[0] as usize];
    triangles
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|k| vertices[k as usize] - o);
            a.dot(b.cross(c))
        })
        .sum::<f64>()
        / 6.0
}

/// The square of the longest edge of the triangle `[a, b, c]`.
pub(super) fn longest_edge_squared([a, b, c]: [DVec3; 3]) -> f64 {
    (b - a)
        .length_squared()
        .max((c - b).length_squared())
        .max((a - c).length_squared())
}

/// A triangle whose cross product `|(b - a) x (c - a)|` is at most this fraction of the
/// square of its longest edge (its smallest angle below about `1e-12` radians, or a repeated
/// vertex) has no normal and is rejected as zero-area.
pub const ZERO_AREA_REL: f64 = 1e-12;

/// Two faces meeting at an edge are coplanar (the edge is flat) when the far vertex of one
/// lies within this fraction of its distance from the edge of the other's plane.
pub const FLAT_REL: f64 = 1e-9;

/// The working range of the body's vertex coordinates: `|x| <= MAX_VERTEX_COORDINATE`.
///
/// Why `1e75` (not the poses' `1e150`): a face's area test squares the cross product of two
/// edges, a fourth power of coordinates: `3 (2 (2e75)^2)^2 ~ 2e302`. Poses may still move the
/// body anywhere within `1e150`.
pub const MAX_VERTEX_COORDINATE: f64 = 1e75;

/// No face on this side of an edge (border edges have one face).
pub const NO_FACE: u32 = u32::MAX;

/// Bytes a [`Body`] and the sweep's per-body buffers hold per vertex and per triangle, with
/// room for the caller's copy of the input (the Python module's: 24 per vertex and per
/// triangle): vertices (24), remap and scratch (40) per vertex; triangles, normals, edges and
/// their half-edge sort, face values and flags (about 200) per triangle.
pub const BODY_BYTES_PER_VERTEX: usize = 96;

/// See [`BODY_BYTES_PER_VERTEX`].
pub const BODY_BYTES_PER_TRIANGLE: usize = 320;

/// How to ask the sweep for less memory.
pub const SWEEP_HINT: &str = "use fewer steps, fewer poses or a coarser mesh";

/// What a [`Body`] of `vertices` and `triangles` and the sweep's buffers for it hold.
pub fn body_footprint(vertices: usize, triangles: usize) -> Footprint {
    Footprint::bytes(BODY_BYTES_PER_VERTEX).times(vertices)
        + Footprint::bytes(BODY_BYTES_PER_TRIANGLE).times(triangles)
}

/// How the faces at an edge meet.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum EdgeKind {
    /// Two consistently oriented faces with the dihedral angle below pi inside (a ridge).
    Convex,
    /// Two consistently oriented coplanar faces.
    Flat,
    /// Two consistently oriented faces meeting in a valley (dihedral angle above pi).
    Concave,
    /// One face only: the border of an open mesh.
    Border,
    /// More than two faces, or two faces that traverse the edge in the same direction.
    NonManifold,
}

/// An edge of the body: its two vertices (`vertices[0] < vertices[1]`) and the faces on each
/// side. `faces[0]` traverses the edge from `vertices[0]` to `vertices[1]` when the edge is
/// manifold; `faces[1]` is [`NO_FACE`] for a border edge.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Edge {
    /// The end vertices, smaller index first.
    pub vertices: [u32; 2],
    /// The incident faces (the first two for a non-manifold edge).
    pub faces: [u32; 2],
    /// How the faces meet.
    pub kind: EdgeKind,
}

/// A triangle mesh ready to be swept: vertices in the body's local frame, triangles wound
/// counter-clockwise seen from outside (a closed mesh given inside out is turned around),
/// unit outward normals and edges.
#[derive(Debug, Clone)]
pub struct Body {
    vertices: Vec<DVec3>,
    triangles: Vec<[u32; 3]>,
    normals: Vec<DVec3>,
    edges: Vec<Edge>,
    face_edges: Vec<[u32; 3]>,
    edge_corners: Vec<[u8; 4]>,
    closed: bool,
    reoriented: bool,
    extent: f64,
}

impl Body {
    /// Validates a mesh and builds its normals and edges.
    ///
    /// The mesh is closed when every edge is manifold (two faces, opposite directions); a
    /// closed mesh whose signed volume `sum a . (b x c) / 6` is negative is inside out and is
    /// turned around (every triangle's winding reversed, see [`Body::is_reoriented`]).
    ///
    /// # Errors
    /// - [`Error::Degenerate`] (`"vertices"`, `"triangles"`) when either is empty,
    ///   [`Error::Limit`] when either has more than `2^32 - 2` entries;
    /// - [`Error::NotFinite`] (`"vertex"`, index) for a NaN or infinite coordinate;
    /// - [`Error::Index`] (`"triangles"`) naming the triangle, for an index that is negative
    ///   or not below the vertex count, and [`Error::Degenerate`] for a zero-area triangle
    ///   (see [`ZERO_AREA_REL`]).
    pub fn new(vertices: &[DVec3], triangles: &[[i64; 3]]) -> Result<Self> {
        if vertices.is_empty() {
            return Err(Error::Degenerate {
                what: "vertices",
                at: None,
                reason: "the mesh has no vertices",
            });
        }
        if triangles.is_empty() {
            return Err(Error::Degenerate {
                what: "triangles",
                at: None,
                reason: "the mesh has no triangles",
            });
        }
        if vertices.len() > (u32::MAX - 1) as usize || triangles.len() > (u32::MAX - 1) as usize {
            return Err(Error::Limit {
                what: "vertices",
                counted: "vertices or triangles",
                count: vertices.len().max(triangles.len()),
                limit: (u32::MAX - 1) as usize,
                hint: "",
            });
        }
        if let Some(i) = vertices.iter().position(|v| !v.is_finite()) {
            return Err(Error::NotFinite {
                what: "vertex",
                index: i,
            });
        }
        if let Some(i) = vertices
            .iter()
            .position(|v| v.abs().max_element() > MAX_VERTEX_COORDINATE)
        {
            return Err(Error::OutOfRange {
                what: "vertex",
                index: i,
                value: vertices[i].abs().max_element(),
                limit: MAX_VERTEX_COORDINATE,
            });
        }
        body_footprint(vertices.len(), triangles.len()).check("the swept body", SWEEP_HINT)?;
        let n = vertices.len();
        let mut tris = Vec::with_capacity(triangles.len());
        let mut normals = Vec::with_capacity(triangles.len());
        for (i, t) in triangles.iter().enumerate() {
            let mut idx = [0u32; 3];
            for (k, &v) in t.iter().enumerate() {
                if v < 0 || v as u64 >= n as u64 {
                    return Err(Error::Index {
                        what: "triangles",
                        item: "vertex",
                        at: Some(At::new("triangle", i)),
                        index: v,
                        len: n,
                    });
                }
                idx[k] = v as u32;
            }
            let [a, b, c] = idx.map(|k| vertices[k as usize]);
            let cross = (b - a).cross(c - a);
            let longest = longest_edge_squared([a, b, c]);
            if idx[0] == idx[1]
                || idx[1] == idx[2]
                || idx[2] == idx[0]
                || cross.length() <= ZERO_AREA_REL * longest
            {
                return Err(Error::Degenerate {
                    what: "triangles",
                    at: Some(At::new("triangle", i)),
                    reason: "has zero area",
                });
            }
            tris.push(idx);
            normals.push(cross.normalize());
        }
        let (min, max) = vertices
            .iter()
            .fold((vertices[0], vertices[0]), |(lo, hi), &v| {
                (lo.min(v), hi.max(v))
            });
        let mut body = Self {
            vertices: vertices.to_vec(),
            triangles: tris,
            normals,
            edges: Vec::new(),
            face_edges: Vec::new(),
            edge_corners: Vec::new(),
            closed: false,
            reoriented: false,
            extent: (max - min).length(),
        };
        body.build_edges();
        if body.closed && body.signed_volume() < 0.0 {
            for t in &mut body.triangles {
                t.swap(1, 2);
            }
            for nrm in &mut body.normals {
                *nrm = -*nrm;
            }
            body.reoriented = true;
            body.build_edges();
        }
        Ok(body)
    }

    /// Edge adjacency by sorting the `3 T` directed half-edges by their undirected key.
    fn build_edges(&mut self) {
        let mut half: Vec<(u64, u32, u8)> = Vec::with_capacity(3 * self.triangles.len());
        for (f, t) in self.triangles.iter().enumerate() {
            for k in 0..3u8 {
                let (a, b) = (t[k as usize], t[(k as usize + 1) % 3]);
                let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
                half.push((key, f as u32, k));
            }
        }
        half.sort_unstable();
        let mut edges = Vec::with_capacity(half.len() / 2 + 1);
        let mut face_edges = vec![[0u32; 3]; self.triangles.len()];
        let mut closed = true;
        let mut i = 0;
        while i < half.len() {
            let key = half[i].0;
            let mut j = i + 1;
            while j < half.len() && half[j].0 == key {
                j += 1;
            }
            let v0 = (key >> 32) as u32;
            let v1 = key as u32;
            let id = edges.len() as u32;
            let forward = |(_, f, k): (u64, u32, u8)| self.triangles[f as usize][k as usize] == v0;
            let edge = match j - i {
                1 => {
                    closed = false;
                    Edge {
                        vertices: [v0, v1],
                        faces: [half[i].1, NO_FACE],
                        kind: EdgeKind::Border,
                    }
                }
                2 => {
                    let (h0, h1) = (half[i], half[i + 1]);
                    let (fw0, fw1) = (forward(h0), forward(h1));
                    if fw0 == fw1 {
                        closed = false;
                        Edge {
                            vertices: [v0, v1],
                            faces: [h0.1, h1.1],
                            kind: EdgeKind::NonManifold,
                        }
                    } else {
                        let (l, r) = if fw0 { (h0, h1) } else { (h1, h0) };
                        Edge {
                            vertices: [v0, v1],
                            faces: [l.1, r.1],
                            kind: self.dihedral(l.1, r.1, (r.2 as usize + 2) % 3, v0),
                        }
                    }
                }
                _ => {
                    closed = false;
                    Edge {
                        vertices: [v0, v1],
                        faces: [half[i].1, half[i + 1].1],
                        kind: EdgeKind::NonManifold,
                    }
                }
            };
            for h in &half[i..j] {
                face_edges[h.1 as usize][h.2 as usize] = id;
            }
            edges.push(edge);
            i = j;
        }
        let slot = |f: u32, v: u32| -> u8 {
            if f == NO_FACE {
                return 0;
            }
            let t = self.triangles[f as usize];
            if t[0] == v {
                0
            } else if t[1] == v {
                1
            } else {
                2
            }
        };
        self.edge_corners = edges
            .iter()
            .map(|e| {
                let [v0, v1] = e.vertices;
                let [f0, f1] = e.faces;
                [slot(f0, v0), slot(f0, v1), slot(f1, v0), slot(f1, v1)]
            })
            .collect();
        self.edges = edges;
        self.face_edges = face_edges;
        self.closed = closed;
    }

    /// Convex, flat or concave: where the far vertex `c` of the right face lies against the
    /// plane of the left face, `s = n_L . (c - a)` (`s < 0`: below, a ridge).
    fn dihedral(&self, left: u32, right: u32, far_slot: usize, a: u32) -> EdgeKind {
        let c = self.vertices[self.triangles[right as usize][far_slot] as usize];
        let a = self.vertices[a as usize];
        let d = c - a;
        let s = self.normals[left as usize].dot(d);
        if s.abs() <= FLAT_REL * d.length() {
            EdgeKind::Flat
        } else if s < 0.0 {
            EdgeKind::Convex
        } else {
            EdgeKind::Concave
        }
    }

    /// The body's [`enclosed_volume`]: negative when it is inside out.
    pub fn signed_volume(&self) -> f64 {
        enclosed_volume(&self.vertices, &self.triangles)
    }

    /// The vertices (body frame).
    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    /// The triangles, wound counter-clockwise seen from outside for a closed mesh.
    pub fn triangles(&self) -> &[[u32; 3]] {
        &self.triangles
    }

    /// Unit face normals `(b - a) x (c - a) / |...|`, outward for a closed mesh.
    pub fn normals(&self) -> &[DVec3] {
        &self.normals
    }

    /// The edges.
    pub fn edges(&self) -> &[Edge] {
        &self.edges
    }

    /// For each triangle, its edges: `face_edges()[f][k]` joins corners `k` and `k + 1`.
    pub fn face_edges(&self) -> &[[u32; 3]] {
        &self.face_edges
    }

    /// For each edge, the corners (0, 1 or 2) of its end vertices in its faces:
    /// `[v0 in faces[0], v1 in faces[0], v0 in faces[1], v1 in faces[1]]`.
    pub fn edge_corners(&self) -> &[[u8; 4]] {
        &self.edge_corners
    }

    /// Whether every edge has exactly two consistently oriented faces.
    pub fn is_closed(&self) -> bool {
        self.closed
    }

    /// Whether the mesh was closed and inside out, and its triangles were turned around.
    pub fn is_reoriented(&self) -> bool {
        self.reoriented
    }

    /// The diagonal of the vertices' bounding box.
    pub fn extent(&self) -> f64 {
        self.extent
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit cube (`sweep::tests::cuboid` of `(1, 1, 1)`).
    fn cube() -> (Vec<DVec3>, Vec<[i64; 3]>) {
        crate::sweep::tests::cuboid(DVec3::ONE)
    }

    #[test]
    fn cube_edges() {
        let (v, t) = cube();
        let b = Body::new(&v, &t).unwrap();
        assert!(b.is_closed());
        assert!(!b.is_reoriented());
        assert!((b.signed_volume() - 1.0).abs() < 1e-15);
        assert_eq!(b.edges().len(), 18);
        let convex = b
            .edges()
            .iter()
            .filter(|e| e.kind == EdgeKind::Convex)
            .count();
        let flat = b
            .edges()
            .iter()
            .filter(|e| e.kind == EdgeKind::Flat)
            .count();
        assert_eq!((convex, flat), (12, 6));
        // Inside out: turned around, same edges.
        let inv: Vec<[i64; 3]> = t.iter().map(|&[a, b, c]| [a, c, b]).collect();
        let bi = Body::new(&v, &inv).unwrap();
        assert!(bi.is_reoriented());
        assert!((bi.signed_volume() - 1.0).abs() < 1e-15);
        let convex = bi
            .edges()
            .iter()
            .filter(|e| e.kind == EdgeKind::Convex)
            .count();
        assert_eq!(convex, 12);
    }

    #[test]
    fn errors() {
        let (v, t) = cube();
        assert!(matches!(
            Body::new(&[], &t),
            Err(Error::Degenerate {
                what: "vertices",
                ..
            })
        ));
        assert!(matches!(
            Body::new(&v, &[]),
            Err(Error::Degenerate {
                what: "triangles",
                ..
            })
        ));
        let mut bad = v.clone();
        bad[5].y = f64::NAN;
        assert_eq!(
            Body::new(&bad, &t).unwrap_err(),
            Error::NotFinite {
                what: "vertex",
                index: 5
            }
        );
        let mut tt = t.clone();
        tt[3][1] = 8;
        let e = Body::new(&v, &tt).unwrap_err().to_string();
        assert!(e.contains("triangle 3") && e.contains("vertex 8"), "{e}");
        tt[3][1] = -1;
        assert!(Body::new(&v, &tt)
            .unwrap_err()
            .to_string()
            .contains("triangle 3"));
        let mut tt = t.clone();
        tt[7] = [0, 1, 1];
        let e = Body::new(&v, &tt).unwrap_err().to_string();
        assert!(e.contains("triangle 7") && e.contains("zero area"), "{e}");
        // Collinear.
        let mut vv = v.clone();
        vv.push(DVec3::new(0.5, 0.0, 0.0));
        let mut tt = t.clone();
        tt.push([0, 8, 1]);
        let e = Body::new(&vv, &tt).unwrap_err().to_string();
        assert!(e.contains("triangle 12") && e.contains("zero area"), "{e}");
    }

    #[test]
    fn open_and_non_manifold() {
        let (v, t) = cube();
        let b = Body::new(&v, &t[..11]).unwrap();
        assert!(!b.is_closed());
        assert_eq!(
            b.edges()
                .iter()
                .filter(|e| e.kind == EdgeKind::Border)
                .count(),
            3
        );
        let mut tt = t.clone();
        tt.push([0, 2, 7]);
        let b = Body::new(&v, &tt).unwrap();
        assert!(!b.is_closed());
        assert!(b.edges().iter().any(|e| e.kind == EdgeKind::NonManifold));
    }
}
