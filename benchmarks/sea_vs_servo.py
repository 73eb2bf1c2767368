"""Open-loop climbing on the series elastic actuators against the ideal servo, on the same seeds.

``python benchmarks/sea_vs_servo.py [--seeds 10] [--json PATH] [--plot PATH]``

Each gait plays two cycles with a zero action, once per reset seed, on the servo
(``actuator_model="servo"``, the v1/v2 physics) and on the SEA (the v3 physics, with its default
spring, motor speed and latencies). Per gait: climb per gait cycle, slip per metre and energy per
metre on each, and the paired SEA - servo difference with its 95 % interval (the same seeds, so
the same start poses). The gaits: the paper's ACL (Eq. 1-5), the tuned ACL of the servo (``acl``)
and of the SEA (``acl_sea``), the rolling helix, and the non-rolling task's gaits (``acl_noroll``,
and ``acl_noroll_sea`` tuned on the SEA).
"""

from __future__ import annotations

from typing import Any

import gymnasium
import numpy as np
from tqdm import tqdm

from acl_env import ACL_CLIMB_ID, ACL_CLIMB_NOROLL_ID, ROLLING_HELIX_CLIMB_ID, cli, tuned_gaits
from acl_env.evaluation import run_episode, zero_policy
from acl_env.evaluation.intervals import mean_ci95
from acl_env.evaluation.summary import PAIRED_METRICS, summarize
from acl_env.io import console_script
from acl_env.scripts import make_parser, save_figure, use_agg, write_outputs

GAITS: dict[str, tuple[str, dict[str, Any]]] = {
    "ACL (paper)": (ACL_CLIMB_ID, {}),
    "tuned ACL (acl)": (ACL_CLIMB_ID, {"tuned_gait": "acl"}),
    "tuned ACL on the SEA (acl_sea)": (ACL_CLIMB_ID, {"tuned_gait": "acl_sea"}),
    "rolling helix": (ROLLING_HELIX_CLIMB_ID, {}),
    "non-rolling (acl_noroll)": (ACL_CLIMB_NOROLL_ID, {}),
    "non-rolling on the SEA (acl_noroll_sea)": (
        ACL_CLIMB_NOROLL_ID,
        tuned_gaits.gait_shape("acl_noroll_sea"),
    ),
}
MODELS = ("servo", "sea")
METRICS = PAIRED_METRICS[:3]  # climb per gait cycle, slip per metre, energy per metre


def compare(seeds: int) -> dict[str, Any]:
    """Per gait and actuator model the summary, and the paired SEA - servo differences."""
    table: dict[str, Any] = {}
    for name, (env_id, kwargs) in GAITS.items():
        summaries = {}
        for model in MODELS:
            env = gymnasium.make(env_id, **kwargs, actuator_model=model)
            episodes = [
                run_episode(env, zero_policy(env), seed)
                for seed in tqdm(range(seeds), desc=f"{name}, {model}", leave=False)
            ]
            env.close()
            summaries[model] = summarize(episodes)
        row: dict[str, Any] = {"falls": {m: summaries[m]["falls"]["count"] for m in MODELS}}
        for metric in METRICS:
            servo, sea = (summaries[m][metric]["values"] for m in MODELS)
            pairs = [b - a for a, b in zip(servo, sea, strict=True) if None not in (a, b)]
            row[metric] = {m: summaries[m][metric]["mean"] for m in MODELS}
            row[metric]["sea_minus_servo"] = mean_ci95(pairs)
        table[name] = row
    return table


def print_table(table: dict[str, Any]) -> None:
    units = {"climb_per_gait_cycle_m": 100.0, "slip_per_m": 1.0, "energy_per_m": 1.0}
    print("| gait | climb (cm/cycle) servo / SEA | slip per m servo / SEA | J/m servo / SEA |")
    print("|---|---|---|---|")
    for name, row in table.items():
        cells = []
        for metric in METRICS:
            k = units[metric]
            d = row[metric]["sea_minus_servo"]
            cells.append(
                f"{k * row[metric]['servo']:.3g} / {k * row[metric]['sea']:.3g} "
                f"({k * d['mean']:+.2g} ± {k * d['half_width']:.2g})"
            )
        print(f"| {name} | " + " | ".join(cells) + " |")


def plot(table: dict[str, Any], path: Any) -> None:
    plt = use_agg()
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8))
    names = list(table)
    x = np.arange(len(names))
    titles = ("climb per gait cycle (cm)", "slip per metre", "energy per metre (J)")
    scale = (100.0, 1.0, 1.0)
    for ax, metric, title, k in zip(axes, METRICS, titles, scale, strict=True):
        for offset, model in ((-0.2, "servo"), (0.2, "sea")):
            ax.bar(x + offset, [k * table[n][metric][model] for n in names], 0.4, label=model)
        ax.set_xticks(x, [n.split(" (")[0] for n in names], rotation=30, ha="right", fontsize=7)
        ax.set_title(title)
    axes[0].legend()
    fig.suptitle("Open loop on the ideal servo and on the series elastic actuators (same seeds)")
    save_figure(fig, path, dpi=110, tight=True)


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = make_parser(__doc__, json=True, plot=True)
    parser.add_argument("--seeds", type=cli.int_at_least(2), default=10, help="episodes per cell")
    args = parser.parse_args(argv)
    table = compare(args.seeds)
    print_table(table)
    write_outputs(args, table, plot)
    return table


if __name__ == "__main__":
    console_script(main)()
