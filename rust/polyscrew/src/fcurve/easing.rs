//! Robert Penner's easing equations as Blender writes them (`BLI_easing_*` in
//! `source/blender/blenlib/intern/easing.cc`), in `f32` and in Blender's order of operations.
//!
//! Every function takes Blender's four arguments: `time` since the segment's first key,
//! `begin` (its value), `change` (second value minus first) and `duration` (frames between the
//! keys), and returns `begin` at `time = 0` and `begin + change` at `time = duration`
//! (exactly for most, to rounding for SINE, CIRC and the `pow` based ones). C's left-to-right
//! evaluation is kept: `change * t * t * t` is `((change * t) * t) * t`.

use super::key::{Easing, Interpolation};

/// `float(M_PI)`.
const PI: f32 = std::f64::consts::PI as f32;
/// `float(M_PI_2)`.
const HALF_PI: f32 = std::f64::consts::FRAC_PI_2 as f32;
/// `2 * float(M_PI)`.
const TWO_PI: f32 = 2.0 * PI;

/// The easing `interpolation` with `easing` (AUTO resolved to Blender's default for it) at
/// `time`: `begin` at 0, `begin + change` at `duration`. BACK uses `back` as its overshoot,
/// ELASTIC `amplitude` and `period`. CONSTANT, LINEAR and BEZIER are not easings: LINEAR is
/// Blender's `BLI_easing_linear_ease`, the others return `begin`.
#[allow(clippy::too_many_arguments)]
pub fn ease(
    interpolation: Interpolation,
    easing: Easing,
    time: f32,
    begin: f32,
    change: f32,
    duration: f32,
    back: f32,
    amplitude: f32,
    period: f32,
) -> f32 {
    use Easing::{In, InOut, Out};
    use Interpolation as I;
    let (t, b, c, d) = (time, begin, change, duration);
    match (interpolation, easing.resolve(interpolation)) {
        (I::Linear, _) => c * t / d + b,
        (I::Constant | I::Bezier, _) => b,
        (I::Back, In) => back_in(t, b, c, d, back),
        (I::Back, InOut) => back_in_out(t, b, c, d, back),
        (I::Back, _) => back_out(t, b, c, d, back),
        (I::Bounce, In) => bounce_in(t, b, c, d),
        (I::Bounce, InOut) => bounce_in_out(t, b, c, d),
        (I::Bounce, _) => bounce_out(t, b, c, d),
        (I::Circ, Out) => circ_out(t, b, c, d),
        (I::Circ, InOut) => circ_in_out(t, b, c, d),
        (I::Circ, _) => circ_in(t, b, c, d),
        (I::Cubic, Out) => cubic_out(t, b, c, d),
        (I::Cubic, InOut) => cubic_in_out(t, b, c, d),
        (I::Cubic, _) => cubic_in(t, b, c, d),
        (I::Elastic, In) => elastic::<ELASTIC_IN>(t, b, c, d, amplitude, period),
        (I::Elastic, InOut) => elastic::<ELASTIC_IN_OUT>(t, b, c, d, amplitude, period),
        (I::Elastic, _) => elastic::<ELASTIC_OUT>(t, b, c, d, amplitude, period),
        (I::Expo, Out) => expo_out(t, b, c, d),
        (I::Expo, InOut) => expo_in_out(t, b, c, d),
        (I::Expo, _) => expo_in(t, b, c, d),
        (I::Quad, Out) => quad_out(t, b, c, d),
        (I::Quad, InOut) => quad_in_out(t, b, c, d),
        (I::Quad, _) => quad_in(t, b, c, d),
        (I::Quart, Out) => quart_out(t, b, c, d),
        (I::Quart, InOut) => quart_in_out(t, b, c, d),
        (I::Quart, _) => quart_in(t, b, c, d),
        (I::Quint, Out) => quint_out(t, b, c, d),
        (I::Quint, InOut) => quint_in_out(t, b, c, d),
        (I::Quint, _) => quint_in(t, b, c, d),
        (I::Sine, Out) => sine_out(t, b, c, d),
        (I::Sine, InOut) => sine_in_out(t, b, c, d),
        (I::Sine, _) => sine_in(t, b, c, d),
    }
}

fn back_in(time: f32, begin: f32, change: f32, duration: f32, overshoot: f32) -> f32 {
    let t = time / duration;
    change * t * t * ((overshoot + 1.0) * t - overshoot) + begin
}

fn back_out(time: f32, begin: f32, change: f32, duration: f32, overshoot: f32) -> f32 {
    let t = time / duration - 1.0;
    change * (t * t * ((overshoot + 1.0) * t + overshoot) + 1.0) + begin
}

fn back_in_out(time: f32, begin: f32, change: f32, duration: f32, overshoot: f32) -> f32 {
    let s = overshoot * 1.525;
    let mut t = time / (duration / 2.0);
    if t < 1.0 {
        return change / 2.0 * (t * t * ((s + 1.0) * t - s)) + begin;
    }
    t -= 2.0;
    change / 2.0 * (t * t * ((s + 1.0) * t + s) + 2.0) + begin
}

fn bounce_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let mut t = time / duration;
    if t < 1.0 / 2.75 {
        return change * (7.5625 * t * t) + begin;
    }
    if t < 2.0 / 2.75 {
        t -= 1.5 / 2.75;
        return change * ((7.5625 * t) * t + 0.75) + begin;
    }
    if t < 2.5 / 2.75 {
        t -= 2.25 / 2.75;
        return change * ((7.5625 * t) * t + 0.9375) + begin;
    }
    t -= 2.625 / 2.75;
    change * ((7.5625 * t) * t + 0.984375) + begin
}

fn bounce_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    change - bounce_out(duration - time, 0.0, change, duration) + begin
}

fn bounce_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    if time < duration / 2.0 {
        return bounce_in(time * 2.0, 0.0, change, duration) * 0.5 + begin;
    }
    bounce_out(time * 2.0 - duration, 0.0, change, duration) * 0.5 + change * 0.5 + begin
}

fn circ_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration;
    -change * ((1.0 - t * t).sqrt() - 1.0) + begin
}

fn circ_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration - 1.0;
    change * (1.0 - t * t).sqrt() + begin
}

fn circ_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let mut t = time / (duration / 2.0);
    if t < 1.0 {
        return -change / 2.0 * ((1.0 - t * t).sqrt() - 1.0) + begin;
    }
    t -= 2.0;
    change / 2.0 * ((1.0 - t * t).sqrt() + 1.0) + begin
}

fn cubic_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration;
    change * t * t * t + begin
}

fn cubic_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration - 1.0;
    change * (t * t * t + 1.0) + begin
}

fn cubic_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let mut t = time / (duration / 2.0);
    if t < 1.0 {
        return change / 2.0 * t * t * t + begin;
    }
    t -= 2.0;
    change / 2.0 * (t * t * t + 2.0) + begin
}

/// Blender's blend of ELASTIC near the crossing point when the amplitude is below the change
/// (`elastic_blend`, `USE_ELASTIC_BLEND`): `f` scaled by `amplitude / |change|` and blended
/// back to 1 within `|s|` frames of the segment's end.
fn elastic_blend(time: f32, change: f32, duration: f32, amplitude: f32, s: f32, f: f32) -> f32 {
    let mut f = f;
    if change != 0.0 {
        let t = s.abs();
        if amplitude != 0.0 {
            f *= amplitude / change.abs();
        } else {
            f = 0.0;
        }
        if (time * duration).abs() < t {
            let l = (time * duration).abs() / t;
            f = (f * l) + (1.0 - l);
        }
    }
    f
}

/// The phase shift `s`, the blend factor `f` and the amplitude ELASTIC uses for `time` (after
/// Blender has shifted it), `change` and the key's `amplitude` and `period` (already defaulted).
fn elastic_shape(
    time: f32,
    change: f32,
    duration: f32,
    amplitude: f32,
    period: f32,
) -> (f32, f32, f32) {
    if amplitude == 0.0 || amplitude < change.abs() {
        let s = period / 4.0;
        let f = elastic_blend(time, change, duration, amplitude, s, 1.0);
        (s, f, change)
    } else {
        let s = period / TWO_PI * (change / amplitude).asin();
        (s, 1.0, amplitude)
    }
}

/// Blender's ELASTIC wave at the shifted `time` (`t`): `f a 2^(10 t) sin((t d - s) 2 pi / p)`
/// for the phase shift `s`, blend factor `f` and amplitude `a` of [`elastic_shape`].
fn elastic_wave(t: f32, duration: f32, period: f32, (s, f, a): (f32, f32, f32)) -> f32 {
    f * (a * 2f32.powf(10.0 * t) * ((t * duration - s) * TWO_PI / period).sin())
}

/// [`elastic`]'s `KIND`: ease in.
const ELASTIC_IN: u8 = 0;
/// [`elastic`]'s `KIND`: ease out.
const ELASTIC_OUT: u8 = 1;
/// [`elastic`]'s `KIND`: ease in and out.
const ELASTIC_IN_OUT: u8 = 2;

/// ELASTIC easing of `KIND` ([`ELASTIC_IN`], [`ELASTIC_OUT`], [`ELASTIC_IN_OUT`]: a
/// constant, so that each is compiled without the others' branches), as Blender's
/// `BLI_easing_elastic_ease_in`, `_ease_out` and `_ease_in_out`: the ends exact; else the
/// time shifted (in: `t - 1`; out: `-t`; in-out: `2 t - 1`, over half the duration), the
/// period defaulted (`0.3 d`, in-out `0.45 d`), and the [`elastic_wave`] added to `begin`
/// (negated, in) or to `begin + change` (out); in-out is half of each, by the sign of its
/// shifted time.
fn elastic<const KIND: u8>(
    time: f32,
    begin: f32,
    change: f32,
    duration: f32,
    amplitude: f32,
    period: f32,
) -> f32 {
    if time == 0.0 {
        return begin;
    }
    let in_out = KIND == ELASTIC_IN_OUT;
    let (span, end, default_period) = if in_out {
        (duration / 2.0, 2.0, duration * (0.3 * 1.5))
    } else {
        (duration, 1.0, duration * 0.3)
    };
    let t = time / span;
    if t == end {
        return begin + change;
    }
    let t = if KIND != ELASTIC_OUT { t - 1.0 } else { -t };
    let period = if period == 0.0 {
        default_period
    } else {
        period
    };
    let (s, f, a) = elastic_shape(t, change, duration, amplitude, period);
    match KIND {
        ELASTIC_IN => elastic_wave(t, duration, period, (s, -f, a)) + begin,
        ELASTIC_IN_OUT if t < 0.0 => elastic_wave(t, duration, period, (s, f * -0.5, a)) + begin,
        ELASTIC_IN_OUT => elastic_wave(-t, duration, period, (s, f * 0.5, a)) + change + begin,
        _ => elastic_wave(t, duration, period, (s, f, a)) + change + begin,
    }
}

/// `2^-10`: where Blender's EXPO curve starts, rescaled to reach 0 and 1 exactly.
const POW_MIN: f32 = 0.0009765625;
/// `1 / (1 - 2^-10)`.
const POW_SCALE: f32 = 1.0 / (1.0 - 0.0009765625);

fn expo_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    if time == 0.0 {
        return begin;
    }
    change * (2f32.powf(10.0 * (time / duration - 1.0)) - POW_MIN) * POW_SCALE + begin
}

fn expo_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    if time == 0.0 {
        return begin;
    }
    change * (1.0 - (2f32.powf(-10.0 * time / duration) - POW_MIN) * POW_SCALE) + begin
}

fn expo_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let duration_half = duration / 2.0;
    let change_half = change / 2.0;
    if time <= duration_half {
        return expo_in(time, begin, change_half, duration_half);
    }
    expo_out(
        time - duration_half,
        begin + change_half,
        change_half,
        duration_half,
    )
}

fn quad_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration;
    change * t * t + begin
}

fn quad_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration;
    -change * t * (t - 2.0) + begin
}

fn quad_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let mut t = time / (duration / 2.0);
    if t < 1.0 {
        return change / 2.0 * t * t + begin;
    }
    t -= 1.0;
    -change / 2.0 * (t * (t - 2.0) - 1.0) + begin
}

fn quart_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration;
    change * t * t * t * t + begin
}

fn quart_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration - 1.0;
    -change * (t * t * t * t - 1.0) + begin
}

fn quart_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let mut t = time / (duration / 2.0);
    if t < 1.0 {
        return change / 2.0 * t * t * t * t + begin;
    }
    t -= 2.0;
    -change / 2.0 * (t * t * t * t - 2.0) + begin
}

fn quint_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration;
    change * t * t * t * t * t + begin
}

fn quint_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let t = time / duration - 1.0;
    change * (t * t * t * t * t + 1.0) + begin
}

fn quint_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    let mut t = time / (duration / 2.0);
    if t < 1.0 {
        return change / 2.0 * t * t * t * t * t + begin;
    }
    t -= 2.0;
    change / 2.0 * (t * t * t * t * t + 2.0) + begin
}

fn sine_in(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    -change * (time / duration * HALF_PI).cos() + change + begin
}

fn sine_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    change * (time / duration * HALF_PI).sin() + begin
}

fn sine_in_out(time: f32, begin: f32, change: f32, duration: f32) -> f32 {
    -change / 2.0 * ((PI * time / duration).cos() - 1.0) + begin
}
