"""Alternating frequency-time (AFT) evaluation of the harmonic-balance residual.

Harmonic coefficients of a periodic signal in normalised time tau = w t
(:mod:`jointdyn.fourier`) are sampled at ``tau_j = 2 pi j / Ns``
(``E @ U``), the contact law is marched over the samples (over whole
periods, repeatedly, until the force repeats: a hysteretic law needs its
periodic internal state), and the force samples are projected back
(``P @ T``). Where a contact re-closes between two samples (its normal
load crosses zero upwards), the law is restarted virgin at the exact
re-contact phase, at the displacement there (:func:`recontact_events`),
before it steps to the next sample: the re-contact instant is not
quantised to the sampling grid. A period that only confirms that the last one repeats is marched
along no direction (:func:`_value_pass`). Derivatives are
carried forward through the same march with the law's ``step_jvp`` kernel, starting from the exact derivative of the
virgin state (the law's ``init_jvp``), so the Jacobian of the force
coefficients with respect to the displacement coefficients (and to a
scalar parameter entering the normal load) is exact for the computed
residual.

The whole evaluation (linear part, AFT of every contact, scatter into the
residual and its Jacobians) is one compiled call per residual evaluation
(:func:`_eval_template`), so Newton and continuation pay no Python per
contact or per harmonic. It is assembled from small helpers inlined by
Numba, each doing one job: linear part, samples of a contact's
displacement, restart of the law at the mean displacement (at the
reference displacement 0 for a structure held only through its contacts), one marched
period, the periodicity tests, projection and scatter.

Nothing here knows the physics of a law: the kernels are called unchanged
through the compiled template bound with :func:`jointdyn._jit.specialize`
(``STEP_JVP``, ``INIT_JVP``) and passed on to the helpers that call them.
"""

from __future__ import annotations

import numpy as np

from .._jit import jit, specialize
from ._recontact import NO_EVENT, _event_point, _spring_event, recontact_events

__all__ = ["eval_kernel", "recontact_events", "NO_EVENT"]

#: the march keeps the first pass's states (and derivatives) at every
#: sample, to stop marching once they repeat, for laws with states of at
#: most this many entries (storing is then cheaper than the kernel calls)
_HIST_MAX_STATE = 16

#: ``info`` entries of an evaluation: largest number of marched periods,
#: largest change of the force between the last two periods (N), and the
#: worst period of the marched force over the contacts (1, 2 or 0)
INFO_PASSES, INFO_ERROR, INFO_PERIOD = 0, 1, 2
#: after this many passes with derivatives whose force has not repeated, one period is
#: marched without them (:func:`_value_pass`): where it repeats the last pass, that pass
#: is the result (most evaluations of Masing-type laws: the first pass, from the virgin
#: state, is a transient, the second is periodic)
_CHECK_AFTER = 2
#: force periods in forcing periods: repeated every period, every second
#: period (the mean of both is used), or not repeated within the bound
PERIOD_ONE, PERIOD_TWO, PERIOD_NONE = 1.0, 2.0, 0.0

#: two consecutive marched periods agree when max|T_p - T_(p-1)| <= rtol max|T|
HB_PERIODIC_RTOL = 1e-10


def _eval_template(lin, con, load, four, ctl, out, scaled):  # pragma: no cover - compiled
    """Whole HB residual and Jacobian in one call: linear part + AFT of every contact.

    Arguments are tuples of arrays (and scalars):

    * ``lin = (AK, AC, AM, w, dwdp, X, Fe, Fp, cols)``: ``A = AK + w AC + w^2 AM``,
      ``R = A X - Fe``, ``JX = A``, ``Jp = dwdp (AC + 2 w AM) X - Fp``
      (see ``problem.py``), row i of the linear terms nonzero only in
      columns ``cols[i, 0] .. cols[i, 1] - 1`` (its harmonic, :func:`_linear_part`);
    * ``con = (Bm, Pm, ssz, Bnm, Sp, spr)``: selection row ``Bm[c]`` and
      kernel parameters ``Pm[c]`` of each contact, state length ``ssz``,
      normal row ``Bnm[c]`` (g = Bnm[c] . x) and ``Sp[c] = (P, kn, restart load)`` of a
      spring contact (kn = 0: prescribed load), ``spr`` True when some
      contact has a spring;
    * ``load = (Nsamp, dN, has_p, events)``: prescribed normal-load samples
      (contacts, Ns) and, when ``has_p``, their derivative along the
      continuation parameter (rows of spring contacts unused);
      ``events = (ev_tau, ev_dtau, ev_load)`` from :func:`recontact_events`:
      per contact and sample, the phase of a re-contact of a prescribed
      load inside the interval before the sample (:data:`NO_EVENT` if none)
      and its derivative along the parameter, and per contact the load at
      which the law restarts there;
    * ``four = (E, P)``: synthesis and analysis matrices;
    * ``ctl = (max_passes, rtol, at_ref)``: bound on the marched periods, the
      periodicity tolerance, and where the laws restart: at the mean
      displacement (False) or at the reference displacement 0 (True, a
      structure held only through its contacts: :func:`_restart`);
    * ``out = (R, JX, Jp, T, Nout, code, info)``: outputs, ``T[c]``,
      ``Nout[c]`` and ``code[c]`` the force samples, normal-load samples
      and motion codes of the last pass,
      ``info`` as described by ``INFO_*``;
    * ``scaled = (scl, Rs, JXs, Jps)``: when ``scl[0] > 0`` also
      ``Rs = R / scl[0]``, ``JXs = JX * scl[1]``, ``Jps = Jp * scl[2]``
      (the continuation's unknowns and residual in units of order one).

    Per contact c: ``U = Xm Bm[c]``, its normal-load samples (prescribed,
    or ``max(0, P + kn g)`` from ``G = Xm Bnm[c]`` for a spring:
    :func:`_prescribed_loads`, :func:`_spring_loads`), restart of the law
    at the mean displacement ``U[0]`` (or 0 with ``at_ref``) and the first load sample (``INIT_JVP``), AFT passes of
    ``STEP_JVP`` (:func:`_pass`) until the force repeats, projection, and
    scatter ``R += b F``, ``JX += b (b^T dF/dU + bn^T dF/dG)``,
    ``Jp += b dF/dp``; a spring also adds its reaction ``bn P (N - P0)``
    and ``bn bn^T P diag(dN/dg) E`` (:func:`_normal_reaction`). AFT
    directions: the 2H+1 coefficients of u (du_i = E[i, d]); with springs,
    the 2H+1 coefficients of g (dN_i = kn E[i, d] where closed, 0 where
    open: the law's dT/dN carried by ``STEP_JVP``); when ``has_p``, the
    parameter entering the prescribed loads (dN_i = dN[c, i]). Separation
    (N <= 0 at a sample) and re-contact are the law's (contract item 2:
    T = 0 while open, virgin again on re-contact), resolved to the samples.

    The march stops when two consecutive passes agree to ``rtol * max|T|``,
    or when the committed state at the end of a pass equals (to ``rtol``,
    entry by entry) the one at the end of the previous pass, so that the
    next pass would repeat this one (period 1; saves a pass). If instead
    passes p and p-2 agree (the law's state alternates between two cycles:
    a period-2 force under a period-1 displacement), the force and its
    derivatives are the mean of the last two passes, which is the exact
    projection of the 2T-periodic force on the T-periodic harmonics
    (:func:`_period_test`). A second pass that neither test stops is
    checked by one more period marched without derivatives (``step_jvp``
    along no direction, :func:`_value_pass`, a fraction of the cost of a
    pass with them): if its force repeats the second pass's (the first
    test), the second pass is the periodic force and the result, with its
    derivatives; otherwise the march goes on with derivatives. The
    first pass, from the virgin state, is a transient for most orbits of
    the exact Iwan law; the check replaces the third pass with derivatives
    that confirmed the second. ``info`` counts the checked period among the
    marched ones.

    Structure, and what it costs to compile: the loops over contacts and
    passes are written here and the helpers are inlined by Numba. Deeper
    chains of inlined functions (a march function inlining the pass,
    inlined into a per-contact function) measured about 50 % more cold
    compile than the single function this replaces, because Numba's
    inliner re-runs its front end on each level; with one level it is
    about 15 %. Variants that compiled the march as a function of its own,
    or wrote the pass out here around more inlined helpers, were
    miscompiled by Numba 0.68 (out-of-bounds writes, wrong forces); this
    structure agrees with the plain-Python reference of
    ``tests/test_hb_aft.py`` for every law, also with bounds checking.
    """
    R, JX, Jp, T, Nout, code, info = out
    _linear_part(lin, R, JX, Jp)
    info[INFO_PASSES] = 0.0
    info[INFO_ERROR] = 0.0
    info[INFO_PERIOD] = PERIOD_ONE
    Bm = con[0]
    Pm = con[1]
    nc = Bm.shape[0]
    if nc == 0:
        _scale_outputs(R, JX, Jp, scaled)
        return
    Nsamp, dN, has_p, events = load
    E, P = four
    max_passes, rtol, at_ref = ctl
    sig, dirs, st, pw, hist, proj, nrm, vst = _workspace(con, four, has_p, code)
    U, u = sig
    a, bb, da, dbb, s_end = st
    Nc, km = nrm[2], nrm[3]
    for c in range(nc):
        # the law restarted at the mean displacement (or at the reference: at_ref), marched until its force repeats
        _contact_samples(lin[5], Bm, c, E, U, u)
        if SPRINGS and con[4][c, 1] > 0.0:  # noqa: F821 - bound by specialize
            _spring_loads(lin[5], con, c, E, nrm)
        else:
            _prescribed_loads(Nsamp, c, nrm)
        prm = Pm[c]
        _restart(INIT_JVP, prm, U[0], Nc[0], km[0], dN[c, 0] if has_p else 0.0, has_p, E, dirs,  # noqa: F821
                 (a, bb, da, dbb), at_ref)
        Tc, dT, T1, T2, dT1, cprev = pw
        for i in range(u.shape[0]):
            T1[i] = 0.0
            T2[i] = 0.0
        passes = 0
        checked = 0  # periods marched without derivatives (_value_pass)
        err = np.inf
        period = PERIOD_NONE
        while passes < max_passes:
            err, err2, tmax, cur = _pass(STEP_JVP, INIT_JVP, prm, (u, U), (Nc, km, nrm[0], nrm[1], con[4][c]), dN, c, has_p, SPRINGS, events,  # noqa: F821
                                         E, dirs, (a, bb, da, dbb), (Tc, dT, T1, T2, dT1, cprev), hist, code,
                                         passes, rtol)
            if cur == 1:  # committed state back in (a, da), once per pass
                a, bb = bb, a
                da, dbb = dbb, da
            passes += 1
            done, period, err = _period_test(passes, err, err2, tmax, rtol, a, s_end, Tc, dT, T1, dT1)
            if not done and passes == _CHECK_AFTER and passes < max_passes:
                # one more period without derivatives: if it repeats this one, this pass
                # is the periodic force and its derivatives are exact
                done, err_v = _value_pass(STEP_JVP, INIT_JVP, prm, (u, U), (Nc, km, nrm[0], nrm[1], con[4][c]),  # noqa: F821
                                          c, SPRINGS, events, a, vst, Tc, rtol)  # noqa: F821
                checked = 1
                if done:
                    period, err = PERIOD_ONE, err_v
            if done:
                break
            # history of the last two passes (buffers swapped, not copied)
            T1, T2 = T2, T1
            for i in range(u.shape[0]):
                T1[i] = Tc[i]
                cprev[i] = code[c, i]
            dT, dT1 = dT1, dT
        _project(c, P, Tc, dT, T, proj)
        for i in range(Nc.shape[0]):
            Nout[c, i] = Nc[i]
        _scatter(c, con, proj, has_p, SPRINGS, R, JX, Jp)  # noqa: F821 - bound by specialize
        if SPRINGS and con[4][c, 1] > 0.0:  # noqa: F821 - bound by specialize
            _normal_reaction(c, con, four, nrm, R, JX)
        _update_info(info, passes + checked, err, period)
    _scale_outputs(R, JX, Jp, scaled)


@jit(inline="always")
def _linear_part(lin, R, JX, Jp):  # pragma: no cover - compiled
    """R = A X - Fe, JX = A, Jp = dwdp (AC + 2 w AM) X - Fp with A = AK + w AC + w^2 AM.

    The linear terms couple the coefficients of one harmonic only: row i of
    AK, AC and AM is zero outside the columns ``cols[i, 0] .. cols[i, 1] - 1``
    (its harmonic's block), which alone are read (JX is zero elsewhere).
    """
    AK, AC, AM, w, dwdp, X, Fe, Fp, cols = lin
    size = X.shape[0]
    w2 = w * w
    w2x = 2.0 * w
    for i in range(size):
        lo = cols[i, 0]
        hi = cols[i, 1]
        for j in range(lo):
            JX[i, j] = 0.0
        r = 0.0
        jp = 0.0
        for j in range(lo, hi):
            a = AK[i, j] + w * AC[i, j] + w2 * AM[i, j]
            JX[i, j] = a
            r += a * X[j]
            jp += (AC[i, j] + w2x * AM[i, j]) * X[j]
        for j in range(hi, size):
            JX[i, j] = 0.0
        R[i] = r - Fe[i]
        Jp[i] = jp * dwdp - Fp[i]


@jit(inline="always")
def _workspace(con, four, has_p, code):  # pragma: no cover - compiled
    """Buffers of the AFT, allocated once per evaluation and grouped by use.

    ``(sig, dirs, st, pw, hist, proj, nrm, vst)``: displacement coefficients and
    samples of a contact; sample and restart directions; committed and
    trial states (and derivatives) and the state at the end of the last
    pass; force samples of the current and the last two passes; first-pass
    states at every sample (small states only); projected force and
    derivatives; normal approach (coefficients, samples), normal-load
    samples, their slope dN/dg (kn closed, 0 open) and the projected
    reaction with its derivative (:func:`_spring_loads`); the two states and
    a scratch row of :func:`_value_pass`.
    """
    E = four[0]
    ssz = con[2]
    ns = E.shape[0]
    nh = E.shape[1]
    nd = nh + (nh if con[5] else 0) + (1 if has_p else 0)
    sig = (np.empty(nh), np.empty(ns))
    # directions of a sample: dx = E[i] on the coefficients of u (0 elsewhere);
    # dN = kn E[i] on the coefficients of g (closed spring) and dN[c, i] on the parameter
    dirs = (np.zeros(nd), np.zeros(nd), np.empty(nd), np.zeros(nd), np.zeros(nd))
    # zeros, not garbage: entries of a state that a law leaves unwritten in a step
    # keep a defined value, so the end-of-pass comparison of states is deterministic
    st = (np.zeros(ssz), np.zeros(ssz), np.zeros((ssz, nd)), np.zeros((ssz, nd)), np.zeros(ssz))
    pw = (np.empty(ns), np.empty((ns, nd)), np.empty(ns), np.empty(ns), np.empty((ns, nd)),
          np.empty(ns, dtype=code.dtype))
    nhist = ns if ssz <= _HIST_MAX_STATE else 0
    hist = (np.empty((nhist, ssz)), np.empty((nhist, ssz, nd)))
    proj = (np.empty(nh), np.empty((nh, nd)))
    nrm = (np.empty(nh), np.empty(ns), np.empty(ns), np.empty(ns), np.empty(nh), np.empty((nh, nh)))
    # states of the period marched without derivatives (zeros, as ``st``), their
    # derivatives and directions along none (the law's step_jvp with no direction),
    # and the scratch derivative of a restart's displacement there (unused)
    vst = (np.zeros(ssz), np.zeros(ssz), np.zeros((ssz, 0)), np.zeros((ssz, 0)), np.zeros(0), np.zeros(0),
           np.empty(2 * nh))
    return sig, dirs, st, pw, hist, proj, nrm, vst


@jit(inline="always")
def _contact_samples(X, Bm, c, E, U, u):  # pragma: no cover - compiled
    """Coefficients ``U`` (2H+1) and samples ``u = E U`` (Ns) of contact c's displacement."""
    n = Bm.shape[1]
    nh = E.shape[1]
    for h in range(nh):
        acc = 0.0
        for i in range(n):
            acc += X[h * n + i] * Bm[c, i]
        U[h] = acc
    for i in range(E.shape[0]):
        acc = 0.0
        for h in range(nh):
            acc += E[i, h] * U[h]
        u[i] = acc


@jit(inline="always")
def _restart(init_jvp, prm, U0, N0, k0, dN0, has_p, E, dirs, st, ref):  # pragma: no cover - compiled
    """Virgin state of the law at the mean displacement ``U0`` and load ``N0``, with its exact derivative.

    Direction 0 (the constant coefficient of u) moves the mean
    displacement. With ``ref`` (a structure held only through its contacts,
    :attr:`jointdyn.hb.HBProblem.restart_at_reference`) the law restarts at
    the reference displacement 0 instead (the preloaded static state, where
    every contact is at rest without tangential force), which no unknown
    moves: direction 0 is then zero. The directions of the normal approach's coefficients
    (indices nh..2nh-1, when the system has springs) move the load by
    ``k0 E[0, d]`` (``k0`` = dN/dg at the first sample); the parameter
    direction (the last) moves it by ``dN0``. The state goes to ``st[0]``,
    its derivative to ``st[2]``.
    """
    dx0 = dirs[3]
    dn0 = dirs[4]
    nh = E.shape[1]
    nd = dx0.shape[0]
    x0 = U0
    dx0[0] = 1.0
    if ref:
        x0 = 0.0
        dx0[0] = 0.0
    if nd - (1 if has_p else 0) > nh:
        for d in range(nh):
            dn0[nh + d] = k0 * E[0, d]
    if has_p:
        dn0[nd - 1] = dN0
    init_jvp(prm, x0, dx0, N0, dn0, st[0], st[2])


@jit(inline="always")
def _project(c, P, Tc, dT, T, proj):  # pragma: no cover - compiled
    """T[c] = Tc; F = P Tc, G = P dT (force coefficients and their derivatives) into ``proj``."""
    for i in range(Tc.shape[0]):
        T[c, i] = Tc[i]
    F, G = proj
    # plain loops, not np.dot: Numba's BLAS binding imports scipy.linalg at
    # the first call (0.2-0.4 s of every process's start), and at these
    # sizes (2H+1 rows, a few hundred samples) the loops are as fast
    nd = dT.shape[1]
    for k in range(P.shape[0]):
        f = 0.0
        for j in range(nd):
            G[k, j] = 0.0
        for i in range(P.shape[1]):
            p = P[k, i]
            f += p * Tc[i]
            for j in range(nd):
                G[k, j] += p * dT[i, j]
        F[k] = f


@jit(inline="always")
def _pass(step_jvp, init_jvp, prm, sig, nk, dN, c, has_p, spr, events, E, dirs, st, pw, hist, code, passes,
          rtol):  # pragma: no cover - compiled
    """One marched period: force samples ``Tc``, derivatives ``dT`` and codes of contact c.

    ``sig = (u, U)``: displacement samples and coefficients; ``nk = (Nc,
    km, G, g, sp)``: the contact's normal-load samples and their slope
    dN/dg (kn while a spring is closed, 0 when open or prescribed), the
    normal approach's coefficients and samples and the spring row
    ``sp = (P, kn, restart load)``. Where the event table has a re-contact
    of a prescribed load in the interval before sample i, or a spring
    closes between samples i-1 and i (:func:`_spring_event`), the
    committed state is first replaced by the virgin state at the
    re-contact phase (:func:`_event_point`, ``init_jvp``). The committed
    state is in ``(a, da)`` when ``cur == 0``, in
    ``(bb, dbb)`` when ``cur == 1``: the kernel writes the other pair, so
    no array variable is reassigned per sample (that costs reference
    counting). For laws with small states the first pass stores its
    committed states at every sample; once the second pass reaches, at
    some sample, the same state and derivatives (to ``rtol``, entry by
    entry, the criterion of the end-of-pass test), the rest of the pass
    would repeat the first one (same kernel, same inputs) and is copied
    from it instead of marched (:func:`_copy_rest`). Returns
    ``(err, err2, tmax, cur)``: max change against the last pass and the
    one before, max |T|, and where the committed state ended.
    """
    a, bb, da, dbb = st
    Tc, dT, T1, T2, dT1, cprev = pw
    Sh, dSh = hist
    Nc, km, Gc, gs, sp = nk
    u, U = sig
    ev_tau, ev_dtau, ev_load = events
    dxj, dNj, dTj = dirs[0], dirs[1], dirs[2]
    ns = u.shape[0]
    nh = E.shape[1]
    nd = dxj.shape[0]
    err = 0.0
    err2 = 0.0
    tmax = 0.0
    cur = 0
    for i in range(ns):
        for d in range(nh):
            dxj[d] = E[i, d]
        if ev_tau[c, i] != NO_EVENT:
            # virgin restart at the re-contact phase (load derivative zero: N = 0 there)
            xr = _event_point(U, ev_tau[c, i], ev_dtau[c, i], has_p, dxj)
            dNj[:] = 0.0
            if cur == 0:
                init_jvp(prm, xr, dxj, ev_load[c], dNj, a, da)
            else:
                init_jvp(prm, xr, dxj, ev_load[c], dNj, bb, dbb)
            for d in range(nh):
                dxj[d] = E[i, d]
            if has_p:
                dxj[nd - 1] = 0.0
        if spr and km[i] > 0.0 and km[i - 1 if i > 0 else ns - 1] == 0.0:
            # a spring closing between samples: virgin restart at the root of P + kn g
            xr = _spring_event(U, Gc, sp, 2.0 * np.pi * i / ns, 2.0 * np.pi / ns, gs[i - 1 if i > 0 else ns - 1],
                               gs[i], dxj)
            dNj[:] = 0.0
            if cur == 0:
                init_jvp(prm, xr, dxj, sp[2], dNj, a, da)
            else:
                init_jvp(prm, xr, dxj, sp[2], dNj, bb, dbb)
            for d in range(nh):
                dxj[d] = E[i, d]
                dxj[nh + d] = 0.0
            if has_p:
                dxj[nd - 1] = 0.0
        if spr:
            for d in range(nh):
                dNj[nh + d] = km[i] * E[i, d]
        if has_p:
            dNj[nd - 1] = dN[c, i]
        if cur == 0:
            t_, k_, c_ = step_jvp(prm, a, da, bb, dbb, u[i], dxj, Nc[i], dNj, dTj)
        else:
            t_, k_, c_ = step_jvp(prm, bb, dbb, a, da, u[i], dxj, Nc[i], dNj, dTj)
        cur = 1 - cur
        for d in range(nd):
            dT[i, d] = dTj[d]
        e = abs(t_ - T1[i])
        if e > err:
            err = e
        err2, tmax = _track(t_, T2[i], err2, tmax)
        Tc[i] = t_
        code[c, i] = c_
        if Sh.shape[0] > 0:
            if cur == 0:
                hit = _history(a, da, Sh, dSh, i, passes, rtol)
            else:
                hit = _history(bb, dbb, Sh, dSh, i, passes, rtol)
            if hit:
                err2, tmax = _copy_rest(i, Tc, dT, T1, T2, dT1, cprev, code, c, err2, tmax)
                if cur == 0:
                    _load_state(a, da, Sh, dSh, ns - 1)
                else:
                    _load_state(bb, dbb, Sh, dSh, ns - 1)
                break
    return err, err2, tmax, cur


@jit(inline="always")
def _value_pass(step_jvp, init_jvp, prm, sig, nk, c, spr, events, s0, vst, Tref, rtol):  # pragma: no cover - compiled
    """One period of contact c marched without derivatives from the committed state ``s0``.

    The check after the second pass (:func:`_eval_template`): the law's
    ``step_jvp`` along no direction (its primal outputs are ``step``'s, bit
    for bit; the compiled kernel already called by the passes, so the check
    compiles no law code of its own) from a copy of ``s0`` over the
    samples, with the restarts of :func:`_pass` (re-contact of a prescribed
    load, closing of a spring; ``init_jvp``), its forces compared with the
    last pass's ``Tref``. Returns
    ``(repeats, err)``: ``repeats`` True when the forces agree to ``rtol
    max|T|`` (the first test of :func:`_period_test`), so that the pass
    that ended in ``s0`` is the periodic force; ``err`` the largest force
    change, N. (A state at the end equal to ``s0`` would make this period
    periodic, not the one before it, whose start differed: it is not a
    test here.) Costs a fraction of a pass with derivatives.
    """
    va, vb, dva, dvb, d0, dT0, dxs = vst
    u, U = sig
    Nc, km, Gc, gs, sp = nk
    ev_tau, ev_dtau, ev_load = events
    ns = u.shape[0]
    for r in range(s0.shape[0]):
        va[r] = s0[r]
    err = 0.0
    tmax = 0.0
    cur = 0
    for i in range(ns):
        if ev_tau[c, i] != NO_EVENT:
            xr = _event_point(U, ev_tau[c, i], ev_dtau[c, i], False, dxs)
            if cur == 0:
                init_jvp(prm, xr, d0, ev_load[c], d0, va, dva)
            else:
                init_jvp(prm, xr, d0, ev_load[c], d0, vb, dvb)
        if spr and km[i] > 0.0 and km[i - 1 if i > 0 else ns - 1] == 0.0:
            xr = _spring_event(U, Gc, sp, 2.0 * np.pi * i / ns, 2.0 * np.pi / ns, gs[i - 1 if i > 0 else ns - 1],
                               gs[i], dxs)
            if cur == 0:
                init_jvp(prm, xr, d0, sp[2], d0, va, dva)
            else:
                init_jvp(prm, xr, d0, sp[2], d0, vb, dvb)
        if cur == 0:
            t_ = step_jvp(prm, va, dva, vb, dvb, u[i], d0, Nc[i], d0, dT0)[0]
        else:
            t_ = step_jvp(prm, vb, dvb, va, dva, u[i], d0, Nc[i], d0, dT0)[0]
        cur = 1 - cur
        err, tmax = _track(t_, Tref[i], err, tmax)
    return err <= rtol * tmax, err


@jit(inline="always")
def _copy_rest(i, Tc, dT, T1, T2, dT1, cprev, code, c, err2, tmax):  # pragma: no cover - compiled
    """Samples i+1.. of this pass copied from the first pass (the march repeats it)."""
    for j in range(i + 1, Tc.shape[0]):
        t_ = T1[j]
        err2, tmax = _track(t_, T2[j], err2, tmax)
        Tc[j] = t_
        for d in range(dT.shape[1]):
            dT[j, d] = dT1[j, d]
        code[c, j] = cprev[j]
    return err2, tmax


@jit(inline="always")
def _period_test(passes, err, err2, tmax, rtol, a, s_end, Tc, dT, T1, dT1):  # pragma: no cover - compiled
    """Periodicity tests after a pass: ``(done, period, err)`` (see :func:`_eval_template`).

    Updates the end-of-pass state ``s_end``; for a period-2 force, ``Tc``
    and ``dT`` become the mean of the last two passes.
    """
    if passes >= 2 and err <= rtol * tmax:
        return True, PERIOD_ONE, err
    if passes >= 2:
        # the committed state at the end of this pass equals the one at the end of the
        # previous pass (entry by entry, to rtol): the next pass would repeat this one
        # exactly, so this pass is the periodic force already
        same = True
        for r in range(a.shape[0]):
            m = max(abs(a[r]), abs(s_end[r]))
            if abs(a[r] - s_end[r]) > rtol * m:
                same = False
                break
        if same:
            return True, PERIOD_ONE, 0.0
    for r in range(a.shape[0]):
        s_end[r] = a[r]
    if passes >= 4 and err2 <= rtol * tmax:
        for i in range(Tc.shape[0]):
            Tc[i] = 0.5 * (Tc[i] + T1[i])
            for d in range(dT.shape[1]):
                dT[i, d] = 0.5 * (dT[i, d] + dT1[i, d])
        return True, PERIOD_TWO, err
    return False, PERIOD_NONE, err


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
def _scatter(c, con, proj, has_p, spr, R, JX, Jp):  # pragma: no cover - compiled
    """R[h n + i] += b_i F_h; JX[(h, i), (g, j)] += b_i (b_j G_hg + bn_j G_h,nh+g); Jp[h n + i] += b_i G_h,p.

    ``b = Bm[c]`` the tangential row, ``bn = Bnm[c]`` the normal row (the
    force's dependence on the normal approach, systems with springs only).
    """
    Bm = con[0]
    Bnm = con[3]
    F, G = proj
    n = Bm.shape[1]
    nh = F.shape[0]
    ip = G.shape[1] - 1
    for h in range(nh):
        for i in range(n):
            bi = Bm[c, i]
            if bi == 0.0:
                continue
            R[h * n + i] += F[h] * bi
            if has_p:
                Jp[h * n + i] += G[h, ip] * bi
            for g in range(nh):
                for j in range(n):
                    bj = Bm[c, j]
                    if bj != 0.0:
                        JX[h * n + i, g * n + j] += G[h, g] * (bi * bj)
            if spr:
                for g in range(nh):
                    for j in range(n):
                        bj = Bnm[c, j]
                        if bj != 0.0:
                            JX[h * n + i, g * n + j] += G[h, nh + g] * (bi * bj)


@jit(inline="always")
def _prescribed_loads(Nsamp, c, nrm):  # pragma: no cover - compiled
    """Normal-load samples ``Nc = Nsamp[c]`` of a contact with a prescribed load, slope ``km`` = dN/dg = 0."""
    Nc, km = nrm[2], nrm[3]
    for i in range(Nc.shape[0]):
        Nc[i] = Nsamp[c, i]
        km[i] = 0.0


@jit
def _spring_loads(X, con, c, E, nrm):  # pragma: no cover - compiled
    """Normal-load samples ``Nc`` of spring contact c and their slope ``km`` = dN/dg.

    ``Sp[c] = (P, kn)``, kn > 0: the approach g = Bnm[c] . x sampled from
    the coefficients, ``Nc = max(0, P + kn g)`` and ``km = kn`` where closed
    (``P + kn g > 0``), 0 where open (the law separates at N <= 0). A plain
    compiled function, called only by evaluations of systems with springs
    (like :func:`_normal_reaction` and :func:`_spring_event`), so that the
    others compile none of the spring work.
    """
    Gc, gs, Nc, km = nrm[0], nrm[1], nrm[2], nrm[3]
    Sp = con[4]
    P0 = Sp[c, 0]
    kn = Sp[c, 1]
    _contact_samples(X, con[3], c, E, Gc, gs)
    for i in range(Nc.shape[0]):
        v = P0 + kn * gs[i]
        if v > 0.0:
            Nc[i] = v
            km[i] = kn
        else:
            Nc[i] = 0.0
            km[i] = 0.0


@jit
def _normal_reaction(c, con, four, nrm, R, JX):  # pragma: no cover - compiled
    """Reaction of spring contact c: R[h n + i] += bn_i Fn_h, JX[(h, i), (g, j)] += bn_i bn_j dFn_hg.

    ``Fn = P (Nc - P0)`` (the load less the preload, projected) and
    ``dFn = P diag(km) E`` (its exact derivative along g's coefficients).
    """
    Bnm = con[3]
    P0 = con[4][c, 0]
    E, P = four
    Nc, km, Fn, dFn = nrm[2], nrm[3], nrm[4], nrm[5]
    n = Bnm.shape[1]
    nh = E.shape[1]
    ns = E.shape[0]
    for h in range(nh):
        acc = 0.0
        for i in range(ns):
            acc += P[h, i] * (Nc[i] - P0)
        Fn[h] = acc
        for g in range(nh):
            acc = 0.0
            for i in range(ns):
                acc += P[h, i] * km[i] * E[i, g]
            dFn[h, g] = acc
    for h in range(nh):
        for i in range(n):
            bi = Bnm[c, i]
            if bi == 0.0:
                continue
            R[h * n + i] += Fn[h] * bi
            for g in range(nh):
                for j in range(n):
                    bj = Bnm[c, j]
                    if bj != 0.0:
                        JX[h * n + i, g * n + j] += dFn[h, g] * (bi * bj)


@jit(inline="always")
def _update_info(info, passes, err, period):  # pragma: no cover - compiled
    """Worst case over the contacts: most passes, largest error, period 0 < 2 < 1."""
    if passes > info[INFO_PASSES]:
        info[INFO_PASSES] = passes
    if err > info[INFO_ERROR]:
        info[INFO_ERROR] = err
    if period == PERIOD_NONE or (period == PERIOD_TWO and info[INFO_PERIOD] == PERIOD_ONE):
        info[INFO_PERIOD] = period


@jit(inline="always")
def _scale_outputs(R, JX, Jp, scaled):  # pragma: no cover - compiled
    """Rs = R / scl[0], JXs = JX scl[1], Jps = Jp scl[2] when scl[0] > 0."""
    scl, Rs, JXs, Jps = scaled
    if scl[0] > 0.0:
        size = R.shape[0]
        for i in range(size):
            Rs[i] = R[i] / scl[0]
            Jps[i] = Jp[i] * scl[2]
            for j in range(size):
                JXs[i, j] = JX[i, j] * scl[1]


def eval_kernel(step_jvp, init_jvp, springs: bool = False):
    """The compiled HB evaluation with a law's ``step_jvp`` and ``init_jvp`` bound (disk-cached).

    ``springs`` (some contact's normal load comes from a normal spring; it
    must equal ``con[5]`` of every call) is a compile-time constant: the
    evaluations of other systems compile none of the spring work.
    """
    return specialize(_eval_template, STEP_JVP=step_jvp, INIT_JVP=init_jvp, SPRINGS=bool(springs))
