"""Harmonic balance of a sparse structure with modal damping kept as an operator.

Modal damping ``C = M Phi diag(2 zeta w) Phi^T M`` (:class:`jointdyn.damping.ModalDamping`)
is a full n x n matrix even where K and M are sparse: its blocks ``+-k w C``
would make the Jacobian of harmonic balance dense. Here C is split as

    C = C_R + (C - C_R),   C_R = alpha M + beta K

with C_R the Rayleigh damping closest to C in the modes
(:meth:`~jointdyn.damping.ModalDamping.rayleigh_fit`), which has the
pattern of K and M. The sparse pattern of :mod:`jointdyn.hb._sparse` takes
C_R, so that the Jacobian's sparse part S (the linear terms with C_R and
the pairs) factorises by SuperLU as for a Rayleigh-damped structure, and the
rest ``E = C - C_R`` enters the residual and the products with the Jacobian
exactly, as an operator (O(n m) per harmonic). The Jacobian
:class:`DampedJacobian` is ``S + blocks(k w E)``: the continuation's solves
(:class:`jointdyn.continuation.linalg.FactorReuse`) factorise S (its
``approximation``) and let GMRES on the exact product correct the rest,
which is a small part of the damping, itself small beside K and M; the
solution is accepted on its true residual only, else the whole matrix is
solved directly.
"""

from __future__ import annotations

import numpy as np

from ._jacobian import product_with_columns

__all__ = ["DampingSplit", "DampedJacobian"]


class DampingSplit:
    """C = C_R + E of a :class:`~jointdyn.damping.ModalDamping` on a structure (M, K) (module docstring).

    Attributes
    ----------
    rayleigh : ndarray (n, n)
        C_R = alpha M + beta K, N s/m (dense array with the pattern of K and M).
    alpha, beta : float
        Its coefficients, 1/s and s.
    """

    def __init__(self, C, M, K):
        import scipy.sparse as sps

        self.C = C
        self.alpha, self.beta = C.rayleigh_fit()
        self.rayleigh = self.alpha * np.asarray(M, dtype=np.float64) + self.beta * np.asarray(K, dtype=np.float64)
        self._R = sps.csr_matrix(self.rayleigh)

    def rest(self, V):
        """E V = (C - C_R) V for V (n,) or (n, k), N s/m times V's unit."""
        return self.C @ V - self._R @ V

    def harmonics(self, X, n: int, H: int, w: float):
        """The terms of E in harmonic balance at coefficients X (harmonic-major, n (2H+1)) and frequency w
        (rad/s): ``(Y, dY/dw)`` with Y on the cosine rows of harmonic k ``k w E b_k`` and on its sine rows
        ``-k w E a_k`` (a_k, b_k the cosine and sine coefficients)."""
        Xh = np.asarray(X, dtype=np.float64).reshape(2 * H + 1, n)
        k = np.arange(1, H + 1, dtype=np.float64)[:, None]
        EA = self.rest(Xh[1::2].T).T  # (H, n): E a_k
        EB = self.rest(Xh[2::2].T).T  # E b_k
        dY = np.zeros_like(Xh)
        dY[1::2] = k * EB
        dY[2::2] = -k * EA
        return (w * dY).ravel(), dY.ravel()


class DampedJacobian:
    """dR/dX = (S + blocks(k w E)) * scale, with some columns replaced whole (module docstring).

    Parameters
    ----------
    S : scipy.sparse.csr_matrix
        The sparse part (linear terms with C_R, pairs), N/m.
    split : DampingSplit
        The damping's split (E).
    n, H : int
        Unknown DOFs per coefficient, highest harmonic.
    w : float
        Frequency of the blocks, rad/s.
    """

    #: read by jointdyn.continuation.linalg: a product, columns, toarray, and a sparse approximation
    structured = True

    def __init__(self, S, split: DampingSplit, n: int, H: int, w: float, scale: float = 1.0, columns=None):
        self.S, self.split = S, split
        self.n, self.H, self.w = int(n), int(H), float(w)
        self.scale = float(scale)
        self.columns = {} if columns is None else dict(columns)  # column j -> its values (already scaled)
        self.shape = S.shape

    def _with(self, S=None, scale=None, columns=None) -> DampedJacobian:
        return DampedJacobian(self.S if S is None else S, self.split, self.n, self.H, self.w,
                              self.scale if scale is None else scale, self.columns if columns is None else columns)

    def scaled(self, f: float) -> DampedJacobian:
        """This Jacobian times f (replaced columns scaled)."""
        return self._with(scale=self.scale * f, columns={j: f * c for j, c in self.columns.items()})

    __mul__ = __rmul__ = scaled

    def plus_sparse(self, A) -> DampedJacobian:
        """This Jacobian plus the sparse A (in this Jacobian's unscaled units; no replaced columns yet)."""
        if self.columns:
            raise ValueError("plus_sparse: add to the sparse part before columns are replaced")
        return self._with(S=(self.S + A / self.scale).tocsr())

    def with_columns(self, columns: dict) -> DampedJacobian:
        """This Jacobian with columns ``j`` replaced by ``columns[j]`` (as they are: not scaled)."""
        return self._with(columns={**self.columns, **columns})

    def __matmul__(self, x):
        return product_with_columns(self._times, self.columns, self.scale, x)

    def _times(self, xs):
        return self.S @ xs + self.split.harmonics(xs, self.n, self.H, self.w)[0]

    def dot(self, x):
        return self @ x

    def column(self, j: int) -> np.ndarray:
        """Column j (size,)."""
        if j in self.columns:
            return np.array(self.columns[j])
        e = np.zeros(self.shape[1])
        e[j] = 1.0
        return (np.asarray(self.S[:, [j]].toarray()).ravel()
                + self.split.harmonics(e, self.n, self.H, self.w)[0]) * self.scale

    def approximation(self):
        """S (scaled, columns replaced) as a ``scipy.sparse.csc_matrix``: what the solves factorise."""
        import scipy.sparse as sps

        A = (self.S * self.scale).tocsc()
        if not self.columns:
            return A
        for j in self.columns:
            A.data[A.indptr[j]:A.indptr[j + 1]] = 0.0
        cols = list(self.columns)
        V = np.stack([self.columns[j] for j in cols], axis=1)
        r, c = np.nonzero(V)
        return (A + sps.csc_matrix((V[r, c], (r, np.asarray(cols)[c])), shape=A.shape)).tocsc()

    def toarray(self) -> np.ndarray:
        """The dense matrix (size x size)."""
        n, H, w = self.n, self.H, self.w
        A = self.S.toarray()
        E = self.split.C.toarray() - self.split.rayleigh
        for k in range(1, H + 1):
            c, s = (2 * k - 1) * n, 2 * k * n
            A[c:c + n, s:s + n] += (k * w) * E
            A[s:s + n, c:c + n] -= (k * w) * E
        A *= self.scale
        for j, col in self.columns.items():
            A[:, j] = col
        return A
