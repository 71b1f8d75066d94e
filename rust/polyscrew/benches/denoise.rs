//! Criterion benchmarks of `polyscrew::denoise` (Remove Noise, issue 19).
//!
//! Group `denoise_rig` (thread CPU time, `common::CpuTime`): 100 bodies x 1,000 frames (a
//! rig of 100 bones, one key per frame), each a different noisy motion (a tumbling flight
//! with 2 cm and 0.5 degree noise), at automatic strength with kinks on (the defaults), in
//! one `denoise_batch` call on one thread. Target: under 100 ms. Group `denoise_rig_wall`:
//! the same call on all of the machine's threads, in wall-clock time.
//!
//! Group `denoise_scaling` (thread CPU time): one body of 1,000, 10,000 and 100,000 frames
//! (automatic strength): the time per frame should not grow with the clip (linear time).
//!
//! Run: `cargo bench -p polyscrew --bench denoise`.
use std::hint::black_box;

use criterion::measurement::{Measurement, WallTime};
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::{DQuat, DVec3};
use polyscrew::{denoise, denoise_batch, DenoiseOptions, Pose};

mod common;
use common::CpuTime;

/// Deterministic noise in [-1, 1] (xorshift).
fn noise(state: &mut u64) -> f64 {
    *state ^= *state << 13;
    *state ^= *state >> 7;
    *state ^= *state << 17;
    (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
}

/// Body `b`'s noisy motion over `n` frames: a tumbling flight along a curve.
fn clip(b: usize, n: usize) -> Vec<Pose> {
    let mut state = 0x9E37_79B9_7F4A_7C15u64 ^ (b as u64 + 1).wrapping_mul(0xD1B5_4A32_D192_ED03);
    let phase = b as f64 * 0.37;
    (0..n)
        .map(|i| {
            let t = i as f64 / 24.0;
            let rot = DQuat::from_axis_angle(
                DVec3::new((0.3 * t + phase).cos(), (0.3 * t).sin(), 1.0).normalize(),
                1.5 * t + phase,
            );
            let pos = DVec3::new(
                2.0 * (0.4 * t).cos(),
                2.0 * (0.3 * t + phase).sin(),
                0.2 * t,
            );
            // 2 cm and about 0.5 degrees per axis (uniform noise of the same deviation).
            let s = 3f64.sqrt();
            let mut f = || noise(&mut state) * s;
            let dr = DVec3::new(f(), f(), f()) * 0.5f64.to_radians();
            let dp = DVec3::new(f(), f(), f()) * 0.02;
            Pose::from_rotation_translation(DQuat::from_scaled_axis(dr) * rot, pos + dp)
        })
        .collect()
}

/// The rig: poses of 100 bodies, their times.
fn rig_clips() -> (Vec<Pose>, Vec<f64>) {
    let (bodies, n) = (100, 1000);
    let poses: Vec<Pose> = (0..bodies).flat_map(|b| clip(b, n)).collect();
    let times: Vec<f64> = (1..=n).map(|i| i as f64).collect();
    (poses, times)
}

fn rig_bench<M: Measurement>(c: &mut Criterion<M>, group: &str, name: &str, threads: usize) {
    let (poses, times) = rig_clips();
    let options = DenoiseOptions::default();
    let mut g = c.benchmark_group(group);
    g.throughput(Throughput::Elements(poses.len() as u64));
    g.bench_function(name, |bench| {
        bench.iter(|| {
            let out =
                denoise_batch(black_box(&poses), 100, &times, None, &options, threads).unwrap();
            black_box(out)
        })
    });
    g.finish();
}

fn rig(c: &mut Criterion<CpuTime>) {
    rig_bench(c, "denoise_rig", "100x1000_one_thread", 1);
}

fn rig_wall(c: &mut Criterion<WallTime>) {
    rig_bench(c, "denoise_rig_wall", "100x1000_all_threads", 0);
}

fn scaling(c: &mut Criterion<CpuTime>) {
    let options = DenoiseOptions::default();
    let mut group = c.benchmark_group("denoise_scaling");
    for n in [1_000usize, 10_000, 100_000] {
        let poses = clip(7, n);
        let times: Vec<f64> = (1..=n).map(|i| i as f64).collect();
        group.throughput(Throughput::Elements(n as u64));
        group.bench_with_input(BenchmarkId::from_parameter(n), &n, |bench, _| {
            bench.iter(|| black_box(denoise(black_box(&poses), &times, None, &options).unwrap()))
        });
    }
    group.finish();
}

criterion_group! {
    name = cpu;
    config = common::long_config(CpuTime);
    targets = rig, scaling
}
criterion_group! {
    name = wall;
    config = common::long_config(WallTime);
    targets = rig_wall
}
criterion_main!(cpu, wall);
