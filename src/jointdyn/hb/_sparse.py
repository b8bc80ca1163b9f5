"""Sparse Jacobians of harmonic balance: interfaces on a structure with sparse K, M and C.

The Jacobian dR/dX of harmonic balance is the sum of the linear terms,
which couple the coefficients of one harmonic only (per harmonic the
blocks of K, M and C: as sparse as the structure), and of each node pair's
``3 (2H+1)`` x ``3 (2H+1)`` Jacobian of its projected forces along its own
relative coordinates, scattered with signs on its six DOFs. Where both
are sparse (a chain or an FE mesh with its pairs on their own DOFs), the
dense N x N Jacobian costs more to write, scan and copy than everything
else of an evaluation at thousands of unknowns; :class:`SparsePattern`
holds the union of both patterns as a CSR structure, built once per
problem, and assembles the Jacobian's entries into it by two index maps.
The values are those of the dense evaluation up to the order of the sums.
"""

from __future__ import annotations

import numpy as np

__all__ = ["SparsePattern", "linear_entries"]


def linear_entries(K, C, M, H):
    """(rows, cols, ak, ac, am): the entries of AK, AC and AM (``A(w) = AK + w AC + w^2 AM``, the linear
    terms of harmonics 0..H, also the dense ones of :func:`jointdyn.hb.problem._linear_blocks`) on their
    union pattern, from the
    nonzeros of K, C and M: per harmonic k the blocks ``K - k^2 w^2 M`` on its cosine and sine rows and
    ``+-k w C`` between them."""
    n = K.shape[0]
    i, j = np.nonzero((K != 0.0) | (M != 0.0))
    kij, mij = K[i, j], M[i, j]
    ci, cj = np.nonzero(C)
    cij = C[ci, cj]
    z, zc = np.zeros(i.size), np.zeros(ci.size)
    out = [[i], [j], [kij], [z], [z]]  # harmonic 0: K
    for k in range(1, H + 1):
        ic, is_ = (2 * k - 1) * n, 2 * k * n
        for lst, v in zip(out, (i + ic, j + ic, kij, z, -(k * k) * mij)):  # cosine rows, cosine columns
            lst.append(v)
        for lst, v in zip(out, (i + is_, j + is_, kij, z, -(k * k) * mij)):  # sine rows, sine columns
            lst.append(v)
        for lst, v in zip(out, (ci + ic, cj + is_, zc, k * cij, zc)):  # cosine rows, sine columns
            lst.append(v)
        for lst, v in zip(out, (ci + is_, cj + ic, zc, -k * cij, zc)):  # sine rows, cosine columns
            lst.append(v)
    return tuple(np.concatenate(v) for v in out)


def _pair_entries(positions, n, nh):
    """(rows, cols, src, sign) of the pairs' Jacobian blocks scattered on their DOFs: entry
    ``src`` of the stacked pair Jacobians (pairs, 3 nh, 3 nh), with its sign (+ on side A, - on B)."""
    npairs = positions.shape[0]
    nd = 3 * nh
    i, k, sr, h, m, sc, g = np.meshgrid(np.arange(npairs), np.arange(3), np.arange(2), np.arange(nh),
                                        np.arange(3), np.arange(2), np.arange(nh), indexing="ij", sparse=True)
    r = positions[i, k + 3 * sr]
    c = positions[i, m + 3 * sc]
    shape = np.broadcast_shapes(r.shape, c.shape, h.shape, g.shape)
    ok = np.broadcast_to((r >= 0) & (c >= 0), shape)
    rows = np.broadcast_to(h * n + r, shape)[ok]
    cols = np.broadcast_to(g * n + c, shape)[ok]
    src = np.broadcast_to(i * nd * nd + (k * nh + h) * nd + (m * nh + g), shape)[ok]
    sign = np.broadcast_to((1.0 - 2.0 * sr) * (1.0 - 2.0 * sc), shape)[ok]
    return rows, cols, src, sign


class SparsePattern:
    """The CSR structure of dR/dX for the linear terms and the pairs of a problem, and its assembly.

    Parameters
    ----------
    KCM : tuple of ndarray
        The structure's K (N/m), C (N s/m) and M (kg), (n, n): every DOF an unknown.
    H : int
        Highest harmonic.
    positions : ndarray of int (pairs, 6)
        Positions of each pair's DOFs among the unknown DOFs (-1: fixed).
    """

    def __init__(self, KCM, H: int, positions):
        K, C, M = (np.asarray(a, dtype=np.float64) for a in KCM)
        n, nh = K.shape[0], 2 * H + 1
        size = n * nh
        self.size = size
        self.rows, self.cols, self.ak, self.ac, self.am = linear_entries(K, C, M, H)
        prow, pcol, self.psrc, self.psign = _pair_entries(positions, n, nh)
        keys = np.concatenate((self.rows * size + self.cols, prow * size + pcol))
        ukeys, inv = np.unique(keys, return_inverse=True)
        #: where each entry (linear terms, then pairs) is added among the CSR entries
        self.map = inv
        self.nl = self.rows.size
        self.indices = (ukeys % size).astype(np.int32)
        self.indptr = np.concatenate(([0], np.cumsum(np.bincount(ukeys // size, minlength=size)))).astype(np.int32)
        self.nnz = ukeys.size

    @property
    def density(self) -> float:
        """Fraction of the N^2 entries in the pattern."""
        return self.nnz / float(self.size) ** 2

    def linear(self, X, w, dwdp, Fe, Fp):
        """``(R, Jp, values)`` of the linear terms at X (m) and w (rad/s): ``R = A X - Fe``,
        ``Jp = dwdp (AC + 2 w AM) X - Fp`` and the entries of A."""
        vals = self.ak + w * self.ac + (w * w) * self.am
        Xc = X[self.cols]
        R = np.bincount(self.rows, weights=vals * Xc, minlength=self.size) - Fe
        Jp = dwdp * np.bincount(self.rows, weights=(self.ac + (2.0 * w) * self.am) * Xc, minlength=self.size) - Fp
        return R, Jp, vals

    def jacobian(self, lin_values, G):
        """dR/dX (``scipy.sparse.csr_matrix``, N/m) from the linear entries and the pairs' Jacobians
        ``G`` (pairs, 3 nh, 3 nh)."""
        import scipy.sparse as sps

        w = np.concatenate((lin_values, self.psign * G.ravel()[self.psrc]))
        data = np.bincount(self.map, weights=w, minlength=self.nnz)
        return sps.csr_matrix((data, self.indices, self.indptr), shape=(self.size, self.size))
