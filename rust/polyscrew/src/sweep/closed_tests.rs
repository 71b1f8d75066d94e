//! Issue 29, item 2: the closed boundary of the swept region.
//!
//! References independent of the code under test: the exact motion `s(p_i, t, p_{i+1})`
//! sampled densely and refined (`min_over_motion`), the body's exact signed distance (a closed
//! form for the box; point-triangle distances signed by the winding number for a mesh); the
//! mesh's closedness counted on its directed edges; self-intersections by a segment-triangle
//! test over every pair of triangles whose boxes share a cell of a uniform grid.

use std::collections::HashMap;
use std::f64::consts::PI;

use glam::DVec3;

use super::body::longest_edge_squared;
use super::closed::{point_triangle_distance, DECIMATE_TARGET};
use super::tests::{cuboid, torus};
use super::tolerance_tests::{l_prism, min_over_motion, screw_pose, sd_box, smoothed_motion};
use super::*;

/// Signed distance from `p` to a closed body (negative inside: winding number above 1/2).
fn sd_mesh(body: &Body, p: DVec3) -> f64 {
    let v = body.vertices();
    let d = body
        .triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| v[i as usize]);
            point_triangle_distance(p, a, b, c)
        })
        .fold(f64::INFINITY, f64::min);
    if winding(v, body.triangles(), p) > 0.5 {
        -d
    } else {
        d
    }
}

/// The winding number of the closed mesh `(v, t)` about `p`: its triangles' solid angles seen
/// from `p` (Van Oosterom and Strackee), summed, over 4 pi.
fn winding(v: &[DVec3], t: &[[u32; 3]], p: DVec3) -> f64 {
    let mut solid = 0.0;
    for tri in t {
        let [ra, rb, rc] = tri.map(|i| v[i as usize] - p);
        let (la, lb, lc) = (ra.length(), rb.length(), rc.length());
        let num = ra.dot(rb.cross(rc));
        let den = la * lb * lc + ra.dot(rb) * lc + rb.dot(rc) * la + rc.dot(ra) * lb;
        solid += 2.0 * num.atan2(den);
    }
    solid / (4.0 * PI)
}

/// Every directed edge once and its reverse once: closed and consistently oriented.
pub(super) fn is_closed_oriented(t: &[[u32; 3]]) -> bool {
    let mut count: HashMap<(u32, u32), u32> = HashMap::new();
    for tri in t {
        for e in 0..3 {
            *count.entry((tri[e], tri[(e + 1) % 3])).or_default() += 1;
        }
    }
    count
        .iter()
        .all(|(&(a, b), &n)| n == 1 && count.get(&(b, a)) == Some(&1))
}

fn orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    (b - a).cross(c - a).dot(d - a)
}

/// Whether the segment `(p, q)` crosses the triangle: its ends on either side of the
/// triangle's plane and the crossing inside the triangle, each by more than round-off (a
/// volume of `eps` = `ROUNDOFF` times the cube of the longest length involved): coplanar
/// pieces of a flat face are not crossings.
fn segment_crosses(p: DVec3, q: DVec3, [a, b, c]: [DVec3; 3]) -> bool {
    const ROUNDOFF: f64 = 1e-12;
    let l = (q - p)
        .length()
        .max((b - a).length())
        .max((c - b).length())
        .max((a - c).length());
    let eps = ROUNDOFF * l * l * l;
    let (sp, sq) = (orient(a, b, c, p), orient(a, b, c, q));
    if !((sp > eps && sq < -eps) || (sp < -eps && sq > eps)) {
        return false;
    }
    let (s1, s2, s3) = (orient(p, q, a, b), orient(p, q, b, c), orient(p, q, c, a));
    (s1 > eps && s2 > eps && s3 > eps) || (s1 < -eps && s2 < -eps && s3 < -eps)
}

/// Pairs of triangles that intersect other than along what they share.
fn self_intersections(v: &[DVec3], t: &[[u32; 3]], cell: f64) -> usize {
    let key = |p: DVec3| (p / cell).floor().to_array().map(|x| x as i64);
    let mut grid: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (i, tri) in t.iter().enumerate() {
        let [a, b, c] = tri.map(|k| v[k as usize]);
        let (lo, hi) = (key(a.min(b).min(c)), key(a.max(b).max(c)));
        for x in lo[0]..=hi[0] {
            for y in lo[1]..=hi[1] {
                for z in lo[2]..=hi[2] {
                    grid.entry([x, y, z]).or_default().push(i as u32);
                }
            }
        }
    }
    let mut bad = std::collections::HashSet::new();
    for list in grid.values() {
        for (n, &i) in list.iter().enumerate() {
            for &j in &list[n + 1..] {
                let (ti, tj) = (t[i as usize], t[j as usize]);
                let shared = ti.iter().filter(|k| tj.contains(k)).count();
                if shared >= 2 {
                    continue;
                }
                let (pi, pj) = (ti.map(|k| v[k as usize]), tj.map(|k| v[k as usize]));
                let crosses = |ta: [u32; 3], pa: [DVec3; 3], tb: [u32; 3], pb: [DVec3; 3]| {
                    (0..3).any(|e| {
                        let (x, y) = (ta[e], ta[(e + 1) % 3]);
                        // An edge through a shared vertex meets the other there.
                        !(tb.contains(&x) || tb.contains(&y))
                            && segment_crosses(pa[e], pa[(e + 1) % 3], pb)
                    })
                };
                if crosses(ti, pi, tj, pj) || crosses(tj, pj, ti, pi) {
                    bad.insert((i.min(j), i.max(j)));
                }
            }
        }
    }
    bad.len()
}

/// The closed mesh's self-intersecting pairs at its vertices as Blender keeps them, float32.
fn crossing_pairs(out: &ClosedMesh) -> usize {
    let rounded: Vec<DVec3> = out
        .vertices
        .iter()
        .map(|v| v.as_vec3().as_dvec3())
        .collect();
    self_intersections(&rounded, &out.triangles, 2.0 * out.cell)
}

/// The cases of issue 29: a unit cube on a 120-degree screw with a slide, an L-prism on a
/// half turn, a torus and a cube on a smoothed polyscrew (4 keys, 24 screws).
/// The tests' cell: 4 % of the body's extent (coarser than the default, to keep the debug
/// build's tests short; tests/python/test_sweep_closed.py checks the default).
const CELL_REL: f64 = 0.04;

/// The contoured mesh as it is (`decimate` off; the decimation test takes it on).
fn options(body: &Body) -> ClosedOptions {
    ClosedOptions {
        cell: Some(CELL_REL * body.extent()),
        decimate: false,
        ..ClosedOptions::default()
    }
}

pub(super) fn cases() -> Vec<(&'static str, Body, Vec<Pose>)> {
    let (cv, ct) = cuboid(DVec3::ONE);
    let cube = Body::new(&cv, &ct).unwrap();
    let (lv, lt) = l_prism(0.5);
    let prism = Body::new(&lv, &lt).unwrap();
    let (tv, tt) = torus(0.6, 0.22, 24, 12);
    let ring = Body::new(&tv, &tt).unwrap();
    vec![
        (
            "cube, 120-degree screw with slide",
            cube.clone(),
            vec![
                Pose::IDENTITY,
                screw_pose(DVec3::Z, DVec3::new(3.0, 0.5, 0.0), 2.0 * PI / 3.0, 1.0),
            ],
        ),
        (
            "L-prism, half turn",
            prism,
            vec![
                Pose::IDENTITY,
                screw_pose(
                    DVec3::new(0.3, 0.2, 1.0),
                    DVec3::new(3.0, 0.0, 0.0),
                    PI * 0.999,
                    0.5,
                ),
            ],
        ),
        ("torus, smoothed polyscrew", ring, smoothed_motion()),
        ("cube, smoothed polyscrew", cube, smoothed_motion()),
    ]
}

#[test]
fn the_closed_boundary_is_closed_oriented_and_without_self_intersections() {
    for (name, body, poses) in cases() {
        let start = std::time::Instant::now();
        let out = sweep_closed(&body, &poses, &options(&body)).unwrap();
        let seconds = start.elapsed().as_secs_f64();
        let crossing = crossing_pairs(&out);
        println!(
            "{name}: {seconds:.3} s, {} vertices, {} triangles, cell {:.4}, {} poses, volume {:.4}, \
             bound {:.2e}, self-intersecting pairs {crossing}",
            out.vertices.len(),
            out.triangles.len(),
            out.cell,
            out.poses,
            out.volume(),
            out.error_bound
        );
        assert!(!out.triangles.is_empty(), "{name}: empty");
        assert!(is_closed_oriented(&out.triangles), "{name}: not closed");
        assert_eq!(crossing, 0, "{name}: self-intersecting triangles");
        assert_eq!(degenerate(&out), 0, "{name}: degenerate triangles");
        assert!(out.volume() > body.signed_volume(), "{name}");
    }
}

/// Triangles with (almost) no area: twice the area at most [`ZERO_AREA_REL`] (`1e-12`) times
/// the longest edge squared, the rule `Body::new` refuses and `scripts/bench/sweep_measures.py`
/// counts.
fn degenerate(out: &ClosedMesh) -> usize {
    out.triangles
        .iter()
        .filter(|t| {
            let p = t.map(|i| out.vertices[i as usize]);
            (p[1] - p[0]).cross(p[2] - p[0]).length() <= ZERO_AREA_REL * longest_edge_squared(p)
        })
        .count()
}

/// `ClosedOptions::decimate`: the mesh is still closed, oriented and uncrossed (at the float32
/// Blender keeps), its vertices are some of the full mesh's, bit for bit, with the same bound,
/// at most 0.6 of its triangles, its volume within 0.2 % of the full mesh's, and every face
/// point of 120 of the triangles the collapses made (20 on the torus) within the bound plus
/// what the collapses allow of the swept boundary: twice [`DECIMATE_TARGET`] cells, the most a
/// flat triangle's distance from a sheet smooth or slightly kinked across it exceeds its edges'
/// midpoints' (`decimate.rs`). The triangles kept from the full mesh are held to its own rule
/// (`every_face_point_lies_within_the_bound`: within that or half a cell): the cube's
/// corner-cutting triangle 0.30 cells off, one of a strip of coplanar triangles across a crease
/// whose inner edges the crease pass never splits (their two triangles face the same way), came
/// into the sample when stop 43's crease collapses changed which triangles are left. Slow in a
/// debug build (`scripts/test.sh` runs it in release).
#[test]
#[ignore = "slow in a debug build: scripts/test.sh runs it in release"]
fn decimation_keeps_some_of_the_vertices_closed_uncrossed_and_near() {
    for (name, body, poses) in cases() {
        let full = sweep_closed(&body, &poses, &options(&body)).unwrap();
        let fewer = ClosedOptions {
            decimate: true,
            ..options(&body)
        };
        let out = sweep_closed(&body, &poses, &fewer).unwrap();
        let crossing = crossing_pairs(&out);
        let (v_full, v_out) = (full.volume(), out.volume());
        println!(
            "{name}: {} of {} triangles, volume {v_out:.5} against {v_full:.5},              self-intersecting pairs {crossing}",
            out.triangles.len(),
            full.triangles.len()
        );
        assert!(is_closed_oriented(&out.triangles), "{name}: not closed");
        assert_eq!(crossing, 0, "{name}: self-intersecting triangles");
        let bits = |v: &DVec3| v.to_array().map(f64::to_bits);
        let kept: std::collections::HashSet<[u64; 3]> = full.vertices.iter().map(bits).collect();
        assert!(
            out.vertices.iter().all(|v| kept.contains(&bits(v))),
            "{name}"
        );
        assert_eq!(out.error_bound, full.error_bound, "{name}");
        assert_eq!(out.vertex_bound, full.vertex_bound, "{name}");
        assert!(
            out.triangles.len() * 10 <= full.triangles.len() * 6,
            "{name}: {} of {} triangles",
            out.triangles.len(),
            full.triangles.len()
        );
        assert!((v_out / v_full - 1.0).abs() <= 0.002, "{name}");
        // The triangles the collapses made, and those kept from the full mesh (by their
        // corners' bits).
        let corners = |m: &ClosedMesh, t: &[u32; 3]| {
            let mut k = t.map(|i| bits(&m.vertices[i as usize]));
            k.sort_unstable();
            k
        };
        let before: std::collections::HashSet<[[u64; 3]; 3]> =
            full.triangles.iter().map(|t| corners(&full, t)).collect();
        let (kept, made): (Vec<[u32; 3]>, Vec<[u32; 3]>) = out
            .triangles
            .iter()
            .partition(|t| before.contains(&corners(&out, t)));
        let allowed = out.vertex_bound + 2.0 * DECIMATE_TARGET * out.cell;
        let extent = body.extent();
        let worst = |triangles: Vec<[u32; 3]>, enough: f64| {
            let part = ClosedMesh {
                triangles,
                ..out.clone()
            };
            let d = mesh_face_distances((name, &body, &poses), &part, [120, 20], enough);
            d[d.len() - 1] * extent
        };
        let (worst_made, worst_kept) = (worst(made, allowed), worst(kept, 0.5 * out.cell));
        println!(
            "{name}: worst face point {worst_made:e} on the collapses' triangles (allowed \
             {allowed:e}), {worst_kept:e} on those kept"
        );
        assert!(
            worst_made <= allowed,
            "{name}: a face point {worst_made:e} off"
        );
        assert!(
            worst_kept <= allowed.max(0.5 * out.cell),
            "{name}: a kept face point {worst_kept:e} off"
        );
    }
}

/// A case's region signed distance at `x`: the exact motion (`min_over_motion`), the body's
/// exact signed distance (closed form for the cube, `sd_mesh` otherwise).
pub(super) fn region_sd(name: &str, body: &Body, poses: &[Pose], x: DVec3) -> f64 {
    let is_cube = name.starts_with("cube");
    min_over_motion(poses, &|p: &Pose| {
        let q = p.inverse().transform_point3(x);
        if is_cube {
            sd_box(q, DVec3::ONE)
        } else {
            sd_mesh(body, q)
        }
    })
}

#[test]
fn every_vertex_lies_on_the_swept_boundary_within_the_bound() {
    for (name, body, poses) in cases() {
        let out = sweep_closed(&body, &poses, &options(&body)).unwrap();
        let is_cube = name.starts_with("cube");
        let sd = |x: DVec3| region_sd(name, &body, &poses, x);
        let probes = if is_cube { 1000 } else { 150 };
        let stride = out.vertices.len().div_ceil(probes).max(1);
        let worst = out
            .vertices
            .iter()
            .step_by(stride)
            .map(|&x| sd(x).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: worst vertex distance {worst:.2e}, vertices' bound {:.2e}, extent {:.3}",
            out.vertex_bound,
            body.extent()
        );
        assert!(
            worst <= out.vertex_bound && out.vertex_bound <= out.error_bound,
            "{name}: {worst:e} over {:e}",
            out.vertex_bound
        );
    }
}

/// The narrow band evaluates the region's field only where the boundary can be: the mesh is
/// the dense grid's, vertex for vertex and triangle for triangle (the band holds every sign
/// change, with the dense grid's values and poses there). The two single screws (convex and
/// non-convex body): the dense grid is the slow reference.
#[test]
fn the_narrow_band_gives_the_dense_grids_mesh() {
    use super::closed::{sweep_closed_with, Evaluation};
    for (name, body, poses) in cases().into_iter().take(2) {
        let time = |evaluation| {
            let start = std::time::Instant::now();
            let out = sweep_closed_with(
                &body,
                &poses,
                &options(&body),
                evaluation,
                &crate::Progress::new(),
            )
            .unwrap();
            (start.elapsed().as_secs_f64(), out)
        };
        let (dense_s, dense) = time(Evaluation::Dense);
        let (band_s, band) = time(Evaluation::NarrowBand);
        println!(
            "{name}: dense {dense_s:.3} s, narrow band {band_s:.3} s, {} triangles",
            band.triangles.len()
        );
        assert!(!band.triangles.is_empty(), "{name}: empty");
        assert_eq!(band.triangles, dense.triangles, "{name}: triangles");
        assert_eq!(band.vertices, dense.vertices, "{name}: vertices");
        assert_eq!(band.error_bound, dense.error_bound, "{name}: bound");
    }
}

/// An upper bound on the distance from `x` to the boundary of the region whose signed
/// distance is `sd` (1-Lipschitz): `sd(x)` outside; from inside, the shortest way out found
/// by sphere tracing (a step of `|sd| + eta` never goes further out than the boundary by more
/// than `eta`) along `dir` (unit: the face's normal), then, unless that way is within `enough`,
/// along the reference's own gradient (central differences) and the 26 directions of a cube's
/// neighbours; `f64::INFINITY` if no way out is found within `reach`.
///
/// One direction is not enough: a sliver triangle's normal can lie along the boundary, and
/// a point a hair inside then runs beside the boundary without crossing it.
fn boundary_distance(
    sd: &dyn Fn(DVec3) -> f64,
    x: DVec3,
    dir: DVec3,
    eta: f64,
    [enough, reach]: [f64; 2],
) -> f64 {
    let g = sd(x);
    if g >= 0.0 {
        return g;
    }
    // The way out along `d`, if shorter than `best`.
    let way_out = |d: DVec3, best: f64| {
        let (mut s, mut g) = (0.0, g);
        while s < best {
            s += -g + eta;
            g = sd(x + s * d);
            if g >= 0.0 {
                return s;
            }
        }
        f64::INFINITY
    };
    let mut best = way_out(dir, reach);
    if best <= enough {
        return best;
    }
    let h = eta;
    let gradient = DVec3::new(
        sd(x + h * DVec3::X) - sd(x - h * DVec3::X),
        sd(x + h * DVec3::Y) - sd(x - h * DVec3::Y),
        sd(x + h * DVec3::Z) - sd(x - h * DVec3::Z),
    );
    let lattice = (0..27).filter(|&k| k != 13).map(|k| {
        DVec3::new(
            (k % 3) as f64 - 1.0,
            ((k / 3) % 3) as f64 - 1.0,
            (k / 9) as f64 - 1.0,
        )
    });
    for d in std::iter::once(gradient).chain(lattice) {
        if best <= enough {
            break;
        }
        if let Some(d) = d.try_normalize() {
            best = best.min(way_out(d, best.min(reach)));
        }
    }
    best
}

/// The face points checked on a triangle: its corners, edge midpoints, centre and three
/// interior barycentric points.
fn face_points([a, b, c]: [DVec3; 3]) -> [DVec3; 10] {
    let bary = |u: f64, v: f64| u * a + v * b + (1.0 - u - v) * c;
    [
        a,
        b,
        c,
        0.5 * (a + b),
        0.5 * (b + c),
        0.5 * (c + a),
        (a + b + c) / 3.0,
        bary(0.6, 0.2),
        bary(0.2, 0.6),
        bary(0.2, 0.2),
    ]
}

/// Each case's sweep at `cell_rel` of the body's extent (`None`: at its defaults, the
/// tolerance's cell), and the distance bounds of the face points of about `triangles[0]` of its
/// triangles (`triangles[1]` for the torus, whose exact distance is slow), an even stride
/// through them: (name, mesh, extent, distances relative to the extent, sorted).
fn face_distances(
    cell_rel: Option<f64>,
    triangles: [usize; 2],
) -> Vec<(&'static str, ClosedMesh, f64, Vec<f64>)> {
    let mut out = Vec::new();
    for (name, body, poses) in cases() {
        let extent = body.extent();
        let mesh = sweep_closed(
            &body,
            &poses,
            &ClosedOptions {
                cell: cell_rel.map(|c| c * extent),
                // The contoured mesh at the tests' cell; at the defaults, what a user gets.
                decimate: cell_rel.is_none(),
                ..ClosedOptions::default()
            },
        )
        .unwrap();
        // A way out within the bound ends a point's search (a way out within the tolerance,
        // as up to stop 43 at the defaults, made every figure printed nearly the tolerance).
        let d = mesh_face_distances((name, &body, &poses), &mesh, triangles, mesh.error_bound);
        out.push((name, mesh, extent, d));
    }
    out
}

/// The distance bounds of the face points of about `triangles[0]` of a case's mesh's triangles
/// (`triangles[1]` for the torus, whose exact distance is slow), an even stride through them,
/// relative to the body's extent, sorted; a way out within `enough` ends a point's search.
fn mesh_face_distances(
    (name, body, poses): (&str, &Body, &[Pose]),
    mesh: &ClosedMesh,
    triangles: [usize; 2],
    enough: f64,
) -> Vec<f64> {
    let extent = body.extent();
    let sd = |x: DVec3| region_sd(name, body, poses, x);
    let probes = if name.starts_with("torus") {
        triangles[1]
    } else {
        triangles[0]
    };
    let stride = mesh.triangles.len().div_ceil(probes).max(1);
    let eta = 1e-4 * extent;
    let reach = 4.0 * mesh.cell;
    let mut d: Vec<f64> = mesh
        .triangles
        .iter()
        .step_by(stride)
        .flat_map(|t| {
            let p = t.map(|k| mesh.vertices[k as usize]);
            let n = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
            face_points(p).map(|x| boundary_distance(&sd, x, n, eta, [enough, reach]) / extent)
        })
        .collect();
    d.sort_by(f64::total_cmp);
    d
}

/// Prints each case's face-point distances (worst, 99th percentile, bound, volume; % of the
/// extent) and returns (name, worst distance, 99th percentile, bound, vertices' bound, extent)
/// per case.
fn face_report(
    cell_rel: Option<f64>,
    triangles: [usize; 2],
) -> Vec<(&'static str, f64, f64, f64, f64, f64)> {
    face_distances(cell_rel, triangles)
        .into_iter()
        .map(|(name, mesh, extent, d)| {
            let (worst, p99) = (d[d.len() - 1], d[(d.len() * 99) / 100]);
            println!(
                "{name}: {} triangles, {} face points, worst {:.3} %, 99th percentile {:.3} %, \
                 bound {:.3} % of the extent, volume {:.5}",
                mesh.triangles.len(),
                d.len(),
                100.0 * worst,
                100.0 * p99,
                100.0 * mesh.error_bound / extent,
                mesh.volume()
            );
            (
                name,
                worst * extent,
                p99 * extent,
                mesh.error_bound,
                mesh.vertex_bound,
                extent,
            )
        })
        .collect()
}

/// Issue 29: face points (corners, edge midpoints, centres, interior points), not only the
/// vertices, near the swept boundary (the exact motion, the body's exact distance), on the four
/// cases at the tests' cell, the contoured mesh: every one within the reported bound, and 99 in
/// 100 within its part for the vertices alone (`vertex_bound`, as up to stop 43). Since
/// stop 44 every edge's midpoint is read, split when off (`crease.rs`) and covered by the bound
/// when a split is refused; up to stop 43 only edges between triangles at an angle were read,
/// strips of coplanar triangles cut across creases, faces were up to about 0.4 cells off, and
/// this test allowed half a cell over a bound that covered the vertices alone. Measured at stop
/// 44: worst 0.28, 0.87, 0.14 and 0.75 % of the extent against bounds of 0.90, 1.96, 1.60 and
/// 0.85 % (the coarse cell leaves some splits refused, up to half a cell off). Before the grid's
/// signs were settled exactly and creases split, faces across creases were up to 0.97 % (cube),
/// 1.83 % (L-prism) and 2.86 % (smoothed cube) of the extent off, over bounds of 1.16, 1.31 and
/// 1.51 %. `cargo test --release -- --ignored face_point` (`scripts/test.sh` runs it).
#[test]
#[ignore = "slow in a debug build: scripts/test.sh runs it in release"]
fn every_face_point_lies_within_the_bound() {
    for (name, worst, p99, bound, vertices, _) in face_report(Some(CELL_REL), [120, 20]) {
        assert!(
            p99 <= vertices,
            "{name}: the 99th percentile face point {p99:e} off, over the vertices' bound \
             {vertices:e}"
        );
        assert!(
            worst <= bound,
            "{name}: a face point {worst:e} off, over the bound {bound:e}"
        );
    }
}

/// Issue 29's claim at the sweep's defaults (the default tolerance, 0.5 % of the extent, and
/// fewer triangles), with more points: every face point within the tolerance of the swept
/// boundary, and the bound within it. Measured at stop 44: worst 0.28 % (cube), 0.33 %
/// (L-prism), 0.10 % (torus) and 0.45 % (smoothed cube) of the extent, against bounds of 0.28,
/// 0.33, 0.46 and 0.45 % (the worst points are edges' midpoints whose splits were refused: the
/// bound covers them). Slow in a debug build: `cargo test --release -- --ignored face_point`
/// (`scripts/test.sh` runs it).
#[test]
#[ignore = "slow in a debug build: scripts/test.sh runs it in release"]
fn face_points_at_the_defaults() {
    for (name, worst, _, bound, _, extent) in face_report(None, [1500, 150]) {
        let tolerance = DEFAULT_CLOSED_TOLERANCE_REL * extent;
        assert!(
            worst <= tolerance,
            "{name}: a face point {worst:e} off, over the tolerance {tolerance:e}"
        );
        assert!(
            bound <= tolerance,
            "{name}: the bound {bound:e} over the tolerance {tolerance:e}"
        );
    }
}

/// The body's distance grid skips a triangle at a point only where a bound shows it cannot
/// lower the point's least distance: every value is the float32 of the least distance over
/// all triangles (clamped to the band), as testing every triangle at every point gives, on a
/// tilted torus (small triangles at every slope) and the L-prism (large flat ones).
#[test]
fn the_body_grid_holds_the_least_distance_over_every_triangle() {
    let (tv, tt) = torus(0.6, 0.22, 16, 8);
    let tilt = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 0.2);
    let tv: Vec<DVec3> = tv.iter().map(|&v| tilt * v).collect();
    let (lv, lt) = l_prism(0.5);
    for (name, v, t, h) in [("torus", tv, tt, 0.05), ("L-prism", lv, lt, 0.09)] {
        let body = Body::new(&v, &t).unwrap();
        let band = 0.2;
        let (origin, [nx, ny, nz], values) =
            super::closed::body_distance_grid(&body, h, band).unwrap();
        let verts = body.vertices();
        let mut within = 0;
        for k in 0..nz {
            for j in 0..ny {
                for i in 0..nx {
                    let p = origin + DVec3::new(i as f64, j as f64, k as f64) * h;
                    let least = body
                        .triangles()
                        .iter()
                        .map(|t| {
                            let [a, b, c] = t.map(|i| verts[i as usize]);
                            point_triangle_distance(p, a, b, c)
                        })
                        .fold(band, f64::min);
                    within += usize::from(least < band);
                    let got = values[(k * ny + j) * nx + i].abs();
                    assert_eq!(got, least as f32, "{name}: point ({i}, {j}, {k})");
                }
            }
        }
        assert!(within > 1000, "{name}: {within} points in the band");
    }
}

/// Uniform numbers in `[0, 1)` from a xorshift generator seeded with `seed` (not 0).
fn uniform_from(mut seed: u64) -> impl FnMut() -> f64 {
    move || {
        seed ^= seed << 13;
        seed ^= seed >> 7;
        seed ^= seed << 17;
        (seed >> 11) as f64 / (1u64 << 53) as f64
    }
}

/// The refinement's bounds skip only poses above the minimum: at points near the swept
/// boundary of the L-prism's half turn and the torus's smoothed motion (the tests' cell), the
/// exact minimum over the motion (`exact_all`, given any upper bound of it) is bit for bit the
/// least exact distance over every refined pose, the minimum near a sample (`exact_near`) is
/// the least over the poses around it, and with those intervals left out (`known`) the
/// minimum elsewhere is below it exactly when the least over every pose is.
#[test]
fn the_pruned_minima_are_every_poses_least() {
    let mut uniform = uniform_from(0x9e37_79b9_7f4a_7c15);
    for (name, body, poses) in cases().into_iter().filter(|c| !c.0.starts_with("cube")) {
        let cell = 0.04 * body.extent();
        // Points about the instances at the key poses and between them (world), near the
        // boundary or inside: the body's box grown by two cells, at a point of each screw.
        let (lo, hi) = body
            .vertices()
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
                (a.min(p), b.max(p))
            });
        let (lo, hi) = (lo - DVec3::splat(2.0 * cell), hi + DVec3::splat(2.0 * cell));
        let mut points = Vec::new();
        while points.len() < 1500 {
            let k = ((uniform() * (poses.len() - 1) as f64) as usize).min(poses.len() - 2);
            let pose = crate::s(&poses[k], uniform(), &poses[k + 1]);
            let y = lo + (hi - lo) * DVec3::new(uniform(), uniform(), uniform());
            points.push(pose.transform_point3(y));
        }
        let lifts: Vec<f64> = points.iter().map(|_| uniform() * cell).collect();
        // Half the points read at the sample nearest their minimum, half up to 4 samples off.
        let shifts: Vec<i64> = (0..points.len() as i64)
            .map(|k| if k % 2 == 0 { 0 } else { (k / 2) % 9 - 4 })
            .collect();
        let minima =
            super::closed::motion_minima(&body, &poses, cell, &points, &lifts, &shifts).unwrap();
        // The exact distance is exact within this of the surface (the band less a list cell's
        // reach: `the_exact_distance_equals_the_winding_number_reference`), clamped beyond.
        let reach = super::closed::BAND_CELLS * cell - 3f64.sqrt() * (cell / 4.0 + cell / 12.0);
        let (mut near, mut exact) = (0, 0);
        for (x, [least, all, at_j, least_at_j, elsewhere]) in points.iter().zip(minima) {
            near += usize::from(least.abs() < 2.0 * cell);
            if least.abs() >= reach {
                continue;
            }
            exact += 1;
            assert_eq!(
                all.to_bits(),
                least.to_bits(),
                "{name}: at {x:?} {all} against {least}"
            );
            assert_eq!(
                at_j.to_bits(),
                least_at_j.to_bits(),
                "{name}: near, at {x:?}"
            );
            assert_eq!(
                elsewhere < at_j,
                least < at_j,
                "{name}: elsewhere, at {x:?}"
            );
            assert_eq!(
                at_j.min(elsewhere).to_bits(),
                least.to_bits(),
                "{name}: at {x:?}"
            );
        }
        assert!(
            near > 300,
            "{name}: {near} points within two cells of the boundary"
        );
        assert!(exact > 500, "{name}: {exact} points within the exact reach");
    }
}

/// The exact distance the refinement reads equals the winding-number reference (`sd_mesh`)
/// at random points around the L-prism and a tilted torus, wherever it is within reach of
/// its lists (`|d|` below the band less a list cell's reach), and elsewhere has the sign of
/// the reference and at least that magnitude; its gradient is a unit vector along which the
/// reference grows at rate 1.
/// The exact distance's lists, made slab by slab on several threads (stop 45), are those of
/// one thread, each in triangle order (what they hold is checked by the next test, against
/// the winding number).
#[test]
fn the_exact_lists_do_not_depend_on_the_thread_count() {
    let (tv, tt) = torus(0.6, 0.22, 24, 12);
    let body = Body::new(&tv, &tt).unwrap();
    let cell = 0.02 * body.extent();
    let (start, items) = super::closed::exact_lists(&body, cell, 1).unwrap();
    assert!(items.len() > 10_000, "{} items", items.len());
    assert_eq!(start.last().map(|&s| s as usize), Some(items.len()));
    for list in start.windows(2) {
        let cell_items = &items[list[0] as usize..list[1] as usize];
        assert!(
            cell_items.windows(2).all(|w| w[0] < w[1]),
            "not in triangle order"
        );
    }
    for threads in [2, 3, 7] {
        let many = super::closed::exact_lists(&body, cell, threads).unwrap();
        assert!(many == (start.clone(), items.clone()), "{threads} threads");
    }
}

#[test]
fn the_exact_distance_equals_the_winding_number_reference() {
    let (tv, tt) = torus(0.6, 0.22, 16, 8);
    let tilt = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 0.2);
    let tv: Vec<DVec3> = tv.iter().map(|&v| tilt * v).collect();
    let (lv, lt) = l_prism(0.5);
    let mut uniform = uniform_from(0x2545_f491_4f6c_dd1d);
    for (name, v, t) in [("torus", tv, tt), ("L-prism", lv, lt)] {
        let body = Body::new(&v, &t).unwrap();
        let cell = 0.04 * body.extent();
        let band = super::closed::BAND_CELLS * cell;
        // A list cell's point is within `sqrt(3) (cell / 2) / 2 + sqrt(3) (cell / 6) / 2` of
        // its test point.
        let reach = band - 3f64.sqrt() * (cell / 4.0 + cell / 12.0);
        let exact = super::closed::exact_distance(&body, cell).unwrap();
        let (lo, hi) = body
            .vertices()
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(a, b), &p| {
                (a.min(p), b.max(p))
            });
        let (lo, hi) = (lo - DVec3::splat(band), hi + DVec3::splat(band));
        let (mut near, mut checked) = (0, 0);
        while checked < 10_000 {
            let p = lo + (hi - lo) * DVec3::new(uniform(), uniform(), uniform());
            let want = sd_mesh(&body, p);
            let (got, gradient) = exact(p);
            if want.abs() < reach {
                near += 1;
                assert!(
                    (got - want).abs() <= 1e-12 * body.extent(),
                    "{name}: at {p:?} {got} against {want}"
                );
                let g = gradient.expect("a gradient within reach");
                assert!((g.length() - 1.0).abs() < 1e-9, "{name}: gradient {g:?}");
                let step = 1e-6 * body.extent();
                let slope = (sd_mesh(&body, p + step * g) - want) / step;
                assert!(slope > 0.999, "{name}: at {p:?} slope {slope} along {g:?}");
            } else {
                assert!(
                    got.signum() == want.signum() && got.abs() >= reach,
                    "{name}: at {p:?} {got} against {want} (beyond reach)"
                );
            }
            checked += 1;
        }
        assert!(near > 2000, "{name}: {near} points within reach");
    }
}

/// A unit cube passes along x, climbs, crosses over and comes back down and along beside its
/// first pass, `gap` (under half a cell) away: the outside slab between the two passes is
/// narrower than a cell and every grid point around it is inside (the world grid's planes
/// across y fall outside the slab here: the grid's origin is the instances' lowest corner less
/// the band and two cells). The cubes there are cut finer (`adaptive.rs`), and the slab stays
/// outside: points on its middle plane are outside the mesh, whose volume is the union's
/// exactly computed `10 + gap` within a quarter of the slab's (`4 gap`); the mesh is closed,
/// oriented and uncrossed, and every vertex is within the bound of the boundary.
#[test]
#[ignore = "slow in a debug build: scripts/test.sh runs it in release"]
fn a_channel_narrower_than_a_cell_between_two_passes_stays_outside() {
    let (cv, ct) = cuboid(DVec3::ONE);
    let cube = Body::new(&cv, &ct).unwrap();
    let cell = 0.2;
    let gap = 0.45 * cell;
    let side = 1.0 + gap;
    let poses: Vec<Pose> = [
        [0.0, 0.0, 0.0],
        [2.0, 0.0, 0.0],
        [2.0, 0.0, 2.0],
        [2.0, side, 2.0],
        [2.0, side, 0.0],
        [0.0, side, 0.0],
    ]
    .map(|t| Pose::from_translation(DVec3::from_array(t)))
    .to_vec();
    let out = sweep_closed(
        &cube,
        &poses,
        &ClosedOptions {
            cell: Some(cell),
            ..ClosedOptions::default()
        },
    )
    .unwrap();
    let v = out.volume();
    println!(
        "{} triangles, volume {v:.5} (exact {:.5}, with the slab filled {:.5}), bound {:.2e}",
        out.triangles.len(),
        10.0 + gap,
        10.0 + 5.0 * gap,
        out.error_bound
    );
    assert!(is_closed_oriented(&out.triangles));
    assert_eq!(crossing_pairs(&out), 0);
    for x in [0.25, 1.0, 1.75] {
        for z in [0.2, 0.5, 0.8] {
            let p = DVec3::new(x, 1.0 + 0.5 * gap, z);
            let sd = region_sd("cube", &cube, &poses, p);
            assert!(sd > 0.2 * gap, "the probe {p} is not in the slab: {sd}");
            let w = winding(&out.vertices, &out.triangles, p);
            assert!(w.abs() < 0.1, "{p} is inside the mesh: winding number {w}");
        }
    }
    assert!((v - (10.0 + gap)).abs() < gap, "volume {v}");
    let worst = out
        .vertices
        .iter()
        .map(|&x| region_sd("cube", &cube, &poses, x).abs())
        .fold(0.0, f64::max);
    assert!(
        worst <= out.vertex_bound,
        "a vertex {worst:e} off, bound {:e}",
        out.vertex_bound
    );
}
