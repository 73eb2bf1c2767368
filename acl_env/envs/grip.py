"""Compliant grip: the ACL gait's squeeze adapted, per body section, to the spring torques.

The paper blames ACL's slip on "frequent downward slipping during ACL's expanding and contracting
phase" and names the remedy: "adding robot force control in parallel with position control". On
the SEA snake the springs measure each joint's torque; this controller, run by the firmware at
100 Hz inside each 0.1 s env step, closes the loop the way CMU's compliant controllers do
(Rollinson, Bilgili & Choset): it changes the gait's *shape parameter*, the squeeze, not the
joint angles one by one.

The squeeze is the one parameter of Eq. 1-5 that sets how hard the helix presses on the pole:
the helix radius is pole + module radius - squeeze. Its generalised force, by virtual work, is

    Q_s = sum_j  w_js  tau_j  dq_j/dsqueeze(k)         (N)

with ``tau_j`` the spring torque the joint reads (``actuators.read_torque``), ``dq_j/dsqueeze``
the gait's own sensitivity at keyframe ``k`` (the secant between the keyframe tables of helices
5 mm tighter and looser, ``envs/modulation.offset_tables``: the joints are far from linear in the
squeeze, and 5 mm is the scale the controller works at) and ``w_js`` joint ``j``'s share of
section ``s`` (``envs/modulation.section_weights``). ``Q_s > 0``: the section's springs push
the body tighter than it is, i.e. it presses on the pole. The springs also carry the wave's and
gravity's loads, so ``Q_s`` is low-passed over one control step (``GRIP_FILTER``) before an
admittance law, integral with a leak back to the gait's own squeeze, holds it at a target:

    d sigma_s / dt = gain (target_s - Qf_s) - sigma_s / leak,      |sigma_s| <= GRIP_RANGE

and the joints are commanded the gait with section ``s``'s helix ``sigma_s`` tighter
(``interpolate_offsets``: the exact tables, interpolated). A section that loses its grip as
the wave expands it tightens, and one pressing harder than it needs relaxes, which a fixed
squeeze (the open loop) cannot do. The leak keeps the loads the filter passes from winding the
sections up to the range's ends; a fast loop loses the pole (falls by gain: ``docs/grip.md``).
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import numpy as np

from acl_env.envs.modulation import interpolate_offsets, offset_tables
from acl_env.gait.gaits import Gait

GRIP_TICKS = 10  # firmware ticks per 0.1 s env step: the 100 Hz loop of the SEA modules
GRIP_RANGE = 0.02  # m: the most the controller tightens or loosens a section's helix
GRIP_TARGET_RANGE = (-500.0, 500.0)  # N: accepted targets of the generalised squeeze force
GRIP_GAIN_RANGE = (0.0, 1e-2)  # m per N s: accepted integral gains
GRIP_GAIN = 1e-4  # m per N s: 1 mm/s of squeeze for every 10 N missing
GRIP_LEAK = 1.0  # s: the time constant of the return to the gait's own squeeze
GRIP_LEAK_RANGE = (0.01, 100.0)  # s
GRIP_FILTER = 0.1  # s: the low-pass of the measured force, one control step
GRIP_ACTION_SCALE_MAX = 500.0  # N per unit action


def squeeze_sensitivity(tables: np.ndarray, scale: float) -> np.ndarray:
    """``(steps_per_cycle, n_joints)`` dq/dsqueeze (rad/m) from a squeeze offset table
    (``offset_tables`` with ``(("squeeze", scale),)``): the central difference at the grid's
    centre."""
    n_grid = tables.shape[1]
    mid, step = n_grid // 2, 2.0 * scale / (n_grid - 1)
    return (tables[0, mid + 1] - tables[0, mid - 1]) / (2.0 * step)


class GripController:
    """The integral squeeze controller of one env (its state: ``offset``, per section, m).

    ``weights``: ``(n_joints, n_sections)`` section hat functions; ``target`` (N), ``gain``
    (m per N s) and ``leak`` (s) the law's; each ``reset`` gives it the episode's gait (the
    pole may change).
    """

    def __init__(self, weights: np.ndarray, target: float, gain: float, leak: float) -> None:
        self.weights = weights
        self.target = np.full(weights.shape[1], float(target))  # N, per section
        self.gain = float(gain)
        self.leak = float(leak)
        self.offset = np.zeros(weights.shape[1])  # m: the sections' squeeze offsets
        self.force = np.zeros(weights.shape[1])  # N: the filtered Q_s
        self._started = False  # the filter starts from the first measurement
        self._tables = np.zeros((1, 3, 1, weights.shape[0]))
        self._sensitivity = np.zeros((1, weights.shape[0]))

    def reset(self, gait: Gait, kwargs: Mapping[str, Any]) -> None:
        """Start an episode on ``gait``, whose squeeze tables are those of ``gait``'s class with
        keyword arguments ``kwargs`` (cached per gait shape: the env gives the pole radius
        rounded to 1 mm), with the sections at the gait's own squeeze."""
        items = tuple(sorted(kwargs.items()))
        self._tables = offset_tables(type(gait), items, (("squeeze", GRIP_RANGE),))
        self._sensitivity = squeeze_sensitivity(self._tables, GRIP_RANGE)
        self.offset[:] = 0.0
        self.force[:] = 0.0
        self._started = False

    def measure(self, torque: np.ndarray, k: int) -> np.ndarray:
        """``Q_s`` (N) at keyframe ``k`` from the joints' read spring torques (N m)."""
        return (torque * self._sensitivity[k]) @ self.weights

    def update(self, torque: np.ndarray, k: int, dt: float) -> np.ndarray:
        """One firmware tick of ``dt`` s: measure and filter, integrate, and return the
        joint-target change (rad)."""
        force = self.measure(torque, k)
        if self._started:
            self.force += (dt / GRIP_FILTER) * (force - self.force)
        else:
            self.force[:], self._started = force, True
        rate = self.gain * (self.target - self.force) - self.offset * (1.0 / self.leak)
        offset = np.maximum(self.offset + dt * rate, -GRIP_RANGE)
        np.minimum(offset, GRIP_RANGE, out=self.offset)  # np.clip, without its dispatch
        return self.change(k)

    def change(self, k: int) -> np.ndarray:
        """Joint-target change (rad) at keyframe ``k`` for the current section offsets."""
        per_joint = (self.weights @ self.offset)[None, :] * (1.0 / GRIP_RANGE)
        return interpolate_offsets(self._tables, k, per_joint)


def check_ticks(frame_skip: int) -> int:
    """Physics steps per firmware tick: the control step must hold ``GRIP_TICKS`` whole ticks."""
    if frame_skip % GRIP_TICKS:
        raise ValueError(
            f"grip_target needs a timestep that divides the 0.1 s step into {GRIP_TICKS} "
            f"firmware ticks, got {frame_skip} physics steps per step"
        )
    return frame_skip // GRIP_TICKS


__all__ = [
    "GRIP_ACTION_SCALE_MAX",
    "GRIP_GAIN",
    "GRIP_GAIN_RANGE",
    "GRIP_LEAK",
    "GRIP_LEAK_RANGE",
    "GRIP_RANGE",
    "GRIP_TARGET_RANGE",
    "GRIP_TICKS",
    "GripController",
    "check_ticks",
    "squeeze_sensitivity",
]
