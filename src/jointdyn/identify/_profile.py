"""Profile-likelihood intervals of a least-squares fit.

The linearised standard error assumes the model is close to linear in its
parameters over the interval it reports. That fails where a parameter's
effect begins at the edge of the data (a slip force the loops just reach), at
a kink of the model inside the data, or along directions the data do not see
at all. The profile does not assume it: each parameter is held on a sequence
of values on either side of the optimum, the others refitted each time, and
the interval is where the refitted sum of squares S stays below

    S_min (1 + F_{1, m-p}(level) / (m - p)),

i.e. S_min plus the F quantile (the chi-square quantile for many residuals)
times the residual variance s^2 = S_min / (m - p). A side on which S never
rises that far before the parameter's range (or a factor
``FIT_PROFILE_SPAN``) is open: the data bound the parameter on one
side only, or not at all, and it is reported as not determined.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

__all__ = ["Interval", "profile_intervals", "FIT_LEVEL"]

#: confidence level of the intervals a fit reports (profile likelihood) (-)
FIT_LEVEL = 0.95
#: a scale parameter whose sum of squares stays below the threshold over this factor (-) on
#: one side of its optimum is not bounded on that side; the steps (doubling) taken on a side
#: before it is called open; regula-falsi steps on the crossing
FIT_PROFILE_SPAN = 100.0
FIT_PROFILE_STEPS = 12
FIT_PROFILE_REFINE = 4
#: tolerances of scipy.optimize.least_squares (on the cost, the parameters and the gradient,
#: relative) and its evaluation limit for each refit with one parameter held
FIT_PROFILE_FTOL = 1e-10
FIT_PROFILE_MAX_NFEV = 60


@dataclass(frozen=True)
class Interval:
    """A profile interval of one parameter: ``low``, ``high`` (None: open on that side,
    the data do not bound it there) at the confidence ``level``."""

    low: float | None
    high: float | None
    level: float

    @property
    def closed(self) -> bool:
        """True when the data bound the parameter on both sides."""
        return self.low is not None and self.high is not None

    def covers(self, value: float) -> bool:
        """Whether ``value`` lies inside (an open side covers everything beyond)."""
        return (self.low is None or self.low <= value) and (self.high is None or value <= self.high)

    def to_dict(self) -> dict:
        """JSON-ready: ``low``, ``high`` (None where open), ``level``, ``method``."""
        return {"low": self.low, "high": self.high, "level": self.level, "method": "profile likelihood"}


def threshold(ssr: float, m: int, p: int, level: float) -> float:
    """The rise of the sum of squares that bounds a ``level`` profile interval."""
    from scipy.stats import f

    dof = max(m - p, 1)
    return ssr * float(f.ppf(level, 1, dof)) / dof


class _Profiler:
    """Refits with one parameter held, in the unit coordinates of :mod:`._lsq` (scales as
    value / start, shapes as is); the stepping coordinate is log(unit) for scales."""

    def __init__(self, resid, params, u_opt, ssr0, rise):
        self.resid, self.params, self.u_opt = resid, params, np.asarray(u_opt, float)
        self.ssr0, self.rise = ssr0, rise
        self.lb = np.array([p.to_unit(p.low) for p in params])
        self.ub = np.array([p.to_unit(p.high) for p in params])
        self.best = (ssr0, self.u_opt.copy())

    def coord(self, i, u):
        return math.log(max(u, 1e-300)) if self.params[i].positive else u

    def unit(self, i, c):
        return math.exp(c) if self.params[i].positive else c

    def refit(self, i, ui, warm):
        """Sum of squares with parameter i held at unit value ui (others refitted) and the
        full unit vector of the refit."""
        from scipy.optimize import least_squares

        free = np.arange(self.u_opt.size) != i
        u = warm.copy()
        u[i] = ui
        if np.any(free):
            def r(v):
                u[free] = v
                return self.resid(u)

            x0 = np.clip(warm[free], self.lb[free], self.ub[free])
            res = least_squares(r, x0, bounds=(self.lb[free], self.ub[free]), method="trf",
                                ftol=FIT_PROFILE_FTOL, xtol=FIT_PROFILE_FTOL,
                                gtol=FIT_PROFILE_FTOL, max_nfev=FIT_PROFILE_MAX_NFEV)
            u[free] = res.x
            ssr = float(res.fun @ res.fun)
        else:
            r0 = self.resid(u)
            ssr = float(r0 @ r0)
        if ssr < self.best[0]:
            self.best = (ssr, u.copy())
        return ssr, u

    def side(self, i, direction, step):
        """The unit value where the profile crosses the threshold on one side, or None."""
        c0 = self.coord(i, self.u_opt[i])
        lim_u = self.ub[i] if direction > 0 else self.lb[i]
        if self.params[i].positive:
            span = math.log(FIT_PROFILE_SPAN)
            lim = c0 + direction * span if lim_u <= 0.0 else (
                min(self.coord(i, lim_u), c0 + span) if direction > 0 else max(self.coord(i, lim_u), c0 - span))
        else:
            lim = lim_u
        if (lim - c0) * direction <= 0.0:
            return None
        g_of = lambda s: math.sqrt(max(s - self.ssr0, 0.0)) - math.sqrt(self.rise)  # noqa: E731
        prev_c, prev_g, warm = c0, -math.sqrt(self.rise), self.u_opt.copy()
        for _ in range(FIT_PROFILE_STEPS):
            c = c0 + direction * step
            at_limit = (c - lim) * direction >= 0.0
            if at_limit:
                c = lim
            ssr, u = self.refit(i, self.unit(i, c), warm)
            g = g_of(ssr)
            if g >= 0.0:
                return self.unit(i, self._cross(i, prev_c, prev_g, c, g, u))
            if at_limit:
                return None
            prev_c, prev_g, warm = c, g, u
            step *= 2.0
        return None

    def _cross(self, i, ca, ga, cb, gb, warm):
        """Regula falsi on g = sqrt(S - S_min) - sqrt(rise) (about linear in the parameter)
        between ca (g < 0) and cb (g >= 0)."""
        c = cb
        for _ in range(FIT_PROFILE_REFINE):
            c = ca + (cb - ca) * (-ga) / (gb - ga) if gb > ga else 0.5 * (ca + cb)
            ssr, warm = self.refit(i, self.unit(i, c), warm)
            g = math.sqrt(max(ssr - self.ssr0, 0.0)) - math.sqrt(self.rise)
            if abs(g) <= 0.02 * math.sqrt(self.rise):
                return c
            if g < 0.0:
                ca, ga = c, g
            else:
                cb, gb = c, g
        return c


def profile_intervals(resid, params, u_opt, se_unit, m: int, level: float = FIT_LEVEL,
                      noise_known: bool = False) -> tuple:
    """Profile-likelihood intervals of every parameter.

    Parameters
    ----------
    resid : callable
        Residual vector of a unit-coordinate parameter vector.
    params : list of Param
        The fitted parameters (their bounds limit the profile).
    u_opt : ndarray
        The optimum, unit coordinates.
    se_unit : ndarray
        Linearised standard errors in unit coordinates (inf or NaN where unknown): the
        first step on each side.
    m : int
        Number of residuals.
    level : float
        Confidence level (0, 1).
    noise_known : bool
        The residuals are whitened by a measured noise: the residual variance is taken as at
        least 1 (a residual smaller than that noise, by chance over few residuals, does not
        narrow the intervals; a larger one widens them).

    Returns
    -------
    intervals : list of (low unit value or None, high unit value or None)
    best : (sum of squares, unit vector)
        The lowest sum of squares met (below the optimum's when the optimiser stopped in a
        local minimum: the caller refits from there).
    """
    r0 = resid(np.asarray(u_opt, float))
    ssr0 = float(r0 @ r0)
    rise = threshold(max(ssr0, float(m - len(params))) if noise_known else ssr0, m, len(params), level)
    prof = _Profiler(resid, params, u_opt, ssr0, rise)
    out = []
    for i, p in enumerate(params):
        se = float(se_unit[i]) if np.isfinite(se_unit[i]) and se_unit[i] > 0.0 else np.nan
        if p.positive:
            step = 1.5 * se / max(abs(u_opt[i]), 1e-300) if np.isfinite(se) else 0.1
            step = min(max(step, 1e-4), 0.5)
        else:
            step = min(max(1.5 * se, 1e-4), 0.25) if np.isfinite(se) else 0.1
        lo = prof.side(i, -1, step)
        hi = prof.side(i, +1, step)
        out.append((lo, hi))
    return out, prof.best
