//! Split&Tweak subdivision of polyscrews (Powell-Rossignac, *ScrewBender: Smoothing Piecewise Helical Motions*, section 4, formulation A),
//! and of polygons by the same code: the rules only need `s(a, t, b)`.
//!
//! With `s` the screw interpolation (or the straight line for points):
//!
//! ```text
//! B-spline  new between (b, c):       s(b, 1/2, c)
//!           old b in (a, b, c):       s(s(b, 1/4, a), 1/2, s(b, 1/4, c))
//! 4-point   new between b, c of (a, b, c, d): s(s(a, 9/8, b), 1/2, s(d, 9/8, c))
//!           old b:                    kept
//! Jarek     new:                      s(s(a, 17/16, b), 1/2, s(d, 17/16, c))
//!           old b:                    s(s(a, 7/8, b), 1/2, s(c, 7/8, b))
//! ```
//!
//! Every inner `s` is on one edge of the current polyscrew, so each edge's screw is built
//! once per level and evaluated where the rules need it, using `s(b, t, a) = s(a, 1 - t, b)`
//! (the minimal screw from `b` to `a` is the inverse of the one from `a` to `b`). All the
//! fractions are sixteenths, so one [`Interpolant::eval_sixteenths`] per edge serves every
//! rule (for screws: no trigonometry, see [`Screw::eval_sixteenths`]), and the schemes are
//! tables read by one refinement pass. The outer `s(., 1/2, .)` is
//! [`Interpolant::midpoint`] (for poses: no screw at all, see [`crate::motion::screw::midpoint`]).
//!
//! Open sequences get a phantom pose at each end at every level, by screw extrapolation
//! `s(P0, -1, P1)` and `s(P[n-1], -1, P[n-2])`; the end poses are kept exactly. Poses sampled
//! on one screw stay on it (the phantoms are on it too).

use glam::DVec3;

use crate::error::{Error, Result};
use crate::memory::{try_vec, Footprint};
use crate::motion::pose::{Pose, MAX_COORDINATE};
use crate::motion::screw::Screw;

/// The largest number of subdivision levels accepted (closed output `n 2^12` poses).
pub const MAX_LEVELS: u32 = 12;

/// The fewest poses a scheme needs (a closed cycle of two poses is the paper's pendulum).
pub const MIN_POSES: usize = 2;

/// A Split&Tweak subdivision scheme (ScrewBender section 4).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Dyn-Gregory-Levin 4-point: interpolating, C1 limit.
    FourPoint,
    /// Uniform cubic B-spline: approximating, C2 limit.
    BSpline,
    /// Rossignac's Jarek scheme, the average of the two: approximating, C2 limit.
    Jarek,
}

impl Scheme {
    /// Parses `"four_point"`, `"bspline"` or `"jarek"`.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "four_point" => Ok(Self::FourPoint),
            "bspline" => Ok(Self::BSpline),
            "jarek" => Ok(Self::Jarek),
            _ => Err(Error::Choice {
                what: "scheme",
                got: name.to_owned(),
                expected: &["four_point", "bspline", "jarek"],
            }),
        }
    }

    /// Whether the scheme keeps the old poses (only 4-point does).
    pub fn is_interpolating(self) -> bool {
        self == Self::FourPoint
    }
}

/// A space with a geodesic-like interpolation `s(a, t, b)`: rigid poses (screws) and points
/// (straight lines). The subdivision rules are written once against this.
pub trait Interpolant: Copy {
    /// The precomputed path from one element to the next.
    type Segment: Copy;
    /// The path from `a` to `b`; `eval(seg, 0) = a`, `eval(seg, 1) = b`.
    fn segment(a: &Self, b: &Self) -> Self::Segment;
    /// The element a fraction `t` along the path (any real `t`).
    fn eval(seg: &Self::Segment, t: f64) -> Self;
    /// `s(a, t, b)`: one segment, evaluated once.
    #[inline]
    fn s(a: &Self, t: f64, b: &Self) -> Self {
        Self::eval(&Self::segment(a, b), t)
    }
    /// `s(a, 1/2, b)`; implementations may have a cheaper formula.
    #[inline]
    fn midpoint(a: &Self, b: &Self) -> Self {
        Self::s(a, 0.5, b)
    }
    /// `[eval(seg, k / 16) for k in ks]`; implementations may share work between the
    /// fractions (the subdivision rules evaluate every edge at a few fixed sixteenths).
    #[inline]
    fn eval_sixteenths<const N: usize>(seg: &Self::Segment, ks: [i32; N]) -> [Self; N] {
        ks.map(|k| Self::eval(seg, f64::from(k) / 16.0))
    }
    /// Checks that the element is finite and within the working range
    /// ([`MAX_COORDINATE`]) in which the formulas stay finite; `index` is its position.
    ///
    /// # Errors
    /// [`Error::BadPose`] for a pose, [`Error::NotFinite`] or [`Error::OutOfRange`] for a
    /// point.
    fn check_range(&self, index: usize) -> Result<()>;
}

/// Checks every element with [`Interpolant::check_range`].
///
/// # Errors
/// The first element outside the working range, by index.
pub fn check_range<T: Interpolant>(items: &[T]) -> Result<()> {
    items
        .iter()
        .enumerate()
        .try_for_each(|(i, item)| item.check_range(i))
}

impl Interpolant for Pose {
    type Segment = Screw;
    #[inline(always)]
    fn segment(a: &Self, b: &Self) -> Screw {
        Screw::between(a, b)
    }
    #[inline]
    fn eval(seg: &Screw, t: f64) -> Self {
        seg.eval(t)
    }
    #[inline(always)]
    fn midpoint(a: &Self, b: &Self) -> Self {
        crate::motion::screw::midpoint(a, b)
    }
    #[inline(always)]
    fn eval_sixteenths<const N: usize>(seg: &Screw, ks: [i32; N]) -> [Self; N] {
        seg.eval_sixteenths(ks)
    }
    fn check_range(&self, index: usize) -> Result<()> {
        Pose::check_range(self, index)
    }
}

impl Interpolant for DVec3 {
    type Segment = (DVec3, DVec3);
    #[inline]
    fn segment(a: &Self, b: &Self) -> (DVec3, DVec3) {
        (*a, *b - *a)
    }
    #[inline]
    fn eval(seg: &(DVec3, DVec3), t: f64) -> Self {
        seg.0 + t * seg.1
    }
    fn check_range(&self, index: usize) -> Result<()> {
        if !self.is_finite() {
            return Err(Error::NotFinite {
                what: "vector",
                index,
            });
        }
        let value = self.abs().max_element();
        if value > MAX_COORDINATE {
            return Err(Error::OutOfRange {
                what: "vector",
                index,
                value,
                limit: MAX_COORDINATE,
            });
        }
        Ok(())
    }
}

/// Checks the pose count and the levels for a subdivision.
///
/// # Errors
/// [`Error::TooFew`] below [`MIN_POSES`], [`Error::Levels`] above [`MAX_LEVELS`].
pub fn check_subdivision(n: usize, levels: u32) -> Result<()> {
    if n < MIN_POSES {
        return Err(Error::TooFew {
            got: n,
            need: MIN_POSES,
        });
    }
    if levels > MAX_LEVELS {
        return Err(Error::Levels {
            got: levels,
            max: MAX_LEVELS,
        });
    }
    Ok(())
}

/// The number of elements after `levels` levels: `n 2^levels` closed, `(n - 1) 2^levels + 1`
/// open (saturating at `usize::MAX`, which no allocation can reach).
pub fn subdivided_len(n: usize, levels: u32, closed: bool) -> usize {
    let scale = 1usize.checked_shl(levels).unwrap_or(usize::MAX);
    if closed {
        n.saturating_mul(scale)
    } else {
        n.saturating_sub(1).saturating_mul(scale).saturating_add(1)
    }
}

/// What [`subdivide`] holds at its peak for `n` elements: the last level and the one
/// before it (two buffers used in turn).
pub fn subdivision_footprint<T>(n: usize, levels: u32, closed: bool) -> Footprint {
    let last = subdivided_len(n, levels, closed);
    let before = if levels == 0 {
        0
    } else {
        subdivided_len(n, levels - 1, closed)
    };
    Footprint::of::<T>(last).and::<T>(before)
}

/// How to ask [`subdivide`] for less memory.
pub const SUBDIVISION_HINT: &str = "use fewer levels or fewer keys";

/// How a scheme's old element is made from the evaluations on its two edges.
#[derive(Debug, Clone, Copy)]
enum OldRule {
    /// Kept (interpolating schemes).
    Keep,
    /// `midpoint(ab[incoming], bc[outgoing])` from the evaluations of the edges `a -> b` and
    /// `b -> c` (indices into [`Rules::sixteenths`]).
    Tweak { incoming: usize, outgoing: usize },
}

/// How a scheme's new element between `b` and `c` is made, from edges `a -> b`, `b -> c`,
/// `c -> d`.
#[derive(Debug, Clone, Copy)]
enum NewRule {
    /// Entry `k` of the edge `b -> c` itself.
    OnEdge(usize),
    /// `midpoint(edge_ab[before], edge_cd[after])`.
    Tweak { before: usize, after: usize },
}

/// One Split&Tweak scheme as a table: every edge of the current polyscrew is evaluated at
/// `t = k / 16` for the `k` in `sixteenths` (`s(b, t, a) = s(a, 1 - t, b)` turns every inner
/// `s` of the rules into one on an edge in its own direction), and the rules pick entries.
#[derive(Debug, Clone, Copy)]
struct Rules<const N: usize> {
    sixteenths: [i32; N],
    old: OldRule,
    new: NewRule,
}

/// Jarek: old `s(s(a, 7/8, b), 1/2, s(b, 1/8, c))`, new `s(s(a, 17/16, b), 1/2, s(c, -1/16, d))`.
const JAREK: Rules<4> = Rules {
    sixteenths: [2, 14, 17, -1],
    old: OldRule::Tweak {
        incoming: 1,
        outgoing: 0,
    },
    new: NewRule::Tweak {
        before: 2,
        after: 3,
    },
};

/// 4-point: old kept, new `s(s(a, 9/8, b), 1/2, s(c, -1/8, d))`.
const FOUR_POINT: Rules<2> = Rules {
    sixteenths: [18, -2],
    old: OldRule::Keep,
    new: NewRule::Tweak {
        before: 0,
        after: 1,
    },
};

/// B-spline: old `s(s(a, 3/4, b), 1/2, s(b, 1/4, c))`, new `s(b, 1/2, c)`.
const BSPLINE: Rules<3> = Rules {
    sixteenths: [4, 12, 8],
    old: OldRule::Tweak {
        incoming: 1,
        outgoing: 0,
    },
    new: NewRule::OnEdge(2),
};

/// Subdivides a closed cycle or an open sequence `levels` times.
///
/// Closed: `n 2^levels` elements, element `i 2^levels` from key `i`. Open:
/// `(n - 1) 2^levels + 1`, first and last kept exactly. Level 0 returns the input.
///
/// # Errors
/// See [`check_subdivision`]; the first element outside the working range
/// ([`Interpolant::check_range`]); [`Error::Memory`] when the result (see
/// [`subdivision_footprint`]) exceeds the memory budget ([`crate::memory`]) or cannot be
/// allocated.
pub fn subdivide<T: Interpolant>(
    items: &[T],
    scheme: Scheme,
    levels: u32,
    closed: bool,
) -> Result<Vec<T>> {
    check_subdivision(items.len(), levels)?;
    check_range(items)?;
    subdivision_footprint::<T>(items.len(), levels, closed)
        .check("subdivided poses", SUBDIVISION_HINT)?;
    subdivide_checked(items, scheme, levels, closed)
}

/// [`subdivide`] without the range and budget checks (the caller made them).
pub(crate) fn subdivide_checked<T: Interpolant>(
    items: &[T],
    scheme: Scheme,
    levels: u32,
    closed: bool,
) -> Result<Vec<T>> {
    check_subdivision(items.len(), levels)?;
    if levels == 0 {
        let mut out = try_vec(items.len(), "subdivided poses")?;
        out.extend_from_slice(items);
        return Ok(out);
    }
    // Two buffers in turn, each allocated once at the size of the last level written to it:
    // the result (level `levels`) and the one before (level `levels - 1`, or the input).
    let n = items.len();
    let last = subdivided_len(n, levels, closed);
    let before_last = subdivided_len(n, levels - 1, closed);
    let (cap_current, cap_next) = if levels % 2 == 0 {
        (last, before_last)
    } else {
        (before_last, last)
    };
    let mut current = try_vec(cap_current, "subdivided poses")?;
    current.extend_from_slice(items);
    let mut next = try_vec(cap_next, "subdivided poses")?;
    for _ in 0..levels {
        next.clear();
        match scheme {
            Scheme::Jarek => refine(&current, &JAREK, closed, &mut next),
            Scheme::FourPoint => refine(&current, &FOUR_POINT, closed, &mut next),
            Scheme::BSpline => refine(&current, &BSPLINE, closed, &mut next),
        }
        std::mem::swap(&mut current, &mut next);
    }
    Ok(current)
}

/// One level: `out` gets `2 n` elements (closed) or `2 n - 1` (open, ends kept exactly).
///
/// The edges are evaluated in one pass with a window of three (`a -> b`, `b -> c`,
/// `c -> d`), each edge's screw built once. Open sequences are extended by a phantom element
/// at each end on the first and last screw (`s(p0, -1, p1)`, `s(p[n-2], 2, p[n-1])`), so
/// the phantom edges are those screws shifted by `-1` and `+1`: evaluated at `k - 16` and
/// `k + 16` sixteenths, with no screw of their own.
#[inline(always)]
fn refine<T: Interpolant, const N: usize>(
    p: &[T],
    rules: &Rules<N>,
    closed: bool,
    out: &mut Vec<T>,
) {
    let n = p.len();
    let ks = rules.sixteenths;
    let shifted = |by: i32| {
        let mut ks = ks;
        for k in &mut ks {
            *k += by;
        }
        ks
    };
    let on = |a: &T, b: &T| T::eval_sixteenths(&T::segment(a, b), ks);
    if !closed {
        out.push(p[0]);
    }
    let mut emit = |b: &T, ab: &[T; N], bc: &[T; N], cd: &[T; N], keep_old: bool| {
        if keep_old {
            out.push(match rules.old {
                OldRule::Keep => *b,
                OldRule::Tweak { incoming, outgoing } => T::midpoint(&ab[incoming], &bc[outgoing]),
            });
        }
        out.push(match rules.new {
            NewRule::OnEdge(k) => bc[k],
            NewRule::Tweak { before, after } => T::midpoint(&ab[before], &cd[after]),
        });
    };
    // A window of three edges in a ring (no copies as it moves): `ring[ia]` is `a -> b`,
    // `ring[ib]` is `b -> c`, `ring[ic]` gets `c -> d`.
    let (mut ia, mut ib, mut ic) = (0, 1, 2);
    if closed {
        // Edge i runs from p[i] to p[i + 1 mod n]; old i sits between edges i - 1 and i.
        let last = on(&p[n - 1], &p[0]);
        let first = on(&p[0], &p[1 % n]);
        let mut ring = [last, first, first];
        for i in 0..n {
            ring[ic] = if i + 2 < n {
                on(&p[i + 1], &p[i + 2])
            } else if i + 2 == n {
                last
            } else {
                first
            };
            emit(&p[i], &ring[ia], &ring[ib], &ring[ic], true);
            (ia, ib, ic) = (ib, ic, ia);
        }
    } else {
        // Extended edges: x[0] = phantom -> p[0], x[i + 1] = p[i] -> p[i + 1],
        // x[n] = p[n - 1] -> phantom; old i sits between x[i] and x[i + 1]. (The first
        // element, p[0], is already in `out`.)
        let first = T::segment(&p[0], &p[1]);
        let x1 = T::eval_sixteenths(&first, ks);
        let mut ring = [T::eval_sixteenths(&first, shifted(-16)), x1, x1];
        for i in 0..n - 1 {
            ring[ic] = if i + 2 < n {
                on(&p[i + 1], &p[i + 2])
            } else {
                T::eval_sixteenths(&T::segment(&p[n - 2], &p[n - 1]), shifted(16))
            };
            emit(&p[i], &ring[ia], &ring[ib], &ring[ic], i > 0);
            (ia, ib, ic) = (ib, ic, ia);
        }
        out.push(p[n - 1]);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The linear schemes' masks from ScrewBender section 2, applied directly.
    fn linear_reference(p: &[DVec3], scheme: Scheme) -> Vec<DVec3> {
        let n = p.len();
        let at = |i: isize| p[i.rem_euclid(n as isize) as usize];
        let mut out = Vec::new();
        for i in 0..n as isize {
            let (a, b, c, d) = (at(i - 1), at(i), at(i + 1), at(i + 2));
            let (old, new) = match scheme {
                Scheme::BSpline => ((2.0 * a + 12.0 * b + 2.0 * c) / 16.0, (b + c) / 2.0),
                Scheme::FourPoint => (b, (-a + 9.0 * b + 9.0 * c - d) / 16.0),
                Scheme::Jarek => (
                    (2.0 * a + 28.0 * b + 2.0 * c) / 32.0,
                    (-a + 17.0 * b + 17.0 * c - d) / 32.0,
                ),
            };
            out.push(old);
            out.push(new);
        }
        out
    }

    #[test]
    fn points_match_the_linear_masks() {
        let p: Vec<DVec3> = (0..7)
            .map(|i| {
                let x = i as f64;
                DVec3::new(x.sin() * 3.0, (x * 1.7).cos(), x * x * 0.1)
            })
            .collect();
        for scheme in [Scheme::FourPoint, Scheme::BSpline, Scheme::Jarek] {
            let got = subdivide(&p, scheme, 1, true).unwrap();
            let want = linear_reference(&p, scheme);
            for (g, w) in got.iter().zip(&want) {
                assert!(g.distance(*w) < 1e-14, "{scheme:?}: {g} vs {w}");
            }
        }
    }

    /// One level of the rules in the module docs written directly with `s`, on a closed
    /// cycle, or on an open sequence extended by its phantoms.
    fn rules_with_s(p: &[Pose], scheme: Scheme, closed: bool) -> Vec<Pose> {
        use crate::motion::screw::s;
        let mut ext = p.to_vec();
        if !closed {
            let n = p.len();
            ext.insert(0, s(&p[0], -1.0, &p[1]));
            ext.push(s(&p[n - 1], -1.0, &p[n - 2]));
        }
        let m = ext.len() as isize;
        let at = |i: isize| ext[i.rem_euclid(m) as usize];
        let (range, offset) = if closed { (0..m, 0) } else { (1..m - 1, 1) };
        let mut out = Vec::new();
        for i in range {
            let (a, b, c, d) = (at(i - 1), at(i), at(i + 1), at(i + 2));
            let old = match scheme {
                Scheme::FourPoint => b,
                Scheme::BSpline => s(&s(&b, 0.25, &a), 0.5, &s(&b, 0.25, &c)),
                Scheme::Jarek => s(&s(&a, 7.0 / 8.0, &b), 0.5, &s(&c, 7.0 / 8.0, &b)),
            };
            let new = match scheme {
                Scheme::BSpline => s(&b, 0.5, &c),
                Scheme::FourPoint => s(&s(&a, 9.0 / 8.0, &b), 0.5, &s(&d, 9.0 / 8.0, &c)),
                Scheme::Jarek => s(&s(&a, 17.0 / 16.0, &b), 0.5, &s(&d, 17.0 / 16.0, &c)),
            };
            if closed {
                out.extend([old, new]);
            } else if i == offset {
                out.extend([p[0], new]);
            } else if i == m - 2 {
                out.push(p[p.len() - 1]);
            } else {
                out.extend([old, new]);
            }
        }
        out
    }

    #[test]
    fn poses_match_the_rules_written_with_s() {
        use glam::DQuat;
        // A tumbling walk with steps up to near a half turn, a pure translation and a repeat.
        let mut p: Vec<Pose> = (0..9)
            .map(|i| {
                let x = i as f64;
                let axis = DVec3::new(x.sin(), (1.3 * x).cos(), 0.5).normalize();
                Pose::from_rotation_translation(
                    DQuat::from_axis_angle(axis, 0.4 * x * x),
                    DVec3::new(x.cos(), 0.1 * x, -x.sin()),
                )
            })
            .collect();
        p.push(Pose::from_rotation_translation(
            p[8].rotation,
            DVec3::new(2.0, 0.0, 1.0),
        ));
        p.push(p[9]);
        for scheme in [Scheme::FourPoint, Scheme::BSpline, Scheme::Jarek] {
            for closed in [true, false] {
                for n in [2, 3, p.len()] {
                    let got = subdivide(&p[..n], scheme, 1, closed).unwrap();
                    let want = rules_with_s(&p[..n], scheme, closed);
                    assert_eq!(got.len(), want.len(), "{scheme:?} closed {closed} n {n}");
                    for (i, (g, w)) in got.iter().zip(&want).enumerate() {
                        let err = g.max_abs_diff(w);
                        assert!(
                            err < 1e-13,
                            "{scheme:?} closed {closed} n {n} pose {i}: {err:e}"
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn counts_and_errors() {
        let p = vec![DVec3::ZERO, DVec3::X, DVec3::Y];
        assert_eq!(subdivide(&p, Scheme::Jarek, 3, true).unwrap().len(), 24);
        assert_eq!(subdivide(&p, Scheme::Jarek, 3, false).unwrap().len(), 17);
        assert_eq!(subdivide(&p, Scheme::Jarek, 0, false).unwrap(), p);
        assert!(matches!(
            subdivide(&p[..1], Scheme::Jarek, 1, false),
            Err(Error::TooFew { .. })
        ));
        assert!(matches!(
            subdivide(&p, Scheme::Jarek, 13, false),
            Err(Error::Levels { .. })
        ));
    }
}
