"""What a continuation is asked and what it returns: :class:`ContinuationOptions` (every number of the
step control), :class:`ContinuationStatus` (how a branch ended) and :class:`ContinuationResult`."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V
from .. import config
from ..status import Status

__all__ = ["ContinuationOptions", "ContinuationResult", "ContinuationStatus", "make_options"]


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


def make_options(options: ContinuationOptions | None = None, overrides: dict | None = None) -> ContinuationOptions:
    """``options`` (default: :class:`ContinuationOptions`) with the fields in ``overrides`` replaced."""
    opt = ContinuationOptions() if options is None else options
    if not isinstance(opt, ContinuationOptions):
        raise ValueError("options must be a ContinuationOptions")
    return dataclasses.replace(opt, **overrides) if overrides else opt
