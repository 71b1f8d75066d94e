//! Tests of the generator and the sweep: grazing, on-surface, tangent faces, winding,
//! degenerate triangles, bad input.

use std::f64::consts::PI;

use glam::{DQuat, DVec3};
use proptest::prelude::*;

use super::*;

/// A box `[0, sx] x [0, sy] x [0, sz]`, outward.
pub(crate) fn cuboid(s: DVec3) -> (Vec<DVec3>, Vec<[i64; 3]>) {
    let v: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                (i & 1) as f64 * s.x,
                ((i >> 1) & 1) as f64 * s.y,
                ((i >> 2) & 1) as f64 * s.z,
            )
        })
        .collect();
    let t = vec![
        [0, 2, 1],
        [1, 2, 3],
        [4, 5, 6],
        [5, 7, 6],
        [0, 1, 4],
        [1, 5, 4],
        [2, 6, 3],
        [3, 6, 7],
        [0, 4, 2],
        [2, 4, 6],
        [1, 3, 5],
        [3, 7, 5],
    ];
    (v, t)
}

/// A torus about `z` (radii `big`, `small`) with `n x m` quads, outward.
pub(crate) fn torus(big: f64, small: f64, n: usize, m: usize) -> (Vec<DVec3>, Vec<[i64; 3]>) {
    let mut v = Vec::new();
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        for j in 0..m {
            let w = 2.0 * PI * j as f64 / m as f64;
            let r = big + small * w.cos();
            v.push(DVec3::new(r * u.cos(), r * u.sin(), small * w.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as i64;
    let mut t = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b, c, d) = (id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1));
            t.push([a, b, c]);
            t.push([a, c, d]);
        }
    }
    (v, t)
}

/// A closed cylinder about `z` (radius `r`, height `h`, `n` sides), outward.
pub(crate) fn cylinder(r: f64, h: f64, n: usize) -> (Vec<DVec3>, Vec<[i64; 3]>) {
    let mut v = vec![DVec3::ZERO, DVec3::new(0.0, 0.0, h)];
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        v.push(DVec3::new(r * u.cos(), r * u.sin(), 0.0));
        v.push(DVec3::new(r * u.cos(), r * u.sin(), h));
    }
    let lo = |i: usize| (2 + 2 * (i % n)) as i64;
    let hi = |i: usize| (3 + 2 * (i % n)) as i64;
    let mut t = Vec::new();
    for i in 0..n {
        t.push([0, lo(i + 1), lo(i)]);
        t.push([1, hi(i), hi(i + 1)]);
        t.push([lo(i), lo(i + 1), hi(i + 1)]);
        t.push([lo(i), hi(i + 1), hi(i)]);
    }
    (v, t)
}

fn pose(axis: DVec3, angle: f64, t: DVec3) -> Pose {
    Pose::from_rotation_translation(DQuat::from_axis_angle(axis.normalize(), angle), t)
}

/// Body-frame screw from `a` to `b`.
fn rel_velocity(a: &Pose, b: &Pose) -> Velocity {
    Velocity::of_screw(&Screw::between(&Pose::IDENTITY, &a.inverse().mul_pose(b)))
}

/// Distance from `p` to the nearest triangle of `body` (exact point-triangle distance).
pub(crate) fn distance_to_surface(body: &Body, p: DVec3) -> f64 {
    body.triangles()
        .iter()
        .map(|t| {
            let [a, b, c] = t.map(|i| body.vertices()[i as usize]);
            point_triangle(p, a, b, c)
        })
        .fold(f64::INFINITY, f64::min)
}

/// Ericson, Real-Time Collision Detection 5.1.5: closest point on triangle.
pub(crate) fn point_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let ab = b - a;
    let ac = c - a;
    let ap = p - a;
    let d1 = ab.dot(ap);
    let d2 = ac.dot(ap);
    if d1 <= 0.0 && d2 <= 0.0 {
        return p.distance(a);
    }
    let bp = p - b;
    let d3 = ab.dot(bp);
    let d4 = ac.dot(bp);
    if d3 >= 0.0 && d4 <= d3 {
        return p.distance(b);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return p.distance(a + ab * (d1 / (d1 - d3)));
    }
    let cp = p - c;
    let d5 = ab.dot(cp);
    let d6 = ac.dot(cp);
    if d6 >= 0.0 && d5 <= d6 {
        return p.distance(c);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return p.distance(a + ac * (d2 / (d2 - d6)));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return p.distance(b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6))));
    }
    let denom = 1.0 / (va + vb + vc);
    p.distance(a + ab * (vb * denom) + ac * (vc * denom))
}

fn shapes() -> Vec<(&'static str, Body)> {
    let (cv, ct) = cuboid(DVec3::new(1.0, 2.0, 0.5));
    let (yv, yt) = cylinder(0.7, 1.5, 24);
    let (tv, tt) = torus(1.0, 0.35, 24, 12);
    vec![
        ("box", Body::new(&cv, &ct).unwrap()),
        ("cylinder", Body::new(&yv, &yt).unwrap()),
        ("torus", Body::new(&tv, &tt).unwrap()),
    ]
}

fn screws() -> Vec<(Pose, Pose)> {
    vec![
        (
            Pose::IDENTITY,
            pose(DVec3::new(0.3, -0.5, 1.0), 1.3, DVec3::new(2.0, 0.5, -1.0)),
        ),
        (
            pose(DVec3::X, 0.4, DVec3::new(1.0, 2.0, 3.0)),
            pose(DVec3::new(1.0, 1.0, 0.2), 2.8, DVec3::new(-1.0, 0.0, 2.0)),
        ),
        (
            Pose::IDENTITY,
            Pose::from_translation(DVec3::new(3.0, 1.0, 0.5)),
        ),
    ]
}

#[test]
fn generator_points_lie_on_the_surface_and_graze() {
    for (name, body) in shapes() {
        assert!(body.is_closed(), "{name}");
        for (a, b) in screws() {
            let vel = rel_velocity(&a, &b);
            let mut g = Generator::default();
            let mut sc = Scratch::default();
            let tol = g.build(&body, &vel, &mut sc);
            assert!(!g.segments.is_empty(), "{name}: empty generator");
            let scale = body.extent();
            for (i, &p) in g.points.iter().enumerate() {
                let d = distance_to_surface(&body, p);
                assert!(
                    d < 1e-12 * scale,
                    "{name}: point {i} {p} off the surface by {d:e}"
                );
            }
            for s in &g.segments {
                let [pa, pb] = s.ends.map(|i| g.points[i as usize]);
                let mid = 0.5 * (pa + pb);
                let v = vel.at(mid);
                match s.kind {
                    SegmentKind::Characteristic { face } => {
                        let n = body.normals()[face as usize];
                        for q in [pa, mid, pb] {
                            let f = n.dot(vel.at(q));
                            assert!(
                                f.abs() <= 2.0 * tol + 1e-12,
                                "{name}: n.v = {f:e} on face {face}"
                            );
                        }
                    }
                    SegmentKind::Silhouette { edge } => {
                        let e = body.edges()[edge as usize];
                        let [nl, nr] = e.faces.map(|f| body.normals()[f as usize]);
                        assert!(
                            nl.dot(v) * nr.dot(v) < 0.0,
                            "{name}: edge {edge} not a silhouette"
                        );
                        assert_ne!(e.kind, EdgeKind::Concave, "{name}: concave silhouette");
                    }
                    SegmentKind::Border { .. } => {}
                }
                // Outward: the sweep's normal (b - a) x v agrees with the faces' normals.
                let m = match s.kind {
                    SegmentKind::Characteristic { face } => body.normals()[face as usize],
                    SegmentKind::Silhouette { edge } | SegmentKind::Border { edge } => {
                        let e = body.edges()[edge as usize];
                        body.normals()[e.faces[0] as usize] + body.normals()[e.faces[1] as usize]
                    }
                };
                assert!(
                    (pb - pa).cross(v).dot(m) >= 0.0,
                    "{name}: segment {s:?} inward"
                );
            }
        }
    }
}

#[test]
fn rotation_about_a_face_normal_gives_nothing_on_that_face() {
    // The box's top faces (z = 0.5, normal +z) turn in their own plane about an axis along z
    // through (0.2, 0.3, *): n . v = 0 everywhere on them.
    let (v, t) = cuboid(DVec3::new(1.0, 2.0, 0.5));
    let body = Body::new(&v, &t).unwrap();
    let top: Vec<u32> = (0..body.triangles().len() as u32)
        .filter(|&f| body.normals()[f as usize].z > 0.999)
        .collect();
    assert_eq!(top.len(), 2);
    let c = DVec3::new(0.2, 0.3, 0.0);
    let b = Pose::from_rotation_translation(
        DQuat::from_rotation_z(1.1),
        c - DQuat::from_rotation_z(1.1) * c,
    );
    let vel = rel_velocity(&Pose::IDENTITY, &b);
    let mut g = Generator::default();
    let tol = g.build(&body, &vel, &mut Scratch::default());
    assert!(tol > 0.0);
    let top_edges: Vec<u32> = top
        .iter()
        .flat_map(|&f| body.face_edges()[f as usize])
        .collect();
    for s in &g.segments {
        match s.kind {
            SegmentKind::Characteristic { face } => {
                assert!(
                    !top.contains(&face),
                    "characteristic segment on the top face {face}"
                )
            }
            SegmentKind::Silhouette { edge } => {
                assert!(!top_edges.contains(&edge), "silhouette on top edge {edge}")
            }
            SegmentKind::Border { edge } => {
                // Only the top's rim (whole edges bordering the side faces) is kept.
                let e = body.edges()[edge as usize];
                assert_eq!(
                    e.kind,
                    EdgeKind::Convex,
                    "border {edge} is the top's diagonal"
                );
            }
        }
    }
    // The vertical edges through the corners are silhouettes (egress on one side, ingress on
    // the other), and the rim of the top and the bottom is kept: 4 + 4 + 4 segments.
    let sil = g
        .segments
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Silhouette { .. }))
        .count();
    let border = g
        .segments
        .iter()
        .filter(|s| matches!(s.kind, SegmentKind::Border { .. }))
        .count();
    assert_eq!((sil, border), (4, 8), "{:?}", g.segments);
}

#[test]
fn translated_box_keeps_the_rims_of_its_leading_and_trailing_faces() {
    let (v, t) = cuboid(DVec3::ONE);
    let body = Body::new(&v, &t).unwrap();
    let vel = rel_velocity(&Pose::IDENTITY, &Pose::from_translation(DVec3::X));
    let mut g = Generator::default();
    g.build(&body, &vel, &mut Scratch::default());
    assert_eq!(g.segments.len(), 8, "{:?}", g.segments);
    assert_eq!(g.points.len(), 8);
    let out = sweep(
        &body,
        &[Pose::IDENTITY, Pose::from_translation(DVec3::X)],
        &SweepOptions {
            steps: 3,
            caps: true,
            accuracy: Accuracy::Steps,
        },
    )
    .unwrap();
    // Edges along x would sweep along themselves and are not kept; the 8 rim edges of the
    // leading (x = 1) and trailing (x = 0) faces give 3 quads each.
    assert_eq!(out.triangles.len(), 24 + 8 * 3 * 2);
    assert_eq!(out.vertices.len(), 16 + 8 * 4);
}

fn check_mesh(out: &SweptMesh, scale: f64) {
    for (i, t) in out.triangles.iter().enumerate() {
        assert!(
            t.iter().all(|&k| (k as usize) < out.vertices.len()),
            "triangle {i} {t:?}"
        );
        assert!(
            t[0] != t[1] && t[1] != t[2] && t[2] != t[0],
            "triangle {i} {t:?}"
        );
        let [a, b, c] = t.map(|k| out.vertices[k as usize]);
        let area = (b - a).cross(c - a).length();
        assert!(
            area > DEGENERATE_REL * scale * scale,
            "triangle {i} area {area:e}"
        );
        assert!(a.is_finite() && b.is_finite() && c.is_finite());
    }
}

#[test]
fn sweeps_have_no_degenerate_triangles_and_face_outward() {
    for (name, body) in shapes() {
        for (a, b) in screws() {
            let out = sweep(
                &body,
                &[a, b],
                &SweepOptions {
                    steps: 8,
                    caps: true,
                    accuracy: Accuracy::Steps,
                },
            )
            .unwrap();
            check_mesh(&out, body.extent());
            let nt = body.triangles().len();
            assert_eq!(out.cap_triangles, 2 * nt, "{name}");
            assert!(out.triangles.len() > 2 * nt, "{name}");
        }
        // Rotation about an axis through the body: points on the axis do not move; their
        // triangles are dropped, not emitted degenerate.
        let b = pose(DVec3::Z, 2.0, DVec3::ZERO);
        let out = sweep(&body, &[Pose::IDENTITY, b], &SweepOptions::default()).unwrap();
        check_mesh(&out, body.extent());
    }
    // Convex body under a translation: the swept region is convex and every sweep triangle
    // lies on its boundary with its normal pointing away from the region's centre.
    let (v, t) = cuboid(DVec3::new(1.0, 2.0, 0.5));
    let body = Body::new(&v, &t).unwrap();
    let d = DVec3::new(3.0, 1.0, 0.5);
    let out = sweep(
        &body,
        &[Pose::IDENTITY, Pose::from_translation(d)],
        &SweepOptions {
            steps: 4,
            caps: true,
            accuracy: Accuracy::Steps,
        },
    )
    .unwrap();
    let centre = DVec3::new(0.5, 1.0, 0.25) + 0.5 * d;
    let sweeps = &out.triangles[12..out.triangles.len() - 12];
    assert!(!sweeps.is_empty());
    for t in sweeps {
        let [a, b, c] = t.map(|k| out.vertices[k as usize]);
        let n = (b - a).cross(c - a);
        let x = (a + b + c) / 3.0;
        assert!((x - centre).dot(n) > 0.0, "triangle {t:?} faces inward");
    }
}

#[test]
fn polyscrew_with_a_reversal_adds_the_turning_face() {
    // Out along x and back: at the middle pose the leading face (+x) is on the boundary.
    let (v, t) = cuboid(DVec3::ONE);
    let body = Body::new(&v, &t).unwrap();
    let p = [
        Pose::IDENTITY,
        Pose::from_translation(DVec3::new(2.0, 0.0, 0.0)),
        Pose::from_translation(DVec3::new(0.0, 0.0, 0.5)),
    ];
    let out = sweep(
        &body,
        &p,
        &SweepOptions {
            steps: 2,
            caps: false,
            accuracy: Accuracy::Steps,
        },
    )
    .unwrap();
    check_mesh(&out, body.extent());
    // Some joint triangle at x = 3 faces +x.
    assert!(out.triangles.iter().any(|t| {
        let [a, b, c] = t.map(|k| out.vertices[k as usize]);
        (a.x - 3.0).abs() < 1e-12 && (b.x - 3.0).abs() < 1e-12 && (b - a).cross(c - a).x > 0.0
    }));
    assert!(out.cap_triangles > 0 && out.cap_triangles < 12);
}

#[test]
fn bad_input_errors() {
    let (v, t) = cuboid(DVec3::ONE);
    let body = Body::new(&v, &t).unwrap();
    assert_eq!(
        sweep(&body, &[Pose::IDENTITY], &SweepOptions::default()).unwrap_err(),
        Error::TooFew { got: 1, need: 2 }
    );
    assert!(matches!(
        sweep_mesh(&v, &t, &[], &SweepOptions::default()),
        Err(Error::TooFew { got: 0, need: 2 })
    ));
    let two = [Pose::IDENTITY, Pose::from_translation(DVec3::X)];
    for steps in [0, MAX_STEPS + 1] {
        assert!(matches!(
            sweep(
                &body,
                &two,
                &SweepOptions {
                    steps,
                    caps: true,
                    accuracy: Accuracy::Steps
                }
            ),
            Err(Error::Value { what: "steps", .. })
        ));
    }
    let mut nan = two;
    nan[1].translation.y = f64::NAN;
    assert!(matches!(
        sweep(&body, &nan, &SweepOptions::default()),
        Err(Error::BadPose { index: 1, .. })
    ));
    assert!(matches!(
        sweep_mesh(&[], &[], &two, &SweepOptions::default()),
        Err(Error::Degenerate {
            what: "vertices",
            ..
        })
    ));
    // Motionless: just the caps.
    let out = sweep(
        &body,
        &[Pose::IDENTITY, Pose::IDENTITY],
        &SweepOptions::default(),
    )
    .unwrap();
    assert_eq!(out.triangles.len(), 24);
}

#[test]
fn open_and_non_manifold_meshes_sweep() {
    let (v, t) = cuboid(DVec3::ONE);
    // Open: one triangle missing; non-manifold: a fin through an edge; a single triangle.
    let mut fin = t.clone();
    fin.push([0, 2, 7]);
    let meshes = [t[..11].to_vec(), fin, vec![[0, 1, 2]]];
    for tt in meshes {
        let body = Body::new(&v, &tt).unwrap();
        assert!(!body.is_closed());
        for (a, b) in screws() {
            let out = sweep(&body, &[a, b], &SweepOptions::default()).unwrap();
            check_mesh(&out, body.extent());
            let mut g = Generator::default();
            g.build(&body, &rel_velocity(&a, &b), &mut Scratch::default());
            // Every border edge is in the generator whole.
            for (e, edge) in body.edges().iter().enumerate() {
                if edge.kind == EdgeKind::Border {
                    assert!(g
                        .segments
                        .iter()
                        .any(|s| s.kind == SegmentKind::Border { edge: e as u32 }));
                }
            }
        }
    }
}

fn arb_pose() -> impl Strategy<Value = Pose> {
    (
        prop::array::uniform3(-1.0f64..1.0),
        -4.0f64..4.0,
        prop::array::uniform3(-3.0f64..3.0),
    )
        .prop_map(|(ax, ang, t)| {
            let axis = DVec3::from(ax).try_normalize().unwrap_or(DVec3::Z);
            pose(axis, ang, DVec3::from(t))
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(64))]

    /// Random junk never panics: vertices with NaN sometimes, indices out of range sometimes,
    /// repeated and collinear vertices, any poses.
    #[test]
    fn junk_never_panics(
        raw in prop::collection::vec(prop::array::uniform3(prop_oneof![
            8 => -2.0f64..2.0, 1 => Just(0.0), 1 => Just(f64::NAN)]), 0..12),
        tris in prop::collection::vec(prop::array::uniform3(-1i64..13), 0..20),
        poses in prop::collection::vec(arb_pose(), 0..4),
        steps in 0u32..5,
        caps in any::<bool>(),
    ) {
        let v: Vec<DVec3> = raw.iter().map(|&a| DVec3::from(a)).collect();
        let r = sweep_mesh(&v, &tris, &poses, &SweepOptions { steps, caps, accuracy: Accuracy::Steps });
        if let Ok(out) = r {
            for t in &out.triangles {
                prop_assert!(t.iter().all(|&k| (k as usize) < out.vertices.len()));
                prop_assert!(t[0] != t[1] && t[1] != t[2] && t[0] != t[2]);
            }
        }
    }

    /// Valid but arbitrary meshes (random triangles over random points: open, non-manifold,
    /// self-intersecting) sweep along random polyscrews into meshes without degenerate
    /// triangles, and every generator point lies on the surface.
    #[test]
    fn random_meshes_sweep_cleanly(
        raw in prop::collection::vec(prop::array::uniform3(-2.0f64..2.0), 3..10),
        tris in prop::collection::vec(prop::array::uniform3(0usize..10), 1..16),
        poses in prop::collection::vec(arb_pose(), 2..5),
    ) {
        let v: Vec<DVec3> = raw.iter().map(|&a| DVec3::from(a)).collect();
        let tris: Vec<[i64; 3]> = tris.iter().map(|t| t.map(|i| (i % v.len()) as i64)).collect();
        let Ok(body) = Body::new(&v, &tris) else { return Ok(()); };
        let out = sweep(&body, &poses, &SweepOptions { steps: 3, caps: true, accuracy: Accuracy::Steps }).unwrap();
        let s = body.extent();
        for t in &out.triangles {
            let [a, b, c] = t.map(|k| out.vertices[k as usize]);
            prop_assert!((b - a).cross(c - a).length() > DEGENERATE_REL * s * s);
        }
        let mut g = Generator::default();
        g.build(&body, &rel_velocity(&poses[0], &poses[1]), &mut Scratch::default());
        for &p in &g.points {
            prop_assert!(distance_to_surface(&body, p) < 1e-12 * s.max(1.0));
        }
    }
}
