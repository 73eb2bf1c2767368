"""Virtual chassis and the non-slip motion estimate (paper section 2.3, Eq. 6)."""

from __future__ import annotations

import numpy as np
import pytest

from acl_env.estimation import (
    SEA_MODULE_RADIUS,
    contact_joints,
    estimate_displacement,
    estimate_from_frames,
    estimate_gait_cycle,
    helix_axis,
    locate_on_pole,
    pole_axis_column,
    virtual_chassis,
)
from acl_env.gait import ACLGait, RollingHelixGait
from acl_env.gait.kinematics import forward_kinematics, rigid_fit

Z = np.array([0.0, 0.0, 1.0])


def random_rotation(rng: np.random.Generator) -> np.ndarray:
    q, r = np.linalg.qr(rng.standard_normal((3, 3)))
    q *= np.sign(np.diag(r))
    if np.linalg.det(q) < 0:
        q[:, 0] *= -1.0
    return q


def helix(
    n: int = 20,
    radius: float = 0.09,
    pitch: float = 0.10,
    turns: float = 2.3,
    phase: float = 0.0,
    radii: np.ndarray | None = None,
) -> np.ndarray:
    """Points on a right-handed helix about z, head (lowest) first."""
    t = phase + np.linspace(0.0, 2.0 * np.pi * turns, n)
    r = radius if radii is None else radii
    return np.column_stack([r * np.cos(t), r * np.sin(t), pitch * t / (2.0 * np.pi)])


def bent_snake(rng: np.random.Generator, n: int = 12) -> np.ndarray:
    """A generic, clearly elongated snake shape, head first."""
    s = np.linspace(0.0, 1.0, n)
    return np.column_stack([s, 0.15 * np.sin(3.0 * s), 0.05 * s**2]) + 0.002 * rng.standard_normal(
        (n, 3)
    )


# -- virtual chassis --------------------------------------------------------------------------


def test_chassis_origin_is_mean_and_axes_are_right_handed_rotation() -> None:
    rng = np.random.default_rng(0)
    for _ in range(20):
        points = rng.standard_normal((15, 3)) * np.array([1.0, 0.4, 0.1])
        origin, axes = virtual_chassis(points)
        np.testing.assert_allclose(origin, points.mean(axis=0), atol=1e-12)
        np.testing.assert_allclose(axes.T @ axes, np.eye(3), atol=1e-12)
        assert np.linalg.det(axes) == pytest.approx(1.0, abs=1e-12)


def test_chassis_axes_are_principal_axes_in_order() -> None:
    rng = np.random.default_rng(1)
    points = rng.standard_normal((200, 3)) * np.array([3.0, 1.0, 0.2])
    _, axes = virtual_chassis(points)
    local = (points - points.mean(axis=0)) @ axes
    spread = local.var(axis=0)
    assert spread[0] > spread[1] > spread[2]
    cov = np.cov(local.T)
    np.testing.assert_allclose(cov - np.diag(np.diag(cov)), 0.0, atol=1e-10)


def test_chassis_x_points_toward_head() -> None:
    rng = np.random.default_rng(2)
    points = bent_snake(rng)
    for shape in (points, points[::-1]):
        origin, axes = virtual_chassis(shape)
        x = (shape - origin) @ axes[:, 0]
        assert x[0] > 0.0 > x[-1]
        assert x[0] == pytest.approx(x.max())


def test_chassis_moves_with_a_rigid_motion() -> None:
    rng = np.random.default_rng(3)
    points = bent_snake(rng)
    origin, axes = virtual_chassis(points)
    for _ in range(10):
        rot, shift = random_rotation(rng), rng.standard_normal(3)
        origin2, axes2 = virtual_chassis(points @ rot.T + shift)
        np.testing.assert_allclose(origin2, rot @ origin + shift, atol=1e-12)
        np.testing.assert_allclose(axes2, rot @ axes, atol=1e-9)


def test_chassis_signs_follow_the_previous_frame() -> None:
    # A planar, symmetric snake: without a previous frame the sign of y is decided by a third
    # moment that is ~0 here, so tiny perturbations flip it; with the previous frame they do not.
    rng = np.random.default_rng(4)
    s = np.linspace(-1.0, 1.0, 21)
    base = np.column_stack([s, 0.2 * np.sin(2.0 * np.pi * s), np.zeros_like(s)])
    _, prev = virtual_chassis(base)
    free_flips = 0
    _, free_prev = virtual_chassis(base)
    for _ in range(200):
        points = base + 1e-4 * rng.standard_normal(base.shape)
        _, axes = virtual_chassis(points, previous=prev)
        assert np.all(np.sum(axes * prev, axis=0) > 0.99)
        assert np.linalg.det(axes) == pytest.approx(1.0)
        _, free = virtual_chassis(points)
        free_flips += int(free[:, 1] @ free_prev[:, 1] < 0.0)
        prev, free_prev = axes, free
    assert free_flips > 0  # the shape is ambiguous, so the previous frame is what fixes y


# -- the pole axis ----------------------------------------------------------------------------


def test_pole_case_first_principal_axis_is_not_the_pole() -> None:
    # 2.3 turns of radius 9 cm and pitch 8 cm: the axial spread (L^2 / 12) is below the radial
    # one (r^2 / 2), so the chassis x axis lies across the pole and z is nearest to it.
    points = helix(radius=0.09, pitch=0.08, turns=2.3)
    _, axes = virtual_chassis(points)
    _, direction, _ = helix_axis(points)
    assert abs(axes[:, 0] @ Z) < 0.1
    assert pole_axis_column(axes, direction) == 2
    assert abs(axes[:, 2] @ Z) > 0.95
    np.testing.assert_allclose(direction, Z, atol=1e-8)


def test_pole_axis_of_the_acl_chain_switches_columns_and_is_found() -> None:
    # The 20-joint chain of the default ACL gait: the pole is the chassis x axis in some keyframes
    # and z in others; helix_axis agrees with the commanded backbone's axis in every keyframe.
    gait = ACLGait()
    joints, _, _ = forward_kinematics(gait.cycle(), gait.module_length)
    backbones = gait.backbones(np.arange(gait.steps_per_cycle) / gait.steps_per_cycle)
    columns = set()
    for points, backbone in zip(joints[::10], backbones[::10], strict=True):
        _, axes = virtual_chassis(points)
        _, direction, _ = helix_axis(points)
        columns.add(pole_axis_column(axes, direction))
        rotation, _, _ = rigid_fit(points, backbone)
        assert rotation @ direction @ Z > np.cos(np.radians(3.0))
    assert 0 in columns and len(columns) > 1


def test_helix_axis_recovers_a_moved_helix() -> None:
    rng = np.random.default_rng(5)
    points = helix(n=25, radius=0.1, pitch=0.08, turns=2.3)
    for _ in range(10):
        rot, shift = random_rotation(rng), rng.standard_normal(3)
        point, direction, radius = helix_axis(points @ rot.T + shift)
        np.testing.assert_allclose(direction, rot @ Z, atol=1e-8)  # head to tail: up
        np.testing.assert_allclose(np.cross(point - shift, rot @ Z), 0.0, atol=1e-8)
        assert radius == pytest.approx(0.1, abs=1e-8)


def test_contacts_are_the_joints_nearest_the_pole_per_segment() -> None:
    radii = np.where(np.arange(20) % 4 < 2, 0.09, 0.1)  # pairs alternate inner/outer...
    radii[1::4] += 0.002  # ...and within an inner pair the first joint is nearer the pole
    radii[2::4] += 0.003  # ...and within an outer pair the second one is
    contacts = contact_joints(helix(radii=radii), np.zeros(3), Z)
    np.testing.assert_array_equal(contacts, [0, 3, 4, 7, 8, 11, 12, 15, 16, 19])


# -- the estimate of Eq. 6 --------------------------------------------------------------------


def test_estimate_is_exact_for_anchored_translation() -> None:
    """Contacts fixed in the world (non-slip) and the rest of the body translated along the pole:
    in the chassis the contacts translate rigidly, and Eq. 6 returns the rise of the origin."""
    rng = np.random.default_rng(6)
    inner = np.arange(20) % 2 == 0
    points = helix(radii=np.where(inner, 0.09, 0.1))
    frames, lifts = [points.copy()], rng.uniform(0.001, 0.01, size=12)
    for lift in lifts:  # the non-contact (outer) joints move up; the contacts hold
        points = points.copy()
        points[~inner, 2] += lift
        frames.append(points)
    frames = np.array(frames)
    rot, shift = random_rotation(rng), rng.standard_normal(3)
    for moved, pole in ((frames, (np.zeros(3), Z)), (frames @ rot.T + shift, (shift, rot @ Z))):
        estimate = estimate_from_frames(moved, pole=pole)
        rise = frames[-1, :, 2].mean() - frames[0, :, 2].mean()
        assert estimate.displacement == pytest.approx(rise, rel=1e-12)
        assert rise == pytest.approx(0.5 * lifts.sum())
        assert np.all(estimate.contacts == np.flatnonzero(inner))


def test_estimate_ignores_rigid_motion_without_roll() -> None:
    rng = np.random.default_rng(7)
    points = helix()
    frames = np.array([points @ random_rotation(rng).T + rng.standard_normal(3) for _ in range(8)])
    estimate = estimate_from_frames(frames)
    np.testing.assert_allclose(estimate.steps, 0.0, atol=1e-12)
    assert estimate.displacement == pytest.approx(0.0, abs=1e-12)


def test_one_roll_of_a_synthetic_helix_gives_two_pi_r_joint() -> None:
    # A non-slipping helix that keeps its shape and rolls once: only the roll term of Eq. 6 is
    # left, and a left-handed roll about the head-to-tail axis of a right-handed helix is up.
    rng = np.random.default_rng(8)
    frames = [helix(phase=0.1 * k) for k in range(20)]
    frames = np.array([f @ random_rotation(rng).T for f in frames])
    up = estimate_from_frames(frames, rolls=-1.0)
    assert up.displacement == pytest.approx(2.0 * np.pi * SEA_MODULE_RADIUS, rel=1e-9)
    down = estimate_from_frames(frames, rolls=1.0)
    assert down.displacement == pytest.approx(-2.0 * np.pi * SEA_MODULE_RADIUS, rel=1e-9)
    mirrored = estimate_from_frames(frames * np.array([1.0, -1.0, 1.0]), rolls=1.0)
    assert mirrored.displacement == pytest.approx(2.0 * np.pi * SEA_MODULE_RADIUS, rel=1e-9)


def test_rolling_helix_gait_with_a_fine_chain_gives_two_pi_r_joint() -> None:
    """The whole pipeline from joint angles: FK, chassis, pole fit, contacts, FK roll count. A
    chain of short modules follows the helix closely, so its joints barely move relative to the
    chassis and one commanded roll per cycle is estimated as 2 pi r_joint up the pole."""
    gait = RollingHelixGait(n_joints=120, module_length=0.0107, steps_per_cycle=60)
    estimate = estimate_gait_cycle(gait)
    assert estimate.rolls == pytest.approx(-1.0, abs=1e-6)  # left-handed: the climbing sense
    assert estimate.roll_travel == pytest.approx(2.0 * np.pi * SEA_MODULE_RADIUS, rel=1e-9)
    assert abs(estimate.shift) < 0.02 * estimate.roll_travel
    assert estimate_displacement(gait, cycles=2) == pytest.approx(
        2.0 * estimate.displacement, rel=1e-12
    )


def test_locate_on_pole_uses_a_known_pole() -> None:
    points = helix(radii=np.where(np.arange(20) % 2 == 1, 0.09, 0.1))
    frame = locate_on_pole(points, pole=(np.zeros(3), Z))
    np.testing.assert_allclose(frame.axes @ frame.axis_direction, Z, atol=1e-12)
    np.testing.assert_allclose(frame.axial, points[:, 2] - points[:, 2].mean(), atol=1e-12)
    np.testing.assert_array_equal(frame.contacts, np.arange(1, 20, 2))
