//! The screw between two poses and `s(a, t, b)`, the motion along it.
//!
//! Rossignac-Kim (*Computing and visualizing pose-interpolating 3D motions*, section "Screw motions"): for poses `L0`, `L1` there is a unique
//! minimal-angle screw `M` with `L1 = M L0`: a rotation by `r` in `[0, pi]` about an axis of
//! unit direction `S` through a point `P`, plus a slide `d` along `S`. Then
//! `s(L0, t, L1) = M^t L0` for any real `t` (`t = 0` gives `L0`, `t = 1` gives `L1`, outside
//! `[0, 1]` the screw extrapolates).
//!
//! Instead of the paper's cross-product construction we take the logarithm of the relative
//! rotation as a unit quaternion `q = q1 q0^-1 = (cos h, sin h S)` with `h = r / 2`, `w >= 0`,
//! and write the translation of `M^t` without the axis point, so nothing divides by the
//! angle. With `tau = o1 - R o0` the translation of `M`:
//!
//! ```text
//! rho(t)  = sin(t h) / sin(h)          (t at h = 0)
//! A(t)    = rho(t) cos((t - 1) h)
//! B(t)    = rho(t) sin((t - 1) h)
//! M^t     : x -> R^t x + A tau + (t - A) (tau . S) S + B (S x tau)
//! R^t     = (cos(t h), rho(t) sin(h) S)
//! ```
//!
//! `A(1) = 1`, `B(1) = 0`, and as `h -> 0`, `A -> t`, `B -> 0`: the screw degrades into the
//! straight translation continuously, and at `h = pi / 2` (`r = pi`) nothing is singular.
//! Derivation: `M^t x = R^t (x - P) + P + t d S` with `P = (tau_perp + cot(h) S x tau) / 2`,
//! expanded with half-angle identities.

use glam::{DQuat, DVec3};

use crate::error::{Error, Result};
use crate::motion::pose::Pose;
use crate::numeric::fastmath;
use crate::numeric::fastmath::Real;
use crate::numeric::lanes::{self, F4, LANES, Q4, V4};

/// The working range of the screw parameter `t` of [`Screw::eval`] (`s(a, t, b)`):
/// `|t| <= MAX_T`, a trillion times the screw and back.
///
/// Why: `M^t o_a` takes `rho^2 (v . o_a)` with `rho = sin(t h) / sin(h)`, which is `t` for a
/// translation (whose `|v|` may still hold round-off up to [`ROTATION_ROUNDOFF`]) and at most
/// `1 / sin(h)` for a turn; with coordinates within
/// [`crate::motion::pose::MAX_COORDINATE`] every term stays below `1e180` for `|t|` up to
/// `1e12`. Subdivision and sampling only evaluate `t` in `[-2, 3]`; callers passing any `t`
/// (the Python `interpolate`) check it.
pub const MAX_T: f64 = 1e12;

/// A relative rotation whose vector part `|q.xyz| = sin(h)` is at most this is round-off:
/// the screw is then a pure translation (axis along the translation, slide its length,
/// angle 0).
///
/// The scale of rotation data is fixed: quaternions are unit. Each component of
/// `q = q_b q_a^-1` is a sum of four rounded products of numbers of magnitude at most 1, so
/// the product alone leaves up to a few `eps` in `q.xyz` when `q_a = q_b`; rotation matrices
/// that went through another conversion (a quaternion, a rotation library) and back leave
/// up to `2 eps` (measured over 20,000 random rotations). `16 eps = 3.6e-15` covers both with
/// room, and is 14 times below the half angle of a `1e-13` rad turn, which stays a screw
/// (exact to `1e-12`). Positions do not enter: the rotation is computed from the rotations
/// alone, so the same round-off angle appears whatever the poses' extent, and comparing it
/// with the translation instead would report a real turn (`1e-6` rad with a `1e-10` move)
/// as a translation.
pub const ROTATION_ROUNDOFF: f64 = 16.0 * f64::EPSILON;

/// The minimal screw carrying pose `a` to pose `b`, ready to be evaluated at any `t`.
///
/// Built once per pair by [`Screw::between`]; [`Screw::eval`] then costs one `sin_cos`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Screw {
    /// The start pose `a` (`eval(0)`).
    base: Pose,
    /// The relative rotation `q = q_b q_a^-1` with `w >= 0`.
    rotation: DQuat,
    /// Half the rotation angle, `h = atan2(|q.xyz|, q.w)` (by [`fastmath::turn_angle`]), in
    /// `[0, pi / 2]`.
    half_angle: f64,
    /// `sin(h) = |q.xyz|`, cached.
    sin_half: f64,
    /// `1 / sin(h)` (0 when `h = 0`), cached.
    inv_sin_half: f64,
    /// Unit axis direction `S` (the translation's direction for a pure translation, `+z` for
    /// the identity).
    axis: DVec3,
    /// The translation `tau = o_b - R o_a` of the world motion `M`.
    tau: DVec3,
    /// `v . o_a` and `v x o_a` (`v = q.xyz`, `o_a` the start's translation): shared by the
    /// rotation of `o_a` by `q` (for `tau`) and by `M^t` (in [`Screw::eval`]).
    v_dot_o: f64,
    v_x_o: DVec3,
}

impl Screw {
    /// The minimal screw from `a` to `b` (Rossignac-Kim, "Screw motions").
    ///
    /// When the relative rotation is exactly a half turn both axis directions are minimal;
    /// the one of the quaternion with `w >= 0` as computed is taken.
    #[inline(always)]
    pub fn between(a: &Pose, b: &Pose) -> Self {
        // A product of unit quaternions is unit to rounding: no normalisation on this path
        // (every division and square root here is on the critical path of `s`).
        let mut q = b.rotation * a.rotation.conjugate();
        if q.w < 0.0 {
            q = -q;
        }
        let v = q.xyz();
        let b2 = v.dot(v);
        let sin_h = b2.sqrt();
        let half_angle = fastmath::turn_angle(q.w, sin_h);
        // q o_a = o_a (w^2 - |v|^2) + v (2 v . o_a) + (v x o_a) (2 w), as glam's `q * o_a`.
        let oa = a.translation;
        let (v_dot_o, v_x_o) = (v.dot(oa), v.cross(oa));
        let tau =
            b.translation - (oa * (q.w * q.w - b2) + v * (v_dot_o * 2.0) + v_x_o * (q.w * 2.0));
        let (inv_sin_half, axis) = if sin_h > ROTATION_ROUNDOFF {
            let inv = 1.0 / sin_h;
            (inv, v * inv)
        } else {
            (0.0, direction(tau).unwrap_or(DVec3::Z))
        };
        Self {
            base: *a,
            rotation: q,
            half_angle,
            sin_half: sin_h,
            inv_sin_half,
            axis,
            tau,
            v_dot_o,
            v_x_o,
        }
    }

    /// The world motion `M^t` as a pose (the transform that carries `a` to `s(a, t, b)`).
    /// `t = 0` is the identity, `t = 1` is `M = b a^-1`.
    #[inline]
    pub fn motion(&self, t: f64) -> Pose {
        let (rotation, translation, _, _) = self.motion_parts(t);
        Pose {
            rotation,
            translation,
        }
    }

    /// `M^t`'s rotation `(rho v, cos(t h))` and translation, with `rho` and `cos(t h)`.
    #[inline(always)]
    fn motion_parts(&self, t: f64) -> (DQuat, DVec3, f64, f64) {
        let h = self.half_angle;
        let th = t * h;
        let (sin_th, cos_th) = fastmath::sin_cos(th);
        let (sin_h, cos_h) = (self.sin_half, self.rotation.w);
        // rho = sin(t h) / sin(h), t at h = 0. No series is needed near 0: sin(h) = |q.xyz| is
        // computed directly and sin(t h) by a kernel of relative accuracy, so the quotient is
        // accurate to a few ulps however small h is. A round-off turn
        // (`ROTATION_ROUNDOFF`) counts as none (`inv_sin_half = 0`): rho = t.
        let rho = if self.inv_sin_half > 0.0 {
            sin_th * self.inv_sin_half
        } else {
            t
        };
        let v = self.rotation.xyz();
        let rotation = DQuat::from_xyzw(v.x * rho, v.y * rho, v.z * rho, cos_th);
        // cos((t-1)h), sin((t-1)h) from the angle-difference identities.
        let a = rho * (cos_th * cos_h + sin_th * sin_h);
        let b = rho * (sin_th * cos_h - cos_th * sin_h);
        // The turn's axis, 0 without a turn (then a = t, b = 0: the terms along it vanish and
        // a pure translation needs no axis of its own).
        let s = v * self.inv_sin_half;
        let tau = self.tau;
        let translation = tau * a + s * ((t - a) * tau.dot(s)) + s.cross(tau) * b;
        (rotation, translation, rho, cos_th)
    }

    /// `s(a, t, b) = M^t a`: `t = 0` gives `a`, `t = 1` gives `b` (to rounding), other `t`
    /// move along or past the screw (ScrewBender section 4, `s(L_a, t, L_b)`). `M^t o_a` by
    /// glam's rotation formula with `rho v` for `v`, from the cached `v . o_a`, `v x o_a`.
    #[inline(always)]
    pub fn eval(&self, t: f64) -> Pose {
        let (m, translation, rho, cos_th) = self.motion_parts(t);
        let v = self.rotation.xyz();
        let oa = self.base.translation;
        let rho2 = rho * rho;
        let position = oa * (cos_th * cos_th - rho2 * v.dot(v))
            + v * (rho2 * self.v_dot_o * 2.0)
            + self.v_x_o * (rho * cos_th * 2.0)
            + translation;
        Pose {
            rotation: m * self.base.rotation,
            translation: position,
        }
    }

    /// `[eval(k / 16) for k in ks]`: the screw at several fractions in sixteenths, for the
    /// fixed fractions of the Split&Tweak rules, without trigonometry.
    ///
    /// With `cos h = q.w`, `sin h = |q.xyz|` the half-angle identities
    /// `cos(x / 2) = sqrt((1 + cos x) / 2)`, `sin(x / 2) = sin x / (2 cos(x / 2))` give `h / 2`,
    /// `h / 4`, `h / 8` and `h / 16` (exact at `h = 0`, no cancellation up to the half turn),
    /// and products of these turns give `k h / 16` (`k = 16 j + r`, `|r| <= 8` in binary), one
    /// or two complex products per fraction. Then, with `theta = k h / 16`, `t = k / 16`,
    /// `rho = sin(theta) / sin(h)` (`t` at `h = 0`), `A = rho cos(theta - h)`,
    /// `B = rho sin(theta - h)` as in [`Screw::motion`]:
    ///
    /// ```text
    /// rotation     cos(theta) q_a + sin(theta) (S q_a)
    /// translation  o_a + A tau + (t - A) (tau . S) S + B (S x tau)
    ///                  + 2 sin(theta) (cos(theta) (S x o_a) + sin(theta) ((o_a . S) S - o_a))
    /// ```
    ///
    /// the last line being `R^t o_a - o_a` (rotation by `2 theta` about `S`). The vectors are
    /// computed once per call, so each fraction costs a few dozen multiply-adds. `k = 0` gives
    /// `a`, `k = 16` gives `b` (to rounding). Meant for `|k| <= 48` (the error grows like
    /// `|k| / 16` ulps of the turn).
    #[inline(always)]
    pub fn eval_sixteenths<const N: usize>(&self, ks: [i32; N]) -> [Pose; N] {
        // (q.w, |q.xyz|) scaled to unit length: q is a product of unit quaternions, so
        // |q|^2 = 1 + O(eps) and one Newton step for 1 / |q| is exact to rounding (the turns
        // below would otherwise carry the excess, doubled at every doubling of the angle).
        let (w, sin_h) = (self.rotation.w, self.sin_half);
        let inv_norm = 1.5 - 0.5 * (w * w + sin_h * sin_h);
        let inv_sin_h = self.inv_sin_half / inv_norm;
        // turns[j] = (cos, sin) of h / 2^j.
        let mut turns = [(w * inv_norm, sin_h * inv_norm); 5];
        for j in 1..turns.len() {
            let (c, s) = turns[j - 1];
            let half_c = (0.5 * (1.0 + c)).sqrt();
            turns[j] = (half_c, s / (2.0 * half_c));
        }
        let s = self.axis;
        let qa = self.base.rotation;
        let oa = self.base.translation;
        let tau = self.tau;
        // (0, S) q_a = (-S . v_a, w_a S + S x v_a).
        let sv = s.cross(qa.xyz()) + qa.w * s;
        let s_qa = DQuat::from_xyzw(sv.x, sv.y, sv.z, -s.dot(qa.xyz()));
        let slide = tau.dot(s) * s;
        let s_x_tau = s.cross(tau);
        let s_x_o = s.cross(oa);
        let o_perp = oa - oa.dot(s) * s;
        // A macro, not a closure: inlined for certain, so with the caller's constant `k` the
        // turns fold into one or two complex products each.
        macro_rules! at {
            ($k:expr) => {{
                let k: i32 = $k;
                let t = f64::from(k) / 16.0;
                let (cos_th, sin_th) = sixteenth_turn(&turns, k);
                let (cos_d, sin_d) = sixteenth_turn(&turns, k - 16);
                let rho = if inv_sin_h > 0.0 {
                    sin_th * inv_sin_h
                } else {
                    t
                };
                let (a, b) = (rho * cos_d, rho * sin_d);
                let two_sin = 2.0 * sin_th;
                Pose {
                    rotation: qa * cos_th + s_qa * sin_th,
                    translation: oa
                        + a * tau
                        + (t - a) * slide
                        + b * s_x_tau
                        + (two_sin * cos_th) * s_x_o
                        - (two_sin * sin_th) * o_perp,
                }
            }};
        }
        // Unrolled by hand for the same reason (LLVM does not unroll a body this size).
        let mut out = [self.base; N];
        macro_rules! unrolled {
            ($($i:literal)*) => {$(
                if $i < N {
                    out[$i] = at!(ks[$i]);
                }
            )*};
        }
        unrolled!(0 1 2 3 4 5);
        for i in 6..N {
            out[i] = at!(ks[i]);
        }
        out
    }

    /// The start pose `a`.
    pub fn base(&self) -> Pose {
        self.base
    }

    /// Unit direction `S` of the screw axis. For a pure translation (a turn of at most
    /// [`ROTATION_ROUNDOFF`] counts as none) it is the translation's direction; when
    /// `a == b` it is `+z` (any direction would do).
    pub fn axis(&self) -> DVec3 {
        self.axis
    }

    /// Whether the screw is a pure translation: the relative rotation is round-off
    /// (`|q.xyz| <= ROTATION_ROUNDOFF`).
    pub fn is_translation(&self) -> bool {
        self.inv_sin_half == 0.0
    }

    /// Rotation angle `r` in `[0, pi]`, radians (0 for a pure translation).
    pub fn angle(&self) -> f64 {
        if self.is_translation() {
            return 0.0;
        }
        2.0 * self.half_angle
    }

    /// Slide `d` along the axis: `M` translates by `d S` along its axis.
    pub fn slide(&self) -> f64 {
        self.tau.dot(self.axis)
    }

    /// The point of the screw axis nearest to the origin of `a`.
    ///
    /// `P = (tau_perp + cot(h) S x tau) / 2` (any point of the axis), then projected; for a
    /// pure translation, the origin of `a` itself. Far away (like `1 / r`) as `r -> 0`.
    pub fn point(&self) -> DVec3 {
        let o = self.base.translation;
        if self.is_translation() {
            return o;
        }
        let s = self.axis;
        let perp = self.tau - self.tau.dot(s) * s;
        let cot = self.rotation.w / self.rotation.xyz().length();
        let p = 0.5 * (perp + cot * s.cross(self.tau));
        p - (p - o).dot(s) * s
    }

    /// The translation `tau` of the world motion `M = b a^-1` (`x -> R x + tau`).
    pub fn translation(&self) -> DVec3 {
        self.tau
    }

    /// The relative rotation `R = q_b q_a^-1` as a unit quaternion with `w >= 0`.
    pub fn rotation(&self) -> DQuat {
        self.rotation
    }
}

/// `(cos, sin)` of `k h / 16` from `turns[j] = (cos, sin)` of `h / 2^j`, `j = 0..=4`:
/// `k = 16 j + r` with `-8 <= r < 8`, the turn by `j h` (`|j| <= 2`) times those of the
/// binary digits of `r` (`|j| > 2`, for `|k| > 40`, by repeated products). Straight-line code: with `k` a constant the branches fold away and
/// what remains is one to three complex products.
#[inline(always)]
fn sixteenth_turn(turns: &[(f64, f64); 5], k: i32) -> (f64, f64) {
    let mul = |(c1, s1): (f64, f64), (c2, s2): (f64, f64)| (c1 * c2 - s1 * s2, s1 * c2 + c1 * s2);
    let times = |turn: Option<(f64, f64)>, step: (f64, f64)| match turn {
        None => step,
        Some(sofar) => mul(sofar, step),
    };
    let whole = (k + 8).div_euclid(16);
    let r = k - 16 * whole;
    let (c, s) = turns[0];
    let (double_c, double_s) = (c * c - s * s, 2.0 * c * s);
    let mut turn = match whole {
        0 => None,
        1 => Some((c, s)),
        -1 => Some((c, -s)),
        2 => Some((double_c, double_s)),
        -2 => Some((double_c, -double_s)),
        _ => {
            let step = if whole < 0 { (c, -s) } else { (c, s) };
            let mut sofar = step;
            for _ in 1..whole.unsigned_abs() {
                sofar = mul(sofar, step);
            }
            Some(sofar)
        }
    };
    // Bit b of |r| is a turn by h / 2^(4 - b).
    for bit in 0..4 {
        if r.unsigned_abs() & (1 << bit) != 0 {
            let (c, s) = turns[4 - bit];
            turn = Some(times(turn, if r < 0 { (c, -s) } else { (c, s) }));
        }
    }
    turn.unwrap_or((1.0, 0.0))
}

/// The unit direction of `v`, for any finite `v` (scaled by a power of two first, so that
/// `|v|^2` cannot overflow); `None` for zero or non-finite `v`.
fn direction(v: DVec3) -> Option<DVec3> {
    let big = v.abs().max_element();
    if !(big > 0.0 && big.is_finite()) {
        return None;
    }
    let scale = 2f64.powi(-(big.log2().floor() as i32).clamp(-1020, 1020));
    (v * scale).try_normalize()
}

/// `s(a, 1/2, b)`, the pose halfway along the minimal screw, without trigonometry.
///
/// With `q_a`, `q_b` the rotations on the same side (`q_a . q_b >= 0`), the relative rotation
/// `q = q_b q_a^-1 = (w, v) = (cos h, sin h S)` and `o_a`, `o_b` the translations:
///
/// ```text
/// rotation     (q_a + q_b) / |q_a + q_b|             (|q_a + q_b|^2 = 2 (1 + w))
/// translation  (o_a + o_b) / 2 - v x (o_b - o_a) / (2 (1 + w))
/// ```
///
/// The first is the half-way quaternion of the rotation; the second is the midpoint of the
/// chord of the helix the origin travels, moved out to the helix: in the plane normal to `S`
/// the arc's midpoint is the chord's midpoint turned by `-90` degrees times
/// `tan(h / 2) / 2 = |v| / (2 (1 + w))` of the chord. No product of a quaternion and a vector,
/// exact at `h = 0` (the average), regular up to the half turn (`w = 0`). The outer step of
/// every Split&Tweak rule.
#[inline(always)]
pub fn midpoint(a: &Pose, b: &Pose) -> Pose {
    let qa = a.rotation;
    let mut qb = b.rotation;
    if qa.dot(qb) < 0.0 {
        qb = -qb;
    }
    let sum = qa + qb;
    let inv_norm = 1.0 / sum.length_squared().sqrt();
    // The vector part of q_b q_a^-1.
    let (va, vb) = (qa.xyz(), qb.xyz());
    let v = qa.w * vb - qb.w * va - vb.cross(va);
    let chord = b.translation - a.translation;
    let translation =
        0.5 * (a.translation + b.translation) - v.cross(chord) * (inv_norm * inv_norm);
    Pose {
        rotation: sum * inv_norm,
        translation,
    }
}

/// `s(a, t, b)`: the pose a fraction `t` along the minimal screw from `a` to `b`
/// (ScrewBender section 4; Rossignac-Kim). `t = 0` gives `a`, `t = 1` gives `b`; any real `t`.
#[inline]
pub fn s(a: &Pose, t: f64, b: &Pose) -> Pose {
    Screw::between(a, b).eval(t)
}

/// `out[i] = s(a[i], t[i], b[i])` for every `i`: the batch form of [`s`], four pairs at a
/// time side by side (structure of arrays, packed SIMD on baseline x86-64) with selects
/// instead of branches for the pure translation and the identity, the rest by [`s`].
///
/// The same formula and kernels as [`s`], operation for operation, so the results equal
/// `s`'s to the bit. A group of four whose `t h` is NaN or beyond the
/// fast range reduction (`|t| > 3e5` or so) is done by [`s`] instead.
///
/// # Errors
/// [`Error::LengthMismatch`] unless `t`, `b` and `out` have the length of `a`.
pub fn s_many(a: &[Pose], t: &[f64], b: &[Pose], out: &mut [Pose]) -> Result<()> {
    let n = a.len();
    for (what, got) in [("t", t.len()), ("b", b.len()), ("out", out.len())] {
        if got != n {
            return Err(Error::LengthMismatch {
                what,
                expected: n,
                got,
            });
        }
    }
    let groups = n / LANES * LANES;
    for (((a, t), b), out) in a[..groups]
        .chunks_exact(LANES)
        .zip(t[..groups].chunks_exact(LANES))
        .zip(b[..groups].chunks_exact(LANES))
        .zip(out[..groups].chunks_exact_mut(LANES))
    {
        s_lanes(a, t, b, out);
    }
    for i in groups..n {
        out[i] = s(&a[i], t[i], &b[i]);
    }
    Ok(())
}

/// [`s`] on four pairs at once (`LANES` of each slice): [`Screw::between`] then
/// [`Screw::eval`] operation for operation, every branch a select.
#[inline]
fn s_lanes(a: &[Pose], t: &[f64], b: &[Pose], out: &mut [Pose]) {
    let qa = Q4::from_fn(|i| a[i].rotation);
    let oa = V4::from_fn(|i| a[i].translation);
    let qb = Q4::from_fn(|i| b[i].rotation);
    let ob = V4::from_fn(|i| b[i].translation);
    let t = F4::from_fn(|i| t[i]);
    // Screw::between, with S = v / sin h (0 for no turn: then rho = t, A = t, B = 0 and the
    // terms along S vanish, so a pure translation needs no axis of its own).
    let q = qb.mul(qa.conjugate());
    let q = q.negate_where(q.w.lt(0.0));
    let (v, cos_h) = (q.v, q.w);
    let b2 = v.dot(v);
    let sin_h = b2.sqrt();
    let h = fastmath::turn_angle(cos_h, sin_h);
    let inv = F4::splat(1.0) / sin_h;
    let turning = sin_h.gt(ROTATION_ROUNDOFF);
    let inv = turning.select(inv, F4::splat(0.0));
    let axis = v.scale(inv);
    // q o_a = o_a (w^2 - |v|^2) + v (2 v . o_a) + (v x o_a) (2 w); v . o_a and v x o_a serve
    // M^t o_a below too.
    let v_dot_o = v.dot(oa);
    let v_x_o = v.cross(oa);
    let tau =
        ob - (oa.scale(cos_h * cos_h - b2) + v.scale(v_dot_o * 2.0) + v_x_o.scale(cos_h * 2.0));
    // Screw::motion and Screw::eval.
    let th = t * h;
    if !th.abs_below(fastmath::FAST_REDUCTION_BELOW).all() {
        for i in 0..LANES {
            out[i] = s(&a[i], t.0[i], &b[i]);
        }
        return;
    }
    let (sin_th, cos_th) = lanes::sin_cos(th);
    let rho = turning.select(sin_th * inv, t);
    let ca = rho * (cos_th * cos_h + sin_th * sin_h);
    let cb = rho * (sin_th * cos_h - cos_th * sin_h);
    let translation =
        tau.scale(ca) + axis.scale((t - ca) * tau.dot(axis)) + axis.cross(tau).scale(cb);
    // M^t = (rho v, cos(t h)): M^t q_a, and M^t o_a by the formula above with rho v for v.
    let m = Q4 {
        v: v.scale(rho),
        w: cos_th,
    };
    let rotation = m.mul(qa);
    let rho2 = rho * rho;
    let position = oa.scale(cos_th * cos_th - rho2 * b2)
        + v.scale(rho2 * v_dot_o * 2.0)
        + v_x_o.scale(rho * cos_th * 2.0)
        + translation;
    for (i, pose) in out.iter_mut().enumerate() {
        *pose = Pose {
            rotation: rotation.lane(i),
            translation: position.lane(i),
        };
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    /// The exact screw by its parameters: rotation by `angle` about the line through `p`
    /// along unit `axis`, plus `slide` along it; evaluated directly at `t`.
    fn exact(axis: DVec3, p: DVec3, angle: f64, slide: f64, t: f64, x: &Pose) -> Pose {
        let r = DQuat::from_axis_angle(axis, t * angle);
        Pose {
            rotation: r * x.rotation,
            translation: r * (x.translation - p) + p + t * slide * axis,
        }
    }

    /// A key pose turned about a tilted axis and moved off the origin, and the axis direction
    /// and point of a screw from it.
    fn tilted_key() -> (Pose, DVec3, DVec3) {
        let a = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(0.3, -0.2, 0.9).normalize(), 0.7),
            DVec3::new(1.0, 2.0, -0.5),
        );
        (a, DVec3::new(0.0, 0.6, 0.8), DVec3::new(0.5, -0.3, 0.1))
    }

    #[test]
    fn endpoints_and_parameters() {
        let (a, _, _) = tilted_key();
        let axis = DVec3::new(1.0, 1.0, 0.0).normalize();
        let p = DVec3::new(0.0, 0.0, 3.0);
        let b = exact(axis, p, 2.0, 0.25, 1.0, &a);
        let sc = Screw::between(&a, &b);
        assert!(sc.eval(0.0).max_abs_diff(&a) < 1e-15);
        assert!(sc.eval(1.0).max_abs_diff(&b) < 1e-14);
        assert!((sc.angle() - 2.0).abs() < 1e-14);
        assert!((sc.slide() - 0.25).abs() < 1e-14);
        assert!(sc.axis().distance(axis) < 1e-14);
        // The reported point is on the true axis.
        let q = sc.point();
        let off = (q - p) - (q - p).dot(axis) * axis;
        assert!(off.length() < 1e-13, "point {q} off the axis by {off}");
        for t in [-0.5, 0.25, 0.5, 1.7] {
            let e = exact(axis, p, 2.0, 0.25, t, &a);
            assert!(sc.eval(t).max_abs_diff(&e) < 1e-14, "t = {t}");
        }
    }

    #[test]
    fn tiny_zero_and_half_turn_angles() {
        let a = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::Y, 0.4),
            DVec3::new(0.2, 0.1, 0.3),
        );
        let axis = DVec3::new(0.0, 0.6, 0.8);
        let p = DVec3::new(0.5, -0.3, 0.1);
        for angle in [0.0, 1e-13, 1e-9, 1e-6, 1e-3, PI - 1e-9, PI - 1e-6] {
            let b = exact(axis, p, angle, 1.0, 1.0, &a);
            let sc = Screw::between(&a, &b);
            for t in [-0.5, 0.3, 0.5, 1.0, 1.5] {
                let e = exact(axis, p, angle, 1.0, t, &a);
                let err = sc.eval(t).max_abs_diff(&e);
                assert!(err < 1e-12, "angle {angle:e} t {t}: error {err:e}");
            }
        }
    }

    #[test]
    fn midpoint_equals_half_screw() {
        let (a, axis, p) = tilted_key();
        for angle in [0.0, 1e-12, 1e-6, 0.5, 2.0, PI - 1e-6] {
            let b = exact(axis, p, angle, 0.7, 1.0, &a);
            let err = midpoint(&a, &b).max_abs_diff(&exact(axis, p, angle, 0.7, 0.5, &a));
            assert!(err < 1e-13, "angle {angle:e}: error {err:e}");
        }
    }

    #[test]
    fn eval_sixteenths_matches_eval() {
        let (a, axis, p) = tilted_key();
        let ks = [
            -34, -18, -17, -16, -14, -2, -1, 0, 1, 2, 4, 7, 8, 12, 14, 16, 17, 18, 30, 33,
        ];
        let mut angles = vec![0.0, 1e-300, 1e-13, 1e-9, 1e-6, 1e-4, 1e-3];
        angles.extend((1..64).map(|i| i as f64 * PI / 64.0));
        angles.extend([PI - 1e-3, PI - 1e-6, PI - 1e-9, PI - 1e-13, PI]);
        for angle in angles {
            for slide in [0.0, 0.7, -2.0] {
                let b = exact(axis, p, angle, slide, 1.0, &a);
                let sc = Screw::between(&a, &b);
                let got = sc.eval_sixteenths(ks);
                for (k, g) in ks.iter().zip(&got) {
                    let want = sc.eval(f64::from(*k) / 16.0);
                    let err = g.max_abs_diff(&want);
                    assert!(
                        err < 1e-14,
                        "angle {angle:e} slide {slide} k {k}: error {err:e}"
                    );
                    let norm = (g.rotation.length() - 1.0).abs();
                    assert!(
                        norm < 4.0 * f64::EPSILON,
                        "angle {angle:e} k {k}: |q| - 1 = {norm:e}"
                    );
                }
            }
        }
        // A pure translation and the identity.
        let b =
            Pose::from_rotation_translation(a.rotation, a.translation + DVec3::new(0.0, 3.0, -4.0));
        for b in [b, a] {
            let sc = Screw::between(&a, &b);
            for (k, g) in ks.iter().zip(sc.eval_sixteenths(ks)) {
                let err = g.max_abs_diff(&sc.eval(f64::from(*k) / 16.0));
                assert!(err < 1e-14, "translation, k {k}: error {err:e}");
            }
        }
    }

    #[test]
    fn midpoint_equals_eval_half_on_random_pairs() {
        // Pairs of general poses, not only screws from a fixed base.
        let mut x = 0.5f64;
        let mut next = || {
            x = (x * 3.7 + 0.123).fract();
            x
        };
        for _ in 0..2000 {
            let mut pose = || {
                let axis = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5 + 1e-3).normalize();
                Pose::from_rotation_translation(
                    DQuat::from_axis_angle(axis, next() * 2.0 * PI),
                    DVec3::new(next(), next(), next()) * 4.0 - 2.0,
                )
            };
            let (a, b) = (pose(), pose());
            let err = midpoint(&a, &b).max_abs_diff(&s(&a, 0.5, &b));
            assert!(err < 1e-13, "{a:?} {b:?}: error {err:e}");
        }
    }

    #[test]
    fn s_many_equals_s() {
        let mut x = 0.25f64;
        let mut next = || {
            x = (x * 3.7 + 0.123).fract();
            x
        };
        let mut a = Vec::new();
        let mut b = Vec::new();
        let mut t = Vec::new();
        let axis = DVec3::new(0.0, 0.6, 0.8);
        for i in 0..403 {
            let pose = |next: &mut dyn FnMut() -> f64| {
                let axis = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5 + 1e-3).normalize();
                Pose::from_rotation_translation(
                    DQuat::from_axis_angle(axis, next() * 2.0 * PI),
                    DVec3::new(next(), next(), next()) * 4.0 - 2.0,
                )
            };
            let p = pose(&mut next);
            // Random pairs, and pairs at angle 0, 1e-13, near pi, pure translations, repeats.
            let q = match i % 8 {
                0 => exact(axis, DVec3::X, 0.0, 1.5, 1.0, &p),
                1 => exact(axis, DVec3::Y, 1e-13, 0.3, 1.0, &p),
                2 => exact(axis, DVec3::Z, PI - 1e-9, -0.7, 1.0, &p),
                3 => Pose::from_rotation_translation(p.rotation, p.translation + DVec3::X),
                4 => p,
                5 => exact(axis, DVec3::ONE, 1e-7, 0.0, 1.0, &p),
                _ => pose(&mut next),
            };
            a.push(p);
            b.push(q);
            t.push(match i % 5 {
                0 => 0.0,
                1 => 1.0,
                _ => next() * 3.0 - 1.0,
            });
        }
        // A group beyond the fast range reduction, and one with a NaN t.
        t[14] = 1e9;
        t[13] = f64::NAN;
        let mut out = vec![Pose::IDENTITY; a.len()];
        s_many(&a, &t, &b, &mut out).unwrap();
        // The same operations in the same order as s: equal to the bit (the NaN lane aside).
        let same = (0..a.len())
            .filter(|&i| out[i] == s(&a[i], t[i], &b[i]))
            .count();
        assert_eq!(same, a.len() - 1, "bitwise equal to s except the NaN lane");
        for i in 0..a.len() {
            let want = s(&a[i], t[i], &b[i]);
            if t[i].is_nan() {
                assert!(
                    out[i].translation.x.is_nan() || out[i].rotation.w.is_nan(),
                    "{i}"
                );
                continue;
            }
            let err = out[i].max_abs_diff(&want);
            assert!(
                err < 1e-14,
                "pair {i}: {:?} {} {:?}: error {err:e}",
                a[i],
                t[i],
                b[i]
            );
        }
        assert!(matches!(
            s_many(&a, &t[1..], &b, &mut out),
            Err(Error::LengthMismatch {
                what: "t",
                expected: 403,
                got: 402
            })
        ));
        assert!(matches!(
            s_many(&a, &t, &b, &mut out[..3]),
            Err(Error::LengthMismatch { what: "out", .. })
        ));
        assert_eq!(s_many(&[], &[], &[], &mut []), Ok(()));
    }

    /// A pose moved by a pure translation gives the translation's screw (axis along it, slide
    /// its length, angle 0) whatever the pose's rotation and position, although the relative
    /// rotation computed from two equal rotations is not exactly the identity (issue 15:
    /// slide 3 instead of 5 for a move of (0, 3, 4)); tiny true turns stay screws.
    #[test]
    fn translation_of_a_rotated_pose() {
        let mut x = 0.7f64;
        let mut next = move || {
            x = (x * 3.7 + 0.123).fract();
            x
        };
        let mv = DVec3::new(0.0, 3.0, 4.0);
        let mut roundoff = 0usize;
        for i in 0..20_000 {
            let axis = DVec3::new(next() - 0.5, next() - 0.5, next() - 0.5 + 1e-3).normalize();
            let position = (DVec3::new(next(), next(), next()) - 0.5) * 10f64.powi(i % 9 - 2);
            let a = Pose::from_rotation_translation(
                DQuat::from_axis_angle(axis, next() * 2.0 * PI),
                position,
            );
            let b = Pose {
                translation: a.translation + mv,
                ..a
            };
            let sc = Screw::between(&a, &b);
            roundoff += usize::from(sc.rotation().xyz().length() > 0.0);
            assert!(sc.is_translation(), "{a:?}");
            assert_eq!(sc.angle(), 0.0);
            let scale = 1.0 + position.length();
            assert!(
                (sc.slide() - 5.0).abs() < 1e-14 * scale,
                "{a:?}: {}",
                sc.slide()
            );
            assert!(sc.axis().distance(mv / 5.0) < 1e-14 * scale, "{a:?}");
            assert!(sc.eval(1.0).max_abs_diff(&b) < 1e-14 * scale);
            assert!(sc.eval(0.5).translation.distance(a.translation + 0.5 * mv) < 1e-14 * scale);
        }
        assert!(
            roundoff > 1000,
            "only {roundoff} pairs had a round-off turn"
        );
        // A true turn of 1e-13 rad is a screw, far above the threshold.
        let a = Pose::from_translation(DVec3::new(0.3, 0.2, 0.1));
        let b = Pose::from_rotation_translation(DQuat::from_rotation_x(1e-13), a.translation + mv);
        let sc = Screw::between(&a, &b);
        assert!(!sc.is_translation());
        assert!((sc.angle() - 1e-13).abs() < 1e-25);
    }

    #[test]
    fn pure_translation_axis() {
        let a = Pose::from_translation(DVec3::new(1.0, 1.0, 1.0));
        let b = Pose::from_translation(DVec3::new(1.0, 4.0, 5.0));
        let sc = Screw::between(&a, &b);
        assert_eq!(sc.angle(), 0.0);
        assert!(sc.axis().distance(DVec3::new(0.0, 0.6, 0.8)) < 1e-15);
        assert!((sc.slide() - 5.0).abs() < 1e-14);
        assert_eq!(sc.point(), a.translation);
    }
}
