"""The one home of drawing response curves: time-domain sweeps (steady amplitudes as lines, points
without a steady state as markers on a rug, never as numbers) and harmonic-balance branches (one line
per run of joined points: :func:`branch_pieces`, the one break rule, from ``point_status``).

Used by the command line (``jointdyn frc``) and the figures.
"""

from __future__ import annotations

import numpy as np

from ..dynamics.status import SteadyStatus

__all__ = ["RUG_MARKERS", "plot_frc_curve", "mark_legend", "branch_pieces"]

#: rug marker per non-periodic status name (marker, face colour or None for filled)
RUG_MARKERS = {"not-settled": ("o", "none"), "unbounded": ("x", None)}
_MARKS = RUG_MARKERS


def plot_frc_curve(ax, gamma, amplitude, status, *, color=None, linestyle="-", label=None, rug_y=0.03):
    """Draw one sweep line on ``ax``.

    Periodic points (status 0) are joined by a line, broken across the other
    points; points that reached no steady state are drawn as markers on a rug
    at height ``rug_y`` (axes fraction): ``x`` unbounded, open circle
    not settled.

    Returns
    -------
    color : the colour used.
    """
    gamma = np.asarray(gamma, float)
    amplitude = np.asarray(amplitude, float)
    status = np.asarray(status, int)
    ok = status == 0
    y = np.where(ok, amplitude, np.nan)
    (line,) = ax.plot(gamma, y, linestyle=linestyle, color=color, label=label, lw=1.2)
    color = line.get_color()
    trans = ax.get_xaxis_transform()
    for s in SteadyStatus:
        code, name = s.code, s.value
        if name not in _MARKS:
            continue
        sel = status == code
        if np.any(sel):
            marker, face = _MARKS[name]
            ax.plot(gamma[sel], np.full(sel.sum(), rug_y), linestyle="none", marker=marker, ms=4,
                    color=color, markerfacecolor=face if face else color, transform=trans, clip_on=False)
    return color


#: legend text per non-periodic status name
_MARK_LABELS = {"unbounded": "unbounded (no steady state)", "not-settled": "not settled"}


def mark_legend(ax, **kw):
    """Legend entries for the rug markers that ``ax`` shows (added to the
    existing handles): a status no point has gets no entry."""
    from matplotlib.lines import Line2D

    drawn = {line.get_marker() for line in ax.lines if line.get_linestyle() in ("None", "none", "")}
    handles, labels = ax.get_legend_handles_labels()
    for name in ("unbounded", "not-settled"):
        marker, face = _MARKS[name]
        if marker in drawn:
            handles.append(Line2D([], [], color="k", linestyle="none", marker=marker, ms=4,
                                  markerfacecolor=face if face else "k"))
            labels.append(_MARK_LABELS[name])
    ax.legend(handles, labels, **kw)


def branch_pieces(point_status) -> list:
    """Index runs of a harmonic-balance branch, each drawn as one line.

    A line is drawn to a point only where it is joined to the point before
    it (``point_status`` in :data:`jointdyn.hb.results.JOINED`: ``joined`` or ``corner``); every
    other point (the start of a segment, a point reached by a jump, the
    point where a segment stopped short) starts a new run.
    """
    from ..hb.results import JOINED

    ps = np.asarray(point_status, dtype=str)
    if ps.size == 0:
        return []
    starts = np.flatnonzero(~np.isin(ps, JOINED))
    starts = starts[starts > 0]
    return np.split(np.arange(ps.size), starts)
