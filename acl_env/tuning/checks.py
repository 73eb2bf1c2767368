"""Checks of the tuner's command line before any work: numbers in range, output paths that can be
written, the study storage, and the recipe it reads.

Each check raises :class:`~acl_env.tuning.space.UsageError` (or, as an argparse ``type=``,
``argparse.ArgumentTypeError``) naming the option, so ``acl-tune-gait`` exits with status 2 and
one line before it creates a study, runs a trial or writes a file. Accepted ranges:

- ``--seeds``: integers in [0, 2**31 - 1]; ``--sampler-seed``: [0, 2**32 - 1];
- ``--n-trials`` [1, 10**6], ``--n-jobs`` [1, 1024], ``--validate-seeds`` [0, 1000],
  ``--validate-top`` [1, 1000], ``--heartbeat`` [0, 3600] s (0: off);
- ``--steps-per-cycle``, ``--cycles``: the env's ranges (:mod:`acl_env.envs.config`);
- ``--reward-weights``: numbers within +-``MAX_REWARD_WEIGHT`` (as ``acl-evaluate``'s), then
  the env's own checks; ``--condition``: finite numbers, then the env's ranges;
- ``--output``: a ``.json`` (or older ``.yml``/``.yaml``) file whose folder can be written, and,
  if it exists, a tuned-gaits file; ``--plot``: a file of a format matplotlib writes, its
  ``{key}`` placeholder the only field; ``--storage``: a SQLite file whose folder can be written,
  or a URL of a database driver that is installed.
"""

from __future__ import annotations

import argparse
import math
from collections.abc import Callable, Mapping
from pathlib import Path
from typing import Any

from acl_env import cli, tuned_gaits
from acl_env.io import check_output, check_writable_folder
from acl_env.tuning.space import UsageError

SEED_RANGE = (0, 2**31 - 1)
SAMPLER_SEED_RANGE = (0, 2**32 - 1)
OUTPUT_SUFFIXES = (".json", ".yml", ".yaml")


def int_in(low: int, high: int) -> Callable[[str], int]:
    """An argparse type: an integer in ``[low, high]`` (:func:`acl_env.cli.int_at_least`;
    a 400-digit one is refused, not converted)."""
    return cli.int_at_least(low, high)


def finite_float(text: str) -> float:
    """An argparse type: a finite number (no nan, no inf, nothing past 1.8e308)."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number, got {text!r}") from None
    if not math.isfinite(value):
        raise argparse.ArgumentTypeError(f"expected a finite number, got {text!r}")
    return value


def _checked_output(option: str, text: str, suffixes: tuple[str, ...], **fields: str) -> Path:
    """:func:`acl_env.io.check_output` for a file the tuner writes (its folder, such as the
    default ``runs/``, is made if missing), refused as a bad ``option``."""
    if not text:
        raise UsageError(option, f"expected a file path, got {text!r}")
    try:
        return check_output(text, suffixes, fields or None, create_folder=True)
    except ValueError as error:
        raise UsageError(option, str(error)) from None


def check_output_file(text: str) -> Path:
    """``--output``: a tuned-gaits file that can be (re)written: see the module docstring."""
    path = _checked_output("--output", text, OUTPUT_SUFFIXES)
    if path.is_file():  # its other entries are kept: it must be a tuned-gaits file
        try:
            tuned_gaits.read(path)
        except tuned_gaits.TunedGaitsError as error:
            raise UsageError("--output", str(error)) from None
    return path


def check_plot(template: str, key: str) -> Path | None:
    """``--plot``: the figure's path with ``{key}`` (its only field) filled in, in a format
    matplotlib writes (None for ``''``: no figure)."""
    if not template:
        return None
    from matplotlib.backend_bases import FigureCanvasBase

    formats = tuple(f".{name}" for name in FigureCanvasBase.get_supported_filetypes())
    return _checked_output("--plot", template, formats, key=key)


def check_storage(storage: str) -> None:
    """``--storage``: a SQLite file (not a folder) whose folder can be written, or a database
    URL whose driver is installed. Nothing is created: the study database is made later."""
    from acl_env.tuning.study import storage_url

    url = storage_url(storage)
    if url.startswith("sqlite:///"):
        path = Path(url.removeprefix("sqlite:///"))
        if path.is_dir():
            raise UsageError("--storage", f"{path} is a folder, not a database file")
        if not path.exists():
            try:
                check_writable_folder(path.parent, f"cannot write {path}:", create=True)
            except ValueError as error:
                raise UsageError("--storage", str(error)) from None
        return
    import sqlalchemy

    try:
        dialect = sqlalchemy.engine.make_url(url).get_dialect()
        (getattr(dialect, "import_dbapi", None) or dialect.dbapi)()  # SQLAlchemy 2 / 1.4
    except ImportError as error:
        raise UsageError(
            "--storage", f"the driver of {url.split('://')[0]!r} is not installed ({error})"
        ) from None
    except Exception as error:  # ArgumentError, NoSuchModuleError: not a URL SQLAlchemy knows
        raise UsageError("--storage", f"cannot use {storage!r}: {error}".splitlines()[0]) from None


def check_recipe(hyperparams: Mapping[str, Any], env_id: str, source: str) -> None:
    """``--config``: the recipe entry's names and values (the trainer's checks), and its
    env_kwargs against the env (a misspelt ``reward_weight`` is named)."""
    from acl_env.envs.kwargs import ConfigError, check_env_kwargs
    from acl_env.training.checks import check_hyperparams

    try:  # the tuner runs no training: a recipe for it alone may leave out n_timesteps
        check_hyperparams({"n_timesteps": 1, **hyperparams}, source)
        env = check_env_kwargs(env_id, dict(hyperparams.get("env_kwargs") or {}))
    except (ConfigError, TypeError, ValueError, OverflowError) as error:
        message = str(error)
        message = message if message.startswith(source) else f"{source}: {message}"
        raise UsageError("--config", message) from None
    env.close()
