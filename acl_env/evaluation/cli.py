"""``acl-evaluate``: judge a trained policy against the open-loop gaits on the same seeds.

The controllers are those of :mod:`acl_env.evaluation.baselines`, run by
:mod:`acl_env.evaluation.runner`; the metrics are those of :mod:`acl_env.evaluation`, reported as
mean and Student-t 95 % interval over the episodes; ``--json`` writes the record of
:mod:`acl_env.evaluation.records`. ``python -m acl_env.evaluation.cli`` runs it too.

Every argument, output path and policy folder is checked before the first episode (a bad one:
exit 2, one line naming it, nothing written); every output is written atomically. An SB3 run
folder loads only with ``--trust-pickles`` (its files are pickles, which can run code).
"""

from __future__ import annotations

import os

# --video renders offscreen; MuJoCo picks its GL backend when first imported, so say it now.
os.environ.setdefault("MUJOCO_GL", "egl")

import argparse
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from acl_env import cli, current_id, shipped, tuned_gaits
from acl_env.evaluation.baselines import (
    DEFAULT_POLICY,
    DEFAULT_TUNED_GAITS,
    SAME_CADENCE,
    Controller,
    build_controllers,
    is_policy,
    read_policy,
)
from acl_env.evaluation.figures import plot_heights, record_video
from acl_env.evaluation.records import REFERENCE, make_record, write_record
from acl_env.evaluation.runner import PolicySetError, evaluate, policies_controllers
from acl_env.evaluation.statistics import MIN_SEEDS, over_seeds
from acl_env.evaluation.summary import summarize
from acl_env.evaluation.tables import format_paired, format_table
from acl_env.evaluation.tasks import shown_path
from acl_env.io import atomic_output, console_script
from acl_env.pretrained import PretrainedPolicy, SpaceMismatchError


def policy_folder(text: str) -> Path:
    """An argparse type: a shipped policy's name (its folder) or an existing folder."""
    path = Path(text)
    if text in shipped.list_policies() and not path.is_dir():
        return shipped.policy_dir(text)
    if not path.is_dir():
        names = ", ".join(shipped.list_policies())
        raise argparse.ArgumentTypeError(
            f"expected a shipped policy ({names}) or an existing folder, got {text!r}"
        )
    return path


def make_parser() -> cli.ArgumentParser:
    """The command line of ``acl-evaluate``."""
    from acl_env.envs.rewards import REWARD_WEIGHT_MAX  # loads MuJoCo: MUJOCO_GL is set by now

    parser = cli.ArgumentParser(
        prog="acl-evaluate",
        description="Evaluate a trained policy against the open-loop gaits, on the same seeds.",
    )
    which = parser.add_mutually_exclusive_group()
    which.add_argument(
        "--policy",
        type=policy_folder,
        nargs="+",
        default=[DEFAULT_POLICY],
        help=f"a shipped policy ({', '.join(shipped.list_policies())}; default "
        f"{shipped.DEFAULT_POLICY}), a pretrained policy folder or an SB3 run folder (with "
        "--trust-pickles); several (the training seeds of one recipe): each plays, and the "
        "summary is over seeds (IQM, bootstrap interval, probability of improvement)",
    )
    which.add_argument("--no-policy", action="store_true", help="open-loop controllers only")
    cli.add_trust_pickles(parser)
    cli.add_episodes(parser, 20, "episodes, >= 1 (default 20)")
    cli.add_seed(parser, 0, f"episode i resets with seed + i (0 to {cli.MAX_SEED})")
    cli.add_key_values(
        parser, "--env-kwargs", "env overrides (numbers finite; ranges: docs/evaluation.md)"
    )
    parser.add_argument(
        "--reward-weights",
        type=cli.reward_weight,
        nargs="*",
        metavar="TERM:WEIGHT",
        help="reward weights of every controller's env (default: the policy's training ones); "
        f"finite numbers with |weight| <= {REWARD_WEIGHT_MAX:g}, negative allowed (the "
        "term's sign flipped: slip:-1 rewards slipping)",
    )
    parser.add_argument(
        "--tuned-gaits",
        type=Path,
        default=DEFAULT_TUNED_GAITS,
        help="tuned open-loop gaits (default: the shipped ones; acl-tune-gait writes others)",
    )
    parser.add_argument(
        "--tuned-key",
        help="entry of --tuned-gaits to play as open_loop_tuned (default: the policy's task's, "
        "acl_env.evaluation.tasks.task_baselines)",
    )
    parser.add_argument(
        "--json", type=cli.output_file(".json"), help="write the record here (.json)"
    )
    parser.add_argument(
        "--plot",
        type=cli.output_file(".png", ".pdf", ".svg"),
        help="COM height against time (png, pdf or svg)",
    )
    parser.add_argument(
        "--video",
        type=cli.output_file(".mp4", ".gif"),
        help="mp4 or gif of the first episode of the policy (of open-loop ACL with --no-policy)",
    )
    parser.add_argument(
        "--video-beside",
        nargs="+",
        default=[],
        metavar="CONTROLLER",
        help="controllers shown beside it in the video, same seed (e.g. open_loop_tuned)",
    )
    parser.add_argument(
        "--video-speedup",
        type=cli.positive_float,
        default=1.0,
        help="video speed, times real time (default 1)",
    )
    cli.add_workers(parser, 2, "processes running episodes")
    cli.add_gym_packages(parser)
    parser.add_argument(
        "--markdown", action="store_true", help="print the table in Markdown (for the README)"
    )
    parser.add_argument("--no-progress-bar", action="store_true")
    return parser


def _checked_controllers(
    parser: cli.ArgumentParser, args: argparse.Namespace
) -> tuple[list[Controller], list[str]]:
    """Controllers built and each env and policy made once, so that every bad argument is refused
    (one line, exit status 2) before any episode runs."""
    overrides, weights = _checked_overrides(parser, args)
    folders = _policy_folders(parser, args)
    controllers, notes = _built_controllers(parser, args, folders, overrides, weights)
    for controller in controllers:
        _check_controller(parser, controller)
    names = [c.name for c in controllers]
    unknown = [name for name in args.video_beside if name not in names]
    if unknown:
        parser.error(f"argument --video-beside: unknown controllers {unknown}; these run: {names}")
    if args.video_beside and not args.video:
        parser.error("argument --video-beside: needs --video")
    return controllers, notes


def _checked_overrides(
    parser: cli.ArgumentParser, args: argparse.Namespace
) -> tuple[dict[str, Any], dict[str, Any] | None]:
    """``--env-kwargs`` and ``--reward-weights`` (None when not given) as dicts, the weights
    checked as the env checks them."""
    from acl_env.envs.rewards import check_reward_weights

    try:
        overrides = cli.pairs_to_dict("--env-kwargs", args.env_kwargs)
        weights = None
        if args.reward_weights is not None:
            weights = cli.pairs_to_dict("--reward-weights", args.reward_weights)
    except argparse.ArgumentTypeError as error:
        parser.error(str(error))
    if weights is not None:
        try:
            check_reward_weights(weights)
        except (ValueError, TypeError) as error:
            parser.error(f"argument --reward-weights: {error}")
    return overrides, weights


def _policy_folders(parser: cli.ArgumentParser, args: argparse.Namespace) -> list[Any]:
    """The ``--policy`` folders read (an SB3 one only with ``--trust-pickles``), all of one
    task; none with ``--no-policy``."""
    folders = []
    for path in [] if args.no_policy else args.policy:
        try:
            folders.append(read_policy(path))
        except ValueError as error:
            parser.error(f"argument --policy: {error}")
        if not isinstance(folders[-1], PretrainedPolicy):
            from acl_env.training.runs import require_trust  # an SB3 folder: PyYAML is here

            try:
                require_trust(path, args.trust_pickles)
            except ValueError as error:
                parser.error(f"argument --policy: {error}")
    tasks = {current_id(folder.env_id) for folder in folders}
    if len(tasks) > 1:
        parser.error(f"argument --policy: the policies are of several tasks: {sorted(tasks)}")
    return folders


def _built_controllers(
    parser: cli.ArgumentParser,
    args: argparse.Namespace,
    folders: list[Any],
    overrides: dict[str, Any],
    weights: dict[str, Any] | None,
) -> tuple[list[Controller], list[str]]:
    """The controllers of the policy (or of each of several policies) and the notes on those
    skipped; a bad gait file, policy set or gait override is refused naming its option."""
    try:
        if len(folders) > 1:
            controllers, notes = policies_controllers(
                args.policy,
                overrides,
                args.tuned_gaits,
                weights,
                args.tuned_key,
                args.trust_pickles,
            )
        else:
            controllers, notes = build_controllers(
                folders[0] if folders else None,
                overrides,
                weights,
                args.tuned_gaits,
                args.tuned_key,
                args.trust_pickles,
            )
    except tuned_gaits.TunedGaitsError as error:
        parser.error(f"argument --tuned-gaits: {error}")
    except PolicySetError as error:
        parser.error(f"argument --policy: {error}")
    except (ValueError, TypeError, AttributeError) as error:  # a malformed gait override
        parser.error(f"argument --env-kwargs: {error}")
    if args.tuned_key is not None and not any(c.name == "open_loop_tuned" for c in controllers):
        skipped = [note for note in notes if note.startswith("open_loop_tuned: skipped")]
        parser.error(f"argument --tuned-key: {'; '.join(skipped)}")
    return controllers, notes


def _check_controller(parser: cli.ArgumentParser, controller: Controller) -> None:
    """Make the controller's env and policy once: what either refuses is refused here."""
    from acl_env.envs.kwargs import check_env_kwargs

    try:
        # quiet: the evaluation spells its controllers' ids (Controller.make_env); the env
        # checked is the one that runs, an error names its registered task, as records do
        env = check_env_kwargs(controller.env_id, controller.env_kwargs, quiet=True)
    except (ValueError, TypeError, ArithmeticError) as error:
        message = str(error).replace(controller.env_id, controller.task()[0])
        parser.error(f"argument --env-kwargs: {controller.title}: {message}")
    try:
        controller.make_policy(env)
    except SpaceMismatchError as error:
        parser.error(f"argument --env-kwargs: {error}")
    except ValueError as error:
        parser.error(f"argument --policy: {error}")
    finally:
        env.close()


def main(argv: Sequence[str] | None = None) -> dict[str, Any]:
    """Evaluate, print the table, write the optional outputs; return the record."""
    parser = make_parser()
    args = parser.parse_args(argv)
    controllers, notes = _checked_controllers(parser, args)
    seeds = [args.seed + i for i in range(args.episodes)]
    results = evaluate(
        controllers, seeds, args.workers, args.gym_packages, not args.no_progress_bar
    )
    summaries = {name: summarize(episodes) for name, episodes in results.items()}
    by_name = {c.name: c for c in controllers}
    tasks = {name: by_name[name].task() for name in results}
    labels = {name: by_name[name].title for name in results}
    document = make_record(
        summaries,
        env_ids={name: env_id for name, (env_id, _) in tasks.items()},
        env_kwargs={name: kwargs for name, (_, kwargs) in tasks.items()},
        policy=None if args.no_policy else ", ".join(shown_path(p) for p in args.policy),
        notes=notes,
        # present whenever a same-cadence open loop is
        same_cadence_phase_rate=(
            results[SAME_CADENCE][0].mean_phase_rate if SAME_CADENCE in results else None
        ),
        labels=labels,
    )
    policies = [name for name in results if is_policy(name) and name != REFERENCE]
    if policies:  # several policies: the summary over seeds
        document["over_seeds"] = over_seeds(summaries, policies)
    # Every file first, then the printing: a reader that stops reading (| head) loses no file.
    if args.json:
        write_record(args.json, document)
    task = tasks[controllers[0].name][0]
    if args.plot:
        with atomic_output(args.plot) as path:
            plot_heights(results, path, labels, title=f"{task}, seeds {seeds[0]}-{seeds[-1]}")
    if args.video:
        shown = [controllers[0], *(by_name[name] for name in args.video_beside)]
        with atomic_output(args.video) as path:
            record_video(shown, seeds[0], path, args.video_speedup)
    print(f"{task}: {len(seeds)} episodes, seeds {seeds[0]}-{seeds[-1]}")
    print(format_table({labels[name]: s for name, s in summaries.items()}, args.markdown))
    if "paired_vs_policy" in document:
        paired = {labels[name]: d for name, d in document["paired_vs_policy"].items()}
        print(format_paired(paired, labels[REFERENCE]))
    if policies:
        print(format_over_seeds(document["over_seeds"], labels))
    for note in notes:
        name, sep, rest = note.partition(": ")
        print(f"{labels.get(name, name)}{sep}{rest}" if name in by_name else note)
    return document


def format_over_seeds(summary: dict[str, Any], labels: dict[str, str]) -> str:
    """The policies over training seeds: IQM [95 % interval], the best analytic controller and
    the probability that a seed beats it."""
    seeds = len(next(iter(summary.values()))["per_seed"])
    lines = [f"over {seeds} training seeds:"]
    if seeds < MIN_SEEDS:
        lines[0] += f" (fewer than {MIN_SEEDS}: the intervals are too narrow to trust)"
    for metric, entry in summary.items():
        low, high = entry["ci95"]
        line = f"  {metric}: IQM {entry['iqm']:.4g} [{low:.4g}, {high:.4g}]"
        if "best_analytic" in entry:
            best, poi = entry["best_analytic"], entry["probability_of_improvement"]
            name = labels.get(best["controller"], best["controller"])
            line += (
                f"; best analytic: {name} {best['mean']:.4g}; P(seed better) "
                f"{poi['mean']:.2f} [{poi['ci95'][0]:.2f}, {poi['ci95'][1]:.2f}]"
            )
        lines.append(line)
    return "\n".join(lines)


# The console script (pyproject.toml): main() without its returned document.
run = console_script(main)

if __name__ == "__main__":
    run()
