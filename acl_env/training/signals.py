"""Deferred signals: Ctrl-C and SIGTERM ask a command to stop at a consistent point instead of
raising wherever they land (a closed stdout or stderr is :func:`acl_env.io.guarded_output`'s)."""

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


def is_output_failure(error: BaseException) -> bool:
    """Whether ``error`` is a writer giving up on a closed output: a broken pipe, or the
    ``SystemExit`` rich's console raises after one (``Console.on_broken_pipe``)."""
    if isinstance(error, SystemExit):
        return isinstance(error.__context__, BrokenPipeError)
    return isinstance(error, BrokenPipeError)
