//! Runs `s(a, t, b)` (ours or nalgebra's ScLERP) a given number of times, for instruction
//! counts under `valgrind --tool=callgrind`, which are stable on a shared machine:
//! `cargo build --release --example count_s && valgrind --tool=callgrind target/release/examples/count_s ours 100000`
//! (`many N` evaluates the same N pairs with `s_many` in batches of 1,024; `subdivide N`
//! instead runs N subdivisions of 100 keys by 6 levels with Jarek).
use std::hint::black_box;

use glam::{DQuat, DVec3};
use polyscrew::{s, Pose};

fn pose(i: usize) -> Pose {
    let x = i as f64;
    let axis = DVec3::new(x.sin(), (1.3 * x).cos(), 0.5).normalize();
    Pose::from_rotation_translation(
        DQuat::from_axis_angle(axis, 0.3 + (x * 0.7).sin().abs() * 2.5),
        DVec3::new(x.cos(), 1.0, -x.sin()),
    )
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let which = args.get(1).map(String::as_str).unwrap_or("ours");
    let n: usize = args.get(2).and_then(|v| v.parse().ok()).unwrap_or(100_000);
    let poses: Vec<Pose> = (0..1024).map(pose).collect();
    let mut acc = 0.0;
    match which {
        "ours" => {
            for i in 0..n {
                let p = s(
                    black_box(&poses[i % 1024]),
                    0.37,
                    black_box(&poses[(i + 1) % 1024]),
                );
                acc += p.translation.x;
            }
        }
        "many" => {
            // The same pairs and t as "ours", through the batch form in batches of 1,024.
            let b: Vec<Pose> = (0..1024).map(|i| poses[(i + 1) % 1024]).collect();
            let t = vec![0.37; 1024];
            let mut out = vec![Pose::IDENTITY; 1024];
            let mut done = 0;
            while done < n {
                let m = (n - done).min(1024);
                polyscrew::s_many(
                    black_box(&poses[..m]),
                    &t[..m],
                    black_box(&b[..m]),
                    &mut out[..m],
                )
                .expect("equal lengths");
                acc += out[m / 2].translation.x;
                done += m;
            }
        }
        "between" => {
            for i in 0..n {
                let sc = polyscrew::Screw::between(
                    black_box(&poses[i % 1024]),
                    black_box(&poses[(i + 1) % 1024]),
                );
                acc += black_box(sc).angle();
            }
        }
        "eval" => {
            // The screw built once per pair, evaluated n times (sampling's hot path).
            let screws: Vec<polyscrew::Screw> = (0..1024)
                .map(|i| polyscrew::Screw::between(&poses[i], &poses[(i + 1) % 1024]))
                .collect();
            for i in 0..n {
                acc += black_box(&screws[i % 1024]).eval(0.37).translation.x;
            }
        }
        "subdivide" => {
            // The case: 100 keys (closed), 6 levels, Jarek; n runs.
            for _ in 0..n {
                let d = polyscrew::subdivide(
                    black_box(&poses[..100]),
                    polyscrew::Scheme::Jarek,
                    6,
                    true,
                )
                .unwrap();
                acc += d[7].translation.x;
            }
        }
        _ => {
            let na: Vec<_> = poses
                .iter()
                .map(|p| {
                    let q = p.rotation;
                    nalgebra::UnitDualQuaternion::from_parts(
                        nalgebra::Translation3::new(
                            p.translation.x,
                            p.translation.y,
                            p.translation.z,
                        ),
                        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(
                            q.w, q.x, q.y, q.z,
                        )),
                    )
                })
                .collect();
            for i in 0..n {
                if let Some(p) =
                    black_box(&na[i % 1024]).try_sclerp(black_box(&na[(i + 1) % 1024]), 0.37, 1e-12)
                {
                    acc += p.translation().vector.x;
                }
            }
        }
    }
    println!("{which}: {n} evaluations, checksum {acc:.6}");
}
