"""Where in the gait cycle does a policy slide less (or more) than its gait at the same cadence?

``python experiments/residual_limits/slip_by_phase.py [--policy DIR] [--episodes 10] [--bins 10]
[--env-kwargs KEY:VALUE ...] [--json PATH] [--plot PATH]``: the policy (deterministic, as
``acl-evaluate`` runs it) and its own base gait played open loop at the policy's mean cadence
(evaluation's ``open_loop_acl_same_cadence`` controller; a policy without a cadence action plays
one keyframe per step, and so does its gait), on the same reset seeds at default
conditions (or ``--env-kwargs``). Each step's contact slip, climb and actuator work (the env's
``info``) is binned by the gait phase the step ends at, and each bin is reported per gait cycle
executed. A policy that slides less overall can still slide more in some tenths of the cycle:
this shows where its corrections pay and where they cost.
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
from acl_env.evaluation import run_episode, steps_per_cycle
from acl_env.evaluation.baselines import (
    DEFAULT_POLICY,
    DEFAULT_TUNED_GAITS,
    POLICY_ACTION_KWARGS,
    SAME_CADENCE,
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
from acl_env.training.checks import check_env_kwargs
from acl_env.training.policy import read_policy_folder

TERMS = ("slip", "climb", "energy")


def binned_run(
    controller: Controller, seeds: list[int], bins: int, progress: bool
) -> tuple[dict[str, np.ndarray], float]:
    """Sum of each term per phase bin, divided by the gait cycles executed; and the mean cadence
    (keyframes per step)."""
    env = controller.make_env()
    policy = controller.make_policy(env)
    sums = {term: np.zeros(bins) for term in TERMS}
    keyframes = steps = 0.0

    def record(env: gymnasium.Env, obs: Any, action: Any, info: dict[str, Any]) -> None:
        if action is None:  # the reset
            return
        index = int((info["phase"] % 1.0) * bins) % bins
        for term in TERMS:
            sums[term][index] += info[term]

    for seed in tqdm(seeds, desc=controller.name, disable=not progress):
        episode = run_episode(env, policy, seed, callback=record)
        keyframes += episode.keyframes
        steps += episode.steps
    cycles = keyframes / steps_per_cycle(env)
    env.close()
    return {term: value / cycles for term, value in sums.items()}, keyframes / steps


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(
        __doc__, plot=True, plot_suffixes=(".png",), seed=0, episodes=10, env_kwargs=True,
        progress=True,
    )  # fmt: skip
    parser.add_argument("--policy", type=Path, default=DEFAULT_POLICY)
    add_trust_pickles(parser)
    parser.add_argument("--bins", type=cli.int_at_least(1), default=10, help="phase bins per cycle")
    args = parser.parse_args(argv)
    try:
        folder = read_policy_folder(args.policy)
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    overrides = args.env_kwargs
    built, _ = build_controllers(
        folder, overrides, None, DEFAULT_TUNED_GAITS, trust_pickles=args.trust_pickles
    )
    controllers = {c.name: c for c in built}
    try:
        check_env_kwargs(folder.env_id, controllers["policy"].env_kwargs).close()
    except ValueError as error:
        parser.error(f"argument --env-kwargs: {error}")
    played = seeds(args)
    progress = not args.no_progress_bar
    policy, rate = binned_run(controllers["policy"], played, args.bins, progress)
    if SAME_CADENCE in controllers:  # the policy sets the cadence: its gait at the mean rate
        own_gait = replace(controllers[SAME_CADENCE], phase_rate=rate)
    else:  # the policy's env and gait with a zero action (one keyframe per step, as the policy)
        kwargs = controllers["policy"].env_kwargs
        own_gait = Controller(
            "its gait",
            folder.env_id,
            {k: v for k, v in kwargs.items() if k not in POLICY_ACTION_KWARGS},
        )
    gait, _ = binned_run(own_gait, played, args.bins, progress)

    print(f"per gait cycle, by the phase a step ends at; open loop at {rate:.3f} keyframes/step")
    print(f"{'phase':>11} " + " ".join(f"{t + ' pol / gait':>26}" for t in TERMS))
    for b in range(args.bins):
        cells = [
            f"{policy[t][b]:9.4f} {gait[t][b]:9.4f} {policy[t][b] / gait[t][b]:5.2f}x"
            for t in TERMS
        ]
        print(
            f"{b / args.bins:5.2f}-{(b + 1) / args.bins:4.2f} "
            + " ".join(f"{c:>26}" for c in cells)
        )
    totals = [
        f"{policy[t].sum():9.4f} {gait[t].sum():9.4f} {policy[t].sum() / gait[t].sum():5.2f}x"
        for t in TERMS
    ]
    print(f"{'cycle':>11} " + " ".join(f"{c:>26}" for c in totals))
    document = {
        "policy": shown_path(args.policy),
        "env_kwargs": overrides,
        "seeds": played,
        "bins": args.bins,
        "phase_rate": rate,
        "note": "per gait cycle executed; bins by the gait phase each step ends at",
        "policy_per_bin": {t: policy[t].tolist() for t in TERMS},
        "gait_per_bin": {t: gait[t].tolist() for t in TERMS},
    }
    write_output(args.json, document)
    if args.plot:
        plot(policy, gait, rate, args.plot)
    return document


def plot(
    policy: dict[str, np.ndarray], gait: dict[str, np.ndarray], rate: float, path: Path
) -> None:
    """Slip and climb per phase bin, policy beside its gait at the same cadence."""
    plt = use_agg()
    bins = len(policy["slip"])
    centres = (np.arange(bins) + 0.5) / bins
    width = 0.4 / bins
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.6))
    for ax, term, unit in zip(
        axes, ("slip", "climb"), ("contact slip", "climb of the centre of mass"), strict=True
    ):
        ax.bar(centres - width / 2, policy[term], width, label="policy")
        ax.bar(centres + width / 2, gait[term], width, label=f"its gait, open loop at {rate:.2f}")
        ax.set_xlabel("gait phase (cycles)")
        ax.set_ylabel(f"{unit} (m per gait cycle)")
        ax.set_title(
            f"{term}: policy {policy[term].sum():.4f}, gait {gait[term].sum():.4f} m/cycle"
        )
    axes[0].legend(fontsize=8)
    save_figure(fig, path, 120, tight=True)


if __name__ == "__main__":
    console_script(main)()
