"""Exact Iwan model with varying normal load: the discrete model at n -> infinity.

The default contact law of jointdyn (:class:`Iwan`, registered as ``iwan``).

The uniform Iwan model (docs/model.md sections 2, 3, 5) is a continuum of Jenkins
elements with slip strengths spread uniformly over [0, 2 fy] at the
reference load, each limit scaled by alpha = N / N_ref. Its state is the
function P(u): the force of the element of slip strength u fy (u in [0, 2]),
as if that element had the full stiffness kt, in units of fy. The tangential
force is the mean of P over the density::

    T = fy / 2 * integral_0^2 P(u) du.

A step from x_prev to x adds dq = (kt / fy)(x - x_prev) to every element and
clips it to [-alpha u, alpha u]; alpha <= 0 (separation) resets P = 0. Both
operations map a piecewise-linear function of u to a piecewise-linear one:
a linear piece a + b u, shifted by dq, is cut by the clip lines +-alpha u
into at most three pieces (above the upper line: P = alpha u; stuck: a + b u;
below the lower line: P = -alpha u; the regions are disjoint since
a + (b - alpha) u <= a + (b + alpha) u for u >= 0). So P is stored exactly as
a list of linear pieces, and the model is the discrete model's limit with
no discretisation at all: Masing's memory (nested loops, rejoins) is
automatic, no reversal is ever detected, and slip caused by a falling normal
load within a branch is included. At constant load it equals the full-memory
closed form (:class:`~jointdyn.IwanClosedForm`) for any history.

Adjacent pieces with identical coefficients are joined (exact). A cut
closer than :data:`SNAP` (units of u) to the end of its piece is dropped
(rounding would otherwise leave slivers; the force changes by
O(SNAP^2) fy). The number of pieces is small for loads in phase with the
motion, but grows by about one per step while the contact slips with alpha
rising (the exact P is then a curve that the steps sample). Above the
capacity K, three adjacent pieces are merged into two: their two inner
breakpoints u1, u2 are replaced by one vertex at (u1 + u2) / 2 whose value
keeps the integral of P over the three pieces, so a merge leaves T
unchanged; the merge chosen is the one that moves P least at u1 and u2
(sum of the two changes times the width of the three pieces) among those
whose vertex lies within the limits, |P| <= alpha u (so that every element
of the merged state is admissible: an element beyond its slip force would
give energy back when it unloads). If none does, the first is taken with
its vertex clamped to the limits. This is the only approximation. Clipping and shifting never enlarge a difference
between two states (both are non-expansive, element by element), so the
force error at any later time is at most fy / 2 times the sum of the
integrals of |change of P| of the merges before it; in practice it is far
smaller, because slip erases the merged parts (docs/exact-iwan.md).

Kernel layouts
--------------
``params = [kt (N/m), fy (N), N_ref (N), K, kt / fy (1/m), 1 / N_ref (1/N)]``.

``state = [x_prev (m), m, (hi_k, a_k, b_k) for k < 3 K]``: ``m`` pieces
in increasing u; piece k covers [hi_(k-1), hi_k] (hi_(-1) = 0,
hi_(m-1) = 2) with P(u) = a_k + b_k u (units of fy). Rows beyond the live
pieces are never read; ``step`` keeps them zero where the buffers started
so (every state from ``init`` does), so that two states with the same
pieces are equal entry by entry (the harmonic-balance AFT compares states
to stop marching periods). A step writes at most three pieces per
committed piece before it merges down to K, hence room for 3 K.

Derivatives (``step_jvp``): rows a_k, b_k carry da_k, db_k, the derivative
of P at a fixed u (stuck: dP + dq; clipped: +-dalpha u; linear on each
piece), and the breakpoint rows carry the breakpoints' derivatives (a cut
by a clip line moves with the line and the piece; an old breakpoint keeps
its derivative; u = 2 is fixed). The force needs only the first (P is
continuous in u, so moving a breakpoint does not change the integral); the
merges need both: the merged vertex depends on the positions of the
breakpoints it replaces, and its derivative is taken through them, so the
derivative is exact at every step, merges included (away from the
measure-zero instants where a cut appears or a merge choice changes).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import config
from .._jit import jit
from ._base import MACROSLIP, SEPARATION, STICK_SLIP, ContactLaw, law_param, register

__all__ = [
    "Iwan",
    "exact_step",
    "exact_step_jvp",
    "exact_init",
    "exact_init_jvp",
    "SNAP",
    "piece_count",
]

#: a cut of a piece by a clip line closer than this (units of u, the slip
#: strength in fy; pieces live on [0, 2]) to an end of the piece is dropped
SNAP = 1e-9
#: upper end of the slip strengths, u = f / fy in [0, U_MAX]
U_MAX = 2.0
# state rows: x_prev, piece count, then (hi, a, b) per piece
_X, _M = 0, 1
_HEAD = 2
# params rows
_P_KT, _P_FY, _P_NREF, _P_CAP, _P_QS, _P_INV_NREF = 0, 1, 2, 3, 4, 5
#: smallest capacity: one piece may split into three in a step
MIN_CAPACITY = 3
# kinds of an element (or segment) after a trial shift: above the upper clip
# line, inside the limits, below the lower line
_ABOVE, _STUCK, _BELOW = 1, 0, -1
# kind of a piece whose derivative rows are zero (separation)
_ZERO = 2
# where the right end of a written piece comes from (its derivative follows):
# the old piece's lower or upper breakpoint, or a cut by the upper or lower
# clip line
_END_LO, _END_HI, _END_CUT_ABOVE, _END_CUT_BELOW = 0, 1, 2, 3


@jit(inline="always")
def _cut(a, b, alpha, kind, lo, hi):
    """Where the piece a + b u on [lo, hi] crosses the clip line of ``kind``
    (:data:`_ABOVE`: alpha u, :data:`_BELOW`: -alpha u), and the end code
    of that position (a cut, or :data:`_END_LO` / :data:`_END_HI`).

    A cut within :data:`SNAP` of an end of the piece moves onto that end
    (the cut is dropped); the position is clamped to [lo, hi].
    """
    if kind == _ABOVE:
        c = -a / (b - alpha)
        end = _END_CUT_ABOVE
    else:
        c = -a / (b + alpha)
        end = _END_CUT_BELOW
    if c - lo <= SNAP:
        return lo, _END_LO
    if hi - c <= SNAP:
        return hi, _END_HI
    return c, end


@jit(inline="always")
def _split(lo, hi, a, b, alpha, k_lo, k_hi):
    """Cuts of the piece a + b u on [lo, hi] whose ends have different kinds.

    ``k_lo``, ``k_hi``: kind (:data:`_ABOVE`, :data:`_STUCK`, :data:`_BELOW`)
    at each end. Returns ``c1 <= c2``: the segments [lo, c1] (kind k_lo),
    [c1, c2] (stuck) and [c2, hi] (kind k_hi) partition the piece (empty
    ones are skipped); an end whose kind is stuck has no cut of its own.
    Also returns the end code (:func:`_cut`) of each.
    """
    c1, e1 = lo, _END_LO
    c2, e2 = hi, _END_HI
    if k_lo != _STUCK:
        c1, e1 = _cut(a, b, alpha, k_lo, lo, hi)
    if k_hi != _STUCK:
        c2, e2 = _cut(a, b, alpha, k_hi, lo, hi)
    if c2 < c1:
        c2, e2 = c1, e1
    return c1, c2, e1, e2


@jit(inline="always")
def _end_kind(p, lim):
    """Kind of an element whose trial force is ``p`` and limit ``lim``."""
    if p > lim:
        return _ABOVE
    if p < -lim:
        return _BELOW
    return _STUCK


@jit(inline="always")
def _coeffs(kind, a, b, alpha):
    """Coefficients and kind of a segment of kind ``kind`` after the clip.

    Clipped: ``(0, +-alpha)``; stuck: ``(a, b)``, whose kind becomes a clip
    kind when the line a + b u is a clip line (no stiffness, and joinable
    with a clipped neighbour).
    """
    if kind == _ABOVE:
        return 0.0, alpha, _ABOVE
    if kind == _BELOW:
        return 0.0, -alpha, _BELOW
    if a == 0.0 and (b == alpha or b == -alpha):
        return a, b, (_ABOVE if b > 0.0 else _BELOW)
    return a, b, _STUCK


@jit(inline="always")
def _integral(lo, hi, a, b):
    """Integral of a + b u over [lo, hi]."""
    return (hi - lo) * (a + 0.5 * b * (hi + lo))


# Helpers that take arrays are straight-line code: Numba keeps the
# reference-count updates of an array argument of an inlined function with
# branches inside the caller's loop (two atomic operations per array and
# call, which cost more than the whole step); decisions are taken by the
# scalar helpers above and by the core.


@jit(inline="always")
def _write(s, k, hi, a, b):
    """Piece k of state ``s`` := (hi, a, b)."""
    r = _HEAD + 3 * k
    s[r] = hi
    s[r + 1] = a
    s[r + 2] = b


@jit(inline="always")
def _end_jvp(ds_old, r_old, end, c, b, alpha, da, dal, j):
    """Derivative along direction j of the right end of a written piece (end
    code ``end``, :func:`_cut`): an old breakpoint keeps its derivative (the
    lower one of the old piece at row ``r_old`` is 0 for the first piece);
    a cut c of the shifted piece (derivatives ``da`` of a, ``ds_old`` row
    of b) by the line +-alpha u moves by -(da + (db -+ dalpha) c) / (b -+ alpha)."""
    if end == _END_HI:
        return ds_old[r_old, j]
    if end == _END_LO:
        return ds_old[r_old - 3, j] if r_old > _HEAD else 0.0
    if end == _END_CUT_ABOVE:
        return -(da + (ds_old[r_old + 2, j] - dal) * c) / (b - alpha)
    return -(da + (ds_old[r_old + 2, j] + dal) * c) / (b + alpha)


@jit(inline="always")
def _write_jvp(ds, ds_old, dx, dN, k, r_old, kind, qs, ia, end, c, b, alpha):
    """Derivative rows of piece k: stuck, those of the old piece (row
    ``r_old``) plus dq = (kt/fy)(dx - dx_prev) on a; clipped (kind +-1),
    (0, +-dalpha); :data:`_ZERO`, zero. The breakpoint row gets the
    derivative of the piece's right end c (:func:`_end_jvp`; zero for
    :data:`_ZERO`, whose end is u = 2)."""
    r = _HEAD + 3 * k
    w = 1.0 if kind == _STUCK else 0.0
    sg = float(kind) * ia if kind != _ZERO else 0.0
    for j in range(ds.shape[1]):
        da = ds_old[r_old + 1, j] + qs * (dx[j] - ds_old[_X, j])
        ds[r, j] = _end_jvp(ds_old, r_old, end, c, b, alpha, da, ia * dN[j], j) if kind != _ZERO else 0.0
        ds[r + 1, j] = w * da
        ds[r + 2, j] = w * ds_old[r_old + 2, j] + sg * dN[j]


@jit(inline="always")
def _removal_cost(u0, u1, u2, u3, p0, p1, p2, p3, area2, alpha):
    """Cost of replacing the breakpoints u1, u2 of three adjacent pieces by
    one vertex, as a fraction ``num / den`` (no division).

    The pieces run through the vertices (u0, p0) .. (u3, p3) (u in fy, P in
    fy), ``area2`` is twice their integral. The new vertex is at
    uw = (u1 + u2) / 2 with the value pw that keeps the integral over
    [u0, u3]; the cost is (|change of P at u1| + |change at u2|)(u3 - u0).
    A vertex outside the limits (|pw| > alpha uw: the merged state would
    hold elements beyond their slip force) costs ``inf``.
    """
    uw = 0.5 * (u1 + u2)
    d = u3 - u0
    left = uw - u0
    right = u3 - uw
    pwd = area2 - left * p0 - right * p3  # pw (u3 - u0)
    if abs(pwd) > alpha * uw * d:
        return np.inf, 1.0
    e1 = (p0 - p1) * left * d + (pwd - p0 * d) * (u1 - u0)  # (change at u1) (uw - u0) d
    e2 = (pwd - p2 * d) * right + (p3 * d - pwd) * (u2 - uw)  # (change at u2) (u3 - uw) d
    return abs(e1) * right + abs(e2) * left, left * right


@jit(inline="always")
def _vertex(u0, u1, u2, u3, p0, p3, area2, alpha):
    """The vertex (uw, pw) of :func:`_removal_cost`, pw clamped to the
    limits [-alpha uw, alpha uw] (only when no merge keeps the integral
    within them: then this merge changes T), and the clamp: 0, or +-1 when
    pw is put on the upper / lower limit."""
    uw = 0.5 * (u1 + u2)
    pw = (area2 - (uw - u0) * p0 - (u3 - uw) * p3) / (u3 - u0)
    lim = alpha * uw
    if pw > lim:
        return uw, lim, 1.0
    if pw < -lim:
        return uw, -lim, -1.0
    return uw, pw, 0.0


@jit(inline="always")
def _triple(s, j):
    """Vertices and twice the integral of pieces j-1, j, j+1 (j >= 1)."""
    r = _HEAD + 3 * (j - 1)
    u0 = 0.0 if j == 1 else s[r - 3]
    u1 = s[r]
    u2 = s[r + 3]
    u3 = s[r + 6]
    a0, b0, a1, b1, a2, b2 = s[r + 1], s[r + 2], s[r + 4], s[r + 5], s[r + 7], s[r + 8]
    area2 = 2.0 * (_integral(u0, u1, a0, b0) + _integral(u1, u2, a1, b1) + _integral(u2, u3, a2, b2))
    return u0, u1, u2, u3, a0 + b0 * u0, a0 + b0 * u1, a1 + b1 * u2, a2 + b2 * u3, area2


@jit(inline="always")
def _least_triple(s, m, alpha):
    """j of the three adjacent pieces j-1, j, j+1 whose merge into two
    (:func:`_removal_cost`) costs least (first on ties; j = 1 when every
    merge would leave the limits); the window of three pieces slides along,
    each integral computed once."""
    best = 1
    b_num = np.inf
    b_den = 1.0
    u0 = 0.0
    u1 = s[_HEAD]
    u2 = s[_HEAD + 3]
    a0, b0, a1, b1 = s[_HEAD + 1], s[_HEAD + 2], s[_HEAD + 4], s[_HEAD + 5]
    i0 = _integral(u0, u1, a0, b0)
    i1 = _integral(u1, u2, a1, b1)
    for j in range(1, m - 1):
        r = _HEAD + 3 * (j + 1)
        u3 = s[r]
        a2 = s[r + 1]
        b2 = s[r + 2]
        i2 = _integral(u2, u3, a2, b2)
        num, den = _removal_cost(u0, u1, u2, u3, a0 + b0 * u0, a0 + b0 * u1, a1 + b1 * u2, a2 + b2 * u3,
                                 2.0 * (i0 + i1 + i2), alpha)
        if num * b_den < b_num * den:
            best = j
            b_num = num
            b_den = den
        u0, u1, u2 = u1, u2, u3
        a0, b0, a1, b1 = a1, b1, a2, b2
        i0, i1 = i1, i2
    return best


@jit(inline="always")
def _line(u0, p0, u1, p1, alpha):
    """Coefficients of the line through (u0, p0), (u1, p1); a line within
    ``SNAP alpha`` of a clip line on [0, u1] is put on it (a merged piece
    that slips like its parts)."""
    b = (p1 - p0) / (u1 - u0)
    a = p0 - b * u0
    if abs(a) + abs(abs(b) - alpha) * u1 <= SNAP * alpha:
        return 0.0, (alpha if b > 0.0 else -alpha)
    return a, b


@jit(inline="always")
def _stuck_part(lo, hi, a, b, alpha):
    """Measure of [lo, hi] if a + b u is not a clip line, else 0."""
    if a == 0.0 and (b == alpha or b == -alpha):
        return 0.0
    return hi - lo


@jit(inline="always")
def _line_jvp(u0, dp0, du0, u1, dp1, du1, a, b, alpha, dal):
    """Derivative (da, db) of the line a + b u through its points at u0 and
    u1 when they move: values by dp0, dp1 and positions by du0, du1 (the
    derivative of the line's value at a fixed u); a line put on a clip line
    (:func:`_line`) moves with it, (0, +-dalpha)."""
    if _stuck_part(0.0, 1.0, a, b, alpha) == 0.0:
        return 0.0, (dal if b > 0.0 else -dal)
    db = ((dp1 - dp0) - b * (du1 - du0)) / (u1 - u0)
    return dp0 - b * du0 - db * u0, db


@jit(inline="always")
def _merge_jvp(s, ds, j, uw, pw, clamp, lines, alpha, ia, dN):
    """Derivative rows of the two pieces replacing j-1, j, j+1 (``s`` still
    holds the three): the exact derivative of the merge, breakpoints
    included. The vertex value pw keeps the integral over [u0, u3], so its
    derivative follows from those of the end values p0, p3, of the
    integral (the pieces' derivatives plus the motion of u0 and u3; P is
    continuous at u1, u2) and of the positions; a clamped vertex moves with
    the limit. ``lines``: the new pieces' coefficients (a1, b1, a2, b2)."""
    a1, b1, a2, b2 = lines
    r = _HEAD + 3 * (j - 1)
    u0 = 0.0 if j == 1 else s[r - 3]
    u1, u2, u3 = s[r], s[r + 3], s[r + 6]
    bl, br = s[r + 2], s[r + 8]
    p0 = s[r + 1] + bl * u0
    p3 = s[r + 7] + br * u3
    for k in range(ds.shape[1]):
        du0 = ds[r - 3, k] if j > 1 else 0.0
        du1, du2, du3 = ds[r, k], ds[r + 3, k], ds[r + 6, k]
        da0, db0, da1, db1, da2, db2 = ds[r + 1, k], ds[r + 2, k], ds[r + 4, k], ds[r + 5, k], ds[r + 7, k], ds[r + 8, k]
        dal = ia * dN[k]
        dp0 = da0 + db0 * u0 + bl * du0
        dp3 = da2 + db2 * u3 + br * du3
        duw = 0.5 * (du1 + du2)
        if clamp != 0.0:
            dpw = clamp * (dal * uw + alpha * duw)
        else:
            darea2 = 2.0 * (_integral(u0, u1, da0, db0) + _integral(u1, u2, da1, db1) + _integral(u2, u3, da2, db2)
                            + p3 * du3 - p0 * du0)
            dpw = (darea2 - (duw - du0) * p0 - (uw - u0) * dp0 - (du3 - duw) * p3 - (u3 - uw) * dp3
                   - pw * (du3 - du0)) / (u3 - u0)
        dal1, dbl1 = _line_jvp(u0, dp0, du0, uw, dpw, duw, a1, b1, alpha, dal)
        dal2, dbl2 = _line_jvp(uw, dpw, duw, u3, dp3, du3, a2, b2, alpha, dal)
        ds[r, k] = duw
        ds[r + 1, k] = dal1
        ds[r + 2, k] = dbl1
        ds[r + 3, k] = du3
        ds[r + 4, k] = dal2
        ds[r + 5, k] = dbl2


@jit(inline="always")
def _shift_down(s, ds, k, m):
    """Drop piece k + 1 of ``m``: pieces above move down one slot (``ds`` too, unless None)."""
    for rr in range(_HEAD + 3 * (k + 1), _HEAD + 3 * (m - 1)):
        s[rr] = s[rr + 3]
    if ds is not None:
        for rr in range(_HEAD + 3 * (k + 1), _HEAD + 3 * (m - 1)):
            for j in range(ds.shape[1]):
                ds[rr, j] = ds[rr + 3, j]


@jit(inline="always")
def _reset_live(s, x):
    """Virgin state at x written into its live rows: one piece P = 0 on [0, 2]."""
    s[_X] = x
    s[_M] = 1.0
    _write(s, 0, U_MAX, 0.0, 0.0)


@jit(inline="always")
def _jvp_force(s, ds, m, fy, dT):
    """dT = fy / 2 * sum over pieces of the integral of da + db u."""
    # pieces outside, directions inside (rows are contiguous); each direction
    # sums its pieces in the same order as a loop per direction would
    for j in range(dT.shape[0]):
        dT[j] = 0.0
    lo = 0.0
    for k in range(m):
        r = _HEAD + 3 * k
        hi = s[r]
        for j in range(dT.shape[0]):
            dT[j] += _integral(lo, hi, ds[r + 1, j], ds[r + 2, j])
        lo = hi
    for j in range(dT.shape[0]):
        dT[j] = 0.5 * fy * dT[j]


@jit(inline="always")
def _exact_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    # Derivative arguments are all arrays or all None (pruned at compile
    # time). One exit and no call that is not inlined: either keeps Numba's
    # reference-count updates of the arrays inside the caller's loop.
    fy = params[_P_FY]
    alpha = N * params[_P_INV_NREF]
    contact = alpha > 0.0 and fy > 0.0
    inc = params[_P_QS] * (x - s_old[_X])
    m = 0
    total = 0.0  # integral of P over [0, 2]
    stuck = 0.0  # measure of the stuck slip strengths
    pa = pb = np.nan  # coefficients of the last piece written
    lo = 0.0
    # kind at each breakpoint from the trial force there (one evaluation per
    # breakpoint, shared by the two pieces meeting there); the limit is 0 at u = 0
    k_lo = _end_kind(s_old[_HEAD + 1] + inc, 0.0)
    for k in range(int(s_old[_M]) if contact else 0):
        r = _HEAD + 3 * k
        hi = s_old[r]
        a = s_old[r + 1] + inc
        b = s_old[r + 2]
        k_hi = _end_kind(a + b * hi, alpha * hi)
        c1 = c2 = hi  # one kind over the whole piece (a + b u is straight)
        e1 = e2 = _END_HI
        if k_lo != k_hi:
            c1, c2, e1, e2 = _split(lo, hi, a, b, alpha, k_lo, k_hi)
        # segments [lo, c1] (kind k_lo), [c1, c2] (stuck), [c2, hi] (kind k_hi)
        left = lo
        for seg in range(1 if k_lo == k_hi else 3):
            right, kind, end = _segment(seg, c1, c2, hi, k_lo, k_hi, e1, e2)
            if right > left:
                a2, b2, kind = _coeffs(kind, a, b, alpha)
                # a clipped segment on the line of the last piece extends it
                if kind == _STUCK or a2 != pa or b2 != pb:
                    m += 1
                _write(s_new, m - 1, right, a2, b2)
                if ds_new is not None:
                    _write_jvp(ds_new, ds_old, dx, dN, m - 1, r, kind, params[_P_QS], params[_P_INV_NREF], end, right,
                               b, alpha)
                total += _integral(left, right, a2, b2)
                if kind == _STUCK:
                    stuck += right - left
                pa = a2
                pb = b2
                left = right
        lo = hi
        k_lo = k_hi
    written = m
    if m > int(params[_P_CAP]):
        m, total, stuck = _enforce_capacity(s_new, ds_new, m, int(params[_P_CAP]), alpha, total, stuck,
                                            params[_P_INV_NREF], dN)
    if not contact:  # separation (or no friction): P = 0
        _write(s_new, 0, U_MAX, 0.0, 0.0)
        m = 1
    # rows beyond the live pieces are zeroed up to the most this step wrote or the
    # buffer held before (a count outside [0, room], e.g. NaN, is not trusted), so
    # that states with equal pieces are equal entry by entry
    top = max(written, _held(s_new[_M], 3 * int(params[_P_CAP])))
    for rr in range(_HEAD + 3 * m, _HEAD + 3 * top):
        s_new[rr] = 0.0
        if ds_new is not None:
            for j in range(ds_new.shape[1]):
                ds_new[rr, j] = 0.0
    s_new[_X] = x
    s_new[_M] = m
    if ds_new is not None:
        if not contact:
            _write_jvp(ds_new, ds_old, dx, dN, 0, _HEAD, _ZERO, 0.0, 0.0, _END_HI, U_MAX, 0.0, 0.0)
        _jvp_force(s_new, ds_new, m, fy, dT)
        for j in range(dx.shape[0]):
            ds_new[_X, j] = dx[j]
            ds_new[_M, j] = 0.0
    code = STICK_SLIP if stuck > 0.0 else MACROSLIP
    if alpha <= 0.0:
        code = SEPARATION
    return 0.5 * fy * total, 0.5 * params[_P_KT] * stuck, code


@jit(inline="always")
def _held(count, room):
    """Pieces a state buffer held (its count entry), or 0 when that is not a count in [0, room]."""
    if count >= 0.0 and count <= room:
        return int(count)
    return 0


@jit(inline="always")
def _segment(seg, c1, c2, hi, k_lo, k_hi, e1, e2):
    """Right end, kind and end code of segment ``seg`` (0, 1, 2) of a split piece."""
    if seg == 0:
        return c1, k_lo, e1
    if seg == 1:
        return c2, _STUCK, e2
    return hi, k_hi, _END_HI


@jit(inline="always")
def _enforce_capacity(s, ds, m, cap, alpha, total, stuck, ia, dN):
    """Merge three adjacent pieces into two (:func:`_removal_cost`, least
    cost first) until at most ``cap`` pieces remain.

    Returns the piece count and the integral of P (unchanged up to
    rounding) and the stuck measure, updated for the merges.
    """
    while m > cap:
        j = _least_triple(s, m, alpha)
        u0, u1, u2, u3, p0, p1, p2, p3, area2 = _triple(s, j)
        uw, pw, clamp = _vertex(u0, u1, u2, u3, p0, p3, area2, alpha)
        r = _HEAD + 3 * (j - 1)
        for q in range(3):
            a, b = s[r + 3 * q + 1], s[r + 3 * q + 2]
            lo = u0 if q == 0 else s[r + 3 * q - 3]
            total -= _integral(lo, s[r + 3 * q], a, b)
            stuck -= _stuck_part(lo, s[r + 3 * q], a, b, alpha)
        a1, b1 = _line(u0, p0, uw, pw, alpha)
        a2, b2 = _line(uw, pw, u3, p3, alpha)
        total += _integral(u0, uw, a1, b1) + _integral(uw, u3, a2, b2)
        stuck += _stuck_part(u0, uw, a1, b1, alpha) + _stuck_part(uw, u3, a2, b2, alpha)
        if ds is not None:
            _merge_jvp(s, ds, j, uw, pw, clamp, (a1, b1, a2, b2), alpha, ia, dN)
        _write(s, j - 1, uw, a1, b1)
        _write(s, j, u3, a2, b2)
        _shift_down(s, ds, j, m)
        m -= 1
    return m, total, stuck


# inline="always": inlined into the caller's compiled loop (march,
# integrators), where a call passing three arrays costs as much as the law
@jit(inline="always")
def exact_step(params, s_old, s_new, x, N):
    """Trial step of the exact Iwan law (see module docstring).

    Parameters
    ----------
    params : float64[:]
        ``[kt (N/m), fy (N), N_ref (N), K, kt / fy (1/m), 1 / N_ref (1/N)]``.
    s_old, s_new : float64[:]
        Committed (not written) and trial state, ``[x_prev (m), m,
        (hi_k, a_k, b_k) * 3 K]`` (module docstring).
    x : float
        Tangential displacement, m.
    N : float
        Normal load, N.

    Returns
    -------
    T : float
        Tangential force, N: fy / 2 times the integral of P over [0, 2].
    kT : float
        Tangent dT/dx at fixed N, N/m: kt times the stuck fraction.
    code : int
        SEPARATION (N <= 0), MACROSLIP (no element stuck) or STICK_SLIP.
    """
    return _exact_core(params, s_old, s_new, x, N, None, None, None, None, None)


@jit
def exact_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
    """:func:`exact_step` with forward-mode derivatives along ``dx.size``
    directions (``ds_*``: (state size, directions), layout in the module
    docstring)."""
    return _exact_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT)


@jit
def exact_init(params, x0, n0, s):
    """Virgin committed state at displacement ``x0`` (m): P = 0 for every
    slip strength (one piece), x_prev = x0, every row written; ``n0`` does
    not enter."""
    s[:] = 0.0
    _reset_live(s, x0)


@jit
def exact_init_jvp(params, x0, dx0, n0, dn0, s, ds):
    """:func:`exact_init` and its derivative: d(x_prev) = dx0, zero elsewhere
    (``ds`` is (state size, directions))."""
    exact_init(params, x0, n0, s)
    ds[:, :] = 0.0
    for j in range(ds.shape[1]):
        ds[_X, j] = dx0[j]


@dataclass(frozen=True)
class Iwan(ContactLaw):
    """Exact Iwan law with slip forces scaled by N(t)/N_ref (the default contact law).

    The limit n -> infinity of :class:`~jointdyn.DiscreteIwan`, computed
    exactly with a piecewise-linear state (module docstring): any history,
    any normal load, separation included. Equal to the full-memory closed
    form :class:`~jointdyn.IwanClosedForm` at constant normal load; unlike
    the closed forms, it includes the slip caused by a falling normal load
    within a branch. Registered as ``iwan``.

    Parameters
    ----------
    kt : float
        Total tangential stiffness, N/m.
    mu : float
        Friction coefficient; fy = mu n_ref is the macroslip force at N_ref.
    n_ref : float
        Reference normal load N_ref, N.
    capacity : int
        Largest number of linear pieces kept after a step (>= 3); above it
        three adjacent pieces are merged into two (the only approximation,
        see the module docstring and docs/exact-iwan.md for its error).
    """

    capacity: int = law_param(
        config.IWAN_CAPACITY, low=MIN_CAPACITY,
        help="linear pieces kept after a step (above it, three adjacent pieces are merged into two)",
    )
    name: ClassVar[str] = "iwan"
    #: microslip from a distribution of slip thresholds: no stick-slip kink (ContactLaw.smooth_force)
    smooth_force: ClassVar[bool] = True

    @property
    def step(self):
        return exact_step

    @property
    def step_jvp(self):
        return exact_step_jvp

    @property
    def params(self) -> np.ndarray:
        qs = self.kt / self.fy if self.fy > 0.0 else 0.0
        return np.array([self.kt, self.fy, self.n_ref, float(self.capacity), qs, 1.0 / self.n_ref])

    @property
    def room(self) -> int:
        """Pieces a step may hold before its closing merges: 3 capacity (each
        piece splits into at most three)."""
        return 3 * self.capacity

    @property
    def state_size(self) -> int:
        return _HEAD + 3 * self.room

    @property
    def x_slip(self) -> float:
        """2 fy / kt (m): the virgin curve reaches macroslip when the
        strongest element (u = 2) slips."""
        return 2.0 * self.fy / self.kt

    @property
    def passive(self) -> bool:
        """True: every element is an elastic-perfectly-plastic Jenkins
        element, which creates no energy over a closed cycle at constant N
        from any state; a merge keeps the integral of P and never leaves the
        limits (the merged pieces lie between their neighbours' values)."""
        return True

    def max_force(self, N):
        """Bound on |T| at normal load ``N`` (N): ``max(N, 0) / n_ref * fy``,
        since |P(u)| <= alpha u and fy / 2 times the integral of alpha u over
        [0, 2] is alpha fy (macroslip reaches it)."""
        return super().max_force(N)

    def _state_error(self, s):
        """x_prev finite, the piece count an integer in [1, capacity], the
        live pieces finite with breakpoints strictly increasing from above 0
        and ending at u = 2 (the rows beyond the live pieces are never read
        and may hold anything)."""
        if not np.all(np.isfinite(s[:_HEAD])):
            return f"entries 0..{_HEAD - 1} (x_prev, piece count) must be finite, got {s[:_HEAD].tolist()}"
        m = s[_M]
        if not (m == int(m) and 1 <= m <= self.capacity):
            return f"entry {_M} (piece count) must be an integer in [1, {self.capacity}], got {float(m)!r}"
        m = int(m)
        live = s[_HEAD : _HEAD + 3 * m]
        if not np.all(np.isfinite(live)):
            return f"the {m} live pieces (entries {_HEAD}..{_HEAD + 3 * m - 1}) must be finite"
        hi = live[0::3]
        if not (hi[0] > 0.0 and np.all(np.diff(hi) > 0.0) and hi[-1] == U_MAX):
            return (
                f"the breakpoints (entries {_HEAD}, {_HEAD + 3}, ...) must increase strictly from above 0 "
                f"and the last live one must be {U_MAX:g}, got {hi.tolist()}"
            )
        return None

    @property
    def init(self):
        return exact_init

    @property
    def init_jvp(self):
        return exact_init_jvp


def piece_count(state) -> int:
    """Number of linear pieces of an :class:`Iwan` state vector."""
    return int(state[_M])


register(
    "iwan", Iwan,
    summary="exact Iwan model with varying normal load (the discrete model at n -> infinity; default)",
    label="exact Iwan model",
)
