"""Input validation: every error names the parameter and the allowed range."""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "positive",
    "nonnegative",
    "finite",
    "positive_int",
    "finite_array",
    "increasing",
    "same_length",
    "choice",
    "in_range",
]


def _num(name: str, value) -> float:
    try:
        v = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(v):
        raise ValueError(f"{name} must be finite, got {v!r}")
    return v


def finite(name: str, value) -> float:
    """A finite real number (any sign)."""
    return _num(name, value)


def positive(name: str, value) -> float:
    """A finite number > 0."""
    v = _num(name, value)
    if not v > 0.0:
        raise ValueError(f"{name} must be > 0 (allowed range (0, inf)), got {v!r}")
    return v


def nonnegative(name: str, value) -> float:
    """A finite number >= 0."""
    v = _num(name, value)
    if not v >= 0.0:
        raise ValueError(f"{name} must be >= 0 (allowed range [0, inf)), got {v!r}")
    return v


def in_range(name: str, value, lo: float, hi: float, *, lo_open=False, hi_open=False) -> float:
    """A finite number in [lo, hi] (or open at either end)."""
    v = _num(name, value)
    ok_lo = v > lo if lo_open else v >= lo
    ok_hi = v < hi if hi_open else v <= hi
    if not (ok_lo and ok_hi):
        lb = "(" if lo_open else "["
        rb = ")" if hi_open else "]"
        raise ValueError(f"{name} must be in {lb}{lo}, {hi}{rb}, got {v!r}")
    return v


def positive_int(name: str, value, minimum: int = 1) -> int:
    """An integer >= minimum."""
    if isinstance(value, bool):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    try:
        f = float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}") from None
    if not math.isfinite(f) or f != int(f) or int(f) < minimum:
        raise ValueError(f"{name} must be an integer >= {minimum}, got {value!r}")
    return int(f)


def finite_array(name: str, values, ndim: int = 1) -> np.ndarray:
    """A float64 array of the given rank with finite entries only."""
    try:
        a = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be an array of real numbers") from None
    if a.ndim != ndim:
        raise ValueError(f"{name} must be a {ndim}-D array, got shape {a.shape}")
    if a.size == 0:
        raise ValueError(f"{name} must not be empty")
    if not np.all(np.isfinite(a)):
        bad = int(np.flatnonzero(~np.isfinite(a.ravel()))[0])
        raise ValueError(f"{name} must be finite everywhere (NaN/inf at index {bad})")
    return np.ascontiguousarray(a)


def increasing(name: str, t: np.ndarray) -> np.ndarray:
    """A strictly increasing 1-D array."""
    if t.size > 1 and not np.all(np.diff(t) > 0):
        i = int(np.flatnonzero(~(np.diff(t) > 0))[0])
        raise ValueError(f"{name} must be strictly increasing (not at index {i + 1})")
    return t


def same_length(**arrays) -> int:
    """All arrays have the same length; returns it."""
    lengths = {k: len(v) for k, v in arrays.items()}
    if len(set(lengths.values())) > 1:
        desc = ", ".join(f"{k}={n}" for k, n in lengths.items())
        raise ValueError(f"histories must have the same length, got {desc}")
    return next(iter(lengths.values()))


def choice(name: str, value, allowed) -> str:
    """One of a fixed set of names."""
    allowed = list(allowed)
    if value not in allowed:
        raise ValueError(f"{name} must be one of {', '.join(map(str, allowed))}; got {value!r}")
    return value
