//! Creases of the closed boundary: where two smooth sheets of the swept boundary meet at an
//! angle (an edge of the body swept, or where one part of the motion's envelope meets
//! another), a triangle of the contoured mesh spans both sheets and its inside cuts the corner
//! by up to a third of a cell, though its vertices are on the boundary. Such edges are split at
//! their midpoint moved onto the boundary, until the midpoints of the edges are within a target
//! of it or [`CREASE_ROUNDS`] rounds have run.
//!
//! Every edge's midpoint is read, not only those of edges whose two triangles meet at an angle
//! (up to stop 43, more than 8 degrees): a strip of coplanar triangles can run diagonally
//! across a crease, its inner edges between triangles of one plane and their midpoints inside
//! the region by a quarter of a cell. On the L-prism at a cell of 4 tolerances the worst
//! sampled face point was 0.96 tolerances off with only the angled edges read, 0.48 with every
//! edge (stop 44, `closed_tests.rs`'s face points at a cell of 2 % of the extent). An edge is
//! read once (its ends never move); the edges a split or a flip makes or changes are read in
//! the next round, and after the last.
//!
//! Splitting an edge splits both its triangles, so the mesh stays closed and consistently
//! oriented. The new vertex moves onto the boundary along the mean normal at the edge's ends
//! (area-weighted: a sliver's own normal says nothing), else along its two triangles' mean
//! normal; a split is refused, and tried again next round, when a new triangle would face
//! against that direction or cross any triangle of the mesh (a segment-triangle test with the
//! vertices rounded to float32, as Blender keeps them, against the triangles in the buckets
//! the new ones meet). So the mesh stays self-intersection-free. An edge no split fits is
//! flipped instead (to the other diagonal of its two triangles) when the flipped diagonal's
//! midpoint is nearer the boundary, under the same checks: where neighbours split in earlier
//! rounds block the move, the flip mostly lines the edge up with the crease.

use super::hash::FastMap;

use glam::DVec3;

use super::body::longest_edge_squared;
use super::closed::point_triangle_distance;
use crate::progress::Span;

/// Rounds of splits at most (each halves the edges across a crease).
pub const CREASE_ROUNDS: usize = 8;

/// A split is refused when its new vertex comes nearer than this many targets to a triangle
/// (or a triangle's corner to a new triangle) that shares no corner with the new one.
pub const TOUCH: f64 = 0.04;

/// The float32 rounding Blender keeps vertices at, relative to their coordinates, and more.
const ROUNDING_SLACK: f64 = 1e-6;

/// An edge's two triangles (by index), the edge by its vertices, lower first.
type Edges = FastMap<(u32, u32), [u32; 2]>;

pub(super) fn key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

/// Twice the area of triangle `t` along its normal.
pub(super) fn cross(v: &[DVec3], t: [u32; 3]) -> DVec3 {
    let [a, b, c] = t.map(|i| v[i as usize]);
    (b - a).cross(c - a)
}

/// How flat a new triangle may be: twice its area along the direction it must face, at least
/// this fraction of its longest edge squared. A split or a flip making a flatter one (three
/// corners in a line to round-off, whose normal is noise) is refused: on the torus at a cell
/// of 4 tolerances a flip once made one of twice-area `8e-19` (stop 44).
const FLAT: f64 = 1e-9;

/// Whether triangle `t` faces along the unit `dir`, by more than [`FLAT`].
fn faces_along(v: &[DVec3], t: [u32; 3], dir: DVec3) -> bool {
    cross(v, t).dot(dir) > FLAT * longest_edge_squared(t.map(|i| v[i as usize]))
}

fn normal(v: &[DVec3], t: [u32; 3]) -> DVec3 {
    cross(v, t).normalize_or_zero()
}

/// Replaces, in `edges`, triangle `old` by `new` on the edge `(a, b)`.
fn retarget(edges: &mut Edges, a: u32, b: u32, old: u32, new: u32) {
    if let Some(pair) = edges.get_mut(&key(a, b)) {
        for slot in pair.iter_mut().filter(|s| **s == old) {
            *slot = new;
        }
    }
}

/// Splits the edges of the closed mesh (`vertices`, `triangles`) whose midpoints are
/// further than `target` from the boundary (at most one split per triangle per round, the
/// farthest first). `field(x, near)` is the region's exact field at `x`, `near` the motion
/// samples near which to look first (a vertex's, in `near`); `onto(from, dir, value, near)`
/// moves the point `from`, where the field is `value`, along the unit `dir` to the field's
/// zero, if it finds it: (the point, the field there). The midpoints (once per edge) and the
/// moves of the splits a round plans are found on `threads` threads; the splits, one after
/// another, do not depend on the count. The new vertex moves along its ends' normals as they
/// were at the round's start, else its two triangles'. Returns the largest
/// `|field|` at a new vertex (0 with none) and at the midpoint of an edge left (every edge's
/// midpoint is read; 0 with none); a new vertex's `near` is its edge's first end's.
/// `span` follows the rounds; once the computation is asked to stop, no round starts (the
/// caller checks).
// The mesh (three parts), the target, how to run (threads, progress) and the field's two
// functions: grouping them would only name the group.
#[allow(clippy::too_many_arguments)]
pub fn split_creases(
    vertices: &mut Vec<DVec3>,
    near: &mut Vec<[u32; 2]>,
    triangles: &mut Vec<[u32; 3]>,
    target: f64,
    threads: usize,
    span: Span<'_>,
    field: &(dyn Fn(DVec3, [u32; 2]) -> f64 + Sync),
    onto: &(dyn Fn(DVec3, DVec3, f64, [u32; 2]) -> Option<(DVec3, f64)> + Sync),
) -> (f64, f64) {
    let mut edges: Edges =
        FastMap::with_capacity_and_hasher(triangles.len() * 3 / 2, Default::default());
    for (i, t) in triangles.iter().enumerate() {
        for e in 0..3 {
            let slot = edges
                .entry(key(t[e], t[(e + 1) % 3]))
                .or_insert([u32::MAX; 2]);
            slot[usize::from(slot[0] != u32::MAX)] = i as u32;
        }
    }
    // Each vertex's normal weighted by area (a sliver's own normal says nothing).
    let mut normals = vec![DVec3::ZERO; vertices.len()];
    for &t in triangles.iter() {
        let c = cross(vertices, t);
        for i in t {
            normals[i as usize] += c;
        }
    }
    // Every edge: a strip of coplanar triangles can cut across a crease, its inner edges
    // between triangles of one plane.
    let mut candidates: Vec<(u32, u32)> = edges.keys().copied().collect();
    candidates.sort_unstable();
    let mut buckets = Buckets::new(vertices, triangles);
    let mut residual: f64 = 0.0;
    // Midpoint values read so far, by edge.
    let mut known: FastMap<(u32, u32), f64> = FastMap::default();
    for round in 0..CREASE_ROUNDS {
        if span.is_cancelled() {
            break;
        }
        span.advance(round as f64 / CREASE_ROUNDS as f64);
        // Each candidate's midpoint value, most off first: read once per edge (an edge's
        // ends never move), the new ones on every core.
        read_midpoints(&mut known, &candidates, (vertices, near), threads, field);
        let mut off: Vec<(f64, (u32, u32))> = candidates
            .iter()
            .map(|e| (known[e], *e))
            .filter(|(g, _)| g.abs() > target)
            .collect();
        if off.is_empty() {
            break;
        }
        off.sort_by(|x, y| y.0.abs().total_cmp(&x.0.abs()).then(x.1.cmp(&y.1)));
        // The splits this round takes if none is refused (at most one per triangle), each
        // moved along its ends' normals as they are at the round's start, on every core. A
        // split the round takes only because one before it was refused moves when its turn
        // comes, along the same normals, so the result does not depend on the thread count.
        let start = normals.clone();
        let mut claimed = vec![false; triangles.len()];
        let planned: Vec<(f64, (u32, u32))> = off
            .iter()
            .copied()
            .filter(|(_, e)| {
                edges.get(e).is_some_and(|&[p, q]| {
                    let free = !claimed[p as usize] && !claimed[q as usize];
                    if free {
                        claimed[p as usize] = true;
                        claimed[q as usize] = true;
                    }
                    free
                })
            })
            .collect();
        let along = |a: u32, b: u32| (start[a as usize] + start[b as usize]).normalize_or_zero();
        let ahead = |&(g, (a, b)): &(f64, (u32, u32))| {
            let dir = along(a, b);
            let mid = 0.5 * (vertices[a as usize] + vertices[b as usize]);
            let moved = (dir != DVec3::ZERO).then(|| onto(mid, dir, g, near[a as usize]));
            ((a, b), moved.flatten())
        };
        let ahead: FastMap<(u32, u32), Option<(DVec3, f64)>> =
            in_chunks(&planned, threads, &ahead).into_iter().collect();
        // At most one split per triangle per round.
        let mut taken = vec![false; triangles.len()];
        let mut next = Vec::new();
        for (g, (a, b)) in off {
            let Some(&[p, q]) = edges.get(&(a, b)) else {
                continue;
            };
            if taken[p as usize] || taken[q as usize] {
                next.push((a, b));
                continue;
            }
            let (pa, pb) = (vertices[a as usize], vertices[b as usize]);
            // Each triangle (u, v, x) with the edge u -> v becomes (u, w, x) in place and
            // (w, v, x) appended.
            let w = vertices.len() as u32;
            let sides = [p, q].map(|tri| {
                let t = triangles[tri as usize];
                let e = (0..3)
                    .find(|&e| key(t[e], t[(e + 1) % 3]) == (a, b))
                    .expect("the edge is in its triangle");
                (tri, t, [t[e], t[(e + 1) % 3], t[(e + 2) % 3]])
            });
            let halves = sides.map(|(_, _, [u, v, x])| [[u, w, x], [w, v, x]]);
            let new: Vec<[u32; 3]> = halves.iter().flatten().copied().collect();
            // The new vertex moved onto the boundary along the ends' normals, else along the
            // two triangles': the first that turns no new triangle against it and crosses
            // nothing.
            let ways = [
                along(a, b),
                (normal(vertices, triangles[p as usize]) + normal(vertices, triangles[q as usize]))
                    .normalize_or_zero(),
            ];
            let mid = 0.5 * (pa + pb);
            // Whether `w` at `at` turns no new triangle against `dir` and crosses nothing.
            let fits = |vertices: &mut Vec<DVec3>, at: DVec3, dir: DVec3| {
                vertices.push(at);
                let fits = new.iter().all(|&n| faces_along(vertices, n, dir))
                    && !buckets.crosses(
                        vertices,
                        triangles,
                        &new,
                        &[p, q],
                        TOUCH * target,
                        Some(w),
                    );
                vertices.pop();
                fits
            };
            let mut found: Option<(DVec3, f64)> = None;
            for (way, dir) in ways.into_iter().enumerate() {
                if dir == DVec3::ZERO {
                    continue;
                }
                let o = match ahead.get(&(a, b)) {
                    Some(&moved) if way == 0 => moved,
                    _ => onto(mid, dir, g, near[a as usize]),
                };
                let Some((at, gw)) = o else {
                    continue;
                };
                if gw.abs() >= g.abs() {
                    continue;
                }
                if fits(vertices, at, dir) {
                    found = Some((at, gw));
                    break;
                }
            }
            let Some((w_at, gw)) = found else {
                // No split fits: the edge flipped instead (to the other diagonal of its two
                // triangles), when that one's midpoint is nearer the boundary and the flip
                // turns nothing over and crosses nothing.
                let [u, v, x] = sides[0].2;
                let y = sides[1].2[2];
                let flipped = [[u, y, x], [y, v, x]];
                let facing =
                    (cross(vertices, sides[0].1) + cross(vertices, sides[1].1)).normalize_or_zero();
                let xy = key(x, y);
                let turns = flipped.iter().any(|&n| !faces_along(vertices, n, facing));
                let gxy = if x == y || edges.contains_key(&xy) || turns {
                    f64::INFINITY
                } else {
                    *known.entry(xy).or_insert_with(|| {
                        field(
                            0.5 * (vertices[x as usize] + vertices[y as usize]),
                            near[xy.0 as usize],
                        )
                    })
                };
                if gxy.abs() < g.abs()
                    && !buckets.crosses(
                        vertices,
                        triangles,
                        &flipped,
                        &[p, q],
                        TOUCH * target,
                        None,
                    )
                {
                    let before = [p, q].map(|t| cross(vertices, triangles[t as usize]));
                    triangles[p as usize] = flipped[0];
                    triangles[q as usize] = flipped[1];
                    taken[p as usize] = true;
                    taken[q as usize] = true;
                    buckets.insert(vertices, flipped[0], p);
                    buckets.insert(vertices, flipped[1], q);
                    let after = flipped.map(|n| cross(vertices, n));
                    normals[u as usize] += after[0] - before[0] - before[1];
                    normals[v as usize] += after[1] - before[0] - before[1];
                    normals[x as usize] += after[0] + after[1] - before[0];
                    normals[y as usize] += after[0] + after[1] - before[1];
                    edges.remove(&(a, b));
                    edges.insert(xy, [p, q]);
                    retarget(&mut edges, u, y, q, p);
                    retarget(&mut edges, v, x, p, q);
                    next.extend([xy, key(u, y), key(v, x), key(u, x), key(v, y)]);
                    continue;
                }
                // Tried again next round, its neighbours perhaps changed.
                next.push((a, b));
                continue;
            };
            vertices.push(w_at);
            taken[p as usize] = true;
            taken[q as usize] = true;
            residual = residual.max(gw.abs());
            normals.push(DVec3::ZERO);
            near.push(near[a as usize]);
            edges.remove(&(a, b));
            let mut added = [0u32; 2];
            for (s, (tri, before, [u, v, x])) in sides.into_iter().enumerate() {
                let appended = triangles.len() as u32;
                let before = cross(vertices, before);
                triangles[tri as usize] = [u, w, x];
                triangles.push([w, v, x]);
                taken.push(true);
                buckets.insert(vertices, [u, w, x], tri);
                buckets.insert(vertices, [w, v, x], appended);
                let (c1, c2) = (cross(vertices, [u, w, x]), cross(vertices, [w, v, x]));
                normals[u as usize] += c1 - before;
                normals[v as usize] += c2 - before;
                normals[x as usize] += c1 + c2 - before;
                normals[w as usize] += c1 + c2;
                retarget(&mut edges, v, x, tri, appended);
                edges.insert(key(w, x), [tri, appended]);
                added[s] = appended;
                next.extend([key(u, x), key(v, x), key(w, x)]);
            }
            // (u, w) and (w, v): the in-place triangle of one side with the appended one of
            // the other (the sides run u -> v and v -> u).
            let [tp, tq] = [triangles[p as usize], triangles[q as usize]];
            edges.insert(key(tp[0], w), [p, added[1]]);
            edges.insert(key(tq[0], w), [q, added[0]]);
            next.extend([key(a, w), key(b, w)]);
        }
        next.sort_unstable();
        next.dedup();
        // (A split or flip later in the round may have removed an edge listed before it.)
        candidates = next.into_iter().filter(|e| edges.contains_key(e)).collect();
    }
    if span.is_cancelled() {
        return (residual, 0.0);
    }
    // The edges the last round made or changed, read too: the bound covers every edge's
    // midpoint, those of the splits refused (a neighbouring sheet in the way) and of the edges
    // the rounds did not reach.
    read_midpoints(&mut known, &candidates, (vertices, near), threads, field);
    span.advance(1.0);
    let left = known
        .iter()
        .filter(|(e, _)| edges.contains_key(e))
        .fold(0.0f64, |m, (_, g)| m.max(g.abs()));
    (residual, left)
}

/// Reads into `known`, on `threads` threads, the field at the midpoints of the `edges` it does
/// not hold yet (near the samples of each edge's first end).
fn read_midpoints(
    known: &mut FastMap<(u32, u32), f64>,
    edges: &[(u32, u32)],
    (vertices, near): (&[DVec3], &[[u32; 2]]),
    threads: usize,
    field: &(dyn Fn(DVec3, [u32; 2]) -> f64 + Sync),
) {
    let unread: Vec<(u32, u32)> = edges
        .iter()
        .copied()
        .filter(|e| !known.contains_key(e))
        .collect();
    let value = |&(a, b): &(u32, u32)| {
        field(
            0.5 * (vertices[a as usize] + vertices[b as usize]),
            near[a as usize],
        )
    };
    known.extend(
        unread
            .iter()
            .copied()
            .zip(in_chunks(&unread, threads, &value)),
    );
}

/// `f` of every item, in order, computed on `threads` threads (contiguous chunks).
pub(super) fn in_chunks<T: Sync, R: Send>(
    items: &[T],
    threads: usize,
    f: &(dyn Fn(&T) -> R + Sync),
) -> Vec<R> {
    let size = items.len().div_ceil(threads.max(1)).max(1);
    if threads <= 1 || items.len() <= size {
        return items.iter().map(f).collect();
    }
    std::thread::scope(|scope| {
        let handles: Vec<_> = items
            .chunks(size)
            .map(|chunk| scope.spawn(move || chunk.iter().map(f).collect::<Vec<R>>()))
            .collect();
        handles
            .into_iter()
            .flat_map(|h| h.join().unwrap_or_else(|e| std::panic::resume_unwind(e)))
            .collect()
    })
}

/// The triangles by the cubes of side [`BUCKET`] their boxes meet (entries of a triangle
/// since reshaped stay: each is read with its current corners).
pub(super) struct Buckets {
    map: FastMap<[i64; 3], Vec<u32>>,
    side: f64,
}

/// The buckets' side, in lengths of the mesh's longest edge at the start.
pub const BUCKET: f64 = 1.0;

impl Buckets {
    fn new(v: &[DVec3], t: &[[u32; 3]]) -> Self {
        let longest = t
            .iter()
            .flat_map(|tri| {
                (0..3).map(move |e| v[tri[e] as usize].distance(v[tri[(e + 1) % 3] as usize]))
            })
            .fold(0.0, f64::max);
        Self::with_side(v, t, BUCKET * longest)
    }

    /// The triangles `t` by cubes of side `side`.
    pub(super) fn with_side(v: &[DVec3], t: &[[u32; 3]], side: f64) -> Self {
        let mut out = Self {
            map: FastMap::with_capacity_and_hasher(t.len() / 4, Default::default()),
            side: side.max(f64::MIN_POSITIVE),
        };
        for (i, &tri) in t.iter().enumerate() {
            out.insert(v, tri, i as u32);
        }
        out
    }

    fn cubes(&self, v: &[DVec3], tri: [u32; 3]) -> impl Iterator<Item = [i64; 3]> {
        let [a, b, c] = tri.map(|i| v[i as usize]);
        let at = |p: DVec3| (p / self.side).floor().to_array().map(|x| x as i64);
        let (lo, hi) = (at(a.min(b).min(c)), at(a.max(b).max(c)));
        (lo[2]..=hi[2]).flat_map(move |z| {
            (lo[1]..=hi[1]).flat_map(move |y| (lo[0]..=hi[0]).map(move |x| [x, y, z]))
        })
    }

    pub(super) fn insert(&mut self, v: &[DVec3], tri: [u32; 3], id: u32) {
        for c in self.cubes(v, tri).collect::<Vec<_>>() {
            self.map.entry(c).or_default().push(id);
        }
    }

    /// Removes triangle `id`, whose corners are `tri`, from the cubes its box meets.
    pub(super) fn remove(&mut self, v: &[DVec3], tri: [u32; 3], id: u32) {
        for c in self.cubes(v, tri).collect::<Vec<_>>() {
            if let Some(list) = self.map.get_mut(&c) {
                list.retain(|&i| i != id);
            }
        }
    }

    /// Whether a triangle of `new` crosses a triangle of the mesh other than those of
    /// `replaced` (other than along what they share: [`crosses`]).
    pub(super) fn crosses(
        &self,
        v: &[DVec3],
        t: &[[u32; 3]],
        new: &[[u32; 3]],
        replaced: &[u32],
        margin: f64,
        apex: Option<u32>,
    ) -> bool {
        // The cubes the new triangles meet, each once (a fan's boxes overlap).
        let mut cubes: Vec<[i64; 3]> = new.iter().flat_map(|&n| self.cubes(v, n)).collect();
        cubes.sort_unstable();
        cubes.dedup();
        let mut near: Vec<u32> = cubes
            .iter()
            .filter_map(|c| self.map.get(c))
            .flatten()
            .copied()
            .filter(|i| !replaced.contains(i))
            .collect();
        near.sort_unstable();
        near.dedup();
        // A split's new vertex (`apex`) nearer than `margin` to a triangle it is not a corner
        // of, or a corner of such a triangle nearer than that to a new triangle, is refused
        // too: a touch is a crossing to a test with a tolerance (Blender's `BVHTree.overlap`).
        let touches = |n: [u32; 3], s: [u32; 3]| {
            let at = |k: u32| v[k as usize];
            let [a, b, c] = s.map(at);
            let [d, e, f] = n.map(at);
            // (A point outside a triangle's box grown by the margin is further than that.)
            let within = |p: DVec3, [a, b, c]: [DVec3; 3]| {
                let (lo, hi) = (a.min(b).min(c) - margin, a.max(b).max(c) + margin);
                p.cmpge(lo).all()
                    && p.cmple(hi).all()
                    && point_triangle_distance(p, a, b, c) < margin
            };
            apex.is_some_and(|w| !s.contains(&w) && within(at(w), [a, b, c]))
                || s.iter()
                    .any(|&k| !n.contains(&k) && within(at(k), [d, e, f]))
        };
        // Triangles whose boxes (grown by the margin and the float32 rounding) are apart
        // neither cross nor touch.
        let boxes = |s: [u32; 3]| {
            let [a, b, c] = s.map(|k| v[k as usize]);
            let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
            let slack = margin + ROUNDING_SLACK * lo.abs().max(hi.abs()).max_element();
            (lo - slack, hi + slack)
        };
        let new_boxes: Vec<(DVec3, DVec3)> = new.iter().map(|&n| boxes(n)).collect();
        let (all_lo, all_hi) = new_boxes.iter().fold(
            (DVec3::INFINITY, DVec3::NEG_INFINITY),
            |(lo, hi), &(a, b)| (lo.min(a), hi.max(b)),
        );
        let apart = |(lo, hi): (DVec3, DVec3), (slo, shi): (DVec3, DVec3)| {
            slo.cmpgt(hi).any() || lo.cmpgt(shi).any()
        };
        // Each near triangle's box once, those apart from every new triangle's left out.
        near.into_iter()
            .map(|i| (t[i as usize], boxes(t[i as usize])))
            .filter(|&(_, b)| !apart((all_lo, all_hi), b))
            .any(|(s, b)| {
                new.iter().zip(&new_boxes).any(|(&n, &nb)| {
                    !apart(nb, b)
                        && (crosses(v, n, s) || (s.iter().all(|k| !n.contains(k)) && touches(n, s)))
                })
            })
    }
}

fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a)
}

/// Whether the segment from `p` to `q` (its ends' orientations `sp` and `sq` against the
/// triangle's plane) crosses the triangle: its ends on either side of the triangle's plane and
/// the crossing inside it, each by more than round-off (a volume of 1e-12 times the cube of the
/// longest length involved).
fn segment_crosses((p, q): (DVec3, DVec3), (sp, sq): (f64, f64), [a, b, c]: [DVec3; 3]) -> bool {
    const ROUNDOFF: f64 = 1e-12;
    let l = (q - p)
        .length()
        .max((b - a).length())
        .max((c - b).length())
        .max((a - c).length());
    let eps = ROUNDOFF * l * l * l;
    if !((sp > eps && sq < -eps) || (sp < -eps && sq > eps)) {
        return false;
    }
    let (s1, s2, s3) = (orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a));
    (s1 > eps && s2 > eps && s3 > eps) || (s1 < -eps && s2 < -eps && s3 < -eps)
}

/// Whether triangles `s` and `t` (vertex indices into `v`) cross other than along what they
/// share: an edge of one, not through a vertex of the other, crosses the other. Read at the
/// vertices rounded to float32, as Blender keeps them.
fn crosses(v: &[DVec3], s: [u32; 3], t: [u32; 3]) -> bool {
    if s.iter().filter(|k| t.contains(k)).count() >= 2 {
        return false;
    }
    let at = |k: u32| v[k as usize].as_vec3().as_dvec3();
    let (ps, pt) = (s.map(at), t.map(at));
    // Each corner's orientation against the other triangle's plane is read once: an edge
    // whose ends are not on either side of it crosses nothing.
    let one_way = |a: [u32; 3], pa: [DVec3; 3], b: [u32; 3], pb: [DVec3; 3]| {
        let [x, y, z] = pb;
        let o = pa.map(|p| orient(x, y, z, p));
        (0..3).any(|e| {
            let f = (e + 1) % 3;
            ((o[e] > 0.0 && o[f] < 0.0) || (o[e] < 0.0 && o[f] > 0.0))
                && !(b.contains(&a[e]) || b.contains(&a[f]))
                && segment_crosses((pa[e], pa[f]), (o[e], o[f]), pb)
        })
    };
    one_way(s, ps, t, pt) || one_way(t, pt, s, ps)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A triangle faces along a direction only when its area along it is more than round-off:
    /// three corners in a line (to round-off, as a flip once made on the torus) do not, however
    /// the noise in their cross product points; a proper triangle does along its normal, not
    /// against it.
    #[test]
    fn a_triangle_with_its_corners_in_a_line_faces_nowhere() {
        let line = [
            DVec3::new(
                0.868_736_255_893_697_3,
                1.673_618_684_510_736_4,
                -0.872_029_002_599_855_2,
            ),
            DVec3::new(
                0.867_199_202_789_668_4,
                1.673_618_684_510_736_4,
                -0.869_193_647_466_818,
            ),
            DVec3::new(
                0.871_571_611_026_734_4,
                1.673_618_684_510_736_4,
                -0.877_259_296_016_113,
            ),
        ];
        let c = cross(&line, [0, 1, 2]);
        assert!(c.length() < 1e-15, "{c}");
        for dir in [
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            -DVec3::Y,
            c.normalize_or_zero(),
        ] {
            assert!(!faces_along(&line, [0, 1, 2], dir), "{dir}");
        }
        let proper = [DVec3::ZERO, DVec3::X, 0.01 * DVec3::Y];
        assert!(faces_along(&proper, [0, 1, 2], DVec3::Z));
        assert!(!faces_along(&proper, [0, 2, 1], DVec3::Z));
    }
}
