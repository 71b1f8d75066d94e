//! A finer grid over the memory budget does not throw away the closed boundary already made:
//! `sweep_closed` returns the last attempt's mesh, with its bound over the tolerance and the
//! budget's refusal as the reason. Its own binary: the memory budget is process-wide, and this
//! is the only test here.

use std::collections::HashMap;
use std::f64::consts::PI;

use glam::{DQuat, DVec3};
use polyscrew::sweep::{closed_work, sweep_closed, Body, ClosedOptions};
use polyscrew::{Error, Pose};

/// An L-shaped prism (non-convex): the L `(0,0) (2,0) (2,1) (1,1) (1,2) (0,2)` extruded by
/// 0.5 along z, its faces fanned from the reflex corner.
fn l_prism() -> Body {
    let l = [(0., 0.), (2., 0.), (2., 1.), (1., 1.), (1., 2.), (0., 2.)];
    let mut v: Vec<DVec3> = l.iter().map(|&(x, y)| DVec3::new(x, y, 0.0)).collect();
    v.extend(l.iter().map(|&(x, y)| DVec3::new(x, y, 0.5)));
    let mut t: Vec<[i64; 3]> = Vec::new();
    for (a, b) in [(4, 5), (5, 0), (0, 1), (1, 2)] {
        t.push([3, b, a]);
        t.push([9, a + 6, b + 6]);
    }
    for i in 0..6 {
        let j = (i + 1) % 6;
        t.push([i, j, j + 6]);
        t.push([i, j + 6, i + 6]);
    }
    Body::new(&v, &t).unwrap()
}

/// A half turn about a tilted axis through `(3, 0, 0)`, with a slide along it.
fn half_turn() -> Vec<Pose> {
    let axis = DVec3::new(0.3, 0.2, 1.0).normalize();
    let point = DVec3::new(3.0, 0.0, 0.0);
    let q = DQuat::from_axis_angle(axis, 0.999 * PI);
    vec![
        Pose::IDENTITY,
        Pose::from_rotation_translation(q, point - q * point + 0.5 * axis),
    ]
}

/// Every edge in exactly two triangles, once each way.
fn closed_oriented(triangles: &[[u32; 3]]) -> bool {
    let mut edges: HashMap<(u32, u32), usize> = HashMap::new();
    for t in triangles {
        for e in 0..3 {
            *edges.entry((t[e], t[(e + 1) % 3])).or_default() += 1;
        }
    }
    edges
        .iter()
        .all(|(&(a, b), &n)| n == 1 && edges.get(&(b, a)) == Some(&1))
}

#[test]
fn a_finer_grid_over_the_budget_keeps_the_mesh_made_and_says_why() {
    let body = l_prism();
    let poses = half_turn();
    // A coarse tolerance (a 4 % cell) at which the first bound exceeds the tolerance: with the
    // default budget a second grid meets it (tests/python/test_sweep_closed_tolerance.py).
    let options = ClosedOptions {
        tolerance: Some(0.04 / 3.0 * body.extent()),
        decimate: false,
        threads: 2,
        ..ClosedOptions::default()
    };
    // A budget that holds the first attempt's grids, not the finer ones.
    let first = closed_work(&body, &poses, &options).unwrap();
    let old = polyscrew::set_memory_budget(first.bytes);
    let kept = sweep_closed(&body, &poses, &options);
    polyscrew::set_memory_budget(old);
    let kept = kept.unwrap();

    assert_eq!(kept.attempts, 1);
    assert_eq!(kept.cell, first.cell);
    assert!(
        kept.error_bound > kept.tolerance,
        "{} within {}",
        kept.error_bound,
        kept.tolerance
    );
    match &kept.finer_refused {
        Some(Error::Memory {
            bytes,
            budget: Some(budget),
            ..
        }) => assert!(*budget == first.bytes && *bytes > first.bytes),
        other => panic!("not the budget's refusal: {other:?}"),
    }
    // The mesh is the first attempt's, bit for bit: the one its cell gives.
    let at_first = sweep_closed(
        &body,
        &poses,
        &ClosedOptions {
            cell: Some(first.cell),
            tolerance: None,
            ..options
        },
    )
    .unwrap();
    assert_eq!(kept.vertices, at_first.vertices);
    assert_eq!(kept.triangles, at_first.triangles);
    assert_eq!(kept.error_bound, at_first.error_bound);
    assert!(closed_oriented(&kept.triangles));
    assert!(kept.volume() > 0.0);
}
