//! Shared by the benches: deterministic test motions and a thread-CPU-time measurement.
//!
//! The machines these benches run on are shared (several builds at once on two cores), so
//! wall-clock time counts the time a benchmark waits for a core. [`CpuTime`] measures the
//! benchmark thread's own CPU time (`CLOCK_THREAD_CPUTIME_ID`, through the `cpu-time`
//! crate), which is what "on one core" means; the wall-clock group in `core.rs` is kept
//! beside it for comparison.
#![allow(dead_code)]

pub mod nalgebra_conv;

use criterion::measurement::{Measurement, ValueFormatter};
use criterion::{Criterion, Throughput};
use glam::{DQuat, DVec3};
use polyscrew::Pose;

/// A deterministic pseudo-random sequence (xorshift), so runs are comparable.
pub struct Rng(pub u64);
impl Rng {
    /// The next number in [0, 1).
    pub fn next(&mut self) -> f64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        (self.0 >> 11) as f64 / (1u64 << 53) as f64
    }
    /// A pose turned by up to `max_angle` about a random axis, moved by up to 1 per axis.
    pub fn pose(&mut self, max_angle: f64) -> Pose {
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

/// Criterion measurement: CPU time of the calling thread, in nanoseconds.
pub struct CpuTime;

impl Measurement for CpuTime {
    type Intermediate = cpu_time::ThreadTime;
    type Value = u64;

    fn start(&self) -> Self::Intermediate {
        cpu_time::ThreadTime::now()
    }
    fn end(&self, i: Self::Intermediate) -> Self::Value {
        i.elapsed().as_nanos() as u64
    }
    fn add(&self, v1: &Self::Value, v2: &Self::Value) -> Self::Value {
        v1 + v2
    }
    fn zero(&self) -> Self::Value {
        0
    }
    fn to_f64(&self, value: &Self::Value) -> f64 {
        *value as f64
    }
    fn formatter(&self) -> &dyn ValueFormatter {
        &NanosFormatter
    }
}

/// Formats CPU nanoseconds like criterion formats wall time.
struct NanosFormatter;

impl ValueFormatter for NanosFormatter {
    fn scale_values(&self, ns: f64, values: &mut [f64]) -> &'static str {
        let (factor, unit) = if ns < 1e3 {
            (1.0, "ns")
        } else if ns < 1e6 {
            (1e-3, "µs")
        } else if ns < 1e9 {
            (1e-6, "ms")
        } else {
            (1e-9, "s")
        };
        values.iter_mut().for_each(|v| *v *= factor);
        unit
    }
    fn scale_throughputs(
        &self,
        typical: f64,
        throughput: &Throughput,
        values: &mut [f64],
    ) -> &'static str {
        let per = match *throughput {
            Throughput::Elements(n) | Throughput::ElementsAndBytes { elements: n, .. } => n as f64,
            Throughput::Bytes(n) | Throughput::BytesDecimal(n) => n as f64,
            Throughput::Bits(n) => n as f64,
        };
        let rate = per * 1e9 / typical;
        let (factor, unit) = if rate >= 1e9 {
            (1e-9, "G/s")
        } else if rate >= 1e6 {
            (1e-6, "M/s")
        } else if rate >= 1e3 {
            (1e-3, "K/s")
        } else {
            (1.0, "/s")
        };
        values.iter_mut().for_each(|v| *v = per * 1e9 / *v * factor);
        unit
    }
    fn scale_for_machines(&self, _values: &mut [f64]) -> &'static str {
        "ns"
    }
}

/// Ten samples of ten seconds each: the configuration of the slow benches (`reduce.rs`,
/// `denoise.rs`).
pub fn long_config<M: Measurement>(m: M) -> Criterion<M> {
    Criterion::default()
        .with_measurement(m)
        .sample_size(10)
        .measurement_time(std::time::Duration::from_secs(10))
}
