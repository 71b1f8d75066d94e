//! Tests of the F-curve evaluation against independent references: the formulas in `f64`
//! (lines, holds, Penner's easings at their ends), a Bezier segment solved by bisection in
//! `f64`, the Cycles modifier's periodicity; and bad input. Agreement with Blender itself is
//! `tests/blender/test_curves.py`.

use proptest::prelude::*;

use super::bezier::{correct_bezpart, solve_cubic, BezierSegment};
use super::easing::ease;
use super::*;
use crate::error::{At, Error, Expected};

/// A curve through `(frame, value)` pairs, every key with `interpolation`.
fn curve(points: &[(f32, f32)], interpolation: Interpolation, ext: Extrapolation) -> FCurve {
    let keys = points
        .iter()
        .map(|&(x, y)| Key::new(x, y).with_interpolation(interpolation))
        .collect();
    FCurve::new(keys, ext, None).unwrap()
}

fn at(c: &FCurve, t: f64) -> f64 {
    c.evaluate(t).unwrap()
}

/// `x(u), y(u)` of the cubic Bezier `p0, p1, p2, p3` in `f64`.
fn bezier_point(p: [[f64; 2]; 4], u: f64) -> [f64; 2] {
    let v = 1.0 - u;
    let w = [v * v * v, 3.0 * v * v * u, 3.0 * v * u * u, u * u * u];
    [0, 1].map(|i| (0..4).map(|j| w[j] * p[j][i]).sum())
}

/// The reference value of a Bezier segment at `frame`: handles clamped to the segment's
/// length (scaled about their key, as the module documents), `x(u) = frame` solved by
/// bisection in `f64` (x is monotone once clamped), `y(u)`.
fn bezier_reference(k0: [f64; 2], h0: [f64; 2], h1: [f64; 2], k1: [f64; 2], frame: f64) -> f64 {
    let len = k1[0] - k0[0];
    let clamp = |key: [f64; 2], h: [f64; 2]| {
        let d = [key[0] - h[0], key[1] - h[1]];
        if d[0].abs() > len {
            let f = len / d[0].abs();
            [key[0] - f * d[0], key[1] - f * d[1]]
        } else {
            h
        }
    };
    let p = [k0, clamp(k0, h0), clamp(k1, h1), k1];
    let (mut lo, mut hi) = (0.0, 1.0);
    for _ in 0..200 {
        let mid = 0.5 * (lo + hi);
        if bezier_point(p, mid)[0] < frame {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    bezier_point(p, 0.5 * (lo + hi))[1]
}

#[test]
fn key_values_are_hit_and_curves_are_continuous_there() {
    let pts = [(1.0, 2.0), (7.5, -3.0), (12.0, 4.0), (20.25, 4.0)];
    for ipo in Interpolation::ALL {
        let c = curve(&pts, ipo, Extrapolation::Linear);
        for &(x, y) in &pts {
            assert_eq!(at(&c, x as f64), y as f64, "{ipo:?} at key {x}");
            // Just outside Blender's 1e-4 search threshold: next to the key's value, except
            // where a CONSTANT segment jumps or ELASTIC's 2^-10 tail starts.
            for d in [-2e-4, 2e-4] {
                let v = at(&c, x as f64 + d);
                let jump = ipo == Interpolation::Constant && d < 0.0;
                // Slopes here are below 20 per frame (EXPO: 7 ln(2) 10 / 4.5), except CIRC,
                // whose slope is infinite at a key (its error goes as the square root:
                // 7 sqrt(2 d / 4.5), with a margin); ELASTIC ends 2^-10 of the change (7) away from its key.
                let tol = match ipo {
                    Interpolation::Circ => 1.5 * 7.0 * (2.0 * 2e-4 / 4.5f64).sqrt(),
                    Interpolation::Elastic => 20.0 * 2e-4 + 7.0 / 1024.0,
                    _ => 20.0 * 2e-4,
                };
                if !jump && x > 1.0 && x < 20.25 {
                    assert!(
                        (v - y as f64).abs() < tol,
                        "{ipo:?} near key {x}{d:+}: {v} vs {y}"
                    );
                }
            }
        }
    }
}

#[test]
fn linear_segments_are_the_straight_line() {
    let pts = [(0.0, 1.0), (3.0, 4.0), (10.0, -10.0), (10.5, 0.0)];
    let c = curve(&pts, Interpolation::Linear, Extrapolation::Constant);
    for i in 0..=1050 {
        // The line at the time Blender evaluates: the frame rounded to float32.
        let t = (i as f64 * 0.01) as f32 as f64;
        let seg = pts.windows(2).find(|w| t <= w[1].0 as f64).unwrap();
        let ((x0, y0), (x1, y1)) = (seg[0], seg[1]);
        let line = y0 as f64 + (y1 - y0) as f64 * (t - x0 as f64) / (x1 - x0) as f64;
        let v = at(&c, t);
        // A few float32 roundings of `change * time / duration + begin`.
        let tol = 4.0 * f32::EPSILON as f64 * (y0.abs() + (y1 - y0).abs()) as f64;
        assert!((v - line).abs() <= tol, "t {t}: {v} vs {line}");
    }
}

#[test]
fn constant_keys_hold_until_the_next_key() {
    let pts = [(1.0, 4.0), (10.0, 7.75), (20.0, -1.0)];
    let c = curve(&pts, Interpolation::Constant, Extrapolation::Linear);
    for i in 0..=2000 {
        let t = 1.0 + i as f64 * 0.0095;
        let expected = if t < 10.0 - 1e-4 {
            4.0
        } else if t < 20.0 - 1e-4 {
            7.75
        } else {
            -1.0
        };
        assert_eq!(at(&c, t), expected, "t {t}");
    }
    // CONSTANT end keys do not extrapolate linearly.
    assert_eq!(at(&c, -50.0), 4.0);
    assert_eq!(at(&c, 99.0), -1.0);
}

#[test]
fn easings_start_at_begin_and_end_at_begin_plus_change() {
    let mut rng = 1u64;
    let mut next = || {
        rng ^= rng << 13;
        rng ^= rng >> 7;
        rng ^= rng << 17;
        (rng >> 11) as f32 / (1u64 << 53) as f32
    };
    for ipo in Interpolation::ALL.into_iter().filter(|i| i.is_easing()) {
        for easing in Easing::ALL {
            for _ in 0..50 {
                let (b, c, d) = (
                    next() * 20.0 - 10.0,
                    next() * 20.0 - 10.0,
                    0.5 + next() * 30.0,
                );
                let (back, amp, per) = (next() * 4.0, next() * 5.0, next() * 8.0);
                let v0 = ease(ipo, easing, 0.0, b, c, d, back, amp, per);
                let v1 = ease(ipo, easing, d, b, c, d, back, amp, per);
                let tol = 1e-5 * (b.abs() + c.abs()).max(1.0);
                assert!(
                    (v0 - b).abs() <= tol,
                    "{ipo:?} {easing:?} at 0: {v0} vs {b}"
                );
                assert!(
                    (v1 - (b + c)).abs() <= tol,
                    "{ipo:?} {easing:?} at end: {v1} vs {}",
                    b + c
                );
            }
        }
    }
}

#[test]
fn easings_follow_penners_formulas() {
    // Penner's equations in f64 (unit segment: begin 0, change 1, duration 1).
    use std::f64::consts::PI;
    type Case = (Interpolation, Easing, fn(f64) -> f64);
    let cases: [Case; 9] = [
        (Interpolation::Quad, Easing::In, |t| t * t),
        (Interpolation::Quad, Easing::Out, |t| -t * (t - 2.0)),
        (Interpolation::Cubic, Easing::Auto, |t| t * t * t),
        (Interpolation::Quart, Easing::Out, |t| {
            1.0 - (t - 1.0).powi(4)
        }),
        (Interpolation::Quint, Easing::InOut, |t| {
            if t < 0.5 {
                16.0 * t.powi(5)
            } else {
                1.0 + 16.0 * (t - 1.0).powi(5)
            }
        }),
        (Interpolation::Sine, Easing::InOut, |t| {
            0.5 * (1.0 - (PI * t).cos())
        }),
        (Interpolation::Circ, Easing::Auto, |t| {
            1.0 - (1.0 - t * t).sqrt()
        }),
        // Blender's EXPO is rescaled to reach 0 and 1: (2^(10 (t - 1)) - 2^-10) / (1 - 2^-10).
        (Interpolation::Expo, Easing::In, |t| {
            (2f64.powf(10.0 * (t - 1.0)) - 2f64.powi(-10)) / (1.0 - 2f64.powi(-10))
        }),
        (Interpolation::Back, Easing::Auto, |t| {
            let s = 1.70158;
            let u = t - 1.0;
            u * u * ((s + 1.0) * u + s) + 1.0
        }),
    ];
    for (ipo, easing, f) in cases {
        for i in 1..100 {
            let t = i as f64 / 100.0;
            let v = ease(ipo, easing, t as f32, 0.0, 1.0, 1.0, 1.70158, 0.8, 4.1) as f64;
            assert!(
                (v - f(t)).abs() < 2e-6,
                "{ipo:?} {easing:?} at {t}: {v} vs {}",
                f(t)
            );
        }
    }
}

#[test]
fn auto_easing_is_out_for_back_bounce_elastic_and_in_otherwise() {
    for ipo in Interpolation::ALL.into_iter().filter(|i| i.is_easing()) {
        let default = if matches!(
            ipo,
            Interpolation::Back | Interpolation::Bounce | Interpolation::Elastic
        ) {
            Easing::Out
        } else {
            Easing::In
        };
        assert_eq!(Easing::Auto.resolve(ipo), default, "{ipo:?}");
        for i in 1..40 {
            let t = i as f32 * 0.25;
            assert_eq!(
                ease(ipo, Easing::Auto, t, 1.0, 3.0, 10.0, 2.0, 1.0, 3.0),
                ease(ipo, default, t, 1.0, 3.0, 10.0, 2.0, 1.0, 3.0),
                "{ipo:?} at {t}"
            );
        }
    }
}

#[test]
fn bezier_segments_match_the_parametric_curve() {
    // Handles inside the span (x monotone) and handles pulled far past the other key (x
    // would loop: Blender scales them back to the span's length first).
    let cases = [
        ([0.0, 0.0], [3.0, 5.0], [7.0, -2.0], [10.0, 1.0]),
        ([0.0, 0.0], [1.0, 0.0], [9.0, 1.0], [10.0, 1.0]),
        ([0.0, 0.0], [25.0, 8.0], [-15.0, -6.0], [10.0, 1.0]),
        ([2.0, 1.0], [40.0, 1.5], [2.5, 3.0], [4.0, 3.0]),
        ([0.0, 3.0], [0.0, 9.0], [10.0, -9.0], [10.0, -3.0]),
    ];
    for (k0, h0, h1, k1) in cases {
        let seg = BezierSegment::new(k0, h0, h1, k1);
        let f64s = |p: [f32; 2]| [p[0] as f64, p[1] as f64];
        for i in 1..400 {
            let t = k0[0] as f64 + (k1[0] - k0[0]) as f64 * i as f64 / 400.0;
            let v = seg.eval(t as f32) as f64;
            let r = bezier_reference(f64s(k0), f64s(h0), f64s(h1), f64s(k1), t);
            assert!(
                (v - r).abs() < 2e-4,
                "{k0:?} {h0:?} {h1:?} {k1:?} at {t}: {v} vs {r}"
            );
        }
    }
}

#[test]
fn handle_correction_scales_only_handles_longer_than_the_span() {
    let (v1, v4) = ([0.0, 0.0], [10.0, 2.0]);
    let (mut v2, mut v3) = ([4.0, 1.0], [6.0, 1.0]);
    correct_bezpart(v1, &mut v2, &mut v3, v4);
    assert_eq!((v2, v3), ([4.0, 1.0], [6.0, 1.0]));
    let (mut v2, mut v3) = ([20.0, 4.0], [-30.0, 8.0]);
    correct_bezpart(v1, &mut v2, &mut v3, v4);
    // Scaled to length 10 about their keys, direction kept.
    assert_eq!(v2, [10.0, 2.0]);
    assert_eq!(v3, [0.0, 3.5]);
}

#[test]
fn cubic_roots_are_roots() {
    // (u - 0.25)(u - 2)(u + 3) = u^3 + 0.75 u^2 - 6.25 u + 1.5: only 0.25 lies in [0, 1].
    let r = solve_cubic(1.5, -6.25, 0.75, 1.0).unwrap();
    assert!((r - 0.25).abs() < 1e-6, "{r}");
    // Quadratic, linear and constant cases.
    assert!((solve_cubic(-0.25, 0.0, 1.0, 0.0).unwrap() - 0.5).abs() < 1e-7);
    assert!((solve_cubic(-0.3, 1.0, 0.0, 0.0).unwrap() - 0.3).abs() < 1e-7);
    assert_eq!(solve_cubic(0.0, 0.0, 0.0, 0.0), Some(0.0));
    assert_eq!(solve_cubic(1.0, 0.0, 0.0, 0.0), None);
    // No root in [0, 1]: u^3 + 8 = 0.
    assert_eq!(solve_cubic(8.0, 0.0, 0.0, 1.0), None);
}

#[test]
fn extrapolation_constant_linear_and_along_handles() {
    let pts = [(0.0, 1.0), (4.0, 3.0), (10.0, -2.0)];
    let lin = curve(&pts, Interpolation::Linear, Extrapolation::Linear);
    assert_eq!(at(&lin, -4.0), -1.0); // slope 0.5 before
    assert!((at(&lin, 16.0) - (-7.0)).abs() < 1e-6); // slope -5/6 after
    let con = curve(&pts, Interpolation::Linear, Extrapolation::Constant);
    assert_eq!((at(&con, -4.0), at(&con, 16.0)), (1.0, -2.0));
    // Bezier end keys extrapolate along their outer handles.
    let keys = vec![
        Key::new(0.0, 1.0).with_handles([-2.0, 0.0], [2.0, 2.0]),
        Key::new(10.0, 5.0).with_handles([8.0, 5.0], [13.0, 11.0]),
    ];
    let bez = FCurve::new(keys, Extrapolation::Linear, None).unwrap();
    assert_eq!(at(&bez, -4.0), -1.0); // slope 1/2 along the left handle
    assert_eq!(at(&bez, 20.0), 25.0); // slope 2 along the right handle
                                      // A single key: its value for LINEAR, along its handles for BEZIER.
    let one = FCurve::new(
        vec![Key::new(3.0, 2.0).with_handles([2.0, 1.0], [4.0, 4.0])],
        Extrapolation::Linear,
        None,
    )
    .unwrap();
    assert_eq!((at(&one, 1.0), at(&one, 5.0)), (0.0, 6.0));
    let one_lin = FCurve::new(
        vec![Key::new(3.0, 2.0).with_interpolation(Interpolation::Linear)],
        Extrapolation::Linear,
        None,
    )
    .unwrap();
    assert_eq!((at(&one_lin, 1.0), at(&one_lin, 5.0)), (2.0, 2.0));
}

/// A three-key Bezier curve with a Cycles modifier.
fn cyclic(before: CycleMode, after: CycleMode, counts: (i32, i32)) -> FCurve {
    let keys = vec![
        Key::new(1.0, 0.0).with_handles([-1.0, -1.0], [3.0, 1.0]),
        Key::new(7.0, 4.0).with_handles([5.0, 5.0], [9.0, 3.0]),
        Key::new(11.0, 2.0).with_handles([10.0, 2.5], [12.0, 1.5]),
    ];
    let mut c = Cycles::new(before, after);
    (c.count_before, c.count_after) = counts;
    FCurve::new(keys, Extrapolation::Linear, Some(c)).unwrap()
}

#[test]
fn cycles_repeat_offset_and_mirror() {
    let (dx, dy) = (10.0, 2.0);
    let plain = cyclic(CycleMode::None, CycleMode::None, (0, 0));
    let rep = cyclic(CycleMode::Repeat, CycleMode::Repeat, (0, 0));
    let off = cyclic(CycleMode::RepeatOffset, CycleMode::RepeatOffset, (0, 0));
    let mir = cyclic(CycleMode::Mirror, CycleMode::Mirror, (0, 0));
    // Times on a 1/8 grid: exact in f32, so t + n dx is the same phase. The keys' own
    // frames map to a cycle's ends, checked below.
    for i in 1..80 {
        let t = 1.0 + i as f64 / 8.0;
        let v = at(&plain, t);
        assert_eq!(at(&rep, t), v, "inside the keys the modifier does nothing");
        for n in [-3.0, -1.0, 1.0, 2.0, 5.0] {
            let tn = t + n * dx;
            assert!((at(&rep, tn) - v).abs() < 1e-5, "REPEAT at {tn}");
            let shifted = v + n * dy;
            assert!(
                (at(&off, tn) - shifted).abs() < 1e-5,
                "REPEAT_OFFSET at {tn}"
            );
        }
        // MIRROR: the first cycle after the keys is the keys backwards.
        assert!(
            (at(&mir, 21.0 - (t - 1.0)) - v).abs() < 1e-5,
            "MIRROR at {t}"
        );
        assert!(
            (at(&mir, 1.0 - (t - 1.0)) - v).abs() < 1e-5,
            "MIRROR before at {t}"
        );
    }
}

#[test]
fn cycles_counts_end_in_the_curves_own_extrapolation() {
    let plain = cyclic(CycleMode::None, CycleMode::None, (0, 0));
    let off = cyclic(CycleMode::RepeatOffset, CycleMode::RepeatOffset, (1, 2));
    // Two cycles after (up to frame 31), one before (down to frame -9): cycled.
    assert!((at(&off, 29.0) - (at(&plain, 9.0) + 4.0)).abs() < 1e-5);
    assert!((at(&off, -7.0) - (at(&plain, 3.0) - 2.0)).abs() < 1e-5);
    // Beyond: the curve's own linear extrapolation, without the offset (Blender jumps back).
    for t in [31.5, 40.0, -9.5, -30.0] {
        assert_eq!(at(&off, t), at(&plain, t), "at {t}");
    }
}

#[test]
fn cycles_influence_and_range() {
    let plain = cyclic(CycleMode::None, CycleMode::None, (0, 0));
    let mut c = *cyclic(CycleMode::RepeatOffset, CycleMode::RepeatOffset, (0, 0))
        .cycles()
        .unwrap();
    c.influence = Some(0.0);
    let none = FCurve::new(plain.keys().to_vec(), Extrapolation::Linear, Some(c)).unwrap();
    c.influence = None;
    c.range = Some(FrameRange {
        start: -5.0,
        end: 25.0,
        blend_in: 0.0,
        blend_out: 0.0,
    });
    let ranged = FCurve::new(plain.keys().to_vec(), Extrapolation::Linear, Some(c)).unwrap();
    let full = cyclic(CycleMode::RepeatOffset, CycleMode::RepeatOffset, (0, 0));
    for i in 0..400 {
        let t = -40.0 + i as f64 * 0.2;
        assert_eq!(at(&none, t), at(&plain, t), "influence 0 at {t}");
        let expected = if (-5.0..=25.0).contains(&t) {
            at(&full, t)
        } else {
            at(&plain, t)
        };
        assert_eq!(at(&ranged, t), expected, "range at {t}");
    }
}

#[test]
fn batch_is_every_curve_at_every_time_in_any_order() {
    let curves = vec![
        cyclic(CycleMode::Mirror, CycleMode::RepeatOffset, (0, 3)),
        curve(
            &[(0.0, 1.0), (5.0, 2.0)],
            Interpolation::Elastic,
            Extrapolation::Linear,
        ),
        curve(
            &[(2.0, 1.0)],
            Interpolation::Bezier,
            Extrapolation::Constant,
        ),
    ];
    let times: Vec<f64> = (0..300)
        .map(|i| ((i * 7919) % 300) as f64 * 0.37 - 40.0)
        .collect();
    let out = evaluate_fcurves(&curves, &times).unwrap();
    assert_eq!(out.len(), 3 * 300);
    for (c, curve) in curves.iter().enumerate() {
        for (i, &t) in times.iter().enumerate() {
            assert_eq!(out[c * 300 + i], at(curve, t), "curve {c} time {t}");
        }
    }
}

/// Packed arrays for `keys` per curve (Bezier, auto easing, default parameters).
struct Packed {
    offsets: Vec<i64>,
    co: Vec<f64>,
    hl: Vec<f64>,
    hr: Vec<f64>,
    ipo: Vec<i64>,
    ease: Vec<i64>,
    back: Vec<f64>,
    amp: Vec<f64>,
    per: Vec<f64>,
    ext: Vec<Extrapolation>,
}

impl Packed {
    fn new(curves: &[&[(f64, f64)]]) -> Self {
        let mut p = Packed {
            offsets: vec![0],
            co: vec![],
            hl: vec![],
            hr: vec![],
            ipo: vec![],
            ease: vec![],
            back: vec![],
            amp: vec![],
            per: vec![],
            ext: vec![],
        };
        for keys in curves {
            for &(x, y) in *keys {
                p.co.extend([x, y]);
                p.hl.extend([x - 1.0, y]);
                p.hr.extend([x + 1.0, y]);
                p.ipo.push(2);
                p.ease.push(0);
                p.back.push(1.7);
                p.amp.push(0.8);
                p.per.push(4.1);
            }
            p.offsets.push(p.co.len() as i64 / 2);
            p.ext.push(Extrapolation::Constant);
        }
        p
    }
    fn view(&self) -> PackedCurves<'_> {
        PackedCurves {
            offsets: &self.offsets,
            co: &self.co,
            handle_left: &self.hl,
            handle_right: &self.hr,
            interpolation: &self.ipo,
            easing: &self.ease,
            back: &self.back,
            amplitude: &self.amp,
            period: &self.per,
            extrapolation: &self.ext,
            cycles: &[],
        }
    }
}

/// The entries an error is about (outermost first, from its [`Error::In`] layers) and the
/// error under them.
fn located(e: &Error) -> (Vec<(&'static str, usize)>, &Error) {
    let mut at = Vec::new();
    let mut e = e;
    while let Error::In { at: a, source, .. } = e {
        at.push((a.item, a.index));
        e = source;
    }
    (at, e)
}

#[test]
fn packed_curves_evaluate_like_the_curves() {
    let p = Packed::new(&[
        &[(0.0, 1.0), (4.0, 2.0)],
        &[(1.0, 5.0)],
        &[(-3.0, 0.0), (0.0, 1.0), (2.0, 0.0)],
    ]);
    let times: Vec<f64> = (0..50).map(|i| i as f64 * 0.3 - 5.0).collect();
    let curves = p.view().to_curves().unwrap();
    assert_eq!(curves.len(), 3);
    assert_eq!(
        evaluate_packed(&p.view(), &times).unwrap(),
        evaluate_fcurves(&curves, &times).unwrap()
    );
}

#[test]
fn bad_input_is_an_error_naming_curve_and_key() {
    let good = Packed::new(&[&[(0.0, 1.0), (4.0, 2.0)], &[(1.0, 5.0), (2.0, 1.0)]]);
    let times = [0.0, 1.0];
    let err = |p: &Packed| evaluate_packed(&p.view(), &times).unwrap_err();

    let mut p = Packed::new(&[&[(0.0, 1.0), (4.0, 2.0)], &[(1.0, 5.0), (2.0, 1.0)]]);
    p.co[6] = 0.5; // curve 1, key 1 before key 0
    let e = err(&p);
    assert!(
        matches!(
            located(&e),
            (at, Error::Spacing { what: "key frames", at: At { item: "key", index: 1 }, gap, .. })
                if at == [("curve", 1)] && *gap == -0.5
        ),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .contains("curve 1: key frames: key 1 is less than"),
        "{e}"
    );

    let mut p = Packed::new(&[&[(0.0, 1.0), (4.0, 2.0)], &[(1.0, 5.0), (2.0, 1.0)]]);
    p.hr[3] = f64::NAN;
    let e = err(&p);
    assert!(
        matches!(
            located(&e),
            (at, Error::Value {
                what: "keys",
                at: Some(At { item: "key", index: 1 }),
                expected: Expected::FiniteInF32("handle_right"),
                value,
            }) if at == [("curve", 0)] && value.is_nan()
        ),
        "{e:?}"
    );
    p.hr[3] = 1e39; // finite in f64, infinite in float32
    let e = err(&p);
    assert!(
        matches!(
            located(&e).1,
            Error::Value { expected: Expected::FiniteInF32("handle_right"), value, .. }
                if *value == f64::INFINITY
        ),
        "{e:?}"
    );
    assert!(
        e.to_string()
            .contains("handle_right is not finite in float32"),
        "{e}"
    );

    let mut p = Packed::new(&[&[(0.0, 1.0), (4.0, 2.0)], &[(1.0, 5.0), (2.0, 1.0)]]);
    p.ipo[2] = 13;
    let e = err(&p);
    assert!(
        matches!(
            located(&e),
            (at, Error::Index { what: "interpolation", index: 13, len: 13, .. })
                if at == [("curve", 1), ("key", 0)]
        ),
        "{e:?}"
    );
    p.ipo[2] = 2;
    p.ease[3] = -1;
    let e = err(&p);
    assert!(
        matches!(
            located(&e),
            (at, Error::Index { what: "easing", index: -1, len: 4, .. })
                if at == [("curve", 1), ("key", 1)]
        ),
        "{e:?}"
    );

    let mut p = Packed::new(&[&[(0.0, 1.0), (4.0, 2.0)], &[(1.0, 5.0), (2.0, 1.0)]]);
    p.offsets = vec![0, 2, 2, 4];
    p.ext.push(Extrapolation::Constant);
    let e = err(&p);
    assert!(
        matches!(
            located(&e),
            (at, Error::Count { what: "keys", got: 0, need: 1 }) if at == [("curve", 1)]
        ),
        "{e:?}"
    );
    p.offsets = vec![0, 3, 2];
    assert!(
        matches!(
            err(&p),
            Error::Spacing { what: "offsets", at: At { index: 2, .. }, gap, .. } if gap == -1.0
        ),
        "{:?}",
        err(&p)
    );
    p.offsets = vec![1, 2, 4];
    assert!(
        matches!(
            err(&p),
            Error::Value { what: "first offset", at: None, value, .. } if value == 1.0
        ),
        "{:?}",
        err(&p)
    );

    let mut p = Packed::new(&[&[(0.0, 1.0), (4.0, 2.0)], &[(1.0, 5.0), (2.0, 1.0)]]);
    p.back.pop();
    assert!(matches!(
        evaluate_packed(&p.view(), &times),
        Err(Error::LengthMismatch {
            what: "back",
            expected: 4,
            got: 3
        })
    ));

    assert!(matches!(
        evaluate_packed(&good.view(), &[0.0, f64::INFINITY]),
        Err(Error::NotFinite {
            what: "time",
            index: 1
        })
    ));
    assert!(matches!(
        evaluate_packed(&good.view(), &[1e300]),
        Err(Error::NotFinite {
            what: "time",
            index: 0
        })
    ));
}

#[test]
fn a_value_blender_would_make_infinite_is_an_error() {
    // A handle a float32 hair's breadth from its key in time but far in value: the slope
    // overflows float32, and linear extrapolation along it is infinite.
    let keys = vec![
        Key::new(0.0, 0.0).with_handles([-1e-30, 1e30], [1.0, 0.0]),
        Key::new(5.0, 1.0),
    ];
    let c = FCurve::new(keys, Extrapolation::Linear, None).unwrap();
    let e = evaluate_fcurves(&[c], &[1.0, -2.0]).unwrap_err();
    assert!(
        matches!(e, Error::Evaluates { curve: Some(0), time: Some(1), value, .. } if value.is_infinite()),
        "{e:?}"
    );
    assert!(e.to_string().contains("curve 0 evaluates to"), "{e}");
}

#[test]
fn sizes_are_checked_before_allocating() {
    assert!(check_batch(10, 100, 1000).is_ok());
    assert!(check_batch(1, MAX_KEYS + 1, 1).is_err());
    assert!(check_batch(MAX_VALUES, 1, 2).is_err());
    assert!(check_batch(usize::MAX, 1, usize::MAX).is_err());
    let c = curve(
        &[(0.0, 0.0)],
        Interpolation::Linear,
        Extrapolation::Constant,
    );
    let curves = vec![c; 2];
    // Times are not even converted when the output would be too large.
    let e = evaluate_fcurves(&curves, &vec![0.0; MAX_VALUES / 2 + 1]).unwrap_err();
    assert!(
        matches!(
            e,
            Error::Limit { counted: "values (curves x times)", count, limit: MAX_VALUES, .. }
                if count == MAX_VALUES + 2
        ),
        "{e:?}"
    );
}

#[test]
fn names_round_trip_and_unknown_names_are_errors() {
    for (i, ipo) in Interpolation::ALL.into_iter().enumerate() {
        assert_eq!(Interpolation::from_name(ipo.name()).unwrap(), ipo);
        assert_eq!(Interpolation::from_code(i as i64).unwrap(), ipo);
    }
    for e in Easing::ALL {
        assert_eq!(Easing::from_name(e.name()).unwrap(), e);
    }
    for m in CycleMode::ALL {
        assert_eq!(CycleMode::from_name(m.name()).unwrap(), m);
    }
    for x in Extrapolation::ALL {
        assert_eq!(Extrapolation::from_name(x.name()).unwrap(), x);
    }
    assert!(Interpolation::from_name("bezier").is_err());
    assert!(CycleMode::from_name("REPEAT_OFFSETS").is_err());
    assert!(Extrapolation::from_code(2).is_err());
}

/// A random curve: 1 to 6 keys, any interpolation and easing, handles anywhere.
fn arb_curve() -> impl Strategy<Value = FCurve> {
    let key = (
        0.05f32..8.0,
        -10f32..10.0,
        (-20f32..20.0, -10f32..10.0, -20f32..20.0, -10f32..10.0),
        0usize..13,
        0usize..4,
        (0f32..4.0, 0f32..5.0, 0f32..8.0),
    );
    (
        prop::collection::vec(key, 1..7),
        any::<bool>(),
        prop::option::of((0usize..4, 0usize..4, 0i32..3, 0i32..3)),
    )
        .prop_map(|(ks, linear, cyc)| {
            let mut x = -3.0f32;
            let keys = ks
                .into_iter()
                .map(
                    |(dx, y, (hlx, hly, hrx, hry), ipo, ease, (back, amp, per))| {
                        x += dx;
                        Key {
                            co: [x, y],
                            handle_left: [x - hlx.abs(), y + hly],
                            handle_right: [x + hrx, y + hry],
                            interpolation: Interpolation::ALL[ipo],
                            easing: Easing::ALL[ease],
                            back,
                            amplitude: amp,
                            period: per,
                        }
                    },
                )
                .collect();
            let ext = if linear {
                Extrapolation::Linear
            } else {
                Extrapolation::Constant
            };
            let cycles = cyc.map(|(b, a, nb, na)| {
                let mut c = Cycles::new(CycleMode::ALL[b], CycleMode::ALL[a]);
                (c.count_before, c.count_after) = (nb, na);
                c
            });
            FCurve::new(keys, ext, cycles).unwrap()
        })
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(256))]

    /// Moderate curves have finite values everywhere, hit their keys, and the batch equals
    /// the single evaluation.
    #[test]
    fn random_curves_are_finite_hit_keys_and_batch_equals_single(
        c in arb_curve(),
        times in prop::collection::vec(-200f64..200.0, 1..40),
    ) {
        let out = evaluate_fcurves(std::slice::from_ref(&c), &times).unwrap();
        for (i, &t) in times.iter().enumerate() {
            prop_assert!(out[i].is_finite());
            prop_assert_eq!(out[i], c.evaluate(t).unwrap());
        }
        for k in c.keys() {
            let v = c.evaluate(k.co[0] as f64).unwrap();
            // Equal frames: the search picks one of the keys, as Blender's does.
            let same = c.keys().iter().filter(|o| (o.co[0] - k.co[0]).abs() <= 1e-4).count();
            if same == 1 {
                prop_assert_eq!(v, k.co[1] as f64);
            }
        }
    }

    /// Between two keys, a Bezier segment stays within the box of its (clamped) control
    /// points, and an easing other than BACK and ELASTIC within its keys' values.
    #[test]
    fn segments_stay_in_their_hull(c in arb_curve(), s in 0.001f32..0.999) {
        let keys = c.keys();
        for w in keys.windows(2) {
            let (a, b) = (w[0], w[1]);
            if b.co[0] - a.co[0] < 1e-3 {
                continue;
            }
            let t = a.co[0] + s * (b.co[0] - a.co[0]);
            if (t - a.co[0]).abs() <= 2e-4 || (b.co[0] - t).abs() <= 2e-4 {
                continue;
            }
            // Only inside the keys' range, where the modifier leaves time alone.
            let v = c.evaluate(t as f64).unwrap() as f32;
            let (lo, hi) = match a.interpolation {
                Interpolation::Bezier => {
                    let (mut h0, mut h1) = (a.handle_right, b.handle_left);
                    correct_bezpart(a.co, &mut h0, &mut h1, b.co);
                    let ys = [a.co[1], h0[1], h1[1], b.co[1]];
                    (ys.iter().cloned().fold(f32::MAX, f32::min), ys.iter().cloned().fold(f32::MIN, f32::max))
                }
                Interpolation::Back | Interpolation::Elastic => continue,
                _ => (a.co[1].min(b.co[1]), a.co[1].max(b.co[1])),
            };
            let tol = 1e-4 * (lo.abs() + hi.abs()).max(1.0);
            prop_assert!(v >= lo - tol && v <= hi + tol, "{:?} at {}: {} outside [{}, {}]", a.interpolation, t, v, lo, hi);
        }
    }
}

#[test]
fn the_cycle_number_is_a_double_from_the_exact_difference() {
    // Found against Blender 4.2.23 and 5.0.1 (whose fcm_cycles_time computes the cycle number
    // with cvtss2sd / subsd / divsd): keys at these float32 frames, a time exactly two
    // cycles after the last key in float32 arithmetic. The float32 quotient is exactly 2.0,
    // the double one from the unrounded difference 2.00000005: Blender does not cycle with
    // cycles_after = 2 and plays the curve's own extrapolation.
    let (x0, x1) = (-9.127_501_f32, 28.307_86_f32);
    let keys = vec![
        Key::new(x0, 0.0).with_interpolation(Interpolation::Linear),
        Key::new(x1, 1000.0).with_interpolation(Interpolation::Linear),
    ];
    let plain = FCurve::new(keys.clone(), Extrapolation::Linear, None).unwrap();
    let mut c = Cycles::new(CycleMode::None, CycleMode::Mirror);
    c.count_after = 2;
    let two = FCurve::new(keys.clone(), Extrapolation::Linear, Some(c)).unwrap();
    let t = 103.178_581_237_792_97;
    assert_eq!(at(&two, t), at(&plain, t), "no cycling past 2 cycles");
    assert_eq!(at(&two, t), 3000.0); // Blender's value
                                     // Unlimited MIRROR, three cycles out: the float32 quotient is 3.0 (even: forwards, ending
                                     // on the last key), the double one 2.9999999 (odd: backwards, ending on the first key).
    c.count_after = 0;
    let free = FCurve::new(keys, Extrapolation::Linear, Some(c)).unwrap();
    assert_eq!(at(&free, 140.613_937_377_929_7), 0.0); // Blender's value
}
