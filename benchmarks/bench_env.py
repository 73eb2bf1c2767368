"""Speed of the climbing env: env step against raw physics, v1 against the v0 2 ms step, the SEA
against the servo, scaling.

``python benchmarks/bench_env.py [--env ID] [--steps 400] [--rounds 7] [--json PATH] [--plot PATH]``

1. **Env overhead.** For every step, from the same saved physics state, ``env.step`` and the raw
   physics of that step (the same ``mj_step`` calls: ``SLIP_SAMPLES`` x ``nstep=substeps`` with
   the same servo targets, nothing else) are timed back to back, alternating which goes first.
   The ratio of their summed wall times per round is reported as the median over ``--rounds``,
   and the same for the thread's CPU time (robust to other processes taking the core).
2. **Steps per second per core** of ``env.step`` at the default physics step and at the old
   2 ms step (``timestep=0.002``), in alternating blocks of the same run (median of rounds).
3. **SEA against servo:** steps per second of ``env.step`` on ACLClimb-v3 (series elastic
   actuators) and ACLClimbServo-v1 (the same task on the ideal servo), alternating blocks of
   thread CPU time, median of the per-round ratio.
4. **Process scaling:** total steps/s of Gymnasium's async vector env with 1 and 2 worker
   processes, alternating, median of rounds; meaningful only on an otherwise idle machine.

Timings on a loaded machine are noisy; the ratios come from interleaved measurements so that
load hits both sides alike.
"""

from __future__ import annotations

import time
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_BENCHMARK_ID, ACL_CLIMB_ID, ACL_CLIMB_SEA_ID
from acl_env.constants import PHYSICS_TIMESTEP
from acl_env.envs.contacts import SLIP_SAMPLES
from acl_env.io import console_script
from acl_env.scripts import (
    make_parser,
    print_figures,
    save_figure,
    timed_steps,
    use_agg,
    write_outputs,
)

V0_TIMESTEP = 0.002  # s: the physics step of the v0 ids
STATE = mujoco.mjtState.mjSTATE_INTEGRATION


def env_vs_raw(steps: int, rounds: int, env_id: str = ACL_CLIMB_ID) -> dict[str, float]:
    """Interleaved ``env.step`` and raw physics of the same step from the same state (the SEA's
    command and sensor histories and motor states included)."""
    env = gym.make(env_id).unwrapped
    env.reset(seed=0)
    model, data = env.model, env.data
    action = np.zeros(env.action_space.shape, dtype=np.float32)
    substeps = env.frame_skip // SLIP_SAMPLES
    state = np.empty(mujoco.mj_stateSize(model, STATE))
    ratios, cpu_ratios, env_ms, raw_ms = [], [], [], []
    for r in tqdm(range(rounds), desc="env vs raw", leave=False):
        t_env = t_raw = c_env = c_raw = 0.0
        for k in range(steps):
            mujoco.mj_getState(model, data, state, STATE)
            target = np.clip(env._base_target(), -np.pi / 2, np.pi / 2)  # the zero residual
            if env.config.gait.phase_rate_range is not None:
                action[-1] = 0.0  # cadence 1: the table row
            env_first = (k + r) % 2 == 0
            for side in ("env", "raw") if env_first else ("raw", "env"):
                if side == "env":
                    start, cpu = time.perf_counter(), time.thread_time()
                    _, _, terminated, truncated, _ = env.step(action)
                    t_env += time.perf_counter() - start
                    c_env += time.thread_time() - cpu
                else:
                    data.ctrl[:] = target
                    start, cpu = time.perf_counter(), time.thread_time()
                    for _ in range(SLIP_SAMPLES):
                        mujoco.mj_step(model, data, nstep=substeps)
                    t_raw += time.perf_counter() - start
                    c_raw += time.thread_time() - cpu
                if side != ("raw" if env_first else "env"):  # same start for the other side
                    mujoco.mj_setState(model, data, state, STATE)
                    mujoco.mj_forward(model, data)  # the env reads derived quantities (COM)
            # Both orders end in the post-step state; only env.step moves the env's counters.
            if terminated or truncated:
                env.reset(seed=r * steps + k)
        ratios.append(t_env / t_raw)
        cpu_ratios.append(c_env / c_raw)
        env_ms.append(1e3 * t_env / steps)
        raw_ms.append(1e3 * t_raw / steps)
    env.close()
    return {
        "env_over_raw": float(np.median(ratios)),
        "env_over_raw_cpu_time": float(np.median(cpu_ratios)),
        "env_over_raw_rounds": [float(x) for x in ratios],
        "env_step_ms": float(np.median(env_ms)),
        "raw_physics_ms": float(np.median(raw_ms)),
    }


def steps_per_second(steps: int, rounds: int) -> dict[str, float]:
    """``env.step`` per second at the default physics step and at 2 ms, alternating blocks."""
    envs = {
        "default": gym.make(ACL_CLIMB_ID).unwrapped,
        "v0_2ms": gym.make(ACL_CLIMB_ID, timestep=V0_TIMESTEP).unwrapped,
    }
    for env in envs.values():
        env.reset(seed=0)
    rates: dict[str, list[float]] = {name: [] for name in envs}
    for _ in tqdm(range(rounds), desc="steps/s", leave=False):
        for name, env in envs.items():
            rates[name].append(steps / timed_steps(env, steps))
    out = {f"steps_per_s_{name}": float(np.median(r)) for name, r in rates.items()}
    out["speedup_default_over_2ms"] = float(
        np.median(np.array(rates["default"]) / np.array(rates["v0_2ms"]))
    )
    return out


def sea_vs_servo(steps: int, rounds: int) -> dict[str, float]:
    """``env.step`` per second of the SEA task and the same task on the servo, alternating."""
    envs = {
        "sea": gym.make(ACL_CLIMB_SEA_ID).unwrapped,
        "servo": gym.make(ACL_CLIMB_BENCHMARK_ID).unwrapped,
    }
    for env in envs.values():
        env.reset(seed=0)
    rates: dict[str, list[float]] = {name: [] for name in envs}
    for _ in tqdm(range(rounds), desc="sea vs servo", leave=False):
        for name, env in envs.items():
            # thread CPU time: other processes on the machine do not count
            rates[name].append(steps / timed_steps(env, steps, time.thread_time, reset_seed=0))
    return {
        "steps_per_s_sea": float(np.median(rates["sea"])),
        "steps_per_s_servo": float(np.median(rates["servo"])),
        "sea_step_over_servo": float(np.median(np.array(rates["servo"]) / np.array(rates["sea"]))),
    }


def vector_scaling(steps: int, rounds: int) -> dict[str, float]:
    """Total steps/s of the async vector env with 1 and 2 processes, alternating rounds."""
    vecs = {n: gym.make_vec(ACL_CLIMB_ID, num_envs=n, vectorization_mode="async") for n in (1, 2)}
    rates: dict[int, list[float]] = {1: [], 2: []}
    for n, vec in vecs.items():
        vec.reset(seed=0)
        vec.step(np.zeros((n, *vec.single_action_space.shape), dtype=np.float32))
    for _ in tqdm(range(rounds), desc="processes", leave=False):
        for n, vec in vecs.items():
            action = np.zeros((n, *vec.single_action_space.shape), dtype=np.float32)
            start = time.perf_counter()
            for _ in range(steps):
                vec.step(action)
            rates[n].append(n * steps / (time.perf_counter() - start))
    for vec in vecs.values():
        vec.close()
    return {
        "vec_async_1_steps_per_s": float(np.median(rates[1])),
        "vec_async_2_steps_per_s": float(np.median(rates[2])),
        "vec_scaling_2_over_1": float(np.median(np.array(rates[2]) / np.array(rates[1]))),
    }


def plot(figures: dict[str, Any], path: Any) -> None:
    """Cost per env step: the env on the SEA and on the servo (thread CPU time), and the measured
    env's step against its raw physics (wall time, step by step from the same states)."""
    plt = use_agg()
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.4))
    sea, servo = 1e3 / figures["steps_per_s_sea"], 1e3 / figures["steps_per_s_servo"]
    labels = ["ACLClimbServo-v1 (servo)", "ACLClimb-v3 (SEA)"]
    axes[0].bar(labels, [servo, sea], color=["C0", "C1"])
    axes[0].set_ylabel("ms per env step (CPU)")
    axes[0].set_title(f"SEA / servo: {figures['sea_step_over_servo']:.2f}x")
    axes[1].bar(
        ["raw physics", "env.step"], [figures["raw_physics_ms"], figures["env_step_ms"]], color="C1"
    )
    axes[1].set_ylabel("ms per env step (wall)")
    axes[1].set_title(f"{figures['env_vs_raw_env']}: env / raw {figures['env_over_raw']:.2f}x")
    save_figure(fig, path, dpi=110, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, plot=True)
    parser.add_argument("--steps", type=int, default=400, help="env steps per round and side")
    parser.add_argument("--rounds", type=int, default=7, help="alternating rounds (median)")
    parser.add_argument("--skip-vector", action="store_true", help="skip the process scaling")
    parser.add_argument(
        "--env",
        default=ACL_CLIMB_ID,
        help="env of the env-vs-raw comparison (default: %(default)s)",
    )
    args = parser.parse_args(argv)

    figures: dict[str, Any] = {"default_timestep_ms": 1e3 * PHYSICS_TIMESTEP}
    figures |= {"env_vs_raw_env": args.env}
    figures |= env_vs_raw(args.steps, args.rounds, args.env)
    figures |= steps_per_second(args.steps, args.rounds)
    figures |= sea_vs_servo(args.steps, args.rounds)
    if not args.skip_vector:
        figures |= vector_scaling(args.steps, args.rounds)
    figures["real_time_factor"] = 0.1 * figures["steps_per_s_default"]
    write_outputs(args, figures, plot)  # the files first: a closed pipe loses nothing
    print_figures(figures)
    return figures


if __name__ == "__main__":
    console_script(main)()
