"""Stopping a study cleanly: Ctrl-C and SIGTERM are taken only at safe points.

A safe point (:func:`stop_point`) is between env steps of a trial, which Optuna then records as
failed (a rerun redoes it), or between trials. Raised anywhere else, the interrupt could land
while a trial's result is being written, leaving it RUNNING in the storage (a rerun would count
it as another process's and skip it until the heartbeat's grace period fails it) or a
half-written transaction.
"""

from __future__ import annotations

import signal
from typing import Any

_stop_requested = False


def request_stop(signum: int, frame: Any) -> None:
    """Signal handler: ask for a stop at the next safe point."""
    global _stop_requested
    _stop_requested = True


def catch_stop_signals() -> dict[int, Any]:
    """Route SIGINT and SIGTERM to the stop request; return the previous handlers."""
    global _stop_requested
    _stop_requested = False
    return {sig: signal.signal(sig, request_stop) for sig in (signal.SIGINT, signal.SIGTERM)}


def restore_signals(previous: dict[int, Any]) -> None:
    """Put back the handlers :func:`catch_stop_signals` returned."""
    for sig, handler in previous.items():
        signal.signal(sig, handler)


def stop_point(*_: Any) -> None:
    """Raise ``KeyboardInterrupt`` here if a stop was requested (also a run_episode callback)."""
    if _stop_requested:
        raise KeyboardInterrupt
