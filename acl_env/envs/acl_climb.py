"""The SEA snake climbing a pole, with an analytic gait as the residual baseline."""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping
from functools import lru_cache
from typing import Any, ClassVar

import mujoco
import numpy as np
from gymnasium import spaces
from gymnasium.envs.mujoco import MujocoEnv
from gymnasium.utils import EzPickle

from acl_env import tuned_gaits
from acl_env.constants import (
    CONTROL_DT,
    DEFAULT_FRICTION,
    DEFAULT_KP,
    DEFAULT_N_JOINTS,
    DEFAULT_POLE_RADIUS,
    FLOOR_GEOM,
    IMU_GYRO_SENSOR,
    IMU_QUAT_SENSOR,
    JOINT_LIMIT,
    PHYSICS_TIMESTEP,
    SCENE_FILE,
    SEA_MODULE_RADIUS,
    TRACK_CAMERA,
)
from acl_env.envs import termination
from acl_env.envs.modulation import (
    DEFAULT_SECTIONS,
    check_modulation,
    check_sections,
    interpolate_offsets,
    offset_tables,
    section_weights,
    table_radius,
)
from acl_env.envs.randomize import (
    DEFAULT_RANDOMIZATION,
    RandomizedElements,
    apply_physics,
    check_randomization,
    draw_physics,
    sensor_noise_std,
)
from acl_env.envs.rewards import (
    DEFAULT_REWARD_WEIGHTS,
    StepMeasures,
    check_reward_weights,
    reward_terms,
)
from acl_env.gait import ACLGait, Gait, RollingHelixGait
from acl_env.gait.gaits import DEFAULT_SQUEEZE, helix_radius
from acl_env.gait.kinematics import clear_placement
from acl_env.model import assets_dir, build_model
from acl_env.validation import (
    check_bool,
    check_choice,
    check_finite,
    check_int,
    check_mapping,
    check_positive,
    check_range,
    check_sequence,
    check_string,
)

GAITS: dict[str, type[Gait] | None] = {
    "acl": ACLGait,
    "rolling_helix": RollingHelixGait,
    "none": None,
}
# Accepted ranges of the constructor's arguments (the Arguments table says why).
N_JOINTS_RANGE = (3, 100)
STEPS_PER_CYCLE_RANGE = (2, 2200)
CYCLES_PER_EPISODE_RANGE = (1, 8)
POLE_RADIUS_RANGE = (0.01, 0.5)  # m
FRICTION_MAX = 5.0
KP_MAX = 200.0  # N m/rad
SQUEEZE_RANGE = (-0.05, 0.05)  # m
RESIDUAL_SCALE_MAX = math.pi  # rad
FALL_DISTANCE_MAX = 4.0  # m: the pole's height
ROLL_LIMIT_MAX = 3600.0  # deg: ten turns, more than any episode can roll (about 2 per cycle)
IMAGE_SIZE_RANGE = (1, 4096)  # pixels
GAIT_SAMPLES_RANGE = (100, 1000)  # the ACL gait's n_samples
# The env's own settings: a gait_kwargs entry for them would disagree with the model.
GAIT_KWARGS_REFUSED = ("n_joints", "steps_per_cycle", "module_length", "module_diameter")
# s: physics steps accepted; 5 ms was the largest without MuJoCo warnings in the fidelity panel
# (benchmarks/fidelity.py), 0.5 ms costs 200 MuJoCo steps per env step.
TIMESTEP_RANGE = (0.0005, 0.005)
SLIP_SAMPLES = 5  # contact velocities are sampled this many times per step (every 20 ms)
START_CLEARANCE = 0.005  # m between shells and pole when the snake is placed
START_HEIGHT = 0.3  # m from the floor to the lowest point of the snake at reset
RAMP_TIME = 0.3  # s to ramp the squeeze in from the placed pose to the first keyframe
SETTLE_TIME = 0.2  # s holding the first keyframe before the episode starts


@lru_cache(maxsize=16)
def _cached_gait(name: str, items: tuple[tuple[str, Any], ...]) -> Gait:
    """Gait objects are immutable; their keyframe tables are worth sharing across resets."""
    gait = GAITS[name](**dict(items))
    gait.cycle()
    return gait


class ACLClimbEnv(MujocoEnv, EzPickle):
    """A 20-joint SEA snake climbs a vertical pole; the policy adds residuals to a gait.

    ## Description
    The CMU SEA snake (module 0.0639 m long, 0.0508 m wide, 0.205 kg, +-90 deg joints, 7 N m) is
    wrapped around a fixed pole of radius ``pole_radius``. Each step plays one keyframe of the base
    gait (Chen & Roth's ACL, Eq. 1-5, or the rolling helix) through position servos that stand in
    for the series springs; the action is a residual on those joint targets. With a zero action
    this is the open-loop gait of the paper (220 keyframes per cycle at 10 Hz, 22 s per cycle).

    ## Action Space
    ``Box(-1, 1, (n_joints,), float32)``. Joint ``j`` target (rad) =
    ``clip(gait(phase)[j] + residual_scale * action[j], -pi/2, pi/2)``. Actions outside [-1, 1]
    are clipped; NaN or inf raises ``ValueError``. With ``base_gait="none"`` the gait term is 0.
    With ``phase_rate_range=(low, high)`` (the PMTG option of Iscen et al. 2018, off by default)
    the action has one more entry that sets how many keyframes the gait advances this step:
    ``1 + a (high - 1)`` for ``a >= 0``, ``1 + a (1 - low)`` below, so a zero action is still the
    open-loop gait; between keyframes the gait's targets are interpolated linearly.
    With ``gait_modulation={parameter: scale}`` (off by default) the action has
    ``len(gait_modulation) * modulation_sections`` more entries, between the joint residual and
    the cadence, parameter-major: entry ``(p, s)`` offsets gait parameter ``p`` (``squeeze``,
    ``amp_pitch``, ``amp_radial``) by up to ``scale`` m in body section ``s`` (head first; hat
    functions between the sections' centres), and the joint targets change as the gait's own
    Eq. 1-5 tables with that offset would (``envs/modulation.py``; docs/residual_rl.md#gait-
    modulation): a grip that can tighten where and when it is needed.
    ``env.unwrapped.action_names`` names every entry (``joint_3``, ``squeeze_section_1``,
    ``cadence``); ``acl-train --init-from`` matches a trained policy's actions by these names.

    ## Observation Space
    What the robot senses (float64, ``n = n_joints``):

    | index | observation | unit |
    |---|---|---|
    | 0 .. n-1 | joint angles | rad |
    | n .. 2n-1 | joint velocities | rad/s |
    | 2n .. 3n-1 | joint torques (servo output: kp x deflection + damping) | N m |
    | 3n .. 3n+3 | head IMU orientation, quaternion (w, x, y, z) | - |
    | 3n+4 .. 3n+6 | head IMU angular velocity | rad/s |
    | 3n+7, 3n+8 | cos, sin of the gait phase of the next step | - |
    | 3n+9 .. 4n+8 | base gait's target angles for the next step | rad |
    | 4n+9 .. 4n+14 | only with ``privileged_obs``: centre of mass position, velocity | m, m/s |

    ## Rewards
    ``reward = reward_climb + reward_slip`` with
    ``reward_climb = w_climb * climb``: rise of the snake's centre of mass along the pole (m), and
    ``reward_slip = -w_slip * slip``: mean sliding distance of the snake-pole contacts (m), from
    MuJoCo's contact velocities (tangential ``efc_vel`` rows), sampled 5 times per step. Weights in
    ``reward_weights`` (default 1 and 1), and ``reward_roll = -w_roll * roll`` (default weight 0,
    so off): the growth over the step of the range each module's roll has swept since the
    episode started, mean over modules (rad; see "Body roll"), and ``reward_energy =
    -w_energy * energy`` (default weight 0: off): the actuator work of the step (J), and
    ``reward_action_rate = -w_action_rate * action_rate`` (default weight 0: off): the action's
    squared change since the last step, summed over its entries and divided by the number of
    joints (action units; the mean over a joints-only action; the step after a reset compares
    with a zero action), ``info["action_rate"]``.
    ``info`` carries every ``reward_<term>``, the raw ``climb``, ``slip`` and ``roll``,
    ``energy`` (J: actuator work sum |tau qdot| dt, as spent by motors that do not regenerate),
    ``com_height``, ``phase`` (cycles) and ``phase_rate`` (keyframes advanced, 1 unless
    ``phase_rate_range`` is set).

    ## Body roll
    Measured in the simulation, not read from the gait's command (a "non-rolling" command can
    hide a roll, docs/gait.md#hidden-roll): after every step each module's roll about its own axis
    relative to the pole surface (the angle from the pole's outward normal to the link's z axis,
    ``acl_env.gait.kinematics.link_roll_angles``, the gait's own roll diagnostic, here from
    MuJoCo's link frames) is unwrapped since the episode started. ``info["roll_span_deg"]`` is
    the largest range any module's roll has swept, ``info["body_rolls"]`` the body's net turns
    about its axis (mean over modules; the rolling ACL reads -1 per cycle, the non-rolling one
    ~0). The range a module's roll sweeps is the body-frame counterpart of the arc of its skin
    that touches the pole (``touched_arc_deg`` in ``acl_env.evaluation``, from contacts).

    ## Starting State
    The first keyframe (phase ``k0 / steps_per_cycle``, ``k0`` drawn from the first
    ``start_phase_range`` of a cycle) is drawn by forward kinematics with a helix loosened until
    every shell clears the pole by 5 mm, fitted onto that helix (Kabsch), turned by a random yaw
    about the pole, 0.3 m above the floor, with joint noise of ``reset_noise_scale`` rad. The
    servos then ramp to the real keyframe (the squeeze) in 0.3 s with gravity off, and hold it
    0.2 s with gravity on. The episode
    starts from there; it is deterministic per seed.

    ## Episode End
    Truncation after ``cycles_per_episode`` gait cycles. Termination when the snake *fell*: its
    centre of mass is ``fall_distance`` below where the episode started, a shell touches the
    floor, or no shell touched the pole at any sample of a step (``info["fell"]``); or when the
    physics became *unstable*: a MuJoCo warning or a non-finite state (``info["unstable"]``; the
    step's reward terms are then 0); or, with ``roll_limit`` set, when the body *rolled*: some
    module's roll swept more than ``roll_limit`` degrees (``info["rolled"]``).

    ## Non-rolling task (``acl_env/ACLClimbNoRoll-v3``)
    The paper's future work: climb without rolling, so that sensors can sit on the part of each
    module's skin that never touches the pole. Registered with ``acl_env.NOROLL_KWARGS``:

    * base gait: ACL with ``rolls_per_cycle=0`` (the roll of the curvature wave compensated, so
      the body truly does not roll) with the open-loop tuner's best parameters for this task's
      reward (``acl_noroll`` in ``train/configs/tuned_gaits.yml``: 300 trials, validated on 10
      new seeds): ``amp_pitch`` 3.88 cm, ``spatial_freq`` 2, ``amp_radial`` 2.19 cm,
      ``radial_freq`` 2, ``pitch`` 8.0 cm, ``squeeze`` 0.72 cm. Larger waves than the default
      non-rolling gait (A_p 1 cm, no radial wave, 0.6 cm per cycle) are what make it climb
      without the roll. Open loop (2 cycles, seeds 0-1): 8.3-9.3 cm per cycle, slip 11 cm per
      cycle, roll swept <= 69 deg, touched arc <= 60 deg, under 0.004 turns per cycle (the
      rolling ACL: 19.8 cm and -1.0 turn per cycle, 730 deg swept, 360 deg touched); 8.7 cm per
      gait cycle over 20 seeds, as far as any open loop the climb studies found (8.8-8.9 cm).
      Played with its squeeze as tuned it sits near a cliff: the joint limit clips 9 % of its
      commands at 0.075 m, 18 % on the 0.065 m pole (inside the training randomisation), where
      it rolls past ``roll_limit`` within 30 steps, and 21 % on the 0.055 m pole, which it loses
      at once; hence the thin-pole squeeze below.
    * reward weights ``{"climb": 1, "slip": 0.25, "roll": 0.05}``. Climbing by rolling is worth
      ~0.2 m per turn (the rolling ACL), so rolling pays only while ``w_roll`` is below
      0.2 / (2 pi) = 0.03 per rad; 0.05 makes every turn cost more than it climbs. The open loop
      sweeps ~1.1 rad once (its waves' own twist), 0.05 of reward per episode. Slip weighs 0.25:
      a non-rolling gait inches by sliding the sections between its anchors (0.8-1.7 m of slip
      per metre climbed), and with slip weighed 1 the reward of the first gaits tried here was
      negative, which would make ending the episode (falling, rolling) pay. The tuner optimised
      the gait under these weights (0.040 reward per gait cycle on the validation seeds).
    * ``roll_limit`` 90 deg: the issue's bound on the touched arc, in the body frame. The episode
      ends when a module's roll sweeps more (the open loop sweeps up to 69); whatever rolling
      could gain after that is lost, and evaluation counts such episodes (``rolled``).

    * ``squeeze_slope`` 0.85: on a pole thinner than 0.075 m the helix is commanded looser by
      0.85 x the difference (``squeeze_at``), so that the joints can still curl it: 9-12 % of the
      commands clipped from 0.055 to 0.075 m, and open loop no roll or fall on any of those poles
      (8.2 cm per gait cycle at 0.065 m, 3.5 cm at 0.055 m; README, "The thin-pole squeeze").

    The shipped non-rolling policy (``train/configs/ppo.yml``) plays this gait and trains for
    the climb itself (``slip`` weight 0, the roll term and limit kept), the issue's metric, with
    ``action_rate`` 0.001 (without it the residual learns to flip at every step and rides the
    contact's creep; README, "The non-rolling task").

    v3 replaces v2's gait: v2 registered the same study's best on v1's gait tables (``amp_pitch``
    2.88 cm, ``amp_radial`` 1.20 cm, ``pitch`` 10.9 cm, ``squeeze`` 1.57 cm; 4.1 cm per gait
    cycle), where large-wave gaits broke; rerun on v2's tables the study found this one, which
    climbs twice as far. ``acl_env/ACLClimbNoRoll-v2`` stays registered (``NOROLL_V2_KWARGS``)
    for the policies trained on it. v2 replaced v1: the non-rolling gaits' keyframe tables
    jumped by up to 180 deg on thin poles, where the quadrature of the curve's torsion failed
    (docs/gait.md#thin-poles); the snake then rolled off in its first steps.

    ## Copies
    ``pickle`` and ``copy.deepcopy`` of the env, taken at any point of an episode, continue
    exactly where the original was: the same actions give the same observations, rewards, infos
    and later resets (branching rollouts from a mid-episode state). ``info`` values are plain
    Python ``float`` and ``bool``, so ``json.dumps(info)`` works.

    ## Arguments
    | argument | default | accepted | meaning |
    |---|---|---|---|
    | base_gait | "acl" | "acl", "rolling_helix", "none" | base gait ("none": pure RL ablation) |
    | gait_kwargs | None | dict of numbers | to the gait; radius: pole + module radius - squeeze |
    | residual_scale | 0.2 (pi/2 for "none") | (0, pi] | rad of joint target per unit action |
    | n_joints | 20 | int in [3, 100] | joints (modules + 1 links) |
    | pole_radius | 0.075 | [0.01, 0.5] | m |
    | friction | 1.0 | (0, 5] | sliding friction of the snake's skin and the pole |
    | kp | 20.0 | (0, 200] | servo stiffness (the series spring), N m/rad |
    | squeeze | None (0.008) | [-0.05, 0.05] | m the gait's helix is commanded inside the pole contact |
    | tuned_gait | None | a key of ``acl_env.tuned_gaits`` | a shipped tuned gait: its squeeze, gait_kwargs |
    | squeeze_slope | 0.0 | [0, 1] | m of squeeze given up per m the pole is under 0.075 m |
    | steps_per_cycle | 220 | int in [2, 2200] | keyframes per gait cycle (one per step, 0.1 s) |
    | cycles_per_episode | 2 | int in [1, 8] | episode length in cycles (the paper's evaluation) |
    | reward_weights | {"climb": 1, "slip": 1} | dict of numbers | weights of the reward terms |
    | domain_randomization | None | None, bool or dict | True for defaults, or a dict (see below) |
    | privileged_obs | False | bool | append the centre of mass position and velocity |
    | start_phase_range | 0.05 | [0, 1] | fraction of a cycle the start keyframe is drawn from |
    | reset_noise_scale | 0.02 | [0, pi/2] | rad of joint noise at reset |
    | fall_distance | 0.2 | (0, 4] | m of centre-of-mass drop that counts as a fall |
    | phase_rate_range | None | None or (low, high) | keyframes per step: policy sets the cadence |
    | timestep | 1/300 | 0.1 s / (5 k), 0.5-5 ms | physics step, s (v0: 0.002) |
    | roll_limit | None | None or (0, 3600] | deg a module's roll may sweep before the end |
    | gait_modulation | None | None or {parameter: (0, 0.02]} | m of offset per unit action |
    | modulation_sections | None (4) | int in [1, min(20, n_joints)] | body sections modulated |
    | render_mode | None | None or a ``metadata`` mode | Gymnasium's render modes |
    | width, height | 640, 480 | int in [1, 4096] | pixels of a rendered frame |
    | camera_name | "track" | a camera of the model | "track" follows the snake; "side", "top" |

    Every argument is checked when the env is built: a value of the wrong kind (``"false"`` for
    a bool, ``1`` for ``domain_randomization``, a string for a number) raises ``TypeError``, one
    out of range ``ValueError``, both naming the argument and what it accepts. Every accepted
    combination resets and steps with finite output (property-tested). The upper bounds and why:
    ``n_joints <= 100``: 300 joints diverge during the reset and 1000 overflow MuJoCo's memory
    arena (``mujoco.FatalError``). ``steps_per_cycle <= 2200`` (10x the paper's cadence): the
    gait's keyframe table is computed in one batch, about 0.1 MB per keyframe (250 MB at 2200;
    ``10**6`` needed 7 GB), which also bounds the ACL gait's ``n_samples`` to [100, 1000].
    ``cycles_per_episode <= 8``: the pole is 4 m tall and the snake climbs 0.25-0.38 m per cycle
    (open loop, policy), so it would reach the top after about 9 cycles; ``fall_distance <= 4``
    for the same reason. ``residual_scale <= pi``: targets are clipped to +-pi/2, so a larger
    residual changes nothing. ``phase_rate_range``: ``0 <= low <= 1 <= high <= steps_per_cycle /
    2`` (beyond half a cycle per step the phase aliases). ``pole_radius``, ``friction``, ``kp``
    and ``squeeze`` span about an order of magnitude around the SEA snake's own; ``squeeze`` must
    also stay below pole + module radius. ``width``, ``height <= 4096``: MuJoCo's offscreen
    buffer. ``gait_kwargs`` must not set ``n_joints``, ``steps_per_cycle`` (the env's),
    ``module_length`` or ``module_diameter`` (the model's).

    ``domain_randomization`` draws, at every reset, ``pole_radius``, ``friction``, ``kp`` and
    ``mass_scale`` uniformly from ``(low, high)`` ranges and adds Gaussian ``sensor_noise`` (std:
    that many rad on angles, 10x in rad/s on velocities, kp x in N m on torques). ``True`` uses
    ``DEFAULT_RANDOMIZATION``. The gait's radius follows the drawn pole radius. Each range must lie
    inside the accepted range of the argument of that name; ``0 < mass_scale <= 10`` and
    ``0 <= sensor_noise <= 1``.

    ## Version History
    * v1: physics step 1/300 s (30 MuJoCo steps per 0.1 s control step) instead of 2 ms,
      argument ``timestep`` (``timestep=0.002`` is the v0 physics). Open-loop climbing stays
      within 2 % (climb) and 15 % (slip, energy per metre) of a 1 ms step in every condition of
      ``benchmarks/fidelity.py``; slip reads up to 15 % higher than at 1 ms (v0: up to 6 %).
      Later options that leave the default dynamics and reward unchanged: ``roll_limit``,
      the ``roll`` and ``energy`` reward terms (weight 0), ``gait_modulation`` and
      ``modulation_sections`` (a zero modulation action is bit-identical
      to the env without it).
    * v0: initial release.
    """

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"],
        "render_fps": 10,
    }

    def __init__(
        self,
        base_gait: str = "acl",
        gait_kwargs: Mapping[str, Any] | None = None,
        residual_scale: float | None = None,
        n_joints: int = DEFAULT_N_JOINTS,
        pole_radius: float = DEFAULT_POLE_RADIUS,
        friction: float = DEFAULT_FRICTION,
        kp: float = DEFAULT_KP,
        squeeze: float | None = None,
        steps_per_cycle: int = 220,
        cycles_per_episode: int = 2,
        reward_weights: Mapping[str, float] | None = None,
        domain_randomization: bool | Mapping[str, Any] | None = None,
        privileged_obs: bool = False,
        start_phase_range: float = 0.05,
        reset_noise_scale: float = 0.02,
        fall_distance: float = 0.2,
        phase_rate_range: tuple[float, float] | None = None,
        timestep: float = PHYSICS_TIMESTEP,
        roll_limit: float | None = None,
        gait_modulation: Mapping[str, float] | None = None,
        modulation_sections: int | None = None,
        squeeze_slope: float = 0.0,
        render_mode: str | None = None,
        width: int = 640,
        height: int = 480,
        camera_name: str = TRACK_CAMERA,
        tuned_gait: str | None = None,
    ) -> None:
        EzPickle.__init__(
            self,
            base_gait,
            gait_kwargs,
            residual_scale,
            n_joints,
            pole_radius,
            friction,
            kp,
            squeeze,
            steps_per_cycle,
            cycles_per_episode,
            reward_weights,
            domain_randomization,
            privileged_obs,
            start_phase_range,
            reset_noise_scale,
            fall_distance,
            phase_rate_range,
            timestep,
            roll_limit,
            gait_modulation,
            modulation_sections,
            squeeze_slope,
            render_mode,
            width,
            height,
            camera_name,
            tuned_gait,
        )
        # Every argument is checked for type and range here (TypeError / ValueError naming it),
        # so that no value accepted now can crash reset or step later.
        self.base_gait = check_choice("base_gait", base_gait, tuple(GAITS))
        self.tuned_gait = tuned_gait
        if tuned_gait is not None:
            # A shipped tuned gait by key (acl_env.tuned_gaits): its squeeze and gait_kwargs.
            if self.base_gait != "acl":
                raise ValueError(f"tuned_gait needs base_gait 'acl', got {base_gait!r}")
            shape = tuned_gaits.resolve(
                {"tuned_gait": tuned_gait, "squeeze": squeeze, "gait_kwargs": gait_kwargs}
            )
            squeeze, gait_kwargs = shape["squeeze"], shape["gait_kwargs"]
        squeeze = DEFAULT_SQUEEZE if squeeze is None else squeeze
        self.n_joints = check_int("n_joints", n_joints, *N_JOINTS_RANGE)
        self.steps_per_cycle = check_int("steps_per_cycle", steps_per_cycle, *STEPS_PER_CYCLE_RANGE)
        self.cycles_per_episode = check_int(
            "cycles_per_episode", cycles_per_episode, *CYCLES_PER_EPISODE_RANGE
        )
        default_scale = JOINT_LIMIT if self.base_gait == "none" else 0.2
        self.residual_scale = check_positive(
            "residual_scale",
            default_scale if residual_scale is None else residual_scale,
            RESIDUAL_SCALE_MAX,
        )
        self.pole_radius = check_range("pole_radius", pole_radius, *POLE_RADIUS_RANGE)
        self.friction = check_positive("friction", friction, FRICTION_MAX)
        self.kp = check_positive("kp", kp, KP_MAX)
        self.squeeze = check_range("squeeze", squeeze, *SQUEEZE_RANGE)
        self.squeeze_slope = check_range("squeeze_slope", squeeze_slope, 0.0, 1.0)
        self.reward_weights = check_reward_weights(
            None
            if reward_weights is None
            else check_mapping("reward_weights", reward_weights, DEFAULT_REWARD_WEIGHTS)
        )
        self.randomization = check_randomization(
            domain_randomization,
            {
                "pole_radius": POLE_RADIUS_RANGE,
                "friction": (0.0, FRICTION_MAX),
                "kp": (0.0, KP_MAX),
            },
        )
        self.privileged_obs = check_bool("privileged_obs", privileged_obs)
        self.start_phase_range = check_range("start_phase_range", start_phase_range, 0.0, 1.0)
        self.reset_noise_scale = check_range(
            "reset_noise_scale", reset_noise_scale, 0.0, JOINT_LIMIT
        )
        self.fall_distance = check_positive("fall_distance", fall_distance, FALL_DISTANCE_MAX)
        self.phase_rate_range = _phase_rate_range(phase_rate_range, self.steps_per_cycle)
        self.roll_limit = (
            None if roll_limit is None else check_positive("roll_limit", roll_limit, ROLL_LIMIT_MAX)
        )
        if render_mode is not None:
            check_choice("render_mode", render_mode, tuple(self.metadata["render_modes"]))
        check_int("width", width, *IMAGE_SIZE_RANGE)
        check_int("height", height, *IMAGE_SIZE_RANGE)
        check_string("camera_name", camera_name)
        self.gait_kwargs = _gait_kwargs(gait_kwargs, self.base_gait)
        # The gait must exist for every pole the episodes can draw (its radius follows the pole).
        radii = {self.pole_radius, *self.randomization.get("pole_radius", ())}
        for radius in sorted(radii):
            squeeze = self.squeeze_at(radius)
            if helix_radius(radius, squeeze) <= 0.0 and "radius" not in self.gait_kwargs:
                raise ValueError(
                    f"squeeze={squeeze} leaves no helix radius for a pole of {radius} m "
                    f"(squeeze must be below pole radius + {SEA_MODULE_RADIUS} m)"
                )
            start_gait = self.base_gait if GAITS[self.base_gait] else "acl"
            GAITS[start_gait](**self._gait_kwargs(radius))  # raises naming the bad entry
        self.gait_modulation = check_modulation(gait_modulation)
        self.modulation_sections = check_sections(
            min(DEFAULT_SECTIONS, self.n_joints)
            if modulation_sections is None
            else modulation_sections,
            self.n_joints,
        )
        if self.gait_modulation and GAITS[self.base_gait] is None:
            raise ValueError("gait_modulation needs a base gait to modulate, got base_gait='none'")
        self._modulated = tuple(self.gait_modulation)
        self._section_weights = section_weights(self.n_joints, self.modulation_sections)
        self.timestep, frame_skip = _timestep(timestep)

        self.gait = self._make_gait(self.pole_radius)
        n = self.n_joints
        obs_size = 4 * n + 9 + (6 if self.privileged_obs else 0)
        observation_space = spaces.Box(-np.inf, np.inf, shape=(obs_size,), dtype=np.float64)
        MujocoEnv.__init__(
            self,
            str(assets_dir() / SCENE_FILE),
            frame_skip,
            observation_space=observation_space,
            render_mode=render_mode,
            width=width,
            height=height,
            camera_name=camera_name,
        )
        if mujoco.mj_name2id(self.model, mujoco.mjtObj.mjOBJ_CAMERA, camera_name) < 0:
            cameras = [self.model.camera(i).name for i in range(self.model.ncam)]
            raise ValueError(
                f"camera_name must be one of the model's cameras {cameras}, got {camera_name!r}"
            )
        n_modulation = len(self._modulated) * self.modulation_sections
        self._rate_index = n + n_modulation  # the cadence action, when there is one
        n_actions = n + n_modulation + (self.phase_rate_range is not None)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n_actions,), dtype=np.float32)
        self._elements = RandomizedElements.of(self.model, n)
        self._nominal_physics = {
            "pole_radius": self.pole_radius,
            "friction": self.friction,
            "kp": self.kp,
            "mass_scale": 1.0,
        }
        # Contact pair (g1, g2) -> 1 snake-pole, 2 snake-floor, 0 other, via key g1 * ngeom + g2.
        ngeom, snake = self.model.ngeom, self._elements.snake_geoms
        pair_kind = np.zeros(ngeom * ngeom, dtype=np.int8)
        for other, code in ((self._elements.pole_geom, 1), (self.model.geom(FLOOR_GEOM).id, 2)):
            pair_kind[snake * ngeom + other] = code
            pair_kind[other * ngeom + snake] = code
        self._ngeom = ngeom
        self._pair_kind: list[int] = pair_kind.tolist()  # indexed per contact: a list is faster
        self._root_body = self._elements.snake_bodies[0]
        self._imu_quat = _sensor_slice(self.model, IMU_QUAT_SENSOR)
        self._imu_gyro = _sensor_slice(self.model, IMU_GYRO_SENSOR)
        # Views into MjData's fixed-size buffers, made once: every attribute access of MjData
        # builds a new array view, which the per-step path pays for many times over.
        data = self.data
        self._joint_pos, self._joint_vel = data.qpos[7:], data.qvel[6:]
        self._torque = data.actuator_force
        self._com_view = data.subtree_com[self._root_body]
        self._pyramidal = False  # friction cone, read at every reset
        self._stability = termination.Stability(data)
        self._body_roll = termination.BodyRoll(self.model, data, n + 1)
        self._roll = termination.RollSpan.begin(np.zeros(n + 1))  # set by each reset
        self._imu_view = np.concatenate(
            [
                np.arange(self._imu_quat.start, self._imu_quat.stop),
                np.arange(self._imu_gyro.start, self._imu_gyro.stop),
            ]
        )
        self._noise_std = np.zeros(3 * n)  # per observed joint quantity; set by each reset
        self._table = self._gait_table()
        self._offset_tables = self._gait_offset_tables(self.pole_radius)
        self._step_count = 0
        self._k0 = 0
        self._keyframe = 0.0  # gait phase in keyframes, advanced by the phase rate each step
        self._com_start = 0.0

    # -- copies -------------------------------------------------------------------------------

    def __getstate__(self) -> dict[str, Any]:
        """The constructor's arguments (EzPickle) plus the episode: the simulation data and the
        model as this episode's randomisation left it, and the env's counters and RNG.

        A copy taken mid-episode (pickle, ``copy.deepcopy``) continues exactly where the original
        was: the same actions give the same observations, rewards, infos and later resets.
        """
        episode = {
            k: v for k, v in self.__dict__.items() if k not in _NOT_COPIED and not _mujoco_owned(v)
        }
        return {**EzPickle.__getstate__(self), "episode": episode, "data": self.data}

    def __setstate__(self, state: dict[str, Any]) -> None:
        state = dict(state)
        episode, data = state.pop("episode", None), state.pop("data", None)
        EzPickle.__setstate__(self, state)  # a fresh env from the constructor's arguments
        if episode is None or data is None:
            return
        self.__dict__.update(episode)
        # Copied into the fresh env's own model and data, so that its views into them (and its
        # renderer's) stay valid. MjData pickles with its model.
        _copy_model(self.model, data.model)
        mujoco.mj_copyData(self.data, self.model, data)

    # -- construction -------------------------------------------------------------------------

    def _initialize_simulation(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        model = build_model(
            self.n_joints, self.pole_radius, self.friction, self.kp, timestep=self.timestep
        )
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, self.width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, self.height)
        return model, mujoco.MjData(model)

    def squeeze_at(self, pole_radius: float) -> float:
        """The squeeze (m) the gait's helix is commanded with on a pole of ``pole_radius``:
        ``squeeze``, less ``squeeze_slope`` times how much thinner the pole is than the default
        0.075 m. At 1 the helix keeps the radius it has on the default pole (Eq. 1's r), which
        the +-90 deg joints can still curl; a tighter one is clipped (see "Non-rolling task")."""
        return self.squeeze - self.squeeze_slope * max(0.0, DEFAULT_POLE_RADIUS - pole_radius)

    def _gait_kwargs(self, pole_radius: float) -> dict[str, Any]:
        kwargs = {"radius": helix_radius(pole_radius, self.squeeze_at(pole_radius))}
        kwargs.update(self.gait_kwargs)
        return {**kwargs, "n_joints": self.n_joints, "steps_per_cycle": self.steps_per_cycle}

    def _make_gait(self, pole_radius: float, base: str | None = None) -> Gait | None:
        base = base or self.base_gait
        if GAITS[base] is None:
            return None
        return _cached_gait(base, tuple(sorted(self._gait_kwargs(pole_radius).items())))

    def _gait_table(self) -> np.ndarray:
        if self.gait is None:
            return np.zeros((self.steps_per_cycle, self.n_joints))
        return self.gait.cycle()

    def _gait_offset_tables(self, pole_radius: float) -> np.ndarray | None:
        """The gait's keyframe tables with each modulated parameter offset, less the base table
        (envs/modulation.py), at the pole radius rounded to 1 mm; None without modulation."""
        if not self._modulated or self.gait is None:
            return None
        items = tuple(sorted(self._gait_kwargs(table_radius(pole_radius)).items()))
        return offset_tables(type(self.gait), items, tuple(self.gait_modulation.items()))

    # -- reset ----------------------------------------------------------------------------------

    def reset_model(self) -> np.ndarray:
        rng = self.np_random
        # Read per contact sample; set here so that a cone changed after construction counts.
        self._pyramidal = self.model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL
        physics = draw_physics(self.randomization, self._nominal_physics, rng)
        apply_physics(self.model, self.data, self._elements, physics)
        self._noise_std = sensor_noise_std(self.randomization, physics["kp"], self.n_joints)
        pole_radius = physics["pole_radius"]
        self.gait = self._make_gait(pole_radius)
        self._table = self._gait_table()
        self._offset_tables = self._gait_offset_tables(pole_radius)
        span = max(1, round(self.start_phase_range * self.steps_per_cycle))
        self._k0 = int(rng.integers(span))
        self._step_count = 0
        self._last_action = np.zeros(self.action_space.shape)
        # "none" starts from the ACL gait's pose: the ablation must still begin on the pole.
        start_gait = self.gait or self._make_gait(pole_radius, "acl")
        phase0 = self._k0 / self.steps_per_cycle
        kwargs = {k: v for k, v in self._gait_kwargs(pole_radius).items() if k != "radius"}
        angles, rotation, translation = clear_placement(
            lambda radius: type(start_gait)(**kwargs, radius=radius),
            phase0,
            contact_radius=pole_radius + SEA_MODULE_RADIUS,
            clearance=START_CLEARANCE,
            height=START_HEIGHT,
        )
        yaw = rng.uniform(-np.pi, np.pi)
        c, s = math.cos(yaw), math.sin(yaw)
        yaw_rot = np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])
        qpos = self.init_qpos.copy()
        qpos[:3] = yaw_rot @ translation
        mujoco.mju_mat2Quat(qpos[3:7], (yaw_rot @ rotation).ravel())
        angles = angles + self.reset_noise_scale * rng.standard_normal(self.n_joints)
        qpos[7:] = np.clip(angles, -JOINT_LIMIT, JOINT_LIMIT)
        self.set_state(qpos, np.zeros(self.model.nv))
        self._ramp_in(qpos[7:].copy(), start_gait.cycle()[self._k0])
        # The ramp ends holding keyframe k0: the first step plays the next one.
        self._keyframe = float((self._k0 + 1) % self.steps_per_cycle)
        self._com_start = self._com()[2]
        self._roll = termination.RollSpan.begin(self._body_roll.angles())
        return self._get_obs()

    def _ramp_in(self, start: np.ndarray, target: np.ndarray) -> None:
        """Ramp the servo targets from the placed pose to the first keyframe, then hold it.

        Gravity is off while the squeeze ramps in (the loose start pose cannot hold yet, and
        would drop ~10 cm before gripping); it is back on for the hold, so the episode starts
        from a snake that carries its own weight.
        """
        chunks, dt = 10, self.model.opt.timestep
        per_chunk = max(1, round(RAMP_TIME / dt / chunks))
        gravity = self.model.opt.gravity.copy()
        self.model.opt.gravity[:] = 0.0
        for i in range(1, chunks + 1):
            self.data.ctrl[:] = start + (target - start) * (i / chunks)
            mujoco.mj_step(self.model, self.data, nstep=per_chunk)
        self.model.opt.gravity[:] = gravity
        mujoco.mj_step(self.model, self.data, nstep=max(1, round(SETTLE_TIME / dt)))
        mujoco.mj_forward(self.model, self.data)

    # -- step -----------------------------------------------------------------------------------

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Play one keyframe (0.1 s) of the gait plus the residual.

        reward = w_climb * climb - w_slip * slip - w_roll * roll - w_energy * energy
        - w_action_rate * action_rate: the centre-of-mass rise, the mean sliding distance of the
        snake-pole contacts, the growth of the body's swept roll, the actuator work over the step
        and the action's squared change (``envs/rewards.py``; ``info``
        holds every weighted term).
        """
        action = np.asarray(action, dtype=np.float64)
        if action.shape != self.action_space.shape:
            raise ValueError(
                f"action must have shape {self.action_space.shape}, got {action.shape}"
            )
        if not np.isfinite(action).all():
            raise ValueError(f"action must be finite, got {action}")
        action = np.minimum(np.maximum(action, -1.0), 1.0)  # np.clip, without its dispatch
        # per joint, so that extra entries held at zero (modulation, cadence) leave it unchanged
        change, n = action - self._last_action, self.n_joints
        action_rate = float(change[:n] @ change[:n] + change[n:] @ change[n:]) / n
        self._last_action = action
        base = self._base_target()
        residual = self.residual_scale * action[: self.n_joints]
        if self._offset_tables is not None:
            residual = residual + self._modulation(action)
        target = np.minimum(np.maximum(base + residual, -JOINT_LIMIT), JOINT_LIMIT)
        rate = self._phase_rate(action)
        phase = self._keyframe / self.steps_per_cycle

        model, data = self.model, self.data
        com_before = float(self._com_view[2])
        self._stability.start()
        data.ctrl[:] = target
        substeps = self.frame_skip // SLIP_SAMPLES
        sample_dt = substeps * model.opt.timestep
        torque, joint_vel = self._torque, self._joint_vel
        slip = energy = 0.0
        touched = grounded = False
        for _ in range(SLIP_SAMPLES):
            mujoco.mj_step(model, data, nstep=substeps)
            speed, on_pole, on_floor = self._contacts()
            slip += speed * sample_dt
            touched |= on_pole
            grounded |= on_floor
            energy += float(np.abs(torque) @ np.abs(joint_vel)) * sample_dt
        self._step_count += 1
        self._keyframe = (self._keyframe + rate) % self.steps_per_cycle

        unstable = self._stability.unstable()
        com_height = float(self._com_view[2])
        climb = 0.0 if unstable else com_height - com_before
        slip = 0.0 if unstable else slip
        fell = not unstable and termination.fell(
            com_height, self._com_start, self.fall_distance, touched, grounded
        )
        roll = 0.0 if unstable else self._roll.update(self._body_roll.angles())
        roll_span = float(self._roll.span_deg.max())
        rolled = not unstable and termination.rolled(roll_span, self.roll_limit)
        measures = StepMeasures(climb, slip, roll, 0.0 if unstable else energy, action_rate)
        terms = reward_terms(self.reward_weights, measures)
        reward = sum(terms.values())
        terminated = fell or unstable or rolled
        truncated = self._step_count >= self.steps_per_cycle * self.cycles_per_episode
        info = {
            **terms,
            "climb": climb,
            "slip": slip,
            "energy": energy,
            "action_rate": action_rate,
            "com_height": com_height,
            "phase": phase,
            "phase_rate": rate,
            "fell": fell,
            "unstable": unstable,
            "roll": roll,
            "roll_span_deg": roll_span,
            "body_rolls": self._roll.body_rolls,
            "rolled": rolled,
        }
        obs = self._get_obs() if not unstable else np.zeros(self.observation_space.shape)
        if self.render_mode == "human":
            self.render()
        return obs, reward, terminated, truncated, info

    def _base_target(self) -> np.ndarray:
        """The base gait's joint targets at the current phase: a table row, or between two rows
        (linear) when the phase rate is modulated."""
        k = int(self._keyframe)
        frac = self._keyframe - k
        if frac == 0.0:
            return self._table[k]
        return (1.0 - frac) * self._table[k] + frac * self._table[(k + 1) % self.steps_per_cycle]

    def _modulation(self, action: np.ndarray) -> np.ndarray:
        """Change of the joint targets (rad) by the per-section parameter offsets: the gait's
        own tables with the offsets applied, less the base (envs/modulation.py)."""
        n, n_params = self.n_joints, len(self._modulated)
        a = action[n : self._rate_index].reshape(n_params, self.modulation_sections)
        offsets = a @ self._section_weights.T  # (P, n), in units of each parameter's scale
        k = int(self._keyframe)
        frac = self._keyframe - k
        change = interpolate_offsets(self._offset_tables, k, offsets)
        if frac != 0.0:
            nxt = interpolate_offsets(self._offset_tables, (k + 1) % self.steps_per_cycle, offsets)
            change = (1.0 - frac) * change + frac * nxt
        return change

    def _phase_rate(self, action: np.ndarray) -> float:
        """Keyframes the gait advances this step: 1, or set by the last action (PMTG option)."""
        if self.phase_rate_range is None:
            return 1.0
        lo, hi = self.phase_rate_range
        a = float(action[self._rate_index])
        return 1.0 + a * (hi - 1.0 if a >= 0.0 else 1.0 - lo)

    def _com(self) -> np.ndarray:
        """Centre of mass of the snake (the subtree of its root link)."""
        return self.data.subtree_com[self._root_body]

    def _contacts(self) -> tuple[float, bool, bool]:
        """Mean sliding speed (m/s) of the snake-pole contacts; is the pole touched; the floor?

        With an elliptic cone each contact's constraint rows are the normal then the two
        tangential directions; their ``efc_vel`` is the relative sliding velocity. With a
        pyramidal cone the rows are the pyramid's edges ``n +- mu_i t_i``, whose differences
        give the same tangential velocities. Hot path (every contact sample): a plain loop over
        the few contacts costs a third of the vectorised version.
        """
        data = self.data
        if data.ncon == 0:
            return 0.0, False, False
        contact = data.contact
        geoms = contact.geom.tolist()
        rows = contact.efc_address.tolist()
        vel = data.efc_vel.tolist()
        friction = contact.friction.tolist() if self._pyramidal else None
        ngeom, pair_kind = self._ngeom, self._pair_kind
        total, count, on_floor = 0.0, 0, False
        for i, ((g1, g2), row) in enumerate(zip(geoms, rows, strict=True)):
            if row < 0:  # excluded by a constraint: not active
                continue
            kind = pair_kind[g1 * ngeom + g2]  # what the contact is (see __init__)
            if kind == 1:
                if friction is None:
                    total += math.hypot(vel[row + 1], vel[row + 2])
                else:  # pyramidal: rows n + mu_j t_j, n - mu_j t_j for j = 1, 2
                    mu = friction[i]
                    total += math.hypot(
                        (vel[row] - vel[row + 1]) / (2.0 * mu[0]),
                        (vel[row + 2] - vel[row + 3]) / (2.0 * mu[1]),
                    )
                count += 1
            elif kind == 2:
                on_floor = True
        return (total / count if count else 0.0), count > 0, on_floor

    @property
    def action_names(self) -> tuple[str, ...]:
        """What each action entry drives, in order: ``joint_<j>`` (the residual of joint ``j``),
        ``<parameter>_section_<s>`` (gait modulation, section ``s`` from the head), ``cadence``."""
        names = [f"joint_{j}" for j in range(self.n_joints)]
        names += [
            f"{key}_section_{s}" for key in self._modulated for s in range(self.modulation_sections)
        ]
        if self.phase_rate_range is not None:
            names.append("cadence")
        return tuple(names)

    def _get_obs(self) -> np.ndarray:
        data = self.data
        angle = 2.0 * np.pi * self._keyframe / self.steps_per_cycle
        parts = [
            self._joint_pos,
            self._joint_vel,
            self._torque,
            data.sensordata[self._imu_view],
            [math.cos(angle), math.sin(angle)],
            self._base_target(),
        ]
        if self.privileged_obs:
            mujoco.mj_subtreeVel(self.model, data)
            parts += [self._com(), data.subtree_linvel[self._root_body]]
        obs = np.concatenate(parts)
        if "sensor_noise" in self.randomization:
            noise = self._noise_std * self.np_random.standard_normal(self._noise_std.size)
            obs[: self._noise_std.size] += noise
        return obs

    def _get_reset_info(self) -> dict[str, Any]:
        return {"com_height": float(self._com()[2]), "phase": self._keyframe / self.steps_per_cycle}


# Not in a copy's episode state: the simulation travels as MjData (with its model), the renderer
# is the fresh env's, the constructor's arguments are EzPickle's.
_NOT_COPIED = ("model", "data", "mujoco_renderer", "_ezpickle_args", "_ezpickle_kwargs")


def _mujoco_owned(value: object, depth: int = 2) -> bool:
    """Whether ``value`` is or holds (``depth`` levels down its attributes) MuJoCo memory: an
    MjModel, an MjData, a struct or an array view of them. A copy keeps the fresh env's own such
    objects, bound to its own model and data, instead of pickled duplicates."""
    if type(value).__module__.startswith("mujoco"):
        return True
    if isinstance(value, np.ndarray):
        while isinstance(value, np.ndarray):
            value = value.base
        return value is not None  # a view whose memory MuJoCo owns
    if depth == 0 or isinstance(value, str | bytes | int | float | np.random.Generator):
        return False
    children = getattr(value, "__dict__", {}).values()
    if isinstance(value, dict):
        children = value.values()
    elif isinstance(value, list | tuple):
        children = value
    return any(_mujoco_owned(child, depth - 1) for child in children)


def _copy_model(dest: mujoco.MjModel, src: mujoco.MjModel) -> None:
    """Every array and physics option of ``src`` into ``dest``, a model of the same structure
    (MuJoCo has ``mj_copyData`` but no in-place model copy)."""
    for name in dir(src):
        value = getattr(src, name)
        if isinstance(value, np.ndarray) and not name.startswith("_"):
            getattr(dest, name)[...] = value
    for name in dir(src.opt):
        if not name.startswith("_"):
            value = getattr(src.opt, name)
            if isinstance(value, np.ndarray):
                getattr(dest.opt, name)[...] = value
            else:
                setattr(dest.opt, name, value)


def _sensor_slice(model: mujoco.MjModel, name: str) -> slice:
    sensor = model.sensor(name)
    start = int(sensor.adr[0])
    return slice(start, start + int(sensor.dim[0]))


def _timestep(value: float) -> tuple[float, int]:
    """Validated physics step (s) and the MuJoCo steps per control step (``frame_skip``): the
    0.1 s control step must be a whole number of physics steps, and of contact samples."""
    timestep = check_positive("timestep", value)
    if not TIMESTEP_RANGE[0] <= timestep <= TIMESTEP_RANGE[1]:
        raise ValueError(
            f"timestep must be in [{TIMESTEP_RANGE[0]}, {TIMESTEP_RANGE[1]}] s, got {value}"
        )
    frame_skip = round(CONTROL_DT / timestep)
    if frame_skip < 1 or not math.isclose(frame_skip * timestep, CONTROL_DT, rel_tol=1e-9):
        raise ValueError(
            f"timestep must divide the {CONTROL_DT} s control step into whole steps, got {value}"
        )
    if frame_skip % SLIP_SAMPLES:
        raise ValueError(
            f"timestep must give a multiple of {SLIP_SAMPLES} physics steps per control step "
            f"(the contact samples), got {value} ({frame_skip} steps)"
        )
    return timestep, frame_skip


def _phase_rate_range(
    value: tuple[float, float] | None, steps_per_cycle: int
) -> tuple[float, float] | None:
    """Validated (low, high) keyframes per step; None keeps the gait's cadence fixed."""
    if value is None:
        return None
    lo, hi = check_sequence("phase_rate_range", value, 2, check_finite)
    if not 0.0 <= lo <= 1.0 <= hi <= steps_per_cycle / 2:
        raise ValueError(
            "phase_rate_range must satisfy 0 <= low <= 1 <= high <= steps_per_cycle / 2 "
            f"= {steps_per_cycle / 2}, got {value}"
        )
    return (lo, hi)


def _gait_kwargs(value: Mapping[str, Any] | None, base_gait: str) -> dict[str, Any]:
    """Validated keyword arguments of the base gait (of ACL, which places the start pose, for
    ``"none"``): known keys, real numbers, an integer ``n_samples`` within its memory bound."""
    if value is None:
        return {}
    gait_class = GAITS[base_gait] or ACLGait
    known = [k for k in inspect.signature(gait_class).parameters if k not in GAIT_KWARGS_REFUSED]
    for key in GAIT_KWARGS_REFUSED:
        if isinstance(value, Mapping) and key in value:
            owner = (
                "pass it to the env" if key in ("n_joints", "steps_per_cycle") else "the model's"
            )
            raise ValueError(f"gait_kwargs must not set {key!r} ({owner})")
    kwargs = check_mapping("gait_kwargs", value, known)
    return {
        key: check_int(f"gait_kwargs[{key!r}]", v, *GAIT_SAMPLES_RANGE)
        if key == "n_samples"
        else check_finite(f"gait_kwargs[{key!r}]", v)
        for key, v in kwargs.items()
    }


__all__ = ["DEFAULT_RANDOMIZATION", "DEFAULT_REWARD_WEIGHTS", "ACLClimbEnv"]
