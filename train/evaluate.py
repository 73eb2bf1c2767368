"""Evaluate a trained residual policy against the open-loop gaits, on the same seeds.

Controllers: ``policy`` (deterministic actions, the run's VecNormalize statistics loaded frozen),
``open_loop_acl`` (zero action on ``acl_env/ACLClimb-v0``) and ``open_loop_rolling_helix`` (zero
action on ``acl_env/RollingHelixClimb-v0``). Episode ``i`` of every controller resets with seed
``seed + i``. Per episode:

    climb_per_cycle_m   climb / (steps / steps_per_cycle)      (climb = sum of info["climb"])
    climb_speed_cm_s    100 * climb / (steps * dt)
    slip_per_cycle_m    slip / (steps / steps_per_cycle)       (slip = sum of info["slip"])
    falls               1 if the episode ended with info["fell"]
    energy_per_m        energy / climb in J/m (sum of info["energy"]; undefined if climb <= 0)

reported as mean and two-sided 95 % confidence interval from Student's t distribution over the
episodes (``falls`` also as a count).

    python train/evaluate.py                         # shipped policy, 20 episodes
    python train/evaluate.py --policy runs/<run> --json eval.json --plot docs/eval.png
    python train/evaluate.py --no-policy --env-kwargs friction:0.6
"""

from __future__ import annotations

import argparse
import json
import math
import os
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")  # headless rendering for --video; before mujoco loads

import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ROLLING_HELIX_CLIMB_ID
from acl_env.evaluation import mean_ci95
from acl_env.training.config import (
    import_gym_packages,
    make_env,
    normalize_kwargs,
    parse_kv_pairs,
    steps_per_cycle,
)
from acl_env.training.runs import latest_model, run_config

ACL_ID = ACL_CLIMB_ID
ROLLING_HELIX_ID = ROLLING_HELIX_CLIMB_ID
DEFAULT_POLICY = Path(__file__).with_name("policies") / "acl_climb_ppo"
METRICS = ("climb_per_cycle_m", "climb_speed_cm_s", "slip_per_cycle_m", "falls", "energy_per_m")
# Training-only env kwargs that evaluation drops from the policy's config: evaluation runs at
# default conditions (plus --env-kwargs), like the open-loop controllers.
TRAINING_ONLY_KWARGS = ("domain_randomization", "reward_weights")
# Kwargs tied to one base gait: not passed to the other gait's env.
GAIT_KWARGS = ("gait_kwargs", "base_gait")


@dataclass(frozen=True)
class Controller:
    """What to run: an env and either a policy folder or zero actions."""

    name: str
    env_id: str
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    policy_dir: str | None = None


@dataclass
class Episode:
    """Sums over one episode and the centre-of-mass height after reset and after each step."""

    seed: int
    steps: int
    climb: float
    slip: float
    energy: float
    fell: bool
    dt: float
    steps_per_cycle: int
    com_height: np.ndarray

    def metrics(self) -> dict[str, float]:
        """The per-episode values of :data:`METRICS`."""
        cycles = self.steps / self.steps_per_cycle
        return {
            "climb_per_cycle_m": self.climb / cycles,
            "climb_speed_cm_s": 100.0 * self.climb / (self.steps * self.dt),
            "slip_per_cycle_m": self.slip / cycles,
            "falls": float(self.fell),
            "energy_per_m": self.energy / self.climb if self.climb > 0.0 else math.nan,
        }


Actor = Callable[[np.ndarray], np.ndarray]


def load_policy(policy_dir: str | Path, env: Any) -> Actor:
    """Deterministic actions of the newest model in ``policy_dir``, observations normalised by its
    VecNormalize statistics frozen (``training=False``, ``norm_reward=False``)."""
    import torch
    from stable_baselines3 import PPO
    from stable_baselines3.common.vec_env import DummyVecEnv, VecNormalize

    torch.set_num_threads(1)  # one small MLP forward per step; threads would fight the workers
    model_path, vecnorm_path = latest_model(policy_dir)
    model = PPO.load(model_path, device="cpu")
    normalize: Callable[[np.ndarray], np.ndarray] = lambda obs: obs  # noqa: E731
    if vecnorm_path is not None:
        vec_normalize = VecNormalize.load(str(vecnorm_path), DummyVecEnv([lambda: env]))
        vec_normalize.training, vec_normalize.norm_reward = False, False
        normalize = vec_normalize.normalize_obs

    def act(obs: np.ndarray) -> np.ndarray:
        action, _ = model.predict(normalize(obs), deterministic=True)
        return action

    return act


def zero_actor(env: Any) -> Actor:
    """The open-loop gait: a zero residual."""
    zero = np.zeros(env.action_space.shape, dtype=env.action_space.dtype)
    return lambda obs: zero


def make_actor(controller: Controller, env: Any) -> Actor:
    """The controller's policy, or zero actions for the open-loop gaits."""
    return load_policy(controller.policy_dir, env) if controller.policy_dir else zero_actor(env)


def run_episode(env: Any, act: Actor, seed: int, frames: list[np.ndarray] | None = None) -> Episode:
    """Roll out one episode from ``reset(seed=seed)``; append rendered frames if asked."""
    obs, info = env.reset(seed=seed)
    heights = [float(info["com_height"])]
    steps, climb, slip, energy, fell = 0, 0.0, 0.0, 0.0, False
    if frames is not None:
        frames.append(env.render())
    terminated = truncated = False
    while not (terminated or truncated):
        obs, _, terminated, truncated, info = env.step(act(obs))
        steps += 1
        climb += float(info["climb"])
        slip += float(info["slip"])
        energy += float(info["energy"])
        heights.append(float(info["com_height"]))
        if frames is not None:
            frames.append(env.render())
    fell = bool(terminated and info.get("fell", False))
    return Episode(
        seed=seed,
        steps=steps,
        climb=climb,
        slip=slip,
        energy=energy,
        fell=fell,
        dt=float(env.unwrapped.dt),
        steps_per_cycle=steps_per_cycle(env),
        com_height=np.asarray(heights),
    )


_WORKER_CACHE: dict[str, tuple[Any, Actor]] = {}


def _env_and_actor(controller: Controller) -> tuple[Any, Actor]:
    """One env and actor per controller and process, reused across its episodes."""
    key = repr(controller)
    if key not in _WORKER_CACHE:
        env = make_env(controller.env_id, controller.env_kwargs)
        _WORKER_CACHE[key] = (env, make_actor(controller, env))
    return _WORKER_CACHE[key]


def _run_task(controller: Controller, seed: int, gym_packages: tuple[str, ...]) -> Episode:
    """Worker task: one episode of one controller."""
    import_gym_packages(gym_packages)
    env, actor = _env_and_actor(controller)
    return run_episode(env, actor, seed)


def evaluate(
    controllers: list[Controller],
    seeds: list[int],
    workers: int = 2,
    gym_packages: tuple[str, ...] = (),
    progress: bool = True,
) -> dict[str, list[Episode]]:
    """Run every controller on every seed, episodes spread over ``workers`` processes."""
    tasks = [(c, s) for c in controllers for s in seeds]
    results: dict[tuple[str, int], Episode] = {}
    bar = tqdm(total=len(tasks), desc="episodes", unit="ep", disable=not progress)
    if workers <= 1:
        for controller, seed in tasks:
            results[controller.name, seed] = _run_task(controller, seed, gym_packages)
            bar.update()
    else:
        with ProcessPoolExecutor(max_workers=workers) as pool:
            futures = {pool.submit(_run_task, c, s, gym_packages): (c.name, s) for c, s in tasks}
            for future in as_completed(futures):
                results[futures[future]] = future.result()
                bar.update()
    bar.close()
    return {c.name: [results[c.name, s] for s in seeds] for c in controllers}


def summarize(episodes: list[Episode]) -> dict[str, Any]:
    """Mean and t-based 95 % CI per metric (``values`` per episode, in seed order)."""
    per_episode = [e.metrics() for e in episodes]
    summary: dict[str, Any] = {}
    for metric in METRICS:
        values = [m[metric] for m in per_episode]
        summary[metric] = {**mean_ci95(values), "values": values}
    summary["falls"]["count"] = sum(e.fell for e in episodes)
    summary["episodes"] = len(episodes)
    summary["seeds"] = [e.seed for e in episodes]
    return summary


def format_table(summaries: dict[str, dict[str, Any]]) -> str:
    """Plain-text table: mean ± 95 % CI half-width per metric."""
    header = ["controller", "climb/cycle (m)", "speed (cm/s)", "slip/cycle (m)", "falls", "J/m"]
    rows = [header]
    for name, s in summaries.items():

        def cell(metric: str, fmt: str, s: dict[str, Any] = s) -> str:
            return f"{s[metric]['mean']:{fmt}} ± {s[metric]['half_width']:{fmt}}"

        falls = f"{s['falls']['count']}/{s['episodes']}"
        rows.append(
            [
                name,
                cell("climb_per_cycle_m", ".4f"),
                cell("climb_speed_cm_s", ".3f"),
                cell("slip_per_cycle_m", ".4f"),
                falls,
                cell("energy_per_m", ".1f"),
            ]
        )
    widths = [max(len(row[i]) for row in rows) for i in range(len(header))]
    lines = ["  ".join(cell.rjust(w) for cell, w in zip(row, widths, strict=True)) for row in rows]
    lines.insert(1, "-" * len(lines[0]))
    n = next(iter(summaries.values()))["episodes"] if summaries else 0
    lines.append(f"mean ± 95 % CI half-width (Student's t, {n} episodes)")
    return "\n".join(lines)


def plot_heights(results: dict[str, list[Episode]], path: str | Path) -> None:
    """Centre-of-mass rise above its start against time: mean and 95 % CI band per controller."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, ax = plt.subplots(figsize=(7, 4), constrained_layout=True)
    for name, episodes in results.items():
        length = max(len(e.com_height) for e in episodes)
        rise = np.full((len(episodes), length), np.nan)
        for row, e in zip(rise, episodes, strict=True):
            row[: len(e.com_height)] = e.com_height - e.com_height[0]
        stats = [mean_ci95(column) for column in rise.T]
        mean = np.array([s["mean"] for s in stats])
        half = np.array([s["half_width"] for s in stats])
        t = np.arange(length) * episodes[0].dt
        ax.plot(t, mean, label=name)
        ax.fill_between(t, mean - half, mean + half, alpha=0.25)
    ax.set_xlabel("time (s)")
    ax.set_ylabel("COM height above start (m)")
    ax.set_title(f"mean ± 95 % CI over {len(next(iter(results.values())))} episodes")
    ax.legend()
    ax.grid(alpha=0.3)
    fig.savefig(path, dpi=120)
    plt.close(fig)


def record_video(controller: Controller, seed: int, path: str | Path) -> None:
    """One episode of ``controller`` rendered offscreen (``rgb_array``) to an mp4."""
    import imageio

    env = make_env(controller.env_id, controller.env_kwargs, render_mode="rgb_array")
    act = make_actor(controller, env)
    frames: list[np.ndarray] = []
    run_episode(env, act, seed, frames)
    env.close()
    imageio.mimsave(path, frames, fps=max(1, round(1.0 / env.unwrapped.dt)))


def build_controllers(args: argparse.Namespace) -> list[Controller]:
    """The policy (unless ``--no-policy``) and the two open-loop gaits, all under the same
    conditions: the env defaults, the policy's non-training env kwargs, then ``--env-kwargs``."""
    overrides = parse_kv_pairs(args.env_kwargs)
    controllers = []
    base: dict[str, Any] = {}
    if not args.no_policy:
        policy_dir = Path(args.policy)
        if not policy_dir.is_dir():
            raise SystemExit(f"no policy folder {policy_dir}; pass --policy RUN_DIR or --no-policy")
        config = run_config(policy_dir)
        if config is None:
            raise SystemExit(f"{policy_dir} has no config.yml: it defines the policy's env")
        env_id, hyperparams = config
        if normalize_kwargs(hyperparams) and latest_model(policy_dir)[1] is None:
            raise SystemExit(f"{policy_dir} was trained with VecNormalize but has no statistics")
        base = {
            k: v
            for k, v in (hyperparams.get("env_kwargs") or {}).items()
            if k not in TRAINING_ONLY_KWARGS
        }
        kwargs = {**base, **overrides}
        controllers.append(Controller("policy", env_id, kwargs, str(policy_dir)))
    acl_kwargs = {**base, **overrides}
    helix_kwargs = {k: v for k, v in base.items() if k not in GAIT_KWARGS} | overrides
    controllers.append(Controller("open_loop_acl", ACL_ID, acl_kwargs))
    controllers.append(Controller("open_loop_rolling_helix", ROLLING_HELIX_ID, helix_kwargs))
    return controllers


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    """Command line."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--policy", default=str(DEFAULT_POLICY), help="run or policy folder")
    parser.add_argument("--no-policy", action="store_true", help="open-loop controllers only")
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--seed", type=int, default=0, help="episode i resets with seed + i")
    parser.add_argument("--env-kwargs", nargs="*", default=[], metavar="KEY:VALUE")
    parser.add_argument("--json", metavar="PATH", help="write the summaries as JSON")
    parser.add_argument("--plot", metavar="FILE", help="COM height against time (png, pdf, ...)")
    parser.add_argument(
        "--video",
        metavar="FILE",
        help="mp4 of the first episode of the policy (of open-loop ACL with --no-policy)",
    )
    parser.add_argument("--workers", type=int, default=2, help="processes running episodes")
    parser.add_argument("--gym-packages", nargs="*", default=[], help="modules registering envs")
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser.parse_args(argv)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    """Evaluate, print the table, write the optional outputs; return the JSON document."""
    args = parse_args(argv)
    import_gym_packages(args.gym_packages)
    controllers = build_controllers(args)
    seeds = [args.seed + i for i in range(args.episodes)]
    results = evaluate(
        controllers, seeds, args.workers, tuple(args.gym_packages), not args.no_progress_bar
    )
    summaries = {name: summarize(episodes) for name, episodes in results.items()}
    document = {
        "controllers": summaries,
        "env_kwargs": {c.name: c.env_kwargs for c in controllers},
        "env_ids": {c.name: c.env_id for c in controllers},
        "policy": None if args.no_policy else str(args.policy),
        "ci": "two-sided 95 % confidence interval of the mean, Student's t distribution",
    }
    print(format_table(summaries))
    if args.json:
        Path(args.json).write_text(json.dumps(_jsonable(document), indent=2) + "\n")
    if args.plot:
        plot_heights(results, args.plot)
    if args.video:
        record_video(controllers[0], seeds[0], args.video)
    return document


def _jsonable(value: Any) -> Any:
    """Plain JSON: numpy scalars as Python numbers, NaN (undefined J/m) as null."""
    if isinstance(value, dict):
        return {k: _jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple):
        return [_jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


if __name__ == "__main__":
    main()
