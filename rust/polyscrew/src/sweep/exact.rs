//! The body's exact signed distance, for the last steps of the closed sweep's refinement
//! (issue 29: the trilinear read of the body's grid was more than half the vertex bound).
//!
//! A uniform grid of triangle lists in the body frame: each list cell keeps only the
//! triangles that can be nearest to one of its points, found from the body's distance grid
//! (exact distances at its points, rounded once to float32): with `q` the grid point nearest
//! the cell's centre, `D` its distance and `R` the farthest a point of the cell is from `q`,
//! the triangle `T*` nearest a point `x` of the cell has
//! `dist(q, T*) <= dist(x, T*) + |x - q| = d(x) + |x - q| <= D + 2 R`, so the triangles farther
//! than that from `q` are left out. The sign is that of `(x - c) . n` with `c` the nearest
//! point and `n` the angle-weighted pseudo-normal of the feature holding it (face, edge or
//! vertex: Baerentzen and Aanaes 2005, "Signed distance computation using the angle weighted
//! pseudonormal"), exact for a closed, consistently oriented mesh.
//!
//! A cell whose `q` is beyond the distance grid's band holds no list: its points are at
//! least `band - R` from the surface, and read as `+-band` (the sign of the grid's value).

use std::ops::Range;

use glam::DVec3;

use super::closed::{BodyField, CLOSED_HINT};
use super::Body;
use crate::error::{Error, Result};
use crate::memory::{try_vec, Footprint};

/// Which feature of a triangle holds its point nearest a query: the face, the edge from
/// corner `k` to corner `k + 1` (mod 3), or corner `k`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Feature {
    /// The triangle's interior.
    Face,
    /// The edge from corner `k` to corner `(k + 1) % 3`.
    Edge(u8),
    /// Corner `k`.
    Vertex(u8),
}

/// The point of the triangle `(a, b, c)` nearest `p` and the feature holding it (Ericson,
/// *Real-Time Collision Detection*, 5.1.5: the closest point by Voronoi regions).
pub fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, Feature) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, Feature::Vertex(0));
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, Feature::Vertex(1));
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, Feature::Edge(0));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, Feature::Vertex(2));
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, Feature::Edge(2));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), Feature::Edge(1));
    }
    let denom = 1.0 / (va + vb + vc);
    let (v, w) = (vb * denom, vc * denom);
    (a + ab * v + ac * w, Feature::Face)
}

/// Round-off allowance of the lists' test, relative to the largest coordinate involved.
const ROUNDOFF_REL: f64 = 1e-9;

/// Relative slack of the triangles' bounding spheres in [`ExactField::at`]'s skip test (the
/// distances involved are computed within about `1e-15` of theirs).
const SPHERE_SLACK: f64 = 1e-9;

/// The body's exact signed distance near its surface (see the module documentation).
pub(super) struct ExactField<'a> {
    body: &'a Body,
    /// Angle-weighted pseudo-normals of the body's vertices (unnormalized).
    vertex_normals: Vec<DVec3>,
    /// Pseudo-normals of the body's edges, by [`Body::edges`] index (unnormalized).
    edge_normals: Vec<DVec3>,
    origin: DVec3,
    s: f64,
    n: [usize; 3],
    /// Per list cell: its triangles are `items[start[c]..start[c + 1]]`; a cell without a
    /// list reads `far[c]`.
    start: Vec<u32>,
    items: Vec<u32>,
    far: Vec<f32>,
    /// Per triangle: its corners (kept together: reading them through the vertex indices
    /// made the 2,304-triangle torus's whole sweep 1.3 times slower), and the centre and
    /// radius of a sphere holding it (the radius rounded up), whose distance bounds the
    /// triangle's from below.
    corners: Vec<[DVec3; 3]>,
    spheres: Vec<(DVec3, f64)>,
}

impl<'a> ExactField<'a> {
    /// Lists for cells of side `s` over the box `lo..hi` (body frame), from the body's
    /// distance grid `grid` (exact distances within its band, rounded to float32).
    pub(super) fn new(
        body: &'a Body,
        grid: &BodyField,
        lo: DVec3,
        hi: DVec3,
        s: f64,
        threads: usize,
    ) -> Result<Self> {
        let verts = body.vertices();
        let tris = body.triangles();
        let normals = body.normals();
        let mut vertex_normals = vec![DVec3::ZERO; verts.len()];
        for (t, &nrm) in tris.iter().zip(normals) {
            for k in 0..3 {
                let p = verts[t[k] as usize];
                let (u, w) = (
                    verts[t[(k + 1) % 3] as usize] - p,
                    verts[t[(k + 2) % 3] as usize] - p,
                );
                let angle = u.angle_between(w);
                if angle.is_finite() {
                    vertex_normals[t[k] as usize] += angle * nrm;
                }
            }
        }
        let edge_normals: Vec<DVec3> = body
            .edges()
            .iter()
            .map(|e| {
                e.faces
                    .iter()
                    .filter(|&&f| (f as usize) < normals.len())
                    .map(|&f| normals[f as usize])
                    .sum()
            })
            .collect();
        let n = [
            ((hi.x - lo.x) / s).ceil().max(1.0) as usize,
            ((hi.y - lo.y) / s).ceil().max(1.0) as usize,
            ((hi.z - lo.z) / s).ceil().max(1.0) as usize,
        ];
        let cells = n[0] * n[1] * n[2];
        let band = grid.band;
        let roundoff = ROUNDOFF_REL * (lo.abs().max(hi.abs()).max_element() + band + s);
        // Each cell's test point `q`, and the reach of its list (`D + 2 R`), or NaN (far).
        let mut far: Vec<f32> = try_vec(cells, "the exact distance's lists")?;
        let mut reach: Vec<f64> = try_vec(cells, "the exact distance's lists")?;
        let mut test: Vec<DVec3> = try_vec(cells, "the exact distance's lists")?;
        let half = 0.5 * 3f64.sqrt() * s;
        let mut widest: f64 = 0.0;
        for k in 0..n[2] {
            for j in 0..n[1] {
                for i in 0..n[0] {
                    let c = lo + (DVec3::new(i as f64, j as f64, k as f64) + 0.5) * s;
                    let (v, q) = grid.nearest_node(c);
                    let delta = q.distance(c);
                    test.push(q);
                    // The grid stores the clamp as the float32 of `band`, and reads `band`
                    // itself off the grid (where the last cells' centres can be): either is
                    // far. (With only the first, a last cell off the grid had no list and read
                    // NaN when `band` rounds up to float32.)
                    if v.abs() >= (band as f32 as f64).min(band) {
                        far.push(band.copysign(v) as f32);
                        reach.push(f64::NAN);
                    } else {
                        let r = delta + half;
                        // `D` is the float32 of the exact distance: within `D * 2^-24` of it.
                        let rch = v.abs() * (1.0 + f32::EPSILON as f64) + 2.0 * r + roundoff;
                        widest = widest.max(rch);
                        far.push(f32::NAN);
                        reach.push(rch);
                    }
                }
            }
        }
        let index = |i: usize, j: usize, k: usize| (k * n[1] + j) * n[0] + i;
        let range = |a: f64, b: f64, o: f64, m: usize| -> (usize, usize) {
            let i0 = ((a - o) / s).floor().max(0.0) as usize;
            let i1 = (((b - o) / s).floor().max(0.0) as usize).min(m - 1);
            (i0, i1)
        };
        let grow = DVec3::splat(widest + half);
        // Calls `found(cell, triangle)` for every cell of the layers `ks` whose reach the
        // triangle is within, triangle after triangle: each cell's list is in triangle order.
        let visit = |ks: Range<usize>, found: &mut dyn FnMut(usize, u32)| {
            for (ti, t) in tris.iter().enumerate() {
                let [a, b, c] = t.map(|i| verts[i as usize]);
                let tbox = (a.min(b).min(c), a.max(b).max(c));
                let (tlo, thi) = (tbox.0 - grow, tbox.1 + grow);
                let (k0, k1) = range(tlo.z, thi.z, lo.z, n[2]);
                let (k0, k1) = (k0.max(ks.start), k1.min(ks.end - 1));
                if k0 > k1 {
                    continue;
                }
                let (i0, i1) = range(tlo.x, thi.x, lo.x, n[0]);
                let (j0, j1) = range(tlo.y, thi.y, lo.y, n[1]);
                for k in k0..=k1 {
                    for j in j0..=j1 {
                        for i in i0..=i1 {
                            let cell = index(i, j, k);
                            let rch = reach[cell];
                            if rch.is_nan() {
                                continue;
                            }
                            // The triangle's box first: the triangle is no nearer than it
                            // (most cells of the grown box are, for their own reach, far).
                            let q = test[cell];
                            let outside = (tbox.0 - q).max(q - tbox.1).max(DVec3::ZERO);
                            if outside.length_squared() > rch * rch {
                                continue;
                            }
                            let (x, _) = closest_on_triangle(q, a, b, c);
                            if q.distance_squared(x) <= rch * rch {
                                found(cell, ti as u32);
                            }
                        }
                    }
                }
            }
        };
        // One slab of layers per thread, each counting, then filling, its own cells' lists
        // (contiguous, the cells being layer after layer): the lists do not depend on the
        // count, and no list of pairs is held (on the 100,000-triangle body it held 60
        // million, 485 MB, and their sort took 1.8 s).
        let layer = n[0] * n[1];
        let per = n[2].div_ceil(threads.clamp(1, n[2]));
        let slabs: Vec<Range<usize>> = (0..n[2])
            .step_by(per)
            .map(|k| k..(k + per).min(n[2]))
            .collect();
        let mut counts: Vec<u32> = try_vec(cells, "the exact distance's lists")?;
        counts.resize(cells, 0);
        let visit = &visit;
        std::thread::scope(|scope| {
            for (ks, part) in slabs.iter().cloned().zip(counts.chunks_mut(per * layer)) {
                scope.spawn(move || {
                    let base = ks.start * layer;
                    visit(ks, &mut |cell, _| part[cell - base] += 1);
                });
            }
        });
        let total: usize = counts.iter().map(|&c| c as usize).sum();
        Footprint::of::<u32>(total).check("the exact distance's lists", CLOSED_HINT)?;
        if total > u32::MAX as usize {
            return Err(Error::Limit {
                what: "cell",
                counted: "entries of the exact distance's lists",
                count: total,
                limit: u32::MAX as usize,
                hint: CLOSED_HINT,
            });
        }
        let mut start: Vec<u32> = try_vec(cells + 1, "the exact distance's lists")?;
        start.push(0);
        start.extend(counts.iter().scan(0u32, |sum, &c| {
            *sum += c;
            Some(*sum)
        }));
        drop(counts);
        let mut items: Vec<u32> = try_vec(total, "the exact distance's lists")?;
        items.resize(total, 0);
        let mut rest: &mut [u32] = &mut items;
        let mut parts = Vec::with_capacity(slabs.len());
        for ks in &slabs {
            let (c0, c1) = (ks.start * layer, ks.end * layer);
            let (part, tail) = rest.split_at_mut((start[c1] - start[c0]) as usize);
            parts.push((ks.clone(), part));
            rest = tail;
        }
        let start_ref = &start;
        std::thread::scope(|scope| {
            for (ks, part) in parts {
                scope.spawn(move || {
                    let c0 = ks.start * layer;
                    let first = start_ref[c0];
                    // Where each cell's next triangle goes, within the slab's part.
                    let mut next: Vec<u32> = start_ref[c0..ks.end * layer]
                        .iter()
                        .map(|&at| at - first)
                        .collect();
                    visit(ks, &mut |cell, ti| {
                        let at = &mut next[cell - c0];
                        part[*at as usize] = ti;
                        *at += 1;
                    });
                });
            }
        });
        let mut corners: Vec<[DVec3; 3]> = try_vec(tris.len(), "the exact distance's lists")?;
        corners.extend(tris.iter().map(|t| t.map(|i| verts[i as usize])));
        let mut spheres: Vec<(DVec3, f64)> = try_vec(tris.len(), "the exact distance's lists")?;
        spheres.extend(corners.iter().map(|&[a, b, c]| {
            let centre = (a + b + c) / 3.0;
            let radius = centre
                .distance(a)
                .max(centre.distance(b))
                .max(centre.distance(c));
            (centre, radius * (1.0 + SPHERE_SLACK) + roundoff)
        }));
        Ok(Self {
            body,
            vertex_normals,
            edge_normals,
            origin: lo,
            s,
            n,
            start,
            items,
            far,
            corners,
            spheres,
        })
    }

    /// Each list cell's start in `items`, and the items: what [`ExactField::new`] made (for the
    /// tests).
    #[cfg(test)]
    pub(super) fn lists(&self) -> (&[u32], &[u32]) {
        (&self.start, &self.items)
    }

    /// The signed distance at `p` (body frame) and the outward unit gradient there (the
    /// direction from the nearest point, or the pseudo-normal on the surface), or `None`
    /// and `+-band` off the lists.
    pub(super) fn at(&self, p: DVec3) -> (f64, Option<DVec3>) {
        let u = (p - self.origin) / self.s;
        let [nx, ny, nz] = self.n;
        if !(u.x >= 0.0 && u.y >= 0.0 && u.z >= 0.0) {
            return (f64::INFINITY, None);
        }
        let (i, j, k) = (u.x as usize, u.y as usize, u.z as usize);
        if i >= nx || j >= ny || k >= nz {
            return (f64::INFINITY, None);
        }
        let cell = (k * ny + j) * nx + i;
        let (a, b) = (self.start[cell] as usize, self.start[cell + 1] as usize);
        if a == b {
            return (self.far[cell] as f64, None);
        }
        let tris = self.body.triangles();
        let mut best = (f64::INFINITY, DVec3::ZERO, 0u32, Feature::Face);
        for &t in &self.items[a..b] {
            // A triangle whose sphere is farther than the nearest found cannot be nearer (nor
            // as near: the list's first nearest is kept, so skipping changes nothing).
            let (centre, radius) = self.spheres[t as usize];
            let gap = p.distance(centre) - radius;
            if gap > 0.0 && gap * gap > best.0 * (1.0 + SPHERE_SLACK) {
                continue;
            }
            let [va, vb, vc] = self.corners[t as usize];
            let (x, feature) = closest_on_triangle(p, va, vb, vc);
            let d2 = p.distance_squared(x);
            if d2 < best.0 {
                best = (d2, x, t, feature);
            }
        }
        let (d2, x, t, feature) = best;
        let pseudo = match feature {
            Feature::Face => self.body.normals()[t as usize],
            Feature::Edge(k) => {
                self.edge_normals[self.body.face_edges()[t as usize][k as usize] as usize]
            }
            Feature::Vertex(k) => self.vertex_normals[tris[t as usize][k as usize] as usize],
        };
        let d = d2.sqrt();
        let away = p - x;
        let inside = away.dot(pseudo) < 0.0;
        let gradient = if d > 0.0 {
            if inside {
                -away / d
            } else {
                away / d
            }
        } else {
            pseudo.normalize_or_zero()
        };
        (if inside { -d } else { d }, Some(gradient))
    }
}
