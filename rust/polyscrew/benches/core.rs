//! Criterion benchmarks of the core: `s(a, t, b)` (ours one by one and in batches through
//! `s_many`, and nalgebra's dual-quaternion ScLERP in the same run) and subdivision (100 keys x 6 levels per scheme, 1,000 keys x 6
//! levels Jarek). Measured in thread CPU time (groups `s`, `subdivide`; see
//! `common::CpuTime`) and, for `s`, also in wall-clock time (group `s wall-clock`). The
//! growth over 10 .. 10,000 keys x 1 .. 8 levels is in `scaling.rs`.

mod common;

use std::hint::black_box;

use common::nalgebra_conv::to_nalgebra;
use common::{keys, CpuTime, Rng};
use criterion::measurement::{Measurement, WallTime};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use polyscrew::{s, s_many, subdivide, Pose, Scheme, Screw};

fn bench_s_cpu(c: &mut Criterion<CpuTime>) {
    bench_s(c, "s");
}

fn bench_s_wall(c: &mut Criterion<WallTime>) {
    bench_s(c, "s wall-clock");
}

fn bench_s<M: Measurement>(c: &mut Criterion<M>, group: &str) {
    let mut rng = Rng(7);
    let pairs: Vec<(Pose, Pose, f64)> = (0..1024)
        .map(|_| (rng.pose(3.0), rng.pose(3.0), rng.next()))
        .collect();
    let na: Vec<_> = pairs
        .iter()
        .map(|(a, b, t)| (to_nalgebra(a), to_nalgebra(b), *t))
        .collect();
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(pairs.len() as u64));
    g.bench_function("polyscrew s(a, t, b)", |bench| {
        bench.iter(|| {
            for (a, b, t) in &pairs {
                black_box(s(black_box(a), *t, black_box(b)));
            }
        })
    });
    g.bench_function("polyscrew s_many (batch of 1024)", |bench| {
        let (a, t, b): (Vec<Pose>, Vec<f64>, Vec<Pose>) = {
            let mut a = Vec::new();
            let mut t = Vec::new();
            let mut b = Vec::new();
            for (pa, pb, pt) in &pairs {
                a.push(*pa);
                b.push(*pb);
                t.push(*pt);
            }
            (a, t, b)
        };
        let mut out = vec![Pose::IDENTITY; pairs.len()];
        bench.iter(|| {
            s_many(black_box(&a), black_box(&t), black_box(&b), &mut out).unwrap();
            black_box(&out);
        })
    });
    g.bench_function("polyscrew Screw::eval (screw reused)", |bench| {
        let screws: Vec<_> = pairs
            .iter()
            .map(|(a, b, t)| (Screw::between(a, b), *t))
            .collect();
        bench.iter(|| {
            for (sc, t) in &screws {
                black_box(sc.eval(*t));
            }
        })
    });
    g.bench_function("nalgebra UnitDualQuaternion::sclerp", |bench| {
        bench.iter(|| {
            for (a, b, t) in &na {
                // try_sclerp: sclerp panics at a half turn; the pairs are below it.
                black_box(black_box(a).try_sclerp(black_box(b), *t, 1e-12));
            }
        })
    });
    g.finish();
}

fn bench_subdivide(c: &mut Criterion<CpuTime>) {
    let mut g = c.benchmark_group("subdivide");
    let keys100 = keys(100, 11);
    for scheme in [Scheme::Jarek, Scheme::FourPoint, Scheme::BSpline] {
        g.throughput(Throughput::Elements(100 << 6));
        g.bench_function(
            BenchmarkId::new(format!("{scheme:?} closed, 6 levels"), 100),
            |bench| bench.iter(|| subdivide(black_box(&keys100), scheme, 6, true).unwrap()),
        );
    }
    let keys1000 = keys(1000, 13);
    g.throughput(Throughput::Elements(1000 << 6));
    g.bench_function(BenchmarkId::new("Jarek closed, 6 levels", 1000), |bench| {
        bench.iter(|| subdivide(black_box(&keys1000), Scheme::Jarek, 6, true).unwrap())
    });
    g.finish();
}

fn config<M: Measurement>(m: M) -> Criterion<M> {
    Criterion::default()
        .with_measurement(m)
        .sample_size(30)
        .measurement_time(std::time::Duration::from_secs(3))
}

criterion_group! {
    name = cpu;
    config = config(CpuTime);
    targets = bench_s_cpu, bench_subdivide
}
criterion_group! {
    name = wall;
    config = config(WallTime);
    targets = bench_s_wall
}
criterion_main!(cpu, wall);
