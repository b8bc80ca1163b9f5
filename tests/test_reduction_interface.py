"""Reduction onto an interface's node pairs (jointdyn.reduction.reduce_interface, issue 23 point 3).

Oracles: static condensation (no modes) reproduces the full model's static
response at the kept DOFs exactly, for any load; the reduced model's
dynamic stiffness at the kept DOFs differs from the full model's exactly by
the omitted fixed-interface modes' terms w^4 g_j g_j^T / (w_j^2 - w^2), so the
linear FRF error is the modal truncation error (zero with every mode kept,
vanishing like w^4 at low frequency); sparse input gives the dense result.
"""

import numpy as np
import pytest
import scipy.sparse as sp
from scipy.linalg import eigh

from jointdyn.reduction import craig_bampton, reduce_interface


def _two_bars(nodes=10, seed=3):
    """Two 3-D bars of ``nodes`` nodes (3 DOFs each; random SPD 3 x 3 springs between neighbours,
    consistent mass), bar A clamped at its first node, bar B at its last; the last 3 nodes of A face the
    first 3 of B. Returns sparse M, K and the pair table (a_xyz, b_xyz)."""
    rng = np.random.default_rng(seed)
    n = 6 * nodes
    K = np.zeros((n, n))
    M = np.zeros((n, n))
    for bar in range(2):
        for i in range(nodes - 1):
            A = rng.normal(size=(3, 3))
            k = 1e6 * (A @ A.T + 3.0 * np.eye(3))
            m = rng.uniform(0.5, 1.5)
            idx = np.r_[3 * (bar * nodes + i) : 3 * (bar * nodes + i) + 6]
            K[np.ix_(idx, idx)] += np.kron([[1.0, -1.0], [-1.0, 1.0]], k)
            M[np.ix_(idx, idx)] += np.kron(m / 6.0 * np.array([[2.0, 1.0], [1.0, 2.0]]), np.eye(3))
    for node in (0, 2 * nodes - 1):  # clamps: stiff ground springs
        K[3 * node : 3 * node + 3, 3 * node : 3 * node + 3] += 1e8 * np.eye(3)
    a = [3 * (nodes - 3 + j) + np.arange(3) for j in range(3)]
    b = [3 * (nodes + j) + np.arange(3) for j in range(3)]
    pairs = np.array([np.concatenate([x, y]) for x, y in zip(a, b)])
    return sp.csr_matrix(M), sp.csr_matrix(K), pairs


def _frf(M, K, w, rows):
    """Receptance of the kept DOFs (rows), dense."""
    D = (K - w**2 * M).toarray() if sp.issparse(K) else K - w**2 * M
    return np.linalg.inv(D)[np.ix_(rows, rows)]


def _omitted_terms(M, K, boundary, kept_modes, w):
    """w^4 sum over the omitted fixed-interface modes of g_j g_j^T / (w_j^2 - w^2)."""
    M, K = M.toarray(), K.toarray()
    interior = np.setdiff1d(np.arange(M.shape[0]), boundary)
    Kii, Mii = K[np.ix_(interior, interior)], M[np.ix_(interior, interior)]
    lam, phi = eigh(Kii, Mii)
    Psi = -np.linalg.solve(Kii, K[np.ix_(interior, boundary)])
    g = phi.T @ (M[np.ix_(interior, boundary)] + Mii @ Psi)  # (modes, nb)
    g, lam = g[kept_modes:], lam[kept_modes:]
    return w**4 * (g.T / (lam - w**2)) @ g, np.sqrt(lam[0]) if lam.size else np.inf


def test_static_condensation_is_exact_for_any_load():
    M, K, pairs = _two_bars()
    rng = np.random.default_rng(1)
    f = rng.normal(size=M.shape[0])
    red = reduce_interface(M, K, pairs, 0, force=f, keep=[4])
    b = red.reduction.boundary
    x = np.linalg.solve(K.toarray(), f)
    xr = np.linalg.solve(red.K, red.force)
    np.testing.assert_allclose(xr, x[b], rtol=1e-11, atol=1e-12 * np.max(np.abs(x)))
    fb = np.zeros_like(f)  # loads on the kept DOFs only: the whole static response is exact
    fb[b] = f[b]
    x = np.linalg.solve(K.toarray(), fb)
    xr = np.linalg.solve(red.K, red.reduction.T.T @ fb)
    np.testing.assert_allclose(red.reduction.expand(xr), x, rtol=1e-10, atol=1e-11 * np.max(np.abs(x)))


@pytest.mark.parametrize("n_modes", [0, 3, 8])
def test_frf_error_is_exactly_the_omitted_modes(n_modes):
    M, K, pairs = _two_bars()
    red = reduce_interface(M, K, pairs, n_modes, keep=[7])
    b = red.reduction.boundary
    nb = b.size
    w1 = red.reduction.error.w_full_rad_s[0]
    for w in (0.3 * w1, 1.7 * w1, 3.1 * w1):
        H_full = _frf(M, K, w, b)
        H_red = _frf(red.M, red.K, w, np.arange(nb))
        delta, _ = _omitted_terms(M, K, b, n_modes, w)
        D_full = np.linalg.inv(H_full)
        np.testing.assert_allclose(np.linalg.inv(H_red) - delta, D_full, atol=1e-9 * np.max(np.abs(D_full)))


def test_frf_exact_with_every_mode_and_at_low_frequency():
    M, K, pairs = _two_bars()
    n = M.shape[0]
    every = reduce_interface(M, K, pairs, n - 18 - 1, keep=[7])
    w1 = every.reduction.error.w_full_rad_s[0]
    b = every.reduction.boundary
    for w in (0.01 * w1, 0.9 * w1, 2.5 * w1, 7.0 * w1):
        H = _frf(M, K, w, b)
        np.testing.assert_allclose(_frf(every.M, every.K, w, np.arange(b.size)), H, atol=1e-9 * np.max(np.abs(H)))
    # with a few modes the error vanishes like w^4 below the first omitted interior mode
    red = reduce_interface(M, K, pairs, 6, keep=[7])
    errs = []
    for w in (0.01 * w1, 0.02 * w1):
        H = _frf(M, K, w, b)
        errs.append(np.max(np.abs(_frf(red.M, red.K, w, np.arange(b.size)) - H)) / np.max(np.abs(H)))
    _, w_next = _omitted_terms(M, K, b, 6, 0.0)
    assert errs[0] < (0.01 * w1 / w_next) ** 4 * 10.0
    assert errs[0] < 1e-9
    assert 8.0 < errs[1] / errs[0] < 24.0  # w^4 (16), within rounding of the small errors


def test_pairs_and_kept_dofs_map_to_the_physical_dofs():
    M, K, pairs = _two_bars()
    grounded = pairs.copy()
    grounded[2, 3:] = -1
    f = np.zeros(M.shape[0])
    f[7], f[30] = 2.0, 3.0
    red = reduce_interface(M, K, grounded, 4, force=f, keep=[7, pairs[0, 1]])
    T = red.reduction.T
    for full, reduced in zip(grounded.ravel(), red.pairs.ravel()):
        if full < 0:
            assert reduced == -1
        else:
            np.testing.assert_array_equal(T[full], np.eye(T.shape[1])[reduced])
    assert red.pairs[0].tolist() == list(range(6))  # the pair table's order
    assert red.kept.tolist() == [15, 1]  # 15 interface DOFs first, then DOF 7; DOF pairs[0, 1] is coordinate 1
    assert red.force[15] == 2.0
    np.testing.assert_allclose(red.force, T.T @ f)
    s = red.system()
    assert s.output_dof == 15 and s.ndof == red.size and not s.contacts


def test_sparse_and_dense_input_give_the_same_reduction():
    M, K, pairs = _two_bars()
    C = 1e-4 * K
    b = np.unique(pairs)
    d = craig_bampton(M.toarray(), K.toarray(), b, 5, C=C.toarray())
    s = craig_bampton(M, K, b, 5, C=C)
    nb = b.size
    np.testing.assert_allclose(s.K[:nb, :nb], d.K[:nb, :nb], rtol=1e-10, atol=1e-10 * np.max(np.abs(d.K)))
    np.testing.assert_allclose(s.M[:nb, :nb], d.M[:nb, :nb], rtol=1e-10, atol=1e-12 * np.max(np.abs(d.M)))
    np.testing.assert_allclose(s.interior_w_rad_s, d.interior_w_rad_s, rtol=1e-10)
    np.testing.assert_allclose(s.error.w_reduced_rad_s, d.error.w_reduced_rad_s[: s.error.w_reduced_rad_s.size],
                               rtol=1e-10)  # fmt: skip
    np.testing.assert_allclose(s.error.w_full_rad_s, d.error.w_full_rad_s[: s.error.w_full_rad_s.size], rtol=1e-10)
    np.testing.assert_allclose(s.error.mac, d.error.mac[: s.error.mac.size], atol=1e-10)
    # modal columns up to sign: the same projected matrices
    np.testing.assert_allclose(s.T @ s.K @ s.T.T, d.T @ d.K @ d.T.T, atol=1e-9 * np.max(np.abs(K)))
    np.testing.assert_allclose(s.C[:nb, :nb], d.C[:nb, :nb], atol=1e-12 * np.max(np.abs(d.C)))


@pytest.mark.parametrize("kwargs, match", [
    (dict(pairs=np.zeros((2, 5), dtype=int)), r"pairs must be an integer array of shape \(npairs, 6\)"),
    (dict(pairs=np.full((1, 6), 60)), r"pairs must hold DOFs in \[0, 59\]"),
    (dict(pairs=np.full((1, 6), -2)), "pairs must hold DOF indices or -1"),
    (dict(force=np.ones(3)), "force and force_phase_deg must have 60 entries"),
    (dict(n_modes=60), r"n_modes must be in \[0, 42\]"),
])  # fmt: skip
def test_bad_input_names_the_parameter(kwargs, match):
    M, K, pairs = _two_bars()
    args = dict(pairs=pairs, n_modes=2) | kwargs
    with pytest.raises(ValueError, match=match):
        reduce_interface(M, K, args.pop("pairs"), args.pop("n_modes"), **args)


def test_interior_block_must_be_positive_definite():
    M, K, pairs = _two_bars()
    K = K.tolil()
    K[0, 0] = K[0, 0] - 1e8 - 1e7 * 20  # a clamp undone and more: K_ii indefinite
    with pytest.raises(ValueError, match="interior block"):
        reduce_interface(M, K.tocsr(), pairs, 2)


def test_pairs_in_tilted_frames_end_to_end():
    """Global model + springs along each pair's (t1, t2, n) in global coordinates has the natural frequencies
    of the reduced model in pair frames + springs on the pair DOFs (every interior mode kept: to rounding;
    a few: from above, close)."""
    from jointdyn.fe import interface_from_triplets, pair_springs

    M, K, pairs = _two_bars()
    n = M.shape[0]
    normals = np.array([[0.2, -0.3, 1.0], [1.0, 0.5, -0.2], [-0.4, 1.0, 0.3]])
    table = interface_from_triplets(pairs[:, :3], pairs[:, 3:], normals, n)
    kt, kn = np.array([2e6, 3e6, 4e6]), np.array([5e6, 6e6, 7e6])
    S = np.zeros((n, n))
    for i, R in enumerate(table.frames):
        k_local = np.diag([kt[i], kt[i], kn[i]])
        k_global = R.T @ k_local @ R  # force = k (x_a - x_b), the relative motion in global components
        a, b = pairs[i, :3], pairs[i, 3:]
        for p, q, sign in ((a, a, 1.0), (b, b, 1.0), (a, b, -1.0), (b, a, -1.0)):
            S[np.ix_(p, q)] += sign * k_global
    full = np.sqrt(eigh(K.toarray() + S, M.toarray(), eigvals_only=True)[:6])
    for n_modes, rtol in ((n - 18, 1e-10), (10, 2e-3)):
        red = reduce_interface(table.to_local(M), table.to_local(K), table.pairs, n_modes)
        Kr = red.K + pair_springs(red.pairs, kt, kn, red.size).toarray()
        w = np.sqrt(eigh(Kr, red.M, eigvals_only=True)[:6])
        assert np.all(w >= full * (1 - 1e-12))
        np.testing.assert_allclose(w, full, rtol=rtol)
