"""Hill's eigenvalues by LAPACK over a stack of points (jointdyn.hb.stability): the batched
path against the eigenvalues of each point's companion matrix, the parity split, the selection
of the exponents against a direct reference, a closed form, and a failing matrix in a stack."""

import numpy as np
import pytest

from jointdyn import System
from jointdyn.laws import Jenkins


def _match_error(a, b):
    """Largest distance between the two multisets of eigenvalues (greedy pairing)."""
    b = list(b)
    err = 0.0
    for x in a:
        j = int(np.argmin([abs(x - y) for y in b]))
        err = max(err, abs(x - b.pop(j)))
    assert not b
    return err


def _branch_points(eta):
    from jointdyn.hb import continue_hb

    br = continue_hb(System.paper_damper(eta=eta, beta=2.0, model="iwan"), 0.9, 1.5, progress=False)
    p = br.problem
    JXs = np.array([p.evaluate(br.X[i], br.lam[i]).JX for i in range(br.lam.size)])
    ws = np.array([p.omega(g) for g in br.lam])
    return p, JXs, ws


@pytest.mark.parametrize("eta,splits", [(0.0, True), (0.5, False)])
def test_batch_matches_each_companion_and_splits_by_parity(eta, splits):
    # constant normal load: the orbit is half-wave symmetric, Hill's matrix is
    # block diagonal in the harmonic parity and is solved by blocks; a varying
    # load couples the parities and the whole matrix is solved
    from jointdyn.hb.stability import (_hill_eigvals_batch, _hill_eigvals_lapack, _hill_matrix, _hill_parts,
                                       _parity_blocks)

    p, JXs, ws = _branch_points(eta)
    M, C = p.system.M, p.system.C
    D2iJ, B1, _, parity = _hill_parts(M, C, p.H)
    lam, ok = _hill_eigvals_batch(D2iJ, JXs, B1[0], B1[1], ws, parity)
    whole, _ = _hill_eigvals_batch(D2iJ, JXs, B1[0], B1[1], ws, np.zeros_like(parity))
    assert ok.all() and lam.shape == (ws.size, 2 * JXs.shape[1])
    for k in range(ws.size):
        A = _hill_matrix(JXs[k], M, C, ws[k], p.H)
        assert (_parity_blocks(A, parity) is not None) == splits
        assert _match_error(lam[k], np.linalg.eigvals(A)) <= 1e-12 * ws[k]
        assert _match_error(lam[k], whole[k]) <= 1e-12 * ws[k]
        assert _match_error(lam[k], _hill_eigvals_lapack(JXs[k], M, C, ws[k], p.H)) <= 1e-12 * ws[k]


def _select_reference(lam, w, m):
    """The selection rule written out with Python's sort: smallest round(|Im| / w, 8) first (stable),
    the m first by decreasing real part (stable), and whether the cut is a tie."""
    keys = [round(abs(x.imag) / w, 8) for x in lam]
    order = sorted(range(len(lam)), key=lambda i: keys[i])
    sel = sorted((lam[i] for i in order[:m]), key=lambda x: -x.real)
    tie = len(lam) > m and keys[order[m]] == keys[order[m - 1]]
    return np.array(sel), tie


def test_selection_matches_a_direct_reference():
    from jointdyn.hb.stability import _select_batch

    rng = np.random.default_rng(4)
    lam = rng.standard_normal((40, 12)) + 1j * rng.standard_normal((40, 12))
    lam[:20, 3] = 0.5  # real eigenvalues: ties at key 0 in the first half
    lam[:20, 7] = -0.25
    lam[:20, 9] = 2.0
    ws = rng.uniform(0.5, 2.0, 40)
    for m in (1, 2, 3, 12):
        sel, tie = _select_batch(lam, ws, m)
        for k in range(40):
            ref, ref_tie = _select_reference(lam[k], ws[k], m)
            assert np.array_equal(sel[k], ref) and tie[k] == ref_tie
    assert _select_batch(lam[:1], ws[:1], 2)[1][0]  # three real eigenvalues, two selected: a tie


def test_linear_oscillator_exponents_are_the_roots_of_its_characteristic_polynomial():
    # no contact: Hill's exponents of the trivial orbit are the roots of m s^2 + c s + k
    from jointdyn.hb import HBProblem, hill_growth, hill_stability

    m, c, k = 2.0, 0.3, 50.0
    s = System(M=np.array([[m]]), C=np.array([[c]]), K=np.array([[k]]), force=np.array([1.0]), contacts=())
    p = HBProblem(s, harmonics=5, samples=32)
    JX = p.evaluate(np.zeros(p.size), 1.3).JX
    w = p.omega(1.3)
    roots = np.roots([m, c, k])
    stable, growth, mult = hill_stability(JX, s.M, s.C, w, p.H)
    assert stable and abs(growth - roots[0].real / w) <= 1e-12
    assert _match_error(mult, np.exp(roots * 2 * np.pi / w)) <= 1e-9  # the multipliers: |mult| < 1
    g = hill_growth(np.array([JX, JX]), s.M, s.C, np.array([w, w]), p.H)
    assert np.allclose(g, roots[0].real / w, rtol=1e-12, atol=0)


def test_a_failing_matrix_leaves_the_others_of_the_stack():
    from jointdyn.hb.stability import _stack_eigvals

    rng = np.random.default_rng(5)
    A = rng.standard_normal((4, 6, 6))
    A[2, 1, 1] = np.nan
    lam, ok = _stack_eigvals(A)
    assert ok.tolist() == [True, True, False, True] and np.isnan(lam[2]).all()
    for k in (0, 1, 3):
        assert np.array_equal(lam[k], np.linalg.eigvals(A[k]).astype(complex))


@pytest.mark.parametrize("eta", [0.0, 0.5])
def test_hill_growth_of_a_large_system(eta):
    # 10 DOFs, H = 7: a companion of 300 rows, above StabilityOptions.small_eig,
    # solved one point at a time by parity blocks of 150 rows (eta = 0) or
    # whole (eta > 0); the growth rates equal those of the batch to rounding
    from jointdyn.hb import HBProblem, StabilityOptions
    from jointdyn.hb.stability import _hill_growth_batch, _hill_parts, hill_growth
    from jointdyn.kinematics import HarmonicLoad
    from jointdyn.systems import Contact

    n = 10
    K = 3.9e5 * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    K[-1, -1] = 3.9e5
    law = Jenkins(kt=3e5, mu=0.5, n_ref=100.0)
    s = System(M=10.0 * np.eye(n), C=1e-4 * K, K=K, force=np.r_[40.0, np.zeros(n - 1)],
               contacts=(Contact(law=law, dof=0, normal=HarmonicLoad(100.0, eta * 100.0)),))
    p = HBProblem(s, harmonics=7, samples=64)
    assert 2 * p.size > StabilityOptions().small_eig
    gammas = (0.5, 1.1, 1.7)
    JXs = np.array([p.evaluate(p.linear_guess(g) * 30.0, g).JX for g in gammas])
    ws = np.array([p.omega(g) for g in gammas])
    got = hill_growth(JXs, s.M, s.C, ws, p.H)
    D2iJ, B1, _, parity = _hill_parts(s.M, s.C, p.H)
    ref, ok = _hill_growth_batch(D2iJ, JXs, B1[0], B1[1], ws, parity, 2 * n)
    assert ok.all() and np.allclose(got, ref, rtol=0, atol=1e-9)
