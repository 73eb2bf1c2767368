"""Pair one controller of two evaluations, seed by seed: is policy A better than policy B?

``acl-compare A.json B.json [--controller policy] [--labels A B] [--json OUT]``

Each file is an ``acl-evaluate --json`` record, read by :func:`acl_env.evaluation.read_record`.
Two evaluations run on the same reset seeds (the default: seeds 0..N-1) give each seed the same
pole, skin and springs on both sides, so the difference per seed, A minus B, and its Student's t
interval (:func:`acl_env.evaluation.paired_differences`) say whether two trained policies (or a
policy and an ablation of it) differ, where their intervals side by side often overlap. Files run
on other seeds, on another env or under other conditions (``CONDITIONS``: a held-out evaluation
against a default one), or without the controller, are refused with a one-line error.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from acl_env.evaluation import format_paired, paired_differences
from acl_env.evaluation.records import controller_env, controller_summary, read_record
from acl_env.io import console_script, write_json
from acl_env.training import cli

# Env kwargs that set the conditions an episode is played under (acl-evaluate's --env-kwargs and
# the held-out overrides), rather than the controller: both sides must agree on them.
CONDITIONS = ("pole_radius", "friction", "kp", "domain_randomization")


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


def compare(
    first: Path, second: Path, controller: str = "policy", labels: tuple[str, str] | None = None
) -> dict[str, Any]:
    """``controller`` of ``first`` minus that of ``second``, paired by seed: ``{"labels",
    "files", "controller", "env", "paired": {metric: mean_ci95}}``. ``ValueError`` when the two
    were played on other envs, under other conditions or on other seeds."""
    a, b = (labels or (first.stem, second.stem))[:2]
    if a == b:
        raise ValueError(f"the two labels must differ, got {a!r} twice")
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
    print(format_paired({b: result["paired"]}, reference=f"{a} ({args.controller})"))
    return result


# The console script (pyproject.toml): main() without its returned document.
run = console_script(main)
