"""Files and command-line values, for the core and every command: the one JSON writer and reader
(atomic writes, strict JSON), and the one ``key:value`` parser. Numpy only, no PyYAML."""

from __future__ import annotations

import ast
import json
import math
import os
import tempfile
from collections.abc import Iterable
from pathlib import Path
from typing import Any

import numpy as np

# Words a command-line value may spell in any case, and the Python values they stand for.
WORDS = {"true": True, "false": False, "none": None, "null": None}

_UMASK = os.umask(0)
os.umask(_UMASK)


def jsonable(value: Any) -> Any:
    """Plain JSON: numpy values as Python numbers and lists, NaN and inf as null."""
    if isinstance(value, dict):
        return {str(k): jsonable(v) for k, v in value.items()}
    if isinstance(value, list | tuple | np.ndarray):
        return [jsonable(v) for v in value]
    if isinstance(value, np.generic):
        value = value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


def atomic_write(path: str | Path, data: bytes | str) -> None:
    """Write ``data`` to ``path`` through a temporary file in the same folder, then rename.

    A reader (or a second Ctrl-C) sees either the old file or the new one, never half of one.
    """
    path = Path(path)
    raw = data.encode() if isinstance(data, str) else data
    fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp", dir=path.parent)
    try:
        os.fchmod(fd, 0o666 & ~_UMASK)  # mkstemp makes 0600; give the usual permissions
        with os.fdopen(fd, "wb") as f:
            f.write(raw)
            f.flush()
            os.fsync(f.fileno())
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise


def write_json(path: str | Path, document: Any, indent: int | None = 2) -> None:
    """``document`` as strict JSON (:func:`jsonable`), written atomically: the one writer of
    every JSON record and figure file the package and its scripts produce."""
    atomic_write(path, json.dumps(jsonable(document), indent=indent) + "\n")


def read_json(path: str | Path) -> Any:
    """A JSON file's content; ``ValueError`` naming the file when it is not JSON."""
    try:
        return json.loads(Path(path).read_text())
    except json.JSONDecodeError as error:
        raise ValueError(f"{path} is not valid JSON ({error})") from None


def parse_value(text: str) -> Any:
    """A command-line value: a Python literal (``0.5``, ``[1, 2]``, ``{'climb': 1}``, ``True``),
    ``true``/``false``/``none``/``null`` in any case, or else the string itself (``acl``)."""
    if text.strip().lower() in WORDS:
        return WORDS[text.strip().lower()]
    try:
        return ast.literal_eval(text)
    except (ValueError, SyntaxError, TypeError, MemoryError, RecursionError):
        return text


def parse_key_value(text: str) -> tuple[str, Any]:
    """``key:value`` (zoo style), the value through :func:`parse_value`; ``ValueError`` unless
    the key is a name."""
    key, sep, raw = text.partition(":")
    if not sep or not key.isidentifier():
        raise ValueError(f"expected key:value with a name as key, got {text!r}")
    return key, parse_value(raw)


def parse_kv_pairs(items: Iterable[str] | None, option: str = "key:value") -> dict[str, Any]:
    """Several ``key:value`` items as a dict; ``ValueError`` naming ``option`` for a malformed
    item or a key given twice."""
    result: dict[str, Any] = {}
    for item in items or ():
        try:
            key, value = parse_key_value(item)
        except ValueError as error:
            raise ValueError(f"{option}: {error}") from None
        if key in result:
            raise ValueError(f"{option}: {key!r} given twice")
        result[key] = value
    return result
