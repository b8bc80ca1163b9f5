"""Damped Newton: the corrector at fixed parameter (:func:`newton`) and on the arc-length hyperplane
(:func:`_solve_damped`, shared with the walk)."""

from __future__ import annotations

import math

import numpy as np

from .linalg import _as_arrays, _merit, _newton_direction, reusing_factors
from .options import ContinuationOptions, make_options

__all__ = ["newton"]


_NO_D = np.zeros(0)


def _solve_damped(residual, v, lam, d, u_pred, opt, cnt, max_evals=None):
    """Damped Newton shared by the fixed-parameter and the arc-length corrector.

    With ``d is None`` solves R(v, lam) = 0 for v; otherwise v holds
    (y, lam) and the constraint d^T (v - u_pred) = 0 is appended. The step
    is halved (``opt.line_search_steps`` trials) until the merit
    max|residual| decreases; the iteration has converged when the merit,
    evaluated at the new point, is at most ``opt.tol`` (the Newton step
    after it would be of order |J^-1| tol). The AFT residual of stick-slip
    laws is only piecewise smooth, and the plain Newton iteration can
    cycle between the pieces near a corner (onset of slip). With
    ``max_evals`` the corrector gives up after that many residual
    evaluations. Returns ``(v, ok, iterations, (R, R_y, R_lam))`` with the
    residual and Jacobians at the returned point.
    """
    dd = _NO_D if d is None else d
    up = _NO_D if d is None else u_pred

    def ev(v):
        cnt["residual_evaluations"] += 1
        if d is None:
            R, Jy, Jl = _as_arrays(*residual(v, lam))
        else:
            n = v.size - 1
            R, Jy, Jl = _as_arrays(*residual(v[:n], v[n]))
        return R, Jy, Jl, _merit(R, dd, v, up)

    start = cnt["residual_evaluations"]
    R, Jy, Jl, merit = ev(v)
    if not math.isfinite(merit):
        return v, False, 0, (R, Jy, Jl)
    for it in range(1, opt.max_iter + 1):
        dv, ok = _newton_direction(Jy, Jl, dd, R, v, up)
        if not ok:
            return v, False, it, (R, Jy, Jl)
        alpha = 1.0
        for _ in range(opt.line_search_steps):
            if max_evals is not None and cnt["residual_evaluations"] - start >= max_evals:
                return v, False, it, (R, Jy, Jl)
            w = v + alpha * dv
            R2, Jy2, Jl2, m2 = ev(w)
            if math.isfinite(m2) and (m2 < merit or m2 <= opt.tol):
                break
            alpha *= 0.5
        else:
            return v, False, it, (R, Jy, Jl)
        v, R, Jy, Jl, merit = w, R2, Jy2, Jl2, m2
        if merit <= opt.tol:
            return v, True, it, (R, Jy, Jl)
    return v, merit <= opt.tol, opt.max_iter, (R, Jy, Jl)


def newton(residual, y, lam, options: ContinuationOptions | None = None, *, counter=None, **overrides):
    """Damped Newton's method for R(y, lam) = 0 at fixed lam.

    ``residual(y, lam) -> (R, R_y, R_lam)``. Converged when
    ``max |R| <= options.tol`` at the returned point, within
    ``options.max_iter`` iterations (keyword arguments override fields of
    ``options``, e.g. ``tol=1e-10``). Returns ``(y, ok, iterations)``.
    """
    opt = make_options(options, overrides)
    cnt = counter if counter is not None else {"residual_evaluations": 0}
    with reusing_factors(opt.linear):
        y, ok, it, _ = _solve_damped(residual, np.asarray(y, dtype=float), lam, None, None, opt, cnt)
    return y, ok, it
