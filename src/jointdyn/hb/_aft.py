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

The whole harmonic-balance evaluation (linear part, AFT of every contact,
scatter into the residual and its Jacobians) is one compiled call per
residual evaluation (:func:`_eval_template`), so Newton and continuation
pay no Python per contact or per harmonic.

Nothing here knows the physics of a law: the kernels are called unchanged
through a compiled loop bound with :func:`jointdyn._jit.specialize`.
"""

from __future__ import annotations

import numpy as np

from .._jit import jit, specialize

__all__ = ["fourier_matrices"]


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


_FOURIER: dict = {}


def _fourier_shared(harmonics: int, samples: int):
    """:func:`fourier_matrices`, built once per (H, Ns) and shared (callers must not write to them)."""
    key = (int(harmonics), int(samples))
    hit = _FOURIER.get(key)
    if hit is None:
        if len(_FOURIER) > 64:
            _FOURIER.clear()
        hit = _FOURIER[key] = fourier_matrices(*key)
    return hit


def _eval_template(AK, AC, AM, w, dwdp, X, Fe, Fp, Bm, Pm, ssz, SX, SN, E, P, Nsamp, dN, has_p, max_passes, rtol,
                   R, JX, Jp, T, code, info, scl, Rs, JXs, Jps):  # pragma: no cover - compiled
    """Whole HB residual and Jacobian in one call: linear part + AFT of every contact.

    Linear part (``problem.py``): ``A = AK + w AC + w^2 AM``, ``R = A X - Fe``,
    ``JX = A``, ``Jp = dwdp (AC + 2 w AM) X - Fp``. Then, per contact c
    (selection row ``Bm[c]``, kernel parameters ``Pm[c]``, virgin state
    (law kernel ``INIT``, padded to ``ssz`` entries) at the mean displacement
    and the first load sample, with derivatives ``SX[c]`` per unit mean
    displacement and ``SN[c]`` per unit load): ``U = Xm Bm[c]``, AFT march of ``STEP_JVP``
    until the force repeats, projection, and scatter ``R += b F``,
    ``JX += b b^T dF/dU``, ``Jp += b dF/dp``.

    AFT directions: the 2H+1 coefficients of u (du_i = E[i, d]) and, when
    ``has_p``, one parameter entering the normal load (dN_i = dN[c, i]).
    The march stops when two consecutive passes agree to ``rtol * max|T|``,
    or when the committed state at the end of a pass equals (to ``rtol``,
    entry by entry) the one at the end of the previous pass, so that the
    next pass would repeat this one (period 1; saves a pass). If instead
    passes p and p-2 agree (the law's state alternates between two cycles:
    a period-2 force under a period-1 displacement), the force and its
    derivatives are the mean of the last two passes, which is the exact
    projection of the 2T-periodic force on the T-periodic harmonics.
    For laws with small states (at most ``_HIST_MAX_STATE`` entries) the
    first pass's committed states and derivatives are kept at every
    sample; once the second pass reaches, at some sample, the same state
    and derivatives (to ``rtol``, entry by entry, the criterion of the
    end-of-pass test), the rest of the pass would repeat the first one
    and is copied from it instead of marched (saves most of the second
    pass: the result agrees with the full march to rounding).
    ``T[c]``, ``code[c]``: force samples and motion codes of the last
    pass; ``info = [max passes, max |T_p - T_(p-1)| (0 when the end states
    repeated), worst period (1, 2; 0 if a force did not repeat within
    max_passes)]`` over the contacts. When ``scl[0] > 0`` the scaled copies
    ``Rs = R / scl[0]``, ``JXs = JX * scl[1]``, ``Jps = Jp * scl[2]`` are
    written too (the continuation's unknowns and residual in units of
    order one).
    """
    size = X.shape[0]
    n = Bm.shape[1]
    nc = Bm.shape[0]
    ns = E.shape[0]
    nh = E.shape[1]
    nd = nh + (1 if has_p else 0)
    w2 = w * w
    w2x = 2.0 * w
    for i in range(size):
        r = 0.0
        jp = 0.0
        for j in range(size):
            a = AK[i, j] + w * AC[i, j] + w2 * AM[i, j]
            JX[i, j] = a
            r += a * X[j]
            jp += (AC[i, j] + w2x * AM[i, j]) * X[j]
        R[i] = r - Fe[i]
        Jp[i] = jp * dwdp - Fp[i]
    info[0] = 0.0
    info[1] = 0.0
    info[2] = 1.0
    if nc == 0:
        _scale_outputs(R, JX, Jp, scl, Rs, JXs, Jps)
        return
    # directions of a sample: dx = E[i] (and 0 for the parameter), dN = dN[c, i]
    # on the parameter direction; copied into fixed buffers (cheaper than views)
    dxj = np.zeros(nd)
    dNj = np.zeros(nd)
    dTj = np.empty(nd)
    U = np.empty(nh)
    u = np.empty(ns)
    F = np.empty(nh)
    G = np.empty((nh, nd))
    s_end = np.empty(ssz)
    Tc = np.empty(ns)
    dT = np.empty((ns, nd))
    T1 = np.empty(ns)
    T2 = np.empty(ns)
    dT1 = np.empty((ns, nd))
    # committed states of the first pass at every sample (small states only):
    # the second pass (usually the last) stops marching once they repeat
    hist = ssz <= _HIST_MAX_STATE
    Sh = np.empty((ns if hist else 0, ssz))
    dSh = np.empty((ns if hist else 0, ssz, nd))
    cprev = np.empty(ns, dtype=code.dtype)
    for c in range(nc):
        for h in range(nh):
            acc = 0.0
            for i in range(n):
                acc += X[h * n + i] * Bm[c, i]
            U[h] = acc
        for i in range(ns):
            acc = 0.0
            for h in range(nh):
                acc += E[i, h] * U[h]
            u[i] = acc
        # virgin state at the mean displacement and the first load sample:
        # direction 0 (the constant term) moves the mean, the parameter the load
        Nc = Nsamp[c]
        prm = Pm[c]
        a = np.empty(ssz)
        INIT(prm, U[0], Nc[0], a)  # noqa: F821 - bound by specialize
        bb = np.empty(ssz)
        da = np.zeros((ssz, nd))
        dbb = np.empty((ssz, nd))
        for r_ in range(ssz):
            da[r_, 0] = SX[c, r_]
            if has_p:
                da[r_, nh] = SN[c, r_] * dN[c, 0]
        for i in range(ns):
            T1[i] = 0.0
            T2[i] = 0.0
        passes = 0
        err = np.inf
        period = 0.0
        while passes < max_passes:
            err = 0.0
            err2 = 0.0
            tmax = 0.0
            # committed state in (a, da) when cur == 0, in (bb, dbb) when cur == 1:
            # the kernel writes the other pair; no array variables are
            # reassigned per sample (that costs reference counting)
            cur = 0
            for i in range(ns):
                for d in range(nh):
                    dxj[d] = E[i, d]
                if has_p:
                    dNj[nh] = dN[c, i]
                if cur == 0:
                    t_, k_, c_ = STEP_JVP(prm, a, da, bb, dbb, u[i], dxj, Nc[i], dNj, dTj)  # noqa: F821
                else:
                    t_, k_, c_ = STEP_JVP(prm, bb, dbb, a, da, u[i], dxj, Nc[i], dNj, dTj)  # noqa: F821
                cur = 1 - cur
                for d in range(nd):
                    dT[i, d] = dTj[d]
                e = abs(t_ - T1[i])
                if e > err:
                    err = e
                err2, tmax = _track(t_, T2[i], err2, tmax)
                Tc[i] = t_
                code[c, i] = c_
                if hist:
                    if cur == 0:
                        hit = _history(a, da, Sh, dSh, i, passes, rtol)
                    else:
                        hit = _history(bb, dbb, Sh, dSh, i, passes, rtol)
                    if hit:
                        # the state and its derivatives after sample i are those of
                        # the first pass after sample i (to rtol, entry by entry,
                        # as the end-of-pass test below): the rest of this pass
                        # repeats the first one (same kernel, same inputs), so it
                        # is copied instead of marched
                        for j in range(i + 1, ns):
                            t_ = T1[j]
                            err2, tmax = _track(t_, T2[j], err2, tmax)
                            Tc[j] = t_
                            for d in range(nd):
                                dT[j, d] = dT1[j, d]
                            code[c, j] = cprev[j]
                        if cur == 0:
                            _load_state(a, da, Sh, dSh, ns - 1)
                        else:
                            _load_state(bb, dbb, Sh, dSh, ns - 1)
                        break
            if cur == 1:  # committed state back in (a, da), once per pass
                a, bb = bb, a
                da, dbb = dbb, da
            passes += 1
            if passes >= 2 and err <= rtol * tmax:
                period = 1.0
                break
            if passes >= 2:
                # the committed state at the end of this pass equals the one at
                # the end of the previous pass: the next pass would repeat this
                # one exactly, so this pass is the periodic force already
                same = True
                for r_ in range(ssz):
                    m = max(abs(a[r_]), abs(s_end[r_]))
                    if abs(a[r_] - s_end[r_]) > rtol * m:
                        same = False
                        break
                if same:
                    period = 1.0
                    err = 0.0  # the next pass would repeat this one exactly
                    break
            for r_ in range(ssz):
                s_end[r_] = a[r_]
            if passes >= 4 and err2 <= rtol * tmax:
                period = 2.0
                for i in range(ns):
                    Tc[i] = 0.5 * (Tc[i] + T1[i])
                    for d in range(nd):
                        dT[i, d] = 0.5 * (dT[i, d] + dT1[i, d])
                break
            # history of the last two passes (buffers swapped, not copied)
            T1, T2 = T2, T1
            for i in range(ns):
                T1[i] = Tc[i]
                cprev[i] = code[c, i]
            dT, dT1 = dT1, dT
        for i in range(ns):
            T[c, i] = Tc[i]
        F[:] = np.dot(P, Tc)
        G[:, :] = np.dot(P, dT)
        # scatter: R[h*n + i] += b_i F_h ; JX[(h,i),(g,j)] += b_i b_j G_hg
        for h in range(nh):
            for i in range(n):
                bi = Bm[c, i]
                if bi == 0.0:
                    continue
                R[h * n + i] += F[h] * bi
                if has_p:
                    Jp[h * n + i] += G[h, nh] * bi
                for g in range(nh):
                    for j in range(n):
                        bj = Bm[c, j]
                        if bj != 0.0:
                            JX[h * n + i, g * n + j] += G[h, g] * (bi * bj)
        if passes > info[0]:
            info[0] = passes
        if err > info[1]:
            info[1] = err
        # worst case over the contacts: 0 (not repeated) < 2 < 1
        if period == 0.0 or (period == 2.0 and info[2] == 1.0):
            info[2] = period
    _scale_outputs(R, JX, Jp, scl, Rs, JXs, Jps)


#: the march keeps the previous pass's states (and derivatives) at every
#: sample, to stop marching once they repeat, for laws with states of at
#: most this many entries (storing is then cheaper than the kernel calls)
_HIST_MAX_STATE = 16


@jit(inline="always")
def _track(t, t2, err2, tmax):  # pragma: no cover - compiled
    """Running max |t - t2| (change against two passes back) and max |t|."""
    e = abs(t - t2)
    if e > err2:
        err2 = e
    if abs(t) > tmax:
        tmax = abs(t)
    return err2, tmax


@jit(inline="always")
def _same_state(a, da, Sh, dSh, i, rtol):  # pragma: no cover - compiled
    """True if (a, da) equal (Sh[i], dSh[i]) to ``rtol`` relative, entry by entry (False on NaN)."""
    for r in range(a.shape[0]):
        x = a[r]
        y = Sh[i, r]
        if not abs(x - y) <= rtol * max(abs(x), abs(y)):
            return False
    for r in range(da.shape[0]):
        for d in range(da.shape[1]):
            x = da[r, d]
            y = dSh[i, r, d]
            if not abs(x - y) <= rtol * max(abs(x), abs(y)):
                return False
    return True


@jit(inline="always")
def _history(s, ds, Sh, dSh, i, passes, rtol):  # pragma: no cover - compiled
    """Pass 0: store (s, ds) as sample i of the first pass; pass 1: True if they repeat it."""
    if passes == 1:
        return _same_state(s, ds, Sh, dSh, i, rtol)
    if passes == 0:
        for r in range(s.shape[0]):
            Sh[i, r] = s[r]
            for d in range(ds.shape[1]):
                dSh[i, r, d] = ds[r, d]
    return False


@jit(inline="always")
def _load_state(s, ds, Sh, dSh, i):  # pragma: no cover - compiled
    """(s, ds) = (Sh[i], dSh[i])."""
    for r in range(s.shape[0]):
        s[r] = Sh[i, r]
        for d in range(ds.shape[1]):
            ds[r, d] = dSh[i, r, d]


@jit(inline="always")
def _scale_outputs(R, JX, Jp, scl, Rs, JXs, Jps):  # pragma: no cover - compiled
    if scl[0] > 0.0:
        size = R.shape[0]
        for i in range(size):
            Rs[i] = R[i] / scl[0]
            Jps[i] = Jp[i] * scl[2]
            for j in range(size):
                JXs[i, j] = JX[i, j] * scl[1]


def _eval_kernel(law):
    """The compiled HB evaluation with ``law.step_jvp`` and ``law.init`` bound (disk-cached)."""
    return specialize(_eval_template, STEP_JVP=law.step_jvp, INIT=law.init)


_DS0_CACHE: dict = {}


def _initial_state_derivatives(law, x0, n0):
    """Derivatives (sx, sn) of the virgin state w.r.t. x0 and n0.

    A central difference of ``law.initial_state`` (the virgin state is an
    affine function of x0 and n0 for every law of the contract: it stores
    the displacement and the load ratio), so the harmonic-balance code needs
    no knowledge of the state layout. It is computed once per law (and side
    of n0 = 0) and reused.
    """
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
    return hit[1], hit[2]
