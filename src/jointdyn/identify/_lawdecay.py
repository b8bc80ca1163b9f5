"""The free decay of the modal model with the whole joint law: a ring-down through macroslip.

A decay that starts in macroslip is not of the microslip form that :mod:`._microslip`
fits (its power law ends at the slip displacement). The energy balance behind that form
holds for any joint of Jenkins elements in parallel (Iwan, Segalman, discrete): the energy
dissipated per period, E(A), is taken from what is stored at a turning point, whose slope in
A is A (k + F'(A)) (the stuck elements' springs; a slipped element keeps its slip force, so
it adds nothing), F the virgin curve of the law. With EPMC's damping ratio D and the
first-harmonic stiffness K1 of the describing function (:func:`.backbone.describing_function`),

    -d ln A / dt = omega D (k + K1) / (k + F'(A)),   omega^2 = (k + K1) / m,
    omega D (k + K1) = E omega / (2 pi A^2) + zeta omega_0 m omega^2,

in macroslip too (F' = 0 there for Iwan's law), so k, kt, fy, zeta (chi and beta of
Segalman's law) are fitted to the ring-down's windows (ln A and frequency, each weighted by
its measured noise), ln A(t) by quadrature over ln A as in :func:`._microslip.decay_model`.
"""

from __future__ import annotations

import math

import numpy as np

from ._lsq import solve
from ._microslip import DECAY_GRID

__all__ = ["law_rates", "law_decay_steps", "law_decay_fit", "law_decay_residual"]

#: relative step of the central difference of the virgin curve's tangent F'(A) (-)
TANGENT_STEP = 1e-6
#: the period-averaged decay's relative error of a fall of ln A, per delta^2 (delta the fall per
#: period): the largest of 1.2 to 2.1 measured (:func:`law_decay_fit`) (-)
AVERAGING_ERROR = 2.0


def law_rates(law, k: float, zeta: float, m: float, A: np.ndarray) -> tuple:
    """(omega rad/s, EPMC's damping ratio, -d ln A / dt 1/s) of the modal model with the joint
    ``law`` at the amplitudes ``A`` (m): module docstring."""
    from .backbone import _virgin_curve, describing_function

    k1, en = describing_function(law, A)
    w2 = np.maximum((k + k1) / m, 1e-12 * (k + law.kt) / m)
    w = np.sqrt(w2)
    w0 = math.sqrt((k + law.kt) / m)
    D = en / (2.0 * math.pi * m * w2 * A * A) + zeta * w0 / w
    F, _ = _virgin_curve(law)
    h = TANGENT_STEP * A
    tangent = (F(A + h) - F(np.maximum(A - h, 0.0))) / (2.0 * h)
    rate = w * D * m * w2 / np.maximum(k + tangent, 1e-12 * (k + law.kt))
    return w, D, rate


def law_decay_steps(law, k: float, zeta: float, m: float, win: dict) -> tuple:
    """(the fall of ln A from each window to the next, omega rad/s at each window) of the modal
    model (``law``, k N/m, zeta, m kg), each fall started from the window's measured ln A:
    the time to each level of ln A by quadrature (:func:`._microslip.decay_times`) on one grid
    over the windows' range, read at t_i and t_i + (t_i+1 - t_i)."""
    lna, t = win["lna"], win["t"]
    top, bottom = float(np.max(lna)), float(np.min(lna))
    lev = np.linspace(top + 0.05, bottom - 0.5, DECAY_GRID)
    w, _, rate = law_rates(law, k, zeta, m, np.exp(lev))
    inv = 1.0 / np.maximum(rate, 1e-300)
    tl = np.concatenate(([0.0], np.cumsum(0.5 * (inv[1:] + inv[:-1]) * (lev[:-1] - lev[1:]))))
    start = np.interp(-lna[:-1], -lev, tl)
    # past the grid's end at the last rate
    end = start + np.diff(t)
    fall = np.where(end <= tl[-1], np.interp(end, tl, lev), lev[-1] - (end - tl[-1]) / inv[-1]) - lna[:-1]
    return fall, np.interp(-lna, -lev, w)


def law_decay_fit(win: dict, m: float, law_of, params: list):
    """Least squares of :func:`law_decay_steps` to a ring-down's windows ``win`` (``t``, ``lna``,
    ``omega`` and their standard errors ``sigma_lna``, ``sigma_omega``) over ``params`` (k, kt,
    fy, zeta, and chi, beta where fitted; ``law_of`` makes the law of a dict of values), with
    profile-likelihood intervals: the Solution.

    Each fall of ln A between consecutive windows is fitted from the measured start, not ln A(t)
    from one release: the decay is averaged over each period, which holds to second order in
    the fall per period delta (measured on noise-free Iwan decays from 10 slip displacements:
    the local rate off by 0.14, 0.5, 1.7, 3 and 6 % at delta = 0.034, 0.06, 0.09, 0.145 and
    0.19, 1.2 to 2.1 delta^2), and integrated from the release the error of the fast macroslip
    part shifts every later window in time (zeta came out 9 % high, noise-free). The falls'
    noise is correlated (each window's error enters two falls) and each carries that model
    error, ``AVERAGING_ERROR`` delta^2 of itself: the residual is whitened by the Cholesky
    factor of that covariance."""
    return solve(law_decay_residual(win, m, law_of), params, profile=True)


def law_decay_residual(win: dict, m: float, law_of):
    """The whitened residual of :func:`law_decay_fit` as a function of a dict of values (the
    falls of ln A through the Cholesky factor of their covariance, the frequencies over their
    standard errors): unit variance where the windows' measured noise is right."""
    lna, om = win["lna"], win["omega"]
    sl, so = win["sigma_lna"], win["sigma_omega"]
    fall_meas = np.diff(lna)
    delta = -fall_meas / np.diff(win["t"]) * 2.0 * math.pi / (0.5 * (om[:-1] + om[1:]))
    cov = np.diag(sl[:-1] ** 2 + sl[1:] ** 2 + (AVERAGING_ERROR * delta * delta * fall_meas) ** 2)
    off = -sl[1:-1] ** 2
    cov += np.diag(off, 1) + np.diag(off, -1)
    from scipy.linalg import cholesky, solve_triangular

    chol = cholesky(cov, lower=True)

    def fun(v):
        fall, wf = law_decay_steps(law_of(v), v["k"], v["zeta"], m, win)
        return np.concatenate((solve_triangular(chol, fall - fall_meas, lower=True), (wf - om) / so))

    return fun
