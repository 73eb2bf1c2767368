"""Speed of the native vector env (``gym.make_vec``): world steps per second on 1 and 2 threads,
against the worlds' raw physics.

``python benchmarks/bench_vector.py [--env ID] [--worlds 16] [--steps 40] [--rounds 5] [--json F]
[--episodes N]``

Three things are timed in interleaved rounds, each over ``--steps`` steps of ``--worlds`` worlds
with a zero action from the same reset (``seed=0``), and reported as the median over
``--rounds``:

* ``threads_1``: :class:`acl_env.envs.vector.ACLClimbVectorEnv` on one thread; the command each
  world's step sent to its motors is recorded (outside the timed steps);
* ``raw``: the same worlds' physics alone, replayed: every world is put back in the state it had
  before those steps, and for each step and world the recorded command is written to ``ctrl``
  and the ``mj_step`` calls of one env step (``SLIP_SAMPLES`` x ``nstep=substeps``) run, nothing
  else. The replay ends in the state the vector env reached, bit for bit (checked): the same
  trajectories, so the same contacts and solver work;
* ``threads_2``: the vector env on two threads.

With ``--episodes N``, each round also plays N whole episodes of the task's open loop (seeds
0 to N - 1) the two ways ``acl-evaluate`` could: in its 2 worker processes (``evaluate``, pool
made and closed in the timing, each episode measured by ``run_episode``), and as one vector env
of N worlds on 2 threads (made, reset and stepped to the episodes' end in the timing, no
measuring). Reported: episodes per second of each.

Only ids whose command is constant over a step replay this way (no compliant grip, whose
firmware changes the command at every tick); the check refuses the others.

Reported: world steps per second of each, the vector env's cost per world step over the raw
physics' (1 thread), the speed-up of 2 threads over 1, and Amdahl's law fitted to it: the serial
fraction and the throughput it predicts on 8, 16 and 64 cores (:func:`amdahl`; a prediction).
Meaningful on an idle machine only: anything else running takes the second core.
"""

from __future__ import annotations

import math
import statistics
import time
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_SEA_ID
from acl_env.envs.contacts import SLIP_SAMPLES
from acl_env.evaluation.baselines import Controller
from acl_env.evaluation.runner import evaluate
from acl_env.io import console_script
from acl_env.scripts import make_parser, write_outputs

STATE = mujoco.mjtState.mjSTATE_INTEGRATION  # qpos, qvel, act, ctrl, warm start, histories


def time_recorded(env: Any, steps: int) -> tuple[float, list[np.ndarray]]:
    """Seconds for ``steps`` steps of the vector env ``env`` with a zero action, and every
    world's motor command at each step (copied outside the timed steps)."""
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    elapsed, commands = 0.0, []
    for _ in range(steps):
        start = time.perf_counter()
        env.step(action)
        elapsed += time.perf_counter() - start
        commands.append(np.stack([world.data.ctrl.copy() for world in env.envs]))
    return elapsed, commands


def time_raw(envs: list[Any], states: list[np.ndarray], commands: list[np.ndarray]) -> float:
    """Seconds for the raw physics of the recorded steps: each world set back to its saved
    ``states``, then per step and world the recorded command and the env step's ``mj_step``
    calls. Raises if the replay does not end where the env did (the trajectories differ)."""
    model = envs[0].model
    substeps = envs[0].frame_skip // SLIP_SAMPLES
    ends = saved_states(envs)
    for world, state in zip(envs, states, strict=True):
        mujoco.mj_setState(model, world.data, state, STATE)
    start = time.perf_counter()
    for command in commands:
        for world, ctrl in zip(envs, command, strict=True):
            world.data.ctrl[:] = ctrl
            for _ in range(SLIP_SAMPLES):
                mujoco.mj_step(model, world.data, nstep=substeps)
    elapsed = time.perf_counter() - start
    replayed = saved_states(envs)
    if not all(np.array_equal(a, b) for a, b in zip(ends, replayed, strict=True)):
        raise RuntimeError("the raw replay left the vector env's trajectory (a grip task?)")
    return elapsed


def saved_states(envs: list[Any]) -> list[np.ndarray]:
    """Every world's integration state (``STATE``)."""
    model = envs[0].model
    states = [np.empty(mujoco.mj_stateSize(model, STATE)) for _ in envs]
    for world, state in zip(envs, states, strict=True):
        mujoco.mj_getState(model, world.data, state, STATE)
    return states


def measure(env_id: str, worlds: int, steps: int, rounds: int) -> dict[str, Any]:
    """The interleaved rounds (module docstring); world steps per second, medians."""
    vectors = {t: gym.make_vec(env_id, num_envs=worlds, threads=t) for t in (1, 2)}
    samples: dict[str, list[float]] = {"raw": [], "threads_1": [], "threads_2": []}
    for r in tqdm(range(rounds), desc="rounds"):
        for t in (1, 2) if r % 2 == 0 else (2, 1):  # alternate which goes first
            vectors[t].reset(seed=0)
            if t == 2:
                elapsed, _ = time_recorded(vectors[2], steps)
                samples["threads_2"].append(worlds * steps / elapsed)
                continue
            states = saved_states(vectors[1].envs)
            elapsed, commands = time_recorded(vectors[1], steps)
            samples["threads_1"].append(worlds * steps / elapsed)
            samples["raw"].append(worlds * steps / time_raw(vectors[1].envs, states, commands))
    for env in vectors.values():
        env.close()
    rate = {k: statistics.median(v) for k, v in samples.items()}
    return {
        "env_id": env_id,
        "worlds": worlds,
        "steps": steps,
        "rounds": rounds,
        "world_steps_per_s": rate,
        "samples": samples,
        "cost_over_raw_1_thread": rate["raw"] / rate["threads_1"],
        "speedup_2_threads": rate["threads_2"] / rate["threads_1"],
        **amdahl(rate["threads_1"], rate["threads_2"] / rate["threads_1"]),
    }


def time_episodes(env_id: str, episodes: int, vector: bool) -> float:
    """Seconds to play ``episodes`` open-loop episodes (module docstring), in 2 worker processes
    or as one vector env on 2 threads."""
    seeds = list(range(episodes))
    start = time.perf_counter()
    if vector:
        env = gym.make_vec(env_id, num_envs=episodes, threads=2)
        env.reset(seed=seeds)
        action = np.zeros(env.action_space.shape, dtype=np.float32)
        for _ in range(env.envs[0].steps_per_cycle * env.envs[0].cycles_per_episode):
            env.step(action)
        env.close()
    else:
        evaluate([Controller("open_loop_tuned", env_id)], seeds, workers=2, progress=False)
    return time.perf_counter() - start


def measure_episodes(env_id: str, episodes: int, rounds: int) -> dict[str, Any]:
    """Episodes per second, processes against the vector env, interleaved, medians."""
    samples: dict[str, list[float]] = {"processes": [], "vector_env": []}
    for r in tqdm(range(rounds), desc="episodes"):
        for vector in (False, True) if r % 2 == 0 else (True, False):
            key = "vector_env" if vector else "processes"
            samples[key].append(episodes / time_episodes(env_id, episodes, vector))
    rate = {k: statistics.median(v) for k, v in samples.items()}
    return {"episodes": episodes, "episodes_per_s": rate, "samples": samples}


PREDICTED_CORES = (8, 16, 64)


def amdahl(one_thread: float, speedup_2: float) -> dict[str, Any]:
    """Amdahl's law fitted to the speed-up of 2 threads over 1: the serial fraction
    ``s = 2 / speedup_2 - 1`` (the share of a world step that does not run in parallel: here the
    worlds' Python, which holds the GIL), and from it the throughput predicted on more cores,
    ``one_thread / (s + (1 - s) / n)``. A prediction from two points on a 2-vCPU machine, not a
    measurement: memory bandwidth and the cores' sharing of caches are outside the model."""
    serial = min(max(2.0 / speedup_2 - 1.0, 0.0), 1.0)
    return {
        "serial_fraction": serial,
        "predicted_world_steps_per_s": {
            str(n): one_thread / (serial + (1.0 - serial) / n) for n in PREDICTED_CORES
        },
        "predicted_ceiling_world_steps_per_s": one_thread / serial if serial > 0 else math.inf,
    }


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__)
    parser.add_argument("--env", default=ACL_CLIMB_SEA_ID, help="env id")
    parser.add_argument("--worlds", type=int, default=16, help="worlds per vector env")
    parser.add_argument("--steps", type=int, default=40, help="steps per round")
    parser.add_argument("--rounds", type=int, default=5, help="interleaved rounds")
    parser.add_argument("--episodes", type=int, help="also time whole episodes (docstring)")
    args = parser.parse_args(argv)
    result = measure(args.env, args.worlds, args.steps, args.rounds)
    if args.episodes:
        result["whole_episodes"] = measure_episodes(args.env, args.episodes, args.rounds)
    write_outputs(args, result)
    rate = result["world_steps_per_s"]
    print(
        f"{args.env}, {args.worlds} worlds: raw physics {rate['raw']:.0f} world steps/s; "
        f"vector env {rate['threads_1']:.0f} (1 thread, {result['cost_over_raw_1_thread']:.2f}x "
        f"the raw cost), {rate['threads_2']:.0f} (2 threads, "
        f"{result['speedup_2_threads']:.2f}x 1 thread)"
    )
    predicted = ", ".join(
        f"{n} cores {v:.0f}" for n, v in result["predicted_world_steps_per_s"].items()
    )
    print(
        f"Amdahl fit: serial fraction {result['serial_fraction']:.2f}; predicted world steps/s: "
        f"{predicted}; ceiling {result['predicted_ceiling_world_steps_per_s']:.0f}"
    )
    if args.episodes:
        rate = result["whole_episodes"]["episodes_per_s"]
        print(
            f"{args.episodes} whole episodes: {rate['processes']:.3f} episodes/s in 2 worker "
            f"processes, {rate['vector_env']:.3f} as a vector env on 2 threads "
            f"({rate['vector_env'] / rate['processes']:.2f}x)"
        )
    return result


if __name__ == "__main__":
    console_script(main)()
