//! The two transcendental functions a screw needs, specialised: `sin` and `cos` of one
//! argument together, and the angle of a turn given by its cosine and sine
//! ([`turn_angle`], in place of `atan2` in the first quadrant). std's `sin_cos` evaluates
//! `sin` and `cos` separately and `atan2` handles every quadrant and special value; these
//! share one range reduction and skip what cannot happen, which halves the cost of
//! `s(a, t, b)`.
//!
//! The polynomial kernels are fdlibm's (`k_sin.c`, `k_cos.c`, `s_atan.c`, Sun Microsystems,
//! 1993), accurate to about 1 ulp on their reduced ranges; the tests compare with std. They
//! are evaluated by Estrin's scheme rather than Horner's: the same polynomial with a
//! dependency chain half as long, which is what bounds `s` (a chain from the quaternion
//! product through the angle and its sine to the pose).

// The constants are fdlibm's, digit for digit.
#![allow(clippy::excessive_precision)]

use std::f64::consts::FRAC_PI_2;
use std::ops::{Add, Div, Mul, Sub};

/// A number type the polynomial kernels accept: `f64` or four lanes of it.
pub(crate) trait Real:
    Copy + Add<Output = Self> + Sub<Output = Self> + Mul<Output = Self> + Div<Output = Self>
{
    /// `v` in every lane.
    fn splat(v: f64) -> Self;
    /// The square root (of every lane).
    fn sqrt(self) -> Self;
}

impl Real for f64 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        v
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        f64::sqrt(self)
    }
}

/// `c[0] + c[1] x + ... + c[N - 1] x^(N - 1)` by Estrin's scheme: pairs `c[i] + c[i + 1] x`
/// combined with `x^2`, `x^4`, ..., a dependency chain of `log2 N` steps instead of Horner's
/// `N - 1` (the kernels sit on the critical path of `s`).
#[inline(always)]
pub(crate) fn estrin<R: Real, const N: usize>(x: R, c: [f64; N]) -> R {
    // Level 0: the terms of degree 0 and 1 in x, N / 2 (rounded up) of them.
    let mut terms: [R; N] = [R::splat(0.0); N];
    let mut len = 0;
    let mut i = 0;
    while i < N {
        terms[len] = if i + 1 < N {
            R::splat(c[i]) + R::splat(c[i + 1]) * x
        } else {
            R::splat(c[i])
        };
        len += 1;
        i += 2;
    }
    let mut power = x * x;
    while len > 1 {
        let mut j = 0;
        let mut k = 0;
        while j < len {
            terms[k] = if j + 1 < len {
                terms[j] + terms[j + 1] * power
            } else {
                terms[j]
            };
            k += 1;
            j += 2;
        }
        len = k;
        if len > 1 {
            power = power * power;
        }
    }
    terms[0]
}

/// `1.5 * 2^52`: adding it rounds an f64 below `2^51` in magnitude to an integer.
pub(crate) const ROUNDING_SHIFT: f64 = 6_755_399_441_055_744.0;

/// Beyond this `|x|` the two-term reduction by `pi / 2` loses bits: std takes over.
pub(crate) const FAST_REDUCTION_BELOW: f64 = 1e6;

// pi / 2 in two parts: 33 bits and the rest (fdlibm `pio2_1`, `pio2_1t`).
pub(crate) const PIO2_HI: f64 = 1.570_796_326_734_125_614_17e0;
pub(crate) const PIO2_LO: f64 = 6.077_100_506_506_192_249_32e-11;

const S1: f64 = -1.666_666_666_666_663_243_48e-1;
const S2: f64 = 8.333_333_333_322_489_461_24e-3;
const S3: f64 = -1.984_126_982_985_794_931_34e-4;
const S4: f64 = 2.755_731_370_707_006_767_89e-6;
const S5: f64 = -2.505_076_025_340_686_341_95e-8;
const S6: f64 = 1.589_690_995_211_550_102_21e-10;

const C1: f64 = 4.166_666_666_666_660_190_37e-2;
const C2: f64 = -1.388_888_888_887_410_957_49e-3;
const C3: f64 = 2.480_158_728_947_672_941_78e-5;
const C4: f64 = -2.755_731_435_139_066_330_35e-7;
const C5: f64 = 2.087_572_321_298_174_827_90e-9;
const C6: f64 = -1.135_964_755_778_819_482_65e-11;

/// `(sin r, cos r)` for `|r| <= pi / 4`, for one value or several lanes (the same
/// operations in the same order, so the lanes agree with the scalar to the bit).
#[inline(always)]
pub(crate) fn kernel<R: Real>(r: R) -> (R, R) {
    let one = R::splat(1.0);
    let z = r * r;
    let s = r + r * z * estrin(z, [S1, S2, S3, S4, S5, S6]);
    let hz = R::splat(0.5) * z;
    let w = one - hz;
    let c = w + (((one - w) - hz) + z * z * estrin(z, [C1, C2, C3, C4, C5, C6]));
    (s, c)
}

/// `(sin x, cos x)` with one range reduction.
#[inline]
pub fn sin_cos(x: f64) -> (f64, f64) {
    // NaN and infinities go to std too.
    if x.is_nan() || x.abs() >= FAST_REDUCTION_BELOW {
        return x.sin_cos();
    }
    // Round to nearest by adding and subtracting 1.5 * 2^52 (exact for |x| < 2^51; std's
    // `round` is a library call on baseline x86-64).
    let n = (x * (1.0 / FRAC_PI_2) + ROUNDING_SHIFT) - ROUNDING_SHIFT;
    let r = (x - n * PIO2_HI) - n * PIO2_LO;
    let (s, c) = kernel(r);
    match (n as i64) & 3 {
        0 => (s, c),
        1 => (c, -s),
        2 => (-s, -c),
        _ => (-c, s),
    }
}

const AT: [f64; 11] = [
    3.333_333_333_333_293_180_27e-1,
    -1.999_999_999_987_648_324_76e-1,
    1.428_571_427_250_346_637_11e-1,
    -1.111_111_040_546_235_578_80e-1,
    9.090_887_133_436_506_561_96e-2,
    -7.691_876_205_044_829_994_95e-2,
    6.661_073_137_387_531_206_69e-2,
    -5.833_570_133_790_573_486_45e-2,
    4.976_877_994_615_932_360_17e-2,
    -3.653_157_274_421_691_552_70e-2,
    1.628_582_011_536_578_236_23e-2,
];

/// fdlibm's `x (s1 + s2)`, with `atan(x) = x - x (s1 + s2)` for `|x| < 7/16`; one value or
/// several lanes.
#[inline(always)]
pub(crate) fn atan_poly<R: Real>(x: R) -> R {
    let z = x * x;
    let w = z * z;
    let s1 = z * estrin(w, [AT[0], AT[2], AT[4], AT[6], AT[8], AT[10]]);
    let s2 = w * estrin(w, [AT[1], AT[3], AT[5], AT[7], AT[9]]);
    x * (s1 + s2)
}

/// The angle `h` in `[0, pi / 2]` of a turn given as `(cos h, sin h)` (`w >= 0`, `s >= 0`,
/// `w^2 + s^2 = 1`, as the relative rotation of a screw has): with
/// `c = cos(h / 2) = sqrt((1 + w) / 2)`,
///
/// ```text
/// tan(h / 4) = sin(h / 2) / (1 + cos(h / 2)) = s / (2 c (1 + c))   in [0, tan(pi / 8)]
/// h = 4 atan(tan(h / 4))
/// ```
///
/// and `tan(pi / 8) = 0.414 < 7 / 16`, inside fdlibm's first range, so one polynomial and no
/// branch (the denominator is at least `2.41`): a few ulps, exact at `h = 0`. For one value
/// or several lanes.
#[inline(always)]
pub(crate) fn turn_angle<R: Real>(w: R, s: R) -> R {
    let one = R::splat(1.0);
    let c = (R::splat(0.5) * (one + w)).sqrt();
    let x = s / (R::splat(2.0) * c * (one + c));
    R::splat(4.0) * (x - atan_poly(x))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sin_cos_matches_std() {
        let mut worst: f64 = 0.0;
        for i in 0..200_000 {
            let x = (i as f64 - 100_000.0) * 1.3e-4 + (i as f64 * 0.618).sin() * 1e-3;
            let (s, c) = sin_cos(x);
            // Absolute error relative to 1 (values near 0 have no meaningful ulps).
            worst = worst.max((s - x.sin()).abs()).max((c - x.cos()).abs());
        }
        assert!(worst < 3.0 * f64::EPSILON, "worst absolute error {worst:e}");
        for x in [0.0, 1e-300, 1e-8, 0.785, 1e7, -1e9] {
            let (s, c) = sin_cos(x);
            assert!((s - x.sin()).abs() <= 2.0 * f64::EPSILON * x.sin().abs().max(1e-300) + 1e-300);
            assert!((c - x.cos()).abs() <= 2.0 * f64::EPSILON);
        }
    }

    #[test]
    fn turn_angle_matches_std() {
        let mut worst: f64 = 0.0;
        for i in 0..=200_000 {
            let h = i as f64 / 200_000.0 * FRAC_PI_2;
            for h in [h, h * 1e-9] {
                let (s, w) = h.sin_cos();
                let want = s.atan2(w);
                worst =
                    worst.max((turn_angle(w, s) - want).abs() / (f64::EPSILON * want.max(1e-300)));
            }
        }
        assert!(worst <= 4.0, "worst {worst} ulps");
        assert_eq!(turn_angle(1.0, 0.0), 0.0);
        assert!((turn_angle(0.0, 1.0) - FRAC_PI_2).abs() <= 2.0 * f64::EPSILON);
    }
}
