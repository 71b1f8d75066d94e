//! Issue 29, item 1 for the closed boundary: `sweep_closed` driven by a tolerance, and its
//! steps 1 and 2 on several threads giving the one-thread mesh bit for bit.
//!
//! The cases are `closed_tests.rs`'s (a cube on a 120-degree screw with a slide, an L-prism
//! on a half turn, a torus and a cube on a smoothed polyscrew); the reference of a vertex's
//! distance is the exact motion and the body's exact signed distance (`region_sd`).

use super::closed::{guaranteed_cell, CELL_PER_TOLERANCE};
use super::closed_tests::{cases, is_closed_oriented, region_sd};
use super::*;
use crate::error::Error;

/// The tests' tolerance: 3 % of the body's extent (coarser than the default 0.5 %, to keep
/// the debug build's tests short; tests/python/test_sweep_closed.py checks the default).
const TOLERANCE_REL: f64 = 0.03;

/// FNV-1a over every vertex's bits and every triangle: equal meshes, equal digests.
fn digest(out: &ClosedMesh) -> u64 {
    out.vertices
        .iter()
        .flat_map(|v| v.to_array().map(f64::to_bits))
        .chain(out.triangles.iter().flat_map(|t| t.map(u64::from)))
        .fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
            (h ^ x).wrapping_mul(0x0100_0000_01b3)
        })
}

/// The bound reported is within the tolerance asked for, on the cube, the L-prism and the
/// torus (single screws and a smoothed polyscrew), the cell is the rule's, and the vertices
/// sampled lie within the bound of the exact swept boundary (so within the tolerance).
#[test]
fn the_bound_reported_is_within_the_tolerance() {
    for (name, body, poses) in cases().into_iter().take(3) {
        let tolerance = TOLERANCE_REL * body.extent();
        let options = ClosedOptions {
            tolerance: Some(tolerance),
            ..ClosedOptions::default()
        };
        let out = sweep_closed(&body, &poses, &options).unwrap();
        let probes = 150;
        let stride = out.vertices.len().div_ceil(probes).max(1);
        let worst = out
            .vertices
            .iter()
            .step_by(stride)
            .map(|&x| region_sd(name, &body, &poses, x).abs())
            .fold(0.0, f64::max);
        println!(
            "{name}: tolerance {tolerance:.4}, cell {:.4}, bound {:.4} ({} attempt(s)), worst vertex \
             {worst:.4}, {} triangles",
            out.cell,
            out.error_bound,
            out.attempts,
            out.triangles.len()
        );
        assert_eq!(out.tolerance, tolerance, "{name}");
        assert!(
            out.error_bound <= tolerance,
            "{name}: bound {} over the tolerance {tolerance}",
            out.error_bound
        );
        // The first cell, else a finer one (the second attempt's, from the first bound), else
        // the one that cannot miss.
        let (first, least) = (CELL_PER_TOLERANCE * tolerance, guaranteed_cell(tolerance));
        let rule = match out.attempts {
            1 => out.cell == first,
            2 => least <= out.cell && out.cell < first,
            _ => out.cell == least,
        };
        assert!(rule, "{name}: the cell {} is not the rule's", out.cell);
        assert!(worst <= out.vertex_bound, "{name}: a vertex {worst} off");
        assert!(is_closed_oriented(&out.triangles), "{name}: not closed");
    }
}

/// The last attempt's cell keeps the bound within the tolerance whatever the case: the
/// bound at `guaranteed_cell(tolerance)` on every case, the cube's at a tolerance whose first
/// cell is two thirds of the tests' (0.02 of the extent).
#[test]
fn the_guaranteed_cell_meets_its_tolerance() {
    for (name, body, poses) in cases() {
        let tolerance = TOLERANCE_REL * body.extent();
        let cell = guaranteed_cell(tolerance);
        let options = ClosedOptions {
            cell: Some(cell),
            ..ClosedOptions::default()
        };
        let out = sweep_closed(&body, &poses, &options).unwrap();
        println!(
            "{name}: tolerance {tolerance:.4}, guaranteed cell {cell:.4}, bound {:.4} ({:.2} cells)",
            out.error_bound,
            out.error_bound / cell
        );
        assert!(cell < tolerance, "{name}");
        assert!(
            out.error_bound <= tolerance,
            "{name}: {} over {tolerance}",
            out.error_bound
        );
    }
}

/// Steps 1 and 2 on several threads (uneven shares: 2, 3 and 7 threads) give the one-thread
/// mesh, every vertex's bits and every triangle, and the same bound and poses; decimated too
/// (two cases, on 3 threads).
#[test]
fn several_threads_give_the_one_thread_mesh_bit_for_bit() {
    // (Decimated on the L-prism and the torus: flat faces and curved ones.)
    for ((name, body, poses), decimate) in cases().into_iter().flat_map(|case| {
        let curved = matches!(case.0, "L-prism, half turn" | "torus, smoothed polyscrew");
        [(case.clone(), false)]
            .into_iter()
            .chain(curved.then_some((case, true)))
    }) {
        let run = |threads| {
            let options = ClosedOptions {
                tolerance: Some(TOLERANCE_REL * body.extent()),
                threads,
                decimate,
                ..ClosedOptions::default()
            };
            sweep_closed(&body, &poses, &options).unwrap()
        };
        let one = run(1);
        assert!(!one.triangles.is_empty(), "{name}: empty");
        let counts: &[usize] = if decimate { &[3] } else { &[2, 3, 7] };
        for &threads in counts {
            let many = run(threads);
            assert_eq!(digest(&many), digest(&one), "{name}: {threads} threads");
            assert_eq!(many.vertices.len(), one.vertices.len(), "{name}");
            assert_eq!(
                many.error_bound.to_bits(),
                one.error_bound.to_bits(),
                "{name}"
            );
            assert_eq!(many.poses, one.poses, "{name}");
        }
    }
}

/// `closed_work` tells the cell, tolerance and dense poses `sweep_closed` then uses (its first
/// attempt), without sampling anything.
#[test]
fn the_work_told_before_is_the_work_done() {
    for (name, body, poses) in cases().into_iter().take(2) {
        for options in [
            ClosedOptions {
                tolerance: Some(TOLERANCE_REL * body.extent()),
                ..ClosedOptions::default()
            },
            ClosedOptions {
                cell: Some(0.05 * body.extent()),
                ..ClosedOptions::default()
            },
        ] {
            let work = closed_work(&body, &poses, &options).unwrap();
            let out = sweep_closed(&body, &poses, &options).unwrap();
            assert_eq!(out.attempts, 1, "{name}");
            assert_eq!(
                (work.cell, work.tolerance, work.poses),
                (out.cell, out.tolerance, out.poses),
                "{name}"
            );
            assert!(
                work.grid_points > out.vertices.len() / 3,
                "{name}: {work:?}"
            );
            assert!(work.body_points > 0, "{name}");
        }
        // The default: 0.5 % of the extent, and the work grows as the tolerance shrinks.
        let default = closed_work(&body, &poses, &ClosedOptions::default()).unwrap();
        assert_eq!(
            default.tolerance,
            DEFAULT_CLOSED_TOLERANCE_REL * body.extent(),
            "{name}"
        );
        let coarse = closed_work(
            &body,
            &poses,
            &ClosedOptions {
                tolerance: Some(2.0 * default.tolerance),
                ..ClosedOptions::default()
            },
        )
        .unwrap();
        assert!(
            coarse.grid_points * 5 < default.grid_points,
            "{name}: {coarse:?} {default:?}"
        );
        assert!(coarse.poses < default.poses, "{name}");
    }
}

/// A cell and a tolerance together, a tolerance that is not positive or finite, or one too
/// fine for the grid's limit, are refused with the argument named.
#[test]
fn bad_tolerances_are_refused() {
    let (name, body, poses) = cases().remove(0);
    let extent = body.extent();
    let both = ClosedOptions {
        cell: Some(0.05 * extent),
        tolerance: Some(0.05 * extent),
        ..ClosedOptions::default()
    };
    assert!(
        matches!(
            sweep_closed(&body, &poses, &both),
            Err(Error::Conflict { what: "cell", .. })
        ),
        "{name}"
    );
    for bad in [0.0, -1.0, f64::NAN, f64::INFINITY, extent / 2000.0] {
        let options = ClosedOptions {
            tolerance: Some(bad),
            ..ClosedOptions::default()
        };
        for result in [
            sweep_closed(&body, &poses, &options).map(|_| ()),
            closed_work(&body, &poses, &options).map(|_| ()),
        ] {
            match result {
                Err(Error::Value {
                    what: "tolerance", ..
                }) => {}
                other => panic!("{name}: tolerance {bad}: {other:?}"),
            }
        }
    }
}

/// `sweep_closed_watched` reports its progress as it goes, never lower (a watcher on another
/// thread reads it every millisecond), ends at 1 and gives `sweep_closed`'s mesh bit for bit;
/// asked to stop before it starts or partway, it stops with `Error::Cancelled`, the rest of
/// its work not done (its progress stays below 1; at 0 for a stop before it starts). The same
/// decimated, stopped within the collapses.
#[test]
fn progress_is_reported_and_a_stop_is_honoured() {
    for decimate in [false, true] {
        progress_with(decimate);
    }
}

fn progress_with(decimate: bool) {
    use crate::Progress;
    use std::time::Duration;
    let (name, body, poses) = cases().swap_remove(1);
    let options = ClosedOptions {
        tolerance: Some(TOLERANCE_REL * body.extent()),
        threads: 2,
        decimate,
        ..ClosedOptions::default()
    };
    let plain = sweep_closed(&body, &poses, &options).unwrap();
    // Runs the sweep while a watcher reads the progress (and stops the run at `stop_at`).
    let watched = |stop_at: f64| {
        let progress = Progress::new();
        let (out, seen) = std::thread::scope(|scope| {
            let worker = scope.spawn(|| sweep_closed_watched(&body, &poses, &options, &progress));
            let mut seen = vec![progress.fraction()];
            while !worker.is_finished() {
                std::thread::sleep(Duration::from_millis(1));
                seen.push(progress.fraction());
                if seen[seen.len() - 1] >= stop_at {
                    progress.cancel();
                }
            }
            (worker.join().unwrap(), seen)
        });
        (out, seen, progress.fraction())
    };
    let (out, seen, last) = watched(f64::INFINITY);
    let distinct = seen.windows(2).filter(|w| w[1] != w[0]).count();
    println!(
        "{name}: {} reads of the progress, {distinct} changes",
        seen.len()
    );
    assert!(seen.windows(2).all(|w| w[1] >= w[0]), "{name}: lowered");
    assert!(distinct >= 10, "{name}: {distinct} changes of the progress");
    assert_eq!(last, 1.0, "{name}");
    assert_eq!(digest(&out.unwrap()), digest(&plain), "{name}");

    // (Decimated, 0.6 is within the collapses: they start at 0.21 + 0.79 * 0.45.)
    let stop_at = if decimate { 0.6 } else { 0.3 };
    let (out, _, at) = watched(stop_at);
    println!("{name}: stopped at {at:.3}");
    assert!(matches!(out, Err(Error::Cancelled)), "{name}: {out:?}");
    assert!((stop_at..1.0).contains(&at), "{name}: stopped at {at}");

    let early = Progress::new();
    early.cancel();
    let out = sweep_closed_watched(&body, &poses, &options, &early);
    assert!(matches!(out, Err(Error::Cancelled)), "{name}: {out:?}");
    assert_eq!(early.fraction(), 0.0, "{name}: work done after the stop");
}
