"""The Jacobian of harmonic balance as its structure: dense blocks per harmonic plus the pairs' sparse part.

For a structure dense on its DOFs (a reduced model: every interface DOF
coupled to every other), the linear terms are (2H + 1) dense N x N blocks
(the mean's, and per harmonic the 2N x 2N block of its cosine and sine),
while the pairs add their 3 (2H + 1) x 3 (2H + 1) blocks on their own DOFs.
Assembled into one sparse matrix, the dense blocks cost more to write,
sum, convert and copy at every evaluation than everything else (the lap
joint at H = 3: 5 million entries, 0.3 s per evaluation against 6 ms for
the pairs' AFT); kept as blocks, a product with the Jacobian is (H + 1)
dense block products and one sparse product, and the harmonic-block
preconditioner (:mod:`jointdyn.hb._precond`) takes its blocks as they are.
"""

from __future__ import annotations

import numpy as np

__all__ = ["HarmonicJacobian", "product_with_columns"]


def product_with_columns(times, columns: dict, scale: float, x):
    """``scale * times(xs) + sum_j columns[j] x[j]``, xs = x with the replaced columns' entries zeroed: the
    product of a Jacobian kept as an operator whose columns ``j`` were replaced (a matrix x column by column).
    """
    x = np.asarray(x, dtype=np.float64)
    if x.ndim != 1:
        return np.stack([product_with_columns(times, columns, scale, c) for c in x.T], axis=1)
    if columns:
        xs = x.copy()
        xs[list(columns)] = 0.0
    else:
        xs = x
    y = times(xs)
    y *= scale
    for j, c in columns.items():
        y += c * x[j]
    return y


class HarmonicJacobian:
    """dR/dX = (blockdiag(blocks) + rest) * scale, with some columns replaced whole.

    Parameters
    ----------
    spans : list of (int, int)
        Rows (and columns) ``[lo, hi)`` of each harmonic's block (:func:`jointdyn.hb._precond.harmonic_blocks`).
    blocks : list of ndarray
        The dense blocks (hi - lo square), owned by this object (changed in place by :meth:`add_to_blocks`).
    rest : scipy.sparse.csr_matrix
        Everything else (the pairs), size x size.
    """

    #: read by jointdyn.continuation.linalg: not an array, not a scipy.sparse matrix, but a product and blocks
    structured = True

    def __init__(self, spans, blocks, rest, scale: float = 1.0, columns=None):
        self.spans, self.blocks, self.rest = spans, blocks, rest
        self.scale = float(scale)
        self.columns = {} if columns is None else dict(columns)  # column j -> its values (already scaled)
        n = rest.shape[0]
        self.shape = (n, n)

    def scaled(self, f: float) -> HarmonicJacobian:
        """This Jacobian times f (the blocks shared, not copied; replaced columns scaled)."""
        return HarmonicJacobian(self.spans, self.blocks, self.rest, self.scale * f,
                                {j: f * c for j, c in self.columns.items()})

    def with_columns(self, columns: dict) -> HarmonicJacobian:
        """This Jacobian with columns ``j`` replaced by ``columns[j]`` (as they are: not scaled)."""
        return HarmonicJacobian(self.spans, self.blocks, self.rest, self.scale, {**self.columns, **columns})

    def __matmul__(self, x):
        return product_with_columns(self._times, self.columns, self.scale, x)

    def _times(self, xs):
        y = self.rest @ xs
        for (lo, hi), B in zip(self.spans, self.blocks):
            y[lo:hi] += B @ xs[lo:hi]
        return y

    def dot(self, x):
        return self @ x

    def block(self, i: int) -> np.ndarray:
        """Block i of the Jacobian's block diagonal (a copy, scaled; replaced columns as they are in it)."""
        lo, hi = self.spans[i]
        B = (self.blocks[i] + self.rest[lo:hi, lo:hi].toarray()) * self.scale
        for j, c in self.columns.items():
            if lo <= j < hi:
                B[:, j - lo] = c[lo:hi]
        return B

    def column(self, j: int) -> np.ndarray:
        """Column j (size,)."""
        if j in self.columns:
            return np.array(self.columns[j])
        c = np.asarray(self.rest[:, [j]].toarray()).ravel()
        for (lo, hi), B in zip(self.spans, self.blocks):
            if lo <= j < hi:
                c[lo:hi] += B[:, j - lo]
        return c * self.scale

    def toarray(self) -> np.ndarray:
        """The dense matrix (size x size)."""
        A = self.rest.toarray()
        for (lo, hi), B in zip(self.spans, self.blocks):
            A[lo:hi, lo:hi] += B
        A *= self.scale
        for j, c in self.columns.items():
            A[:, j] = c
        return A
