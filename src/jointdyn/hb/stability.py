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
form, size 2 n (2H+1) (all its eigenvalues by LAPACK ``dgeev``, except
for matrices (or parity blocks, below) of at most
``StabilityOptions.small_eig`` rows: the compiled EISPACK QR iteration of :mod:`jointdyn.hb._eig` is
faster there, ``benchmarks/bench_linalg.py``).
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
from .._jit import jit
from ..fourier import derivative_matrix
from ._eig import eigvals_inplace
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


@jit
def _hill_eigvals(D2iJ, JX, B1c, B1w, w, parity):  # pragma: no cover - compiled
    """All eigenvalues of the companion matrix of Hill's quadratic problem.

    ``A = [[0, I], [-D2i JX, -(B1c + w B1w)]]`` (see :func:`_hill_parts`),
    eigenvalues by :func:`jointdyn.hb._eig.eigvals_inplace`. ``parity[j]``
    is the parity of the harmonic of unknown j.

    Parity split: the linear terms couple only equal harmonics, and the
    contact Jacobian of a half-wave symmetric orbit (x(t + T/2) = -x(t):
    an odd contact law and no even-harmonic excitation, e.g. a constant
    normal load) couples only harmonics of equal parity, so that A is
    block diagonal after grouping even and odd harmonics. The blocks are
    then solved separately (sizes about N each instead of 2N: a quarter of
    the QR work). The split is made only when the dropped cross-parity
    entries have a Frobenius norm of at most ``2N eps ||A||_F``, the order
    of the backward error of the QR iteration itself (on a symmetric orbit
    they are AFT rounding, ~1e-17 ||A||; otherwise they are of order
    ||A||), so the eigenvalues are as accurate as from the whole matrix.
    Returns ``(eigenvalues, ok)``.
    """
    N = JX.shape[0]
    M2 = 2 * N
    A = np.zeros((M2, M2))
    for i in range(N):
        A[i, N + i] = 1.0
        for k in range(N):  # A[N:, :N] = -(D2i JX), written out (no BLAS binding to compile)
            dik = D2iJ[i, k]
            if dik != 0.0:
                for j in range(N):
                    A[N + i, j] -= dik * JX[k, j]
        for j in range(N):
            A[N + i, N + j] = -(B1c[i, j] + w * B1w[i, j])
    nrm2 = 0.0
    cross2 = 0.0
    n_even = 0
    for i in range(M2):
        pi = parity[i % N]
        n_even += 1 - pi
        for j in range(M2):
            a2 = A[i, j] * A[i, j]
            nrm2 += a2
            if parity[j % N] != pi:
                cross2 += a2
    if 0 < n_even < M2 and np.sqrt(cross2) <= M2 * _EPS * np.sqrt(nrm2):
        out = np.empty(M2, dtype=np.complex128)
        ok = True
        k = 0
        for g in range(2):
            idx = np.empty(n_even if g == 0 else M2 - n_even, dtype=np.int64)
            m = 0
            for i in range(M2):
                if parity[i % N] == g:
                    idx[m] = i
                    m += 1
            sub = np.empty((m, m))
            for a in range(m):
                for b in range(m):
                    sub[a, b] = A[idx[a], idx[b]]
            lam, ok_g = eigvals_inplace(sub)
            ok = ok and ok_g
            for a in range(m):
                out[k] = lam[a]
                k += 1
        return out, ok
    return eigvals_inplace(A)


def _parity(n, H):
    """Parity (0 even, 1 odd) of the harmonic of each unknown X[h * n + i]."""
    return np.array([((j // n + 1) // 2) % 2 for j in range(n * (2 * H + 1))], dtype=np.int64)


@jit
def _select(lam, w, m):  # pragma: no cover - compiled
    """The m eigenvalues with the smallest |Im| / w (rounded to 1e-8), by decreasing real part.

    Returns ``(selected, tie)``; ``tie`` is True when the m-th and the
    (m+1)-th smallest keys are equal (the caller then breaks the tie by the
    eigenvector centroid). Keys are ``numpy.round(|Im| / w, 8)`` (NumPy's
    rule: ``rint(x * 1e8) / 1e8``); both orderings are stable (insertion
    sorts: the arrays hold 2 n (2H+1) and m entries).
    """
    N = lam.shape[0]
    key = np.empty(N)
    for i in range(N):
        key[i] = np.rint(abs(lam[i].imag) / w * 1e8) / 1e8
    order = np.arange(N)
    for i in range(1, N):
        j = i
        while j > 0 and key[order[j - 1]] > key[order[j]]:
            t = order[j - 1]
            order[j - 1] = order[j]
            order[j] = t
            j -= 1
    tie = N > m and key[order[m]] == key[order[m - 1]]
    sel = np.empty(m, dtype=np.complex128)
    for i in range(m):
        sel[i] = lam[order[i]]
    for i in range(1, m):
        j = i
        while j > 0 and -sel[j - 1].real > -sel[j].real:
            t = sel[j - 1]
            sel[j - 1] = sel[j]
            sel[j] = t
            j -= 1
    return sel, tie


def _hill_matrix(JX, M, C, w, H):
    """The companion matrix of :func:`_hill_eigvals`, built with NumPy."""
    N = M.shape[0] * (2 * H + 1)
    D2iJ_pre, B1, A0, _ = _hill_parts(M, C, H)
    A = A0.copy()
    A[N:, :N] = -(D2iJ_pre @ JX)
    A[N:, N:] = -(B1[0] + w * B1[1])
    return A


def _parity_blocks(A, parity):
    """Index arrays of the even- and odd-harmonic rows of the companion matrix A, or None.

    The split criterion of :func:`_hill_eigvals`: the cross-parity entries
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


def _hill_eigvals_lapack(JX, M, C, w, H, small: int = 0):
    """All eigenvalues of the companion matrix assembled with NumPy, with the parity split of
    :func:`_hill_eigvals`: blocks of at most ``small`` rows by the compiled EISPACK port (LAPACK
    if its QR fails), larger ones by LAPACK ``dgeev``."""
    A = _hill_matrix(JX, M, C, w, H)
    blocks = _parity_blocks(A, _hill_parts(M, C, H)[3]) or (np.arange(A.shape[0]),)
    out = []
    for b in blocks:
        sub = A[np.ix_(b, b)]
        if sub.shape[0] <= small:
            lam, ok = eigvals_inplace(sub)
            if ok:
                out.append(lam)
                continue
            sub = A[np.ix_(b, b)]
        out.append(np.linalg.eigvals(sub))
    return np.concatenate(out)


def _small_eig(JX, small: int) -> bool:
    """True when the whole companion matrix of JX (twice its rows) has at most ``small`` rows (the compiled
    path, ``StabilityOptions.small_eig``)."""
    return 2 * JX.shape[0] <= small


def _hill_all(JX, M, C, w, H, small: int):
    """All Hill eigenvalues: compiled for companions of at most ``small`` rows (LAPACK if its QR fails),
    else assembled with NumPy and solved by blocks (:func:`_hill_eigvals_lapack`)."""
    JX = np.ascontiguousarray(JX, dtype=np.float64)
    if _small_eig(JX, small):
        D2iJ_pre, B1, _, parity = _hill_parts(M, C, H)
        lam, ok = _hill_eigvals(D2iJ_pre, JX, B1[0], B1[1], float(w), parity)
        if ok:
            return lam
    return _hill_eigvals_lapack(JX, M, C, w, H, small)


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
        ``small_eig``: the size of the compiled eigenvalue path.

    Returns
    -------
    exponents : ndarray complex (2n,)
        Floquet exponents s, 1/s (sorted by decreasing real part).
    all_eigenvalues : ndarray complex (2 n (2H+1),)

    Notes
    -----
    The eigenvalues of the 2 n (2H+1) companion matrix (or of its parity
    blocks) are computed by LAPACK (``numpy.linalg.eigvals``), up to
    ``StabilityOptions.small_eig`` rows by the compiled EISPACK sequence of
    :mod:`jointdyn.hb._eig` (balancing,
    Hessenberg reduction, Francis double-shift QR), which agrees with
    LAPACK to rounding and is faster there (LAPACK is used if its QR
    iteration does not converge); the eigenvectors of the tie-break come
    from LAPACK.
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


@jit
def _hill_growth_batch(D2iJ, JXs, B1c, B1w, ws, parity, m):  # pragma: no cover - compiled
    """max Re(s) / w of the selected exponents of many points; (growth, ok) with ok False where
    the QR iteration failed or the selection has a tie (the caller recomputes those)."""
    P = JXs.shape[0]
    growth = np.empty(P)
    ok = np.empty(P, dtype=np.bool_)
    for k in range(P):
        lam, good = _hill_eigvals(D2iJ, JXs[k], B1c, B1w, ws[k], parity)
        sel, tie = _select(lam, ws[k], m)
        ok[k] = good and not tie
        growth[k] = sel[0].real / ws[k]
    return growth, ok


def hill_growth(JXs, M, C, ws, H, options: StabilityOptions | None = None):
    """max Re(s) / w of the selected Floquet exponents at many points.

    ``JXs`` (points, N, N) are the HB Jacobians and ``ws`` (points,) the
    angular frequencies; the same exponents as :func:`hill_exponents`
    (points with a tie at the selection cut or a QR failure go through it).
    Small companions (``StabilityOptions.small_eig``, of ``options``) in one compiled loop.
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
            sel, tie = _select(_hill_eigvals_lapack(JXs[k], M, C, ws[k], H, opt.small_eig), ws[k], 2 * n)
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
