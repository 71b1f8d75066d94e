//! Criterion benchmarks of feature-point motion design (Hofer-Pottmann-Ravani, *From curve
//! design algorithms to the design of rigid body motions*, Table 1: 6 closed keys, 7 levels, 768 poses; their Matlab took 0.16 s + 0.55 s = 0.71 s)
//! against screw subdivision (Jarek) of the same keys, in the same run.
//!
//! Group `hofer_table1`: the four cases of the paper's Table 1 (m = 7 subdivision steps), with
//! the paper's key counts, open/closed, parametrisation and springs, on keys of our own (the
//! paper's key poses are not published): bunny 6/768 closed uniform interpolating (CUI),
//! teapot 5/513 open non-uniform (centripetal) interpolating (ONI), gripper 6/641 open uniform
//! approximating (OUA, the springs of its Fig. 10c), window 4/385 open uniform interpolating
//! (OUI). Their Matlab 6.5 times (curve design T_c + registration T_r, 1.8 GHz PC) are quoted
//! beside ours in BENCHMARKS.md as figures from another machine.
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

/// `n` keys of a tumbling object on an open arc (about 1 rad of turn between keys).
fn open_keys(n: usize) -> Vec<Pose> {
    (0..n)
        .map(|i| {
            let a = i as f64;
            Pose::from_rotation_translation(
                DQuat::from_axis_angle(DVec3::new(0.4, 1.0, 0.2 * a).normalize(), 0.9 * a),
                DVec3::new(3.0 * (0.8 * a).cos(), 3.0 * (0.8 * a).sin(), 0.6 * a),
            )
        })
        .collect()
}

/// The four cases of Hofer et al., Table 1: (name, keys, spec, poses out).
fn table1() -> Vec<(&'static str, Vec<Pose>, FeatureSpec, usize)> {
    let variational = |closed: bool| FeatureSpec {
        scheme: CurveScheme::Variational,
        levels: 7,
        closed,
        ..FeatureSpec::default()
    };
    // Fig. 10c: keys 1, 4 and 6 pinned (lambda = 1e8), keys 2, 3, 5 on springs 0.5, 1.5, 0.9,
    // every inserted point lambda = 1.
    let gripper = Stiffness {
        keys: Some(vec![1e8, 0.5, 1.5, 1e8, 0.9, 1e8]),
        inserted: 1.0,
    };
    vec![
        ("bunny 6/768 CUI", keys(), variational(true), 768),
        (
            "teapot 5/513 ONI",
            open_keys(5),
            FeatureSpec {
                parametrization: Parametrization::Centripetal,
                ..variational(false)
            },
            513,
        ),
        (
            "gripper 6/641 OUA",
            open_keys(6),
            FeatureSpec {
                stiffness: gripper,
                ..variational(false)
            },
            641,
        ),
        ("window 4/385 OUI", open_keys(4), variational(false), 385),
    ]
}

fn bench_table1(c: &mut Criterion) {
    let mut group = c.benchmark_group("hofer_table1");
    for (name, keys, spec, poses) in table1() {
        assert_eq!(
            feature_motion(&keys, None, &spec).unwrap().len(),
            poses,
            "{name}: {spec:?}"
        );
        group.bench_function(name, |b| {
            b.iter(|| feature_motion(black_box(&keys), None, black_box(&spec)).unwrap())
        });
    }
    group.finish();
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

criterion_group!(benches, bench, bench_table1);
criterion_main!(benches);
