//! Criterion benchmarks of feature-point motion design (Hofer-Pottmann-Ravani `004_*`,
//! Table 1: 6 closed keys, 7 levels, 768 poses; their Matlab took 0.16 s + 0.55 s = 0.71 s)
//! against screw subdivision (Jarek) of the same keys, in the same run.
//!
//! Run: `cargo bench -p polyscrew --bench feature`.
use std::hint::black_box;

use criterion::{criterion_group, criterion_main, Criterion};
use glam::{DQuat, DVec3};
use polyscrew::{
    feature_motion, subdivide, CurveScheme, FeatureSpec, Parametrization, Pose, Scheme, Stiffness,
};

/// Six keys of a tumbling object on a closed loop (turns of about 1 rad between keys).
fn keys() -> Vec<Pose> {
    (0..6)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 6.0;
            Pose::from_rotation_translation(
                DQuat::from_axis_angle(DVec3::new(1.0, 0.5 * a.sin(), 0.3).normalize(), a),
                DVec3::new(4.0 * a.cos(), 4.0 * a.sin(), 0.5 * (2.0 * a).sin()),
            )
        })
        .collect()
}

fn bench(c: &mut Criterion) {
    let keys = keys();
    let mut group = c.benchmark_group("6 closed keys, 7 levels (768 poses)");
    let spec = FeatureSpec {
        scheme: CurveScheme::Variational,
        levels: 7,
        closed: true,
        ..FeatureSpec::default()
    };
    assert_eq!(feature_motion(&keys, None, &spec).unwrap().len(), 768);
    group.bench_function("feature points, variational CUI (paper's bunny)", |b| {
        b.iter(|| feature_motion(black_box(&keys), None, black_box(&spec)).unwrap())
    });
    let centripetal = FeatureSpec {
        parametrization: Parametrization::Centripetal,
        ..spec.clone()
    };
    group.bench_function("feature points, variational centripetal", |b| {
        b.iter(|| feature_motion(black_box(&keys), None, black_box(&centripetal)).unwrap())
    });
    let approximating = FeatureSpec {
        stiffness: Stiffness::keys(vec![f64::INFINITY, 0.5, 1.0, f64::INFINITY, 2.0, 0.3]),
        ..spec.clone()
    };
    group.bench_function("feature points, variational approximating", |b| {
        b.iter(|| feature_motion(black_box(&keys), None, black_box(&approximating)).unwrap())
    });
    let jarek_points = FeatureSpec {
        scheme: CurveScheme::Jarek,
        ..spec.clone()
    };
    group.bench_function("feature points, Jarek on points", |b| {
        b.iter(|| feature_motion(black_box(&keys), None, black_box(&jarek_points)).unwrap())
    });
    assert_eq!(subdivide(&keys, Scheme::Jarek, 7, true).unwrap().len(), 768);
    group.bench_function("screw subdivision, Jarek", |b| {
        b.iter(|| subdivide(black_box(&keys), Scheme::Jarek, 7, true).unwrap())
    });
    group.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
