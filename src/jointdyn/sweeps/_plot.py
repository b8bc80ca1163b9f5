"""Drawing frequency-response curves: steady amplitudes as lines, points
without a steady state as markers on the axis (never as numbers)."""

from __future__ import annotations

import numpy as np

from .. import config

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
    for code, name in enumerate(config.SWEEP_STATUS):
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
