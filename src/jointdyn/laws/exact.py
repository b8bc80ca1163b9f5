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

from .._jit import jit
from ._base import MACROSLIP, SEPARATION, STICK_SLIP, ContactLaw, law_param, register
from ._density_march import (
    IWAN_CAPACITY,
    _END_HI,
    _HEAD,
    _M,
    _P_CAP,
    _P_FY,
    _P_INV_NREF,
    _P_KT,
    _P_QS,
    _X,
    _ZERO,
    MIN_CAPACITY,
    SNAP,
    _enforce_capacity,
    _integral,
    _write,
    _write_jvp,
    clear_rows,
    density_params,
    finish_state,
    march_pieces,
    pieces_error,
    stale_top,
)

__all__ = [
    "Iwan",
    "exact_step",
    "exact_step_jvp",
    "exact_init",
    "exact_init_jvp",
    "SNAP",
    "piece_count",
]

#: upper end of the slip strengths, u = f / fy in [0, U_MAX]
U_MAX = 2.0


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
    # time). One exit, and every helper that takes an array inlined by
    # Numba: a second exit, or a call with arrays that LLVM does not inline,
    # keeps Numba's reference-count updates of the arrays inside the caller's
    # loop. The scalar helpers of the merges are ordinary compiled functions
    # (typed once; LLVM inlines them: laws/_density_march.py).
    fy = params[_P_FY]
    cap = int(params[_P_CAP])
    alpha = N * params[_P_INV_NREF]
    contact = alpha > 0.0 and fy > 0.0
    inc = params[_P_QS] * (x - s_old[_X])
    m, total, stuck, _, _, _, _ = march_pieces(params, s_old, s_new, alpha, inc, contact, ds_old, ds_new, dx, dN, None)
    written = m
    if m > cap:
        m, total, stuck = _enforce_capacity(s_new, ds_new, m, cap, alpha, total, stuck, params[_P_INV_NREF], dN)
    if not contact:  # separation (or no friction): P = 0
        _write(s_new, 0, U_MAX, 0.0, 0.0)
        m = 1
    clear_rows(s_new, ds_new, _HEAD + 3 * m, _HEAD + 3 * stale_top(s_new, written, 3 * cap))
    if ds_new is not None:
        if not contact:
            _write_jvp(ds_new, ds_old, dx, dN, 0, _HEAD, _ZERO, 0.0, 0.0, _END_HI, U_MAX, 0.0, 0.0)
        _jvp_force(s_new, ds_new, m, fy, dT)
    finish_state(s_new, ds_new, dx, x, m)
    code = STICK_SLIP if stuck > 0.0 else MACROSLIP
    if alpha <= 0.0:
        code = SEPARATION
    return 0.5 * fy * total, 0.5 * params[_P_KT] * stuck, code


# inline="always": inlined into the caller's compiled loop (march,
# integrators), where a call passing three arrays costs as much as the law
@jit(inline="always")
def exact_step(params, s_old, s_new, x, N):
    """Trial step of the exact Iwan law: the kernel contract's ``step``
    (:mod:`jointdyn.laws._base`: arguments, returns, units), with

    ``params = [kt (N/m), fy (N), N_ref (N), K, kt / fy (1/m), 1 / N_ref (1/N)]``,
    states ``[x_prev (m), m, (hi_k, a_k, b_k) * 3 K]`` (module docstring);
    T = fy / 2 times the integral of P over [0, 2] (N), kT = kt times the
    stuck fraction of the slip strengths (N/m).
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
        IWAN_CAPACITY, low=MIN_CAPACITY,
        help="linear pieces kept after a step (above it, three adjacent pieces are merged into two)",
    )
    name: ClassVar[str] = "iwan"
    kernels: ClassVar[tuple] = (exact_step, exact_step_jvp, exact_init, exact_init_jvp)
    #: microslip from a distribution of slip thresholds: no stick-slip kink (ContactLaw.smooth_force)
    smooth_force: ClassVar[bool] = True

    @property
    def params(self) -> np.ndarray:
        return np.array(density_params(self))

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
        """The head and live pieces (:func:`jointdyn.laws._density_march.pieces_error`),
        the last breakpoint at u = 2."""
        return pieces_error(s, self.capacity, U_MAX, f"{U_MAX:g}")


def piece_count(state) -> int:
    """Number of linear pieces of an :class:`Iwan` state vector."""
    return int(state[_M])


register(
    "iwan", Iwan,
    summary="exact Iwan model with varying normal load (the discrete model at n -> infinity; default)",
    label="exact Iwan model",
)
