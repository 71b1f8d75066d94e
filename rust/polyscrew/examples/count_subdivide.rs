//! Subdivides 1,000 closed keys by 6 levels with Jarek's scheme a given number of times (0 or
//! more), for instruction counts under `valgrind --tool=callgrind` (stable on a shared
//! machine): the count for 1 minus the count for 0 is one subdivision without the set-up.
//! `cargo build --release --example count_subdivide && valgrind --tool=callgrind target/release/examples/count_subdivide 1`
//! Optional second and third arguments: keys (default 1000) and levels (default 6), to check
//! that the instructions per output pose do not grow with the size.
use std::hint::black_box;

use glam::{DQuat, DVec3};
use polyscrew::{subdivide, Pose, Scheme};

fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .and_then(|v| v.parse().ok())
        .unwrap_or(1);
    let mut args = std::env::args().skip(2);
    let count: usize = args.next().and_then(|v| v.parse().ok()).unwrap_or(1000);
    let levels: u32 = args.next().and_then(|v| v.parse().ok()).unwrap_or(6);
    // A tumbling walk: each key a screw of about a radian from the previous one.
    let keys: Vec<Pose> = (0..count)
        .map(|i| {
            let x = i as f64;
            let axis = DVec3::new(x.sin(), (1.3 * x).cos(), 0.5).normalize();
            Pose::from_rotation_translation(
                DQuat::from_axis_angle(axis, 0.02 * x),
                DVec3::new(x.cos(), 0.1 * x, -x.sin()),
            )
        })
        .collect();
    let mut acc = 0.0;
    for _ in 0..n {
        let out = subdivide(black_box(&keys), Scheme::Jarek, levels, true).expect("valid keys");
        acc += out[17].translation.x;
    }
    println!("subdivide: {n} runs of {count} keys x {levels} levels Jarek, checksum {acc:.6}");
}
