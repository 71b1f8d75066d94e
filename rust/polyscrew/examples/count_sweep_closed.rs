//! Runs `sweep_closed` on a case read from a text file, for instruction counts under
//! `valgrind --tool=callgrind` (stable on a shared machine) and CPU times:
//! `scripts/bench/bench_sweep_closed.py --dump DIR` writes the bench's cases (`cube.txt`,
//! `lprism.txt`, `torus.txt`, `big.txt`), then
//! `cargo build --profile bench --example count_sweep_closed && valgrind --tool=callgrind
//! target/release/examples/count_sweep_closed DIR/cube.txt`.
//!
//! The file: a line `vertices triangles poses`, then one line per vertex (`x y z`), per
//! triangle (`a b c`) and per pose (its 4 x 4 matrix, rows one after the other). Prints the
//! closed mesh's counts, its volume, its bound, a digest of its vertices' bits and triangles
//! (equal meshes, equal digests) and the process's CPU time (all threads) and wall time. `CELL` 0 or none:
//! the default tolerance; `THREADS` 0 or none: the machine's; a fourth argument `decimate`:
//! `ClosedOptions::decimate`.
use glam::DVec3;
use polyscrew::sweep::{sweep_closed_mesh, ClosedOptions};
use polyscrew::Pose;

/// The process's CPU time in seconds, all threads (Linux `/proc/self/stat`: user and system
/// time in clock ticks, 100 a second), if readable.
fn cpu_seconds() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/self/stat").ok()?;
    // The fields after the command's closing parenthesis: utime and stime are the 12th and 13th.
    let rest = &s[s.rfind(')')? + 2..];
    let mut fields = rest.split_whitespace().skip(11);
    let user: f64 = fields.next()?.parse().ok()?;
    let system: f64 = fields.next()?.parse().ok()?;
    Some((user + system) / 100.0)
}

fn main() {
    let path = std::env::args()
        .nth(1)
        .expect("usage: count_sweep_closed CASE.txt [CELL [THREADS [decimate]]]");
    // A cell of 0 (or none): the default tolerance.
    let cell = std::env::args()
        .nth(2)
        .map(|c| c.parse::<f64>().expect("a cell"))
        .filter(|&c| c > 0.0);
    let threads = std::env::args()
        .nth(3)
        .map_or(0, |t| t.parse::<usize>().expect("a thread count"));
    let text = std::fs::read_to_string(&path).expect("a readable case file");
    let mut lines = text.lines();
    let numbers = |line: &str| -> Vec<f64> {
        line.split_whitespace()
            .map(|x| x.parse().expect("a number"))
            .collect()
    };
    let head = numbers(lines.next().expect("a header"));
    let (nv, nt, np) = (head[0] as usize, head[1] as usize, head[2] as usize);
    let vertices: Vec<DVec3> = (0..nv)
        .map(|_| DVec3::from_slice(&numbers(lines.next().expect("a vertex"))))
        .collect();
    let triangles: Vec<[i64; 3]> = (0..nt)
        .map(|_| {
            let t = numbers(lines.next().expect("a triangle"));
            [t[0] as i64, t[1] as i64, t[2] as i64]
        })
        .collect();
    let poses: Vec<Pose> = (0..np)
        .map(|i| {
            let m = numbers(lines.next().expect("a pose"));
            let rows = [0, 1, 2, 3].map(|r| [m[4 * r], m[4 * r + 1], m[4 * r + 2], m[4 * r + 3]]);
            Pose::from_rows(&rows, i).expect("a pose")
        })
        .collect();
    let before = cpu_seconds();
    let wall = std::time::Instant::now();
    let options = ClosedOptions {
        cell,
        threads,
        decimate: std::env::args().nth(4).is_some_and(|d| d == "decimate"),
        ..ClosedOptions::default()
    };
    let out = sweep_closed_mesh(
        &vertices,
        &triangles,
        &poses,
        &options,
        &polyscrew::Progress::new(),
    )
    .expect("the closed sweep");
    let cpu = cpu_seconds().zip(before).map(|(a, b)| a - b);
    let wall = wall.elapsed().as_secs_f64();
    // FNV-1a over the vertices' bits and the triangles: equal meshes, equal digests.
    let digest = out
        .vertices
        .iter()
        .flat_map(|v| v.to_array().map(f64::to_bits))
        .chain(out.triangles.iter().flat_map(|t| t.map(u64::from)))
        .fold(0xcbf2_9ce4_8422_2325u64, |h, x| {
            (h ^ x).wrapping_mul(0x0100_0000_01b3)
        });
    let volume = out.volume();
    println!(
        "{path}: {} vertices, {} triangles, volume {volume:.6}, cell {:.4}, bound {:.3e}, {} attempt(s), {} poses, digest {digest:016x}, CPU {:.3} s, wall {wall:.3} s",
        out.vertices.len(),
        out.triangles.len(),
        out.cell,
        out.error_bound,
        out.attempts,
        out.poses,
        cpu.unwrap_or(f64::NAN)
    );
}
