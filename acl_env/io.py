"""Files and command-line values, for the core and every command: the one JSON writer and reader
(atomic writes, strict JSON), and the one ``key:value`` parser. Numpy only, no PyYAML."""

from __future__ import annotations

import ast
import contextlib
import json
import math
import os
import sys
import tempfile
from collections.abc import Callable, Iterable, Iterator, Mapping
from contextlib import contextmanager
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


def check_output(
    path: str | Path,
    suffixes: Iterable[str] = (),
    fields: Mapping[str, Any] | None = None,
    create_folder: bool = False,
) -> Path:
    """``path`` as a file to write later, checked now (nothing is left behind); ``ValueError``
    saying what is wrong. With ``fields``, ``path`` is a template (``run_{seed}.json``) that must
    format with them; the formatted path is checked and returned.

    The folder must exist and take a new file (probed by creating and removing one: permission
    bits say nothing to root, nor of ``/proc``); the path must not be a folder or another
    non-file; its suffix must be one of ``suffixes`` (any case) when given. A symlink at the path
    is fine: :func:`atomic_write` replaces the link, never writes through it out of its folder.
    With ``create_folder``, the folder may be missing (the caller makes it): see
    :func:`check_writable_folder`.
    """
    text = str(path)
    if fields is not None:
        try:
            text = text.format(**fields)
        except (KeyError, IndexError, ValueError, AttributeError) as error:
            raise ValueError(
                f"{str(path)!r} does not format ({type(error).__name__}: {error})"
            ) from None
    path = Path(text)
    suffixes = tuple(suffixes)
    if path.is_dir():
        raise ValueError(f"expected a file path, got the folder {text!r}")
    if suffixes and path.suffix.lower() not in suffixes:
        raise ValueError(f"expected a file ending in {' or '.join(suffixes)}, got {text!r}")
    if path.exists() and not path.is_file():
        raise ValueError(f"{text!r} exists and is not a regular file")
    try:
        check_writable_folder(path.parent, create=create_folder)
    except ValueError as error:
        raise ValueError(f"{error}, so {text!r} cannot be written") from None
    return path


def check_writable_folder(
    folder: str | Path, what: str = "the folder", create: bool = False
) -> Path:
    """``folder`` exists and a file can be created in it (probed: created and removed at once);
    ``ValueError`` naming ``what`` otherwise. With ``create``, a folder the caller will make
    (with its parents) may be missing: its nearest existing ancestor is probed instead."""
    folder = probed = Path(folder)
    if create:
        while not probed.exists() and probed != probed.parent:
            if probed.is_symlink():
                raise ValueError(f"{what} {str(probed)!r} is a broken symbolic link")
            probed = probed.parent
    if not probed.is_dir():
        missing = "is not a folder" if probed.exists() else "does not exist"
        raise ValueError(f"{what} {str(probed)!r} {missing}")
    try:
        fd, probe = tempfile.mkstemp(prefix=".write-probe.", dir=probed)
    except OSError as error:
        raise ValueError(f"{what} {str(probed)!r} is not writable ({error.strerror})") from None
    os.close(fd)
    os.unlink(probe)
    return folder


@contextmanager
def atomic_output(path: str | Path) -> Iterator[Path]:
    """A temporary path in ``path``'s folder, with its suffix (a figure or video writer picks its
    format by it), renamed over ``path`` when the block ends without an error (a symlink at
    ``path`` is replaced, not followed) and removed when it raises."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(
        prefix=f".{path.stem}.", suffix=f".tmp{path.suffix}", dir=path.parent
    )
    os.close(fd)
    try:
        yield Path(tmp)
        os.chmod(tmp, 0o666 & ~_UMASK)
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


# --- standard streams: a reader that goes away (``| head -1``) loses its output, never the work


class GuardedStream:
    """A text stream whose failures are not the writer's problem: the first write or flush that
    fails (a broken pipe, a closed terminal) points the stream's file descriptor at
    ``os.devnull`` (so that later writers, Python's final flush included, succeed) and from then
    on output is dropped. Everything else is the wrapped stream's."""

    def __init__(self, stream: Any, name: str) -> None:
        self.stream, self.name = stream, name
        self.lost: str | None = None  # why the output was lost

    def write(self, text: str) -> int:
        if self.lost is None:
            try:
                return self.stream.write(text)
            except (OSError, ValueError) as error:  # ValueError: a closed file
                self.lose(error)
        return len(text)

    def writelines(self, lines: Any) -> None:
        for line in lines:
            self.write(line)

    def flush(self) -> None:
        if self.lost is None:
            try:
                self.stream.flush()
            except (OSError, ValueError) as error:
                self.lose(error)

    def lose(self, error: BaseException) -> None:
        """Drop this stream's output from now on (``error`` is why)."""
        self.lost = f"{type(error).__name__}: {error}"
        with contextlib.suppress(OSError, ValueError):
            devnull = os.open(os.devnull, os.O_WRONLY)
            try:
                os.dup2(devnull, self.stream.fileno())
            finally:
                os.close(devnull)
        with contextlib.suppress(OSError, ValueError):
            self.stream.flush()  # what the buffer still holds goes to devnull (or stays)

    def __getattr__(self, name: str) -> Any:
        return getattr(self.stream, name)


class GuardedOutput:
    """The guarded ``sys.stdout`` and ``sys.stderr`` of :func:`guarded_output`."""

    def __init__(self, streams: list[GuardedStream]) -> None:
        self.streams = streams

    @property
    def lost(self) -> dict[str, str]:
        """The streams whose output was lost, and why."""
        return {s.name: s.lost for s in self.streams if s.lost is not None}


@contextlib.contextmanager
def guarded_output() -> Iterator[GuardedOutput]:
    """Replace ``sys.stdout`` and ``sys.stderr`` by :class:`GuardedStream` s while the block runs
    (``print``, loggers and progress bars that look the streams up then write through them);
    on exit flush them, still guarded, and put the originals back. Nested, it reuses the guards
    in place."""
    originals = sys.stdout, sys.stderr
    guarded = [
        s if isinstance(s, GuardedStream) else GuardedStream(s, n)
        for s, n in zip(originals, ("stdout", "stderr"), strict=True)
        if s is not None
    ]
    for stream in guarded:
        setattr(sys, stream.name, stream)
    try:
        yield GuardedOutput(guarded)
    finally:
        for stream in guarded:
            stream.flush()
        sys.stdout, sys.stderr = originals


def console_script(main: Callable[[], object]) -> Callable[[], None]:
    """A console-script entry point for ``main``: ``main()`` with the standard streams guarded
    (:func:`guarded_output`: a closed pipe drops what is printed after it, and the command goes
    on to write every file it was asked for and exits 0), whatever it returns dropped (a
    console script runs ``sys.exit(target())``, which would print a returned document and exit
    with status 1)."""

    def run() -> None:
        with guarded_output():
            main()

    return run
