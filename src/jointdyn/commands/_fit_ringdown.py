"""``jointdyn fit --ringdown FILE.csv``: a ring-down to a backbone to a fitted model.

The CSV has a header row and the columns ``t`` (s) and one of ``x`` (m),
``v`` (m/s) or ``a`` (m/s^2), uniformly sampled. The backbone is extracted
by :func:`jointdyn.backbone_from_ringdown` and fitted as ``--backbone`` would
be (``--mass``, ``--model``); with ``--out DIR`` it is also written as
``ringdown_backbone.csv`` with the ``--backbone`` columns, trimmed to the amplitudes where the
fit determines the damping ratio within its bound (``damping_range`` of ``fit.json``). ``--band LOW:HIGH``
(Hz) gives the mode's pass band where the spectrum's peak does not (a decay
through macroslip drifts in frequency enough to show two peaks).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

SIGNAL_COLUMNS = ("x", "v", "a")
BACKBONE_FILE = "ringdown_backbone.csv"


def _signal_column(path) -> str:
    from .. import _validate as V

    path = V.input_file("--ringdown", path)
    try:
        with open(path, encoding="utf-8") as fh:
            header = [c.strip() for c in fh.readline().split(",")]
    except (OSError, UnicodeDecodeError) as exc:
        raise ValueError(f"--ringdown {str(path)!r} cannot be read: {exc}") from None
    found = [c for c in SIGNAL_COLUMNS if c in header]
    if len(found) != 1:
        raise ValueError(f"--ringdown {str(path)!r} must have the column t and exactly one of x (m), v (m/s), "
                         f"a (m/s^2); header: {', '.join(header)}")
    return found[0]


def read_ringdown(path, read_columns) -> tuple:
    """(t, signal, kind) of a ring-down CSV file (module docstring), read by ``read_columns``
    (the reader of ``jointdyn fit``'s other files)."""
    kind = _signal_column(path)
    d = read_columns(path, ("t", kind), "--ringdown")
    if not np.all(np.diff(d["t"]) > 0.0):
        raise ValueError(f"--ringdown {str(path)!r}: t must increase strictly from row to row")
    return d["t"], d[kind], kind


def parse_band(text: str) -> tuple[float, float]:
    """``--band LOW:HIGH`` (Hz) -> (low, high) rad/s with 0 < low < high."""
    from .. import _validate as V

    lo, hi = V.positive_interval("--band", text, ("LOW", "HIGH"), "Hz", "Hz")
    return 2.0 * np.pi * lo, 2.0 * np.pi * hi


def backbone_of(args, read_columns):
    """The extracted :class:`~jointdyn.identify.RingdownBackbone` of ``args.ringdown``, in the pass band
    ``args.band`` (rad/s) when given (ValueError naming the file, or ``--band``, on bad data)."""
    from ..identify import backbone_from_ringdown

    t, y, kind = read_ringdown(args.ringdown, read_columns)
    band = getattr(args, "band", None)
    try:
        return backbone_from_ringdown(t, y, kind, band=band)
    except ValueError as exc:
        msg = str(exc).replace("pass band=", "give the mode's pass band as --band LOW:HIGH (Hz)")
        if band is not None and "band" in msg:
            msg = msg.replace("band must be", "--band must be")
        raise ValueError(f"--ringdown {str(args.ringdown)!r}: {msg}") from None


def backbone_rows(b, damping_range) -> np.ndarray:
    """The backbone points written: those of the fit's damping range (``FitResult.damping_range``:
    where the ring-down determines the damping ratio within its bound), or every point where the
    range was not assessed (None) or holds fewer than two points (the JSON says so)."""
    keep = np.ones(b.amplitude_m.size, bool)
    if damping_range is not None and damping_range["points"] >= 2:
        keep = np.array(damping_range["determined"], bool)
    return keep


def backbone_csv(b, damping_range=None) -> str:
    """The backbone as CSV text with the ``--backbone`` columns, trimmed to the fit's damping range
    (:func:`backbone_rows`)."""
    keep = backbone_rows(b, damping_range)
    lines = ["amplitude_m,omega_rad_s,damping_ratio"]
    for row in zip(b.amplitude_m[keep], b.omega_rad_s[keep], b.damping_ratio[keep]):
        lines.append(",".join(f"{float(v):.17g}" for v in row))
    return "\n".join(lines) + "\n"


def write_backbone(out, b, damping_range=None) -> None:
    from .._io import atomic_path

    with atomic_path(Path(out) / BACKBONE_FILE) as tmp:
        Path(tmp).write_text(backbone_csv(b, damping_range))
