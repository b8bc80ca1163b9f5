"""AFT evaluation of the node pairs of interfaces (docs/model.md section 10), with exact Jacobians.

A sibling of :mod:`jointdyn.hb._aft` (which evaluates the scalar contacts):
systems without interfaces never call or compile anything here, so their
kernels, outputs and compile time are unchanged.

Per pair, the harmonic coefficients of its relative coordinates
``y = (u1, u2, g)`` are taken from the unknowns (``y_k = x[a_k] - x[b_k]``),
sampled (``E @ Y``), and the pairs are marched over the samples with
:func:`jointdyn.interfaces.interface_step_jvp`: the step to sample j starts
at sample j - 1 (the path between samples is the straight line the element
integrates exactly), the first step of a pass at the last sample of the
previous one. The first pass starts from the virgin pair at the mean point
``(U_0, G_0)`` (slider ``w = U_0``: no force at the mean displacement, as the
scalar laws restart there), or, for a structure held only through its
contacts (:attr:`jointdyn.hb.HBProblem.restart_at_reference`), at the
reference point ``(0, G_0)`` (slider ``w = 0``: the preloaded static state,
at rest without tangential force; the tangential rows of the mean point's
derivative are zero, :func:`pair_directions`); the march goes on, pass after pass, until the
slider and its derivative at the end of a pass equal (to ``rtol``) those at
the end of the previous one, or the force repeats (the periodic steady
slider). The derivatives are carried along the ``3 (2H+1)`` coefficients of
``(u1, u2, g)`` of the pair, through the slider, over every pass (the
mean point's derivative included), so the Jacobian is exact for the
computed residual.

The projected forces ``F_k = P T_k`` (k = 1, 2) and ``F_3 = P (N - P0)``
enter the residual as the reactions of the pairs (``+F`` on side A, ``-F``
on side B: the structure feels ``-T`` and ``-(N - P0)`` on side A) and their
Jacobian as the 3 x 3 blocks (per harmonic pair) of each pair, scattered on
its six DOFs only.
"""

from __future__ import annotations

import numpy as np

from .._jit import jit, specialize
from ..interfaces import interface_step_jvp
from ._aft import INFO_ERROR, INFO_PASSES, INFO_PERIOD, PERIOD_NONE, PERIOD_ONE

__all__ = ["pair_directions", "pairs_aft", "pairs_aft_kernel"]


def pair_directions(E: np.ndarray, at_reference: bool = False):
    """(DU, DG): derivatives of one pair's samples along the 3 nh coefficients of (u1, u2, g).

    ``DU`` (Ns + 1, 1, 2, 3 nh), ``DG`` (Ns + 1, 1, 3 nh): row j < Ns is
    sample j (``d u_k / d Y[k, h] = E[j, h]``), row Ns the start of the first
    pass: the mean point (``d / d Y[k, 0] = 1``), or with ``at_reference``
    the reference point, whose tangential displacements are 0 whatever the
    unknowns (``DU[Ns] = 0``; the normal gap stays at its mean). The entry
    ``DU[Ns, 0, k, k nh]`` (1 or 0) is also the weight of the mean in the
    start of the slider (:func:`pairs_aft`: ``w = DU[Ns, 0, k, k nh] U_0``),
    so that the choice is data of the problem. Built once per problem.
    """
    ns, nh = E.shape
    nd = 3 * nh
    DU = np.zeros((ns + 1, 1, 2, nd))
    DG = np.zeros((ns + 1, 1, nd))
    for k in range(2):
        DU[:ns, 0, k, k * nh:(k + 1) * nh] = E
        DU[ns, 0, k, k * nh] = 0.0 if at_reference else 1.0
    DG[:ns, 0, 2 * nh:] = E
    DG[ns, 0, 2 * nh] = 1.0
    return DU, DG


@jit(inline="always")
def _pair_coefficients(pairs, i, X, n, Y):  # pragma: no cover - compiled
    """Y[k, h] = X[h n + a_k] - X[h n + b_k] (k = u1, u2, g; -1: a fixed side)."""
    nh = Y.shape[1]
    for k in range(3):
        ia = pairs[i, k]
        ib = pairs[i, k + 3]
        for h in range(nh):
            v = 0.0
            if ia >= 0:
                v += X[h * n + ia]
            if ib >= 0:
                v -= X[h * n + ib]
            Y[k, h] = v


@jit(inline="always")
def _pair_samples(E, Y, Us, Gs, DU):  # pragma: no cover - compiled
    """Samples of (u1, u2, g) into Us[j, 0], Gs[j, 0] (j < Ns) and the start point into row Ns: the mean
    point, its tangential components weighted by ``DU[Ns, 0, k, k nh]`` (1: the mean; 0: the reference 0)."""
    ns, nh = E.shape
    for j in range(ns):
        for k in range(3):
            acc = 0.0
            for h in range(nh):
                acc += E[j, h] * Y[k, h]
            if k < 2:
                Us[j, 0, k] = acc
            else:
                Gs[j, 0] = acc
    Us[ns, 0, 0] = Y[0, 0] * DU[ns, 0, 0, 0]
    Us[ns, 0, 1] = Y[1, 0] * DU[ns, 0, 1, nh]
    Gs[ns, 0] = Y[2, 0]


@jit(inline="always")
def _same(a, da, s, ds, rtol):  # pragma: no cover - compiled
    """True if (a, da) equal (s, ds) to ``rtol`` relative, entry by entry (False on NaN)."""
    for k in range(2):
        if not abs(a[0, k] - s[0, k]) <= rtol * max(abs(a[0, k]), abs(s[0, k])):
            return False
        for d in range(da.shape[2]):
            x = da[0, k, d]
            y = ds[0, k, d]
            if not abs(x - y) <= rtol * max(abs(x), abs(y)):
                return False
    return True


@jit(inline="always")
def _project(P0, P, Tb, dTb, Nb, dNb, F, G):  # pragma: no cover - compiled
    """F = P (T1, T2, N - P0) (3, nh) and G = P d(.)/dY (3 nh, 3 nh): the pair's projected forces and
    their exact Jacobian along its own coefficients."""
    nh, ns = P.shape
    nd = G.shape[1]
    for h in range(nh):
        f1 = 0.0
        f2 = 0.0
        f3 = 0.0
        for j in range(ns):
            p = P[h, j]
            f1 += p * Tb[j, 0, 0]
            f2 += p * Tb[j, 0, 1]
            f3 += p * (Nb[j, 0] - P0)
        F[0, h] = f1
        F[1, h] = f2
        F[2, h] = f3
        for d in range(nd):
            g1 = 0.0
            g2 = 0.0
            g3 = 0.0
            for j in range(ns):
                p = P[h, j]
                g1 += p * dTb[j, 0, 0, d]
                g2 += p * dTb[j, 0, 1, d]
                g3 += p * dNb[j, 0, d]
            G[h, d] = g1
            G[nh + h, d] = g2
            G[2 * nh + h, d] = g3


@jit(inline="always")
def _scatter(pairs, i, n, F, G, R, JX, jx):  # pragma: no cover - compiled
    """R += +-F on the pair's DOFs, and JX += +-G there when ``jx`` (else the caller keeps G)."""
    nh = F.shape[1]
    for k in range(3):
        for sr in range(2):
            r = pairs[i, k + 3 * sr]
            if r < 0:
                continue
            sgr = 1.0 - 2.0 * sr
            for h in range(nh):
                R[h * n + r] += sgr * F[k, h]
                if not jx:
                    continue
                for m in range(3):
                    for sc in range(2):
                        c = pairs[i, m + 3 * sc]
                        if c < 0:
                            continue
                        sg = sgr * (1.0 - 2.0 * sc)
                        for g in range(nh):
                            JX[h * n + r, g * n + c] += sg * G[k * nh + h, m * nh + g]


def pairs_aft(pairs, params, X, n, E, P, DU, DG, max_passes, rtol, R, JX, Gout, T, N, code, info):  # pragma: no cover
    """Add the reactions of every pair and their exact Jacobian to R and JX (see the module docstring).

    A template: :func:`pairs_aft_kernel` compiles it with the pair's step bound as ``PAIR_STEP_JVP``,
    so that its disk cache follows the source of :mod:`jointdyn.interfaces` (a direct call would keep a
    stale cache after the element changes).

    Parameters
    ----------
    pairs : int64 (np, 6)
        Positions among the unknown DOFs of ``a_t1, a_t2, a_n, b_t1, b_t2, b_n`` (-1: fixed).
    params : float64 (np, 4)
        kt, kn, mu, P per pair (:attr:`jointdyn.interfaces.Interface.params`).
    X : float64 (n nh,)
        Unknown coefficients, harmonic-major (``X[h n + i]``), m.
    E, P : synthesis (Ns, nh) and analysis (nh, Ns) matrices.
    DU, DG : :func:`pair_directions` of E.
    max_passes, rtol : bound on the marched periods and the periodicity tolerance.
    R, JX : residual (N) and Jacobian (N/m), added to (JX only when ``Gout`` is empty).
    Gout : float64 (np, 3 nh, 3 nh) or (0, 0, 0)
        When not empty, each pair's Jacobian G (N/m) of its projected forces
        ``(F1, F2, F3)`` (rows ``k nh + h``) along its coefficients of
        ``(u1, u2, g)`` (columns ``m nh + g``), instead of the scatter into JX
        (:meth:`jointdyn.hb.HBProblem.evaluate` with a sparse Jacobian).
    T, N, code : outputs (np, Ns, 2), (np, Ns), (np, Ns): forces, loads and states of the last pass.
    info : float64 (3,), updated with the worst case over the pairs (``INFO_*`` of ``_aft``).
    """
    ns, nh = E.shape
    nd = 3 * nh
    Y = np.empty((3, nh))
    Us = np.empty((ns + 1, 1, 2))
    Gs = np.empty((ns + 1, 1))
    a = np.empty((1, 2))
    b = np.empty((1, 2))
    da = np.empty((1, 2, nd))
    db = np.empty((1, 2, nd))
    s = np.empty((1, 2))
    ds = np.empty((1, 2, nd))
    Tb = np.empty((ns, 1, 2))
    dTb = np.empty((ns, 1, 2, nd))
    Nb = np.empty((ns, 1))
    dNb = np.empty((ns, 1, nd))
    cb = np.empty((ns, 1), dtype=code.dtype)
    Tp = np.empty((ns, 2))
    F = np.empty((3, nh))
    G = np.empty((nd, nd))
    prm = np.empty((1, 4))
    for i in range(pairs.shape[0]):
        for k in range(4):
            prm[0, k] = params[i, k]
        _pair_coefficients(pairs, i, X, n, Y)
        _pair_samples(E, Y, Us, Gs, DU)
        # the virgin pair at the start point: slider at the mean displacement (or at the reference 0)
        a[0, 0] = Us[ns, 0, 0]
        a[0, 1] = Us[ns, 0, 1]
        for k in range(2):
            for d in range(nd):
                da[0, k, d] = DU[ns, 0, k, d]
        passes = 0
        err = np.inf
        period = PERIOD_NONE
        while passes < max_passes:
            err = 0.0
            tmax = 0.0
            for j in range(ns):
                q = j - 1 if j > 0 else (ns if passes == 0 else ns - 1)
                PAIR_STEP_JVP(prm, Us[q], DU[q], Gs[q], DG[q], Us[j], DU[j], Gs[j], DG[j], a, da, b, db,  # noqa: F821
                              Tb[j], dTb[j], Nb[j], dNb[j], cb[j])
                a, b = b, a
                da, db = db, da
                for k in range(2):
                    t_ = Tb[j, 0, k]
                    if passes > 0 and abs(t_ - Tp[j, k]) > err:
                        err = abs(t_ - Tp[j, k])
                    if abs(t_) > tmax:
                        tmax = abs(t_)
                    Tp[j, k] = t_
            passes += 1
            if passes >= 2 and _same(a, da, s, ds, rtol):
                # the next pass would start from the state this one started from: it repeats this one
                period, err = PERIOD_ONE, 0.0
                break
            if passes >= 2 and err <= rtol * tmax:
                period = PERIOD_ONE
                break
            s[:, :] = a
            ds[:, :, :] = da
        _project(prm[0, 3], P, Tb, dTb, Nb, dNb, F, G)
        keep = Gout.shape[0] > 0
        _scatter(pairs, i, n, F, G, R, JX, not keep)
        if keep:
            for r in range(nd):
                for c in range(nd):
                    Gout[i, r, c] = G[r, c]
        for j in range(ns):
            T[i, j, 0] = Tb[j, 0, 0]
            T[i, j, 1] = Tb[j, 0, 1]
            N[i, j] = Nb[j, 0]
            code[i, j] = cb[j, 0]
        if passes > info[INFO_PASSES]:
            info[INFO_PASSES] = passes
        if err > info[INFO_ERROR]:
            info[INFO_ERROR] = err
        if period == PERIOD_NONE:
            info[INFO_PERIOD] = PERIOD_NONE


def pairs_aft_kernel():
    """:func:`pairs_aft` compiled with :func:`jointdyn.interfaces.interface_step_jvp` bound as its pair step
    (memoised; disk-cached under a name that carries the hash of the element's source)."""
    return specialize(pairs_aft, PAIR_STEP_JVP=interface_step_jvp)
