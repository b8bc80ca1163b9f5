"""Least squares shared by the fits: scaled parameters, bounds, standard errors, identifiability."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ._profile import FIT_LEVEL
from .result import FitStatus, correlation, covariance

__all__ = ["Param", "solve", "Solution"]

#: most evaluations of the model (marches, describing functions) of one least-squares fit
FIT_MAX_NFEV = 400
#: tolerances of scipy.optimize.least_squares on the cost, the parameters and the gradient
#: (relative); FIT_XTOL x 1e-4 is also the singular-value ratio at or below which the
#: covariance treats a direction as unseen by the data
FIT_FTOL = 1e-12
FIT_XTOL = 1e-10
FIT_GTOL = 1e-12
#: a stiffness, force or friction coefficient whose standard error exceeds this fraction
#: of its value is reported as not identifiable (-)
FIT_MAX_RELATIVE_SE = 0.5
#: a shape parameter (chi, beta) whose standard error exceeds this is reported as not identifiable (-)
FIT_MAX_SHAPE_SE = 0.5
#: largest beta of a Segalman fit (-; the law's own range is unbounded)
FIT_BETA_MAX = 100.0
#: start of beta in a Segalman fit (-)
FIT_BETA_START = 0.1
#: global start of a Segalman fit (loops, backbones, response curves): the grid of chi, beta
#: and slip-force factors (times the data's start value) whose best point (least sum of
#: squares) starts least squares (-)
FIT_GRID_CHI = (-0.8, -0.5, 0.0, 0.5)
FIT_GRID_BETA = (0.0, 0.1, 1.0, 10.0, 50.0)
FIT_GRID_SLIP = (0.7, 1.0, 1.4)


@dataclass(frozen=True)
class Param:
    """A fitted parameter: ``name``, start ``value``, whether it is a positive scale
    (fitted as value / start, relative errors) or a shape number (fitted as is, absolute
    errors), and its bounds (in its own units)."""

    name: str
    value: float
    positive: bool
    low: float
    high: float

    def to_unit(self, v):
        return v / self.value if self.positive else v

    def from_unit(self, u):
        return u * self.value if self.positive else u


@dataclass(frozen=True)
class Solution:
    """Values (by name), standard errors (by name; those of the parameters not weak, with
    the weak ones held), correlation, the residual at the optimum, the names whose
    linearised errors say the data do not determine them (``weak``), the evaluations,
    whether least squares converged, and, when profiled, the profile intervals by name
    (:class:`._profile.Interval`) and the names whose interval is open (``open``)."""

    values: dict
    errors: dict
    correlation: np.ndarray
    residual: np.ndarray
    weak: tuple
    evaluations: int
    converged: bool
    intervals: dict = None
    open: tuple = ()


def _least_squares(resid, u0, lb, ub, diff_step):
    from scipy.optimize import least_squares

    return least_squares(resid, np.clip(u0, lb, ub), bounds=(lb, ub), method="trf", x_scale=1.0,
                         ftol=FIT_FTOL, xtol=FIT_XTOL, gtol=FIT_GTOL,
                         max_nfev=FIT_MAX_NFEV, diff_step=diff_step)


def _weak(params, u, jac, fun):
    """Mask of the parameters kept (not weak) and the weak names, dropping the worst first."""
    keep = np.ones(len(params), bool)
    weak = []
    for _ in range(len(params)):
        cov = covariance(jac, fun, keep, FIT_XTOL)
        se = np.sqrt(np.abs(np.diag(cov)))
        worst, excess = None, 1.0
        for i, p in enumerate(params):
            if not keep[i]:
                continue
            lim = FIT_MAX_RELATIVE_SE * abs(u[i]) if p.positive else FIT_MAX_SHAPE_SE
            ratio = se[i] / lim if lim > 0.0 else np.inf
            if not np.isfinite(se[i]) or ratio > excess:
                worst, excess = i, (np.inf if not np.isfinite(se[i]) else ratio)
        if worst is None:
            break
        keep[worst] = False
        weak.append(params[worst].name)
    return keep, weak


def solve(fun, params: list, *, diff_step=None, profile: bool = False, level: float = FIT_LEVEL,
          starts=(), noise_known: bool = False) -> Solution:
    """Minimise ``sum(fun(values)^2)`` over the parameters (``fun`` takes a dict of
    values by name and returns the residual vector) with scipy's trust-region
    least squares within the bounds; then the standard errors from the Jacobian at the
    optimum and the residual variance. A parameter whose error exceeds
    ``FIT_MAX_RELATIVE_SE`` of its value (scales) or ``FIT_MAX_SHAPE_SE``
    (shapes) is *weak*: the errors of the others are then those with it held.

    ``profile``: also the profile-likelihood interval of every parameter at ``level``
    (:mod:`._profile`); a lower sum of squares met on a profile (the optimiser stopped in
    a local minimum) restarts least squares from there, once. ``starts``: further start
    points (dicts of values by name, the others from ``params``); least squares begins at
    the one of lowest sum of squares. ``noise_known``: ``fun`` is whitened by a measured noise,
    so the profile intervals take the residual variance as at least 1 (:func:`._profile.profile_intervals`)."""
    from ._profile import Interval, profile_intervals

    def values(u):
        return {p.name: float(p.from_unit(float(ui))) for p, ui in zip(params, u)}

    def resid(u):
        return fun(values(u))

    u0 = np.array([p.to_unit(p.value) for p in params])
    lb = np.array([p.to_unit(p.low) for p in params])
    ub = np.array([p.to_unit(p.high) for p in params])
    if starts:
        cands = [u0] + [np.array([p.to_unit(s.get(p.name, p.value)) for p in params]) for s in starts]
        cost = [float(np.sum(resid(np.clip(c, lb, ub)) ** 2)) for c in cands]
        u0 = cands[int(np.nanargmin(cost))]
    res = _least_squares(resid, u0, lb, ub, diff_step)
    nfev = int(res.nfev)
    for attempt in range(2 if profile else 0):
        cov0 = covariance(np.asarray(res.jac, float), res.fun, np.ones(len(params), bool), FIT_XTOL)
        se_u = np.sqrt(np.abs(np.diag(cov0)))
        bounds, best = profile_intervals(resid, params, res.x, se_u, res.fun.size, level, noise_known)
        ssr0 = float(res.fun @ res.fun)
        if attempt == 0 and best[0] < ssr0 * (1.0 - 1e-6):
            res = _least_squares(resid, best[1], lb, ub, diff_step)
            nfev += int(res.nfev)
            continue
        break
    u = res.x
    jac = np.asarray(res.jac, dtype=float)
    keep, weak = _weak(params, u, jac, res.fun)
    cov = covariance(jac, res.fun, keep, FIT_XTOL)
    se_u = np.sqrt(np.abs(np.diag(cov)))
    vals = values(u)
    errors = {p.name: (float(se_u[i] * p.value) if p.positive else float(se_u[i])) if keep[i] else None
              for i, p in enumerate(params)}
    intervals, opened = None, ()
    if profile:
        intervals = {p.name: Interval(None if lo is None else float(p.from_unit(lo)),
                                      None if hi is None else float(p.from_unit(hi)), level)
                     for p, (lo, hi) in zip(params, bounds)}
        opened = tuple(k for k, v in intervals.items() if not v.closed)
    return Solution(values=vals, errors=errors, correlation=correlation(cov), residual=res.fun, weak=tuple(weak),
                    evaluations=nfev, converged=bool(res.status > 0), intervals=intervals, open=opened)


def open_reason(interval) -> str:
    """Why a parameter with an open profile interval is not determined, in words."""
    pct = f"{100 * interval.level:.3g} %"
    if interval.low is None and interval.high is None:
        return f"the data bound it on neither side ({pct} profile likelihood)"
    if interval.low is None:
        return f"the data bound it only from above, <= {interval.high:.4g} ({pct} profile likelihood)"
    return f"the data bound it only from below, >= {interval.low:.4g} ({pct} profile likelihood)"


def status_of(sol: Solution, reasons: dict) -> tuple:
    """``(FitStatus, message)`` of a solution and the reasons of its weak parameters."""
    if not sol.converged:
        return FitStatus.NOT_CONVERGED, FitStatus.NOT_CONVERGED.message
    if reasons:
        return FitStatus.PARTLY_IDENTIFIED, "; ".join(f"{k} not identifiable: {v}" for k, v in reasons.items())
    return FitStatus.IDENTIFIED, FitStatus.IDENTIFIED.message


def start_values(model: str, s_data: dict, start) -> dict:
    """The data's start values ``s_data`` of a fit of ``model``, with those of ``start`` (a
    mapping of fitted parameter names to values) put in their place.

    Raises
    ------
    ValueError
        ``start`` names a parameter that ``model`` does not fit.
    """
    s0 = dict(s_data)
    for k, v in (start or {}).items():
        if k not in s0:
            raise ValueError(f"start has {k!r}, which model {model} does not fit (it fits {', '.join(s0)})")
        s0[k] = float(v)
    return s0
