//! Fewer triangles where the closed boundary is flat (issue 29: the grid's density everywhere
//! gave 5 times gpytoolbox's triangles on the cube).
//!
//! The contoured mesh has a vertex on every crossed grid edge, whatever the boundary's shape.
//! Where it is flat, a vertex `u` is removed by a half-edge collapse onto a neighbour `w`: the
//! triangles around `u` that hold `w` go, the others have `u` replaced by `w`. No vertex moves
//! and none is added, so every vertex left is one the refinement put on the boundary and the
//! reported bound still holds for all of them. A collapse is taken only when
//! - every triangle around `u`, and every new one, is within [`FLAT_COSINE`] of their
//!   area-weighted mean normal (so creases, which the crease pass refined, stay), and no new
//!   triangle folds onto a neighbour (normals more than [`FOLD_COSINE`] apart);
//! - the exact field at the midpoint of every new edge is within `target` of zero. A flat
//!   triangle's distance from a sheet smooth across it is a quadratic that vanishes at the
//!   corners (up to the vertices' own distance), at most 4/3 of its largest value at the
//!   edges' midpoints; across a kink of the sheet (flatter than [`FLAT_COSINE`]) it is linear
//!   on either side, largest where the kink meets an edge, at most twice that edge's midpoint
//!   value. So the new faces are within about twice `target` of the boundary, plus the
//!   vertices' bound;
//! - no new edge is longer than `longest`, and the new triangles are no worse shaped than
//!   [`LEAST_QUALITY`] (or the worst triangle they replace);
//! - the mesh stays a closed manifold (the link condition: `u` and `w` share exactly the two
//!   neighbours of their edge's triangles, each of which keeps three or more neighbours), and
//!   no new triangle crosses or touches the mesh ([`Buckets::crosses`], as for the crease
//!   splits).
//!
//! Rounds plan collapses at vertices none of which are neighbours (their triangles are then
//! disjoint), the shortest collapsing edge first (a collapse refused is not planned again
//! until the vertex's triangles change); read the new midpoints on every core (each
//! edge once: no vertex moves); then take them one after another, checking the mesh as it is.
//! The result does not depend on the thread count.

use std::collections::HashMap;

use glam::DVec3;

use super::crease::{cross, in_chunks, key, Buckets};
use crate::progress::Span;

/// A vertex is removed only where the triangles around it, before and after, are within this
/// angle (its cosine) of their area-weighted mean normal.
pub const FLAT_COSINE: f64 = 0.984_807_753_012_208; // cos 10 degrees

/// A new triangle and a neighbour across one of its edges must face within this of each
/// other (their normals' dot product above it).
pub const FOLD_COSINE: f64 = -0.5;

/// The shape below which a new triangle is refused (unless the triangles replaced were as
/// bad): `4 sqrt(3) area / (sum of squared edges)`, 1 for an equilateral triangle.
pub const LEAST_QUALITY: f64 = 0.25;

/// Rounds of collapses at most.
pub const DECIMATE_ROUNDS: usize = 16;

/// Rounds stop once one removes fewer than this fraction of the vertices left.
const LEAST_GAIN: f64 = 0.002;

/// `4 sqrt(3) area / (sum of squared edges)`: 1 for an equilateral triangle, 0 for a flat one.
fn quality(v: &[DVec3], t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|i| v[i as usize]);
    let s = a.distance_squared(b) + b.distance_squared(c) + c.distance_squared(a);
    if s > 0.0 {
        2.0 * 3f64.sqrt() * cross(v, t).length() / s
    } else {
        0.0
    }
}

/// Whether `c` (a triangle's cross product) is within [`FLAT_COSINE`] of the unit `axis`.
fn along(c: DVec3, axis: DVec3) -> bool {
    let l = c.length();
    l > 0.0 && c.dot(axis) >= FLAT_COSINE * l
}

/// The mesh with each vertex's triangles.
struct Mesh<'a> {
    v: &'a [DVec3],
    t: &'a mut Vec<[u32; 3]>,
    around: Vec<Vec<u32>>,
}

impl Mesh<'_> {
    /// The neighbours of `u`, sorted.
    fn ring(&self, u: u32) -> Vec<u32> {
        let mut ring: Vec<u32> = self.around[u as usize]
            .iter()
            .flat_map(|&i| self.t[i as usize])
            .filter(|&k| k != u)
            .collect();
        ring.sort_unstable();
        ring.dedup();
        ring
    }

    /// The triangle of `u` replaced by `w`, for each triangle around `u` not holding `w`.
    fn moved(&self, u: u32, w: u32) -> impl Iterator<Item = (u32, [u32; 3])> + '_ {
        self.around[u as usize]
            .iter()
            .filter(move |&&i| !self.t[i as usize].contains(&w))
            .map(move |&i| (i, self.t[i as usize].map(|k| if k == u { w } else { k })))
    }

    /// The neighbour `w` of `u` to collapse `u` onto, with the edge's length: the one whose new
    /// triangles are best shaped, if the star of `u` is flat and some neighbour's new
    /// triangles keep it flat, short enough and well enough shaped.
    fn target(&self, u: u32, longest: f64, refused: &[u32]) -> Option<(u32, f64)> {
        let star = &self.around[u as usize];
        if star.len() < 4 {
            return None;
        }
        let axis = star
            .iter()
            .map(|&i| cross(self.v, self.t[i as usize]))
            .sum::<DVec3>()
            .normalize_or_zero();
        if axis == DVec3::ZERO
            || !star
                .iter()
                .all(|&i| along(cross(self.v, self.t[i as usize]), axis))
        {
            return None;
        }
        let floor = star
            .iter()
            .map(|&i| quality(self.v, self.t[i as usize]))
            .fold(LEAST_QUALITY, f64::min);
        let at = |k: u32| self.v[k as usize];
        let mut best: Option<(u32, f64)> = None;
        let mut best_quality = 0.0;
        for w in self.ring(u) {
            if refused.contains(&w) {
                continue;
            }
            let mut worst = f64::INFINITY;
            let fits = self.moved(u, w).all(|(_, n)| {
                worst = worst.min(quality(self.v, n));
                worst >= floor
                    && along(cross(self.v, n), axis)
                    && n.iter().all(|&k| at(k).distance(at(w)) <= longest)
            });
            if fits && worst > best_quality {
                best_quality = worst;
                best = Some((w, at(u).distance(at(w))));
            }
        }
        best
    }

    /// The triangle other than those of `skip` on the edge `(a, b)`.
    fn across(&self, a: u32, b: u32, skip: &[u32]) -> Option<u32> {
        self.around[a as usize]
            .iter()
            .copied()
            .find(|&i| !skip.contains(&i) && self.t[i as usize].contains(&b))
    }
}

/// Removes vertices where the closed mesh (`vertices`, `triangles`) is flat (see the module
/// documentation); `near`: each vertex's motion samples. `field(x, near)` is the region's exact
/// field at `x`, `near` the motion samples near which to look first; a new edge's midpoint
/// within `target` of zero, new edges no longer than `longest`; `margin`: the touch distance
/// of [`Buckets::crosses`]. The midpoints are read on `threads` threads; the result does not
/// depend on the count. `span` follows the rounds; once the computation is asked to stop, no
/// round starts (the caller checks).
// The mesh (three parts), three lengths, how to run (threads, progress) and the field.
#[allow(clippy::too_many_arguments)]
pub fn collapse_flat(
    vertices: &mut Vec<DVec3>,
    near: &[[u32; 2]],
    triangles: &mut Vec<[u32; 3]>,
    target: f64,
    longest: f64,
    margin: f64,
    threads: usize,
    span: Span<'_>,
    field: &(dyn Fn(DVec3, [u32; 2]) -> f64 + Sync),
) {
    let count = vertices.len();
    let mut around = vec![Vec::with_capacity(6); count];
    for (i, t) in triangles.iter().enumerate() {
        for &k in t {
            around[k as usize].push(i as u32);
        }
    }
    let side = triangles
        .iter()
        .flat_map(|t| (0..3).map(move |e| (t[e], t[(e + 1) % 3])))
        .map(|(a, b)| vertices[a as usize].distance(vertices[b as usize]))
        .fold(0.0, f64::max);
    let mut buckets = Buckets::with_side(vertices, triangles, side);
    let mut mesh = Mesh {
        v: vertices,
        t: triangles,
        around,
    };
    let mut gone = vec![false; count];
    let mut left = count;
    // Each vertex's collapse as last found, and whether its triangles changed since.
    let mut targets: Vec<Option<(u32, f64)>> = vec![None; count];
    let mut dirty = vec![true; count];
    // The neighbours a vertex's collapse onto was refused (midpoints off, a crossing, a fold),
    // while its star stays.
    let mut refused: HashMap<u32, Vec<u32>> = HashMap::new();
    // Midpoint values read so far, by edge (no vertex moves).
    let mut known: HashMap<(u32, u32), f64> = HashMap::new();
    for round in 0..DECIMATE_ROUNDS {
        if span.is_cancelled() {
            break;
        }
        span.advance(round as f64 / DECIMATE_ROUNDS as f64);
        // Plan: each vertex's collapse, the shortest first, at vertices no two of which are
        // neighbours.
        let stale: Vec<u32> = (0..count as u32)
            .filter(|&u| !gone[u as usize] && dirty[u as usize])
            .collect();
        let none = Vec::new();
        let found = in_chunks(&stale, threads, &|&u| {
            mesh.target(u, longest, refused.get(&u).unwrap_or(&none))
        });
        for (&u, t) in stale.iter().zip(found) {
            targets[u as usize] = t;
            dirty[u as usize] = false;
        }
        let mut order: Vec<(f64, u32, u32)> = targets
            .iter()
            .enumerate()
            .filter(|&(u, _)| !gone[u])
            .filter_map(|(u, t)| t.map(|(w, length)| (length, u as u32, w)))
            .collect();
        order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
        // (No two centres neighbours: their stars, the triangles a collapse changes, are
        // disjoint.)
        let mut centre = vec![false; count];
        let mut planned = Vec::new();
        for (_, u, w) in order {
            if mesh.ring(u).iter().any(|&k| centre[k as usize]) {
                continue;
            }
            centre[u as usize] = true;
            planned.push((u, w));
        }
        // The new edges' midpoints, each read once, on every core.
        let new_edges = |mesh: &Mesh<'_>, u: u32, w: u32| -> Vec<(u32, u32)> {
            let ring_w = mesh.ring(w);
            mesh.ring(u)
                .into_iter()
                .filter(|&x| x != w && ring_w.binary_search(&x).is_err())
                .map(|x| key(w, x))
                .collect()
        };
        let mut unread: Vec<(u32, u32)> = planned
            .iter()
            .flat_map(|&(u, w)| new_edges(&mesh, u, w))
            .filter(|e| !known.contains_key(e))
            .collect();
        unread.sort_unstable();
        unread.dedup();
        let read = |&(a, b): &(u32, u32)| {
            let at = |k: u32| mesh.v[k as usize];
            field(0.5 * (at(a) + at(b)), near[a as usize])
        };
        known.extend(
            unread
                .iter()
                .copied()
                .zip(in_chunks(&unread, threads, &read)),
        );
        // Take them, checking the mesh as it is now.
        let mut removed = 0;
        for (u, w) in planned {
            let star = mesh.around[u as usize].clone();
            let shared: Vec<u32> = star
                .iter()
                .copied()
                .filter(|&i| mesh.t[i as usize].contains(&w))
                .collect();
            if shared.len() != 2 {
                continue;
            }
            // The link condition: `u` and `w` share only their edge's two opposite corners.
            let opposite: Vec<u32> = shared
                .iter()
                .map(|&i| {
                    let t = mesh.t[i as usize];
                    t.into_iter().find(|&k| k != u && k != w).unwrap_or(u)
                })
                .collect();
            let ring_w = mesh.ring(w);
            let common = mesh
                .ring(u)
                .iter()
                .filter(|x| ring_w.binary_search(x).is_ok())
                .count();
            if common != 2
                || opposite[0] == opposite[1]
                || opposite.iter().any(|&x| mesh.around[x as usize].len() <= 3)
            {
                continue;
            }
            let edges = new_edges(&mesh, u, w);
            let mut refuse = |u: u32, w: u32| {
                refused.entry(u).or_default().push(w);
                dirty[u as usize] = true;
            };
            if !edges
                .iter()
                .all(|e| known.get(e).is_some_and(|g| g.abs() <= target))
            {
                refuse(u, w);
                continue;
            }
            let new: Vec<(u32, [u32; 3])> = mesh.moved(u, w).collect();
            // No fold onto a neighbour across a new triangle's edges (the fan's own are flat).
            let folds = new.iter().any(|&(_, n)| {
                let c = cross(mesh.v, n).normalize_or_zero();
                (0..3).any(|e| {
                    let (a, b) = (n[e], n[(e + 1) % 3]);
                    mesh.across(a, b, &star).is_some_and(|o| {
                        let d = cross(mesh.v, mesh.t[o as usize]).normalize_or_zero();
                        c.dot(d) <= FOLD_COSINE
                    })
                })
            });
            let tris: Vec<[u32; 3]> = new.iter().map(|&(_, n)| n).collect();
            if folds || buckets.crosses(mesh.v, mesh.t, &tris, &star, margin, None) {
                refuse(u, w);
                continue;
            }
            for &i in &star {
                buckets.remove(mesh.v, mesh.t[i as usize], i);
            }
            for &i in &shared {
                for k in mesh.t[i as usize] {
                    if k != u {
                        mesh.around[k as usize].retain(|&j| j != i);
                    }
                }
            }
            for (i, n) in new {
                mesh.t[i as usize] = n;
                buckets.insert(mesh.v, n, i);
                mesh.around[w as usize].push(i);
            }
            // The stars changed: `w`'s and its neighbours' (the ring of `u`, `w` among them).
            for k in mesh.ring(w) {
                dirty[k as usize] = true;
                refused.remove(&k);
            }
            dirty[w as usize] = true;
            refused.remove(&w);
            mesh.around[u as usize].clear();
            gone[u as usize] = true;
            removed += 1;
        }
        left -= removed;
        if (removed as f64) < LEAST_GAIN * left as f64 || removed == 0 {
            break;
        }
    }
    if !span.is_cancelled() {
        span.advance(1.0);
    }
    // The vertices and triangles left, in their order (a valid mesh after a stop too).
    let dead: Vec<bool> = mesh
        .t
        .iter()
        .map(|t| t.iter().any(|&k| gone[k as usize]))
        .collect();
    let mut index = vec![u32::MAX; count];
    let mut kept = 0u32;
    for (k, slot) in index.iter_mut().enumerate() {
        if !gone[k] {
            *slot = kept;
            vertices[kept as usize] = vertices[k];
            kept += 1;
        }
    }
    vertices.truncate(kept as usize);
    let mut i = 0;
    triangles.retain(|_| {
        i += 1;
        !dead[i - 1]
    });
    for t in triangles.iter_mut() {
        *t = t.map(|k| index[k as usize]);
    }
}
