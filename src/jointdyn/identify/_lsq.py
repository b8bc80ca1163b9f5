"""Least squares shared by the fits: scaled parameters, bounds, standard errors, identifiability."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .. import config
from .result import FitStatus, correlation, covariance

__all__ = ["Param", "solve", "Solution"]


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
    """Values (by name), standard errors (by name), correlation, the residual at the
    optimum, the names whose errors say the data do not determine them, the evaluations
    and whether least squares converged."""

    values: dict
    errors: dict
    correlation: np.ndarray
    residual: np.ndarray
    weak: tuple
    evaluations: int
    converged: bool


def solve(fun, params: list, *, diff_step=None) -> Solution:
    """Minimise ``sum(fun(values)^2)`` over the parameters (``fun`` takes a dict of
    values by name and returns the residual vector) with scipy's trust-region
    least squares within the bounds; then the standard errors from the Jacobian at the
    optimum and the residual variance. A parameter whose error exceeds
    ``config.FIT_MAX_RELATIVE_SE`` of its value (scales) or ``config.FIT_MAX_SHAPE_SE``
    (shapes) is *weak*: the errors of the others are then those with it held."""
    from scipy.optimize import least_squares

    def values(u):
        return {p.name: float(p.from_unit(float(ui))) for p, ui in zip(params, u)}

    def resid(u):
        return fun(values(u))

    u0 = np.array([p.to_unit(p.value) for p in params])
    lb = np.array([p.to_unit(p.low) for p in params])
    ub = np.array([p.to_unit(p.high) for p in params])
    u0 = np.clip(u0, lb, ub)
    res = least_squares(resid, u0, bounds=(lb, ub), method="trf", x_scale=1.0, ftol=config.FIT_FTOL,
                        xtol=config.FIT_XTOL, gtol=config.FIT_GTOL, max_nfev=config.FIT_MAX_NFEV,
                        diff_step=diff_step)
    u = res.x
    jac = np.asarray(res.jac, dtype=float)
    keep = np.ones(len(params), bool)
    weak = []
    for _ in range(len(params)):
        cov = covariance(jac, res.fun, keep)
        se = np.sqrt(np.abs(np.diag(cov)))
        worst, excess = None, 1.0
        for i, p in enumerate(params):
            if not keep[i]:
                continue
            lim = config.FIT_MAX_RELATIVE_SE * abs(u[i]) if p.positive else config.FIT_MAX_SHAPE_SE
            ratio = se[i] / lim if lim > 0.0 else np.inf
            if not np.isfinite(se[i]) or ratio > excess:
                worst, excess = i, (np.inf if not np.isfinite(se[i]) else ratio)
        if worst is None:
            break
        keep[worst] = False
        weak.append(params[worst].name)
    cov = covariance(jac, res.fun, keep)
    se_u = np.sqrt(np.abs(np.diag(cov)))
    vals = values(u)
    errors = {p.name: (float(se_u[i] * p.value) if p.positive else float(se_u[i])) if keep[i] else None
              for i, p in enumerate(params)}
    return Solution(values=vals, errors=errors, correlation=correlation(cov), residual=res.fun, weak=tuple(weak),
                    evaluations=int(res.nfev), converged=bool(res.status > 0))


def status_of(sol: Solution, reasons: dict) -> tuple:
    """``(FitStatus, message)`` of a solution and the reasons of its weak parameters."""
    if not sol.converged:
        return FitStatus.NOT_CONVERGED, FitStatus.NOT_CONVERGED.message
    if reasons:
        return FitStatus.PARTLY_IDENTIFIED, "; ".join(f"{k} not identifiable: {v}" for k, v in reasons.items())
    return FitStatus.IDENTIFIED, FitStatus.IDENTIFIED.message
