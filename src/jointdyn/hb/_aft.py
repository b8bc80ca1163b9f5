"""Alternating frequency-time (AFT) evaluation of contact forces.

Harmonic coefficients of a periodic signal in normalised time tau = w t::

    u(tau) = U_0 + sum_{k=1}^{H} U_{2k-1} cos(k tau) + U_{2k} sin(k tau)

are sampled at ``tau_j = 2 pi j / Ns`` (``E @ U``), the contact law is
marched over the samples (over whole periods, repeatedly, until the force
repeats: a hysteretic law needs its periodic internal state), and the
force samples are projected back (``P @ T``; ``P @ E = I`` when
``Ns > 2 H``). Derivatives are carried forward through the same march with
the law's ``step_jvp`` kernel, so the Jacobian of the coefficients of the
force with respect to the coefficients of the displacement (and a scalar
parameter entering the normal load) is exact for the computed residual.

Nothing here knows the physics of a law: the kernels are called unchanged
through a compiled loop bound with :func:`jointdyn._jit.specialize`.
"""

from __future__ import annotations

import numpy as np

from .._jit import specialize

__all__ = ["fourier_matrices", "aft_contact"]


def fourier_matrices(harmonics: int, samples: int):
    """Synthesis ``E`` (Ns, 2H+1) and analysis ``P`` (2H+1, Ns) matrices.

    Columns of ``E`` are ``1, cos(tau), sin(tau), ..., cos(H tau), sin(H tau)``
    at ``tau_j = 2 pi j / Ns``; ``P`` is the discrete Fourier projection
    (trapezoidal rule), ``P @ E = I`` for ``Ns > 2H``.
    """
    tau = 2.0 * np.pi * np.arange(samples) / samples
    E = np.empty((samples, 2 * harmonics + 1))
    E[:, 0] = 1.0
    for k in range(1, harmonics + 1):
        E[:, 2 * k - 1] = np.cos(k * tau)
        E[:, 2 * k] = np.sin(k * tau)
    P = np.ascontiguousarray(E.T * (2.0 / samples))
    P[0] *= 0.5
    return E, P


def _aft_template(params, s0, ds0, E, P, U, N, dNp, has_p, max_passes, rtol, F, G, T, code, info):  # pragma: no cover - compiled
    """AFT of one contact: sample, march ``STEP_JVP`` until the force repeats, project.

    Directions: the 2H+1 coefficients of u (du_i = E[i, d]) and, when
    ``has_p``, one parameter entering the normal load (dN_i = dNp[i]).
    Stops when two consecutive passes agree to ``rtol * max|T|``, or when
    the committed state at the end of a pass equals (to ``rtol``, entry by
    entry) the one at the end of the previous pass, so that the next pass
    would repeat this one (period 1; saves a pass). If instead passes p and p-2 agree (the law's state alternates
    between two cycles: a period-2 force under a period-1 displacement),
    the force and its derivatives are the mean of the last two passes,
    which is the exact projection of the 2T-periodic force on the
    T-periodic harmonics. Outputs ``F = P T`` and ``G = P dT``;
    ``info = [passes, max |T_p - T_(p-1)| (0 when the end states
    repeated), period (1, 2; 0 if neither repeated within max_passes)]``.
    """
    ns = E.shape[0]
    nh = E.shape[1]
    nd = nh + (1 if has_p else 0)
    a = s0.copy()
    b = np.empty_like(s0)
    da = ds0.copy()
    db = np.empty_like(ds0)
    u = np.zeros(ns)
    for i in range(ns):
        acc = 0.0
        for h in range(nh):
            acc += E[i, h] * U[h]
        u[i] = acc
    dxj = np.zeros(nd)
    dNj = np.zeros(nd)
    dTj = np.empty(nd)
    dT = np.empty((ns, nd))
    T1 = np.zeros(ns)
    T2 = np.zeros(ns)
    dT1 = np.zeros((ns, nd))
    s_end = np.empty_like(s0)
    passes = 0
    err = np.inf
    period = 0.0
    while passes < max_passes:
        err = 0.0
        err2 = 0.0
        tmax = 0.0
        for i in range(ns):
            for d in range(nh):
                dxj[d] = E[i, d]
            if has_p:
                dNj[nh] = dNp[i]
            t_, k_, c_ = STEP_JVP(params, a, da, b, db, u[i], dxj, N[i], dNj, dTj)  # noqa: F821
            e = abs(t_ - T1[i])
            if e > err:
                err = e
            e = abs(t_ - T2[i])
            if e > err2:
                err2 = e
            if abs(t_) > tmax:
                tmax = abs(t_)
            T[i] = t_
            for d in range(nd):
                dT[i, d] = dTj[d]
            code[i] = c_
            a, b = b, a
            da, db = db, da
        passes += 1
        if passes >= 2 and err <= rtol * tmax:
            period = 1.0
            break
        if passes >= 2:
            # the committed state at the end of this pass equals the one at
            # the end of the previous pass: the next pass would repeat this
            # one exactly, so this pass is the periodic force already
            same = True
            for r in range(a.shape[0]):
                m = max(abs(a[r]), abs(s_end[r]))
                if abs(a[r] - s_end[r]) > rtol * m:
                    same = False
                    break
            if same:
                period = 1.0
                err = 0.0  # the next pass would repeat this one exactly
                break
        for r in range(a.shape[0]):
            s_end[r] = a[r]
        if passes >= 4 and err2 <= rtol * tmax:
            period = 2.0
            for i in range(ns):
                T[i] = 0.5 * (T[i] + T1[i])
                for d in range(nd):
                    dT[i, d] = 0.5 * (dT[i, d] + dT1[i, d])
            break
        for i in range(ns):
            T2[i] = T1[i]
            T1[i] = T[i]
            for d in range(nd):
                dT1[i, d] = dT[i, d]
    F[:] = np.dot(P, T)
    G[:, :] = np.dot(P, dT)
    info[0] = passes
    info[1] = err
    info[2] = period


def _aft_kernel(law):
    return specialize(_aft_template, STEP_JVP=law.step_jvp)


_DS0_CACHE: dict = {}


def _initial_state_jacobian(law, x0, n0, dx0, dn0):
    """Virgin state at (x0, n0) and its derivative along directions.

    The derivative is a central difference of ``law.initial_state`` (the
    virgin state is an affine function of x0 and n0 for every law of the
    contract: it stores the displacement and the load ratio), so the
    harmonic-balance code needs no knowledge of the state layout. It is
    computed once per law (and side of n0 = 0) and reused.
    """
    s0 = law.initial_state(x0, n0)
    key = (id(law), n0 > 0.0)
    hit = _DS0_CACHE.get(key)
    if hit is None or hit[0] is not law:
        hx = 1e-3 * (law.x_slip if np.isfinite(law.x_slip) and law.x_slip > 0 else 1.0)
        hn = 1e-3 * max(abs(n0), 1.0)
        sx = (law.initial_state(x0 + hx, n0) - law.initial_state(x0 - hx, n0)) / (2 * hx)
        sn = (law.initial_state(x0, n0 + hn) - law.initial_state(x0, n0 - hn)) / (2 * hn)
        if len(_DS0_CACHE) > 256:
            _DS0_CACHE.clear()
        hit = _DS0_CACHE[key] = (law, sx, sn)
    _, sx, sn = hit
    ds0 = sx[:, None] * dx0[None, :]
    if dn0.any():
        ds0 += sn[:, None] * dn0[None, :]
    return s0, ds0


_EMPTY = np.zeros(1)


def aft_contact(law, E, P, U, Nsamp, dNsamp=None, *, max_passes=8, rtol=1e-10, params=None, kernel=None):
    """Periodic force coefficients of one contact and their Jacobians.

    Parameters
    ----------
    law : ContactLaw
        The contact law (its kernels are called unchanged).
    E, P : ndarray
        From :func:`fourier_matrices`.
    U : ndarray (2H+1,)
        Coefficients of the relative displacement u(tau), m.
    Nsamp : ndarray (Ns,)
        Normal load at the samples, N.
    dNsamp : ndarray (Ns,), optional
        Derivative of the normal-load samples w.r.t. a scalar parameter;
        when given, one more direction is propagated.
    max_passes : int
        Bound on the number of periods marched (>= 2).
    rtol : float
        The periodic force is accepted when two consecutive passes differ
        by at most ``rtol * max|T|``.
    params : ndarray, optional
        ``law.params`` if already at hand (saves rebuilding it).
    kernel : dispatcher, optional
        The specialised march for ``law`` if already at hand.

    Returns
    -------
    F : ndarray (2H+1,)
        Coefficients of T(tau), N.
    dF_dU : ndarray (2H+1, 2H+1)
        dF/dU, N/m.
    dF_dp : ndarray (2H+1,) or None
        dF/dp (only with ``dNsamp``).
    T, code : ndarray
        Force samples (N) and motion-state codes of the last pass.
    info : ndarray
        ``[passes, last pass difference (N), period]``: period 1 (the force
        repeated), 2 (it alternated between two cycles; the mean of the two
        is used) or 0 (no repetition within ``max_passes``).
    """
    ns, nh = E.shape
    has_p = dNsamp is not None
    nd = nh + (1 if has_p else 0)
    # the virgin state is started at the mean displacement and the load of
    # the first sample: direction 0 (the constant term) moves the mean
    dx0 = np.zeros(nd)
    dx0[0] = 1.0
    dn0 = np.zeros(nd)
    if has_p:
        dNp = np.ascontiguousarray(dNsamp, dtype=np.float64)
        dn0[nh] = dNp[0]
    else:
        dNp = _EMPTY
    s0, ds0 = _initial_state_jacobian(law, float(U[0]), float(Nsamp[0]), dx0, dn0)
    F = np.empty(nh)
    G = np.empty((nh, nd))
    T = np.empty(ns)
    code = np.empty(ns, dtype=np.int64)
    info = np.zeros(3)
    fn = _aft_kernel(law) if kernel is None else kernel
    fn(law.params if params is None else params, s0, ds0, E, P, np.ascontiguousarray(U, dtype=np.float64),
       np.ascontiguousarray(Nsamp, dtype=np.float64), dNp, has_p, int(max_passes), float(rtol), F, G, T, code, info)
    dF_dp = G[:, nh] if has_p else None
    return F, G[:, :nh], dF_dp, T, code, info
