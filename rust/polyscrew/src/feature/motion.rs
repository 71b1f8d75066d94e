//! Motion design from feature points (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*,
//! sections 3 and 4.3): run a curve scheme on the homologous positions of feature points of the key poses, then
//! register the rigid body to the distorted points at every output sample.
//!
//! ```text
//! f^k_i = L_i(f^k)                      homologous positions of feature point k   (sec. 3.1)
//! f^k(t) = curve scheme on f^k_1..f^k_N  the distorted ("affine") motion            (eq. 11-12)
//! L(t) = argmin_m sum_k |m(f^k) - f^k(t)|^2   registration (Horn)                  (eq. 13)
//! ```
//!
//! Every scheme offered is linear once its parametrisation is fixed (the centripetal one is
//! computed once from all feature points, the metric of `A^12`), so the distorted body is an
//! affine image of the rest body and the section 4.3 shortcut applies: the scheme runs on
//! the four control points of the feature cloud's [`InertiaFrame`], and the six inertia
//! points, carried along by their barycentric coordinates, are registered at every sample.
//! The result equals registering all the feature points (Proposition 2; tested).
//!
//! Properties: the output is rigid (unit quaternions); it is invariant under a change of
//! world frame (`A L_i -> A L(t)`), since the schemes commute with affine maps and
//! registration with rigid ones; interpolating schemes (four-point, variational with all
//! keys stiff) return the keys exactly. The motion is as smooth as the curve scheme
//! (Theorem 1) wherever the largest eigenvalue of Horn's matrix is simple; where it is not
//! (the distorted body is degenerate, for example two keys half a turn apart averaged by an
//! approximating scheme), the motion is undefined and an error names the sample.
//!
//! ```
//! use glam::{DQuat, DVec3};
//! use polyscrew::{feature_motion, FeatureSpec, Pose, Stiffness};
//!
//! let keys: Vec<Pose> = (0..6)
//!     .map(|i| {
//!         let a = i as f64;
//!         Pose::from_rotation_translation(DQuat::from_rotation_z(a), DVec3::new(a, a.sin(), 0.0))
//!     })
//!     .collect();
//! // The paper's Table 1 case: 6 closed keys, 7 levels of closed uniform interpolating design.
//! let spec = FeatureSpec { levels: 7, closed: true, ..FeatureSpec::default() };
//! let dense = feature_motion(&keys, None, &spec).unwrap();
//! assert_eq!(dense.len(), 768);
//! assert_eq!(dense[128], keys[1]); // every key is hit
//! // Approximating: inner keys on springs of stiffness 0.5, the ends hit.
//! let inf = f64::INFINITY;
//! let spec = FeatureSpec {
//!     stiffness: Stiffness::keys(vec![inf, 0.5, 0.5, 0.5, 0.5, inf]),
//!     ..FeatureSpec::default()
//! };
//! let smooth = feature_motion(&keys, None, &spec).unwrap();
//! assert_eq!(smooth.len(), 5 * 32 + 1);
//! ```

use glam::DVec3;

use crate::error::{Error, Result};
use crate::feature::inertia::InertiaFrame;
use crate::feature::registration::{cross_covariance, rotation_from_covariance_warm, IDENTITY4};
use crate::feature::variational::{
    spans_spacing, variational_subdivide, Parametrization, Stiffness,
};
use crate::memory::{try_vec, Footprint};
use crate::motion::pose::Pose;
use crate::motion::sample::Motion;
use crate::motion::subdivision::{check_subdivision, subdivide_checked, subdivided_len, Scheme};
use crate::motion::timing::Timing;

/// The curve scheme run on the feature points' trajectories.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
pub enum CurveScheme {
    /// Dyn-Gregory-Levin 4-point on points: interpolating, C1.
    FourPoint,
    /// Uniform cubic B-spline on points: approximating, C2.
    BSpline,
    /// Jarek on points: approximating, C2.
    Jarek,
    /// Kobbelt's variational subdivision: interpolating, or approximating with per-key
    /// springs; uniform or centripetal; C2 (Hofer-Pottmann-Ravani, *From curve design algorithms to the design of rigid body motions*, section 4).
    #[default]
    Variational,
}

impl CurveScheme {
    /// Parses `"four_point"`, `"bspline"`, `"jarek"` or `"variational"`.
    ///
    /// # Errors
    /// [`Error::Choice`] for any other name.
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "variational" => Ok(Self::Variational),
            _ => match Scheme::from_name(name) {
                Ok(Scheme::FourPoint) => Ok(Self::FourPoint),
                Ok(Scheme::BSpline) => Ok(Self::BSpline),
                Ok(Scheme::Jarek) => Ok(Self::Jarek),
                Err(_) => Err(Error::Choice {
                    what: "scheme",
                    got: name.to_owned(),
                    expected: &["variational", "four_point", "bspline", "jarek"],
                }),
            },
        }
    }

    /// The Split&Tweak scheme on points, for the three local schemes.
    pub fn split(self) -> Option<Scheme> {
        match self {
            Self::FourPoint => Some(Scheme::FourPoint),
            Self::BSpline => Some(Scheme::BSpline),
            Self::Jarek => Some(Scheme::Jarek),
            Self::Variational => None,
        }
    }
}

/// Everything that defines a feature-point motion besides its keys and feature points.
#[derive(Debug, Clone, PartialEq)]
pub struct FeatureSpec {
    /// The curve scheme.
    pub scheme: CurveScheme,
    /// Subdivision levels, `0..=MAX_LEVELS`.
    pub levels: u32,
    /// Whether the keys form a cycle.
    pub closed: bool,
    /// Parameter spacing of the variational scheme (the local schemes are uniform).
    pub parametrization: Parametrization,
    /// Springs of the variational scheme (the local schemes take none).
    pub stiffness: Stiffness,
}

impl Default for FeatureSpec {
    fn default() -> Self {
        Self {
            scheme: CurveScheme::Variational,
            levels: 5,
            closed: false,
            parametrization: Parametrization::Uniform,
            stiffness: Stiffness::default(),
        }
    }
}

impl FeatureSpec {
    /// Whether the motion passes through every key exactly.
    pub fn interpolates_keys(&self) -> bool {
        match self.scheme {
            CurveScheme::FourPoint => true,
            CurveScheme::Variational => self.stiffness.keeps_keys(),
            CurveScheme::BSpline | CurveScheme::Jarek => false,
        }
    }
}

/// The default feature points: the six points `+-x, +-y, +-z` of the body's unit frame.
///
/// Their barycentre is the body origin and their inertia is isotropic (`J = 2 I`), so the
/// motion does not depend on how the body's local axes are turned about its origin
/// (`L_i B -> L(t) B` for a rotation `B`) nor on any scale; registration to them is the
/// nearest rotation (polar decomposition) of the distorted frame.
pub const UNIT_FRAME_POINTS: [DVec3; 6] = [
    DVec3::X,
    DVec3::NEG_X,
    DVec3::Y,
    DVec3::NEG_Y,
    DVec3::Z,
    DVec3::NEG_Z,
];

/// Bytes [`feature_motion`] holds per output pose at its peak, with room: the four control
/// points' trajectories (96) and, for the variational scheme, the last level's system
/// (unknowns, stencils, springs, band factor, right-hand side: about 200), the pose (56).
pub const FEATURE_BYTES_PER_POSE: usize = 512;

/// How to ask the feature-point design for less memory.
pub const FEATURE_HINT: &str = "use fewer levels or fewer keys";

/// What [`feature_motion`] holds at its peak for `keys` keys and `feature_points` points.
pub fn feature_footprint(keys: usize, feature_points: usize, spec: &FeatureSpec) -> Footprint {
    let poses = subdivided_len(keys, spec.levels, spec.closed);
    let centripetal = if spec.parametrization == Parametrization::Centripetal {
        Footprint::of::<DVec3>(keys.saturating_mul(feature_points))
    } else {
        Footprint::ZERO
    };
    Footprint::bytes(FEATURE_BYTES_PER_POSE).times(poses) + centripetal
}

/// The rigid motion designed from the keys by the feature-point method, as dense poses:
/// `n 2^levels` closed, `(n - 1) 2^levels + 1` open, pose `i 2^levels` belonging to key `i`.
///
/// `feature_points` are in the body (local) frame; `None` takes [`UNIT_FRAME_POINTS`].
///
/// # Errors
/// [`Error::TooFew`] / [`Error::Levels`] as [`crate::subdivide`]; [`Error::Conflict`] for
/// stiffness or a centripetal parametrisation given to a local scheme, [`Error::Degenerate`]
/// for collinear feature points and for coincident consecutive keys under the centripetal
/// parametrisation, and the errors of [`Stiffness::check`]; [`Error::NotUnique`]
/// (`what = "registration"`) inside [`Error::In`] naming the key span and the first sample
/// where the distorted body cannot be registered uniquely.
pub fn feature_motion(
    keys: &[Pose],
    feature_points: Option<&[DVec3]>,
    spec: &FeatureSpec,
) -> Result<Vec<Pose>> {
    let n = keys.len();
    check_subdivision(n, spec.levels)?;
    crate::motion::subdivision::check_range(keys)?;
    feature_footprint(n, feature_points.map_or(6, <[DVec3]>::len), spec)
        .check("the feature-point motion", FEATURE_HINT)?;
    if spec.scheme != CurveScheme::Variational {
        if spec.stiffness != Stiffness::default() {
            return Err(Error::Conflict {
                what: "stiffness",
                reason: "only the variational scheme takes springs".into(),
            });
        }
        if spec.parametrization != Parametrization::Uniform {
            return Err(Error::Conflict {
                what: "parametrization",
                reason: "only the variational scheme takes a non-uniform parametrisation".into(),
            });
        }
    }
    let points = feature_points.unwrap_or(&UNIT_FRAME_POINTS);
    let frame = InertiaFrame::of(points)?;
    let control = frame.control_points();
    // The four control points' homologous positions (section 4.3).
    let tracks: Vec<Vec<DVec3>> = control
        .iter()
        .map(|c| keys.iter().map(|k| k.transform_point3(*c)).collect())
        .collect();
    let dense_tracks = match spec.scheme.split() {
        Some(scheme) => tracks
            .iter()
            .map(|t| subdivide_checked(t, scheme, spec.levels, spec.closed))
            .collect::<Result<Vec<_>>>()?,
        None => {
            let spacing = match spec.parametrization {
                Parametrization::Uniform => vec![1.0; if spec.closed { n } else { n - 1 }],
                Parametrization::Centripetal => {
                    // The metric of A^12: all feature points' homologous positions.
                    let all: Vec<Vec<DVec3>> = points
                        .iter()
                        .map(|f| keys.iter().map(|k| k.transform_point3(*f)).collect())
                        .collect();
                    spans_spacing(&all, spec.closed, Parametrization::Centripetal)?
                }
            };
            variational_subdivide(&tracks, &spacing, spec.levels, spec.closed, &spec.stiffness)?
        }
    };
    let six = frame.inertia_points();
    let per_span = 1usize << spec.levels;
    let keep_keys = spec.interpolates_keys();
    let m = dense_tracks[0].len();
    let mut out: Vec<Pose> = try_vec(m, "the feature-point motion")?;
    // Eigenvectors of the previous sample's Horn matrix: a warm start for the next.
    let mut basis = IDENTITY4;
    for j in 0..m {
        let pose = if keep_keys && j % per_span == 0 {
            keys[j / per_span]
        } else {
            let images = [
                dense_tracks[0][j],
                dense_tracks[1][j],
                dense_tracks[2][j],
                dense_tracks[3][j],
            ];
            let distorted = frame.affine_images(&images);
            let (xbar, ybar, s) = cross_covariance(&six, &distorted, None)?;
            let rotation = rotation_from_covariance_warm(&s, &mut basis)
                .map_err(|e| e.within("sample", j).within("key span", j / per_span))?;
            Pose {
                rotation,
                translation: ybar - rotation * xbar,
            }
        };
        // Keep registered quaternions sign-continuous with the previous pose (the sign
        // carries no meaning; keys are returned as given).
        let registered = !(keep_keys && j % per_span == 0);
        let pose = match out.last() {
            Some(prev) if registered && prev.rotation.dot(pose.rotation) < 0.0 => Pose {
                rotation: -pose.rotation,
                ..pose
            },
            _ => pose,
        };
        out.push(pose);
    }
    Ok(out)
}

/// The feature-point motion as a function of time, ready to be sampled: the dense poses of
/// [`feature_motion`], the time map of [`crate::TimeMap`] (key `i` at `key_times[i]`), and
/// between dense poses the screw joining them (as [`Motion`] does for screw subdivision).
///
/// # Errors
/// [`Error::LengthMismatch`] when `keys` and `key_times` differ in length, the errors of
/// [`crate::TimeMap::new`], then those of [`feature_motion`].
pub fn feature_motion_timed(
    keys: &[Pose],
    key_times: &[f64],
    feature_points: Option<&[DVec3]>,
    spec: &FeatureSpec,
    period: Option<f64>,
    timing: Timing,
) -> Result<Motion<Pose>> {
    if keys.len() != key_times.len() {
        return Err(Error::LengthMismatch {
            what: "key times",
            expected: keys.len(),
            got: key_times.len(),
        });
    }
    // Validate the timing before the (costlier) design.
    crate::motion::timing::TimeMap::new(key_times, spec.closed, period, timing)?;
    let dense = feature_motion(keys, feature_points, spec)?;
    Motion::from_dense(dense, key_times, spec.levels, spec.closed, period, timing)
}

/// The feature-point motion of `keys` at `times` (see [`feature_motion_timed`]).
///
/// # Errors
/// As [`feature_motion_timed`] and [`Motion::sample`].
pub fn sample_feature_motion(
    keys: &[Pose],
    key_times: &[f64],
    times: &[f64],
    feature_points: Option<&[DVec3]>,
    spec: &FeatureSpec,
    period: Option<f64>,
    timing: Timing,
) -> Result<Vec<Pose>> {
    feature_motion_timed(keys, key_times, feature_points, spec, period, timing)?.sample(times)
}

/// The tests' rigidity measure (a test fixture, not part of the library).
#[cfg(test)]
#[path = "../../tests/fixtures/rigidity.rs"]
mod rigidity;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::feature::registration::register;
    use crate::feature::registration::tests::Rng;
    use glam::DQuat;

    fn keys(n: usize, seed: u64) -> Vec<Pose> {
        // A wandering motion with moderate turns between keys.
        let mut rng = Rng::new(seed);
        let mut pose = Pose::IDENTITY;
        (0..n)
            .map(|_| {
                let step = Pose::from_rotation_translation(
                    DQuat::from_axis_angle(rng.vec3(1.0).normalize(), 0.3 + rng.uniform()),
                    rng.vec3(2.0),
                );
                pose = step.mul_pose(&pose);
                pose
            })
            .collect()
    }

    fn specs() -> Vec<FeatureSpec> {
        let mut out = Vec::new();
        for closed in [false, true] {
            for scheme in [
                CurveScheme::FourPoint,
                CurveScheme::BSpline,
                CurveScheme::Jarek,
                CurveScheme::Variational,
            ] {
                out.push(FeatureSpec {
                    scheme,
                    levels: 4,
                    closed,
                    ..FeatureSpec::default()
                });
            }
            out.push(FeatureSpec {
                parametrization: Parametrization::Centripetal,
                levels: 4,
                closed,
                ..FeatureSpec::default()
            });
            out.push(FeatureSpec {
                stiffness: Stiffness::keys(vec![1e3, 0.5, 2.0, 0.1, 1.0, 1e3]),
                levels: 4,
                closed,
                ..FeatureSpec::default()
            });
        }
        out
    }

    fn rigidity(p: &Pose) -> f64 {
        super::rigidity::rigidity_error(&p.to_rows())
    }

    #[test]
    fn counts_rigidity_and_keys() {
        let k = keys(6, 11);
        let closed = FeatureSpec {
            levels: 7,
            closed: true,
            ..FeatureSpec::default()
        };
        let dense = feature_motion(&k, None, &closed).unwrap();
        assert_eq!(dense.len(), 768, "paper Table 1: 6 closed keys, 7 levels");
        for spec in specs() {
            let dense = feature_motion(&k, None, &spec).unwrap();
            for (j, p) in dense.iter().enumerate() {
                assert!(rigidity(p) < 1e-12, "{spec:?} pose {j}: {:e}", rigidity(p));
            }
            if spec.interpolates_keys() {
                for (i, key) in k.iter().enumerate() {
                    assert_eq!(dense[i << spec.levels], *key, "{spec:?} key {i}");
                }
            }
        }
    }

    #[test]
    fn world_and_body_frame_invariance() {
        let k = keys(6, 5);
        let a = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(0.2, -1.0, 0.4).normalize(), 2.2),
            DVec3::new(10.0, -3.0, 7.0),
        );
        let b = Pose::from_rotation_translation(
            DQuat::from_axis_angle(DVec3::new(1.0, 0.3, 0.1).normalize(), 0.9),
            DVec3::new(0.3, 0.2, -0.4),
        );
        let pts: Vec<DVec3> = (0..9)
            .map(|i| {
                let x = i as f64;
                DVec3::new((x * 1.1).sin(), (x * 0.7).cos() * 0.5, x * 0.05)
            })
            .collect();
        let moved_pts: Vec<DVec3> = pts
            .iter()
            .map(|p| b.inverse().transform_point3(*p))
            .collect();
        for spec in specs() {
            let base = feature_motion(&k, Some(&pts), &spec).unwrap();
            // World frame: A L_i -> A L(t).
            let ak: Vec<Pose> = k.iter().map(|p| a.mul_pose(p)).collect();
            let world = feature_motion(&ak, Some(&pts), &spec).unwrap();
            // Body frame: keys L_i B with the same physical feature points B^-1 f.
            let kb: Vec<Pose> = k.iter().map(|p| p.mul_pose(&b)).collect();
            let body = feature_motion(&kb, Some(&moved_pts), &spec).unwrap();
            for j in 0..base.len() {
                let e = world[j].max_abs_diff(&a.mul_pose(&base[j]));
                assert!(e < 1e-11, "{spec:?} world, pose {j}: {e:e}");
                let e = body[j].max_abs_diff(&base[j].mul_pose(&b));
                assert!(e < 1e-11, "{spec:?} body, pose {j}: {e:e}");
            }
        }
        // The default points are isotropic: a rotation of the body axes commutes.
        let r = Pose::from_rotation_translation(DQuat::from_rotation_x(0.7), DVec3::ZERO);
        let spec = FeatureSpec::default();
        let base = feature_motion(&k, None, &spec).unwrap();
        let kr: Vec<Pose> = k.iter().map(|p| p.mul_pose(&r)).collect();
        let turned = feature_motion(&kr, None, &spec).unwrap();
        for j in 0..base.len() {
            assert!(turned[j].max_abs_diff(&base[j].mul_pose(&r)) < 1e-12);
        }
    }

    #[test]
    fn affine_shortcut_equals_registering_every_feature_point() {
        // Section 4.3 / Proposition 2: run the scheme on all K feature trajectories and
        // register all K points at every sample; the shortcut must agree.
        let k = keys(5, 9);
        let pts: Vec<DVec3> = (0..20)
            .map(|i| {
                let x = i as f64;
                DVec3::new(
                    (x * 2.3).sin() * 2.0,
                    (x * 1.7).cos(),
                    (x * 0.9).sin() * 0.5,
                )
            })
            .collect();
        for spec in specs() {
            if spec.stiffness.keys.as_ref().is_some_and(|s| s.len() != 5) {
                continue;
            }
            let fast = feature_motion(&k, Some(&pts), &spec).unwrap();
            let all: Vec<Vec<DVec3>> = pts
                .iter()
                .map(|f| k.iter().map(|p| p.transform_point3(*f)).collect())
                .collect();
            let dense: Vec<Vec<DVec3>> = match spec.scheme.split() {
                Some(s) => all
                    .iter()
                    .map(|t| crate::subdivide(t, s, spec.levels, spec.closed).unwrap())
                    .collect(),
                None => {
                    let spacing = spans_spacing(&all, spec.closed, spec.parametrization).unwrap();
                    variational_subdivide(&all, &spacing, spec.levels, spec.closed, &spec.stiffness)
                        .unwrap()
                }
            };
            for j in 0..fast.len() {
                let targets: Vec<DVec3> = dense.iter().map(|t| t[j]).collect();
                let slow = register(&pts, &targets, None).unwrap();
                let e = fast[j].max_abs_diff(&slow);
                assert!(e < 1e-11, "{spec:?} pose {j}: {e:e}");
            }
        }
    }

    #[test]
    fn weak_interior_springs_give_the_straight_line() {
        // lambda -> 0 inside, ends pinned: the feature centroid (kept by registration, eq. 8)
        // runs on the segment between the end keys' centroids.
        let k = keys(6, 3);
        let mut lambda = vec![1e-9; 6];
        lambda[0] = f64::INFINITY;
        lambda[5] = f64::INFINITY;
        let spec = FeatureSpec {
            stiffness: Stiffness::keys(lambda),
            ..FeatureSpec::default()
        };
        let dense = feature_motion(&k, None, &spec).unwrap();
        let (a, b) = (k[0].translation, k[5].translation);
        let dir = (b - a).normalize();
        for p in &dense {
            let d = p.translation - a;
            let off = (d - d.dot(dir) * dir).length();
            assert!(off < 1e-6, "centroid off the line by {off:e}");
        }
    }

    #[test]
    fn trajectories_are_c2() {
        // Theorem 1 with a C2 scheme: scaled second differences of a body point's
        // trajectory converge (compare the curve test in `variational`).
        let k = keys(5, 21);
        let q = DVec3::new(0.7, -0.4, 1.2);
        for closed in [false, true] {
            let mut prev: Option<Vec<DVec3>> = None;
            let mut changes = Vec::new();
            for levels in 3..=8 {
                let spec = FeatureSpec {
                    levels,
                    closed,
                    ..FeatureSpec::default()
                };
                let w: Vec<DVec3> = feature_motion(&k, None, &spec)
                    .unwrap()
                    .iter()
                    .map(|p| p.transform_point3(q))
                    .collect();
                let m = w.len();
                let scale = 4f64.powi(levels as i32);
                let range = if closed { 0..m } else { 1..m - 1 };
                let d2: Vec<DVec3> = range
                    .map(|j| (w[(j + m - 1) % m] - 2.0 * w[j] + w[(j + 1) % m]) * scale)
                    .collect();
                if let Some(p) = &prev {
                    let off = usize::from(!closed);
                    changes.push(
                        p.iter()
                            .enumerate()
                            .map(|(j, v)| v.distance(d2[2 * (j + off) - off]))
                            .fold(0.0, f64::max),
                    );
                }
                prev = Some(d2);
            }
            for pair in changes.windows(2) {
                assert!(
                    pair[1] < 0.75 * pair[0],
                    "closed {closed}: changes {changes:?}"
                );
            }
        }
    }

    #[test]
    fn sampling_hits_keys_at_their_times() {
        let k = keys(5, 2);
        let times = [0.0, 4.0, 10.0, 11.0, 20.0];
        for closed in [false, true] {
            let spec = FeatureSpec {
                closed,
                ..FeatureSpec::default()
            };
            let got = sample_feature_motion(&k, &times, &times, None, &spec, None, Timing::Smooth)
                .unwrap();
            for (g, key) in got.iter().zip(&k) {
                assert!(g.max_abs_diff(key) < 1e-14, "closed {closed}");
            }
            let dense = feature_motion(&k, None, &spec).unwrap();
            // Halfway between keys 0 and 1 in the motion parameter.
            let motion =
                feature_motion_timed(&k, &times, None, &spec, None, Timing::Linear).unwrap();
            let mid = motion.at(2.0);
            assert!(mid.max_abs_diff(&dense[(1 << spec.levels) / 2]) < 1e-12);
        }
    }

    #[test]
    fn errors() {
        let k = keys(4, 1);
        // Half a turn between two keys of a closed cycle, averaged by the B-spline: the
        // distorted frame is flat and the rotation is not unique.
        let pair = [
            Pose::IDENTITY,
            Pose::from_rotation_translation(
                DQuat::from_rotation_z(std::f64::consts::PI),
                DVec3::ZERO,
            ),
        ];
        let spec = FeatureSpec {
            scheme: CurveScheme::BSpline,
            levels: 2,
            closed: true,
            ..FeatureSpec::default()
        };
        let err = feature_motion(&pair, None, &spec).unwrap_err();
        assert!(
            matches!(
                err.innermost(),
                Error::NotUnique {
                    what: "registration",
                    ..
                }
            ) && err.to_string().contains("sample"),
            "{err}"
        );
        let bad = FeatureSpec {
            scheme: CurveScheme::Jarek,
            stiffness: Stiffness::keys(vec![1.0; 4]),
            ..FeatureSpec::default()
        };
        assert!(matches!(
            feature_motion(&k, None, &bad),
            Err(Error::Conflict {
                what: "stiffness",
                ..
            })
        ));
        let line = [DVec3::ZERO, DVec3::X, 2.0 * DVec3::X];
        assert!(matches!(
            feature_motion(&k, Some(&line), &FeatureSpec::default()),
            Err(Error::Degenerate {
                what: "feature points",
                ..
            })
        ));
        assert!(matches!(
            sample_feature_motion(
                &k,
                &[0.0, 1.0],
                &[0.5],
                None,
                &FeatureSpec::default(),
                None,
                Timing::Smooth
            ),
            Err(Error::LengthMismatch { .. })
        ));
    }
}
