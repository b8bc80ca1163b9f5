"""Generic pseudo-arc-length continuation of R(y, lam) = 0.

Knows nothing of contacts or harmonic balance: it takes a residual with its
Jacobian and returns a branch. Algorithm (Keller's pseudo-arc-length method;
e.g. Allgower & Georg, *Introduction to Numerical Continuation Methods*,
SIAM 2003, ch. 2; Seydel, *Practical Bifurcation and Stability Analysis*,
Springer 2010, sec. 4.4):

* start: Newton at fixed ``lam0`` from a guess (e.g. the linear solution);
* tangent t of unit length from ``[R_y R_lam; t_prev^T] t = [0; 1]`` (the
  orientation follows the previous tangent, so folds are passed);
* predictor ``u + ds t`` (tangent) or ``u + ds (u - u_prev)/|u - u_prev|``
  (secant);
* corrector: Newton on ``R(u) = 0, t^T (u - u_pred) = 0``;
* step length: grown after easy corrections, shrunk after hard ones and
  where the tangent turned by more than ~10 degrees (folds are resolved),
  halved and retried after a failure, down to ``ds_min``;
* a fold (turning point in lam) is where the lam component of the tangent
  changes sign; it is flagged at the first point past it;
* a residual that jumps (a contact law with a discontinuous force, e.g.
  the closed-form Iwan rules under a varying load) can leave no solution
  on the arc: when the corrector fails at ``ds_min``, Newton at fixed lam
  is tried a little further on (1e-4, 1e-3, 1e-2 of the range); if it
  converges the branch goes on from there and the point is marked as a
  ``gap``;
* the branch stops when lam leaves ``[min(lam0, lam_stop), max(..)]``
  (the end point is corrected onto ``lam_stop`` exactly), after
  ``max_points``, when a ``monitor`` says so, or when the corrector fails
  at ``ds_min``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .. import _validate as V
from .. import config
from .._jit import jit

__all__ = ["ContinuationResult", "continuation", "newton", "turning_points"]

#: below this (scaled) step a sharp turn or a long correction is a corner of
#: a piecewise-smooth branch, not a jump to another branch
_CORNER_DS = 2e-3
#: step factor after a rejection for a sharp turn or a far-away correction
#: (a corner of a non-smooth branch or a jump to another branch): such a
#: step is accepted only at corner size, reached here in fewer rejections
_CORNER_SHRINK = 0.25
#: the step is halved after a turn of the tangent by more than ~10 degrees
_TURN_COS = 0.985
#: bound on the jumps over discontinuities per branch
_MAX_JUMPS = 5


@dataclass
class ContinuationResult:
    """A computed branch.

    Attributes
    ----------
    status : str
        ``complete`` (reached lam_stop or left the range), ``max-points``,
        ``failed`` (Newton failed at the smallest step) or a status set by
        the monitor (e.g. ``unbounded``).
    message : str
        What happened, with the parameter value where it stopped.
    y : ndarray (points, n)
        Unknowns along the branch.
    lam : ndarray (points,)
        Parameter along the branch.
    tangent_lam : ndarray (points,)
        lam component of the unit tangent.
    fold : ndarray of bool (points,)
        True at the first point past a turning point in lam.
    iterations : ndarray of int (points,)
        Newton iterations of each point.
    gap : ndarray of bool (points,)
        True where the point was reached by a jump over a discontinuity of
        the residual (see :func:`continuation`), not along the curve.
    counters : dict
        ``points, residual_evaluations, steps_rejected, folds, jumps``.
    """

    status: str
    message: str
    y: np.ndarray
    lam: np.ndarray
    tangent_lam: np.ndarray
    fold: np.ndarray
    iterations: np.ndarray
    gap: np.ndarray
    counters: dict = field(default_factory=dict)


@jit
def _merit(R, d, v, u_pred):  # pragma: no cover - compiled
    """max |R| (and |d^T (v - u_pred)| when d has entries); NaN if any entry is NaN."""
    m = 0.0
    for i in range(R.shape[0]):
        a = abs(R[i])
        if a != a:
            return np.nan
        if a > m:
            m = a
    if d.shape[0]:
        c = 0.0
        for i in range(d.shape[0]):
            c += d[i] * (v[i] - u_pred[i])
        c = abs(c)
        if c != c:
            return np.nan
        if c > m:
            m = c
    return m


@jit
def _bordered(Jy, Jl, d):  # pragma: no cover - compiled
    """The matrix [[R_y, R_lam], [d^T]] (or R_y alone when d is empty)."""
    n = Jy.shape[0]
    if d.shape[0] == 0:
        return Jy.copy()
    A = np.empty((n + 1, n + 1))
    for i in range(n):
        for j in range(n):
            A[i, j] = Jy[i, j]
        A[i, n] = Jl[i]
    for j in range(n + 1):
        A[n, j] = d[j]
    return A


@jit
def _lu_solve(A, b):  # pragma: no cover - compiled
    """Solve A x = b in place by Gaussian elimination with partial pivoting.

    The algorithm of LAPACK ``dgesv`` (row interchanges by the largest
    pivot, LU factors overwrite A, b becomes x), written out: the systems
    here are small (n(2H+1) + 1) and NumPy's per-call overhead and Numba's
    LAPACK bindings (slow to compile) cost more than the arithmetic.
    Returns False for an exactly singular matrix (a zero pivot, where
    ``dgesv`` reports info > 0) or a non-finite solution.
    """
    n = A.shape[0]
    for k in range(n):
        p = k
        amax = abs(A[k, k])
        for i in range(k + 1, n):
            if abs(A[i, k]) > amax:
                amax = abs(A[i, k])
                p = i
        if amax == 0.0 or amax != amax:
            return False
        if p != k:
            for j in range(n):
                t = A[k, j]
                A[k, j] = A[p, j]
                A[p, j] = t
            t = b[k]
            b[k] = b[p]
            b[p] = t
        piv = A[k, k]
        for i in range(k + 1, n):
            f = A[i, k] / piv
            if f != 0.0:
                A[i, k] = f
                for j in range(k + 1, n):
                    A[i, j] -= f * A[k, j]
                b[i] -= f * b[k]
    for i in range(n - 1, -1, -1):
        acc = b[i]
        for j in range(i + 1, n):
            acc -= A[i, j] * b[j]
        b[i] = acc / A[i, i]
        if not np.isfinite(b[i]):
            return False
    return True


@jit
def _newton_direction(Jy, Jl, d, R, v, u_pred):  # pragma: no cover - compiled
    """Newton step of R(y, lam) = 0 (and d^T (v - u_pred) = 0 when d has entries).

    Returns ``(dv, ok)``; ok is False for a singular matrix or a non-finite step.
    """
    n = Jy.shape[0]
    A = _bordered(Jy, Jl, d)
    m = A.shape[0]
    rhs = np.empty(m)
    for i in range(n):
        rhs[i] = -R[i]
    if m > n:
        c = 0.0
        for i in range(m):
            c += d[i] * (v[i] - u_pred[i])
        rhs[n] = -c
    ok = _lu_solve(A, rhs)
    return rhs, ok


@jit
def _tangent_solve(Jy, Jl, t_prev):  # pragma: no cover - compiled
    """Unit t with [R_y R_lam] t = 0, t_prev^T t = 1 (normalised); ok flag."""
    n = Jy.shape[0]
    A = _bordered(Jy, Jl, t_prev)
    t = np.zeros(n + 1)
    t[n] = 1.0
    if not _lu_solve(A, t):
        return t, False
    nt = 0.0
    for i in range(n + 1):
        nt += t[i] * t[i]
    nt = np.sqrt(nt)
    if not np.isfinite(nt) or nt == 0:
        return t, False
    return t / nt, True


_NO_D = np.zeros(0)


def _as_arrays(R, Jy, Jl):
    """(R, R_y, R_lam) as C-contiguous float64 arrays of dims 1, 2, 1 (no copy when they are)."""
    f = np.float64
    if (type(R) is np.ndarray and type(Jy) is np.ndarray and type(Jl) is np.ndarray and R.dtype == f
            and Jy.dtype == f and Jl.dtype == f and R.ndim == 1 and Jy.ndim == 2 and Jl.ndim == 1
            and R.flags.c_contiguous and Jy.flags.c_contiguous and Jl.flags.c_contiguous):
        return R, Jy, Jl
    R = np.ascontiguousarray(R, dtype=f).reshape(-1)
    return R, np.ascontiguousarray(Jy, dtype=f).reshape(R.size, -1), np.ascontiguousarray(Jl, dtype=f).reshape(-1)


def _solve_damped(residual, v, lam, d, u_pred, *, tol, max_iter, cnt, max_evals=None):
    """Damped Newton shared by the fixed-parameter and the arc-length corrector.

    With ``d is None`` solves R(v, lam) = 0 for v; otherwise v holds
    (y, lam) and the constraint d^T (v - u_pred) = 0 is appended. The step
    is halved (up to 8 times) until the merit max|residual| decreases; the
    iteration has converged when the merit, evaluated at the new point, is
    at most ``tol`` (the Newton step after it would be of order
    |J^-1| tol). The
    AFT residual of stick-slip laws is only piecewise smooth, and the plain
    Newton iteration can cycle between the pieces near a corner (onset of
    slip). With ``max_evals`` the corrector gives up after that many
    residual evaluations (a step that needs many damped iterations is
    better retried smaller). Returns ``(v, ok, iterations, (R, R_y,
    R_lam))`` with the residual and Jacobians at the returned point.
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
    for it in range(1, max_iter + 1):
        dv, ok = _newton_direction(Jy, Jl, dd, R, v, up)
        if not ok:
            return v, False, it, (R, Jy, Jl)
        alpha = 1.0
        for _ in range(9):
            if max_evals is not None and cnt["residual_evaluations"] - start >= max_evals:
                return v, False, it, (R, Jy, Jl)
            w = v + alpha * dv
            R2, Jy2, Jl2, m2 = ev(w)
            if math.isfinite(m2) and (m2 < merit or m2 <= tol):
                break
            alpha *= 0.5
        else:
            return v, False, it, (R, Jy, Jl)
        v, R, Jy, Jl, merit = w, R2, Jy2, Jl2, m2
        if merit <= tol:
            return v, True, it, (R, Jy, Jl)
    return v, merit <= tol, max_iter, (R, Jy, Jl)


def newton(residual, y, lam, *, tol, max_iter, counter=None):
    """Damped Newton's method for R(y, lam) = 0 at fixed lam.

    Converged when ``|R|_inf <= tol`` at the returned point. Returns
    ``(y, ok, iterations)``.
    """
    cnt = counter if counter is not None else {"residual_evaluations": 0}
    y, ok, it, _ = _solve_damped(residual, np.asarray(y, dtype=float), lam, None, None,
                                 tol=tol, max_iter=max_iter, cnt=cnt)
    return y, ok, it


def _tangent(Jy, Jl, t_prev):
    f = np.float64
    Jl = np.ascontiguousarray(Jl, dtype=f).reshape(-1)
    Jy = np.ascontiguousarray(Jy, dtype=f).reshape(Jl.size, -1)
    t, ok = _tangent_solve(Jy, Jl, np.ascontiguousarray(t_prev, dtype=np.float64))
    return t if ok else None


def turning_points(lam, gap=None, band: float = 0.0):
    """Indices where lam is extremal along a branch (secant turning points).

    A reversal counts only once lam has come back from the running extreme
    by more than ``band`` (dead band: jitter of the points of a
    piecewise-smooth branch is ignored). Points reached by a jump
    (``gap``) restart the search.
    """
    lam = np.asarray(lam, dtype=float)
    gap = np.zeros(lam.size, dtype=bool) if gap is None else np.asarray(gap, dtype=bool)
    out = []
    i_ext = 0
    direction = 0
    for i in range(1, lam.size):
        if gap[i]:
            i_ext, direction = i, 0
            continue
        if direction == 0:
            if abs(lam[i] - lam[i_ext]) > band:
                direction = 1 if lam[i] > lam[i_ext] else -1
                i_ext = i
            continue
        if direction * (lam[i] - lam[i_ext]) >= 0:
            i_ext = i
        elif abs(lam[i] - lam[i_ext]) > band:
            out.append(i_ext)
            direction = -direction
            i_ext = i
    return np.array(out, dtype=int)


def _jump(residual, u, t, span, sgn, tol, max_iter, cnt):
    """Newton at fixed lam a little beyond u (over a discontinuity)."""
    n = u.size - 1
    d = sgn  # forward in the range: never bounce back over the same discontinuity
    for frac in (1e-4, 1e-3, 1e-2):
        lam = u[n] + d * frac * span
        y0 = u[:n] + (t[:n] * ((lam - u[n]) / t[n]) if abs(t[n]) > 1e-3 else 0.0)
        y, ok, it, (R, Jy, Jl) = _solve_damped(residual, y0, lam, None, None, tol=tol, max_iter=max_iter, cnt=cnt)
        if ok:
            tn = _tangent(Jy, Jl, t)
            if tn is not None:
                return np.concatenate((y, [lam])), tn, it
    return None


def continuation(
    residual: Callable,
    y0,
    lam0: float,
    lam_stop: float,
    *,
    ds: float = 0.02,
    ds_min: float = config.HB_DS_MIN,
    ds_max: float = config.HB_DS_MAX,
    max_points: int = config.HB_MAX_POINTS,
    tol: float = config.HB_NEWTON_RTOL,
    max_iter: int = config.HB_NEWTON_MAX_ITER,
    predictor: str = "tangent",
    monitor: Callable | None = None,
    progress=None,
) -> ContinuationResult:
    """Follow the solution curve of R(y, lam) = 0 from lam0 towards lam_stop.

    Parameters
    ----------
    residual : callable
        ``residual(y, lam) -> (R, R_y, R_lam)``: residual (n,), Jacobian
        dR/dy (n, n) and dR/dlam (n,). Scale y, lam and R so that a unit
        change is comparable in all components.
    y0 : array_like
        Starting guess at lam0.
    lam0, lam_stop : float
        Start and end of the parameter range.
    ds, ds_min, ds_max : float
        Initial, smallest and largest arc-length step (scaled units).
    max_points : int
        Bound on the branch points.
    tol : float
        Newton tolerance (scaled units).
    max_iter : int
        Newton iterations per correction.
    predictor : {"tangent", "secant"}
        Predictor direction.
    monitor : callable, optional
        ``monitor(y, lam) -> None | (status, message)`` called at every
        accepted point; a tuple stops the branch with that status (the
        point is kept).
    progress : tqdm-like, optional
        Its ``update(1)`` is called per accepted point.

    Returns
    -------
    ContinuationResult
    """
    lam0 = V.finite("lam0", lam0)
    lam_stop = V.finite("lam_stop", lam_stop)
    if lam_stop == lam0:
        raise ValueError("lam_stop must differ from lam0")
    ds = V.positive("ds", ds)
    ds_min = V.positive("ds_min", ds_min)
    ds_max = V.positive("ds_max", ds_max)
    max_points = V.positive_int("max_points", max_points, 1)
    V.choice("predictor", predictor, ("tangent", "secant"))
    ds = min(max(ds, ds_min), ds_max)
    sgn = 1.0 if lam_stop > lam0 else -1.0
    lo, hi = min(lam0, lam_stop), max(lam0, lam_stop)
    cnt = {"points": 0, "residual_evaluations": 0, "steps_rejected": 0, "folds": 0, "jumps": 0}
    Y, L, TL, FOLD, IT, GAP = [], [], [], [], [], []
    ds_init = ds

    def finish(status, message):
        cnt["points"] = len(L)
        n = len(np.asarray(y0).ravel())
        return ContinuationResult(
            status=status,
            message=message,
            y=np.array(Y) if Y else np.empty((0, n)),
            lam=np.array(L),
            tangent_lam=np.array(TL),
            fold=np.array(FOLD, dtype=bool),
            iterations=np.array(IT, dtype=int),
            gap=np.array(GAP, dtype=bool),
            counters=dict(cnt),
        )

    y, ok, it = newton(residual, np.array(y0, dtype=float), lam0, tol=tol, max_iter=max_iter, counter=cnt)
    if not ok:
        return finish("failed", f"Newton did not converge at the start lam = {lam0:.6g}")
    R, Jy, Jl = residual(y, lam0)
    cnt["residual_evaluations"] += 1
    n = y.size
    t_seed = np.zeros(n + 1)
    t_seed[n] = sgn
    t = _tangent(Jy, Jl, t_seed)
    if t is None:
        return finish("failed", f"singular Jacobian at the start lam = {lam0:.6g}")
    u = np.concatenate((y, [lam0]))
    Y.append(y.copy()); L.append(lam0); TL.append(t[n]); FOLD.append(False); IT.append(it); GAP.append(False)
    if progress is not None:
        progress.update(1)
    if monitor is not None:
        m = monitor(y, lam0)
        if m is not None:
            return finish(*m)
    u_prev = None
    u_prev_t = t
    while True:
        if len(L) >= max_points:
            return finish("max-points", f"stopped after {len(L)} points at lam = {u[n]:.6g}")
        accepted = False
        gap = False
        while not accepted:
            if predictor == "secant" and u_prev is not None:
                d = u - u_prev
                d /= np.linalg.norm(d)
            else:
                d = t
            u_pred = u + ds * d
            # away from the smallest steps, a corrector that needs more than
            # twice the target iterations is stopped: retrying at half the
            # step is cheaper (a corner of a non-smooth branch)
            v, ok, it, (R, Jy, Jl) = _solve_damped(
                residual, u_pred.copy(), None, d, u_pred, tol=tol, max_iter=max_iter, cnt=cnt,
                max_evals=2 * config.HB_TARGET_NEWTON_ITER if ds > _CORNER_DS else None)
            corner_like = False
            if ok and np.linalg.norm(v - u_pred) > 2.0 * ds and ds > _CORNER_DS:
                corner_like = True
                # the corrector went much further than the step: maybe onto
                # another part of the branch; retry smaller (at small steps
                # the distance is that of a corner of a non-smooth branch)
                ok = False
            if ok:
                t_new = _tangent(Jy, Jl, t)
                # a sharp turn at a large step may be a jump to another
                # branch: retry smaller; at small steps it is a corner of a
                # non-smooth branch (e.g. onset of slip) and is accepted
                if t_new is None or (t_new @ t < 0.5 and ds > _CORNER_DS):
                    ok = False
                    corner_like = t_new is not None
            if not ok:
                cnt["steps_rejected"] += 1
                ds *= _CORNER_SHRINK if corner_like else 0.5
                if corner_like and ds < _CORNER_DS:
                    ds = _CORNER_DS
                if ds < ds_min:
                    jump = None
                    if cnt["jumps"] < _MAX_JUMPS:
                        jump = _jump(residual, u, t, hi - lo, sgn, tol, max_iter, cnt)
                    if jump is None:
                        why = "" if cnt["jumps"] < _MAX_JUMPS else f" after {_MAX_JUMPS} jumps over discontinuities"
                        return finish("failed", f"corrector failed at the smallest step near lam = {u[n]:.6g}{why}")
                    v, t_new, it = jump
                    cnt["jumps"] += 1
                    ds = ds_init
                    gap = True
                    break
                continue
            accepted = True
            gap = False
        fold = bool(np.sign(t_new[n]) != np.sign(t[n]) and t[n] != 0.0) and not gap
        cnt["folds"] += fold
        lam_new = v[n]
        if lam_new > hi or lam_new < lo:
            # end of the range: land exactly on the bound that was crossed
            lam_end = hi if lam_new > hi else lo
            frac = (lam_end - u[n]) / (lam_new - u[n])
            y_guess = u[:n] + frac * (v[:n] - u[:n])
            y_end, ok_end, it_end = newton(residual, y_guess, lam_end, tol=tol, max_iter=max_iter, counter=cnt)
            if ok_end:
                R, Jy, Jl = residual(y_end, lam_end)
                cnt["residual_evaluations"] += 1
                te = _tangent(Jy, Jl, t)
                Y.append(y_end); L.append(lam_end); TL.append(te[n] if te is not None else np.nan)
                FOLD.append(fold); IT.append(it_end); GAP.append(False)
            where = "lam_stop" if lam_end == lam_stop else "the start of the range (the branch turned back)"
            note = "" if ok_end else f" (Newton at lam = {lam_end:.6g} itself failed; last point lam = {u[n]:.6g})"
            return finish("complete", f"reached {where} lam = {lam_end:.6g}{note}")
        u_prev = u
        u_prev_t = t
        u = v
        t = t_new
        Y.append(v[:n].copy()); L.append(lam_new); TL.append(t[n]); FOLD.append(fold); IT.append(it)
        GAP.append(gap)
        if progress is not None:
            progress.update(1)
        if monitor is not None:
            m = monitor(v[:n], lam_new)
            if m is not None:
                return finish(*m)
        turn = float(t @ u_prev_t) if u_prev_t is not None else 1.0
        if turn < _TURN_COS:
            ds = max(ds * 0.5, ds_min)  # the branch bends: resolve it (folds)
        elif it <= config.HB_TARGET_NEWTON_ITER - 1:
            ds = min(ds * config.HB_DS_GROW, ds_max)
        elif it > config.HB_TARGET_NEWTON_ITER:
            ds = max(ds * 0.6, ds_min)
