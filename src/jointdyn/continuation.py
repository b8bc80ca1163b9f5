"""Generic pseudo-arc-length continuation of R(y, lam) = 0.

Knows nothing of contacts, harmonic balance or modes: it takes a residual
with its Jacobians and returns a branch. Algorithm (Keller's
pseudo-arc-length method; e.g. Allgower & Georg, *Introduction to
Numerical Continuation Methods*, SIAM 2003, ch. 2; Seydel, *Practical
Bifurcation and Stability Analysis*, Springer 2010, sec. 4.4):

* start: Newton at fixed ``lam0`` from a guess (e.g. a linear solution);
* tangent t of unit length from ``[R_y R_lam; t_prev^T] t = [0; 1]`` (the
  orientation follows the previous tangent, so folds are passed);
* predictor ``u + ds t`` (tangent) or ``u + ds (u - u_prev)/|u - u_prev|``
  (secant);
* corrector: damped Newton on ``R(u) = 0, d^T (u - u_pred) = 0``;
* step length: grown after easy corrections, shrunk after hard ones and
  where the tangent turned (folds are resolved), cut and retried after a
  failure, down to ``ds_min``;
* a fold (turning point in lam) is where the lam component of the tangent
  changes sign; it is flagged at the first point past it;
* a residual that jumps (a contact law with a discontinuous force, e.g.
  the closed-form Iwan rules under a varying load) can leave no solution
  on the arc: when the corrector fails at ``ds_min``, Newton at fixed lam
  is tried a little further on (``jump_fractions`` of the range); if it
  converges the branch goes on from there and the point is marked as a
  ``gap``;
* the branch stops when lam leaves ``[min(lam0, lam_stop), max(..)]``
  (the end point is corrected onto the bound exactly), after
  ``max_points``, when a ``monitor`` says so, or when the corrector fails
  at ``ds_min``.

Every number of the step control is a field of :class:`ContinuationOptions`
(defaults in :mod:`jointdyn.config`, group "continuation"). Bordered linear
systems go through LAPACK, except small ones (``config.CONT_SMALL_SOLVE``
unknowns or fewer), where a compiled Gaussian elimination is faster
(``benchmarks/bench_linalg.py``).
"""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from . import _validate as V
from . import config
from ._jit import jit
from .status import Status

__all__ = ["ContinuationOptions", "ContinuationStatus", "ContinuationResult", "continuation", "newton",
           "turning_points", "make_options"]


class ContinuationStatus(Status):
    """How a branch ended."""

    COMPLETE = "complete", "the branch reached the end of the parameter range", True
    MAX_POINTS = "max-points", "the branch stopped at the bound on its number of points"
    FAILED = "failed", "Newton failed (at the start, or at the smallest step): the branch stops short"
    UNBOUNDED = "unbounded", "the solution grows without bound (stopped by the problem's monitor)"
    STOPPED = "stopped", "the problem's monitor stopped the branch"


@dataclass(frozen=True)
class ContinuationOptions:
    """Every number of the step control (NLvib's ``Sopt`` is the model).

    Units: the unknowns y, the parameter lam and the residual are those
    the caller passes, scaled so that a unit change is comparable in every
    component (harmonic balance scales y by fy/kt, R by max(F1, fy)); the
    arc length s is measured in them.

    Attributes
    ----------
    ds : float
        First arc-length step.
    ds_min, ds_max : float
        Smallest and largest step; below ``ds_min`` a failed corrector ends
        the branch (after the jumps below).
    max_points : int
        Bound on the points of a branch (>= 1).
    tol : float
        Newton converged when max |R| (and the arc-length constraint) is
        at most this, at the returned point.
    max_iter : int
        Newton iterations per correction.
    predictor : {"tangent", "secant"}
        Direction of the predictor.
    target_iter : int
        Newton iterations aimed at per correction: the step is multiplied
        by ``grow`` after a correction in fewer (``<= target_iter - 1``),
        by ``shrink`` after one in more.
    grow, shrink : float
        Step factors of that rule (> 1 and in (0, 1)).
    turn_cos, turn_shrink : float
        After the unit tangent turned by more than arccos(turn_cos) between
        two points, the step is multiplied by ``turn_shrink`` (folds and
        bends are resolved).
    reject_shrink : float
        Step factor after a rejected step.
    line_search_steps : int
        Trial steps of the damped Newton line search (full step, then
        halved), after which the iteration counts as failed.
    max_evals_factor : int
        With a step above ``corner_ds``, the corrector gives up after
        ``max_evals_factor * target_iter`` residual evaluations (a step
        that needs many damped iterations is better retried smaller).
    corner_ds : float
        Below this step a sharp turn or a long correction is accepted as a
        corner of a piecewise-smooth branch (onset of slip); above it such
        a step is rejected as a possible jump to another branch.
    corner_shrink : float
        Step factor after such a rejection (not below ``corner_ds``).
    min_tangent_dot : float
        Above ``corner_ds``, a step whose new unit tangent has a dot
        product with the previous one below this is rejected.
    max_distance : float
        Above ``corner_ds``, a step whose corrector moved farther than
        ``max_distance * ds`` from the predicted point is rejected.
    jump_fractions : tuple of float
        Newton at fixed lam tried this far beyond the last point (fractions
        of the parameter range) when the corrector failed at ``ds_min``.
    max_jumps : int
        Bound on those jumps per branch.
    jump_tangent_min : float
        A jump's guess follows the tangent when |t_lam| exceeds this.
    """

    ds: float = config.CONT_DS_START
    ds_min: float = config.CONT_DS_MIN
    ds_max: float = config.CONT_DS_MAX
    max_points: int = config.CONT_MAX_POINTS
    tol: float = config.CONT_TOL
    max_iter: int = config.CONT_MAX_ITER
    predictor: str = config.CONT_PREDICTOR
    target_iter: int = config.CONT_TARGET_ITER
    grow: float = config.CONT_GROW
    shrink: float = config.CONT_SHRINK
    turn_cos: float = config.CONT_TURN_COS
    turn_shrink: float = config.CONT_TURN_SHRINK
    reject_shrink: float = config.CONT_REJECT_SHRINK
    line_search_steps: int = config.CONT_LINE_SEARCH_STEPS
    max_evals_factor: int = config.CONT_MAX_EVALS_FACTOR
    corner_ds: float = config.CONT_CORNER_DS
    corner_shrink: float = config.CONT_CORNER_SHRINK
    min_tangent_dot: float = config.CONT_MIN_TANGENT_DOT
    max_distance: float = config.CONT_MAX_DISTANCE
    jump_fractions: tuple = config.CONT_JUMP_FRACTIONS
    max_jumps: int = config.CONT_MAX_JUMPS
    jump_tangent_min: float = config.CONT_JUMP_TANGENT_MIN

    def __post_init__(self) -> None:
        for name in ("ds", "ds_min", "ds_max", "tol", "grow", "max_distance", "corner_ds"):
            V.positive(name, getattr(self, name))
        for name in ("max_points", "max_iter", "target_iter", "line_search_steps", "max_evals_factor"):
            V.positive_int(name, getattr(self, name))
        V.positive_int("max_jumps", self.max_jumps, 0)
        for name in ("shrink", "turn_shrink", "reject_shrink", "corner_shrink"):
            V.in_range(name, getattr(self, name), 0.0, 1.0, lo_open=True, hi_open=True)
        for name in ("turn_cos", "min_tangent_dot"):
            V.in_range(name, getattr(self, name), -1.0, 1.0)
        V.nonnegative("jump_tangent_min", self.jump_tangent_min)
        V.choice("predictor", self.predictor, ("tangent", "secant"))
        object.__setattr__(self, "jump_fractions", tuple(V.positive("jump_fractions", f)
                                                         for f in self.jump_fractions))
        if not self.ds_min <= self.ds_max:
            raise ValueError(f"ds_min must be <= ds_max ({self.ds_max!r}), got {self.ds_min!r}")


@dataclass(frozen=True)
class ContinuationResult:
    """A computed branch.

    Attributes
    ----------
    status : Status
        :class:`ContinuationStatus` (or the status a monitor returned);
        ``status.ok`` only for a complete branch.
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

    status: Status
    message: str
    y: np.ndarray
    lam: np.ndarray
    tangent_lam: np.ndarray
    fold: np.ndarray
    iterations: np.ndarray
    gap: np.ndarray
    counters: dict = field(default_factory=dict)


# --- linear algebra -------------------------------------------------------------------


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
    pivot, LU factors overwrite A, b becomes x), written out: for small
    systems NumPy's per-call overhead costs more than the arithmetic.
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
def _border_rhs(R, d, v, u_pred):  # pragma: no cover - compiled
    """Right-hand side (-R, -d^T (v - u_pred)) of a Newton step (-R alone when d is empty)."""
    n = R.shape[0]
    m = n + (1 if d.shape[0] else 0)
    rhs = np.empty(m)
    for i in range(n):
        rhs[i] = -R[i]
    if m > n:
        c = 0.0
        for i in range(m):
            c += d[i] * (v[i] - u_pred[i])
        rhs[n] = -c
    return rhs


@jit
def _normalise(t):  # pragma: no cover - compiled
    """(t / |t|, ok); ok is False for a zero or non-finite norm."""
    nt = 0.0
    for i in range(t.shape[0]):
        nt += t[i] * t[i]
    nt = np.sqrt(nt)
    if not np.isfinite(nt) or nt == 0:
        return t, False
    return t / nt, True


@jit
def _newton_direction_small(Jy, Jl, d, R, v, u_pred):  # pragma: no cover - compiled
    """Newton step by the compiled elimination: ``(dv, ok)``."""
    rhs = _border_rhs(R, d, v, u_pred)
    ok = _lu_solve(_bordered(Jy, Jl, d), rhs)
    return rhs, ok


@jit
def _tangent_small(Jy, Jl, t_prev):  # pragma: no cover - compiled
    """Unit tangent by the compiled elimination: ``(t, ok)``."""
    n = Jy.shape[0]
    t = np.zeros(n + 1)
    t[n] = 1.0
    if not _lu_solve(_bordered(Jy, Jl, t_prev), t):
        return t, False
    return _normalise(t)


def _lapack_solve(A, b):
    """Solve A x = b by LAPACK ``dgesv``: ``(x, ok)``, ok False for a singular matrix or a non-finite x."""
    try:
        x = np.linalg.solve(A, b)
    except np.linalg.LinAlgError:
        return b, False
    return x, bool(np.isfinite(x).all())


def _small(Jy) -> bool:
    """True when the bordered system of R_y is solved by the compiled elimination (see the module docstring)."""
    return Jy.shape[0] + 1 <= config.CONT_SMALL_SOLVE


def _newton_direction(Jy, Jl, d, R, v, u_pred):
    """Newton step of R(y, lam) = 0 (and d^T (v - u_pred) = 0 when d has entries): ``(dv, ok)``."""
    if _small(Jy):
        return _newton_direction_small(Jy, Jl, d, R, v, u_pred)
    return _lapack_solve(_bordered(Jy, Jl, d), _border_rhs(R, d, v, u_pred))


def _tangent(Jy, Jl, t_prev):
    """Unit t with [R_y R_lam] t = 0, t_prev^T t = 1 (normalised), or None if singular."""
    f = np.float64
    Jl = np.ascontiguousarray(Jl, dtype=f).reshape(-1)
    Jy = np.ascontiguousarray(Jy, dtype=f).reshape(Jl.size, -1)
    t_prev = np.ascontiguousarray(t_prev, dtype=f)
    if _small(Jy):
        t, ok = _tangent_small(Jy, Jl, t_prev)
    else:
        e = np.zeros(Jy.shape[0] + 1)
        e[-1] = 1.0
        t, ok = _lapack_solve(_bordered(Jy, Jl, t_prev), e)
        if ok:
            t, ok = _normalise(t)
    return t if ok else None


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


# --- Newton ---------------------------------------------------------------------------


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
    y, ok, it, _ = _solve_damped(residual, np.asarray(y, dtype=float), lam, None, None, opt, cnt)
    return y, ok, it


def make_options(options: ContinuationOptions | None = None, overrides: dict | None = None) -> ContinuationOptions:
    """``options`` (default: :class:`ContinuationOptions`) with the fields in ``overrides`` replaced."""
    opt = ContinuationOptions() if options is None else options
    if not isinstance(opt, ContinuationOptions):
        raise ValueError("options must be a ContinuationOptions")
    return dataclasses.replace(opt, **overrides) if overrides else opt


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


# --- the branch -----------------------------------------------------------------------


class _Points:
    """The accepted points of a branch being computed, and its counters."""

    def __init__(self, n: int):
        self.n = n
        self.Y, self.L, self.TL, self.FOLD, self.IT, self.GAP = [], [], [], [], [], []
        self.cnt = {"points": 0, "residual_evaluations": 0, "steps_rejected": 0, "folds": 0, "jumps": 0}

    def add(self, y, lam, t_lam, fold, it, gap) -> None:
        self.Y.append(y)
        self.L.append(lam)
        self.TL.append(t_lam)
        self.FOLD.append(fold)
        self.IT.append(it)
        self.GAP.append(gap)

    def finish(self, status: Status, message: str) -> ContinuationResult:
        self.cnt["points"] = len(self.L)
        return ContinuationResult(
            status=status,
            message=message,
            y=np.array(self.Y) if self.Y else np.empty((0, self.n)),
            lam=np.array(self.L),
            tangent_lam=np.array(self.TL),
            fold=np.array(self.FOLD, dtype=bool),
            iterations=np.array(self.IT, dtype=int),
            gap=np.array(self.GAP, dtype=bool),
            counters=dict(self.cnt),
        )


def _jump(residual, u, t, span, sgn, opt, cnt):
    """Newton at fixed lam a little beyond u (over a discontinuity): ``(v, t, iterations)`` or None."""
    n = u.size - 1
    for frac in opt.jump_fractions:
        lam = u[n] + sgn * frac * span  # forward in the range: never bounce back over the same discontinuity
        y0 = u[:n] + (t[:n] * ((lam - u[n]) / t[n]) if abs(t[n]) > opt.jump_tangent_min else 0.0)
        y, ok, it, (R, Jy, Jl) = _solve_damped(residual, y0, lam, None, None, opt, cnt)
        if ok:
            tn = _tangent(Jy, Jl, t)
            if tn is not None:
                return np.concatenate((y, [lam])), tn, it
    return None


def _try_step(residual, u, t, u_prev, ds, opt, cnt):
    """Predict and correct one step of length ds: ``(v, t_new, iterations, ok, corner_like)``.

    A corrected point is rejected, above ``opt.corner_ds``, when the
    corrector went farther than ``opt.max_distance * ds`` from the
    prediction or the tangent turned sharply (maybe onto another part of
    the branch; ``corner_like``); at smaller steps those are corners of a
    non-smooth branch (e.g. onset of slip) and are accepted.
    """
    if opt.predictor == "secant" and u_prev is not None:
        d = u - u_prev
        d /= np.linalg.norm(d)
    else:
        d = t
    u_pred = u + ds * d
    # away from the smallest steps, a corrector that needs many iterations is
    # stopped: retrying at a smaller step is cheaper (a corner of a non-smooth branch)
    big = ds > opt.corner_ds
    v, ok, it, (R, Jy, Jl) = _solve_damped(residual, u_pred.copy(), None, d, u_pred, opt, cnt,
                                           max_evals=opt.max_evals_factor * opt.target_iter if big else None)
    if ok and big and np.linalg.norm(v - u_pred) > opt.max_distance * ds:
        return v, None, it, False, True
    if not ok:
        return v, None, it, False, False
    t_new = _tangent(Jy, Jl, t)
    if t_new is None:
        return v, None, it, False, False
    if t_new @ t < opt.min_tangent_dot and big:
        return v, t_new, it, False, True
    return v, t_new, it, True, False


def _advance(residual, u, t, u_prev, ds, ds_init, span, sgn, opt, cnt):
    """The next point: steps tried (and cut) until one is accepted, else a jump.

    Returns ``(v, t_new, iterations, gap, ds)``, or ``None`` when the
    corrector failed at the smallest step and no jump succeeded.
    """
    while True:
        v, t_new, it, ok, corner_like = _try_step(residual, u, t, u_prev, ds, opt, cnt)
        if ok:
            return v, t_new, it, False, ds
        cnt["steps_rejected"] += 1
        ds *= opt.corner_shrink if corner_like else opt.reject_shrink
        if corner_like and ds < opt.corner_ds:
            ds = opt.corner_ds
        if ds < opt.ds_min:
            jump = _jump(residual, u, t, span, sgn, opt, cnt) if cnt["jumps"] < opt.max_jumps else None
            if jump is None:
                return None
            cnt["jumps"] += 1
            return (*jump, True, ds_init)


def _next_ds(ds, turn, it, opt) -> float:
    """Step after an accepted point: cut where the branch bends, grown after easy corrections."""
    if turn < opt.turn_cos:
        return max(ds * opt.turn_shrink, opt.ds_min)
    if it <= opt.target_iter - 1:
        return min(ds * opt.grow, opt.ds_max)
    if it > opt.target_iter:
        return max(ds * opt.shrink, opt.ds_min)
    return ds


def _land(residual, u, v, t, lam_end, fold, pts, opt):
    """Correct the end point onto the bound ``lam_end`` crossed between u and v; add it. True on success."""
    n = u.size - 1
    frac = (lam_end - u[n]) / (v[n] - u[n])
    y_guess = u[:n] + frac * (v[:n] - u[:n])
    y_end, ok, it = newton(residual, y_guess, lam_end, opt, counter=pts.cnt)
    if ok:
        R, Jy, Jl = residual(y_end, lam_end)
        pts.cnt["residual_evaluations"] += 1
        te = _tangent(Jy, Jl, t)
        pts.add(y_end, lam_end, te[n] if te is not None else np.nan, fold, it, False)
    return ok


def _start(residual, y0, lam0, sgn, opt, pts):
    """First point at lam0: ``(u, t)`` or ``(None, message)``."""
    y, ok, it = newton(residual, np.array(y0, dtype=float), lam0, opt, counter=pts.cnt)
    if not ok:
        return None, f"Newton did not converge at the start lam = {lam0:.6g}"
    R, Jy, Jl = residual(y, lam0)
    pts.cnt["residual_evaluations"] += 1
    n = y.size
    t_seed = np.zeros(n + 1)
    t_seed[n] = sgn
    t = _tangent(Jy, Jl, t_seed)
    if t is None:
        return None, f"singular Jacobian at the start lam = {lam0:.6g}"
    pts.add(y.copy(), lam0, t[n], False, it, False)
    return np.concatenate((y, [lam0])), t


def continuation(residual: Callable, y0, lam0: float, lam_stop: float, options: ContinuationOptions | None = None,
                 *, monitor: Callable | None = None, progress=None, **overrides) -> ContinuationResult:
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
        Start and end of the parameter range (distinct).
    options : ContinuationOptions, optional
        Step control (defaults from :mod:`jointdyn.config`); keyword
        arguments override its fields (e.g. ``ds_max=0.05``).
    monitor : callable, optional
        ``monitor(y, lam) -> None | (status, message)`` called at every
        accepted point; a tuple stops the branch with that status (a
        :class:`~jointdyn.status.Status`; the point is kept).
    progress : tqdm-like, optional
        Its ``update(1)`` is called per accepted point.

    Returns
    -------
    ContinuationResult
    """
    opt = make_options(options, overrides)
    lam0 = V.finite("lam0", lam0)
    lam_stop = V.finite("lam_stop", lam_stop)
    if lam_stop == lam0:
        raise ValueError("lam_stop must differ from lam0")
    ds = ds_init = min(max(opt.ds, opt.ds_min), opt.ds_max)
    sgn = 1.0 if lam_stop > lam0 else -1.0
    lo, hi = min(lam0, lam_stop), max(lam0, lam_stop)
    n = len(np.asarray(y0).ravel())
    pts = _Points(n)
    u, t = _start(residual, y0, lam0, sgn, opt, pts)
    if u is None:
        return pts.finish(ContinuationStatus.FAILED, t)
    stop = _accepted(u, n, monitor, progress)
    if stop is not None:
        return pts.finish(*stop)
    u_prev = None
    while True:
        if len(pts.L) >= opt.max_points:
            return pts.finish(ContinuationStatus.MAX_POINTS, f"stopped after {len(pts.L)} points at lam = {u[n]:.6g}")
        step = _advance(residual, u, t, u_prev, ds, ds_init, hi - lo, sgn, opt, pts.cnt)
        if step is None:
            why = "" if pts.cnt["jumps"] < opt.max_jumps else f" after {opt.max_jumps} jumps over discontinuities"
            return pts.finish(ContinuationStatus.FAILED,
                              f"corrector failed at the smallest step near lam = {u[n]:.6g}{why}")
        v, t_new, it, gap, ds = step
        fold = bool(np.sign(t_new[n]) != np.sign(t[n]) and t[n] != 0.0) and not gap
        pts.cnt["folds"] += fold
        if v[n] > hi or v[n] < lo:
            lam_end = hi if v[n] > hi else lo
            ok_end = _land(residual, u, v, t, lam_end, fold, pts, opt)
            where = "lam_stop" if lam_end == lam_stop else "the start of the range (the branch turned back)"
            note = "" if ok_end else f" (Newton at lam = {lam_end:.6g} itself failed; last point lam = {u[n]:.6g})"
            return pts.finish(ContinuationStatus.COMPLETE, f"reached {where} lam = {lam_end:.6g}{note}")
        u_prev, t_prev, u, t = u, t, v, t_new
        pts.add(v[:n].copy(), v[n], t[n], fold, it, gap)
        stop = _accepted(v, n, monitor, progress)
        if stop is not None:
            return pts.finish(*stop)
        ds = _next_ds(ds, float(t @ t_prev), it, opt)


def _accepted(v, n, monitor, progress):
    """Progress and monitor at an accepted point: None or the monitor's (status, message)."""
    if progress is not None:
        progress.update(1)
    if monitor is not None:
        return monitor(v[:n], v[n])
    return None
