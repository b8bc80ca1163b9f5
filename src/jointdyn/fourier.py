"""The real Fourier basis of periodic signals, in one place.

A periodic signal of normalised time tau = w t (period 2 pi) truncated to
harmonics 0..H is stored as ``2H + 1`` real coefficients::

    u(tau) = U_0 + sum_{k=1}^{H} U_{2k-1} cos(k tau) + U_{2k} sin(k tau)

Harmonic balance (:mod:`jointdyn.hb`), its stability analysis and the
monodromy check build on the matrices here: the synthesis matrix ``E``
(coefficients -> samples at ``tau_j = 2 pi j / Ns``), the analysis matrix
``P`` (samples -> coefficients, the discrete Fourier projection), the
derivative ``D`` (d/dtau on the coefficients), the basis at arbitrary
phases, and the reconstruction and extrema of a signal on a fine grid.

Matrices that depend only on (H, Ns) are built once per process and shared
(:func:`jointdyn._cache.by_value`): callers must not write into them.
"""

from __future__ import annotations

import math

import numpy as np

from ._cache import by_value
from ._jit import jit

__all__ = ["phases", "basis", "fourier_matrices", "event_projection", "separation_grid", "derivative_matrix",
           "reconstruct", "extrema"]

#: a contact force is zero while the contact is open and continuous at separation and re-contact: where a
#: prescribed normal load changes sign, the AFT projects the force with the corners there taken into
#: account (jointdyn.fourier.event_projection): one-sided polynomials of this degree through the corner
#: and the nearest samples (error O(h^4) for a force smooth on either side, against O(h^2) uniform) ...
HB_EVENT_ORDER = 3
#: ... skipping samples nearer to the corner than this fraction of the sampling interval (nearly zero)
HB_EVENT_MIN_OFFSET = 0.25
#: before a separation the friction bound mu N falls to zero and a stuck contact slips only in the last
#: ~|T| / (mu |dN/dtau|) rad, a near-jump of the force inside one sampling interval at large mu N0 / F1: the
#: AFT marches the law also at phases graded towards each separation (jointdyn.fourier.separation_grid),
#: over this many uniform samples before it (a slip stretch as wide as a few samples, eta = 10 and beta
#: = 1-10, needs 4: with 2 its peaks at 7 x 128 are up to 1.4e-3 off the converged ones, with 4 within 4e-4) ...
HB_SEPARATION_SPAN = 4
#: ... each phase's distance to the separation this fraction of the one before (spacing 20 % of the
#: distance) ...
HB_SEPARATION_RATIO = 0.8
#: ... down to this distance (rad): a slip stretch shorter than it costs at most its own width times the
#: stuck force in the force's integral (with 4 samples, 0.8 and 1e-4: 32 phases more than the 128 samples)
HB_SEPARATION_FINEST = 1e-4
#: uniform samples per period of the fine grid on which amplitudes and
#: extrema of a harmonic-balance response are located
HB_FINE_SAMPLES = 1024

#: one side of a zero stretch of a signal (:func:`event_projection`): the signal is zero before the phase
#: (it starts there) or after it (it stops there)
STARTS, STOPS = 1, -1
#: Gauss-Legendre points per interval, and degree of the piecewise polynomials, of the product integration
#: of :func:`separation_grid`
_GAUSS_POINTS, _PRODUCT_DEGREE = 8, 3


def phases(samples: int) -> np.ndarray:
    """Uniform phases ``tau_j = 2 pi j / Ns``, j = 0..Ns-1 (rad)."""
    return 2.0 * np.pi * np.arange(samples) / samples


def basis(harmonics: int, tau) -> np.ndarray:
    """Basis functions at the phases ``tau`` (rad): array (len(tau), 2H+1).

    Columns ``1, cos(tau), sin(tau), ..., cos(H tau), sin(H tau)``; row j
    times the coefficients is the signal at ``tau[j]``.
    """
    tau = np.asarray(tau, dtype=np.float64)
    E = np.empty((tau.size, 2 * harmonics + 1))
    E[:, 0] = 1.0
    for k in range(1, harmonics + 1):
        E[:, 2 * k - 1] = np.cos(k * tau)
        E[:, 2 * k] = np.sin(k * tau)
    return E


@by_value()
def fourier_matrices(harmonics: int, samples: int):
    """Synthesis ``E`` (Ns, 2H+1) and analysis ``P`` (2H+1, Ns) matrices.

    ``E = basis(H, phases(Ns))``; ``P`` is the discrete Fourier projection
    (trapezoidal rule, exact for trigonometric polynomials of degree below
    Ns - H), so that ``P @ E = I`` for ``Ns > 2H``. Built once per (H, Ns)
    and shared: do not write into them.
    """
    E = basis(harmonics, phases(samples))
    P = np.ascontiguousarray(E.T * (2.0 / samples))
    P[0] *= 0.5
    return E, P


def _bernoulli(m: int, x: float) -> float:
    """Bernoulli polynomial B_m(x), m = 1..4."""
    return (x - 0.5, x * x - x + 1.0 / 6.0, x ** 3 - 1.5 * x * x + 0.5 * x,
            x ** 4 - 2.0 * x ** 3 + x * x - 1.0 / 30.0)[m - 1]


def _basis_derivatives(harmonics: int, tau: float) -> np.ndarray:
    """The basis functions and their first three derivatives at ``tau``: (4, 2H+1)."""
    out = np.zeros((4, 2 * harmonics + 1))
    out[0, 0] = 1.0
    for k in range(1, harmonics + 1):
        c, s = np.cos(k * tau), np.sin(k * tau)
        out[:, 2 * k - 1] = (c, -k * s, -k * k * c, k ** 3 * s)
        out[:, 2 * k] = (s, k * c, -k * k * s, -k ** 3 * c)
    return out


def _one_sided_derivatives(tau_e: float, side: int, samples: int, order: int, min_offset: float):
    """(sample indices, D): D[m - 1] @ u[indices] is d^m u / dtau^m (m = 1..p) at ``tau_e`` from the side
    where u is not zero, by the polynomial of degree p <= ``order`` through u(tau_e) = 0 and the p nearest
    samples on that side at least ``min_offset`` sampling intervals away (None where fewer than 1)."""
    h = 2.0 * np.pi / samples
    x = (tau_e % (2.0 * np.pi)) / h
    j0 = int(np.floor(x))
    first = j0 + 1 if side == STARTS else (j0 if x > j0 else j0 - 1)
    js = [first + side * i for i in range(order + 1)]
    s = [(j * h - tau_e) / h for j in js]
    keep = [i for i in range(len(js)) if abs(s[i]) >= min_offset][:order]
    if not keep:
        return None
    sl = np.array([s[i] for i in keep])
    p = sl.size
    C = np.linalg.inv(sl[:, None] ** np.arange(1, p + 1)[None, :])  # u(s) = sum_q a_q s^q, a = C u
    fact = np.cumprod(np.arange(1, p + 1, dtype=float))
    return [js[i] % samples for i in keep], (fact / h ** np.arange(1, p + 1))[:, None] * C


@by_value()
def event_projection(harmonics: int, samples: int, events: tuple, order: int = HB_EVENT_ORDER,
                     min_offset: float = HB_EVENT_MIN_OFFSET) -> np.ndarray:
    """Analysis matrix (2H+1, Ns) for a signal that is zero on stretches of the period, given their ends.

    The uniform projection (:func:`fourier_matrices`) is the trapezoidal
    rule: spectrally accurate for a smooth periodic signal, but only
    O(h^2), with an error that jumps with the position of a corner inside
    its sampling interval, for a signal with corners. A contact force
    that is zero while the contact is open and continuous at separation
    and re-contact (|T| <= mu N -> 0) has corners there, at phases known
    before the force is. Each such corner at ``tau_e = (j + theta) h`` adds
    to the trapezoidal sum of ``g = u b_k`` the terms
    ``(-1)^m [g^(m)] h^(m+1) B_(m+1)(theta) / (m+1)!`` (generalised
    Euler-Maclaurin; ``[g^(m)]`` the jump of the m-th derivative, B the
    Bernoulli polynomials), m = 1..p; they are subtracted with the
    one-sided derivatives of u at the corner from the polynomial through
    u(tau_e) = 0 and the p nearest samples on the side where u is not zero
    (``order`` p = 3: error O(h^4) for a signal smooth on either side).
    The result is linear in the samples, so an AFT Jacobian through it is
    exact. Built once per arguments and shared: do not write into it.

    Parameters
    ----------
    harmonics, samples : int
        H and Ns.
    events : tuple of (float, int)
        ``(tau_e, side)``: a phase (rad) where the signal leaves zero
        (``side`` = :data:`STARTS`) or comes to zero (:data:`STOPS`).
    order : int
        Degree p of the one-sided polynomials.
    min_offset : float
        Samples nearer than this many sampling intervals to a corner are
        not nodes of its polynomial (their value is nearly zero).
    """
    E, P = fourier_matrices(harmonics, samples)
    out = P.copy()
    h = 2.0 * np.pi / samples
    weight = np.full(2 * harmonics + 1, 2.0 / samples)  # coefficient per unit of the trapezoidal sum / h
    weight[0] = 1.0 / samples
    for tau_e, side in events:
        x = (tau_e % (2.0 * np.pi)) / h
        j0 = np.floor(x)
        theta = x - j0
        if side == STARTS and theta == 0.0:
            theta = 1.0  # the sample on the corner is open: the corner ends the interval before it
        nodes = _one_sided_derivatives(tau_e, side, samples, order, min_offset)
        if nodes is None:
            continue
        idx, D = nodes
        b = _basis_derivatives(harmonics, tau_e)
        jumps = [np.outer(b[0], D[0])]  # [g'] = u' b (u = 0 at the corner)
        if len(D) > 1:
            jumps.append(np.outer(b[0], D[1]) + 2.0 * np.outer(b[1], D[0]))
        if len(D) > 2:
            jumps.append(np.outer(b[0], D[2]) + 3.0 * np.outer(b[1], D[1]) + 3.0 * np.outer(b[2], D[0]))
        corr = np.zeros((2 * harmonics + 1, len(idx)))
        for m, J in enumerate(jumps, start=1):
            corr += ((-1.0) ** m * side * h ** (m + 1) * _bernoulli(m + 1, theta) / np.prod(np.arange(1, m + 2))) * J
        # the trapezoidal sum h sum_j g_j exceeds the integral by corr; the coefficient is weight / h times it
        out[:, idx] -= (weight / h)[:, None] * corr
    return np.ascontiguousarray(out)


def _cut_excess(harmonics: int, samples: int, a: int, order: int):
    """(sample indices, X): X @ u[indices] is the excess ``h sum'' g - int g`` (k = 0..2H) of the trapezoidal
    rule over a stretch that ends at sample ``a`` (weighted one half there) for g = u b_k, u smooth up to it:
    ``(h^2 / 12) g^(1)(t_a) - (h^4 / 720) g^(3)(t_a)`` (Euler-Maclaurin), with the derivatives of u from the
    polynomial of degree ``order`` through the samples a, a - 1, ..., a - order."""
    h = 2.0 * np.pi / samples
    s = -np.arange(order + 1, dtype=float)
    C = np.linalg.inv(s[:, None] ** np.arange(order + 1)[None, :])  # u(s h) = sum_q c_q s^q, c = C u
    du = [np.zeros(order + 1) for _ in range(4)]
    for m in range(min(order, 3) + 1):
        du[m] = math.factorial(m) * C[m] / h ** m
    b = _basis_derivatives(harmonics, a * h)
    g1 = np.outer(b[0], du[1]) + np.outer(b[1], du[0])
    g3 = np.outer(b[0], du[3]) + 3.0 * np.outer(b[1], du[2]) + 3.0 * np.outer(b[2], du[1]) + np.outer(b[3], du[0])
    return [(a - i) % samples for i in range(order + 1)], (h * h / 12.0) * g1 - (h ** 4 / 720.0) * g3


def _product_weights(harmonics: int, nodes: np.ndarray, first: int, degree: int) -> np.ndarray:
    """W (2H+1, len(nodes)): ``W @ u`` is the integral over [nodes[first], nodes[-1]] of ``p b_k``, p on each
    interval the polynomial of degree ``degree`` through the ``degree + 1`` nodes around it (centred where the
    nodes allow; the nodes before ``first`` serve the stencils only). Gauss-Legendre on every interval: exact
    to rounding while k times the interval stays below 1."""
    x, w = np.polynomial.legendre.leggauss(_GAUSS_POINTS)
    W = np.zeros((2 * harmonics + 1, nodes.size))
    for i in range(first, nodes.size - 1):
        lo = max(0, min(i - (degree - 1) // 2, nodes.size - degree - 1))
        z = nodes[lo: lo + degree + 1]
        d = nodes[i + 1] - nodes[i]
        t = nodes[i] + 0.5 * d * (x + 1.0)
        L = np.ones((t.size, z.size))  # Lagrange basis of the stencil at the quadrature points
        for j in range(z.size):
            for m in range(z.size):
                if m != j:
                    L[:, j] *= (t - z[m]) / (z[j] - z[m])
        W[:, lo: lo + degree + 1] += basis(harmonics, t).T @ ((0.5 * d * w)[:, None] * L)
    return W


def _graded_nodes(tau_e: float, length: float, uniform: np.ndarray, ratio: float, finest: float) -> np.ndarray:
    """Phases ``tau_e - length ratio^k`` (k >= 1, down to ``finest`` before ``tau_e``), less those within a
    quarter of their spacing of a uniform sample."""
    k = np.arange(1, int(math.log(finest / length) / math.log(ratio)) + 1)
    d = length * ratio ** k
    g = tau_e - d
    near = np.abs(g[:, None] - uniform[None, :]).min(axis=1) < 0.25 * (1.0 - ratio) * d / ratio
    return g[~near]


@by_value()
def separation_grid(harmonics: int, samples: int, events: tuple, order: int = HB_EVENT_ORDER,
                    min_offset: float = HB_EVENT_MIN_OFFSET, span: int = HB_SEPARATION_SPAN,
                    ratio: float = HB_SEPARATION_RATIO, finest: float = HB_SEPARATION_FINEST):
    """AFT phases and matrices for a contact force that stops at separations (``tau, E, P, uniform``).

    Before a separation the normal load N falls to zero and the friction
    bound mu N with it: a contact that is stuck far below the bound slips
    only in the last ``~|T| / (mu |dN/dtau|)`` rad (0.002 rad at the
    paper's beta = 1000, eta = 1.5), and the force falls from the stuck
    value to zero there: a near-jump inside one sampling interval, which
    neither the trapezoidal rule nor the corner correction of
    :func:`event_projection` (a force smooth on the sample scale) resolves.
    Here the stretch ``R = [t_a, tau_e]`` from the ``span``-th sample
    before each separation ``tau_e`` to it gets extra phases, graded
    geometrically towards ``tau_e`` (spacing ``(1 - ratio)`` times the
    distance to it, down to ``finest`` rad), at which the AFT marches the
    law like at the uniform samples; the force is integrated over R as
    piecewise cubic through these nodes (zero at ``tau_e``:
    ``|T| <= mu N``; error O(h^4) where the force is smooth), and
    over the rest of the period by the trapezoidal rule with the
    Euler-Maclaurin terms of its end at ``t_a`` (:func:`_cut_excess`) and
    the corner corrections of the re-contacts (:func:`event_projection`).
    ``P`` stays linear in the samples: an AFT Jacobian through it is exact.
    Where a closed stretch is too short for R and the polynomial before
    it, the uniform samples with :func:`event_projection` are returned.
    Built once per arguments and shared: do not write into the arrays.

    Parameters
    ----------
    harmonics, samples : int
        H and the uniform samples Ns.
    events : tuple of (float, int)
        As for :func:`event_projection`.
    order, min_offset : int, float
        As for :func:`event_projection` (``order``: also the degree of the
        polynomial of the Euler-Maclaurin terms at ``t_a``).
    span : int
        Uniform samples of R (its start ``t_a`` included).
    ratio, finest : float
        Geometric ratio of the extra phases' distances to ``tau_e`` and the
        smallest distance (rad).

    Returns
    -------
    tau : ndarray (Ng,)
        Increasing phases in [0, 2 pi) (rad), the uniform ones among them
        (``tau[0] = 0``).
    E : ndarray (Ng, 2H+1)
        Basis functions at ``tau``.
    P : ndarray (2H+1, Ng)
        Analysis matrix: the force's coefficients are ``P @ T``.
    uniform : ndarray (Ns,) of int
        Position of uniform sample j in ``tau``.
    """
    h = 2.0 * np.pi / samples
    starts = tuple(ev for ev in events if ev[1] == STARTS)
    stops = [ev[0] % (2.0 * np.pi) for ev in events if ev[1] == STOPS]
    if not stops or not _room(events, (span + order + 1) * h):
        return (phases(samples), fourier_matrices(harmonics, samples)[0],
                event_projection(harmonics, samples, events, order, min_offset), np.arange(samples))
    Pu = fourier_matrices(harmonics, samples)[1]
    out = event_projection(harmonics, samples, starts, order, min_offset).copy()
    scale = np.full(2 * harmonics + 1, 1.0 / np.pi)  # coefficient per unit of the integral of u b_k
    scale[0] = 0.5 / np.pi
    extra_tau, extra_cols = [], []
    for tau_e in stops:
        j0 = int(np.ceil(tau_e / h)) - 1  # last sample before tau_e
        a = j0 - span + 1
        # the rest of the period: trapezoidal up to t_a (half its sample there), corrected for its end
        for j in range(a + 1, j0 + 1):
            out[:, j % samples] -= Pu[:, j % samples]
        out[:, a % samples] -= 0.5 * Pu[:, a % samples]
        idx, excess = _cut_excess(harmonics, samples, a, order)
        out[:, idx] -= scale[:, None] * excess
        # R: piecewise cubic through the uniform samples (one before t_a for the first stencil) and the graded
        # phases, zero at tau_e
        uni = np.arange(a - 1, j0 + 1) * h
        graded = _graded_nodes(tau_e, tau_e - a * h, uni, ratio, finest)
        nodes = np.concatenate([uni, graded])
        perm = np.argsort(nodes, kind="stable")
        cols = np.empty((2 * harmonics + 1, nodes.size))
        cols[:, perm] = (_product_weights(harmonics, np.append(nodes[perm], tau_e), 1, _PRODUCT_DEGREE)[:, :-1]
                         * scale[:, None])
        for i, j in enumerate(range(a - 1, j0 + 1)):
            out[:, j % samples] += cols[:, i]
        extra_tau.append(graded % (2.0 * np.pi))
        extra_cols.append(cols[:, uni.size:])
    tau_all = np.concatenate([phases(samples)] + extra_tau)
    perm = np.argsort(tau_all, kind="stable")
    tau = tau_all[perm]
    P = np.ascontiguousarray(np.concatenate([out] + extra_cols, axis=1)[:, perm])
    uniform = np.argsort(perm, kind="stable")[:samples]
    return tau, np.ascontiguousarray(basis(harmonics, tau)), P, uniform


def _room(events: tuple, needed: float) -> bool:
    """True when every stretch from a re-contact to the next separation is longer than ``needed`` (rad)."""
    two_pi = 2.0 * np.pi
    for tau_e, side in events:
        if side != STOPS:
            continue
        closed = [(tau_e - t) % two_pi for t, s in events if s == STARTS]
        if not closed or min(closed) <= needed:
            return False
    return True


@by_value()
def derivative_matrix(harmonics: int) -> np.ndarray:
    """d/dtau on the coefficients: (2H+1, 2H+1), shared (do not write into it).

    ``D @ U`` are the coefficients of du/dtau: the pair (cos k tau,
    sin k tau) of harmonic k maps to (k sin, -k cos) coefficients.
    """
    D = np.zeros((2 * harmonics + 1, 2 * harmonics + 1))
    for k in range(1, harmonics + 1):
        D[2 * k - 1, 2 * k] = k
        D[2 * k, 2 * k - 1] = -k
    return D


def reconstruct(coefficients, harmonics: int, points: int = HB_FINE_SAMPLES) -> np.ndarray:
    """The signal at ``points`` uniform phases over one period.

    ``coefficients`` is (2H+1,) or (2H+1, m) (m signals); the result is
    (points,) or (points, m), in the coefficients' unit.
    """
    return fourier_matrices(harmonics, points)[0] @ coefficients


@jit
def _extrema(Ef, c):  # pragma: no cover - compiled
    """(max, min) of x = Ef c, each refined by the parabola through three samples."""
    # loops, not Ef @ c and np.argmax: code loaded from Numba's cache that
    # calls numpy's array functions imports Numba's numpy module, which
    # imports scipy.linalg (0.2-0.4 s of the CLI's start; see hb._aft._project)
    n = Ef.shape[0]
    x = np.zeros(n)
    hi_i = 0
    lo_i = 0
    for i in range(n):
        for k in range(c.size):
            x[i] += Ef[i, k] * c[k]
        if x[i] > x[hi_i]:
            hi_i = i
        if x[i] < x[lo_i]:
            lo_i = i
    out = np.empty(2)
    for k in range(2):
        i = hi_i if k == 0 else lo_i
        xm = x[(i - 1) % n]
        x0 = x[i]
        xp = x[(i + 1) % n]
        den = xm - 2.0 * x0 + xp
        pk = x0 if den == 0.0 else x0 - 0.125 * (xp - xm) ** 2 / den
        if k == 0:
            out[0] = x0 if pk < x0 else pk  # max(peak, grid max)
        else:
            out[1] = x0 if pk > x0 else pk  # min(peak, grid min)
    return out[0], out[1]


def extrema(coefficients, harmonics: int, points: int = HB_FINE_SAMPLES):
    """(max, min) of one signal over a period, in the coefficients' unit.

    Located on ``points`` uniform samples and refined by the vertex of the
    parabola through the three samples around each extremum (never inside
    the grid value). The vertex error is O(h^4) for a smooth extremum: with
    1024 samples per period about 1e-9 of the amplitude (the raw grid
    value is up to 5e-6 off).
    """
    c = np.ascontiguousarray(coefficients, dtype=np.float64)
    return _extrema(fourier_matrices(harmonics, points)[0], c)
