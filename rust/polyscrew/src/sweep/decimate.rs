//! Fewer triangles where the closed boundary is flat (issue 29: the grid's density everywhere
//! gave 5 times gpytoolbox's triangles on the cube).
//!
//! The contoured mesh has a vertex on every crossed grid edge, whatever the boundary's shape.
//! Where it is flat, a vertex `u` is removed by a half-edge collapse onto a neighbour `w`: the
//! triangles around `u` that hold `w` go, the others have `u` replaced by `w`. No vertex moves
//! and none is added, so every vertex left is one the refinement put on the boundary and the
//! reported bound still holds for all of them. A collapse is taken only when
//! - every triangle around `u`, and every new one, is within [`FLAT_COSINE`] of their
//!   area-weighted mean normal, and no new triangle folds onto a neighbour (normals more than
//!   [`FOLD_COSINE`] apart). Or, where `u` is on a crease (the crease pass made such vertices
//!   dense): its triangles part into two sides, each within [`FLAT_COSINE`] of its own mean
//!   normal, the two more than [`CREASE_SIDES_COSINE`] apart and meeting at two edges of
//!   `u`; then `w` is one of those edges' other ends and every new triangle stays within
//!   [`FLAT_COSINE`] of its side's normal, so the crease keeps its place (a chord of it,
//!   checked as every new edge is) and no triangle comes to span it;
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

use glam::DVec3;

use super::crease::{cross, in_chunks, key, Buckets};
use super::hash::FastMap;
use crate::progress::Span;

/// A vertex is removed only where the triangles around it, before and after, are within this
/// angle (its cosine) of their area-weighted mean normal.
pub const FLAT_COSINE: f64 = 0.984_807_753_012_208; // cos 10 degrees

/// A star that is not flat may still lose its centre along a crease through it when it
/// parts into two sides, each flat (within [`FLAT_COSINE`] of its own mean normal), whose mean
/// normals are further apart than this (twice the flatness: no triangle can then be within it
/// of both).
pub const CREASE_SIDES_COSINE: f64 = 0.939_692_620_785_908_4; // cos 20 degrees

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

/// What a planned collapse comes to.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Verdict {
    /// Not a collapse the mesh allows now (the link condition): not refused, so planned
    /// again in the next round.
    Skip,
    /// Refused (a midpoint off, a fold or a crossing): not planned again onto this `w` until
    /// the star of `u` changes.
    Refuse,
    /// Taken.
    Take,
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

    /// The axis each triangle of the star of `u` must stay within [`FLAT_COSINE`] of, and the
    /// neighbours `u` may collapse onto: where the star is flat, its area-weighted mean normal
    /// and every neighbour; where it folds along a crease through `u` (two flat sides meeting
    /// at two of its edges), each side's own mean normal and the crease's two other ends, so
    /// that a collapse along the crease keeps it (the crease pass made its vertices dense).
    fn sides(&self, u: u32) -> Option<(Vec<DVec3>, Vec<u32>)> {
        let star = &self.around[u as usize];
        if star.len() < 4 {
            return None;
        }
        let normals: Vec<DVec3> = star
            .iter()
            .map(|&i| cross(self.v, self.t[i as usize]))
            .collect();
        let axis = normals.iter().sum::<DVec3>().normalize_or_zero();
        if axis != DVec3::ZERO && normals.iter().all(|&c| along(c, axis)) {
            return Some((vec![axis; star.len()], self.ring(u)));
        }
        // Two sides: the triangles nearer in normal to the first one's or to the one facing
        // farthest from it.
        let first = normals[0].normalize_or_zero();
        let other = normals
            .iter()
            .map(|c| c.normalize_or_zero())
            .min_by(|a, b| a.dot(first).total_cmp(&b.dot(first)))?;
        let side: Vec<bool> = normals
            .iter()
            .map(|c| c.dot(other) > c.dot(first))
            .collect();
        let axes = [false, true].map(|s| {
            normals
                .iter()
                .zip(&side)
                .filter(|&(_, &t)| t == s)
                .map(|(&c, _)| c)
                .sum::<DVec3>()
                .normalize_or_zero()
        });
        let per: Vec<DVec3> = side.iter().map(|&s| axes[s as usize]).collect();
        if axes.contains(&DVec3::ZERO)
            || axes[0].dot(axes[1]) > CREASE_SIDES_COSINE
            || !normals.iter().zip(&per).all(|(&c, &a)| along(c, a))
        {
            return None;
        }
        // The crease: the edges of `u` whose two triangles lie on different sides.
        let mut ends = Vec::with_capacity(2);
        for (&i, &s) in star.iter().zip(&side) {
            for k in self.t[i as usize] {
                if k == u || ends.contains(&k) {
                    continue;
                }
                let across = star
                    .iter()
                    .zip(&side)
                    .any(|(&j, &r)| j != i && r != s && self.t[j as usize].contains(&k));
                if across {
                    ends.push(k);
                }
            }
        }
        (ends.len() == 2).then_some((per, ends))
    }

    /// The neighbour `w` of `u` to collapse `u` onto, with the edge's length: the one whose new
    /// triangles are best shaped, if the star of `u` is flat (or folds along a crease through
    /// `u`, [`Mesh::sides`]) and some neighbour's new triangles keep it so, short enough and
    /// well enough shaped.
    fn target(&self, u: u32, longest: f64, refused: &[u32]) -> Option<(u32, f64)> {
        let (axes, candidates) = self.sides(u)?;
        let star = &self.around[u as usize];
        let floor = star
            .iter()
            .map(|&i| quality(self.v, self.t[i as usize]))
            .fold(LEAST_QUALITY, f64::min);
        let at = |k: u32| self.v[k as usize];
        let axis_of = |i: u32| axes[star.iter().position(|&j| j == i).unwrap_or(0)];
        let mut best: Option<(u32, f64)> = None;
        let mut best_quality = 0.0;
        for w in candidates {
            if refused.contains(&w) {
                continue;
            }
            let mut worst = f64::INFINITY;
            let fits = self.moved(u, w).all(|(i, n)| {
                worst = worst.min(quality(self.v, n));
                worst >= floor
                    && along(cross(self.v, n), axis_of(i))
                    && n.iter().all(|&k| at(k).distance(at(w)) <= longest)
            });
            if fits && worst > best_quality {
                best_quality = worst;
                best = Some((w, at(u).distance(at(w))));
            }
        }
        best
    }

    /// The edges a collapse of `u` onto `w` makes: `w` to each neighbour of `u` not already
    /// one of `w`'s.
    fn new_edges(&self, u: u32, w: u32) -> Vec<(u32, u32)> {
        let ring_w = self.ring(w);
        self.ring(u)
            .into_iter()
            .filter(|&x| x != w && ring_w.binary_search(&x).is_err())
            .map(|x| key(w, x))
            .collect()
    }

    /// Whether the collapse of `u` onto `w` keeps a closed manifold (else [`Verdict::Skip`]),
    /// and its new edges' midpoints near the boundary (`known`: whether each is within the
    /// target), its new triangles unfolded and uncrossed ([`Buckets::crosses`] with `margin`)
    /// (else [`Verdict::Refuse`]).
    fn verdict(
        &self,
        buckets: &Buckets,
        known: &FastMap<(u32, u32), bool>,
        u: u32,
        w: u32,
        margin: f64,
    ) -> Verdict {
        let star = &self.around[u as usize];
        let shared: Vec<u32> = star
            .iter()
            .copied()
            .filter(|&i| self.t[i as usize].contains(&w))
            .collect();
        if shared.len() != 2 {
            return Verdict::Skip;
        }
        // The link condition: `u` and `w` share only their edge's two opposite corners.
        let opposite: Vec<u32> = shared
            .iter()
            .map(|&i| {
                let t = self.t[i as usize];
                t.into_iter().find(|&k| k != u && k != w).unwrap_or(u)
            })
            .collect();
        let ring_w = self.ring(w);
        let common = self
            .ring(u)
            .iter()
            .filter(|x| ring_w.binary_search(x).is_ok())
            .count();
        if common != 2
            || opposite[0] == opposite[1]
            || opposite.iter().any(|&x| self.around[x as usize].len() <= 3)
        {
            return Verdict::Skip;
        }
        if !self
            .new_edges(u, w)
            .iter()
            .all(|e| known.get(e).copied().unwrap_or(false))
        {
            return Verdict::Refuse;
        }
        let new: Vec<[u32; 3]> = self.moved(u, w).map(|(_, n)| n).collect();
        // No fold onto a neighbour across a new triangle's edges (the fan's own are flat).
        let folds = new.iter().any(|&n| {
            let c = cross(self.v, n).normalize_or_zero();
            (0..3).any(|e| {
                let (a, b) = (n[e], n[(e + 1) % 3]);
                self.across(a, b, star).is_some_and(|o| {
                    let d = cross(self.v, self.t[o as usize]).normalize_or_zero();
                    c.dot(d) <= FOLD_COSINE
                })
            })
        });
        if folds || buckets.crosses(self.v, self.t, &new, star, margin, None) {
            Verdict::Refuse
        } else {
            Verdict::Take
        }
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
    let mut refused: FastMap<u32, Vec<u32>> = FastMap::default();
    // Whether each midpoint read so far is within `target` of the boundary, by edge (no vertex
    // moves).
    let mut known: FastMap<(u32, u32), bool> = FastMap::default();
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
        let mut unread: Vec<(u32, u32)> = planned
            .iter()
            .flat_map(|&(u, w)| mesh.new_edges(u, w))
            .filter(|e| !known.contains_key(e))
            .collect();
        unread.sort_unstable();
        unread.dedup();
        let read = |&(a, b): &(u32, u32)| {
            let at = |k: u32| mesh.v[k as usize];
            field(0.5 * (at(a) + at(b)), near[a as usize]).abs() <= target
        };
        known.extend(
            unread
                .iter()
                .copied()
                .zip(in_chunks(&unread, threads, &read)),
        );
        // Take them one after another, each checked against the mesh as it is then.
        let mut removed = 0;
        for (u, w) in planned {
            match mesh.verdict(&buckets, &known, u, w, margin) {
                Verdict::Skip => continue,
                Verdict::Refuse => {
                    refused.entry(u).or_default().push(w);
                    dirty[u as usize] = true;
                    continue;
                }
                Verdict::Take => {}
            }
            let star = mesh.around[u as usize].clone();
            let new: Vec<(u32, [u32; 3])> = mesh.moved(u, w).collect();
            for &i in &star {
                buckets.remove(mesh.v, mesh.t[i as usize], i);
                let t = mesh.t[i as usize];
                if t.contains(&w) {
                    for k in t {
                        if k != u {
                            mesh.around[k as usize].retain(|&j| j != i);
                        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::progress::Progress;

    /// The surface of the box of `[nx, ny, nz]` cells of side `h` (a corner at the origin),
    /// each face a grid of squares split in two, facing out, its vertices shared.
    fn box_mesh(n: [usize; 3], h: f64) -> (Vec<DVec3>, Vec<[u32; 3]>) {
        let mut index: FastMap<[usize; 3], u32> = FastMap::default();
        let mut v = Vec::new();
        let mut vertex = |p: [usize; 3]| {
            *index.entry(p).or_insert_with(|| {
                v.push(DVec3::new(p[0] as f64, p[1] as f64, p[2] as f64) * h);
                (v.len() - 1) as u32
            })
        };
        let mut t = Vec::new();
        for a in 0..3 {
            let (b, c) = ((a + 1) % 3, (a + 2) % 3);
            for side in [0, n[a]] {
                for i in 0..n[b] {
                    for j in 0..n[c] {
                        let corner = |di: usize, dj: usize| {
                            let mut p = [0; 3];
                            (p[a], p[b], p[c]) = (side, i + di, j + dj);
                            p
                        };
                        let [p00, p10, p11, p01] =
                            [corner(0, 0), corner(1, 0), corner(1, 1), corner(0, 1)]
                                .map(&mut vertex);
                        // b x c is along +a: reversed on the low side.
                        for tri in [[p00, p10, p11], [p00, p11, p01]] {
                            t.push(if side == 0 {
                                [tri[0], tri[2], tri[1]]
                            } else {
                                tri
                            });
                        }
                    }
                }
            }
        }
        (v, t)
    }

    /// A box's edges are creases of its surface: a vertex on one (not a corner) goes by a
    /// collapse along it ([`Mesh::sides`]), the creases and corners stay where they were. On a
    /// box of 8 x 4 x 2 cells, its exact signed distance as the field: the mesh stays closed and
    /// facing out, every triangle lies in a face of the box (so the volume is the box's), all 8
    /// corners stay, and fewer than half of the 44 vertices inside its edges (none goes with
    /// the flat collapses alone: their stars fold) and of those inside its faces are left.
    #[test]
    fn vertices_go_along_the_creases_of_a_box_and_the_creases_stay() {
        let (n, h) = ([8, 4, 2], 0.25);
        let size = DVec3::new(n[0] as f64, n[1] as f64, n[2] as f64) * h;
        let (mut v, mut t) = box_mesh(n, h);
        let half = 0.5 * size;
        let field = |x: DVec3, _: [u32; 2]| {
            let q = (x - half).abs() - half;
            q.max(DVec3::ZERO).length() + q.max_element().min(0.0)
        };
        let on = |p: DVec3| -> Vec<usize> {
            (0..3)
                .filter(|&a| p[a].abs() < 1e-12 || (p[a] - size[a]).abs() < 1e-12)
                .collect()
        };
        let count =
            |v: &[DVec3], planes: usize| v.iter().filter(|&&p| on(p).len() == planes).count();
        let (faces_before, edges_before) = (count(&v, 1), count(&v, 2));
        assert_eq!(edges_before, 44);
        let near = vec![[0u32; 2]; v.len()];
        let progress = Progress::new();
        collapse_flat(
            &mut v,
            &near,
            &mut t,
            0.05 * h,
            8.0 * h,
            1e-3 * h,
            2,
            progress.span(0.0, 1.0),
            &field,
        );
        let mut directed: FastMap<(u32, u32), usize> = FastMap::default();
        for tri in &t {
            for e in 0..3 {
                *directed.entry((tri[e], tri[(e + 1) % 3])).or_default() += 1;
            }
        }
        assert!(directed
            .iter()
            .all(|(&(a, b), &k)| k == 1 && directed.get(&(b, a)) == Some(&1)));
        for tri in &t {
            let [p, q, r] = tri.map(|k| v[k as usize]);
            let shared = on(p).into_iter().any(|a| {
                let level = p[a];
                [q, r].iter().all(|s| (s[a] - level).abs() < 1e-12)
            });
            assert!(shared, "{tri:?} spans two faces of the box");
        }
        let volume = crate::sweep::enclosed_volume(&v, &t);
        assert!(
            (volume - size.x * size.y * size.z).abs() < 1e-12,
            "{volume}"
        );
        assert_eq!(count(&v, 3), 8);
        let (faces_after, edges_after) = (count(&v, 1), count(&v, 2));
        println!("inside faces {faces_before} -> {faces_after}, inside edges {edges_before} -> {edges_after}");
        assert!(
            edges_after * 2 < edges_before,
            "{edges_after} of {edges_before} left on the edges"
        );
        assert!(
            faces_after * 2 < faces_before,
            "{faces_after} of {faces_before} left in the faces"
        );
    }
}
