//! Four `f64` lanes side by side (structure of arrays), for batches: [`F4`] numbers,
//! [`M4`] masks, [`V4`] vectors and [`Q4`] quaternions, with element-wise operators that
//! LLVM compiles to packed SSE2 instructions (two lanes per instruction on baseline x86-64).
//! Branches become selects: every lane computes every case and a mask picks.
//!
//! [`F4`] implements [`fastmath`](crate::numeric::fastmath)'s [`Real`], so one polynomial
//! kernel serves `f64` and four lanes (the same operations in the same order, so a lane
//! agrees with the scalar to the bit): the sin/cos kernel and `turn_angle` take either;
//! [`sin_cos`] is the lane form of its range reduction. This module depends on `fastmath`,
//! never the other way round.

use std::f64::consts::FRAC_PI_2;
use std::ops::{Add, Div, Mul, Neg, Sub};

use glam::{DQuat, DVec3};

use crate::numeric::fastmath::{kernel, Real, PIO2_HI, PIO2_LO, ROUNDING_SHIFT};

/// The number of lanes.
pub(crate) const LANES: usize = 4;

/// Four `f64` lanes.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct F4(pub [f64; LANES]);

/// Four lane masks (the result of a comparison).
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct M4(pub [bool; LANES]);

macro_rules! lanewise {
    ($trait:ident, $method:ident, $op:tt) => {
        impl $trait for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, o: F4) -> F4 {
                let (a, b) = (self.0, o.0);
                F4(std::array::from_fn(|i| a[i] $op b[i]))
            }
        }
        impl $trait<f64> for F4 {
            type Output = F4;
            #[inline(always)]
            fn $method(self, o: f64) -> F4 {
                self $op F4::splat(o)
            }
        }
    };
}
lanewise!(Add, add, +);
lanewise!(Sub, sub, -);
lanewise!(Mul, mul, *);
lanewise!(Div, div, /);

impl Neg for F4 {
    type Output = F4;
    #[inline(always)]
    fn neg(self) -> F4 {
        self.map(|x| -x)
    }
}

impl Real for F4 {
    #[inline(always)]
    fn splat(v: f64) -> Self {
        F4([v; LANES])
    }
    #[inline(always)]
    fn sqrt(self) -> Self {
        self.map(f64::sqrt)
    }
}

impl F4 {
    /// `v` in every lane.
    #[inline(always)]
    pub(crate) fn splat(v: f64) -> Self {
        F4([v; LANES])
    }

    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub(crate) fn from_fn(f: impl FnMut(usize) -> f64) -> Self {
        F4(std::array::from_fn(f))
    }

    #[inline(always)]
    fn map(self, f: impl Fn(f64) -> f64) -> F4 {
        let a = self.0;
        F4(std::array::from_fn(|i| f(a[i])))
    }

    #[inline(always)]
    fn compare(self, o: F4, f: impl Fn(f64, f64) -> bool) -> M4 {
        let (a, b) = (self.0, o.0);
        M4(std::array::from_fn(|i| f(a[i], b[i])))
    }

    /// `self < o` per lane.
    #[inline(always)]
    pub(crate) fn lt(self, o: f64) -> M4 {
        self.compare(F4::splat(o), |a, b| a < b)
    }

    /// `self > o` per lane (false for NaN).
    #[inline(always)]
    pub(crate) fn gt(self, o: f64) -> M4 {
        self.compare(F4::splat(o), |a, b| a > b)
    }

    /// Lanes that are neither NaN nor `>= bound` in magnitude.
    #[inline(always)]
    pub(crate) fn abs_below(self, bound: f64) -> M4 {
        self.compare(F4::splat(bound), |a, b| a.abs() < b)
    }
}

impl M4 {
    /// Lane by lane: `yes` where the mask is set, `no` elsewhere.
    #[inline(always)]
    pub(crate) fn select(self, yes: F4, no: F4) -> F4 {
        let (m, a, b) = (self.0, yes.0, no.0);
        F4(std::array::from_fn(|i| if m[i] { a[i] } else { b[i] }))
    }

    /// [`M4::select`] for vectors.
    #[inline(always)]
    pub(crate) fn select_v(self, yes: V4, no: V4) -> V4 {
        V4 {
            x: self.select(yes.x, no.x),
            y: self.select(yes.y, no.y),
            z: self.select(yes.z, no.z),
        }
    }

    /// Whether every lane is set.
    #[inline(always)]
    pub(crate) fn all(self) -> bool {
        self.0.iter().all(|&m| m)
    }
}

/// Four 3-vectors, one per lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct V4 {
    pub x: F4,
    pub y: F4,
    pub z: F4,
}

impl V4 {
    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub(crate) fn from_fn(mut f: impl FnMut(usize) -> DVec3) -> Self {
        let v: [DVec3; LANES] = std::array::from_fn(&mut f);
        V4 {
            x: F4::from_fn(|i| v[i].x),
            y: F4::from_fn(|i| v[i].y),
            z: F4::from_fn(|i| v[i].z),
        }
    }

    /// Lane `i`.
    #[inline(always)]
    pub(crate) fn lane(&self, i: usize) -> DVec3 {
        DVec3::new(self.x.0[i], self.y.0[i], self.z.0[i])
    }

    #[inline(always)]
    pub(crate) fn dot(self, o: V4) -> F4 {
        self.x * o.x + self.y * o.y + self.z * o.z
    }

    /// The cross product, with glam's order of operations.
    #[inline(always)]
    pub(crate) fn cross(self, o: V4) -> V4 {
        V4 {
            x: self.y * o.z - o.y * self.z,
            y: self.z * o.x - o.z * self.x,
            z: self.x * o.y - o.x * self.y,
        }
    }

    #[inline(always)]
    pub(crate) fn scale(self, s: F4) -> V4 {
        V4 {
            x: self.x * s,
            y: self.y * s,
            z: self.z * s,
        }
    }
}

impl Add for V4 {
    type Output = V4;
    #[inline(always)]
    fn add(self, o: V4) -> V4 {
        V4 {
            x: self.x + o.x,
            y: self.y + o.y,
            z: self.z + o.z,
        }
    }
}

impl Sub for V4 {
    type Output = V4;
    #[inline(always)]
    fn sub(self, o: V4) -> V4 {
        V4 {
            x: self.x - o.x,
            y: self.y - o.y,
            z: self.z - o.z,
        }
    }
}

/// Four quaternions, one per lane.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Q4 {
    pub v: V4,
    pub w: F4,
}

impl Q4 {
    /// Lane `i` is `f(i)`.
    #[inline(always)]
    pub(crate) fn from_fn(mut f: impl FnMut(usize) -> DQuat) -> Self {
        let q: [DQuat; LANES] = std::array::from_fn(&mut f);
        Q4 {
            v: V4 {
                x: F4::from_fn(|i| q[i].x),
                y: F4::from_fn(|i| q[i].y),
                z: F4::from_fn(|i| q[i].z),
            },
            w: F4::from_fn(|i| q[i].w),
        }
    }

    /// Lane `i`.
    #[inline(always)]
    pub(crate) fn lane(&self, i: usize) -> DQuat {
        DQuat::from_xyzw(self.v.x.0[i], self.v.y.0[i], self.v.z.0[i], self.w.0[i])
    }

    #[inline(always)]
    pub(crate) fn conjugate(self) -> Q4 {
        Q4 {
            v: V4 {
                x: -self.v.x,
                y: -self.v.y,
                z: -self.v.z,
            },
            w: self.w,
        }
    }

    /// Lane-wise negation where `mask` is set.
    #[inline(always)]
    pub(crate) fn negate_where(self, mask: M4) -> Q4 {
        let n = self.conjugate();
        Q4 {
            v: mask.select_v(n.v, self.v),
            w: mask.select(-self.w, self.w),
        }
    }

    /// The Hamilton product `self * o`, with glam's order of operations.
    #[inline(always)]
    pub(crate) fn mul(self, o: Q4) -> Q4 {
        let (x0, y0, z0, w0) = (self.v.x, self.v.y, self.v.z, self.w);
        let (x1, y1, z1, w1) = (o.v.x, o.v.y, o.v.z, o.w);
        Q4 {
            v: V4 {
                x: w0 * x1 + x0 * w1 + y0 * z1 - z0 * y1,
                y: w0 * y1 - x0 * z1 + y0 * w1 + z0 * x1,
                z: w0 * z1 + x0 * y1 - y0 * x1 + z0 * w1,
            },
            w: w0 * w1 - x0 * x1 - y0 * y1 - z0 * z1,
        }
    }
}

/// `(sin x, cos x)` per lane for `|x| < crate::numeric::fastmath::FAST_REDUCTION_BELOW` (the caller
/// checks), with [`crate::numeric::fastmath::sin_cos`]'s reduction and kernel; the quadrant by
/// selects.
#[inline(always)]
pub(crate) fn sin_cos(x: F4) -> (F4, F4) {
    let n = (x * (1.0 / FRAC_PI_2) + ROUNDING_SHIFT) - ROUNDING_SHIFT;
    let r = (x - n * PIO2_HI) - n * PIO2_LO;
    let (s, c) = kernel(r);
    // Quadrant n mod 4: 0 (s, c), 1 (c, -s), 2 (-s, -c), 3 (-c, s).
    let quadrant = n.0.map(|n| (n as i64) & 3);
    let swap = M4(quadrant.map(|q| q & 1 == 1));
    let neg_sin = M4(quadrant.map(|q| q >= 2));
    let neg_cos = M4(quadrant.map(|q| q == 1 || q == 2));
    let (s1, c1) = (swap.select(c, s), swap.select(s, c));
    (neg_sin.select(-s1, s1), neg_cos.select(-c1, c1))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::numeric::fastmath;

    #[test]
    fn kernels_agree_with_the_scalar_to_the_bit() {
        for i in 0..4000 {
            let base = (i as f64 - 2000.0) * 7.3e-3;
            let x = F4::from_fn(|l| [base, base * 1e-9, -base * 3.1, base * 0.5 + 1e-3][l % 4]);
            let (s, c) = sin_cos(x);
            for l in 0..LANES {
                let (ws, wc) = fastmath::sin_cos(x.0[l]);
                assert_eq!((s.0[l], c.0[l]), (ws, wc), "sin_cos({})", x.0[l]);
            }
            let w = F4::from_fn(|l| [1.0, 0.0, (base * 0.1).cos().abs(), 1e-3][(i + l) % 4]);
            let sin = F4(w.0.map(|w: f64| (1.0 - w * w).sqrt()));
            let got = fastmath::turn_angle(w, sin);
            for l in 0..LANES {
                assert_eq!(got.0[l], fastmath::turn_angle(w.0[l], sin.0[l]));
            }
        }
    }
}
