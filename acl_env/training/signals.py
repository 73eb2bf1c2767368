"""Deferred signals and guarded output: Ctrl-C and SIGTERM ask a command to stop at a consistent
point instead of raising wherever they land, and a closed stdout or stderr (``| head``, a ``tee``
killed by the same Ctrl-C) never stops it from saving its work."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Callable, Iterator
from typing import Any


@contextlib.contextmanager
def deferred_signals(on_signal: Callable[[int], None], restore: bool = True) -> Iterator[None]:
    """SIGINT and SIGTERM call ``on_signal`` instead of raising; on exit the previous handlers
    come back (``restore``), or the signals are ignored: a command line that has saved its work
    must not die of a late second signal in its last lines.

    An inherited ignored SIGINT stays ignored: a shell starts background jobs (``acl-train &``
    from a script, ``nohup ... &``) that way so that a terminal's Ctrl-C does not reach them.
    SIGTERM is always handled. Messages go through ``os.write``: a ``print`` inside a handler can
    hit a reentrant stdout.
    """
    seen: list[int] = []

    def handler(signum: int, frame: object) -> None:
        name = signal.Signals(signum).name
        if not seen:
            msg = f"\n{name}: stopping after the current update; saving what was trained\n"
        else:
            msg = f"\n{name} again: still saving (files are replaced atomically), please wait\n"
        seen.append(signum)
        with contextlib.suppress(OSError, ValueError):
            os.write(sys.stderr.fileno(), msg.encode())
        on_signal(signum)

    handled = [signal.SIGTERM]
    if signal.getsignal(signal.SIGINT) is not signal.SIG_IGN:
        handled.insert(0, signal.SIGINT)
    previous = {s: signal.signal(s, handler) for s in handled}
    try:
        yield
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old if restore else signal.SIG_IGN)


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


def is_output_failure(error: BaseException) -> bool:
    """Whether ``error`` is a writer giving up on a closed output: a broken pipe, or the
    ``SystemExit`` rich's console raises after one (``Console.on_broken_pipe``)."""
    if isinstance(error, SystemExit):
        return isinstance(error.__context__, BrokenPipeError)
    return isinstance(error, BrokenPipeError)
