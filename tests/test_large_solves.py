"""Large harmonic-balance problems: reused LU factors as GMRES preconditioner, block-wise linear terms,
EPMC's in-place Jacobian, and Hill's method skipped where it costs more than the branch.

The oracles: LAPACK's direct solve (the answer the reuse must reproduce), the dense block matrices that
the block-wise code replaces (written out here), and the same HB / EPMC solutions computed with the
reuse switched off.
"""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn import config
from jointdyn.continuation import LinearSolveOptions, linalg
from jointdyn.hb import HBOptions


def _bordered_case(rng, n):
    J = rng.standard_normal((n, n)) + n ** 0.5 * np.eye(n)
    Jl = rng.standard_normal(n)
    d = rng.standard_normal(n + 1)
    b = rng.standard_normal(n + 1)
    return J, Jl, d, b


def _direct(J, Jl, d, b):
    A = np.block([[J, Jl[:, None]], [d[None, :]]])
    return np.linalg.solve(A, b)


def test_factor_reuse_solves_like_lapack_and_factorises_only_when_gmres_fails():
    rng = np.random.default_rng(3)
    J, Jl, d, b = _bordered_case(rng, 120)
    fr = linalg.FactorReuse()
    x, ok = fr.solve(J, Jl, d, b)
    assert ok and fr.counts == {"factorisations": 1, "krylov_solves": 0, "krylov_iterations": 0,
                                "sparse_factorisations": 0}
    np.testing.assert_allclose(x, _direct(J, Jl, d, b), rtol=1e-10, atol=1e-12)
    # a nearby matrix (the next point of a branch): GMRES with the kept factors, no factorisation
    J2 = J + 1e-3 * rng.standard_normal(J.shape)
    x2, ok = fr.solve(J2, Jl, d, b)
    ref = _direct(J2, Jl, d, b)
    assert ok and fr.counts["factorisations"] == 1 and fr.counts["krylov_solves"] == 1
    assert np.linalg.norm(x2 - ref) <= 1e-8 * np.linalg.norm(ref)
    # an unrelated matrix: GMRES does not reach the tolerance in its iterations, the matrix is factorised
    J3, Jl3, d3, b3 = _bordered_case(np.random.default_rng(4), 120)
    x3, ok = fr.solve(J3, Jl3, d3, b3)
    assert ok and fr.counts["factorisations"] == 2
    np.testing.assert_allclose(x3, _direct(J3, Jl3, d3, b3), rtol=1e-10, atol=1e-12)
    # R_y alone (no border), and an exactly singular matrix is reported
    x4, ok = linalg.FactorReuse().solve(J, Jl, np.zeros(0), b[:-1])
    assert ok
    np.testing.assert_allclose(J @ x4, b[:-1], rtol=0, atol=1e-10 * np.abs(b).max())
    S = J.copy()
    S[:, 5] = 0.0
    assert not linalg.FactorReuse().solve(S, Jl, np.zeros(0), b[:-1])[1]


def _banded(rng, n, width=3):
    J = np.zeros((n, n))
    for k in range(-width, width + 1):
        J += np.diag(rng.standard_normal(n - abs(k)), k)
    return J + 4 * width * np.eye(n)


def test_sparse_matrices_are_factorised_by_superlu_while_their_factors_stay_sparse():
    rng = np.random.default_rng(8)
    n = 400
    J, Jl, d, b = _banded(rng, n), rng.standard_normal(n), rng.standard_normal(n + 1), rng.standard_normal(n + 1)
    fr = linalg.FactorReuse()
    x, ok = fr.solve(J, Jl, d, b)
    assert ok and fr.sparse and fr.counts["sparse_factorisations"] == 1 and fr.counts["factorisations"] == 0
    ref = _direct(J, Jl, d, b)
    assert np.linalg.norm(x - ref) <= 1e-12 * np.linalg.norm(ref)
    # nearby matrices (the next points of a branch): GMRES preconditioned by the kept sparse factors
    for k in (1, 2):
        Jk = J + 1e-3 * k * _banded(rng, n)
        x, ok = fr.solve(Jk, Jl, d, b)
        ref = _direct(Jk, Jl, d, b)
        assert ok and np.linalg.norm(x - ref) <= 1e-8 * np.linalg.norm(ref)
    assert fr.counts["sparse_factorisations"] == 1 and fr.counts["krylov_solves"] == 2
    assert fr.counts["factorisations"] == 0
    # an unrelated sparse matrix: GMRES fails, SuperLU factorises it
    J3 = _banded(np.random.default_rng(9), n)
    x, ok = fr.solve(J3, Jl, d, b)
    ref = _direct(J3, Jl, d, b)
    assert ok and fr.counts["sparse_factorisations"] == 2
    assert np.linalg.norm(x - ref) <= 1e-12 * np.linalg.norm(ref)
    # a sparse matrix whose factors fill in: solved, and the walk goes on dense
    R = np.where(rng.random((n, n)) < 0.015, rng.standard_normal((n, n)), 0.0) + 3 * np.eye(n)  # fill 0.4
    fr = linalg.FactorReuse()
    x, ok = fr.solve(R, Jl, d, b)
    assert ok and fr.sparse is False and fr.counts["sparse_factorisations"] >= 1
    np.testing.assert_allclose(x, _direct(R, Jl, d, b), rtol=1e-9, atol=1e-11)
    nf = fr.counts["sparse_factorisations"]
    x, ok = fr.solve(R + 1e-4 * np.eye(n), Jl, d, b)
    assert ok and fr.counts["sparse_factorisations"] == nf and fr.counts["factorisations"] + fr.counts[
        "krylov_solves"] == 1
    # exactly singular, sparse
    S = J.copy()
    S[:, 7] = 0.0
    assert not linalg.FactorReuse().solve(S, Jl, np.zeros(0), b[:-1])[1]


def test_superlu_takes_safer_pivots_where_the_diagonal_ones_are_inaccurate():
    """The diagonal pivots first (least fill); where the solve is then not accurate (tiny diagonal
    entries), the next threshold of LinearSolveOptions.sparse_pivots: the answer is LAPACK's either way."""
    rng = np.random.default_rng(10)
    n = 600  # 1.2 % nonzero: sparse (config.CONT_SPARSE_DENSITY)
    J = _banded(rng, n)
    fr = linalg.FactorReuse()
    Jl, d, b = rng.standard_normal(n), rng.standard_normal(n + 1), rng.standard_normal(n + 1)
    fr.solve(J, Jl, d, b)
    assert fr.counts["sparse_factorisations"] == 1  # diagonal pivots suffice
    P = J.copy()
    P[np.arange(n), np.arange(n)] = 1e-13  # a zero-ish diagonal: the diagonal pivots amplify rounding
    fr = linalg.FactorReuse()
    x, ok = fr.solve(P, Jl, d, b)
    ref = _direct(P, Jl, d, b)
    assert ok and fr.counts["sparse_factorisations"] == 2
    assert np.linalg.norm(x - ref) <= 1e-8 * np.linalg.norm(ref)


def test_a_sparse_jacobian_is_solved_as_its_dense_array():
    """A residual may return R_y as a scipy.sparse matrix: Newton steps and tangents, small (the compiled
    elimination) and large (FactorReuse, sparse and dense), equal those of its dense array."""
    import scipy.sparse as sps

    rng = np.random.default_rng(11)
    n = 300
    J, Jl, d, R = _banded(rng, n), rng.standard_normal(n), rng.standard_normal(n + 1), rng.standard_normal(n)
    v, up = rng.standard_normal(n + 1), rng.standard_normal(n + 1)
    ref_dv = linalg._newton_direction(J, Jl, d, R, v, up)[0]
    ref_t = linalg._tangent(J, Jl, d)
    for small, density in ((800, 1.0), (0, 1.0), (0, 0.0)):
        with pytest.MonkeyPatch.context() as mp:
            mp.setattr(config, "CONT_KRYLOV_SOLVE", 0)  # shared with the solvers (config): the large path
            mp.setattr(config, "CONT_SPARSE_DENSITY", density)
            with linalg.reusing_factors(LinearSolveOptions(small_solve=small)):
                dv, ok = linalg._newton_direction(sps.csr_matrix(J), Jl, d, R, v, up)
                t = linalg._tangent(sps.csr_matrix(J), Jl, d)
        assert ok
        np.testing.assert_allclose(dv, ref_dv, rtol=0, atol=1e-10 * np.abs(ref_dv).max())
        np.testing.assert_allclose(t, ref_t, rtol=0, atol=1e-10)


def test_reusing_factors_is_scoped_and_nests():
    assert linalg._REUSE.get() is None
    with linalg.reusing_factors() as outer:
        with linalg.reusing_factors() as inner:
            assert inner is outer
        assert linalg._REUSE.get() is outer
    assert linalg._REUSE.get() is None


def test_harmonic_columns_cover_every_nonzero_of_the_linear_terms():
    from jointdyn.hb.problem import _linear_blocks, harmonic_columns

    rng = np.random.default_rng(5)
    n, H = 4, 3
    A = rng.standard_normal((n, n))
    s = jd.System(M=np.eye(n) + 0.1 * (A + A.T) ** 2 / n, C=0.3 * np.eye(n) + 0.01 * A @ A.T,
                  K=10 * np.eye(n) + A @ A.T, force=np.ones(n))
    cols = harmonic_columns(n, H)
    inside = np.zeros((n * (2 * H + 1),) * 2, dtype=bool)
    for i, (lo, hi) in enumerate(cols):
        inside[i, lo:hi] = True
    for B in _linear_blocks(s, H):
        assert np.all(B[~inside] == 0.0)
        assert np.any(B[inside] != 0.0)


def _chain(nodes=4):
    """The node-pair chain of benchmarks/bench_hb_interface_chain.py (sparse K, M, C; a pair at every node)."""
    from test_modes_tmdsimpy_interface import _module

    return _module("benchmarks/bench_hb_interface_chain.py").chain(nodes)


def _reuse_everywhere(monkeypatch, path):
    """Every bordered solve through FactorReuse: dense (GMRES with kept factors) or sparse (SuperLU).
    Returns the counter that says so and the walk's linear-solve options."""
    # CONT_KRYLOV_SOLVE and CONT_SPARSE_DENSITY are shared (the walk's solves and the form harmonic balance and
    # EPMC give their Jacobians): patched here so that both take the large path at this small size
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    monkeypatch.setattr(config, "CONT_SPARSE_DENSITY", 1.0 if path == "sparse" else 0.0)
    key = "sparse_factorisations" if path == "sparse" else "krylov_solves"
    return key, LinearSolveOptions(small_solve=0, sparse_fill=1.0)


def test_epmc_in_place_jacobian_equals_the_dense_mass_block():
    """EPMC's xi w A_M term by blocks equals the dense block matrix A_M = [[0, k M], [-k M, 0]] per harmonic."""
    from jointdyn.modes.epmc import EPMCProblem

    s = _chain(3)
    s = jd.System(M=s.M + 0.01 * np.ones_like(s.M), C=s.C, K=s.K, interfaces=s.interfaces, output_dof=0)
    q = EPMCProblem(s, harmonics=3, samples=16)
    n, H = q.n, q.H
    AM = np.zeros((q.size, q.size))
    for k in range(1, H + 1):
        c, sn = slice((2 * k - 1) * n, 2 * k * n), slice(2 * k * n, (2 * k + 1) * n)
        AM[c, sn] = k * s.M
        AM[sn, c] = -k * s.M
    assert q.A_M is not None
    np.testing.assert_array_equal(q.A_M, AM)
    q.A_M = None  # the block-wise products of large problems
    X = np.random.default_rng(6).standard_normal(q.size)
    np.testing.assert_allclose(q._times_mass_damping(X), AM @ X, rtol=0, atol=1e-14 * np.abs(AM @ X).max())
    J = np.random.default_rng(7).standard_normal((q.size, q.size))
    ref = J - 0.37 * AM
    q._subtract_mass_damping(J, 0.37)
    np.testing.assert_array_equal(J, ref)


@pytest.mark.parametrize("path", ["dense", "sparse"])
def test_epmc_points_with_reused_factors_equal_direct_solves(monkeypatch, path):
    from jointdyn.hb.problem import reference_scales
    from jointdyn.modes.epmc import EPMCProblem

    c = _chain()
    s = jd.System(M=c.M, C=c.C, K=c.K, interfaces=c.interfaces, output_dof=0)
    kt, fy = reference_scales(s)
    amps = fy / kt * np.array([0.05, 0.3, 1.0, 3.0])

    def points(linear=None):
        q = EPMCProblem(s, harmonics=3, samples=32)
        v, out = q.linear_guess(), []
        with linalg.reusing_factors(linear) as fr:
            for a in amps:
                v, ok, _ = q.solve(a, v, tol=1e-11)
                assert ok
                out.append(v.copy())
        return np.array(out), fr.counts

    direct, counts = points()
    assert counts["factorisations"] == 0  # small: the compiled elimination, no reuse
    key, linear = _reuse_everywhere(monkeypatch, path)
    reused, counts = points(linear)
    assert counts[key] > 0
    np.testing.assert_allclose(reused, direct, rtol=0, atol=1e-8 * np.abs(direct).max())


@pytest.mark.parametrize("path", ["dense", "sparse"])
def test_hb_branch_with_reused_factors_has_the_same_peak(monkeypatch, path):
    from jointdyn.hb import continue_hb

    s = _chain(3)
    a = continue_hb(s, 0.8, 1.2, harmonics=2, samples=32, condense=False)
    key, linear = _reuse_everywhere(monkeypatch, path)
    b = continue_hb(s, 0.8, 1.2, harmonics=2, samples=32, condense=False, linear=linear)
    assert a.status.ok and b.status.ok
    assert b.counters[key] > 0 and key not in a.counters
    pa, pb = a.response()[0].max(), b.response()[0].max()
    assert pb == pytest.approx(pa, rel=1e-6)


def test_stability_beyond_the_dense_size_is_computed_and_not_computed_only_when_asked():
    """Beyond the size of the dense Jacobian (lowered here) the branch's stability is computed by Arnoldi on
    the Jacobians the continuation used, as dense Hill computes it; ``stability=False`` alone gives none."""
    from jointdyn.hb import StabilityOptions, branch_dataset, continue_hb, hill_stability

    s = _chain(2)
    kw = dict(harmonics=2, samples=32, condense=False)
    kw["hb_options"] = HBOptions(dense_max_unknowns=6 * 5 - 1)  # n (2H+1) unknowns with n = 6, H = 2
    br = continue_hb(s, 0.8, 1.2, stability=StabilityOptions(method="arnoldi"), **kw)
    assert br.status.ok and br.lam.size > 5 and br.stability == "hill-arnoldi"
    assert branch_dataset(br).attrs["stability"] == "hill-arnoldi"
    p = br.problem
    for i in range(br.lam.size):  # dense Hill on the dense Jacobian of every point: the same labels and growth
        w = p.omega(br.lam[i])
        stable, growth, _ = hill_stability(p.evaluate(br.X[i], br.lam[i]).JX, s.M, s.C, w, p.H)
        assert br.stable[i] == stable and abs(br.growth[i] - growth) <= 1e-6
    none = continue_hb(s, 0.8, 1.2, stability=False, **kw)
    assert np.all(np.isnan(none.growth)) and not np.any(none.stable) and none.stability == "not-computed"
    assert branch_dataset(none).attrs["stability"] == "not-computed"
