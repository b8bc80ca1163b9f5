"""The piecewise-linear march shared by the Iwan laws with a density of slip strengths.

The exact Iwan law (:mod:`jointdyn.laws.exact`, uniform density) and
Segalman's law (:mod:`jointdyn.laws.segalman`, density u^chi plus a delta)
hold the same state: the function P(u) of the elements' forces (as if each
had the full stiffness kt, in units of fy) over the slip strengths u, stored
exactly as a list of linear pieces. A step shifts every piece by
dq = (kt / fy) dx, clips it to [-alpha u, alpha u] (alpha = N / N_ref) and
joins the pieces that end on one clip line; above the capacity, three
adjacent pieces are merged into two. The physics is in
:mod:`jointdyn.laws.exact`'s docstring; what the laws do differently is only
how a piece is weighted in the force (uniformly, or by u^chi with a delta at
u_max) and, for Segalman's law, a cache of the breakpoints' powers.

This module holds that common march (:func:`march_pieces`) and the helpers
it is made of; each law's kernel calls it and adds its own weights. The
helpers of the march itself and those that take arrays are inlined into the
law's kernel by Numba (``inline="always"``), which is itself inlined into the
compiled loops that call it: the march costs no call. The scalar helpers of
the merges and of Segalman's powers (:func:`_removal_cost`, :func:`_vertex`,
:func:`_line`, :func:`_stuck_part`, :func:`_line_jvp`, :func:`_held`,
:func:`_right_power`, :func:`_pow1`) are ordinary compiled functions: Numba
types each once, where its inliner types a copy at every call site of every
kernel and loop that inlines them, and LLVM inlines them (no call is left in
the compiled loops, and with scalar arguments no reference count either),
so they cost no time at run time and a quarter to a third of the laws'
compile time less (docs/performance.md, cold start). A helper that loops
over an array argument is left as a real call by LLVM, with the reference
counts of its arrays, which costs time in every step: those stay inlined.
It is a private module of :mod:`jointdyn.laws` (its name starts with ``_``):
it registers no law.

State layout (both laws)
------------------------
``state = [x_prev (m), m, (hi_k, a_k, b_k) for k < 3 K, ...]``: ``m`` pieces
in increasing u; piece k covers [hi_(k-1), hi_k] (hi_(-1) = 0, the last
ending at the law's largest slip strength) with P(u) = a_k + b_k u (units
of fy). ``params`` start with ``[kt (N/m), fy (N), N_ref (N), K, kt / fy
(1/m), 1 / N_ref (1/N)]``.
"""

from __future__ import annotations

import numpy as np

from .._jit import jit

__all__ = ["SNAP", "MIN_CAPACITY", "march_pieces", "clear_rows", "finish_state", "density_params",
           "pieces_error"]

#: linear pieces kept by the exact Iwan law (``iwan``) after a step; beyond,
#: three adjacent pieces are merged into two (results within 0.1 % of the
#: converged limit, measured 3e-3 % at most on the Fig 6 grid:
#: docs/exact-iwan.md)
IWAN_CAPACITY = 32

#: a cut of a piece by a clip line closer than this (units of u, the slip
#: strength in fy; pieces live on [0, u_max]) to an end of the piece is dropped
SNAP = 1e-9
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
    :data:`_ZERO`, whose end is the fixed u_max)."""
    r = _HEAD + 3 * k
    w = 1.0 if kind == _STUCK else 0.0
    sg = float(kind) * ia if kind != _ZERO else 0.0
    for j in range(ds.shape[1]):
        da = ds_old[r_old + 1, j] + qs * (dx[j] - ds_old[_X, j])
        ds[r, j] = _end_jvp(ds_old, r_old, end, c, b, alpha, da, ia * dN[j], j) if kind != _ZERO else 0.0
        ds[r + 1, j] = w * da
        ds[r + 2, j] = w * ds_old[r_old + 2, j] + sg * dN[j]


@jit
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


@jit
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


@jit
def _line(u0, p0, u1, p1, alpha):
    """Coefficients of the line through (u0, p0), (u1, p1); a line within
    ``SNAP alpha`` of a clip line on [0, u1] is put on it (a merged piece
    that slips like its parts)."""
    b = (p1 - p0) / (u1 - u0)
    a = p0 - b * u0
    if abs(a) + abs(abs(b) - alpha) * u1 <= SNAP * alpha:
        return 0.0, (alpha if b > 0.0 else -alpha)
    return a, b


@jit
def _stuck_part(lo, hi, a, b, alpha):
    """Measure of [lo, hi] if a + b u is not a clip line, else 0."""
    if a == 0.0 and (b == alpha or b == -alpha):
        return 0.0
    return hi - lo


@jit
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


@jit
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


@jit
def _right_power(end, right, chi, p_hi, p_lo):
    """right^(chi+1) of a written segment: the cached power ``p_hi`` of the old piece's
    upper (end code _END_HI) or ``p_lo`` of its lower (_END_LO) breakpoint, computed for
    a cut. Scalars only (see the note above :func:`_write`)."""
    if end == _END_HI:
        return p_hi
    if end == _END_LO:
        return p_lo
    return _pow1(right, chi)


@jit
def _pow1(u, chi):
    """u^(chi + 1) (u itself when chi = 0, so that the uniform law's bits are kept)."""
    if chi == 0.0:
        return u
    return u ** (chi + 1.0)


@jit(inline="always")
def march_pieces(params, s_old, s_new, alpha, inc, contact, ds_old, ds_new, dx, dN, weights):
    """Shift every piece of ``s_old`` by ``inc`` (dq, units of fy), clip it to
    [-alpha u, alpha u] and write the pieces into ``s_new`` (and their
    derivative rows into ``ds_new``), joining a clipped segment with the
    last piece when both lie on one clip line. No merges (the caller merges
    down to the capacity), no rows beyond the written pieces, no x_prev and
    count: those are the caller's.

    Parameters
    ----------
    params : float64[:]
        The law's parameters (module docstring: the leading six are read).
    s_old, s_new : float64[:]
        Committed state (read) and trial state (written).
    alpha : float
        N / N_ref (-).
    inc : float
        The shift dq = (kt / fy)(x - x_prev) (units of fy).
    contact : bool
        False (separation, or no friction): nothing is written, m = 0.
    ds_old, ds_new, dx, dN : arrays or None
        Derivative rows and directions, all arrays or all None (pruned at
        compile time).
    weights : None or tuple (chi, base)
        None: uniform density (the integral of P and the stuck measure).
        ``(chi, base)``: density u^chi with the powers hi_k^(chi+1) cached
        at rows ``base + k`` (read from ``s_old``, written to ``s_new``).

    Returns
    -------
    m : int
        Pieces written.
    total, stuck : float
        Uniform density (or chi = 0): integral of P and measure of the stuck
        slip strengths. With chi != 0: zero.
    tot_a, tot_b, st_a : float
        chi != 0: numerators of the weighted moments (sum of a_k and b_k
        times the differences of u^(chi+1) and u^(chi+2), and of the stuck
        u^(chi+1)); multiplied by 1/(chi+1), 1/(chi+2) by the caller.
    end_stuck : float
        1.0 when the last segment written (the strongest element) is stuck.
    """
    m = 0
    total = 0.0  # integral of P over the slip strengths
    stuck = 0.0  # measure of the stuck slip strengths
    tot_a = tot_b = st_a = 0.0
    end_stuck = 0.0
    pa = pb = np.nan  # coefficients of the last piece written
    lo = 0.0
    pleft = 0.0  # left^(chi + 1) of the next segment
    pl_old = ph_old = 0.0  # cached powers of the old piece's lower and upper breakpoints
    # kind at each breakpoint from the trial force there (one evaluation per
    # breakpoint, shared by the two pieces meeting there); the limit is 0 at u = 0
    k_lo = _end_kind(s_old[_HEAD + 1] + inc, 0.0)
    for k in range(int(s_old[_M]) if contact else 0):
        r = _HEAD + 3 * k
        hi = s_old[r]
        if weights is not None:
            ph_old = s_old[weights[1] + k]
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
                if weights is None:
                    total += _integral(left, right, a2, b2)
                    if kind == _STUCK:
                        stuck += right - left
                else:
                    chi = weights[0]
                    pright = _right_power(end, right, chi, ph_old, pl_old)
                    s_new[weights[1] + m - 1] = pright
                    if chi == 0.0:  # the uniform law's operations
                        total += _integral(left, right, a2, b2)
                        if kind == _STUCK:
                            stuck += right - left
                    else:  # the moments' numerators
                        tot_a += a2 * (pright - pleft)
                        tot_b += b2 * (right * pright - left * pleft)
                        if kind == _STUCK:
                            st_a += pright - pleft
                    pleft = pright
                end_stuck = 0.0
                if kind == _STUCK:
                    end_stuck = 1.0
                pa = a2
                pb = b2
                left = right
        lo = hi
        pl_old = ph_old
        k_lo = k_hi
    return m, total, stuck, tot_a, tot_b, st_a, end_stuck


@jit(inline="always")
def clear_rows(s, ds, lo, hi):
    """Rows lo .. hi - 1 of ``s`` (and of ``ds``, unless None) set to zero: the
    rows beyond the live pieces, so that two states with the same pieces are
    equal entry by entry (the harmonic-balance AFT compares states to stop
    marching periods)."""
    for rr in range(lo, hi):
        s[rr] = 0.0
        if ds is not None:
            for j in range(ds.shape[1]):
                ds[rr, j] = 0.0


@jit(inline="always")
def stale_top(s_new, written, room):
    """Rows to clear above the live pieces: up to the most this step wrote or the
    buffer held before (its count entry; a count outside [0, room], e.g. NaN,
    is not trusted)."""
    return max(written, _held(s_new[_M], room))


@jit(inline="always")
def finish_state(s_new, ds_new, dx, x, m):
    """x_prev and piece count of the trial state (their derivative rows: dx and 0)."""
    s_new[_X] = x
    s_new[_M] = m
    if ds_new is not None:
        for j in range(dx.shape[0]):
            ds_new[_X, j] = dx[j]
            ds_new[_M, j] = 0.0


def density_params(law) -> list:
    """The leading six kernel parameters of a density law (module docstring)."""
    qs = law.kt / law.fy if law.fy > 0.0 else 0.0
    return [law.kt, law.fy, law.n_ref, float(law.capacity), qs, 1.0 / law.n_ref]


def pieces_error(s, capacity: int, u_end: float, end_name: str):
    """Why a state's head and live pieces are not admissible (None if they are):
    x_prev finite, the piece count an integer in [1, capacity], the live
    pieces finite with breakpoints strictly increasing from above 0 and the
    last at ``u_end`` (named ``end_name`` in the message). Rows beyond the
    live pieces are never read and may hold anything."""
    if not np.all(np.isfinite(s[:_HEAD])):
        return f"entries 0..{_HEAD - 1} (x_prev, piece count) must be finite, got {s[:_HEAD].tolist()}"
    m = s[_M]
    if not (m == int(m) and 1 <= m <= capacity):
        return f"entry {_M} (piece count) must be an integer in [1, {capacity}], got {float(m)!r}"
    m = int(m)
    live = s[_HEAD : _HEAD + 3 * m]
    if not np.all(np.isfinite(live)):
        return f"the {m} live pieces (entries {_HEAD}..{_HEAD + 3 * m - 1}) must be finite"
    hi = live[0::3]
    if not (hi[0] > 0.0 and np.all(np.diff(hi) > 0.0) and hi[-1] == u_end):
        return (
            f"the breakpoints (entries {_HEAD}, {_HEAD + 3}, ...) must increase strictly from above 0 "
            f"and the last live one must be {end_name}, got {hi.tolist()}"
        )
    return None
