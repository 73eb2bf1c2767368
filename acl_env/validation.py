"""Argument checks shared by the gaits and the environment: errors that name the parameter.

Every check raises ``TypeError`` for a value of the wrong kind (a string where a number is
expected, ``1`` where a bool is, a scalar where a pair is) and ``ValueError`` for a value of the
right kind outside its range; both messages name the argument and say what is accepted. Numbers
are ``int``, ``float`` or NumPy scalars, never ``bool`` (``True`` is not a pole radius) and never
strings (``"0.5"`` is refused rather than parsed: parsing belongs to the command line). An integer
too large for a float (``10**400``) is a number out of range: a ``ValueError`` naming the argument,
never Python's bare ``OverflowError``; messages show such values abbreviated (:func:`shown`).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Collection, Mapping, Sequence
from numbers import Integral, Real
from typing import Any, TypeVar

import numpy as np

T = TypeVar("T")


SHOWN_CHARS = 80  # longest value a message quotes; the rest is elided


def shown(value: object) -> str:
    """``repr(value)`` for an error message: at most :data:`SHOWN_CHARS` characters, a huge
    integer as its number of digits (Python refuses to print one of over 4300), and never an
    exception of its own."""
    if isinstance(value, Integral) and not _is_bool(value):
        bits = abs(int(value)).bit_length()
        if bits > 64:
            return f"an integer of about {int(bits * math.log10(2)) + 1} digits"
    try:
        text = repr(value)
    except Exception:  # a repr that fails (a huge integer inside a list): name the type
        text = f"<{type(value).__name__}>"
    return text if len(text) <= SHOWN_CHARS else f"{text[: SHOWN_CHARS - 3]}..."


def _kind(value: object) -> str:
    return f"{shown(value)} ({type(value).__name__})"


def _is_bool(value: object) -> bool:
    return isinstance(value, bool | np.bool_)


def check_bool(name: str, value: object) -> bool:
    """``value`` as a ``bool``: only ``True``/``False`` (or NumPy's), not ``1``, not ``"false"``."""
    if not _is_bool(value):
        raise TypeError(f"{name} must be True or False, got {_kind(value)}")
    return bool(value)


def check_finite(name: str, value: object) -> float:
    """``value`` as a float: a real number (not a bool, not a string), NaN and inf refused."""
    if _is_bool(value) or not isinstance(value, Real):
        raise TypeError(f"{name} must be a real number, got {_kind(value)}")
    try:
        number = float(value)
    except OverflowError:  # an int (or Fraction) beyond the largest float, ~1.8e308
        raise ValueError(f"{name} must be finite, got {shown(value)}") from None
    if not math.isfinite(number):
        raise ValueError(f"{name} must be finite, got {number}")
    return number


def check_positive(name: str, value: object, maximum: float | None = None) -> float:
    """A finite ``0 < value`` (``<= maximum`` when given)."""
    value = check_finite(name, value)
    if value <= 0.0 or (maximum is not None and value > maximum):
        accepted = "positive" if maximum is None else f"in (0, {maximum}]"
        raise ValueError(f"{name} must be {accepted}, got {value}")
    return value


def check_range(
    name: str,
    value: object,
    low: float,
    high: float,
    *,
    low_open: bool = False,
    high_open: bool = False,
) -> float:
    """A finite ``value`` in ``[low, high]``; ``low_open``/``high_open`` exclude the ends."""
    value = check_finite(name, value)
    too_low = value <= low if low_open else value < low
    too_high = value >= high if high_open else value > high
    if too_low or too_high:
        interval = f"{'(' if low_open else '['}{low}, {high}{')' if high_open else ']'}"
        raise ValueError(f"{name} must be in {interval}, got {value}")
    return value


def check_int(name: str, value: object, minimum: int, maximum: int | None = None) -> int:
    """An ``int`` (or NumPy integer) in ``[minimum, maximum]``.

    A non-number (a string, ``None``, a bool) is a ``TypeError``; a float, even ``20.0``, NaN or
    inf, is a number of the wrong value: a ``ValueError``.
    """
    accepted = f">= {minimum}" if maximum is None else f"in [{minimum}, {maximum}]"
    if _is_bool(value) or not isinstance(value, Real):
        raise TypeError(f"{name} must be an integer {accepted}, got {_kind(value)}")
    if not isinstance(value, Integral):
        raise ValueError(f"{name} must be an integer {accepted}, got {_kind(value)}")
    value = int(value)
    if value < minimum or (maximum is not None and value > maximum):
        raise ValueError(f"{name} must be an integer {accepted}, got {shown(value)}")
    return value


def check_choice(name: str, value: object, choices: Collection[T]) -> T:
    """One of ``choices``: a value of none of their types is a ``TypeError``, another a
    ``ValueError``."""
    accepted = ", ".join(map(repr, choices))
    # A str subclass (NumPy's) passes for a str; a bool never passes for an int.
    if not any(isinstance(value, type(c)) and _is_bool(value) == _is_bool(c) for c in choices):
        raise TypeError(f"{name} must be one of {accepted}; got {_kind(value)}")
    if value not in choices:
        raise ValueError(f"{name} must be one of {accepted}; got {shown(value)}")
    return value  # type: ignore[return-value]


def check_sequence(
    name: str,
    value: object,
    length: int,
    item: Callable[[str, object], T],
) -> tuple[T, ...]:
    """A sequence (list, tuple, 1-D array; not a string) of exactly ``length`` items, each passed
    through ``item(f"{name}[i]", x)``."""
    if isinstance(value, np.ndarray):
        if value.ndim != 1:
            raise TypeError(
                f"{name} must be a sequence of {length} items, got an array {shown(value)}"
            )
        value = list(value)
    if isinstance(value, str | bytes) or not isinstance(value, Sequence):
        raise TypeError(f"{name} must be a sequence of {length} items, got {_kind(value)}")
    if len(value) != length:
        raise ValueError(f"{name} must have {length} items, got {len(value)}: {shown(value)}")
    return tuple(item(f"{name}[{i}]", x) for i, x in enumerate(value))


def check_mapping(name: str, value: object, known: Collection[str]) -> dict[str, Any]:
    """A mapping with string keys drawn from ``known``, as a plain ``dict``."""
    if not isinstance(value, Mapping):
        raise TypeError(
            f"{name} must be a mapping (dict) with keys from {sorted(known)}, got {_kind(value)}"
        )
    bad = [key for key in value if not isinstance(key, str)]
    if bad:
        raise TypeError(f"{name} keys must be strings from {sorted(known)}, got {shown(bad)}")
    unknown = sorted(set(value) - set(known))
    if unknown:
        raise ValueError(f"{name} has unknown keys {shown(unknown)}; known: {sorted(known)}")
    return dict(value)


def check_string(name: str, value: object) -> str:
    """A ``str``."""
    if not isinstance(value, str):
        raise TypeError(f"{name} must be a string, got {_kind(value)}")
    return value


__all__ = [
    "check_bool",
    "check_choice",
    "check_finite",
    "check_int",
    "check_mapping",
    "check_positive",
    "check_range",
    "check_sequence",
    "check_string",
    "shown",
]
