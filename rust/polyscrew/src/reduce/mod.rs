//! Key reduction: a dense rigid motion -> the fewest Bezier keys whose playback by Blender
//! stays within a world-space tolerance on the moving body (ScrewBender issue 26).
//!
//! What it implements, and where from:
//!
//! - the motion measured against: the dense poses at the given frames, the screw between two
//!   consecutive ones in between (Rossignac-Kim's `s(L0, t, L1)`, [`crate::Screw`]), a held
//!   pose across a CONSTANT span;
//! - the error of a played pose against it on a body of radius `r`: no point within `r` of the
//!   body's origin further than `|dt| + 2 r sin(theta / 2)` (+ `r |ds|` with scale), no
//!   rotation differing by more than `theta` ([`compose::row_error`]);
//! - key frames chosen greedily (the longest feasible span from each key, found by an
//!   exponential then a binary search), each candidate span a Bezier per channel with its
//!   handles at 1/3 and 2/3 of the span in time (so the segment is a cubic in time) whose two
//!   inner handle values are fitted by least squares to the dense channel values, keys
//!   on the dense values; the search is the cubic in `f64`, within
//!   [`SEARCH_MARGIN`] of the tolerance, and every span it keeps is checked through Blender's
//!   own evaluation ([`crate::fcurve::bezier`], `float32` keys, bit-identical to
//!   `FCurve.evaluate`) at every dense frame and [`SUBSAMPLES`]` - 1` subframes between two;
//!   (the curve-fitting literature's "longest span" greedy segmentation; Blender's
//!   `graph.decimate` reduces one curve at a time by a value error instead);
//! - rotation channels unwrapped along the dense samples (quaternion signs continuous, Euler
//!   triples compatible, axis-angle unwrapped: [`crate::rotation_channels`]), from the
//!   source's own first values when given;
//! - rigs: owners are reduced parents first; a child's target is
//!   `(world_parent_reduced @ offset)^-1 @ world_child_dense`, so it compensates its parent's
//!   error and the tolerance holds in world space at every owner. It is formed from the
//!   parent's error transform `E = world_reduced^-1 @ world_dense` as
//!   `offset^-1 @ E_parent @ offset @ local_dense`, and the child's own `E` is
//!   `played^-1 @ target`: no world pose is formed.
//!
//! Owners are independent within a depth of the hierarchy and are spread over threads.
//! Every size that input drives is checked against the memory budget ([`reduce_footprint`])
//! before anything is allocated.

pub mod compose;
mod owner;

use glam::DVec3;

use crate::error::{At, Error, Expected, Result};
use crate::fcurve::Interpolation;
use crate::memory::{try_vec, Footprint};
use crate::motion::channels::RotationMode;
use crate::motion::pose::Pose;

pub use owner::ReducedKey;

/// Samples per dense span: the dense frame and `SUBSAMPLES - 1` evenly spaced subframes
/// after it (3 subframes: at 1/4, 1/2 and 3/4 of the span).
pub const SUBSAMPLES: usize = 4;

/// The key search accepts a span whose `f64` cubic stays within this fraction of the
/// tolerance, so that the `float32` keys Blender stores and evaluates (checked exactly
/// afterwards) rarely fail where the `f64` cubic passed.
pub const SEARCH_MARGIN: f64 = 0.95;

/// Most dense frames per owner.
pub const MAX_REDUCE_FRAMES: usize = 1_000_000;

/// Most poses (owners x frames) in one call.
pub const MAX_REDUCE_POSES: usize = 20_000_000;

/// How to ask [`reduce_keys`] for less memory.
pub const REDUCE_HINT: &str = "reduce fewer owners or fewer frames in one call";

/// How far the reduced motion may depart from the dense one.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Tolerance {
    /// No point of the body within its radius further than this from its place (> 0).
    pub distance: f64,
    /// No rotation differing by more than this (radians, > 0).
    pub angle: f64,
}

/// A group of an owner's transform channels.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Group {
    /// `location`.
    Location,
    /// The rotation property of the owner's mode.
    Rotation,
    /// `scale`.
    Scale,
}

impl Group {
    /// Blender's property of this group for an owner in rotation mode `mode`.
    pub fn path(self, mode: RotationMode) -> &'static str {
        match self {
            Self::Location => "location",
            Self::Scale => "scale",
            Self::Rotation => crate::intent::playback::rotation_property(mode),
        }
    }
}

/// Blender's key handle types (`Keyframe.handle_left_type`), in the order of
/// [`HandleType::NAMES`] (the index is the packed code).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum HandleType {
    /// `FREE`: each handle where it was put.
    Free,
    /// `ALIGNED`: both handles on one line through the key.
    Aligned,
    /// `VECTOR`: pointing at the neighbouring keys.
    Vector,
    /// `AUTO`: smooth, chosen by Blender.
    Auto,
    /// `AUTO_CLAMPED`: smooth without overshoot, chosen by Blender.
    AutoClamped,
}

impl HandleType {
    /// The RNA identifiers; a handle type's code is its index here.
    pub const NAMES: [&'static str; 5] = ["FREE", "ALIGNED", "VECTOR", "AUTO", "AUTO_CLAMPED"];

    /// The packed code.
    pub fn code(self) -> i64 {
        self as i64
    }
}

/// The dense motion of `B` owners to reduce. Arrays hold owner-major rows: owner `b`'s
/// frame `i` is entry `b * N + i`.
#[derive(Debug, Clone, Copy)]
pub struct ReduceInput<'a> {
    /// `B * N` poses, each in the space its channels key (an object's parent space, a bone's
    /// `matrix_basis`), scale separated.
    pub poses: &'a [Pose],
    /// `N >= 2` frames, finite and strictly increasing, shared by all owners.
    pub frames: &'a [f64],
    /// `B` rotation modes.
    pub modes: &'a [RotationMode],
    /// `B` body radii (finite, `>= 0`).
    pub radius: &'a [f64],
    /// `B * N` positive scales to reduce too, or `None`.
    pub scales: Option<&'a [DVec3]>,
    /// `B` rows: whether the owner keys location, rotation, scale (`None`: location and
    /// rotation, and scale when `scales` is given).
    pub channels: Option<&'a [[bool; 3]]>,
    /// `B` parents (`None`: a root), batch indices; the tolerance then holds in world space,
    /// `world_i = world_parent @ offsets[i] @ poses[i]`.
    pub parents: Option<&'a [Option<usize>]>,
    /// `B` constant rigid offsets (a bone's rest relative to its parent's), or `None`
    /// (identity).
    pub offsets: Option<&'a [Pose]>,
    /// `B * (N - 1)` flags: span `i -> i + 1` of owner `b` (entry `b * (N - 1) + i`) is a
    /// step or hold and stays one (a CONSTANT key).
    pub constant: Option<&'a [bool]>,
    /// `B` rows of the source's own channel values at the first frame (Euler: the first 3;
    /// axis-angle: angle, axis; quaternion: its sign): the first key takes the equivalent
    /// values nearest to them. `None`: those nearest zero.
    pub start: Option<&'a [[f64; 4]]>,
}

/// The dense motion between two dense frames, which the tolerance is measured against at
/// the subframes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum Between {
    /// The screw between the two poses (`s(P_i, u, P_i+1)`): what the source plays when it
    /// is keyed on every frame with LINEAR keys (to first order), and the agreed default.
    #[default]
    Screw,
    /// The cubic through the four poses around the span (two each side, fewer at the ends
    /// of the clip and of CONSTANT spans), by Aitken-Neville's scheme with screws in place
    /// of straight lines: `P_ij(t) = s(P_i,j-1(t), (t - t_i) / (t_j - t_i), P_i+1,j(t))`.
    /// Smooth like the source's own playback when it is keyed on every frame with Bezier
    /// keys (an `nla.bake`, an imported capture); screws are reproduced exactly and it is
    /// coordinate-free like the screw.
    Cubic,
    /// The owner's channels (location, the rotation channels of its mode, unwrapped from
    /// `start`) interpolated linearly between the two frames: exactly what the source plays
    /// when it is keyed on every frame with LINEAR keys (a Smooth Motion bake). Not
    /// coordinate-free (Euler channels are not).
    Linear,
}

impl Between {
    /// The names, in the order of the variants.
    pub const NAMES: [&'static str; 3] = ["screw", "cubic", "linear"];

    /// The variant named `name`.
    ///
    /// # Errors
    /// [`Error::Choice`] for another name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "screw" => Ok(Self::Screw),
            "cubic" => Ok(Self::Cubic),
            "linear" => Ok(Self::Linear),
            _ => Err(Error::Choice {
                what: "between",
                got: name.to_owned(),
                expected: &Self::NAMES,
            }),
        }
    }
}

/// How to reduce.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReduceOptions {
    /// The tolerance.
    pub tolerance: Tolerance,
    /// The dense frames are one period of a cycle (first pose == last pose): keys at the first
    /// and last frame, with equal values where the channels return to their first values.
    pub cyclic: bool,
    /// Each channel gets its own key frames (default: an owner's channels share them).
    pub per_channel: bool,
    /// Worker threads (0: as many as the machine has).
    pub threads: usize,
    /// The dense motion between two frames.
    pub between: Between,
}

/// One reduced F-curve.
#[derive(Debug, Clone, PartialEq)]
pub struct ReducedCurve {
    /// The owner's batch index.
    pub owner: usize,
    /// Its group.
    pub group: Group,
    /// Its array index in the group's property.
    pub index: usize,
    /// Its keys, in time order.
    pub keys: Vec<ReducedKey>,
    /// The handle type both handles of every key should be given so that editing keeps
    /// the fitted handles.
    pub handle_type: HandleType,
}

/// The result of [`reduce_keys`].
#[derive(Debug, Clone, PartialEq)]
pub struct Reduced {
    /// The curves, owner by owner; within an owner location, rotation, scale, by index.
    pub curves: Vec<ReducedCurve>,
    /// Distinct key frames per owner.
    pub keys: Vec<usize>,
    /// Per owner, the largest distance error measured at the checked samples (world space
    /// when there are parents), through Blender's evaluation of the `float32` keys.
    pub distance_error: Vec<f64>,
    /// Per owner, the largest angle error (radians) measured the same way.
    pub angle_error: Vec<f64>,
}

/// The samples of `n` dense frames: `(n - 1) * SUBSAMPLES + 1`.
pub fn sample_count(n: usize) -> usize {
    n.saturating_sub(1)
        .saturating_mul(SUBSAMPLES)
        .saturating_add(1)
}

/// The most bytes [`reduce_keys`] holds for `bodies` owners of `n` frames on `threads`
/// workers (0: the machine's), `with_parents` when error transforms are kept for children: the
/// sample times, one working set per worker (targets, channels, reduced poses), one error
/// transform per sample of every owner, and the curves when each of the 10 channels keeps up
/// to one key per frame.
pub fn reduce_footprint(bodies: usize, n: usize, threads: usize, with_parents: bool) -> Footprint {
    let m = sample_count(n);
    let workers = effective_threads(threads, bodies).max(1);
    let per_owner = Footprint::of::<Pose>(m.saturating_mul(6))
        .and::<DVec3>(m)
        .and::<f64>(m.saturating_mul(compose::STRIDE + 4))
        .and::<[f64; compose::STRIDE]>(m.saturating_mul(3))
        .and::<usize>(m);
    let worlds = if with_parents {
        Footprint::of::<Pose>(m.saturating_mul(2)).times(bodies)
    } else {
        Footprint::ZERO
    };
    Footprint::of::<f64>(m.saturating_mul(2))
        + per_owner.times(workers)
        + worlds
        + Footprint::of::<ReducedKey>(n.saturating_mul(compose::STRIDE)).times(bodies)
}

fn effective_threads(threads: usize, bodies: usize) -> usize {
    let cores = std::thread::available_parallelism().map_or(1, |p| p.get());
    if threads == 0 { cores } else { threads }
        .min(cores)
        .min(bodies.max(1))
}

/// Checks every input against `B = modes.len()` owners and `N = frames.len()` frames.
fn validate(input: &ReduceInput<'_>, options: &ReduceOptions) -> Result<(usize, usize)> {
    let n = input.frames.len();
    let b = input.modes.len();
    if n < 2 {
        return Err(Error::TooFew { got: n, need: 2 });
    }
    if n > MAX_REDUCE_FRAMES {
        return Err(Error::Limit {
            what: "frames",
            counted: "frames per owner",
            count: n,
            limit: MAX_REDUCE_FRAMES,
            hint: "",
        });
    }
    if b.saturating_mul(n) > MAX_REDUCE_POSES {
        return Err(Error::Limit {
            what: "poses",
            counted: "poses (owners x frames)",
            count: b.saturating_mul(n),
            limit: MAX_REDUCE_POSES,
            hint: "reduce fewer owners at once",
        });
    }
    for (i, f) in input.frames.iter().enumerate() {
        crate::motion::timing::check_time("frame", i, *f)?;
        if i > 0 && *f <= input.frames[i - 1] {
            return Err(Error::Spacing {
                what: "frames",
                at: At::new("frame", i),
                gap: *f - input.frames[i - 1],
                min: f64::MIN_POSITIVE,
            });
        }
    }
    let Tolerance { distance, angle } = options.tolerance;
    if !(distance.is_finite() && distance > 0.0) {
        return Err(Error::Value {
            what: "distance",
            at: None,
            value: distance,
            expected: Expected::Positive("distance"),
        });
    }
    if !(angle.is_finite() && angle > 0.0) {
        return Err(Error::Value {
            what: "angle",
            at: None,
            value: angle,
            expected: Expected::Positive("angle"),
        });
    }
    let len = |what: &'static str, got: usize, expected: usize| {
        if got == expected {
            Ok(())
        } else {
            Err(Error::LengthMismatch {
                what,
                expected,
                got,
            })
        }
    };
    len("poses", input.poses.len(), b * n)?;
    len("radius", input.radius.len(), b)?;
    for (g, p) in input.poses.iter().enumerate() {
        p.check_range(g % n)
            .map_err(|e| e.within_argument("poses", "owner", g / n))?;
    }
    for (o, r) in input.radius.iter().enumerate() {
        if !(r.is_finite() && *r >= 0.0 && *r <= crate::motion::pose::MAX_COORDINATE) {
            return Err(Error::Value {
                what: "radius",
                at: Some(At::new("owner", o)),
                value: *r,
                expected: Expected::Within {
                    low: 0.0,
                    high: crate::motion::pose::MAX_COORDINATE,
                },
            });
        }
    }
    if let Some(s) = input.scales {
        len("scales", s.len(), b * n)?;
        for (g, v) in s.iter().enumerate() {
            let ok = v.is_finite()
                && v.min_element() > 0.0
                && v.max_element() <= crate::motion::pose::MAX_COORDINATE;
            if !ok {
                let worst = v
                    .to_array()
                    .into_iter()
                    .find(|x| !(*x > 0.0 && *x <= crate::motion::pose::MAX_COORDINATE))
                    .unwrap_or(f64::NAN);
                return Err(Error::Value {
                    what: "scale",
                    at: Some(At::new("frame", g % n)),
                    value: worst,
                    expected: Expected::PositiveUpTo(crate::motion::pose::MAX_COORDINATE),
                }
                .within_argument("scales", "owner", g / n));
            }
        }
    }
    if let Some(c) = input.channels {
        len("channels", c.len(), b)?;
        if input.scales.is_none() {
            if let Some(o) = c.iter().position(|row| row[2]) {
                return Err(Error::Conflict {
                    what: "channels",
                    reason: format!("owner {o} keys scale but no scales were given"),
                });
            }
        }
    }
    if let Some(o) = input.offsets {
        len("offsets", o.len(), b)?;
        for (i, p) in o.iter().enumerate() {
            p.check_range(i)
                .map_err(|e| e.within_argument("offsets", "owner", i))?;
        }
    }
    if let Some(c) = input.constant {
        len("constant", c.len(), b * (n - 1))?;
    }
    if let Some(s) = input.start {
        len("start", s.len(), b)?;
        for (o, row) in s.iter().enumerate() {
            if let Some(v) = row.iter().find(|v| !v.is_finite()) {
                return Err(Error::Value {
                    what: "start",
                    at: Some(At::new("owner", o)),
                    value: *v,
                    expected: Expected::Finite("channel value"),
                });
            }
        }
    }
    if let Some(p) = input.parents {
        len("parents", p.len(), b)?;
        for (o, parent) in p.iter().enumerate() {
            if let Some(q) = parent {
                if *q >= b {
                    return Err(Error::Index {
                        what: "parents",
                        item: "owner",
                        at: Some(At::new("owner", o)),
                        index: i64::try_from(*q).unwrap_or(i64::MAX),
                        len: b,
                    });
                }
                if *q == o {
                    return Err(Error::Degenerate {
                        what: "parents",
                        at: Some(At::new("owner", o)),
                        reason: "is its own parent",
                    });
                }
            }
        }
    }
    Ok((b, n))
}

/// The depth of every owner in the hierarchy (roots 0).
///
/// # Errors
/// [`Error::Degenerate`] naming an owner whose parents form a cycle.
fn depths(parents: Option<&[Option<usize>]>, b: usize) -> Result<Vec<usize>> {
    let mut depth = try_vec::<usize>(b, "owner depths")?;
    depth.resize(b, usize::MAX);
    let Some(parents) = parents else {
        depth.iter_mut().for_each(|d| *d = 0);
        return Ok(depth);
    };
    for o in 0..b {
        // Walk up until a known depth or a root; more than b steps is a cycle.
        let mut chain = 0usize;
        let mut cur = o;
        while depth[cur] == usize::MAX {
            match parents[cur] {
                None => {
                    depth[cur] = 0;
                    break;
                }
                Some(p) => {
                    chain += 1;
                    if chain > b {
                        return Err(Error::Degenerate {
                            what: "parents",
                            at: Some(At::new("owner", o)),
                            reason: "its parents form a cycle",
                        });
                    }
                    cur = p;
                }
            }
        }
        // Fill the chain from the top down.
        let mut path = Vec::new();
        let mut cur = o;
        while depth[cur] == usize::MAX {
            path.push(cur);
            cur = parents[cur].expect("not a root");
        }
        let mut d = depth[cur];
        for &p in path.iter().rev() {
            d += 1;
            depth[p] = d;
        }
    }
    Ok(depth)
}

/// Reduces the dense motion of every owner of `input` to Bezier keys within
/// `options.tolerance` (see the module documentation for the method).
///
/// For each owner: the keyed channel groups' curves (location, rotation in the owner's mode,
/// scale), keys at shared frames (or per channel with `per_channel`), the first and last
/// frame always keyed; CONSTANT spans kept as CONSTANT keys; quaternion keys unit and sign
/// continuous, Euler and axis-angle keys following the dense motion's turns (no wraps).
/// Blender's evaluation of the curves at every dense frame and the subframes between them
/// stays within the tolerance, except where the `float32` storage of the keys alone departs
/// further (a tolerance below `float32`'s resolution at the motion's scale): the errors
/// reported are the ones measured.
///
/// # Errors
/// [`Error::TooFew`] for fewer than 2 frames, [`Error::LengthMismatch`] for arrays of the wrong length, errors
/// naming the argument and the owner ([`Error::In`], [`Error::Value`], [`Error::Index`],
/// [`Error::Degenerate`], [`Error::Conflict`]) for non-finite or out-of-range poses, radii, scales,
/// offsets or start values, tolerances that are not positive, scale keyed without scales,
/// parents out of range or forming a cycle, [`Error::Limit`] for sizes over [`MAX_REDUCE_FRAMES`] /
/// [`MAX_REDUCE_POSES`]; [`Error::Memory`] when [`reduce_footprint`] exceeds the memory budget
/// or the allocator refuses.
pub fn reduce_keys(input: &ReduceInput<'_>, options: &ReduceOptions) -> Result<Reduced> {
    let (b, n) = validate(input, options)?;
    let with_parents = input.parents.is_some_and(|p| p.iter().any(|q| q.is_some()));
    reduce_footprint(b, n, options.threads, with_parents)
        .check("the key reduction", REDUCE_HINT)?;
    let depth = depths(input.parents, b)?;
    let ctx = owner::Context::new(input, options, n)?;
    let mut has_children = try_vec::<bool>(b, "owner flags")?;
    has_children.resize(b, false);
    if let Some(p) = input.parents {
        for q in p.iter().flatten() {
            has_children[*q] = true;
        }
    }
    let max_depth = depth.iter().copied().max().unwrap_or(0);
    let mut results: Vec<Option<owner::OwnerResult>> = try_vec(b, "reduced owners")?;
    results.resize_with(b, || None);
    let threads = effective_threads(options.threads, b);
    // One thread: one set of buffers for every owner of every level.
    let mut single = owner::Workspace::default();
    for level in 0..=max_depth {
        let owners: Vec<usize> = (0..b).filter(|o| depth[*o] == level).collect();
        let run = |part: &[usize],
                   ws: &mut owner::Workspace|
         -> Vec<(usize, Result<owner::OwnerResult>)> {
            part.iter()
                .map(|&o| {
                    let parent = input.parents.and_then(|p| p[o]).map(|q| {
                        let r = results[q].as_ref().expect("parents first");
                        r.world
                            .as_ref()
                            .expect("a parent keeps its error transforms")
                    });
                    (o, ctx.reduce_owner(ws, o, parent, has_children[o]))
                })
                .collect()
        };
        let done: Vec<(usize, Result<owner::OwnerResult>)> = if threads <= 1 || owners.len() <= 1 {
            run(&owners, &mut single)
        } else {
            let per = owners.len().div_ceil(threads);
            let parts = std::thread::scope(|scope| {
                let handles: Vec<_> = owners
                    .chunks(per)
                    .map(|chunk| scope.spawn(move || run(chunk, &mut owner::Workspace::default())))
                    .collect();
                handles.into_iter().map(|h| h.join()).collect::<Vec<_>>()
            });
            let mut all = Vec::with_capacity(owners.len());
            for part in parts {
                all.extend(part.map_err(|_| Error::Worker { what: "poses" })?);
            }
            all
        };
        for (o, r) in done {
            results[o] = Some(r.map_err(|e| e.within("owner", o))?);
        }
        // The owners one level up have no children left to reduce: their error transforms
        // go (their memory is reused by the next level's).
        if let Some(up) = level.checked_sub(1) {
            for o in (0..b).filter(|o| depth[*o] == up) {
                if let Some(r) = results[o].as_mut() {
                    r.world = None;
                }
            }
        }
    }
    let mut curves = Vec::new();
    let mut keys = try_vec(b, "key counts")?;
    let mut distance_error = try_vec(b, "errors")?;
    let mut angle_error = try_vec(b, "errors")?;
    for r in results.into_iter() {
        let r = r.expect("every owner reduced");
        keys.push(r.keys);
        distance_error.push(r.distance_error);
        angle_error.push(r.angle_error);
        curves.extend(r.curves);
    }
    Ok(Reduced {
        curves,
        keys,
        distance_error,
        angle_error,
    })
}

/// The interpolation a reduced key's span gets.
pub(crate) fn interpolation(constant: bool) -> Interpolation {
    if constant {
        Interpolation::Constant
    } else {
        Interpolation::Bezier
    }
}
