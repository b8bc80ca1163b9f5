"""Stability of harmonic-balance solutions: Hill's method.

Hill's method
-------------
A perturbation ``x = x*(t) + exp(s t) p(tau)`` with ``p`` periodic,
``p = Q(tau) P`` in the HB basis, turns the linearised equation of motion
into the quadratic eigenvalue problem (von Groll & Ewins, J. Sound Vib. 241,
2001; Detroux, Renson, Masset & Kerschen, CMAME 296, 2015, eq. 24)::

    (s^2 Delta_2 + s Delta_1 + J_X) P = 0,
    Delta_2 = I (x) M,   Delta_1 = 2 w (nabla (x) M) + I (x) C,

with J_X the HB Jacobian dR/dX (the contact part is the AFT-derived
derivative of the periodic force coefficients, the standard choice for
hysteretic forces, which are not differentiable in velocity) and nabla the
d/dtau operator on the coefficients. It is solved in first-order (companion)
form, size 2 n (2H+1), all its eigenvalues by LAPACK ``dgeev``
(``numpy.linalg.eigvals``; companions of at most ``StabilityOptions.small_eig``
rows of many points assembled as one stack and solved in one call, its loop
over the points in C, so that nothing here is compiled by Numba).
Each Floquet exponent s appears there as a family
s + i k w (k = -H..H), of which the truncation resolves well only the
members whose eigenvectors are centred on the low harmonics. Following
Moore (Int. J. Numer. Meth. Eng. 62, 2005) and the comparison of Peletan,
Baguet, Torkhani & Jacquet-Richardet (Nonlinear Dyn. 72, 2013), the 2n
exponents are the eigenvalues with the smallest |Im s| (one representative
per family lies in |Im s| <= w/2); ties (several real eigenvalues, whose
real eigenvectors are all symmetric) are broken by the symmetry criterion
of Lazarus & Thomas (C. R. Mecanique 338, 2010; Guillot et al., J. Comput.
Phys. 416, 2020): the eigenvector's harmonic centroid, in the complex
exponential basis, nearest to 0. The large-|Im| eigenvalues that this
discards include the truncation artefacts at the edge of the harmonic
range, which may have spurious positive real parts. The solution is
unstable when a selected exponent has ``Re(s) > StabilityOptions.rtol * w``.
Floquet multipliers are ``exp(2 pi s / w)``.

The independent monodromy check lives in :mod:`jointdyn.hb.monodromy`.
"""

from __future__ import annotations

import math

import numpy as np

from .._cache import by_value
from ..fourier import derivative_matrix
from .stability_options import StabilityOptions

__all__ = ["hill_exponents", "hill_stability", "hill_growth"]


def _centroids(V, n, H):
    """Harmonic centroid of the displacement part of each eigenvector."""
    nh = 2 * H + 1
    P = V[: n * nh].reshape(nh, n, -1)
    num = np.zeros(V.shape[1])
    den = np.sum(np.abs(P[0]) ** 2, axis=0)
    for k in range(1, H + 1):
        a = P[2 * k - 1]
        b = P[2 * k]
        cp = np.sum(np.abs(0.5 * (a - 1j * b)) ** 2, axis=0)
        cm = np.sum(np.abs(0.5 * (a + 1j * b)) ** 2, axis=0)
        num += k * (cp - cm)
        den += cp + cm
    return num / np.where(den > 0, den, 1.0)


def _hill_parts(M, C, H):
    """(I (x) M^-1, [I (x) M^-1 (I (x) C), I (x) M^-1 (2 nabla (x) M)], companion template,
    harmonic parity of each unknown), built once per (M, C, H) and shared."""
    return _hill_parts_of(M.tobytes(), C.tobytes(), M.shape[0], int(H))


@by_value()
def _hill_parts_of(Mb: bytes, Cb: bytes, n: int, H: int):
    M = np.frombuffer(Mb).reshape(n, n)
    C = np.frombuffer(Cb).reshape(n, n)
    nh = 2 * H + 1
    D2i = np.kron(np.eye(nh), np.linalg.inv(M))
    B1 = (np.ascontiguousarray(D2i @ np.kron(np.eye(nh), C)),
          np.ascontiguousarray(D2i @ (2.0 * np.kron(derivative_matrix(H), M))))
    N = n * nh
    A0 = np.zeros((2 * N, 2 * N))
    A0[:N, N:] = np.eye(N)
    return D2i, B1, A0, _parity(n, H)


#: machine epsilon of float64
_EPS = float(np.finfo(np.float64).eps)


def _hill_batch(D2iJ, JXs, B1c, B1w, ws):
    """The companion matrices ``A = [[0, I], [-D2i JX, -(B1c + w B1w)]]`` of many points (see
    :func:`_hill_parts`), a stack (points, 2N, 2N) built with NumPy (batched matrix products)."""
    P, N = JXs.shape[0], JXs.shape[1]
    A = np.zeros((P, 2 * N, 2 * N))
    A[:, :N, N:] = np.eye(N)
    A[:, N:, :N] = -(D2iJ @ JXs)
    A[:, N:, N:] = -(B1c + ws[:, None, None] * B1w)
    return A


def _stack_eigvals(A):
    """Eigenvalues of each matrix of the stack ``A`` (points, m, m) by LAPACK ``dgeev`` (one NumPy call,
    its loop over the stack in C); ``(values complex (points, m), ok (points,))``, ok False (values NaN)
    for a matrix whose QR iteration did not converge or that holds a NaN or an infinity."""
    try:
        return np.linalg.eigvals(A).astype(np.complex128, copy=False), np.ones(A.shape[0], dtype=bool)
    except np.linalg.LinAlgError:  # one matrix failed: NumPy refuses the whole stack, redo them one by one
        lam = np.full(A.shape[:2], np.nan, dtype=np.complex128)
        ok = np.zeros(A.shape[0], dtype=bool)
        for k in range(A.shape[0]):
            try:
                lam[k], ok[k] = np.linalg.eigvals(A[k]), True
            except np.linalg.LinAlgError:
                pass
        return lam, ok


def _hill_eigvals_batch(D2iJ, JXs, B1c, B1w, ws, parity):
    """All eigenvalues of the companion matrices of Hill's quadratic problem at many points.

    ``parity[j]`` is the parity of the harmonic of unknown j. Parity split:
    the linear terms couple only equal harmonics, and the contact Jacobian of
    a half-wave symmetric orbit (x(t + T/2) = -x(t): an odd contact law and
    no even-harmonic excitation, e.g. a constant normal load) couples only
    harmonics of equal parity, so that A is block diagonal after grouping
    even and odd harmonics. The blocks are then solved separately (sizes
    about N each instead of 2N: a quarter of the QR work). The split is made,
    point by point, only when the dropped cross-parity entries have a
    Frobenius norm of at most ``2N eps ||A||_F``, the order of the backward
    error of the QR iteration itself (on a symmetric orbit they are AFT
    rounding, ~1e-17 ||A||; otherwise they are of order ||A||), so the
    eigenvalues are as accurate as from the whole matrix (even block's
    eigenvalues first). Returns ``(eigenvalues complex (points, 2N), ok
    (points,))``, ok False where LAPACK failed (:func:`_stack_eigvals`).
    """
    A = _hill_batch(D2iJ, JXs, B1c, B1w, np.asarray(ws, dtype=np.float64))
    P, M2 = A.shape[0], A.shape[1]
    par2 = np.concatenate((parity, parity))
    even, odd = np.flatnonzero(par2 == 0), np.flatnonzero(par2 == 1)
    split = np.zeros(P, dtype=bool)
    if even.size and odd.size:
        nrm2 = np.einsum("pij,pij->p", A, A)
        eo, oe = A[:, even[:, None], odd], A[:, odd[:, None], even]
        cross2 = np.einsum("pij,pij->p", eo, eo) + np.einsum("pij,pij->p", oe, oe)
        split = np.sqrt(cross2) <= M2 * _EPS * np.sqrt(nrm2)
    lam = np.empty((P, M2), dtype=np.complex128)
    ok = np.empty(P, dtype=bool)
    if split.any():
        As = A[split]
        le, oke = _stack_eigvals(As[:, even[:, None], even])
        lo, oko = _stack_eigvals(As[:, odd[:, None], odd])
        lam[split] = np.concatenate((le, lo), axis=1)
        ok[split] = oke & oko
    if not split.all():
        lam[~split], ok[~split] = _stack_eigvals(A[~split])
    return lam, ok


def _parity(n, H):
    """Parity (0 even, 1 odd) of the harmonic of each unknown X[h * n + i]."""
    return np.array([((j // n + 1) // 2) % 2 for j in range(n * (2 * H + 1))], dtype=np.int64)


def _select_batch(lam, ws, m):
    """For each row of ``lam`` (points, N), the m eigenvalues with the smallest |Im| / w (rounded to
    1e-8), by decreasing real part.

    Returns ``(selected (points, m), tie (points,))``; ``tie`` is True when the m-th and the (m+1)-th
    smallest keys are equal (the caller then breaks the tie by the eigenvector centroid). Keys are
    ``numpy.round(|Im| / w, 8)``; both orderings are stable.
    """
    lam = np.atleast_2d(lam)
    key = np.round(np.abs(lam.imag) / np.reshape(ws, (-1, 1)), 8)
    order = np.argsort(key, axis=1, kind="stable")
    keys = np.take_along_axis(key, order, axis=1)
    N = lam.shape[1]
    tie = keys[:, m] == keys[:, m - 1] if N > m else np.zeros(lam.shape[0], dtype=bool)
    sel = np.take_along_axis(lam, order[:, :m], axis=1)
    sel = np.take_along_axis(sel, np.argsort(-sel.real, axis=1, kind="stable"), axis=1)
    return sel, tie


def _select(lam, w, m):
    """The m eigenvalues of ``lam`` with the smallest |Im| / w, by decreasing real part, and whether
    the cut is a tie (:func:`_select_batch` of one point)."""
    sel, tie = _select_batch(np.asarray(lam)[None, :], np.array([float(w)]), m)
    return sel[0], bool(tie[0])


def _hill_matrix(JX, M, C, w, H):
    """The companion matrix of :func:`_hill_batch` of one point, built with NumPy."""
    N = M.shape[0] * (2 * H + 1)
    D2iJ_pre, B1, A0, _ = _hill_parts(M, C, H)
    A = A0.copy()
    A[N:, :N] = -(D2iJ_pre @ JX)
    A[N:, N:] = -(B1[0] + w * B1[1])
    return A


def _parity_blocks(A, parity):
    """Index arrays of the even- and odd-harmonic rows of the companion matrix A, or None.

    The split criterion of :func:`_hill_eigvals_batch`: the cross-parity entries
    have a Frobenius norm of at most ``2N eps ||A||_F``.
    """
    M2 = A.shape[0]
    par2 = np.concatenate((parity, parity))
    even = np.flatnonzero(par2 == 0)
    odd = np.flatnonzero(par2 == 1)
    if even.size == 0 or odd.size == 0:
        return None
    nrm2 = float(np.sum(A * A))
    cross2 = float(np.sum(A[np.ix_(even, odd)] ** 2) + np.sum(A[np.ix_(odd, even)] ** 2))
    if math.sqrt(cross2) <= M2 * _EPS * math.sqrt(nrm2):
        return even, odd
    return None


def _hill_eigvals_lapack(JX, M, C, w, H):
    """All eigenvalues of the companion matrix of one point assembled with NumPy, with the parity split
    of :func:`_hill_eigvals_batch`, each block by LAPACK ``dgeev`` (the path of companions above
    ``StabilityOptions.small_eig`` rows, one point at a time)."""
    A = _hill_matrix(JX, M, C, w, H)
    blocks = _parity_blocks(A, _hill_parts(M, C, H)[3]) or (np.arange(A.shape[0]),)
    return np.concatenate([np.linalg.eigvals(A[np.ix_(b, b)]) for b in blocks]).astype(np.complex128)


def _small_eig(JX, small: int) -> bool:
    """True when the whole companion matrix of JX (twice its rows) has at most ``small`` rows (the batched
    path, ``StabilityOptions.small_eig``)."""
    return 2 * JX.shape[0] <= small


def _hill_all(JX, M, C, w, H, small: int):
    """All Hill eigenvalues: for companions of at most ``small`` rows by :func:`_hill_eigvals_batch` of one
    point, else by :func:`_hill_eigvals_lapack` (both LAPACK, parity blocks where they split)."""
    JX = np.ascontiguousarray(JX, dtype=np.float64)
    if _small_eig(JX, small):
        D2iJ_pre, B1, _, parity = _hill_parts(M, C, H)
        lam, ok = _hill_eigvals_batch(D2iJ_pre, JX[None], B1[0], B1[1], np.array([float(w)]), parity)
        if ok[0]:
            return lam[0]
    return _hill_eigvals_lapack(JX, M, C, w, H)


def hill_exponents(JX, M, C, w, H, options: StabilityOptions | None = None):
    """All Hill eigenvalues and the 2n selected Floquet exponents.

    Parameters
    ----------
    JX : ndarray (n(2H+1), n(2H+1))
        HB Jacobian dR/dX (harmonic-major ordering), N/m.
    M, C : ndarray (n, n)
        Mass (kg) and damping (N s/m) matrices.
    w : float
        Angular frequency of the periodic solution, rad/s.
    H : int
        Number of harmonics.
    options : StabilityOptions, optional
        ``small_eig``: the size up to which the companions go through the batched path.

    Returns
    -------
    exponents : ndarray complex (2n,)
        Floquet exponents s, 1/s (sorted by decreasing real part).
    all_eigenvalues : ndarray complex (2 n (2H+1),)

    Notes
    -----
    The eigenvalues of the 2 n (2H+1) companion matrix (or of its parity
    blocks) are computed by LAPACK (``numpy.linalg.eigvals``); the
    eigenvectors of the tie-break also come from LAPACK.
    """
    n = M.shape[0]
    lam = _hill_all(JX, M, C, w, H, (StabilityOptions() if options is None else options).small_eig)
    sel, tie = _select(lam, float(w), 2 * n)
    if tie:
        # a tie at the cut: break it by the eigenvector centroid
        lam, V = np.linalg.eig(_hill_matrix(JX, M, C, w, H))
        key_imag = np.round(np.abs(lam.imag) / w, 8)
        cen = _centroids(V, n, H)
        order = np.lexsort((np.abs(cen), key_imag))
        sel = lam[order[: 2 * n]]
        sel = sel[np.argsort(-sel.real, kind="stable")]
    return sel, lam


def _hill_growth_batch(D2iJ, JXs, B1c, B1w, ws, parity, m):
    """max Re(s) / w of the selected exponents of many points; (growth, ok) with ok False where
    LAPACK failed or the selection has a tie (the caller recomputes those).

    The companions of all points are assembled as one stack and their eigenvalues taken in one
    LAPACK call per parity block (:func:`_hill_eigvals_batch`): no compiled code, no Python loop
    over the points.
    """
    ws = np.asarray(ws, dtype=np.float64)
    lam, good = _hill_eigvals_batch(D2iJ, JXs, B1c, B1w, ws, parity)
    sel, tie = _select_batch(lam, ws, m)
    return sel[:, 0].real / ws, good & ~tie


def hill_growth(JXs, M, C, ws, H, options: StabilityOptions | None = None):
    """max Re(s) / w of the selected Floquet exponents at many points.

    ``JXs`` (points, N, N) are the HB Jacobians and ``ws`` (points,) the
    angular frequencies; the same exponents as :func:`hill_exponents`
    (points with a tie at the selection cut or a QR failure go through it).
    Small companions (``StabilityOptions.small_eig``, of ``options``) as one stack of LAPACK calls
    (:func:`_hill_growth_batch`), larger ones point by point.
    """
    opt = StabilityOptions() if options is None else options
    JXs = np.ascontiguousarray(JXs, dtype=np.float64)
    ws = np.ascontiguousarray(ws, dtype=np.float64)
    n = M.shape[0]
    if JXs.shape[0] == 0:
        return np.empty(0)
    if _small_eig(JXs[0], opt.small_eig):
        D2iJ_pre, B1, _, parity = _hill_parts(M, C, H)
        growth, ok = _hill_growth_batch(D2iJ_pre, JXs, B1[0], B1[1], ws, parity, 2 * n)
    else:
        growth, ok = np.empty(JXs.shape[0]), np.empty(JXs.shape[0], dtype=bool)
        for k in range(JXs.shape[0]):
            sel, tie = _select(_hill_eigvals_lapack(JXs[k], M, C, ws[k], H), ws[k], 2 * n)
            growth[k], ok[k] = sel[0].real / ws[k], not tie
    for k in np.flatnonzero(~ok):
        sel, _ = hill_exponents(JXs[k], M, C, ws[k], H, opt)
        growth[k] = float(sel[0].real) / ws[k]
    return growth


def hill_stability(JX, M, C, w, H, options: StabilityOptions | None = None):
    """(stable, max Re(s) / w, Floquet multipliers) of a periodic HB solution: stable when the growth is at
    most ``options.rtol`` (StabilityOptions; defaults when None).

    See the module docstring for the method and references.
    """
    opt = StabilityOptions() if options is None else options
    sel, _ = hill_exponents(JX, M, C, w, H, opt)
    growth = float(sel[0].real) / w  # sel is sorted by decreasing real part
    mult = np.exp(sel * 2.0 * np.pi / w)
    return growth <= opt.rtol, growth, mult
