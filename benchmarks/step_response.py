"""One joint's step response under the candidate actuator models: command, motor, joint, torque.

``python benchmarks/step_response.py [--step 0.5] [--duration 0.6] [--json PATH] [--plot PATH]``

One SEA module joint, its axis vertical (no gravity torque), drives a load: the three modules
beyond it as a rigid rod (0.615 kg over 0.19 m). At t = 0.05 s the command steps by ``--step``
rad. The candidates:

* ``servo``: the v1 tasks' ideal position servo (kp 20 N m/rad, kv 0.3, +-7 N m);
* ``sea``: the shipped series elastic actuator (``acl_env.actuators``: MuJoCo's PID actuator with
  a slew limit as the motor, its gain as the spring, the command ``CONTROL_LATENCY`` late);
* ``sea_two_hinge``: the same spring with the motor as its own degree of freedom: a second hinge
  on the joint's axis whose armature is the rotor inertia reflected through the gearbox
  (:data:`ROTOR_INERTIA`), driven by a stiff PID actuator with the same slew limit and +-7 N m,
  the spring a joint stiffness between motor and link.

The shipped ``sea`` keeps the motor kinematic (its angle is the slew-limited command): this
benchmark measures what that leaves out, the RMS difference of the joint angle and the spring
torque from the two-hinge model's.
"""

from __future__ import annotations

from typing import Any

import mujoco
import numpy as np

from acl_env.actuators import sea as actuators
from acl_env.actuators.sea_rotor import MOTOR_KP, ROTOR_INERTIA
from acl_env.constants import JOINT_LIMIT, PEAK_TORQUE, PHYSICS_TIMESTEP
from acl_env.io import console_script
from acl_env.scripts import make_parser, print_figures, save_figure, use_agg, write_outputs

LOAD_MASS = 3 * 0.205  # kg: three modules
LOAD_LENGTH = 3 * 0.0639  # m
STEP_TIME = 0.05  # s
CANDIDATES = ("servo", "sea", "sea_two_hinge")


def build(candidate: str) -> mujoco.MjModel:
    """The one-joint model of ``candidate``: hinge ``joint`` (plus ``motor`` for the two-hinge)."""
    spec = mujoco.MjSpec()
    spec.compiler.degree = False
    spec.option.timestep = PHYSICS_TIMESTEP
    spec.option.gravity = [0.0, 0.0, 0.0]
    body = spec.worldbody.add_body(name="load")
    if candidate == "sea_two_hinge":
        motor = body.add_joint(name="motor", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
        motor.armature = ROTOR_INERTIA
    joint = body.add_joint(name="joint", type=mujoco.mjtJoint.mjJNT_HINGE, axis=[0, 0, 1])
    joint.armature = 0.01
    joint.range = [-JOINT_LIMIT, JOINT_LIMIT]
    body.add_geom(
        name="rod",
        type=mujoco.mjtGeom.mjGEOM_CAPSULE,
        fromto=[0.0, 0.0, 0.0, LOAD_LENGTH, 0.0, 0.0],
        size=[0.0254, 0, 0],
        mass=LOAD_MASS,
    )
    actuator = spec.add_actuator(name="actuator", trntype=mujoco.mjtTrn.mjTRN_JOINT)
    actuator.forcerange = [-PEAK_TORQUE, PEAK_TORQUE]
    pos_only = int(mujoco.mjtCtrlInput.mjINPUT_POS)
    if candidate == "servo":
        actuator.target = "joint"
        actuator.set_to_position(kp=20.0, kv=0.3)
        joint.damping[0] = 0.05
    elif candidate == "sea":
        actuator.target = "joint"
        actuator.set_to_pid(
            kp=actuators.SPRING_STIFFNESS,
            kv=0.0,
            slewmax=actuators.MOTOR_SPEED_LIMIT,
            ctrlspec=pos_only,
        )
        joint.damping[0] = actuators.SPRING_DAMPING
    else:
        actuator.target = "motor"
        actuator.set_to_pid(
            kp=MOTOR_KP, dampratio=1.0, slewmax=actuators.MOTOR_SPEED_LIMIT, ctrlspec=pos_only
        )
        joint.stiffness[0] = actuators.SPRING_STIFFNESS
        joint.damping[0] = actuators.SPRING_DAMPING
    if candidate != "servo":
        actuator.nsample = actuators.history_samples(actuators.CONTROL_LATENCY, PHYSICS_TIMESTEP)
        actuator.delay = actuators.CONTROL_LATENCY
    return spec.compile()


def respond(candidate: str, step: float, duration: float) -> dict[str, list[float]]:
    """Time series of the step response: command, motor angle, joint angle, spring torque."""
    model = build(candidate)
    data = mujoco.MjData(model)
    out: dict[str, list[float]] = {k: [] for k in ("t", "command", "motor", "joint", "torque")}
    joint = model.joint("joint")
    for _ in range(round(duration / model.opt.timestep)):
        data.ctrl[0] = step if data.time >= STEP_TIME else 0.0
        mujoco.mj_step(model, data)
        angle = float(data.qpos[joint.qposadr[0]])
        if candidate == "sea_two_hinge":
            motor = float(data.qpos[model.joint("motor").qposadr[0]])
            angle += motor  # the link turns by the motor's angle plus the spring's deflection
            torque = actuators.SPRING_STIFFNESS * (motor - angle)
        elif candidate == "sea":
            motor = float(data.act[0])
            torque = float(data.actuator_force[0])
        else:
            motor = float(data.ctrl[0])  # an ideal servo: its "motor" is the command
            torque = float(data.actuator_force[0])
        for key, value in zip(
            out, (data.time, float(data.ctrl[0]), motor, angle, torque), strict=True
        ):
            out[key].append(value)
    return out


def compare(runs: dict[str, dict[str, list[float]]]) -> dict[str, float]:
    """RMS differences of the shipped SEA and of the servo from the two-hinge model."""
    ref = runs["sea_two_hinge"]
    out = {}
    for name in ("sea", "servo"):
        for key in ("joint", "torque"):
            diff = np.array(runs[name][key]) - np.array(ref[key])
            out[f"{name}_{key}_rms_vs_two_hinge"] = float(np.sqrt(np.mean(diff**2)))
    return out


def plot(document: dict[str, Any], path: Any) -> None:
    plt = use_agg()
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.6), sharex=True)
    styles = {"servo": ":", "sea": "-", "sea_two_hinge": "--"}
    for name, run in document["runs"].items():
        t = np.array(run["t"])
        axes[0].plot(t, run["motor"], styles[name], label=f"{name} motor")
        axes[1].plot(t, run["joint"], styles[name], label=name)
        axes[2].plot(t, run["torque"], styles[name], label=name)
    axes[0].plot(
        np.array(document["runs"]["sea"]["t"]),
        document["runs"]["sea"]["command"],
        "k",
        lw=0.8,
        label="command",
    )
    for ax, title in zip(
        axes, ("command and motor (rad)", "joint (rad)", "spring torque (N m)"), strict=True
    ):
        ax.set_title(title)
        ax.set_xlabel("time (s)")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=10)  # the docs show the figure about 690 px wide
    axes[2].legend(fontsize=10)
    fig.suptitle(f"One joint's step response ({document['step']} rad step, 3-module load)")
    save_figure(fig, path, dpi=110, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, json=True, plot=True)
    parser.add_argument("--step", type=float, default=0.5, help="command step (rad)")
    parser.add_argument("--duration", type=float, default=0.6, help="simulated time (s)")
    args = parser.parse_args(argv)
    runs = {name: respond(name, args.step, args.duration) for name in CANDIDATES}
    document = {"step": args.step, "rotor_inertia": ROTOR_INERTIA, **compare(runs), "runs": runs}
    write_outputs(args, document, plot)  # the files first: a closed pipe loses nothing
    print_figures(document, ".4f", 36)
    return document


if __name__ == "__main__":
    console_script(main)()
