//! Grid cubes cut finer where the boundary has a feature narrower than a cell (issue 29;
//! `docs/sweep.md`, "Slabs of outside space narrower than a cell").
//!
//! The contouring sees the region's sign at the grid's points only, so a slab of outside space
//! narrower than a cell between two sheets of the boundary, with every grid point around it
//! inside, is filled, and where such a slab opens to the outside the grid's surface passes over
//! its mouth. Such slabs lie where two sheets of the motion meet: the grid points on either side
//! take their minimum from poses far apart in the motion. The cubes where that happens near the
//! boundary ([`channel_cubes`]) and the grid misses something (read on a lattice [`SPLIT`]
//! times finer, by the caller) are cut into [`SPLIT`]`^3` subcubes, each into Kuhn's six
//! tetrahedra.
//!
//! The tetrahedra stay conforming (every two that meet share a whole face, edge or corner), so
//! marching tetrahedra still gives a closed, oriented, intersection-free surface:
//! - a grid edge of a refined cube is **split**: it holds the lattice points along it;
//! - a cube that is not refined but has a split edge (it shares a face or an edge with a refined
//!   cube) is a **transition** cube: it is cut into tetrahedra from its centre to the triangles
//!   of its six faces;
//! - a face is cut as the refined subcubes cut it when either cube holding it is refined (the
//!   diagonal of each small square from its lowest corner to its highest, as Kuhn's
//!   tetrahedra cut a cube's faces), else into triangles from its centre to its corners and the
//!   lattice points of its split edges when it has a split edge, else along its own diagonal
//!   from its lowest corner, as the plain cubes' Kuhn tetrahedra cut it.
//!
//! Both cubes holding a face derive its triangles from the same facts, and every cube holding a
//! split edge cuts it at the same points, so neighbours agree. With no cube refined nothing
//! changes: the plain cubes are the grid's own.

use super::hash::{FastMap, FastSet};

use glam::DVec3;

/// Subcubes per refined cube along each axis. A power of two, so every lattice point's
/// position is the grid's own arithmetic on binary fractions of the cell.
pub(super) const SPLIT: usize = 4;

/// Lattice points per grid cube (`SPLIT^3`).
const PER_CUBE: u64 = (SPLIT * SPLIT * SPLIT) as u64;

/// A lattice point: the grid cube holding it (by its lowest corner's index, which may be a
/// point of the grid's last layer) times [`PER_CUBE`] plus its offset in that cube, each axis
/// `0..SPLIT`. A grid point `p` is `p * PER_CUBE`, so grid points' keys sort as their indices.
pub(super) type Key = u64;

/// The six tetrahedra of Kuhn's triangulation of the unit cube, as corner codes
/// (`x | y << 1 | z << 2`).
pub(super) const KUHN: [[u8; 4]; 6] = [
    [0, 1, 3, 7],
    [0, 1, 5, 7],
    [0, 2, 3, 7],
    [0, 2, 6, 7],
    [0, 4, 5, 7],
    [0, 4, 6, 7],
];

/// The key of grid point `p`.
#[inline]
pub(super) fn grid_key(p: usize) -> Key {
    p as u64 * PER_CUBE
}

/// The grid point of `key`, if it is one.
#[inline]
pub(super) fn grid_point(key: Key) -> Option<usize> {
    (key % PER_CUBE == 0).then_some((key / PER_CUBE) as usize)
}

/// The cubes that may hide a feature of the boundary finer than a cell: none of their corners
/// deeper than `deep` (no outside point can be in a cube with a corner deeper than its
/// diagonal: the field is 1-Lipschitz), some inside, and their corners' minima from samples of
/// the motion more than `gap` apart (two sheets meet there). `g` and `arg` are the grid's
/// values and samples (`u32::MAX`: none), `n` its points per axis. Sorted.
pub(super) fn channel_cubes(
    g: &[f32],
    arg: &[u32],
    n: [usize; 3],
    deep: f32,
    gap: u32,
) -> Vec<usize> {
    let [nx, ny, nz] = n;
    let offsets = corner_offsets(n);
    let mut found = Vec::new();
    for k in 0..nz.saturating_sub(1) {
        for j in 0..ny.saturating_sub(1) {
            let row = (k * ny + j) * nx;
            'cube: for base in row..row + nx.saturating_sub(1) {
                let (mut lo, mut hi) = (u32::MAX, 0u32);
                let mut inside = false;
                for &o in &offsets {
                    let v = g[base + o];
                    if v < -deep {
                        continue 'cube;
                    }
                    inside |= v < 0.0;
                    let a = arg[base + o];
                    lo = lo.min(a);
                    hi = hi.max(a);
                }
                if inside && hi != u32::MAX && hi - lo > gap {
                    found.push(base);
                }
            }
        }
    }
    found
}

/// The value at `x` (in cells from a grid cube's lowest corner, each in `[0, 1]`) of the
/// linear interpolation of the cube's corner values `corner` (by corner code) over the Kuhn
/// tetrahedron holding `x`: the field the plain grid contours.
pub(super) fn kuhn_value(corner: [f64; 8], x: [f64; 3]) -> f64 {
    // The axes by decreasing coordinate: the tetrahedron 0, e_a, e_a + e_b, 7.
    let mut order = [0usize, 1, 2];
    order.sort_by(|&a, &b| x[b].total_cmp(&x[a]));
    let [a, b, c] = order;
    let (ca, cb) = (1usize << a, (1usize << a) | (1usize << b));
    (1.0 - x[a]) * corner[0]
        + (x[a] - x[b]) * corner[ca]
        + (x[b] - x[c]) * corner[cb]
        + x[c] * corner[7]
}

/// The offset of lattice point `key` from grid cube `cube`'s lowest corner, in cells (both of
/// a grid of `n` points per axis; `key` one of the cube's [`cube_points`]).
pub(super) fn offset_in(n: [usize; 3], cube: usize, key: Key) -> [f64; 3] {
    let c = coords(n, cube);
    let l = lattice_coords(n, key);
    std::array::from_fn(|a| (l[a] - c[a] * SPLIT) as f64 / SPLIT as f64)
}

/// The coordinates `(i, j, k)` of grid point `p` of a grid of `n` points per axis.
#[inline]
pub(super) fn coords(n: [usize; 3], p: usize) -> [usize; 3] {
    [p % n[0], (p / n[0]) % n[1], p / (n[0] * n[1])]
}

/// The index of grid point `(i, j, k)` of a grid of `n` points per axis (`coords`' inverse).
#[inline]
fn index(n: [usize; 3], [i, j, k]: [usize; 3]) -> usize {
    (k * n[1] + j) * n[0] + i
}

/// The index offsets of a grid cube's corners from its lowest, by corner code
/// (`x | y << 1 | z << 2`).
pub(super) fn corner_offsets(n: [usize; 3]) -> [usize; 8] {
    std::array::from_fn(|c| (c & 1) + ((c >> 1) & 1) * n[0] + ((c >> 2) & 1) * n[0] * n[1])
}

/// The key of the lattice point at lattice coordinates `l` (`SPLIT` per cell) of a grid of
/// `n` points per axis.
fn lattice_key(n: [usize; 3], l: [usize; 3]) -> Key {
    let [a, b, c] = l.map(|v| v % SPLIT);
    index(n, l.map(|v| v / SPLIT)) as u64 * PER_CUBE + ((c * SPLIT + b) * SPLIT + a) as u64
}

/// The lattice coordinates of `key` in a grid of `n` points per axis ([`lattice_key`]'s
/// inverse).
fn lattice_coords(n: [usize; 3], key: Key) -> [usize; 3] {
    let cube = coords(n, (key / PER_CUBE) as usize);
    let o = (key % PER_CUBE) as usize;
    let off = [o % SPLIT, (o / SPLIT) % SPLIT, o / (SPLIT * SPLIT)];
    std::array::from_fn(|a| cube[a] * SPLIT + off[a])
}

/// The lattice points of grid cube `cube` (by its lowest corner) and its faces, edges and
/// corners, but for its corners (grid points), in a grid of `n` points per axis.
pub(super) fn cube_points(n: [usize; 3], cube: usize) -> impl Iterator<Item = Key> {
    let c = coords(n, cube).map(|x| x * SPLIT);
    let m = SPLIT + 1;
    (0..m * m * m).filter_map(move |s| {
        let l = [c[0] + s % m, c[1] + (s / m) % m, c[2] + s / (m * m)];
        let key = lattice_key(n, l);
        grid_point(key).is_none().then_some(key)
    })
}

/// The refined cubes and their transition cubes, and the lattice points they add.
pub(super) struct Lattice {
    origin: DVec3,
    cell: f64,
    n: [usize; 3],
    refined: FastSet<usize>,
    transition: FastSet<usize>,
    /// The added points' values and samples (as the grid's: `f32`, negative inside).
    values: FastMap<Key, (f32, u32)>,
}

impl Lattice {
    /// The lattice over the grid (`origin`, `cell`, `n` points per axis), no cube refined yet.
    pub(super) fn new(origin: DVec3, cell: f64, n: [usize; 3]) -> Self {
        Self {
            origin,
            cell,
            n,
            refined: FastSet::default(),
            transition: FastSet::default(),
            values: FastMap::default(),
        }
    }

    /// Refines the cubes `cubes` (by their lowest corners), and makes their neighbours
    /// sharing a face or an edge transition cubes.
    pub(super) fn refine(&mut self, cubes: &[usize]) {
        let n = self.n;
        self.refined.extend(cubes);
        let refined = &self.refined;
        let mut transition = FastSet::default();
        for &c in refined {
            let at = coords(n, c);
            for d in 0..27usize {
                let step = [d % 3, (d / 3) % 3, d / 9].map(|s| s as isize - 1);
                let moved = step.iter().filter(|&&s| s != 0).count();
                if moved == 0 || moved == 3 {
                    continue;
                }
                let mut there = [0usize; 3];
                let mut valid = true;
                for a in 0..3 {
                    let x = at[a] as isize + step[a];
                    valid &= x >= 0 && (x as usize) + 1 < n[a];
                    there[a] = x.max(0) as usize;
                }
                let cube = index(n, there);
                if valid && !refined.contains(&cube) {
                    transition.insert(cube);
                }
            }
        }
        self.transition = transition;
    }

    /// How many cubes are refined, and how many are transition cubes.
    pub(super) fn counts(&self) -> (usize, usize) {
        (self.refined.len(), self.transition.len())
    }

    /// Whether cube `c` is refined or a transition cube (its tetrahedra are
    /// [`Lattice::tetrahedra`]'s, not Kuhn's six).
    #[inline]
    pub(super) fn special(&self, c: usize) -> bool {
        !self.refined.is_empty() && (self.refined.contains(&c) || self.transition.contains(&c))
    }

    fn key(&self, l: [usize; 3]) -> Key {
        lattice_key(self.n, l)
    }

    /// The position of `key` (a grid point's is the grid's own: `origin + (i, j, k) cell`).
    pub(super) fn point(&self, key: Key) -> DVec3 {
        let l = lattice_coords(self.n, key);
        let at = l.map(|v| (v / SPLIT) as f64 + (v % SPLIT) as f64 / SPLIT as f64);
        self.origin + DVec3::new(at[0], at[1], at[2]) * self.cell
    }

    /// The grid points of the cube holding `key` (its last layer's: the cube before it),
    /// by their indices.
    pub(super) fn corners(&self, key: Key) -> [usize; 8] {
        let l = lattice_coords(self.n, key);
        let base = index(
            self.n,
            std::array::from_fn(|a| (l[a] / SPLIT).min(self.n[a] - 2)),
        );
        corner_offsets(self.n).map(|o| base + o)
    }

    /// Whether the grid edge from grid point `at` along `axis` is split: an edge of a refined
    /// cube.
    fn split(&self, at: [usize; 3], axis: usize) -> bool {
        let (u, v) = ((axis + 1) % 3, (axis + 2) % 3);
        if at[axis] + 1 >= self.n[axis] {
            return false;
        }
        (0..4).any(|d| {
            let (du, dv) = (d & 1, d >> 1);
            if at[u] < du || at[v] < dv {
                return false;
            }
            let mut c = at;
            c[u] -= du;
            c[v] -= dv;
            c[u] + 1 < self.n[u] && c[v] + 1 < self.n[v] && self.refined.contains(&index(self.n, c))
        })
    }

    /// The triangles of the face of cube `c` (grid coordinates) across `axis` on side `side`,
    /// as lattice keys (module documentation).
    fn face(&self, c: [usize; 3], axis: usize, side: usize, out: &mut Vec<[Key; 3]>) {
        let (u, v) = if axis == 0 {
            (1, 2)
        } else if axis == 1 {
            (0, 2)
        } else {
            (0, 1)
        };
        let across = c[axis] + side;
        // The cube on the face's other side, if the grid has one.
        let beyond = if side == 1 {
            (across + 1 < self.n[axis]).then_some(across)
        } else {
            c[axis].checked_sub(1)
        };
        let fine = self.refined.contains(&index(self.n, c))
            || beyond.is_some_and(|x| {
                let mut other = c;
                other[axis] = x;
                self.refined.contains(&index(self.n, other))
            });
        let at = |a: usize, b: usize| {
            let mut l = c.map(|x| x * SPLIT);
            l[axis] = across * SPLIT;
            l[u] += a;
            l[v] += b;
            self.key(l)
        };
        if fine {
            for a in 0..SPLIT {
                for b in 0..SPLIT {
                    out.push([at(a, b), at(a + 1, b), at(a + 1, b + 1)]);
                    out.push([at(a, b), at(a, b + 1), at(a + 1, b + 1)]);
                }
            }
            return;
        }
        let mut corner = c;
        corner[axis] = across;
        let from = |du: usize, dv: usize| {
            let mut p = corner;
            p[u] += du;
            p[v] += dv;
            p
        };
        // The four edges in turn around the face, each with whether it is split.
        let edges = [
            self.split(from(0, 0), u),
            self.split(from(1, 0), v),
            self.split(from(0, 1), u),
            self.split(from(0, 0), v),
        ];
        if !edges.iter().any(|&s| s) {
            let s = SPLIT;
            out.push([at(0, 0), at(s, 0), at(s, s)]);
            out.push([at(0, 0), at(0, s), at(s, s)]);
            return;
        }
        // The face's boundary in turn, with the lattice points of its split edges.
        let s = SPLIT;
        let mut ring: Vec<Key> = Vec::with_capacity(4 * s);
        let walk: [(usize, usize, isize, isize); 4] =
            [(0, 0, 1, 0), (s, 0, 0, 1), (s, s, -1, 0), (0, s, 0, -1)];
        for (&(a, b, da, db), &split) in walk.iter().zip(&edges) {
            ring.push(at(a, b));
            if split {
                for m in 1..s as isize {
                    ring.push(at(
                        (a as isize + m * da) as usize,
                        (b as isize + m * db) as usize,
                    ));
                }
            }
        }
        let centre = at(s / 2, s / 2);
        for m in 0..ring.len() {
            out.push([centre, ring[m], ring[(m + 1) % ring.len()]]);
        }
    }

    /// The tetrahedra of a refined or transition cube `cube` (by its lowest corner), as
    /// lattice keys, appended to `out`.
    pub(super) fn tetrahedra(&self, cube: usize, out: &mut Vec<[Key; 4]>) {
        let c = coords(self.n, cube);
        let l0 = c.map(|x| x * SPLIT);
        if self.refined.contains(&cube) {
            for sub in 0..SPLIT * SPLIT * SPLIT {
                let s = [sub % SPLIT, (sub / SPLIT) % SPLIT, sub / (SPLIT * SPLIT)];
                for tet in KUHN {
                    out.push(tet.map(|code| {
                        let code = code as usize;
                        self.key([
                            l0[0] + s[0] + (code & 1),
                            l0[1] + s[1] + ((code >> 1) & 1),
                            l0[2] + s[2] + ((code >> 2) & 1),
                        ])
                    }));
                }
            }
            return;
        }
        let centre = self.key(l0.map(|x| x + SPLIT / 2));
        let mut faces = Vec::new();
        for axis in 0..3 {
            for side in 0..2 {
                self.face(c, axis, side, &mut faces);
            }
        }
        out.extend(faces.into_iter().map(|[a, b, t]| [centre, a, b, t]));
    }

    /// Every lattice point of the refined and transition cubes' tetrahedra that is not a grid
    /// point, sorted.
    pub(super) fn added_points(&self) -> Vec<Key> {
        let mut cubes: Vec<usize> = self
            .refined
            .iter()
            .chain(&self.transition)
            .copied()
            .collect();
        cubes.sort_unstable();
        let mut tets = Vec::new();
        let mut keys = FastSet::default();
        for c in cubes {
            tets.clear();
            self.tetrahedra(c, &mut tets);
            keys.extend(tets.iter().flatten().filter(|&&k| grid_point(k).is_none()));
        }
        let mut keys: Vec<Key> = keys.into_iter().collect();
        keys.sort_unstable();
        keys
    }

    /// Sets added points' values and samples.
    pub(super) fn set_values(&mut self, keys: &[Key], values: &[(f32, u32)]) {
        self.values
            .extend(keys.iter().copied().zip(values.iter().copied()));
    }

    /// Whether the added point `key` has its value already.
    pub(super) fn has_value(&self, key: Key) -> bool {
        self.values.contains_key(&key)
    }

    /// The value and sample at an added point.
    #[inline]
    pub(super) fn value(&self, key: Key) -> (f32, u32) {
        self.values[&key]
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::collections::{HashMap, HashSet};

    /// [`kuhn_value`] is the corner values at the corners and, inside each of Kuhn's
    /// tetrahedra, the linear function through its four corners' values (barycentric
    /// coordinates found by Cramer's rule).
    #[test]
    fn the_grids_linear_field_is_linear_on_each_kuhn_tetrahedron() {
        let corner: [f64; 8] = std::array::from_fn(|c| ((c * 37 + 11) % 17) as f64 - 8.0);
        let at = |c: u8| DVec3::new((c & 1) as f64, ((c >> 1) & 1) as f64, ((c >> 2) & 1) as f64);
        for c in 0..8u8 {
            assert_eq!(kuhn_value(corner, at(c).to_array()), corner[c as usize]);
        }
        let mut seed = 7u64;
        let mut uniform = move || {
            seed = seed
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            (seed >> 11) as f64 / (1u64 << 53) as f64
        };
        for _ in 0..2000 {
            let x = DVec3::new(uniform(), uniform(), uniform());
            let tet = KUHN
                .iter()
                .find(|t| {
                    let p = t.map(at);
                    let whole = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]);
                    (0..4).all(|m| {
                        let mut q = p;
                        q[m] = x;
                        (q[1] - q[0]).cross(q[2] - q[0]).dot(q[3] - q[0]) / whole >= -1e-12
                    })
                })
                .unwrap();
            let p = tet.map(at);
            let whole = (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0]);
            let expected: f64 = (0..4)
                .map(|m| {
                    let mut q = p;
                    q[m] = x;
                    let w = (q[1] - q[0]).cross(q[2] - q[0]).dot(q[3] - q[0]) / whole;
                    w * corner[tet[m] as usize]
                })
                .sum();
            let got = kuhn_value(corner, x.to_array());
            assert!(
                (got - expected).abs() < 1e-12,
                "{x}: {got} against {expected}"
            );
        }
    }

    /// Six times the signed volume of the tetrahedron `p`.
    fn det(p: [DVec3; 4]) -> f64 {
        (p[1] - p[0]).cross(p[2] - p[0]).dot(p[3] - p[0])
    }

    /// Every cube's tetrahedra (Kuhn's six for a plain cube, [`Lattice::tetrahedra`] for the
    /// others) over a grid of `n` points with the cubes `refined` cut finer.
    fn all_tetrahedra(n: [usize; 3], refined: &[usize]) -> (Lattice, Vec<[Key; 4]>) {
        let mut lattice = Lattice::new(DVec3::new(0.25, -1.0, 0.5), 0.5, n);
        lattice.refine(refined);
        let offsets = corner_offsets(n);
        let mut tets = Vec::new();
        for k in 0..n[2] - 1 {
            for j in 0..n[1] - 1 {
                for i in 0..n[0] - 1 {
                    let base = (k * n[1] + j) * n[0] + i;
                    if lattice.special(base) {
                        lattice.tetrahedra(base, &mut tets);
                    } else {
                        tets.extend(KUHN.map(|t| t.map(|c| grid_key(base + offsets[c as usize]))));
                    }
                }
            }
        }
        (lattice, tets)
    }

    #[test]
    fn the_tetrahedra_fill_the_grid_and_meet_face_to_face() {
        let n = [7, 6, 8];
        let cubes = (n[0] - 1) * (n[1] - 1) * (n[2] - 1);
        let index = |i: usize, j: usize, k: usize| (k * n[1] + j) * n[0] + i;
        // Cubes alone, sharing a face, an edge, a corner, in a block and at the grid's border.
        let mut patterns: Vec<Vec<usize>> = vec![
            vec![],
            vec![index(2, 2, 2)],
            vec![index(2, 2, 2), index(3, 2, 2)],
            vec![index(2, 2, 2), index(3, 3, 2)],
            vec![index(2, 2, 2), index(3, 3, 3)],
            (1..4)
                .flat_map(|k| (1..3).map(move |j| index(2, j, k)))
                .collect(),
            vec![index(0, 0, 0), index(5, 4, 6), index(0, 4, 3)],
        ];
        // And about one cube in five, spread by a fixed sequence.
        patterns.push(
            (0..cubes)
                .filter(|c| (c * 7919) % 5 == 0)
                .map(|c| {
                    let (w, h) = (n[0] - 1, n[1] - 1);
                    index(c % w, (c / w) % h, c / (w * h))
                })
                .collect(),
        );
        for refined in patterns {
            let (lattice, tets) = all_tetrahedra(n, &refined);
            let mut volume = 0.0;
            // Each face (its sorted keys) with the sides its tetrahedra lie on.
            let mut faces: HashMap<[Key; 3], Vec<f64>> = HashMap::new();
            for tet in &tets {
                let p = tet.map(|k| lattice.point(k));
                let v = det(p).abs() / 6.0;
                assert!(v > 1e-9, "{refined:?}: a flat tetrahedron {tet:?}");
                volume += v;
                for (skip, &apex) in p.iter().enumerate() {
                    let mut face = [0; 3];
                    let mut m = 0;
                    for (s, &k) in tet.iter().enumerate() {
                        if s != skip {
                            face[m] = k;
                            m += 1;
                        }
                    }
                    face.sort_unstable();
                    let f = face.map(|k| lattice.point(k));
                    let side = (f[1] - f[0]).cross(f[2] - f[0]).dot(apex - f[0]);
                    faces.entry(face).or_default().push(side);
                }
            }
            let cell = 0.5;
            let whole = cubes as f64 * cell * cell * cell;
            assert!(
                (volume - whole).abs() < 1e-9 * whole,
                "{refined:?}: volume {volume} of {whole}"
            );
            let lo = lattice.point(grid_key(0));
            let hi = lattice.point(grid_key(n[0] * n[1] * n[2] - 1));
            for (face, sides) in &faces {
                let f = face.map(|k| lattice.point(k));
                let border = (0..3)
                    .any(|a| f.iter().all(|p| p[a] == lo[a]) || f.iter().all(|p| p[a] == hi[a]));
                if border {
                    assert_eq!(sides.len(), 1, "{refined:?}: border face {face:?}");
                } else {
                    assert_eq!(
                        sides.len(),
                        2,
                        "{refined:?}: face {face:?} in {} tetrahedra",
                        sides.len()
                    );
                    assert!(
                        sides[0] * sides[1] < 0.0,
                        "{refined:?}: both tetrahedra on one side of {face:?}"
                    );
                }
            }
            let (r, t) = lattice.counts();
            assert_eq!(r, refined.iter().collect::<HashSet<_>>().len());
            assert!(refined.is_empty() == (t == 0));
        }
    }
}
