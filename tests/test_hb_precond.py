"""Newton-Krylov preconditioned by the harmonic blocks (jointdyn.hb._precond, continuation.linalg).

Oracles: the exact solution of the bordered system (LAPACK on the assembled matrix), and the direct
dense path of the same walks (one LU of the whole bordered matrix, reused through GMRES): backbones,
branches and peaks must agree to 1e-8 on a dense reduced model (every DOF coupled to every other) with
modal damping (a dense C), where the preconditioner is not exact (pairs in partial slip couple the
harmonics) and GMRES must make up the difference.
"""

from __future__ import annotations

import numpy as np
import pytest

import jointdyn as jd
from jointdyn import config
from jointdyn.continuation import LinearSolveOptions, linalg
from jointdyn.hb import HBOptions
from jointdyn.hb._precond import HarmonicBlocks, harmonic_blocks
from jointdyn.hb.problem import HBProblem, reference_scales
from jointdyn.interfaces import Interface


def _dense_reduced(nodes=3, zeta=0.01):
    """A structure dense on its DOFs (as a Craig-Bampton model is on its interface): two bodies of
    ``nodes`` nodes (t1, t2, n) each, every DOF of a body coupled to every other, pressed together
    node to node by pairs, with modal damping (a dense C) and forcing on the first node."""
    n = 6 * nodes
    rng = np.random.default_rng(7)
    K = np.zeros((n, n))
    for body in range(2):
        d = slice(3 * nodes * body, 3 * nodes * (body + 1))
        A = rng.standard_normal((3 * nodes, 3 * nodes))
        K[d, d] = 2e3 * (A @ A.T) / (3 * nodes) + 3e3 * np.eye(3 * nodes)
    M = np.diag(rng.uniform(0.05, 0.15, n))
    M[:3 * nodes, :3 * nodes] += 0.01  # a dense mass too
    C = jd.modal_damping(M, K, zeta)
    table = [[3 * i, 3 * i + 1, 3 * i + 2, 3 * (nodes + i), 3 * (nodes + i) + 1, 3 * (nodes + i) + 2]
             for i in range(nodes)]
    itf = Interface(kt=3e3, kn=6e3, mu=0.3, preload=np.linspace(1.0, 2.0, nodes), pairs=np.array(table))
    f = np.zeros(n)
    f[0], f[1] = 1.0, 0.6
    return jd.System(M=M, C=C, K=K, interfaces=(itf,), force=f, output_dof=0)


def test_blocks_are_those_of_the_harmonics():
    assert harmonic_blocks(4, 2) == [(0, 4), (4, 12), (12, 20)]


@pytest.mark.parametrize("cols", [(), (5, 13)])
@pytest.mark.parametrize("bordered", [False, True])
def test_corrected_preconditioner_is_exact_on_a_block_diagonal_matrix(cols, bordered):
    """Where R_y is block diagonal over harmonics apart from the exact columns, the corrected
    preconditioner is R_y's bordered matrix itself: its solve is the exact solution."""
    rng = np.random.default_rng(1)
    n, H = 4, 2
    size = n * (2 * H + 1)
    J = np.zeros((size, size))
    for lo, hi in harmonic_blocks(n, H):
        J[lo:hi, lo:hi] = rng.standard_normal((hi - lo, hi - lo)) + 5 * np.eye(hi - lo)
    for j in cols:
        J[:, j] = rng.standard_normal(size)
    Jl = rng.standard_normal(size)
    d = rng.standard_normal(size + 1) if bordered else np.zeros(0)
    f = HarmonicBlocks(n, H, cols).factor(J)
    P = linalg._Corrected.of(f, J, Jl, d)
    A = linalg._bordered(J, Jl, d)
    b = rng.standard_normal(A.shape[0])
    np.testing.assert_allclose(P.solve(b), np.linalg.solve(A, b), rtol=1e-10, atol=1e-12)


def test_structured_solve_meets_the_tolerance_on_a_coupled_matrix(monkeypatch):
    """With harmonics coupled on a few DOFs (pairs in partial slip), GMRES with the blocks' factors
    reaches the solution of the whole bordered system; the factors are kept for the next matrix."""
    import scipy.sparse as sps

    rng = np.random.default_rng(3)
    n, H = 30, 3
    size = n * (2 * H + 1)
    J = np.zeros((size, size))
    for lo, hi in harmonic_blocks(n, H):
        J[lo:hi, lo:hi] = rng.standard_normal((hi - lo, hi - lo)) + 20 * np.eye(hi - lo)
    dofs = np.concatenate([h * n + np.arange(3) for h in range(2 * H + 1)])
    J[np.ix_(dofs, dofs)] += 0.5 * rng.standard_normal((dofs.size, dofs.size))
    Jl = rng.standard_normal(size)
    d = rng.standard_normal(size + 1)
    b = rng.standard_normal(size + 1)
    exact = np.linalg.solve(linalg._bordered(J, Jl, d), b)
    for A in (J, sps.csr_matrix(J)):
        fr = linalg.FactorReuse(HarmonicBlocks(n, H))
        x, ok = fr.solve(A, Jl, d, b)
        assert ok and fr.counts["block_factorisations"] == 1 and fr.counts["factorisations"] == 0
        np.testing.assert_allclose(x, exact, rtol=1e-7, atol=1e-9 * np.abs(exact).max())
        assert fr.counts["krylov_iterations"] <= LinearSolveOptions().krylov_refresh
        A2 = A + 1e-3 * (sps.identity(size) if sps.issparse(A) else np.eye(size))
        x, ok = fr.solve(A2, Jl, d, b)
        np.testing.assert_allclose(x, np.linalg.solve(linalg._bordered(A2 if isinstance(A2, np.ndarray) else
                                                                       A2.toarray(), Jl, d), b), rtol=1e-7,
                                   atol=1e-9 * np.abs(exact).max())
        assert ok and fr.counts["block_factorisations"] == 1 and fr.counts["krylov_solves"] == 2


def _large(monkeypatch, on: bool):
    """The large-problem path at this small size: direct (on False) or preconditioned by the blocks; returns
    the keyword arguments of that path (the linear-solve options and harmonic balance's options)."""
    # CONT_KRYLOV_SOLVE and CONT_SPARSE_DENSITY are shared (the walk's solves and the form harmonic balance and
    # EPMC give their Jacobians): patched here so that both take the large path at this small size
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)
    return {"linear": LinearSolveOptions(small_solve=0),
            "hb_options": HBOptions(dense_max_unknowns=0, block_preconditioner=on)}


def test_hb_branch_on_a_dense_reduced_model_equals_the_direct_path(monkeypatch):
    from jointdyn.hb import continue_hb

    s = _dense_reduced()
    w0 = s.w0
    kw = dict(harmonics=3, samples=32, condense=False)
    out = {}
    for on in (False, True):
        out[on] = continue_hb(s, 0.8, 1.25, **_large(monkeypatch, on), **kw)
    a, b = out[False], out[True]
    assert HBProblem(s, harmonics=3, samples=32).large_jacobian() == "blocks"  # (the blocks by default)
    assert a.status.ok and b.status.ok
    # the whole bordered matrix factorised only where fresh blocks did not reach the tolerance
    assert b.counters["block_factorisations"] > 0 and b.counters["factorisations"] < a.counters["factorisations"] / 4
    assert b.counters["factorisations"] <= b.counters["block_fallbacks"]
    assert "block_factorisations" not in a.counters and a.counters["factorisations"] > 0
    assert a.lam.size == b.lam.size
    np.testing.assert_allclose(b.lam, a.lam, rtol=1e-8, atol=0)
    np.testing.assert_allclose(b.X, a.X, rtol=0, atol=1e-8 * np.abs(a.X).max())
    pa, pb = a.peaks[0], b.peaks[0]
    assert pb.gamma == pytest.approx(pa.gamma, rel=1e-8) and pb.amplitude_m == pytest.approx(pa.amplitude_m, rel=1e-8)
    assert w0 > 0


def test_epmc_backbone_on_a_dense_reduced_model_equals_the_direct_path(monkeypatch):
    from jointdyn.modes import epmc

    s = _dense_reduced()
    s = jd.System(M=s.M, C=s.C, K=s.K, interfaces=s.interfaces, output_dof=0)
    kt, fy = reference_scales(s)
    rng_a = (0.01 * fy / kt, 10.0 * fy / kt)
    out = {}
    for on in (False, True):
        out[on] = epmc(s, rng_a, harmonics=3, samples=32, **_large(monkeypatch, on))
    a, b = out[False], out[True]
    assert a.status.ok and b.status.ok
    assert b.counters["block_factorisations"] > 0 and b.counters["factorisations"] < a.counters["factorisations"] / 4
    assert a.amplitude_m.size == b.amplitude_m.size >= 10
    for name in ("amplitude_m", "omega_rad_s", "damping_ratio"):
        np.testing.assert_allclose(getattr(b, name), getattr(a, name), rtol=1e-8)
    # the damping grew from the modal value by the joint's slip: partial slip was crossed
    assert b.damping_ratio.max() > 2 * b.damping_ratio[0]


@pytest.mark.parametrize("scale", [1e-3, 0.5, 5.0])
def test_block_evaluation_equals_the_dense_one(scale):
    """The Jacobian kept in its harmonic blocks (HBProblem.evaluate_blocks) against the dense evaluation:
    residual, Jacobian, parameter derivative and pair outputs, from all stuck to slip and separation."""
    s = _dense_reduced()
    q = HBProblem(s, harmonics=3, samples=32)
    kt, fy = reference_scales(s)
    rng = np.random.default_rng(int(scale * 100))
    X = rng.standard_normal(q.size) * scale * fy / kt
    for p in (0.9, 1.2):
        a, b = q.evaluate(X, p), q.evaluate_blocks(X, p)
        for u, v in ((a.R, b.R), (a.JX, b.JX.toarray()), (a.Jp, b.Jp)):
            assert np.max(np.abs(u - v)) <= 1e-13 * np.max(np.abs(u))
        np.testing.assert_array_equal(a.pair_code, b.pair_code)
        np.testing.assert_array_equal(a.pair_T, b.pair_T)
        J = b.JX.scaled(0.5).with_columns({4: np.arange(q.size, dtype=float)})
        D = 0.5 * a.JX
        D[:, 4] = np.arange(q.size)
        x = rng.standard_normal(q.size)
        np.testing.assert_allclose(J @ x, D @ x, rtol=1e-12, atol=1e-12 * np.abs(D @ x).max())
        np.testing.assert_allclose(J.toarray(), D, rtol=0, atol=1e-13 * np.abs(D).max())
        for j in (0, 4, q.size - 1):
            np.testing.assert_allclose(J.column(j), D[:, j], rtol=0, atol=1e-13 * np.abs(D).max())
        np.testing.assert_allclose(J.block(1), D[18:54, 18:54], rtol=0, atol=1e-13 * np.abs(D).max())


def test_linear_guess_by_harmonic_blocks_equals_the_whole_solve(monkeypatch):
    s = _dense_reduced()
    q = HBProblem(s, harmonics=3, samples=32)
    a = q.linear_guess(1.1)
    monkeypatch.setattr(config, "CONT_KRYLOV_SOLVE", 0)  # shared (config): the solves and the Jacobian's form
    b = q.linear_guess(1.1)
    np.testing.assert_allclose(b, a, rtol=0, atol=1e-12 * np.abs(a).max())
