//! One owner's reduction: its target at every sample, its channels, the greedy choice of
//! key frames with least-squares handles, the exact check through Blender's evaluation.

use glam::{DQuat, DVec3};

use super::compose::{
    jacobian, relative_angle, rotation, row_error, Keyed, Turn, ROT, SCALE, STRIDE,
};
use super::{
    interpolation, Between, Group, HandleType, ReduceInput, ReduceOptions, ReducedCurve, Tolerance,
    SEARCH_MARGIN, SUBSAMPLES,
};
use crate::error::Result;
use crate::fcurve::bezier::BezierSegment;
use crate::fcurve::curve::KEY_THRESHOLD;
use crate::fcurve::{Extrapolation, FCurve, Interpolation, Key};
use crate::memory::try_vec;
use crate::motion::channels::{rotation_channels, RotationMode};
use crate::motion::pose::Pose;
use crate::motion::screw::{s, Screw};

/// Channels of a cycle's last frame within this of the first frame's (relative to
/// `1 + |value|`) are set equal to them, so the cycle's first and last keys are equal.
pub const CYCLE_SNAP: f64 = 1e-9;

/// The subframes in sixteenths of a span: 1/4, 1/2, 3/4 ([`SUBSAMPLES`] = 4).
const SUBFRAME_SIXTEENTHS: [i32; SUBSAMPLES - 1] = [4, 8, 12];

/// Rounds of per-channel reduction, each with half the previous share of the tolerance,
/// before the last one is kept (its errors reported as measured).
const PER_CHANNEL_ROUNDS: usize = 8;

/// The share of the tolerance each channel gets in the first per-channel round.
const PER_CHANNEL_SHARE: f64 = 0.5;

/// A reduced key: frame and value, handles, and the interpolation of the span it starts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ReducedKey {
    /// `(frame, value)`.
    pub co: [f64; 2],
    /// The left handle `(frame, value)`.
    pub handle_left: [f64; 2],
    /// The right handle `(frame, value)`.
    pub handle_right: [f64; 2],
    /// The interpolation from this key to the next (BEZIER, or CONSTANT for a hold or step).
    pub interpolation: Interpolation,
}

impl ReducedKey {
    /// The key as Blender stores it (`f32` frame, value and handles): what plays.
    pub fn key(&self) -> Key {
        Key::new(self.co[0] as f32, self.co[1] as f32)
            .with_handles(
                [self.handle_left[0] as f32, self.handle_left[1] as f32],
                [self.handle_right[0] as f32, self.handle_right[1] as f32],
            )
            .with_interpolation(self.interpolation)
    }
}

/// What an owner's children need of it at every sample: its error transform
/// `E = W_reduced^-1 @ W_dense` (its played world pose's inverse times its dense world pose,
/// `played^-1 @ target` in its own channels' space). A child of offset `O` and dense local
/// motion `L` then has the target `(W_reduced @ O)^-1 @ W_dense @ O @ L = O^-1 @ E @ O @ L`,
/// and its own `E` is again `played^-1 @ target`: no world pose is ever formed.
///
/// `error` is what the children compensate: the played pose counts the groups the owner does
/// not key as exact (they carry the parent's error, which the owner cannot change). `held`,
/// when the owner or one of its ancestors does not key a group, is the error transform of
/// what Blender plays (those groups at their dense values), which the error reported in world
/// space is measured with ([`held_error`]).
#[derive(Debug, Clone)]
pub(crate) struct World {
    pub error: Vec<Pose>,
    pub held: Option<Vec<Pose>>,
}

/// What one owner's reduction gives.
#[derive(Debug)]
pub(crate) struct OwnerResult {
    pub curves: Vec<ReducedCurve>,
    pub keys: usize,
    pub distance_error: f64,
    pub angle_error: f64,
    pub world: Option<World>,
}

/// The buffers of one owner's reduction, reused from owner to owner on a worker.
#[derive(Default)]
pub(crate) struct Workspace {
    local: Vec<Pose>,
    target: Vec<Pose>,
    scale: Vec<DVec3>,
    v: Vec<[f64; STRIDE]>,
    reduced: Vec<Pose>,
    quats: Vec<DQuat>,
    jac: Vec<[[f64; 4]; 3]>,
    /// The dense local motion before its parent's error is composed in, for a child that
    /// does not key one of its groups ([`held_error`]).
    dense: Vec<Pose>,
}

/// What every owner shares: the inputs, the sample times.
pub(crate) struct Context<'a> {
    input: ReduceInput<'a>,
    tolerance: Tolerance,
    cyclic: bool,
    per_channel: bool,
    between: Between,
    n: usize,
    times: Vec<f64>,
    times32: Vec<f32>,
}

/// A span between two keys: sample positions, CONSTANT or not, the inner handle values.
#[derive(Debug, Clone, Copy)]
struct Span {
    s: usize,
    e: usize,
    constant: bool,
    h1: [f64; STRIDE],
    h2: [f64; STRIDE],
}

impl<'a> Context<'a> {
    pub fn new(input: &ReduceInput<'a>, options: &ReduceOptions, n: usize) -> Result<Self> {
        let m = super::sample_count(n);
        let mut times = try_vec(m, "sample times")?;
        for f in 0..n - 1 {
            let (a, b) = (input.frames[f], input.frames[f + 1]);
            for k in 0..SUBSAMPLES {
                times.push(a + (b - a) * (k as f64 / SUBSAMPLES as f64));
            }
        }
        times.push(input.frames[n - 1]);
        let mut times32 = try_vec(m, "sample times")?;
        times32.extend(times.iter().map(|t| *t as f32));
        Ok(Self {
            input: *input,
            tolerance: options.tolerance,
            cyclic: options.cyclic,
            per_channel: options.per_channel,
            between: options.between,
            n,
            times,
            times32,
        })
    }

    fn keyed(&self, o: usize) -> Keyed {
        match self.input.channels {
            Some(c) => Keyed {
                location: c[o][0],
                rotation: c[o][1],
                scale: c[o][2] && self.input.scales.is_some(),
            },
            None => Keyed {
                location: true,
                rotation: true,
                scale: self.input.scales.is_some(),
            },
        }
    }

    fn constant(&self, o: usize, f: usize) -> bool {
        self.input.constant.is_some_and(|c| c[o * (self.n - 1) + f])
    }

    /// Reduces owner `o` whose parent's world poses are `parent` (`None`: a root); keeps its
    /// own world poses when `keep_world` (it has children).
    pub fn reduce_owner(
        &self,
        ws: &mut Workspace,
        o: usize,
        parent: Option<&World>,
        keep_world: bool,
    ) -> Result<OwnerResult> {
        let n = self.n;
        let m = self.times.len();
        let mode = self.input.modes[o];
        let keyed = self.keyed(o);
        let poses = &self.input.poses[o * n..(o + 1) * n];
        let offset = self.input.offsets.map_or(Pose::IDENTITY, |p| p[o]);
        // The dense local motion at every sample: the screw between frames, held across
        // CONSTANT spans.
        ws.local.clear();
        ws.local.reserve(m);
        ws.scale.clear();
        let width = mode.width();
        let start = self.input.start.map(|s| &s[o][..width]);
        // LINEAR keys on every frame: the channels at the frames, interpolated.
        let frame_channels = if self.between == Between::Linear {
            ws.quats.clear();
            ws.quats.extend(poses.iter().map(|p| p.rotation));
            Some(rotation_channels(&ws.quats, mode, start)?)
        } else {
            None
        };
        for f in 0..n - 1 {
            ws.local.push(poses[f]);
            if self.constant(o, f) {
                ws.local.extend([poses[f]; SUBSAMPLES - 1]);
            } else if let Some(ch) = &frame_channels {
                let (a, b) = (
                    &ch[f * width..(f + 1) * width],
                    &ch[(f + 1) * width..(f + 2) * width],
                );
                for k in 1..SUBSAMPLES {
                    let u = k as f64 / SUBSAMPLES as f64;
                    let mut r = [0.0; 4];
                    for i in 0..width {
                        r[i] = a[i] + (b[i] - a[i]) * u;
                    }
                    ws.local.push(Pose {
                        rotation: rotation(mode, &r),
                        translation: poses[f].translation.lerp(poses[f + 1].translation, u),
                    });
                }
            } else if self.between == Between::Cubic {
                // Up to two poses each side, not across CONSTANT spans or the clip's ends.
                let lo = if f > 0 && !self.constant(o, f - 1) {
                    f - 1
                } else {
                    f
                };
                let hi = if f + 2 < n && !self.constant(o, f + 1) {
                    f + 2
                } else {
                    f + 1
                };
                let t = &self.input.frames;
                for k in 1..SUBSAMPLES {
                    let time = t[f] + (t[f + 1] - t[f]) * (k as f64 / SUBSAMPLES as f64);
                    let mut p = [Pose::IDENTITY; 4];
                    let m = hi - lo + 1;
                    p[..m].copy_from_slice(&poses[lo..=hi]);
                    for level in 1..m {
                        for i in 0..m - level {
                            let (ti, tj) = (t[lo + i], t[lo + i + level]);
                            p[i] = s(&p[i], (time - ti) / (tj - ti), &p[i + 1]);
                        }
                    }
                    ws.local.push(p[0]);
                }
            } else {
                // 1/4, 1/2, 3/4 of the screw, without trigonometry.
                let screw = Screw::between(&poses[f], &poses[f + 1]);
                ws.local.extend(screw.eval_sixteenths(SUBFRAME_SIXTEENTHS));
            }
        }
        ws.local.push(poses[n - 1]);
        if let Some(scales) = self.input.scales {
            let sc = &scales[o * n..(o + 1) * n];
            ws.scale.reserve(m);
            for f in 0..n - 1 {
                let held = self.constant(o, f);
                for k in 0..SUBSAMPLES {
                    let u = if held {
                        0.0
                    } else {
                        k as f64 / SUBSAMPLES as f64
                    };
                    ws.scale.push(sc[f].lerp(sc[f + 1], u));
                }
            }
            ws.scale.push(sc[n - 1]);
        } else {
            ws.scale.resize(m, DVec3::ONE);
        }
        // A group the owner does not key (a connected bone's location) plays its dense
        // value, not the target's: kept to measure the error in world space (`held_error`).
        let holds = parent.is_some_and(|p| p.held.is_some() || !(keyed.location && keyed.rotation));
        ws.dense.clear();
        if holds {
            ws.dense.reserve(m);
            ws.dense.extend_from_slice(&ws.local);
        }
        // The target of the owner's own channels: `O^-1 @ E_parent @ O @ L` (module docs).
        if let Some(p) = parent {
            let o = offset;
            // An offset without rotation (exactly) skips the two quaternion products with the
            // identity.
            let pure = o.rotation == DQuat::IDENTITY;
            for (l, e) in ws.local.iter_mut().zip(&p.error) {
                let c = if pure {
                    Pose {
                        rotation: e.rotation,
                        translation: e.rotation * o.translation + e.translation - o.translation,
                    }
                } else {
                    mul_inverse(&o, &mul(e, &o))
                };
                *l = mul(&c, l);
            }
        }
        std::mem::swap(&mut ws.local, &mut ws.target);
        // Channels, continuous along the samples.
        ws.quats.clear();
        ws.quats.extend(ws.target.iter().map(|p| p.rotation));
        let rot = rotation_channels(&ws.quats, mode, start)?;
        ws.v.clear();
        ws.v.reserve(m);
        for j in 0..m {
            let mut row = [0.0; STRIDE];
            let t = ws.target[j].translation;
            row[0..3].copy_from_slice(&t.to_array());
            row[ROT..ROT + width].copy_from_slice(&rot[j * width..(j + 1) * width]);
            row[SCALE..SCALE + 3].copy_from_slice(&ws.scale[j].to_array());
            ws.v.push(row);
        }
        drop(rot);
        ws.jac.clear();
        if keyed.rotation && mode != RotationMode::AxisAngle {
            ws.jac.reserve(m);
            for j in 0..m {
                let r = &ws.v[j][ROT..ROT + 4];
                let q = ws.target[j].rotation;
                ws.jac.push(jacobian(mode, r, q).unwrap_or([[0.0; 4]; 3]));
            }
        }
        let mut cols = Vec::with_capacity(STRIDE);
        if keyed.location {
            cols.extend(0..3);
        }
        if keyed.rotation {
            cols.extend(ROT..ROT + width);
        }
        if keyed.scale {
            cols.extend(SCALE..SCALE + 3);
        }
        if self.cyclic {
            let (first, last) = (ws.v[0], &mut ws.v[m - 1]);
            for &c in &cols {
                if (last[c] - first[c]).abs() <= CYCLE_SNAP * (1.0 + first[c].abs()) {
                    last[c] = first[c];
                }
            }
        }
        ws.reduced.clear();
        ws.reduced.resize(m, Pose::IDENTITY);
        let fitter = Fitter {
            times: &self.times,
            times32: &self.times32,
            v: &ws.v,
            target: &ws.target,
            scale: &ws.scale,
            jac: (!ws.jac.is_empty()).then_some(&ws.jac[..]),
            mode,
            keyed,
            radius: self.input.radius[o],
            keyed_cols: cols.len(),
        };
        let constant: Vec<bool> = (0..n - 1).map(|f| self.constant(o, f)).collect();
        let (curves, keys, distance_error, angle_error) = if self.per_channel && cols.len() > 1 {
            self.per_channel_curves(&fitter, o, &cols, &constant, &mut ws.reduced)?
        } else {
            let mut spans = Vec::new();
            let (d, a) = fitter.greedy(
                &cols,
                &constant,
                self.tolerance,
                &mut ws.reduced,
                &mut spans,
            );
            let curves = cols
                .iter()
                .map(|&c| curve_of(&fitter, o, c, &spans))
                .collect::<Result<Vec<_>>>()?;
            // An owner that keys nothing has no key frames.
            let keys = if cols.is_empty() { 0 } else { spans.len() + 1 };
            (curves, keys, d, a)
        };
        let held = match parent {
            Some(p) if holds => Some(held_error(
                &ws.reduced,
                &ws.dense,
                p.held.as_ref().unwrap_or(&p.error),
                &offset,
                keyed,
                self.input.radius[o],
            )?),
            _ => None,
        };
        let (distance_error, angle_error, held) = match (held, parent) {
            (Some((_, _, chain)), Some(p)) if keyed.scale => {
                // (the scale's error per sample is not kept: Blender's evaluation again,
                // against the target of the chain as played)
                let mut v = try_vec(m, "channel rows")?;
                v.extend_from_slice(&ws.v);
                hold_rows(&mut v, &ws.dense, mode, keyed, start)?;
                let target = chain_target(p.held.as_ref().unwrap_or(&p.error), &offset, &ws.dense)?;
                let whole = Fitter {
                    v: &v,
                    target: &target,
                    keyed: Keyed {
                        location: true,
                        rotation: true,
                        scale: true,
                    },
                    ..fitter
                };
                let mut played = try_vec(m, "played poses")?;
                played.resize(m, Pose::IDENTITY);
                let (d, a) = whole.check_curves(&cols, &curves, &mut played)?;
                (d, a, Some(chain))
            }
            (Some((d, a, chain)), _) => (d, a, Some(chain)),
            (None, _) => (distance_error, angle_error, None),
        };
        let world = if keep_world {
            let mut error = try_vec(m, "error transforms")?;
            error.extend(
                ws.reduced
                    .iter()
                    .zip(&ws.target)
                    .map(|(played, target)| mul_inverse(played, target)),
            );
            Some(World { error, held })
        } else {
            None
        };
        Ok(OwnerResult {
            curves,
            keys,
            distance_error,
            angle_error,
            world,
        })
    }

    /// Per-channel key frames: each channel reduced on its own within a share of the
    /// tolerance (the others exact), the whole checked through Blender's evaluation of every
    /// curve; the share halved until the whole is within the tolerance.
    #[allow(clippy::type_complexity)]
    fn per_channel_curves(
        &self,
        fitter: &Fitter<'_>,
        o: usize,
        cols: &[usize],
        constant: &[bool],
        reduced: &mut [Pose],
    ) -> Result<(Vec<ReducedCurve>, usize, f64, f64)> {
        let mut share = PER_CHANNEL_SHARE;
        let mut scratch = vec![Pose::IDENTITY; reduced.len()];
        let mut last = None;
        for _ in 0..PER_CHANNEL_ROUNDS {
            let tol = Tolerance {
                distance: self.tolerance.distance * share,
                angle: self.tolerance.angle * share,
            };
            let mut curves = Vec::with_capacity(cols.len());
            for &c in cols {
                let mut spans = Vec::new();
                fitter.greedy(&[c], constant, tol, &mut scratch, &mut spans);
                curves.push(curve_of(fitter, o, c, &spans)?);
            }
            let (d, a) = fitter.check_curves(cols, &curves, reduced)?;
            let mut frames: Vec<f64> = curves
                .iter()
                .flat_map(|c| c.keys.iter().map(|k| k.co[0]))
                .collect();
            frames.sort_by(f64::total_cmp);
            frames.dedup();
            let within = d <= self.tolerance.distance && a <= self.tolerance.angle;
            last = Some((curves, frames.len(), d, a));
            if within {
                break;
            }
            share *= 0.5;
        }
        Ok(last.expect("at least one round"))
    }
}

/// The target of a child of offset `offset` and dense local motion `dense` whose parent's
/// error transform is `e`: `O^-1 @ E @ O @ L` (module docs).
fn chain_target(e: &[Pose], offset: &Pose, dense: &[Pose]) -> Result<Vec<Pose>> {
    let mut out = try_vec(dense.len(), "targets")?;
    out.extend(
        e.iter()
            .zip(dense)
            .map(|(e, l)| mul(&mul_inverse(offset, &mul(e, offset)), l)),
    );
    Ok(out)
}

/// The error in world space of an owner whose played poses are `reduced` (the groups it does
/// not key counted as exact), where those groups play their `dense` values (a connected
/// bone's location: Blender ignores it) and its parent's played error transform is `e`
/// ([`World::held`], else [`World::error`]): the largest `|dt| + 2 r sin(theta / 2)` and
/// `theta` over the samples, and its own played error transform (for its children). The
/// search counted those groups as exact: they carry the parents' error, which only a smaller
/// tolerance on the parents reduces.
fn held_error(
    reduced: &[Pose],
    dense: &[Pose],
    e: &[Pose],
    offset: &Pose,
    keyed: Keyed,
    radius: f64,
) -> Result<(f64, f64, Vec<Pose>)> {
    let target = chain_target(e, offset, dense)?;
    let (mut dmax, mut tmax) = (0.0f64, Turn::default());
    let mut chain = try_vec(reduced.len(), "error transforms")?;
    for ((played, aim), held) in reduced.iter().zip(&target).zip(dense) {
        let played = Pose {
            rotation: if keyed.rotation {
                played.rotation
            } else {
                held.rotation
            },
            translation: if keyed.location {
                played.translation
            } else {
                held.translation
            },
        };
        let turn = Turn::between(aim.rotation, played.rotation);
        let d = (played.translation - aim.translation).length() + 2.0 * radius * turn.sin_half();
        dmax = dmax.max(d);
        if turn.exceeds(tmax) {
            tmax = turn;
        }
        chain.push(mul_inverse(&played, aim));
    }
    Ok((dmax, tmax.angle(), chain))
}

/// Channel rows `v` with the groups the owner does not key set to their `dense` values.
fn hold_rows(
    v: &mut [[f64; STRIDE]],
    dense: &[Pose],
    mode: RotationMode,
    keyed: Keyed,
    start: Option<&[f64]>,
) -> Result<()> {
    if !keyed.location {
        for (row, p) in v.iter_mut().zip(dense) {
            row[0..3].copy_from_slice(&p.translation.to_array());
        }
    }
    if !keyed.rotation {
        let width = mode.width();
        let quats: Vec<DQuat> = dense.iter().map(|p| p.rotation).collect();
        let rot = rotation_channels(&quats, mode, start)?;
        for (row, r) in v.iter_mut().zip(rot.chunks_exact(width)) {
            row[ROT..ROT + width].copy_from_slice(r);
        }
    }
    Ok(())
}

/// `a @ b` without renormalising the product of the unit quaternions (unit to rounding; the
/// channels normalise what they read).
#[inline(always)]
fn mul(a: &Pose, b: &Pose) -> Pose {
    Pose {
        rotation: a.rotation * b.rotation,
        translation: a.rotation * b.translation + a.translation,
    }
}

/// `a^-1 @ b`, as [`mul`].
#[inline(always)]
fn mul_inverse(a: &Pose, b: &Pose) -> Pose {
    let r = a.rotation.conjugate();
    Pose {
        rotation: r * b.rotation,
        translation: r * (b.translation - a.translation),
    }
}

/// The curve of channel column `c` through `spans`.
fn curve_of(fitter: &Fitter<'_>, o: usize, c: usize, spans: &[Span]) -> Result<ReducedCurve> {
    let (group, index) = match c {
        0..3 => (Group::Location, c),
        ROT..SCALE => (Group::Rotation, c - ROT),
        _ => (Group::Scale, c - SCALE),
    };
    let mut keys = try_vec(spans.len() + 1, "reduced keys")?;
    let t = fitter.times;
    let v = fitter.v;
    for (k, span) in spans.iter().enumerate() {
        let dt = t[span.e] - t[span.s];
        let co = [t[span.s], v[span.s][c]];
        let right = [t[span.s] + dt / 3.0, span.h1[c]];
        let left = match k.checked_sub(1).map(|p| spans[p]) {
            Some(p) => [t[p.e] - (t[p.e] - t[p.s]) / 3.0, p.h2[c]],
            None => [2.0 * co[0] - right[0], 2.0 * co[1] - right[1]],
        };
        keys.push(ReducedKey {
            co,
            handle_left: left,
            handle_right: right,
            interpolation: interpolation(span.constant),
        });
    }
    if let Some(p) = spans.last() {
        let co = [t[p.e], v[p.e][c]];
        let left = [t[p.e] - (t[p.e] - t[p.s]) / 3.0, p.h2[c]];
        keys.push(ReducedKey {
            co,
            handle_left: left,
            handle_right: [2.0 * co[0] - left[0], 2.0 * co[1] - left[1]],
            interpolation: Interpolation::Bezier,
        });
    }
    Ok(ReducedCurve {
        owner: o,
        group,
        index,
        keys,
        handle_type: HandleType::Free,
    })
}

/// The samples, target and channels of one owner, and the span fitting and checks on them.
struct Fitter<'w> {
    times: &'w [f64],
    times32: &'w [f32],
    v: &'w [[f64; STRIDE]],
    target: &'w [Pose],
    scale: &'w [DVec3],
    /// Per sample, the rotation channels' Jacobian (`None`: axis-angle, composed exactly).
    jac: Option<&'w [[[f64; 4]; 3]]>,
    mode: RotationMode,
    keyed: Keyed,
    radius: f64,
    /// The number of keyed columns (a search over all of them takes
    /// [`Fitter::model_ok_groups`]).
    keyed_cols: usize,
}

/// Cubic Bernstein basis at `u`.
#[inline(always)]
fn bernstein(u: f64) -> [f64; 4] {
    let w = 1.0 - u;
    [w * w * w, 3.0 * u * w * w, 3.0 * u * u * w, u * u * u]
}

/// Running sums of the samples after a key, from which [`Fitter::fit_sums`] fits any span
/// starting at the key in O(columns): with `tau_j = t_j - t_key`, `sum tau^p` (p = 1..6) and
/// per column `sum tau^p v` (p = 1..3), over the samples `key + 1 ..= last`. A span's end
/// only rescales them (`u = tau / D`), so the search extends one set of sums from its
/// longest success instead of refitting every candidate over all its samples.
#[derive(Debug, Clone, Copy)]
struct Sums {
    key: usize,
    last: usize,
    /// `sum tau^p`, `p = 0..7` (entry 0 unused).
    powers: [f64; 7],
    /// Per column, `sum tau^p v` for `p = 1, 2, 3`.
    values: [[f64; 3]; STRIDE],
}

impl Sums {
    /// No samples yet after `key`.
    fn new(key: usize) -> Self {
        Self {
            key,
            last: key,
            powers: [0.0; 7],
            values: [[0.0; 3]; STRIDE],
        }
    }

    /// Adds the samples `self.last + 1 ..= last` of columns `cols` (of every column when
    /// `cols` has more than one).
    #[inline]
    fn extend(&mut self, fitter: &Fitter<'_>, last: usize, cols: &[usize]) {
        if last <= self.last {
            return;
        }
        let t0 = fitter.times[self.key];
        let range = self.last + 1..last + 1;
        let samples = fitter.times[range.clone()].iter().zip(&fitter.v[range]);
        // The sums in locals while they are added to (kept in registers, stored once).
        let mut powers = self.powers;
        let mut values = self.values;
        // The keyed groups' columns at fixed places: a group holds all its columns or none
        // (one column alone: per-channel keys). The fourth rotation column of an Euler
        // owner is zero; a sum that is not read may take any value.
        let group = |first: usize| cols.contains(&first);
        let (loc, rot, scale) = match cols {
            [_] => (false, false, false),
            _ => (group(0), group(ROT), group(SCALE)),
        };
        for (t, v) in samples {
            let tau = t - t0;
            let t2 = tau * tau;
            let t3 = t2 * tau;
            powers[1] += tau;
            powers[2] += t2;
            powers[3] += t3;
            powers[4] += t2 * t2;
            powers[5] += t2 * t3;
            powers[6] += t3 * t3;
            let mut add = |c: usize| {
                let sum = &mut values[c];
                sum[0] += tau * v[c];
                sum[1] += t2 * v[c];
                sum[2] += t3 * v[c];
            };
            if let [c] = cols {
                add(*c);
            }
            if loc {
                (0..3).for_each(&mut add);
            }
            if rot {
                (ROT..ROT + 4).for_each(&mut add);
            }
            if scale {
                (SCALE..SCALE + 3).for_each(&mut add);
            }
        }
        self.powers = powers;
        self.values = values;
        self.last = last;
    }
}

impl Fitter<'_> {
    /// [`row_error`] of channel row `y` at sample `j`.
    #[inline(always)]
    fn error(&self, j: usize, y: &[f64; STRIDE]) -> (f64, Turn, DQuat, DVec3) {
        let p = &self.target[j];
        row_error(
            self.mode,
            self.keyed,
            self.radius,
            y,
            p.rotation,
            p.translation,
            self.scale[j],
        )
    }

    /// The search's error of channel row `y` at sample `j`: as [`row_error`], with the
    /// rotation's angle to first order (`|J dr|`, see [`jacobian`]) and `r theta` for
    /// `2 r sin(theta / 2)` (never less).
    #[inline(always)]
    fn model_error(&self, j: usize, y: &[f64; STRIDE]) -> (f64, f64) {
        let v = &self.v[j];
        let mut d = 0.0;
        if self.keyed.location {
            let (a, b, c) = (y[0] - v[0], y[1] - v[1], y[2] - v[2]);
            d += (a * a + b * b + c * c).sqrt();
        }
        let mut theta = 0.0;
        if self.keyed.rotation {
            theta = match self.jac {
                Some(jac) => {
                    let jj = &jac[j];
                    let dr = [
                        y[ROT] - v[ROT],
                        y[ROT + 1] - v[ROT + 1],
                        y[ROT + 2] - v[ROT + 2],
                        y[ROT + 3] - v[ROT + 3],
                    ];
                    let w = |row: &[f64; 4]| {
                        row[0] * dr[0] + row[1] * dr[1] + row[2] * dr[2] + row[3] * dr[3]
                    };
                    let (a, b, c) = (w(&jj[0]), w(&jj[1]), w(&jj[2]));
                    (a * a + b * b + c * c).sqrt()
                }
                None => {
                    relative_angle(
                        self.target[j].rotation,
                        rotation(self.mode, &y[ROT..ROT + 4]),
                    )
                    .1
                }
            };
            d += self.radius * theta;
        }
        if self.keyed.scale {
            let (a, b, c) = (
                y[SCALE] - v[SCALE],
                y[SCALE + 1] - v[SCALE + 1],
                y[SCALE + 2] - v[SCALE + 2],
            );
            d += self.radius * (a * a + b * b + c * c).sqrt();
        }
        (d, theta)
    }

    /// [`Self::model_ok`] when every keyed column is fitted and the rotation has a Jacobian:
    /// the groups' columns at fixed places, so the loop holds no lookup. The columns of a
    /// group that is not keyed are computed and not read; the fourth rotation column of an
    /// Euler owner is zero in the dense rows, the handles and the Jacobian, so its terms are
    /// zeros: the same numbers as the general path, in the same order.
    fn model_ok_groups(
        &self,
        jac: &[[[f64; 4]; 3]],
        s: usize,
        e: usize,
        h1: &[f64; STRIDE],
        h2: &[f64; STRIDE],
        limit: Tolerance,
    ) -> bool {
        let (p0, p3) = (&self.v[s], &self.v[e]);
        let ts = self.times[s];
        let inv = 1.0 / (self.times[e] - ts);
        let Keyed {
            location,
            rotation,
            scale,
        } = self.keyed;
        let radius = self.radius;
        let within = |j: usize| -> bool {
            let [b0, b1, b2, b3] = bernstein((self.times[j] - ts) * inv);
            let v = &self.v[j];
            let dy = |c: usize| (p0[c] * b0 + h1[c] * b1 + h2[c] * b2 + p3[c] * b3) - v[c];
            let mut d = 0.0;
            if location {
                let (a, b, c) = (dy(0), dy(1), dy(2));
                d += (a * a + b * b + c * c).sqrt();
            }
            let mut theta = 0.0;
            if rotation {
                let dr = [dy(ROT), dy(ROT + 1), dy(ROT + 2), dy(ROT + 3)];
                let jj = &jac[j];
                let w = |row: &[f64; 4]| {
                    row[0] * dr[0] + row[1] * dr[1] + row[2] * dr[2] + row[3] * dr[3]
                };
                let (a, b, c) = (w(&jj[0]), w(&jj[1]), w(&jj[2]));
                theta = (a * a + b * b + c * c).sqrt();
                d += radius * theta;
            }
            if scale {
                let (a, b, c) = (dy(SCALE), dy(SCALE + 1), dy(SCALE + 2));
                d += radius * (a * a + b * b + c * c).sqrt();
            }
            !(d > limit.distance || theta > limit.angle)
        };
        // The middle of every frame first, where a span that is too long fails soonest,
        // then the other samples.
        let half = SUBSAMPLES / 2;
        let mut j = s + half;
        while j < e {
            if !within(j) {
                return false;
            }
            j += SUBSAMPLES;
        }
        for j in s + 1..e {
            if (j - s) % SUBSAMPLES != half && !within(j) {
                return false;
            }
        }
        true
    }

    /// [`Self::model_error`] from the differences `dy` of the channel row to the dense one
    /// and the sample's rotation Jacobian `jj` (the same operations on the same numbers).
    #[inline(always)]
    fn model_error_of(&self, jj: &[[f64; 4]; 3], dy: &[f64; STRIDE]) -> (f64, f64) {
        let mut d = 0.0;
        if self.keyed.location {
            let (a, b, c) = (dy[0], dy[1], dy[2]);
            d += (a * a + b * b + c * c).sqrt();
        }
        let mut theta = 0.0;
        if self.keyed.rotation {
            let dr = [dy[ROT], dy[ROT + 1], dy[ROT + 2], dy[ROT + 3]];
            let w =
                |row: &[f64; 4]| row[0] * dr[0] + row[1] * dr[1] + row[2] * dr[2] + row[3] * dr[3];
            let (a, b, c) = (w(&jj[0]), w(&jj[1]), w(&jj[2]));
            theta = (a * a + b * b + c * c).sqrt();
            d += self.radius * theta;
        }
        if self.keyed.scale {
            let (a, b, c) = (dy[SCALE], dy[SCALE + 1], dy[SCALE + 2]);
            d += self.radius * (a * a + b * b + c * c).sqrt();
        }
        (d, theta)
    }

    /// The inner handle values of the span `s..=e` for columns `cols`: least squares over
    /// the samples strictly inside, the key values fixed; a straight line when fewer than
    /// three samples are inside ([`Sums`] from `s`, then [`Self::fit_sums`]).
    fn fit(
        &self,
        s: usize,
        e: usize,
        cols: &[usize],
        h1: &mut [f64; STRIDE],
        h2: &mut [f64; STRIDE],
    ) {
        let mut sums = Sums::new(s);
        sums.extend(self, e - 1, cols);
        self.fit_sums(&sums, e, cols, h1, h2);
    }

    /// [`Self::fit`] of the span from `sums.key` to `e` from the running sums `sums` of the
    /// samples strictly inside (`sums.last == e - 1`): with `u = tau / D`, `D = t_e - t_key`,
    /// `S_p = sum u^p` and `Q_p = sum u^p v`, the normal equations of the two inner Bernstein
    /// coefficients are
    ///
    /// ```text
    /// [a11 a12] [h1]   [r1]     a11 = sum b1^2 = 9 sum u^2 (1 - u)^4, a12 = sum b1 b2 = 9 sum u^3 (1 - u)^3,
    /// [a12 a22] [h2] = [r2]     a22 = sum b2^2 = 9 sum u^4 (1 - u)^2,
    /// r1 = sum b1 v - v0 sum b1 b0 - v3 sum b1 b3 = 3 (Q1 - 2 Q2 + Q3) - 3 v0 sum u (1 - u)^5 - 3 v3 sum u^4 (1 - u)^2,
    /// r2 = sum b2 v - v0 sum b2 b0 - v3 sum b2 b3 = 3 (Q2 - Q3) - 3 v0 sum u^2 (1 - u)^4 - 3 v3 sum u^5 (1 - u),
    /// ```
    ///
    /// each sum of powers of `u` expanded in `S_1 .. S_6`: O(columns) per span instead of
    /// O(samples x columns).
    fn fit_sums(
        &self,
        sums: &Sums,
        e: usize,
        cols: &[usize],
        h1: &mut [f64; STRIDE],
        h2: &mut [f64; STRIDE],
    ) {
        let s = sums.key;
        debug_assert_eq!(sums.last + 1, e);
        let (v0, v3) = (&self.v[s], &self.v[e]);
        let d = self.times[e] - self.times[s];
        let inv = 1.0 / d;
        let mut scale = [1.0; 7];
        for p in 1..7 {
            scale[p] = scale[p - 1] * inv;
        }
        let sp = |p: usize| sums.powers[p] * scale[p];
        let (s1, s2, s3, s4, s5, s6) = (sp(1), sp(2), sp(3), sp(4), sp(5), sp(6));
        // sum u^2 (1 - u)^4, u^3 (1 - u)^3, u^4 (1 - u)^2, u (1 - u)^5, u^5 (1 - u).
        let p24 = s2 - 4.0 * s3 + 6.0 * s4 - 4.0 * s5 + s6;
        let p33 = s3 - 3.0 * s4 + 3.0 * s5 - s6;
        let p42 = s4 - 2.0 * s5 + s6;
        let p15 = s1 - 5.0 * s2 + 10.0 * s3 - 10.0 * s4 + 5.0 * s5 - s6;
        let p51 = s5 - s6;
        let (a11, a12, a22) = (9.0 * p24, 9.0 * p33, 9.0 * p42);
        let det = a11 * a22 - a12 * a12;
        if e - s < 4 || det <= 1e-9 * a11 * a22 {
            for &c in cols {
                h1[c] = v0[c] + (v3[c] - v0[c]) / 3.0;
                h2[c] = v3[c] - (v3[c] - v0[c]) / 3.0;
            }
            return;
        }
        let inv_det = 1.0 / det;
        for &c in cols {
            let [q1, q2, q3] = sums.values[c];
            let (q1, q2, q3) = (q1 * scale[1], q2 * scale[2], q3 * scale[3]);
            let r1 = 3.0 * (q1 - 2.0 * q2 + q3) - 3.0 * v0[c] * p15 - 3.0 * v3[c] * p42;
            let r2 = 3.0 * (q2 - q3) - 3.0 * v0[c] * p24 - 3.0 * v3[c] * p51;
            h1[c] = (a22 * r1 - a12 * r2) * inv_det;
            h2[c] = (a11 * r2 - a12 * r1) * inv_det;
        }
    }

    /// Whether the `f64` cubic of the span stays within `limit` at every sample inside.
    fn model_ok(
        &self,
        s: usize,
        e: usize,
        cols: &[usize],
        h1: &[f64; STRIDE],
        h2: &[f64; STRIDE],
        limit: Tolerance,
    ) -> bool {
        if let (Some(jac), true) = (self.jac, cols.len() == self.keyed_cols) {
            return self.model_ok_groups(jac, s, e, h1, h2, limit);
        }
        let (v0, v3) = (&self.v[s], &self.v[e]);
        let ts = self.times[s];
        let inv = 1.0 / (self.times[e] - ts);
        // Each column's four Bezier values, gathered once per span.
        let mut coef = [(0usize, [0.0f64; 4]); STRIDE];
        for (slot, &c) in coef.iter_mut().zip(cols) {
            *slot = (c, [v0[c], h1[c], h2[c], v3[c]]);
        }
        let coef = &coef[..cols.len()];
        let within = |j: usize| {
            let [b0, b1, b2, b3] = bernstein((self.times[j] - ts) * inv);
            match self.jac {
                Some(jac) => {
                    // The cubic minus the dense values (zero in the other columns): the
                    // same numbers `model_error` forms from the whole row.
                    let v = &self.v[j];
                    let mut dy = [0.0; STRIDE];
                    for &(c, [p0, p1, p2, p3]) in coef {
                        dy[c] = (p0 * b0 + p1 * b1 + p2 * b2 + p3 * b3) - v[c];
                    }
                    let (d, a) = self.model_error_of(&jac[j], &dy);
                    !(d > limit.distance || a > limit.angle)
                }
                None => {
                    let mut y = self.v[j];
                    for &(c, [p0, p1, p2, p3]) in coef {
                        y[c] = p0 * b0 + p1 * b1 + p2 * b2 + p3 * b3;
                    }
                    let (d, a) = self.model_error(j, &y);
                    !(d > limit.distance || a > limit.angle)
                }
            }
        };
        // The middle of every frame first, where a span that is too long fails soonest,
        // then the other samples.
        let half = SUBSAMPLES / 2;
        if !(s + half..e).step_by(SUBSAMPLES).all(within) {
            return false;
        }
        (s + 1..e)
            .filter(|j| (j - s) % SUBSAMPLES != half)
            .all(within)
    }

    /// Blender's evaluation of the span's `float32` keys at every sample of `s..=e` (the
    /// first key's value across a CONSTANT span): whether it stays within `limit`, the
    /// largest errors, and the played poses written to `out[s..=e]`.
    #[allow(clippy::needless_range_loop)]
    fn exact(
        &self,
        span: &Span,
        cols: &[usize],
        limit: Tolerance,
        out: &mut [Pose],
    ) -> (bool, f64, f64) {
        let Span { s, e, .. } = *span;
        let (x0, x3) = (self.times32[s], self.times32[e]);
        let dt = self.times[e] - self.times[s];
        let hx1 = (self.times[s] + dt / 3.0) as f32;
        let hx2 = (self.times[e] - dt / 3.0) as f32;
        let mut segs = [None; STRIDE];
        let mut k0 = [0.0f32; STRIDE];
        let mut k1 = [0.0f32; STRIDE];
        for &c in cols {
            let (y0, y3) = (self.v[s][c] as f32, self.v[e][c] as f32);
            k0[c] = y0;
            k1[c] = y3;
            if !span.constant {
                segs[c] = Some(BezierSegment::new(
                    [x0, y0],
                    [hx1, span.h1[c] as f32],
                    [hx2, span.h2[c] as f32],
                    [x3, y3],
                ));
            }
        }
        let first = cols.first().and_then(|c| segs[*c]);
        let near = |a: f32, b: f32| (a - b).abs() <= KEY_THRESHOLD;
        // The largest turn, its angle taken once at the end (one `atan2` per span).
        let (mut dmax, mut tmax) = (0.0f64, Turn::default());
        let mut finite = true;
        for j in s..=e {
            let t = self.times32[j];
            let mut y = self.v[j];
            if j == s || near(t, x0) || (span.constant && !near(t, x3) && j != e) {
                for &c in cols {
                    y[c] = k0[c] as f64;
                }
            } else if j == e || near(t, x3) {
                for &c in cols {
                    y[c] = k1[c] as f64;
                }
            } else {
                let u = first.and_then(|seg| seg.parameter(t));
                for &c in cols {
                    y[c] = segs[c].map_or(k0[c], |seg| seg.value_at(u)) as f64;
                }
            }
            let (d, turn, q, tr) = self.error(j, &y);
            finite &= !(d.is_nan() || turn.s.is_nan() || turn.c.is_nan());
            dmax = dmax.max(d);
            if turn.exceeds(tmax) {
                tmax = turn;
            }
            out[j] = Pose {
                rotation: q,
                translation: tr,
            };
        }
        let amax = tmax.angle();
        let ok = finite && dmax <= limit.distance && amax <= limit.angle;
        (ok, dmax, amax)
    }

    /// Fits the span `s..=e` (from `sums`, the running sums of its inner samples, when
    /// given) and checks it by the model (`exact`: and by Blender's evaluation): the span,
    /// and the exact errors when checked exactly.
    #[allow(clippy::too_many_arguments)]
    fn try_span(
        &self,
        s: usize,
        e: usize,
        cols: &[usize],
        tol: Tolerance,
        exact: bool,
        out: &mut [Pose],
        sums: Option<&Sums>,
    ) -> (Option<Span>, f64, f64) {
        let mut span = Span {
            s,
            e,
            constant: false,
            h1: [0.0; STRIDE],
            h2: [0.0; STRIDE],
        };
        match sums {
            Some(sums) => self.fit_sums(sums, e, cols, &mut span.h1, &mut span.h2),
            None => self.fit(s, e, cols, &mut span.h1, &mut span.h2),
        }
        let model = Tolerance {
            distance: tol.distance * SEARCH_MARGIN,
            angle: tol.angle * SEARCH_MARGIN,
        };
        if !self.model_ok(s, e, cols, &span.h1, &span.h2, model) {
            return (None, 0.0, 0.0);
        }
        if !exact {
            return (Some(span), 0.0, 0.0);
        }
        let (ok, d, a) = self.exact(&span, cols, tol, out);
        (ok.then_some(span), d, a)
    }

    /// Key frames for columns `cols` within `tol`: CONSTANT spans kept, the longest feasible
    /// span from each key elsewhere. Writes the played poses to `out` and the spans to
    /// `spans`; returns the largest exact errors.
    fn greedy(
        &self,
        cols: &[usize],
        constant: &[bool],
        tol: Tolerance,
        out: &mut [Pose],
        spans: &mut Vec<Span>,
    ) -> (f64, f64) {
        let n = constant.len() + 1;
        let (mut dmax, mut amax) = (0.0f64, 0.0f64);
        let mut f = 0;
        while f < n - 1 {
            if constant[f] {
                let s = f * SUBSAMPLES;
                let span = Span {
                    s,
                    e: s + SUBSAMPLES,
                    constant: true,
                    h1: self.v[s],
                    h2: self.v[s],
                };
                let (_, d, a) = self.exact(&span, cols, tol, out);
                dmax = dmax.max(d);
                amax = amax.max(a);
                spans.push(span);
                f += 1;
                continue;
            }
            let mut g = f;
            while g < n - 1 && !constant[g] {
                g += 1;
            }
            let (d, a) = self.run(f * SUBSAMPLES, g * SUBSAMPLES, cols, tol, out, spans);
            dmax = dmax.max(d);
            amax = amax.max(a);
            f = g;
        }
        (dmax, amax)
    }

    /// The greedy choice over the samples `a..=b` (no CONSTANT span inside).
    fn run(
        &self,
        a: usize,
        b: usize,
        cols: &[usize],
        tol: Tolerance,
        out: &mut [Pose],
        spans: &mut Vec<Span>,
    ) -> (f64, f64) {
        let (mut dmax, mut amax) = (0.0f64, 0.0f64);
        let mut key = a;
        // Spans of neighbouring keys are alike: the search starts from the last one's length.
        let mut guess = 4;
        while key < b {
            let first = (key / SUBSAMPLES + 1) * SUBSAMPLES;
            let count = (b - first) / SUBSAMPLES + 1;
            let pos = |k: usize| first + k * SUBSAMPLES;
            // The span of the longest model success so far (that of `lo` below), so that
            // the exact check does not fit it again.
            let mut fitted: Option<Span> = None;
            // The running sums of that span's inner samples (none yet): every candidate is
            // longer than the longest success so far, so its sums extend these.
            let mut fitted_sums = Sums::new(key);
            let mut ok = |k: usize, out: &mut [Pose]| {
                let e = pos(k - 1);
                let mut sums = fitted_sums;
                sums.extend(self, e - 1, cols);
                let span = self.try_span(key, e, cols, tol, false, out, Some(&sums)).0;
                let pass = span.is_some();
                if pass {
                    fitted = span;
                    fitted_sums = sums;
                }
                pass
            };
            // The longest span by the model: from the previous span's length, exponential
            // steps out to the first failure, then binary search (indices shifted by one:
            // 0 means no whole-frame span fits).
            let g = guess.clamp(1, count);
            let (mut lo, mut hi) = if ok(g, out) {
                let (mut lo, mut hi) = (g, count + 1);
                let mut step = 1.max(g / 2);
                while lo < count {
                    let k = (lo + step).min(count);
                    if ok(k, out) {
                        lo = k;
                        step *= 2;
                    } else {
                        hi = k;
                        break;
                    }
                }
                (lo, hi)
            } else {
                (0, g)
            };
            while hi - lo > 1 {
                let mid = lo + (hi - lo) / 2;
                if ok(mid, out) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            let best = lo.checked_sub(1);
            if let Some(b) = best {
                guess = b + 1;
            }
            // Blender's evaluation of the chosen span; shorter ones while it fails.
            let mut accepted: Option<(Span, f64, f64)> = None;
            if let Some(lo) = best {
                // `lo` only ever takes a model success, each longer than the last: `fitted`
                // is the span ending at `pos(lo)`, fitted and passed by the model.
                let span = fitted.expect("the longest model success is kept");
                debug_assert_eq!(span.e, pos(lo));
                let (pass, d, a) = self.exact(&span, cols, tol, out);
                if pass {
                    accepted = Some((span, d, a));
                } else {
                    let (mut good, mut bad) = (None, lo);
                    let mut lo2 = 0;
                    while lo2 < bad {
                        let mid = lo2 + (bad - lo2) / 2;
                        match self.try_span(key, pos(mid), cols, tol, true, out, None) {
                            (Some(_), _, _) => {
                                good = Some(mid);
                                lo2 = mid + 1;
                            }
                            _ => bad = mid,
                        }
                    }
                    if let Some(g) = good {
                        let (span, d, a) = self.try_span(key, pos(g), cols, tol, true, out, None);
                        accepted = span.map(|s| (s, d, a));
                    }
                }
            }
            // Shorter than a frame: subframe keys, down to the next sample (exact keys).
            let (span, d, a) = match accepted {
                Some(x) => x,
                None => {
                    let mut e = first - 1;
                    loop {
                        if e <= key + 1 {
                            let mut span = Span {
                                s: key,
                                e: key + 1,
                                constant: false,
                                h1: [0.0; STRIDE],
                                h2: [0.0; STRIDE],
                            };
                            self.fit(key, key + 1, cols, &mut span.h1, &mut span.h2);
                            let (_, d, a) = self.exact(&span, cols, tol, out);
                            break (span, d, a);
                        }
                        if let (Some(span), d, a) =
                            self.try_span(key, e, cols, tol, true, out, None)
                        {
                            break (span, d, a);
                        }
                        e -= 1;
                    }
                }
            };
            dmax = dmax.max(d);
            amax = amax.max(a);
            key = span.e;
            spans.push(span);
        }
        (dmax, amax)
    }

    /// Blender's evaluation of whole curves (columns `cols`, `curves` in the same order) at
    /// every sample: the largest errors, the played poses written to `out`.
    fn check_curves(
        &self,
        cols: &[usize],
        curves: &[ReducedCurve],
        out: &mut [Pose],
    ) -> Result<(f64, f64)> {
        let mut fcurves = Vec::with_capacity(curves.len());
        for c in curves {
            let keys = c.keys.iter().map(ReducedKey::key).collect();
            fcurves.push(FCurve::new(keys, Extrapolation::Constant, None)?);
        }
        let (mut dmax, mut amax) = (0.0f64, 0.0f64);
        for (j, slot) in out.iter_mut().enumerate() {
            let mut y = self.v[j];
            for (&c, curve) in cols.iter().zip(&fcurves) {
                y[c] = curve.evaluate(self.times[j])?;
            }
            let (d, turn, q, t) = self.error(j, &y);
            let a = turn.angle();
            dmax = dmax.max(d);
            amax = amax.max(a);
            *slot = Pose {
                rotation: q,
                translation: t,
            };
        }
        Ok((dmax, amax))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The direct least-squares fit the running sums replace: the normal equations summed
    /// sample by sample (the reduction's fit before [`Sums`]).
    fn direct_fit(
        times: &[f64],
        v: &[[f64; STRIDE]],
        s: usize,
        e: usize,
        cols: &[usize],
    ) -> ([f64; STRIDE], [f64; STRIDE]) {
        let (v0, v3) = (&v[s], &v[e]);
        let ts = times[s];
        let inv = 1.0 / (times[e] - ts);
        let (mut a11, mut a12, mut a22) = (0.0, 0.0, 0.0);
        let mut r1 = [0.0; STRIDE];
        let mut r2 = [0.0; STRIDE];
        for j in s + 1..e {
            let [b0, b1, b2, b3] = bernstein((times[j] - ts) * inv);
            a11 += b1 * b1;
            a12 += b1 * b2;
            a22 += b2 * b2;
            for &c in cols {
                let r = v[j][c] - v0[c] * b0 - v3[c] * b3;
                r1[c] += b1 * r;
                r2[c] += b2 * r;
            }
        }
        let det = a11 * a22 - a12 * a12;
        let (mut h1, mut h2) = ([0.0; STRIDE], [0.0; STRIDE]);
        for &c in cols {
            h1[c] = (a22 * r1[c] - a12 * r2[c]) / det;
            h2[c] = (a11 * r2[c] - a12 * r1[c]) / det;
        }
        (h1, h2)
    }

    #[test]
    fn running_sum_fit_equals_the_direct_fit() {
        // Uneven frames far from 0 (so that tau, not t, must be summed), 4 samples per frame.
        let frames: Vec<f64> = (0..200)
            .map(|i| 1000.0 + i as f64 + 0.3 * (i as f64 * 0.7).sin())
            .collect();
        let mut times = Vec::new();
        for w in frames.windows(2) {
            for k in 0..SUBSAMPLES {
                times.push(w[0] + (w[1] - w[0]) * k as f64 / SUBSAMPLES as f64);
            }
        }
        times.push(*frames.last().unwrap());
        let times32: Vec<f32> = times.iter().map(|t| *t as f32).collect();
        let v: Vec<[f64; STRIDE]> = times
            .iter()
            .map(|t| {
                let mut row = [0.0; STRIDE];
                for (c, x) in row.iter_mut().enumerate() {
                    *x = (0.05 * t * (1.0 + c as f64 * 0.1)).sin() * (1.0 + c as f64) + 30.0;
                }
                row
            })
            .collect();
        let m = times.len();
        let target = vec![Pose::IDENTITY; m];
        let scale = vec![DVec3::ONE; m];
        let fitter = Fitter {
            times: &times,
            times32: &times32,
            v: &v,
            target: &target,
            scale: &scale,
            jac: None,
            mode: RotationMode::Quaternion,
            keyed: Keyed {
                location: true,
                rotation: true,
                scale: true,
            },
            radius: 1.0,
            keyed_cols: STRIDE,
        };
        let cols: Vec<usize> = (0..STRIDE).collect();
        for key in [0usize, 37, 400] {
            // One set of sums extended span by span, as the search does.
            let mut sums = Sums::new(key);
            for len in [5usize, 9, 16, 40, 41, 120, 300] {
                let e = key + len;
                if e >= m {
                    continue;
                }
                sums.extend(&fitter, e - 1, &cols);
                let (mut h1, mut h2) = ([0.0; STRIDE], [0.0; STRIDE]);
                fitter.fit_sums(&sums, e, &cols, &mut h1, &mut h2);
                let (d1, d2) = direct_fit(&times, &v, key, e, &cols);
                for c in 0..STRIDE {
                    for (got, want) in [(h1[c], d1[c]), (h2[c], d2[c])] {
                        assert!(
                            (got - want).abs() <= 1e-9 * (1.0 + want.abs()),
                            "key {key}, span {len}, column {c}: {got} vs {want}"
                        );
                    }
                }
                // And the fit from scratch agrees with the extended one.
                let (mut g1, mut g2) = ([0.0; STRIDE], [0.0; STRIDE]);
                fitter.fit(key, e, &cols, &mut g1, &mut g2);
                assert_eq!((g1, g2), (h1, h2), "key {key}, span {len}");
            }
        }
    }
}
