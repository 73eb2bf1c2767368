"""The ACL gait of Chen & Roth (Eq. 1-5) and the rolling helix of Zhen, Gong & Choset (2015).

Joint conventions are those of :mod:`acl_env.gait.kinematics`: head joint first, even joints
dorsal (about the link's y axis), odd joints lateral (about z), joint ``j`` at arc length
``(j + 1) l`` from the head tip. The pole axis is z and the backbone starts (head) at ``t = 0``
and rises with ``t``: the head is the lowest end, and climbing is motion toward the tail (+z).

Both gaits are periodic in ``phase`` (cycles). ``phi_0`` rolls the body once per cycle times
``rolls_per_cycle`` (docs/gait.md#roll-offset), signed so that a positive roll rate climbs, plus
an optional rocking roll that returns each cycle (``rock_amp``, ``rock_phase``).
"""

from __future__ import annotations

from dataclasses import dataclass
from functools import cached_property

import numpy as np

from acl_env.constants import (
    DEFAULT_N_JOINTS,
    DEFAULT_POLE_RADIUS,
    DEFAULT_STEPS_PER_CYCLE,
    JOINT_LIMIT,
    SEA_MODULE_DIAMETER,
    SEA_MODULE_LENGTH,
    SEA_MODULE_RADIUS,
)
from acl_env.gait.curves import (
    TWIST_MISMATCH,
    CurveSamples,
    PitchVaryingHelix,
    bellows_integrals,
    first_rows,
    points_at_arclength,
    sample_curve,
    surface_frame_offset,
    transported,
    twist_mismatch,
)
from acl_env.gait.kinematics import count_body_rolls
from acl_env.validation import check_finite, check_int, check_positive, check_range

# phi_0 = ROLL_SIGN * 2 pi * rolls_per_cycle * phase: with this sign the body rolls so that the
# snake moves toward its tail, i.e. up the pole (checked in MuJoCo, tests/test_env.py).
ROLL_SIGN = 1.0

# Defaults for the 20-joint SEA snake on a 0.075 m pole. The contact radius of the backbone
# (pole + module radius) is 0.1004 m; the helix is commanded 0.8 cm tighter, and the jointed
# chain sits a further ~1 cm inside the curve, so the series springs squeeze the pole
# (docs/robot_and_contact.md#squeeze). The pitch (rise per turn, 0.10 m) is two module
# diameters: adjacent turns never touch, and the 1.34 m body makes about 2.3 turns. Omega = 2
# inches (Omega = 1 only tilts the helix); A_p = 1 cm keeps every joint inside +-90 deg and the
# chain within 1.3 cm rms of the curve (a 2 cm wave pushes the chain's fit past 1.5 cm).
DEFAULT_SQUEEZE = 0.008


def helix_radius(pole_radius: float, squeeze: float = DEFAULT_SQUEEZE) -> float:
    """Backbone radius (m) that wraps a pole: its contact radius (pole + module radius) less the
    squeeze that makes the series springs press on it (docs/robot_and_contact.md#squeeze)."""
    return pole_radius + SEA_MODULE_RADIUS - squeeze


DEFAULT_RADIUS = helix_radius(DEFAULT_POLE_RADIUS)
# Accepted ranges of the gaits' arguments, wide around the SEA snake's (a 5 cm module on a 7.5 cm
# pole) and narrow enough that every keyframe table is finite (a 1e300 m radius or wave number
# makes NaN angles, and a 10**9-entry table no memory): lengths (m) in (0, 10], amplitudes in
# [0, 10] m, wave numbers within +-20 per turn, whole rolls within +-10 per cycle, phases within
# +-2 pi, and at most 1000 joints, 100000 keyframes per cycle and 100000 curve samples.
MAX_LENGTH = 10.0  # m: module length and diameter, radius, pitch, wave amplitudes
MAX_WAVES = 20.0  # axial or radial waves per turn (spatial_freq, radial_freq)
MAX_ROLLS = 10  # |rolls_per_cycle|
MAX_JOINTS, MAX_STEPS, MAX_SAMPLES = 1000, 100_000, 100_000
DEFAULT_PITCH = 0.10
DEFAULT_AMP_PITCH = 0.01


@dataclass(frozen=True)
class Saturation:
    """How much of the keyframe table hit the +-90 deg joint limit."""

    keyframe_fraction: float  # keyframes with at least one clipped joint
    sample_fraction: float  # clipped (keyframe, joint) entries
    max_excess: float  # largest |angle| - limit before clipping (rad), 0 if none


@dataclass(eq=False, kw_only=True)
class Gait:
    """Shared machinery: validation, roll offset, clipping, the cached keyframe table.

    Its fields are the arguments every gait takes; a gait's own arguments are its subclass's
    fields. Each is checked once, when the gait is made.
    """

    n_joints: int = DEFAULT_N_JOINTS
    module_length: float = SEA_MODULE_LENGTH
    radius: float = DEFAULT_RADIUS
    pitch: float = DEFAULT_PITCH
    rolls_per_cycle: float = 1.0
    steps_per_cycle: int = DEFAULT_STEPS_PER_CYCLE
    module_diameter: float = SEA_MODULE_DIAMETER
    rock_amp: float = 0.0
    rock_phase: float = 0.0

    def __post_init__(self) -> None:
        self.n_joints = check_int("n_joints", self.n_joints, 3, MAX_JOINTS)
        self.steps_per_cycle = check_int("steps_per_cycle", self.steps_per_cycle, 2, MAX_STEPS)
        self.module_length = check_positive("module_length", self.module_length, MAX_LENGTH)
        self.module_diameter = check_positive("module_diameter", self.module_diameter, MAX_LENGTH)
        self.radius = check_positive("radius", self.radius, MAX_LENGTH)
        self.pitch = check_positive("pitch", self.pitch, MAX_LENGTH)
        if self.pitch < self.module_diameter:
            raise ValueError(
                f"pitch must be at least one module diameter ({self.module_diameter} m) so that "
                f"adjacent turns do not collide, got {self.pitch}"
            )
        rolls_per_cycle = self.rolls_per_cycle
        self.rolls_per_cycle = check_range(
            "rolls_per_cycle", rolls_per_cycle, -MAX_ROLLS, MAX_ROLLS
        )
        if self.rolls_per_cycle != round(self.rolls_per_cycle):
            # phi_0 must return to itself mod 2 pi after one cycle, or phase + 1 != phase and the
            # keyframe table jumps when it wraps around.
            raise ValueError(
                f"rolls_per_cycle must be a whole number for a periodic gait, got {rolls_per_cycle}"
            )
        rock_amp = self.rock_amp
        self.rock_amp = check_finite("rock_amp", rock_amp)
        if not 0.0 <= self.rock_amp <= np.pi:
            raise ValueError(f"rock_amp must be in [0, pi] rad, got {rock_amp}")
        self.rock_phase = check_range("rock_phase", self.rock_phase, -2.0 * np.pi, 2.0 * np.pi)
        self.joint_limit = JOINT_LIMIT

    @property
    def body_length(self) -> float:
        """Head tip to tail tip (m): ``(n_joints + 1)`` modules."""
        return (self.n_joints + 1) * self.module_length

    @property
    def joint_arclengths(self) -> np.ndarray:
        """Arc length of each joint from the head tip (m)."""
        return self.module_length * np.arange(1, self.n_joints + 1)

    def roll_offset(self, phase: np.ndarray) -> np.ndarray:
        """phi_0 (rad) of Eq. 4-5: ``rolls_per_cycle`` body rolls per cycle, plus a rocking roll
        ``rock_amp sin(2 pi phase + rock_phase)`` that returns each cycle (0 unless set)."""
        phase = np.asarray(phase, dtype=float)
        angle = 2.0 * np.pi * phase
        rock = self.rock_amp * np.sin(angle + self.rock_phase) if self.rock_amp else 0.0
        return ROLL_SIGN * (self.rolls_per_cycle * angle + rock)

    def raw_angles(self, phases: np.ndarray) -> np.ndarray:
        """Unclipped joint angles, shape ``(len(phases), n_joints)``."""
        raise NotImplementedError

    def backbones(self, phases: np.ndarray) -> np.ndarray:
        """Backbone points at the joints' arc lengths, shape ``(len(phases), n_joints, 3)``."""
        raise NotImplementedError

    def joint_angles(self, phase: float) -> np.ndarray:
        """Joint angles (rad) at ``phase`` (cycles), head joint first, clipped to +-90 deg."""
        phase = check_finite("phase", phase)
        raw = self.raw_angles(np.array([phase]))[0]
        return np.clip(raw, -self.joint_limit, self.joint_limit)

    def backbone(self, phase: float) -> np.ndarray:
        """Target curve points (m) at the joints' arc lengths, shape ``(n_joints, 3)``, pole = z."""
        return self.backbones(np.array([check_finite("phase", phase)]))[0]

    @cached_property
    def _raw_cycle(self) -> np.ndarray:
        return self.raw_angles(np.arange(self.steps_per_cycle) / self.steps_per_cycle)

    def cycle(self) -> np.ndarray:
        """Keyframe table ``(steps_per_cycle, n_joints)``, row k at phase k / steps_per_cycle."""
        return self._cycle

    @cached_property
    def _cycle(self) -> np.ndarray:
        table = np.clip(self._raw_cycle, -self.joint_limit, self.joint_limit)
        table.setflags(write=False)
        return table

    @cached_property
    def saturation(self) -> Saturation:
        """Share of the cycle that the +-90 deg joint limit clips."""
        excess = np.abs(self._raw_cycle) - self.joint_limit
        return Saturation(
            keyframe_fraction=float(np.mean(np.any(excess > 0, axis=1))),
            sample_fraction=float(np.mean(excess > 0)),
            max_excess=float(max(excess.max(), 0.0)),
        )

    def measured_rolls_per_cycle(self) -> float:
        """Body rolls over one cycle relative to the pole, measured by FK (not the command).

        Same sign as ``rolls_per_cycle``: phi_0 growing by 2 pi is one left-handed roll about the
        head-to-tail axis as :func:`count_body_rolls` counts it, hence the factor ``-ROLL_SIGN``.
        """
        phases = np.arange(self.steps_per_cycle) / self.steps_per_cycle
        rolls = count_body_rolls(self.cycle(), self.backbones(phases), self.module_length)
        return -ROLL_SIGN * rolls


class RollingHelixGait(Gait):
    """Rolling helix, closed form (Zhen, Gong & Choset, ICRA 2015).

    For x = r cos t, y = r sin t, z = b t: kappa = r / (r^2 + b^2), tau = b / (r^2 + b^2),
    amplitude A = 2 kappa sin(tau l) / tau; dorsal joint ``j`` = A cos(phi_0 + tau l (j + 1)),
    lateral joint ``j`` = A sin(phi_0 + tau l (j + 1)).
    """

    # Its arguments are the shared ones (Gait's fields); the closed form's constants follow.
    @property
    def kappa(self) -> float:
        """Curvature of the helix (1/m)."""
        b = self.pitch / (2.0 * np.pi)
        return self.radius / (self.radius**2 + b**2)

    @property
    def tau(self) -> float:
        """Torsion of the helix (1/m)."""
        b = self.pitch / (2.0 * np.pi)
        return b / (self.radius**2 + b**2)

    @property
    def amplitude(self) -> float:
        """The joints' amplitude (rad)."""
        return 2.0 * self.kappa * np.sin(self.tau * self.module_length) / self.tau

    def raw_angles(self, phases: np.ndarray) -> np.ndarray:
        arg = self.roll_offset(phases)[:, None] + self.tau * self.joint_arclengths
        return np.where(
            np.arange(self.n_joints) % 2 == 0,
            self.amplitude * np.cos(arg),
            self.amplitude * np.sin(arg),
        )

    def backbones(self, phases: np.ndarray) -> np.ndarray:
        b = self.pitch / (2.0 * np.pi)
        t = self.joint_arclengths / np.hypot(self.radius, b)
        pts = np.stack([self.radius * np.cos(t), self.radius * np.sin(t), b * t], axis=-1)
        return np.broadcast_to(pts, (len(np.atleast_1d(phases)), *pts.shape)).copy()


@dataclass(eq=False, kw_only=True)
class ACLGait(Gait):
    """Arboreal Concertina Locomotion: the pitch-varying helix of Eq. 1 by curvature integration.

    The backbone (Eq. 1; Eq. 2 when ``amp_radial = 0``) is sampled per phase; kappa and tau are
    computed numerically and the joint angles follow the bellows model (Eq. 3-5), rotated by
    phi_0. ``rolls_per_cycle`` counts body rolls relative to the pole surface: the roll of the
    Frenet frame itself, which a modulated helix can hide (docs/gait.md#hidden-roll), is
    compensated in phi_0, so ``rolls_per_cycle=0`` is a gait that truly does not roll and 1 is the
    paper's rolling ACL.
    With ``amp_pitch = amp_radial = 0`` the compensation vanishes and this is the rolling helix.

    Args:
        radius: backbone helix radius r (m).
        pitch: rise per turn, 2 pi p (m).
        amp_pitch: axial wave amplitude A_p (m).
        spatial_freq: Omega, axial waves per turn.
        amp_radial: radial wave amplitude A_r (m), 0 in the paper's Eq. 2.
        radial_freq: k_r, radial waves per turn.
        n_samples: grid points of t for the numerical curvature integration.
        rock_amp, rock_phase: a rocking roll added to phi_0, ``rock_amp sin(2 pi phase +
            rock_phase)`` (rad): the body rolls back and forth once per cycle and keeps its skin
            within about 2 ``rock_amp`` of the pole (docs/gait.md#roll-offset).
    """

    amp_pitch: float = DEFAULT_AMP_PITCH
    spatial_freq: float = 2.0
    amp_radial: float = 0.0
    radial_freq: float = 2.0
    n_samples: int = 300

    def __post_init__(self) -> None:
        super().__post_init__()
        amp_pitch = self.amp_pitch = check_finite("amp_pitch", self.amp_pitch)
        amp_radial = self.amp_radial = check_finite("amp_radial", self.amp_radial)
        if not 0.0 <= amp_pitch <= MAX_LENGTH:
            raise ValueError(f"amp_pitch must be >= 0 and <= {MAX_LENGTH}, got {amp_pitch}")
        if not 0.0 <= amp_radial < self.radius:
            raise ValueError(f"amp_radial must be in [0, radius={self.radius}), got {amp_radial}")
        self.n_samples = check_int("n_samples", self.n_samples, 100, MAX_SAMPLES)
        self.spatial_freq = check_range("spatial_freq", self.spatial_freq, -MAX_WAVES, MAX_WAVES)
        self.radial_freq = check_range("radial_freq", self.radial_freq, -MAX_WAVES, MAX_WAVES)
        self.curve = PitchVaryingHelix(
            radius=self.radius,
            pitch=self.pitch,
            amp_pitch=amp_pitch,
            spatial_freq=self.spatial_freq,
            amp_radial=amp_radial,
            radial_freq=self.radial_freq,
        )
        # One twist for the whole gait, decided on its keyframes: the quadrature of tau where the
        # grid resolves it (the table is then the one it always was), the normal's measured
        # turns where it does not (docs/gait.md#thin-poles). Deciding per gait, not per phase,
        # keeps the table continuous in the phase. The keyframes' samples give the table too.
        keyframes = np.arange(self.steps_per_cycle) / self.steps_per_cycle
        samples = sample_curve(self.curve, keyframes, self.body_length, self.n_samples)
        self.transport_twist = twist_mismatch(samples) > TWIST_MISMATCH
        if self.transport_twist:
            samples = transported(samples)
        # phi_0's reference is the first keyframe's offset. The keyframe table is made from these
        # samples on first use: placing the snake at a reset needs one keyframe, not the cycle.
        first = surface_frame_offset(first_rows(samples, 1), self.body_length)
        self._frame_offset_0 = float(first[0])
        self._keyframe_samples: CurveSamples | None = samples

    @cached_property
    def _keyframe_angles(self) -> np.ndarray:
        """The keyframe table, unclipped (Eq. 3-5 at each keyframe)."""
        keyframes = np.arange(self.steps_per_cycle) / self.steps_per_cycle
        samples, self._keyframe_samples = self._keyframe_samples, None  # the table is kept
        assert samples is not None  # the table is made once (cached), from __init__'s samples
        offsets = surface_frame_offset(samples, self.body_length)
        return self._angles(keyframes, samples, offsets)

    @property
    def _raw_cycle(self) -> np.ndarray:
        return self._keyframe_angles

    def _samples(self, phases: np.ndarray):
        return sample_curve(
            self.curve, phases, self.body_length, self.n_samples, self.transport_twist
        )

    def _angles(
        self, phases: np.ndarray, samples: CurveSamples, offsets: np.ndarray | None = None
    ) -> np.ndarray:
        """Eq. 3-5 on the curve sampled at ``phases``, phi_0 with the hidden roll compensated
        (``offsets``: the samples' ``surface_frame_offset``, when already computed)."""
        c, s = bellows_integrals(samples, self.n_joints, self.module_length)
        if offsets is None:
            offsets = surface_frame_offset(samples, self.body_length)
        hidden = offsets - self._frame_offset_0
        phi0 = (self.roll_offset(phases) + hidden)[:, None]
        dorsal = np.cos(phi0) * c - np.sin(phi0) * s  # Eq. 5
        lateral = np.sin(phi0) * c + np.cos(phi0) * s  # Eq. 4
        return np.where(np.arange(self.n_joints) % 2 == 0, dorsal, lateral)

    def raw_angles(self, phases: np.ndarray) -> np.ndarray:
        phases = np.atleast_1d(np.asarray(phases, dtype=float))
        return self._angles(phases, self._samples(phases))

    def backbones(self, phases: np.ndarray) -> np.ndarray:
        samples = self._samples(np.atleast_1d(np.asarray(phases, dtype=float)))
        return points_at_arclength(samples, self.joint_arclengths)
