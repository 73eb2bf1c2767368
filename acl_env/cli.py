"""Command-line building blocks shared by the console scripts of every subpackage (training,
evaluation, tuning, benchmark) and by the scripts of ``benchmarks/`` (:mod:`acl_env.scripts`):
argument types that refuse bad input before any work, with a one-line message naming the argument
and what is accepted. Core dependencies only, so that any command line may import it.

argparse turns an ``ArgumentTypeError`` raised by a ``type=`` function into
``argument --name: <message>``; :class:`ArgumentParser` prints that single line (no usage block)
and exits with status 2, argparse's status for a bad command line.
"""

from __future__ import annotations

import argparse
import importlib
import math
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import Any, NoReturn

from acl_env import io
from acl_env.validation import shown


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line on stderr, exit status 2."""

    def error(self, message: str) -> NoReturn:
        message = " ".join(message.split())  # a YAML or pickle error may span lines
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


# Upper bounds of the command lines' counts: far beyond any use, short of what would hang or
# exhaust memory (a 400-digit --episodes).
MAX_SEED = 2**31 - 1  # numpy and SB3 seed with 32-bit integers; seed + env index stays valid
MAX_COUNT = 10**12  # env steps, episodes
MAX_PROCESSES = 1024  # workers, envs, threads


def int_at_least(minimum: int, maximum: int | None = None) -> Callable[[str], int]:
    """An argparse type: an integer ``>= minimum`` (and ``<= maximum`` when given)."""
    accepted = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected an integer {accepted}, got {shown(text)}"
            ) from None
        if value < minimum:
            raise argparse.ArgumentTypeError(
                f"expected an integer >= {minimum}, got {shown(value)}"
            )
        if maximum is not None and value > maximum:
            raise argparse.ArgumentTypeError(f"expected an integer {accepted}, got {shown(value)}")
        return value

    parse.__name__ = f"int_at_least_{minimum}"
    return parse


def positive_float(text: str) -> float:
    """An argparse type: a finite number ``> 0``."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}") from None
    if not (math.isfinite(value) and value > 0.0):
        raise argparse.ArgumentTypeError(f"expected a positive number, got {text!r}")
    return value


def existing_dir(text: str) -> Path:
    """An argparse type: a folder that exists."""
    path = Path(text)
    if not path.is_dir():
        raise argparse.ArgumentTypeError(f"expected an existing folder, got {text!r}")
    return path


def output_file(*suffixes: str) -> Callable[[str], Path]:
    """An argparse type: a file path to write later, checked now by
    :func:`acl_env.io.check_output` (its folder exists and is writable, it is not a folder, its
    suffix is one of ``suffixes`` when given). Nothing is left behind."""

    def parse(text: str) -> Path:
        try:
            return io.check_output(text, suffixes)
        except ValueError as error:
            raise argparse.ArgumentTypeError(str(error)) from None

    parse.__name__ = "output_file"
    return parse


def output_folder(text: str) -> Path:
    """An argparse type: a folder to write into later, made (with its parents) if missing: it is
    not a file, and its nearest existing folder takes a new file (probed, nothing left)."""
    path = Path(text)
    try:
        return io.check_writable_folder(path, "the folder", create=True)
    except ValueError as error:
        raise argparse.ArgumentTypeError(f"{error}, so {text!r} cannot be written") from None


def _out_of_range(value: Any) -> Any:
    """The first number in ``value`` (nested lists, tuples, dicts) that is not finite or is an
    integer too large for a float, else None."""
    if isinstance(value, dict):
        value = list(value.values())
    if isinstance(value, list | tuple):
        return next((v for v in map(_out_of_range, value) if v is not None), None)
    if isinstance(value, int | float) and not isinstance(value, bool):
        try:
            return None if math.isfinite(float(value)) else value
        except OverflowError:
            return value
    return None


def key_value(text: str) -> tuple[str, Any]:
    """An argparse type: ``key:value`` (zoo style), parsed by :func:`acl_env.io.parse_key_value`;
    a non-finite number (``1e309``) or an integer beyond float range (400 digits) is refused."""
    try:
        key, value = io.parse_key_value(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None
    bad = _out_of_range(value)
    if bad is not None:
        raise argparse.ArgumentTypeError(
            f"{key}: {shown(bad)} is not a finite number within float range"
        )
    return key, value


def reward_weight(text: str) -> tuple[str, float]:
    """An argparse type: ``term:weight``, the weight a finite number; its range is the env's
    (``acl_env.envs.rewards.check_reward_weights``: ``|weight| <= REWARD_WEIGHT_MAX``)."""
    from acl_env.envs.rewards import REWARD_WEIGHT_MAX

    key, value = key_value(text)
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise argparse.ArgumentTypeError(f"{key}: expected a number, got {shown(value)}")
    if abs(value) > REWARD_WEIGHT_MAX:
        raise argparse.ArgumentTypeError(
            f"{key}: {shown(value)} is outside [-{REWARD_WEIGHT_MAX:g}, {REWARD_WEIGHT_MAX:g}]"
        )
    return key, float(value)


# The opt-in to load a Stable-Baselines3 folder's pickles (acl-evaluate, acl-train, export).
TRUST_PICKLES_HELP = (
    "load model.zip and vecnormalize.pkl of an SB3 folder: they are pickles, which can run "
    "code when loaded; only for folders you made or trust (shipped and exported numpy policies "
    "need no flag)"
)


def add_trust_pickles(parser: argparse.ArgumentParser) -> None:
    """``--trust-pickles`` (:data:`TRUST_PICKLES_HELP`) on a command that may load SB3 files."""
    parser.add_argument("--trust-pickles", action="store_true", help=TRUST_PICKLES_HELP)


def add_episodes(parser: argparse.ArgumentParser, default: int, help: str) -> None:
    """``--episodes``: a count >= 1."""
    parser.add_argument("--episodes", type=int_at_least(1, MAX_COUNT), default=default, help=help)


def add_seed(parser: argparse.ArgumentParser, default: int | None, help: str) -> None:
    """``--seed``: 0 to :data:`MAX_SEED` (``None``: the command's own default applies)."""
    parser.add_argument("--seed", type=int_at_least(0, MAX_SEED), default=default, help=help)


def add_workers(parser: argparse.ArgumentParser, default: int | None, help: str) -> None:
    """``--workers``: processes, 1 to :data:`MAX_PROCESSES`."""
    parser.add_argument(
        "--workers", type=int_at_least(1, MAX_PROCESSES), default=default, help=help
    )


def add_key_values(
    parser: argparse.ArgumentParser, option: str, help: str, repeat: bool = False
) -> None:
    """``option KEY:VALUE ...``: :func:`key_value` pairs (read them with :func:`pairs_to_dict`);
    ``repeat``: the option may be given again, its pairs appended."""
    parser.add_argument(
        option,
        type=key_value,
        nargs="*",
        action="extend" if repeat else "store",
        default=None if repeat else [],
        metavar="KEY:VALUE",
        help=help,
    )


def add_gym_packages(parser: argparse.ArgumentParser) -> None:
    """``--gym-packages``: modules imported (so registering their envs) while parsing."""
    parser.add_argument(
        "--gym-packages",
        type=importable_module,
        nargs="*",
        default=[],
        help="modules registering envs",
    )


def importable_module(text: str) -> str:
    """An argparse type: a module that imports (and so registers its envs), imported now."""
    try:
        importlib.import_module(text)
    except Exception as error:  # a broken package fails in its own way
        raise argparse.ArgumentTypeError(f"cannot import {text!r} ({error})") from None
    return text


def pairs_to_dict(option: str, pairs: Sequence[tuple[str, Any]] | None) -> dict[str, Any]:
    """The :func:`key_value` pairs of one option as a dict; a key given twice is refused."""
    keys = [key for key, _ in pairs or ()]
    twice = next((key for key in keys if keys.count(key) > 1), None)
    if twice is not None:
        raise argparse.ArgumentTypeError(f"argument {option}: {twice!r} given twice")
    return dict(pairs or ())
