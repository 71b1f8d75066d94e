//! Split&Tweak subdivision of polyscrews (ScrewBender, `000_*` section 4, formulation A),
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
//! (the minimal screw from `b` to `a` is the inverse of the one from `a` to `b`). Only the
//! outer `s(., 1/2, .)` needs a new screw per output pose.
//!
//! Open sequences get a phantom pose at each end at every level, by screw extrapolation
//! `s(P0, -1, P1)` and `s(P[n-1], -1, P[n-2])`; the end poses are kept exactly. Poses sampled
//! on one screw stay on it (the phantoms are on it too).

use glam::DVec3;

use crate::error::{Error, Result};
use crate::pose::Pose;
use crate::screw::Screw;

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
    /// [`Error::Invalid`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "four_point" => Ok(Self::FourPoint),
            "bspline" => Ok(Self::BSpline),
            "jarek" => Ok(Self::Jarek),
            _ => Err(Error::Invalid {
                what: "scheme",
                reason: format!("{name:?} is not one of \"four_point\", \"bspline\", \"jarek\""),
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
}

impl Interpolant for Pose {
    type Segment = Screw;
    #[inline]
    fn segment(a: &Self, b: &Self) -> Screw {
        Screw::between(a, b)
    }
    #[inline]
    fn eval(seg: &Screw, t: f64) -> Self {
        seg.eval(t)
    }
    #[inline]
    fn midpoint(a: &Self, b: &Self) -> Self {
        crate::screw::midpoint(a, b)
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
/// open.
pub fn subdivided_len(n: usize, levels: u32, closed: bool) -> usize {
    if closed {
        n << levels
    } else {
        ((n - 1) << levels) + 1
    }
}

/// Subdivides a closed cycle or an open sequence `levels` times.
///
/// Closed: `n 2^levels` elements, element `i 2^levels` from key `i`. Open:
/// `(n - 1) 2^levels + 1`, first and last kept exactly. Level 0 returns the input.
///
/// # Errors
/// See [`check_subdivision`].
pub fn subdivide<T: Interpolant>(
    items: &[T],
    scheme: Scheme,
    levels: u32,
    closed: bool,
) -> Result<Vec<T>> {
    check_subdivision(items.len(), levels)?;
    let mut current = items.to_vec();
    let mut next = Vec::with_capacity(subdivided_len(items.len(), levels, closed));
    let mut work = Vec::new();
    for _ in 0..levels {
        next.clear();
        if closed {
            refine_closed(&current, scheme, &mut next, &mut work);
        } else {
            refine_open(&current, scheme, &mut next, &mut work);
        }
        std::mem::swap(&mut current, &mut next);
    }
    Ok(current)
}

/// One level on a closed cycle: `out` gets `2 n` elements.
fn refine_closed<T: Interpolant>(
    p: &[T],
    scheme: Scheme,
    out: &mut Vec<T>,
    edges: &mut Vec<T::Segment>,
) {
    let n = p.len();
    edges.clear();
    edges.extend((0..n).map(|i| T::segment(&p[i], &p[(i + 1) % n])));
    // Edge i runs from p[i] to p[i + 1]; around old i: edge i - 1 (in), edge i (out).
    for i in 0..n {
        let e_in = &edges[(i + n - 1) % n];
        let e = &edges[i];
        let e_next = &edges[(i + 1) % n];
        out.push(old_rule(scheme, &p[i], e_in, e));
        out.push(new_rule(scheme, e_in, e, e_next));
    }
}

/// One level on an open sequence: `out` gets `2 n - 1` elements; ends kept exactly.
fn refine_open<T: Interpolant>(
    p: &[T],
    scheme: Scheme,
    out: &mut Vec<T>,
    edges: &mut Vec<T::Segment>,
) {
    let n = p.len();
    // Edges of the sequence extended by one phantom pose at each end:
    // edges[0] = phantom -> p[0], edges[i + 1] = p[i] -> p[i + 1], edges[n] = p[n-1] -> phantom.
    edges.clear();
    let first = T::segment(&p[0], &p[1]);
    let last = T::segment(&p[n - 2], &p[n - 1]);
    let phantom_start = T::eval(&first, -1.0);
    let phantom_end = T::eval(&last, 2.0);
    edges.push(T::segment(&phantom_start, &p[0]));
    edges.extend((0..n - 1).map(|i| T::segment(&p[i], &p[i + 1])));
    edges.push(T::segment(&p[n - 1], &phantom_end));
    out.push(p[0]);
    for i in 0..n - 1 {
        if i > 0 {
            out.push(old_rule(scheme, &p[i], &edges[i], &edges[i + 1]));
        }
        out.push(new_rule(scheme, &edges[i], &edges[i + 1], &edges[i + 2]));
    }
    out.push(p[n - 1]);
}

/// The tweaked old element `b`, from its incoming edge `a -> b` and outgoing edge `b -> c`.
#[inline]
fn old_rule<T: Interpolant>(scheme: Scheme, b: &T, e_in: &T::Segment, e_out: &T::Segment) -> T {
    match scheme {
        Scheme::FourPoint => *b,
        // s(s(b, 1/4, a), 1/2, s(b, 1/4, c)) with s(b, 1/4, a) = s(a, 3/4, b).
        Scheme::BSpline => T::midpoint(&T::eval(e_in, 0.75), &T::eval(e_out, 0.25)),
        // s(s(a, 7/8, b), 1/2, s(c, 7/8, b)) with s(c, 7/8, b) = s(b, 1/8, c).
        Scheme::Jarek => T::midpoint(&T::eval(e_in, 0.875), &T::eval(e_out, 0.125)),
    }
}

/// The new element between `b` and `c`, from edges `a -> b`, `b -> c`, `c -> d`.
#[inline]
fn new_rule<T: Interpolant>(
    scheme: Scheme,
    e_ab: &T::Segment,
    e_bc: &T::Segment,
    e_cd: &T::Segment,
) -> T {
    // s(s(a, w, b), 1/2, s(d, w, c)) with s(d, w, c) = s(c, 1 - w, d).
    let tweak = |w: f64| T::midpoint(&T::eval(e_ab, w), &T::eval(e_cd, 1.0 - w));
    match scheme {
        Scheme::BSpline => T::eval(e_bc, 0.5),
        Scheme::FourPoint => tweak(9.0 / 8.0),
        Scheme::Jarek => tweak(17.0 / 16.0),
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
