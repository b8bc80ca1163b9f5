"""Harmonic balance of systems with interfaces (docs/model.md section 10): the AFT of the node pairs
(jointdyn.hb._aft_pairs) against finite differences, the linear limits (all stuck, all open) and the
exact 1-D reduction to the discrete Iwan law under the same normal spring."""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.hb import branch as hb_branch
from jointdyn.hb import HBOptions
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
    ev = q.evaluate(X, gamma)
    assert np.all(ev.pair_code == STICK_SLIP)
    res = q.pair_results(X, ev)  # stuck all period: no dissipation (to rounding of the loop's area)
    assert res["stick"].tolist() == [1.0, 1.0] and np.all(np.abs(res["energy_J"]) < 1e-12 * 5.0 * np.max(np.abs(X)))
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
    ev = q.evaluate(X, 1.1)
    assert np.all(ev.pair_code == SEPARATION)
    res = q.pair_results(X, ev)
    assert res["open"].tolist() == [1.0, 1.0] and np.all(res["energy_J"] == 0.0)
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


# --- branches, stability, nonlinear modes and the command line ---------------------------------------


def _energy_balance(q, X, p, ev):
    """(input, viscous, pairs' dissipation, normal work by quadrature) per cycle, J, at a solution."""
    from jointdyn.fourier import derivative_matrix

    w = q.omega(p)
    Xm = X.reshape(q.nh, q.n)
    DX = derivative_matrix(q.H) @ Xm
    f = q.parameter.forcing(q, p)[0]
    e_in = np.pi * float(f * q.phase_sin @ Xm[2] - f * q.phase_cos @ Xm[1])
    e_visc = w * np.pi * float(np.einsum("ri,ij,rj->", DX, q.system.C, DX))
    pairs = q.pair_results(X, ev)
    dg = q.E @ DX
    g = np.stack([sum(s * dg[:, q.pair_positions[i, c]] for c, s in ((2, 1.0), (5, -1.0))
                      if q.pair_positions[i, c] >= 0) for i in range(q.pair_positions.shape[0])])
    e_n = float(np.sum((ev.pair_N - q.pair_params[:, 3:4]) * g)) * 2.0 * np.pi / q.Ns
    return e_in, e_visc, float(np.sum(pairs["energy_J"])), e_n, pairs


def test_branch_with_interfaces_balances_energy_and_condenses_exactly():
    s = _system(_patch(), force=(0.5, 0.25, 0.0, 0.0))
    from jointdyn.hb import continue_hb

    br = continue_hb(s, 0.6, 1.6, harmonics=3, samples=64, condense=False)
    assert br.status == "complete" and br.lam.size >= 10
    assert np.all(np.isfinite(br.growth)) and np.all(br.stable)
    q = br.problem
    i = int(np.argmax(br.response()[0]))  # near the resonance
    X, p = br.X[i], br.lam[i]
    ev = q.evaluate(X, p)
    e_in, e_visc, e_pairs, e_n, pairs = _energy_balance(q, X, p, ev)
    assert e_pairs > 0.01 * e_in  # the pairs slip
    assert abs(e_in - e_visc - e_pairs - e_n) <= 1e-8 * e_in
    np.testing.assert_allclose(pairs["stick"] + pairs["slip"] + pairs["open"], 1.0, rtol=0, atol=1e-12)
    # the slip map's data in the branch's Dataset, per point and pair
    from jointdyn.hb import branch_dataset

    ds = branch_dataset(br)
    assert ds["pair_energy_J"].dims == ("point", "pair") and ds.sizes["pair"] == 2
    np.testing.assert_allclose(ds["pair_energy_J"].values[i], pairs["energy_J"], rtol=1e-12, atol=0)
    frac = sum(ds[f"pair_{k}_fraction"].values for k in ("stick", "slip", "open"))
    np.testing.assert_allclose(frac, 1.0, rtol=0, atol=1e-12)
    assert np.all(ds["pair_energy_J"].values >= -1e-12 * e_in)
    # the problem condensed onto the pairs' DOFs (and the response DOF) has the same solution
    from jointdyn.hb.condense import make_problem

    qc = make_problem(s, condense=True, harmonics=3, samples=64, response_dofs=(br.response_dof,))
    assert qc.condensed and set(np.unique(_patch().pairs[_patch().pairs >= 0])) <= set(qc.dofs.tolist())
    Xc = _newton(qc, p, qc.full_coefficients(X, p).reshape(q.nh, q.n)[:, qc.dofs].ravel())
    np.testing.assert_allclose(qc.full_coefficients(Xc, p), X, rtol=0, atol=1e-9 * np.max(np.abs(X)))


def test_epmc_backbone_with_interfaces_balances_energy():
    from jointdyn.modes import epmc

    s = jd.System(M=M4, C=0.05 * M4, K=K4, interfaces=(_patch(),))  # C = c M: xi M cancels it exactly
    bb = epmc(s, harmonics=3, samples=64)
    assert bb.status.ok and bb.points >= 20
    np.testing.assert_allclose(bb.damping_ratio, bb.damping_ratio_contacts + bb.damping_ratio_viscous,
                               rtol=1e-6, atol=0)
    assert bb.pair_energy_J.shape == (bb.points, 2) and np.max(bb.pair_energy_J[-1]) > 0.0
    # small amplitude: the linear stuck mode with the pairs' springs
    assert bb.omega_rad_s[0] == pytest.approx(bb.linear.omega_rad_s, rel=1e-9)
    from jointdyn.modes.backbone import backbone_dataset

    assert backbone_dataset(bb)["pair_energy_J"].dims == ("point", "pair")


SYSTEM = """\
[structure]
M = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 2.0]]
K = [[1e3, 0.0, 0.0, -200.0], [0.0, 1.2e3, 0.0, 0.0], [0.0, 0.0, 2e3, 0.0], [-200.0, 0.0, 0.0, 4e3]]
C = [[10.0, 0.0, 0.0, -2.0], [0.0, 12.0, 0.0, 0.0], [0.0, 0.0, 20.0, 0.0], [-2.0, 0.0, 0.0, 40.0]]

[[force]]
dof = 0
amplitude = 0.2

[[contact]]
law = "jenkins"
kt = 1e3
mu = 0.3
tangential = { dof = 3 }
normal = { n0 = 1.0 }

[[interface]]
kt = [1.5e3, 800.0]
kn = [1.5e3, 3e3]
mu = 0.5
preload = [0.5, 0.2]
pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]
"""


def test_command_line_hb_and_modes_take_interfaces(tmp_path, capsys):
    import json

    from jointdyn.cli import main

    p = tmp_path / "sys.toml"
    p.write_text(SYSTEM)
    rc = main(["frc", "--method", "hb", "--system", str(p), "--gamma", "0.8:1.2:0.1", "--harmonics", "3",
               "--samples", "32", "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["status"] == "complete"
    rc = main(["modes", "--system", str(p), "--harmonics", "3", "--samples", "32", "--amplitude", "1e-6:1e-4",
               "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["status"] == "complete"


def test_branch_keeps_no_jacobian_beyond_its_budget():
    """With no room for Jacobians, the points are evaluated again one by one for Hill's method: the same
    branch, the same stability."""
    from jointdyn.hb import continue_hb

    s = _system(_patch(), force=(0.5, 0.25, 0.0, 0.0))
    a = continue_hb(s, 0.8, 1.2, harmonics=2, samples=32, condense=False)
    b = continue_hb(s, 0.8, 1.2, harmonics=2, samples=32, condense=False,
                    hb_options=HBOptions(jacobian_budget_bytes=1))
    np.testing.assert_array_equal(a.lam, b.lam)
    np.testing.assert_array_equal(a.growth, b.growth)
    np.testing.assert_array_equal(a.stable, b.stable)
    np.testing.assert_array_equal(a.passes, b.passes)



def test_marginal_hill_growth_with_interfaces_keeps_hills_criterion():
    """A growth in the band where contacts are confirmed by the time-domain period map: that map does not
    march interfaces, so a system with interfaces keeps Hill's criterion (no monodromy check)."""
    from jointdyn.hb import StabilityOptions
    from jointdyn.hb.floquet import confirmed_stability

    opt = StabilityOptions()
    q = HBProblem(_system(_patch()), harmonics=2, samples=32)
    X = np.zeros((2, q.size))
    growth = np.array([0.5 * opt.rtol, 0.5 * (opt.rtol + opt.confirm)])
    stable, checked = confirmed_stability(q, X, np.array([1.0, 1.0]), growth, opt)
    assert stable.tolist() == [True, False] and checked == 0
