"""Starting states of :func:`~jointdyn.dynamics.steady_state`.

* the equivalent-linearisation estimate (describing function of each
  contact law, marched over the harmonic displacement of the estimate);
* law states rebuilt from one period alone (forgetting a transient's memory)
  before shooting;
* the rigid-body part of a free-free structure's start set to the periodic
  motion of the free body (:func:`free_body_start`).

Both march a law over a history with the compiled march of
:mod:`jointdyn.drivers` (:func:`~jointdyn.drivers._march.law_marcher`).
"""

from __future__ import annotations

import math

import numpy as np

from .._jit import jit, specialize
from ..drivers import march
from ..drivers._march import law_marcher
from ..kinematics import load_table, tangential_history

__all__ = ["linear_start", "clean_states", "free_body_start"]


@jit
def _df_matrix(Z0, B, kc):  # pragma: no cover - compiled
    """Z0 + sum_c B_c k_c B_c^T (N/m): the dynamic stiffness with the contacts' describing functions."""
    n = Z0.shape[0]
    Z = np.zeros((n, n), dtype=np.complex128)
    for a in range(n):
        for b in range(n):
            Z[a, b] = Z0[a, b]
    for i in range(B.shape[0]):
        for a in range(n):
            for b in range(n):
                Z[a, b] += B[i, a] * kc[i] * B[i, b]
    return Z


def _df_solve(Z, f):
    """Z^-1 f by LAPACK ``zgesv`` (what ``np.linalg.solve`` calls); None when Z
    is not finite or singular. Called from Python: compiled, the solve costs
    every process seconds of compilation for a few small solves."""
    from scipy.linalg import lapack

    if not np.all(np.isfinite(Z)):
        return None
    _, _, Xn, info = lapack.zgesv(Z, f)
    return None if info != 0 else Xn


@jit
def _df_accept(Xn, X, have, rtol, xmax):  # pragma: no cover - compiled
    """Accept the solve Xn (m) into X.

    Returns (ok, converged): ok False when Xn is non-finite or larger than
    ``xmax`` (m); converged when X changed by at most ``rtol`` of its size
    since the last solve (``have``: there was one).
    """
    n = Xn.shape[0]
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


def _df_template(contacts, cycle, X, kc, final, S_out):  # pragma: no cover - compiled
    """One update of the describing-function iteration of :func:`linear_start`, compiled (``INIT``, ``MARCH`` bound).

    ``contacts = (B, P)``: selection rows and law parameters; ``cycle =
    (sin theta, cos theta, ns, N)``: the samples (two cycles of ns, then
    theta = 0) and the normal loads per contact; ``X``: the current
    estimate (complex amplitudes, m). Each contact's law is marched over
    its displacement u = Im(U e^{i theta}), U = B_c X, from its virgin
    state: unless ``final``, its describing function ``kc[c]`` (N/m) is
    relaxed by 1/2 towards the first harmonic of the force over the second
    cycle (a contact at rest keeps it); when ``final``, ``S_out[c]`` gets
    the law state at the end of the march.
    """
    B, P = contacts
    loads = cycle[3]
    n, nc, L = X.shape[0], B.shape[0], loads.shape[1]
    u, T, kT, code = np.zeros(L), np.zeros(L), np.zeros(L), np.zeros(L, dtype=np.int8)
    s0, sf = np.zeros(S_out.shape[1]), np.zeros(S_out.shape[1])
    for i in range(nc):
        U = 0.0 + 0.0j
        for a in range(n):
            U += B[i, a] * X[a]
        if U == 0 and not final:
            continue
        ca, cb = _df_march(INIT, MARCH, P[i], U, cycle, loads[i], u, T, kT, code, s0, sf)  # noqa: F821
        if final:
            for r in range(sf.shape[0]):  # not a slice assignment: see drivers._march
                S_out[i, r] = sf[r]
        else:
            kc[i] = 0.5 * kc[i] + 0.5 * (2.0 / cycle[2]) * (ca + 1j * cb) / U


# the describing-function march: two cycles of 64 samples ending before t = 0
# (theta = w t), and t = 0 itself; the first harmonic is taken over the second
_DF_NS = 64
_DF_TH = np.append(2 * math.pi * np.arange(2 * _DF_NS) / _DF_NS - 4 * math.pi, 0.0)
_DF_GRID = (_DF_NS, _DF_TH, np.sin(_DF_TH), np.cos(_DF_TH))


def linear_start(model, iters: int, rtol: float):
    """Equivalent-linearisation estimate of the periodic state at phase 0.

    Solves (K + Kn - w^2 M + i w C + sum_c k_c B_c B_c^T) X = f e^{i phi}
    (Kn: the normal springs closed, phi: the forcing phases) with k_c the
    describing function (first harmonic of T over one cycle of
    u = Im(U e^{i w t}) with the prescribed N_c(t), a spring contact at its
    preload, marched with the real law),
    started from the stuck stiffness kt and iterated with relaxation 1/2
    until X changes by less than ``rtol``, relative (at most ``iters``
    solves; ``SteadyStateOptions.linear_rtol`` and ``linear_iters``). Each iteration is a LAPACK solve
    (:func:`_df_solve`) and one compiled call marching every contact
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
    S = np.zeros((pk.state_rows, pk.slen))  # interface pairs: sliders at 0, stuck as K_closed has them
    X = np.zeros(pk.ndof, dtype=np.complex128)
    run = specialize(_df_template, INIT=pk.init, MARCH=law_marcher(pk.step))
    xmax = 1e3 * (pk.fmax / pk.kmin + pk.xlin)
    iters = iters if pk.ncontacts else 1
    kc = pk.kt.astype(np.complex128)
    have, final, it = False, False, 0
    while True:
        if not final:
            Xn = _df_solve(_df_matrix(Z0, pk.B, kc), f)
            if Xn is None:
                return None
            ok, conv = _df_accept(Xn, X, have, rtol, xmax)
            if not ok:
                return None
            have, it = True, it + 1
            final = conv or it >= iters
        run((pk.B, pk.P), (sin_th, cos_th, ns, loads), X, kc, final, S)
        if final:
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
    Snew[model.nc:] = S[model.nc:]  # a pair's slider is its whole memory: kept
    for i, law in enumerate(model.pack.laws):
        uu = np.concatenate([U[:, i], U[1:, i]])
        NN = np.concatenate([N[:, i], N[1:, i]])
        s0 = law.initial_state(float(uu[0]), float(NN[0]))
        sf = march(law, uu, NN, state=s0)[3]
        Snew[i, : sf.size] = sf
    return x, v, np.ascontiguousarray(Snew)


def free_body_start(model, x, v):
    """(x, v) with their rigid-body part replaced by the periodic motion of the free body at t = 0.

    A free-free structure (rigid-body modes Phi_r of the stuck structure, M-orthonormal:
    :func:`jointdyn.systems.free_modes`) feels no force of K, of the contacts or of the pairs along Phi_r;
    its rigid-body coordinates q = Phi_r^T M x obey q'' + Phi_r^T C Phi_r q' = Phi_r^T F(t). Started at rest,
    the forcing f sin(w t + phi) gives them a mean velocity (f cos(phi) / w for a free mass) and the body
    drifts for ever. Their periodic motion q = Im(Q e^{i w t}),
    (-w^2 + i w Phi_r^T C Phi_r) Q = Phi_r^T f e^{i phi}, has a zero mean position and momentum; its state
    at t = 0, (Im Q, w Re Q), replaces the rigid-body part Phi_r Phi_r^T M (x, v) of the start (the
    contacts cannot see it: b^T Phi_r = 0), the elastic part is kept. Exact when C does not couple the
    rigid-body modes to the elastic ones (C Phi_r = 0: stiffness-proportional or modal damping; a
    mass-proportional part damps the rigid-body motion, and any drift then decays). ``(x, v)`` themselves
    for a structure held in place or sampled loads (w = 0)."""
    from ..systems import free_modes

    phi = free_modes(model.system)
    r, w = phi.shape[1], float(model.w)
    if r == 0 or not w > 0.0:
        return x, v
    pk = model.pack
    Cr = phi.T @ pk.C @ phi
    Q = np.linalg.solve(-w * w * np.eye(r) + 1j * w * Cr, phi.T @ (pk.fsin + 1j * pk.fcos))
    x = x - phi @ (phi.T @ (pk.M @ x)) + phi @ Q.imag
    v = v - phi @ (phi.T @ (pk.M @ v)) + phi @ (w * Q.real)
    return x, v
