//! Criterion benchmark of Blender's F-curve evaluation (`polyscrew::fcurve`), in thread CPU
//! time (`common::CpuTime`): 10 Bezier curves x 100,000 frames (a key every 10 frames,
//! 10,000 keys per curve) and 1,000 Bezier curves x 1,000 frames (a key every 10 frames, 100
//! keys per curve); keys with random values and handles, some pulled past their neighbours.
//! Times are whole frames and subframes in increasing order, as a bake asks for them; one
//! case repeats the first with the times shuffled.
mod common;

use std::hint::black_box;

use common::{CpuTime, Rng};
use criterion::{criterion_group, criterion_main, Criterion, Throughput};
use polyscrew::fcurve::{evaluate_fcurves, Extrapolation, FCurve, Key};

/// `n` Bezier keys every 10 frames from frame 1, random values and handles.
fn bezier_curve(n: usize, rng: &mut Rng) -> FCurve {
    let keys = (0..n)
        .map(|i| {
            let x = 1.0 + 10.0 * i as f32;
            let y = (rng.next() * 10.0 - 5.0) as f32;
            // Handles 1 to 12 frames long: the longer ones reach past the neighbour key.
            let (l, r) = (
                (1.0 + rng.next() * 11.0) as f32,
                (1.0 + rng.next() * 11.0) as f32,
            );
            let (dl, dr) = (
                (rng.next() * 6.0 - 3.0) as f32,
                (rng.next() * 6.0 - 3.0) as f32,
            );
            Key::new(x, y).with_handles([x - l, y + dl], [x + r, y + dr])
        })
        .collect();
    FCurve::new(keys, Extrapolation::Linear, None).unwrap()
}

fn bench(c: &mut Criterion<CpuTime>) {
    let mut rng = Rng(17);
    let long: Vec<FCurve> = (0..10).map(|_| bezier_curve(10_000, &mut rng)).collect();
    let long_times: Vec<f64> = (0..100_000).map(|i| 1.0 + i as f64 * 0.99999).collect();
    let mut shuffled = long_times.clone();
    for i in (1..shuffled.len()).rev() {
        let j = (rng.next() * (i + 1) as f64) as usize;
        shuffled.swap(i, j.min(i));
    }
    let many: Vec<FCurve> = (0..1000).map(|_| bezier_curve(100, &mut rng)).collect();
    let many_times: Vec<f64> = (0..1000).map(|i| 1.0 + i as f64 * 0.99).collect();

    let mut g = c.benchmark_group("fcurve");
    g.sample_size(20);
    g.throughput(Throughput::Elements(1_000_000));
    g.bench_function("10 Bezier curves x 100,000 frames", |b| {
        b.iter(|| evaluate_fcurves(black_box(&long), black_box(&long_times)).unwrap())
    });
    g.bench_function("10 Bezier curves x 100,000 frames, shuffled", |b| {
        b.iter(|| evaluate_fcurves(black_box(&long), black_box(&shuffled)).unwrap())
    });
    g.bench_function("1,000 Bezier curves x 1,000 frames", |b| {
        b.iter(|| evaluate_fcurves(black_box(&many), black_box(&many_times)).unwrap())
    });
    g.finish();
}

criterion_group! {
    name = benches;
    config = Criterion::default().with_measurement(CpuTime);
    targets = bench
}
criterion_main!(benches);
