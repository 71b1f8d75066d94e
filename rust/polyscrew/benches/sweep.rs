//! Criterion benchmark of the swept region: a 100,000-triangle bumpy torus over 64 screws
//! (65 poses on a helical path with tumbling), 8 steps per screw, caps on.
//! The triangle count of the output is printed once.
use std::f64::consts::PI;
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DQuat, DVec3};
use polyscrew::sweep::{sweep, sweep_mesh, Accuracy, Body, SweepOptions};
use polyscrew::Pose;

/// A bumpy torus with `n x m` quads (`2 n m` triangles).
fn bumpy_torus(n: usize, m: usize) -> (Vec<DVec3>, Vec<[i64; 3]>) {
    let mut v = Vec::with_capacity(n * m);
    for i in 0..n {
        let u = 2.0 * PI * i as f64 / n as f64;
        for j in 0..m {
            let w = 2.0 * PI * j as f64 / m as f64;
            let s = 0.22 * (1.0 + 0.25 * (5.0 * u).sin() * (3.0 * w).cos());
            let r = 0.6 + s * w.cos();
            v.push(DVec3::new(r * u.cos(), r * u.sin(), s * w.sin()));
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as i64;
    let mut t = Vec::with_capacity(2 * n * m);
    for i in 0..n {
        for j in 0..m {
            t.push([id(i, j), id(i + 1, j), id(i + 1, j + 1)]);
            t.push([id(i, j), id(i + 1, j + 1), id(i, j + 1)]);
        }
    }
    (v, t)
}

/// 65 poses: a helix with a tumbling rotation.
fn motion() -> Vec<Pose> {
    (0..=64)
        .map(|i| {
            let s = i as f64 / 64.0;
            let axis = DVec3::new(0.3, 1.0, 0.5).normalize();
            Pose::from_rotation_translation(
                DQuat::from_axis_angle(axis, 3.0 * s),
                DVec3::new(
                    3.0 * (2.0 * PI * s).cos(),
                    3.0 * (2.0 * PI * s).sin(),
                    2.0 * s,
                ),
            )
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let (v, t) = bumpy_torus(250, 200);
    assert_eq!(t.len(), 100_000);
    let poses = motion();
    let opts = SweepOptions {
        steps: 8,
        caps: true,
        accuracy: Accuracy::Steps,
    };
    let out = sweep_mesh(&v, &t, &poses, &opts).unwrap();
    println!(
        "sweep: {} triangles in, 64 screws, 8 steps: {} triangles out ({} generator segments, {} cap/band triangles); stroboscopic 64 x 8 + 1 instances would be {} triangles",
        t.len(),
        out.triangles.len(),
        out.generator_segments,
        out.cap_triangles,
        (64 * 8 + 1) * t.len()
    );
    // CPU time of the thread (Linux /proc/thread-self/schedstat, ns on CPU): on a shared,
    // loaded machine the wall times below include waiting for a core.
    let cpu_ns = || -> Option<u64> {
        let s = std::fs::read_to_string("/proc/thread-self/schedstat").ok()?;
        s.split_whitespace().next()?.parse().ok()
    };
    if let Some(before) = cpu_ns() {
        let runs = 5;
        let wall = std::time::Instant::now();
        for _ in 0..runs {
            black_box(sweep_mesh(&v, &t, &poses, &opts).unwrap());
        }
        let wall = wall.elapsed().as_secs_f64() / runs as f64;
        if let Some(after) = cpu_ns() {
            println!(
                "sweep: CPU time per sweep (from arrays) {:.3} s (wall {:.3} s)",
                (after - before) as f64 * 1e-9 / runs as f64,
                wall
            );
        }
    }
    let mut g = c.benchmark_group("sweep");
    g.sample_size(10);
    g.bench_function("100k triangles, 64 screws, 8 steps (from arrays)", |b| {
        b.iter(|| sweep_mesh(black_box(&v), black_box(&t), black_box(&poses), &opts).unwrap())
    });
    let body = Body::new(&v, &t).unwrap();
    g.bench_function("100k triangles, 64 screws, 8 steps (body prepared)", |b| {
        b.iter(|| sweep(black_box(&body), black_box(&poses), &opts).unwrap())
    });
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
