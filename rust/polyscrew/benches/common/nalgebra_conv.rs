//! Poses to and from nalgebra's dual quaternions, for the comparisons with its sclerp (the
//! benches, and `tests/against_nalgebra.rs` through `#[path]`).

use glam::{DQuat, DVec3};
use polyscrew::Pose;

/// `p` as nalgebra's unit dual quaternion.
pub fn to_nalgebra(p: &Pose) -> nalgebra::UnitDualQuaternion<f64> {
    let q = p.rotation;
    let r =
        nalgebra::UnitQuaternion::from_quaternion(nalgebra::Quaternion::new(q.w, q.x, q.y, q.z));
    let t = nalgebra::Translation3::new(p.translation.x, p.translation.y, p.translation.z);
    nalgebra::UnitDualQuaternion::from_parts(t, r)
}

/// nalgebra's unit dual quaternion as a pose.
#[allow(dead_code)] // used by the test, not by the benches
pub fn from_nalgebra(d: &nalgebra::UnitDualQuaternion<f64>) -> Pose {
    let iso = d.to_isometry();
    let (q, t) = (iso.rotation.quaternion(), iso.translation.vector);
    Pose {
        rotation: DQuat::from_xyzw(q.i, q.j, q.k, q.w),
        translation: DVec3::new(t.x, t.y, t.z),
    }
}
