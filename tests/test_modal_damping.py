"""Modal damping as an operator (jointdyn.damping.ModalDamping) against the dense C it stands for.

Oracles: the dense matrix M Phi diag(2 zeta w) Phi^T M (``modal_damping(..., form="array")``), the
dense evaluations and direct dense solves of harmonic balance, EPMC and the time march with that
matrix, closed forms (Rayleigh damping is modal damping with zeta_r = (alpha / w_r + beta w_r) / 2;
all modes kept, the damped harmonic block is diagonal in the modes).
"""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn import config
from jointdyn.continuation import LinearSolveOptions
from jointdyn.hb import HBOptions
from jointdyn.hb.problem import HBProblem, reference_scales
from test_sparse_jacobian import _two_bodies


def _pencil(n=7, seed=0):
    rng = np.random.default_rng(seed)
    A = rng.standard_normal((n, n))
    B = rng.standard_normal((n, n))
    return A @ A.T + n * np.eye(n), B @ B.T + 0.5 * np.eye(n)


def _with_damping(s, C):
    return jd.System(M=s.M, C=C, K=s.K, contacts=s.contacts, interfaces=s.interfaces, force=s.force,
                     force_phase_deg=s.force_phase_deg, output_dof=s.output_dof, w0_rad_s=s.w0_rad_s)


def _pair(nodes=4, zeta=0.02):
    """The two-body interface model of test_sparse_jacobian with modal damping: (dense C, operator)."""
    s = _two_bodies(nodes)
    op = jd.modal_damping(s.M, s.K, zeta, form="operator")
    return _with_damping(s, op.toarray()), _with_damping(s, op)


def test_operator_applies_the_dense_matrix():
    M, K = _pencil()
    z = np.linspace(0.01, 0.05, 7)
    C = jd.modal_damping(M, K, z)
    op = jd.modal_damping(M, K, z, form="operator")
    assert isinstance(op, jd.ModalDamping) and op.shape == (7, 7) and op.complete
    np.testing.assert_array_equal(op.toarray(), C)
    np.testing.assert_array_equal(np.asarray(op), C)
    rng = np.random.default_rng(1)
    v, V2 = rng.standard_normal(7), rng.standard_normal((7, 3))
    scale = np.abs(C).max()
    np.testing.assert_allclose(op @ v, C @ v, rtol=0, atol=1e-14 * scale * np.abs(v).sum())
    np.testing.assert_allclose(op @ V2, C @ V2, rtol=0, atol=1e-14 * scale * np.abs(V2).sum())
    np.testing.assert_allclose(V2.T @ op, V2.T @ C, rtol=0, atol=1e-14 * scale * np.abs(V2).sum())
    np.testing.assert_allclose(op.diagonal(), np.diag(C), rtol=1e-13)
    # the ratios: Phi^T C Phi = diag(2 zeta w) on the modes of (M, K)
    from scipy.linalg import eigh

    lam, phi = eigh(K, M)
    np.testing.assert_allclose(phi.T @ (op @ phi), np.diag(2 * z * np.sqrt(lam)), atol=1e-12 * scale)
    assert jd.modal_damping(M, K, 0.0, form="operator").toarray().any() == False  # noqa: E712


def test_operator_refuses_bad_input():
    M, K = _pencil(4)
    with pytest.raises(ValueError, match="form must be one of array, operator"):
        jd.modal_damping(M, K, 0.01, form="sparse")
    with pytest.raises(ValueError, match="zeta must be"):
        jd.ModalDamping(M, np.eye(4), -0.1, 1.0)
    with pytest.raises(ValueError, match="w must be"):
        jd.ModalDamping(M, np.eye(4), 0.1, -1.0)
    with pytest.raises(ValueError, match="phi must have between 1 and 4 columns"):
        jd.ModalDamping(M, np.ones((4, 5)), 0.1, 1.0)
    with pytest.raises(ValueError, match="M must be 3 x 3"):
        jd.ModalDamping(M, np.ones((3, 2)), 0.1, 1.0)
    with pytest.raises(ValueError, match="C must be 3 x 3, got a ModalDamping of shape"):
        jd.System(M=np.eye(3), C=jd.modal_damping(M, K, 0.01, form="operator"), K=np.eye(3))


def test_rayleigh_fit_recovers_rayleigh_damping():
    """zeta_r = (alpha / w_r + beta w_r) / 2 is C = alpha M + beta K: the fit gives alpha and beta, and the
    operator's rest E = C - C_R vanishes."""
    from jointdyn.hb._damped import DampingSplit

    M, K = _pencil(9, seed=3)
    from scipy.linalg import eigh

    w = np.sqrt(eigh(K, M, eigvals_only=True))
    alpha, beta = 0.7, 2e-3
    op = jd.modal_damping(M, K, 0.5 * (alpha / w + beta * w), form="operator")
    a, b = op.rayleigh_fit()
    assert a == pytest.approx(alpha, rel=1e-10) and b == pytest.approx(beta, rel=1e-10)
    np.testing.assert_allclose(op.toarray(), alpha * M + beta * K, rtol=0, atol=1e-12 * np.abs(K).max() * beta)
    rest = DampingSplit(op, M, K).rest(np.eye(9))
    assert np.abs(rest).max() <= 1e-12 * np.abs(op.toarray()).max()


def test_all_modes_make_the_damped_harmonic_block_diagonal():
    """(K - (kw)^2 M + i kw C)^-1 = Phi diag(1 / (w_r^2 - (kw)^2 + i kw 2 zeta_r w_r)) Phi^T."""
    M, K = _pencil(8, seed=5)
    op = jd.modal_damping(M, K, np.linspace(0.002, 0.03, 8), form="operator")
    rng = np.random.default_rng(2)
    r = rng.standard_normal((8, 2)) + 1j * rng.standard_normal((8, 2))
    for kw in (0.3, 1.7, 4.0):
        x = np.linalg.solve(K - kw * kw * M + 1j * kw * op.toarray(), r)
        np.testing.assert_allclose(op.harmonic_solve(kw, r), x, rtol=0, atol=1e-11 * np.abs(x).max())


@pytest.mark.parametrize("scale", [1e-3, 0.3, 2.0])
def test_hb_evaluations_with_the_operator_equal_those_with_dense_c(scale):
    """Residual, Jacobian (entries, products, columns) and dR/dp: the sparse evaluation with the operator
    (Rayleigh part in the pattern, the rest an operator) against the dense evaluation with the dense C; the
    dense and harmonic-block evaluations with the operator are those with the array."""
    sa, so = _pair()
    qa, qo = HBProblem(sa, harmonics=3, samples=32), HBProblem(so, harmonics=3, samples=32)
    kt, fy = reference_scales(sa)
    rng = np.random.default_rng(int(scale * 1000) + 7)
    X = rng.standard_normal(qa.size) * scale * fy / kt
    for p in (0.9, 1.15):
        a, b = qa.evaluate(X, p), qo.evaluate_sparse(X, p)
        J = b.JX.toarray()
        assert np.max(np.abs(a.R - b.R)) <= 1e-13 * np.max(np.abs(a.R))
        assert np.max(np.abs(a.JX - J)) <= 1e-13 * np.max(np.abs(a.JX))
        assert np.max(np.abs(a.Jp - b.Jp)) <= 1e-13 * np.max(np.abs(a.Jp))
        v = rng.standard_normal(qa.size)
        assert np.max(np.abs(a.JX @ v - b.JX @ v)) <= 1e-13 * np.max(np.abs(a.JX @ v))
        for j in (0, qa.n + 3, qa.size - 1):
            np.testing.assert_allclose(b.JX.column(j), a.JX[:, j], rtol=0, atol=1e-13 * np.abs(a.JX).max())
        c = qo.evaluate(X, p)
        np.testing.assert_array_equal(c.R, a.R)
        np.testing.assert_array_equal(c.JX, a.JX)
        ba, bo = qa.evaluate_blocks(X, p), qo.evaluate_blocks(X, p)
        np.testing.assert_array_equal(bo.R, ba.R)
        np.testing.assert_array_equal(bo.JX.toarray(), ba.JX.toarray())


def test_large_solves_with_the_operator_equal_the_direct_dense_solve(monkeypatch):
    """The continuation's bordered solve with the operator's Jacobian (SuperLU of its sparse part, GMRES on
    the exact product) equals LAPACK's dense solve of the same matrix to 1e-8."""
    from jointdyn.continuation.linalg import FactorReuse, _bordered

    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    _, so = _pair()
    q = HBProblem(so, harmonics=3, samples=32)
    kt, fy = reference_scales(so)
    rng = np.random.default_rng(11)
    fr = FactorReuse()
    for scale in (0.01, 1.0, 5.0):
        X = rng.standard_normal(q.size) * scale * fy / kt
        for p in (0.95, 1.0, 1.05):
            ev = q.evaluate_sparse(X, p)
            d = rng.standard_normal(q.size + 1)
            b = rng.standard_normal(q.size + 1)
            x, ok = fr.solve(ev.JX, ev.Jp, d, b)
            ref = np.linalg.solve(_bordered(ev.JX.toarray(), ev.Jp, d), b)
            assert ok
            np.testing.assert_allclose(x, ref, rtol=0, atol=1e-8 * np.abs(ref).max())
    assert fr.counts["sparse_factorisations"] > 0 and fr.counts["krylov_solves"] >= 9
    assert "approximation_fallbacks" not in fr.counts


def test_large_solve_falls_back_to_the_dense_solve(monkeypatch):
    """Where GMRES with the sparse part's factors does not reach the tolerance (here: one nobody reaches), the
    solve is LAPACK's on the dense matrix, and counted."""
    from jointdyn.continuation.linalg import FactorReuse, _bordered

    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    _, so = _pair(3)
    q = HBProblem(so, harmonics=2, samples=32)
    rng = np.random.default_rng(5)
    ev = q.evaluate_sparse(1e-4 * rng.standard_normal(q.size), 1.0)
    d, b = rng.standard_normal(q.size + 1), rng.standard_normal(q.size + 1)
    fr = FactorReuse(linear=LinearSolveOptions(krylov_rtol=1e-300))  # a tolerance nobody reaches
    x, ok = fr.solve(ev.JX, ev.Jp, d, b)
    assert ok and fr.counts["approximation_fallbacks"] == 1
    np.testing.assert_array_equal(x, np.linalg.solve(_bordered(ev.JX.toarray(), ev.Jp, d), b))


def test_hb_branch_and_solution_with_the_operator_equal_those_with_dense_c(monkeypatch):
    """A branch through the sparse evaluation with the operator (and its solves) against the dense path with
    the dense C: the same peak; one solution at a fixed frequency equal to 1e-8."""
    from jointdyn.hb import continue_hb, harmonic_balance

    sa, so = _pair(3)
    a = continue_hb(sa, 0.7, 1.3, harmonics=2, samples=32, condense=False)
    xa = harmonic_balance(sa, 1.02, harmonics=2, samples=32, condense=False)
    # shared numbers: the size above which Krylov solves and the sparse evaluation are used
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    b = continue_hb(so, 0.7, 1.3, harmonics=2, samples=32, condense=False, linear=LinearSolveOptions(small_solve=0),
                    hb_options=HBOptions(dense_max_unknowns=0))  # harmonic balance's own bound, its option
    assert a.status.ok and b.status.ok
    assert b.counters["sparse_factorisations"] > 0 and b.counters["krylov_solves"] > 0
    assert b.response()[0].max() == pytest.approx(a.response()[0].max(), rel=1e-8)
    xb = harmonic_balance(so, 1.02, harmonics=2, samples=32, condense=False)
    assert xa.status.ok and xb.status.ok
    np.testing.assert_allclose(xb.X, xa.X, rtol=0, atol=1e-8 * np.abs(xa.X).max())


def test_epmc_with_the_operator_equals_epmc_with_dense_c(monkeypatch):
    """EPMC's residual with the operator (sparse evaluation) equals the dense one with the dense C; a backbone
    through the operator's sparse path follows the dense backbone, and the same walk on the dense path is
    the same with the operator as with the array."""
    from jointdyn.modes import epmc
    from jointdyn.modes.epmc import EPMCProblem

    sa, so = _pair(3)
    sa = jd.System(M=sa.M, C=sa.C, K=sa.K, interfaces=sa.interfaces, output_dof=0)
    so = jd.System(M=so.M, C=so.C, K=so.K, interfaces=so.interfaces, output_dof=0)
    kt, fy = reference_scales(sa)
    rng_a = (0.05 * fy / kt, 5.0 * fy / kt)
    a = epmc(sa, rng_a, harmonics=3, samples=32)
    a2 = epmc(so, rng_a, harmonics=3, samples=32)
    np.testing.assert_allclose(a2.omega_rad_s, a.omega_rad_s, rtol=1e-12)
    np.testing.assert_allclose(a2.damping_ratio, a.damping_ratio, rtol=1e-10)
    dense = EPMCProblem(sa, harmonics=3, samples=32)
    # shared numbers: the size above which Krylov solves and the sparse evaluation are used
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    sparse = EPMCProblem(so, harmonics=3, samples=32)
    assert sparse.sparse and not dense.sparse
    rng = np.random.default_rng(4)
    v = dense.linear_guess()
    np.testing.assert_allclose(sparse.linear_guess(), v, rtol=1e-13)
    for amp in (0.1, 2.0):
        w = v + 0.05 * rng.standard_normal(v.size)
        lam = np.log10(amp * fy / kt)
        Ra, Ja, La = dense.residual(w, lam)
        Rb, Jb, Lb = sparse.residual(w, lam)
        np.testing.assert_allclose(Rb, Ra, rtol=0, atol=1e-13 * np.abs(Ra).max())
        np.testing.assert_allclose(Jb.toarray(), Ja, rtol=0, atol=1e-13 * np.abs(Ja).max())
        np.testing.assert_allclose(Lb, La, rtol=0, atol=1e-13 * max(np.abs(La).max(), 1.0))
    b = epmc(so, rng_a, harmonics=3, samples=32, linear=LinearSolveOptions(small_solve=0))
    assert a.status.ok and b.status.ok and b.counters["sparse_factorisations"] > 0
    for name in ("omega_rad_s", "damping_ratio"):
        ya = np.interp(np.log(b.amplitude_m), np.log(a.amplitude_m), getattr(a, name))
        np.testing.assert_allclose(getattr(b, name), ya, rtol=2e-3)


def test_time_integration_with_the_operator_equals_dense_c():
    """The time march with the operator: the same response as with the dense C (the march takes C.toarray())."""
    sa, so = _pair(3, zeta=0.05)
    ta = jd.integrate(sa, 1.05, periods=3)
    tb = jd.integrate(so, 1.05, periods=3)
    assert ta.status.ok and tb.status.ok
    np.testing.assert_array_equal(tb.x, ta.x)
    # the damping acts: without it the response differs
    t0 = jd.integrate(_with_damping(sa, None), 1.05, periods=3)
    assert np.max(np.abs(t0.x[-1] - ta.x[-1])) > 1e-3 * np.max(np.abs(ta.x))


def test_reduced_dense_model_with_modal_damping_through_both_paths():
    """A Craig-Bampton model of the two bodies (dense on its DOFs) with modal damping of the full model:
    the reduction of the operator equals that of the array, and the reduced model's own modal damping
    as an operator gives the same branch as its array, through the harmonic-block Jacobians, to 1e-8."""
    from jointdyn.hb import continue_hb
    from jointdyn.reduction import reduce_system

    sa, so = _pair(4)
    ra, _ = reduce_system(sa, 3)
    rb, _ = reduce_system(so, 3)
    np.testing.assert_array_equal(rb.C, ra.C)
    opr = jd.modal_damping(ra.M, ra.K, 0.02, form="operator")
    r1, r2 = _with_damping(ra, opr.toarray()), _with_damping(ra, opr)
    a = continue_hb(r1, 0.7, 1.3, harmonics=2, samples=32, condense=False)
    b = continue_hb(r2, 0.7, 1.3, harmonics=2, samples=32, condense=False)
    assert a.status.ok and b.status.ok
    assert b.response()[0].max() == pytest.approx(a.response()[0].max(), rel=1e-8)


def test_condensation_takes_the_modes_of_the_operator():
    """Ratios on the modes of (M, K) itself (no normal springs: K_reference is K): the condensed receptance
    takes the operator's modes instead of decomposing (M, K) again, and equals the receptance of the dense
    C at frequencies across the modes; an HB solution through the condensation is the same to 1e-8."""
    from jointdyn.hb import harmonic_balance
    from jointdyn.hb.condense import receptance
    from jointdyn.laws.discrete import Jenkins

    M, K = _pencil(12, seed=8)
    op = jd.modal_damping(M, K, np.linspace(0.01, 0.04, 12), form="operator")
    law = Jenkins(kt=float(np.mean(np.diag(K))), mu=0.3, n_ref=1.0)
    f = np.zeros(12)
    f[0] = 0.2
    kw = dict(M=M, K=K, contacts=(jd.Contact(law, dof=3),), force=f, output_dof=3)
    sa, so = jd.System(C=op.toarray(), **kw), jd.System(C=op, **kw)
    ra, ro = receptance(sa), receptance(so)
    np.testing.assert_array_equal(ro.vectors, op.phi)
    cols = np.array([0, 3, 7])
    for W in np.sqrt(op.lam[[0, 5, 11]]) * 1.01:
        Ha, Ho = ra.block(W, np.arange(12), cols), ro.block(W, np.arange(12), cols)
        np.testing.assert_allclose(Ho, Ha, rtol=0, atol=1e-10 * np.abs(Ha).max())
    xa = harmonic_balance(sa, 1.05, harmonics=3, samples=32, condense=True)
    xo = harmonic_balance(so, 1.05, harmonics=3, samples=32, condense=True)
    assert xa.status.ok and xo.status.ok
    np.testing.assert_allclose(xo.X, xa.X, rtol=0, atol=1e-8 * np.abs(xa.X).max())


def test_resume_key_of_a_system_with_the_operator():
    """A sweep's resume key describes the operator by its factors: the same damping gives the same key,
    other ratios another one."""
    from jointdyn.sweeps._family import fingerprint

    M, K = _pencil(5, seed=9)
    keys = [fingerprint(jd.System(M=M, K=K, C=jd.modal_damping(M, K, z, form="operator"))) for z in (0.01, 0.01, 0.02)]
    assert keys[0] == keys[1] != keys[2]


def test_arnoldi_stability_of_a_branch_with_the_operator_equals_dense_c(monkeypatch):
    """Stability by Arnoldi on a branch evaluated sparse with the modal-damping operator (its Jacobian a
    sparse part plus the operator) equals that of the dense C."""
    from jointdyn.hb import HBOptions, StabilityOptions, continue_hb

    sa, so = _pair(3)
    arnoldi = StabilityOptions(method="arnoldi")
    a = continue_hb(sa, 0.9, 1.1, harmonics=2, samples=32, condense=False, stability=arnoldi)
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)  # shared: the large-solve paths at this size
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    b = continue_hb(so, 0.9, 1.1, harmonics=2, samples=32, condense=False, stability=arnoldi,
                    linear=LinearSolveOptions(small_solve=0), hb_options=HBOptions(dense_max_unknowns=0))
    assert a.status.ok and b.status.ok and b.stability == a.stability
    assert np.all(np.isfinite(b.growth))
    peak_a, peak_b = np.argmax(a.response()[0]), np.argmax(b.response()[0])
    assert b.growth[peak_b] == pytest.approx(a.growth[peak_a], rel=1e-6, abs=1e-9)
