"""The walk along a branch: :func:`continuation` (start, predictor, corrector, step control, corners,
jumps, the end of the range; see :mod:`jointdyn.continuation`)."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable

import numpy as np

from .. import _validate as V
from ..status import Status
from .linalg import _tangent, reusing_factors
from .newton import _solve_damped, newton
from .options import ContinuationOptions, ContinuationResult, ContinuationStatus, make_options

__all__ = ["continuation"]


#: a step is sized to move lam by at most this fraction of ``max_dlam`` (the
#: corrector moves lam a little more or less than the prediction)
DLAM_SAFETY = 0.95


#: attempts of a corner pass, each a quarter of the distance in lam of the one before
CORNER_TRIES = 3

#: a fold at a corner (:func:`_kink_pass`) is looked past at this fraction of ``corner_ds``
KINK_STEP = 0.05
#: ... when the tangent there differs from the one behind: |cos| of their angle below this
KINK_MAX_COS = 0.999
#: ... and the way on turns by less than about 154 degrees (cos above this): closer to a reversal it is the
#: part of the branch just walked (where the residual also stays small)
KINK_MIN_COS = -0.9


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
    kink: bool = False  # past a fold at a corner (:func:`_kink_pass`): a turning point in lam


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
            tn = _oriented(tn, walk.sgn, n, opt)
            if corner and tn @ t < 0.0:
                continue  # the part of the branch just walked, oriented back along it: no way on
            return _Step(v, tn, it, True, 1.0, g=walk.observed(v), gap=not corner, corner=corner)
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


def _kink_pass(walk: _Walk, u, t) -> _Step | None:
    """Past a fold at a corner: a corner of a piecewise-smooth branch where lam turns back.

    Where the branch turns by more than a right angle at a corner and its
    direction of travel in lam reverses there, no hyperplane ahead of u
    meets it and no lam beyond u holds a point near it: the corrector
    fails at every step, the corner pass finds nothing, and Newton at a
    lam on the other side (:func:`_jump`) finds the part of the branch
    just walked. The branch past the corner is followed from the Jacobian
    just ahead of u (``KINK_STEP`` times ``corner_ds`` along t, past the
    corner): its tangent there, taken in the direction along which the
    residual stays at its size at u (on the other side, where the
    Jacobian behind holds, it grows linearly), and a corrector on the
    hyperplane across it. Accepted when the tangent ahead differs from t
    (a corner), turns lam back (a fold) but does not go back along the
    branch just walked (``KINK_MIN_COS``), the corrector stays within
    ``max_distance`` times the step of its prediction and the straight
    line to the point stays within ``chord_tol`` of the curve
    (:func:`_joined`). A jump of the residual leaves no branch on either
    side of u close to the prediction: the jump (:func:`_jump`) is tried
    next, as before.
    """
    opt, n = walk.opt, walk.n
    h = KINK_STEP * opt.corner_ds
    ahead = u + h * t
    _, Jy, Jl = walk.residual(ahead[:n], ahead[n])
    walk.cnt["residual_evaluations"] += 1
    tk = _tangent(Jy, Jl, t)
    if tk is None or abs(float(tk @ t)) > KINK_MAX_COS:
        return None
    size = []
    for d in (tk, -tk):
        p = u + h * d
        size.append(float(np.max(np.abs(walk.residual(p[:n], p[n])[0]))))
        walk.cnt["residual_evaluations"] += 1
    d = tk if size[0] <= size[1] else -tk
    if not d[n] * t[n] < 0.0:
        return None  # lam goes on in its direction: a corner (:func:`_corner_pass`) or a jump, not a fold
    if not d @ t > KINK_MIN_COS:
        return None  # back along the part of the branch just walked
    p = u + h * d
    v, ok, it, (_, Jy, Jl) = _solve_damped(walk.residual, p.copy(), None, d, p, opt, walk.cnt)
    if not ok or np.linalg.norm(v - p) > opt.max_distance * h:
        return None
    t_new = _tangent(Jy, Jl, d)
    if t_new is None or not _joined(walk, u, v, d):
        return None
    return _Step(v, t_new, it, True, 1.0, g=walk.observed(v), corner=True, kink=True)


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
            st = _kink_pass(walk, u, t)
            if st is not None:
                walk.cnt["corners"] += 1
                return st, ds_init
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
        Step control (defaults documented there); keyword
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
    with reusing_factors(opt.linear) as fr:
        res = _walk(residual, y0, lam0, lam_stop, opt, monitor, progress, observe, lam_name)
    if any(fr.counts.values()):  # large bordered systems (continuation.linalg): how they were solved
        res.counters.update(fr.counts)
    return res


def _walk(residual, y0, lam0, lam_stop, opt, monitor, progress, observe, lam_name) -> ContinuationResult:
    """The walk of :func:`continuation` (arguments checked)."""
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
        fold = bool(np.sign(t_new[n]) != np.sign(t[n]) and t[n] != 0.0) and (st.kink or not (st.gap or st.corner))
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
