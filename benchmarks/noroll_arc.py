"""Each module's touched arc on the non-rolling task: open loop against a policy.

``python benchmarks/noroll_arc.py [--policy FOLDER] [--episodes 5] [--plot PATH] [--json PATH]
[--env-kwargs KEY:VALUE ...]`` (``--out`` is ``--plot``; default ``runs/noroll_arc.png``)

Controllers, episode ``i`` of each resetting with seed ``seed + i``
(:func:`acl_env.evaluation.runner.run_controllers`, :func:`acl_env.evaluation.run_episode`):

* ``open_loop_noroll``: ``acl_env/ACLClimbNoRollBase-v3`` with a zero action (the policy's env
  and its non-training kwargs when ``--policy`` is given, its gait included, so both run under the
  same conditions);
* ``open_loop_tuned_noroll``: the tuner's non-rolling gait (``acl_noroll`` of the shipped tuned
  gaits, :mod:`acl_env.tuned_gaits`; ``acl_noroll_v2`` for a policy on ``ACLClimbNoRollBase-v2``)
  on the same env, when it differs from the gait ``open_loop_noroll`` plays;
* ``policy``: the policy folder (deterministic, VecNormalize frozen), with ``--policy``;
* ``open_loop_rolling_acl``: the rolling ACL (``acl_env/ACLClimbPaperGait-v1``), for reference.

Prints, per controller, the largest touched arc of any module (mean and max over episodes) and
the modules above the task's 90-degree target; draws each module's touched arc (bars: mean over
episodes, whiskers: the largest) and where on each module's circumference the pole touched
(share of episodes per 10-degree bin, angle about the module's axis from its y axis), as
:data:`acl_env.evaluation.METRICS`' ``touched_arc_deg`` measures it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

os.environ.setdefault("MUJOCO_GL", "egl")

import gymnasium
import numpy as np

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID, cli
from acl_env.evaluation import Episode
from acl_env.evaluation.baselines import DEFAULT_TUNED_GAITS, Controller
from acl_env.evaluation.runner import evaluate
from acl_env.evaluation.tasks import evaluation_env_kwargs, tuned_gait
from acl_env.io import console_script
from acl_env.scripts import (
    RUNS,
    add_trust_pickles,
    make_parser,
    save_figure,
    seeds,
    use_agg,
    write_output,
)
from acl_env.training.policy import read_policy_folder

ARC_TARGET_DEG = 90.0  # the non-rolling task's target: at most 90 deg on every module and episode


def build(
    policy: Path | None, overrides: dict[str, Any], tuned_path: Path, trust_pickles: bool = False
) -> tuple[list[Controller], list[str]]:
    """The controllers to compare (see the module docstring) and notes on what was skipped."""
    env_id, base, notes = ACL_CLIMB_NOROLL_ID, dict(overrides), []
    controllers = []
    if policy is not None:
        folder = read_policy_folder(policy)
        env_id = folder.env_id
        base = {**evaluation_env_kwargs(folder), **overrides}
        controllers.append(
            Controller("policy", env_id, base, str(folder.path), trust_pickles=trust_pickles)
        )
    controllers.insert(0, Controller("open_loop_noroll", env_id, base))
    played = {**(gymnasium.spec(env_id).kwargs or {}), **base}  # what open_loop_noroll plays
    tuned, note = tuned_gait(tuned_path, played.get("reward_weights"), True, env_id=env_id)
    if tuned is None:
        notes.append(f"open_loop_tuned_noroll: skipped, {note}")
    elif all(played.get(k) == v for k, v in tuned[1].items()):
        notes.append("open_loop_tuned_noroll: open_loop_noroll plays the tuned gait")
    else:
        kwargs = {**base, **tuned[1]}
        controllers.insert(1, Controller("open_loop_tuned_noroll", env_id, kwargs))
        notes.append(f"open_loop_tuned_noroll: {note}")
    rolling = {k: v for k, v in overrides.items() if k not in ("gait_kwargs", "reward_weights")}
    controllers.append(Controller("open_loop_rolling_acl", ACL_CLIMB_ID, rolling))
    return controllers, notes


def arc_summary(episodes: list[Episode]) -> dict[str, Any]:
    """Per module: touched arc per episode, and the share of episodes touching each bin."""
    arcs = np.array([e.touched_arcs_deg for e in episodes])  # episodes x modules
    bins = np.mean([e.touched_bins for e in episodes], axis=0)  # modules x bins
    return {
        "arc_deg_per_episode": arcs,
        "largest_arc_deg": arcs.max(axis=1),
        "modules_over_target": sorted({int(m) for m in np.argwhere(arcs > ARC_TARGET_DEG)[:, 1]}),
        "bin_touch_share": bins,
        "falls": sum(e.fell for e in episodes),
        "rolled": sum(e.rolled for e in episodes),
        "climb_per_gait_cycle_m": [e.metrics()["climb_per_gait_cycle_m"] for e in episodes],
    }


def plot(summaries: dict[str, dict[str, Any]], path: Path) -> None:
    """Bars of each module's touched arc; below, where each module touched, per controller."""
    plt = use_agg()
    names = list(summaries)
    fig = plt.figure(figsize=(11, 3.2 + 2.6 * len(names)), constrained_layout=True)
    grid = fig.add_gridspec(1 + len(names), 1, height_ratios=[1.4] + [1.0] * len(names))
    ax = fig.add_subplot(grid[0])
    width = 0.8 / len(names)
    for i, name in enumerate(names):
        arcs = summaries[name]["arc_deg_per_episode"]
        modules = np.arange(arcs.shape[1])
        mean, top = arcs.mean(axis=0), arcs.max(axis=0)
        x = modules + (i - (len(names) - 1) / 2) * width
        ax.bar(x, mean, width, label=name)
        ax.errorbar(x, mean, yerr=[np.zeros_like(mean), top - mean], fmt="none", ecolor="k", lw=0.6)
    ax.axhline(ARC_TARGET_DEG, color="k", ls="--", lw=0.8, label="target: 90 deg")
    ax.set_xlabel("module (0 = head)")
    ax.set_xticks(range(0, len(mean), 2))
    ax.set_ylabel("touched arc (deg)")
    ax.set_ylim(0, 370)
    ax.set_yticks(range(0, 361, 90))
    episodes = len(next(iter(summaries.values()))["largest_arc_deg"])
    ax.set_title(f"touched arc per module: mean over {episodes} episodes, whisker: largest")
    ax.legend(fontsize=10, ncol=2)  # the docs show the figure about 690 px wide
    for row, name in enumerate(names, start=1):
        share = summaries[name]["bin_touch_share"]
        axh = fig.add_subplot(grid[row])
        image = axh.imshow(
            share.T,
            origin="lower",
            aspect="auto",
            cmap="viridis",
            vmin=0.0,
            vmax=1.0,
            extent=(-0.5, share.shape[0] - 0.5, 0.0, 360.0),
        )
        axh.set_yticks(range(0, 361, 90))
        axh.set_xticks(range(0, share.shape[0], 2))
        axh.set_ylabel("angle about\nmodule axis (deg)")
        axh.set_title(f"{name}: where the pole touched (share of episodes)", fontsize=9)
        fig.colorbar(image, ax=axh, fraction=0.02)
    axh.set_xlabel("module (0 = head)")
    save_figure(fig, path, 110)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(
        __doc__, plot=True, plot_names=("--plot", "--out"), plot_default=RUNS / "noroll_arc.png",
        seed=0, episodes=5, workers=2, env_kwargs=True,
    )  # fmt: skip
    parser.add_argument("--policy", type=cli.existing_dir, help="policy or run folder")
    add_trust_pickles(parser)
    parser.add_argument("--tuned-gaits", type=Path, default=DEFAULT_TUNED_GAITS)
    args = parser.parse_args(argv)
    overrides = args.env_kwargs
    try:
        controllers, notes = build(args.policy, overrides, args.tuned_gaits, args.trust_pickles)
        for controller in controllers:
            controller.make_env().close()  # bad kwargs or folder: refused before any episode
    except (ValueError, TypeError) as error:
        parser.error(str(error))
    played = seeds(args)
    results = evaluate(controllers, played, min(args.workers, len(controllers) * len(played)))
    summaries = {name: arc_summary(episodes) for name, episodes in results.items()}
    for name, s in summaries.items():
        largest = s["largest_arc_deg"]
        climb = np.mean(s["climb_per_gait_cycle_m"])
        print(
            f"{name:24s} largest touched arc {largest.mean():5.0f} deg mean, {largest.max():3.0f}"
            f" max; modules over 90: {s['modules_over_target'] or 'none'}; climb per gait cycle"
            f" {climb:.4f} m; falls {s['falls']}, rolled {s['rolled']} of {len(played)}"
        )
    for note in notes:
        print(note)
    plot(summaries, args.plot)
    document = {
        "controllers": summaries,
        "env_ids": {c.name: c.env_id for c in controllers},
        "env_kwargs": {c.name: c.env_kwargs for c in controllers},
        "seeds": played,
        "notes": notes,
    }
    write_output(args.json, document, indent=1)
    return document


if __name__ == "__main__":
    console_script(main)()
