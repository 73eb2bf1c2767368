"""Non-slip motion estimate of the paper (section 2.3, Eq. 6) from kinematics alone, pure numpy.

    X = sum_t delta x + 2 pi r_joint (per body roll),
    delta x = -(mean_k x_k^{t+1} - mean_k x_k^t)                                     (Eq. 6)

``x_k`` is the axial (pole-direction) coordinate of contact joint ``k`` in the virtual chassis,
i.e. relative to the mean of the module positions. The paper's three assumptions pick the
contacts: (1) contacts do not slip, (2) they sit at the joints, (3) in every two-link segment
the joint nearest the pole centre line touches. A non-slipping contact is fixed in the world, so
when it moves by ``dx`` relative to the chassis the chassis moved by ``-dx``: the minus sign.

Conventions of this module: the contact set of step ``t -> t + 1`` is the one identified at
``t`` (the anchors held during the step); a *two-link segment* is a pair of consecutive joints
``(2m, 2m + 1)``, one dorsal and one lateral (each SEA module carries one joint), so a 20-joint
snake has 10 contacts per frame; the axial direction is the fitted pole axis oriented from head
to tail, which is up the pole for a snake whose head is its lowest end.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import pairwise

import numpy as np

from acl_env.estimation.chassis import (
    distance_to_axis,
    helix_axis,
    to_chassis,
    virtual_chassis,
)
from acl_env.gait.gaits import SEA_MODULE_RADIUS, Gait
from acl_env.gait.kinematics import count_body_rolls, forward_kinematics

# The contact is on the module's surface, a cylinder of this radius about the centre line that
# FK follows: a module rolling once about its own axis without slip carries its centre line
# 2 pi r_joint over the pole, travel that no joint position shows (the last term of Eq. 6).


@dataclass(frozen=True)
class PoleFrame:
    """One snake shape placed on its pole, everything in its virtual chassis frame."""

    origin: np.ndarray  # (3,) chassis origin in the input coordinates
    axes: np.ndarray  # (3, 3) chassis axes (columns) in the input coordinates
    axis_point: np.ndarray  # (3,) a point of the pole centre line, chassis coordinates
    axis_direction: np.ndarray  # (3,) unit pole direction (head to tail), chassis coordinates
    axial: np.ndarray  # (n,) x_k of Eq. 6 for every joint: axial coordinate from the origin (m)
    contacts: np.ndarray  # (ceil(n / 2),) indices of the contact joints (assumptions 2-3)
    roll_climb: float  # axial travel per unit right-handed roll angle of the links, over r_joint


def contact_joints(points: np.ndarray, axis_point: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Contact joints under the paper's assumptions 2-3: per two-link segment (joints ``2m``,
    ``2m + 1``), the joint nearest the pole centre line. Returns their indices, head first."""
    dist = distance_to_axis(points, axis_point, direction)
    if len(dist) % 2:
        dist = np.append(dist, np.inf)  # an odd last joint is a segment of its own
    pairs = dist.reshape(-1, 2)
    return 2 * np.arange(len(pairs)) + np.argmin(pairs, axis=1)


def _roll_climb(points: np.ndarray, axis_point: np.ndarray, direction: np.ndarray) -> float:
    """Mean of ``(t x n) . d`` over the links between joints (t: chord toward the tail, n: outward
    radial from the pole, d: pole direction): the axial travel of a link rolling right-handedly
    about its own axis without slip, per radian and per metre of rolling radius. About
    ``-cos(helix angle)`` on a right-handed helix, ``+cos`` on a left-handed one."""
    chords = np.diff(points, axis=0)
    chords /= np.linalg.norm(chords, axis=1, keepdims=True)
    outward = 0.5 * (points[1:] + points[:-1]) - axis_point
    outward -= np.outer(outward @ direction, direction)
    outward /= np.linalg.norm(outward, axis=1, keepdims=True)
    return float(np.mean(np.cross(chords, outward) @ direction))


def locate_on_pole(
    points: np.ndarray,
    previous: np.ndarray | None = None,
    pole: tuple[np.ndarray, np.ndarray] | None = None,
) -> PoleFrame:
    """Virtual chassis, pole centre line, axial coordinates and contacts of one shape.

    Args:
        points: joint positions (n, 3), head first, in any frame.
        previous: the previous frame's chassis ``axes`` (sign consistency).
        pole: ``(point, direction)`` of the pole centre line in the frame of ``points`` when it
            is known (e.g. world z in a simulation); otherwise it is fitted (:func:`helix_axis`).
    """
    origin, axes = virtual_chassis(points, previous)
    local = to_chassis(points, origin, axes)
    if pole is None:
        axis_point, direction, _ = helix_axis(local)
    else:
        direction = np.asarray(pole[1], dtype=float) @ axes
        direction /= np.linalg.norm(direction)
        axis_point = to_chassis(np.asarray(pole[0], dtype=float)[None], origin, axes)[0]
    return PoleFrame(
        origin=origin,
        axes=axes,
        axis_point=axis_point,
        axis_direction=direction,
        axial=local @ direction,
        contacts=contact_joints(local, axis_point, direction),
        roll_climb=_roll_climb(local, axis_point, direction),
    )


def axial_shift(before: PoleFrame, after: PoleFrame) -> float:
    """delta x of Eq. 6: minus the mean axial shift, relative to the chassis, of the contact
    joints identified in ``before`` (non-slip anchors during the step)."""
    k = before.contacts
    return -float(np.mean(after.axial[k]) - np.mean(before.axial[k]))


@dataclass(frozen=True)
class MotionEstimate:
    """Eq. 6 over a sequence of frames, split into its two terms."""

    steps: np.ndarray  # (n_steps,) delta x of every step (m)
    contacts: np.ndarray  # (n_frames, n_contacts) contact joints of every frame
    rolls: float  # body rolls, right-handed about the head-to-tail axis (count_body_rolls)
    roll_travel: float  # 2 pi r_joint per roll, signed so that rolling up the pole is positive

    @property
    def shift(self) -> float:
        """sum_t delta x of Eq. 6 (m)."""
        return float(np.sum(self.steps))

    @property
    def displacement(self) -> float:
        """X_rigid_body of Eq. 6 (m), positive up the pole (toward the tail)."""
        return self.shift + self.roll_travel


def estimate_from_frames(
    frames: np.ndarray,
    rolls: float = 0.0,
    r_joint: float = SEA_MODULE_RADIUS,
    pole: tuple[np.ndarray, np.ndarray] | None = None,
    closed: bool = False,
) -> MotionEstimate:
    """Eq. 6 over a sequence of joint positions ``frames`` (n_frames, n, 3), head first.

    Each frame may be in its own coordinates (e.g. the head link's frame of forward
    kinematics): only the shape enters, through the virtual chassis. ``rolls`` counts the body
    rolls over the sequence, right-handed about the head-to-tail axis; each adds ``2 pi r_joint``
    in the direction that rolling without slip on this coil moves the body (Eq. 6 writes the
    magnitude; the exact no-slip travel has a factor cos(helix angle), 0.99 here, which the paper
    drops and so does this). ``closed`` adds the step from the last frame back to the first (a
    periodic gait cycle). ``pole`` is passed to :func:`locate_on_pole`.
    """
    frames = np.asarray(frames, dtype=float)
    if frames.ndim != 3 or frames.shape[0] < 2:
        raise ValueError(f"frames must have shape (n_frames >= 2, n, 3), got {frames.shape}")
    located: list[PoleFrame] = []
    for points in frames:
        located.append(locate_on_pole(points, located[-1].axes if located else None, pole))
    pairs = list(pairwise(located))
    if closed:
        pairs.append((located[-1], located[0]))
    steps = np.array([axial_shift(a, b) for a, b in pairs])
    climb_sign = np.sign(np.mean([f.roll_climb for f in located]))
    return MotionEstimate(
        steps=steps,
        contacts=np.array([f.contacts for f in located]),
        rolls=float(rolls),
        roll_travel=float(2.0 * np.pi * r_joint * rolls * climb_sign),
    )


def estimate_gait_cycle(gait: Gait, r_joint: float = SEA_MODULE_RADIUS) -> MotionEstimate:
    """Eq. 6 over one cycle of ``gait`` from kinematics alone.

    The frames are the forward kinematics of the commanded keyframes (``gait.cycle()``), the
    cycle closed on itself; the rolls are counted by FK against the commanded backbone
    (:func:`acl_env.gait.kinematics.count_body_rolls`).
    """
    table = gait.cycle()
    joints, _, _ = forward_kinematics(table, gait.module_length)
    phases = np.arange(gait.steps_per_cycle) / gait.steps_per_cycle
    rolls = count_body_rolls(table, gait.backbones(phases), gait.module_length)
    return estimate_from_frames(joints, rolls=rolls, r_joint=r_joint, closed=True)


def estimate_displacement(
    gait: Gait, cycles: float = 2.0, r_joint: float = SEA_MODULE_RADIUS
) -> float:
    """Displacement (m) up the pole over ``cycles`` gait cycles, estimated by Eq. 6 (the cycle
    is periodic, so it is ``cycles`` times the one-cycle estimate)."""
    return float(cycles * estimate_gait_cycle(gait, r_joint).displacement)
