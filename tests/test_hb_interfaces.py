"""Harmonic balance of systems with interfaces (docs/model.md section 10): the AFT of the node pairs
(jointdyn.hb._aft_pairs) against finite differences, the linear limits (all stuck, all open) and the
exact 1-D reduction to the discrete Iwan law under the same normal spring."""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.hb.problem import HBProblem
from jointdyn.interfaces import Interface
from jointdyn.kinematics import NormalSpring
from jointdyn.laws._base import MACROSLIP, SEPARATION, STICK_SLIP
from jointdyn.laws.discrete import DiscreteIwan

M4 = np.diag([1.0, 1.0, 1.0, 2.0])
K4 = np.diag([1e3, 1.2e3, 2e3, 4e3])
K4[0, 3] = K4[3, 0] = -200.0


def _system(interface, contacts=(), K=K4, force=(0.1, 0.05, 0.0, 0.0)):
    return jd.System(M=M4, C=0.01 * K, K=K, contacts=contacts, force=list(force),
                     force_phase_deg=[0.0, 90.0, 0.0, 0.0], interfaces=(interface,) if interface else ())


def _patch(mu=0.5, preload=(0.5, 0.2)):
    return Interface(kt=[1.5e3, 800.0], kn=[1.5e3, 3e3], mu=mu, preload=list(preload),
                     pairs=[[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]])


def _fd_jacobian(q, X, p, h):
    J = np.empty((q.size, q.size))
    for j in range(q.size):
        e = np.zeros(q.size)
        e[j] = h
        J[:, j] = (q.evaluate(X + e, p).R - q.evaluate(X - e, p).R) / (2.0 * h)
    return J


@pytest.mark.parametrize("scale", [2e-5, 4e-4])
def test_jacobian_matches_finite_differences_through_stick_slip_and_separation(scale):
    q = HBProblem(_system(_patch()), harmonics=3, samples=64)
    X = np.random.default_rng(1).normal(size=q.size) * scale
    ev = q.evaluate(X, 1.0)
    if scale > 1e-4:  # the large orbit sticks, slips and opens within the period
        assert {STICK_SLIP, MACROSLIP, SEPARATION} <= set(np.unique(ev.pair_code).tolist())
    Jfd = _fd_jacobian(q, X, 1.0, 1e-9 * scale / 4e-4)
    assert np.max(np.abs(ev.JX - Jfd)) <= 1e-7 * np.max(np.abs(ev.JX))
    assert ev.info[2] == 1.0  # the periodic slider was reached


def test_mixed_with_a_scalar_contact():
    c = jd.Contact(DiscreteIwan(kt=900.0, mu=0.4, n_ref=0.3, n=4), dof=3, normal=NormalSpring(kn=2e3, preload=0.3, dof=2))
    q = HBProblem(_system(_patch(), contacts=(c,)), harmonics=2, samples=32)
    X = np.random.default_rng(2).normal(size=q.size) * 2e-4
    ev = q.evaluate(X, 1.0)
    assert np.max(np.abs(ev.JX - _fd_jacobian(q, X, 1.0, 5e-10))) <= 1e-7 * np.max(np.abs(ev.JX))


def _newton(q, p, X):
    for _ in range(20):
        ev = q.evaluate(X, p)
        dX = np.linalg.solve(ev.JX, ev.R)
        X = X - dX
        if np.max(np.abs(dX)) <= 1e-15 * max(np.max(np.abs(X)), 1e-300):
            break
    return X


def _frf(K, gamma_w, f, phase_deg):
    """Complex first harmonic a - i b of the linear structure (M4, 0.01 K4 damping, stiffness K)."""
    w = gamma_w
    Z = K - w * w * M4 + 1j * w * (0.01 * K4)
    ph = np.radians(phase_deg)
    F = np.asarray(f) * (np.sin(ph) - 1j * np.cos(ph))
    return np.linalg.solve(Z, F)


def _pair_springs(interface, stuck=True):
    B = interface.selection(4)
    d = np.tile([interface.kt[0], interface.kt[0], interface.kn[0]], interface.npairs)
    d[0::3], d[1::3], d[2::3] = interface.kt, interface.kt, interface.kn
    if not stuck:
        d[0::3] = d[1::3] = 0.0
    return B.T @ np.diag(d) @ B


@pytest.mark.parametrize("gamma", [0.7, 1.3])
def test_all_stuck_is_the_linear_structure_with_the_pair_springs(gamma):
    itf = _patch(mu=1e3, preload=(5.0, 5.0))  # slip forces far above the forces of a 1e-3 N forcing
    f = (1e-3, 5e-4, 0.0, 0.0)
    q = HBProblem(_system(itf, force=f), harmonics=3, samples=32)
    X = _newton(q, gamma, q.linear_guess(gamma))
    assert np.all(q.evaluate(X, gamma).pair_code == STICK_SLIP)
    w = gamma * q.w0
    x = _frf(K4 + _pair_springs(itf), w, f, [0.0, 90.0, 0.0, 0.0])
    got = X[4:8] - 1j * X[8:12]
    assert np.max(np.abs(got - x)) <= 1e-9 * np.max(np.abs(x))
    assert np.max(np.abs(X[12:])) <= 1e-9 * np.max(np.abs(x))  # no higher harmonics


def test_all_open_is_the_structure_without_the_pairs():
    # no preload and no normal DOF: N = max(0, 0) = 0 at every sample, the pairs never touch
    itf = Interface(kt=1.5e3, kn=1e3, mu=0.5, preload=0.0, pairs=[[0, 1, -1, -1, -1, -1], [3, -1, -1, 0, -1, -1]])
    f = (0.1, 0.05, 0.0, 0.0)
    q = HBProblem(_system(itf, force=f), harmonics=3, samples=32)
    X = _newton(q, 1.1, q.linear_guess(1.1, stuck=False))
    assert np.all(q.evaluate(X, 1.1).pair_code == SEPARATION)
    x = _frf(K4, 1.1 * q.w0, f, [0.0, 90.0, 0.0, 0.0])
    got = X[4:8] - 1j * X[8:12]
    assert np.max(np.abs(got - x)) <= 1e-9 * np.max(np.abs(x))


def test_one_dimensional_patch_is_the_discrete_iwan_law_under_the_same_normal_spring():
    # pairs moving along t1 only, P_i = P f_i and kn_i = kn f_i: the patch is the discrete Iwan law (n
    # Jenkins elements kt / n with slip forces mu N f_i) under the normal spring (kn, P)
    n, kt, kn, mu, P = 5, 1.2e3, 2e3, 0.4, 0.6
    f = 2.0 * (np.arange(n) + 0.5) / n**2
    itf = Interface(kt=kt / n, kn=kn * f, mu=mu, preload=P * f, pairs=[[0, -1, 1, -1, -1, -1]] * n)
    law = jd.Contact(DiscreteIwan(kt=kt, mu=mu, n_ref=P, n=n), dof=0, normal=NormalSpring(kn=kn, preload=P, dof=1))
    M, K = np.diag([1.0, 1.5]), np.diag([1e3, 3e3])
    kw = dict(M=M, C=0.01 * K, K=K, force=[0.1, 0.2], force_phase_deg=[0.0, 60.0])
    qp = HBProblem(jd.System(**kw, interfaces=(itf,)), harmonics=3, samples=64)
    ql = HBProblem(jd.System(**kw, contacts=(law,)), harmonics=3, samples=64)
    rng = np.random.default_rng(3)
    for scale in (1e-5, 2e-4, 1e-3):
        X = rng.normal(size=qp.size) * scale
        X[1::2] *= 0.05  # the normal DOF moves less than the opening displacement P / kn = 3e-4 m
        a, b = qp.evaluate(X, 1.0), ql.evaluate(X, 1.0)
        assert np.all(a.pair_N > 0.0)
        np.testing.assert_allclose(a.R, b.R, rtol=0, atol=1e-12 * np.max(np.abs(b.R)))
        np.testing.assert_allclose(a.JX, b.JX, rtol=0, atol=1e-11 * np.max(np.abs(b.JX)))
        np.testing.assert_allclose(a.pair_T[:, :, 0].sum(axis=0), b.T[0], rtol=0, atol=1e-12 * mu * P)


def test_systems_without_interfaces_evaluate_no_pairs():
    q = HBProblem(_system(None), harmonics=1, samples=8)
    assert not q.has_interfaces
    assert q.evaluate(np.zeros(q.size), 1.0).pair_T is None
