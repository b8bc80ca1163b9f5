"""The compiled HB evaluation (jointdyn.hb._aft._eval_template) against a
plain-Python reference of the same AFT march: every pass marched in full,
the law's kernels (restart by ``init_jvp``, march by ``step_jvp``) called
one sample at a time from Python. Covers the
shortcut of the compiled march (a pass stops once the state and its
derivatives repeat, to HB_PERIODIC_RTOL, those of the first pass at the
same sample; the rest of the pass is then copied; after a second pass
that did not repeat the first, one period is marched without derivatives,
and the second pass is the result if that period repeats it) on stuck,
slipping and separating orbits, with and without a parameter direction:
the results agree to rounding."""

import math

import numpy as np
import pytest

from jointdyn import System
from jointdyn.fourier import basis, derivative_matrix
from jointdyn.hb import HBProblem
from jointdyn.hb._aft import HB_PERIODIC_RTOL


def _value_period(p, law, c, U, u, Nsamp, ev_tau, ev_load, s0, vbuf, Tref):
    """The compiled march's check after the second pass: one period from s0 with the law's plain
    ``step`` (restarts by ``init``), trial states alternating between a copy of s0 and ``vbuf``.
    Returns (largest change of the force against Tref, True when it repeats Tref)."""
    rtol = HB_PERIODIC_RTOL
    va, vb = s0.copy(), vbuf
    Tv = np.empty(u.size)
    for i in range(u.size):
        if ev_tau[c, i] >= 0.0:
            law.init(law.params, float(basis(p.H, [ev_tau[c, i]])[0] @ U), float(ev_load[c]), va)
        Tv[i] = law.step(law.params, va, vb, u[i], Nsamp[c, i])[0]
        va, vb = vb, va
    err, tmax = np.max(np.abs(Tv - Tref)), np.max(np.abs(Tv))
    return err, bool(err <= rtol * tmax)


def _reference(p, X, lam):
    """R, JX, Jp, T, code, info of HBProblem.evaluate, marched in Python."""
    w, dwdp, Fe, Fp, Nsamp, dN, (ev_tau, ev_dtau, ev_load) = p._inputs(lam)
    AK, AC, AM = p._lin
    A = AK + w * AC + w * w * AM
    R = A @ X - Fe
    JX = A.copy()
    Jp = (AC + 2.0 * w * AM) @ X * dwdp - Fp
    # the AFT's phases: the uniform samples, or with separations also the phases graded towards them
    Eg, Pg, ns, n, nh = p._Eg, p._Pg, p._taug.size, p.n, p.nh
    has_p = dN is not None
    nd = nh + int(has_p)
    rtol = HB_PERIODIC_RTOL
    info = np.array([0.0, 0.0, 1.0])
    # the compiled march's second state buffer of its period without derivatives,
    # kept from one contact to the next (zeros at first)
    vbuf = np.zeros(max(contact.law.state_size for contact in p.contacts))
    Ts, codes = [], []
    for c, contact in enumerate(p.contacts):
        law = contact.law
        b = p._Bm[c]
        U = X.reshape(nh, n) @ b
        u = Eg @ U
        # virgin state at the mean displacement: direction 0 moves the mean, the parameter the load
        dx0, dn0 = np.zeros(nd), np.zeros(nd)
        dx0[0] = 1.0
        if has_p:
            dn0[nh] = dN[c, 0]
        a, da = np.zeros(law.state_size), np.zeros((law.state_size, nd))
        law.init_jvp(law.params, float(U[0]), dx0, float(Nsamp[c, 0]), dn0, a, da)
        assert np.array_equal(a, law.initial_state(float(U[0]), float(Nsamp[c, 0])))
        # the trial state goes into the buffer that held the state before the last
        # one, as in the compiled march: a law may leave the entries its current
        # state does not use unwritten (the closed-form Iwan's reversal stack),
        # and the end-of-pass test compares whole states
        b_, db_ = np.zeros_like(a), np.zeros_like(da)
        T1, T2, dT1 = np.zeros(ns), np.zeros(ns), np.zeros((ns, nd))
        s_end = np.zeros_like(a)
        passes, period, checked = 0, 0.0, 0
        while passes < p.max_passes:
            T, dT, code = np.empty(ns), np.empty((ns, nd)), np.empty(ns, dtype=np.int64)
            for i in range(ns):
                if ev_tau[c, i] >= 0.0:  # virgin restart at the re-contact phase inside the interval
                    tr = ev_tau[c, i]
                    Er = basis(p.H, [tr])[0]
                    dxr = np.zeros(nd)
                    dxr[:nh] = Er
                    if has_p:
                        dxr[nh] = (Er @ (derivative_matrix(p.H) @ U)) * ev_dtau[c, i]
                    law.init_jvp(law.params, float(Er @ U), dxr, float(ev_load[c]), np.zeros(nd), a, da)
                dx = np.zeros(nd)
                dx[:nh] = Eg[i]
                dn = np.zeros(nd)
                if has_p:
                    dn[nh] = dN[c, i]
                dT_ = np.empty(nd)
                T[i], _, code[i] = law.step_jvp(law.params, a, da, b_, db_, u[i], dx, Nsamp[c, i], dn, dT_)
                dT[i] = dT_
                a, da, b_, db_ = b_, db_, a, da
            passes += 1
            err, err2, tmax = np.max(np.abs(T - T1)), np.max(np.abs(T - T2)), np.max(np.abs(T))
            if passes >= 2 and err <= rtol * tmax:
                period = 1.0
                break
            if passes >= 2 and not np.any(np.abs(a - s_end) > rtol * np.maximum(np.abs(a), np.abs(s_end))):
                period, err = 1.0, 0.0
                break
            s_end = a.copy()
            if passes >= 4 and err2 <= rtol * tmax:
                period = 2.0
                T, dT = 0.5 * (T + T1), 0.5 * (dT + dT1)
                break
            if passes == 2 and passes < p.max_passes:
                checked = 1
                err_v, same = _value_period(p, law, c, U, u, Nsamp, ev_tau, ev_load, a, vbuf, T)
                if same:
                    period, err = 1.0, err_v
                    break
            T2, T1, dT1 = T1, T, dT
        F, G = Pg @ T, Pg @ dT
        R += np.kron(F, b)
        JX += np.kron(G[:, :nh], np.outer(b, b))
        if has_p:
            Jp += np.kron(G[:, nh], b)
        Ts.append(T)
        codes.append(code)
        info[0] = max(info[0], passes + checked)
        info[1] = max(info[1], err)
        if period == 0.0 or (period == 2.0 and info[2] == 1.0):
            info[2] = period
    at = np.arange(p.Ns) if p._uniform is None else p._uniform  # the evaluation reports the uniform samples
    return R, JX, Jp, np.array(Ts)[:, at], np.array(codes)[:, at], info


@pytest.mark.parametrize("model,kw", [("jenkins", {}), ("discrete", {"n": 4}), ("iwan", {}), ("iwan-paper", {})])
@pytest.mark.parametrize("eta,par", [(0.0, "gamma"), (0.5, "gamma"), (1.5, "gamma"), (0.5, "delta"), (1.5, "eta")])
def test_compiled_evaluation_equals_plain_march(model, kw, eta, par):
    s = System.paper_damper(eta=eta, beta=2.0, model=model, delta_deg=math.degrees(0.3), zeta=0.01, **kw)
    p = HBProblem(s, harmonics=3, samples=32, parameter=par, gamma=None if par == "gamma" else 1.1)
    lam = {"gamma": 1.1, "delta": math.degrees(0.3), "eta": eta}[par]
    X0 = p.linear_guess(lam)
    rng = np.random.default_rng(7)
    slipping = 0
    for scale in (0.2, 1.0, 3.0, 10.0, 40.0):  # stuck ... mostly in macroslip
        X = X0 * scale * (1.0 + 0.2 * rng.standard_normal(X0.size))
        ev = p.evaluate(X, lam)
        R, JX, Jp, T, code, info = _reference(p, X, lam)
        assert np.array_equal(ev.code, code)
        assert np.array_equal(ev.info[[0, 2]], info[[0, 2]])
        assert abs(ev.info[1] - info[1]) <= 1e-12 * max(np.abs(T).max(), 1.0)
        for got, ref in ((ev.T, T), (ev.R, R), (ev.JX, JX), (ev.Jp, Jp)):
            assert np.allclose(got, ref, rtol=0.0, atol=1e-12 * max(np.abs(ref).max(), 1e-300))
        slipping += bool((code != 0).any())
    assert slipping >= 2


def _last_of_full_passes(p, X, lam, passes):
    """(T, JX) after ``passes`` whole periods marched from the virgin state with derivatives, no shortcut
    (one contact, a load that does not separate, the parameter entering nothing but w)."""
    w, _, Fe, _, Nsamp, _, _ = p._inputs(lam)
    AK, AC, AM = p._lin
    nh, ns = p.nh, p.Ns
    law, b = p.contacts[0].law, p._Bm[0]
    U = X.reshape(nh, p.n) @ b
    u = p.E @ U
    a, da = np.zeros(law.state_size), np.zeros((law.state_size, nh))
    dx0 = np.zeros(nh)
    dx0[0] = 1.0
    law.init_jvp(law.params, float(U[0]), dx0, float(Nsamp[0, 0]), np.zeros(nh), a, da)
    b_, db_ = np.zeros_like(a), np.zeros_like(da)
    T, dT = np.empty(ns), np.empty((ns, nh))
    for _ in range(passes):
        for i in range(ns):
            dT_ = np.empty(nh)
            T[i] = law.step_jvp(law.params, a, da, b_, db_, u[i], p.E[i].copy(), Nsamp[0, i], np.zeros(nh), dT_)[0]
            dT[i] = dT_
            a, da, b_, db_ = b_, db_, a, da
    return T, AK + w * AC + w * w * AM + np.kron(p.P @ dT, np.outer(b, b))


@pytest.mark.parametrize("model,kw", [("jenkins", {}), ("discrete", {"n": 4}), ("iwan", {})])
def test_second_pass_checked_without_derivatives_is_the_periodic_one(model, kw):
    """Where the period marched without derivatives after the second pass repeats it (3 periods
    reported, the force periodic), the force and the Jacobian are those of the periodic march:
    equal, to rounding, to the last of five whole passes marched with derivatives."""
    s = System.paper_damper(eta=0.5, beta=2.0, model=model, zeta=0.01, **kw)
    p = HBProblem(s, harmonics=3, samples=32)
    X0 = p.linear_guess(1.1)
    rng = np.random.default_rng(11)
    checked = 0
    for scale in (0.5, 0.8, 1.0, 1.5, 2.0, 3.0, 5.0, 10.0):
        X = X0 * scale * (1.0 + 0.2 * rng.standard_normal(X0.size))
        ev = p.evaluate(X, 1.1)
        assert ev.info[2] == 1.0
        T, JX = _last_of_full_passes(p, X, 1.1, 5)
        assert np.allclose(ev.T[0], T, rtol=0.0, atol=1e-12 * np.abs(T).max())
        assert np.allclose(ev.JX, JX, rtol=0.0, atol=1e-12 * np.abs(JX).max())
        checked += ev.info[0] == 3.0
    # the exact Iwan law's first pass is a transient at the first two scales (the others
    # repeat within two passes, Jenkins and the 4-element model on their stored states)
    assert checked >= (2 if model == "iwan" else 0)
