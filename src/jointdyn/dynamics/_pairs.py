"""Node pairs (interfaces) in the time integrator (compiled; only in runners of systems with interfaces).

Each pair of an interface carries an elastic-slider state between two nodes
(or a node and the ground) in the integrator's state vector; these helpers
make their workspace, compute their forces and split a step where a pair
changes its motion state or opens or closes, commit them at the end of a
step and summarise their stick, slip and open times per period, for
:mod:`jointdyn.dynamics._core`.
"""

from __future__ import annotations

import numpy as np

from .._jit import jit
from ..laws._base import MACROSLIP, SEPARATION
from ._step_events import _SPLIT_GUARD, _crossing, _hermite_root

@jit(inline="always")
def _rel(y, a, b, off):  # pragma: no cover - compiled
    """y[off + a] - y[off + b] with -1 a fixed side (0): a relative coordinate of a pair."""
    return (y[off + a] if a >= 0 else 0.0) - (y[off + b] if b >= 0 else 0.0)


@jit
def _pair_workspace(S, nc, x, pairs):  # pragma: no cover - compiled
    """Buffers of the pairs of a run: ``(W, u, g, u0, g0, T, N, code, code_c, times)``.

    W (2, np, 2): committed and trial sliders (m; W[ia] committed), read from
    the rows of S after the nc contacts (flat, two numbers per pair); u, g
    the pairs' relative displacements at an evaluation and u0, g0 at the
    committed point (m, here those of x); T, N the forces (N); the trial and
    committed codes (committed -1: unknown before the first step); times
    (np, 3): seconds stuck, slipping, open in the current repetition.
    """
    m = pairs.shape[0]
    W = np.zeros((2, m, 2))
    L = S.shape[1]
    u0 = np.zeros((m, 2))
    g0 = np.zeros(m)
    for i in range(m):
        for k in range(2):
            W[0, i, k] = S[nc + (2 * i + k) // L, (2 * i + k) % L]
            u0[i, k] = _rel(x, pairs[i, k], pairs[i, 3 + k], 0)
        g0[i] = _rel(x, pairs[i, 2], pairs[i, 5], 0)
    return (W, np.zeros((m, 2)), np.zeros(m), u0, g0, np.zeros((m, 2)), np.zeros(m), np.zeros(m, dtype=np.int64),
            np.full(m, -1, dtype=np.int64), np.zeros((m, 3)))  # fmt: skip


@jit
def _pair_point(pairs, ys, u, g):  # pragma: no cover - compiled
    """u, g (m) of every pair at the stage state ys."""
    for i in range(pairs.shape[0]):
        u[i, 0] = _rel(ys, pairs[i, 0], pairs[i, 3], 0)
        u[i, 1] = _rel(ys, pairs[i, 1], pairs[i, 4], 0)
        g[i] = _rel(ys, pairs[i, 2], pairs[i, 5], 0)


@jit
def _pair_reactions(pairs, par, ys, n, T, N, work, kk, row):  # pragma: no cover - compiled
    """work -= the pairs' reactions (-T on side A, +T on side B along t1, t2;
    -(N - P) on a_n, +(N - P) on b_n; N); the power T . du of pair i (W) into
    ``kk[row, 2 n + 4 + i]`` (its dissipation integral); returns their sum."""
    tot = 0.0
    for i in range(pairs.shape[0]):
        dn = N[i] - par[i, 3]
        p = 0.0
        for k in range(3):
            a = pairs[i, k]
            b = pairs[i, 3 + k]
            f = T[i, k] if k < 2 else dn
            if a >= 0:
                work[a] -= f
            if b >= 0:
                work[b] += f
            if k < 2:
                p += f * _rel(ys, a, b, n)
        kk[row, 2 * n + 4 + i] = p
        tot += p
    return tot


@jit
def _pair_split(pairs, par, y0, y1, h, n, sbest, ev_c, pw):  # pragma: no cover - compiled
    """Earliest pair event inside the step before ``sbest`` and away from the
    ends: a velocity reversal of u1 or u2 (Hermite root) of a pair slipping
    at the committed point or at the last stage (``pw``: its codes), or an
    opening or closing (P + kn g changes sign on the Hermite interpolant of
    g, as a normal spring's). Returns (fraction, ev_c: -1 when a pair event
    comes first, since a pair's load needs no snapping). One pass over the
    pairs: cost linear in their number.

    A stuck pair's reversal does not split the step: its slider stays where
    it is (a slip only at an extremum inside the step is missed, as between
    the samples of any sampled history). On the lap joint the ringing of the
    stiff interface DOFs made nearly every step split four times at the
    reversals of stuck pairs (88700 steps per period against 18264 grid
    steps; 36250 with this rule); on the 1-D patch it changed the response
    by 2e-10 (tests/test_interface_dynamics.py)."""
    for i in range(pairs.shape[0]):
        for k in range(3):
            a = pairs[i, k]
            b = pairs[i, 3 + k]
            u0 = _rel(y0, a, b, 0)
            u1 = _rel(y1, a, b, 0)
            du0 = _rel(y0, a, b, n)
            du1 = _rel(y1, a, b, n)
            sr = 2.0
            if k == 2:
                sr = _crossing(par[i, 3], par[i, 1], u0, u1, du0, du1, h)[0]
            elif du0 * du1 < 0.0 and (pw[8][i] == MACROSLIP or pw[7][i] == MACROSLIP):
                sr = _hermite_root(u0, u1, du0, du1, h)
            if sr > _SPLIT_GUARD and sr < 1.0 - _SPLIT_GUARD and sr < sbest:
                sbest = sr
                ev_c = -1
    return sbest, ev_c


@jit
def _pairs_commit(pw, ia, pairs, y0, h, nopen, S, nc, psum, k, n, last, period):  # pragma: no cover - compiled
    """Accept the step for the pairs: the trial sliders become the committed
    ones (returns their new index in W) and are written into S (rows after
    the nc contacts), the step's time h (s) booked to the pairs' motion
    states (half to each when a pair's state changed inside the step:
    stick/slip fractions are exact to a step, openings and closings are
    step boundaries), the committed point moved to y0; ``nopen`` plus 1 if
    a pair opened or closed in the step (a pair open all along, e.g. one
    without preload whose normal DOFs stay apart, does not count: the
    refinement it triggers is for the ringing at re-contacts). At the
    ``last`` step of repetition k, its per-pair summary
    (:func:`_pair_summary`)."""
    code, code_c, times = pw[7], pw[8], pw[9]
    _pair_write_back(S, nc, pw[0][1 - ia])
    opened = 0
    for i in range(pairs.shape[0]):
        c = code[i]
        if code_c[i] < 0 or code_c[i] == c:
            times[i, c] += h
        else:
            times[i, code_c[i]] += 0.5 * h
            times[i, c] += 0.5 * h
            if (c == SEPARATION) != (code_c[i] == SEPARATION):
                opened = 1
        code_c[i] = c
    _pair_point(pairs, y0, pw[3], pw[4])
    if last:
        _pair_summary(psum, k, y0, n, times, period)
    return 1 - ia, nopen + opened


@jit
def _pair_summary(psum, k, y0, n, times, period):  # pragma: no cover - compiled
    """Per-pair row of repetition k: work of the pair's force (J: its
    dissipation over a periodic repetition) and the fractions of the
    repetition it was stuck, slipping, open; the times are reset."""
    for i in range(psum.shape[1]):
        psum[k, i, 0] = y0[2 * n + 4 + i]
        for c in range(3):
            psum[k, i, 1 + c] = times[i, c] / period
            times[i, c] = 0.0


@jit
def _pair_write_back(S, nc, W):  # pragma: no cover - compiled
    """The committed sliders W (np, 2) into the rows of S after the contacts."""
    L = S.shape[1]
    for i in range(W.shape[0]):
        for k in range(2):
            S[nc + (2 * i + k) // L, (2 * i + k) % L] = W[i, k]
