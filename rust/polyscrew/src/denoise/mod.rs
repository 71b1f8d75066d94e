//! Remove noise from a captured rigid motion: a coordinate-free smoothing spline on the
//! rotation group and on the path of one body point, with its strengths chosen from the data.
//!
//! # The method
//!
//! Dense noisy poses `P_i = (Q_i, o_i)` at times `t_i` (one per frame from a camera solve,
//! motion capture or a baked simulation) are replaced by the poses `X_i = (R_i, p_i - R_i c)`
//! that minimise two penalised least-squares energies, each a smoothing spline (Reinsch,
//! "Smoothing by spline functions", 1967; Wahba, *Spline models for observational data*,
//! 1990) on a space where it is coordinate-free:
//!
//! ```text
//! rotation:     sum_i h_i |log(Q_i R_i^-1)|^2     + lambda_r sum_k u_k |D_k y(R)|^2
//! translation:  sum_i h_i |p_i - (Q_i c + o_i)|^2 + lambda_t sum_k u_k |D_k p|^2
//! ```
//!
//! - `c` is the *pivot* (`pivot.rs`), a body point chosen from the data: the point of least
//!   jitter, then refined to the point whose path the spline changes least. Its world path is
//!   the translation that is smoothed. It moves with the body, so the result does not depend
//!   on where the body's origin is.
//! - `y(R)` is the development of the spatial increments `log(R_{j+1} R_j^-1)` and `D_k` are
//!   divided differences of order `m` (3 by default: a quintic spline, which keeps constant
//!   accelerations; 2 gives the cubic spline) on the given, possibly uneven, times
//!   (`stencil.rs`), `h_i` the time each pose stands for, `u_k` 1 or 0 (a kink). Rotation
//!   vectors' norms do not change when every pose is multiplied by one rotation on either
//!   side, and world distances do not change under a rigid motion of the world, so for any
//!   rigid `G`, `H`: `denoise(G P H) = G denoise(P) H` (with automatic strengths too:
//!   everything they are chosen from is invariant; measured to 1e-9 and better in
//!   `tests/denoise_properties.rs`).
//! - A rotation at constant angular velocity and a pivot moving at constant velocity (for
//!   `m = 3`, constant acceleration) cost nothing: such motion, in particular every screw
//!   motion (its pivot lies on the axis), comes back unchanged.
//! - The rotation energy is minimised by Gauss-Newton (`rotation.rs`), the translation one is
//!   a linear band system (`smoother.rs`): both are `O(n)`, one call per clip.
//! - `lambda = tau^(2m)`: the strength `tau` is a time (in the units of the times) with the
//!   frequency response `1 / (1 + (tau omega)^(2m))`: motion faster than about `2 pi tau` per
//!   cycle is removed. Rotation and translation have their own (noise of 2 cm and of 0.5
//!   degrees are different things), chosen by generalised cross-validation (Craven and
//!   Wahba, 1979) on the linear model unless given.
//! - Kinks (a prop that stops dead, a foot that plants) are found in a pilot fit and the
//!   penalty is released there (`kinks.rs`), so a hard stop stays sharp instead of being
//!   rounded over the spline's time scale.
//! - Pops (a jump far faster than the motion around it: a tracker re-acquiring its target,
//!   a teleport) cut the clip into pieces that are smoothed apart, each with its own
//!   strengths (`pops.rs`); the jump stays as captured. Pieces of fewer than
//!   [`MIN_DENOISE_POSES`] poses are kept as they are.
//! - Held poses (`held[i]`) are kept exactly; the smooth motion passes through them.
//! - The work is done in a normalised time (the median spacing of a piece's times is 1):
//!   the result does not depend on the unit of the times beyond rounding, and keys as
//!   close as `1e-300` apart are served like keys one frame apart. A given strength above
//!   [`MAX_STRENGTH_SPACINGS`] spacings acts as that many (the one the result reports).
//!
//! What was measured to choose this (`scripts/bench/bench_denoise.py`, the tables in
//! BENCHMARKS.md, the alternatives in `docs/denoise.md`): the SE(3) spline on logarithms
//! relative to each pose (screw motions as the straight lines) smooths a spinning object that
//! travels along a curve badly, because in its geometry the translation of a spinning body
//! oscillates; splitting rotation and the pivot's path keeps both smooth. Order 3 beat order
//! 2 on every smooth clip; robust (Huber, Cauchy) reweighting of the penalty rounded a hard
//! stop almost as much as no reweighting, releasing the rows at detected kinks did not.

pub(crate) mod kinks;
pub(crate) mod pivot;
pub(crate) mod pops;
pub(crate) mod rotation;
mod rows;
pub(crate) mod smoother;
pub(crate) mod so3;
pub(crate) mod stencil;

pub use rows::{denoise_footprint, denoised_rows, DENOISE_BYTES_PER_POSE, DENOISE_HINT};

use glam::{DQuat, DVec3};

use crate::{Error, Expected, Pose, PoseDefect, Result};
use rotation::RotationSpline;
use smoother::{Gcv, Whittaker};
use stencil::Stencils;

/// The fewest poses [`denoise`] accepts (a third difference needs four).
pub const MIN_DENOISE_POSES: usize = 4;

/// Times the pivot is refined at the translation's strength (`pivot::refine`): the second
/// refinement still moved it on the hard stop clip, a third did not.
pub const PIVOT_REFINEMENTS: usize = 2;

/// The most poses of one clip [`denoise`] accepts (about 12 hours at 24 frames per second;
/// its scratch memory is about 1 kB per pose).
pub const MAX_DENOISE_POSES: usize = 1_000_000;

/// The most poses (bodies times frames) one [`denoise_batch`] call accepts.
pub const MAX_DENOISE_BATCH: usize = 20_000_000;

/// The automatic strength is searched between this many times the median spacing of the
/// times...
pub const AUTO_MIN_SPACINGS: f64 = 0.25;

/// ... and this many times the median spacing (or the clip's span, if shorter).
pub const AUTO_MAX_SPACINGS: f64 = 100.0;

/// The largest strength used, in median spacings of the times: a larger given strength
/// acts as this one (and the result reports it). Beyond it the band system
/// `H + tau^6 M` (with `M` of size about 20 per spacing) loses every digit: measured, it
/// fails from about 300 spacings on an even clip. At 100 spacings the spline's frequency
/// response already removes every period shorter than about 600 spacings: on a clip
/// shorter than that the result is within rounding of the least-squares polynomial of
/// degree `m - 1` that an infinite strength gives.
pub const MAX_STRENGTH_SPACINGS: f64 = 100.0;

/// How strongly to smooth.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum Strength {
    /// Chosen from the data by generalised cross-validation, for rotation and translation
    /// apart.
    #[default]
    Auto,
    /// Given time scales `tau` (in the units of the times, 0 = leave as is): rotation and
    /// translation.
    Fixed {
        /// The rotation's `tau`.
        rotation: f64,
        /// The translation's `tau`.
        translation: f64,
    },
}

/// Options of [`denoise`].
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DenoiseOptions {
    /// The strength (default automatic).
    pub strength: Strength,
    /// The order `m` of the divided differences penalised: 3 (default, quintic spline:
    /// constant acceleration is free) or 2 (cubic spline: constant velocity is free).
    pub order: usize,
    /// Let kinks through (default true): an abrupt turn (a second difference of a pilot fit
    /// six times the median one) is kept sharp instead of rounded (see the module
    /// documentation).
    pub kinks: bool,
}

impl Default for DenoiseOptions {
    fn default() -> Self {
        Self {
            strength: Strength::Auto,
            order: 3,
            kinks: true,
        }
    }
}

/// The denoised motion and what was chosen on the way.
#[derive(Debug, Clone, PartialEq)]
pub struct Denoised {
    /// The smooth poses, one per input pose (held ones exactly as given).
    pub poses: Vec<Pose>,
    /// The rotation's strength `tau` (chosen or given), in the units of the times.
    pub rotation_strength: f64,
    /// The translation's strength `tau`.
    pub translation_strength: f64,
    /// The pivot `c` in body coordinates: the point whose world path was smoothed.
    pub pivot: DVec3,
    /// Estimated noise of the input's rotation: standard deviation per axis, radians
    /// (`sqrt(RSS / (3 (n - tr A)))` of the linear model at the strength used).
    pub rotation_noise: f64,
    /// Estimated noise of the pivot's position, per axis, in the units of the poses.
    pub translation_noise: f64,
    /// Samples where a kink in the rotation was let through.
    pub rotation_kinks: Vec<usize>,
    /// Samples where a kink in the translation was let through.
    pub translation_kinks: Vec<usize>,
    /// Gauss-Newton iterations of the rotation solve.
    pub iterations: usize,
    /// Whether the rotation solve converged (its last step below `1e-10` rad).
    pub converged: bool,
    /// Pops (see the module documentation): the index of the first pose after each jump
    /// the clip was cut at, increasing. The strengths, noise and pivot above are those of
    /// the longest piece; kinks and iterations are those of every piece.
    pub pops: Vec<usize>,
}

impl Denoised {
    /// The smooth poses as 4x4 matrices row by row (Blender's layout), 16 values per pose,
    /// into `out`: a held pose (`held[i]`) is the next matrix of `source` bit for bit (the
    /// held poses' matrices as they were read, in order: a matrix read into a quaternion
    /// and written back may differ in the last bit), the others [`Pose::to_rows`]. Returns
    /// how many matrices of `source` were used.
    ///
    /// # Panics
    /// If `out` holds fewer than 16 values per pose, or `source` fewer matrices than there
    /// are held poses (a caller's bug, not user data).
    pub fn write_rows(
        &self,
        held: Option<&[bool]>,
        source: &[[[f64; 4]; 4]],
        out: &mut [f64],
    ) -> usize {
        let mut used = 0;
        for (i, (p, dst)) in self.poses.iter().zip(out.chunks_exact_mut(16)).enumerate() {
            let rows = if held.is_some_and(|h| h[i]) {
                used += 1;
                source[used - 1]
            } else {
                p.to_rows()
            };
            for (d, v) in dst.iter_mut().zip(rows.iter().flatten()) {
                *d = *v;
            }
        }
        used
    }
}

/// Scratch memory, reused between clips (one per thread in [`denoise_batch`]).
#[derive(Debug, Default)]
struct Workspace {
    common: Common,
    w2: Whittaker<2>,
    w3: Whittaker<3>,
    rot2: RotationSpline<2>,
    rot3: RotationSpline<3>,
}

/// The scratch both orders use.
#[derive(Debug, Default)]
struct Common {
    st: Stencils,
    st2: Stencils,
    y_t: Vec<DVec3>,
    y_r: Vec<DVec3>,
    u_t: Vec<f64>,
    u_r: Vec<f64>,
    quats: Vec<DQuat>,
    origins: Vec<DVec3>,
    times: Vec<f64>,
    r: Vec<DQuat>,
    scratch: Vec<f64>,
    paths: [Vec<DVec3>; 4],
    zs: [Vec<DVec3>; 4],
}

/// Estimates the true motion from noisy poses (see the module documentation).
///
/// `poses` at strictly increasing `times` (frames or seconds; uneven spacing is fine);
/// `held[i]` keeps pose `i` exactly. One call smooths the whole clip in `O(n)`.
///
/// # Errors
/// [`Error::TooFew`] for fewer than [`MIN_DENOISE_POSES`] poses; [`Error::Limit`] for more
/// than [`MAX_DENOISE_POSES`], [`Error::Value`] for an order other than 2 or 3, a strength that is negative or not
/// finite, [`Error::Overflow`] for values so large that the computation overflows; [`Error::LengthMismatch`] when
/// `times` or `held` do not match `poses`; [`Error::KeyTimes`] for times that are not finite
/// and increasing; [`Error::BadPose`] for a pose with a non-finite or zero rotation or a
/// non-finite translation.
pub fn denoise(
    poses: &[Pose],
    times: &[f64],
    held: Option<&[bool]>,
    options: &DenoiseOptions,
) -> Result<Denoised> {
    check(poses.len(), times, options)?;
    denoise_with(&mut Workspace::default(), poses, times, held, options)
}

/// [`denoise`] for many bodies sampled at the same times: `poses` holds `bodies` clips of
/// `times.len()` poses one after the other (body-major), `held` (if given) the same layout.
/// Bodies are spread over `threads` threads (0, or more than the machine has: as many as it
/// has). Each body's result or error is returned in order.
///
/// # Errors
/// The checks of [`denoise`] that concern every body (times, order, strength, sizes:
/// [`MAX_DENOISE_BATCH`] poses at most), and [`Error::LengthMismatch`] when `poses` or
/// `held` do not hold `bodies * times.len()` entries.
pub fn denoise_batch(
    poses: &[Pose],
    bodies: usize,
    times: &[f64],
    held: Option<&[bool]>,
    options: &DenoiseOptions,
    threads: usize,
) -> Result<Vec<Result<Denoised>>> {
    let n = times.len();
    if n > MAX_DENOISE_POSES {
        return Err(Error::Limit {
            what: "poses",
            counted: "poses per clip",
            count: n,
            limit: MAX_DENOISE_POSES,
            hint: "",
        });
    }
    let total = bodies
        .checked_mul(n)
        .filter(|t| *t <= MAX_DENOISE_BATCH)
        .ok_or(Error::Limit {
            what: "poses",
            counted: "poses of all bodies",
            count: bodies.saturating_mul(n),
            limit: MAX_DENOISE_BATCH,
            hint: "",
        })?;
    if poses.len() != total {
        return Err(Error::LengthMismatch {
            what: "poses",
            expected: total,
            got: poses.len(),
        });
    }
    if let Some(h) = held {
        if h.len() != total {
            return Err(Error::LengthMismatch {
                what: "held",
                expected: total,
                got: h.len(),
            });
        }
    }
    // The times and options are checked even for no bodies: a call is valid or not
    // whatever the number of bodies.
    check(n, times, options)?;
    if bodies == 0 {
        return Ok(Vec::new());
    }
    // More threads than cores gains nothing; the count is bounded so that a huge request
    // cannot exhaust the system.
    let cores = std::thread::available_parallelism().map_or(1, |p| p.get());
    let threads = if threads == 0 { cores } else { threads }
        .min(cores)
        .min(bodies);
    let run = |range: std::ops::Range<usize>| {
        let mut ws = Workspace::default();
        range
            .map(|b| {
                let clip = &poses[b * n..(b + 1) * n];
                let h = held.map(|h| &h[b * n..(b + 1) * n]);
                denoise_with(&mut ws, clip, times, h, options)
            })
            .collect::<Vec<_>>()
    };
    if threads <= 1 {
        return Ok(run(0..bodies));
    }
    let per = bodies.div_ceil(threads);
    let parts = std::thread::scope(|scope| {
        let handles: Vec<_> = (0..threads)
            .map(|t| {
                let range = (t * per).min(bodies)..((t + 1) * per).min(bodies);
                scope.spawn(move || run(range))
            })
            .collect();
        handles.into_iter().map(|h| h.join()).collect::<Vec<_>>()
    });
    let mut results = Vec::with_capacity(bodies);
    for part in parts {
        // A worker only fails by a bug (the core does not panic on data): report it.
        results.extend(part.map_err(|_| Error::Worker { what: "poses" })?);
    }
    Ok(results)
}

/// The checks shared by one clip and a batch.
fn check(n: usize, times: &[f64], options: &DenoiseOptions) -> Result<()> {
    if n > MAX_DENOISE_POSES {
        return Err(Error::Limit {
            what: "poses",
            counted: "poses",
            count: n,
            limit: MAX_DENOISE_POSES,
            hint: "",
        });
    }
    if n < MIN_DENOISE_POSES {
        return Err(Error::TooFew {
            got: n,
            need: MIN_DENOISE_POSES,
        });
    }
    if times.len() != n {
        return Err(Error::LengthMismatch {
            what: "times",
            expected: n,
            got: times.len(),
        });
    }
    crate::check_key_times(times)?;
    if !(2..=3).contains(&options.order) {
        return Err(Error::Value {
            what: "order",
            at: None,
            value: options.order as f64,
            expected: Expected::OneOf(&[2.0, 3.0]),
        });
    }
    if let Strength::Fixed {
        rotation,
        translation,
    } = options.strength
    {
        for v in [rotation, translation] {
            if !(v.is_finite() && v >= 0.0) {
                return Err(Error::Value {
                    what: "strength",
                    at: None,
                    value: v,
                    expected: Expected::NonNegative("time"),
                });
            }
        }
    }
    Ok(())
}

fn overflow() -> Error {
    Error::Overflow {
        what: "poses",
        at: None,
        hint: "",
    }
}

fn denoise_with(
    ws: &mut Workspace,
    poses: &[Pose],
    times: &[f64],
    held: Option<&[bool]>,
    options: &DenoiseOptions,
) -> Result<Denoised> {
    let n = poses.len();
    check(n, times, options)?;
    if let Some(h) = held {
        if h.len() != n {
            return Err(Error::LengthMismatch {
                what: "held",
                expected: n,
                got: h.len(),
            });
        }
    }
    let cm = &mut ws.common;
    cm.quats.clear();
    cm.origins.clear();
    for (index, p) in poses.iter().enumerate() {
        let len = p.rotation.length();
        if !(p.rotation.is_finite() && p.translation.is_finite() && len > 0.0) {
            return Err(Error::BadPose {
                index,
                defect: PoseDefect::NotFinite,
            });
        }
        cm.quats.push(p.rotation / len);
        cm.origins.push(p.translation);
    }
    let pops = if options.kinks {
        pops::find(&cm.quats, &cm.origins, times)
    } else {
        Vec::new()
    };
    if pops.is_empty() {
        // (the rotations are normalised in `ws` already)
        return denoise_piece(ws, poses, times, held, options, false);
    }
    // Each piece between pops apart; a piece too short to smooth is kept as it is.
    let mut out = Denoised {
        poses: Vec::with_capacity(n),
        rotation_strength: 0.0,
        translation_strength: 0.0,
        pivot: DVec3::ZERO,
        rotation_noise: 0.0,
        translation_noise: 0.0,
        rotation_kinks: Vec::new(),
        translation_kinks: Vec::new(),
        iterations: 0,
        converged: true,
        pops: pops.clone(),
    };
    let mut longest = 0;
    let bounds: Vec<usize> = std::iter::once(0)
        .chain(pops.iter().copied())
        .chain(std::iter::once(n))
        .collect();
    for w in bounds.windows(2) {
        let (a, b) = (w[0], w[1]);
        if b - a < MIN_DENOISE_POSES {
            out.poses.extend_from_slice(&poses[a..b]);
            continue;
        }
        let d = denoise_piece(
            ws,
            &poses[a..b],
            &times[a..b],
            held.map(|h| &h[a..b]),
            options,
            true,
        )?;
        out.poses.extend_from_slice(&d.poses);
        out.rotation_kinks
            .extend(d.rotation_kinks.iter().map(|k| k + a));
        out.translation_kinks
            .extend(d.translation_kinks.iter().map(|k| k + a));
        out.iterations += d.iterations;
        out.converged &= d.converged;
        if b - a > longest {
            longest = b - a;
            out.rotation_strength = d.rotation_strength;
            out.translation_strength = d.translation_strength;
            out.pivot = d.pivot;
            out.rotation_noise = d.rotation_noise;
            out.translation_noise = d.translation_noise;
        }
    }
    Ok(out)
}

/// One clip without pops (at least [`MIN_DENOISE_POSES`] finite poses), in normalised time:
/// the times shifted to start at 0 and divided by their median spacing, a given strength
/// likewise (at most [`MAX_STRENGTH_SPACINGS`]); the strengths found are scaled back. The
/// normalised rotations are in `ws` unless `part` (a piece of the clip they were made for).
fn denoise_piece(
    ws: &mut Workspace,
    poses: &[Pose],
    times: &[f64],
    held: Option<&[bool]>,
    options: &DenoiseOptions,
    part: bool,
) -> Result<Denoised> {
    let n = poses.len();
    let cm = &mut ws.common;
    cm.scratch.clear();
    cm.scratch.extend(times.windows(2).map(|w| w[1] - w[0]));
    let mid = cm.scratch.len() / 2;
    let unit = *cm.scratch.select_nth_unstable_by(mid, f64::total_cmp).1;
    cm.times.clear();
    cm.times.extend(times.iter().map(|t| (t - times[0]) / unit));
    crate::check_key_times(&cm.times)?;
    if part {
        cm.quats.clear();
        cm.quats
            .extend(poses.iter().map(|p| p.rotation / p.rotation.length()));
    }
    let scale = |tau: f64| (tau / unit).min(MAX_STRENGTH_SPACINGS);
    let options = DenoiseOptions {
        strength: match options.strength {
            Strength::Auto => Strength::Auto,
            Strength::Fixed {
                rotation,
                translation,
            } => Strength::Fixed {
                rotation: scale(rotation),
                translation: scale(translation),
            },
        },
        ..*options
    };
    let times = std::mem::take(&mut cm.times);
    let result = match options.order {
        2 => run(&mut ws.w2, &mut ws.rot2, cm, poses, &times, held, &options),
        _ => run(&mut ws.w3, &mut ws.rot3, cm, poses, &times, held, &options),
    };
    ws.common.times = times;
    debug_assert!(result.as_ref().map_or(true, |d| d.poses.len() == n));
    result.map(|mut d| {
        d.rotation_strength *= unit;
        d.translation_strength *= unit;
        d
    })
}

/// The pipeline for order `M`.
fn run<const M: usize>(
    wh: &mut Whittaker<M>,
    rot: &mut RotationSpline<M>,
    cm: &mut Common,
    poses: &[Pose],
    times: &[f64],
    held: Option<&[bool]>,
    options: &DenoiseOptions,
) -> Result<Denoised> {
    let n = poses.len();
    let Common {
        st,
        st2,
        y_t,
        y_r,
        u_t,
        u_r,
        quats,
        r,
        origins: _,
        times: _,
        scratch,
        paths,
        zs,
    } = cm;
    st.rebuild(times, M)?;
    st2.rebuild(times, 2)?;
    let rows = st.len();
    // The development of the rotation's spatial increments.
    y_r.clear();
    y_r.push(DVec3::ZERO);
    for j in 0..n - 1 {
        let w = so3::log(quats[j + 1] * quats[j].conjugate());
        let next = y_r[j] + w;
        y_r.push(next);
    }
    if y_r.iter().any(|v| !v.is_finite()) {
        return Err(overflow());
    }
    // The search range of the automatic strength.
    scratch.clear();
    scratch.extend(times.windows(2).map(|w| w[1] - w[0]));
    let mid = scratch.len() / 2;
    let spacing = *scratch.select_nth_unstable_by(mid, f64::total_cmp).1;
    let span = times[n - 1] - times[0];
    let range = (
        AUTO_MIN_SPACINGS * spacing,
        (AUTO_MAX_SPACINGS * spacing).min(span),
    );
    let (fixed_r, fixed_t) = match options.strength {
        Strength::Auto => (None, None),
        Strength::Fixed {
            rotation,
            translation,
        } => (Some(rotation), Some(translation)),
    };
    let part = Part {
        st,
        st2,
        range,
        kinks: options.kinks,
    };
    // The rotation's strength and kinks, on its linear model.
    u_r.clear();
    u_r.resize(rows, 1.0);
    let Chosen {
        gcv: gcv_r,
        kinks: kinks_r,
        ..
    } = part.choose(wh, y_r, u_r, fixed_r, None, scratch)?;
    let tau_r = gcv_r.tau;
    // The rotation, started from the linear model's fit carried back to the rotations (its
    // correction z of the development applied on the left: the increments then change by
    // the differences of z to first order), where the Gauss-Newton matrix is nearly final.
    r.clear();
    r.extend_from_slice(quats);
    let solve = if tau_r > 0.0 {
        let lambda = tau_r.powi(2 * M as i32);
        wh.prepare(st, u_r, y_r, range);
        if !wh.smooth(lambda, held) {
            return Err(overflow());
        }
        for (r, z) in r.iter_mut().zip(&wh.z) {
            *r = (so3::exp(-*z) * *r).normalize();
        }
        rot.solve(st, u_r, quats, r, lambda, held)
    } else {
        rotation::Solve {
            iterations: 0,
            converged: true,
            rss: 0.0,
        }
    };
    // The translation: the pivot's path, the pivot refined at the strength found while
    // that lowers the GCV score.
    let mut c = pivot::pivot(poses, st2);
    let path = |c: DVec3, y: &mut Vec<DVec3>| -> Result<()> {
        y.clear();
        y.extend(
            poses
                .iter()
                .zip(quats.iter())
                .map(|(p, q)| *q * c + p.translation),
        );
        if y.iter().all(|v| v.is_finite()) {
            Ok(())
        } else {
            Err(overflow())
        }
    };
    let mut guess_t = None;
    let mut refinements = 0;
    let (gcv_t, kinks_t) = loop {
        path(c, y_t)?;
        u_t.clear();
        u_t.resize(rows, 1.0);
        let Chosen {
            gcv: g,
            index,
            kinks: found,
        } = part.choose(wh, y_t, u_t, fixed_t, guess_t, scratch)?;
        let Some(index) = index.filter(|_| refinements < PIVOT_REFINEMENTS && g.tau > 0.0) else {
            break (g, found);
        };
        refinements += 1;
        let next = pivot::refine(quats, poses, st, index, wh, paths, zs);
        if !next.is_finite() {
            return Err(overflow());
        }
        // Keep the refined pivot if it scores better at the same strength, and search its
        // strength again from there.
        path(next, y_t)?;
        wh.set_data(y_t);
        match wh.gcv_grid(index) {
            Some(h) if h.score < g.score => {
                c = next;
                guess_t = Some(g.tau);
            }
            _ => {
                path(c, y_t)?;
                break (g, found);
            }
        }
    };
    let tau_t = gcv_t.tau;
    let p: &[DVec3] = if tau_t > 0.0 {
        wh.prepare(st, u_t, y_t, range);
        if !wh.smooth(tau_t.powi(2 * M as i32), held) {
            return Err(overflow());
        }
        &wh.x
    } else {
        y_t
    };
    let hbar = span / (n - 1) as f64;
    let noise = |g: &Gcv| -> f64 {
        if g.trace < n as f64 && g.rss > 0.0 {
            (g.rss / (hbar * 3.0 * (n as f64 - g.trace))).sqrt()
        } else {
            0.0
        }
    };
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        if held.is_some_and(|h| h[i]) {
            out.push(poses[i]);
            continue;
        }
        let pose = Pose {
            rotation: r[i],
            translation: p[i] - r[i] * c,
        };
        if !(pose.rotation.is_finite() && pose.translation.is_finite()) {
            return Err(overflow());
        }
        out.push(pose);
    }
    Ok(Denoised {
        poses: out,
        rotation_strength: tau_r,
        translation_strength: tau_t,
        pivot: c,
        rotation_noise: noise(&gcv_r),
        translation_noise: noise(&gcv_t),
        rotation_kinks: kinks_r,
        translation_kinks: kinks_t,
        iterations: solve.iterations,
        converged: solve.converged,
        pops: Vec::new(),
    })
}

/// What choosing one part's strength needs.
struct Part<'a> {
    st: &'a Stencils,
    st2: &'a Stencils,
    range: (f64, f64),
    kinks: bool,
}

impl Part<'_> {
    /// The strength of one part with its GCV statistics and, when searched, its grid index
    /// (searched from `guess` unless `fixed`) and, if kinks are on, the kinks let through
    /// (zeroing their rows in `u`; the strength is searched again after a release).
    fn choose<const M: usize>(
        &self,
        wh: &mut Whittaker<M>,
        y: &[DVec3],
        u: &mut [f64],
        fixed: Option<f64>,
        guess: Option<f64>,
        scratch: &mut Vec<f64>,
    ) -> Result<Chosen> {
        if fixed == Some(0.0) {
            let none = Gcv {
                tau: 0.0,
                score: f64::INFINITY,
                rss: 0.0,
                trace: y.len() as f64,
            };
            return Ok(Chosen {
                gcv: none,
                index: None,
                kinks: Vec::new(),
            });
        }
        wh.prepare(self.st, u, y, self.range);
        let evaluate =
            |wh: &mut Whittaker<M>, guess: Option<f64>| -> Result<(Gcv, Option<usize>)> {
                match fixed {
                    Some(t) => wh.gcv(t).map(|g| (g, None)),
                    None => wh.search(guess).map(|(g, k)| (g, Some(k))),
                }
                .ok_or_else(overflow)
            };
        let mut g = evaluate(wh, guess)?;
        let mut found = Vec::new();
        if self.kinks {
            let fit = if fixed.is_some() { &wh.x } else { &wh.best };
            found = kinks::release(fit, self.st2, M, u, scratch);
            if !found.is_empty() {
                wh.prepare(self.st, u, y, self.range);
                g = evaluate(wh, Some(g.0.tau))?;
            }
        }
        Ok(Chosen {
            gcv: g.0,
            index: g.1,
            kinks: found,
        })
    }
}

/// What [`Part::choose`] chose: the strength's GCV statistics, its grid index when it was
/// searched, and the kinks let through.
struct Chosen {
    gcv: Gcv,
    index: Option<usize>,
    kinks: Vec<usize>,
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A noisy tumbling flight of `n` poses, one per frame; with `pop`, teleported by 5 m and
    /// turned 90 degrees from pose `n / 2` on.
    fn flight(n: usize, pop: bool) -> (Vec<Pose>, Vec<f64>) {
        let mut state = 0x2545_F491_4F6C_DD1D_u64;
        let mut noise = || smoother_noise(&mut state);
        let times: Vec<f64> = (0..n).map(|i| i as f64).collect();
        let jump = Pose::from_rotation_translation(
            DQuat::from_rotation_z(std::f64::consts::FRAC_PI_2),
            DVec3::new(5.0, 0.0, 0.0),
        );
        let poses = times
            .iter()
            .enumerate()
            .map(|(i, t)| {
                let t = t / 24.0;
                let wobble = DVec3::new(noise(), noise(), noise()) * 0.01;
                let q = DQuat::from_scaled_axis(DVec3::new(0.3, 0.2, 1.1) * t + wobble);
                let p = DVec3::new((0.5 * t).cos() * 2.0, (0.3 * t).sin(), 0.3 * t)
                    + DVec3::new(noise(), noise(), noise()) * 0.02;
                let pose = Pose::from_rotation_translation(q, p);
                if pop && i >= n / 2 {
                    Pose::from_rotation_translation(
                        jump.rotation * pose.rotation,
                        jump.rotation * pose.translation + jump.translation,
                    )
                } else {
                    pose
                }
            })
            .collect();
        (poses, times)
    }

    fn smoother_noise(state: &mut u64) -> f64 {
        *state ^= *state << 13;
        *state ^= *state >> 7;
        *state ^= *state << 17;
        (*state >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    /// A pop cuts the clip: each piece is what denoising it alone gives, and the jump across
    /// the pop is the input's.
    #[test]
    fn a_pop_cuts_the_clip_into_pieces_smoothed_apart() {
        let (poses, times) = flight(120, true);
        let o = DenoiseOptions::default();
        let d = denoise(&poses, &times, None, &o).unwrap();
        assert_eq!(d.pops, vec![60]);
        let first = denoise(&poses[..60], &times[..60], None, &o).unwrap();
        let second = denoise(&poses[60..], &times[60..], None, &o).unwrap();
        assert!(first.pops.is_empty() && second.pops.is_empty());
        assert_eq!(d.poses[..60], first.poses[..]);
        assert_eq!(d.poses[60..], second.poses[..]);
        // No pop without the jump; with kinks off, no cut either.
        let (smooth, _) = flight(120, false);
        assert!(denoise(&smooth, &times, None, &o).unwrap().pops.is_empty());
        let off = DenoiseOptions { kinks: false, ..o };
        assert!(denoise(&poses, &times, None, &off).unwrap().pops.is_empty());
    }

    /// Every strength is served: tiny ones leave the clip as it is, huge ones act as
    /// MAX_STRENGTH_SPACINGS spacings (and say so), in any unit of time.
    #[test]
    fn every_strength_in_any_unit_is_served() {
        let (poses, times) = flight(250, false);
        let fixed = |s: f64| DenoiseOptions {
            strength: Strength::Fixed {
                rotation: s,
                translation: s,
            },
            ..DenoiseOptions::default()
        };
        for s in [1e-300, 0.0005, 0.001, 316.0, 1000.0, 1e300] {
            let d = denoise(&poses, &times, None, &fixed(s)).unwrap();
            let used = s.min(MAX_STRENGTH_SPACINGS);
            assert!(
                (d.rotation_strength - used).abs() <= 1e-12 * used,
                "{s}: {d:?}"
            );
            assert!(d.poses.iter().all(|p| p.rotation.is_finite()
                && p.translation.is_finite()
                && (p.rotation.length() - 1.0).abs() < 1e-12));
        }
        let at = |s: f64, k: f64| {
            let t: Vec<f64> = times.iter().map(|t| t * k).collect();
            denoise(&poses, &t, None, &fixed(s * k)).unwrap()
        };
        assert_eq!(at(1000.0, 1.0).poses, at(100.0, 1.0).poses);
        for k in [1e-100, 1e50, 0.001] {
            let (a, b) = (at(4.0, k), at(4.0, 1.0));
            let diff = a
                .poses
                .iter()
                .zip(&b.poses)
                .map(|(p, q)| (p.translation - q.translation).length())
                .fold(0.0, f64::max);
            assert!(diff < 1e-9, "x{k}: {diff}");
        }
    }

    /// Held poses come back as the matrices given, bit for bit; the others as their poses.
    #[test]
    fn held_rows_are_the_source_matrices() {
        let (poses, times) = flight(20, false);
        let held: Vec<bool> = (0..20).map(|i| i % 3 == 0).collect();
        let d = denoise(&poses, &times, Some(&held), &DenoiseOptions::default()).unwrap();
        let source: Vec<[[f64; 4]; 4]> = (0..7)
            .map(|k| {
                let mut m = poses[3 * k].to_rows();
                m[0][3] += 1e-17 * k as f64; // not what the pose would give back
                m
            })
            .collect();
        let mut out = vec![0.0; 16 * 20];
        assert_eq!(d.write_rows(Some(&held), &source, &mut out), 7);
        for i in 0..20 {
            let want = if held[i] {
                source[i / 3]
            } else {
                d.poses[i].to_rows()
            };
            let got: Vec<f64> = out[16 * i..16 * i + 16].to_vec();
            assert_eq!(
                got,
                want.iter().flatten().copied().collect::<Vec<_>>(),
                "{i}"
            );
        }
    }
}
