//! Pops: steps where the captured body jumps (a tracker that loses and re-acquires its
//! target, a teleport cut into a simulation), far faster than the motion around them.
//!
//! A smoothing spline across a pop spreads the jump over its whole time scale, and the
//! strength search, which sees the jump as signal, collapses towards no smoothing at all.
//! Remove Noise therefore cuts the clip at its pops and smooths the pieces apart, each with
//! its own strengths (`super::denoise`); the pop itself stays as it was captured.
//!
//! Step `j` (between samples `j` and `j + 1`) is a pop when its speed, in rotation
//! (`sin(theta_j / 2) / (t_{j+1} - t_j)` with `theta_j` the angle of `Q_{j+1} Q_j^-1`, the
//! same in any coordinate frame; the sine keeps it cheap and is monotone in the angle) or in
//! translation (`|o_{j+1} - o_j| / (t_{j+1} - t_j)`, world distances),
//! is more than [`POP_RATIO`] times the fastest of the [`POP_WINDOW`] steps on either side.
//! Noise, and motion that speeds up over a few samples, raise the neighbours with it; a
//! kink (a stop) changes the speed but never makes one step stand out; a single sample off
//! and back (two fast steps side by side) is not a pop either.

use glam::{DQuat, DVec3};

/// A pop's step is this many times faster than any step within [`POP_WINDOW`] of it: far
/// above what noise or a change of pace makes. Measured on the orbit-and-dolly capture of
/// `tests/blender/test_denoise_data.py` (20 noise seeds; 2 cm / 0.5 degrees, 5 mm / 0.1
/// degrees and no noise): no step without a pop stands out by more than 2.4; the 5 m / 90
/// degree teleport by at least 31.
pub(crate) const POP_RATIO: f64 = 10.0;

/// The steps compared on either side of a candidate pop.
pub(crate) const POP_WINDOW: usize = 3;

/// Speeds below this fraction of the fastest one are rounding, never a pop's neighbours'
/// scale (a motion that holds exactly still and then jumps is a pop).
const ROUNDING_FLOOR: f64 = 1e-12;

/// The pops of a clip: the index of the first sample after each pop, increasing.
pub(crate) fn find(quats: &[DQuat], origins: &[DVec3], times: &[f64]) -> Vec<usize> {
    let n = quats.len();
    if n < 2 {
        return Vec::new();
    }
    let mut rotation = Vec::with_capacity(n - 1);
    let mut translation = Vec::with_capacity(n - 1);
    for j in 0..n - 1 {
        let per = 1.0 / (times[j + 1] - times[j]);
        rotation.push((quats[j + 1] * quats[j].conjugate()).xyz().length() * per);
        translation.push((origins[j + 1] - origins[j]).length() * per);
    }
    (0..n - 1)
        .filter(|j| stands_out(&rotation, *j) || stands_out(&translation, *j))
        .map(|j| j + 1)
        .collect()
}

/// Whether step `j` of `speed` is more than [`POP_RATIO`] times its neighbours' fastest.
fn stands_out(speed: &[f64], j: usize) -> bool {
    let v = speed[j];
    let last = speed.len() - 1;
    // Most steps are no faster than POP_RATIO times a direct neighbour: decided at once.
    let near = |k: usize| speed[k] * POP_RATIO >= v;
    if !(v.is_finite() && v > 0.0)
        || last == 0
        || (j > 0 && near(j - 1))
        || (j < last && near(j + 1))
    {
        return false;
    }
    let lo = j.saturating_sub(POP_WINDOW);
    let hi = (j + POP_WINDOW).min(last);
    let fastest = speed[lo..j]
        .iter()
        .chain(&speed[j + 1..=hi])
        .fold(0.0, |a: f64, b| a.max(*b));
    v > POP_RATIO * fastest.max(ROUNDING_FLOOR * v)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn clip(n: usize) -> (Vec<DQuat>, Vec<DVec3>, Vec<f64>) {
        let times: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let q = times
            .iter()
            .map(|t| DQuat::from_axis_angle(DVec3::new(0.3, 0.4, 0.866).normalize(), 0.05 * t))
            .collect();
        let o = times
            .iter()
            .map(|t| DVec3::new((0.1 * t).sin(), 0.02 * t, 0.3))
            .collect();
        (q, o, times)
    }

    #[test]
    fn a_jump_is_a_pop_and_smooth_motion_a_stop_and_an_outlier_are_not() {
        let (q, mut o, times) = clip(60);
        assert!(find(&q, &o, &times).is_empty());
        // A stop: the speed drops to zero.
        let stop: Vec<DVec3> = o
            .iter()
            .take(30)
            .copied()
            .chain(std::iter::repeat_n(o[29], 30))
            .collect();
        assert!(find(&q, &stop, &times).is_empty());
        // One sample off and back: two fast steps side by side.
        let mut outlier = o.clone();
        outlier[20] += DVec3::X * 5.0;
        assert!(find(&q, &outlier, &times).is_empty());
        // A teleport after sample 40 (translation), and a turn of 90 degrees after 10.
        for p in &mut o[41..] {
            *p += DVec3::new(5.0, 0.0, 0.0);
        }
        let mut q2 = q.clone();
        for r in &mut q2[11..] {
            *r = DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2) * *r;
        }
        assert_eq!(find(&q2, &o, &times), vec![11, 41]);
        // Uneven times: a gap of ten frames at the normal speed is not a pop.
        let (q, _, mut times) = clip(30);
        for t in &mut times[15..] {
            *t += 9.0;
        }
        let o: Vec<DVec3> = times
            .iter()
            .map(|t| DVec3::new(0.1 * t, 0.0, 0.0))
            .collect();
        assert!(find(&q, &o, &times).is_empty());
    }
}
