"""PPO training throughput: env steps/s of the whole training loop, and where the time goes.

Runs short trainings of the shipped recipe (``acl_env/data/ppo.yml``) and of variants given as
extra ``acl-train`` arguments, interleaved (A B A B ...) so that load from other processes hits
all alike, and prints the median env steps/s per variant with the breakdown that the trainer
records in ``summary.json``: stepping the envs (workers + transfer), policy inference, the rest
of the rollout (buffer, callbacks, advantages), gradient updates, other (logging, checkpoints).

Each round also times one core's raw physics of the task (``--raw-env``, default the shipped
SEA task): ``bench_env.py``'s replay of ``--raw-steps`` env steps, the same ``mj_step`` calls from
the same states with nothing else. The whole loop's rate is reported against it, both medians of
the same run.

    python benchmarks/bench_ppo.py                                  # shipped config, 20k steps
    python benchmarks/bench_ppo.py --steps 20000 --rounds 3 \\
        --variant "2 envs=--n-envs 2 --hyperparams n_steps:1024" --variant "shipped="
"""

from __future__ import annotations

import os
import shlex
import statistics
import tempfile
from pathlib import Path

from bench_env import env_vs_raw  # this folder's: the script's directory is on the path

from acl_env import ACL_CLIMB_SEA_ID
from acl_env.io import console_script, read_json
from acl_env.scripts import make_parser
from acl_env.training import trainer

PARTS = ("env_step", "policy_inference", "rollout_other", "gradient_update", "other")


def run_once(extra: list[str], steps: int, run_root: Path) -> dict:
    """One short training run; its summary's segment."""
    argv = ["--n-timesteps", str(steps), "--run-dir", str(run_root), "--no-progress-bar", *extra]
    argv += ["--checkpoint-freq", str(10**9)]
    run_dir = trainer.train(argv)
    return read_json(run_dir / "summary.json")["segments"][-1]


def main() -> None:
    parser = make_parser(__doc__, json=None)
    parser.add_argument("--steps", type=int, default=20_000, help="env steps per run")
    parser.add_argument("--rounds", type=int, default=2, help="runs per variant (interleaved)")
    parser.add_argument(
        "--variant",
        action="append",
        metavar="NAME=ARGS",
        help="extra acl-train arguments; default: the shipped config alone",
    )
    parser.add_argument("--raw-env", default=ACL_CLIMB_SEA_ID, help="task of the raw physics")
    parser.add_argument("--raw-steps", type=int, default=400, help="raw physics steps per round")
    args = parser.parse_args()
    variants = dict(v.split("=", 1) for v in (args.variant or ["shipped="]))
    results: dict[str, list[dict]] = {name: [] for name in variants}
    raw: list[float] = []  # one core's raw physics, env steps/s
    with tempfile.TemporaryDirectory() as tmp:
        for round_ in range(args.rounds):
            for name, extra in variants.items():
                segment = run_once(shlex.split(extra), args.steps, Path(tmp) / name)
                results[name].append(segment)
                print(f"round {round_} {name}: {segment['env_steps_per_s']:.0f} env steps/s")
            raw.append(1e3 / env_vs_raw(args.raw_steps, 1, args.raw_env)["raw_physics_ms"])
            print(f"round {round_} raw physics of {args.raw_env}, one core: {raw[-1]:.0f} steps/s")
    raw_rate = statistics.median(raw)
    print(f"\none core's raw physics: {raw_rate:.0f} env steps/s (median of rounds)")
    for name, segments in results.items():
        rate = statistics.median(s["env_steps_per_s"] for s in segments)
        print(f"{name}: {rate:.0f} env steps/s, {rate / raw_rate:.2f}x one core's raw physics")
    print(f"\n{'variant':<28} {'steps/s':>8} " + " ".join(f"{p:>16}" for p in PARTS))
    for name, segments in results.items():
        rate = statistics.median(s["env_steps_per_s"] for s in segments)
        shares = []
        for part in PARTS:
            share = statistics.median(s["time_s"][part] / s["wall_time_s"] for s in segments)
            per_step = statistics.median(s["time_s"][part] / s["steps"] * 1e6 for s in segments)
            shares.append(f"{100 * share:5.1f}% {per_step:6.0f}us")
        print(f"{name:<28} {rate:8.0f} " + " ".join(f"{s:>16}" for s in shares))
    print("\n(per-part: share of the wall time, and microseconds per env step; median of rounds)")
    print(f"\n{'variant':<28} " + " ".join(f"{h:>14}" for h in CPU_HEADS))
    for name, segments in results.items():
        cells = [statistics.median(cpu_row(s)[i] for s in segments) for i in range(len(CPU_HEADS))]
        print(f"{name:<28} " + " ".join(f"{c:14.0f}" for c in cells))
    print(
        "(CPU microseconds per env step, all processes: less sensitive to other load than wall "
        "time; env compute is the time inside the envs' step/reset; the parallel limit is the "
        f"steps/s if the total CPU were spread over {os.cpu_count()} cores)"
    )


CPU_HEADS = ("trainer_cpu", "workers_cpu", "env_compute", "total_cpu", "parallel_limit")


def cpu_row(segment: dict) -> tuple[float, ...]:
    """CPU use per env step (us), and the steps/s that total CPU allows on this machine."""
    t, steps = segment["time_s"], segment["steps"]
    trainer_cpu, workers_cpu = t["cpu_trainer"], t["cpu_workers"]
    total = trainer_cpu + workers_cpu
    return (
        1e6 * trainer_cpu / steps,
        1e6 * workers_cpu / steps,
        1e6 * (t.get("env_compute_all_envs") or 0.0) / steps,
        1e6 * total / steps,
        steps * (os.cpu_count() or 1) / total,
    )


if __name__ == "__main__":
    console_script(main)()
