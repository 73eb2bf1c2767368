"""Deferred signals: Ctrl-C and SIGTERM ask a command to stop at a consistent point instead of
raising wherever they land."""

from __future__ import annotations

import contextlib
import os
import signal
import sys
from collections.abc import Callable, Iterator


@contextlib.contextmanager
def deferred_signals(on_signal: Callable[[int], None], restore: bool = True) -> Iterator[None]:
    """SIGINT and SIGTERM call ``on_signal`` instead of raising; on exit the previous handlers
    come back (``restore``), or the signals are ignored: a command line that has saved its work
    must not die of a late second signal in its last lines.

    Messages go through ``os.write``: a ``print`` inside a handler can hit a reentrant stdout.
    """
    seen: list[int] = []

    def handler(signum: int, frame: object) -> None:
        name = signal.Signals(signum).name
        if not seen:
            msg = f"\n{name}: stopping after the current update; saving what was trained\n"
        else:
            msg = f"\n{name} again: still saving (files are replaced atomically), please wait\n"
        seen.append(signum)
        with contextlib.suppress(OSError):
            os.write(sys.stderr.fileno(), msg.encode())
        on_signal(signum)

    previous = {s: signal.signal(s, handler) for s in (signal.SIGINT, signal.SIGTERM)}
    try:
        yield
    finally:
        for signum, old in previous.items():
            signal.signal(signum, old if restore else signal.SIG_IGN)
