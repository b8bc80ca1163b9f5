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
* corrector: damped Newton on ``R(u) = 0, d^T (u - u_pred) = 0`` from
  ``u_pred``, or, where the caller sets ``start_extrapolation``, from the
  cubic Hermite extrapolation of the last two points and their tangents
  moved onto that hyperplane (the same solution, fewer iterations; from
  ``u_pred`` again if Newton fails there);
* step length: grown after easy corrections, shrunk after hard ones and
  where the tangent turned (folds are resolved), cut and retried after a
  failure, down to ``ds_min``; bounded so that lam moves by at most
  ``max_dlam`` per step (a user's grid spacing) and, given an
  ``observe`` function (e.g. the logarithm of an amplitude), so that the
  straight line between consecutive points stays within ``chord_tol`` of
  the curve in the plane (lam, observe): a resonance peak cannot be
  stepped over;
* a fold (turning point in lam) is where the lam component of the tangent
  changes sign; it is flagged at the first point past it;
* a sharp corner of a piecewise-smooth branch (turning by more than a
  right angle while lam keeps its direction) is passed by Newton at fixed
  lam just beyond it (points marked ``corner``);
* a residual that jumps (a contact law with a discontinuous force, e.g.
  the closed-form Iwan rules under a varying load) can leave no solution
  on the arc: when the corrector fails at ``ds_min``, Newton at fixed lam
  is tried a little further on (``jump_fractions`` of the range, at most
  ``max_dlam``); if it converges the branch goes on from there and the
  point is marked as a ``gap``;
* the branch stops when lam leaves ``[min(lam0, lam_stop), max(..)]``
  (the end point is corrected onto the bound exactly; ``complete`` only at
  ``lam_stop``, ``turned-back`` at ``lam0``), after ``max_points``, when a
  ``monitor`` says so, or when the corrector fails at ``ds_min``.

:func:`refine_maximum` locates the maximum of an observable along a
computed branch between three points (peaks of response curves), and
:func:`local_maxima` finds the points to start from.

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
           "turning_points", "make_options", "local_maxima", "refine_maximum", "ParameterProgress"]

#: a step is sized to move lam by at most this fraction of ``max_dlam`` (the
#: corrector moves lam a little more or less than the prediction)
DLAM_SAFETY = 0.95
#: attempts of a corner pass, each a quarter of the distance in lam of the one before
CORNER_TRIES = 3
#: golden-section fraction of :func:`refine_maximum`'s fallback step, and the
#: margin (fraction of the bracket) a parabolic step keeps from the bracket's points
GOLDEN = 0.381966
GOLDEN_MARGIN = 0.05
#: a step of :func:`refine_maximum` that left the bracket wider than this fraction of its width before
#: is followed by a golden-section step (a golden step leaves 0.618 of it)
STALL_FRACTION = 0.7


class ContinuationStatus(Status):
    """How a branch ended."""

    COMPLETE = "complete", "the branch reached the end of the parameter range", True
    MAX_POINTS = "max-points", "the branch stopped at the bound on its number of points"
    FAILED = "failed", "Newton failed (at the start, or at the smallest step): the branch stops short"
    UNBOUNDED = "unbounded", "the solution grows without bound (stopped by the problem's monitor)"
    STOPPED = "stopped", "the problem's monitor stopped the branch"
    TURNED_BACK = "turned-back", "the branch turned back to the start of the range: the end was not reached"


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
    ds_max_rel : float
        Where the unknowns are large, the largest step is this fraction of
        their norm instead of ``ds_max`` (a response growing without bound
        is followed in as many steps per decade as a small one).
    max_points : int
        Bound on the points of a branch (>= 1).
    tol : float
        Newton converged when max |R| (and the arc-length constraint) is
        at most this, at the returned point.
    max_iter : int
        Newton iterations per correction.
    predictor : {"tangent", "secant"}
        Direction of the predictor.
    start_extrapolation : float or None
        The corrector starts from the cubic Hermite extrapolation of the
        last two points and their unit tangents, moved onto the
        corrector's hyperplane ``d^T (v - u_pred) = 0`` (so it converges
        to the same point as from ``u_pred``), when the step is at most
        this many times the distance between those points and both were
        reached along the curve (not by a jump or a corner pass); where
        Newton fails from there it is tried again from ``u_pred``.
        0 or None (the default: the solver decides, e.g.
        ``config.CONT_START_EXTRAPOLATION`` in harmonic balance where
        every contact law has a smooth force): always from ``u_pred``.
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
    max_dlam : float
        Largest change of lam between consecutive points (inf: none).
    chord_tol : float
        Largest deviation between the straight line joining consecutive
        points and the curve, in the plane (lam, observable), when
        :func:`continuation` is given an ``observe`` function (inf: none).
    stall_points, stall_ratio : int, float
        The branch stops as failed where, over the last ``stall_points``
        points, the distance from the first to the last is below
        ``stall_ratio`` times the path through them (it goes back and
        forth); those points are dropped.
    """

    ds: float = config.CONT_DS_START
    ds_min: float = config.CONT_DS_MIN
    ds_max: float = config.CONT_DS_MAX
    ds_max_rel: float = config.CONT_DS_MAX_REL
    max_points: int = config.CONT_MAX_POINTS
    tol: float = config.CONT_TOL
    max_iter: int = config.CONT_MAX_ITER
    predictor: str = config.CONT_PREDICTOR
    start_extrapolation: float | None = None
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
    max_dlam: float = math.inf
    chord_tol: float = config.CONT_CHORD_TOL
    stall_points: int = config.CONT_STALL_POINTS
    stall_ratio: float = config.CONT_STALL_RATIO

    def __post_init__(self) -> None:
        for name in ("ds", "ds_min", "ds_max", "ds_max_rel", "tol", "grow", "max_distance", "corner_ds"):
            V.positive(name, getattr(self, name))
        for name in ("max_dlam", "chord_tol"):
            if not getattr(self, name) > 0:  # inf allowed (no bound)
                raise ValueError(f"{name} must be > 0 (inf: no bound), got {getattr(self, name)!r}")
        for name in ("max_points", "max_iter", "target_iter", "line_search_steps", "max_evals_factor",
                     "stall_points"):
            V.positive_int(name, getattr(self, name))
        V.positive_int("max_jumps", self.max_jumps, 0)
        for name in ("shrink", "turn_shrink", "reject_shrink", "corner_shrink"):
            V.in_range(name, getattr(self, name), 0.0, 1.0, lo_open=True, hi_open=True)
        for name in ("turn_cos", "min_tangent_dot"):
            V.in_range(name, getattr(self, name), -1.0, 1.0)
        V.nonnegative("jump_tangent_min", self.jump_tangent_min)
        if self.start_extrapolation is not None:
            V.nonnegative("start_extrapolation", self.start_extrapolation)
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
        ``points, residual_evaluations, steps_rejected, folds, jumps, corners``.
    corner : ndarray of bool (points,)
        True where the point was reached past a sharp corner by Newton at
        fixed lam (see :func:`continuation`); the curve is continuous there.
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
    corner: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))


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


def turning_points(lam, gap=None, band: float = 0.0, observed=None, observed_band: float = math.inf):
    """Indices where lam is extremal along a branch (secant turning points).

    A reversal counts only once lam has come back from the running extreme
    by more than ``band``, or, given ``observed`` values along the branch
    (what a plot shows against lam), once they have moved by more than
    ``observed_band`` from their value at the extreme while lam is still
    short of it (a fold whose branches are close in lam but far apart in
    the observable): jitter of the points of a piecewise-smooth branch is
    ignored. Points reached by a jump (``gap``) restart the search.
    """
    lam = np.asarray(lam, dtype=float)
    gap = np.zeros(lam.size, dtype=bool) if gap is None else np.asarray(gap, dtype=bool)
    obs = np.zeros(lam.size) if observed is None else np.asarray(observed, dtype=float)
    out = []
    i_ext = 0
    direction = 0
    for i in range(1, lam.size):
        if gap[i]:
            i_ext, direction = i, 0
            continue
        if direction == 0:
            if lam[i] != lam[i_ext] and (abs(lam[i] - lam[i_ext]) > band
                                         or abs(obs[i] - obs[i_ext]) > observed_band):
                direction = 1 if lam[i] > lam[i_ext] else -1
                i_ext = i
            continue
        if direction * (lam[i] - lam[i_ext]) >= 0:
            i_ext = i
        elif abs(lam[i] - lam[i_ext]) > band or abs(obs[i] - obs[i_ext]) > observed_band:
            out.append(i_ext)
            direction = -direction
            i_ext = i
    return np.array(out, dtype=int)


# --- the branch -----------------------------------------------------------------------


class _Points:
    """The accepted points of a branch being computed, and its counters."""

    def __init__(self, n: int):
        self.n = n
        self.Y, self.L, self.TL, self.FOLD, self.IT, self.GAP, self.CORNER = [], [], [], [], [], [], []
        # PATH[i]: length of the polygon through points 0..i (scaled unknowns and parameter), for the
        # stall test (:func:`_stalled`) in constant time per point
        self.PATH = []
        self.cnt = {"points": 0, "residual_evaluations": 0, "steps_rejected": 0, "folds": 0, "jumps": 0,
                    "corners": 0}

    def add(self, y, lam, t_lam, fold, it, gap, corner=False) -> None:
        if self.Y:
            d = y - self.Y[-1]
            self.PATH.append(self.PATH[-1] + math.sqrt(float(d @ d) + (lam - self.L[-1]) ** 2))
        else:
            self.PATH.append(0.0)
        self.Y.append(y)
        self.L.append(lam)
        self.TL.append(t_lam)
        self.FOLD.append(fold)
        self.IT.append(it)
        self.GAP.append(gap)
        self.CORNER.append(corner)

    def drop(self, k: int) -> None:
        """Forget the last ``k`` points."""
        for col in (self.Y, self.L, self.TL, self.FOLD, self.IT, self.GAP, self.CORNER, self.PATH):
            del col[-k:]

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
            corner=np.array(self.CORNER, dtype=bool),
        )


@dataclass(slots=True)
class _Walk:
    """What every step of one branch needs: residual, options, counters, observable, direction."""

    residual: Callable
    opt: ContinuationOptions
    cnt: dict
    observe: Callable | None
    sgn: float
    span: float
    n: int

    def observed(self, u) -> float:
        """The observable at u (NaN without one, or where it is not finite)."""
        if self.observe is None:
            return math.nan
        g = float(self.observe(u[:self.n], u[self.n]))
        return g if math.isfinite(g) else math.nan


@dataclass(slots=True)
class _Step:
    """Outcome of one predicted and corrected step (see :func:`_try_step`)."""

    v: np.ndarray
    t: np.ndarray | None
    it: int
    ok: bool
    factor: float  # step factor after a rejection
    corner_like: bool = False
    err: float = 0.0  # chord error estimate (0 without an observable)
    g: float = math.nan  # observable at v
    gap: bool = False
    corner: bool = False


def _oriented(t_new, direction, n, opt):
    """t_new, reversed if its lam component opposes ``direction`` (when that component is not negligible)."""
    if t_new[n] * direction < 0.0 and abs(t_new[n]) > opt.jump_tangent_min:
        return -t_new
    return t_new


def _fixed_lam_point(walk: _Walk, u, t, lam, guesses):
    """Newton at fixed lam from each guess in turn: ``(v, t_new, iterations)`` or None."""
    for y0 in guesses:
        y, ok, it, (_, Jy, Jl) = _solve_damped(walk.residual, y0.copy(), lam, None, None, walk.opt, walk.cnt)
        if ok:
            tn = _tangent(Jy, Jl, t)
            if tn is not None:
                return np.concatenate((y, [lam])), tn, it
    return None


def _guesses(u, t, lam, n, opt):
    """Starting guesses at parameter lam near u: along the tangent (if it has a lam component), then u."""
    out = [u[:n]]
    if abs(t[n]) > opt.jump_tangent_min:
        out.insert(0, u[:n] + t[:n] * ((lam - u[n]) / t[n]))
    return out


def _jump(walk: _Walk, u, t) -> _Step | None:
    """Newton at fixed lam a little beyond u (over a discontinuity of the residual), oriented forward.

    The point found is a ``gap`` unless the straight line to it stays
    within ``chord_tol`` of the curve (:func:`_joined`): then the step
    passed a corner, not a discontinuity.
    """
    opt, n = walk.opt, walk.n
    for frac in opt.jump_fractions:
        # forward in the range, never farther than the largest lam step: never bounce back over the same
        # discontinuity, never skip more than a step
        lam = u[n] + walk.sgn * min(frac * walk.span, opt.max_dlam)
        hit = _fixed_lam_point(walk, u, t, lam, _guesses(u, t, lam, n, opt))
        if hit is not None:
            v, tn, it = hit
            corner = _joined(walk, u, v, t)
            return _Step(v, _oriented(tn, walk.sgn, n, opt), it, True, 1.0, g=walk.observed(v), gap=not corner,
                         corner=corner)
    return None


def _corner_pass(walk: _Walk, u, t) -> _Step | None:
    """Past a sharp corner of a piecewise-smooth branch by Newton at fixed lam.

    Where the branch turns by more than a right angle at a corner (the
    onset of slip at one more sample, say) while lam keeps its direction,
    no hyperplane ahead of u meets it and the arc-length corrector fails
    at every step. Newton at ``lam + sign(t_lam) |t_lam| corner_ds``
    finds the point past the corner; it is accepted when the straight line
    to it stays within ``chord_tol`` of the curve (:func:`_joined`), else
    tried closer (:data:`CORNER_TRIES` times, a quarter of the distance
    each time). Its tangent keeps the direction of travel in lam.
    """
    opt, n = walk.opt, walk.n
    if abs(t[n]) <= opt.jump_tangent_min:
        return None  # a vertical tangent (a fold): no direction of travel in lam
    direction = math.copysign(1.0, t[n])
    dlam = min(abs(t[n]) * opt.corner_ds, opt.max_dlam)
    for _ in range(CORNER_TRIES):
        lam = u[n] + direction * dlam
        hit = _fixed_lam_point(walk, u, t, lam, _guesses(u, t, lam, n, opt))
        if hit is not None and _joined(walk, u, hit[0], t):
            v, tn, it = hit
            return _Step(v, _oriented(tn, direction, n, opt), it, True, 1.0, g=walk.observed(v), corner=True)
        dlam *= 0.25
    return None


def _joined(walk: _Walk, u, v, t) -> bool:
    """True if the straight line u-v stays within ``chord_tol`` of the curve at its middle.

    The curve's middle is found by Newton at the middle value of lam from
    the middle of the chord; the deviation is measured in the plane
    (lam, observable), or in (y, lam) without an observable. A
    discontinuity of the residual between u and v leaves the middle point
    on one side, far from the chord.
    """
    n = walk.n
    mid = 0.5 * (u + v)
    hit = _fixed_lam_point(walk, u, t, mid[n], [mid[:n]])
    if hit is None:
        return False
    w = hit[0]
    if walk.observe is None:
        return bool(np.linalg.norm(w - mid) <= walk.opt.chord_tol)
    g = (walk.observed(u), walk.observed(v), walk.observed(w))
    if not all(math.isfinite(x) for x in g):
        return False
    return abs(g[2] - 0.5 * (g[0] + g[1])) <= walk.opt.chord_tol


def _chord_error(walk: _Walk, u, g_u, v, g_v, t, t_new) -> float:
    """Deviation of the curve from the chord u-v at its middle, in the plane (lam, observable).

    The curve's middle is the cubic Hermite interpolant of the two points
    and their unit tangents at half the chord length L:
    ``(u + v) / 2 + L (t - t_new) / 8``; its observable against the
    chord's middle gives the deviation (error O(L^4)).
    """
    if walk.observe is None or not (math.isfinite(g_u) and math.isfinite(g_v)):
        return 0.0
    L = float(np.linalg.norm(v - u))
    mid = 0.5 * (u + v) + (0.125 * L) * (t - t_new)
    g_mid = walk.observed(mid)
    if not math.isfinite(g_mid):
        return 0.0
    n = walk.n
    return math.hypot(mid[n] - 0.5 * (u[n] + v[n]), g_mid - 0.5 * (g_u + g_v))


def _chord_factor(err, opt) -> float:
    """Step factor that brings a chord error ``err`` (O(ds^2)) to ``0.9 chord_tol``, within [1/8, grow]."""
    if err <= 0.0:
        return opt.grow
    return min(max(0.9 * math.sqrt(opt.chord_tol / err), 0.125), opt.grow)


def _hermite_start(u, t, prev, ds, u_pred, d, opt):
    """Where the corrector starts: the cubic Hermite extrapolation to arc length ``ds`` beyond u of
    the curve through ``prev = (u_prev, t_prev)`` and ``(u, t)``, moved along ``d`` onto the
    hyperplane ``d^T (v - u_pred) = 0`` (``u_pred`` itself when ``prev`` is None, the step exceeds
    ``opt.start_extrapolation`` times the distance of the two points, or the extrapolation strays more
    than half a step from the prediction).

    The tangent prediction is off the curve by O(ds^2) (its curvature);
    the extrapolation by O(ds^3) where the curve is smooth, so that Newton
    needs one iteration less at many points. The corrector's constraint is
    unchanged, and so is the point it converges to.
    """
    if prev is None or not opt.start_extrapolation:
        return u_pred
    u_prev, t_prev = prev
    h = float(np.linalg.norm(u - u_prev))
    if not (h > 0.0 and ds <= opt.start_extrapolation * h):
        return u_pred
    # Hermite basis on [u_prev, u] (parameter 0 at u_prev, 1 at u, arc length ~ h), evaluated at 1 + ds / h
    s = 1.0 + ds / h
    s2, s3 = s * s, s * s * s
    p = ((2.0 * s3 - 3.0 * s2 + 1.0) * u_prev + ((s3 - 2.0 * s2 + s) * h) * t_prev
         + (3.0 * s2 - 2.0 * s3) * u + ((s3 - s2) * h) * t)
    p -= u_pred
    p -= (d @ p) * d
    if not (np.isfinite(p).all() and np.linalg.norm(p) <= 0.5 * ds):
        return u_pred
    return u_pred + p


def _try_step(walk: _Walk, u, t, u_prev, g_u, ds, prev=None) -> _Step:
    """Predict and correct one step of length ds, then check it.

    Rejected (with the factor for the next try) when the corrector failed;
    above ``opt.corner_ds`` when it went farther than ``opt.max_distance * ds``
    from the prediction or the tangent turned sharply (maybe onto another
    part of the branch; ``corner_like``), or the chord to the new point
    strays more than ``opt.chord_tol`` from the curve; and when lam moved by
    more than ``opt.max_dlam``. At smaller steps sharp turns are corners of
    a non-smooth branch (e.g. onset of slip) and are accepted. ``prev =
    (u_prev, t_prev)``: the last step, when it followed the curve, from
    which the corrector's start is extrapolated (:func:`_hermite_start`).
    """
    opt, n = walk.opt, walk.n
    if opt.predictor == "secant" and u_prev is not None:
        d = u - u_prev
        d /= np.linalg.norm(d)
    else:
        d = t
    u_pred = u + ds * d
    # away from the smallest steps, a corrector that needs many iterations is
    # stopped: retrying at a smaller step is cheaper (a corner of a non-smooth branch)
    big = ds > opt.corner_ds
    max_evals = opt.max_evals_factor * opt.target_iter if big else None
    v0 = _hermite_start(u, t, prev, ds, u_pred, d, opt)
    # the prediction itself is kept for the constraint: Newton gets a copy of it (the extrapolation is new)
    v, ok, it, (R, Jy, Jl) = _solve_damped(walk.residual, u_pred.copy() if v0 is u_pred else v0, None, d, u_pred,
                                           opt, walk.cnt, max_evals=max_evals)
    if not ok and v0 is not u_pred:
        # the extrapolation did not help here (a corner or a jump of a piecewise-smooth residual
        # ahead): the step is decided from the prediction, as without it
        v, ok, it, (R, Jy, Jl) = _solve_damped(walk.residual, u_pred.copy(), None, d, u_pred, opt, walk.cnt,
                                               max_evals=max_evals)
    if ok and big and np.linalg.norm(v - u_pred) > opt.max_distance * ds:
        return _Step(v, None, it, False, opt.corner_shrink, corner_like=True)
    t_new = _tangent(Jy, Jl, t) if ok else None
    if t_new is None:
        return _Step(v, None, it, False, opt.reject_shrink)
    if t_new @ t < opt.min_tangent_dot and big:
        return _Step(v, t_new, it, False, opt.corner_shrink, corner_like=True)
    dlam = abs(v[n] - u[n])
    if dlam > opt.max_dlam:
        return _Step(v, t_new, it, False, min(DLAM_SAFETY * opt.max_dlam / dlam, opt.reject_shrink))
    g_v = walk.observed(v)
    err = _chord_error(walk, u, g_u, v, g_v, t, t_new)
    if err > opt.chord_tol and big:
        return _Step(v, t_new, it, False, min(_chord_factor(err, opt), opt.reject_shrink))
    return _Step(v, t_new, it, True, 1.0, err=err, g=g_v)


def _advance(walk: _Walk, u, t, u_prev, g_u, ds, ds_init, prev=None):
    """The next point: steps tried (and cut) until one is accepted, else a corner pass or a jump.
    ``prev``: as for :func:`_try_step`.

    Returns ``(step, ds)`` with the accepted :class:`_Step` and the step
    length it was taken with, or ``None`` when the corrector failed at the
    smallest step and neither a corner pass nor a jump succeeded.
    """
    opt = walk.opt
    corner_tried = False
    while True:
        st = _try_step(walk, u, t, u_prev, g_u, ds, prev)
        if st.ok:
            return st, ds
        walk.cnt["steps_rejected"] += 1
        ds *= st.factor
        if st.corner_like and ds < opt.corner_ds:
            ds = opt.corner_ds
        if ds < opt.corner_ds and not corner_tried:
            corner_tried = True
            st = _corner_pass(walk, u, t)
            if st is not None:
                walk.cnt["corners"] += 1
                return st, opt.corner_ds
        if ds < opt.ds_min:
            st = _jump(walk, u, t) if walk.cnt["jumps"] < opt.max_jumps else None
            if st is None:
                return None
            walk.cnt["corners" if st.corner else "jumps"] += 1
            return st, ds_init


def _next_ds(ds, turn, it, err, opt, size) -> float:
    """Step after an accepted point: cut where the branch bends, grown after easy corrections,
    bounded by the chord error and by max(ds_max, ds_max_rel size) (size: norm of the unknowns)."""
    if turn < opt.turn_cos:
        new = ds * opt.turn_shrink
    elif it <= opt.target_iter - 1:
        new = ds * opt.grow
    elif it > opt.target_iter:
        new = ds * opt.shrink
    else:
        new = ds
    if err > 0.0:
        new = min(new, ds * _chord_factor(err, opt))
    return min(max(new, opt.ds_min), max(opt.ds_max, opt.ds_max_rel * size))


def _bound_dlam(ds, t, n, opt) -> float:
    """ds such that the predicted change of lam, ds |t_lam|, stays below the largest lam step."""
    tl = abs(t[n])
    if tl * ds > DLAM_SAFETY * opt.max_dlam:
        return max(DLAM_SAFETY * opt.max_dlam / tl, opt.ds_min)
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


def _start(residual, y0, lam0, sgn, opt, pts, lam_name):
    """First point at lam0: ``(u, t)`` or ``(None, message)``."""
    y, ok, it = newton(residual, np.array(y0, dtype=float), lam0, opt, counter=pts.cnt)
    if not ok:
        return None, f"Newton did not converge at the start {lam_name} = {lam0:.6g}"
    R, Jy, Jl = residual(y, lam0)
    pts.cnt["residual_evaluations"] += 1
    n = y.size
    t_seed = np.zeros(n + 1)
    t_seed[n] = sgn
    t = _tangent(Jy, Jl, t_seed)
    if t is None:
        return None, f"singular Jacobian at the start {lam_name} = {lam0:.6g}"
    pts.add(y.copy(), lam0, t[n], False, it, False)
    return np.concatenate((y, [lam0])), t


def _range_end(walk, u, v, t, fold, pts, lam_stop, lam_name):
    """(status, message) after the step to v left the range: the end point landed on the bound it crossed."""
    n = walk.n
    lam_end = lam_stop if (v[n] - lam_stop) * walk.sgn > 0 else lam_stop - walk.sgn * walk.span
    ok_end = _land(walk.residual, u, v, t, lam_end, fold, pts, walk.opt)
    note = "" if ok_end else f" (Newton at {lam_name} = {lam_end:.6g} itself failed; last point {lam_name} = {u[n]:.6g})"
    if lam_end == lam_stop:
        return ContinuationStatus.COMPLETE, f"reached {lam_name} = {lam_end:.6g}{note}"
    return ContinuationStatus.TURNED_BACK, (
        f"the branch turned back at {lam_name} = {max(pts.L) if walk.sgn > 0 else min(pts.L):.6g} and returned "
        f"to the start of the range {lam_name} = {lam_end:.6g}{note}")


def continuation(residual: Callable, y0, lam0: float, lam_stop: float, options: ContinuationOptions | None = None,
                 *, monitor: Callable | None = None, progress=None, observe: Callable | None = None,
                 lam_name: str = "lam", **overrides) -> ContinuationResult:
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
        Its ``update(1)`` is called per accepted point, and its
        ``reached(lam)`` where it has one (:class:`ParameterProgress`).
    observe : callable, optional
        ``observe(y, lam) -> float``, the quantity a plot of the branch
        shows against lam (e.g. the logarithm of an amplitude, so that the
        bound is relative): the straight line between consecutive points
        stays within ``options.chord_tol`` of the curve in the plane
        (lam, observe) (estimated at the middle of each chord; steps above
        ``corner_ds`` are cut until it holds).
    lam_name : str
        Name of the parameter in messages.

    Returns
    -------
    ContinuationResult
        ``status`` COMPLETE only when the branch reached ``lam_stop``.
    """
    opt = make_options(options, overrides)
    lam0 = V.finite("lam0", lam0)
    lam_stop = V.finite("lam_stop", lam_stop)
    if lam_stop == lam0:
        raise ValueError("lam_stop must differ from lam0")
    ds = ds_init = min(max(opt.ds, opt.ds_min), opt.ds_max)
    sgn = 1.0 if lam_stop > lam0 else -1.0
    n = len(np.asarray(y0).ravel())
    pts = _Points(n)
    walk = _Walk(residual, opt, pts.cnt, observe, sgn, abs(lam_stop - lam0), n)
    u, t = _start(residual, y0, lam0, sgn, opt, pts, lam_name)
    if u is None:
        return pts.finish(ContinuationStatus.FAILED, t)
    stop = _accepted(u, n, monitor, progress)
    if stop is not None:
        return pts.finish(*stop)
    u_prev, g_u = None, walk.observed(u)
    prev = None  # (u_prev, t_prev) when the step to u followed the curve
    while True:
        if len(pts.L) >= opt.max_points:
            return pts.finish(ContinuationStatus.MAX_POINTS,
                              f"stopped after {len(pts.L)} points at {lam_name} = {u[n]:.6g}")
        adv = _advance(walk, u, t, u_prev, g_u, _bound_dlam(ds, t, n, opt), ds_init, prev)
        if adv is None:
            why = "" if pts.cnt["jumps"] < opt.max_jumps else f" after {opt.max_jumps} jumps over discontinuities"
            return pts.finish(ContinuationStatus.FAILED,
                              f"corrector failed at the smallest step near {lam_name} = {u[n]:.6g}{why}")
        st, ds = adv
        v, t_new = st.v, st.t
        fold = bool(np.sign(t_new[n]) != np.sign(t[n]) and t[n] != 0.0) and not (st.gap or st.corner)
        pts.cnt["folds"] += fold
        if (v[n] - lam_stop) * sgn > 0 or (v[n] - lam0) * sgn < 0:
            end = _range_end(walk, u, v, t, fold, pts, lam_stop, lam_name)
            if hasattr(progress, "reached"):  # the point landed on the end of the range
                progress.reached(float(pts.L[-1]))
            return pts.finish(*end)
        u_prev, t_prev, u, t, g_u = u, t, v, t_new, st.g
        prev = None if (st.gap or st.corner) else (u_prev, t_prev)
        pts.add(v[:n].copy(), v[n], t[n], fold, st.it, st.gap, st.corner)
        if _stalled(pts, opt):
            pts.drop(opt.stall_points)
            return pts.finish(ContinuationStatus.FAILED,
                              f"stalled near {lam_name} = {v[n]:.6g}: {opt.stall_points} points went back and "
                              f"forth there (the corrector accepts a zigzag at a jump of the residual)")
        stop = _accepted(v, n, monitor, progress)
        if stop is not None:
            return pts.finish(*stop)
        ds = _next_ds(ds, float(t @ t_prev), st.it, st.err, opt, float(np.linalg.norm(v[:n])))


def _stalled(pts, opt) -> bool:
    """True when the last ``opt.stall_points`` points got nowhere: the first-to-last distance is below
    ``opt.stall_ratio`` times the path through them (scaled unknowns and parameter)."""
    k = opt.stall_points
    if len(pts.L) <= k:
        return False
    path = pts.PATH[-1] - pts.PATH[-k - 1]
    d = pts.Y[-1] - pts.Y[-k - 1]
    return path > 0.0 and math.sqrt(float(d @ d) + (pts.L[-1] - pts.L[-k - 1]) ** 2) < opt.stall_ratio * path


def _accepted(v, n, monitor, progress):
    """Progress and monitor at an accepted point: None or the monitor's (status, message)."""
    if progress is not None:
        progress.update(1)
        if hasattr(progress, "reached"):  # a bar over the parameter's range (ParameterProgress)
            progress.reached(float(v[n]))
    if monitor is not None:
        return monitor(v[:n], v[n])
    return None


# --- extrema along a branch --------------------------------------------------------------


def local_maxima(values, gap=None, prominence: float = 0.0) -> np.ndarray:
    """Indices of the interior local maxima of ``values`` along a branch.

    A maximum counts when, on each side, the values fall below it by more
    than ``prominence`` times |value| before they rise above it (or the
    piece ends). Points reached by a jump (``gap``) start a new piece: a
    maximum needs a neighbour on each side within its piece; NaN values
    end a piece too.
    """
    g = np.asarray(values, dtype=float)
    gap = np.zeros(g.size, dtype=bool) if gap is None else np.asarray(gap, dtype=bool)
    piece = np.cumsum(gap | ~np.isfinite(g))
    out = []
    for i in range(1, g.size - 1):
        if not (np.isfinite(g[i]) and piece[i - 1] == piece[i] == piece[i + 1]):
            continue
        if not (g[i] >= g[i - 1] and g[i] > g[i + 1]):
            continue
        drop = prominence * abs(g[i])
        if _falls(g, piece, i, -1, drop) and _falls(g, piece, i, 1, drop):
            out.append(i)
    return np.array(out, dtype=int)


def _falls(g, piece, i, step, drop) -> bool:
    """True if, walking from i by ``step`` within its piece, g falls below g[i] - drop before exceeding g[i]."""
    j = i + step
    while 0 <= j < g.size and piece[j] == piece[i]:
        if g[j] > g[i]:
            return False
        if g[j] < g[i] - drop:
            return True
        j += step
    return True


def _vertex(s, g):
    """Abscissa of the vertex of the parabola through three points, or None if it is not a maximum."""
    d1 = (g[1] - g[0]) / (s[1] - s[0])
    d2 = (g[2] - g[1]) / (s[2] - s[1])
    a = (d2 - d1) / (s[2] - s[0])
    if not a < 0.0:
        return None
    return 0.5 * (s[0] + s[1]) - d1 / (2.0 * a)


def _interpolate(s, U, x):
    """Value and unit derivative at x of the quadratic through (s_k, U_k), k = 0, 1, 2."""
    w = np.empty(3)
    dw = np.empty(3)
    for k in range(3):
        o = [j for j in range(3) if j != k]
        den = (s[k] - s[o[0]]) * (s[k] - s[o[1]])
        w[k] = (x - s[o[0]]) * (x - s[o[1]]) / den
        dw[k] = ((x - s[o[0]]) + (x - s[o[1]])) / den
    d = dw @ U
    return w @ U, d / np.linalg.norm(d)


def _bracketed(s, g, width0) -> bool:
    """True when the bracket of :func:`refine_maximum` is narrow enough or flat enough (value converged)."""
    return bool(s[2] - s[0] <= config.CONT_REFINE_STOL * width0
                or g[1] - min(g[0], g[2]) <= config.CONT_REFINE_GTOL)


def refine_maximum(residual: Callable, observe: Callable, y, lam, options: ContinuationOptions | None = None,
                   *, iterations: int = config.CONT_REFINE_ITER, **overrides):
    """Maximum of an observable along the solution curve, refined between three branch points.

    ``y`` (3, n) and ``lam`` (3,) are consecutive points of a branch whose
    middle one has the largest ``observe(y, lam)``. Successive parabolic
    interpolation in the chord length s: the vertex of the parabola
    through the three values (a golden-section point of the larger half
    when the parabola has no maximum inside), the point of the curve there
    by the arc-length corrector (predicted by the quadratic through the
    three points, constrained to the hyperplane orthogonal to its
    derivative), and the bracket shrunk around the best point; until the
    bracket is ``config.CONT_REFINE_STOL`` of its first width, or the
    observable varies by at most ``config.CONT_REFINE_GTOL`` across it
    (the value has converged; a flat maximum's location is then known to
    the square root of that), or
    ``iterations`` corrections were made (a maximum at a corner of a
    piecewise-smooth branch converges linearly).

    Returns
    -------
    (y, lam, value, converged) : the best point found (one of the three
    given points if no correction succeeded), its observable, and whether
    the bracket shrank to the tolerance.
    """
    opt = make_options(options, overrides)
    U = np.column_stack((np.asarray(y, dtype=float), np.asarray(lam, dtype=float)))
    n = U.shape[1] - 1
    g = np.array([float(observe(U[k, :n], U[k, n])) for k in range(3)])
    s = np.array([0.0, np.linalg.norm(U[1] - U[0]), 0.0])
    s[2] = s[1] + np.linalg.norm(U[2] - U[1])
    width0 = s[2] - s[0]
    cnt = {"residual_evaluations": 0}
    last_width = math.inf
    for _ in range(iterations):
        if _bracketed(s, g, width0):
            break
        x = _vertex(s, g)
        lo, hi = s[0] + GOLDEN_MARGIN * (s[1] - s[0]), s[2] - GOLDEN_MARGIN * (s[2] - s[1])
        # golden section where the parabola has no maximum inside, lands next to the best point, or the
        # last step hardly shrank the bracket (a maximum at a corner: Brent's safeguard)
        stalled = s[2] - s[0] > STALL_FRACTION * last_width
        last_width = s[2] - s[0]
        if x is None or stalled or not lo < x < hi or abs(x - s[1]) < GOLDEN_MARGIN * (s[2] - s[0]):
            wide = 0 if s[1] - s[0] > s[2] - s[1] else 2
            x = s[1] + GOLDEN * (s[wide] - s[1])
        u_pred, d = _interpolate(s, U, x)
        v, ok, _, _ = _solve_damped(residual, u_pred.copy(), None, d, u_pred, opt, cnt)
        if not ok:
            break
        gv = float(observe(v[:n], v[n]))
        if not math.isfinite(gv):
            break
        # the bracket keeps the best point in the middle
        k = 0 if x < s[1] else 2
        if gv > g[1]:
            U[2 - k], g[2 - k], s[2 - k] = U[1], g[1], s[1]
            U[1], g[1], s[1] = v, gv, x
        else:
            U[k], g[k], s[k] = v, gv, x
    converged = _bracketed(s, g, width0)
    return U[1, :n].copy(), float(U[1, n]), float(g[1]), bool(converged)


class ParameterProgress:
    """A progress bar over the continued parameter's range, for :func:`continuation`.

    The bar stands at the farthest fraction ``|lam - start| / |stop - start|``
    reached (in per mille), so that it fills as the branch covers the range
    and its estimate of the time left means something; a count of points
    against ``max_points`` (a bound that a complete branch never reaches)
    would do neither. The current value of the parameter is shown beside
    it.

    Parameters
    ----------
    start, stop : float
        The range, in the units ``continuation`` sees (scaled).
    desc : str
        Label of the bar.
    progress : bool or None
        True: always shown; None: shown on a terminal only; False: no bar
        (tqdm is not even imported).
    name : str
        Name of the parameter shown beside the bar (``"gamma"``).
    scale : float
        Factor from the continued value to the shown one.
    """

    STEPS = 1000

    def __init__(self, start: float, stop: float, desc: str, progress=None, *, name: str = "lam",
                 scale: float = 1.0):
        self.start, self.span = float(start), float(stop) - float(start)
        self.name, self.scale = name, float(scale)
        self.done = 0
        self.bar = None
        if progress is not False:
            from tqdm.auto import tqdm

            self.bar = tqdm(total=self.STEPS, desc=desc, disable=None if progress is None else not progress,
                            leave=False,  # tqdm writes the postfix as ", gamma = ..."
                            bar_format="{desc}: {percentage:3.0f}%|{bar}| [{elapsed}<{remaining}{postfix}]")

    def fraction(self, lam: float) -> float:
        """Share of the range between ``start`` and ``lam`` (0 to 1)."""
        if not self.span or not math.isfinite(lam):
            return 0.0
        return min(max((lam - self.start) / self.span, 0.0), 1.0)

    def update(self, n: int = 1) -> None:
        """Points are not progress: the bar moves in :meth:`reached`."""

    def reached(self, lam: float) -> None:
        """An accepted point at ``lam``: the bar moves to the farthest fraction reached."""
        k = int(self.STEPS * self.fraction(lam))
        if self.bar is None:
            self.done = max(self.done, k)
            return
        if k > self.done:
            self.bar.update(k - self.done)
            self.done = k
        self.bar.set_postfix_str(f"{self.name} = {lam * self.scale:.5g}", refresh=False)

    def close(self) -> None:
        """Close the bar (leaves nothing on the terminal)."""
        if self.bar is not None:
            self.bar.close()

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        self.close()
