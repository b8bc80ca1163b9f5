"""Hill's method at any size: the Floquet exponents nearest the imaginary axis by shift-invert Arnoldi.

The dense method of :mod:`jointdyn.hb.stability` computes every eigenvalue
of the companion matrix ``A = [[0, I], [-D2^-1 J_X, -D2^-1 D1]]`` of Hill's
quadratic problem ``(s^2 D2 + s D1 + J_X) P = 0`` (2 n (2H+1) rows,
O(rows^3) work and rows^2 memory). Stability is decided by the exponents
nearest the imaginary axis, a few of them, which shift-invert Arnoldi
(ARPACK through :func:`scipy.sparse.linalg.eigs`) finds from products with
``(A - sigma I)^-1`` alone. That product never forms A: for ``v = (a, b)``
(displacement and velocity parts), ``(A - sigma I)^-1 v = (x, a + sigma x)``
with::

    Q(sigma) x = -(D2 b + (D1 + sigma D2) a),
    Q(sigma) = J_X + sigma D1 + sigma^2 D2,

so each product is one solve with Q(sigma), a matrix of the HB Jacobian's
size and structure (the linear terms D1 = I (x) C + 2 w nabla (x) M and
D2 = I (x) M couple the cosine and sine of one harmonic only), factorised
once per shift: sparse LU (SuperLU) where at most
``StabilityOptions.arnoldi_sparse_density`` of its entries are nonzero (a
structure coupled locally: a chain, a mesh), whether the Jacobian is a dense
array, a sparse matrix or kept as harmonic blocks plus the pairs' sparse part
(:class:`~jointdyn.hb._jacobian.HarmonicJacobian`), else dense LU (LAPACK
``getrf``: a reduced model dense on its interface, where SuperLU's fill
costs more).

Shifts sigma_j = i j w / (2 m), j = 0..m (``StabilityOptions.arnoldi_shifts``
= m + 1), lie on the imaginary axis between 0 and i w / 2: the strip
|Im s| <= w/2 where each family s + i k w has its representative when its
members are resolved (the upper half suffices: the spectrum of the real A
is symmetric about the real axis). At each shift the ``arnoldi_eigenvalues``
eigenvalues nearest it are computed; every eigenvalue within the distance
r_j of the farthest of them is among those found (Arnoldi converged), so
the union of the disks covers the band ``|Re s| <= d`` along the strip with
``d = sqrt(min_j r_j^2 - h^2)``, h the farthest a point of the axis between
0 and i w/2 lies from a shift (0 when the disks do not overlap: the band is
not covered). ``arnoldi_shifts = 1`` (an option) is the one real shift
sigma = 0 (a real Q(0) = J_X, whose LU costs about a quarter of a complex
one's): its disk covers the strip when the farthest of its eigenvalues lies
beyond w/2 (h = w/2, d = sqrt(r_0^2 - w^2/4)), as on a structure whose
exponents near the axis are few (a reduced model: the exponents of a mode
above (H + 1/2) w have no member near the axis); where it does not (band 0:
exponents crowd the strip), the shifts j = 1..m of the layout of
``arnoldi_cover_shifts`` = m + 1 shifts are added to it, and the band is that
of all of them. A shift that falls on an eigenvalue (Q exactly singular) is
moved by 1e-3 w. Hill's selection is applied to what was found: the
conjugates added, copies found from two shifts counted once, and where more
than 2n were found the 2n with the smallest |Im s| (the dense method's
rule, which also keeps the members of families with no member in the strip:
modes above (H + 1/2) w); the growth is the largest real part among them.
An exponent farther than d from the imaginary axis with a larger real part
is not seen: the result says d (``band``), and a branch whose exponents of
largest real part are near the axis (the folds and Neimark-Sacker points
where stability changes have Re s = 0) is labelled as the dense method
labels it (tests/test_hb_hill_arnoldi.py).
"""

from __future__ import annotations

import math
import warnings
from dataclasses import dataclass

import numpy as np

from ..fourier import derivative_matrix
from .stability_options import StabilityOptions

__all__ = ["ArnoldiExponents", "hill_arnoldi_exponents", "hill_arnoldi_growth"]


@dataclass(frozen=True)
class ArnoldiExponents:
    """The Floquet exponents found near the imaginary axis.

    Attributes
    ----------
    exponents : ndarray complex
        Exponents s (1/s) found nearest the axis between -i w/2 and i w/2,
        after Hill's selection (module docstring), by decreasing real part.
    band : float
        Half-width d (1/s) of the band about the imaginary axis (between
        -i w/2 and i w/2) in which every exponent has been found; 0 where the
        shifts' disks do not cover the strip.
    growth : float
        Largest Re(s) / w among ``exponents`` (NaN when none was found).
    """

    exponents: np.ndarray
    band: float
    growth: float


def _linear_parts(M, C, w, H):
    """(D1, D2) of Hill's quadratic problem as sparse matrices (harmonic-major unknowns)."""
    import scipy.sparse as sp

    nh = 2 * H + 1
    eye = sp.identity(nh, format="csr")
    D2 = sp.kron(eye, sp.csr_matrix(M), format="csr")
    D1 = sp.kron(eye, sp.csr_matrix(C), format="csr") + 2.0 * w * sp.kron(
        sp.csr_matrix(derivative_matrix(H)), sp.csr_matrix(M), format="csr")
    return D1.tocsr(), D2


def _as_sparse(JX):
    """JX (a HarmonicJacobian, a scipy.sparse matrix) as CSR."""
    import scipy.sparse as sp

    if getattr(JX, "structured", False) is True:  # jointdyn.hb._jacobian.HarmonicJacobian
        A = sp.block_diag(JX.blocks, format="csr")
        A = (A + JX.rest.tocsr()) * JX.scale
        if JX.columns:
            A = A.tolil()
            for j, c in JX.columns.items():
                A[:, j] = c[:, None]
        return A.tocsr()
    return sp.csr_matrix(JX)


def _nonzeros(JX) -> int:
    """Nonzero entries of JX (a HarmonicJacobian: its dense blocks and the pairs' part, an upper bound)."""
    if isinstance(JX, np.ndarray):
        return int(np.count_nonzero(JX))
    if getattr(JX, "structured", False) is True:
        return sum(B.size for B in JX.blocks) + int(JX.rest.nnz) + JX.shape[0] * len(JX.columns)
    return int(JX.nnz)


class _ShiftInvert:
    """``v -> (A - sigma I)^-1 v`` through one factorisation of Q(sigma) (module docstring)."""

    def __init__(self, JX, D1, D2, sigma, sparse_density: float):
        self.sigma, self.D1, self.D2 = sigma, D1, D2
        self.N = D2.shape[0]
        dtype = np.complex128 if isinstance(sigma, complex) else np.float64
        self.dtype = dtype
        if _nonzeros(JX) > sparse_density * self.N * self.N:
            import scipy.linalg as sla

            J = JX if isinstance(JX, np.ndarray) else JX.toarray()
            Q = J.astype(dtype) + sigma * D1.toarray() + (sigma * sigma) * D2.toarray()
            with warnings.catch_warnings():  # a zero pivot is reported below, as a singular sparse LU is
                warnings.simplefilter("ignore", sla.LinAlgWarning)
                lu = sla.lu_factor(Q, check_finite=True)
            if not np.all(np.abs(lu[0].diagonal()) > 0.0):
                raise ValueError("Q(sigma) is exactly singular")
            self._solve = lambda r: sla.lu_solve(lu, r, check_finite=False)
        else:
            import scipy.sparse.linalg as spla

            Q = (_as_sparse(JX).astype(dtype) + sigma * D1 + (sigma * sigma) * D2).tocsc()
            lu = spla.splu(Q)
            self._solve = lu.solve

    def __call__(self, v):
        v = np.asarray(v).ravel()
        a, b = v[: self.N], v[self.N:]
        x = -self._solve(self.D2 @ b + self.D1 @ a + self.sigma * (self.D2 @ a))
        return np.concatenate((x, a + self.sigma * x))


def _dedupe(lam, w, tol):
    """The values of lam (complex) with copies closer than ``tol * w`` counted once."""
    out = []
    for z in lam[np.argsort(-lam.real, kind="stable")]:
        if all(abs(z - u) > tol * w for u in out):
            out.append(z)
    return np.array(out, dtype=np.complex128)


def _nearest(operator, N, y, w, k, opt):
    """(shift y, the k eigenvalues nearest i y): the shift moved towards the middle of the strip by
    ``1e-3 w`` at a time where Q(i y) is exactly singular (i y is then an eigenvalue itself, e.g. an
    undamped mean at w = 2 w0). ``operator(sigma)`` is the shift-invert product at sigma (``sigma``,
    ``dtype``, called on a vector of 2N), raising RuntimeError or ValueError where Q(sigma) is singular."""
    import scipy.sparse.linalg as spla

    step = 1e-3 * w * (1.0 if y < 0.25 * w else -1.0)
    for attempt in range(3):
        sigma = complex(0.0, y) if y != 0.0 else 0.0
        try:
            op = operator(sigma)
            break
        except (RuntimeError, ValueError) as exc:  # SuperLU: "Factor is exactly singular"
            if attempt == 2:
                raise np.linalg.LinAlgError(f"Hill's Q(sigma) is singular at sigma = {sigma}: {exc}") from None
            y += step
    L = spla.LinearOperator((2 * N, 2 * N), matvec=op, dtype=op.dtype)
    ncv = min(2 * N, max(2 * k + 1, 20))
    try:
        mu = spla.eigs(L, k=k, which="LM", ncv=ncv, tol=opt.arnoldi_tol, maxiter=opt.arnoldi_maxiter,
                       return_eigenvectors=False)
    except spla.ArpackNoConvergence as exc:
        raise np.linalg.LinAlgError(f"Arnoldi did not converge at sigma = {sigma}: {exc}") from None
    return y, sigma + 1.0 / mu


def hill_arnoldi_exponents(JX, M, C, w, H, options: StabilityOptions | None = None) -> ArnoldiExponents:
    """Floquet exponents nearest the imaginary axis by shift-invert Arnoldi on Hill's companion problem.

    Parameters
    ----------
    JX : ndarray, scipy.sparse matrix or HarmonicJacobian (n(2H+1), n(2H+1))
        HB Jacobian dR/dX (harmonic-major ordering), N/m.
    M, C : ndarray (n, n)
        Mass (kg) and damping (N s/m) matrices.
    w : float
        Angular frequency of the periodic solution, rad/s.
    H : int
        Number of harmonics.
    options : StabilityOptions, optional
        ``arnoldi_shifts``, ``arnoldi_cover_shifts``, ``arnoldi_eigenvalues``, ``arnoldi_tol``,
        ``arnoldi_maxiter``.

    Returns
    -------
    ArnoldiExponents
        The exponents found (after Hill's selection), the band covered and the growth.

    Raises
    ------
    numpy.linalg.LinAlgError
        Where Q(sigma) is singular at a shift, or ARPACK does not converge.
    """
    opt = StabilityOptions() if options is None else options
    if getattr(JX, "approximation", None) is not None:  # a sparse part plus a modal-damping operator: Q(sigma)
        JX = JX.toarray()                                # is factorised as the whole matrix it is
    w = float(w)
    n = M.shape[0]
    D1, D2 = _linear_parts(np.asarray(M, dtype=np.float64), np.asarray(C, dtype=np.float64), w, H)
    return shift_invert_exponents(lambda sigma: _ShiftInvert(JX, D1, D2, sigma, opt.arnoldi_sparse_density),
                                  n, H, w, opt)


def shift_invert_exponents(operator, n: int, H: int, w: float, opt: StabilityOptions) -> ArnoldiExponents:
    """The exponents nearest the imaginary axis of a Hill problem of ``n`` DOFs and ``H`` harmonics from its
    shift-invert product: ``operator(sigma)`` gives ``v -> (A - sigma I)^-1 v`` on vectors of 2 n (2H+1)
    (with attributes ``sigma`` and ``dtype``; RuntimeError or ValueError where Q(sigma) is singular), in any
    coordinates similar to the companion matrix A's. The shifts, the Hill selection and the band of the
    module docstring; ``opt`` the StabilityOptions."""
    w = float(w)
    N = n * (2 * H + 1)
    k = min(opt.arnoldi_eigenvalues, 2 * N - 2)
    if k < 1:
        raise ValueError(f"Hill's companion matrix has {2 * N} rows: too few for Arnoldi (at least 3)")
    found, radii, ys = [], [], []

    def at(y):
        y, lam = _nearest(operator, N, y, w, k, opt)
        found.append(lam)
        ys.append(y)
        radii.append(float(np.max(np.abs(lam - complex(0.0, y)))))

    for y in _layout(opt.arnoldi_shifts, w):
        at(y)
    if opt.arnoldi_shifts == 1 and _band(ys, radii, w) == 0.0:  # one disk short of i w/2: the covering shifts
        for y in _layout(opt.arnoldi_cover_shifts, w)[1:]:
            at(y)
    lam = np.concatenate(found)
    lam = np.concatenate((lam, lam.conj()))
    sel = _dedupe(lam, w, 1e-8)
    if sel.size > 2 * n:  # Hill's selection: the 2n with the smallest |Im| (as the dense method)
        key = np.round(np.abs(sel.imag) / w, 8)
        sel = sel[np.argsort(key, kind="stable")[: 2 * n]]
        sel = sel[np.argsort(-sel.real, kind="stable")]
    band = _band(ys, radii, w)
    growth = float(sel[0].real) / w if sel.size else math.nan
    return ArnoldiExponents(exponents=sel, band=band, growth=growth)


def _layout(count: int, w: float) -> list:
    """Imaginary parts (rad/s) of ``count`` shifts evenly from 0 to w/2 (0 alone for one)."""
    return [0.5 * w * j / (count - 1) for j in range(count)] if count > 1 else [0.0]


def _band(ys, radii, w: float) -> float:
    """Half-width d (1/s) of the band about the axis, between 0 and i w/2, that the disks of radii ``radii``
    about the shifts i ``ys`` (ascending) cover (module docstring); 0 where they do not cover the axis."""
    # every point of the axis between 0 and i w/2 lies within h of a shift
    h = max(ys[0], 0.5 * w - ys[-1], *(0.5 * (b - a) for a, b in zip(ys, ys[1:])))
    r2 = min(radii) ** 2 - h * h
    return math.sqrt(r2) if r2 > 0.0 else 0.0


def hill_arnoldi_growth(JXs, M, C, ws, H, options: StabilityOptions | None = None) -> np.ndarray:
    """max Re(s) / w of the exponents nearest the imaginary axis (:func:`hill_arnoldi_exponents`) at many
    points (``JXs`` a sequence of Jacobians, ``ws`` their frequencies, rad/s)."""
    return np.array([hill_arnoldi_exponents(J, M, C, w, H, options).growth for J, w in zip(JXs, ws)])
