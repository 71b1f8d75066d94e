//! Growth of subdivision with the output size: 10, 100, 1,000 and 10,000 keys (closed) by
//! 1 ..= 8 levels, for each scheme, in thread CPU time (`common::CpuTime`).
//!
//! Each benchmark is `scaling/<scheme>/<keys>x<levels>` with its output size (poses) as the
//! throughput, so `scripts/bench/bench_report.py` reads poses per second and fits the growth
//! exponent of time against output size (log-log least squares) from criterion's JSON.
//! Combinations above [`MAX_OUTPUT`] poses are skipped (none are at 10,000 keys x 8 levels =
//! 2,560,000 poses; the bound keeps the run short if the grid is widened).

mod common;

use std::hint::black_box;
use std::time::Duration;

use common::{keys, CpuTime};
use criterion::{
    criterion_group, criterion_main, BenchmarkId, Criterion, SamplingMode, Throughput,
};
use polyscrew::{subdivide, subdivided_len, Scheme};

/// The largest output (poses) benchmarked; larger combinations are skipped and reported.
const MAX_OUTPUT: usize = 3_000_000;

fn bench_scaling(c: &mut Criterion<CpuTime>) {
    let mut g = c.benchmark_group("scaling");
    g.sampling_mode(SamplingMode::Flat)
        .sample_size(10)
        .warm_up_time(Duration::from_millis(200))
        .measurement_time(Duration::from_millis(600));
    for n in [10usize, 100, 1_000, 10_000] {
        let input = keys(n, 17 + n as u64);
        for scheme in [Scheme::Jarek, Scheme::FourPoint, Scheme::BSpline] {
            for levels in 1..=8u32 {
                let out = subdivided_len(n, levels, true);
                if out > MAX_OUTPUT {
                    println!(
                        "scaling: skipped {scheme:?} {n}x{levels} ({out} poses > {MAX_OUTPUT})"
                    );
                    continue;
                }
                g.throughput(Throughput::Elements(out as u64));
                g.bench_with_input(
                    BenchmarkId::new(format!("{scheme:?}"), format!("{n}x{levels}")),
                    &input,
                    |bench, input| {
                        bench.iter(|| subdivide(black_box(input), scheme, levels, true).unwrap())
                    },
                );
            }
        }
    }
    g.finish();
}

criterion_group! {
    name = scaling;
    config = Criterion::default().with_measurement(CpuTime);
    targets = bench_scaling
}
criterion_main!(scaling);
