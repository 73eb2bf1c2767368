"""What the scripts in ``benchmarks/`` and ``experiments/`` share: one parent parser for their
common options, the headless figure backend, and the writers of their JSON and figure files.

Each script builds its parser with :func:`make_parser` (or passes :func:`parent_parser` to its
own), keeps its own option names (``--plot`` is also ``--figure`` or ``--out`` where a script
named it so), and writes only where it is told, or under ``runs/`` (ignored by git): never a
shipped or published file unless given its path.
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any

from acl_env import cli, io
from acl_env.cli import add_trust_pickles

FIGURE_SUFFIXES = (".png", ".pdf", ".svg")
RUNS = Path("runs")  # where a script writes what it is not told where to write (ignored by git)


class KeyValues(argparse.Action):
    """``--option KEY:VALUE ...`` as one dict (:func:`acl_env.io.parse_kv_pairs`); a malformed
    item or a key given twice is refused naming the option."""

    def __call__(
        self,
        parser: argparse.ArgumentParser,
        namespace: argparse.Namespace,
        values: Any,
        option_string: str | None = None,
    ) -> None:
        try:
            pairs = io.parse_kv_pairs(values, f"argument {option_string}")
        except ValueError as error:
            parser.error(str(error))
        setattr(namespace, self.dest, pairs)


def parent_parser(
    *,
    json: bool | str = True,
    plot: bool | str = False,
    plot_names: Sequence[str] = ("--plot",),
    plot_suffixes: Sequence[str] = FIGURE_SUFFIXES,
    plot_default: Path | None = None,
    seed: int | None = None,
    episodes: int | None = None,
    workers: int | None = None,
    env_kwargs: bool | str = False,
    progress: bool = False,
) -> argparse.ArgumentParser:
    """An argparse parent with the scripts' common options, each left out when its argument is
    False or None: ``--json PATH``, the figure (``plot_names``, ``--plot`` unless told), ``--seed``
    (the first reset seed, default ``seed``), ``--episodes`` and ``--workers`` (their defaults),
    ``--env-kwargs KEY:VALUE ...`` (a dict) and ``--no-progress-bar``. A string for ``json``,
    ``plot`` or ``env_kwargs`` is that option's help."""
    parser = argparse.ArgumentParser(add_help=False)
    if json:
        help_ = json if isinstance(json, str) else "write the results to this JSON file"
        parser.add_argument("--json", type=cli.output_file(".json"), metavar="PATH", help=help_)
    if plot:
        parser.add_argument(
            *plot_names,
            dest="plot",
            type=cli.output_file(*plot_suffixes),
            default=plot_default,
            metavar="PATH",
            help=plot if isinstance(plot, str) else "draw the figure here",
        )
    if seed is not None:
        cli.add_seed(parser, seed, "first seed")
    if episodes is not None:
        cli.add_episodes(parser, episodes, f"episodes (default {episodes})")
    if workers is not None:
        cli.add_workers(parser, workers, "processes")
    if env_kwargs:
        help_ = env_kwargs if isinstance(env_kwargs, str) else "env arguments of every episode"
        parser.add_argument(
            "--env-kwargs", action=KeyValues, nargs="*", default={}, metavar="KEY:VALUE",
            help=help_,
        )  # fmt: skip
    if progress:
        parser.add_argument("--no-progress-bar", action="store_true")
    return parser


def make_parser(doc: str | None, prog: str | None = None, **common: Any) -> cli.ArgumentParser:
    """A script's parser: its docstring's first line as description, one-line errors
    (:class:`acl_env.cli.ArgumentParser`) and the :func:`parent_parser` options
    ``common`` asks for."""
    description = (doc or "").strip().splitlines()[0] if doc else None
    return cli.ArgumentParser(prog=prog, description=description, parents=[parent_parser(**common)])


def policy_parser(doc: str | None, episodes: int) -> cli.ArgumentParser:
    """The parser of a script that plays one policy folder: ``--policy DIR`` (required),
    ``--episodes``, ``--env-kwargs``, ``--json``, ``--plot`` and ``--no-progress-bar``."""
    parser = make_parser(doc, plot=True, episodes=episodes, env_kwargs=True, progress=True)
    parser.add_argument("--policy", type=cli.existing_dir, required=True, help="policy folder")
    add_trust_pickles(parser)
    return parser


def parse_policy_args(
    parser: argparse.ArgumentParser, argv: Sequence[str] | None
) -> tuple[argparse.Namespace, Any]:
    """A :func:`policy_parser`'s arguments, and the policy's env made with ``--env-kwargs`` over
    its own: a bad folder or env argument is refused in one line before any episode. The caller
    closes the env."""
    from acl_env.training.checks import check_env_kwargs
    from acl_env.training.policy import read_policy_folder

    args = parser.parse_args(argv)
    try:
        env = check_env_kwargs(read_policy_folder(args.policy).env_id, args.env_kwargs)
    except (ValueError, TypeError) as error:
        parser.error(str(error))
    return args, env


def seeds(args: argparse.Namespace) -> list[int]:
    """The reset seeds ``--seed`` .. ``--seed + --episodes - 1``."""
    return list(range(args.seed, args.seed + args.episodes))


def use_agg() -> Any:
    """``matplotlib.pyplot`` on the headless Agg backend (figures to files, no display)."""
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def save_figure(
    fig: Any, path: str | Path, dpi: int, tight: bool = False, close: bool = True
) -> None:
    """Write ``fig`` to ``path`` (its folder made if missing; ``tight``: after
    ``fig.tight_layout()``), close it and say so."""
    if tight:
        fig.tight_layout()
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(path, dpi=dpi)
    if close:
        use_agg().close(fig)
    print(f"wrote {path}")


def write_output(path: str | Path | None, document: Any, indent: int | None = 2) -> None:
    """``document`` as JSON at ``path`` (:func:`acl_env.io.write_json`; nothing when None)."""
    if path is None:
        return
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    io.write_json(path, document, indent=indent)
    print(f"wrote {path}")


def write_outputs(
    args: argparse.Namespace,
    document: Any,
    plot: Callable[[Any, Path], None] | None = None,
    indent: int | None = 2,
) -> None:
    """``--json`` and, with ``plot``, the figure ``plot(document, args.plot)``, where given."""
    write_output(getattr(args, "json", None), document, indent)
    if plot is not None and getattr(args, "plot", None) is not None:
        Path(args.plot).parent.mkdir(parents=True, exist_ok=True)
        plot(document, Path(args.plot))


def print_figures(document: dict[str, Any], fmt: str = ".3f", width: int = 34) -> None:
    """Print a record's top-level float figures, one ``name value`` line each."""
    print(f"{'measure':{width}s} value")
    for key, value in document.items():
        if isinstance(value, float):
            print(f"{key:{width}s} {value:10{fmt}}")


def timed_steps(
    env: Any,
    steps: int,
    clock: Callable[[], float] = time.perf_counter,
    reset_seed: int | None = None,
) -> float:
    """Time (s, by ``clock``) spent in ``steps`` zero-action ``env.step`` calls; an episode that
    ends is reset (``reset_seed``) untimed."""
    import numpy as np

    action = np.zeros(env.action_space.shape, dtype=np.float32)
    elapsed = 0.0
    for _ in range(steps):
        start = clock()
        _, _, terminated, truncated, _ = env.step(action)
        elapsed += clock() - start
        if terminated or truncated:
            env.reset(seed=reset_seed)
    return elapsed
