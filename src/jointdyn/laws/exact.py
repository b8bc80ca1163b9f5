"""Exact Iwan model with varying normal load: the discrete model at n -> infinity.

The uniform Iwan model (MODEL.md sections 2, 3, 5) is a continuum of Jenkins
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
closed form (:class:`~jointdyn.Iwan`) for any history.

Adjacent pieces with identical coefficients are joined (exact). A cut
closer than :data:`SNAP` (units of u) to the end of its piece is dropped
(rounding would otherwise leave slivers; the force changes by
O(SNAP^2) fy). The number of pieces is small for loads in phase with the
motion, but grows by about one per step while the contact slips with alpha
rising (the exact P is then a curve that the steps sample). Above the
capacity K the two adjacent pieces whose replacement by the chord through
their outer ends changes integral |P| du least are joined (chord merge): this
is the only approximation. Clipping and shifting never enlarge a difference
between two states (both are non-expansive, element by element), so the
force error after a merge stays below fy / 2 times the area it removed, for
the rest of the history.

Kernel layouts
--------------
``params = [kt (N/m), fy (N), N_ref (N), K, room]`` with ``room = 2 K``
(pieces a step may hold before its closing merges).

``state = [x_prev (m), m, (hi_k, a_k, b_k) for k < room]``: ``m`` pieces
in increasing u; piece k covers [hi_(k-1), hi_k] (hi_(-1) = 0,
hi_(m-1) = 2) with P(u) = a_k + b_k u (units of fy). Rows beyond the live
pieces are not written by ``step``.

Derivatives (``step_jvp``): rows a_k, b_k carry da_k, db_k; the breakpoint
rows carry zero. Breakpoints need none: P is continuous in u, so moving a
breakpoint does not change the integral, and the element-wise derivative
dP(u) (stuck: dP + dq; clipped: +-dalpha u) is linear on each piece. Where
a chord merge joins two pieces, the derivative is the chord of the
derivatives at fixed breakpoints (the only step at which it is not exact).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import _validate as V
from .. import config
from .._jit import jit
from ._base import MACROSLIP, SEPARATION, STICK_SLIP, ContactLaw, register

__all__ = [
    "ExactIwan",
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
_P_KT, _P_FY, _P_NREF, _P_CAP, _P_ROOM = 0, 1, 2, 3, 4
#: smallest capacity: one piece may split into three in a step
MIN_CAPACITY = 3


@jit(inline="always")
def _on_line(a, b, alpha):
    """True if a + b u is a clip line +-alpha u (the piece slips)."""
    return a == 0.0 and (b == alpha or b == -alpha)


@jit(inline="always")
def _cut(g_lo, g_hi, a, slope, lo, hi):
    """Crossing of a + slope u with zero inside [lo, hi] (``hi`` if none).

    A crossing exists when the sign test ``g > 0`` differs at the two ends
    (``g_lo``, ``g_hi`` the values there); it is dropped (``hi`` returned)
    when it lies within :data:`SNAP` of an end.
    """
    if (g_lo > 0.0) == (g_hi > 0.0):
        return hi
    c = -a / slope
    if c - lo <= SNAP or hi - c <= SNAP:
        return hi
    return c


@jit(inline="always")
def _cuts(lo, hi, a, b, alpha):
    """Cuts of the piece a + b u on [lo, hi] by the clip lines, sorted.

    Returns ``c1 <= c2`` in [lo, hi]; a missing cut is ``hi``, so the
    segments [lo, c1], [c1, c2], [c2, hi] (empty ones skipped) partition
    the piece into regions of one kind each (above, stuck, below).
    """
    su = b - alpha  # a + su u > 0: above the upper line
    sl = b + alpha  # a + sl u < 0: below the lower line
    cu = _cut(a + su * lo, a + su * hi, a, su, lo, hi)
    cl = _cut(a + sl * lo, a + sl * hi, a, sl, lo, hi)
    if cl < cu:
        return cl, cu
    return cu, cl


@jit(inline="always")
def _kind(lo, hi, a, b, alpha):
    """Coefficients of a segment after the clip, decided at its midpoint.

    Returns ``(a', b', stuck)``: ``(0, +-alpha, False)`` on a clip line,
    ``(a, b, True)`` inside the limits.
    """
    mid = 0.5 * (lo + hi)
    v = a + b * mid
    lim = alpha * mid
    if v > lim:
        return 0.0, alpha, False
    if v < -lim:
        return 0.0, -alpha, False
    return a, b, True


@jit(inline="always")
def _integral(lo, hi, a, b):
    """Integral of a + b u over [lo, hi]."""
    return (hi - lo) * (a + 0.5 * b * (hi + lo))


@jit(inline="always")
def _lo_of(s, k):
    """Lower end of piece k."""
    if k == 0:
        return 0.0
    return s[_HEAD + 3 * (k - 1)]


@jit(inline="always")
def _merge_cost(s, k):
    """Twice the area between pieces k, k+1 and the chord through their
    outer ends, ``|b_k - b_(k+1)| (mid - lo)(hi - mid)`` for a continuous P
    (the integral of |P - chord| du a merge would add is half of it).
    """
    r = _HEAD + 3 * k
    lo = _lo_of(s, k)
    mid = s[r]
    hi = s[r + 3]
    return abs(s[r + 2] - s[r + 5]) * (mid - lo) * (hi - mid)


@jit(inline="always")
def _merge_pair(s, ds, k, m, alpha):
    """Replace pieces k, k+1 by the chord through P at their outer ends.

    Shifts the pieces above down by one. ``ds`` (or None) gets the chord of
    the derivatives at fixed breakpoints. Returns the change of the
    integral of P and of the stuck measure.
    """
    r = _HEAD + 3 * k
    lo = _lo_of(s, k)
    mid = s[r]
    hi = s[r + 3]
    aL, bL, aR, bR = s[r + 1], s[r + 2], s[r + 4], s[r + 5]
    pl = aL + bL * lo
    ph = aR + bR * hi
    b = (ph - pl) / (hi - lo)
    a = pl - b * lo
    d_int = _integral(lo, hi, a, b) - _integral(lo, mid, aL, bL) - _integral(mid, hi, aR, bR)
    d_stuck = 0.0
    if not _on_line(a, b, alpha):
        d_stuck += hi - lo
    if not _on_line(aL, bL, alpha):
        d_stuck -= mid - lo
    if not _on_line(aR, bR, alpha):
        d_stuck -= hi - mid
    s[r] = hi
    s[r + 1] = a
    s[r + 2] = b
    if ds is not None:
        for j in range(ds.shape[1]):
            dl = ds[r + 1, j] + ds[r + 2, j] * lo
            dh = ds[r + 4, j] + ds[r + 5, j] * hi
            db = (dh - dl) / (hi - lo)
            ds[r + 1, j] = dl - db * lo
            ds[r + 2, j] = db
    for rr in range(r + 3, _HEAD + 3 * (m - 1)):
        s[rr] = s[rr + 3]
        if ds is not None:
            for j in range(ds.shape[1]):
                ds[rr, j] = ds[rr + 3, j]
    return d_int, d_stuck


@jit(inline="always")
def _merge_least(s, ds, m, alpha):
    """Chord-merge the adjacent pair of least cost (first on ties); see
    :func:`_merge_pair` for the returns."""
    best = 0
    cbest = _merge_cost(s, 0)
    for k in range(1, m - 1):
        c = _merge_cost(s, k)
        if c < cbest:
            cbest = c
            best = k
    return _merge_pair(s, ds, best, m, alpha)


@jit(inline="always")
def _emit(s, ds, ds_old, dx, dN, qs, ia, m, room, lo, hi, a, b, alpha, r_old):
    """Append the clipped segment [lo, hi] of the shifted old piece (row
    ``r_old``, coefficients ``a``, ``b`` after the shift) to the new state.

    A segment with the coefficients of the last piece extends it. When the
    state is full (``room`` pieces) the least-cost pair is chord-merged
    first. ``ds`` (or None) receives the derivative rows: stuck, the old
    piece's plus dq = (kt/fy)(dx - dx_prev) on a; clipped, (0, +-dalpha).
    Returns the new piece count, the integral of P over the segment (plus
    the change of a merge) and the stuck measure added.
    """
    a2, b2, stuck = _kind(lo, hi, a, b, alpha)
    d_int = _integral(lo, hi, a2, b2)
    d_stuck = 0.0 if _on_line(a2, b2, alpha) else hi - lo
    if m > 0:
        rp = _HEAD + 3 * (m - 1)
        if s[rp + 1] == a2 and s[rp + 2] == b2:
            s[rp] = hi
            return m, d_int, d_stuck
    if m == room:
        di, dst = _merge_least(s, ds, m, alpha)
        m -= 1
        d_int += di
        d_stuck += dst
    r = _HEAD + 3 * m
    s[r] = hi
    s[r + 1] = a2
    s[r + 2] = b2
    if ds is not None:
        sg = 1.0 if b2 > 0.0 else -1.0
        for j in range(ds.shape[1]):
            ds[r, j] = 0.0
            if stuck:
                ds[r + 1, j] = ds_old[r_old + 1, j] + qs * (dx[j] - ds_old[_X, j])
                ds[r + 2, j] = ds_old[r_old + 2, j]
            else:
                ds[r + 1, j] = 0.0
                ds[r + 2, j] = sg * ia * dN[j]
    return m + 1, d_int, d_stuck


@jit(inline="always")
def _reset(s, ds, x, dx):
    """Virgin state at x: one piece P = 0 on [0, 2], x_prev = x (``ds``, or
    None: d(x_prev) = dx, zero elsewhere). Rows beyond the piece are
    zeroed too (written in full)."""
    s[:] = 0.0
    s[_X] = x
    s[_M] = 1.0
    s[_HEAD] = U_MAX
    if ds is not None:
        for r in range(ds.shape[0]):
            for j in range(ds.shape[1]):
                ds[r, j] = 0.0
        for j in range(ds.shape[1]):
            ds[_X, j] = dx[j]


@jit(inline="always")
def _reset_live(s, ds, x, dx):
    """:func:`_reset` writing only the rows of the one live piece (steps)."""
    s[_X] = x
    s[_M] = 1.0
    s[_HEAD] = U_MAX
    s[_HEAD + 1] = 0.0
    s[_HEAD + 2] = 0.0
    if ds is not None:
        for j in range(ds.shape[1]):
            ds[_X, j] = dx[j]
            ds[_M, j] = 0.0
            ds[_HEAD, j] = 0.0
            ds[_HEAD + 1, j] = 0.0
            ds[_HEAD + 2, j] = 0.0


@jit(inline="always")
def _jvp_force(s, ds, m, fy, dT):
    """dT = fy / 2 * sum over pieces of the integral of da + db u."""
    for j in range(dT.shape[0]):
        acc = 0.0
        lo = 0.0
        for k in range(m):
            r = _HEAD + 3 * k
            hi = s[r]
            acc += _integral(lo, hi, ds[r + 1, j], ds[r + 2, j])
            lo = hi
        dT[j] = 0.5 * fy * acc


@jit(inline="always")
def _exact_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    # derivative arguments are all arrays or all None (pruned at compile time)
    kt = params[_P_KT]
    fy = params[_P_FY]
    n_ref = params[_P_NREF]
    cap = int(params[_P_CAP])
    room = int(params[_P_ROOM])
    alpha = N / n_ref
    if alpha <= 0.0 or fy <= 0.0:
        _reset_live(s_new, ds_new, x, dx)
        if dT is not None:
            dT[:] = 0.0
        return 0.0, 0.0, (SEPARATION if alpha <= 0.0 else MACROSLIP)
    qs = kt / fy
    ia = 1.0 / n_ref
    inc = qs * (x - s_old[_X])
    m_old = int(s_old[_M])
    m = 0
    total = 0.0  # integral of P over [0, 2]
    stuck = 0.0  # measure of the stuck slip strengths
    lo = 0.0
    for k in range(m_old):
        r = _HEAD + 3 * k
        hi = s_old[r]
        a = s_old[r + 1] + inc
        b = s_old[r + 2]
        c1, c2 = _cuts(lo, hi, a, b, alpha)
        if c1 > lo:
            m, di, dst = _emit(s_new, ds_new, ds_old, dx, dN, qs, ia, m, room, lo, c1, a, b, alpha, r)
            total += di
            stuck += dst
        if c2 > c1:
            m, di, dst = _emit(s_new, ds_new, ds_old, dx, dN, qs, ia, m, room, c1, c2, a, b, alpha, r)
            total += di
            stuck += dst
        if hi > c2:
            m, di, dst = _emit(s_new, ds_new, ds_old, dx, dN, qs, ia, m, room, c2, hi, a, b, alpha, r)
            total += di
            stuck += dst
        lo = hi
    while m > cap:
        di, dst = _merge_least(s_new, ds_new, m, alpha)
        m -= 1
        total += di
        stuck += dst
    s_new[_X] = x
    s_new[_M] = m
    if ds_new is not None:
        for j in range(dx.shape[0]):
            ds_new[_X, j] = dx[j]
            ds_new[_M, j] = 0.0
        _jvp_force(s_new, ds_new, m, fy, dT)
    code = STICK_SLIP if stuck > 0.0 else MACROSLIP
    return 0.5 * fy * total, 0.5 * kt * stuck, code


@jit
def exact_step(params, s_old, s_new, x, N):
    """Trial step of the exact Iwan law (see module docstring).

    Parameters
    ----------
    params : float64[:]
        ``[kt (N/m), fy (N), N_ref (N), K, room]``.
    s_old, s_new : float64[:]
        Committed (not written) and trial state, ``[x_prev (m), m,
        (hi_k, a_k, b_k) * room]``.
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
    slip strength (one piece), x_prev = x0; ``n0`` does not enter."""
    _reset(s, None, x0, None)


@jit
def exact_init_jvp(params, x0, dx0, n0, dn0, s, ds):
    """:func:`exact_init` and its derivative: d(x_prev) = dx0, zero elsewhere
    (``ds`` is (state size, directions))."""
    _reset(s, ds, x0, dx0)


@dataclass(frozen=True)
class ExactIwan(ContactLaw):
    """Exact Iwan law with slip forces scaled by N(t)/N_ref.

    The limit n -> infinity of :class:`~jointdyn.DiscreteIwan`, computed
    exactly with a piecewise-linear state (module docstring): any history,
    any normal load, separation included. Equal to the full-memory closed
    form :class:`~jointdyn.Iwan` at constant normal load.

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
        pieces are chord-merged (the only approximation, see module
        docstring and docs/exact-iwan.md for its error).
    """

    capacity: int = config.IWAN_EXACT_CAPACITY
    name: ClassVar[str] = "iwan-exact"

    def __post_init__(self) -> None:
        super().__post_init__()
        object.__setattr__(self, "capacity", V.positive_int("capacity", self.capacity, MIN_CAPACITY))

    @property
    def step(self):
        return exact_step

    @property
    def step_jvp(self):
        return exact_step_jvp

    @property
    def params(self) -> np.ndarray:
        return np.array([self.kt, self.fy, self.n_ref, float(self.capacity), float(self.room)])

    @property
    def room(self) -> int:
        """Pieces a step may hold before its closing merges (2 capacity)."""
        return 2 * self.capacity

    @property
    def state_size(self) -> int:
        return _HEAD + 3 * self.room

    @property
    def init(self):
        return exact_init

    @property
    def init_jvp(self):
        return exact_init_jvp


def piece_count(state) -> int:
    """Number of linear pieces of an :class:`ExactIwan` state vector."""
    return int(state[_M])


def _make_exact(*, kt, mu, n_ref, capacity=config.IWAN_EXACT_CAPACITY, **_):
    return ExactIwan(kt=kt, mu=mu, n_ref=n_ref, capacity=capacity)


register("iwan-exact", _make_exact)
