"""Command-line building blocks for the console scripts: argument types that refuse bad
input before any work, with a one-line message naming the argument and what is accepted.

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

# The one key:value parser is acl_env.io's; its value parser and words, re-exported.
from acl_env.io import WORDS as WORDS
from acl_env.io import parse_value as parse_value


class ArgumentParser(argparse.ArgumentParser):
    """``argparse.ArgumentParser`` whose errors are one line on stderr, exit status 2."""

    def error(self, message: str) -> NoReturn:
        message = " ".join(message.split())  # a YAML or pickle error may span lines
        self.exit(2, f"{self.prog}: error: {message} (see --help)\n")


def int_at_least(minimum: int) -> Callable[[str], int]:
    """An argparse type: an integer ``>= minimum``."""

    def parse(text: str) -> int:
        try:
            value = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"expected an integer >= {minimum}, got {text!r}"
            ) from None
        if value < minimum:
            raise argparse.ArgumentTypeError(f"expected an integer >= {minimum}, got {value}")
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
    """An argparse type: a file path to write later, checked now: its folder exists, it is not a
    folder, and (if ``suffixes`` are given) its suffix is one of them. Nothing is created."""

    def parse(text: str) -> Path:
        path = Path(text)
        if path.is_dir():
            raise argparse.ArgumentTypeError(f"expected a file path, got the folder {text!r}")
        if not path.parent.is_dir():
            raise argparse.ArgumentTypeError(
                f"the folder {str(path.parent)!r} of {text!r} does not exist"
            )
        if suffixes and path.suffix.lower() not in suffixes:
            raise argparse.ArgumentTypeError(
                f"expected a file ending in {' or '.join(suffixes)}, got {text!r}"
            )
        return path

    parse.__name__ = "output_file"
    return parse


def key_value(text: str) -> tuple[str, Any]:
    """An argparse type: ``key:value`` (zoo style), parsed by :func:`acl_env.io.parse_key_value`."""
    try:
        return io.parse_key_value(text)
    except ValueError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


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


def script(main: Callable[[], object]) -> Callable[[], None]:
    """A console-script entry point for ``main``: it runs ``main()`` and drops what it returns.
    ``main`` returns its document for callers in Python; a console script runs
    ``sys.exit(target())``, which would print that document and exit with status 1."""

    def run() -> None:
        main()

    return run
