//! Fitting a rotation to a sketched angular velocity (Xie, Xu, Yu, Weng 2011, "Sketch-based
//! rotation editing", section 2).
//!
//! Given key orientations `q^i` at times `t_i` and a target angular velocity `omega^s(t)`
//! (world frame), find the Hermite quaternion spline `q(t)` ([`QuatSpline`]) minimising
//!
//! `E = alpha W_T + W_A`, with
//! `W_T = ∫ |q''|^2 - (q . q'')^2 / |q|^2 dt` (tangential acceleration, Barr et al. 1992) and
//! `W_A = ∫ |2 q' q^-1 - omega^s|^2 dt` (deviation from the target),
//!
//! subject to `q(t_i) = q^i` for the constrained keys `i in D` and unit norm. The unknowns
//! are the quaternions and derivatives at the control points: the keys and the *variable
//! frames* the paper's Algorithm 1 inserts at the midpoints of fragments whose error
//! `F_n = ∫_fragment |2 q' q^-1 - omega^s|^2 dt` (eq. 2) exceeds `delta`.
//!
//! Differences from the paper, all in favour of exactness:
//! - Unit norm: the orientation is the normalised spline `q / |q|` (exactly unit everywhere,
//!   its angular velocity exactly `vec(2 q' q^-1)`), and every free control quaternion is
//!   moved on the unit sphere by `q <- exp(d) q` (a local parametrisation by its tangent
//!   space), so the constraint `U = 0` of the paper holds at the control points by
//!   construction and the scalar part of `2 q' q^-1` in `W_A` keeps `|q|` near 1 between them.
//! - Optimiser: instead of SQP, Levenberg-Marquardt on the residuals whose squares are the
//!   quadrature terms of `E` (Gauss-Legendre, [`QUADRATURE_POINTS`] per segment), with exact
//!   analytic Jacobians; constrained keys are simply not unknowns, so they are met exactly.
//!   A Hermite spline couples only neighbouring control points, so the normal equations are
//!   banded and each step costs `O(n)`.
//!
//! Times are in seconds and angular velocities in rad/s for the paper's defaults
//! `alpha = 0.002` (units s^2) and `delta = 0.1` (units rad^2/s) to mean what they meant there.

#![allow(clippy::neg_cmp_op_on_partial_ord)] // `!(x > y)` also catches NaN

use glam::{DQuat, DVec3, DVec4};

use crate::angular_velocity::quat_spline::{
    check_keys, hermite_weights, quat_conj, quat_exp, quat_mul, QuatSpline,
};
use crate::error::{At, Error, Expected, Result};
use crate::memory::{try_vec, Footprint};
use crate::motion::timing::MAX_TIME;
use crate::numeric::band::Band;

/// The fit's working range of times (key, target and sample times): `|t| <= FIT_MAX_TIME`,
/// and consecutive key times at least [`MIN_KEY_SPACING`] apart. Derived from the crate's one
/// working range of times, [`MAX_TIME`]: its tenth root, `MAX_TIME^(1/10) = 1e30` (checked
/// when the crate compiles).
///
/// Why smaller: the time map uses times only through differences and ratios, but the fit
/// multiplies them. Its energy integrates `|q''|^2`, and `q''` of a Hermite segment of length
/// `h` is up to `6 / h^2 + 4 |q'| / h` with `|q'| ~ |omega|`; the Levenberg-Marquardt normal
/// equations square the Jacobian again. Up to about ten factors that are each a time, a
/// reciprocal spacing, an angular velocity ([`MAX_ANGULAR_VELOCITY`]) or `alpha`
/// ([`MAX_ALPHA`]) meet in one product, so each must stay within the tenth root of the
/// range every product must stay within: with all of them in `[1e-30, 1e30]` every energy,
/// Jacobian entry and damped normal equation stays below about `1e200 < MAX_TIME`. An
/// animator's seconds and radians per second are far inside.
pub const FIT_MAX_TIME: f64 = 1e30;

// FIT_MAX_TIME is MAX_TIME^(1/10): its tenth power is MAX_TIME to rounding.
const _: () = {
    let mut power = 1.0;
    let mut i = 0;
    while i < 10 {
        power *= FIT_MAX_TIME;
        i += 1;
    }
    assert!(power > MAX_TIME * (1.0 - 1e-12) && power < MAX_TIME * (1.0 + 1e-12));
};

/// The smallest spacing of consecutive key times of a fit: `1 / FIT_MAX_TIME` (see
/// [`FIT_MAX_TIME`]).
pub const MIN_KEY_SPACING: f64 = 1e-30;

/// The largest target angular velocity (rad per time unit) and target speed:
/// [`FIT_MAX_TIME`], for the same reason.
pub const MAX_ANGULAR_VELOCITY: f64 = FIT_MAX_TIME;

/// The largest `alpha`: [`FIT_MAX_TIME`], for the same reason.
pub const MAX_ALPHA: f64 = FIT_MAX_TIME;

/// The most fragments the key range may be cut into (`fragment_duration` at least
/// `span / MAX_FRAGMENTS`): each costs eight spline evaluations per round.
pub const MAX_FRAGMENTS: usize = 1_000_000;

/// The largest `max_iterations` and `max_frames` accepted.
pub const MAX_ITERATIONS: usize = 1_000_000;

/// Bytes a fit holds per control point (key or variable frame) at its peak, with room: the
/// quadrature points of its segment (8 x 144 bytes), its share of the banded normal
/// equations and their copies (3 x 7 x 14 x 8 bytes), the node itself and the step vectors.
pub const FIT_BYTES_PER_NODE: usize = 8192;

/// How to ask the fit for less memory.
pub const FIT_HINT: &str = "use fewer keys, fewer variable frames (max_frames) or a longer \
     fragment_duration";

/// What [`fit_angular_velocity`] holds at its peak for `keys` keys, `targets` target
/// samples and the options (the fragments counted as `options` asks).
pub fn fit_footprint(keys: usize, targets: usize, options: &FitOptions) -> Footprint {
    let fragments = fragment_count(keys, options).unwrap_or(MAX_FRAGMENTS);
    let nodes = keys.saturating_add(options.max_frames.min(fragments));
    Footprint::bytes(FIT_BYTES_PER_NODE).times(nodes)
        + Footprint::of::<[f64; 3]>(fragments)
        + Footprint::of::<[f64; 4]>(targets).times(2)
}

/// The number of fragments of the key range (`span` known only to the fit: here the
/// default count, or an upper bound from the duration when the range is not known).
fn fragment_count(keys: usize, options: &FitOptions) -> Option<usize> {
    match options.fragment_duration {
        None => Some(
            FRAGMENTS_PER_KEY_SPAN
                .saturating_mul(keys.saturating_sub(1))
                .max(MIN_FRAGMENTS),
        ),
        Some(_) => None,
    }
}

fn check_fit_time(what: &'static str, index: usize, t: f64) -> Result<()> {
    crate::motion::timing::check_time_within(what, index, t, FIT_MAX_TIME)
}

/// The paper's weight of the tangential-acceleration term `W_T` (section 2: 0.002; it found
/// `[0.001, 0.005]` to work well).
pub const DEFAULT_ALPHA: f64 = 0.002;

/// The paper's threshold on the per-fragment fit error `F_n` (section 2).
pub const DEFAULT_DELTA: f64 = 0.1;

/// Default limit on Levenberg-Marquardt steps per optimisation round.
pub const DEFAULT_MAX_ITERATIONS: usize = 200;

/// Default limit on inserted variable frames (the paper never needed more than 10).
pub const DEFAULT_MAX_FRAMES: usize = 10;

/// By default the range is cut into this many fragments per key span ...
pub const FRAGMENTS_PER_KEY_SPAN: usize = 2;

/// ... but never fewer than this many.
pub const MIN_FRAGMENTS: usize = 8;

/// Gauss-Legendre points per spline segment and per fragment.
pub const QUADRATURE_POINTS: usize = 8;

/// A step that brings `|q(t)|^2` below this at a quadrature point is rejected: the spline
/// would pass too close to the origin of R^4 for `q / |q|` to be a sound rotation.
pub const NORM_FLOOR: f64 = 1e-3;

/// Target directions shorter than this cannot be normalised and are rejected.
pub const MIN_DIRECTION_LENGTH: f64 = 1e-9;

/// Target and sample times may miss the key range by this fraction of its length.
pub const TIME_TOLERANCE: f64 = 1e-9;

/// A variable frame is not inserted closer to an existing control point than this fraction
/// of the fragment length.
pub const MIN_FRAME_GAP: f64 = 0.25;

/// Levenberg-Marquardt stops when an accepted step lowers the energy by less than this
/// fraction of it while the damping is below [`CONVERGED_DAMPING`].
pub const ENERGY_TOLERANCE: f64 = 1e-10;

/// The damping below which a step counts as a Gauss-Newton step for the stopping test.
pub const CONVERGED_DAMPING: f64 = 1e-2;

/// An energy below this is zero for the stopping test.
pub const ENERGY_FLOOR: f64 = 1e-24;

/// Damping beyond which no step can lower the energy any more: the point is stationary to
/// rounding and the round stops as converged.
pub const MAX_DAMPING: f64 = 1e12;

/// Gauss-Legendre nodes on `[-1, 1]` for [`QUADRATURE_POINTS`] = 8.
const GL_NODES: [f64; QUADRATURE_POINTS] = [
    -0.960_289_856_497_536_2,
    -0.796_666_477_413_626_7,
    -0.525_532_409_916_329,
    -0.183_434_642_495_649_8,
    0.183_434_642_495_649_8,
    0.525_532_409_916_329,
    0.796_666_477_413_626_7,
    0.960_289_856_497_536_2,
];

/// Gauss-Legendre weights on `[-1, 1]` for [`QUADRATURE_POINTS`] = 8.
const GL_WEIGHTS: [f64; QUADRATURE_POINTS] = [
    0.101_228_536_290_376_3,
    0.222_381_034_453_374_5,
    0.313_706_645_877_887_3,
    0.362_683_783_378_362,
    0.362_683_783_378_362,
    0.313_706_645_877_887_3,
    0.222_381_034_453_374_5,
    0.101_228_536_290_376_3,
];

/// `(s, w)`: Gauss-Legendre points and weights on `[0, 1]` (weights sum to 1).
fn unit_quadrature() -> impl Iterator<Item = (f64, f64)> {
    GL_NODES
        .iter()
        .zip(GL_WEIGHTS)
        .map(|(x, w)| (0.5 * (x + 1.0), 0.5 * w))
}

/// A target angular velocity sampled over time, linear between samples.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularVelocityTarget {
    times: Vec<f64>,
    omega: Vec<DVec3>,
}

impl AngularVelocityTarget {
    /// A target through world-frame angular velocities `omega[j]` (rad/s) at `times[j]`.
    ///
    /// # Errors
    /// [`Error::Count`] for fewer than 2 samples, [`Error::Spacing`] for times that are not strictly
    /// increasing, [`Error::LengthMismatch`] when the slices differ in length,
    /// [`Error::NotFinite`] for a NaN or infinite angular velocity.
    pub fn new(times: &[f64], omega: &[DVec3]) -> Result<Self> {
        if omega.len() != times.len() {
            return Err(Error::LengthMismatch {
                what: "target angular velocities",
                expected: times.len(),
                got: omega.len(),
            });
        }
        check_target_times(times)?;
        if let Some(index) = omega.iter().position(|w| !w.is_finite()) {
            return Err(Error::NotFinite {
                what: "target angular velocity",
                index,
            });
        }
        if let Some(index) = omega
            .iter()
            .position(|w| w.abs().max_element() > MAX_ANGULAR_VELOCITY)
        {
            return Err(Error::OutOfRange {
                what: "target angular velocity",
                index,
                value: omega[index].abs().max_element(),
                limit: MAX_ANGULAR_VELOCITY,
            });
        }
        let mut own_times = try_vec(times.len(), "target")?;
        own_times.extend_from_slice(times);
        let mut own_omega = try_vec(omega.len(), "target")?;
        own_omega.extend_from_slice(omega);
        Ok(Self {
            times: own_times,
            omega: own_omega,
        })
    }

    /// A target from the paper's two sketches: a direction curve on the unit sphere and a
    /// magnitude curve, `omega[j] = speeds[j] * directions[j] / |directions[j]|`.
    ///
    /// Directions need not be unit: they are normalised (a stroke drawn near, not exactly
    /// on, the sphere is what the user meant).
    ///
    /// # Errors
    /// As [`AngularVelocityTarget::new`], and [`Error::Value`] for a direction shorter
    /// than [`MIN_DIRECTION_LENGTH`], [`Error::NotFinite`] for a NaN or infinite direction
    /// or speed.
    pub fn from_directions(times: &[f64], directions: &[DVec3], speeds: &[f64]) -> Result<Self> {
        for (what, len) in [
            ("target directions", directions.len()),
            ("target speeds", speeds.len()),
        ] {
            if len != times.len() {
                return Err(Error::LengthMismatch {
                    what,
                    expected: times.len(),
                    got: len,
                });
            }
        }
        let mut omega = try_vec(times.len(), "target")?;
        for (index, (d, s)) in directions.iter().zip(speeds).enumerate() {
            if !d.is_finite() {
                return Err(Error::NotFinite {
                    what: "target direction",
                    index,
                });
            }
            if !s.is_finite() {
                return Err(Error::NotFinite {
                    what: "target speed",
                    index,
                });
            }
            if s.abs() > MAX_ANGULAR_VELOCITY {
                return Err(Error::OutOfRange {
                    what: "target speed",
                    index,
                    value: *s,
                    limit: MAX_ANGULAR_VELOCITY,
                });
            }
            // Directions are only normalised: scale huge ones first so |d|^2 stays finite.
            let d = if d.abs().max_element() > 1e150 {
                *d * 1e-150
            } else {
                *d
            };
            let length = d.length();
            if length < MIN_DIRECTION_LENGTH {
                return Err(Error::Value {
                    what: "target direction",
                    at: Some(At::new("direction", index)),
                    value: length,
                    expected: Expected::Normalisable(MIN_DIRECTION_LENGTH),
                });
            }
            omega.push(d * (*s / length));
        }
        Self::new(times, &omega)
    }

    /// Sample times.
    pub fn times(&self) -> &[f64] {
        &self.times
    }

    /// Sampled angular velocities.
    pub fn omega(&self) -> &[DVec3] {
        &self.omega
    }

    /// The target at time `t`: linear between samples, the end samples held outside (and
    /// the first for a NaN time).
    pub fn eval(&self, t: f64) -> DVec3 {
        let n = self.times.len();
        if !(t > self.times[0]) {
            return self.omega[0];
        }
        if t >= self.times[n - 1] {
            return self.omega[n - 1];
        }
        let j = (self.times.partition_point(|&x| x <= t).max(1) - 1).min(n - 2);
        let u = (t - self.times[j]) / (self.times[j + 1] - self.times[j]);
        self.omega[j].lerp(self.omega[j + 1], u)
    }
}

fn check_target_times(times: &[f64]) -> Result<()> {
    if times.len() < 2 {
        return Err(Error::Count {
            what: "target samples",
            got: times.len(),
            need: 2,
        });
    }
    for (i, t) in times.iter().enumerate() {
        check_fit_time("target time", i, *t)?;
        if i > 0 && *t <= times[i - 1] {
            return Err(Error::Spacing {
                what: "target times",
                at: At::new("target time", i),
                gap: *t - times[i - 1],
                min: f64::MIN_POSITIVE,
            });
        }
    }
    Ok(())
}

/// Settings of [`fit_angular_velocity`]; `Default` gives the paper's.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FitOptions {
    /// Weight of the tangential acceleration `W_T` (`W_A` has weight 1), `>= 0`.
    pub alpha: f64,
    /// Threshold on the per-fragment error `F_n`, `> 0`.
    pub delta: f64,
    /// Levenberg-Marquardt steps allowed per optimisation round, `>= 1`.
    pub max_iterations: usize,
    /// Variable frames allowed in total.
    pub max_frames: usize,
    /// Fragment length `Delta T` (rounded so whole fragments tile the range); `None`:
    /// [`FRAGMENTS_PER_KEY_SPAN`] per key span, at least [`MIN_FRAGMENTS`].
    pub fragment_duration: Option<f64>,
}

impl Default for FitOptions {
    fn default() -> Self {
        Self {
            alpha: DEFAULT_ALPHA,
            delta: DEFAULT_DELTA,
            max_iterations: DEFAULT_MAX_ITERATIONS,
            max_frames: DEFAULT_MAX_FRAMES,
            fragment_duration: None,
        }
    }
}

impl FitOptions {
    fn check(&self) -> Result<()> {
        let bad = |what, value, expected| {
            Err(Error::Value {
                what,
                at: None,
                value,
                expected,
            })
        };
        let counts = |low: usize| Expected::Within {
            low: low as f64,
            high: MAX_ITERATIONS as f64,
        };
        if !(self.alpha >= 0.0 && self.alpha <= MAX_ALPHA) {
            let range = Expected::Within {
                low: 0.0,
                high: MAX_ALPHA,
            };
            return bad("alpha", self.alpha, range);
        }
        if !(self.delta.is_finite() && self.delta > 0.0) {
            return bad("delta", self.delta, Expected::Positive("number"));
        }
        if self.max_iterations == 0 || self.max_iterations > MAX_ITERATIONS {
            return bad("max_iterations", self.max_iterations as f64, counts(1));
        }
        if self.max_frames > MAX_ITERATIONS {
            return bad("max_frames", self.max_frames as f64, counts(0));
        }
        if let Some(d) = self.fragment_duration {
            if !(d.is_finite() && d > 0.0) {
                return bad("fragment_duration", d, Expected::Positive("duration"));
            }
        }
        Ok(())
    }
}

/// How a fit ended.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
#[non_exhaustive]
pub enum FitStatus {
    /// The last optimisation converged and every fragment error is at most `delta`.
    Converged,
    /// The last optimisation hit `max_iterations` before converging.
    IterationLimit,
    /// The optimisation converged but some fragment error still exceeds `delta` and no
    /// more variable frames may (or can) be inserted: the target is infeasible for these
    /// keys and limits.
    AboveDelta,
}

/// The result of [`fit_angular_velocity`]: the best spline found and how well it fits.
#[derive(Debug, Clone, PartialEq)]
pub struct AngularVelocityFit {
    /// The fitted spline over keys and variable frames; its orientations are
    /// `spline.rotation(t)`.
    pub spline: QuatSpline,
    /// The fitted orientation at each key time (equal to the key, up to sign, for the
    /// constrained ones).
    pub keys: Vec<DQuat>,
    /// Times of the inserted variable frames, increasing.
    pub frame_times: Vec<f64>,
    /// The largest fragment error `max_n F_n` (eq. 2).
    pub fit_error: f64,
    /// Every fragment error `F_n`, in time order.
    pub fragment_errors: Vec<f64>,
    /// The fragment length `Delta T` used.
    pub fragment_duration: f64,
    /// The energy `E = alpha W_T + W_A`.
    pub energy: f64,
    /// The tangential acceleration term `W_T`.
    pub tangential: f64,
    /// The deviation term `W_A`.
    pub deviation: f64,
    /// Levenberg-Marquardt steps taken over all rounds.
    pub iterations: usize,
    /// Optimisation rounds (one more than the times variable frames were inserted).
    pub rounds: usize,
    /// How the fit ended.
    pub status: FitStatus,
    /// The `delta` the fit was held to.
    pub delta: f64,
}

impl AngularVelocityFit {
    /// Whether the fit ended with [`FitStatus::Converged`].
    pub fn converged(&self) -> bool {
        self.status == FitStatus::Converged
    }

    /// The fitted orientation (unit) at time `t`, clamped to the key range.
    pub fn rotation(&self, t: f64) -> DQuat {
        self.spline.rotation(t)
    }

    /// The fitted world-frame angular velocity `vec(2 q' q^-1)` at time `t`.
    pub fn angular_velocity(&self, t: f64) -> DVec3 {
        self.spline.angular_velocity(t)
    }

    /// Unit orientations at `times`, sign-continuous along the spline (the first key's sign).
    ///
    /// # Errors
    /// [`Error::NotFinite`] for a NaN time, [`Error::Value`] for a time outside the key
    /// range (beyond [`TIME_TOLERANCE`] of its length), [`Error::Memory`] when the output
    /// exceeds the memory budget.
    pub fn sample(&self, times: &[f64]) -> Result<Vec<DQuat>> {
        let (t0, t1) = self.spline.range();
        let slack = TIME_TOLERANCE * (t1 - t0);
        Footprint::of::<DQuat>(times.len()).check("sampled orientations", FIT_HINT)?;
        let mut out = try_vec(times.len(), "sampled orientations")?;
        for (index, &t) in times.iter().enumerate() {
            out.push({
                if !t.is_finite() {
                    return Err(Error::NotFinite {
                        what: "sample time",
                        index,
                    });
                }
                if t < t0 - slack || t > t1 + slack {
                    return Err(Error::Value {
                        what: "sample times",
                        at: Some(At::new("time", index)),
                        value: t,
                        expected: Expected::KeyRange { low: t0, high: t1 },
                    });
                }
                self.spline.rotation(t)
            });
        }
        Ok(out)
    }

    /// `Ok(self)` when converged, otherwise [`Error::FitFailed`] carrying this best result.
    ///
    /// # Errors
    /// [`Error::FitFailed`] when [`AngularVelocityFit::converged`] is false.
    pub fn into_result(self) -> Result<Self> {
        if self.converged() {
            Ok(self)
        } else {
            Err(Error::FitFailed {
                best: Box::new(self),
            })
        }
    }
}

/// One quadrature point of a round: which segment, its weight (times the segment length),
/// the Hermite weights and the target there (as a pure quaternion).
#[derive(Debug, Clone, Copy)]
struct QuadPoint {
    segment: usize,
    weight: f64,
    basis: [[f64; 4]; 3],
    target: DVec4,
}

/// The control points being optimised.
#[derive(Debug, Clone)]
struct Nodes {
    times: Vec<f64>,
    values: Vec<DVec4>,
    derivatives: Vec<DVec4>,
    /// The value is a hard constraint (a constrained key).
    fixed: Vec<bool>,
    /// Index of the key at this node, `None` for a variable frame.
    key: Vec<Option<usize>>,
}

impl Nodes {
    fn jet(&self, p: &QuadPoint) -> (DVec4, DVec4, DVec4) {
        let i = p.segment;
        let c = [
            self.values[i],
            self.derivatives[i],
            self.values[i + 1],
            self.derivatives[i + 1],
        ];
        let b = &p.basis;
        let comb = |r: &[f64; 4]| r[0] * c[0] + r[1] * c[1] + r[2] * c[2] + r[3] * c[3];
        (comb(&b[0]), comb(&b[1]), comb(&b[2]))
    }

    fn spline(&self) -> QuatSpline {
        QuatSpline::from_parts(
            self.times.clone(),
            self.values.clone(),
            self.derivatives.clone(),
        )
    }
}

/// Half-bandwidth of the normal equations: a segment couples its two nodes' parameters,
/// at most 7 each (3 tangent parameters of a free value, 4 derivatives), so `7 + 7 - 1`.
const HESSIAN_BANDWIDTH: usize = 13;

/// The normal equations' matrix `J^T J`: symmetric, banded ([`Band`]).
type Hessian = Band<f64, HESSIAN_BANDWIDTH>;

/// The energy terms and the structure of the unknowns for one round.
struct Problem {
    alpha: f64,
    points: Vec<QuadPoint>,
    /// First parameter of each node: 3 tangent parameters if its value is free, then 4
    /// derivative parameters.
    offsets: Vec<usize>,
    params: usize,
    bandwidth: usize,
}

/// The three energies at one spline.
#[derive(Debug, Clone, Copy)]
struct Energy {
    total: f64,
    tangential: f64,
    deviation: f64,
}

impl Problem {
    fn new(nodes: &Nodes, target: &AngularVelocityTarget, alpha: f64) -> Self {
        let n = nodes.times.len();
        let mut points = Vec::with_capacity((n - 1) * QUADRATURE_POINTS);
        for segment in 0..n - 1 {
            let (t0, t1) = (nodes.times[segment], nodes.times[segment + 1]);
            let h = t1 - t0;
            for (s, w) in unit_quadrature() {
                let t = t0 + s * h;
                points.push(QuadPoint {
                    segment,
                    weight: w * h,
                    basis: hermite_weights(s, h),
                    target: target.eval(t).extend(0.0),
                });
            }
        }
        let mut offsets = Vec::with_capacity(n);
        let mut params = 0;
        let mut bandwidth = 0;
        let size = |k: usize| if nodes.fixed[k] { 4 } else { 7 };
        for k in 0..n {
            offsets.push(params);
            params += size(k);
            if k + 1 < n {
                bandwidth = bandwidth.max(size(k) + size(k + 1) - 1);
            }
        }
        Self {
            alpha,
            points,
            offsets,
            params,
            bandwidth,
        }
    }

    /// `E`, `W_T`, `W_A` by quadrature; `None` if the spline comes too close to 0.
    fn energy(&self, nodes: &Nodes) -> Option<Energy> {
        let (mut wt, mut wa) = (0.0, 0.0);
        for p in &self.points {
            let (q, q1, q2) = nodes.jet(p);
            let n = q.length_squared();
            if n.is_nan() || n < NORM_FLOOR {
                return None;
            }
            let a = 2.0 * quat_mul(q1, quat_conj(q)) / n - p.target;
            let tau = q2 - q * (q.dot(q2) / n);
            wa += p.weight * a.length_squared();
            wt += p.weight * tau.length_squared();
        }
        Some(Energy {
            total: self.alpha * wt + wa,
            tangential: wt,
            deviation: wa,
        })
    }

    /// The Gauss-Newton normal equations `J^T J`, `J^T r` and the energy `r^T r`, with the
    /// exact Jacobian of the residuals `sqrt(w) (2 q' q^-1 - omega^s)` and
    /// `sqrt(alpha w) (q'' - (q . q'') q / |q|^2)` at every quadrature point.
    fn normal_equations(&self, nodes: &Nodes) -> Option<(Hessian, Vec<f64>, f64)> {
        const E: [DVec4; 4] = [DVec4::X, DVec4::Y, DVec4::Z, DVec4::W];
        debug_assert!(self.bandwidth <= HESSIAN_BANDWIDTH);
        let mut h = Hessian::zeros(self.params);
        let mut g = vec![0.0; self.params];
        let mut cost = 0.0;
        // Tangent directions of each free node value: d(exp(d) q)/dd_i = e_i q.
        let tangents: Vec<[DVec4; 3]> = nodes
            .values
            .iter()
            .map(|&q| [0, 1, 2].map(|i| quat_mul(E[i], q)))
            .collect();
        let mut jac = [[0.0f64; 14]; 8];
        for p in &self.points {
            let (q, q1, q2) = nodes.jet(p);
            let n = q.length_squared();
            if n.is_nan() || n < NORM_FLOOR {
                return None;
            }
            let a0 = 2.0 * quat_mul(q1, quat_conj(q)) / n;
            let ra = a0 - p.target;
            let qq2 = q.dot(q2);
            let rt = q2 - q * (qq2 / n);
            let (sa, st) = (p.weight.sqrt(), (self.alpha * p.weight).sqrt());
            let mut res = [0.0; 8];
            for c in 0..4 {
                res[c] = sa * ra[c];
                res[4 + c] = st * rt[c];
            }
            cost += res.iter().map(|r| r * r).sum::<f64>();
            // Columns: derivative of each residual along unit vector e_c of q, q', q''.
            let mut dq_a = [DVec4::ZERO; 4];
            let mut dq1_a = [DVec4::ZERO; 4];
            let mut dq_t = [DVec4::ZERO; 4];
            let mut dq2_t = [DVec4::ZERO; 4];
            for c in 0..4 {
                let e = E[c];
                dq_a[c] = sa * (2.0 * quat_mul(q1, quat_conj(e)) / n - a0 * (2.0 * q[c] / n));
                dq1_a[c] = sa * (2.0 * quat_mul(e, quat_conj(q)) / n);
                dq_t[c] = st * (-(q * q2[c] + e * qq2) / n + q * (qq2 * 2.0 * q[c] / (n * n)));
                dq2_t[c] = st * (e - q * (q[c] / n));
            }
            let seg = p.segment;
            let mut col = 0;
            for (side, k) in [(0usize, seg), (1, seg + 1)] {
                let (bv, bd) = (2 * side, 2 * side + 1);
                let b = &p.basis;
                if !nodes.fixed[k] {
                    for t in &tangents[k] {
                        let mut ja = DVec4::ZERO;
                        let mut jt = DVec4::ZERO;
                        for c in 0..4 {
                            ja += t[c] * (dq_a[c] * b[0][bv] + dq1_a[c] * b[1][bv]);
                            jt += t[c] * (dq_t[c] * b[0][bv] + dq2_t[c] * b[2][bv]);
                        }
                        for r in 0..4 {
                            jac[r][col] = ja[r];
                            jac[4 + r][col] = jt[r];
                        }
                        col += 1;
                    }
                }
                for c in 0..4 {
                    let ja = dq_a[c] * b[0][bd] + dq1_a[c] * b[1][bd];
                    let jt = dq_t[c] * b[0][bd] + dq2_t[c] * b[2][bd];
                    for r in 0..4 {
                        jac[r][col] = ja[r];
                        jac[4 + r][col] = jt[r];
                    }
                    col += 1;
                }
            }
            let off = self.offsets[seg];
            for a in 0..col {
                g[off + a] += jac.iter().zip(&res).map(|(row, r)| row[a] * r).sum::<f64>();
                for b in 0..=a {
                    let s: f64 = jac.iter().map(|row| row[a] * row[b]).sum();
                    h.add(off + a, off + b, s);
                }
            }
        }
        Some((h, g, cost))
    }

    /// The nodes moved by parameter step `x`: `q <- unit(exp(d) q)`, `q' <- q' + m`.
    fn apply(&self, nodes: &Nodes, x: &[f64]) -> Nodes {
        let mut out = nodes.clone();
        for k in 0..out.times.len() {
            let mut o = self.offsets[k];
            if !out.fixed[k] {
                let d = DVec3::new(x[o], x[o + 1], x[o + 2]);
                out.values[k] = quat_mul(quat_exp(d), out.values[k]).normalize();
                o += 3;
            }
            out.derivatives[k] += DVec4::new(x[o], x[o + 1], x[o + 2], x[o + 3]);
        }
        out
    }

    /// Levenberg-Marquardt (Nielsen's damping update, Marquardt's diagonal scaling) from
    /// `nodes`. Returns the steps taken and whether it converged.
    fn minimise(&self, nodes: &mut Nodes, max_iterations: usize) -> (usize, bool) {
        let Some((mut h, mut g, mut cost)) = self.normal_equations(nodes) else {
            return (0, false);
        };
        let mut lambda = 1e-3;
        let mut nu = 2.0;
        let mut steps = 0;
        while steps < max_iterations {
            if cost <= ENERGY_FLOOR {
                return (steps, true);
            }
            let max_diag = (0..h.len()).map(|i| h.get(i, i)).fold(0.0, f64::max);
            let floor = 1e-12 * max_diag.max(f64::MIN_POSITIVE);
            let mut damped = h.clone();
            for i in 0..h.len() {
                damped.add(i, i, lambda * h.get(i, i).max(floor));
            }
            let rhs: Vec<f64> = g.iter().map(|v| -v).collect();
            steps += 1;
            let trial = damped
                .solved(&rhs)
                .map(|x| (self.apply(nodes, &x), x))
                .and_then(|(t, x)| self.energy(&t).map(|e| (t, x, e.total)));
            match trial {
                Some((t, x, new_cost)) if new_cost < cost => {
                    // Predicted decrease of the linear model: -(2 g.x + x^T H x).
                    let hx = h.mul(&x);
                    let predicted: f64 = -x
                        .iter()
                        .zip(&g)
                        .zip(&hx)
                        .map(|((xi, gi), hxi)| xi * (2.0 * gi + hxi))
                        .sum::<f64>();
                    let rho = (cost - new_cost) / predicted.max(f64::MIN_POSITIVE);
                    let small = cost - new_cost <= ENERGY_TOLERANCE * cost;
                    let was_gauss_newton = lambda <= CONVERGED_DAMPING;
                    *nodes = t;
                    lambda *= (1.0 - (2.0 * rho - 1.0).powi(3)).max(1.0 / 3.0);
                    nu = 2.0;
                    match self.normal_equations(nodes) {
                        Some((h2, g2, c2)) => {
                            h = h2;
                            g = g2;
                            cost = c2;
                        }
                        None => return (steps, false),
                    }
                    if small && was_gauss_newton {
                        return (steps, true);
                    }
                }
                _ => {
                    lambda *= nu;
                    nu *= 2.0;
                    if lambda > MAX_DAMPING {
                        return (steps, true);
                    }
                }
            }
        }
        (steps, false)
    }
}

/// The fragment errors `F_n = ∫ |2 q' q^-1 - omega^s|^2 dt` (eq. 2) over `count` equal
/// fragments of the spline's range.
fn fragment_errors(spline: &QuatSpline, target: &AngularVelocityTarget, count: usize) -> Vec<f64> {
    let (t0, t1) = spline.range();
    let dt = (t1 - t0) / count as f64;
    (0..count)
        .map(|k| {
            let a = t0 + k as f64 * dt;
            unit_quadrature()
                .map(|(s, w)| {
                    let t = a + s * dt;
                    let jet = spline.jet(t);
                    let e = jet.velocity_quaternion() - target.eval(t).extend(0.0);
                    w * dt * e.length_squared()
                })
                .sum()
        })
        .collect()
}

/// Sub-steps per key span when the target is integrated to choose the keys' signs.
pub const SIGN_STEPS: usize = 64;

/// The starting spline: the paper's `InitCurve`, made aware of the target.
///
/// A key and its negative are the same orientation, but the spline segment towards `q` or
/// `-q` turns the short or the long way round. Each key's sign is chosen so that it lies
/// closer (in R^4) to the orientation reached by integrating the target from the previous
/// key, `q <- exp(omega^s dt / 2) q` in [`SIGN_STEPS`] steps; for a target that spins by
/// less than half a turn per key span this is the paper's shortest-way choice. The
/// derivatives are those of a rotation following the target, `q'_i = (omega^s(t_i) / 2) q_i`,
/// instead of the paper's central differences, which cannot see a spin of more than half
/// a turn per key span.
fn initial_curve(
    times: &[f64],
    mut values: Vec<DVec4>,
    target: &AngularVelocityTarget,
) -> (Vec<DVec4>, Vec<DVec4>) {
    for i in 1..values.len() {
        let (a, b) = (times[i - 1], times[i]);
        let dt = (b - a) / SIGN_STEPS as f64;
        let mut q = values[i - 1];
        for j in 0..SIGN_STEPS {
            let w = target.eval(a + (j as f64 + 0.5) * dt);
            q = quat_mul(quat_exp(w * (0.5 * dt)), q);
        }
        if q.dot(values[i]) < 0.0 {
            values[i] = -values[i];
        }
    }
    let derivatives = times
        .iter()
        .zip(&values)
        .map(|(&t, &q)| 0.5 * quat_mul(target.eval(t).extend(0.0), q))
        .collect();
    (values, derivatives)
}

/// Fits a rotation to a target angular velocity, keeping the constrained keys (Xie et al.
/// 2011, Algorithm 1).
///
/// Starts from the paper's `InitCurve` with the keys normalised, their signs and the
/// derivatives taken from the target (see [`SIGN_STEPS`]), minimises `E = alpha W_T + W_A` over the
/// free control quaternions (on the unit sphere) and all control derivatives, then while
/// some fragment error `F_n` exceeds `delta` inserts variable frames at the midpoints of
/// the worst such fragments (at most `max_frames` in all, none closer than
/// [`MIN_FRAME_GAP`] fragments to a control point) and minimises again. At `t_0` the
/// orientation is the first key if it is constrained; at every constrained key time it is
/// that key exactly.
///
/// A fit that does not converge or stays above `delta` is still returned, with
/// [`AngularVelocityFit::status`] saying so; [`AngularVelocityFit::into_result`] turns that
/// into an error carrying the best result.
///
/// # Errors
/// Bad input only: [`Error::TooFew`] for fewer than 2 keys; [`Error::LengthMismatch`] when
/// `key_times` or `constrained` differ in length from `keys`; [`Error::KeyTimes`],
/// [`Error::NotFinite`], [`Error::Spacing`] for key times closer than [`MIN_KEY_SPACING`],
/// [`Error::Value`], [`Error::Limit`] and [`Error::Conflict`] for
/// NaN keys, zero-length keys, a target that does not cover the key range or options out of
/// range.
pub fn fit_angular_velocity(
    keys: &[DQuat],
    key_times: &[f64],
    constrained: &[bool],
    target: &AngularVelocityTarget,
    options: &FitOptions,
) -> Result<AngularVelocityFit> {
    options.check()?;
    for (index, &t) in key_times.iter().enumerate() {
        check_fit_time("key time", index, t)?;
        if index > 0 && t - key_times[index - 1] < MIN_KEY_SPACING {
            // (Not increasing at all is reported by check_keys below.)
            if t > key_times[index - 1] {
                return Err(Error::Spacing {
                    what: "key times",
                    at: At::new("key time", index),
                    gap: t - key_times[index - 1],
                    min: MIN_KEY_SPACING,
                });
            }
        }
    }
    fit_footprint(keys.len(), target.times.len(), options).check("the fit", FIT_HINT)?;
    let values = check_keys(key_times, keys)?;
    if constrained.len() != keys.len() {
        return Err(Error::LengthMismatch {
            what: "constrained flags",
            expected: keys.len(),
            got: constrained.len(),
        });
    }
    let k = keys.len();
    let (t0, t1) = (key_times[0], key_times[k - 1]);
    let span = t1 - t0;
    let slack = TIME_TOLERANCE * span;
    let (s0, s1) = (target.times[0], target.times[target.times.len() - 1]);
    if s0 > t0 + slack || s1 < t1 - slack {
        return Err(Error::Conflict {
            what: "target",
            reason: format!("its times [{s0}, {s1}] do not cover the key range [{t0}, {t1}]"),
        });
    }
    let (values, derivatives) = initial_curve(key_times, values, target);
    let fragments = match options.fragment_duration {
        Some(d) => {
            let count = (span / d).round();
            if !(count <= MAX_FRAGMENTS as f64) {
                return Err(Error::Value {
                    what: "fragment_duration",
                    at: None,
                    value: d,
                    expected: Expected::AtLeastCutting {
                        min: span / MAX_FRAGMENTS as f64,
                        range: span,
                        limit: MAX_FRAGMENTS,
                        counted: "fragments of the key range",
                    },
                });
            }
            (count as usize).max(1)
        }
        None => (FRAGMENTS_PER_KEY_SPAN * (k - 1)).max(MIN_FRAGMENTS),
    };
    Footprint::of::<[f64; 3]>(fragments).check("fit fragments", FIT_HINT)?;
    let fragment_duration = span / fragments as f64;
    let mut nodes = Nodes {
        times: key_times.to_vec(),
        values,
        derivatives,
        fixed: constrained.to_vec(),
        key: (0..k).map(Some).collect(),
    };
    let mut iterations = 0;
    let mut rounds = 0;
    let mut frames = 0;
    let (status, errors, energy) = loop {
        let problem = Problem::new(&nodes, target, options.alpha);
        let (steps, converged) = problem.minimise(&mut nodes, options.max_iterations);
        iterations += steps;
        rounds += 1;
        let spline = nodes.spline();
        let errors = fragment_errors(&spline, target, fragments);
        let energy = problem.energy(&nodes);
        let worst = errors.iter().copied().fold(0.0, f64::max);
        if !converged {
            break (FitStatus::IterationLimit, errors, energy);
        }
        if worst <= options.delta {
            break (FitStatus::Converged, errors, energy);
        }
        // VariableFrames: midpoints of the worst fragments above delta.
        let mut order: Vec<usize> = (0..fragments)
            .filter(|&i| errors[i] > options.delta)
            .collect();
        order.sort_by(|&a, &b| errors[b].total_cmp(&errors[a]));
        let mut inserted = 0;
        // One new frame per spline segment and round: the segment's worst fragment.
        let mut used_segments = Vec::new();
        for i in order {
            if frames >= options.max_frames {
                break;
            }
            let t = t0 + (i as f64 + 0.5) * fragment_duration;
            let at = nodes.times.partition_point(|&x| x < t);
            let gap = MIN_FRAME_GAP * fragment_duration;
            let near = |j: usize| nodes.times.get(j).is_some_and(|&x| (x - t).abs() < gap);
            let segment = spline.segment(t);
            if near(at) || (at > 0 && near(at - 1)) || used_segments.contains(&segment) {
                continue;
            }
            used_segments.push(segment);
            let jet = spline.jet(t);
            let norm = jet.value.length();
            let value = jet.value / norm;
            // The derivative of q/|q|: (q' - (q.q') q/|q|^2) / |q|.
            let derivative =
                (jet.first - jet.value * (jet.value.dot(jet.first) / (norm * norm))) / norm;
            nodes.times.insert(at, t);
            nodes.values.insert(at, value);
            nodes.derivatives.insert(at, derivative);
            nodes.fixed.insert(at, false);
            nodes.key.insert(at, None);
            frames += 1;
            inserted += 1;
        }
        if inserted == 0 {
            break (FitStatus::AboveDelta, errors, energy);
        }
    };
    let spline = nodes.spline();
    let fitted_keys = nodes
        .key
        .iter()
        .zip(&nodes.values)
        .filter_map(|(k, v)| k.map(|_| DQuat::from_vec4(*v)))
        .collect();
    let frame_times = nodes
        .key
        .iter()
        .zip(&nodes.times)
        .filter_map(|(k, t)| k.is_none().then_some(*t))
        .collect();
    let energy = energy.unwrap_or(Energy {
        total: f64::INFINITY,
        tangential: f64::INFINITY,
        deviation: f64::INFINITY,
    });
    // Finite in, finite out: inside the working ranges nothing overflows; should anything
    // still, say so rather than report NaN.
    let finite = errors.iter().all(|e| e.is_finite())
        && spline.values().iter().all(|v| v.is_finite())
        && spline.derivatives().iter().all(|v| v.is_finite());
    if !finite {
        return Err(Error::Overflow {
            what: "fit",
            at: None,
            hint: "scale times or angular velocities towards seconds and radians per second",
        });
    }
    Ok(AngularVelocityFit {
        spline,
        keys: fitted_keys,
        frame_times,
        fit_error: errors.iter().copied().fold(0.0, f64::max),
        fragment_errors: errors,
        fragment_duration,
        energy: energy.total,
        tangential: energy.tangential,
        deviation: energy.deviation,
        iterations,
        rounds,
        status,
        delta: options.delta,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::angular_velocity::spinning_top::SpinningTop;

    /// The angle of the rotation taking `a` to `b`.
    fn angle(a: DQuat, b: DQuat) -> f64 {
        let d = DVec4::from(a.conjugate() * b);
        2.0 * d.truncate().length().atan2(d.w.abs())
    }

    fn sampled_target(
        f: impl Fn(f64) -> DVec3,
        t0: f64,
        t1: f64,
        n: usize,
    ) -> AngularVelocityTarget {
        let times: Vec<f64> = (0..n)
            .map(|j| t0 + (t1 - t0) * j as f64 / (n - 1) as f64)
            .collect();
        let omega: Vec<DVec3> = times.iter().map(|&t| f(t)).collect();
        AngularVelocityTarget::new(&times, &omega).unwrap()
    }

    fn top_keys(top: &SpinningTop, n: usize, duration: f64) -> (Vec<f64>, Vec<DQuat>) {
        let times: Vec<f64> = (0..n)
            .map(|i| duration * i as f64 / (n - 1) as f64)
            .collect();
        let keys = times.iter().map(|&t| top.rotation(t)).collect();
        (times, keys)
    }

    #[test]
    fn gradient_is_exact() {
        let top = SpinningTop::default();
        let (times, keys) = top_keys(&top, 5, 1.0);
        let target = sampled_target(|t| top.target(t), 0.0, 1.0, 50);
        let values = check_keys(&times, &keys).unwrap();
        let init = QuatSpline::through(&times, &keys).unwrap();
        let nodes = Nodes {
            times: times.clone(),
            values,
            derivatives: init.derivatives().to_vec(),
            fixed: vec![true, false, true, false, false],
            key: (0..5).map(Some).collect(),
        };
        let problem = Problem::new(&nodes, &target, 0.01);
        let (h, g, cost) = problem.normal_equations(&nodes).unwrap();
        let e0 = problem.energy(&nodes).unwrap().total;
        assert!((cost - e0).abs() < 1e-12 * e0, "{cost} vs {e0}");
        let eps = 1e-6;
        let mut x = vec![0.0; problem.params];
        for i in 0..problem.params {
            x[i] = eps;
            let plus = problem.energy(&problem.apply(&nodes, &x)).unwrap().total;
            x[i] = -eps;
            let minus = problem.energy(&problem.apply(&nodes, &x)).unwrap().total;
            x[i] = 0.0;
            let fd = (plus - minus) / (2.0 * eps);
            // dE/dx = 2 J^T r
            assert!(
                (fd - 2.0 * g[i]).abs() < 1e-5 * (1.0 + fd.abs()),
                "param {i}: finite difference {fd} vs analytic {}",
                2.0 * g[i]
            );
            assert!(h.get(i, i) >= 0.0);
        }
    }

    #[test]
    fn constant_speed_rotation_is_kept() {
        let axis = DVec3::new(1.0, 2.0, -3.0).normalize();
        let rate = 3.0;
        let start = DQuat::from_rotation_x(0.4);
        let exact = |t: f64| DQuat::from_axis_angle(axis, rate * t) * start;
        let times: Vec<f64> = (0..11).map(|i| 0.2 * i as f64).collect();
        let keys: Vec<DQuat> = times.iter().map(|&t| exact(t)).collect();
        let target = sampled_target(|_| axis * rate, 0.0, 2.0, 3);
        for constrained in [vec![true; 11], {
            let mut c = vec![false; 11];
            c[0] = true;
            c
        }] {
            let fit =
                fit_angular_velocity(&keys, &times, &constrained, &target, &FitOptions::default())
                    .unwrap();
            println!(
                "constant speed ({} constrained): fit error {:.3e}, energy {:.3e}, {} iterations, {} frames",
                constrained.iter().filter(|c| **c).count(),
                fit.fit_error,
                fit.energy,
                fit.iterations,
                fit.frame_times.len()
            );
            assert!(fit.converged(), "{:?}", fit.status);
            assert!(fit.fit_error < 1e-6, "fit error {}", fit.fit_error);
            assert!(fit.frame_times.is_empty());
            let mut worst = 0.0f64;
            for j in 0..=200 {
                let t = 2.0 * j as f64 / 200.0;
                worst = worst.max(angle(fit.rotation(t), exact(t)));
            }
            for (k, key) in fit.keys.iter().zip(&keys) {
                worst = worst.max(angle(*k, *key));
            }
            println!("  largest change from the exact rotation {worst:.3e} rad");
            // What remains is the cubic's deviation from a great circle at 0.6 rad per span.
            assert!(worst < 1e-5, "changed by {worst} rad");
            let w_err = (0..=200)
                .map(|j| (fit.angular_velocity(2.0 * j as f64 / 200.0) - axis * rate).length())
                .fold(0.0, f64::max);
            assert!(w_err < 1e-3 * rate, "angular velocity off by {w_err}");
        }
    }

    /// Figures of a fit against the spinning top's sketch.
    struct TopFigures {
        worst_direction: f64,
        mean_direction: f64,
        worst_unit: f64,
        worst_constrained: f64,
        free_moves: Vec<f64>,
    }

    /// The paper's figure 3: `n` keys of a precessing top over 4 s, every third key and the
    /// last constrained, the target sketched with a wobble pattern.
    fn top_fit(n: usize) -> (AngularVelocityFit, TopFigures) {
        let top = SpinningTop::default();
        let (times, keys) = top_keys(&top, n, 4.0);
        let target = sampled_target(|t| top.target(t), 0.0, 4.0, 241);
        let constrained: Vec<bool> = (0..n).map(|i| i % 3 == 0 || i == n - 1).collect();
        let fit =
            fit_angular_velocity(&keys, &times, &constrained, &target, &FitOptions::default())
                .unwrap();
        let (mut worst_direction, mut sum, mut worst_unit) = (0.0f64, 0.0, 0.0f64);
        let samples = 2000;
        for j in 0..=samples {
            let t = 4.0 * j as f64 / samples as f64;
            let a = fit.angular_velocity(t).angle_between(top.target(t));
            worst_direction = worst_direction.max(a);
            sum += a;
            worst_unit = worst_unit.max((fit.rotation(t).length() - 1.0).abs());
        }
        let moves = |want: bool| -> Vec<f64> {
            constrained
                .iter()
                .zip(fit.keys.iter().zip(&keys))
                .filter(|(c, _)| **c == want)
                .map(|(_, (a, b))| angle(*a, *b))
                .collect()
        };
        let figures = TopFigures {
            worst_direction,
            mean_direction: sum / (samples + 1) as f64,
            worst_unit,
            worst_constrained: moves(true).into_iter().fold(0.0, f64::max),
            free_moves: moves(false),
        };
        println!(
            "spinning top, {n} keys ({} constrained): {:?}, fit error {:.4} (delta {}), \
             {} variable frames, {} iterations in {} rounds",
            constrained.iter().filter(|c| **c).count(),
            fit.status,
            fit.fit_error,
            fit.delta,
            fit.frame_times.len(),
            fit.iterations,
            fit.rounds
        );
        println!(
            "  omega direction vs sketch: max {:.2} deg, mean {:.2} deg (wobble loops of {:.0} deg)",
            figures.worst_direction.to_degrees(),
            figures.mean_direction.to_degrees(),
            top.wobble_amplitude.to_degrees()
        );
        println!(
            "  constrained keys off by {:.1e} rad; free keys moved {:.3}..{:.3} rad; unit error {:.1e}",
            figures.worst_constrained,
            figures.free_moves.iter().copied().fold(f64::INFINITY, f64::min),
            figures.free_moves.iter().copied().fold(0.0, f64::max),
            figures.worst_unit
        );
        (fit, figures)
    }

    #[test]
    fn spinning_top_fits_within_delta() {
        // 20 keys (the benchmark's case): the keys are dense enough, no frame is needed.
        let (fit, f) = top_fit(20);
        assert!(fit.converged(), "{:?}", fit.status);
        assert!(fit.fit_error < fit.delta, "fit error {}", fit.fit_error);
        assert!(fit.frame_times.len() <= 10);
        assert!(
            f.worst_direction < 8f64.to_radians(),
            "direction off by {} rad",
            f.worst_direction
        );
        assert!(
            f.mean_direction < 3f64.to_radians(),
            "direction off by {} rad",
            f.mean_direction
        );
        assert!(
            f.worst_constrained < 1e-9,
            "constrained keys moved {}",
            f.worst_constrained
        );
        assert!(f.worst_unit < 1e-12);
        assert!(
            f.free_moves.iter().all(|m| *m > 1e-3),
            "free keys moved {:?}",
            f.free_moves
        );
    }

    #[test]
    fn sparse_spinning_top_needs_variable_frames() {
        // 10 keys, 0.44 s and more than half a turn apart: the loop inserts frames.
        let (fit, f) = top_fit(10);
        assert!(fit.converged(), "{:?}", fit.status);
        assert!(fit.fit_error < fit.delta, "fit error {}", fit.fit_error);
        assert!(!fit.frame_times.is_empty() && fit.frame_times.len() <= 10);
        assert!(fit.rounds > 1);
        assert!(
            f.worst_direction < 8f64.to_radians(),
            "direction off by {} rad",
            f.worst_direction
        );
        assert!(f.worst_constrained < 1e-9);
        assert!(f.worst_unit < 1e-12);
        assert!(
            f.free_moves.iter().all(|m| *m > 1e-3),
            "free keys moved {:?}",
            f.free_moves
        );
        // Frames sit at fragment midpoints, strictly inside the range, away from the keys.
        for t in &fit.frame_times {
            assert!(*t > 0.0 && *t < 4.0);
        }
    }

    #[test]
    fn infeasible_or_unfinished_fits_say_so_and_keep_the_best() {
        // Identity at both ends, constrained, but the target spins 10 rad in 1 s: the
        // rotation cannot end where it started.
        let keys = [DQuat::IDENTITY, DQuat::IDENTITY];
        let target = sampled_target(|_| DVec3::Z * 10.0, 0.0, 1.0, 2);
        let options = FitOptions {
            max_frames: 2,
            ..FitOptions::default()
        };
        let fit =
            fit_angular_velocity(&keys, &[0.0, 1.0], &[true, true], &target, &options).unwrap();
        assert_eq!(fit.status, FitStatus::AboveDelta);
        assert!(fit.frame_times.len() <= 2);
        let failure = fit.clone().into_result().unwrap_err();
        assert!(failure.to_string().contains("infeasible"), "{failure}");
        assert!(
            matches!(&failure, Error::FitFailed { best } if **best == fit),
            "{failure:?}"
        );
        // Keys still hold in the best result.
        assert!(angle(fit.rotation(1.0), DQuat::IDENTITY) < 1e-12);

        let options = FitOptions {
            max_iterations: 1,
            ..FitOptions::default()
        };
        let top = SpinningTop::default();
        let (times, keys) = top_keys(&top, 6, 2.0);
        let target = sampled_target(|t| top.target(t), 0.0, 2.0, 50);
        let fit = fit_angular_velocity(&keys, &times, &[true; 6], &target, &options).unwrap();
        assert_eq!(fit.status, FitStatus::IterationLimit);
        assert_eq!(fit.iterations, 1);
        let failure = fit.into_result().unwrap_err();
        assert!(
            failure.to_string().contains("did not converge"),
            "{failure}"
        );
    }

    #[test]
    fn bad_input_is_rejected_clearly() {
        let q = DQuat::IDENTITY;
        let ok = sampled_target(|_| DVec3::Z, 0.0, 1.0, 3);
        let o = FitOptions::default();
        let fit = |keys: &[DQuat],
                   times: &[f64],
                   c: &[bool],
                   t: &AngularVelocityTarget,
                   o: &FitOptions| {
            fit_angular_velocity(keys, times, c, t, o).unwrap_err()
        };
        // No keys, one key.
        assert_eq!(
            fit(&[], &[], &[], &ok, &o),
            Error::TooFew { got: 0, need: 2 }
        );
        assert_eq!(
            fit(&[q], &[0.0], &[true], &ok, &o),
            Error::TooFew { got: 1, need: 2 }
        );
        // Zero-length key range.
        assert_eq!(
            fit(&[q, q], &[0.5, 0.5], &[true; 2], &ok, &o),
            Error::KeyTimes { index: 1 }
        );
        // NaN key, zero key.
        let nan = DQuat::from_xyzw(0.0, f64::NAN, 0.0, 1.0);
        assert!(matches!(
            fit(&[q, nan], &[0.0, 1.0], &[true; 2], &ok, &o),
            Error::NotFinite { index: 1, .. }
        ));
        let zero = DQuat::from_xyzw(0.0, 0.0, 0.0, 0.0);
        let e = fit(&[zero, q], &[0.0, 1.0], &[true; 2], &ok, &o);
        assert!(e.to_string().contains("key 0"), "{e}");
        // Constrained flags of the wrong length.
        assert!(matches!(
            fit(&[q, q], &[0.0, 1.0], &[true], &ok, &o),
            Error::LengthMismatch { .. }
        ));
        // Target: NaN, zero-length range, not covering the keys.
        let e =
            AngularVelocityTarget::new(&[0.0, 1.0], &[DVec3::Z, DVec3::new(f64::NAN, 0.0, 0.0)])
                .unwrap_err();
        assert_eq!(
            e,
            Error::NotFinite {
                what: "target angular velocity",
                index: 1
            }
        );
        let e = AngularVelocityTarget::new(&[0.0, 0.0], &[DVec3::Z, DVec3::Z]).unwrap_err();
        assert!(e.to_string().contains("increase strictly"), "{e}");
        let e = AngularVelocityTarget::new(&[0.0], &[DVec3::Z]).unwrap_err();
        assert!(e.to_string().contains("at least 2"), "{e}");
        let short = sampled_target(|_| DVec3::Z, 0.0, 0.5, 3);
        let e = fit(&[q, q], &[0.0, 1.0], &[true; 2], &short, &o);
        assert!(e.to_string().contains("do not cover"), "{e}");
        // Options.
        for bad in [
            FitOptions { alpha: -1.0, ..o },
            FitOptions { delta: 0.0, ..o },
            FitOptions {
                delta: f64::NAN,
                ..o
            },
            FitOptions {
                max_iterations: 0,
                ..o
            },
            FitOptions {
                fragment_duration: Some(0.0),
                ..o
            },
        ] {
            assert!(
                matches!(
                    fit(&[q, q], &[0.0, 1.0], &[true; 2], &ok, &bad),
                    Error::Value { at: None, .. }
                ),
                "{bad:?}"
            );
        }
    }

    #[test]
    fn directions_are_normalised_and_zero_directions_rejected() {
        let t = AngularVelocityTarget::from_directions(
            &[0.0, 1.0],
            &[DVec3::new(0.0, 0.0, 3.0), DVec3::new(0.5, 0.0, 0.0)],
            &[2.0, 4.0],
        )
        .unwrap();
        assert_eq!(
            t.omega(),
            &[DVec3::new(0.0, 0.0, 2.0), DVec3::new(4.0, 0.0, 0.0)]
        );
        assert_eq!(t.eval(0.5), DVec3::new(2.0, 0.0, 1.0));
        let e = AngularVelocityTarget::from_directions(
            &[0.0, 1.0],
            &[DVec3::Z, DVec3::ZERO],
            &[1.0, 1.0],
        )
        .unwrap_err();
        assert!(e.to_string().contains("direction 1"), "{e}");
        let e = AngularVelocityTarget::from_directions(
            &[0.0, 1.0],
            &[DVec3::Z, DVec3::Z],
            &[1.0, f64::NAN],
        )
        .unwrap_err();
        assert!(matches!(
            e,
            Error::NotFinite {
                what: "target speed",
                index: 1
            }
        ));
    }

    #[test]
    fn samples_are_unit_and_sign_continuous() {
        let (fit, _) = top_fit(20);
        let times: Vec<f64> = (0..=400).map(|j| 4.0 * j as f64 / 400.0).collect();
        let q = fit.sample(&times).unwrap();
        for (i, w) in q.windows(2).enumerate() {
            assert!(w[0].dot(w[1]) > 0.0, "sign flip at sample {i}");
            assert!((w[1].length() - 1.0).abs() < 1e-12);
        }
        assert!(fit
            .sample(&[4.5])
            .unwrap_err()
            .to_string()
            .contains("outside"));
        assert!(matches!(
            fit.sample(&[f64::NAN]).unwrap_err(),
            Error::NotFinite { .. }
        ));
    }
}
