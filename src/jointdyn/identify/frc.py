"""Fit a modal Iwan model to stepped-sine response curves at several force levels.

The single nonlinear mode forced at F cos(Omega t) (docs/guide/identify.md),
one harmonic q = A cos(Omega t - phi): with K1(A) and E(A) the describing
function of the joint (:func:`jointdyn.identify.describing_function`),

    | k + K1(A) - m Omega^2 + i (E(A) / (pi A^2) + c Omega) | A = F,
    c = 2 zeta sqrt((k + kt) m),

which every measured point (F, Omega, A) must satisfy. The fit minimises the
relative equation error g = |Z| A / F - 1 divided by its slope in ln A (to
first order the relative error of the amplitude, which is what is measured
with noise) over k, kt, fy, zeta (chi, beta of Segalman's law): no response
has to be solved for, so folds and the jump of a stepped sine do not matter,
and all force levels are fitted at once.
Intervals and identifiability as for the other fits (profile likelihood).
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np

from .. import _validate as V
from .. import config
from ._lsq import FIT_BETA_START, open_reason, solve, start_values, status_of
from .backbone import BACKBONE_MODELS, _grid, _params, describing_function, modal_law
from .result import FitResult

__all__ = ["fit_frc", "FRC_COLUMNS"]

#: the amplitudes searched for the model's response: from the data's least / _GRID_SPAN to its
#: largest * _GRID_SPAN, _GRID_POINTS log-spaced, then _SECANT_STEPS secant steps on each root
_EPS = 1e-6
_MIN_SLOPE = 0.05
_GRID_SPAN = 3.0
_GRID_POINTS = 200
_SECANT_STEPS = 3

#: the columns of a response-curve file (``jointdyn fit --frc``)
FRC_COLUMNS = ("force_N", "omega_rad_s", "amplitude_m")


def _check(F, w, A, mass):
    out = []
    for name, v in zip(FRC_COLUMNS, (F, w, A)):
        a = np.asarray(v, dtype=np.float64)
        if a.ndim != 1 or not np.all(np.isfinite(a)):
            raise ValueError(f"{name} must be a 1-D array of finite numbers, got shape {a.shape}")
        if not np.all(a > 0.0):
            raise ValueError(f"{name} must be > 0 (allowed range (0, inf))")
        out.append(a)
    F, w, A = out
    if not (F.size == w.size == A.size):
        raise ValueError(f"force_N, omega_rad_s and amplitude_m must have one length, got {F.size}, {w.size}, "
                         f"{A.size}")
    if F.size < 6:
        raise ValueError(f"a response-curve fit needs at least 6 points, got {F.size}")
    return F, w, A, V.positive("mass", mass)


def _start(model, F, w, A, m):
    """Start values: k + kt from the peak of the lowest force level, zeta from its height,
    kt a third of the stuck stiffness, fy where the largest amplitude reaches macroslip."""
    low = F == F.min()
    i = int(np.argmax(np.where(low, A, -np.inf)))
    kstuck = m * w[i] ** 2
    zeta0 = max(0.5 * F[i] / (2.0 * kstuck * A[i]), 1e-6)
    kt0 = kstuck / 3.0
    s0 = {"k": kstuck - kt0, "kt": kt0, "fy": 0.5 * kt0 * float(A.max()), "zeta": zeta0}
    if model == "segalman":
        s0["chi"], s0["beta"] = config.SEGALMAN_CHI, FIT_BETA_START
    return s0


def response(ratio_of, A, grid):
    """The amplitude of the model's response nearest each measured one, m.

    ``ratio_of(a)`` is |Z(a)| a / F at every point, for one amplitude per point (a shape like
    ``A``) or a column of amplitudes for all of them (shape (g, 1) -> (g, n)); its roots of ratio - 1 in ln a are bracketed on ``grid`` (every point's curve at
    once), refined by secant steps on the model itself, and the root nearest the measured
    ``A`` in ln a is taken among the stable ones (a fold has two: the measurement says which
    branch it is on).
    A point whose curve has no root on the grid gets the grid's end nearest to it.
    """
    n = A.size
    h = np.log(ratio_of(grid[:, None]))
    lg = np.log(grid)
    # upward crossings only: where |Z| A falls as A rises (the middle root of a fold) the
    # response is unstable and never measured
    cross = (h[:-1] < 0.0) & (h[1:] >= 0.0)
    la = np.log(A)
    # each bracket's linear root, the one nearest the measured ln A per point
    with np.errstate(divide="ignore", invalid="ignore"):
        r = lg[:-1, None] - h[:-1] * (lg[1:, None] - lg[:-1, None]) / (h[1:] - h[:-1])
    dist = np.where(cross, np.abs(r - la), np.inf)
    j = np.argmin(dist, axis=0)
    cols = np.arange(n)
    found = np.isfinite(dist[j, cols])
    lo, hi = lg[j], lg[j + 1]
    x = np.where(found, r[j, cols], np.where(la < lg.mean(), lg[0], lg[-1]))
    # secant steps on the model within the bracket (the grid's linear root is off by its curvature)
    x0, f0 = lo, h[j, cols]
    for _ in range(_SECANT_STEPS):
        f = np.log(ratio_of(np.exp(x)))
        with np.errstate(divide="ignore", invalid="ignore"):
            step = np.where(f != f0, f * (x - x0) / (f - f0), 0.0)
        x0, f0 = x, f
        x = np.where(found, np.clip(x - step, lo, hi), x)
    return np.exp(x)


def fit_frc(force_N, omega_rad_s, amplitude_m, *, mass: float, model: str = config.MODEL,
            law_params: dict | None = None, start: dict | None = None) -> FitResult:
    """Fit a modal Iwan model to response curves (force, frequency, amplitude) of a stepped sine.

    Parameters
    ----------
    force_N : array_like
        Forcing amplitude of each point, N (several levels).
    omega_rad_s : array_like
        Forcing frequency, rad/s.
    amplitude_m : array_like
        Response amplitude (first harmonic), m.
    mass : float
        Modal mass, kg.
    model : str
        Joint law, one of :data:`jointdyn.identify.BACKBONE_MODELS`.
    law_params : dict, optional
        Law parameters held (``n`` of ``discrete``).
    start : dict, optional
        Start values by name (``k``, ``kt``, ``fy``, ``zeta``, ``chi``, ``beta``); least
        squares begins at the best of these, the data's and a grid (Segalman).

    Returns
    -------
    FitResult
        ``kind`` ``"frc"``; ``parameters`` k, kt (N/m), fy_N (N), zeta, and chi, beta for
        Segalman; ``intervals``; ``rms_residual`` of the relative amplitude error (first order).

    Raises
    ------
    ValueError
        Bad arrays or mass, an unknown model or parameter.
    """
    V.choice("model", model, BACKBONE_MODELS)
    F, w, A, m = _check(force_N, omega_rad_s, amplitude_m, mass)
    law_of = modal_law(model, law_params)
    s_data = _start(model, F, w, A, m)
    s0 = start_values(model, s_data, start)
    params = _params(s0)

    def ratio(v, law, a):
        # a: one amplitude per point, or a column (g, 1) of amplitudes for every point at once
        a = np.asarray(a, dtype=float)
        k1, en = (x.reshape(a.shape) for x in describing_function(law, a.ravel()))
        c = 2.0 * v["zeta"] * math.sqrt((v["k"] + v["kt"]) * m)
        return np.hypot(v["k"] + k1 - m * w * w, en / (math.pi * a * a) + c * w) * a / F

    def slope_at(v):
        # the slope of the equation error in ln A: dividing by it (held fixed, from the plain
        # fit) turns the equation error into, to first order, the relative amplitude error;
        # kept away from zero at a fold
        law = law_of(v)
        sl = (ratio(v, law, A * (1.0 + _EPS)) - ratio(v, law, A)) / math.log1p(_EPS)
        return np.where(sl >= 0.0, np.maximum(sl, _MIN_SLOPE), np.minimum(sl, -_MIN_SLOPE))

    kt_grid = [{**s_data, "kt": f * (s_data["k"] + s_data["kt"]), "k": (1.0 - f) * (s_data["k"] + s_data["kt"]),
                "fy": g * s_data["fy"]} for f in (0.1, 0.33, 0.6) for g in (0.25, 1.0, 4.0)]
    # the plain equation error first (smooth far from the optimum, no response to solve), then
    # divided by its slope in ln A (to first order the amplitude's error: it brings the plain
    # fit's start near), then the amplitude's own error: the model's response at each
    # (F, Omega), the stable root of |Z(A)| A = F nearest the measured amplitude, against the
    # measured one (ln A). The weighted equation error alone left zeta 5 % off at 1 % noise
    # (the noisy amplitude inside K1(A) and E(A)) and intervals that missed kt, fy and zeta.
    first = solve(lambda v: ratio(v, law_of(v), A) - 1.0, params, starts=[s_data] + kt_grid + _grid(s_data))
    near = [replace(p, value=first.values[p.name]) if (not p.positive or first.values[p.name] > 0.0) else p
            for p in params]
    slope = slope_at(first.values)
    mid = solve(lambda v: (ratio(v, law_of(v), A) - 1.0) / slope, near, starts=[s_data] + kt_grid)
    near = [replace(p, value=mid.values[p.name]) if (not p.positive or mid.values[p.name] > 0.0) else p
            for p in params]
    grid = np.geomspace(A.min() / _GRID_SPAN, A.max() * _GRID_SPAN, _GRID_POINTS)
    def amplitude_error(v):
        law = law_of(v)
        r = np.log(response(lambda a: ratio(v, law, a), A, grid) / A)
        # a model without a response inside the grid's span misses by the span
        return np.where(np.isfinite(r), r, math.log(_GRID_SPAN))

    # begun at the best, by the amplitude's error, of the weighted fit and the starts (the
    # equation errors have minima of their own that the amplitude's error does not share)
    sol = solve(amplitude_error, near, profile=True, starts=[s_data] + kt_grid)
    reasons = {k: "the response curves depend too weakly on it (its standard error exceeds the limit)"
               for k in sol.weak}
    for k in sol.open:
        reasons[k] = (reasons[k] + "; " if k in reasons else "") + open_reason(sol.intervals[k])
    status, message = status_of(sol, reasons)
    ren = {"fy": "fy_N"}
    values = {ren.get(k, k): (None if k in reasons else v) for k, v in sol.values.items()}
    errors = {ren.get(k, k): (None if k in reasons else v) for k, v in sol.errors.items()}
    r = sol.residual
    return FitResult(kind="frc", model=model, status=status, message=message, parameters=values,
                     standard_errors=errors, names=tuple(ren.get(p.name, p.name) for p in params),
                     correlation=sol.correlation, not_identifiable={ren.get(k, k): v for k, v in reasons.items()},
                     rms_residual=math.sqrt(float(np.mean(r * r))), law=law_of(sol.values),
                     measured={"force_N": F, "omega_rad_s": w, "amplitude_m": A},
                     fitted={"equation_error": r}, evaluations=sol.evaluations,
                     intervals={ren.get(k, k): v for k, v in sol.intervals.items()},
                     conditional_on=tuple(ren.get(k, k) for k in sol.weak))
