"""Argument checks shared by the gaits and the environment: errors that name the parameter."""

from __future__ import annotations

import math


def check_finite(name: str, value: float) -> float:
    """``value`` as a float; NaN and inf raise ``ValueError`` naming ``name``."""
    value = float(value)
    if not math.isfinite(value):
        raise ValueError(f"{name} must be finite, got {value}")
    return value


def check_positive(name: str, value: float) -> float:
    """A finite ``value > 0``."""
    value = check_finite(name, value)
    if value <= 0.0:
        raise ValueError(f"{name} must be positive, got {value}")
    return value


def check_int(name: str, value: float, minimum: int) -> int:
    """An integer-valued ``value >= minimum``; NaN and inf fail with a message naming ``name``."""
    if not (math.isfinite(float(value)) and int(value) == value and value >= minimum):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value}")
    return int(value)
