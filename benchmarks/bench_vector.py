"""Speed of the native vector env (``gym.make_vec``): world steps per second on 1 and 2 threads,
against the worlds' raw physics.

``python benchmarks/bench_vector.py [--env ID] [--worlds 16] [--steps 40] [--rounds 5] [--json F]``

Three things are timed in interleaved rounds (A, B, C, A, B, C, ...), each over ``--steps`` steps
of ``--worlds`` worlds with a zero action, and reported as the median over ``--rounds``:

* ``raw``: the worlds' physics alone, one after the other on one thread: for each world, the
  ``mj_step`` calls of one env step (``SLIP_SAMPLES`` x ``nstep=substeps``) and nothing else;
* ``threads_1``: :class:`acl_env.envs.vector.ACLClimbVectorEnv` on one thread;
* ``threads_2``: the same on two threads.

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
from acl_env.scripts import make_parser, write_outputs


def time_raw(envs: list[Any], steps: int) -> float:
    """Seconds for ``steps`` env steps' worth of raw physics of every world (``envs``: the vector
    env's worlds, whose states it advances)."""
    substeps = envs[0].frame_skip // SLIP_SAMPLES
    start = time.perf_counter()
    for _ in range(steps):
        for env in envs:
            for _ in range(SLIP_SAMPLES):
                mujoco.mj_step(env.model, env.data, nstep=substeps)
    return time.perf_counter() - start


def time_vector(env: Any, steps: int) -> float:
    """Seconds for ``steps`` steps of the vector env ``env`` with a zero action."""
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    start = time.perf_counter()
    for _ in range(steps):
        env.step(action)
    return time.perf_counter() - start


def measure(env_id: str, worlds: int, steps: int, rounds: int) -> dict[str, Any]:
    """The interleaved rounds (module docstring); world steps per second, medians."""
    vectors = {t: gym.make_vec(env_id, num_envs=worlds, threads=t) for t in (1, 2)}
    raw_env = gym.make_vec(env_id, num_envs=worlds, threads=1)
    for env in (*vectors.values(), raw_env):
        env.reset(seed=0)
    samples: dict[str, list[float]] = {"raw": [], "threads_1": [], "threads_2": []}
    for _ in tqdm(range(rounds), desc="rounds"):
        samples["raw"].append(worlds * steps / time_raw(raw_env.envs, steps))
        for t, env in vectors.items():
            samples[f"threads_{t}"].append(worlds * steps / time_vector(env, steps))
    for env in (*vectors.values(), raw_env):
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
    args = parser.parse_args(argv)
    result = measure(args.env, args.worlds, args.steps, args.rounds)
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
    return result


if __name__ == "__main__":
    main()
