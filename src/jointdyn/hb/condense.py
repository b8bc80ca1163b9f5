"""Harmonic balance condensed exactly onto the contact DOFs.

A structure of n linear DOFs with a few contacts has all its nonlinearity
on the m DOFs that the contacts' selections touch. Per harmonic k the
linear part is eliminated exactly (the Schur complement of the dynamic
stiffness, as pyHarm's substructuring does): with the retained DOFs c and
the others o, in complex form ``x_k = a_k - i b_k`` (the coefficients of
cos k tau and sin k tau)::

    Z(W) = K - W^2 M + i W C,   H(W) = Z(W)^-1 (receptance),  W = k w,
    Z_red(W) = H_cc(W)^-1,      F_red = Z_red H_c:(W) F_k,
    R_c = Z_red x_c - F_red + g(x_c) = 0,

g the Fourier coefficients of the contact forces (the AFT of
:mod:`jointdyn.hb._aft`, unchanged). ``R_c`` is in newtons like the full
residual, with the same scaling and tolerances; its solution is the full
problem's solution restricted to c (equal to rounding). The unknowns are
the harmonics of the retained DOFs only, so a structure of 1000 DOFs with
two contacts solves systems of the size of the two contacts.

The receptance comes from a once-per-system eigen-decomposition
(:func:`receptance`), H(W) = Psi diag(g(W)) Psi^T:

* ``modal`` (C diagonal in the mass-normalised modes Phi of (M, K), which
  includes C = 0, Rayleigh damping and :func:`jointdyn.modal_damping`):
  Psi = Phi, g_r = 1 / (w_r^2 - W^2 + i W c_r), c_r = (Phi^T C Phi)_rr;
* ``state-space`` (any other C): the 2n eigenpairs (lambda_r, y_r) of the
  quadratic problem (lambda^2 I + lambda Phi^T C Phi + diag(w_r^2)) y = 0
  in modal coordinates, Psi_r = Phi y_r / sqrt(y_r^T (2 lambda_r I +
  Phi^T C Phi) y_r), g_r = 1 / (i W - lambda_r) (the spectral expansion of
  a symmetric quadratic pencil; Tisseur & Meerbergen, SIAM Rev. 43, 2001).

So an evaluation costs O(R m^2) per harmonic (R = n or 2n terms, one
compiled pass over all harmonics: :func:`_condensed_blocks`) plus m x m
inverses, and dZ_red/dw = -Z_red (dH_cc/dw) Z_red is exact. The static
harmonic (W = 0) uses the static Schur complement K_cc - K_co K_oo^-1 K_oc,
computed once: H_cc(0)^-1 from the expansion when K is positive definite,
else by a Cholesky factorisation of K_oo (a structure whose K is singular
only through the retained DOFs, e.g. a damper held by its contacts, is
allowed). Rayleigh (or no) damping (C = alpha M + beta K, found by an
O(n^2) fit) keeps the modes factored (Householder tridiagonalisation and a
tridiagonal eigensolver, :func:`_tridiagonal_modes`; rows of Psi cost
O(n^2)), about a third of a dense eigen-decomposition; other damping forms
the dense modes, and that expansion is checked once at a frequency W
between natural frequencies: Z(W) H(W) = I on a few columns
(:func:`receptance`). The decomposition also gives ``System.w0`` when the
system has no normal springs, so the n x n eigenproblem is solved once.

Retained DOFs: every DOF of a contact's tangential selection, DOF 0 (the
DOF the branch monitor of :mod:`jointdyn.hb.frc` measures) and the
response DOFs asked for; any other DOF's response is recovered from the
solution (:meth:`CondensedHBProblem.dof_coefficients` with the parameter
value, :meth:`CondensedHBProblem.full_coefficients`). Where the contacts and
pairs act on relative coordinates (a pair's x_a - x_b) that are fewer than
those DOFs, the problem keeps the coordinates y = S x instead
(:mod:`jointdyn.hb._coordinates`): everything above holds with the rows of
the retained DOFs c replaced by S (H_cc = S H S^T, Psi_c = S Psi).

Stability: Hill's method on the full structure. Where its companion matrix
is small (``StabilityOptions.dense_max_rows``) the full Jacobian is
assembled exactly (:meth:`CondensedHBProblem.full_jacobian`) for dense
Hill; beyond, shift-invert Arnoldi solves Hill's problem through the
condensed form, the receptance at complex frequencies plus the contact part
of the condensed Jacobian (:mod:`jointdyn.hb.hill_condensed`), without
forming anything of the full size. The choice between the two, for branches and
single solutions alike: :mod:`jointdyn.hb.floquet`.
"""

from __future__ import annotations

import dataclasses
import math
import time
from dataclasses import dataclass

import numpy as np

from .. import config
from .._cache import by_identity
from .._jit import jit
from ..damping import dense_damping, is_operator
from ..systems import System, free_modes
from ._coordinates import Coordinates, retained_coordinates, retained_dofs, static_cholesky
from .options import HBOptions, hb_options
from .problem import HBProblem, _linear_blocks, held_by_contacts

__all__ = ["Receptance", "receptance", "retained_dofs", "retained_coordinates", "CondensedHBProblem",
           "make_problem", "use_condensed"]

#: the damping is modal (receptance by the undamped modes) when C = alpha M +
#: beta K to this fraction of max |C|, or when the off-diagonal entries of
#: Phi^T C Phi are at most this fraction of its largest entry; otherwise the
#: damped (state-space) eigenproblem is used
HB_CONDENSE_MODAL_RTOL = 1e-12
#: the static Schur complement comes from the expansion (H_cc(0)^-1) when every
#: static factor |1 / g_r(0)| is at least this fraction of the largest (K
#: positive definite); otherwise from a Cholesky factorisation of K_oo
HB_CONDENSE_STATIC_RTOL = 1e-6
#: the spectral expansion H of the receptance must satisfy Z(W) H(W) = I at one
#: frequency to this, relative to max |Z| max |H| (backward error)
HB_CONDENSE_CHECK_RTOL = 1e-9
#: condensed onto more than this many coordinates, the blocks H_yy = P diag(g) P^T and their inverses are
#: formed by BLAS and LAPACK per harmonic (:func:`_blas_blocks`); up to it by one compiled pass over the
#: distinct entries (:func:`_condensed_blocks`, whose derivative costs O(m^4))
HB_CONDENSE_BLAS_MIN = 16

#: kinds of spectral expansion of the receptance
MODAL, STATE_SPACE = "modal", "state-space"
#: the same kinds as codes of the compiled reduced receptance
MODAL_CODE, STATE_SPACE_CODE = 0, 1


@dataclass(frozen=True)
class Receptance:
    """Spectral expansion H(W) = Psi diag(g(W)) Psi^T of a structure's receptance.

    Attributes
    ----------
    kind : str
        ``"modal"`` or ``"state-space"`` (module docstring).
    vectors : ndarray (n, R) or None
        Psi (real for ``modal``, complex for ``state-space``), in
        1/sqrt(kg); None when only its factors are kept (``basis``).
    a, b : ndarray (R,)
        ``modal``: w_r^2 (rad^2/s^2) and c_r (rad/s); ``state-space``:
        the eigenvalues lambda_r (1/s) and unused zeros.
    seconds : float
        CPU seconds the decomposition took.
    basis : tuple or None
        Psi in factored form (``modal`` with Rayleigh damping):
        Psi = L^-T Q S with M = L L^T (``L`` lower triangular, or the vector
        sqrt(diag M) for a diagonal M), Q the Householder reflectors of
        LAPACK's dsytrd (``(reflectors, tau)``) and S the eigenvectors of the
        tridiagonal matrix: rows of Psi cost O(n^2) each
        (:meth:`rows`, :meth:`project`), not the O(n^3) of forming Q S.
    modes : tuple or None
        ``state-space`` only: (Phi (n, n), Phi^T C Phi (n, n), Y (n, 2n)), the undamped mass-normalised
        modes, the damping in their coordinates and the damped eigenvectors there (Psi = Phi Y), for the stability of a condensed problem
        (:mod:`jointdyn.hb.hill_condensed`).
    """

    kind: str
    vectors: np.ndarray | None
    a: np.ndarray
    b: np.ndarray
    seconds: float
    basis: tuple | None = None
    modes: tuple | None = None

    def _coordinates(self, B):
        """S^T Q^T L^-1 B = Psi^T B for a real B (n, r) (``basis`` form)."""
        from scipy.linalg import solve_triangular
        from scipy.linalg.lapack import dormqr

        L, refl, tau, S = self.basis
        U = B / L[:, None] if L.ndim == 1 else solve_triangular(L, B, lower=True)
        if tau.size:
            cq, _, info = dormqr(b"L", b"T", refl, tau, U[1:], max(1, 64 * U.shape[1]))
            if info != 0:
                raise RuntimeError(f"LAPACK dormqr failed (info = {info})")
            U = np.vstack([U[:1], cq])
        return S.T @ U

    def rows(self, idx):
        """Psi[idx] (len(idx), R): the rows of the DOFs ``idx``."""
        idx = np.atleast_1d(np.asarray(idx, dtype=np.int64))
        if self.basis is None:
            return self.vectors[idx]
        E = np.zeros((self.basis[3].shape[0], idx.size))
        E[idx, np.arange(idx.size)] = 1.0
        return self._coordinates(E).T

    def rows_of(self, coords):
        """S Psi (m, R) of the coordinates ``coords`` (:class:`~jointdyn.hb._coordinates.Coordinates`,
        y = S x): the rows of their DOFs for unit rows, else the rows' combinations."""
        if coords.unit:
            return self.rows(coords.dofs)
        if self.basis is None:
            from scipy.sparse import csr_matrix

            return np.asarray(csr_matrix(coords.S) @ self.vectors)
        return self._coordinates(np.ascontiguousarray(coords.S.T)).T

    def project(self, F):
        """Psi^T F (R,) for a load vector F (n,), real or complex, N."""
        F = np.asarray(F)
        if self.basis is None:
            return self.vectors.T @ F
        out = self._coordinates(np.ascontiguousarray(F.real)[:, None])[:, 0]
        if np.iscomplexobj(F):
            out = out + 1j * self._coordinates(np.ascontiguousarray(F.imag)[:, None])[:, 0]
        return out

    def factors(self, W):
        """(g, dg/dW) at the angular frequencies W (array (k,), rad/s): arrays (k, R) complex."""
        W = np.asarray(W, dtype=np.float64)[:, None]
        if self.kind == MODAL:
            g = 1.0 / (self.a[None, :] - W * W + 1j * W * self.b[None, :])
            return g, (2.0 * W - 1j * self.b[None, :]) * g * g
        g = 1.0 / (1j * W - self.a[None, :])
        return g, -1j * g * g

    def block(self, W, rows, cols):
        """H(W)[rows][:, cols] (complex, m/N) at one angular frequency W (rad/s)."""
        g, _ = self.factors(np.array([W]))
        left = self.rows(rows)
        right = g[0][:, None] * self.rows(cols).T
        if np.isrealobj(left):
            return _real_times(left, right)
        return left @ right


@jit(inline="always")
def _expansion_factors(kind, a, b, W, k, g, dg):  # pragma: no cover - compiled
    """The expansion factors g_r(W_h) and d g_r(k_h w) / dw into ``g``, ``dg`` (H, R) complex.

    ``a`` (R,) complex, ``b`` (R,) real: the expansion's constants
    (:class:`Receptance`) of kind ``MODAL_CODE`` (g = 1 / (a - W^2 + i W b))
    or ``STATE_SPACE_CODE`` (g = 1 / (i W - a)); ``W = k w`` (H,) rad/s with
    the harmonic numbers ``k``. Reciprocals as conj(d) / |d|^2.
    """
    for h in range(W.shape[0]):
        Wh = W[h]
        for r in range(a.shape[0]):
            if kind == MODAL_CODE:
                dr, di = a[r].real - Wh * Wh, Wh * b[r]
            else:
                dr, di = -a[r].real, Wh - a[r].imag
            s = 1.0 / (dr * dr + di * di)
            gr = complex(dr * s, -di * s)
            g[h, r] = gr
            if kind == MODAL_CODE:
                dg[h, r] = k[h] * complex(2.0 * Wh, -b[r]) * gr * gr
            else:
                dg[h, r] = -1j * k[h] * gr * gr


@jit(inline="always")
def _block_sums(g, dg, Q, iu, ju, h, Hc, dHc):  # pragma: no cover - compiled
    """H_cc and dH_cc/dw of harmonic h into ``Hc``, ``dHc`` (m, m) from their distinct entries
    (pair p = (iu[p], ju[p])): sum_r Q[r, p] g[h, r] (``Q`` the products Psi_ir Psi_jr)."""
    for p in range(iu.shape[0]):
        acc = 0j
        dacc = 0j
        for r in range(Q.shape[0]):
            acc += g[h, r] * Q[r, p]
            dacc += dg[h, r] * Q[r, p]
        Hc[iu[p], ju[p]] = acc
        Hc[ju[p], iu[p]] = acc
        dHc[iu[p], ju[p]] = dacc
        dHc[ju[p], iu[p]] = dacc


@jit(inline="always")
def _invert(A, Z, work):  # pragma: no cover - compiled
    """Z = A^-1 (m x m complex) by Gauss-Jordan elimination with partial pivoting, ``work`` a
    scratch copy of A (a singular A gives non-finite entries, which the residual carries)."""
    m = A.shape[0]
    for i in range(m):
        for j in range(m):
            work[i, j] = A[i, j]
            Z[i, j] = 1.0 if i == j else 0.0
    for col in range(m):
        piv = col
        for r in range(col + 1, m):
            if abs(work[r, col]) > abs(work[piv, col]):
                piv = r
        if piv != col:
            for j in range(m):
                work[col, j], work[piv, j] = work[piv, j], work[col, j]
                Z[col, j], Z[piv, j] = Z[piv, j], Z[col, j]
        d = 1.0 / work[col, col]
        for j in range(m):
            work[col, j] *= d
            Z[col, j] *= d
        for r in range(m):
            if r != col:
                f = work[r, col]
                for j in range(m):
                    work[r, j] -= f * work[col, j]
                    Z[r, j] -= f * Z[col, j]


@jit(inline="always")
def _sandwich(Z, D, out):  # pragma: no cover - compiled
    """out = -Z D Z (m x m complex): the derivative of Z = H^-1 for dH = D."""
    m = Z.shape[0]
    for i in range(m):
        for j in range(m):
            acc = 0j
            for k in range(m):
                zd = 0j
                for q in range(m):
                    zd += Z[i, q] * D[q, k]
                acc += zd * Z[k, j]
            out[i, j] = -acc


@jit(inline="always")
def _put_block(Z, row, col, sign, out):  # pragma: no cover - compiled
    """The real and imaginary parts of harmonic block Z (m, m) at (row, col) of ``out``:
    [[Re Z, Im Z], [-Im Z, Re Z]] with rows/cols (row, row + m) and (col, col + m); sign +-1 scales it."""
    m = Z.shape[0]
    for i in range(m):
        for j in range(m):
            zr, zi = sign * Z[i, j].real, sign * Z[i, j].imag
            out[row + i, col + j] = zr
            out[row + i, col + m + j] = zi
            out[row + m + i, col + j] = -zi
            out[row + m + i, col + m + j] = zr


@jit
def _condensed_blocks(exp, pairs, w, Z0, out):  # pragma: no cover - compiled
    """Z_red(w) and dZ_red/dw of every harmonic (module docstring), in one pass.

    ``exp = (kind, a, b, Q, k)``: the expansion (:func:`_expansion_factors`)
    with the pair products ``Q`` (R, pairs) and harmonic numbers ``k``;
    ``pairs = (iu, ju)``; ``Z0`` (m, m) the static Schur complement. ``out =
    (g, dg, Zk, dZk, Zb, dZb)``: the factors (H, R), the complex blocks
    (H, m, m), and the real block matrices m(2H+1) square (written on the
    diagonal blocks only; the rest must be zero).
    """
    kind, a, b, Q, k = exp
    iu, ju = pairs
    g, dg, Zk, dZk, Zb, dZb = out
    _expansion_factors(kind, a, b, k * w, k, g, dg)
    m = Z0.shape[0]
    Hc = np.empty((m, m), dtype=np.complex128)
    dHc = np.empty((m, m), dtype=np.complex128)
    work = np.empty((m, m), dtype=np.complex128)
    for i in range(m):
        for j in range(m):
            Zb[i, j] = Z0[i, j]
    for h in range(k.shape[0]):
        _block_sums(g, dg, Q, iu, ju, h, Hc, dHc)
        _invert(Hc, Zk[h], work)
        _sandwich(Zk[h], dHc, dZk[h])
        row = (2 * h + 1) * m
        _put_block(Zk[h], row, row, 1.0, Zb)
        _put_block(dZk[h], row, row, 1.0, dZb)


def _is_modal(Ct) -> bool:
    """True when the modal damping matrix Phi^T C Phi is diagonal to ``HB_CONDENSE_MODAL_RTOL``."""
    off = Ct - np.diag(np.diag(Ct))
    scale = float(np.max(np.abs(Ct))) if Ct.size else 0.0
    return float(np.max(np.abs(off), initial=0.0)) <= HB_CONDENSE_MODAL_RTOL * scale


def _state_space(w2, Ct):
    """(lambda, Y) of the quadratic pencil lambda^2 I + lambda Ct + diag(w2), Y normalised (module docstring)."""
    from scipy.linalg import eig

    R = w2.size
    A = np.zeros((2 * R, 2 * R))
    A[:R, R:] = np.eye(R)
    A[R:, :R] = -np.diag(w2)
    A[R:, R:] = -Ct
    lam, V = eig(A)
    Y = V[:R]
    a = np.einsum("ir,ir->r", Y, Y) * (2.0 * lam) + np.einsum("ir,ij,jr->r", Y, Ct, Y)
    if np.any(a == 0.0):
        raise ValueError("condense: the structure's damped eigenproblem is defective (a repeated eigenvalue "
                         "without a full set of eigenvectors); use condense=False")
    return lam, Y / np.sqrt(a)[None, :]


def _check_frequency(w2) -> float:
    """A frequency (rad/s) between the two lowest distinct natural frequencies (or above the only one)."""
    w = np.unique(np.sqrt(np.maximum(w2, 0.0)))
    w = w[w > 0.0]
    if w.size == 0:
        return 1.0
    if w.size == 1:
        return 1.5 * float(w[0])
    return math.sqrt(float(w[0] * w[1]))


def _rayleigh(M, C, K):
    """(alpha, beta) when C = alpha M + beta K to ``HB_CONDENSE_MODAL_RTOL`` (0, 0 for C = 0), else None.

    A least-squares fit on the entries (2 x 2 normal equations), O(n^2):
    Rayleigh damping (and no damping) needs no product Phi^T C Phi of the
    dense modes.
    """
    scale = float(np.max(np.abs(C)))
    if scale == 0.0:
        return 0.0, 0.0
    m, k, c = M.ravel(), K.ravel(), C.ravel()
    G = np.array([[m @ m, m @ k], [m @ k, k @ k]])
    try:
        alpha, beta = np.linalg.solve(G, np.array([m @ c, k @ c]))
    except np.linalg.LinAlgError:  # K a multiple of M
        return None
    if float(np.max(np.abs(C - alpha * M - beta * K))) <= HB_CONDENSE_MODAL_RTOL * scale:
        return float(alpha), float(beta)
    return None


def _tridiagonal_modes(M, K):
    """(w2, basis) of (M, K): eigenvalues w_r^2 (ascending) and Psi in the factored form of
    :class:`Receptance` (``basis``), by Householder tridiagonalisation (dsytrd) and a
    tridiagonal eigensolver; O(n^3) only in the reduction."""
    from scipy.linalg import cholesky, eigh_tridiagonal, lapack, solve_triangular

    if np.any(M != np.diag(np.diag(M))):
        L = cholesky(M, lower=True)
        A = solve_triangular(L, solve_triangular(L, K, lower=True).T, lower=True)
        A = 0.5 * (A + A.T)
    else:
        L = np.sqrt(np.diag(M))
        A = K / L[:, None] / L[None, :]
    lwork, _ = lapack.dsytrd_lwork(A.shape[0], lower=1)
    c, d, e, tau, info = lapack.dsytrd(A, lower=1, lwork=int(lwork))
    if info != 0:
        raise RuntimeError(f"LAPACK dsytrd failed (info = {info})")
    stevd = getattr(lapack, "dstevd", None)  # divide and conquer, when scipy wraps it
    w2, S, info = stevd(d, e) if stevd is not None else (None, None, 1)
    if info != 0:
        w2, S = eigh_tridiagonal(d, e, lapack_driver="stemr")
    return w2, (L, np.asfortranarray(c[1:, :-1]), tau, S)


def _expansion(system: System):
    """(kind, vectors, a, b, basis, modes) of the receptance expansion and the undamped w_r^2 (module docstring).

    Rayleigh (or no) damping keeps Psi factored (:func:`_tridiagonal_modes`);
    other damping needs the dense modes for Phi^T C Phi, except modal damping kept as an operator on the
    modes of (M, K) (:class:`jointdyn.damping.ModalDamping`), whose modes are taken as they are.
    """
    from scipy.linalg import eigh

    if is_operator(system.C) and system.C.modes_of(system.K):  # modal damping on the modes of (M, K)
        op = system.C
        return (MODAL, np.array(op.phi), np.array(op.lam), np.array(op.d), None, None), np.array(op.lam)
    M, C, K = system.M, dense_damping(system.C), system.K
    ab = _rayleigh(M, C, K)
    if ab is not None and system.ndof > 1:
        w2, basis = _tridiagonal_modes(M, K)
        return (MODAL, None, w2, ab[0] + ab[1] * w2, basis, None), w2
    w2, Phi = eigh(K, M)
    if ab is not None:
        return (MODAL, Phi, w2, ab[0] + ab[1] * w2, None, None), w2
    Ct = Phi.T @ C @ Phi
    if _is_modal(Ct):
        return (MODAL, Phi, w2, np.diag(Ct).copy(), None, None), w2
    lam, Y = _state_space(w2, Ct)
    return (STATE_SPACE, Phi @ Y, lam, np.zeros(lam.size), None, (Phi, Ct, Y)), w2


def _real_times(A, B):
    """A @ B for a real A and a complex B without a complex copy of A."""
    return A @ B.real + 1j * (A @ B.imag)


def _share_w0(system: System, w2) -> None:
    """Give ``system.w0`` (a cached property: lowest natural frequency of (M, K_reference))
    the value of the decomposition just made when K_reference is K, so that the
    same n x n eigenproblem is not solved twice."""
    if system.w0_rad_s is None and "w0" not in vars(system) and np.array_equal(system.K_reference, system.K):
        vars(system)["w0"] = math.sqrt(max(float(w2[0]), 0.0))


@by_identity
def receptance(system: System) -> Receptance:
    """The spectral expansion of ``system``'s receptance (once per System; module docstring).

    A dense expansion (damping other than Rayleigh) is checked at one
    frequency W between natural frequencies: the residual Z(W) H(W)[:, cols]
    - I[:, cols] of a few columns (O(n^2)) must be at most
    ``HB_CONDENSE_CHECK_RTOL`` times max|Z(W)| max|H(W)[:, cols]| (a
    backward-error test, rounding being ~1e-16 n of that); ValueError
    naming ``condense`` otherwise (a defective damped eigenproblem). The
    factored form (orthogonal reductions, backward stable) is not checked:
    forming its columns would cost the O(n^3) it avoids.
    """
    t0 = time.process_time()
    (kind, vectors, a, b, basis, modes), w2 = _expansion(system)
    _share_w0(system, w2)
    out = Receptance(kind, vectors, a, b, 0.0, basis, modes)
    if basis is None:
        _check(system, out, w2)
    return dataclasses.replace(out, seconds=time.process_time() - t0)


def _check(system: System, rec: Receptance, w2) -> None:
    """The test of :func:`receptance` (ValueError naming ``condense`` on failure)."""
    n = system.ndof
    W = _check_frequency(w2)
    cols = np.unique(np.linspace(0, n - 1, min(n, 4)).astype(int))
    Zr = system.K - W * W * system.M
    Hb = rec.block(W, np.arange(n), cols)
    C = dense_damping(system.C)
    ZH = _real_times(Zr, Hb) + 1j * W * _real_times(C, Hb)
    err = float(np.max(np.abs(ZH - np.eye(n)[:, cols])))
    zmax = float(np.max(np.abs(Zr) + W * np.abs(C)))
    bound = HB_CONDENSE_CHECK_RTOL * zmax * float(np.max(np.abs(Hb)))
    if not err <= bound:
        raise ValueError(f"condense: the {rec.kind} expansion of the receptance misses Z(W) H(W) = I by "
                         f"{err:.3g} (allowed {bound:.3g}); use condense=False")


def _static_parts(K, c, rec: Receptance | None = None):
    """(Z0, S0): the static Schur complement Z0 = (S K^-1 S^T)^-1 onto the retained coordinates ``c``
    (a :class:`~jointdyn.hb._coordinates.Coordinates`, or DOFs: their unit rows) and the static recovery:
    x = S0(rows) y for a static load S^T lambda on them.

    With a receptance ``rec`` whose static factors g(0) are all finite and no smaller than
    ``HB_CONDENSE_STATIC_RTOL`` of the largest (K positive definite), Z0 = H_yy(0)^-1 from the
    expansion and S0 ``rows -> H(0)[rows] S^T Z0`` (O(n^2) per row). Otherwise by a Cholesky
    factorisation of K on null(S) (:func:`~jointdyn.hb._coordinates.static_cholesky`, which refuses).
    """
    coords = c if isinstance(c, Coordinates) else Coordinates.of_dofs(c, K.shape[0])
    if rec is not None:
        g0 = rec.factors(np.zeros(1))[0][0]
        inv = np.abs(1.0 / g0) if np.all(np.isfinite(g0)) and np.all(g0 != 0.0) else None
        if inv is not None and float(inv.min()) > HB_CONDENSE_STATIC_RTOL * float(inv.max()):
            Pc = rec.rows_of(coords)
            Z0 = np.linalg.inv(((Pc * g0) @ Pc.T).real)
            right = g0[:, None] * (Pc.T @ Z0)
            return Z0, lambda rows: (rec.rows(rows) @ right).real
    return static_cholesky(K, coords)


def _static_cholesky(K, c):
    """(Z0, S0) of :func:`_static_parts` onto the DOFs ``c`` by a Cholesky factorisation of K_oo."""
    return static_cholesky(K, Coordinates.of_dofs(c, K.shape[0]))


def _coordinate_sum(P, g):
    """P diag(g) P^T (m, m) complex for P (m, R) real or complex and g (R,) complex."""
    if np.isrealobj(P):
        return _real_times(P, g[:, None] * P.T)
    return (P * g[None, :]) @ P.T


def _blas_blocks(rec: Receptance, P, k, w: float, Z0, out) -> None:
    """What :func:`_condensed_blocks` writes into ``out``, by BLAS and LAPACK per harmonic (many coordinates):
    the factors g, dg/dw (H, R), Z_red and dZ_red/dw (H, m, m) and their real block matrices."""
    g, dg, Zk, dZk, Zb, dZb = out
    gw, dgw = rec.factors(k * w)
    g[:], dg[:] = gw, dgw * k[:, None]
    m = Z0.shape[0]
    Zb[:m, :m] = Z0
    for h in range(k.size):
        Z = np.linalg.inv(_coordinate_sum(P, g[h]))
        Zk[h], dZk[h] = Z, -(Z @ _coordinate_sum(P, dg[h]) @ Z)
        row = (2 * h + 1) * m
        for A, B in ((Zk[h], Zb), (dZk[h], dZb)):
            B[row:row + m, row:row + m] = B[row + m:row + 2 * m, row + m:row + 2 * m] = A.real
            B[row:row + m, row + m:row + 2 * m] = A.imag
            B[row + m:row + 2 * m, row:row + m] = -A.imag


def _to_complex(v, nh, m):
    """Real harmonic coefficients (nh m) -> (static (m,), harmonics (H, m) complex a - i b)."""
    V = np.asarray(v).reshape(nh, m)
    return V[0], V[1::2] - 1j * V[2::2]


def _to_real(x0, xk):
    """Inverse of :func:`_to_complex` for (x0 (q,), xk (H, q)): array (nh, q)."""
    out = np.empty((1 + 2 * xk.shape[0], x0.shape[0]))
    out[0] = x0
    out[1::2] = xk.real
    out[2::2] = -xk.imag
    return out


class CondensedHBProblem(HBProblem):
    """Harmonic-balance residual condensed exactly onto the retained coordinates.

    Same interface as :class:`~jointdyn.hb.problem.HBProblem` (``evaluate``,
    ``linear_guess``, ``amplitudes``, ...); the unknowns are the harmonics
    of the coordinates y = S x of ``coordinates``
    (:func:`~jointdyn.hb._coordinates.retained_coordinates`: the retained DOFs, or relative
    coordinates) only; ``dofs`` gives the DOF of each unit row, -1 for a relative coordinate. See
    the module docstring.

    Parameters
    ----------
    system, harmonics, samples, parameter, gamma, max_passes, options
        As for :class:`~jointdyn.hb.problem.HBProblem`.
    response_dofs : sequence of int
        DOFs kept among the unknowns besides the contact DOFs and DOF 0.
    """

    def __init__(self, system: System, *, harmonics: int = config.HB_HARMONICS, samples: int = config.HB_SAMPLES,
                 parameter="gamma", gamma: float | None = None, max_passes: int = config.HB_MAX_PASSES,
                 response_dofs=(), options: HBOptions | None = None):
        if not isinstance(system, System):
            raise ValueError("system must be a jointdyn.System")
        self.options = hb_options(options)
        use_condensed(system, True)  # refuses a structure held only through its contacts
        #: the retained coordinates y = S x (:class:`~jointdyn.hb._coordinates.Coordinates`)
        self.coordinates = retained_coordinates(system, response_dofs, self.options.condense_relative)
        self.receptance = receptance(system)  # first: it also gives system.w0 (_share_w0)
        self._setup(system, harmonics, samples, parameter, gamma, max_passes, self.coordinates.dofs)
        self._dof_positions.pop(-1, None)  # -1 marks a relative coordinate, no DOF
        self._Z0, self._S0 = _static_parts(system.K, self.coordinates, self.receptance)
        #: S Psi (m, R): the expansion's rows of the coordinates
        self._Psi_c = np.ascontiguousarray(self.receptance.rows_of(self.coordinates))
        self._a = self.receptance.a.astype(np.complex128)
        self._k = np.arange(1, self.H + 1, dtype=np.float64)
        self._kind = MODAL_CODE if self.receptance.kind == MODAL else STATE_SPACE_CODE
        R, m = self._Psi_c.shape[1], self.n
        self._pairs = self._exp = None  # many coordinates: _blas_blocks
        if m <= HB_CONDENSE_BLAS_MIN:
            #: distinct entries (i <= j) of the symmetric m x m blocks and the products
            #: Psi_ir Psi_jr (R, pairs) that H_yy = Psi_c diag(g) Psi_c^T sums
            self._pairs = tuple(np.ascontiguousarray(v, dtype=np.int64) for v in np.triu_indices(m))
            Q = np.ascontiguousarray((self._Psi_c[self._pairs[0]] * self._Psi_c[self._pairs[1]]).T,
                                     dtype=np.complex128)
            self._exp = (self._kind, self._a, self.receptance.b, Q, self._k)
        # workspace of _condensed_blocks (the real block matrices stay zero off their blocks)
        self._work = (np.empty((self.H, R), complex), np.empty((self.H, R), complex),
                      np.empty((self.H, m, m), complex), np.empty((self.H, m, m), complex),
                      np.zeros((self.size, self.size)), np.zeros((self.size, self.size)))
        self._zero = np.zeros((self.size, self.size))
        self._at_w = None
        self._modal_force = (None, None)
        self._fixed_forcing = None
        self._fixed_loads = None if self.parameter.enters_loads else self._loads_at(0.0)

    @property
    def condensed(self) -> bool:
        return True

    def _on_unknowns(self, B):
        """Rows B (k, ndof) in the retained coordinates (:meth:`Coordinates.express`)."""
        return self.coordinates.express(B)

    def _pair_positions(self, table):
        """Per pair of ``table`` (pairs, 6) the positions of its three relative coordinates (side a, side b):
        of its DOFs among the unknowns, or (j, -1) / (-1, j) where the coordinate is +- unknown j."""
        pos = np.full(table.shape, -1, dtype=np.int64)
        for i, row in enumerate(table):
            for k in range(3):
                pos[i, k], pos[i, k + 3] = self.coordinates.position(int(row[k]), int(row[k + 3]))
        return pos

    # --- linear part at a frequency -----------------------------------------
    def _linear_at(self, w: float):
        """(Zb, dZb, Zk, dZk, g1, dg1) at w (rad/s), kept for the last w.

        Zb, dZb: real block matrices of Z_red and dZ_red/dw; Zk, dZk: the
        complex (H, m, m) harmonics; g1, dg1: expansion factors of the
        first harmonic and their w-derivative (for the forcing).
        """
        if self._at_w is not None and self._at_w[0] == w:
            return self._at_w[1]
        ws = self._work
        if self._exp is None:
            _blas_blocks(self.receptance, self._Psi_c, self._k, float(w), self._Z0, ws)
        else:
            _condensed_blocks(self._exp, self._pairs, float(w), self._Z0, ws)
        g, dg, Zk, dZk, Zb, dZb = ws
        out = (Zb, dZb, Zk, dZk, g[0].copy(), dg[0].copy())  # harmonic 1: k = 1
        self._at_w = (w, out)
        return out

    def _linear_terms(self, w):
        # the compiled evaluation forms AK + w AC + w^2 AM and dwdp (AC + 2 w AM) X:
        # with AK = Z_red(w), AC = dZ_red/dw, AM = 0 and 0 in place of w it forms
        # exactly Z_red(w) and dwdp dZ_red/dw X
        Zb, dZb = self._linear_at(float(w))[:2]
        return Zb, dZb, self._zero, 0.0

    def linear_matrix(self, w):
        """Block matrix of Z_red(w) (size m(2H+1)): the condensed linear terms."""
        return self._linear_at(float(w))[0].copy()

    # --- forcing ------------------------------------------------------------
    def _modal(self, f):
        """Psi^T F1 for amplitudes f (N) with the system's phases (F1 = f sin(phi) - i f cos(phi)); last kept."""
        key, q = self._modal_force
        if key is not None and np.array_equal(key, f):
            return q
        f = np.asarray(f, dtype=np.float64)
        nz = np.flatnonzero(f)
        F1 = f[nz] * (self.phase_sin[nz] - 1j * self.phase_cos[nz])
        F = np.zeros(self.system.ndof, complex)
        F[nz] = F1
        q = self.receptance.project(F)
        self._modal_force = (f.copy(), q)
        return q

    def _forcing_pair(self, f, w):
        """(F_red, dF_red/dw) coefficient vectors of the forcing f (N) at w (rad/s)."""
        _, _, Zk, dZk, g1, dg1 = self._linear_at(float(w))
        q = self._modal(f)
        y = self._Psi_c @ (g1 * q)
        dy = self._Psi_c @ (dg1 * q)
        Fr, dFr = np.zeros(self.size), np.zeros(self.size)
        m = self.n
        z, dz = Zk[0] @ y, dZk[0] @ y + Zk[0] @ dy
        Fr[m:2 * m], Fr[2 * m:3 * m] = z.real, -z.imag
        dFr[m:2 * m], dFr[2 * m:3 * m] = dz.real, -dz.imag
        return Fr, dFr

    def forcing(self, f, w: float | None = None):
        """Condensed coefficient vector F_red of the forcing f_i sin(tau + phi_i) at w (rad/s)."""
        if w is None:
            raise ValueError("w must be given: the condensed forcing depends on the frequency")
        return self._forcing_pair(f, w)[0]

    def _forcing_at(self, p):
        f, df = self.parameter.forcing(self, p)
        w, dwdp = self.parameter.frequency(self, p)
        Fe, dFe = self._forcing_pair(f, w)
        Fp = dwdp * dFe
        if df is not None:
            Fp = Fp + self._forcing_pair(df, w)[0]
        return Fe, Fp

    # --- recovery -------------------------------------------------------------
    def _recover(self, X, p, rows):
        """Coefficients (nh, len(rows)) of the system DOFs ``rows`` at the condensed X, parameter p.

        Per harmonic k >= 1, x = H(k w) (F_k - S^T gamma_k) with the contact
        forces on the retained coordinates gamma = F_red - Z_red X (so that the
        coordinates reproduce X); statically x = S0 y. Rows of retained DOFs are
        X itself.
        """
        rows = np.asarray(rows, dtype=np.int64)
        X = np.asarray(X, dtype=np.float64)
        w = self.omega(p)
        f = self.parameter.forcing(self, p)[0]
        gamma = self.forcing(f, w) - self._linear_at(w)[0] @ X
        x0, _ = _to_complex(X, self.nh, self.n)
        _, gk = _to_complex(gamma, self.nh, self.n)
        g, _ = self.receptance.factors(self._k * w)
        modal = -(gk @ self._Psi_c)  # (H, R): -(S Psi)^T gamma_k
        modal[0] += self._modal(f)
        out = _to_real(self._S0(rows) @ x0, (g * modal) @ self.receptance.rows(rows).T)
        kept = np.flatnonzero(np.isin(rows, self.dofs[self.dofs >= 0]))
        Xm = X.reshape(self.nh, self.n)
        for j in kept:
            out[:, j] = Xm[:, self.dof_index(int(rows[j]))]
        return out

    def dof_coefficients(self, X, dof: int, p=None):
        X = np.asarray(X, dtype=np.float64)
        if dof in self._dof_positions:
            return super().dof_coefficients(X, dof)
        if not 0 <= dof < self.system.ndof:
            raise ValueError(f"dof must be in [0, {self.system.ndof - 1}], got {dof!r}")
        if p is None:
            raise ValueError(f"dof {dof} is not retained by the condensed problem: give the parameter value p "
                             "to recover it (or keep it with response_dof)")
        if X.ndim == 1:
            return self._recover(X, float(p), [dof])[:, 0]
        ps = np.broadcast_to(np.asarray(p, dtype=np.float64), X.shape[:1])
        return np.array([self._recover(x, float(q), [dof])[:, 0] for x, q in zip(X, ps)]).reshape(X.shape[0], -1)

    def full_coefficients(self, X, p):
        """Coefficients of every DOF (harmonic-major, ndof (2H+1)) recovered from the condensed X, m."""
        return self._recover(X, float(p), np.arange(self.system.ndof)).ravel()

    # --- stability ------------------------------------------------------------
    def contact_jacobian(self, JX, w):
        """The contact part ``JX - Z_red(w)`` of the condensed dR/dX at w (rad/s), N/m: it acts on the
        retained DOFs only (harmonic-major, m(2H+1) square)."""
        return np.asarray(JX) - self._linear_at(float(w))[0]

    def full_jacobian(self, JX, w):
        """The full problem's dR/dX (ndof(2H+1) square) from the condensed one at w (rad/s).

        The contact part (:meth:`contact_jacobian`) acts on the retained coordinates only
        (S^T G S per pair of harmonics); the linear part is the full A(w) of
        :func:`~jointdyn.hb.problem._linear_blocks`.
        """
        n, nh, m = self.system.ndof, self.nh, self.n
        AK, AC, AM = _linear_blocks(self.system, self.H)
        J = AK + w * AC + (w * w) * AM
        G = self.contact_jacobian(JX, w)
        if self.coordinates.unit:
            idx = (np.arange(nh)[:, None] * n + self.dofs[None, :]).ravel()
            J[np.ix_(idx, idx)] += G.reshape(nh * m, nh * m)
            return J
        Sb = np.kron(np.eye(nh), self.coordinates.S)  # (nh m, nh n)
        return J + Sb.T @ G @ Sb

    def dense_jacobians(self) -> bool:
        """True: a condensed branch is continued with dense condensed Jacobians at any size."""
        return True


def use_condensed(system: System, condense=None, response_dofs=(), options: HBOptions | None = None) -> bool:
    """Whether harmonic balance condenses ``system``: ``condense`` if True/False, else automatic.

    Automatic: condensed when the system has at least
    ``options.condense_min_dofs`` DOFs, retains at most
    ``options.condense_max_fraction`` of them (:class:`~jointdyn.hb.options.HBOptions`; its retained DOFs,
    even where the problem then keeps fewer relative coordinates: the lap joint's 362 coordinates of 733
    DOFs condensed cost more than the harmonic blocks, docs/performance.md), and K is positive definite
    on the motions that keep the retained coordinates at zero. A structure held only through its
    contacts (:func:`~jointdyn.hb.problem.held_by_contacts`) is never
    condensed: the receptance and the static Schur complement are those of K,
    which has a rigid-body mode there (ValueError naming ``condense`` when it
    is asked for). Nor is a free-free structure (rigid-body modes with every
    contact stuck, :func:`jointdyn.systems.free_modes`): its receptance has
    rigid-body terms 1/w^2 and K no static inverse; the full problem gauges
    the rigid-body part of the mean (:func:`jointdyn.hb.problem.mean_gauge`).
    """
    if condense is not None and condense not in (True, False):
        raise ValueError(f"condense must be True, False or None (automatic), got {condense!r}")
    if condense is False:
        return False
    if free_modes(system).shape[1]:
        if condense:
            raise ValueError("condense: the structure is free-free (rigid-body modes even with every contact "
                             "stuck), so its receptance has 1/w^2 rigid-body terms and no static part to condense "
                             "with; use condense=False (or None: the full problem)")
        return False
    if held_by_contacts(system):
        if condense:
            raise ValueError("condense: the structure is held only through its contacts (K with the tangential "
                             "contacts free has a rigid-body mode), so its receptance has no static part to "
                             "condense with; use condense=False (or None: the full problem)")
        return False
    if condense:
        return True
    opts = hb_options(options)
    if system.ndof < opts.condense_min_dofs:
        return False
    if retained_dofs(system, response_dofs).size > opts.condense_max_fraction * system.ndof:
        return False  # the DOFs, not the relative coordinates (docs/performance.md: the lap joint)
    try:
        _static_parts(system.K, retained_coordinates(system, response_dofs, opts.condense_relative),
                      receptance(system))
    except ValueError:
        return False
    return True


def make_problem(system: System, *, condense=None, response_dofs=(), **kwargs) -> HBProblem:
    """The harmonic-balance problem of ``system``: condensed (:class:`CondensedHBProblem`) or full.

    ``condense``: True, False, or None for the automatic choice of
    :func:`use_condensed`; ``response_dofs`` are kept among the unknowns of
    a condensed problem; other keyword arguments go to the problem (``options``, an
    :class:`~jointdyn.hb.options.HBOptions`, also to the automatic choice).
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    if use_condensed(system, condense, response_dofs, kwargs.get("options")):
        return CondensedHBProblem(system, response_dofs=response_dofs, **kwargs)
    return HBProblem(system, **kwargs)
