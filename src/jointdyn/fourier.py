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

import numpy as np

from . import config
from ._cache import by_value
from ._jit import jit

__all__ = ["phases", "basis", "fourier_matrices", "derivative_matrix", "reconstruct", "extrema"]


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


def reconstruct(coefficients, harmonics: int, points: int = config.HB_FINE_SAMPLES) -> np.ndarray:
    """The signal at ``points`` uniform phases over one period.

    ``coefficients`` is (2H+1,) or (2H+1, m) (m signals); the result is
    (points,) or (points, m), in the coefficients' unit.
    """
    return fourier_matrices(harmonics, points)[0] @ coefficients


@jit
def _extrema(Ef, c):  # pragma: no cover - compiled
    """(max, min) of x = Ef c, each refined by the parabola through three samples."""
    x = Ef @ c
    n = x.size
    hi_i = np.argmax(x)
    lo_i = np.argmin(x)
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


def extrema(coefficients, harmonics: int, points: int = config.HB_FINE_SAMPLES):
    """(max, min) of one signal over a period, in the coefficients' unit.

    Located on ``points`` uniform samples and refined by the vertex of the
    parabola through the three samples around each extremum (never inside
    the grid value). The vertex error is O(h^4) for a smooth extremum: with
    1024 samples per period about 1e-9 of the amplitude (the raw grid
    value is up to 5e-6 off).
    """
    c = np.ascontiguousarray(coefficients, dtype=np.float64)
    return _extrema(fourier_matrices(harmonics, points)[0], c)
