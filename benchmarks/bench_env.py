"""Speed of the climbing env: raw physics, env step, their ratio, real-time factor, vector scaling.

Run on an idle machine: ``python benchmarks/bench_env.py [--steps 2000] [--json PATH]``.
The raw figure plays the same open-loop keyframes with ``mj_step(nstep=50)`` from the same start
state, so the ratio is what the env adds (reward, slip sampling, observation) over physics.
"""

from __future__ import annotations

import argparse
import json
import time

import gymnasium as gym
import mujoco
import numpy as np

import acl_env  # noqa: F401  (registers the ids)
from acl_env.envs.acl_climb import SLIP_SAMPLES

ENV_ID = "acl_env/ACLClimb-v0"


def time_raw_physics(steps: int) -> tuple[float, float]:
    """Seconds per env-step worth of ``mj_step`` (frame_skip substeps), and per single mj_step."""
    env = gym.make(ENV_ID).unwrapped
    env.reset(seed=0)
    model, data, table = env.model, env.data, env.gait.cycle()
    substeps = env.frame_skip // SLIP_SAMPLES
    first = int(env._keyframe)  # the keyframe the env would play next
    start = time.perf_counter()
    for k in range(steps):
        data.ctrl[:] = table[(first + k) % len(table)]
        for _ in range(SLIP_SAMPLES):  # same call pattern as the env, nothing else
            mujoco.mj_step(model, data, nstep=substeps)
    elapsed = time.perf_counter() - start
    return elapsed / steps, elapsed / (steps * env.frame_skip)


def time_env(steps: int) -> float:
    """Seconds per ``env.step`` with zero actions (episodes reset as they end)."""
    env = gym.make(ENV_ID).unwrapped
    env.reset(seed=0)
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    elapsed, done = 0.0, 0
    while done < steps:
        start = time.perf_counter()
        _, _, terminated, truncated, _ = env.step(action)
        elapsed += time.perf_counter() - start
        done += 1
        if terminated or truncated:
            env.reset()
    return elapsed / steps


def time_vector(num_envs: int, steps: int) -> float:
    """Total env steps per second of an async (multi-process) vector env."""
    envs = gym.make_vec(ENV_ID, num_envs=num_envs, vectorization_mode="async")
    envs.reset(seed=0)
    action = np.zeros((num_envs, *envs.single_action_space.shape), dtype=np.float32)
    envs.step(action)
    start = time.perf_counter()
    for _ in range(steps):
        envs.step(action)
    elapsed = time.perf_counter() - start
    envs.close()
    return num_envs * steps / elapsed


def main(argv: list[str] | None = None) -> dict[str, float]:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--steps", type=int, default=2000, help="env steps per measurement")
    parser.add_argument("--json", help="write the figures to this JSON file")
    args = parser.parse_args(argv)

    raw_step, mj_step = time_raw_physics(args.steps)
    env_step = time_env(args.steps)
    one = time_vector(1, args.steps // 2)
    two = time_vector(2, args.steps // 2)
    dt = gym.make(ENV_ID).unwrapped.dt
    figures = {
        "mj_step_per_s": 1.0 / mj_step,
        "raw_physics_ms_per_env_step": 1e3 * raw_step,
        "env_step_ms": 1e3 * env_step,
        "env_steps_per_s": 1.0 / env_step,
        "env_overhead_pct": 100.0 * (env_step / raw_step - 1.0),
        "real_time_factor": dt / env_step,
        "vec_async_1_steps_per_s": one,
        "vec_async_2_steps_per_s": two,
        "vec_scaling_2_over_1": two / one,
    }
    print(f"{'measure':34s} value")
    for key, value in figures.items():
        print(f"{key:34s} {value:10.2f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(figures, f, indent=2)
    return figures


if __name__ == "__main__":
    main()
