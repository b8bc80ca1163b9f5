"""Free-free assemblies: structures held by nothing, whose stuck stiffness has rigid-body modes.

Harmonic balance gauges the rigid-body part of the mean at zero (harmonic 0 alone), keeps the free-mass
response at the harmonics k >= 1; EPMC counts the elastic modes; the time domain starts the rigid-body part
in the free body's periodic motion. The oracles: the linear free-free FRF (a direct complex solve, and the
modal sum with the rigid-body mass line), the same structure grounded by ever softer springs, the fully
slipping limit (the structure without its contact), the first elastic mode, and the energy balance.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.linalg import eigh

import jointdyn as jd
from jointdyn.cli import main
from jointdyn.fourier import derivative_matrix
from jointdyn.hb import harmonic_balance
from jointdyn.hb.condense import use_condensed
from jointdyn.hb.problem import HBProblem, held_by_contacts, mean_gauge
from jointdyn.systems import free_modes, stuck_stiffness

KT, MU, N0 = 2.0e4, 0.5, 10.0  # fy = 5 N
M4 = np.diag([1.0, 1.0, 0.5, 0.5])


def _spring(n, a, b, k):
    K = np.zeros((n, n))
    K[np.ix_([a, b], [a, b])] = k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return K


K4 = _spring(4, 0, 1, 1.0e4) + _spring(4, 2, 3, 2.0e4)  # part A: DOFs 0, 1; part B: DOFs 2, 3


def _chain(law="jenkins", f=0.1, ground=0.0, n0=N0, w0=None, beta=2e-4):
    """Two free parts (0-1 and 2-3) joined by a contact between DOFs 1 and 2, forced at DOF 0; nothing holds
    the whole (``ground`` > 0: soft springs to ground at DOFs 0 and 3). C = beta K_stuck (C Phi_r = 0)."""
    K = K4 + ground * np.diag([1.0, 0.0, 0.0, 1.0])
    c = jd.Contact(jd.make_law(law, kt=KT, mu=MU, n_ref=N0), dof=1, dof2=2, normal=jd.ConstantLoad(n0))
    Ks = K4.copy()
    Ks[np.ix_([1, 2], [1, 2])] += KT * np.array([[1.0, -1.0], [-1.0, 1.0]])
    return jd.System(M4, beta * Ks, K, contacts=(c,), force=np.array([f, 0.0, 0.0, 0.0]), w0_rad_s=w0)


def _body(n0=N0, f=0.5):
    """One free elastic body (springs 0-1-2) with an inner friction contact between DOFs 0 and 2."""
    M = np.diag([1.0, 0.7, 0.4])
    K = _spring(3, 0, 1, 1.0e4) + _spring(3, 1, 2, 1.5e4)
    c = jd.Contact(jd.make_law("jenkins", kt=KT, mu=MU, n_ref=N0), dof=0, dof2=2, normal=jd.ConstantLoad(n0))
    return jd.System(M, 1e-4 * K + 5e-5 * _spring(3, 0, 2, KT), K, contacts=(c,), force=np.array([f, 0.0, 0.0]))


def _frf(system, w, K=None):
    """First-harmonic complex amplitudes a - i b (m) of the linear structure (stiffness K, default the stuck
    one) forced by f sin(w t): a direct solve, nonsingular at w > 0 (the rigid-body modes as free masses)."""
    K = stuck_stiffness(system) if K is None else K
    return np.linalg.solve(K - w * w * system.M + 1j * w * np.asarray(system.C), -1j * system.force)


def _first(X, n):
    X = np.asarray(X).reshape(-1, n)
    return X[1] - 1j * X[2]


def test_the_rigid_body_modes_of_a_free_free_assembly():
    s = _chain()
    phi = free_modes(s)
    assert phi.shape == (4, 1)
    np.testing.assert_allclose(phi.T @ s.M @ phi, np.eye(1), atol=1e-14)
    np.testing.assert_allclose(np.abs(phi[:, 0]), 1.0 / math.sqrt(3.0), rtol=1e-12)  # 1 / sqrt(total mass)
    # the parts are also held through their contact (freed, each part has its own rigid-body mode)
    assert held_by_contacts(s) and not held_by_contacts(_body())
    assert free_modes(_body()).shape == (3, 1)
    grounded = _chain(ground=1e2)
    assert free_modes(grounded).shape == (4, 0) and mean_gauge(grounded, grounded.w0) is None
    G = mean_gauge(s, s.w0)
    np.testing.assert_allclose(G @ phi, s.w0 ** 2 * (s.M @ phi), rtol=1e-12)  # s M Phi on the rigid mode


@pytest.mark.parametrize("gamma", [0.4, 0.9, 1.7])
def test_hb_of_a_stuck_free_free_assembly_equals_the_free_free_frf(gamma):
    """(1) Stuck joint: the response is the linear free-free FRF, whose drive point carries the rigid-body
    mass line -1 / (m_total w^2); the mean is zero (gauged), the higher harmonics vanish."""
    s = _chain()
    sol = harmonic_balance(s, gamma, harmonics=3, samples=64)
    assert sol.status.ok
    w = gamma * s.w0
    z = _frf(s, w)
    np.testing.assert_allclose(_first(sol.X, 4), z, rtol=1e-8, atol=1e-8 * np.abs(z).max())
    X = sol.X.reshape(7, 4)
    assert np.abs(X[0]).max() <= 1e-12 * np.abs(z).max() and np.abs(X[3:]).max() <= 1e-8 * np.abs(z).max()
    # the modal sum, the rigid-body mode's term a free mass: phi_r0^2 / (-w^2) = -1 / (m_total w^2)
    lam, phi = eigh(stuck_stiffness(s), s.M)
    c = np.einsum("ij,ik,kj->j", phi, np.asarray(s.C), phi)
    h00 = np.sum(phi[0] ** 2 / (np.where(np.arange(4) == 0, 0.0, lam) - w * w + 1j * w * c))
    assert abs(lam[0]) < 1e-9 * lam[-1]
    np.testing.assert_allclose(z[0], -1j * s.force[0] * h00, rtol=1e-10)
    assert abs(phi[0, 0] ** 2 / (-w * w) + 1.0 / (3.0 * w * w)) < 1e-12 / w ** 2
    # stable: the elastic motion's exponents, or the free body's neutral one (0, shifted to +-i w0 by the
    # gauge and counted where it falls into Hill's central strip)
    A = np.block([[np.zeros((4, 4)), np.eye(4)], [-np.linalg.solve(s.M, stuck_stiffness(s)),
                                                   -np.linalg.solve(s.M, np.asarray(s.C))]])
    ex = np.linalg.eigvals(A)
    elastic = ex[np.abs(ex) > 1e-6 * np.abs(ex).max()].real.max() / w
    # the neutral exponent is a double eigenvalue (a Jordan block of the rigid-body mode): any eigensolver
    # gets it to about sqrt(eps) of w, here 2.3e-8 by LAPACK (the compiled solver before it gave < 1e-8)
    assert sol.stable and (abs(sol.growth) < 1e-6 or sol.growth == pytest.approx(elastic, rel=1e-8))
    # the free body's mean stays where it was; the Jacobian's static block is K_stuck + s M Phi Phi^T M
    ev = sol.problem.evaluate(sol.X, sol.problem.f1_ref)
    np.testing.assert_allclose(ev.JX[:4, :4], stuck_stiffness(s) + sol.problem.gauge, rtol=1e-12)


def test_a_free_free_assembly_grounded_by_ever_softer_springs_converges_to_it():
    """(2) Soft springs to ground (eps k): the grounded answer converges to the free-free one, O(eps)."""
    w0 = 120.0
    free = harmonic_balance(_chain(w0=w0), 0.8, harmonics=3, samples=64)
    errs = []
    for eps in (1e1, 1e0, 1e-1):
        g = _chain(ground=eps, w0=w0)
        assert free_modes(g).shape[1] == 0
        sol = harmonic_balance(g, 0.8, harmonics=3, samples=64)
        assert sol.status.ok
        errs.append(np.abs(sol.X - free.X).max() / np.abs(free.X).max())
    assert errs[2] < 1e-4 and errs[0] / errs[1] > 8.0 and errs[1] / errs[2] > 8.0


def test_fully_slipping_limit_is_the_structure_without_its_contact():
    """(3) An inner contact of a free body with a vanishing slip force: the response tends to the linear FRF
    of K alone (its rigid-body mode a free mass); the stuck limit is the FRF of K + kt."""
    gamma = 0.8
    for n0, K_of, bound in ((1e-7, lambda s: s.K, 1e-5), (N0, stuck_stiffness, 1e-8)):
        s = _body(n0=n0, f=0.5 if n0 < 1.0 else 1e-3)
        assert not held_by_contacts(s) and free_modes(s).shape[1] == 1
        sol = harmonic_balance(s, gamma, harmonics=5, samples=128)
        assert sol.status.ok
        z = _frf(s, gamma * s.w0, K_of(s))
        err = np.abs(_first(sol.X, 3) - z).max() / np.abs(z).max()
        assert err < bound, (n0, err)
        assert np.abs(sol.X[:3]).max() <= 1e-9 * np.abs(z).max()  # the gauged mean


def test_time_domain_of_a_stuck_free_free_assembly_equals_the_free_free_frf():
    """(4) The steady state settles (no drift: the rigid-body part starts in the free body's periodic
    motion) on the free-free FRF; from rest, the integration's rigid-body mean velocity is zero, where
    a start at rest proper drifts at f / (m_total w)."""
    s = _chain()
    gamma = 0.9
    w = gamma * s.w0
    z = _frf(s, w)
    ss = jd.steady_state(s, gamma, response_dof=0)
    assert ss.status.ok
    assert ss.amplitude_m == pytest.approx(abs(z[0]), rel=1e-5)
    phi = free_modes(s)[:, 0]
    T = 2.0 * math.pi / w
    q = ss.loop.x @ s.M @ phi
    assert abs(q[-1] - q[0]) / T < 1e-6 * w * abs(z[0])
    tr = jd.integrate(s, gamma, periods=4)
    q = tr.x @ s.M @ phi
    drift = (q[-1] - q[0]) / (tr.t[-1] - tr.t[0])
    naive = jd.integrate(s, gamma, periods=4, x0=np.zeros(4), v0=np.zeros(4))
    qn = naive.x @ s.M @ phi
    drift_rest = (qn[-1] - qn[0]) / (naive.t[-1] - naive.t[0])
    free_mass = s.force[0] * phi[0] / w  # Phi^T f / w
    assert drift_rest == pytest.approx(free_mass, rel=1e-3)
    assert abs(drift) < 1e-6 * abs(free_mass)


def test_energy_balance_of_a_free_free_assembly_in_microslip():
    """(5) Iwan joint in microslip: the forcing's work per period is what the contact and the viscous
    damping dissipate, in harmonic balance (to its residual) and in the time domain, which agree."""
    s = _chain("iwan", f=2.0)
    gamma = 0.9
    sol = harmonic_balance(s, gamma, harmonics=7, samples=256, response_dof=3)
    assert sol.status.ok
    p = sol.problem
    n, H, w = 4, p.H, gamma * s.w0
    X = sol.X.reshape(-1, n)
    ev = p.evaluate(sol.X, p.f1_ref)
    assert np.abs(ev.T).max() < MU * N0 * (1.0 - 1e-3)  # microslip: never slipping as a whole
    b = np.array([0.0, 1.0, -1.0, 0.0])
    du = p.E @ derivative_matrix(H) @ (X @ b)  # du/dtau at the samples, m
    e_contact = float(np.sum(ev.T[0] * du) * (2.0 * math.pi / p.Ns))
    work = -math.pi * float(s.force @ X[1])  # of f sin(tau) over x = a_1 cos(tau) + ...: -pi f . a_1
    C = np.asarray(s.C)
    e_visc = math.pi * w * sum(k * k * (X[2 * k - 1] @ C @ X[2 * k - 1] + X[2 * k] @ C @ X[2 * k])
                               for k in range(1, H + 1))
    assert e_contact > 0.05 * work > 0.0
    assert work == pytest.approx(e_contact + e_visc, rel=1e-8)
    ss = jd.steady_state(s, gamma, response_dof=3)
    assert ss.status.ok
    assert ss.work_force_J == pytest.approx(ss.energy_contact_J + ss.energy_viscous_J, rel=1e-2)
    assert ss.energy_contact_J == pytest.approx(e_contact, rel=2e-2)
    assert ss.amplitude_m == pytest.approx(sol.amplitude_m, rel=1e-2)


def test_epmc_starts_from_the_first_elastic_mode_of_a_free_free_assembly():
    """(6) Mode 1 is the first elastic mode; at small amplitude a stuck Jenkins joint gives its frequency to
    rounding; the rigid-body mode is never chosen (the mode numbers stop at the elastic modes)."""
    from jointdyn.modes import epmc, linear_stuck_mode

    s = _chain(f=0.0)
    lam = eigh(stuck_stiffness(s), s.M, eigvals_only=True)
    lin = linear_stuck_mode(s, 1, 1)
    assert lin.omega_rad_s == pytest.approx(math.sqrt(lam[1]), rel=1e-12)
    scale = MU * N0 / KT
    b = epmc(s, (1e-3 * scale, 1e-2 * scale), mode=1, output_dof=1, harmonics=3, samples=64, progress=False)
    assert b.status.ok
    np.testing.assert_allclose(b.omega_rad_s, math.sqrt(lam[1]), rtol=1e-9)
    with pytest.raises(ValueError, match=r"mode must be in \[1, 3\].*3 elastic modes beside its 1 rigid-body"):
        linear_stuck_mode(s, 4, 1)
    # Iwan: softening through microslip from the same linear limit
    bi = epmc(_chain("iwan", f=0.0), (1e-3 * scale, 0.3 * scale), mode=1, output_dof=1, harmonics=3, samples=64,
              progress=False)
    assert bi.status.ok
    wi = np.asarray(bi.omega_rad_s)
    assert abs(wi[0] / math.sqrt(lam[1]) - 1.0) < 1e-2 and wi[-1] < wi[0]


def test_condensation_refuses_a_free_free_structure():
    s = _body()
    assert not use_condensed(s)
    with pytest.raises(ValueError, match="condense: the structure is free-free"):
        use_condensed(s, True)
    assert HBProblem(s, harmonics=1, samples=8).gauge is not None


FREE_FREE_TOML = """
# two parts joined by one node pair, hung free: 3 rigid-body translations even stuck
[structure]
M = {M}
K = {K}
zeta = 0.02

[[force]]
dof = 0
amplitude = 0.01

[[interface]]
kt = 1.5e4
kn = 3.0e4
mu = 0.5
preload = 20.0
pairs = [[3, 4, 5, 6, 7, 8]]

[output]
dof = 9
"""


def _free_free_file(path):
    M = np.diag([1.0] * 6 + [0.5] * 6)
    K = np.zeros((12, 12))
    for d, k in ((0, 1.0e4), (1, 1.2e4), (2, 1.0e4), (6, 2.0e4), (7, 2.0e4), (8, 2.0e4)):
        K += _spring(12, d, d + 3, k)
    fmt = lambda A: "[" + ", ".join("[" + ", ".join(f"{v:g}" for v in row) + "]" for row in A) + "]"  # noqa: E731
    path.write_text(FREE_FREE_TOML.format(M=fmt(M), K=fmt(K)))
    return path


def test_a_free_free_system_file_through_the_command_line(tmp_path, capsys):
    """(7) Two parts joined by an interface pair, free-free in 3 translations: frc --method hb and modes."""
    import json

    f = _free_free_file(tmp_path / "ff.toml")
    s = jd.read_system(f)
    assert free_modes(s).shape[1] == 3 and held_by_contacts(s)
    # stuck pair: harmonic balance and the time domain on the free-free FRF (modal damping: no rigid-body part)
    from jointdyn.damping import dense_damping

    w = 0.8 * s.w0
    z = np.linalg.solve(stuck_stiffness(s) - w * w * s.M + 1j * w * dense_damping(s.C), -1j * s.force)
    sol = harmonic_balance(s, 0.8, harmonics=3, samples=32, response_dof=9)
    assert sol.status.ok and sol.amplitude_m == pytest.approx(abs(z[9]), rel=1e-8)
    ss = jd.steady_state(s, 0.8, response_dof=9)
    assert ss.status.ok and ss.amplitude_m == pytest.approx(abs(z[9]), rel=1e-4)
    capsys.readouterr()
    rc = main(["frc", "--system", str(f), "--method", "hb", "--gamma", "0.3:1.5:0.05", "--harmonics", "3",
               "--samples", "32", "--out", str(tmp_path / "o1"), "--json"])
    out = json.loads(capsys.readouterr().out)
    assert rc == 0 and out["status"] == "complete"
    rc = main(["modes", "--system", str(f), "--harmonics", "3", "--samples", "32", "--amplitude", "1e-6:1e-4",
               "--out", str(tmp_path / "o2"), "--json"])
    out = json.loads(capsys.readouterr().out)
    lam = eigh(stuck_stiffness(s), s.M, eigvals_only=True)
    assert rc == 0 and out["status"] == "complete", out["message"]
    assert out["omega_linear_rad_s"] == pytest.approx(math.sqrt(lam[3]), rel=1e-10)  # after 3 rigid-body modes


def test_rigid_body_modes_large_path_agrees(monkeypatch):
    """The shift-invert path of large structures finds the same rigid-body subspace as the dense one: a
    free chain of 40 DOFs in two directions (2 rigid-body modes), and none once one DOF is grounded."""
    from jointdyn import config
    from jointdyn.systems import rigid_body_modes

    rng = np.random.default_rng(5)
    n = 40
    K = np.zeros((n, n))
    for d in range(n - 2):  # two interleaved chains: DOFs of the same parity joined
        K += _spring(n, d, d + 2, float(rng.uniform(1e3, 1e4)))
    M = np.diag(rng.uniform(0.5, 2.0, n))
    dense = rigid_body_modes(K, M)
    assert dense.shape == (n, 2)
    monkeypatch.setattr(config, "SYSTEM_DENSE_CHECK_MAX_DOF", 10)
    large = rigid_body_modes(K, M)
    assert large.shape == (n, 2)
    np.testing.assert_allclose(large.T @ M @ large, np.eye(2), atol=1e-10)
    P = dense @ dense.T @ M  # the M-orthogonal projector on the dense subspace keeps the large one
    np.testing.assert_allclose(P @ large, large, atol=1e-8 * np.abs(large).max())
    Kg = K.copy()
    Kg[0, 0] += 1e3
    assert rigid_body_modes(Kg, M).shape == (n, 1)


def test_qsma_of_a_free_free_body_is_the_free_equilibrium_with_its_rigid_body_part_at_zero():
    """QSMA of a free-free body (its inner contact between DOFs 0 and 2): at every point of the push the free
    structure's equilibrium K x + b T = M phi alpha holds with |T| <= fy (the gauge adds nothing there) and the
    rigid-body part of x is zero; the backbone starts at the first elastic mode and goes through macroslip."""
    from jointdyn.modes import qsma

    s = _body()
    b = qsma(s, (1e-5, 1e-2))
    assert b.status.ok
    n = s.ndof
    x = b.X[:, n:2 * n]
    phi = b.linear.mass_normalised
    alpha = b.omega_rad_s ** 2 * (x @ (s.M @ phi))
    r = x @ s.K_reference - alpha[:, None] * (s.M @ phi)[None, :]  # = -b T at an equilibrium
    bvec = np.array([1.0, 0.0, -1.0])
    T = -(r @ bvec) / (bvec @ bvec)
    scale = np.abs(alpha)[:, None] * np.abs(s.M @ phi).max()
    assert np.abs(r + T[:, None] * bvec[None, :]).max() <= 1e-9 * scale.max()
    assert np.abs(T).max() <= MU * N0 * (1.0 + 1e-9) and np.abs(T[-1]) >= MU * N0 * (1.0 - 1e-9)  # macroslip
    rigid = free_modes(s)
    assert np.abs(x @ (s.M @ rigid)).max() <= 1e-9 * np.abs(x).max()  # to the push's Newton tolerance
    w_elastic = math.sqrt(eigh(stuck_stiffness(s), s.M, eigvals_only=True)[1])
    assert b.omega_rad_s[0] == pytest.approx(w_elastic, rel=1e-9) and b.omega_rad_s[-1] < 0.9 * w_elastic


def test_qsma_of_a_free_free_assembly_through_macroslip():
    """Two free parts joined by a Jenkins contact, pushed along their first elastic mode (output DOF 0).
    While the contact sticks, the same assembly grounded by ever softer springs converges to it, in
    proportion; once it slips, each part is balanced by the slip force alone: the modal force is
    alpha = mu N / |sum over part A of (M phi)| (closed form), and the rigid-body part stays at zero."""
    from jointdyn.modes import qsma

    b = qsma(_chain(), (1e-5, 1e-2), output_dof=0)
    assert b.status.ok
    s, phi = b.system, b.linear.mass_normalised
    x = b.X[:, 4:8]
    alpha = b.omega_rad_s ** 2 * (x @ (s.M @ phi))
    u = x[:, 1] - x[:, 2]
    stuck = np.abs(u) < 0.999 * MU * N0 / KT
    slipping = np.abs(u) > 1.001 * MU * N0 / KT
    assert stuck.sum() > 20 and slipping.sum() > 20 and abs(u[-1]) > 10.0 * MU * N0 / KT
    np.testing.assert_allclose(np.abs(alpha[slipping]), MU * N0 / abs((s.M @ phi)[:2].sum()), rtol=1e-9)
    assert np.abs(x @ (s.M @ free_modes(s))).max() <= 1e-9 * np.abs(x).max()
    errors = []
    for ground in (1e2, 1e1, 1e0):
        g = qsma(_chain(ground=ground), (1e-5, 1e-2), mode=2, output_dof=0)  # mode 1: the soft springs' own
        assert g.status.ok
        errors.append(np.max(np.abs(g.omega_rad_s[stuck] / b.omega_rad_s[stuck] - 1.0)))
    assert errors[2] < 1e-4 and 5.0 < errors[0] / errors[1] < 20.0 and 5.0 < errors[1] / errors[2] < 20.0
