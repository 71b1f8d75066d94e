//! Issue 29, item 1: the steps of each screw chosen from a tolerance.
//!
//! The reference is the exact motion `s(p_i, t, p_{i+1})` (the minimal screw between two
//! poses), sampled densely and refined around its best samples, and the body's exact distance
//! (a closed form for a box, point-triangle distances for a mesh). Every point of every output
//! triangle that matters (its corners, its edge midpoints, among them the centre of each swept
//! quad, and its centroid) must lie within the tolerance of the body's surface at some pose of
//! the motion; on a convex body whose swept surfaces all lie on the region's boundary, within
//! the tolerance of the boundary of the union of all the instances.

use std::f64::consts::PI;

use glam::{DQuat, DVec3};

use super::tests::{cuboid, distance_to_surface, torus};
use super::*;
use crate::motion::subdivision::{subdivide, Scheme};

/// Signed distance from `p` to the box `[0, s]` (negative inside).
pub(super) fn sd_box(p: DVec3, size: DVec3) -> f64 {
    let c = 0.5 * size;
    let q = (p - c).abs() - c;
    q.max(DVec3::ZERO).length() + q.x.max(q.y).max(q.z).min(0.0)
}

/// The minimum of `f(pose)` over the motion through `poses` (the exact screws between them):
/// `64 / screws` samples per screw (at least 12), then the best `BEST` samples refined four
/// times by `FINE` samples over a neighbourhood of one sample spacing (a final spacing of
/// about `1e-6` of a screw). `Screw::eval` is `s(p_i, t, p_{i+1})`.
pub(super) fn min_over_motion(poses: &[Pose], f: &dyn Fn(&Pose) -> f64) -> f64 {
    const FINE: usize = 24;
    const BEST: usize = 4;
    let spans = poses.len() - 1;
    // Fewer coarse samples on the short screws of a polyscrew.
    let coarse_per_span = (64 / spans).max(12);
    // `s(p_i, t, p_{i+1})`, its screw found once per span.
    let screws: Vec<Screw> = poses
        .windows(2)
        .map(|w| Screw::between(&w[0], &w[1]))
        .collect();
    let at = |u: f64| {
        let i = (u.floor() as usize).min(spans - 1);
        f(&screws[i].eval(u - i as f64))
    };
    let n = spans * coarse_per_span;
    let mut coarse: Vec<(f64, f64)> = (0..=n)
        .map(|j| {
            let u = j as f64 / coarse_per_span as f64;
            (at(u), u)
        })
        .collect();
    coarse.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut best = coarse[0].0;
    for &(_, u0) in coarse.iter().take(BEST) {
        let mut centre = u0;
        let mut width = 1.0 / coarse_per_span as f64;
        for _ in 0..4 {
            let mut local = (f64::INFINITY, centre);
            for j in 0..=FINE {
                let u = (centre - width + 2.0 * width * j as f64 / FINE as f64)
                    .clamp(0.0, spans as f64);
                let v = at(u);
                if v < local.0 {
                    local = (v, u);
                }
            }
            best = best.min(local.0);
            centre = local.1;
            width *= 2.0 / FINE as f64;
        }
    }
    best
}

/// The points of each triangle checked: its corners, edge midpoints and centroid.
fn probe_points(out: &SweptMesh) -> Vec<DVec3> {
    let mut pts = Vec::with_capacity(7 * out.triangles.len());
    for t in &out.triangles {
        let [a, b, c] = t.map(|k| out.vertices[k as usize]);
        pts.extend([
            a,
            b,
            c,
            0.5 * (a + b),
            0.5 * (b + c),
            0.5 * (c + a),
            (a + b + c) / 3.0,
        ]);
    }
    pts.sort_by(|p, q| p.to_array().partial_cmp(&q.to_array()).unwrap());
    pts.dedup();
    pts
}

/// Rotation by `angle` about the axis through `point` along `axis`, then a slide along it.
pub(super) fn screw_pose(axis: DVec3, point: DVec3, angle: f64, slide: f64) -> Pose {
    let axis = axis.normalize();
    let q = DQuat::from_axis_angle(axis, angle);
    Pose::from_rotation_translation(q, point - q * point + slide * axis)
}

/// An L-shaped prism (non-convex): the L `(0,0) (2,0) (2,1) (1,1) (1,2) (0,2)` extruded by
/// `h` along z (20 triangles, wound either way: `Body::new` turns it outward).
pub(super) fn l_prism(h: f64) -> (Vec<DVec3>, Vec<[i64; 3]>) {
    let l = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 1.0),
        (1.0, 1.0),
        (1.0, 2.0),
        (0.0, 2.0),
    ];
    let mut v: Vec<DVec3> = l.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    v.extend(l.iter().map(|&(x, y)| DVec3::new(x, y, h)));
    let mut t: Vec<[i64; 3]> = Vec::new();
    // Fans from the reflex corner 3, which sees the whole L.
    for (a, b) in [(4, 5), (5, 0), (0, 1), (1, 2)] {
        t.push([3, b, a]);
        t.push([9, a + 6, b + 6]);
    }
    for i in 0..6i64 {
        let j = (i + 1) % 6;
        t.push([i, j, j + 6]);
        t.push([i, j + 6, i + 6]);
    }
    (v, t)
}

/// A smoothed polyscrew: 4 keys, 4-point subdivision, 3 levels (25 poses, 24 screws).
pub(super) fn smoothed_motion() -> Vec<Pose> {
    let keys = [
        Pose::IDENTITY,
        screw_pose(
            DVec3::new(0.2, 1.0, 0.3),
            DVec3::new(1.0, 0.0, 0.0),
            1.1,
            0.4,
        ),
        screw_pose(
            DVec3::new(1.0, -0.3, 0.5),
            DVec3::new(0.5, 2.0, 0.0),
            2.2,
            1.0,
        ),
        screw_pose(
            DVec3::new(-0.4, 0.2, 1.0),
            DVec3::new(2.0, 1.0, 1.0),
            3.0,
            2.0,
        ),
    ];
    subdivide(&keys, Scheme::FourPoint, 3, false).unwrap()
}

/// The largest distance of a probe point from the body's surface at the nearest pose of the
/// motion, `surface(p)` the unsigned distance from a body-frame point to the body's surface.
/// At most `max_probes` probe points, evenly strided (a mesh body's distance is costly).
fn worst_distance(
    out: &SweptMesh,
    poses: &[Pose],
    surface: &dyn Fn(DVec3) -> f64,
    max_probes: usize,
) -> f64 {
    let probes = probe_points(out);
    let stride = probes.len().div_ceil(max_probes).max(1);
    probes
        .into_iter()
        .step_by(stride)
        .map(|x| min_over_motion(poses, &|p: &Pose| surface(p.inverse().transform_point3(x))))
        .fold(0.0, f64::max)
}

fn mesh_surface(body: &Body) -> impl Fn(DVec3) -> f64 + '_ {
    move |p| distance_to_surface(body, p)
}

#[test]
fn chord_steps_meet_the_closed_form_and_are_the_fewest() {
    for &(theta, rho, tol) in &[
        (2.0 * PI / 3.0, 1.0, 1e-3),
        (PI, 3.0, 2e-3),
        (0.01, 1.0, 1e-3),
        (1.0, 1e-6, 1e-3),
        (2.5, 10.0, 1e-6),
    ] {
        let (k, bound) = chord_steps(theta, rho, tol, 1);
        let sag = |k: u32| rho * (1.0 - (theta / (2.0 * k as f64)).cos());
        assert!(
            sag(k) <= 0.5 * tol && (bound - sag(k)).abs() <= 1e-15,
            "theta {theta} rho {rho} tol {tol}: k {k} sagitta {}",
            sag(k)
        );
        assert!(
            k == 1 || sag(k - 1) > 0.5 * tol,
            "theta {theta} rho {rho} tol {tol}: {} steps would do",
            k - 1
        );
        // `steps` stays a minimum.
        assert_eq!(chord_steps(theta, rho, tol, k + 5).0, k + 5);
    }
    assert_eq!(chord_steps(0.0, 1.0, 1e-3, 3), (3, 0.0));
}

/// Cube, L-prism and torus, on one long screw (120 degrees with a slide) and on a smoothed
/// polyscrew: every probe point within the tolerance of the body at some pose, and the bound
/// the sweep reports met; with 2 fixed steps (the former default of the add-on) it is not.
#[test]
fn every_point_is_within_the_tolerance_of_the_body_along_the_motion() {
    let (cv, ct) = cuboid(DVec3::ONE);
    let (lv, lt) = l_prism(0.5);
    let (tv, tt) = torus(1.0, 0.35, 12, 6);
    let cube = Body::new(&cv, &ct).unwrap();
    let lbody = Body::new(&lv, &lt).unwrap();
    let tbody = Body::new(&tv, &tt).unwrap();
    let long = vec![
        Pose::IDENTITY,
        screw_pose(
            DVec3::new(0.3, 0.2, 1.0),
            DVec3::new(0.5, -1.0, 0.0),
            2.0 * PI / 3.0,
            1.0,
        ),
    ];
    let smooth = smoothed_motion();
    let half_turn = vec![
        Pose::IDENTITY,
        screw_pose(DVec3::Z, DVec3::new(0.5, 0.5, 0.0), PI * 0.999, 0.0),
    ];
    let box_surface = |p: DVec3| sd_box(p, DVec3::ONE).abs();
    let l_surface = mesh_surface(&lbody);
    let t_surface = mesh_surface(&tbody);
    type Case<'a> = (
        &'a str,
        &'a Body,
        &'a [Pose],
        &'a dyn Fn(DVec3) -> f64,
        usize,
    );
    let cases: [Case; 6] = [
        ("cube, 120-degree screw", &cube, &long, &box_surface, 4000),
        (
            "cube, smoothed polyscrew",
            &cube,
            &smooth,
            &box_surface,
            3000,
        ),
        ("L-prism, half turn", &lbody, &half_turn, &l_surface, 1500),
        (
            "L-prism, smoothed polyscrew",
            &lbody,
            &smooth,
            &l_surface,
            500,
        ),
        ("torus, 120-degree screw", &tbody, &long, &t_surface, 500),
        (
            "torus, smoothed polyscrew",
            &tbody,
            &smooth[..9],
            &t_surface,
            300,
        ),
    ];
    for (name, body, poses, surface, max_probes) in cases {
        let tol = DEFAULT_TOLERANCE_REL * 0.5 * body.extent();
        let out = sweep(body, poses, &SweepOptions::default()).unwrap();
        let worst = worst_distance(&out, poses, surface, max_probes);
        let coarse = sweep(
            body,
            poses,
            &SweepOptions {
                steps: 2,
                caps: true,
                accuracy: Accuracy::Steps,
            },
        )
        .unwrap();
        let worst_coarse = worst_distance(&coarse, poses, surface, max_probes);
        println!(
            "{name}: tolerance {tol:.2e}: {} triangles, at most {} steps per screw, bound {:.2e}, \
             measured {worst:.2e} (2 steps: {} triangles, measured {worst_coarse:.2e})",
            out.triangles.len(),
            out.max_steps,
            out.error_bound,
            coarse.triangles.len(),
        );
        assert_eq!(out.tolerance, tol, "{name}");
        assert!(out.error_bound <= tol, "{name}: bound {}", out.error_bound);
        // The measured error is within the bound (plus the reference's sampling, 1e-2 tol).
        assert!(
            worst <= out.error_bound + 1e-2 * tol,
            "{name}: worst {worst:e} over the bound {:e}",
            out.error_bound
        );
        if name.contains("120") || name.contains("half") {
            assert!(
                worst_coarse > tol,
                "{name}: 2 steps already within the tolerance"
            );
        }
    }
}

/// A cube standing on an edge towards a 120-degree screw whose axis runs outside it (turned
/// by 45 degrees about z: its nearest and farthest parts from the axis are edges, so that no
/// characteristic line crosses a face inside the region): every swept surface lies on the
/// region's boundary, so every probe point is within the tolerance of the boundary of the
/// union of the instances (signed distance: the minimum over the motion of the box's).
#[test]
fn convex_sweep_lies_on_the_union_boundary_within_the_tolerance() {
    let (cv, ct) = cuboid(DVec3::ONE);
    let cube = Body::new(&cv, &ct).unwrap();
    let turn = screw_pose(DVec3::Z, DVec3::new(0.5, 0.5, 0.0), PI / 4.0, 0.0);
    let poses = [
        turn,
        screw_pose(DVec3::Z, DVec3::new(3.0, 0.5, 0.0), 2.0 * PI / 3.0, 1.0).mul_pose(&turn),
    ];
    let tol = DEFAULT_TOLERANCE_REL * 0.5 * cube.extent();
    let out = sweep(
        &cube,
        &poses,
        &SweepOptions {
            caps: false,
            ..SweepOptions::default()
        },
    )
    .unwrap();
    let sd = |x: DVec3| {
        min_over_motion(&poses, &|p: &Pose| {
            sd_box(p.inverse().transform_point3(x), DVec3::ONE)
        })
    };
    let probes = probe_points(&out);
    let stride = probes.len().div_ceil(4000);
    let values: Vec<f64> = probes.into_iter().step_by(stride).map(sd).collect();
    let (lo, hi) = values
        .iter()
        .fold((f64::INFINITY, f64::NEG_INFINITY), |(lo, hi), &v| {
            (lo.min(v), hi.max(v))
        });
    println!(
        "cube on a 120-degree screw, axis outside: {} probe points, signed distance to the union \
         in [{lo:.2e}, {hi:.2e}], tolerance {tol:.2e}, bound {:.2e}, {} steps",
        values.len(),
        out.error_bound,
        out.max_steps
    );
    assert!(-lo <= tol && hi <= tol, "[{lo:e}, {hi:e}] against {tol:e}");
}

#[test]
fn a_bad_tolerance_is_refused() {
    let (cv, ct) = cuboid(DVec3::ONE);
    let cube = Body::new(&cv, &ct).unwrap();
    let two = [Pose::IDENTITY, Pose::from_translation(DVec3::X)];
    for accuracy in [
        Accuracy::Tolerance(0.0),
        Accuracy::Tolerance(-1.0),
        Accuracy::Tolerance(f64::NAN),
        Accuracy::Relative(f64::INFINITY),
    ] {
        let options = SweepOptions {
            accuracy,
            ..SweepOptions::default()
        };
        assert!(
            matches!(
                sweep(&cube, &two, &options),
                Err(Error::Value {
                    what: "tolerance",
                    expected: Expected::Positive("length"),
                    ..
                })
            ),
            "{accuracy:?}"
        );
    }
}
