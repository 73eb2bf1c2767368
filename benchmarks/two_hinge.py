"""The candidate SEA models on climbing: the shipped single-hinge SEA against a two-hinge SEA.

``python benchmarks/two_hinge.py [--seeds 5] [--json PATH]``

The two-hinge candidate gives every motor its own degree of freedom: a second hinge on each
joint's axis, in the same link, carries the rotor inertia reflected through the gearbox
(``acl_env.actuators.ROTOR_INERTIA``) and is driven by a stiff PID actuator (``MOTOR_KP``,
critically
damped) with the same slew limit, ±7 N m and command latency; the original hinge becomes the
spring (joint stiffness ``spring_stiffness``, the SEA's damping). The link turns by the motor's
angle plus the spring's deflection.

Each episode starts from the shipped SEA env's state after its reset (the motor angles and
spring deflections copied into the two-hinge model), then both models play the same gait
keyframes with a zero residual for two cycles: climb and slip per cycle and the motors' work per
metre, per gait, mean over seeds, and the paired two-hinge - SEA difference.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID, ROLLING_HELIX_CLIMB_ID
from acl_env.actuators import sea
from acl_env.actuators.sea_rotor import MOTOR_KP, ROTOR_INERTIA
from acl_env.constants import PEAK_TORQUE, actuator_name, joint_name, link_name
from acl_env.envs.contacts import SLIP_SAMPLES, ContactSampler
from acl_env.evaluation.intervals import mean_ci95
from acl_env.io import console_script
from acl_env.model import build_spec, snake_geom_ids
from acl_env.scripts import make_parser, write_output

GAITS: dict[str, tuple[str, dict[str, Any]]] = {
    "ACL (paper)": (ACL_CLIMB_ID, {}),
    "tuned ACL on the SEA (acl_sea)": (ACL_CLIMB_ID, {"tuned_gait": "acl_sea"}),
    "rolling helix": (ROLLING_HELIX_CLIMB_ID, {}),
    "non-rolling (acl_noroll)": (ACL_CLIMB_NOROLL_ID, {}),
}


def two_hinge_model(env: Any) -> mujoco.MjModel:
    """The env's scene with a motor hinge beside every joint (see the module docstring)."""
    n = env.n_joints
    # plain position actuators (the default servo), turned into the motors below
    spec = build_spec(
        n,
        env.config.physics.pole_radius,
        env.config.physics.friction,
        timestep=env.config.physics.timestep,
    )
    latency = env.config.actuator.values["control_latency"]
    for j in range(n):
        spring = spec.joint(joint_name(j))
        spring.stiffness[0] = env.config.actuator.values["spring_stiffness"]
        spring.damping[0] = sea.SPRING_DAMPING
        motor = spec.body(link_name(j + 1)).add_joint(
            name=f"motor_{j}", type=mujoco.mjtJoint.mjJNT_HINGE, axis=spring.axis
        )
        motor.armature = ROTOR_INERTIA
        actuator = spec.actuator(actuator_name(j))
        actuator.target = f"motor_{j}"
        actuator.set_to_pid(
            kp=MOTOR_KP,
            dampratio=1.0,
            slewmax=env.config.actuator.values["motor_speed_limit"],
            ctrlspec=int(mujoco.mjtCtrlInput.mjINPUT_POS),
        )
        actuator.forcerange = [-PEAK_TORQUE, PEAK_TORQUE]
        actuator.nsample = sea.history_samples(latency, env.config.physics.timestep)
        actuator.delay = latency
    return spec.compile()


def copy_state(env: Any, model: mujoco.MjModel, data: mujoco.MjData) -> None:
    """The SEA env's state in the two-hinge model: motor at the SEA's motor angle, spring at the
    deflection (joint - motor), joint velocities on the springs, the same command history."""
    n, src = env.n_joints, env.data
    data.qpos[:7], data.qvel[:6] = src.qpos[:7], src.qvel[:6]
    for j in range(n):
        spring, motor = model.joint(joint_name(j)), model.joint(f"motor_{j}")
        data.qpos[motor.qposadr[0]] = src.act[j]
        data.qpos[spring.qposadr[0]] = src.qpos[7 + j] - src.act[j]
        data.qvel[spring.dofadr[0]] = src.qvel[6 + j]
    data.act[:], data.ctrl[:] = src.act, src.ctrl
    for j in range(n):
        samples = int(model.actuator_history[j, 0])
        values = np.full((samples, 1), float(src.ctrl[j]))
        mujoco.mj_initCtrlHistory(model, data, j, None, values)
    mujoco.mj_forward(model, data)


def play(env_id: str, kwargs: dict[str, Any], seed: int) -> dict[str, dict[str, float]]:
    """One episode of each model from the same start: climb, slip per cycle, work per metre."""
    env = gym.make(env_id, actuator_model="sea", **kwargs).unwrapped
    env.reset(seed=seed)
    model = two_hinge_model(env)
    data = mujoco.MjData(model)
    copy_state(env, model, data)
    snake = snake_geom_ids(model, env.n_joints)
    contacts = ContactSampler(model, snake, model.geom("pole").id)
    motors = np.array([model.joint(f"motor_{j}").qposadr[0] for j in range(env.n_joints)])
    root = model.body(link_name(0)).id
    steps, cycles = env.steps_per_cycle * env.cycles_per_episode, env.cycles_per_episode
    start = {"sea": float(env.data.subtree_com[env._root_body][2]), "two": 0.0}
    start["two"] = float(data.subtree_com[root][2])
    totals = {name: {"slip": 0.0, "work": 0.0} for name in ("sea", "two")}
    substeps = env.frame_skip // SLIP_SAMPLES
    dt = substeps * model.opt.timestep
    for _ in range(steps):
        _, _, terminated, _, info = env.step(np.zeros(env.action_space.shape))
        totals["sea"]["slip"] += info["slip"]
        totals["sea"]["work"] += info["energy"]
        data.ctrl[:] = env.data.ctrl  # the keyframe the SEA env just commanded
        for _ in range(SLIP_SAMPLES):
            before = data.qpos[motors].copy()
            mujoco.mj_step(model, data, nstep=substeps)
            speed, _, _ = contacts.sample(data)
            totals["two"]["slip"] += speed * dt
            moved = np.abs(data.qpos[motors] - before)
            totals["two"]["work"] += float(np.abs(data.actuator_force) @ moved)
        if terminated:
            break
    climbs = {
        "sea": float(env.data.subtree_com[env._root_body][2]) - start["sea"],
        "two": float(data.subtree_com[root][2]) - start["two"],
    }
    env.close()
    return {
        name: {
            "climb_per_cycle_m": climbs[name] / cycles,
            "slip_per_cycle_m": totals[name]["slip"] / cycles,
            "energy_per_m": totals[name]["work"] / climbs[name] if climbs[name] > 0 else np.nan,
        }
        for name in ("sea", "two")
    }


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("--seeds", type=int, default=5, help="episodes per gait")
    args = parser.parse_args(argv)
    table: dict[str, Any] = {}
    print("| gait | climb per cycle (cm): SEA / two-hinge | slip per cycle (cm) | J/m |")
    print("|---|---|---|---|")
    for name, (env_id, kwargs) in GAITS.items():
        runs = [play(env_id, kwargs, seed) for seed in tqdm(range(args.seeds), desc=name)]
        row: dict[str, Any] = {}
        for metric in ("climb_per_cycle_m", "slip_per_cycle_m", "energy_per_m"):
            sea_values = [r["sea"][metric] for r in runs]
            two_values = [r["two"][metric] for r in runs]
            pairs = zip(sea_values, two_values, strict=True)
            row[metric] = {
                "sea": float(np.mean(sea_values)),
                "two_hinge": float(np.mean(two_values)),
                "two_minus_sea": mean_ci95(b - a for a, b in pairs),
            }
        table[name] = row
        cells = []
        for metric, k in (
            ("climb_per_cycle_m", 100),
            ("slip_per_cycle_m", 100),
            ("energy_per_m", 1),
        ):
            r = row[metric]
            d = r["two_minus_sea"]
            cells.append(
                f"{k * r['sea']:.3g} / {k * r['two_hinge']:.3g} "
                f"({k * d['mean']:+.2g} ± {k * d['half_width']:.2g})"
            )
        print(f"| {name} | " + " | ".join(cells) + " |")
    write_output(args.json, table)
    return table


if __name__ == "__main__":
    console_script(main)()
