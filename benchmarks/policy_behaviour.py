"""What the residual policy on the compliant grip does, by phase of the gait cycle.

``python benchmarks/policy_behaviour.py [--policy DIR] [--seed 0] [--episodes 10] [--json PATH]
[--plot PATH]``

Plays the policy (default: the shipped ``acl_climb_compliant_ppo``) at its env's defaults, then
``compliant_acl`` and the tuned open loop at the policy's mean cadence, when it sets one (the
controllers and kwargs of ``acl-evaluate``), on the same seeds. Per eighth of the gait cycle it
gives each one's slip and climb (mm per gait cycle, mean over episodes) and, for the policy and
``compliant_acl``, the mean grip target and squeeze offset of each body section
(:mod:`acl_env.envs.grip`); for the policy also its joint residual (RMS, rad) and cadence
(keyframes per step). Two ablations split the policy's gain: the policy with its grip-target
actions held at zero (the tuned targets) and with its joint residuals held at zero;
``acl-evaluate``'s table and paired differences say what each group is worth.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Any

import numpy as np
from tqdm import tqdm

from acl_env import cli, shipped
from acl_env.envs.grip import GRIP_RANGE
from acl_env.envs.observations import env_observation_names
from acl_env.evaluation import baselines, tasks
from acl_env.evaluation.protocol import Episode, run_episode
from acl_env.evaluation.summary import paired_differences, summarize
from acl_env.evaluation.tables import format_paired, format_table
from acl_env.io import console_script
from acl_env.scripts import make_parser, save_figure, seeds, use_agg, write_outputs

BINS = 8  # eighths of the gait cycle
# Ablations: the policy with the action entries whose names start so held at zero
ABLATIONS = {
    "policy_without_grip_actions": "grip_section_",
    "policy_without_joint_residuals": "joint_",
}
# compliant_acl at the policy's cadence, or at the gait's when the policy does not set it
COMPLIANTS = (baselines.COMPLIANT_SAME_CADENCE, baselines.COMPLIANT)
# The tuned open loop at the policy's cadence: its own name, or the policy's gait's when that is it
OPEN_LOOPS = (baselines.TUNED_SAME_CADENCE, baselines.SAME_CADENCE, "open_loop_tuned")


class PhaseSums:
    """Per-eighth sums of one controller's steps over its episodes."""

    def __init__(self, env: Any) -> None:
        base = env.unwrapped  # an ACLClimbEnv: its options, action and observation names
        sections = base.config.gait.modulation_sections
        self.count = np.zeros(BINS)
        self.slip, self.climb = np.zeros(BINS), np.zeros(BINS)
        self.target, self.offset = np.zeros((BINS, sections)), np.zeros((BINS, sections))
        self.residual, self.rate = np.zeros(BINS), np.zeros(BINS)
        self.episodes: list[Episode] = []  # as acl-evaluate measures them
        self.keyframes, self.steps_per_cycle = 0.0, base.steps_per_cycle
        self.n_joints, self.residual_scale = base.n_joints, base.config.gait.residual_scale
        # The grip's target and offsets, as the policy sets and observes them (None: no grip)
        grip = base.config.grip
        self.grip_target = None if grip is None else grip.target
        self.grip_scale = 0.0 if grip is None else grip.action_scale
        self.grip_actions = [i for i, n in enumerate(base.action_names) if n.startswith("grip_")]
        names = env_observation_names(base)
        first = names.index("grip_offset_0") if "grip_offset_0" in names else 0
        self.offset_obs = slice(first, first + sections)

    def add(self, env: Any, obs: np.ndarray, action: Any, info: dict[str, Any]) -> None:
        """A :func:`~acl_env.evaluation.protocol.run_episode` callback."""
        if action is None:
            return
        b = min(int(info["phase"] * BINS), BINS - 1)
        self.count[b] += 1
        self.slip[b] += info["slip"]
        self.climb[b] += info["climb"]
        self.rate[b] += info["phase_rate"]
        self.keyframes += info["phase_rate"]
        played = np.clip(np.asarray(action, dtype=float), -1.0, 1.0)  # as the env plays it
        rms = float(np.sqrt(np.mean(played[: self.n_joints] ** 2)))
        self.residual[b] += self.residual_scale * rms
        if self.grip_target is not None:
            self.offset[b] += obs[self.offset_obs] * GRIP_RANGE
            moved = self.grip_scale * played[self.grip_actions] if self.grip_actions else 0.0
            self.target[b] += self.grip_target + moved

    def summary(self) -> dict[str, Any]:
        """Slip and climb in mm per gait cycle; the rest as means over each eighth's steps."""
        cycles = self.keyframes / self.steps_per_cycle
        n = np.maximum(self.count, 1)
        return {
            "slip_mm": (1e3 * self.slip / cycles).tolist(),
            "climb_mm": (1e3 * self.climb / cycles).tolist(),
            "slip_per_m_of_sums": float(self.slip.sum() / self.climb.sum()),
            "grip_target_n": (self.target / n[:, None]).tolist(),
            "squeeze_offset_mm": (1e3 * self.offset / n[:, None]).tolist(),
            "residual_rms_rad": (self.residual / n).tolist(),
            "phase_rate": (self.rate / n).tolist(),
        }


def play(
    controller: baselines.Controller,
    seed_list: list[int],
    progress: bool,
    zeroed: str | None = None,
    name: str | None = None,
) -> PhaseSums:
    """``controller`` on ``seed_list``; ``zeroed``: its action entries named so held at zero."""
    env = controller.make_env()
    policy = acting = controller.make_policy(env)
    if zeroed is not None:
        keep = np.array([not n.startswith(zeroed) for n in env.unwrapped.action_names])

        def policy(obs: np.ndarray) -> np.ndarray:
            return acting(obs) * keep

    sums = PhaseSums(env)
    for seed in tqdm(seed_list, desc=name or controller.name, disable=not progress):
        sums.episodes.append(run_episode(env, policy, seed, callback=sums.add))
    env.close()
    return sums


def plot(document: dict, path: Path) -> None:
    plt = use_agg()
    fig, axes = plt.subplots(2, 2, figsize=(11, 7), sharex=True)
    x = (np.arange(BINS) + 0.5) / BINS
    phases = document["by_phase"]
    for name, marker in zip(document["shown"], "osd", strict=True):
        axes[0, 0].plot(x, phases[name]["slip_mm"], marker=marker, label=name)
    axes[0, 0].set_ylabel("slip per eighth (mm per gait cycle)")
    axes[0, 0].set_title("slip by phase")
    policy, compliant = phases["policy"], phases[document["shown"][1]]
    offsets = np.asarray(policy["squeeze_offset_mm"])
    for s in range(offsets.shape[1]):
        line = axes[0, 1].plot(x, offsets[:, s], marker="o", label=f"policy, section {s}")
        axes[0, 1].plot(
            x, np.asarray(compliant["squeeze_offset_mm"])[:, s], ls="--", color=line[0].get_color()
        )
    axes[0, 1].set_ylabel("squeeze offset (mm; dashed: compliant_acl)")
    axes[0, 1].set_title("the grip loop's squeeze, per section")
    targets = np.asarray(policy["grip_target_n"])
    for s in range(targets.shape[1]):
        axes[1, 0].plot(x, targets[:, s], marker="o", label=f"section {s}")
    axes[1, 0].axhline(np.asarray(compliant["grip_target_n"])[0, 0], color="k", ls="--", lw=1)
    axes[1, 0].set_ylabel("grip target (N; dashed: the tuned one)")
    axes[1, 0].set_title("the policy's grip targets")
    axes[1, 1].plot(x, policy["residual_rms_rad"], marker="o", color="C0", label="residual RMS")
    axes[1, 1].set_ylabel("joint residual RMS (rad)")
    twin = axes[1, 1].twinx()
    twin.plot(x, policy["phase_rate"], marker="s", color="C3", label="cadence")
    twin.set_ylabel("cadence (keyframes per step)", color="C3")
    twin.set_ylim(0.0, 1.1 * max(policy["phase_rate"]))
    axes[1, 1].set_title("the policy's residual and cadence")
    for ax in axes.flat:
        ax.grid(alpha=0.3)
        ax.legend(fontsize=10)  # the docs show the figure about 690 px wide
    for ax in axes[1]:
        ax.set_xlabel("phase of the gait cycle")
    fig.suptitle(f"{document['env_id']}: {document['policy_dir']}, {len(document['seeds'])} seeds")
    save_figure(fig, path, dpi=110, tight=True)


def _row(values: Any, fmt: str = "6.1f") -> str:
    return " ".join(f"{v:{fmt}}" for v in values)


def main(argv: list[str] | None = None) -> dict:
    parser = make_parser(__doc__, json=True, plot=True, seed=0, episodes=10, progress=True)
    parser.add_argument(
        "--policy",
        type=cli.existing_dir,
        default=shipped.policy_dir("acl_climb_compliant_ppo"),
        help="a pretrained policy folder on a compliant task",
    )
    args = parser.parse_args(argv)
    try:
        folder = baselines.read_policy(args.policy)
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    controllers, _ = baselines.build_controllers(folder, {}, None, baselines.DEFAULT_TUNED_GAITS)
    by_name = {c.name: c for c in controllers}
    compliant = next((name for name in COMPLIANTS if name in by_name), None)
    open_loop = next((name for name in OPEN_LOOPS if name in by_name), None)
    if compliant is None or open_loop is None:
        parser.error("argument --policy: not a policy on a compliant task (acl_env/*Compliant-*)")
    shown = ("policy", compliant, open_loop)
    seed_list, progress = seeds(args), not args.no_progress_bar
    results = {"policy": play(by_name["policy"], seed_list, progress)}
    rate = summarize(results["policy"].episodes)["mean_phase_rate"]
    for name in shown[1:]:
        at_rate = by_name[name]
        if name in baselines.AT_POLICY_CADENCE:
            at_rate = dataclasses.replace(at_rate, phase_rate=rate)
        results[name] = play(at_rate, seed_list, progress)
    for name, prefix in ABLATIONS.items():
        results[name] = play(by_name["policy"], seed_list, progress, prefix, name)
    summaries = {name: summarize(sums.episodes) for name, sums in results.items()}
    document = {
        "env_id": folder.env_id,
        "policy_dir": tasks.shown_path(args.policy),
        "seeds": seed_list,
        "phase_rate": rate,
        "shown": list(shown),
        "ablations": {
            name: f"the policy, its {prefix}* actions held at 0"
            for name, prefix in ABLATIONS.items()
        },
        "by_phase": {name: sums.summary() for name, sums in results.items()},
        "summaries": summaries,
        "paired_vs_policy": paired_differences(summaries),
    }
    print(format_table(summaries))
    print(format_paired(document["paired_vs_policy"], "policy"))
    phases = document["by_phase"]
    for name in shown:
        print(f"{name:30s} slip by eighth (mm/cycle): " + _row(phases[name]["slip_mm"]))
    for key in ("grip_target_n", "squeeze_offset_mm"):
        for name in shown[:2]:
            for s, row in enumerate(np.asarray(phases[name][key]).T):
                print(f"{name:30s} {key} {s}: " + _row(row))
    print("policy residual RMS (rad):", _row(phases["policy"]["residual_rms_rad"], ".3f"))
    print("policy cadence:", _row(phases["policy"]["phase_rate"], ".2f"))
    write_outputs(args, document, plot)
    return document


if __name__ == "__main__":
    console_script(main)()
