"""What a policy does when the pole turns slippery: its grip and cadence actions, the spring
torques, the slip and the climb, aligned at the friction step.

``python experiments/friction_step/slip_response.py [--policy DIR] [--episodes 10]
[--friction 0.5] [--env-kwargs KEY:VALUE ...] [--json PATH] [--plot PATH]``

The policy (deterministic, as ``acl-evaluate`` plays it), its compliant controller at the policy's
mean cadence (``compliant_acl_same_cadence``: the same env and grip loop with a zero residual, so
what the policy adds) and the paper's gait (``open_loop_acl``) play the same reset seeds with
``friction_step=--friction``: on a seed every controller meets the step at the same step.
Each episode's per-step trace is aligned at its step (``info["slippery"]`` turning true) and
averaged over the seeds, from ``--before`` s before it to ``--after`` s after (an episode that
ends sooner, at its time limit or by a fall, drops out of the later bins; each bin's count is
recorded).
"""

from __future__ import annotations

import os
from dataclasses import replace
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import cli
from acl_env.evaluation import run_episode
from acl_env.evaluation.baselines import (
    COMPLIANT_SAME_CADENCE,
    DEFAULT_TUNED_GAITS,
    Controller,
    build_controllers,
)
from acl_env.evaluation.tasks import shown_path
from acl_env.io import console_script
from acl_env.scripts import (
    add_trust_pickles,
    make_parser,
    save_figure,
    seeds,
    use_agg,
    write_output,
)
from acl_env.shipped import policy_dir
from acl_env.training.policy import read_policy_folder

DEFAULT_POLICY = policy_dir("acl_climb_compliant_ppo")
PLAYED = ("policy", COMPLIANT_SAME_CADENCE, "open_loop_acl")
TRACES = ("climb_cm_s", "slip_cm_s", "spring_torque_nm", "grip_action", "cadence_action")


def episode_traces(controller: Controller, seed: int) -> tuple[dict[str, np.ndarray], int, float]:
    """One episode's per-step traces, the index of the first slippery step, and the mean
    cadence (keyframes per step)."""
    env = controller.make_env()
    policy = controller.make_policy(env)
    names = list(getattr(env.unwrapped, "action_names", []) or [])
    grip = [i for i, n in enumerate(names) if n.startswith("grip_section")]
    cadence = names.index("cadence") if "cadence" in names else None
    dt = float(env.unwrapped.dt)
    rows: dict[str, list[float]] = {name: [] for name in TRACES}
    slippery: list[bool] = []

    def record(env: gymnasium.Env, obs: Any, action: Any, info: dict[str, Any]) -> None:
        if action is None:
            return
        played = np.asarray(action, dtype=float)
        rows["climb_cm_s"].append(100.0 * info["climb"] / dt)
        rows["slip_cm_s"].append(100.0 * info["slip"] / dt)
        rows["spring_torque_nm"].append(float(np.abs(env.unwrapped.data.actuator_force).mean()))
        rows["grip_action"].append(float(played[grip].mean()) if grip else np.nan)
        rows["cadence_action"].append(float(played[cadence]) if cadence is not None else np.nan)
        slippery.append(bool(info.get("slippery", False)))

    episode = run_episode(env, policy, seed, callback=record)
    env.close()
    at = slippery.index(True) if any(slippery) else -1
    return {k: np.asarray(v) for k, v in rows.items()}, at, episode.keyframes / episode.steps


def aligned(
    runs: list[tuple[dict[str, np.ndarray], int]], before: int, after: int
) -> dict[str, Any]:
    """Mean of each trace over the episodes, at each step from ``-before`` to ``after - 1``
    relative to the step; and how many episodes each bin holds."""
    width = before + after
    sums = {name: np.zeros(width) for name in TRACES}
    counts = np.zeros(width)
    for traces, at in runs:
        if at < 0:
            continue
        for j in range(width):
            k = at - before + j
            if 0 <= k < len(traces["climb_cm_s"]):
                counts[j] += 1
                for name in TRACES:
                    sums[name][j] += traces[name][k]
    with np.errstate(invalid="ignore", divide="ignore"):
        means = {name: (sums[name] / counts).tolist() for name in TRACES}
    return {**means, "episodes": counts.astype(int).tolist()}


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(
        __doc__, plot=True, plot_suffixes=(".png",), seed=0, episodes=10, env_kwargs=True,
        progress=True,
    )  # fmt: skip
    parser.add_argument("--policy", type=Path, default=DEFAULT_POLICY)
    add_trust_pickles(parser)
    parser.add_argument("--friction", type=cli.positive_float, default=0.5, help="after the step")
    parser.add_argument("--before", type=cli.positive_float, default=3.0, help="s shown before")
    parser.add_argument("--after", type=cli.positive_float, default=8.0, help="s shown after")
    args = parser.parse_args(argv)
    try:
        folder = read_policy_folder(args.policy)
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    overrides = {**args.env_kwargs, "friction_step": args.friction}
    built, _ = build_controllers(
        folder, overrides, None, DEFAULT_TUNED_GAITS, trust_pickles=args.trust_pickles
    )
    controllers = {c.name: c for c in built}
    played = seeds(args)
    runs: dict[str, list[tuple[dict[str, np.ndarray], int]]] = {}
    rate = 1.0
    for name in PLAYED:
        controller = controllers[name]
        if name == COMPLIANT_SAME_CADENCE:
            controller = replace(controller, phase_rate=rate)
        results = [
            episode_traces(controller, seed)
            for seed in tqdm(played, desc=name, disable=args.no_progress_bar)
        ]
        if name == "policy":
            rate = float(np.mean([r[2] for r in results]))
        runs[name] = [(traces, at) for traces, at, _ in results]
    dt = float(controllers["policy"].make_env().unwrapped.dt)
    before, after = round(args.before / dt), round(args.after / dt)
    document = {
        "policy": shown_path(args.policy),
        "env_kwargs": overrides,
        "seeds": played,
        "dt": dt,
        "policy_cadence": rate,
        "time_s": (dt * (np.arange(-before, after) + 0.5)).tolist(),
        "controllers": {name: aligned(runs[name], before, after) for name in PLAYED},
    }
    write_output(args.json, document)
    if args.plot:
        plot(document, args.plot)
    return document


LABELS = {
    "policy": "residual policy",
    COMPLIANT_SAME_CADENCE: "its compliant controller, same cadence",
    "open_loop_acl": "the paper's gait",
}
PANELS = (
    ("climb_cm_s", "climb of the centre of mass (cm/s)"),
    ("slip_cm_s", "contact slip (cm/s)"),
    ("spring_torque_nm", "mean |spring torque| (N m)"),
    ("grip_action", "policy's actions"),
)


def plot(document: dict[str, Any], path: Path) -> None:
    """Four panels against the time since the step: climb, slip, spring torque, actions."""
    plt = use_agg()
    t = np.asarray(document["time_s"])
    fig, axes = plt.subplots(1, 4, figsize=(16, 3.6), sharex=True)
    for ax, (key, title) in zip(axes, PANELS, strict=True):
        if key == "grip_action":
            trace = document["controllers"]["policy"]
            ax.plot(t, trace["grip_action"], label="grip target (mean of sections)")
            ax.plot(t, trace["cadence_action"], label="cadence")
            ax.axhline(0.0, color="0.6", lw=0.6)
        else:
            for name, trace in document["controllers"].items():
                ax.plot(t, trace[key], label=LABELS[name])
        ax.axvline(0.0, color="k", ls="--", lw=0.8)
        ax.set_title(title, fontsize=10)
        ax.set_xlabel("time since the pole turned slippery (s)")
    axes[0].legend(fontsize=8)
    axes[3].legend(fontsize=8)
    fig.suptitle(
        f"friction 1.0 -> {document['env_kwargs']['friction_step']} at t = 0, "
        f"mean of {len(document['seeds'])} episodes; {shown_path(document['policy'])}",
        fontsize=10,
    )
    save_figure(fig, path, dpi=110, tight=True)


if __name__ == "__main__":
    console_script(main)()
