"""The compiled eigenvalue solver of Hill's method (jointdyn.hb._eig)
against LAPACK (numpy.linalg.eigvals): random, graded, structured and
degenerate matrices, and Hill matrices along a harmonic-balance branch."""

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from jointdyn import System
from jointdyn.hb._eig import eigvals_real
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


def _check(A, rtol=1e-11):
    lam, ok = eigvals_real(A)
    ref = np.linalg.eigvals(A)
    assert ok
    assert lam.shape == ref.shape
    scale = max(np.abs(ref).max(), np.abs(A).max(), 1e-300)
    assert _match_error(lam, ref) <= rtol * scale
    # conjugate pairs come together, positive imaginary part first
    i = 0
    while i < lam.size:
        if lam[i].imag != 0.0:
            assert lam[i].imag > 0 and lam[i + 1] == np.conj(lam[i])
            i += 2
        else:
            i += 1


@settings(max_examples=150, deadline=None)
@given(n=st.integers(1, 40), seed=st.integers(0, 2**32 - 1), grade=st.floats(0.0, 4.0))
def test_random_graded_matrices_match_lapack(n, seed, grade):
    rng = np.random.default_rng(seed)
    rows = 10.0 ** rng.uniform(-grade, grade, size=(n, 1))
    cols = 10.0 ** rng.uniform(-grade, grade, size=(1, n))
    _check(rng.standard_normal((n, n)) * rows * cols)


@pytest.mark.parametrize("case", ["zero", "identity", "diag", "triangular", "rotation", "companion", "jordan",
                                  "permutation", "nilpotent-shift"])
def test_structured_matrices_match_lapack(case):
    n = 12
    rng = np.random.default_rng(3)
    A = {
        "zero": np.zeros((n, n)),
        "identity": np.eye(n),
        "diag": np.diag(rng.standard_normal(n)),
        "triangular": np.triu(rng.standard_normal((n, n))),
        "rotation": np.kron(np.eye(n // 2), np.array([[0.0, -2.0], [2.0, 0.0]])),
        "companion": np.vstack([np.eye(n)[1:], -rng.standard_normal(n)]).T,
        "jordan": 2.0 * np.eye(n) + np.diag(np.ones(n - 1), 1),
        "permutation": np.roll(np.eye(n), 1, axis=0),
        "nilpotent-shift": np.diag(np.ones(n - 1), -1) + 1e-3 * np.eye(n),
    }[case]
    # defective matrices (jordan, shift) have eigenvalues sensitive to
    # rounding at the n-th root of eps: compare the spectra loosely there
    rtol = 1e-2 if case in ("jordan", "nilpotent-shift") else 1e-11
    _check(A, rtol)


def test_input_not_modified():
    A = np.random.default_rng(0).standard_normal((7, 7))
    B = A.copy()
    eigvals_real(A)
    assert np.array_equal(A, B)


def test_hill_matrices_along_a_branch_match_lapack():
    from jointdyn.hb import continue_hb
    from jointdyn.hb.stability import _hill_matrix

    law = Jenkins(kt=3e5, mu=0.5, n_ref=100.0)
    br = continue_hb(System.sdof(m=10.0, k=3.9e5, law=law, f1=20.0, zeta=1e-3), 0.9, 1.5, progress=False)
    p = br.problem
    for i in range(0, br.lam.size, 3):
        ev = p.evaluate(br.X[i], br.lam[i])
        _check(_hill_matrix(ev.JX, p.system.M, p.system.C, p.omega(br.lam[i]), p.H), 1e-12)


@pytest.mark.parametrize("eta,splits", [(0.0, True), (0.5, False)])
def test_hill_parity_split_matches_lapack(eta, splits):
    # constant normal load: the orbit is half-wave symmetric, Hill's matrix
    # is block diagonal in the harmonic parity and is solved by blocks; a
    # varying load couples the parities and the whole matrix is solved
    from jointdyn.hb import continue_hb
    from jointdyn.hb.stability import _hill_eigvals, _hill_matrix, _hill_parts

    br = continue_hb(System.paper_damper(eta=eta, beta=2.0, model="iwan"), 0.9, 1.5, progress=False)
    p = br.problem
    D2iJ, B1, _, parity = _hill_parts(p.system.M, p.system.C, p.H)
    for i in range(0, br.lam.size, 4):
        ev = p.evaluate(br.X[i], br.lam[i])
        w = p.omega(br.lam[i])
        lam, ok = _hill_eigvals(D2iJ, ev.JX, B1[0], B1[1], w, parity)
        whole, _ = _hill_eigvals(D2iJ, ev.JX, B1[0], B1[1], w, np.zeros_like(parity))
        assert ok
        assert (not np.array_equal(lam, whole)) == splits
        ref = np.linalg.eigvals(_hill_matrix(ev.JX, p.system.M, p.system.C, w, p.H))
        assert _match_error(lam, ref) <= 1e-12 * w


@pytest.mark.parametrize("eta", [0.0, 0.5])
def test_lapack_and_compiled_hill_paths_agree(eta):
    # the two paths of Hill's eigenvalues (compiled EISPACK for small
    # companions, LAPACK above StabilityOptions.small_eig): same spectrum to rounding,
    # same parity split decision
    from jointdyn.hb import continue_hb
    from jointdyn.hb.stability import _hill_eigvals, _hill_eigvals_lapack, _hill_matrix, _hill_parts, _parity_blocks

    br = continue_hb(System.paper_damper(eta=eta, beta=2.0, model="iwan"), 0.9, 1.5, progress=False)
    p = br.problem
    M, C = p.system.M, p.system.C
    D2iJ, B1, _, parity = _hill_parts(M, C, p.H)
    for i in range(0, br.lam.size, 4):
        ev = p.evaluate(br.X[i], br.lam[i])
        w = p.omega(br.lam[i])
        lam, ok = _hill_eigvals(D2iJ, ev.JX, B1[0], B1[1], w, parity)
        whole, _ = _hill_eigvals(D2iJ, ev.JX, B1[0], B1[1], w, np.zeros_like(parity))
        split = _parity_blocks(_hill_matrix(ev.JX, M, C, w, p.H), parity) is not None
        assert ok and split == (not np.array_equal(lam, whole))
        assert _match_error(_hill_eigvals_lapack(ev.JX, M, C, w, p.H), lam) <= 1e-12 * w


@pytest.mark.parametrize("eta", [0.0, 0.5])
def test_hill_growth_of_a_large_system(eta):
    # 10 DOFs, H = 7: a companion of 300 rows, above StabilityOptions.small_eig,
    # assembled with NumPy and solved by parity blocks of 150 rows (compiled
    # EISPACK, eta = 0) or whole (LAPACK, eta > 0); the growth rates equal
    # those of the all-compiled batch to rounding
    from jointdyn.hb import HBProblem, StabilityOptions
    from jointdyn.hb.stability import _hill_growth_batch, _hill_parts, hill_growth

    n = 10
    K = 3.9e5 * (2 * np.eye(n) - np.eye(n, k=1) - np.eye(n, k=-1))
    K[-1, -1] = 3.9e5
    law = Jenkins(kt=3e5, mu=0.5, n_ref=100.0)
    from jointdyn.kinematics import HarmonicLoad
    from jointdyn.systems import Contact

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
