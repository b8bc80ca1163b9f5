"""Parts held only through their joint: harmonic balance and EPMC restart the laws at the reference.

A structure whose K (with the normal springs closed, the tangential contacts free) has a rigid-body
mode, while the stuck structure has none, is held by the preloaded static state: harmonic balance
restarts every law (and every interface pair) virgin at the reference displacement, so that a stuck
contact's force is kt u and its mean holds the part. The oracles: the linear FRF of the stuck structure
(a stuck Jenkins contact and stuck pairs are exactly linear), the periodic steady state of the time
domain started from rest at the reference, and the stuck linear mode at small amplitude.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.hb import check_mean_position, harmonic_balance
from jointdyn.hb.condense import use_condensed
from jointdyn.hb.problem import HBProblem, held_by_contacts, stuck_stiffness
from jointdyn.interfaces import Interface

KT, MU, N0 = 2.0e4, 0.5, 10.0  # fy / kt = 2.5e-4 m
M2 = np.diag([1.0, 0.5])
K2 = np.array([[1.0e4, 0.0], [0.0, 0.0]])  # DOF 1 hangs on DOF 0 through the contact only


def _hanging(law: str, f0: float, C=None) -> jd.System:
    """DOF 0 on a spring to ground, DOF 1 held only by a contact between DOF 0 and DOF 1, forced at DOF 0."""
    return jd.System(M2, C, K2, contacts=(jd.Contact(jd.make_law(law, kt=KT, mu=MU, n_ref=N0), dof=0, dof2=1,
                                                     normal=jd.ConstantLoad(N0)),), force=np.array([f0, 0.0]))


def _stuck_frf(system: jd.System, w: float) -> np.ndarray:
    """First-harmonic complex amplitudes a - i b (m) of the stuck linear structure forced by f sin(w t)."""
    C = np.zeros_like(system.M) if system.C is None else np.asarray(system.C)
    A = stuck_stiffness(system) - w * w * system.M + 1j * w * C
    return np.linalg.solve(A, -1j * system.force)


def test_only_a_structure_held_through_its_contacts_restarts_at_the_reference():
    held = _hanging("jenkins", 1e-3)
    assert held_by_contacts(held) and HBProblem(held, harmonics=1, samples=8).restart_at_reference
    grounded = jd.System(M2, None, K2 + np.diag([0.0, 1e2]), contacts=held.contacts, force=held.force)
    assert not held_by_contacts(grounded) and not HBProblem(grounded, harmonics=1, samples=8).restart_at_reference
    # a structure held through its contacts is never condensed (its K has a rigid-body mode)
    assert not use_condensed(held)
    with pytest.raises(ValueError, match="condense: the structure is held only through its contacts"):
        use_condensed(held, True)


@pytest.mark.parametrize("gamma", [0.5, 0.9, 1.3])
def test_stuck_jenkins_hanging_part_equals_the_stuck_linear_frf(gamma):
    """(1) At a forcing that keeps the contact stuck, the response is the stuck structure's, to rounding."""
    s = _hanging("jenkins", 1e-3, C=np.diag([2.0, 0.0]))
    sol = harmonic_balance(s, gamma, harmonics=3, samples=64)
    assert sol.status.ok
    X = sol.X.reshape(7, 2)
    z = _stuck_frf(s, gamma * s.w0)
    np.testing.assert_allclose(X[1] - 1j * X[2], z, rtol=1e-8, atol=1e-8 * np.abs(z).max())
    # no mean and no higher harmonics: the stuck contact is a linear spring about the reference
    assert np.abs(X[0]).max() <= 1e-12 * np.abs(z).max() and np.abs(X[3:]).max() <= 1e-8 * np.abs(z).max()
    # the contact holds the static block: its Jacobian there is K + kt, not K
    ev = sol.problem.evaluate(sol.X, sol.problem.f1_ref)
    np.testing.assert_allclose(ev.JX[:2, :2], stuck_stiffness(s), rtol=1e-12)


def test_microslip_of_a_hanging_part_equals_the_time_domain_started_from_rest():
    """(2) Iwan contact in microslip (it slips over part of the cycle, never as a whole): the HB response
    equals the periodic steady state of the time march started from rest at the reference."""
    C = np.diag([4.0, 0.0]) + 0.002 * KT * np.array([[1.0, -1.0], [-1.0, 1.0]])
    s = _hanging("iwan", 2.0, C=C)
    gamma = 0.7
    sol = harmonic_balance(s, gamma, harmonics=7, samples=256, response_dof=1)
    assert sol.status.ok
    X = sol.X.reshape(-1, 2)
    rel = X[:, 0] - X[:, 1]
    q = math.hypot(rel[1], rel[2]) * KT / (MU * N0)
    assert 0.2 < q < 0.9  # a relative amplitude in microslip: part of the sliders slip
    ev = sol.problem.evaluate(sol.X, sol.problem.f1_ref)
    assert np.abs(ev.T).max() < MU * N0 * (1.0 - 1e-3)  # never slipping as a whole
    ss = jd.steady_state(s, gamma, start=jd.integrate(s, gamma, periods=1).final, response_dof=1)
    assert ss.status.ok
    assert sol.amplitude_m == pytest.approx(ss.amplitude_m, rel=1e-4)
    assert abs(sol.offset_m - ss.offset_m) <= 1e-3 * ss.amplitude_m


def test_epmc_backbone_of_a_hanging_part_through_microslip():
    """(3) The relative mode of the hanging part: its frequency starts at the stuck linear mode and falls
    through microslip, the damping rises."""
    from scipy.linalg import eigh

    from jointdyn.modes import epmc

    s = jd.System(M2, None, K2, contacts=_hanging("iwan", 0.0).contacts)
    w_lin = math.sqrt(eigh(stuck_stiffness(s), M2, eigvals_only=True)[1])
    scale = MU * N0 / KT
    b = epmc(s, (1e-3 * scale, 0.8 * scale), mode=2, output_dof=1, harmonics=3, samples=64, progress=False)
    assert b.status.ok
    w = np.asarray(b.omega_rad_s)
    # Iwan softens in proportion to the amplitude at small amplitude: |w / w_lin - 1| = O(q)
    assert abs(w[0] / w_lin - 1.0) < 0.5 * b.amplitude_m[0] / scale
    assert w[-1] < 0.9 * w_lin and np.all(np.diff(w) < 0.0)
    assert b.damping_ratio[-1] > 10.0 * b.damping_ratio[0] > 0.0
    # beyond microslip the part slides as a whole: the backbone ends there and says why
    end = epmc(s, (0.5 * scale, 3.0 * scale), mode=2, output_dof=1, harmonics=3, samples=64, progress=False)
    assert not end.status.ok and "slides as a whole" in end.message
    # a stuck Jenkins contact: the backbone's start is the stuck mode to rounding
    j = jd.System(M2, None, K2, contacts=_hanging("jenkins", 0.0).contacts)
    bj = epmc(j, (1e-3 * scale, 1e-2 * scale), mode=2, output_dof=1, harmonics=3, samples=64, progress=False)
    assert bj.status.ok
    np.testing.assert_allclose(bj.omega_rad_s, w_lin, rtol=1e-9)


def test_a_dof_held_by_nothing_is_still_refused():
    """(4) DOF 2 is held by nothing, not even with the contact stuck: harmonic balance and EPMC refuse it."""
    from jointdyn.modes import epmc

    s = jd.System(np.diag([1.0, 0.5, 0.3]), None, np.diag([1e4, 0.0, 0.0]),
                  contacts=_hanging("jenkins", 1e-3).contacts, force=np.array([1e-3, 0.0, 0.0]))
    with pytest.raises(ValueError, match="mostly DOF 2: held by nothing"):
        check_mean_position(s)
    with pytest.raises(ValueError, match="positive definite with every contact stuck"):
        epmc(s, progress=False)


def _two_parts(preload: float = 50.0) -> jd.System:
    """Part A (nodes 0, 1: DOFs 0-5) on springs to ground, part B (nodes 2, 3: DOFs 6-11) joined to it by
    two node pairs (A node i on B node i) and held only by them."""
    n = 12
    K = np.zeros((n, n))
    for d in range(6):  # part A: every DOF on a spring to ground, the two nodes coupled
        K[d, d] += 4.0e4
    for a, b, k in [(d, d + 3, 1.0e4) for d in range(3)] + [(d, d + 3, 2.0e4) for d in range(6, 9)]:
        K[np.ix_([a, b], [a, b])] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])  # A's and B's inner springs
    M = np.diag([1.0] * 6 + [0.4] * 6)
    pairs = [[0, 1, 2, 6, 7, 8], [3, 4, 5, 9, 10, 11]]
    itf = Interface(kt=[1.5e4, 1.0e4], kn=[3.0e4, 2.0e4], mu=0.5, preload=preload, pairs=pairs)
    f = np.zeros(n)
    f[0], f[4] = 1e-3, 5e-4
    return jd.System(M, 0.01 * np.eye(n) @ K + 0.5 * M, K, interfaces=(itf,), force=f)


def test_part_held_only_by_stuck_pairs_equals_the_stuck_linear_frf():
    """(5) Two parts joined by node pairs, one held only by them: at small amplitude every pair sticks and
    the response is the stuck linear structure's."""
    s = _two_parts()
    assert held_by_contacts(s)
    for gamma in (0.6, 1.1):
        sol = harmonic_balance(s, gamma, harmonics=3, samples=64)
        assert sol.status.ok and sol.problem.restart_at_reference
        X = sol.X.reshape(7, 12)
        z = _stuck_frf(s, gamma * s.w0)
        np.testing.assert_allclose(X[1] - 1j * X[2], z, rtol=1e-8, atol=1e-8 * np.abs(z).max())
        assert np.abs(X[0]).max() <= 1e-10 * np.abs(z).max()


def test_qsma_of_a_part_held_only_through_its_contacts_goes_through_macroslip():
    """QSMA pushes the hanging part while its contact holds it, and on through macroslip (the load held at the
    slip force, the prescribed displacement carrying the part). Oracle: the same structure grounded by ever
    softer springs converges to it, in proportion."""
    from jointdyn.modes import qsma

    s = jd.System(M2, None, K2, contacts=_hanging("iwan", 0.0).contacts)
    scale = MU * N0 / KT
    b = qsma(s, (1e-3 * scale, 30.0 * scale), mode=2, output_dof=1)
    assert b.status.ok
    w = np.asarray(b.omega_rad_s)
    x = b.X[:, 2:4]
    assert abs(x[-1, 0] - x[-1, 1]) > 10.0 * scale and w[-1] < 0.3 * w[0]  # the part slides
    errors = []
    for ground in (1e1, 1e0, 1e-1):
        g = jd.System(M2, None, K2 + np.diag([0.0, ground]), contacts=s.contacts)
        bg = qsma(g, (1e-3 * scale, 30.0 * scale), mode=2, output_dof=1)
        assert bg.status.ok
        errors.append(np.max(np.abs(np.asarray(bg.omega_rad_s) / w - 1.0)))
    assert errors[2] < 1e-3 and 5.0 < errors[0] / errors[1] < 20.0 and 5.0 < errors[1] / errors[2] < 20.0


def test_a_part_sliding_as_a_whole_is_named_where_newton_fails():
    """A Jenkins contact that slips every cycle resists no shift of the hanging part: its mean is not unique
    and Newton fails; the solution's and the branch's messages say why. Where it sticks, nothing is said."""
    from jointdyn.hb import continue_hb
    from jointdyn.hb.results import sliding_as_a_whole

    C = np.diag([2.0, 0.0])
    sol = harmonic_balance(_hanging("jenkins", 50.0, C=C), 1.3, harmonics=3, samples=64)
    assert not sol.status.ok and "slides as a whole" in sol.message and "mostly DOF 1" in sol.message
    stuck = harmonic_balance(_hanging("jenkins", 1.0, C=C), 1.3, harmonics=3, samples=64)
    assert stuck.status.ok and "slides as a whole" not in stuck.message
    assert sliding_as_a_whole(stuck.problem, stuck.problem.evaluate(stuck.X, stuck.problem.f1_ref).JX) == ""
    br = continue_hb(_hanging("jenkins", 5.0, C=C), 0.5, 1.5, harmonics=3, samples=64, progress=False)
    assert not br.status.ok and "slides as a whole" in br.message
