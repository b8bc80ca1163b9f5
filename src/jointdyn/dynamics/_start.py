"""Starting states of :func:`~jointdyn.dynamics.steady_state`.

* the equivalent-linearisation estimate (describing function of each
  contact law, marched over the harmonic displacement of the estimate);
* law states rebuilt from one period alone (forgetting a transient's memory)
  before shooting.

Both march a law over a history with the compiled march of
:mod:`jointdyn.drivers` (:func:`~jointdyn.drivers._march.law_marcher`).
"""

from __future__ import annotations

import math

import numpy as np

from .. import config
from .._jit import jit, specialize
from ..drivers import march
from ..drivers._march import law_marcher
from ..kinematics import load_table, tangential_history

__all__ = ["linear_start", "clean_states"]


@jit(inline="always")
def _df_solve(Z0, f, B, kc, X, have, rtol, xmax):  # pragma: no cover - compiled
    """One solve of (Z0 + sum_c B_c k_c B_c^T) X = f into X.

    Returns (ok, converged): ok False when X is non-finite or larger than
    ``xmax`` (m); converged when X changed by at most ``rtol`` of its size
    since the last solve (``have``: there was one).
    """
    n = f.shape[0]
    Z = np.zeros((n, n), dtype=np.complex128)
    for a in range(n):
        for b in range(n):
            Z[a, b] = Z0[a, b]
    for i in range(B.shape[0]):
        for a in range(n):
            for b in range(n):
                Z[a, b] += B[i, a] * kc[i] * B[i, b]
    Xn = np.linalg.solve(Z, f)
    big = 0.0
    diff = 0.0
    for a in range(n):
        if not (np.isfinite(Xn[a].real) and np.isfinite(Xn[a].imag)):
            return False, False
        big = max(big, abs(Xn[a]))
        diff = max(diff, abs(Xn[a] - X[a]))
    if big > xmax:
        return False, False
    conv = have and diff <= rtol * big
    for a in range(n):
        X[a] = Xn[a]
    return True, conv


@jit(inline="always")
def _df_march(init, marcher, params, U, cycle, Nrow, u, T, kT, code, s0, sf):  # pragma: no cover - compiled
    """March a law over u = Im(U e^{i theta}) on the samples of ``cycle`` from
    its virgin state; returns the first-harmonic sums (sum T sin, sum T cos)
    over the second cycle. ``sf`` receives the final state."""
    sin_th, cos_th, ns = cycle[0], cycle[1], cycle[2]
    ur = U.real
    ui = U.imag
    for j in range(sin_th.shape[0]):
        u[j] = ur * sin_th[j] + ui * cos_th[j]
    init(params, u[0], Nrow[0], s0)
    marcher(params, s0, u, Nrow, T, kT, code, sf)
    ca = 0.0
    cb = 0.0
    for j in range(ns, 2 * ns):
        ca += T[j] * sin_th[j]
        cb += T[j] * cos_th[j]
    return ca, cb


def _df_template(lin, contacts, cycle, opts, out):  # pragma: no cover - compiled
    """Describing-function iteration of :func:`linear_start`, compiled (``INIT``, ``MARCH`` bound).

    ``lin = (Z0, f)``: dynamic stiffness without contacts (N/m) and forcing
    (N); ``contacts = (B, kt, P)``: selection rows, stuck stiffnesses (N/m),
    law parameters; ``cycle = (sin theta, cos theta, ns, N)``: the samples
    (two cycles of ns, then theta = 0) and the normal loads per contact;
    ``opts = (iterations, rtol, xmax m)``; ``out = (S, X)``. Returns False
    if the iteration diverges (non-finite or absurdly large X); else writes
    X (complex amplitudes, m) and the law states after the two-cycle march
    of the final estimate. ``np.linalg.solve`` raises ``LinAlgError`` for a
    singular dynamic stiffness.
    """
    Z0, f = lin
    B, kt, P = contacts
    loads = cycle[3]
    iters, rtol, xmax = opts
    S_out, X_out = out
    n, nc, L = f.shape[0], B.shape[0], loads.shape[1]
    kc = np.zeros(nc, dtype=np.complex128)
    for i in range(nc):
        kc[i] = kt[i]
    X = np.zeros(n, dtype=np.complex128)
    U = np.zeros(nc, dtype=np.complex128)
    u, T, kT, code = np.zeros(L), np.zeros(L), np.zeros(L), np.zeros(L, dtype=np.int8)
    s0, sf = np.zeros(S_out.shape[1]), np.zeros(S_out.shape[1])
    have = False
    final = False
    it = 0
    while True:
        if not final:
            ok, conv = _df_solve(Z0, f, B, kc, X, have, rtol, xmax)
            if not ok:
                return False
            have = True
            it += 1
            final = conv or it >= iters
        for i in range(nc):
            acc = 0.0 + 0.0j
            for a in range(n):
                acc += B[i, a] * X[a]
            U[i] = acc
        for i in range(nc):
            if U[i] == 0 and not final:
                continue
            ca, cb = _df_march(INIT, MARCH, P[i], U[i], cycle, loads[i], u, T, kT, code, s0, sf)  # noqa: F821
            if final:
                S_out[i, :] = sf
            else:
                kc[i] = 0.5 * kc[i] + 0.5 * (2.0 / cycle[2]) * (ca + 1j * cb) / U[i]
        if final:
            break
    X_out[:] = X
    return True


# the describing-function march: two cycles of 64 samples ending before t = 0
# (theta = w t), and t = 0 itself; the first harmonic is taken over the second
_DF_NS = 64
_DF_TH = np.append(2 * math.pi * np.arange(2 * _DF_NS) / _DF_NS - 4 * math.pi, 0.0)
_DF_GRID = (_DF_NS, _DF_TH, np.sin(_DF_TH), np.cos(_DF_TH))


def linear_start(model):
    """Equivalent-linearisation estimate of the periodic state at phase 0.

    Solves (K + Kn - w^2 M + i w C + sum_c k_c B_c B_c^T) X = f e^{i phi}
    (Kn: the normal springs closed, phi: the forcing phases) with k_c the
    describing function (first harmonic of T over one cycle of
    u = Im(U e^{i w t}) with the prescribed N_c(t), a spring contact at its
    preload, marched with the real law),
    started from the stuck stiffness kt and iterated with relaxation 1/2
    until X changes by less than ``config.SS_LINEAR_RTOL`` (at most
    ``config.SS_LINEAR_ITERS`` solves). The iteration is one compiled call
    (``_df_template``). Returns x, v (m, m/s) and law states at t = 0 (law
    marched over the last two cycles of the estimate), or None if the
    iteration diverges.
    """
    pk = model.pack
    w = model.w
    Z0 = pk.K_closed - w * w * pk.M + 1j * w * pk.C
    f = pk.fsin + 1j * pk.fcos
    ns, th, sin_th, cos_th = _DF_GRID
    loads = load_table(pk.kin.arrays, th, 1.0).T.copy()
    S = np.zeros((pk.ncontacts, pk.slen))
    X = np.zeros(pk.ndof, dtype=np.complex128)
    run = specialize(_df_template, INIT=pk.init, MARCH=law_marcher(pk.step))
    xscale = pk.fmax / pk.kmin + pk.xlin
    opts = (config.SS_LINEAR_ITERS if pk.ncontacts else 1, config.SS_LINEAR_RTOL, 1e3 * xscale)
    try:
        ok = run((Z0, f), (pk.B, pk.kt, pk.P), (sin_th, cos_th, ns, loads), opts, (S, X))
    except np.linalg.LinAlgError:
        return None
    if not ok:
        return None
    return np.imag(X).copy(), w * np.real(X).copy(), S


def clean_states(model, x, v, S, rdof, count):
    """One recorded period, then law states rebuilt from that period alone.

    A slowly decaying transient leaves a long nested sequence of reversal
    points in a Masing law's memory, which makes the state at a period
    boundary differ from period to period even once (x, v) repeat. The law
    is re-marched (drivers.march) from its virgin state over two repetitions
    of the last period's contact displacement and normal load, which keeps
    the current loop and forgets the transient. Returns (x, v, S) at the
    end of the period, or None on a blow-up. ``count(result)`` books the
    period.
    """
    x = x.copy()
    v = v.copy()
    S = S.copy()
    res = model.run_periods(x, v, S, 1, rec=True, rdof=rdof)
    count(res)
    if not res.status.ok or res.done < 1:
        return None
    _, X, _, _, N, _ = res.samples
    U = tangential_history(model.pack.kin.arrays, X)
    Snew = np.zeros_like(S)
    for i, law in enumerate(model.pack.laws):
        uu = np.concatenate([U[:, i], U[1:, i]])
        NN = np.concatenate([N[:, i], N[1:, i]])
        s0 = law.initial_state(float(uu[0]), float(NN[0]))
        sf = march(law, uu, NN, state=s0)[3]
        Snew[i, : sf.size] = sf
    return x, v, np.ascontiguousarray(Snew)
