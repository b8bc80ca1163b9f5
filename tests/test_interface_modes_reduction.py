"""Interfaces in the reduction and the nonlinear modes (issue 23): a Craig-Bampton reduction of a System
with interfaces keeps the pairs' DOFs (exact with every interior mode kept), QSMA refuses interfaces (in
Python and on the command line), and EPMC backbones with pairs."""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.interfaces import Interface
from jointdyn.reduction import default_boundary, reduce_system

from test_bad_input import no_compute, refused  # noqa: F401 (no_compute: a fixture)


def _beam(nodes=5, pair_nodes=(1, 3), preload=(0.4, 0.15)):
    """A chain of ``nodes`` nodes (t1, t2, n each) with springs between neighbours and to ground, node
    pairs against ground at ``pair_nodes`` (the other nodes' DOFs are interior), forced at node 0 along t1
    and t2 with 90 degrees between them."""
    n = 3 * nodes
    K = np.zeros((n, n))
    for i in range(nodes - 1):
        for d, kd in enumerate((2e3, 2.6e3, 4e3)):
            a, b = 3 * i + d, 3 * (i + 1) + d
            K[[a, b], [a, b]] += kd
            K[a, b] -= kd
            K[b, a] -= kd
    K[np.arange(n), np.arange(n)] += np.tile([300.0, 500.0, 800.0], nodes)
    table = np.full((len(pair_nodes), 6), -1)
    table[:, :3] = 3 * np.asarray(pair_nodes)[:, None] + np.arange(3)
    itf = Interface(kt=1.2e3, kn=2e3, mu=0.5, preload=list(preload), pairs=table)
    f = np.zeros(n)
    f[0], f[1] = 0.6, 0.4
    phase = np.zeros(n)
    phase[1] = 90.0
    return jd.System(M=0.5 * np.eye(n), C=0.02 * K, K=K, force=f, force_phase_deg=phase, interfaces=(itf,),
                     output_dof=0)


# --- reduction ------------------------------------------------------------------------------------------


def test_reduce_system_keeps_the_pairs_dofs_and_is_exact_with_every_interior_mode():
    s = _beam()
    b = default_boundary(s)
    assert set(b) == {0, 1, 3, 4, 5, 9, 10, 11}  # forced/output DOFs 0, 1 and the pairs' DOFs
    red, cb = reduce_system(s, s.ndof - len(b))
    itf = red.interfaces[0]
    assert cb.boundary[itf.pairs[itf.pairs >= 0]].tolist() == s.interfaces[0].pairs[:, :3].ravel().tolist()
    np.testing.assert_array_equal(itf.preload, s.interfaces[0].preload)
    # harmonic balance of the full and of the reduced model where both pairs stick and slip (2-D slip):
    # the same response, the same per-pair energies
    from jointdyn.hb import harmonic_balance

    full = harmonic_balance(s, 1.0, harmonics=3, samples=64, condense=False)
    part = harmonic_balance(red, 1.0, harmonics=3, samples=64, condense=False)
    assert full.status.ok and part.status.ok
    ef = full.problem.pair_results(full.X, full.problem.evaluate(full.X, full.problem.f1_ref))
    er = part.problem.pair_results(part.X, part.problem.evaluate(part.X, part.problem.f1_ref))
    assert np.all(ef["slip"] > 0.0) and np.min(ef["energy_J"]) > 0.0
    assert part.amplitude_m == pytest.approx(full.amplitude_m, rel=1e-8)
    np.testing.assert_allclose(er["energy_J"], ef["energy_J"], rtol=1e-7)


def test_reduce_system_refuses_a_boundary_without_the_pairs_dofs():
    s = _beam()
    with pytest.raises(ValueError, match=r"boundary_dofs must contain every DOF of the interfaces' node pairs, "
                                         r"missing \[9, 10, 11\]"):
        reduce_system(s, 2, boundary_dofs=[0, 1, 3, 4, 5])


# --- QSMA refuses interfaces ------------------------------------------------------------------------------


def test_qsma_refuses_interfaces_and_names_epmc():
    from jointdyn.modes import qsma

    with pytest.raises(ValueError, match=r"^system: has interfaces \(2 node pairs\), which QSMA does not support.*"
                                         r"use EPMC"):
        qsma(_beam())


SYSTEM = """\
[structure]
M = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
K = [[1e3, 0.0, 0.0], [0.0, 1e3, 0.0], [0.0, 0.0, 1e3]]

[[interface]]
kt = 1.5e3
kn = 1.5e3
mu = 0.5
preload = 0.5
pairs = [[0, 1, 2, -1, -1, -1]]
"""


def test_cli_modes_qsma_refuses_a_system_with_interfaces(no_compute, capsys, tmp_path):  # noqa: F811
    p = tmp_path / "itf.toml"
    p.write_text(SYSTEM)
    refused(capsys, tmp_path, ["modes", "--method", "qsma", "--system", p, "--out", tmp_path / "o"],
            "interfaces", "QSMA", "EPMC")


# --- EPMC backbones with pairs ----------------------------------------------------------------------------


def _chain(nodes: int, pairs: bool) -> jd.System:
    """The chain of benchmarks/bench_hb_interface_chain.py: nodes (t1, t2, n) joined along each direction,
    springs to ground, a node pair against ground at every node with a preload peaked in the middle; or
    (``pairs=False``) the same stuck structure with one Jenkins contact per node along t1 under a normal
    spring and the pair's stuck t2 stiffness as a spring to ground. Mode 1 moves along t1 only, where a
    pair at constant normal load is that Jenkins element: the two backbones are the same."""
    from jointdyn.kinematics import NormalSpring
    from jointdyn.laws.discrete import Jenkins

    n = 3 * nodes
    K = np.zeros((n, n))
    for i in range(nodes - 1):
        for d, kd in enumerate((1e5, 1.3e5, 2e5)):
            a, b = 3 * i + d, 3 * (i + 1) + d
            K[[a, b], [a, b]] += kd
            K[a, b] -= kd
            K[b, a] -= kd
    K[np.arange(n), np.arange(n)] += np.tile([1e3, 4e3, 1e3], nodes)
    P = 10.0 * (0.2 + np.exp(-((np.arange(nodes) - nodes / 2) / (nodes / 4)) ** 2))
    kw = dict(M=0.1 * np.eye(n), C=1e-4 * K, output_dof=0)
    if pairs:
        table = np.full((nodes, 6), -1)
        table[:, :3] = 3 * np.arange(nodes)[:, None] + np.arange(3)
        return jd.System(K=K, **kw, interfaces=(Interface(kt=2e4, kn=5e4, mu=0.5, preload=P, pairs=table),))
    cs = tuple(jd.Contact(Jenkins(kt=2e4, mu=0.5, n_ref=float(p)), dof=3 * i,
                          normal=NormalSpring(kn=5e4, preload=float(p), dof=3 * i + 2)) for i, p in enumerate(P))
    return jd.System(K=K + np.diag(np.tile([0.0, 2e4, 0.0], nodes)), **kw, contacts=cs)


def test_epmc_backbone_of_a_chain_of_pairs_is_that_of_jenkins_contacts_and_goes_from_stuck_to_slipped():
    from jointdyn.modes import epmc

    a = 10.0 * 0.5 / 2e4  # mu P / kt of a pair at the preload 10 N, m
    amp = (0.02 * a, 10.0 * a)
    bp = epmc(_chain(4, True), amp, harmonics=3, samples=64, progress=False)
    bc = epmc(_chain(4, False), amp, harmonics=3, samples=64, progress=False)
    assert bp.status.ok and bc.status.ok, (bp.message, bc.message)
    assert bp.points == bc.points
    for f in ("amplitude_m", "omega_rad_s", "damping_ratio"):
        np.testing.assert_allclose(getattr(bp, f), getattr(bc, f), rtol=1e-8, err_msg=f)
    # the t2 and normal DOFs stay at rest: mode 1 moves along t1 only
    X = bp.X.reshape(bp.points, -1, 12)
    assert np.max(np.abs(X[:, :, 1::3])) + np.max(np.abs(X[:, :, 2::3])) <= 1e-12 * np.max(np.abs(X[:, :, 0::3]))
    # small amplitude: the linear stuck mode (ground 1e3 + kt 2e4 N/m on 0.1 kg per node, uniform) and its viscous
    # damping (C = 1e-4 K: xi = 1e-4 * 1e3 / 0.1 = 1 1/s); large: towards the slipped structure's 100 rad/s
    w_stuck = np.sqrt(2.1e4 / 0.1)
    assert bp.omega_rad_s[0] == pytest.approx(w_stuck, rel=1e-9)
    assert bp.damping_ratio[0] == pytest.approx(1.0 / (2.0 * w_stuck), rel=1e-6)
    assert 100.0 < bp.omega_rad_s[-1] < 0.5 * w_stuck
    assert np.max(bp.damping_ratio) > 0.1  # the pairs slip and dissipate


def test_epmc_on_a_reduction_keeps_the_pairs_and_with_every_interior_mode_is_the_full_backbone():
    from jointdyn.modes import epmc

    s = _beam()
    amp = (1e-5, 1e-3)
    full = epmc(s, amp, harmonics=2, samples=32, progress=False)
    red = epmc(s, amp, harmonics=2, samples=32, progress=False, reduce=s.ndof - len(default_boundary(s)))
    assert full.status.ok and red.status.ok and red.system.interfaces[0].npairs == 2
    # the two walks step differently (other coordinates); both land exactly on the ends of the range
    assert red.amplitude_m[[0, -1]] == pytest.approx(full.amplitude_m[[0, -1]], rel=1e-12)
    np.testing.assert_allclose(red.omega_rad_s[[0, -1]], full.omega_rad_s[[0, -1]], rtol=1e-8)
    np.testing.assert_allclose(red.damping_ratio[[0, -1]], full.damping_ratio[[0, -1]], rtol=1e-6)
    assert np.max(full.damping_ratio_contacts) > 0.01  # the pairs slip
