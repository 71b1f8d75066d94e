"""polyscrew.fit_angular_velocity (Xie et al. 2011) through Python, checked independently:
orientations and angular velocities against scipy's Rotation (finite differences of the
returned quaternions), the spinning top of the paper's figure 3 (tests/fixtures/spinning_top.py)."""

import numpy as np
import polyscrew
import pytest
from scipy.spatial.transform import Rotation

from spinning_top import top_omega, top_rotation, top_target

DURATION = 4.0


def wxyz(rot):
    """scipy Rotation -> (N, 4) w, x, y, z."""
    return np.roll(rot.as_quat(), 1, axis=-1)


def rot(q_wxyz):
    """(N, 4) w, x, y, z -> scipy Rotation."""
    return Rotation.from_quat(np.roll(np.asarray(q_wxyz), -1, axis=-1))


def angle_between_rotations(a, b):
    """Angles (rad) of the rotations taking a to b."""
    return (rot(b) * rot(a).inv()).magnitude()


def finite_difference_omega(fit, times, h=1e-5):
    """World angular velocity from the returned orientations: rotvec(R(t+h) R(t-h)^-1) / 2h."""
    a = rot(fit.sample(times - h))
    b = rot(fit.sample(times + h))
    return (b * a.inv()).as_rotvec() / (2 * h)


def top_case(n_keys, every=3):
    key_times = np.linspace(0.0, DURATION, n_keys)
    keys = wxyz(top_rotation(key_times))
    target_times = np.linspace(0.0, DURATION, 241)
    target = top_target(target_times)
    mask = np.array([i % every == 0 or i == n_keys - 1 for i in range(n_keys)])
    return key_times, keys, target_times, target, mask


@pytest.fixture(scope="module")
def top20():
    key_times, keys, tt, target, mask = top_case(20)
    dense = np.linspace(0.0, DURATION, 801)
    fit = polyscrew.fit_angular_velocity(keys, key_times, tt, target, constrained=mask, sample_times=dense)
    return key_times, keys, tt, target, mask, dense, fit


def test_constrained_keys_are_met_and_orientations_are_unit(top20):
    key_times, keys, _, _, mask, _, fit = top20
    got = fit.key_quaternions
    # Equal up to sign, componentwise.
    sign = np.sign(np.sum(got * keys, axis=1))[:, None]
    err = np.abs(got - sign * keys).max(axis=1)
    assert err[mask].max() < 1e-9, err[mask]
    at_keys = fit.sample(key_times[mask])
    sign = np.sign(np.sum(at_keys * keys[mask], axis=1))[:, None]
    assert np.abs(at_keys - sign * keys[mask]).max() < 1e-9
    assert np.abs(np.linalg.norm(fit.quaternions, axis=1) - 1.0).max() < 1e-12
    # Sign-continuous output.
    assert (np.sum(fit.quaternions[1:] * fit.quaternions[:-1], axis=1) > 0).all()


def test_free_keys_move_and_constrained_keys_do_not(top20):
    _, keys, _, _, mask, _, fit = top20
    moved = angle_between_rotations(keys, fit.key_quaternions)
    print(f"constrained keys moved at most {moved[mask].max():.1e} rad; free keys {moved[~mask].min():.3f}..{moved[~mask].max():.3f} rad")
    assert moved[mask].max() < 1e-9
    assert (moved[~mask] > 1e-3).all(), moved[~mask]


def test_spinning_top_fit_follows_the_sketch(top20):
    _, _, _, _, _, dense, fit = top20
    assert fit.converged and fit.status == "converged"
    assert fit.fit_error < fit.delta == 0.1
    assert len(fit.frame_times) <= 10
    # Independent angular velocity: finite differences of the returned orientations.
    inner = dense[1:-1]
    fd = finite_difference_omega(fit, inner)
    w = fit.angular_velocity(inner)
    assert np.abs(fd - w).max() < 1e-4 * np.abs(w).max()
    assert np.allclose(fit.omega[1:-1], w)
    target = top_target(inner)
    cos = np.sum(fd * target, axis=1) / np.linalg.norm(fd, axis=1) / np.linalg.norm(target, axis=1)
    angles = np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))
    # Without the fit the direction would be off by the loops' radius, 12 degrees.
    original = np.degrees(
        np.arccos(np.clip(np.sum(top_omega(inner) * target, axis=1) / np.linalg.norm(top_omega(inner), axis=1) / np.linalg.norm(target, axis=1), -1, 1))
    )
    print(
        f"spinning top: fit error {fit.fit_error:.4f} (delta 0.1), {len(fit.frame_times)} variable frames, "
        f"{fit.iterations} iterations; omega direction vs sketch max {angles.max():.2f} deg, mean {angles.mean():.2f} deg "
        f"(original motion: mean {original.mean():.2f} deg)"
    )
    assert angles.max() < 8.0
    assert angles.mean() < 3.0
    speed_err = np.abs(np.linalg.norm(fd, axis=1) - np.linalg.norm(target, axis=1)) / np.linalg.norm(target, axis=1)
    assert speed_err.mean() < 0.05


def test_sparse_keys_get_variable_frames():
    key_times, keys, tt, target, mask = top_case(10)
    fit = polyscrew.fit_angular_velocity(keys, key_times, tt, target, constrained=np.flatnonzero(mask))
    print(f"10 keys: fit error {fit.fit_error:.4f}, frames at {np.round(fit.frame_times, 3)}, {fit.rounds} rounds")
    assert fit.converged
    assert 0 < len(fit.frame_times) <= 10
    assert np.all((fit.frame_times > 0) & (fit.frame_times < DURATION))
    assert np.all(np.diff(fit.frame_times) > 0)


def test_satisfied_target_changes_nothing():
    axis = np.array([1.0, 2.0, -3.0]) / np.linalg.norm([1.0, 2.0, -3.0])
    rate = 3.0
    start = Rotation.from_euler("x", 0.4)

    def exact(t):
        return Rotation.from_rotvec(np.outer(np.atleast_1d(t), axis * rate)) * start

    key_times = np.linspace(0.0, 2.0, 11)
    keys = wxyz(exact(key_times))
    dense = np.linspace(0.0, 2.0, 401)
    for constrained in (None, [0]):
        fit = polyscrew.fit_angular_velocity(
            keys, key_times, [0.0, 2.0], [axis * rate] * 2, constrained=constrained, sample_times=dense
        )
        change = angle_between_rotations(wxyz(exact(dense)), fit.quaternions).max()
        print(f"constant speed, constrained={constrained}: fit error {fit.fit_error:.2e}, largest change {change:.2e} rad")
        assert fit.converged
        assert fit.fit_error < 1e-6
        assert len(fit.frame_times) == 0
        assert change < 1e-5
        assert angle_between_rotations(keys, fit.key_quaternions).max() < 1e-5


def test_directions_are_normalised():
    key_times, keys, tt, target, mask = top_case(20)
    speed = np.linalg.norm(target, axis=1)
    scaled = target / speed[:, None] * np.linspace(0.5, 3.0, len(tt))[:, None]  # not unit
    a = polyscrew.fit_angular_velocity(keys, key_times, tt, target, constrained=mask)
    b = polyscrew.fit_angular_velocity(keys, key_times, tt, scaled, constrained=mask, target_speed=speed)
    assert np.allclose(a.quaternions, b.quaternions, atol=1e-9)
    with pytest.raises(ValueError, match="direction 3 has length"):
        polyscrew.fit_angular_velocity(
            keys, key_times, tt, np.where(np.arange(len(tt))[:, None] == 3, 0.0, scaled), target_speed=speed
        )


def test_non_convergence_raises_with_the_best_result():
    key_times, keys, tt, target, _ = top_case(6)
    with pytest.raises(ValueError, match="did not converge") as info:
        polyscrew.fit_angular_velocity(keys, key_times, tt, target, max_iterations=1)
    best = info.value.result
    assert isinstance(best, polyscrew.AngularVelocityFit)
    assert not best.converged and best.status == "iteration_limit" and best.iterations == 1
    assert np.abs(np.linalg.norm(best.quaternions, axis=1) - 1).max() < 1e-12


def test_infeasible_target_raises_with_the_best_result():
    # Identity at both ends, but the target turns 10 rad in 1 s.
    keys = [[1.0, 0.0, 0.0, 0.0]] * 2
    with pytest.raises(ValueError, match="infeasible") as info:
        polyscrew.fit_angular_velocity(keys, [0.0, 1.0], [0.0, 1.0], [[0.0, 0.0, 10.0]] * 2, max_frames=2)
    best = info.value.result
    assert best.status == "above_delta" and best.fit_error > best.delta
    assert len(best.frame_times) <= 2
    assert np.allclose(np.abs(best.key_quaternions[:, 0]), 1.0, atol=1e-12)


@pytest.mark.parametrize(
    ("kwargs", "message"),
    [
        ({"key_quaternions": np.zeros((0, 4)), "key_times": []}, "0 keys given"),
        ({"key_quaternions": [[1.0, 0, 0, 0]], "key_times": [0.0]}, "1 keys given"),
        ({"key_times": [0.0, 0.0]}, "key time 1"),
        ({"key_quaternions": [[1.0, 0, 0, 0], [np.nan, 0, 0, 1]]}, "key quaternion 1 is NaN"),
        ({"key_quaternions": [[0.0, 0, 0, 0], [1.0, 0, 0, 0]]}, "key 0 has length"),
        ({"key_quaternions": [[1.0, 0, 0], [1.0, 0, 0]]}, r"expected shape \(N, 4\)"),
        ({"target_omega": [[0, 0, 1.0], [0, np.nan, 1.0]]}, "target angular velocity 1 is NaN"),
        ({"target_times": [0.0, 0.0]}, "increase strictly"),
        ({"target_times": [0.0, 0.5]}, "do not cover"),
        ({"target_times": [0.0], "target_omega": [[0, 0, 1.0]]}, "at least 2"),
        ({"target_omega": [[0, 0, 1.0]]}, "expected 2 entries"),
        ({"constrained": [5]}, "index 5 out of range"),
        ({"constrained": [True, False, True]}, "boolean mask has 3 entries"),
        ({"alpha": -1.0}, "alpha"),
        ({"delta": 0.0}, "delta"),
        ({"max_iterations": 0}, "max_iterations"),
        ({"sample_times": [2.0]}, "outside the key range"),
        ({"target_speed": [1.0, np.inf]}, "target speed 1 is NaN"),
    ],
)
def test_bad_input_raises_a_clear_value_error(kwargs, message):
    args = {
        "key_quaternions": [[1.0, 0, 0, 0], [0.0, 0, 0, 1.0]],
        "key_times": [0.0, 1.0],
        "target_times": [0.0, 1.0],
        "target_omega": [[0.0, 0.0, np.pi], [0.0, 0.0, np.pi]],
    }
    args.update(kwargs)
    with pytest.raises(ValueError, match=message) as info:
        polyscrew.fit_angular_velocity(**args)
    assert "fit_angular_velocity" in str(info.value)
    assert not hasattr(info.value, "result")


def test_default_arguments_are_the_papers():
    fit = polyscrew.fit_angular_velocity(
        [[1.0, 0, 0, 0], [0.0, 0, 0, 1.0]], [0.0, 1.0], [0.0, 1.0], [[0.0, 0.0, np.pi]] * 2
    )
    assert fit.delta == 0.1
    assert fit.converged
    # Half a turn about z in 1 s at pi rad/s: the fitted motion is that turn.
    mid = fit.sample([0.5])
    assert angle_between_rotations(mid, wxyz(Rotation.from_rotvec([[0, 0, np.pi / 2]])))[0] < 1e-4
    assert np.allclose(fit.sample_times, [0.0, 1.0])
    assert "AngularVelocityFit" in repr(fit)
