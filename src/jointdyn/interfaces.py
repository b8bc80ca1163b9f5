"""Interfaces: a contact patch of node pairs with 2-D slip and a normal load from the motion.

docs/model.md section 10. A pair names six DOFs of the structure,
``(a_t1, a_t2, a_n, b_t1, b_t2, b_n)`` (side A along t1, t2, n, then side
B; -1 is a fixed side), and sees

    u_k = x[a_tk] - x[b_tk]  (k = 1, 2),   g = x[a_n] - x[b_n]  (positive closes),
    N = max(0, P + kn g),   T = kt (u - w),   |T| <= mu N,

with the slider ``w`` (a 2-vector, m) its only memory. A step is
integrated exactly along the straight path from its start point
``(u0, g0)``, where the slider was committed, to its end ``(u, g)``
(histories are piecewise linear between samples): open at the end
(N = 0) gives T = 0 and w = u; a pair open at the start closes at the
instant where ``P + kn g`` = 0 with T = 0 and w = u there; closed, it
sticks while the trial force stays in the disc ``|T| <= mu N`` (the exit
instant a root of a quadratic, ``_exit``) and slips from there to
the end with the closed form of the turning angle (``_turn``). The
radial return of the end point's trial force onto the circle is the
special case without turning (1-D motion). A step that starts where it
ends (a march's first sample) is that radial return. The structure feels
``-T`` on side A and ``+T`` on side B along t1, t2, and ``-(N - P)`` on
``a_n``, ``+(N - P)`` on ``b_n`` (the signs of the normal springs,
:mod:`jointdyn.kinematics`).

Compiled kernels (allocation-free, a loop over the pairs, cost linear in
their number)::

    interface_step(params, u0, g0, u, g, w_old, w_new, T, N, code)
    interface_step_jvp(params, u0, du0, g0, dg0, u, du, g, dg, w_old, dw_old, w_new, dw_new,
                       T, dT, N, dN, code)
    interface_step_tangent(params, u0, g0, u, g, w_old, w_new, T, N, code, J)
    interface_march(params, w0, U, G, T, N, code, w_final)
    interface_march_jvp(params, w0, dw0, U, dU, G, dG, T, dT, N, dN, code, w_final, dw_final)
    interface_gather(pairs, x, u, g)
    interface_scatter(pairs, T, N, params, f)

with the arguments::

    params      float64 (np, 4)     per pair: kt (N/m), kn (N/m), mu, P (N)
    u0, g0      float64 (np, 2), (np,)  the step's start point: relative displacement
                                    and normal approach at the committed state, m
    u           float64 (np, 2)     relative tangential displacement, m
    g           float64 (np,)       normal approach, m
    w_old/new   float64 (np, 2)     committed (w_old, not written) and trial
                                    (w_new, written in full) slider, m
    T           float64 (np, 2)     tangential force, N (output)
    N           float64 (np,)       normal load, N (output)
    code        int8 or int64 (np,) STICK_SLIP (stuck), MACROSLIP (slipping) or
                                    SEPARATION (open), the codes of the laws
    du          float64 (np, 2, nd) derivatives of u along nd directions per pair
                                    (du0 (np, 2, nd), dg0, dg (np, nd), dw_old/new (np, 2, nd),
                                    dT (np, 2, nd), dN (np, nd) alike)
    J           float64 (np, 3, 3)  d(T1, T2, N) / d(u1, u2, g) of every pair at the
                                    end point, start point and committed slider
                                    fixed (output)

The derivatives are exact: forward mode through the closed form (``_dpair``), along directions
of the start point (du0, dg0), the end point (du, dg) and the committed slider (dw_old). The
derivative of the slider carries the history (as ``step_jvp`` of the contact laws,
``jointdyn.laws._base``): the chain rule through a march is exact away from the measure-zero
instants where a pair changes state. ``interface_step_jvp`` and ``interface_step_tangent``
return the primal outputs of ``interface_step`` bit for bit.
"""

from __future__ import annotations

import math
import sys
from dataclasses import dataclass

import numpy as np

from . import _validate as V
from . import config
from ._jit import jit
from .laws._base import _HUGE, MACROSLIP, SEPARATION, STICK_SLIP

__all__ = [
    "Interface",
    "PAIR_COLUMNS",
    "interface_step",
    "interface_step_jvp",
    "interface_step_tangent",
    "interface_march",
    "interface_march_jvp",
    "interface_gather",
    "interface_scatter",
]

#: the six DOF columns of a pair, in order
PAIR_COLUMNS = ("a_t1", "a_t2", "a_n", "b_t1", "b_t2", "b_n")
#: the parameters of a pair, in the column order of ``params``
PARAM_NAMES = ("kt", "kn", "mu", "preload")


# --- compiled kernels ----------------------------------------------------------------


#: the intermediates of an open pair (:func:`_pair`)
_NO_AUX = (0.0,) * 27


@jit(inline="always")
def _log1p_ratio(z):  # pragma: no cover - compiled
    """``h(z) = log(1 + z) / z`` and ``h'(z)`` (z > -1), by their series near 0 where the quotients
    cancel (|z| < 1e-3: truncation below 1e-18, the quotients' rounding below 3e-13 beyond)."""
    if abs(z) < 1e-3:
        h = 1.0 + z * (-1.0 / 2 + z * (1.0 / 3 + z * (-1.0 / 4 + z * (1.0 / 5 + z * (-1.0 / 6 + z / 7)))))
        dh = -1.0 / 2 + z * (2.0 / 3 + z * (-3.0 / 4 + z * (4.0 / 5 + z * (-5.0 / 6 + z * 6.0 / 7))))
        return h, dh
    lg = math.log1p(z)
    return lg / z, (z / (1.0 + z) - lg) / (z * z)


@jit(inline="always")
def _closing(kt, mu, n0, n1, a1, a2, w1, w2):  # pragma: no cover - compiled
    """Start of the closed part of a step: its length L (in units of the step), force Ta and load Na
    there, the committed trial force T0 = kt (u0 - w_old) and its norm r0, and the flags
    ``reclose`` (open at the start: closes at tau = n0 / (n0 - n1) with T = 0 and no memory) and
    ``proj`` (a start outside the disc |T| <= mu N, slid back onto it radially first)."""
    if not n0 > 0.0:
        return n1 / (n1 - n0), 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0
    t1 = kt * (a1 - w1)
    t2 = kt * (a2 - w2)
    r2 = t1 * t1 + t2 * t2
    lim = mu * n0
    if r2 <= lim * lim:  # (r0 is only needed to slide back)
        return 1.0, t1, t2, n0, t1, t2, 0.0, 0.0, 0.0
    r = math.sqrt(r2)
    f = lim / r
    return 1.0, f * t1, f * t2, n0, t1, t2, r, 0.0, 1.0


#: the smallest positive normal double: below it a sum of squares is subnormal
_NORMAL_MIN = 2.2250738585072014e-308

@jit(inline="always")
def _exit(kt, mu, v1, v2, s, nd, Ta1, Ta2, Na, proj):  # pragma: no cover - compiled
    """First sigma >= 0 where the stuck trial ``Ta + kt v sigma`` leaves the disc of radius
    ``mu (Na + nd sigma)``: the root of ``a sigma^2 + 2 b sigma + c`` where it rises through 0, in
    the forms free of cancellation; inf when it never leaves."""
    a = (kt * s) ** 2 - (mu * nd) ** 2
    b = kt * (Ta1 * v1 + Ta2 * v2) - mu * mu * Na * nd
    c = 0.0 if proj > 0.0 else min(Ta1 * Ta1 + Ta2 * Ta2 - (mu * Na) ** 2, 0.0)
    if b > 0.0:
        q2 = b * b - a * c
        return -c / (b + math.sqrt(q2)) if q2 >= 0.0 else math.inf
    if a > 0.0:
        return (math.sqrt(b * b - a * c) - b) / a
    return math.inf


@jit(inline="always")
def _turn(kt, mu, v1, v2, s, nd, Ts1, Ts2, Ns, Ls, n1):  # pragma: no cover - compiled
    """Slip from the force Ts (on the circle, load Ns) over the rest Ls of the step: the direction e
    at the end, at the angle phi from v / |v| with tan(phi / 2) = F tan(phi_s / 2),
    F = exp(-kt |v| l / mu), l = int dtau / N. Returns e1, e2, the half-angle (x, y) of phi_s
    (a vector along it, not of unit length), F, l, dl / dnd and ``turned`` (0: no start
    direction, e = v / |v|)."""
    rs = math.sqrt(Ts1 * Ts1 + Ts2 * Ts2)
    if s == 0.0:  # no tangential motion: the force keeps its direction
        return Ts1 / rs, Ts2 / rs, 1.0, 0.0, 1.0, 0.0, 0.0, 1.0
    inv = 1.0 / s
    p1 = v1 * inv
    p2 = v2 * inv
    x, y, F, ell, dl, turned = 1.0, 0.0, 0.0, 0.0, 0.0, 0.0
    if rs > 0.0:
        inv = 1.0 / rs
        c = (p1 * Ts1 + p2 * Ts2) * inv
        sn = (p1 * Ts2 - p2 * Ts1) * inv
        if c >= 0.0:
            x, y = 1.0 + c, sn
        else:  # (1 + cos, sin) without the cancellation near phi_s = pi
            x, y = abs(sn), (1.0 - c if sn >= 0.0 else c - 1.0)
        q = Ls / Ns
        hz, dhz = _log1p_ratio(nd * q)
        ell = q * hz
        dl = q * q * dhz
        F = math.exp(-kt * s * ell / mu)
        turned = 1.0
    Fy = F * y
    D = x * x + Fy * Fy
    inv = 1.0 / D if D > 0.0 else 0.0
    cp, sp = ((x * x - Fy * Fy) * inv, 2.0 * x * Fy * inv) if D > 0.0 else (-1.0, 0.0)
    return cp * p1 - sp * p2, cp * p2 + sp * p1, x, y, F, ell, dl, turned


@jit(inline="always")
def _pair(kt, kn, mu, P, a1, a2, g0, u1, u2, g, w1, w2):  # pragma: no cover - compiled
    """Step of one pair along the straight path from (a, g0) to (u, g) (docs/model.md section 10),
    scalars in and out: open at the end; else closed from the start (or from re-closing), stuck
    until the trial leaves the disc (:func:`_exit`), slipping from there to the end (:func:`_turn`).

    Returns ``code, T1, T2, N, w1_new, w2_new`` and the tuple of intermediates :func:`_dpair` takes.
    """
    n1 = P + kn * g
    if not n1 > 0.0:
        return SEPARATION, 0.0, 0.0, 0.0, u1, u2, _NO_AUX
    n0 = P + kn * g0
    L, Ta1, Ta2, Na, T01, T02, r0, reclose, proj = _closing(kt, mu, n0, n1, a1, a2, w1, w2)
    v1 = u1 - a1
    v2 = u2 - a2
    s2 = v1 * v1 + v2 * v2
    # hypot where the squares are subnormal (a step below about 1e-154 m: sqrt of their sum loses up to
    # half the digits there); the sum of squares elsewhere, exact to rounding and cheaper on this path
    s = math.sqrt(s2) if s2 >= _NORMAL_MIN else math.hypot(v1, v2)
    nd = n1 - n0
    sig = _exit(kt, mu, v1, v2, s, nd, Ta1, Ta2, Na, proj)
    if not sig < L:  # stuck to the end
        if reclose > 0.0:
            T1, T2, wn1, wn2 = kt * v1 * L, kt * v2 * L, u1 - v1 * L, u2 - v2 * L
        elif proj > 0.0:
            T1, T2 = Ta1 + kt * v1, Ta2 + kt * v2
            wn1, wn2 = u1 - T1 / kt, u2 - T2 / kt
        else:
            T1, T2, wn1, wn2 = kt * (u1 - w1), kt * (u2 - w2), w1, w2
        aux = (1.0, L, n0, n1, v1, v2, s, Ta1, Ta2, T01, T02, r0, reclose, proj, sig,
               0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
        # the state at the end: stuck inside the disc; a start slid back onto the circle reports slip
        # when the step does not carry the force off it (as the radial return of a step without motion)
        slid = proj > 0.0 and ((s == 0.0 and nd == 0.0) or not T1 * T1 + T2 * T2 < (mu * n1) ** 2)
        return (MACROSLIP if slid else STICK_SLIP), T1, T2, n1, wn1, wn2, aux
    Ts1 = Ta1 + kt * v1 * sig
    Ts2 = Ta2 + kt * v2 * sig
    Ns = Na + nd * sig
    Ls = L - sig
    e1, e2, x, y, F, ell, dl, turned = _turn(kt, mu, v1, v2, s, nd, Ts1, Ts2, Ns, Ls, n1)
    T1 = mu * n1 * e1
    T2 = mu * n1 * e2
    aux = (2.0, L, n0, n1, v1, v2, s, Ta1, Ta2, T01, T02, r0, reclose, proj, sig,
           Ls, Ts1, Ts2, Ns, x, y, F, ell, dl, e1, e2, turned)
    return MACROSLIP, T1, T2, n1, u1 - T1 / kt, u2 - T2 / kt, aux


@jit(inline="always")
def _dstart(kt, kn, mu, aux, da1, da2, dg0, dg, dw1, dw2):  # pragma: no cover - compiled
    """Derivatives of the closed part's start (:func:`_closing`) along one direction: dL, dTa, dNa."""
    L, n0, n1, T01, T02, r0, reclose, proj = aux[1], aux[2], aux[3], aux[9], aux[10], aux[11], aux[12], aux[13]
    if reclose > 0.0:
        nd = n1 - n0
        return kn * (n1 * dg0 - n0 * dg) / (nd * nd), 0.0, 0.0, 0.0
    d1 = kt * (da1 - dw1)
    d2 = kt * (da2 - dw2)
    if proj > 0.0:  # radial return of the start
        q1 = T01 / r0
        q2 = T02 / r0
        along = q1 * d1 + q2 * d2
        f = mu * n0 / r0
        dn0 = mu * kn * dg0
        d1, d2 = dn0 * q1 + f * (d1 - q1 * along), dn0 * q2 + f * (d2 - q2 * along)
    return 0.0, d1, d2, kn * dg0


@jit(inline="always")
def _dpair(kt, kn, mu, aux, da1, da2, dg0, du1, du2, dg, dw1, dw2):  # pragma: no cover - compiled
    """Forward-mode derivative of a closed pair's step (:func:`_pair`, its ``aux``) along one direction
    of the start (da, dg0), end (du, dg) and committed slider (dw): returns dT1, dT2, dw1_new, dw2_new.
    The exit instant needs no derivative: the force turns at the same rate stuck or slipping when on
    the circle, so the end force does not depend on where along the path the slip starts."""
    kind, L, n0, n1, v1, v2, s, sig = aux[0], aux[1], aux[2], aux[3], aux[4], aux[5], aux[6], aux[14]
    if kind == 1.0 and aux[12] == 0.0 and aux[13] == 0.0:  # plain stick: T = kt (u - w_old)
        return kt * (du1 - dw1), kt * (du2 - dw2), dw1, dw2
    dL, dTa1, dTa2, dNa = _dstart(kt, kn, mu, aux, da1, da2, dg0, dg, dw1, dw2)
    dv1 = du1 - da1
    dv2 = du2 - da2
    if kind == 1.0:
        d1 = dTa1 + kt * (dv1 * L + v1 * dL)
        d2 = dTa2 + kt * (dv2 * L + v2 * dL)
        return d1, d2, du1 - d1 / kt, du2 - d2 / kt
    Ls, Ts1, Ts2, Ns, x, y, F, ell, dl, e1, e2, turned = aux[15:27]
    dnd = kn * (dg - dg0)
    dTs1 = dTa1 + kt * dv1 * sig
    dTs2 = dTa2 + kt * dv2 * sig
    if s == 0.0:
        dth = (Ts1 * dTs2 - Ts2 * dTs1) / (Ts1 * Ts1 + Ts2 * Ts2)
    else:
        dth = (v1 * dv2 - v2 * dv1) / (s * s)  # turn of v
        Fy = F * y
        D = x * x + Fy * Fy
        if turned > 0.0 and D > 0.0:
            dphis = (Ts1 * dTs2 - Ts2 * dTs1) / (Ts1 * Ts1 + Ts2 * Ts2) - dth
            dNs = dNa + dnd * sig
            dell = dL / n1 - Ls / (Ns * n1) * dNs + dl * dnd
            dF = -F * kt / mu * ((v1 * dv1 + v2 * dv2) / s * ell + s * dell)
            dth += (F * (x * x + y * y) * dphis + 2.0 * x * y * dF) / D
    dn1 = mu * kn * dg
    f = mu * n1 * dth
    d1 = dn1 * e1 - f * e2
    d2 = dn1 * e2 + f * e1
    return d1, d2, du1 - d1 / kt, du2 - d2 / kt


@jit(inline="always")
def _pair_step(params, i, u0, g0, u, g, w_old, w_new, T, N):  # pragma: no cover - compiled
    """:func:`_pair` of pair i, its outputs written (the arrays read and written in one place: a first
    radial-return version that wrote them in every branch measured 71 instead of 5.7 ns per pair and
    step); returns code and the intermediates."""
    c, T1, T2, n, v1, v2, aux = _pair(params[i, 0], params[i, 1], params[i, 2], params[i, 3],
                                      u0[i, 0], u0[i, 1], g0[i], u[i, 0], u[i, 1], g[i], w_old[i, 0], w_old[i, 1])
    T[i, 0] = T1
    T[i, 1] = T2
    N[i] = n
    w_new[i, 0] = v1
    w_new[i, 1] = v2
    return c, aux


@jit
def interface_step(params, u0, g0, u, g, w_old, w_new, T, N, code):  # pragma: no cover - compiled
    """Step of every pair along the straight path from its start point to (u, g), from the committed
    sliders (module docstring).

    Parameters
    ----------
    params : float64 (np, 4)
        kt (N/m), kn (N/m), mu, P (N) per pair.
    u0, g0 : float64 (np, 2), (np,)
        Start point of the step (the committed relative displacements and approaches), m.
    u : float64 (np, 2)
        Relative tangential displacements, m.
    g : float64 (np,)
        Normal approaches, m (positive closes).
    w_old, w_new : float64 (np, 2)
        Committed slider (not written) and trial slider (written), m.
    T, N, code : outputs
        Tangential force (np, 2) N, normal load (np,) N, motion state (np,).
    """
    for i in range(params.shape[0]):
        code[i] = _pair_step(params, i, u0, g0, u, g, w_old, w_new, T, N)[0]


@jit
def interface_step_jvp(params, u0, du0, g0, dg0, u, du, g, dg, w_old, dw_old, w_new, dw_new, T, dT, N, dN,
                       code):  # pragma: no cover - compiled
    """:func:`interface_step` with forward-mode derivatives along ``du.shape[2]`` directions per pair
    of the start point (du0, dg0), the end point (du, dg) and the committed slider (dw_old).

    Open at the end: dT = dN = 0, dw = du. Closed: dN = kn dg and dT from the closed form
    (:func:`_dpair`), dw = du - dT / kt (stuck from a consistent start: dw = dw_old).
    """
    nd = du.shape[2]
    for i in range(params.shape[0]):
        c, aux = _pair_step(params, i, u0, g0, u, g, w_old, w_new, T, N)
        code[i] = c
        kt = params[i, 0]
        kn = params[i, 1]
        mu = params[i, 2]
        for j in range(nd):
            if c == SEPARATION:
                dN[i, j] = 0.0
                dT[i, 0, j] = 0.0
                dT[i, 1, j] = 0.0
                dw_new[i, 0, j] = du[i, 0, j]
                dw_new[i, 1, j] = du[i, 1, j]
                continue
            d1, d2, e1, e2 = _dpair(kt, kn, mu, aux, du0[i, 0, j], du0[i, 1, j], dg0[i, j], du[i, 0, j],
                                    du[i, 1, j], dg[i, j], dw_old[i, 0, j], dw_old[i, 1, j])
            dN[i, j] = kn * dg[i, j]
            dT[i, 0, j] = d1
            dT[i, 1, j] = d2
            dw_new[i, 0, j] = e1
            dw_new[i, 1, j] = e2


@jit
def interface_step_tangent(params, u0, g0, u, g, w_old, w_new, T, N, code, J):  # pragma: no cover - compiled
    """:func:`interface_step` and the 3 x 3 block ``J[i] = d(T1, T2, N) / d(u1, u2, g)`` of every pair at
    the end point, the start point and the committed slider fixed (N/m): open zero; stuck from a
    consistent start diag(kt, kt, kn); slipping the derivative of the closed form (:func:`_dpair`)
    and kn in the corner."""
    for i in range(params.shape[0]):
        c, aux = _pair_step(params, i, u0, g0, u, g, w_old, w_new, T, N)
        code[i] = c
        for a in range(3):
            for b in range(3):
                J[i, a, b] = 0.0
        if c == SEPARATION:
            continue
        kt = params[i, 0]
        kn = params[i, 1]
        mu = params[i, 2]
        J[i, 2, 2] = kn
        for k in range(3):
            d1, d2 = _dpair(kt, kn, mu, aux, 0.0, 0.0, 0.0, 1.0 if k == 0 else 0.0, 1.0 if k == 1 else 0.0,
                            1.0 if k == 2 else 0.0, 0.0, 0.0)[:2]
            J[i, 0, k] = d1
            J[i, 1, k] = d2


@jit
def interface_march(params, w0, U, G, T, N, code, w_final):  # pragma: no cover - compiled
    """March every pair over the samples ``U[j]`` (np, 2), ``G[j]`` (np,) from the committed sliders
    ``w0`` (not written), committing after each sample, into ``T[j]``, ``N[j]``, ``code[j]`` and the
    final sliders ``w_final``. The samples are the vertices of the path: step j runs from sample
    j - 1 to sample j, the first from the first sample itself."""
    a = w0.copy()
    b = w0.copy()
    for j in range(U.shape[0]):
        k = j - 1 if j > 0 else 0
        interface_step(params, U[k], G[k], U[j], G[j], a, b, T[j], N[j], code[j])
        a, b = b, a
    for i in range(a.shape[0]):
        w_final[i, 0] = a[i, 0]
        w_final[i, 1] = a[i, 1]


@jit
def interface_march_jvp(params, w0, dw0, U, dU, G, dG, T, dT, N, dN, code, w_final, dw_final):  # pragma: no cover
    """:func:`interface_march` with forward-mode derivatives along ``dU.shape[3]`` directions per pair:
    ``dU[j]`` (np, 2, nd), ``dG[j]`` (np, nd) the derivatives of the samples, ``dw0`` (np, 2, nd) that
    of the starting sliders (not written); ``dT[j]``, ``dN[j]`` and ``dw_final`` are written. The
    chain rule through the whole march is exact away from the instants where a pair changes state."""
    a = w0.copy()
    b = w0.copy()
    da = dw0.copy()
    db = dw0.copy()
    for j in range(U.shape[0]):
        k = j - 1 if j > 0 else 0
        interface_step_jvp(params, U[k], dU[k], G[k], dG[k], U[j], dU[j], G[j], dG[j], a, da, b, db,
                           T[j], dT[j], N[j], dN[j], code[j])
        a, b = b, a
        da, db = db, da
    for i in range(a.shape[0]):
        for k in range(2):
            w_final[i, k] = a[i, k]
            for d in range(da.shape[2]):
                dw_final[i, k, d] = da[i, k, d]


@jit(inline="always")
def _dof(x, d):  # pragma: no cover - compiled
    return x[d] if d >= 0 else 0.0


@jit
def interface_gather(pairs, x, u, g):  # pragma: no cover - compiled
    """u[i, k] = x[a_tk] - x[b_tk] and g[i] = x[a_n] - x[b_n] (m) of every pair (-1: fixed, 0)."""
    for i in range(pairs.shape[0]):
        u[i, 0] = _dof(x, pairs[i, 0]) - _dof(x, pairs[i, 3])
        u[i, 1] = _dof(x, pairs[i, 1]) - _dof(x, pairs[i, 4])
        g[i] = _dof(x, pairs[i, 2]) - _dof(x, pairs[i, 5])


@jit(inline="always")
def _push(f, d, v):  # pragma: no cover - compiled
    if d >= 0:
        f[d] += v


@jit
def interface_scatter(pairs, T, N, params, f):  # pragma: no cover - compiled
    """Subtract the reactions of every pair from the generalised forces f (N): -T on side A and +T
    on side B along t1, t2; -(N - P) on a_n and +(N - P) on b_n."""
    for i in range(pairs.shape[0]):
        dn = N[i] - params[i, 3]
        _push(f, pairs[i, 0], -T[i, 0])
        _push(f, pairs[i, 1], -T[i, 1])
        _push(f, pairs[i, 2], -dn)
        _push(f, pairs[i, 3], T[i, 0])
        _push(f, pairs[i, 4], T[i, 1])
        _push(f, pairs[i, 5], dn)


# --- the interface as users give it --------------------------------------------------


#: largest stiffness (N/m) or preload (N) of a pair: that of a matrix entry of a system file, the
#: largest double over a headroom for the sums of many pairs on one DOF and the solvers' scalings
_MAX_PARAM = sys.float_info.max / 2.0**20


def _per_pair(name: str, value, npairs: int, positive: bool) -> np.ndarray:
    """A parameter given as one number or one number per pair, validated, as (npairs,) float64."""
    sign = V.positive if positive else V.nonnegative

    def check(label, v):
        v = sign(label, v)
        if v > _MAX_PARAM:
            raise ValueError(f"{label} must be at most {_MAX_PARAM:.4g} (the solvers add it to K, sum it over the "
                             f"pairs and scale it), got {v!r}")
        return v

    if np.ndim(value) == 0:
        return np.full(npairs, check(name, value))
    try:
        a = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a number or a list of {npairs} numbers (one per pair)") from None
    if a.ndim != 1 or a.size != npairs:
        raise ValueError(f"{name} must be a number or a list of {npairs} numbers (one per pair), got shape {a.shape}")
    for i, v in enumerate(a):
        check(f"{name}[{i}]", v)
    return np.ascontiguousarray(a)


def _pairs(value) -> np.ndarray:
    """The (npairs, 6) int64 DOF table, validated (entries >= -1, distinct DOFs within a pair)."""
    cols = ", ".join(PAIR_COLUMNS)
    count = len(value) if hasattr(value, "__len__") else 0
    if count > config.INTERFACE_MAX_PAIRS:  # before a table of them is built or evaluated
        raise ValueError(f"pairs must have at most {config.INTERFACE_MAX_PAIRS} rows (config.INTERFACE_MAX_PAIRS: "
                         f"every solver evaluates each pair at every sample of every step), got {count}")
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        a = None
    if a is None or a.ndim != 2 or a.shape[1] != 6 or a.shape[0] < 1:
        shape = None if a is None else a.shape
        raise ValueError(f"pairs must be a table of at least one row of 6 DOF indices ({cols}), got shape {shape}")
    if a.dtype.kind not in "iuf" or (a.dtype.kind == "f" and not np.all(np.isfinite(a))):
        raise ValueError(f"pairs must hold integers >= -1 ({cols}; -1 = fixed), got dtype {a.dtype}")
    p = a.astype(np.int64)
    bad = np.argwhere((p != a) | (p < -1))
    if bad.size:
        i, k = (int(v) for v in bad[0])
        raise ValueError(f"pairs[{i}, {k}] ({PAIR_COLUMNS[k]}) must be an integer >= -1 (-1 = fixed), "
                         f"got {a[i, k]!r}")
    for i, row in enumerate(p):
        live = row[row >= 0]
        if live.size == 0:
            raise ValueError(f"pairs[{i}] names no DOF (all six are -1): a pair needs at least one DOF")
        if np.unique(live).size != live.size:
            raise ValueError(f"pairs[{i}] names a DOF twice ({row.tolist()}): the six DOFs of a pair must differ")
    return np.ascontiguousarray(p)


@dataclass(frozen=True, eq=False)
class Interface:
    """A contact patch: node pairs with 2-D friction and a normal load from the motion.

    docs/model.md section 10. Every parameter is one number for all pairs or
    one number per pair.

    Parameters
    ----------
    kt : float or array_like
        Tangential stiffness of each pair, N/m (> 0).
    kn : float or array_like
        Normal stiffness of each pair, N/m (> 0).
    mu : float or array_like
        Friction coefficient of each pair (>= 0).
    preload : float or array_like
        Normal load of each pair at rest (g = 0), N (>= 0; a pair with no
        preload touches without load and opens as soon as g < 0).
    pairs : array_like of int, shape (npairs, 6)
        Per pair the DOFs ``a_t1, a_t2, a_n, b_t1, b_t2, b_n``
        (:data:`PAIR_COLUMNS`), -1 for a fixed side: u_k = x[a_tk] - x[b_tk],
        g = x[a_n] - x[b_n].

    Raises
    ------
    ValueError
        Naming the parameter (and the pair) and the allowed range.
    """

    kt: object
    kn: object
    mu: object
    preload: object
    pairs: object

    def __post_init__(self) -> None:
        pairs = _pairs(self.pairs)
        n = pairs.shape[0]
        object.__setattr__(self, "pairs", pairs)
        for name in PARAM_NAMES:
            object.__setattr__(self, name, _per_pair(name, getattr(self, name), n, name in ("kt", "kn")))
        fmax = float(np.max(self.mu * self.preload))
        if not fmax <= _HUGE:
            raise ValueError(f"mu x preload (slip force of a pair, N) must be at most {_HUGE:.6g}, got {fmax!r}")
        gmax = float(np.max(self.preload / self.kn))
        if not gmax <= _HUGE:
            raise ValueError(f"preload / kn (opening displacement of a pair, m) must be finite, got {gmax!r}")
        params = np.ascontiguousarray(np.stack([self.kt, self.kn, self.mu, self.preload], axis=1))
        object.__setattr__(self, "_params", params)

    @property
    def npairs(self) -> int:
        """Number of node pairs."""
        return self.pairs.shape[0]

    @property
    def params(self) -> np.ndarray:
        """float64 (npairs, 4): kt (N/m), kn (N/m), mu, preload (N) per pair, as the kernels take them."""
        return self._params

    @property
    def max_dof(self) -> int:
        """The largest DOF index named by the pairs (-1 if none)."""
        return int(self.pairs.max())

    def check_ndof(self, ndof: int, what: str = "interface") -> None:
        """ValueError naming the pair and column when a DOF index is not below ``ndof``."""
        bad = np.argwhere(self.pairs >= ndof)
        if bad.size:
            i, k = (int(v) for v in bad[0])
            raise ValueError(f"{what} pairs[{i}, {k}] ({PAIR_COLUMNS[k]}) must be in [-1, {ndof - 1}] "
                             f"(a DOF of the structure or -1), got {int(self.pairs[i, k])}")

    def relative(self, x) -> tuple[np.ndarray, np.ndarray]:
        """(u (npairs, 2), g (npairs,)) of the structure displacements ``x`` (m, length > max_dof)."""
        x = V.finite_array("x", x)
        self.check_ndof(x.size, "x: interface")
        u = np.empty((self.npairs, 2))
        g = np.empty(self.npairs)
        interface_gather(self.pairs, x, u, g)
        return u, g

    def forces(self, T, N, ndof: int) -> np.ndarray:
        """Generalised forces (ndof,) N that the pairs' forces T (npairs, 2) and loads N (npairs,) exert
        on the structure (see the module docstring for the signs)."""
        f = np.zeros(int(ndof))
        interface_scatter(self.pairs, np.ascontiguousarray(T, dtype=np.float64),
                          np.ascontiguousarray(N, dtype=np.float64), self.params, f)
        return f

    def selection(self, ndof: int) -> np.ndarray:
        """Dense selection B (3 npairs, ndof): rows ``3 i, 3 i + 1, 3 i + 2`` give u1, u2 and g of pair i
        (``(u1, u2, g) = B x``; the structure feels ``-B^T (T1, T2, N - P)``)."""
        self.check_ndof(int(ndof))
        B = np.zeros((3 * self.npairs, int(ndof)))
        for k, (a, b) in enumerate(((0, 3), (1, 4), (2, 5))):
            rows = 3 * np.arange(self.npairs) + k
            for col, sign in ((a, 1.0), (b, -1.0)):
                d = self.pairs[:, col]
                live = d >= 0
                np.add.at(B, (rows[live], d[live]), sign)
        return B

    def tangent(self, x, w, x0=None) -> tuple[np.ndarray, np.ndarray]:
        """Forces and exact stiffness of the interface at structure displacements ``x`` (m) from the
        committed sliders ``w`` (npairs, 2), m, the step starting from the structure displacements
        ``x0`` (m; None: from ``x`` itself, as :meth:`step`).

        Returns
        -------
        f : ndarray (ndof,)
            Generalised forces the pairs exert on the structure, N (:meth:`forces`).
        K : ndarray (ndof, ndof)
            Their stiffness ``-df/dx = B^T J B`` (N/m) with the 3 x 3 blocks J = d(T1, T2, N) /
            d(u1, u2, g) and B of :meth:`selection`: each pair couples only its own DOFs. With
            ``x0`` the blocks of :func:`interface_step_tangent` (start point and sliders fixed);
            without, the start moves with ``x`` (a step without motion: the radial return of
            the trial, whose derivative :func:`interface_step_jvp` gives). All pairs stuck: the
            springs kt, kt, kn between their DOFs; all open: 0.
        """
        u, g = self.relative(x)
        n = u.shape[0]
        w = self.check_state(w)
        T, N, J = np.empty((n, 2)), np.empty(n), np.empty((n, 3, 3))
        code, w_new = np.empty(n, dtype=np.int8), np.empty((n, 2))
        if x0 is not None:
            u0, g0 = self.relative(x0)
            interface_step_tangent(self.params, u0, g0, u, g, w, w_new, T, N, code, J)
        else:
            du = np.zeros((n, 2, 3))
            du[:, 0, 0] = du[:, 1, 1] = 1.0
            dg = np.zeros((n, 3))
            dg[:, 2] = 1.0
            dT, dN = np.empty((n, 2, 3)), np.empty((n, 3))
            interface_step_jvp(self.params, u, du, g, dg, u, du, g, dg, w, np.zeros((n, 2, 3)), w_new,
                               np.empty((n, 2, 3)), T, dT, N, dN, code)
            J[:, :2, :] = dT
            J[:, 2, :] = dN
        ndof = np.asarray(x).size
        B = self.selection(ndof)
        Jd = np.zeros((3 * n, 3 * n))
        for i in range(n):
            Jd[3 * i : 3 * i + 3, 3 * i : 3 * i + 3] = J[i]
        return self.forces(T, N, ndof), B.T @ Jd @ B

    def initial_state(self, u=None) -> np.ndarray:
        """Virgin sliders (npairs, 2), m: every pair unstretched at the relative displacements ``u``
        (default 0), so that a step there gives T = 0."""
        if u is None:
            return np.zeros((self.npairs, 2))
        return self.check_state(u).copy()

    def check_state(self, w) -> np.ndarray:
        """Sliders given by users (npairs, 2), validated (finite), as float64; ValueError naming ``state``."""
        try:
            a = np.array(w, dtype=np.float64)
        except (TypeError, ValueError):
            raise ValueError("state must be an array of real numbers (the sliders, m)") from None
        if a.shape != (self.npairs, 2):
            raise ValueError(f"state must have shape ({self.npairs}, 2) (one slider per pair, m), got {a.shape}")
        if not np.all(np.isfinite(a)):
            raise ValueError("state must be finite (the sliders, m)")
        return a

    def step(self, u, g, w, u0=None, g0=None):
        """One step of every pair from the committed sliders ``w`` (Python convenience over
        :func:`interface_step`).

        Parameters
        ----------
        u : array_like (npairs, 2)
            Relative tangential displacements at the end of the step, m.
        g : array_like (npairs,)
            Normal approaches at the end of the step, m.
        w : array_like (npairs, 2)
            Committed sliders, m.
        u0, g0 : array_like (npairs, 2), (npairs,), optional
            The step's start point (where the sliders ``w`` were committed), m; the path of the
            step is the straight line from (u0, g0) to (u, g). None (each separately): the step
            starts at (u, g) itself, a step without motion.

        Returns
        -------
        T : ndarray (npairs, 2)
            Tangential forces, N.
        N : ndarray (npairs,)
            Normal loads, N.
        code : ndarray of int8 (npairs,)
            Motion states (STICK_SLIP, MACROSLIP, SEPARATION).
        w_new : ndarray (npairs, 2)
            Trial sliders, m (commit by using them as the next ``w``).
        """
        u = np.ascontiguousarray(u, dtype=np.float64).reshape(self.npairs, 2)
        g = np.ascontiguousarray(g, dtype=np.float64).reshape(self.npairs)
        u0 = u if u0 is None else np.ascontiguousarray(u0, dtype=np.float64).reshape(self.npairs, 2)
        g0 = g if g0 is None else np.ascontiguousarray(g0, dtype=np.float64).reshape(self.npairs)
        w = self.check_state(w)
        T = np.empty((self.npairs, 2))
        N = np.empty(self.npairs)
        code = np.empty(self.npairs, dtype=np.int8)
        w_new = np.empty((self.npairs, 2))
        interface_step(self.params, u0, g0, u, g, w, w_new, T, N, code)
        return T, N, code, w_new
