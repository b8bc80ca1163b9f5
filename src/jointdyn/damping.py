"""Modal viscous damping kept as the operator it is, instead of a dense matrix.

Modal damping ratios zeta_r on the mass-normalised modes Phi (natural
frequencies w_r, rad/s) of a pair (M, K) give the viscous damping::

    C = M Phi diag(2 zeta_r w_r) Phi^T M                      (N s/m)

so that mode r of the undamped structure has damping ratio zeta_r. As an
n x n array C is full even where M and K are sparse (a finite-element
mesh): :class:`ModalDamping` keeps the factors ``B = M Phi`` (n x m, m
modes) and ``d = 2 zeta w`` (m) and applies ``C v = B (d * (B^T v))`` in
O(n m). :class:`~jointdyn.systems.System` takes it as its ``C`` beside a
dense array.

Where a solver needs C as an array it calls :meth:`ModalDamping.toarray`
(made once per object and kept), also through ``np.asarray(C)``: the
dense Hill stability, the condensation of harmonic balance onto the
contacts, harmonic balance's dense and harmonic-block Jacobians (a
structure dense on its DOFs, where C's blocks cost what K's do) and the
time march (whose K and inverse mass are dense n x n arrays as well, so
that C x' costs what K x does). Harmonic balance and EPMC on a sparse
structure keep the operator (:mod:`jointdyn.hb._damped`).

Diagonal in the modes: when Phi holds all n modes of (M, K), the linear
terms of harmonic k in the modal coordinates q (x = Phi q) are the 2 x 2
blocks ``[[w_r^2 - (k w)^2, k w d_r], [-k w d_r, w_r^2 - (k w)^2]]`` per
mode, so that ``(K - (k w)^2 M + i k w C)^-1 = Phi diag(1 / (w_r^2 - (k w)^2
+ i k w d_r)) Phi^T`` (:meth:`ModalDamping.harmonic_solve`: no
factorisation). The condensation of harmonic balance onto the contacts
(:mod:`jointdyn.hb.condense`), whose receptance is this expansion, takes
the modes from the operator when they are those of the structure's K
(:meth:`ModalDamping.modes_of`: the ratios given for (M, K) itself), instead
of decomposing (M, K) and projecting C again (two O(n^3) steps).
"""

from __future__ import annotations

import functools

import numpy as np

from . import _validate as V

__all__ = ["ModalDamping", "is_operator", "dense_damping", "has_damping"]


class ModalDamping:
    """``C = M Phi diag(2 zeta w) Phi^T M`` (N s/m) as its factors.

    Parameters
    ----------
    M : array_like (n, n)
        Mass matrix, kg.
    phi : array_like (n, m)
        Mass-normalised modes (Phi^T M Phi = I), m <= n columns.
    zeta : array_like (m,)
        Damping ratio of each mode (>= 0).
    w : array_like (m,)
        Natural frequency of each mode, rad/s (>= 0; 0: a rigid-body mode, undamped).
    lam : array_like (m,), optional
        Eigenvalues w^2 of (M, K) of the modes (rad^2/s^2; default w^2): with all n modes,
        :meth:`harmonic_solve` uses them.
    stiffness : ndarray (n, n), optional
        The K (N/m) whose modes these are (kept as given, not copied: a solver whose structure has this
        K takes the modes from here instead of decomposing (M, K) again).

    Notes
    -----
    The object is read-only (its arrays are not writeable). ``np.asarray(C)``
    and :meth:`toarray` give the dense matrix (made once).
    """

    #: numpy defers its binary operators to the reflected ones of this class (``A @ C`` is ``__rmatmul__``)
    __array_priority__ = 100.0

    def __init__(self, M, phi, zeta, w, lam=None, stiffness=None):
        M = V.finite_array("M", np.atleast_2d(M), 2)
        phi = V.finite_array("phi", np.atleast_2d(np.asarray(phi, dtype=np.float64)), 2)
        n, m = phi.shape
        if M.shape != (n, n):
            raise ValueError(f"M must be {n} x {n} (phi has {n} rows), got shape {M.shape}")
        if m < 1 or m > n:
            raise ValueError(f"phi must have between 1 and {n} columns (modes), got {m}")
        z = np.broadcast_to(np.asarray(zeta, dtype=np.float64), (m,)).copy()
        w = np.broadcast_to(np.asarray(w, dtype=np.float64), (m,)).copy()
        if not np.all(np.isfinite(z)) or np.any(z < 0):
            raise ValueError(f"zeta must be {m} finite numbers >= 0 (one per mode), got {zeta!r}")
        if not np.all(np.isfinite(w)) or np.any(w < 0):
            raise ValueError(f"w must be {m} finite frequencies >= 0 rad/s (one per mode), got {w!r}")
        lam = w * w if lam is None else np.broadcast_to(np.asarray(lam, dtype=np.float64), (m,)).copy()
        self.phi = phi
        self.zeta, self.w, self.lam = z, w, lam
        #: the K of the modes (N/m) when given, else None
        self.stiffness = stiffness
        #: B = M Phi (n, m), kg
        self.B = np.ascontiguousarray(M @ phi)
        #: d = 2 zeta w (m,), 1/s
        self.d = 2.0 * z * w
        for a in (self.phi, self.zeta, self.w, self.lam, self.B, self.d):
            a.flags.writeable = False

    shape = property(lambda self: (self.B.shape[0], self.B.shape[0]), doc="(n, n)")
    ndim = 2
    dtype = np.dtype(np.float64)

    @property
    def modes(self) -> int:
        """Number m of modes kept."""
        return self.B.shape[1]

    @property
    def complete(self) -> bool:
        """True when all n modes are kept (C is diagonal in the modes of (M, K))."""
        return self.modes == self.shape[0]

    @property
    def T(self) -> ModalDamping:
        """C is symmetric: itself."""
        return self

    def __matmul__(self, v):
        """C v for v (n,) or (n, k), N s/m times v's unit."""
        v = np.asarray(v)
        if v.shape[0] != self.shape[0]:
            raise ValueError(f"C @ v: v must have {self.shape[0]} rows, got shape {v.shape}")
        t = self.B.T @ v
        t = self.d * t if t.ndim == 1 else self.d[:, None] * t
        return self.B @ t

    def __rmatmul__(self, u):
        """u C for u (n,) or (k, n) (C symmetric: (C u^T)^T)."""
        u = np.asarray(u)
        return self @ u if u.ndim == 1 else (self @ u.T).T

    def dot(self, v):
        """C v (as :meth:`__matmul__`)."""
        return self @ v

    @functools.cached_property
    def _dense(self) -> np.ndarray:
        A = (self.B * self.d) @ self.B.T
        A.flags.writeable = False
        return A

    def toarray(self) -> np.ndarray:
        """The dense n x n matrix, N s/m (a new array; made once and kept)."""
        return np.array(self._dense)

    def __array__(self, dtype=None, copy=None):
        return np.array(self._dense, dtype=dtype)

    def diagonal(self) -> np.ndarray:
        """diag(C), N s/m."""
        return np.einsum("ij,j,ij->i", self.B, self.d, self.B)

    def count_nonzero(self) -> int:
        """Non-zero entries of the dense matrix (n^2 unless some modes are undamped or the modes local)."""
        return int(np.count_nonzero(self._dense))

    def rayleigh_fit(self) -> tuple[float, float]:
        """(alpha 1/s, beta s) >= 0 of the Rayleigh damping alpha M + beta K closest to C in the modes:
        least squares of (alpha + beta w_r^2) / d_r - 1 over the damped modes (0, 0 when none is)."""
        on = self.d > 0.0
        if not np.any(on):
            return 0.0, 0.0
        A = np.stack((1.0 / self.d[on], self.lam[on] / self.d[on]), axis=1)
        rhs = np.ones(A.shape[0])
        ab = np.linalg.lstsq(A, rhs, rcond=None)[0]
        if ab[0] >= 0.0 and ab[1] >= 0.0:
            return float(ab[0]), float(ab[1])
        # one term alone, the better of the two (both >= 0 by construction)
        best = None
        for col in (0, 1):
            a = A[:, col]
            c = float(a @ rhs / (a @ a))
            err = float(np.sum((c * a - rhs) ** 2))
            if best is None or err < best[0]:
                best = (err, (c, 0.0) if col == 0 else (0.0, c))
        return best[1]

    def modes_of(self, K) -> bool:
        """True when all n modes are kept and they are those of (M, ``K``) (the ``stiffness`` given is K)."""
        return self.complete and self.stiffness is not None and (
            self.stiffness is K or np.array_equal(self.stiffness, K))

    def harmonic_solve(self, kw: float, r) -> np.ndarray:
        """x of (K - kw^2 M + i kw C) x = r for complex r (n,) or (n, k), with all n modes kept
        (:attr:`complete`): ``x = Phi diag(1 / (w_r^2 - kw^2 + i kw d_r)) Phi^T r``.

        Parameters
        ----------
        kw : float
            Frequency k w of the harmonic, rad/s.
        r : array_like
            Right-hand side, N.
        """
        if not self.complete:
            raise ValueError(f"harmonic_solve needs all {self.shape[0]} modes, C keeps {self.modes}")
        den = self.lam - kw * kw + 1j * kw * self.d
        t = self.phi.T @ r
        return self.phi @ (t / den if t.ndim == 1 else t / den[:, None])

    def __repr__(self) -> str:
        return f"ModalDamping(n={self.shape[0]}, modes={self.modes})"


def is_operator(C) -> bool:
    """True when C is a :class:`ModalDamping` (not an array)."""
    return isinstance(C, ModalDamping)


def dense_damping(C) -> np.ndarray:
    """C as a float64 array (a :class:`ModalDamping` made dense; an array as it is)."""
    return C.toarray() if isinstance(C, ModalDamping) else np.asarray(C, dtype=np.float64)


def has_damping(C) -> bool:
    """True when C (array or :class:`ModalDamping`) is not zero."""
    return bool(np.any(C.d > 0.0)) if isinstance(C, ModalDamping) else bool(np.any(np.asarray(C) != 0.0))
