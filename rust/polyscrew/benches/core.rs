//! Criterion benchmarks of the core: `s(a, t, b)` (ours and nalgebra's dual-quaternion
//! ScLERP in the same run) and subdivision (the 100 keys x 6 levels, and the growth
//! over 10 .. 10,000 keys x 1 .. 8 levels).

use std::hint::black_box;

use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use glam::{DQuat, DVec3};
use polyscrew::{s, subdivide, Pose, Scheme, Screw};

/// A deterministic pseudo-random sequence (xorshift), so runs are comparable.
struct Rng(u64);
impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    fn pose(&mut self, max_angle: f64) -> Pose {
        let axis = DVec3::new(self.next() - 0.5, self.next() - 0.5, self.next() - 0.5).normalize();
        let t = DVec3::new(self.next(), self.next(), self.next()) * 2.0 - 1.0;
        Pose::from_rotation_translation(DQuat::from_axis_angle(axis, self.next() * max_angle), t)
    }
}

/// `n` keys, each a random screw of up to 90 degrees from the previous.
pub fn keys(n: usize, seed: u64) -> Vec<Pose> {
    let mut rng = Rng(seed);
    let mut out = vec![rng.pose(3.0)];
    for _ in 1..n {
        let step = rng.pose(std::f64::consts::FRAC_PI_2);
        out.push(step.mul_pose(out.last().unwrap()));
    }
    out
}

fn to_nalgebra(p: &Pose) -> nalgebra::UnitDualQuaternion<f64> {
    let q = p.rotation;
    let r =
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z));
    let t = nalgebra::Translation3::new(p.translation.x, p.translation.y, p.translation.z);
    nalgebra::UnitDualQuaternion::from_parts(t, r)
}

fn bench_s(c: &mut Criterion) {
    let mut rng = Rng(7);
    let pairs: Vec<(Pose, Pose, f64)> = (0..1024)
        .map(|_| (rng.pose(3.0), rng.pose(3.0), rng.next()))
        .collect();
    let na: Vec<_> = pairs
        .iter()
        .map(|(a, b, t)| (to_nalgebra(a), to_nalgebra(b), *t))
        .collect();
    let mut g = c.benchmark_group("s");
    g.throughput(Throughput::Elements(pairs.len() as u64));
    g.bench_function("polyscrew s(a, t, b)", |bench| {
        bench.iter(|| {
            for (a, b, t) in &pairs {
                black_box(s(black_box(a), *t, black_box(b)));
            }
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

fn bench_subdivide(c: &mut Criterion) {
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

criterion_group! {
    name = benches;
    config = Criterion::default().sample_size(30).measurement_time(std::time::Duration::from_secs(3));
    targets = bench_s, bench_subdivide
}
criterion_main!(benches);
