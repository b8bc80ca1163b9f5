"""Drawing frequency-response curves: steady amplitudes as lines, points
without a steady state as markers on the axis (never as numbers)."""

from __future__ import annotations

import numpy as np

from ..dynamics.status import SteadyStatus

__all__ = ["plot_frc_curve", "mark_legend"]

#: marker per non-periodic status name
_MARKS = {"not-settled": ("o", "none"), "unbounded": ("x", None)}


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


def mark_legend(ax, **kw):
    """Legend entries for the rug markers (added to the existing handles)."""
    from matplotlib.lines import Line2D

    handles, labels = ax.get_legend_handles_labels()
    handles += [
        Line2D([], [], color="k", linestyle="none", marker="x", ms=4),
        Line2D([], [], color="k", linestyle="none", marker="o", markerfacecolor="none", ms=4),
    ]
    labels += ["unbounded (no steady state)", "not settled"]
    ax.legend(handles, labels, **kw)
