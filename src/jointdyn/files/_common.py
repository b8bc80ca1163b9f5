"""The one-line errors of a system file and the TOML values every table reads (numbers, DOFs, lists)."""

from __future__ import annotations

import math

import numpy as np

from .. import _validate as V


class _Where:
    """Key path inside one file: formats the one-line errors."""

    def __init__(self, file: Path):
        self.file = file

    def error(self, key: str, message: str) -> ValueError:
        """``<file>: <key> <message>`` as a ValueError (one line)."""
        return ValueError(" ".join(f"{self.file}: {key} {message}".split()))

    def wrap(self, key: str, exc: ValueError, fields=()) -> ValueError:
        """A constructor's error under ``key``: ``key.field ...`` when the
        message starts with one of ``fields``, else ``key: ...``."""
        msg = str(exc)
        first = msg.split(" ", 1)[0]
        if first in fields:
            return self.error(f"{key}.{first}", msg.split(" ", 1)[1] if " " in msg else "")
        return ValueError(" ".join(f"{self.file}: {key}: {msg}".split()))


def _table(where: _Where, key: str, value, allowed, required=()) -> dict:
    """A TOML table with only ``allowed`` keys and every ``required`` one
    (``key`` "" is the document itself)."""
    if not isinstance(value, dict):
        raise where.error(key, f"must be a table, got {type(value).__name__} {value!r:.60}")
    def full(k):
        return f"{key}.{k}" if key else k

    for k in value:
        if k not in allowed:
            raise where.error(full(k), f"is not a known key (allowed: {', '.join(allowed)})")
    for k in required:
        if k not in value:
            raise where.error(full(k), "is missing")
    return value


def _number(where: _Where, key: str, value, *, low=-math.inf, low_open=False) -> float:
    """A finite TOML number (integer or float, not a string or boolean) above ``low``."""
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise where.error(key, f"must be a number, got {type(value).__name__} {value!r:.60}")
    try:
        v = float(value)
    except OverflowError:
        raise where.error(key, f"must be finite, got {V.short_repr(value)}") from None
    if not math.isfinite(v):
        raise where.error(key, f"must be finite, got {v!r}")
    if (v <= low) if low_open else (v < low):
        bound = f"> {low:g}" if low_open else f">= {low:g}"
        raise where.error(key, f"must be {bound}, got {v!r}")
    return v


def _dof(where: _Where, key: str, value, n: int, *, ground: bool = False) -> int:
    """A DOF index in [0, n - 1] (or -1 for ground when ``ground``)."""
    if isinstance(value, bool) or not isinstance(value, int):
        raise where.error(key, f"must be an integer DOF index, got {type(value).__name__} {value!r:.60}")
    lo = -1 if ground else 0
    if not lo <= value < n:
        extra = " (or -1 for ground)" if ground else ""
        got = value if abs(value) < 10**20 else V.short_repr(value)
        raise where.error(key, f"must be in [0, {n - 1}]{extra}, got {got}")
    return value


def _vector(where: _Where, key: str, value, length: int | None = None) -> np.ndarray:
    """A list of finite numbers (of ``length`` when given)."""
    if not isinstance(value, list) or not value:
        raise where.error(key, f"must be a non-empty list of numbers, got {value!r:.60}")
    out = np.array([_number(where, f"{key}[{i}]", v) for i, v in enumerate(value)])
    if length is not None and out.size != length:
        raise where.error(key, f"must have {length} entries (one per DOF), got {out.size}")
    return out
