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

in macroslip too (F' = 0 there for Iwan's law); :func:`law_rates` gives that rate, the
frequency and the damping ratio of the fitted model. That balance is an average over a
period: through macroslip, where ln A falls by up to 0.2 a period and the fall per period
peaks and bends (near 1.4 slip displacements of Iwan's law), it and the taking of a window's
amplitude as the envelope at its centre put the falls from window to window up to 0.0056 off
those of a simulated decay (noise-free, from 5 slip displacements; at 1.3 to 2 slip
displacements, 1.5 % of the fall). So the model the windows are fitted with
(:func:`law_decay_steps`) is not averaged: the turning points of the free decay come from the
exact work balance of each half-cycle of the Masing law (:func:`law_turning_points`), and the
amplitude each window would measure of them from the window's own estimator
(:func:`window_levels`); k, kt, fy, zeta (chi and beta of Segalman's law) are fitted to the
ring-down's windows (the falls of ln A between them and their frequencies, each weighted by
its measured noise) with it (:func:`law_decay_fit`).
"""

from __future__ import annotations

import math

import numpy as np

from ._lsq import solve

__all__ = ["law_rates", "law_turning_points", "window_levels", "law_decay_steps", "law_decay_fit", "law_decay_residual"]

#: relative step of the central difference of the virgin curve's tangent F'(A) (-)
TANGENT_STEP = 1e-6
#: points of the table of the virgin curve's integral G in :func:`law_turning_points` (-)
G_GRID = 4097
#: most half-cycles of :func:`law_turning_points` (-)
TURNING_POINTS = 4000
#: samples of a window of two cycles in :func:`window_levels` (-)
WINDOW_SAMPLES = 128
#: ln A of turning points computed beyond the windows' top and bottom, so that every window
#: (two cycles: a fall of ln A of up to about 0.4 through macroslip) lies within them (-)
LEAD = 0.8


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


def law_turning_points(law, k: float, zeta: float, m: float, top: float, bottom: float) -> tuple:
    """(times s, ln A) of the turning points of the modal model's free decay (``law``, k N/m,
    zeta, m kg) from ln A = ``top`` down to ``bottom`` (or ``TURNING_POINTS`` half-cycles), by the
    exact work balance of each half-cycle of a Masing law rather than its average over a period.

    From a turning point at +A1, where the joint's force is f1, the branch down to -A2 is
    f1 - 2 F((A1 - u) / 2) (F the virgin curve), so with S = (A1 + A2) / 2 and G the integral
    of F from 0, the kinetic energy being zero at both ends,

        k (A2^2 - A1^2) / 2 = 2 f1 S - 4 G(S) - pi zeta omega_0 m omega A1 A2,

    (the viscous work of the half-cycle at omega(S) of the describing function), solved for A2
    by safeguarded Newton; the force at -A2 is 2 F(S) - f1 (in magnitude), and the half-cycle
    lasts pi / omega(S). The joint's residual force shifts the oscillation's centre, so A1 and
    A2 (distances from the spring's zero) alternate about the amplitude: the points returned
    are the half travels S at the middle of each half-cycle. The first point's force is that of
    a decay arriving from A1 exp(d) (d the averaged fall of ln A per half-cycle there:
    :func:`law_rates`).
    """
    from .backbone import _virgin_curve

    F, _ = _virgin_curve(law)
    a_top = math.exp(top)
    # G on a geometric grid from far below the bottom, each value refined by the trapezoid of its
    # own cell (F exact at S): relative cell width ~ 1e-3, so G is exact to ~1e-7 of itself
    lu = np.linspace(bottom - 8.0, top + 0.5, G_GRID)
    u = np.exp(lu)
    Fu = F(u)
    Gu = np.concatenate(([0.5 * u[0] * Fu[0]], np.diff(u) * 0.5 * (Fu[1:] + Fu[:-1]))).cumsum()
    dl = lu[1] - lu[0]

    def G(s, fs):
        if s <= u[0]:
            return 0.5 * s * fs
        i = min(int((math.log(s) - lu[0]) / dl), G_GRID - 2)
        return Gu[i] + 0.5 * (s - u[i]) * (Fu[i] + fs)

    lev = np.linspace(top + 0.1, bottom - 0.6, 200)
    wl, _, rl = law_rates(law, k, zeta, m, np.exp(lev))
    w0 = math.sqrt((k + law.kt) / m)
    cv = math.pi * zeta * w0 * m

    def omega(s):
        return float(np.interp(-math.log(max(s, 1e-300)), -lev, wl))

    a1 = a_top
    d = float(np.interp(-top, -lev, rl)) * math.pi / omega(a1)
    a_prev = a1 * math.exp(d)
    f1 = 2.0 * float(F(0.5 * (a_prev + a1))) - float(F(a_prev))
    times, lnas = [], []
    t = 0.0
    for _ in range(TURNING_POINTS):
        # the joint's residual force shifts the oscillation's centre, so the distance of the
        # next turning point from the spring's zero may exceed this one's
        lo, hi = 0.0, 2.0 * a1
        a2 = a1 * math.exp(-d)
        for _ in range(60):
            s = 0.5 * (a1 + a2)
            fs = float(F(s))
            w = omega(s)
            h = 0.5 * k * (a2 * a2 - a1 * a1) - 2.0 * f1 * s + 4.0 * G(s, fs) + cv * w * a1 * a2
            if h > 0.0:
                hi = a2
            else:
                lo = a2
            dh = k * a2 - f1 + 2.0 * fs + cv * w * a1
            step = h / dh if dh > 0.0 else math.inf
            a_new = a2 - step
            if not lo < a_new < hi:
                a_new = 0.5 * (lo + hi)
            if abs(a_new - a2) <= 1e-13 * a1:
                a2 = a_new
                break
            a2 = a_new
        s = 0.5 * (a1 + a2)
        f1 = 2.0 * float(F(s)) - f1
        half = math.pi / omega(s)
        # the amplitude about the centre: half the travel, at the half-cycle's middle
        times.append(t + 0.5 * half)
        lnas.append(math.log(s))
        if len(lnas) > 1:
            d = max(lnas[-2] - lnas[-1], 1e-12)
        t += half
        a1 = a2
        if lnas[-1] < bottom - 0.5:
            break
    lnas = np.minimum.accumulate(np.array(lnas) - 1e-15 * np.arange(len(lnas)))
    return np.array(times), np.array(lnas)


def window_levels(tl, lev, centres, omega) -> np.ndarray:
    """ln of the amplitude that a ring-down's window of two whole cycles centred at each of
    ``centres`` (s), at ``omega`` (rad/s), measures of a decay whose ln A runs through the
    turning points (``tl`` s, ``lev``) linearly in t: the estimator of
    :func:`.ringdown._local_decay` (A exp(r tau) cos(omega tau + phi), r iterated) applied to
    that envelope times the window's sine, ``WINDOW_SAMPLES`` samples. Where ln A bends within
    a window (the rate of a decay through macroslip peaks near 1.4 slip displacements) the
    window's amplitude is not the envelope's at its centre."""
    u = (np.arange(WINDOW_SAMPLES) + 0.5) / WINDOW_SAMPLES * 2.0 - 1.0  # tau in periods
    X = np.column_stack([np.cos(2.0 * math.pi * u), np.sin(2.0 * math.pi * u), u * np.cos(2.0 * math.pi * u),
                         u * np.sin(2.0 * math.pi * u)])
    pinv = np.linalg.pinv(X)
    centres = np.asarray(centres, float)
    tau = np.outer(2.0 * math.pi / np.asarray(omega, float), u)
    last = (lev[-2] - lev[-1]) / (tl[-1] - tl[-2])
    tt = centres[:, None] + tau
    ln_env = np.where(tt <= tl[-1], np.interp(tt, tl, lev), lev[-1] - (tt - tl[-1]) * last)
    at = np.where(centres <= tl[-1], np.interp(centres, tl, lev), lev[-1] - (centres - tl[-1]) * last)
    y = np.exp(ln_env - at[:, None]) * X[:, 1]
    r = np.zeros(centres.size)
    for _ in range(3):
        coef = (y * np.exp(-r[:, None] * u)) @ pinv.T
        a2 = coef[:, 0] ** 2 + coef[:, 1] ** 2
        r += (coef[:, 0] * coef[:, 2] + coef[:, 1] * coef[:, 3]) / a2
    return at + 0.5 * np.log(a2)


def law_decay_steps(law, k: float, zeta: float, m: float, win: dict) -> tuple:
    """(the fall of ln A from each window to the next, omega rad/s at each window) of the modal
    model (``law``, k N/m, zeta, m kg), each fall started from the window's measured ln A:
    ln A(t) through the turning points of :func:`law_turning_points` from above the windows'
    top down past their bottom, each window's amplitude as the window measures it
    (:func:`window_levels`), placed where that equals the window's ln A and read a window
    spacing later."""
    lna, t, om = win["lna"], win["t"], win["omega"]
    top, bottom = float(np.max(lna)), float(np.min(lna))
    tl, lev = law_turning_points(law, k, zeta, m, top + LEAD, bottom - LEAD)
    start = np.interp(-lna[:-1], -lev, tl)
    bias = window_levels(tl, lev, start, om[:-1]) - np.interp(start, tl, lev)
    start = np.interp(-(lna[:-1] - bias), -lev, tl)
    fall = window_levels(tl, lev, start + np.diff(t), om[1:]) - window_levels(tl, lev, start, om[:-1])
    return fall, law_rates(law, k, zeta, m, np.exp(lna))[0]


def law_decay_fit(win: dict, m: float, law_of, params: list):
    """Least squares of :func:`law_decay_steps` to a ring-down's windows ``win`` (``t``, ``lna``,
    ``omega`` and their standard errors ``sigma_lna``, ``sigma_omega``) over ``params`` (k, kt,
    fy, zeta, and chi, beta where fitted; ``law_of`` makes the law of a dict of values), with
    profile-likelihood intervals: the Solution.

    Each fall of ln A between consecutive windows is fitted from the measured start, not ln A(t)
    from one release (so an error of the model at the fast top does not shift the time of every
    later window). On a noise-free simulated decay from 5 slip displacements the falls of
    :func:`law_decay_steps` with the true parameters matched the windows' within 0.0004 (from
    10: 0.0004), but the first, 0.002 to 0.003 (the band-pass filter's start); the period-averaged
    model missed them by up to 0.0056 (from 10: 0.0051). The falls' noise is the windows'
    measured noise, correlated (each window's error enters two falls): the residual is whitened
    by the Cholesky factor of that covariance. The profile intervals take that noise as a floor
    (``noise_known``): over 40 noise seeds of the decay from 5 slip displacements the weighted
    residual came out below 1 (rms 0.47 to 0.69 in seeds 7, 8 and 19), and intervals scaled
    down by it held the truth of kt in 34 of 40 (seed 7: kt determined 3.6 % low, fy 4.5 %)."""
    return solve(law_decay_residual(win, m, law_of), params, profile=True, noise_known=True)


def law_decay_residual(win: dict, m: float, law_of):
    """The whitened residual of :func:`law_decay_fit` as a function of a dict of values (the
    falls of ln A through the Cholesky factor of their covariance, the frequencies over their
    standard errors): unit variance where the windows' measured noise is right."""
    lna, om = win["lna"], win["omega"]
    sl, so = win["sigma_lna"], win["sigma_omega"]
    fall_meas = np.diff(lna)
    cov = np.diag(sl[:-1] ** 2 + sl[1:] ** 2)
    off = -sl[1:-1] ** 2
    cov += np.diag(off, 1) + np.diag(off, -1)
    from scipy.linalg import cholesky, solve_triangular

    chol = cholesky(cov, lower=True)

    def fun(v):
        fall, wf = law_decay_steps(law_of(v), v["k"], v["zeta"], m, win)
        return np.concatenate((solve_triangular(chol, fall - fall_meas, lower=True), (wf - om) / so))

    return fun
