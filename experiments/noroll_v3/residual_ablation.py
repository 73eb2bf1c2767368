"""Which joints' residual does a policy's work, and does it push against its bound?

``python experiments/noroll_v3/residual_ablation.py --policy DIR [--episodes 10] [--groups 0-3 0-9
10-19] [--env-kwargs KEY:VALUE ...] [--json PATH] [--plot PATH]``

Two questions about a joint-residual policy, answered on the same seeds (episode ``i`` resets
with seed ``i``):

* **where its effect lives**: the policy played with its residual zeroed on a group of joints
  (``--groups``, inclusive index ranges; joint 0 is at the head), beside the policy as trained
  and the zero action (its gait). A group whose zeroing removes a gain (or a roll) is where it
  comes from;
* **whether the bound limits it**: per joint, the mean ``|a|`` of the policy's own action and
  the share of steps at ``|a| > 0.95`` (the action range is [-1, 1], ``residual_scale`` radians
  per unit). A policy that sits at its bound on many joints may want more authority; one that
  uses a fraction of it is not limited by it.

Printed and in the JSON per controller: climb per gait cycle (mean and 95 % CI,
:func:`acl_env.evaluation.mean_ci95`), largest touched arc, falls and episodes ended by rolling
past ``roll_limit``; and the policy's per-joint action statistics. Cadence and gait-modulation
entries, if any, are never zeroed and not counted.
"""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env.evaluation import Policy, action_recorder, mean_ci95, run_episode, zero_policy
from acl_env.evaluation.tasks import evaluation_env_kwargs
from acl_env.io import console_script
from acl_env.scripts import parse_policy_args, policy_parser, save_figure, use_agg, write_outputs
from acl_env.training.policy import load_policy, read_policy_folder

SATURATED = 0.95  # |a| above this counts as at the bound
DEFAULT_GROUPS = ["0-3", "0-9", "10-19"]


def joint_range(text: str) -> tuple[int, int]:
    """``"A-B"`` (or ``"A"``) as an inclusive joint index range, checked A <= B."""
    first, _, last = text.partition("-")
    try:
        lo, hi = int(first), int(last or first)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected A-B joint indices, got {text!r}") from None
    if not 0 <= lo <= hi:
        raise argparse.ArgumentTypeError(f"expected 0 <= A <= B, got {text!r}")
    return lo, hi


def joint_columns(env: gymnasium.Env) -> np.ndarray:
    """Indices of the action entries that are joint residuals (``joint_<i>``), in joint order."""
    names = list(env.unwrapped.action_names)
    return np.array([names.index(f"joint_{i}") for i in range(env.unwrapped.n_joints)])


def masked(policy: Policy, columns: np.ndarray) -> Policy:
    """``policy`` with the action entries ``columns`` set to 0 (their gait unchanged)."""

    def act(obs: np.ndarray) -> np.ndarray:
        action = np.array(policy(obs), dtype=np.float32)
        action[columns] = 0.0
        return action

    return act


def summarize_episodes(name: str, played: list[Any]) -> dict[str, Any]:
    """One controller's row: climb per gait cycle, largest touched arc, falls and rolls."""
    metrics = [e.metrics() for e in played]
    return {
        "controller": name,
        "climb_per_gait_cycle_m": mean_ci95(m["climb_per_gait_cycle_m"] for m in metrics),
        "touched_arc_deg_max": max(m["touched_arc_deg"] for m in metrics),
        "falls": sum(e.fell for e in played),
        "rolled": sum(e.rolled for e in played),
    }


def run(
    policy_dir: Path,
    episodes: int,
    groups: list[tuple[int, int]],
    overrides: dict[str, Any],
    progress: bool = True,
    trust_pickles: bool = False,
) -> dict[str, Any]:
    """The policy, the policy with each group zeroed, and the zero action, on seeds 0..n-1."""
    folder = read_policy_folder(policy_dir)
    env = gymnasium.make(folder.env_id, **{**evaluation_env_kwargs(folder), **overrides})
    policy = load_policy(folder, env, trust_pickles=trust_pickles)
    columns = joint_columns(env)
    controllers: list[tuple[str, Any]] = [("policy", None)]
    controllers += [(f"policy, joints {lo}-{hi} zeroed", (lo, hi)) for lo, hi in groups]
    controllers.append(("zero action (its gait)", "zero"))
    rows = []
    actions, record = action_recorder()  # the policy's own actions, as trained
    bar = tqdm(total=len(controllers) * episodes, unit="ep", disable=not progress)
    for name, group in controllers:
        played = []
        for seed in range(episodes):
            if group is None:
                played.append(run_episode(env, policy, seed, callback=record))
            else:
                actor = (
                    zero_policy(env)
                    if group == "zero"
                    else masked(policy, columns[group[0] : group[1] + 1])
                )
                played.append(run_episode(env, actor, seed))
            bar.update()
        rows.append(summarize_episodes(name, played))
    bar.close()
    env.close()
    joint_actions = np.abs(np.array(actions)[:, columns])
    return {
        "policy": str(policy_dir),
        "env_id": folder.env_id,
        "residual_scale": float(env.unwrapped.config.gait.residual_scale),
        "episodes": episodes,
        "env_kwargs": overrides,
        "rows": rows,
        "mean_abs_action": joint_actions.mean(axis=0).tolist(),
        "saturated_share": (joint_actions > SATURATED).mean(axis=0).tolist(),
    }


def print_table(document: dict[str, Any]) -> None:
    """One Markdown row per controller, then the policy's action statistics."""
    print("| controller | climb per gait cycle (cm) | arc max (deg) | falls / rolled |")
    print("|---|---|---|---|")
    for row in document["rows"]:
        climb = row["climb_per_gait_cycle_m"]
        print(
            f"| {row['controller']} | {100 * climb['mean']:.2f} ± "
            f"{100 * climb['half_width']:.2f} | {row['touched_arc_deg_max']:.0f} | "
            f"{row['falls']} / {row['rolled']} |"
        )
    mean_abs = np.array(document["mean_abs_action"])
    saturated = np.array(document["saturated_share"])
    scale = document["residual_scale"]
    print(
        f"\npolicy's action: mean |a| {mean_abs.mean():.2f} ({scale * mean_abs.mean():.3f} rad), "
        f"share at |a| > {SATURATED}: {saturated.mean():.3f} "
        f"(largest {saturated.max():.2f}, joint {int(saturated.argmax())})"
    )


def plot(document: dict[str, Any], path: Path) -> None:
    """Per joint: the policy's mean |a| and its share of steps at the bound."""
    plt = use_agg()
    mean_abs = np.array(document["mean_abs_action"])
    saturated = np.array(document["saturated_share"])
    joints = np.arange(len(mean_abs))
    fig, ax = plt.subplots(figsize=(8, 3.5))
    ax.bar(joints - 0.2, mean_abs, 0.4, label="mean |a|")
    ax.bar(joints + 0.2, saturated, 0.4, label=f"share of steps at |a| > {SATURATED}")
    ax.set_xticks(joints)
    ax.set_xlabel("joint (0: head)")
    ax.set_ylim(0, 1)
    ax.set_title(
        f"{Path(document['policy']).name}: residual_scale {document['residual_scale']:g} rad, "
        f"{document['episodes']} seeds"
    )
    ax.legend(fontsize=8)
    save_figure(fig, path, 120, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = policy_parser(__doc__, episodes=10)
    parser.add_argument(
        "--groups",
        type=joint_range,
        nargs="*",
        default=[joint_range(g) for g in DEFAULT_GROUPS],
        metavar="A-B",
        help="joint ranges whose residual is zeroed, one controller each (0: head)",
    )
    args, env = parse_policy_args(parser, argv)
    n_joints = env.unwrapped.n_joints
    env.close()
    for lo, hi in args.groups:
        if hi >= n_joints:
            parser.error(f"--groups {lo}-{hi}: the snake's joints are 0-{n_joints - 1}")
    progress = not args.no_progress_bar
    document = run(
        args.policy, args.episodes, args.groups, args.env_kwargs, progress, args.trust_pickles
    )
    print_table(document)
    write_outputs(args, document, plot)
    return document


if __name__ == "__main__":
    console_script(main)()
