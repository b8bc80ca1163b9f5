"""Input validation: every error names the parameter and the allowed range."""

from __future__ import annotations

import math
import os
import tempfile
from pathlib import Path

import numpy as np

__all__ = [
    "positive",
    "positive_interval",
    "nonnegative",
    "finite",
    "positive_int",
    "finite_array",
    "increasing",
    "same_length",
    "choice",
    "in_range",
    "derived",
    "count_at_most",
    "short_repr",
    "memory_budget",
    "memory_fits",
    "output_dir",
    "input_file",
]


def short_repr(value) -> str:
    """``repr(value)``, an integer of many digits shortened to its digit count."""
    if isinstance(value, int) and not isinstance(value, bool) and abs(value).bit_length() > 200:
        return f"an integer of {len(str(abs(value))) if abs(value).bit_length() < 13000 else 'over 4000'} digits"
    return f"{value!r:.80}"


def _num(name: str, value) -> float:
    try:
        v = float(value)
    except OverflowError:
        raise ValueError(f"{name} must be finite, got {short_repr(value)}") from None
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


def positive_interval(name: str, text, ends=("MIN", "MAX"), unit: str = "m", unit_name: str = "metres"):
    """``LO:HI`` of a command-line option ``name`` -> (lo, hi) with 0 < lo < hi (``ends`` name the two
    numbers, ``unit`` and ``unit_name`` their unit, in the messages)."""
    low, high = ends
    parts = str(text).split(":")
    if len(parts) != 2:
        raise ValueError(f"{name} must be {low}:{high} ({unit_name}), got {text!r}")
    try:
        lo, hi = (float(s) for s in parts)
    except ValueError:
        raise ValueError(f"{name} must be {low}:{high} of numbers ({unit_name}), got {text!r}") from None
    positive(f"{name} {low}", lo)
    positive(f"{name} {high}", hi)
    if not hi > lo:
        raise ValueError(f"{name} {high} must be > {low} ({lo:g} {unit}), got {hi:g} {unit}")
    return lo, hi


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
    except (TypeError, ValueError, OverflowError):
        raise ValueError(f"{name} must be an integer >= {minimum}, got {short_repr(value)}") from None
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


def derived(label: str, value: float, *, positive: bool = False) -> float:
    """A quantity computed from several inputs: finite (and > 0 if asked).

    ``label`` names the quantity and the inputs it comes from, e.g.
    ``"fy = --mu x --n-ref"``, so that an overflow or underflow points at
    the parameters to change.
    """
    v = float(value)
    if not math.isfinite(v):
        raise ValueError(f"{label} must be finite (overflow), got {v!r}")
    if positive and not v > 0.0:
        raise ValueError(f"{label} must be > 0 (underflow), got {v!r}")
    return v


def count_at_most(label: str, count: float, limit: int, unit: str) -> int:
    """A size computed from several inputs, bounded before anything is allocated.

    ``count`` may be a float (inf, NaN or huge when the inputs are extreme);
    it is compared as a float and converted to int only when in range.
    """
    c = float(count)
    if not c <= limit:  # also catches NaN and inf
        raise ValueError(f"{label} must be at most {limit} {unit}, got {c:.4g}")
    return int(c)


def _available_bytes() -> int:
    """Memory available to a new allocation, bytes: MemAvailable of
    /proc/meminfo, else the physical memory (os.sysconf), else 4 GiB."""
    try:
        with open("/proc/meminfo", "rb") as fh:
            for line in fh:
                if line.startswith(b"MemAvailable:"):
                    return int(line.split()[1]) * 1024
    except (OSError, ValueError, IndexError):
        pass
    try:
        return int(os.sysconf("SC_PAGE_SIZE")) * int(os.sysconf("SC_PHYS_PAGES"))
    except (AttributeError, OSError, ValueError):
        return 4 << 30


def memory_budget() -> int:
    """Bytes one computation may allocate: ``config.MEMORY_LIMIT_BYTES``, or
    ``config.MEMORY_FRACTION`` of the memory available now."""
    from . import config

    if config.MEMORY_LIMIT_BYTES is not None:
        return int(config.MEMORY_LIMIT_BYTES)
    return int(config.MEMORY_FRACTION * _available_bytes())


def _gib(nbytes: float) -> str:
    return f"{nbytes / 2**30:.3g} GiB" if nbytes >= 2**30 else f"{nbytes / 2**20:.3g} MiB"


def memory_fits(label: str, nbytes: float, *, hint: str = "") -> None:
    """ValueError naming ``label`` (the option or parameter that sets the
    size) when an estimate of ``nbytes`` (a float: it may be huge or inf)
    exceeds :func:`memory_budget`; checked before anything is allocated."""
    from . import config

    budget = memory_budget()
    b = float(nbytes)
    if b <= budget:
        return
    where = ("config.MEMORY_LIMIT_BYTES" if config.MEMORY_LIMIT_BYTES is not None
             else f"{config.MEMORY_FRACTION:g} of the available memory, config.MEMORY_FRACTION")
    size = _gib(b) if math.isfinite(b) and b < 1e30 else f"{b:.3g} bytes"
    raise ValueError(f"{label} needs about {size} of memory, more than the bound of {_gib(budget)} ({where})"
                     + (f"; {hint}" if hint else ""))


def _probe_writable(directory: str) -> bool:
    """True when a file can really be created in ``directory`` (the
    permission bits do not stop root, a read-only mount or /proc does)."""
    try:
        fd, probe = tempfile.mkstemp(prefix=".jointdyn-probe-", dir=directory)
    except OSError:
        return False
    os.close(fd)
    os.unlink(probe)
    return True


def _path(name: str, path) -> Path:
    if not isinstance(path, (str, os.PathLike)) or not str(path):
        raise ValueError(f"{name} must be a file-system path (str or os.PathLike), got {path!r:.80}")
    return Path(path)


def output_dir(name: str, path, files=(), subdirs=()) -> Path:
    """A directory that exists and is writable, or can be created.

    Checked before any computing, so that no work is lost to an output that
    cannot be written: ``path`` is a directory or does not exist yet; its
    nearest existing ancestor is a directory in which files can be created
    (permissions and a probe file, removed at once); the ``files`` to be
    written into it are not existing directories; the ``subdirs`` are not
    existing files. Nothing is created.
    """
    p = _path(name, path)
    s = str(p)
    if os.path.lexists(s) and not os.path.isdir(s):
        raise ValueError(f"{name} must be a directory, got existing file {s!r}")
    anc = os.path.abspath(s)
    while not os.path.lexists(anc):
        anc = os.path.dirname(anc)
    if not os.path.isdir(anc):
        raise ValueError(f"{name} {s!r} cannot be created: {anc!r} is a file, not a directory")
    if not (os.access(anc, os.W_OK | os.X_OK) and _probe_writable(anc)):
        raise ValueError(f"{name} {s!r} is not writable: files cannot be created in {anc!r}")
    for f in files:
        if os.path.isdir(os.path.join(s, f)):
            raise ValueError(f"{name} {s!r} holds a directory named {f!r} where a file is to be written")
    for d in subdirs:
        q = os.path.join(s, d)
        if os.path.lexists(q) and not os.path.isdir(q):
            raise ValueError(f"{name} {s!r} holds a file named {d!r} where a directory is to be created")
        if os.path.isdir(q) and not (os.access(q, os.W_OK | os.X_OK) and _probe_writable(q)):
            raise ValueError(f"{name} {s!r} is not writable: files cannot be created in {q!r}")
    return p


def input_file(name: str, path) -> Path:
    """An existing regular file that can be opened and read."""
    p = _path(name, path)
    s = str(p)
    if not os.path.isfile(s):
        what = "a directory" if os.path.isdir(s) else "not a regular file" if os.path.lexists(s) else "no such file"
        raise ValueError(f"{name} must be an existing file, got {s!r} ({what})")
    try:
        with open(s, "rb") as fh:
            fh.read(1)
    except OSError as exc:
        raise ValueError(f"{name} {s!r} cannot be read: {exc.strerror or exc}") from None
    return p
