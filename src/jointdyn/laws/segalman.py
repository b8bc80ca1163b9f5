"""Segalman's four-parameter Iwan law with varying normal load, exact (no discretisation).

Registered as ``segalman`` (:class:`Segalman`). The joint is a continuum of
Jenkins elements whose slip displacements phi (at the reference load) have
the density (docs/model.md, "Segalman's four-parameter Iwan law")::

    rho(phi) = R phi^chi on [0, phi_max]  +  S delta(phi - phi_max),

chi > -1 the microslip exponent, beta = S phi_max / (R phi_max^(chi+2) / (chi+2))
the weight of the final delta; with fy = mu N_ref and kt the macroslip force
and stiffness, phi_max = (fy / kt) u_max with u_max = (1 + beta) / D and
D = beta + (chi + 1) / (chi + 2). As in the paper's model, every element's
slip force follows N(t) (its slip displacement is phi N / N_ref).

Representation
--------------
Exactly that of the uniform law (:mod:`jointdyn.laws.exact`): elements are
labelled by u = phi kt / fy in [0, u_max], the state is the piecewise-linear
function P(u) (the element's force as if it had the full stiffness kt, in
fy), a step adds dq = (kt / fy) dx and clips to [-alpha u, alpha u], and the
element at u_max carries the delta. Only the weight changes::

    T = fy (c_R integral_0^u_max u^chi P(u) du + c_S P(u_max)),
    c_R = (chi + 1) / (u_max^(chi+2) D),   c_S = beta / (1 + beta),

and the integral of u^chi (a + b u) over a piece is closed form. The tangent
is kt (c_R integral over the stuck elements of u^chi du + c_S [u_max stuck]).
With chi = 0 and beta = 0 (u_max = 2, c_R = 1/2, c_S = 0) every operation is
the uniform law's, in the same order: ``segalman`` then returns the bits of
``iwan``.

Above the capacity K, three adjacent pieces are merged into two as in the
uniform law, the new vertex keeping the *weighted* integral of P over the
three pieces (so T is unchanged) and lying within the limits; the merge
chosen is the one that moves P least at the two removed breakpoints.
Derivatives (``step_jvp``) follow the uniform law's rows; the merged
vertex's derivative keeps the weighted integral (exact, merges included).

Kernel layouts
--------------
``params = [kt, fy, N_ref, K, kt / fy, 1 / N_ref, chi, u_max, c_R, c_S, u_max^(chi+1),
1 / (chi+1), 1 / (chi+2)]``.

``state = [x_prev, m, (hi_k, a_k, b_k) for k < 3 K, hp_k for k < 3 K]``: the
pieces as in :mod:`jointdyn.laws.exact` (last breakpoint at u_max), then a
cache of hi_k^(chi+1), so that a step computes a power only at the cuts it
makes (a power costs more than the rest of a piece's work).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import ClassVar

import numpy as np

from .. import config
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
    _enforce_capacity,
    _least_triple,
    _integral,
    _line,
    _line_jvp,
    _pow1,
    _shift_down,
    _stuck_part,
    _write,
    _write_jvp,
    clear_rows,
    density_params,
    finish_state,
    march_pieces,
    pieces_error,
    stale_top,
)

__all__ = ["Segalman", "segalman_step", "segalman_step_jvp", "segalman_init", "segalman_init_jvp",
           "CHI_MIN", "CHI_MAX", "segalman_constants"]

#: weight beta of the final delta of the ``segalman`` density when none is given
SEGALMAN_BETA = 0.0

#: smallest microslip exponent: the moments of u^chi lose about
#: -log10(chi + 1) digits to cancellation as chi approaches -1
CHI_MIN = -0.95
#: largest microslip exponent (a density that grows as phi^4 towards phi_max)
CHI_MAX = 4.0
# params rows beyond the uniform law's
_P_CHI, _P_UMAX, _P_CR, _P_CS, _P_UMAXP, _P_INV1, _P_INV2 = 6, 7, 8, 9, 10, 11, 12


def segalman_constants(chi: float, beta: float) -> tuple:
    """``(u_max, c_R, c_S)`` of the density (module docstring).

    Parameters
    ----------
    chi : float
        Microslip exponent (> -1).
    beta : float
        Weight of the final delta (>= 0).

    Returns
    -------
    u_max : float
        phi_max kt / fy (-): 2 for chi = beta = 0, 1 as beta -> infinity.
    c_R, c_S : float
        Weights of the continuum and of the delta in the force (-).
    """
    d = beta + (chi + 1.0) / (chi + 2.0)
    umax = (1.0 + beta) / d
    c_r = (chi + 1.0) / (umax ** (chi + 2.0) * d)
    c_s = beta / (1.0 + beta)
    return umax, c_r, c_s


# --- weighted moments ----------------------------------------------------------------


@jit(inline="always")
def _wint(lo, hi, plo, phi, a, b, chi):
    """Integral of u^chi (a + b u) over [lo, hi]; ``plo``, ``phi`` are lo^(chi+1), hi^(chi+1)."""
    if chi == 0.0:
        return _integral(lo, hi, a, b)
    return a * (phi - plo) / (chi + 1.0) + b * (hi * phi - lo * plo) / (chi + 2.0)


@jit(inline="always")
def _wstuck(lo, hi, plo, phi, a, b, alpha, chi):
    """Integral of u^chi over [lo, hi] if a + b u is not a clip line, else 0."""
    if _stuck_part(lo, hi, a, b, alpha) == 0.0:
        return 0.0
    if chi == 0.0:
        return hi - lo
    return (phi - plo) / (chi + 1.0)


@jit(inline="always")
def _lin(lo, hi, c0, c1, anchor, chi):
    """Integral of u^chi (c0 + c1 (u - anchor)) over [lo, hi]."""
    return _wint(lo, hi, _pow1(lo, chi), _pow1(hi, chi), c0 - c1 * anchor, c1, chi)


@jit(inline="always")
def _hats(u0, uw, u3, p0, pw, p3, chi):
    """Integrals of u^chi times the hat functions of the vertices u0, uw, u3 of two pieces
    (``p0``, ``pw``, ``p3``: the vertices' powers u^(chi+1))."""
    m0a = (pw - p0) / (chi + 1.0)
    m1a = (uw * pw - u0 * p0) / (chi + 2.0)
    m0b = (p3 - pw) / (chi + 1.0)
    m1b = (u3 * p3 - uw * pw) / (chi + 2.0)
    h0 = (uw * m0a - m1a) / (uw - u0)
    hw = (m1a - u0 * m0a) / (uw - u0) + (u3 * m0b - m1b) / (u3 - uw)
    h3 = (m1b - uw * m0b) / (u3 - uw)
    return h0, hw, h3


@jit(inline="always")
def _wtriple(s, j, chi, base):
    """Vertices of pieces j-1, j, j+1 (j >= 1), their powers u^(chi+1) (from the cache
    at row ``base``) and their weighted integral."""
    r = _HEAD + 3 * (j - 1)
    u0 = 0.0 if j == 1 else s[r - 3]
    q0 = 0.0 if j == 1 else s[base + j - 2]
    u1, u2, u3 = s[r], s[r + 3], s[r + 6]
    q1, q2, q3 = s[base + j - 1], s[base + j], s[base + j + 1]
    a0, b0, a1, b1, a2, b2 = s[r + 1], s[r + 2], s[r + 4], s[r + 5], s[r + 7], s[r + 8]
    area = _wint(u0, u1, q0, q1, a0, b0, chi) + _wint(u1, u2, q1, q2, a1, b1, chi) + _wint(u2, u3, q2, q3, a2, b2, chi)
    return u0, u1, u2, u3, q0, q3, a0 + b0 * u0, a0 + b0 * u1, a1 + b1 * u2, a2 + b2 * u3, area


@jit(inline="always")
def _wvertex(u0, u3, uw, q0, qw, q3, p0, p3, area, chi):
    """Value at uw of the two pieces through (u0, p0), (uw, pw), (u3, p3) whose weighted
    integral is ``area`` (q: the powers u^(chi+1) of u0, uw, u3), and the hat integral of uw."""
    h0, hw, h3 = _hats(u0, uw, u3, q0, qw, q3, chi)
    return (area - p0 * h0 - p3 * h3) / hw, hw


@jit(inline="always")
def _wcost(s, j, alpha, chi, base):
    """Cost of merging pieces j-1, j, j+1 (the uniform law's measure: change of P at
    the two removed breakpoints times the width), inf when the vertex leaves the limits."""
    u0, u1, u2, u3, q0, q3, p0, p1, p2, p3, area = _wtriple(s, j, chi, base)
    uw = 0.5 * (u1 + u2)
    pw, _hw = _wvertex(u0, u3, uw, q0, _pow1(uw, chi), q3, p0, p3, area, chi)
    if abs(pw) > alpha * uw:
        return np.inf
    e1 = p0 + (pw - p0) * (u1 - u0) / (uw - u0) - p1
    e2 = pw + (p3 - pw) * (u2 - uw) / (u3 - uw) - p2
    return (abs(e1) + abs(e2)) * (u3 - u0)


@jit(inline="always")
def _wmerge_jvp(s, ds, j, uw, pw, hw, clamp, lines, alpha, ia, dN, chi):
    """Derivative rows of the two pieces replacing j-1, j, j+1 (``s`` still holds the
    three): the vertex value keeps the weighted integral, so its derivative solves
    d(new integral) = d(old integral); the motion of u0 and u3 enters both alike (P is
    continuous) and cancels. A clamped vertex moves with the limit."""
    a1, b1, a2, b2 = lines
    r = _HEAD + 3 * (j - 1)
    u0 = 0.0 if j == 1 else s[r - 3]
    u1, u2, u3 = s[r], s[r + 3], s[r + 6]
    bl, br = s[r + 2], s[r + 8]
    p0 = s[r + 1] + bl * u0
    p3 = s[r + 7] + br * u3
    g1 = (pw - p0) / (uw - u0)  # slopes of the two new pieces (before any snap to a clip line)
    g2 = (p3 - pw) / (u3 - uw)
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
            dold = _lin(u0, u1, da0, db0, 0.0, chi) + _lin(u1, u2, da1, db1, 0.0, chi) + _lin(u2, u3, da2, db2, 0.0, chi)
            e1 = (-dp0 - g1 * (duw - du0)) / (uw - u0)
            e2 = (dp3 - g2 * (du3 - duw)) / (u3 - uw)
            rest = _lin(u0, uw, dp0 - g1 * du0, e1, u0, chi) + _lin(uw, u3, -g2 * duw, e2, uw, chi)
            dpw = (dold - rest) / hw
        dal1, dbl1 = _line_jvp(u0, dp0, du0, uw, dpw, duw, a1, b1, alpha, dal)
        dal2, dbl2 = _line_jvp(uw, dpw, duw, u3, dp3, du3, a2, b2, alpha, dal)
        ds[r, k] = duw
        ds[r + 1, k] = dal1
        ds[r + 2, k] = dbl1
        ds[r + 3, k] = du3
        ds[r + 4, k] = dal2
        ds[r + 5, k] = dbl2


# inlined (as _ucapacity): a call of a function that is not inlined, even on the rare
# path of the merges, cost about 40 ns in every step of the caller's loop (measured)
@jit(inline="always")
def _wcapacity(s, ds, m, cap, alpha, ia, dN, chi):
    """Merge three adjacent pieces into two until at most ``cap`` pieces remain: the
    triple the uniform law would merge (:func:`jointdyn.laws._density_march._least_triple`,
    no powers to compute) when its weighted vertex lies within the limits, else the
    least cost by the weighted vertices (:func:`_wcost`; the first triple, clamped,
    when none does). Keeps the power cache (rows from ``3 cap``) and returns the piece
    count."""
    base = _HEAD + 9 * cap
    while m > cap:
        j = _least_triple(s, m, alpha)
        u0, u1, u2, u3, q0, q3, p0, p1, p2, p3, area = _wtriple(s, j, chi, base)
        uw = 0.5 * (u1 + u2)
        qw = _pow1(uw, chi)
        pw, hw = _wvertex(u0, u3, uw, q0, qw, q3, p0, p3, area, chi)
        if abs(pw) > alpha * uw:
            j = 1
            bcost = np.inf
            for jj in range(1, m - 1):
                c = _wcost(s, jj, alpha, chi, base)
                if c < bcost:
                    j = jj
                    bcost = c
            u0, u1, u2, u3, q0, q3, p0, p1, p2, p3, area = _wtriple(s, j, chi, base)
            uw = 0.5 * (u1 + u2)
            qw = _pow1(uw, chi)
            pw, hw = _wvertex(u0, u3, uw, q0, qw, q3, p0, p3, area, chi)
        clamp = 0.0
        if pw > alpha * uw:
            pw, clamp = alpha * uw, 1.0
        elif pw < -alpha * uw:
            pw, clamp = -alpha * uw, -1.0
        a1, b1 = _line(u0, p0, uw, pw, alpha)
        a2, b2 = _line(uw, pw, u3, p3, alpha)
        if ds is not None:
            _wmerge_jvp(s, ds, j, uw, pw, hw, clamp, (a1, b1, a2, b2), alpha, ia, dN, chi)
        _write(s, j - 1, uw, a1, b1)
        _write(s, j, u3, a2, b2)
        _shift_down(s, ds, j, m)
        s[base + j - 1] = qw
        for k in range(j, m - 1):
            s[base + k] = s[base + k + 1]
        m -= 1
    return m


@jit(inline="always")
def _ucapacity(s, ds, m, cap, alpha, total, stuck, ia, dN):
    """chi = 0: the uniform law's merges (:func:`jointdyn.laws._density_march._enforce_capacity`,
    the same operations and bits); the power cache (u^1) follows."""
    m, total, stuck = _enforce_capacity(s, ds, m, cap, alpha, total, stuck, ia, dN)
    base = _HEAD + 9 * cap
    for k in range(m):
        s[base + k] = s[_HEAD + 3 * k]
    return m, total, stuck


@jit(inline="always")
def _merges(s, ds, m, cap, alpha, total, stuck, params, dN, chi, base):
    """Merges down to ``cap`` pieces (the uniform law's when chi = 0, with its bits when
    beta = 0; else :func:`_wcapacity`): the piece count, the force integrals and whether
    the last piece is stuck (a merge may put it on a clip line or take it off)."""
    if chi == 0.0:
        m, total, stuck = _ucapacity(s, ds, m, cap, alpha, total, stuck, params[_P_INV_NREF], dN)
    else:
        m = _wcapacity(s, ds, m, cap, alpha, params[_P_INV_NREF], dN, chi)
        total, stuck = _totals(s, m, alpha, chi, base)
    r = _HEAD + 3 * (m - 1)
    return m, total, stuck, _stuck_part(0.0, 1.0, s[r + 1], s[r + 2], alpha)


@jit(inline="always")
def _totals(s, m, alpha, chi, base):
    """Weighted integral of P and weighted stuck measure of the ``m`` pieces of ``s``."""
    total = 0.0
    stuck = 0.0
    lo = 0.0
    plo = 0.0
    for k in range(m):
        r = _HEAD + 3 * k
        hi = s[r]
        phi = s[base + k]
        total += _wint(lo, hi, plo, phi, s[r + 1], s[r + 2], chi)
        stuck += _wstuck(lo, hi, plo, phi, s[r + 1], s[r + 2], alpha, chi)
        lo = hi
        plo = phi
    return total, stuck


@jit(inline="always")
def _jvp_force(s, ds, m, params, dT, base):
    """dT = fy (c_R sum over pieces of the weighted integral of da + db u + c_S dP(u_max));
    the power cache's rows get the derivative of u^(chi+1) through their breakpoints'."""
    chi = params[_P_CHI]
    for j in range(dT.shape[0]):
        dT[j] = 0.0
    lo = 0.0
    plo = 0.0
    for k in range(m):
        r = _HEAD + 3 * k
        hi = s[r]
        phi = s[base + k]
        for j in range(dT.shape[0]):
            dT[j] += _wint(lo, hi, plo, phi, ds[r + 1, j], ds[r + 2, j], chi)
            ds[base + k, j] = (chi + 1.0) * phi / hi * ds[r, j]
        lo = hi
        plo = phi
    r = _HEAD + 3 * (m - 1)
    umax = params[_P_UMAX]
    for j in range(dT.shape[0]):
        dT[j] = params[_P_FY] * (params[_P_CR] * dT[j] + params[_P_CS] * (ds[r + 1, j] + ds[r + 2, j] * umax))


@jit(inline="always")
def _segalman_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT):
    # the uniform law's march (jointdyn.laws._density_march) with weighted integrals and
    # the delta; derivative arguments all arrays or all None (pruned at compile time)
    fy = params[_P_FY]
    chi = params[_P_CHI]
    cap = int(params[_P_CAP])
    base = _HEAD + 9 * cap  # the power cache: right^(chi+1) of each piece
    alpha = N * params[_P_INV_NREF]
    contact = alpha > 0.0 and fy > 0.0
    inc = params[_P_QS] * (x - s_old[_X])
    m, total, stuck, tot_a, tot_b, st_a, end_stuck = march_pieces(params, s_old, s_new, alpha, inc, contact, ds_old,
                                                                  ds_new, dx, dN, (chi, base))
    # unconditional (a conditional reassignment cost 20 ns a step); 0 numerators when chi = 0
    total = total + (tot_a * params[_P_INV1] + tot_b * params[_P_INV2])
    stuck = stuck + st_a * params[_P_INV1]
    written = m
    if m > cap:
        m, total, stuck, end_stuck = _merges(s_new, ds_new, m, cap, alpha, total, stuck, params, dN, chi, base)
    if not contact:
        _write(s_new, 0, params[_P_UMAX], 0.0, 0.0)
        s_new[base] = params[_P_UMAXP]
        m = 1
    top = stale_top(s_new, written, 3 * cap)
    clear_rows(s_new, ds_new, _HEAD + 3 * m, _HEAD + 3 * top)
    clear_rows(s_new, ds_new, base + m, base + top)
    if ds_new is not None:
        if not contact:
            _write_jvp(ds_new, ds_old, dx, dN, 0, _HEAD, _ZERO, 0.0, 0.0, _END_HI, params[_P_UMAX], 0.0, 0.0)
        _jvp_force(s_new, ds_new, m, params, dT, base)
    finish_state(s_new, ds_new, dx, x, m)
    return _force(params, s_new, m, alpha, total, stuck, end_stuck)


@jit(inline="always")
def _force(params, s_new, m, alpha, total, stuck, end_stuck):
    """Force, tangent and code from the weighted integrals and the delta at u_max: the
    last piece's end value (end_stuck tracked while writing: from the state here it cost
    40 ns a step); a stuck last piece makes stuck > 0."""
    rl = _HEAD + 3 * (m - 1)
    p_end = s_new[rl + 1] + s_new[rl + 2] * params[_P_UMAX]
    code = STICK_SLIP if stuck > 0.0 else MACROSLIP
    if alpha <= 0.0:
        code = SEPARATION
    c_r = params[_P_CR]
    c_s = params[_P_CS]
    return params[_P_FY] * (c_r * total + c_s * p_end), params[_P_KT] * (c_r * stuck + c_s * end_stuck), code


@jit(inline="always")
def segalman_step(params, s_old, s_new, x, N):
    """Trial step of the Segalman law: the kernel contract's ``step``
    (:mod:`jointdyn.laws._base`: arguments, returns, units), with the
    parameters and state of the module docstring (the pieces as in
    :mod:`jointdyn.laws.exact`, the last breakpoint at u_max, then the power
    cache); T and kT weigh the pieces by u^chi and add the delta at u_max.
    """
    return _segalman_core(params, s_old, s_new, x, N, None, None, None, None, None)


@jit
def segalman_step_jvp(params, s_old, ds_old, s_new, ds_new, x, dx, N, dN, dT):
    """:func:`segalman_step` with forward-mode derivatives along ``dx.size`` directions."""
    return _segalman_core(params, s_old, s_new, x, N, ds_old, ds_new, dx, dN, dT)


@jit
def segalman_init(params, x0, n0, s):
    """Virgin committed state at ``x0`` (m): P = 0 on [0, u_max] (one piece); ``n0`` does not enter."""
    s[:] = 0.0
    s[_X] = x0
    s[_M] = 1.0
    _write(s, 0, params[_P_UMAX], 0.0, 0.0)
    s[_HEAD + 9 * int(params[_P_CAP])] = params[_P_UMAXP]


@jit
def segalman_init_jvp(params, x0, dx0, n0, dn0, s, ds):
    """:func:`segalman_init` and its derivative: d(x_prev) = dx0, zero elsewhere."""
    segalman_init(params, x0, n0, s)
    ds[:, :] = 0.0
    for j in range(ds.shape[1]):
        ds[_X, j] = dx0[j]


@dataclass(frozen=True)
class Segalman(ContactLaw):
    """Segalman's four-parameter Iwan law, slip forces scaled by N(t)/N_ref, exact.

    Slip-displacement density R phi^chi on [0, phi_max] plus a delta S at
    phi_max (module docstring), every element's slip force following the
    normal load; computed exactly like :class:`~jointdyn.Iwan` (a
    piecewise-linear state, no discretisation). ``chi = 0, beta = 0`` is the
    uniform Iwan law, bit for bit. Registered as ``segalman``.

    Parameters
    ----------
    kt : float
        Total tangential stiffness K_T, N/m.
    mu : float
        Friction coefficient; fy = mu n_ref is the macroslip force F_S at N_ref.
    n_ref : float
        Reference normal load N_ref, N.
    chi : float
        Microslip exponent (-): the energy dissipated per cycle at constant
        load grows as A^(chi + 3). In [CHI_MIN, CHI_MAX].
    beta : float
        Weight of the final delta (-, >= 0): the elements that slip last,
        all at phi_max, hold the fraction beta / (1 + beta) of kt; 0 for none.
    capacity : int
        Largest number of linear pieces kept after a step (>= 3), as for ``iwan``.
    """

    chi: float = law_param(config.SEGALMAN_CHI, low=CHI_MIN, high=CHI_MAX,
                           help="microslip exponent: slip-displacement density R phi^chi (dissipation ~ A^(chi+3))")
    beta: float = law_param(SEGALMAN_BETA, low=0.0,
                            help="weight of the delta of slip displacements at phi_max (0: none)")
    capacity: int = law_param(
        IWAN_CAPACITY, low=MIN_CAPACITY,
        help="linear pieces kept after a step (above it, three adjacent pieces are merged into two)",
    )
    name: ClassVar[str] = "segalman"
    kernels: ClassVar[tuple] = (segalman_step, segalman_step_jvp, segalman_init, segalman_init_jvp)

    @property
    def smooth_force(self) -> bool:
        """True without a delta: the force then has no kink at the onset of macroslip
        (with beta > 0 the elements at phi_max slip all at once)."""
        return self.beta == 0.0

    @property
    def constants(self) -> tuple:
        """``(u_max, c_R, c_S)`` (:func:`segalman_constants`)."""
        return segalman_constants(self.chi, self.beta)

    @property
    def phi_max(self) -> float:
        """Largest slip displacement at N_ref, m: u_max fy / kt."""
        return self.constants[0] * self.fy / self.kt

    @property
    def params(self) -> np.ndarray:
        umax, c_r, c_s = self.constants
        return np.array(density_params(self) + [self.chi, umax, c_r, c_s, umax ** (self.chi + 1.0),
                                                1.0 / (self.chi + 1.0), 1.0 / (self.chi + 2.0)])

    @property
    def state_size(self) -> int:
        return _HEAD + 12 * self.capacity

    @property
    def x_slip(self) -> float:
        """phi_max (m): the virgin curve reaches macroslip when the last element slips."""
        return self.phi_max

    @property
    def passive(self) -> bool:
        """True: every element is an elastic-perfectly-plastic Jenkins element; a merge
        keeps the weighted integral of P and never leaves the limits."""
        return True

    def _state_error(self, s):
        """As :class:`~jointdyn.Iwan` (last live breakpoint at u_max), and the power cache."""
        umax = self.constants[0]
        err = pieces_error(s, self.capacity, umax, f"u_max = {umax!r}")
        if err is not None:
            return err
        m = int(s[_M])
        hi = s[_HEAD : _HEAD + 3 * m : 3]
        base = _HEAD + 9 * self.capacity
        cache = s[base : base + m]
        want = hi ** (self.chi + 1.0)
        if not (np.all(np.isfinite(cache)) and np.allclose(cache, want, rtol=1e-12, atol=0.0)):
            return (
                f"entries {base}..{base + m - 1} must hold the breakpoints' powers u^(chi + 1) = {want.tolist()}, "
                f"got {cache.tolist()}"
            )
        return None


register(
    "segalman", Segalman,
    summary="Segalman's four-parameter Iwan law (density R phi^chi plus a delta) with varying normal load, exact",
    label="Segalman",
)
