"""The physics of one 0.1 s env step: MuJoCo steps between the contact samples and, with the
compliant grip (``envs/grip.py``), the firmware's 100 Hz torque loop between them."""

from __future__ import annotations

import mujoco
import numpy as np
from gymnasium.envs.mujoco import MujocoEnv

from acl_env.actuators.base import JointReadout
from acl_env.constants import JOINT_LIMIT
from acl_env.envs.contacts import SLIP_SAMPLES, ContactSampler
from acl_env.envs.grip import GRIP_TICKS, GripController


class StepPhysics:
    """Plays one control step's joint targets on ``env``'s model (its MjData, ``frame_skip``):
    returns the slip (m), whether the pole and the floor were touched, and the actuators' work
    (J), sampled ``SLIP_SAMPLES`` times a step."""

    def __init__(
        self,
        env: MujocoEnv,
        contacts: ContactSampler,
        readout: JointReadout,
    ) -> None:
        model, frame_skip = env.model, env.frame_skip
        self.model, self.data = model, env.data
        self.contacts, self.readout = contacts, readout
        self.substeps = frame_skip // SLIP_SAMPLES  # physics steps per contact sample
        self.sample_dt = self.substeps * model.opt.timestep
        # The firmware's ticks, for the grip (envs/config.py checks that they fit).
        self.tick_steps = max(1, frame_skip // GRIP_TICKS)
        self.tick_dt = self.tick_steps * model.opt.timestep
        self.ticks_per_sample = GRIP_TICKS // SLIP_SAMPLES

    def run(
        self, target: np.ndarray, k: int, stiffness: float, grip: GripController | None = None
    ) -> tuple[float, bool, bool, float]:
        """Command ``target`` (rad) for one control step at keyframe ``k``, adapted by ``grip``
        at every firmware tick; ``stiffness``: the springs' (N m/rad), by which the grip reads
        their torques. (The env owns ``grip``, whose state a copy of the env carries.)"""
        model, data, readout = self.model, self.data, self.readout
        readout.begin_step()
        slip = energy = 0.0
        touched = grounded = False
        if grip is None:
            data.ctrl[:] = target
        for _ in range(SLIP_SAMPLES):
            if grip is None:
                mujoco.mj_step(model, data, nstep=self.substeps)
            else:
                for _ in range(self.ticks_per_sample):
                    change = grip.update(readout.read_torque(stiffness), k, self.tick_dt)
                    command = np.maximum(target + change, -JOINT_LIMIT)
                    np.minimum(command, JOINT_LIMIT, out=data.ctrl)  # np.clip's result
                    mujoco.mj_step(model, data, nstep=self.tick_steps)
            speed, on_pole, on_floor = self.contacts.sample(data)
            slip += speed * self.sample_dt
            touched |= on_pole
            grounded |= on_floor
            energy += readout.work(self.sample_dt)
        return slip, touched, grounded, energy


__all__ = ["StepPhysics"]
