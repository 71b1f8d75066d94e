//! Criterion benchmarks of `polyscrew::reduce_keys` (key reduction, issue 26).
//!
//! Group `reduce_rig` (thread CPU time, `common::CpuTime`): a rig of 100 bones (ten chains
//! of ten, 0.1 m apart, each bone its own swing: sums of sinusoids of 0.2 to 1.3 Hz at 30
//! frames per second, up to about 40 degrees; the chains' roots also travel) x 1,000 frames,
//! Euler XYZ, reduced to 1 mm / 0.5 degrees in world space (parents first, children
//! compensating), in one call on one thread. Target: under 100 ms. Group `reduce_rig_wall`:
//! the same call on all of the machine's threads, in wall-clock time.
//!
//! Group `reduce_scaling` (thread CPU time): one owner of 1,000, 10,000 and 100,000 frames:
//! the time per frame should not grow with the clip (linear time).
//!
//! Run: `cargo bench -p polyscrew --bench reduce`. With `REDUCE_RIG_ONCE=1` in the
//! environment the bench binary reduces the rig once on one thread and exits (no criterion):
//! for instruction counts, `REDUCE_RIG_ONCE=1 valgrind --tool=callgrind <bench binary>`.
use std::hint::black_box;

use criterion::measurement::{Measurement, WallTime};
use criterion::{criterion_group, BenchmarkId, Criterion, Throughput};
use glam::{DQuat, DVec3};
use polyscrew::reduce::{ReduceInput, ReduceOptions};
use polyscrew::{reduce_keys, Pose, RotationMode};

mod common;
use common::CpuTime;
#[path = "../tests/fixtures/reduce.rs"]
mod fixtures;

/// Bone `b`'s swing over `n` frames at 30 fps (a root also travels).
pub fn swing(b: usize, n: usize, root: bool) -> Vec<Pose> {
    let k = b as f64;
    (0..n)
        .map(|i| {
            let t = i as f64 / 30.0;
            let w = |f: f64, p: f64| (std::f64::consts::TAU * f * t + p).sin();
            let rv = DVec3::new(
                0.5 * w(0.2 + 0.05 * (k % 7.0), k) + 0.15 * w(1.3, 2.0 * k),
                0.3 * w(0.35 + 0.03 * (k % 5.0), 0.5 * k),
                0.2 * w(0.6, 1.7 * k) + 0.1 * w(1.1, k),
            );
            let translation = if root {
                DVec3::new(0.3 * w(0.1, k), 0.8 * t, 0.05 * w(0.7, k))
            } else {
                DVec3::ZERO
            };
            Pose::from_rotation_translation(DQuat::from_scaled_axis(rv), translation)
        })
        .collect()
}

/// The rig: poses, frames, parents, offsets.
fn rig(bones: usize, n: usize) -> (Vec<Pose>, Vec<f64>, Vec<Option<usize>>, Vec<Pose>) {
    let poses: Vec<Pose> = (0..bones).flat_map(|b| swing(b, n, b % 10 == 0)).collect();
    let frames: Vec<f64> = (1..=n).map(|i| i as f64).collect();
    let parents = (0..bones).map(|b| (b % 10 != 0).then(|| b - 1)).collect();
    let offsets = (0..bones)
        .map(|b| Pose::from_translation(DVec3::new(0.0, if b % 10 == 0 { 0.0 } else { 0.1 }, 0.0)))
        .collect();
    (poses, frames, parents, offsets)
}

/// The benches' tolerance (1 mm, 0.5 degrees) on one thread.
fn bench_options() -> ReduceOptions {
    fixtures::options(1e-3, 0.5f64.to_radians())
}

/// The rig bench's input and options on `threads` threads, handed to `f`.
fn with_rig<R>(threads: usize, f: impl FnOnce(&ReduceInput<'_>, &ReduceOptions) -> R) -> R {
    let bones = 100;
    let (poses, frames, parents, offsets) = rig(bones, 1000);
    let modes = vec![RotationMode::Euler(polyscrew::EulerOrder::Xyz); bones];
    let radius = vec![0.1; bones];
    let input = ReduceInput {
        parents: Some(&parents),
        offsets: Some(&offsets),
        ..fixtures::input(&poses, &frames, &modes, &radius)
    };
    let options = ReduceOptions {
        threads,
        ..bench_options()
    };
    f(&input, &options)
}

/// Key frames of the rig's reduction, and as a share of its frames.
fn rig_keys(input: &ReduceInput<'_>, options: &ReduceOptions) -> (usize, f64) {
    let r = reduce_keys(input, options).unwrap();
    let keys: usize = r.keys.iter().sum();
    (keys, keys as f64 / input.poses.len() as f64)
}

fn rig_bench<M: Measurement>(c: &mut Criterion<M>, group: &str, name: &str, threads: usize) {
    with_rig(threads, |input, options| {
        let (keys, share) = rig_keys(input, options);
        eprintln!(
            "{group}: {keys} key frames over {} bones x 1000 frames ({:.1} % of frames)",
            input.modes.len(),
            100.0 * share
        );
        let mut g = c.benchmark_group(group);
        g.throughput(Throughput::Elements(input.poses.len() as u64));
        g.bench_function(name, |bench| {
            bench.iter(|| black_box(reduce_keys(black_box(input), options).unwrap()))
        });
        g.finish();
    })
}

fn rig_cpu(c: &mut Criterion<CpuTime>) {
    rig_bench(c, "reduce_rig", "100x1000_one_thread", 1);
}

fn rig_wall(c: &mut Criterion<WallTime>) {
    rig_bench(c, "reduce_rig_wall", "100x1000_all_threads", 0);
}

fn scaling(c: &mut Criterion<CpuTime>) {
    let mut group = c.benchmark_group("reduce_scaling");
    for n in [1_000usize, 10_000, 100_000] {
        let poses = swing(3, n, true);
        let frames: Vec<f64> = (1..=n).map(|i| i as f64).collect();
        let modes = [RotationMode::Quaternion];
        let input = fixtures::input(&poses, &frames, &modes, &[0.3]);
        let options = bench_options();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| black_box(reduce_keys(black_box(&input), &options).unwrap()))
        });
    }
    group.finish();
}

criterion_group! {
    name = cpu;
    config = common::long_config(CpuTime);
    targets = rig_cpu, scaling
}
criterion_group! {
    name = wall;
    config = common::long_config(WallTime);
    targets = rig_wall
}
fn main() {
    if std::env::var_os("REDUCE_RIG_ONCE").is_some() {
        let (keys, share) = with_rig(1, rig_keys);
        println!(
            "reduce_rig once: {keys} key frames ({:.2} % of frames)",
            100.0 * share
        );
        return;
    }
    cpu();
    wall();
    Criterion::default().configure_from_args().final_summary();
}
