//! Where dual-quaternion ScLERP (nalgebra's `UnitDualQuaternion::sclerp`, the peer of the
//! benchmarks) fails and `s` does not: tiny angles with a unit translation, and the half turn.
//! Run with `--nocapture` to see both errors.

use std::f64::consts::PI;

use glam::{DQuat, DVec3};
use polyscrew::{s, Pose};

#[path = "../benches/common/nalgebra_conv.rs"]
mod nalgebra_conv;
use nalgebra_conv::{from_nalgebra, to_nalgebra};

#[path = "fixtures/poses.rs"]
mod poses;
use poses::exact;

fn key() -> (Pose, DVec3, DVec3) {
    let a = Pose {
        rotation: DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 0.9).normalize(), 0.7),
        translation: DVec3::new(0.4, -0.3, 0.2),
    };
    let axis = DVec3::new(0.48, 0.6, 0.64); // unit
    let point = DVec3::new(0.5, -0.2, 0.1);
    (a, axis, point)
}

#[test]
fn tiny_angles_with_a_unit_translation() {
    let (a, axis, point) = key();
    for angle in [1e-4, 1e-6, 1e-9, 1e-13] {
        let b = exact(axis, point, angle, 1.0, 1.0, &a);
        let (mut ours, mut theirs) = (0.0f64, 0.0f64);
        for t in [0.25, 0.5, 0.75] {
            let want = exact(axis, point, angle, 1.0, t, &a);
            ours = ours.max(s(&a, t, &b).max_abs_diff(&want));
            if let Some(d) = to_nalgebra(&a).try_sclerp(&to_nalgebra(&b), t, 1e-12) {
                theirs = theirs.max(from_nalgebra(&d).max_abs_diff(&want));
            } else {
                theirs = f64::INFINITY;
            }
        }
        println!("angle {angle:e}: s error {ours:.1e}, nalgebra sclerp error {theirs:.1e}");
        assert!(ours < 1e-12, "angle {angle:e}: s error {ours:e}");
        if angle <= 1e-6 {
            // README: at 1e-6 rad and below nalgebra's sclerp loses the rotation (an error of
            // about half the angle, the whole of the rotation's effect here).
            assert!(
                theirs > 0.1 * angle,
                "nalgebra's sclerp got accurate at {angle:e} rad: {theirs:e}; update README"
            );
        }
    }
}

#[test]
fn half_turn() {
    let (a, axis, point) = key();
    let b = exact(axis, point, PI, 0.5, 1.0, &a);
    let want = exact(axis, point, PI, 0.5, 0.5, &a);
    let ours = s(&a, 0.5, &b).max_abs_diff(&want);
    // s takes either of the two half turns; both are exact, so compare with the nearer.
    let other = exact(-axis, point, PI, -0.5, 0.5, &a);
    let ours = ours.min(s(&a, 0.5, &b).max_abs_diff(&other));
    assert!(ours < 1e-12, "s error at the half turn {ours:e}");
    let (na, nb) = (to_nalgebra(&a), to_nalgebra(&b));
    assert!(
        na.try_sclerp(&nb, 0.5, 1e-9).is_none(),
        "nalgebra's try_sclerp now handles the half turn"
    );
    // The expected panic, without its message and backtrace in the test output.
    let hook = std::panic::take_hook();
    std::panic::set_hook(Box::new(|_| {}));
    let panicked = std::panic::catch_unwind(|| na.sclerp(&nb, 0.5)).is_err();
    std::panic::set_hook(hook);
    println!(
        "half turn: s error {ours:.1e}; nalgebra try_sclerp None, sclerp panicked: {panicked}"
    );
    assert!(
        panicked,
        "nalgebra's sclerp no longer panics at the half turn; update README"
    );
}
