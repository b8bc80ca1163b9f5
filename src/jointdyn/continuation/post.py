"""Post-processing of a computed branch: its turning points (:func:`turning_points`), its local maxima
(:func:`local_maxima`) and a maximum refined between three points by solving on the arc
(:func:`refine_maximum`)."""

from __future__ import annotations

import math
from typing import Callable

import numpy as np

from .newton import _solve_damped
from .options import ContinuationOptions, make_options

__all__ = ["local_maxima", "refine_maximum", "turning_points"]


#: golden-section fraction of :func:`refine_maximum`'s fallback step, and the
#: margin (fraction of the bracket) a parabolic step keeps from the bracket's points
GOLDEN = 0.381966


GOLDEN_MARGIN = 0.05


#: a step of :func:`refine_maximum` that left the bracket wider than this fraction of its width before
#: is followed by a golden-section step (a golden step leaves 0.618 of it)
STALL_FRACTION = 0.7


def turning_points(lam, gap=None, band: float = 0.0, observed=None, observed_band: float = math.inf):
    """Indices where lam is extremal along a branch (secant turning points).

    A reversal counts only once lam has come back from the running extreme
    by more than ``band``, or, given ``observed`` values along the branch
    (what a plot shows against lam), once they have moved by more than
    ``observed_band`` from their value at the extreme while lam is still
    short of it (a fold whose branches are close in lam but far apart in
    the observable): jitter of the points of a piecewise-smooth branch is
    ignored. Points reached by a jump (``gap``) restart the search.
    """
    lam = np.asarray(lam, dtype=float)
    gap = np.zeros(lam.size, dtype=bool) if gap is None else np.asarray(gap, dtype=bool)
    obs = np.zeros(lam.size) if observed is None else np.asarray(observed, dtype=float)
    out = []
    i_ext = 0
    direction = 0
    for i in range(1, lam.size):
        if gap[i]:
            i_ext, direction = i, 0
            continue
        if direction == 0:
            if lam[i] != lam[i_ext] and (abs(lam[i] - lam[i_ext]) > band
                                         or abs(obs[i] - obs[i_ext]) > observed_band):
                direction = 1 if lam[i] > lam[i_ext] else -1
                i_ext = i
            continue
        if direction * (lam[i] - lam[i_ext]) >= 0:
            i_ext = i
        elif abs(lam[i] - lam[i_ext]) > band or abs(obs[i] - obs[i_ext]) > observed_band:
            out.append(i_ext)
            direction = -direction
            i_ext = i
    return np.array(out, dtype=int)


def local_maxima(values, gap=None, prominence: float = 0.0) -> np.ndarray:
    """Indices of the interior local maxima of ``values`` along a branch.

    A maximum counts when, on each side, the values fall below it by more
    than ``prominence`` times |value| before they rise above it (or the
    piece ends). Points reached by a jump (``gap``) start a new piece: a
    maximum needs a neighbour on each side within its piece; NaN values
    end a piece too.
    """
    g = np.asarray(values, dtype=float)
    gap = np.zeros(g.size, dtype=bool) if gap is None else np.asarray(gap, dtype=bool)
    piece = np.cumsum(gap | ~np.isfinite(g))
    out = []
    for i in range(1, g.size - 1):
        if not (np.isfinite(g[i]) and piece[i - 1] == piece[i] == piece[i + 1]):
            continue
        if not (g[i] >= g[i - 1] and g[i] > g[i + 1]):
            continue
        drop = prominence * abs(g[i])
        if _falls(g, piece, i, -1, drop) and _falls(g, piece, i, 1, drop):
            out.append(i)
    return np.array(out, dtype=int)


def _falls(g, piece, i, step, drop) -> bool:
    """True if, walking from i by ``step`` within its piece, g falls below g[i] - drop before exceeding g[i]."""
    j = i + step
    while 0 <= j < g.size and piece[j] == piece[i]:
        if g[j] > g[i]:
            return False
        if g[j] < g[i] - drop:
            return True
        j += step
    return True


def _vertex(s, g):
    """Abscissa of the vertex of the parabola through three points, or None if it is not a maximum."""
    d1 = (g[1] - g[0]) / (s[1] - s[0])
    d2 = (g[2] - g[1]) / (s[2] - s[1])
    a = (d2 - d1) / (s[2] - s[0])
    if not a < 0.0:
        return None
    return 0.5 * (s[0] + s[1]) - d1 / (2.0 * a)


def _interpolate(s, U, x):
    """Value and unit derivative at x of the quadratic through (s_k, U_k), k = 0, 1, 2."""
    w = np.empty(3)
    dw = np.empty(3)
    for k in range(3):
        o = [j for j in range(3) if j != k]
        den = (s[k] - s[o[0]]) * (s[k] - s[o[1]])
        w[k] = (x - s[o[0]]) * (x - s[o[1]]) / den
        dw[k] = ((x - s[o[0]]) + (x - s[o[1]])) / den
    d = dw @ U
    return w @ U, d / np.linalg.norm(d)


def _bracketed(s, g, width0, opt: ContinuationOptions) -> bool:
    """True when the bracket of :func:`refine_maximum` is narrow enough or flat enough (value converged)."""
    return bool(s[2] - s[0] <= opt.refine_stol * width0
                or g[1] - min(g[0], g[2]) <= opt.refine_gtol)


def refine_maximum(residual: Callable, observe: Callable, y, lam, options: ContinuationOptions | None = None,
                   *, iterations: int | None = None, **overrides):
    """Maximum of an observable along the solution curve, refined between three branch points.

    ``y`` (3, n) and ``lam`` (3,) are consecutive points of a branch whose
    middle one has the largest ``observe(y, lam)``. Successive parabolic
    interpolation in the chord length s: the vertex of the parabola
    through the three values (a golden-section point of the larger half
    when the parabola has no maximum inside), the point of the curve there
    by the arc-length corrector (predicted by the quadratic through the
    three points, constrained to the hyperplane orthogonal to its
    derivative), and the bracket shrunk around the best point; until the
    bracket is ``options.refine_stol`` of its first width, or the
    observable varies by at most ``options.refine_gtol`` across it
    (the value has converged; a flat maximum's location is then known to
    the square root of that), or
    ``iterations`` corrections were made (default ``options.refine_iter``) (a maximum at a corner of a
    ``iterations`` corrections were made (default ``options.refine_iter``; a maximum at a corner of a

    Returns
    -------
    (y, lam, value, converged) : the best point found (one of the three
    given points if no correction succeeded), its observable, and whether
    the bracket shrank to the tolerance.
    """
    opt = make_options(options, overrides)
    U = np.column_stack((np.asarray(y, dtype=float), np.asarray(lam, dtype=float)))
    n = U.shape[1] - 1
    g = np.array([float(observe(U[k, :n], U[k, n])) for k in range(3)])
    s = np.array([0.0, np.linalg.norm(U[1] - U[0]), 0.0])
    s[2] = s[1] + np.linalg.norm(U[2] - U[1])
    width0 = s[2] - s[0]
    cnt = {"residual_evaluations": 0}
    last_width = math.inf
    for _ in range(opt.refine_iter if iterations is None else iterations):
        if _bracketed(s, g, width0, opt):
            break
        x = _vertex(s, g)
        lo, hi = s[0] + GOLDEN_MARGIN * (s[1] - s[0]), s[2] - GOLDEN_MARGIN * (s[2] - s[1])
        # golden section where the parabola has no maximum inside, lands next to the best point, or the
        # last step hardly shrank the bracket (a maximum at a corner: Brent's safeguard)
        stalled = s[2] - s[0] > STALL_FRACTION * last_width
        last_width = s[2] - s[0]
        if x is None or stalled or not lo < x < hi or abs(x - s[1]) < GOLDEN_MARGIN * (s[2] - s[0]):
            wide = 0 if s[1] - s[0] > s[2] - s[1] else 2
            x = s[1] + GOLDEN * (s[wide] - s[1])
        u_pred, d = _interpolate(s, U, x)
        v, ok, _, _ = _solve_damped(residual, u_pred.copy(), None, d, u_pred, opt, cnt)
        if not ok:
            break
        gv = float(observe(v[:n], v[n]))
        if not math.isfinite(gv):
            break
        # the bracket keeps the best point in the middle
        k = 0 if x < s[1] else 2
        if gv > g[1]:
            U[2 - k], g[2 - k], s[2 - k] = U[1], g[1], s[1]
            U[1], g[1], s[1] = v, gv, x
        else:
            U[k], g[k], s[k] = v, gv, x
    converged = _bracketed(s, g, width0, opt)
    return U[1, :n].copy(), float(U[1, n]), float(g[1]), bool(converged)
