"""Where one MuJoCo step of a climbing env spends its time, by MuJoCo's own stage timers.

``python benchmarks/physics_stages.py [--env ID] [--steps 600] [--json PATH]``

Plays ``--steps`` env steps of the open-loop gait (a zero action) from ``reset(seed=0)``, then
reads ``MjData.timer``: for each stage of ``mj_step`` (position: kinematics, inertia, collision,
constraint making; velocity; actuation; constraint: the solver and its Jacobians; the
integrator's advance), its mean time per physics step and its share of the step. MuJoCo times
its stages itself, in every build; the env's Python is not in these figures (``bench_env.py``
sets the env step against its raw physics). Times are wall clock, so a loaded machine inflates
them all; the shares are what to read.
"""

from __future__ import annotations

from typing import Any

import gymnasium as gym
import mujoco
import numpy as np

from acl_env import ACL_CLIMB_SEA_ID
from acl_env.io import guarded_output
from acl_env.scripts import make_parser, write_output

# The stages reported, as MuJoCo names them (mjtTimer), and what a reader calls them.
STAGES = {
    "mjTIMER_STEP": "whole step",
    "mjTIMER_POSITION": "position (kinematics, inertia, collision, constraint rows)",
    "mjTIMER_POS_KINEMATICS": "  kinematics",
    "mjTIMER_POS_INERTIA": "  inertia",
    "mjTIMER_POS_COLLISION": "  collision (broad and narrow phase)",
    "mjTIMER_POS_MAKE": "  constraint rows",
    "mjTIMER_VELOCITY": "velocity",
    "mjTIMER_ACTUATION": "actuation",
    "mjTIMER_CONSTRAINT": "constraint solver",
    "mjTIMER_ADVANCE": "integrator (implicitfast)",
}


def stage_times(env_id: str, steps: int) -> dict[str, Any]:
    """Each stage's mean microseconds per physics step and share of the step, over ``steps``
    env steps of the open loop, with the contacts and constraint rows at the end."""
    env = gym.make(env_id)
    env.reset(seed=0)
    data = env.unwrapped.data
    for index in range(len(data.timer)):  # the reset's own steps left out
        data.timer[index].duration, data.timer[index].number = 0.0, 0
    zero = np.zeros(env.action_space.shape)
    for _ in range(steps):
        env.step(zero)
    whole = data.timer[mujoco.mjtTimer.mjTIMER_STEP]
    out: dict[str, Any] = {"env_id": env_id, "env_steps": steps, "physics_steps": whole.number}
    out["stages"] = {
        name: {
            "what": what,
            "us_per_step": 1e6 * data.timer[getattr(mujoco.mjtTimer, name)].duration / whole.number,
            "share": data.timer[getattr(mujoco.mjtTimer, name)].duration / whole.duration,
        }
        for name, what in STAGES.items()
    }
    out["contacts"], out["constraint_rows"] = int(data.ncon), int(data.nefc)
    out["solver_iterations_last"] = int(data.solver_niter[0])
    env.close()
    return out


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("--env", default=ACL_CLIMB_SEA_ID, help="the env id (default %(default)s)")
    parser.add_argument("--steps", type=int, default=600, help="env steps (default %(default)s)")
    args = parser.parse_args(argv)
    if args.steps < 1:
        parser.error(f"--steps must be at least 1, got {args.steps}")
    document = stage_times(args.env, args.steps)
    write_output(args.json, document)  # the record first: a closed pipe loses nothing
    print(f"{args.env}: {document['physics_steps']} physics steps")
    for row in document["stages"].values():
        print(f"{row['what']:60s} {row['us_per_step']:7.1f} us  {100 * row['share']:5.1f} %")
    return document


if __name__ == "__main__":
    with guarded_output():
        main()
