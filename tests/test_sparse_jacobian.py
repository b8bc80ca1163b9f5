"""Sparse Jacobians of harmonic balance (jointdyn.hb._sparse): interfaces on sparse structures.

The oracle is the dense evaluation (the compiled kernel that writes the N x N Jacobian): the sparse one
must give the same residual, Jacobian, parameter derivative and pair outputs up to the order of the
sums, through stick, slip, separation and re-contact of the pairs, for pairs against ground and pairs
between two bodies; and EPMC's residual built on it must equal the dense one.
"""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn import config
from jointdyn.continuation import LinearSolveOptions
from jointdyn.hb import HBOptions
from jointdyn.hb.problem import HBProblem, reference_scales
from jointdyn.interfaces import Interface


def _two_bodies(nodes=4):
    """Two chains of nodes (t1, t2, n each) pressed together node to node: pairs with both sides free,
    one pair against ground, a damped structure, preloads of both signs of slack."""
    n = 6 * nodes
    rng = np.random.default_rng(2)
    K = np.zeros((n, n))
    for body in range(2):
        for i in range(nodes - 1):
            for d in range(3):
                a, b = 3 * (body * nodes + i) + d, 3 * (body * nodes + i + 1) + d
                k = 1e4 * (1.0 + d)
                K[[a, b, a, b], [a, b, b, a]] += [k, k, -k, -k]
    K += np.diag(rng.uniform(1e3, 3e3, n))
    M = np.diag(rng.uniform(0.05, 0.15, n))
    table = [[3 * i, 3 * i + 1, 3 * i + 2, 3 * (nodes + i), 3 * (nodes + i) + 1, 3 * (nodes + i) + 2]
             for i in range(nodes - 1)]
    table.append([3 * (nodes - 1), 3 * (nodes - 1) + 1, 3 * (nodes - 1) + 2, -1, -1, -1])
    itf = Interface(kt=2e3, kn=5e3, mu=0.4, preload=np.linspace(0.5, 3.0, nodes), pairs=np.array(table))
    f = np.zeros(n)
    f[0], f[1] = 1.0, 0.7
    return jd.System(M=M, C=1e-4 * K + 0.2 * M, K=K, interfaces=(itf,), force=f,
                     force_phase_deg=np.where(np.arange(n) == 1, 90.0, 0.0), output_dof=0)


@pytest.mark.parametrize("scale", [1e-3, 0.3, 2.0, 30.0])
def test_sparse_evaluation_equals_the_dense_one(scale):
    """Small amplitudes (all stuck) to large ones (slip, and separation with re-contact: random normal
    coefficients of this size open the lightly loaded pairs for part of the period)."""
    s = _two_bodies()
    q = HBProblem(s, harmonics=3, samples=32)
    kt, fy = reference_scales(s)
    rng = np.random.default_rng(int(scale * 1000))
    for p in (0.9, 1.15):
        X = rng.standard_normal(q.size) * scale * fy / kt
        a, b = q.evaluate(X, p), q.evaluate_sparse(X, p)
        J = b.JX.toarray()
        assert np.max(np.abs(a.R - b.R)) <= 1e-13 * np.max(np.abs(a.R))
        assert np.max(np.abs(a.JX - J)) <= 1e-13 * np.max(np.abs(a.JX))
        assert np.max(np.abs(a.Jp - b.Jp)) <= 1e-13 * np.max(np.abs(a.Jp))
        np.testing.assert_array_equal(a.pair_code, b.pair_code)
        np.testing.assert_array_equal(a.pair_T, b.pair_T)
        np.testing.assert_array_equal(a.pair_N, b.pair_N)
        np.testing.assert_array_equal(a.info, b.info)
        # the pattern holds every nonzero of the dense Jacobian
        pattern = b.JX.copy()
        pattern.data[:] = 1.0
        assert not np.any((a.JX != 0.0) & (pattern.toarray() == 0.0))
        assert b.JX.nnz == q.sparse_pattern().nnz
    if scale >= 2.0:
        codes = set(np.unique(b.pair_code))
        assert len(codes) >= 2  # more than one motion state among the pairs' samples


def test_sparse_pattern_only_for_interfaces_without_scalar_contacts():
    from jointdyn.laws.discrete import Jenkins

    s = _two_bodies(3)
    assert HBProblem(s, harmonics=2, samples=16).sparse_pattern() is not None
    both = jd.System(M=s.M, C=s.C, K=s.K, interfaces=s.interfaces, force=s.force,
                     contacts=(jd.Contact(Jenkins(kt=1e3, mu=0.3, n_ref=1.0), dof=4),))
    q = HBProblem(both, harmonics=2, samples=16)
    assert q.sparse_pattern() is None
    with pytest.raises(ValueError, match="interfaces and no scalar contacts"):
        q.evaluate_sparse(np.zeros(q.size), 1.0)
    plain = jd.System(M=s.M, C=s.C, K=s.K, force=s.force)
    assert HBProblem(plain, harmonics=2, samples=16).sparse_pattern() is None


def test_epmc_residual_with_a_sparse_jacobian_equals_the_dense_one(monkeypatch):
    """EPMC switches to the sparse evaluation from config.CONT_KRYLOV_SOLVE unknowns on a sparse
    structure: its residual and both Jacobians equal those of the dense path at slipping points."""
    from jointdyn.modes.epmc import EPMCProblem

    s = _two_bodies()
    s = jd.System(M=s.M, C=s.C, K=s.K, interfaces=s.interfaces, output_dof=0)
    dense = EPMCProblem(s, harmonics=3, samples=32)
    assert not dense.sparse
    # CONT_KRYLOV_SOLVE and CONT_SPARSE_DENSITY are shared (the walk's solves and the form harmonic balance and
    # EPMC give their Jacobians): patched here so that both take the large path at this small size
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    sparse = EPMCProblem(s, harmonics=3, samples=32)
    assert sparse.sparse
    kt, fy = reference_scales(s)
    rng = np.random.default_rng(4)
    v = dense.linear_guess()
    for amp in (0.1, 2.0, 20.0):
        w = v + 0.05 * rng.standard_normal(v.size)
        lam = np.log10(amp * fy / kt)
        Ra, Ja, La = dense.residual(w, lam)
        Rb, Jb, Lb = sparse.residual(w, lam)
        np.testing.assert_allclose(Rb, Ra, rtol=0, atol=1e-13 * np.abs(Ra).max())
        np.testing.assert_allclose(Jb.toarray(), Ja, rtol=0, atol=1e-13 * np.abs(Ja).max())
        # dR/dlam = ln 10 (J Y / k_ref - R_s): a difference of terms of order one (the scaled unknowns)
        np.testing.assert_allclose(Lb, La, rtol=0, atol=1e-13 * max(np.abs(La).max(), 1.0))


def test_epmc_backbone_with_sparse_jacobians_equals_the_dense_one(monkeypatch):
    """A whole backbone through the sparse evaluation and the sparse solves (SuperLU, GMRES with its
    factors) against the dense path: the same points to the continuation's tolerance."""
    from jointdyn.modes import epmc

    s = _two_bodies(3)
    s = jd.System(M=s.M, C=s.C, K=s.K, interfaces=s.interfaces, output_dof=0)
    kt, fy = reference_scales(s)
    rng_a = (0.05 * fy / kt, 5.0 * fy / kt)
    a = epmc(s, rng_a, harmonics=3, samples=32)
    # CONT_KRYLOV_SOLVE and CONT_SPARSE_DENSITY are shared (the walk's solves and the form harmonic balance and
    # EPMC give their Jacobians): patched here so that both take the large path at this small size
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    b = epmc(s, rng_a, harmonics=3, samples=32, linear=LinearSolveOptions(small_solve=0))
    assert a.status.ok and b.status.ok
    assert b.counters["sparse_factorisations"] > 0 and "sparse_factorisations" not in a.counters
    # the two walks may place their points differently: compare b's points with a's curve
    for name in ("omega_rad_s", "damping_ratio"):
        ya = np.interp(np.log(b.amplitude_m), np.log(a.amplitude_m), getattr(a, name))
        np.testing.assert_allclose(getattr(b, name), ya, rtol=2e-3)


def test_hb_branch_with_sparse_jacobians_has_the_same_peak(monkeypatch):
    """An HB branch through the sparse evaluation (large, sparse, Hill beyond its size: the conditions
    lowered here) against the dense path: the same peak; the same stability (dense Hill at this size)."""
    from jointdyn.hb import continue_hb

    s = _two_bodies(3)
    a = continue_hb(s, 0.7, 1.3, harmonics=2, samples=32, condense=False)
    # CONT_KRYLOV_SOLVE and CONT_SPARSE_DENSITY are shared (the walk's solves and the form harmonic balance and
    # EPMC give their Jacobians): patched here so that both take the large path at this small size
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0)
    calls = []
    orig = HBProblem.evaluate_sparse

    def counted(self, X, p):
        calls.append(p)
        return orig(self, X, p)

    monkeypatch.setattr(HBProblem, "evaluate_sparse", counted)
    b = continue_hb(s, 0.7, 1.3, harmonics=2, samples=32, condense=False,
                    linear=LinearSolveOptions(small_solve=0), hb_options=HBOptions(dense_max_unknowns=0))
    assert a.status.ok and b.status.ok and calls
    assert b.counters["sparse_factorisations"] > 0
    pa, pb = a.response()[0].max(), b.response()[0].max()
    assert pb == pytest.approx(pa, rel=1e-6)
    assert b.stability == a.stability == "hill" and np.all(np.isfinite(b.growth))
    same = np.isin(b.lam, a.lam)  # the points both paths reached (to the last bit) have one stability
    assert same.any()
    np.testing.assert_allclose(b.growth[same], [a.growth[np.flatnonzero(a.lam == v)[0]] for v in b.lam[same]],
                               rtol=0, atol=1e-9)
