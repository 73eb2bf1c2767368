"""The SEA snake climbing a pole, with an analytic gait as the residual baseline."""

from __future__ import annotations

import math
from typing import Any, ClassVar

import mujoco
import numpy as np
from gymnasium import spaces
from gymnasium.envs.mujoco import MujocoEnv
from gymnasium.utils import EzPickle

from acl_env.constants import IMU_GYRO_SENSOR, IMU_QUAT_SENSOR, JOINT_LIMIT, SCENE_FILE
from acl_env.envs import modulation, termination
from acl_env.envs import observations as layouts
from acl_env.envs.arguments import ARGUMENTS, signature
from acl_env.envs.config import EnvConfig, check_camera
from acl_env.envs.contacts import ContactSampler
from acl_env.envs.events import FrictionStep
from acl_env.envs.gait_config import GAITS, cached_gait
from acl_env.envs.grip import GRIP_RANGE, GripController
from acl_env.envs.lifecycle import LifecycleMixin
from acl_env.envs.modulation import offset_tables, table_radius
from acl_env.envs.pickling import MujocoPickleMixin
from acl_env.envs.randomize import (
    RandomizedElements,
    apply_physics,
    draw_order,
    draw_physics,
    sensor_noise_std,
)
from acl_env.envs.rewards import StepMeasures, reward_terms
from acl_env.envs.start import RAMP_TIME, placed_qpos, ramp_in
from acl_env.envs.stepping import StepPhysics
from acl_env.gait import Gait
from acl_env.model import assets_dir, build_model, sensor_indices


class ACLClimbEnv(LifecycleMixin, MujocoPickleMixin, MujocoEnv, EzPickle):
    """A 20-joint SEA snake climbs a vertical pole; the policy adds residuals to a gait.

    ## Description
    The CMU SEA snake (module 0.0639 m long, 0.0508 m wide, 0.205 kg, +-90 deg joints, 7 N m)
    wraps a fixed pole of radius ``pole_radius``. Each 0.1 s step plays one keyframe of the base
    gait (Chen & Roth's ACL, Eq. 1-5, or the rolling helix) through the joint actuators
    (``actuator_model``: "sea", series elastic actuators, "servo", ideal position servos, or
    another model of :mod:`acl_env.actuators`); a zero action plays the paper's open loop (220
    keyframes, 22 s).

    ## Action Space
    ``Box(-1, 1, (n,), float32)``, clipped to [-1, 1] (NaN, inf or a wrong shape: ``ValueError``;
    a non-real dtype: ``TypeError``); its entries, in order, are declared in
    :func:`acl_env.envs.observations.action_layout` (``action_names``). Joint ``j``'s target
    (rad) is ``clip(gait(phase)[j] + residual_scale * action[j], -pi/2, pi/2)`` (gait term 0 for
    ``base_gait="none"``). ``gait_modulation`` entries offset a gait parameter by up to its scale
    (m) in one body section, through the gait's Eq. 1-5 tables; the grip entries move a
    section's grip target (``envs/grip.py``); the cadence entry ``a`` (``phase_rate_range=(low,
    high)``, PMTG) advances the gait ``1 + a (high - 1)`` keyframes for ``a >= 0``, ``1 + a (1 -
    low)`` below, with targets interpolated between keyframes.

    ## Observation Space
    What the robot senses (float64): joint angles, velocities and torques, the head IMU, the
    gait's phase and its next targets, then the compliant grip's state (``grip_target``), past
    readings (``obs_history``) and what only a simulator knows (``privileged_obs``). Declared
    once, with sizes and units, in :func:`acl_env.envs.observations.observation_layout`;
    ``docs/environments.md`` shows it.

    ## Rewards
    The sum of ``reward_<term> = +-w_<term> * <term>``, weights ``reward_weights``: ``climb`` (+),
    the rise of the snake's centre of mass (m); ``slip`` (-), the mean sliding distance of the
    snake-pole contacts (m; MuJoCo's tangential ``efc_vel``, sampled 5 times per step); ``roll``
    (-), the growth of the range each module's roll about its axis relative to the pole surface
    (link frames) has swept since the reset, mean over modules (rad); ``energy`` (-), the work
    sum abs(tau omega) dt (J; motors do not regenerate; omega: the SEA motor's speed, the servo's
    joint's); ``action_rate`` (-), the action's squared change since the last step, over n.

    ## Starting State
    Keyframe ``k0``, drawn from the first ``start_phase_range`` of a cycle, posed with its helix
    loosened until every shell clears the pole by 5 mm (Kabsch fit), turned by a random yaw, 0.3 m
    above the floor, with ``reset_noise_scale`` rad of joint noise; the servos then ramp to the
    keyframe in 0.3 s, gravity off, and hold it 0.2 s, on (``envs/start.py``). Seed-deterministic.

    ## Episode End
    Truncation after ``cycles_per_episode`` gait cycles. Termination when the snake *fell* (its
    centre of mass ``fall_distance`` below its start, a shell on the floor, or no shell touching
    the pole during a step), the physics became *unstable* (a MuJoCo warning or a non-finite
    state; that step's reward terms are 0), or, with ``roll_limit``, the body *rolled* (some
    module's roll swept more than ``roll_limit`` deg).

    ## Info
    Plain ``float``/``bool`` values: every ``reward_<term>``, the raw ``climb``, ``slip``,
    ``roll``, ``energy`` and ``action_rate``, ``com_height`` (m), ``phase`` (cycles),
    ``phase_rate`` (keyframes advanced: 1 without ``phase_rate_range``), ``fell``, ``unstable``,
    ``rolled``, ``roll_span_deg`` (largest range any module's roll swept), ``body_rolls`` (net
    turns about the body's axis, mean over modules). Reset: ``com_height``, ``phase``. A copy
    (``pickle``, ``copy.deepcopy``) continues exactly where the original was (``envs/pickling.py``).
    ``step``/``render`` before ``reset`` and any call after ``close`` raise (``lifecycle.py``).

    ## Non-rolling task
    ``acl_env/ACLClimbNoRollBase-v3`` and the ids built on it climb without rolling (ACL with
    ``rolls_per_cycle=0``, a roll term and ``roll_limit``): ``docs/environments.md`` says why.

    ## Arguments
    Keyword arguments only, declared once with their defaults, accepted values and meaning in
    ``envs/arguments.py`` (``docs/environments.md`` shows the table; the actuator models'
    options, ``kp``, ``spring_stiffness``, ..., come from :mod:`acl_env.actuators`).
    ``env.config`` holds them checked, one typed config per concern (``envs/config.py``). A
    value of the wrong kind raises ``TypeError``, one out of range ``ValueError``, both naming
    the argument; ``envs/config.py`` and ``envs/gait_config.py`` say why each bound.
    ``domain_randomization=True`` draws ``envs.randomize.default_randomization(actuator_model)``
    at every reset.

    ## Version History
    The ids' versions and renames: ``docs/environments.md#version-history``. Options added
    later, off by default, leave the dynamics and reward unchanged (``friction_step`` too).
    """

    metadata: ClassVar[dict[str, Any]] = {
        "render_modes": ["human", "rgb_array", "depth_array", "rgbd_tuple"],
        "render_fps": 10,
    }

    def __init__(self, **kwargs: Any) -> None:
        EzPickle.__init__(self, **kwargs)
        # Every keyword argument (envs/config.py: ARGUMENTS, the signature) is checked once, into
        # one typed config per concern.
        config = self.config = EnvConfig.from_kwargs(kwargs, self.metadata["render_modes"])
        self.n_joints, self.steps_per_cycle = config.physics.n_joints, config.gait.steps_per_cycle
        self.cycles_per_episode = config.episode.cycles_per_episode
        gait, grip_config, render = config.gait, config.grip, config.render
        self.gait = self._make_gait(config.physics.pole_radius)
        n = self.n_joints
        # The spaces, from the layouts declared in envs/observations.py.
        obs_size = layouts.size(layouts.env_observation_layout(self))
        observation_space = spaces.Box(-np.inf, np.inf, shape=(obs_size,), dtype=np.float64)
        MujocoEnv.__init__(
            self,
            str(assets_dir() / SCENE_FILE),
            config.physics.frame_skip,
            observation_space=observation_space,
            render_mode=render.render_mode,
            width=render.width,
            height=render.height,
            camera_name=render.camera_name,
        )
        check_camera(self.model, render.camera_name)
        n_actions = layouts.size(layouts.env_action_layout(self))
        # the cadence action, the last, when there is one
        self._rate_index = n_actions - (gait.phase_rate_range is not None)
        self.action_space = spaces.Box(-1.0, 1.0, shape=(n_actions,), dtype=np.float32)
        elements = self._elements = RandomizedElements.of(self.model, n)
        actuators, physics = config.actuator.model, config.physics
        scene = {"pole_radius": physics.pole_radius, "friction": physics.friction}
        scene["mass_scale"] = 1.0
        nominal = {**scene, **config.actuator.values}
        self._nominal_physics = {key: nominal[key] for key in draw_order(actuators)}
        self._readout = actuators.readout(self.model, self.data, n)
        self._stiffness = config.actuator.values[actuators.stiffness]  # of this episode
        self._contacts = ContactSampler(self.model, elements.snake_geoms, elements.pole_geom)
        self._grip = None  # the 100 Hz loop, envs/grip.py
        if grip_config is not None:
            grip = (grip_config.target, grip_config.gain, grip_config.leak)
            self._grip = GripController(gait.section_weights, *grip)
        self._physics = StepPhysics(self, self._contacts, self._readout)
        # the pole turning slippery (envs/events.py): at a set friction, or a drawn one
        drop, drawn = config.physics.friction_step, config.randomization.get("friction_step")
        self._friction_step = None
        if drop is not None or drawn is not None:
            self._friction_step = FrictionStep(drop or 0.0, elements, drawn)
        self._bind_views(elements.snake_bodies[0])
        self._table = self._gait_table()
        self._offset_tables = self._gait_offset_tables(physics.pole_radius)
        self._step_count, self._k0, self._com_start = 0, 0, 0.0
        self._keyframe = 0.0  # gait phase in keyframes, advanced by the phase rate each step

    def _bind_views(self, root_body: int) -> None:
        """Views into MjData made once: each attribute access of MjData builds a new array view."""
        n, data = self.n_joints, self.data
        self._root_body = root_body
        self._com_view = data.subtree_com[root_body]
        self._stability = termination.Stability(data)
        self._body_roll = termination.BodyRoll(self.model, data, n + 1)
        self._roll = termination.RollSpan.begin(np.zeros(n + 1))  # set by each reset
        self._imu_view = sensor_indices(self.model, IMU_QUAT_SENSOR, IMU_GYRO_SENSOR)
        self._noise_std = np.zeros(3 * n)  # per observed joint quantity; set by each reset
        self._history = layouts.ReadingHistory(self.config.episode.obs_history, n)

    def _initialize_simulation(self) -> tuple[mujoco.MjModel, mujoco.MjData]:
        physics = self.config.physics
        args = (physics.n_joints, physics.pole_radius, physics.friction)
        model = build_model(*args, timestep=physics.timestep, actuators=self.config.actuator)
        model.vis.global_.offwidth = max(model.vis.global_.offwidth, self.width)
        model.vis.global_.offheight = max(model.vis.global_.offheight, self.height)
        return model, mujoco.MjData(model)

    def squeeze_at(self, pole_radius: float) -> float:
        """The squeeze (m) the gait's helix is commanded with on a pole of ``pole_radius``: less
        ``squeeze_slope`` per m the pole is thinner than 0.075 m (``arguments.squeeze_at``)."""
        return self.config.gait.squeeze_at(pole_radius)

    def _gait_kwargs(self, pole_radius: float) -> dict[str, Any]:
        return self.config.gait.kwargs_at(pole_radius, self.n_joints)

    def _make_gait(self, pole_radius: float, base: str | None = None) -> Gait | None:
        base = base or self.config.gait.base_gait
        if GAITS[base] is None:
            return None
        return cached_gait(base, tuple(sorted(self._gait_kwargs(pole_radius).items())))

    def _gait_table(self) -> np.ndarray:
        if self.gait is None:
            return np.zeros((self.steps_per_cycle, self.n_joints))
        return self.gait.cycle()

    def _gait_offset_tables(self, pole_radius: float) -> np.ndarray | None:
        """The gait's keyframe tables with each modulated parameter offset, less the base table
        (envs/modulation.py), at the pole radius rounded to 1 mm; None without modulation."""
        if not self.config.gait.modulated or self.gait is None:
            return None
        items = tuple(sorted(self._gait_kwargs(table_radius(pole_radius)).items()))
        modulated = tuple(self.config.gait.gait_modulation.items())
        return offset_tables(type(self.gait), items, modulated)

    def reset_model(self) -> np.ndarray:
        rng = self.np_random
        self._contacts.pyramidal = self.model.opt.cone == mujoco.mjtCone.mjCONE_PYRAMIDAL
        config = self.config
        physics = draw_physics(config.randomization, self._nominal_physics, rng)
        actuators = config.actuator.model
        apply_physics(self.model, self.data, self._elements, physics, actuators)
        self._stiffness = physics[actuators.stiffness]
        self._noise_std = sensor_noise_std(config.randomization, self._stiffness, self.n_joints)
        pole_radius = physics["pole_radius"]
        self.gait = self._make_gait(pole_radius)
        self._table = self._gait_table()
        self._offset_tables = self._gait_offset_tables(pole_radius)
        if self._grip is not None:  # tables per 1 mm of pole, as the modulation's
            self._grip.reset(self.gait, self._gait_kwargs(table_radius(pole_radius)))
        span = max(1, round(config.episode.start_phase_range * self.steps_per_cycle))
        self._k0 = int(rng.integers(span))
        self._step_count = 0
        self._last_action = np.zeros(self.action_space.shape)
        # "none" starts from the ACL gait's pose: the ablation must still begin on the pole.
        start_gait = self.gait or self._make_gait(pole_radius, "acl")
        yaw = rng.uniform(-np.pi, np.pi)
        noise = config.episode.reset_noise_scale * rng.standard_normal(self.n_joints)
        phase0, kwargs = self._k0 / self.steps_per_cycle, self._gait_kwargs(pole_radius)
        qpos = placed_qpos(
            type(start_gait), kwargs, phase0, pole_radius, yaw, noise, self.init_qpos
        )
        self.set_state(qpos, np.zeros(self.model.nv))
        start, target = qpos[7 : 7 + self.n_joints].copy(), start_gait.cycle()[self._k0]
        # the actuators at rest there, given the time their speed asks
        duration = actuators.start(self.model, self.data, start, target, RAMP_TIME)
        ramp_in(self.model, self.data, start, target, duration)
        # The ramp ends holding keyframe k0: the first step plays the next one.
        self._keyframe = float((self._k0 + 1) % self.steps_per_cycle)
        self._com_start = self._com_view[2]
        self._roll = termination.RollSpan.begin(self._body_roll.angles())
        if self._friction_step is not None:  # drawn last: the other draws as without it
            self._friction_step.reset(rng, self.steps_per_cycle * self.cycles_per_episode)
        return self._get_obs()

    def step(self, action: np.ndarray) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Play one keyframe (0.1 s) of the gait plus the residual; the reward terms are the
        class docstring's (``envs/rewards.py``), each in ``info``."""
        action = self._checked_action(action)  # after reset, before close; shape, dtype, finite
        action = np.minimum(np.maximum(action, -1.0), 1.0)  # np.clip, without its dispatch
        # per joint, so that extra entries held at zero (modulation, cadence) leave it unchanged
        change, n = action - self._last_action, self.n_joints
        action_rate = float(change[:n] @ change[:n] + change[n:] @ change[n:]) / n
        self._last_action = action
        config, target = self.config, self._command(action)
        rate = self._phase_rate(action)
        phase = self._keyframe / self.steps_per_cycle
        com_before = float(self._com_view[2])
        self._stability.start()
        drop = self._friction_step
        slippery = drop is not None and drop.before_step(self.model, self._step_count)
        run = self._physics.run(target, int(self._keyframe), self._stiffness, self._grip)
        slip, touched, grounded, energy = run
        self._step_count += 1
        self._keyframe = (self._keyframe + rate) % self.steps_per_cycle

        unstable = self._stability.unstable()
        com_height = float(self._com_view[2])
        climb = 0.0 if unstable else com_height - com_before
        slip = 0.0 if unstable else slip
        fell = not unstable and termination.fell(
            com_height, self._com_start, config.episode.fall_distance, touched, grounded
        )
        roll = 0.0 if unstable else self._roll.update(self._body_roll.angles())
        roll_span = float(self._roll.span_deg.max())
        rolled = not unstable and termination.rolled(roll_span, config.episode.roll_limit)
        measures = StepMeasures(climb, slip, roll, 0.0 if unstable else energy, action_rate)
        terms = reward_terms(config.reward_weights, measures)
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
        if drop is not None:
            info["slippery"] = slippery
        obs = self._get_obs() if not unstable else np.zeros(self.observation_space.shape)
        if self.render_mode == "human":
            self.render()
        return obs, reward, terminated, truncated, info

    def _command(self, action: np.ndarray) -> np.ndarray:
        """The joint targets (rad) for the clipped ``action``: the gait's keyframe plus the
        residual and the modulation, within the joints' range. Sets the sections' grip targets
        where the policy moves them."""
        config = self.config
        residual = config.gait.residual_scale * action[: self.n_joints]
        if self._offset_tables is not None:
            residual = residual + self._modulation(action)
        grip = config.grip
        if grip is not None and grip.action_scale:  # the sections' grip targets
            a = action[self._rate_index - config.gait.modulation_sections : self._rate_index]
            self._grip.target = grip.target + grip.action_scale * a
        return np.minimum(np.maximum(self._base_target() + residual, -JOINT_LIMIT), JOINT_LIMIT)

    def _base_target(self) -> np.ndarray:
        """The base gait's joint targets at the current phase: a table row, or between two rows
        (linear) when the phase rate is modulated."""
        k = int(self._keyframe)
        frac = self._keyframe - k
        if frac == 0.0:
            return self._table[k]
        return (1.0 - frac) * self._table[k] + frac * self._table[(k + 1) % self.steps_per_cycle]

    def _modulation(self, action: np.ndarray) -> np.ndarray:
        """Change of the joint targets (rad) by the per-section parameter offsets."""
        n, gait = self.n_joints, self.config.gait
        sections = gait.modulation_sections
        a = action[n : n + len(gait.modulated) * sections].reshape(-1, sections)
        offsets = a @ gait.section_weights.T  # (P, n), in units of each parameter's scale
        return modulation.keyframe_change(self._offset_tables, self._keyframe, offsets)

    def _phase_rate(self, action: np.ndarray) -> float:
        """Keyframes the gait advances this step: 1, or set by the last action (PMTG option)."""
        rate_range = self.config.gait.phase_rate_range
        if rate_range is None:
            return 1.0
        lo, hi = rate_range
        a = float(action[self._rate_index])
        return 1.0 + a * (hi - 1.0 if a >= 0.0 else 1.0 - lo)

    @property
    def action_names(self) -> tuple[str, ...]:
        """What each action entry drives, in order (``envs/observations.py``)."""
        return layouts.names(layouts.env_action_layout(self))

    def _get_obs(self) -> np.ndarray:
        data = self.data
        angle = 2.0 * np.pi * self._keyframe / self.steps_per_cycle
        joints = self._readout.observe(self._stiffness)  # a new array: the noise goes on it
        if "sensor_noise" in self.config.randomization:
            joints += self._noise_std * self.np_random.standard_normal(self._noise_std.size)
        parts = [joints, data.sensordata[self._imu_view]]  # the readings obs_history keeps
        sensed = np.concatenate(parts) if self._history.frames else None
        parts += [[math.cos(angle), math.sin(angle)], self._base_target()]
        if self._grip is not None:  # the controller's state: section offsets (of the range), N
            parts += [self._grip.offset * (1.0 / GRIP_RANGE), self._grip.force]
        if sensed is not None:
            parts.append(self._history.read_then_keep(sensed, self._step_count == 0))
        if self.config.episode.privileged_obs:
            mujoco.mj_subtreeVel(self.model, data)
            pole = self._elements.pole_geom
            physics = layouts.privileged_physics(self.model, pole, self._stiffness)
            parts += [self._com_view, data.subtree_linvel[self._root_body], physics]
        return np.concatenate(parts)

    def _get_reset_info(self) -> dict[str, Any]:
        com, phase = float(self._com_view[2]), self._keyframe / self.steps_per_cycle
        return {"com_height": com, "phase": phase}


# The keyword arguments, declared once in envs/config.py (ARGUMENTS), as the signature.
ACLClimbEnv.__init__.__signature__ = signature()  # type: ignore[attr-defined]
ACLClimbEnv.__init__.__annotations__ = {a.name: a.annotation for a in ARGUMENTS}

__all__ = ["ACLClimbEnv"]
