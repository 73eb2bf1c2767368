"""How does an open-loop gait's reward per gait cycle change with the cadence it is played at?

``python experiments/acl_cadence/cadence_sweep.py [--tuned-gaits FILE ...] [--rates 1.0 1.1 ...]
[--episodes 10] [--policy-point EVAL_JSON[=LABEL] ...] [--json PATH] [--plot PATH]`` plays the
``acl`` entry of each tuned-gaits file open loop at constant cadences (gait keyframes per env
step, as the evaluation's ``open_loop_acl_same_cadence`` does for a policy that sets the cadence),
on the same reset seeds for every gait and rate, under the same reward weights
(``--reward-weights``, default the shipped recipe's), and prints climb, slip, energy and reward
per gait cycle (mean and 95 % CI). ``--policy-point`` marks a policy's (mean cadence, reward per
gait cycle) from an evaluation JSON of ``acl-evaluate``.

A residual policy with the cadence action is compared with open loops at its own cadence; this
shows what the cadence alone is worth to each open loop, and which gait is the best open loop at
each cadence.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from acl_env import ACL_CLIMB_ID, shipped, tuned_gaits
from acl_env.envs.rewards import check_reward_weights
from acl_env.evaluation import summarize
from acl_env.evaluation.baselines import Controller
from acl_env.evaluation.records import controller_summary, read_record
from acl_env.evaluation.runner import evaluate
from acl_env.evaluation.tasks import shown_path, tuned_gait
from acl_env.io import console_script
from acl_env.scripts import KeyValues, make_parser, save_figure, use_agg, write_output
from acl_env.training import config

EXPERIMENTS = Path(__file__).resolve().parent.parent
DEFAULT_GAITS = (
    tuned_gaits.shipped_path(),
    EXPERIMENTS / "acl_cadence" / "tuned_gaits_cadence2.json",
    EXPERIMENTS / "acl_earlier_gaits" / "tuned_gaits_acl_energy.json",
)
METRICS = ("climb_per_gait_cycle_m", "slip_per_m", "energy_per_m", "reward_per_gait_cycle")


def gait_controllers(
    path: Path, rates: list[float], reward_weights: dict[str, float]
) -> tuple[list[Controller], str]:
    """The ``acl`` gait of a tuned-gaits file (read by :func:`tuned_gait`, which refuses a
    malformed file) at each cadence, and the note saying which gait and for which weights."""
    gait, note = tuned_gait(path, reward_weights, non_rolling=False)
    if gait is None:
        raise tuned_gaits.TunedGaitsError(note)
    env_id, env_kwargs = gait
    kwargs = {
        **env_kwargs,
        "phase_rate_range": [min(0.5, *rates), max(1.5, *rates)],
        "reward_weights": reward_weights,
    }
    controllers = [
        Controller(f"{path.stem}@{rate:g}", env_id, kwargs, phase_rate=rate) for rate in rates
    ]
    return controllers, note


def policy_point(spec: str) -> dict[str, Any]:
    """``EVAL_JSON[=LABEL]`` -> the policy's mean cadence, label and metrics (mean, half-width)."""
    path, _, label = spec.partition("=")
    policy = controller_summary(read_record(path), "policy")
    point = {"rate": policy["mean_phase_rate"], "label": label or Path(path).stem}
    return point | {m: {k: policy[m][k] for k in ("mean", "half_width")} for m in METRICS}


def plot(rows: list[dict[str, Any]], points: list[dict[str, Any]], path: Path) -> None:
    """Reward, climb and slip per gait cycle against cadence, one line per gait, policies as
    markers."""
    plt = use_agg()
    fig, axes = plt.subplots(1, 3, figsize=(13, 3.8), constrained_layout=True)
    panels = (
        ("reward_per_gait_cycle", "reward per gait cycle"),
        ("climb_per_gait_cycle_m", "climb per gait cycle (m)"),
        ("slip_per_m", "slip per metre climbed"),
    )
    for gait in dict.fromkeys(r["gait"] for r in rows):
        mine = [r for r in rows if r["gait"] == gait]
        for ax, (metric, _) in zip(axes, panels, strict=True):
            ax.errorbar(
                [r["rate"] for r in mine],
                [r[metric]["mean"] for r in mine],
                yerr=[r[metric]["half_width"] for r in mine],
                marker="o",
                capsize=3,
                label=f"open loop: {gait}",
            )
    for point in points:
        for ax, (metric, _) in zip(axes, panels, strict=True):
            value = point[metric]
            ax.errorbar(
                [point["rate"]],
                [value["mean"]],
                yerr=[value["half_width"]],
                marker="*",
                ms=12,
                ls="",
                label=point["label"],
            )
    for ax, (_, title) in zip(axes, panels, strict=True):
        ax.set_xlabel("cadence (gait keyframes per step)")
        ax.set_title(title)
        ax.grid(alpha=0.3)
    fig.legend(*axes[0].get_legend_handles_labels(), loc="outside lower center", ncols=2)
    save_figure(fig, path, 120)


def main(argv: list[str] | None = None) -> list[dict[str, Any]]:
    parser = make_parser(__doc__, plot=True, plot_suffixes=(".png",), episodes=10, workers=2)
    parser.add_argument("--tuned-gaits", type=Path, nargs="+", default=DEFAULT_GAITS)
    parser.add_argument(
        "--rates",
        type=float,
        nargs="+",
        default=[1.0, 1.1, 1.2, 1.3, 1.4, 1.5, 1.6, 1.7, 1.8, 1.9, 2.0],
    )
    parser.add_argument(
        "--reward-weights",
        action=KeyValues,
        nargs="+",
        default=None,
        metavar="TERM:WEIGHT",
        help="reward weights of every gait's env (default: the shipped recipe's, ppo.yml)",
    )
    parser.add_argument("--policy-point", action="append", default=[], metavar="EVAL_JSON[=LABEL]")
    args = parser.parse_args(argv)
    if any(not 0.0 < rate <= 3.0 for rate in args.rates):
        parser.error(f"argument --rates: each must be in (0, 3], got {args.rates}")
    weights = args.reward_weights
    if weights is None:
        recipe = config.load_hyperparams(shipped.recipe_path(), ACL_CLIMB_ID)
        weights = recipe["env_kwargs"]["reward_weights"]
    try:
        check_reward_weights(weights)
    except (TypeError, ValueError) as error:
        parser.error(f"argument --reward-weights: {error}")
    try:
        points = [policy_point(spec) for spec in args.policy_point]
    except (OSError, KeyError, ValueError) as error:
        parser.error(f"argument --policy-point: {error!r}")
    controllers = []
    for path in args.tuned_gaits:
        try:
            gaits, note = gait_controllers(Path(path), args.rates, weights)
        except tuned_gaits.TunedGaitsError as error:
            parser.error(f"argument --tuned-gaits: {error}")
        print(note)
        controllers += gaits
    results = evaluate(controllers, list(range(args.episodes)), args.workers)
    rows = []
    for controller in controllers:
        summary = summarize(results[controller.name])
        gait, _, _ = controller.name.rpartition("@")
        row = {"gait": gait, "rate": controller.phase_rate}
        row |= {m: {k: summary[m][k] for k in ("mean", "half_width")} for m in METRICS}
        row["falls"] = summary["falls"]["count"]
        rows.append(row)
    print(f"{'gait':<24} {'cadence':>7} " + " ".join(f"{m:>26}" for m in METRICS) + "  falls")
    for row in rows:
        cells = " ".join(f"{row[m]['mean']:>16.4f} ± {row[m]['half_width']:<7.4f}" for m in METRICS)
        print(f"{row['gait']:<24} {row['rate']:>7.3f} {cells}  {row['falls']}")
    print(
        f"mean ± 95 % CI half-width, {args.episodes} episodes (reset seeds 0-{args.episodes - 1})"
    )
    document = {
        "tuned_gaits": [shown_path(p) for p in args.tuned_gaits],
        "reward_weights": weights,
        "episodes": args.episodes,
        "rows": rows,
    }
    write_output(args.json, document)
    if args.plot:
        plot(rows, points, args.plot)
    return rows


if __name__ == "__main__":
    console_script(main)()
