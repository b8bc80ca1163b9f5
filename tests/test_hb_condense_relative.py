"""Harmonic balance condensed onto relative coordinates (jointdyn.hb._coordinates): two plates joined by
two-sided node pairs keep one unknown per pair direction (x_a - x_b) instead of two DOFs. Oracles: the
uncondensed problem solved directly (solutions, recovered DOFs, the full Jacobian, a branch's points and
peaks), dense Hill on the full Jacobian (growths and exponents), the static condensation by the
expansion against the Cholesky route, and the compiled blocks against the BLAS ones."""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.damping import dense_damping
from jointdyn.hb import (
    HBOptions,
    StabilityOptions,
    continue_hb,
    harmonic_balance,
    hill_arnoldi_exponents,
    hill_exponents,
)
from jointdyn.hb._coordinates import Coordinates, retained_coordinates, static_cholesky
from jointdyn.hb.condense import (
    _blas_blocks,
    _condensed_blocks,
    _static_parts,
    make_problem,
    receptance,
    use_condensed,
)
from jointdyn.hb.hill_condensed import condensed_hill_exponents
from jointdyn.hb.problem import HBProblem
from jointdyn.interfaces import Interface

#: the condensed solutions equal the direct ones to this, relative to the largest coefficient
RTOL = 1e-8
#: exponents and growths agree to this (relative to the largest exponent's modulus, growth absolute)
HILL_RTOL = 1e-6
NODES, CONTACT = 5, 4  # nodes of each plate (3 DOFs each), of which the first CONTACT are joined by pairs


def _plates(damping: str = "rayleigh", force: float = 3.0, free_b: bool = False) -> jd.System:
    """Two plates of NODES nodes (3 DOFs each: a chain with a weak coupling of every DOF to every other,
    grounded at both ends; plate B free with ``free_b``: held only through the pairs' coordinates), their
    first CONTACT nodes joined by preloaded node pairs, a force (N) at DOF 1 (3 N: the pairs stick, slip
    and open near the first resonance, w0 = 29 rad/s)."""
    nb = 3 * NODES
    n = 2 * nb
    K, M = np.zeros((n, n)), np.zeros((n, n))
    for p, (k0, m0) in enumerate(((1e4, 1.0), (1.6e4, 1.3))):
        o = p * nb
        for i in range(nb - 1):
            K[np.ix_([o + i, o + i + 1], [o + i, o + i + 1])] += k0 * np.array([[1.0, -1.0], [-1.0, 1.0]])
        if not (free_b and p == 1):
            K[o, o] += k0
            K[o + nb - 1, o + nb - 1] += 0.5 * k0
            K[o:o + nb, o:o + nb] += 0.02 * k0 * np.ones((nb, nb))
        M[o:o + nb, o:o + nb] = m0 * np.diag(1.0 + 0.1 * np.arange(nb))
    pairs = [[3 * i, 3 * i + 1, 3 * i + 2, nb + 3 * i, nb + 3 * i + 1, nb + 3 * i + 2] for i in range(CONTACT)]
    itf = Interface(kt=2e3, kn=5e3, mu=0.3, preload=0.4, pairs=pairs)
    if damping == "rayleigh":
        C = 0.5 * M + 2e-5 * K
    elif damping == "modal":
        C = jd.modal_damping(M, K, 0.01)
    else:  # "local": Rayleigh plus one dashpot, not diagonal in the modes (the state-space expansion)
        C = 0.5 * M + 2e-5 * K
        C[n - 1, n - 1] += 3.0
    f = np.zeros(n)
    f[1] = force
    return jd.System(M=M, C=C, K=K, interfaces=(itf,), force=f)


def _newton(q, p, X):
    for _ in range(60):
        ev = q.evaluate(X, p)
        dX = np.linalg.solve(ev.JX, ev.R)
        X = X - dX
        if np.max(np.abs(dX)) <= 1e-13 * np.max(np.abs(X)):
            return X
    raise AssertionError("Newton did not converge")


def _direct(s, H, Ns):
    return HBProblem(s, harmonics=H, samples=Ns)


def test_two_sided_pairs_keep_their_relative_coordinates():
    s = _plates()
    c = retained_coordinates(s)
    assert not c.unit and c.m == 1 + 3 * CONTACT  # DOF 0 and x_a - x_b of every pair direction
    assert c.dofs.tolist() == [0] + [-1] * (3 * CONTACT)
    assert retained_coordinates(s, relative=False).m == 6 * CONTACT  # the pairs' DOFs (DOF 0 among them)
    q = make_problem(s, condense=True, harmonics=2, samples=16, response_dofs=(20,))
    assert q.n == c.m + 1 and q.dof_index(20) == q.dofs.tolist().index(20)
    # each pair direction is one coordinate, on side a (the rows are x_a - x_b with x_a first)
    assert np.all(q.pair_positions[:, 3:] == -1) and sorted(q.pair_positions[:, :3].ravel()) == sorted(
        np.flatnonzero(q.dofs == -1).tolist())
    rows = q.coordinates.S[q.pair_positions[:, :3].ravel()]
    assert np.all(np.count_nonzero(rows, axis=1) == 2) and np.all(rows.sum(axis=1) == 0.0)
    # the same pair written the other way round is minus the coordinate: side b
    a, b = q.coordinates.position(3 * NODES, 0)
    assert a == -1 and b == q.pair_positions[0, 0]
    # the automatic choice counts the retained DOFs (24 of 30: not condensed), not the 13 coordinates
    assert not use_condensed(s) and use_condensed(s, options=HBOptions(condense_max_fraction=0.9))
    # HBOptions(condense_relative=False): the DOFs, today's form
    qd = make_problem(s, condense=True, harmonics=2, samples=16, options=HBOptions(condense_relative=False))
    assert qd.coordinates.unit and qd.n == 6 * CONTACT


def test_dependent_rows_and_one_sided_contacts_keep_the_dofs():
    s = _plates()
    nb = 3 * NODES
    loop = [[0, 1, 2, nb, nb + 1, nb + 2], [nb, nb + 1, nb + 2, 3, 4, 5], [0, 1, 2, 3, 4, 5]]  # a closed loop
    itf = Interface(kt=2e3, kn=5e3, mu=0.3, preload=0.4, pairs=loop)
    c = retained_coordinates(jd.System(M=s.M, C=s.C, K=s.K, interfaces=(itf,), force=s.force))
    assert c.unit and c.dofs.tolist() == [0, 1, 2, 3, 4, 5, nb, nb + 1, nb + 2]
    one = [[0, 1, 2, -1, -1, -1], [3, 4, 5, -1, -1, -1]]  # pairs to ground: unit rows, the same as the DOFs
    itf = Interface(kt=2e3, kn=5e3, mu=0.3, preload=0.4, pairs=one)
    c = retained_coordinates(jd.System(M=s.M, C=s.C, K=s.K, interfaces=(itf,), force=s.force))
    assert c.unit and c.dofs.tolist() == [0, 1, 2, 3, 4, 5]


@pytest.mark.parametrize("damping", ["rayleigh", "modal", "local"])
def test_condensed_on_coordinates_equals_the_direct_solve(damping):
    s = _plates(damping)
    H, Ns = 3, 32
    codes = set()
    for gamma in (0.95, 1.0, 1.04):
        # harmonic_balance's damped Newton (and homotopy), then plain Newton to rounding on both problems
        sol = harmonic_balance(s, gamma, harmonics=H, samples=Ns, condense=True, stability=False,
                               response_dof=20)
        qc, p = sol.problem, sol.problem.f1_ref
        assert qc.condensed and not qc.coordinates.unit
        assert (qc.receptance.kind == "state-space") == (damping == "local")
        q = HBProblem(s, harmonics=H, samples=Ns, parameter="f1", gamma=gamma)
        Xc = _newton(qc, p, sol.X)
        X = _newton(q, p, qc.full_coefficients(Xc, p))
        codes |= set(np.unique(q.evaluate(X, p).pair_code).tolist())
        scale = np.max(np.abs(X))
        assert np.max(np.abs(qc.full_coefficients(Xc, p) - X)) <= RTOL * scale
        for dof in (0, 1, 13, 20, 29):  # retained (0) or recovered
            got = qc.dof_coefficients(Xc, dof, p)
            assert np.max(np.abs(got - X.reshape(q.nh, q.n)[:, dof])) <= RTOL * scale
        # the full Jacobian recovered from the condensed one is the direct problem's
        J = q.evaluate(X, p).JX
        Jr = qc.full_jacobian(qc.evaluate(Xc, p).JX, qc.omega(p))
        assert np.max(np.abs(Jr - J)) <= RTOL * np.max(np.abs(J))
    assert len(codes) > 1  # the pairs did not only stick (the test is of the nonlinear problem)


def _check_points(a, s, H, Ns, every):
    """Every ``every``-th point of the condensed branch ``a``: the direct problem solved at its parameter
    from the recovered coefficients stays there (RTOL), and dense Hill on the direct Jacobian gives its
    growth (HILL_RTOL) and its label. Returns the labels checked."""
    q = _direct(s, H, Ns)
    C = dense_damping(s.C)
    labels = []
    for i in range(0, a.lam.size, every):
        lam = float(a.lam[i])
        Xf = a.problem.full_coefficients(a.X[i], lam)
        X = _newton(q, lam, Xf)
        assert np.max(np.abs(Xf - X)) <= RTOL * np.max(np.abs(X))
        w = q.omega(lam)
        sel, _ = hill_exponents(q.evaluate(X, lam).JX, s.M, C, w, H)
        assert abs(a.growth[i] - sel[0].real / w) <= HILL_RTOL
        if abs(sel[0].real / w) > 1e-6:  # clear of the marginal band, where the period map decides
            assert bool(a.stable[i]) == (sel[0].real < 0.0)
            labels.append(bool(a.stable[i]))
    return labels


def test_branch_on_coordinates_equals_the_direct_solves_and_dense_hill():
    s = _plates("rayleigh", force=3.0)  # unstable points between the resonance's peaks
    H, Ns = 3, 32
    a = continue_hb(s, 0.95, 1.05, harmonics=H, samples=Ns, condense=True, progress=False,
                    stability=StabilityOptions(method="dense"))
    assert a.status.ok and a.problem.condensed and not a.problem.coordinates.unit
    labels = _check_points(a, s, H, Ns, 5)
    assert True in labels and False in labels
    # at each peak the direct problem has the condensed peak's amplitude
    assert a.peaks
    q = _direct(s, H, Ns)
    for pk in a.peaks:
        X = _newton(q, pk.gamma, a.problem.full_coefficients(pk.X, pk.gamma))
        assert q.amplitudes(X, 0)[0] == pytest.approx(pk.amplitude_m, rel=RTOL)  # half peak-to-peak


@pytest.mark.parametrize("damping", ["rayleigh", "local"])
def test_condensed_arnoldi_on_coordinates_equals_dense_hill(damping):
    s = _plates(damping)
    H, Ns = 3, 32
    C = dense_damping(s.C)
    for gamma in (0.95, 1.04):
        sol = harmonic_balance(s, gamma, harmonics=H, samples=Ns, condense=True, stability=False)
        qc, p = sol.problem, sol.problem.f1_ref
        Xc = _newton(qc, p, sol.X)
        w = qc.omega(p)
        got = condensed_hill_exponents(qc, qc.evaluate(Xc, p).JX, w, StabilityOptions(method="arnoldi"))
        q = HBProblem(s, harmonics=H, samples=Ns, parameter="f1", gamma=gamma)
        X = _newton(q, p, qc.full_coefficients(Xc, p))
        _, every = hill_exponents(q.evaluate(X, p).JX, s.M, C, w, H)
        scale = float(np.max(np.abs(got.exponents)))
        # every exponent found is an eigenvalue of dense Hill's matrix of the direct problem ...
        assert max(float(np.min(np.abs(every - z))) for z in got.exponents) <= HILL_RTOL * scale
        # ... and the same Arnoldi on the direct Jacobian finds the same ones, with the same growth
        ref = hill_arnoldi_exponents(q.evaluate(X, p).JX, s.M, C, w, H, StabilityOptions(method="arnoldi"))
        assert got.exponents.size == ref.exponents.size > 0
        assert max(float(np.min(np.abs(ref.exponents - z))) for z in got.exponents) <= HILL_RTOL * scale
        assert abs(got.growth - ref.growth) <= HILL_RTOL * abs(ref.growth) + 1e-12


def test_blas_blocks_equal_the_compiled_pass():
    for damping in ("modal", "local"):
        qc = make_problem(_plates(damping), condense=True, harmonics=3, samples=16)
        assert qc._exp is not None  # few coordinates: the compiled pass
        a = tuple(x.copy() for x in qc._work)
        b = tuple(x.copy() for x in qc._work)
        w = qc.omega(1.01)
        _condensed_blocks(qc._exp, qc._pairs, w, qc._Z0, a)
        _blas_blocks(qc.receptance, qc._Psi_c, qc._k, w, qc._Z0, b)
        for x, y in zip(a, b):
            assert np.max(np.abs(x - y)) <= 1e-12 * np.max(np.abs(x))


def test_static_condensation_onto_coordinates():
    s = _plates()
    c = retained_coordinates(s)
    n, S = s.ndof, c.S
    Z0m, S0m = _static_parts(s.K, c, receptance(s))
    Z0c, S0c = static_cholesky(s.K, c)
    rows = np.arange(n)
    assert np.max(np.abs(Z0m - Z0c)) <= 1e-9 * np.max(np.abs(Z0c))
    assert np.max(np.abs(S0m(rows) - S0c(rows))) <= 1e-9 * np.max(np.abs(S0c(rows)))
    # plate B held only through the pairs' coordinates (K singular): the Cholesky route, exact
    free = _plates(free_b=True).K
    assert np.linalg.eigvalsh(free)[0] < 1e-9 * np.max(np.abs(free))
    Z0, S0 = static_cholesky(free, c)
    X0 = S0(rows)
    assert np.max(np.abs(S @ X0 - np.eye(c.m))) <= 1e-12  # x = S0 y has the coordinates y
    # its load is S^T Z0 y: on the coordinates only, Z0 = (S K^+ S^T)^-1 restricted to the held part
    assert np.max(np.abs(free @ X0 - S.T @ Z0)) <= 1e-9 * np.max(np.abs(free @ X0))
    assert np.max(np.abs(Z0 - X0.T @ free @ X0)) <= 1e-9 * np.max(np.abs(Z0))
    # for unit rows the same as the partition into retained and other DOFs
    d = Coordinates.of_dofs([0, 5, 17], n)
    Zd, Sd = static_cholesky(s.K, d)
    o = np.setdiff1d(rows, [0, 5, 17])
    K = s.K
    ref = K[np.ix_([0, 5, 17], [0, 5, 17])] - K[np.ix_([0, 5, 17], o)] @ np.linalg.solve(
        K[np.ix_(o, o)], K[np.ix_(o, [0, 5, 17])])
    assert np.max(np.abs(Zd - ref)) <= 1e-9 * np.max(np.abs(ref))
    # K not positive definite on the motions that keep the coordinates at zero: refused, naming condense
    bad = free.copy()
    bad[-1, -1] = bad[-2, -2] = 0.0
    with pytest.raises(ValueError, match="condense"):
        static_cholesky(bad - 1e3 * np.eye(n), c)
