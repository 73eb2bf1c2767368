"""Forward kinematics of the module chain, rigid fits and the body-roll diagnostic (pure numpy).

Conventions (shared with the MuJoCo model in :mod:`acl_env.model`):

* The chain has ``n_joints + 1`` links of length ``l``; link 0 is the head. Arc length ``s`` runs
  from the head tip (``s = 0``) to the tail tip (``s = (n_joints + 1) l``); joint ``j`` (0-based,
  head joint first) sits at ``s = (j + 1) l``, between link ``j`` and link ``j + 1``.
* Each link frame has its x axis along the body, pointing from head to tail. Even joints
  (0, 2, ...) are *dorsal*: they rotate about the link's y axis. Odd joints are *lateral*: they
  rotate about the link's z axis. A positive angle is a right-handed rotation about that axis.
* With these axes the bellows model of the paper (Eq. 3-5) maps curvature to joint angles with
  the roll angle ``phi(s) = phi_0 + int_0^s tau ds`` (no sign flip). The mirrored convention
  (``phi_0 - int tau``) draws the mirror helix; :func:`backbone_fit_rms` tells them apart.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import NamedTuple, Protocol

import numpy as np

DORSAL_AXIS = 1  # index of the link's y axis
LATERAL_AXIS = 2  # index of the link's z axis


def joint_axes(n_joints: int) -> np.ndarray:
    """Unit rotation axes of the joints in their parent link frame, shape ``(n_joints, 3)``."""
    axes = np.zeros((n_joints, 3))
    axes[0::2, DORSAL_AXIS] = 1.0
    axes[1::2, LATERAL_AXIS] = 1.0
    return axes


def _axis_rotations(angles: np.ndarray, axis: int) -> np.ndarray:
    """Rotation matrices about the link's y (axis=1) or z (axis=2) axis, shape ``(..., 3, 3)``."""
    c, s = np.cos(angles), np.sin(angles)
    rot = np.zeros((*angles.shape, 3, 3))
    if axis == DORSAL_AXIS:
        rot[..., 0, 0], rot[..., 0, 2] = c, s
        rot[..., 2, 0], rot[..., 2, 2] = -s, c
        rot[..., 1, 1] = 1.0
    else:
        rot[..., 0, 0], rot[..., 0, 1] = c, -s
        rot[..., 1, 0], rot[..., 1, 1] = s, c
        rot[..., 2, 2] = 1.0
    return rot


def forward_kinematics(
    angles: np.ndarray, module_length: float
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Forward kinematics of the chain in the head link's frame.

    Args:
        angles: joint angles, shape ``(..., n_joints)``, head joint first.
        module_length: joint-to-joint distance ``l`` (m).

    Returns:
        ``joints`` ``(..., n_joints, 3)`` joint positions, ``ends`` ``(..., 2, 3)`` head and tail
        tips, ``frames`` ``(..., n_joints + 1, 3, 3)`` link rotations (columns are the link axes).
    """
    angles = np.asarray(angles, dtype=float)
    n = angles.shape[-1]
    batch = angles.shape[:-1]
    frames = np.empty((*batch, n + 1, 3, 3))
    points = np.empty((*batch, n + 2, 3))
    frames[..., 0, :, :] = np.eye(3)
    points[..., 0, :] = 0.0
    for j in range(n):
        rot = _axis_rotations(angles[..., j], DORSAL_AXIS if j % 2 == 0 else LATERAL_AXIS)
        points[..., j + 1, :] = points[..., j, :] + module_length * frames[..., j, :, 0]
        frames[..., j + 1, :, :] = frames[..., j, :, :] @ rot
    points[..., n + 1, :] = points[..., n, :] + module_length * frames[..., n, :, 0]
    ends = np.stack([points[..., 0, :], points[..., n + 1, :]], axis=-2)
    return points[..., 1 : n + 1, :], ends, frames


def rigid_fit(source: np.ndarray, target: np.ndarray) -> tuple[np.ndarray, np.ndarray, float]:
    """Best rigid motion (Kabsch) mapping ``source`` points onto ``target`` points.

    Returns ``(rotation, translation, rms)`` with ``target ~ source @ rotation.T + translation``
    and the root-mean-square residual distance (m). Reflections are excluded.
    """
    src_mean, tgt_mean = source.mean(axis=0), target.mean(axis=0)
    h = (source - src_mean).T @ (target - tgt_mean)
    u, _, vt = np.linalg.svd(h)
    d = np.sign(np.linalg.det(vt.T @ u.T)) or 1.0
    rotation = vt.T @ np.diag([1.0, 1.0, d]) @ u.T
    translation = tgt_mean - rotation @ src_mean
    residual = source @ rotation.T + translation - target
    rms = float(np.sqrt(np.mean(np.sum(residual**2, axis=1))))
    return rotation, translation, rms


class PlacedChain(NamedTuple):
    """The chain of FK placed onto a backbone by the best rigid fit of its joints."""

    points: np.ndarray  # (n_joints + 2, 3): head tip, joints, tail tip, in the backbone's frame
    frames: np.ndarray  # (n_joints + 1, 3, 3): link rotations in the backbone's frame
    rotation: np.ndarray  # fit: backbone ~ fk @ rotation.T + translation
    translation: np.ndarray
    rms: float  # RMS distance (m) of the joints from the backbone points


def place_chain(angles: np.ndarray, backbone: np.ndarray, module_length: float) -> PlacedChain:
    """Forward kinematics of ``angles`` fitted (Kabsch) onto ``backbone`` (joint positions)."""
    joints, ends, frames = forward_kinematics(angles, module_length)
    rotation, translation, rms = rigid_fit(joints, backbone)
    points = np.concatenate([ends[:1], joints, ends[1:]]) @ rotation.T + translation
    return PlacedChain(points, rotation @ frames, rotation, translation, rms)


class HelixChain(Protocol):
    """What the start-pose search needs of a gait: joint angles and backbone at a phase."""

    module_length: float

    def joint_angles(self, phase: float) -> np.ndarray: ...

    def backbone(self, phase: float) -> np.ndarray: ...


def min_axis_distance(points: np.ndarray) -> float:
    """Smallest distance from the pole axis (z) to the polyline through ``points``."""
    u = np.linspace(0.0, 1.0, 9)[None, :, None]
    samples = points[:-1, None] + u * (points[1:] - points[:-1])[:, None]
    return float(np.linalg.norm(samples[..., :2], axis=-1).min())


def clear_placement(
    gait_at: Callable[[float], HelixChain],
    phase: float,
    contact_radius: float,
    clearance: float,
    height: float,
    tries: int = 8,
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint angles and root pose of a keyframe drawn on a helix loose enough to clear the pole.

    ``gait_at(radius)`` is the gait with its helix at ``radius``. Starting at ``contact_radius +
    clearance`` (the contact radius is pole + module radius), the helix is loosened until every
    point of the placed chain (:func:`place_chain`) is ``clearance`` clear of the contact radius,
    at most ``tries`` times. Returns ``(angles, rotation, translation)``, the chain's root pose
    lifted so that its lowest point is at ``height``.
    """
    radius = contact_radius + clearance
    for _ in range(tries):
        loose = gait_at(radius)
        angles = loose.joint_angles(phase)
        chain = place_chain(angles, loose.backbone(phase), loose.module_length)
        rotation, translation, points = chain.rotation, chain.translation, chain.points
        gap = min_axis_distance(points) - contact_radius
        if gap >= clearance - 1e-4:
            break
        radius += clearance - gap + 1e-3
    translation = translation + np.array([0.0, 0.0, height - points[:, 2].min()])
    return angles, rotation, translation


def backbone_fit_rms(
    angles: np.ndarray, backbone: np.ndarray, module_length: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """RMS distance (m) between the chain's joints (FK of ``angles``) and ``backbone`` points.

    Returns ``(rms, rotation, translation)`` of the best rigid fit of the FK joints to ``backbone``.
    """
    chain = place_chain(angles, backbone, module_length)
    return chain.rms, chain.rotation, chain.translation


def surface_roll_angles(
    angles: np.ndarray, backbone: np.ndarray, module_length: float
) -> np.ndarray:
    """Roll angle (rad) of every link about its own axis, measured from the pole's outward normal.

    The chain is placed on ``backbone`` (pole axis = world z) by the best rigid fit; the roll of
    a link is the angle about its x axis from the outward radial direction (projected normal to
    the link) to the link's z axis. Returned in ``(-pi, pi]``, shape ``(n_joints + 1,)``.
    """
    chain = place_chain(angles, backbone, module_length)
    pts = chain.points
    return link_roll_angles(chain.frames, 0.5 * (pts[:-1] + pts[1:]))


def link_roll_angles(frames: np.ndarray, centres: np.ndarray) -> np.ndarray:
    """Roll angle (rad) of links about their own x axis, from the pole's outward normal.

    ``frames`` ``(N, 3, 3)``: the links' world rotations (columns: the link's x, y, z axes);
    ``centres`` ``(N, 3)``: the links' midpoints; the pole's axis is the world z axis. The roll is
    the angle about x from the outward radial direction (projected normal to the link) to the
    link's z axis, in ``(-pi, pi]``. Shared by the gait's diagnostic and the simulated snake
    (:class:`acl_env.envs.termination.BodyRoll`, from MuJoCo's link frames).
    """
    # With r the horizontal radial vector and r' its part normal to x, the angle's sine is
    # (r' x z) . x = r' . (z x x) = r . y (x is normal to y) and its cosine r' . z = r . z:
    # neither the projection nor a normalisation changes atan2 of the pair.
    x, y = centres[:, 0:1], centres[:, 1:2]
    sin = x * frames[:, 0, 1:2] + y * frames[:, 1, 1:2]
    cos = x * frames[:, 0, 2:3] + y * frames[:, 1, 2:3]
    return np.arctan2(sin[:, 0], cos[:, 0])


def count_body_rolls(table: np.ndarray, backbones: np.ndarray, module_length: float) -> float:
    """How many times the body rolls about its own axis over one cycle, relative to the pole.

    ``table`` ``(K, n_joints)`` holds the joint angles of ``K`` keyframes spanning one cycle and
    ``backbones`` ``(K, n_joints, 3)`` the matching backbone points. Each link's surface roll is
    unwrapped over the cycle (closing back on keyframe 0); the mean net turn over 2 pi is returned,
    positive for a right-handed roll about the head-to-tail axis. A "non-rolling" command can
    hide a roll (docs/gait.md#hidden-roll): this measures it from the kinematics alone.
    """
    rolls = np.array(
        [surface_roll_angles(a, b, module_length) for a, b in zip(table, backbones, strict=True)]
    )
    rolls = np.concatenate([rolls, rolls[:1]])
    unwrapped = np.unwrap(rolls, axis=0)
    return float(np.mean(unwrapped[-1] - unwrapped[0]) / (2.0 * np.pi))
