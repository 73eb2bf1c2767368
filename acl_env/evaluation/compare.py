"""Pair one controller of two evaluations, seed by seed: is policy A better than policy B?

``acl-compare A.json B.json [--controller policy] [--labels A B] [--json OUT]``

Each file is an ``acl-evaluate --json`` record, read by :func:`acl_env.evaluation.read_record`.
Two evaluations run on the same reset seeds (the default: seeds 0..N-1) give each seed the same
pole, skin and springs on both sides, so the difference per seed, A minus B, and its Student's t
interval (:func:`acl_env.evaluation.paired_differences`) say whether two trained policies (or a
policy and an ablation of it) differ, where their intervals side by side often overlap. Files run
on other seeds, on another env or under other conditions (``CONDITIONS``: a held-out evaluation
against a default one), or without the controller, are refused with a one-line error.

Two records of several policies each (``acl-evaluate --policy SEED0 SEED1 ...``: two recipes,
each over its training seeds) are compared as recipes: per metric, each recipe's interquartile
mean, their difference and the probability that a seed of A beats a seed of B, with bootstrap
95 % intervals over seeds (:func:`acl_env.evaluation.statistics.compare_samples`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from acl_env import cli
from acl_env.evaluation import format_paired, paired_differences
from acl_env.evaluation.baselines import POLICY_PREFIX
from acl_env.evaluation.records import controller_env, controller_summary, read_record
from acl_env.evaluation.statistics import SEED_METRICS, compare_samples
from acl_env.io import console_script, write_json

# Env kwargs that set the conditions an episode is played under (acl-evaluate's --env-kwargs and
# the held-out overrides), rather than the controller: both sides must agree on them.
CONDITIONS = (
    "pole_radius",
    "friction",
    "kp",
    "spring_stiffness",
    "control_latency",
    "motor_speed_limit",
    "actuator_model",
    "reward_weights",
    "domain_randomization",
)


def read_controller(path: Path, controller: str) -> tuple[dict[str, Any], dict[str, Any]]:
    """The summary of ``controller`` in the evaluation JSON at ``path``, and the env it was played
    on (``{"env_id", CONDITIONS...}``); ``ValueError`` naming the file when it is not an
    evaluation or lacks that controller."""
    record = read_record(path)
    try:
        summary = controller_summary(record, controller)
    except ValueError as error:
        raise ValueError(f"{path}: {error}") from None
    env_id, env_kwargs = controller_env(record, controller)
    env = {"env_id": env_id}
    env.update({key: env_kwargs.get(key) for key in CONDITIONS})
    return summary, env


def check_same_conditions(first: Path, second: Path, records: list[dict[str, Any]]) -> None:
    """``ValueError`` unless two records of several seeds were played on one task, under the
    same conditions and on the same reset seeds (as their first seeds say)."""
    envs, seeds = [], []
    for record in records:
        name = next(n for n in record["controllers"] if n.startswith(POLICY_PREFIX))
        env_id, env_kwargs = controller_env(record, name)
        envs.append({"env_id": env_id, **{k: env_kwargs.get(k) for k in CONDITIONS}})
        seeds.append(controller_summary(record, name)["seeds"])
    for key, value in envs[0].items():
        if envs[1][key] != value:
            raise ValueError(f"{first} ran with {key}={value!r}, {second} with {envs[1][key]!r}")
    if seeds[0] != seeds[1]:
        raise ValueError(f"{first} and {second} were played on other reset seeds")


def compare_recipes(
    first: Path, second: Path, recipes: list[dict[str, Any]], labels: tuple[str, str]
) -> dict[str, Any]:
    """Two recipes, each evaluated over its training seeds (``acl-evaluate --policy SEED ...``):
    per metric, each IQM, their difference and the probability that a seed of the first beats
    one of the second, with bootstrap intervals over seeds."""
    over: dict[str, Any] = {}
    for metric, higher in SEED_METRICS.items():
        x, y = (list(recipe[metric]["per_seed"].values()) for recipe in recipes)
        over[metric] = {
            "iqm": [recipes[0][metric]["iqm"], recipes[1][metric]["iqm"]],
            **compare_samples(x, y, higher),
        }
    return {"labels": list(labels), "files": [str(first), str(second)], "over_seeds": over}


def _number(value: float | None, fmt: str) -> str:
    """``value`` formatted, or ``n/a`` where a record holds none (an undefined metric)."""
    return "n/a" if value is None or value != value else format(value, fmt)


def format_recipes(result: dict[str, Any]) -> str:
    """The recipe comparison as lines of text."""
    a, b = result["labels"]
    lines = [f"{a} against {b}, over training seeds (bootstrap 95 % intervals):"]
    for metric, entry in result["over_seeds"].items():
        diff, poi = entry["iqm_difference"], entry["probability_of_improvement"]
        lines.append(
            f"  {metric}: IQM {_number(entry['iqm'][0], '.4g')} vs "
            f"{_number(entry['iqm'][1], '.4g')}, difference {_number(diff['mean'], '+.4g')} "
            f"[{_number(diff['ci95'][0], '+.4g')}, {_number(diff['ci95'][1], '+.4g')}]; "
            f"P({a} better) {_number(poi['mean'], '.2f')} [{_number(poi['ci95'][0], '.2f')}, "
            f"{_number(poi['ci95'][1], '.2f')}]"
        )
    return "\n".join(lines)


def compare(
    first: Path, second: Path, controller: str = "policy", labels: tuple[str, str] | None = None
) -> dict[str, Any]:
    """``controller`` of ``first`` minus that of ``second``, paired by seed: ``{"labels",
    "files", "controller", "env", "paired": {metric: mean_ci95}}``. ``ValueError`` when the two
    were played on other envs, under other conditions or on other seeds."""
    a, b = (labels or (first.stem, second.stem))[:2]
    if a == b:
        raise ValueError(f"the two labels must differ, got {a!r} twice")
    records = [read_record(path) for path in (first, second)]
    recipes = [record.get("over_seeds") for record in records]
    if controller == "policy" and any(recipes):
        if not all(recipes):
            one = first if recipes[0] else second
            raise ValueError(
                f"{one} holds several training seeds and the other one policy: evaluate both "
                "recipes over their seeds (acl-evaluate --policy SEED0 SEED1 ...)"
            )
        check_same_conditions(first, second, records)
        return compare_recipes(first, second, recipes, (a, b))
    (summary_a, env_a), (summary_b, env_b) = (
        read_controller(first, controller),
        read_controller(second, controller),
    )
    for key, value in env_a.items():
        if env_b[key] != value:
            raise ValueError(f"{first} ran with {key}={value!r}, {second} with {env_b[key]!r}")
    paired = paired_differences({a: summary_a, b: summary_b}, reference=a)[b]
    return {
        "labels": [a, b],
        "files": [str(first), str(second)],
        "controller": controller,
        "env": env_a,
        "paired": paired,
    }


def main(argv: list[str] | None = None) -> dict[str, Any]:
    parser = cli.ArgumentParser(prog="acl-compare", description=__doc__.splitlines()[0])
    parser.add_argument("first", type=Path, help="evaluation JSON of A")
    parser.add_argument("second", type=Path, help="evaluation JSON of B")
    parser.add_argument(
        "--controller", default="policy", help="controller to pair (default policy)"
    )
    parser.add_argument("--labels", nargs=2, metavar=("A", "B"), help="names (default: file stems)")
    parser.add_argument(
        "--json", type=cli.output_file(".json"), help="write the differences here (.json)"
    )
    args = parser.parse_args(argv)
    try:
        result = compare(args.first, args.second, args.controller, args.labels)
    except (ValueError, OSError) as err:  # not an evaluation record, or unreadable
        parser.error(str(err))
    a, b = result["labels"]
    if args.json:  # the file first, then the printing
        write_json(args.json, result)
    if "over_seeds" in result:
        print(format_recipes(result))
    else:
        print(format_paired({b: result["paired"]}, reference=f"{a} ({args.controller})"))
    return result


# The console script (pyproject.toml): main() without its returned document.
run = console_script(main)
