//! A BEZIER segment as Blender evaluates it (`fcurve_eval_keyframes_interpolate`, case
//! `BEZT_IPO_BEZ`): the handles clamped to the segment (`BKE_fcurve_correct_bezpart`), the
//! parameter `u` of a frame found by solving the cubic `x(u) = frame` in closed form
//! (`findzero`, `solve_cubic`, Cardano and the trigonometric form, in `double`), and the value
//! `y(u)` (`berekeny`, in `float`).
//!
//! With `P0 = (x0, y0)` the first key, `P1` its right handle, `P2` the second key's left
//! handle and `P3` the second key:
//! `x(u) = x0 + 3 (x1 - x0) u + 3 (x0 - 2 x1 + x2) u^2 + (x3 - x0 + 3 (x1 - x2)) u^3`, the
//! same for `y`. The coefficients that do not depend on the frame are computed once per
//! segment ([`BezierSegment::new`]), with exactly the operations Blender repeats per frame.

/// Blender's `SMALL` (`-1.0e-10`): roots of the cubic down to this are accepted.
const SMALL: f64 = -1.0e-10;
/// Largest root of the cubic accepted (`1.000001f`).
const ROOT_MAX: f32 = 1.000001;

/// Clamps the handles of a segment so that neither reaches past the other key in time
/// (Blender's `BKE_fcurve_correct_bezpart`): a handle whose horizontal length `|x1 - x0|`
/// exceeds the segment's length `x3 - x0` is scaled about its key by `len / |x1 - x0|`
/// (direction kept). `v1`, `v4` are the keys, `v2` the first key's right handle, `v3` the
/// second key's left handle.
pub fn correct_bezpart(v1: [f32; 2], v2: &mut [f32; 2], v3: &mut [f32; 2], v4: [f32; 2]) {
    let h1 = [v1[0] - v2[0], v1[1] - v2[1]];
    let h2 = [v4[0] - v3[0], v4[1] - v3[1]];
    let len = v4[0] - v1[0];
    let len1 = h1[0].abs();
    let len2 = h2[0].abs();
    if (len1 + len2) == 0.0 {
        return;
    }
    if len1 > len {
        let fac = len / len1;
        v2[0] = v1[0] - fac * h1[0];
        v2[1] = v1[1] - fac * h1[1];
    }
    if len2 > len {
        let fac = len / len2;
        v3[0] = v4[0] - fac * h2[0];
        v3[1] = v4[1] - fac * h2[1];
    }
}

/// Blender's `sqrt3d`: the real cube root as `exp(log(d) / 3)`, sign kept.
fn sqrt3d(d: f64) -> f64 {
    if d == 0.0 {
        0.0
    } else if d < 0.0 {
        -((-d).ln() / 3.0).exp()
    } else {
        (d.ln() / 3.0).exp()
    }
}

/// Whether a root is accepted: within `[SMALL, 1.000001]` as a `float`.
fn accepted(o: f32) -> bool {
    o >= SMALL as f32 && o <= ROOT_MAX
}

/// The first root Blender's `solve_cubic` reports of `c0 + c1 u + c2 u^2 + c3 u^3` in
/// `[SMALL, 1.000001]`, or `None` where it reports none. Same branches, same order of roots.
pub fn solve_cubic(c0: f64, c1: f64, c2: f64, c3: f64) -> Option<f32> {
    if c3 != 0.0 {
        let a = c2 / c3 / 3.0;
        let b = c1 / c3;
        return solve_normalised(CubicShape::new(a, b), c0 / c3);
    }
    let (a, b, c) = (c2, c1, c0);
    if a != 0.0 {
        let p = b * b - 4.0 * a * c;
        if p > 0.0 {
            let p = p.sqrt();
            let o = ((-b - p) / (2.0 * a)) as f32;
            if accepted(o) {
                return Some(o);
            }
            let o = ((-b + p) / (2.0 * a)) as f32;
            return accepted(o).then_some(o);
        }
        if p == 0.0 {
            let o = (-b / (2.0 * a)) as f32;
            return accepted(o).then_some(o);
        }
        return None;
    }
    if b != 0.0 {
        let o = (-c / b) as f32;
        return accepted(o).then_some(o);
    }
    if c == 0.0 {
        return Some(0.0);
    }
    None
}

/// The parts of `solve_cubic`'s normalised cubic `u^3 + 3 a u^2 + b u + c` that do not
/// depend on `c` (so on the frame): `a` (already divided by 3), `p = b / 3 - a^2`, `p^3` and
/// `2 a^3 - a b`, each as Blender computes it.
#[derive(Debug, Clone, Copy, PartialEq)]
struct CubicShape {
    a: f64,
    p: f64,
    ppp: f64,
    k: f64,
}

impl CubicShape {
    fn new(a: f64, b: f64) -> Self {
        let p = b / 3.0 - a * a;
        Self {
            a,
            p,
            ppp: p * p * p,
            k: 2.0 * a * a * a - a * b,
        }
    }
}

/// `solve_cubic` from `q = (2 a^3 - a b + c) / 2` on (the case `c3 != 0`).
fn solve_normalised(s: CubicShape, c: f64) -> Option<f32> {
    let a = s.a;
    let q = (s.k + c) / 2.0;
    let d = q * q + s.ppp;
    if d > 0.0 {
        let t = d.sqrt();
        let o = (sqrt3d(-q + t) + sqrt3d(-q - t) - a) as f32;
        return accepted(o).then_some(o);
    }
    if d == 0.0 {
        let t = sqrt3d(-q);
        let o = (2.0 * t - a) as f32;
        if accepted(o) {
            return Some(o);
        }
        let o = (-t - a) as f32;
        return accepted(o).then_some(o);
    }
    let phi = (-q / (-s.ppp).sqrt()).acos();
    let t = (-s.p).sqrt();
    let p = (phi / 3.0).cos();
    let q = (3.0 - 3.0 * p * p).sqrt();
    let o = (2.0 * t * p - a) as f32;
    if accepted(o) {
        return Some(o);
    }
    let o = (-t * (p + q) - a) as f32;
    if accepted(o) {
        return Some(o);
    }
    let o = (-t * (p - q) - a) as f32;
    accepted(o).then_some(o)
}

/// One BEZIER segment, prepared once: the flat shortcut, the corrected handles, and the
/// frame-independent coefficients of `x(u)` and `y(u)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BezierSegment {
    /// All four values within `f32::EPSILON` of each other: Blender returns the first value
    /// without solving anything.
    flat: bool,
    /// The first key's frame `x0` (`findzero`'s `q0`).
    x0: f32,
    /// `x(u)`'s coefficients `c1, c2, c3` as `double`s (computed in `float`, as Blender does).
    xc: [f64; 3],
    /// `c3 != 0`: the normalised cubic's frame-independent parts.
    shape: Option<CubicShape>,
    /// `y(u)`'s coefficients `c0, c1, c2, c3` (`berekeny`).
    yc: [f32; 4],
}

/// A root of [`BezierSegment::parameter`] and what it depends on (the frame, the segment's
/// key and handle frames), for the next segment evaluated at the same frame
/// ([`BezierSegment::eval_sharing`]).
#[derive(Debug, Clone, Copy)]
pub(crate) struct SharedRoot {
    frame: f32,
    x0: f32,
    xc: [f64; 3],
    root: Option<f32>,
}

impl BezierSegment {
    /// The segment from key `v1` with right handle `v2` to key `v4` with left handle `v3`
    /// (`(frame, value)` each, as stored).
    pub fn new(v1: [f32; 2], v2: [f32; 2], v3: [f32; 2], v4: [f32; 2]) -> Self {
        let eps = f32::EPSILON;
        let flat = (v1[1] - v4[1]).abs() < eps
            && (v2[1] - v3[1]).abs() < eps
            && (v3[1] - v4[1]).abs() < eps;
        let (mut v2, mut v3) = (v2, v3);
        correct_bezpart(v1, &mut v2, &mut v3, v4);
        let (q0, q1, q2, q3) = (v1[0], v2[0], v3[0], v4[0]);
        let c1 = (3.0 * (q1 - q0)) as f64;
        let c2 = (3.0 * (q0 - 2.0 * q1 + q2)) as f64;
        let c3 = (q3 - q0 + 3.0 * (q1 - q2)) as f64;
        let shape = (c3 != 0.0).then(|| CubicShape::new(c2 / c3 / 3.0, c1 / c3));
        let (f1, f2, f3, f4) = (v1[1], v2[1], v3[1], v4[1]);
        let yc = [
            f1,
            3.0 * (f2 - f1),
            3.0 * (f1 - 2.0 * f2 + f3),
            f4 - f1 + 3.0 * (f2 - f3),
        ];
        Self {
            flat,
            x0: q0,
            xc: [c1, c2, c3],
            shape,
            yc,
        }
    }

    /// The segment's value at `frame`, or `0.0` where Blender's root finder finds no
    /// parameter (Blender returns 0 there too).
    pub fn eval(&self, frame: f32) -> f32 {
        if self.flat {
            return self.yc[0];
        }
        let c0 = (self.x0 - frame) as f64;
        let root = match self.shape {
            Some(shape) => solve_normalised(shape, c0 / self.xc[2]),
            None => solve_cubic(c0, self.xc[0], self.xc[1], self.xc[2]),
        };
        let Some(t) = root else {
            return 0.0;
        };
        let [c0, c1, c2, c3] = self.yc;
        c0 + t * c1 + t * t * c2 + t * t * t * c3
    }

    /// [`BezierSegment::eval`], the root taken from `shared` when it was solved there for
    /// the same `frame` on a segment with the same key and handle frames, else solved and
    /// kept there: the same value, bit for bit.
    pub(crate) fn eval_sharing(&self, frame: f32, shared: &mut Option<SharedRoot>) -> f32 {
        if self.flat {
            return self.yc[0];
        }
        let same = |s: &SharedRoot| {
            s.frame.to_bits() == frame.to_bits()
                && s.x0.to_bits() == self.x0.to_bits()
                && s.xc.map(f64::to_bits) == self.xc.map(f64::to_bits)
        };
        let root = match shared {
            Some(s) if same(s) => s.root,
            _ => {
                let root = self.parameter(frame);
                *shared = Some(SharedRoot {
                    frame,
                    x0: self.x0,
                    xc: self.xc,
                    root,
                });
                root
            }
        };
        self.value_at(root)
    }

    /// The parameter `u` Blender's root finder gives `frame` on this segment (`None` where it
    /// finds none). It depends only on the keys' and handles' frames, so segments of several
    /// curves keyed at the same frames with the same handle frames share it:
    /// `value_at(parameter(frame))` is [`BezierSegment::eval`] bit for bit.
    pub(crate) fn parameter(&self, frame: f32) -> Option<f32> {
        let c0 = (self.x0 - frame) as f64;
        match self.shape {
            Some(shape) => solve_normalised(shape, c0 / self.xc[2]),
            None => solve_cubic(c0, self.xc[0], self.xc[1], self.xc[2]),
        }
    }

    /// The segment's value at parameter `u` from [`BezierSegment::parameter`] (`berekeny`;
    /// the flat shortcut and the no-root `0.0` as in [`BezierSegment::eval`]).
    pub(crate) fn value_at(&self, u: Option<f32>) -> f32 {
        if self.flat {
            return self.yc[0];
        }
        let Some(t) = u else {
            return 0.0;
        };
        let [c0, c1, c2, c3] = self.yc;
        c0 + t * c1 + t * t * c2 + t * t * t * c3
    }
}
