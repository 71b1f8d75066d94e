//! The denoised poses as the caller writes them back: 4x4 matrices row by row (Blender's
//! layout), held poses bit for bit as they were read, and what a call holds at its peak.

use crate::memory::{try_vec, Footprint};
use crate::{Error, Result};

use super::Denoised;

/// Bytes one pose of a denoise call holds at its peak besides the caller's own arrays: its
/// copy of the input and the output matrices (16 values each), and the solves' scratch
/// (measured: 1,500 bytes per pose at the peak of a 400,000-pose clip with the strengths
/// chosen automatically; 1,536 counted). A held pose's matrix kept as read (128 bytes) fits
/// in the margin.
pub const DENOISE_BYTES_PER_POSE: usize = 16 * 8 * 2 + 1536;

/// How to ask a denoise call for less memory.
pub const DENOISE_HINT: &str = "denoise fewer frames or fewer bodies in one call";

/// What a denoise call of `poses` poses (all bodies) holds at its peak
/// ([`DENOISE_BYTES_PER_POSE`] each), to check against the budget before anything is read.
pub fn denoise_footprint(poses: usize) -> Footprint {
    Footprint::bytes(poses.saturating_mul(DENOISE_BYTES_PER_POSE))
}

/// The smooth poses of a batch's `results` (one per body, each of `n` poses) as 4x4
/// matrices row by row, body after body: `results.len() * n * 16` values. A held pose
/// (`held[b * n + i]`) is the next matrix of `held_rows` (the held poses' matrices as they
/// were read, in order, bit for bit: a matrix read into a quaternion and written back may
/// differ in the last bit), the others [`crate::Pose::to_rows`].
///
/// # Errors
/// [`Error::Memory`] when the output cannot be allocated; [`Error::LengthMismatch`] when a
/// result does not hold `n` poses, `held` does not hold one entry per pose, or `held_rows`
/// does not hold one matrix per held pose.
pub fn denoised_rows(
    results: &[Denoised],
    n: usize,
    held: Option<&[bool]>,
    held_rows: &[[[f64; 4]; 4]],
) -> Result<Vec<f64>> {
    let total = results.len().saturating_mul(n);
    let mismatch = |what, expected, got| Error::LengthMismatch {
        what,
        expected,
        got,
    };
    if let Some(r) = results.iter().find(|r| r.poses.len() != n) {
        return Err(mismatch("denoised poses", n, r.poses.len()));
    }
    let kept = match held {
        Some(h) if h.len() != total => return Err(mismatch("held", total, h.len())),
        Some(h) => h.iter().filter(|h| **h).count(),
        None => 0,
    };
    if held_rows.len() != kept {
        return Err(mismatch("held matrices", kept, held_rows.len()));
    }
    let mut out = try_vec(total.saturating_mul(16), "denoised matrices")?;
    out.resize(total.saturating_mul(16), 0.0);
    let mut used = 0;
    for (b, (r, dst)) in results
        .iter()
        .zip(out.chunks_exact_mut(16 * n.max(1)))
        .enumerate()
    {
        let h = held.map(|h| &h[b * n..(b + 1) * n]);
        used += r.write_rows(h, &held_rows[used..], dst);
    }
    debug_assert_eq!(used, kept, "every held matrix written once");
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::denoise::{denoise_batch, DenoiseOptions};
    use crate::Pose;
    use glam::{DQuat, DVec3};

    /// Poses along a noisy line, one body.
    fn clip(n: usize) -> (Vec<Pose>, Vec<f64>) {
        let poses = (0..n)
            .map(|i| {
                let t = i as f64;
                let q = DQuat::from_rotation_z(0.1 * t + 1e-3 * (t * 7.3).sin());
                Pose {
                    rotation: q,
                    translation: DVec3::new(t, 1e-3 * (t * 3.1).cos(), 0.0),
                }
            })
            .collect();
        (poses, (0..n).map(|i| i as f64).collect())
    }

    #[test]
    fn held_matrices_are_written_bit_for_bit_and_the_others_from_the_poses() {
        let n = 12;
        let (poses, times) = clip(n);
        let mut held = vec![false; n];
        held[3] = true;
        held[7] = true;
        // matrices that differ from the poses' own (a caller's float32 rounding, say)
        let odd = |i: usize| {
            let mut m = poses[i].to_rows();
            m[0][3] += 0.25;
            m
        };
        let held_rows = [odd(3), odd(7)];
        let results: Vec<Denoised> = denoise_batch(
            &poses,
            1,
            &times,
            Some(&held),
            &DenoiseOptions::default(),
            1,
        )
        .expect("valid clip")
        .into_iter()
        .map(|r| r.expect("smoothed"))
        .collect();
        let rows = denoised_rows(&results, n, Some(&held), &held_rows).expect("rows");
        assert_eq!(rows.len(), n * 16);
        for i in 0..n {
            let got = &rows[16 * i..16 * (i + 1)];
            let want: Vec<f64> = if held[i] {
                odd(i).iter().flatten().copied().collect()
            } else {
                results[0].poses[i]
                    .to_rows()
                    .iter()
                    .flatten()
                    .copied()
                    .collect()
            };
            assert_eq!(got, want.as_slice(), "pose {i}");
        }
        let short = denoised_rows(&results, n, Some(&held), &held_rows[..1]);
        assert!(
            matches!(short, Err(Error::LengthMismatch { .. })),
            "{short:?}"
        );
    }
}
