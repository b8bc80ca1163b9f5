"""What a continuation is asked and what it returns: :class:`ContinuationOptions` (every number of the
step control), :class:`LinearSolveOptions` (how its bordered systems are solved),
:class:`ContinuationStatus` (how a branch ended) and :class:`ContinuationResult`.

The defaults written here are the continuation's own numbers; ``config`` keeps only the two it shares
with the solvers that build its Jacobians (``config.CONT_KRYLOV_SOLVE``, ``config.CONT_SPARSE_DENSITY``:
harmonic balance and EPMC choose the form of their Jacobians by them) and the tolerance harmonic balance
uses for a single solution (``config.CONT_TOL``)."""

from __future__ import annotations

import dataclasses
import math
from dataclasses import dataclass, field

import numpy as np

from .. import _validate as V
from .. import config
from ..status import Status

__all__ = ["ContinuationOptions", "ContinuationResult", "ContinuationStatus", "LinearSolveOptions", "START_EXTRAPOLATION",
           "make_options"]


#: the step bound (a multiple of the last step) up to which a solver that asks for it starts the corrector
#: from the cubic Hermite extrapolation of the last two points (``start_extrapolation``). Harmonic balance
#: asks where every contact law has a smooth force (``ContactLaw.smooth_force``): on the paper damper's
#: branch with the default law (eta 0.5, beta 2) it saves 14 % of the residual evaluations, 17 % at eta 1.5,
#: beta 5 (a start about 10x closer to the curve: one Newton iteration less at many points). Laws with kinks
#: or jumps at the onset of slip (Jenkins, the discrete model, the closed forms) do not use it: there Newton
#: from the extrapolation lands on other points of the piecewise-smooth residual, and the step control
#: follows another path
START_EXTRAPOLATION = 2.0


class ContinuationStatus(Status):
    """How a branch ended."""

    COMPLETE = "complete", "the branch reached the end of the parameter range", True
    MAX_POINTS = "max-points", "the branch stopped at the bound on its number of points"
    FAILED = "failed", "Newton failed (at the start, or at the smallest step): the branch stops short"
    UNBOUNDED = "unbounded", "the solution grows without bound (stopped by the problem's monitor)"
    STOPPED = "stopped", "the problem's monitor stopped the branch"
    TURNED_BACK = "turned-back", "the branch turned back to the start of the range: the end was not reached"


@dataclass(frozen=True)
class LinearSolveOptions:
    """How the bordered systems of a walk are solved (:mod:`jointdyn.continuation.linalg`).

    Sizes count the unknowns of the bordered system (R_y's rows + 1). From ``config.CONT_KRYLOV_SOLVE``
    unknowns (shared with the solvers that choose the form of their Jacobian by it) the factors of an
    earlier matrix of the walk precondition GMRES; a first matrix with at most
    ``config.CONT_SPARSE_DENSITY`` of its entries nonzero is factorised by SuperLU.

    Attributes
    ----------
    small_solve : int
        Systems of at most this many unknowns are solved by the compiled elimination
        (:func:`~jointdyn.continuation.linalg.lu_solve`), larger ones by LAPACK (default 800;
        ``benchmarks/bench_linalg.py``: the compiled elimination is 1.2-3.5x faster at 16 to 751
        unknowns with single-threaded BLAS; beyond the sizes measured, LAPACK).
    krylov_rtol : float
        A GMRES solution is accepted when ``|A x - b| <= krylov_rtol |b|`` (true residual; default 1e-9).
    krylov_maxiter : int
        GMRES iterations (one cycle, no restart) before the matrix is factorised (default 12; at 5500
        unknowns an iteration costs about 1/20 of a factorisation; on the 167-pair chain of
        ``benchmarks/bench_hb_interface_chain.py`` 20 instead of 12 saved no factorisation and cost 372
        instead of 245 iterations).
    krylov_refresh : int
        A solve that needed more iterations than this has the next matrix factorised at once (the kept
        factors have drifted from the walk's matrices; default 8).
    sparse_fill : float
        Sparse factors are kept while they hold at most this fraction of N^2 entries; beyond, the walk
        goes on dense (default 0.25).
    sparse_pivots : tuple of float
        Pivot thresholds of SuperLU tried in turn until the solve is accurate (default (0.0, 0.1): the
        diagonal pivots first, least fill, then safer ones).
    block_maxiter : int
        GMRES iterations with a structured preconditioner (:func:`~jointdyn.continuation.linalg.preconditioned_by`)
        before it is made anew at the current matrix (default 100).
    block_refresh : int
        A structured solve that needed more iterations than this has the preconditioner made anew at the
        next matrix (default 25).
    """

    small_solve: int = 800
    krylov_rtol: float = 1e-9
    krylov_maxiter: int = 12
    krylov_refresh: int = 8
    sparse_fill: float = 0.25
    sparse_pivots: tuple = (0.0, 0.1)
    block_maxiter: int = 100
    block_refresh: int = 25

    def __post_init__(self) -> None:
        V.positive_int("small_solve", self.small_solve, 0)
        for name in ("krylov_maxiter", "krylov_refresh", "block_maxiter", "block_refresh"):
            V.positive_int(name, getattr(self, name))
        V.positive("krylov_rtol", self.krylov_rtol)
        V.in_range("sparse_fill", self.sparse_fill, 0.0, 1.0, lo_open=True)
        pivots = tuple(V.in_range("sparse_pivots", float(f), 0.0, 1.0) for f in self.sparse_pivots)
        if not pivots:
            raise ValueError("sparse_pivots must hold at least one pivot threshold in [0, 1]")
        object.__setattr__(self, "sparse_pivots", pivots)


@dataclass(frozen=True)
class ContinuationOptions:
    """Every number of the step control (NLvib's ``Sopt`` is the model), with its default.

    Units: the unknowns y, the parameter lam and the residual are those
    the caller passes, scaled so that a unit change is comparable in every
    component (harmonic balance scales y by fy/kt, R by max(F1, fy)); the
    arc length s is measured in them.

    Attributes
    ----------
    ds : float
        First arc-length step (default 0.05).
    ds_min, ds_max : float
        Smallest and largest step (defaults 1e-6, 0.1); below ``ds_min`` a failed corrector ends
        the branch (after the jumps below).
    ds_max_rel : float
        Where the unknowns are large, the largest step is this fraction of
        their norm instead of ``ds_max`` (a response growing without bound
        is followed in as many steps per decade as a small one; default 0.02).
    max_points : int
        Bound on the points of a branch (>= 1; default 2000).
    tol : float
        Newton converged when max |R| (and the arc-length constraint) is
        at most this, at the returned point (default ``config.CONT_TOL``, 1e-9, which harmonic
        balance also uses for a single solution).
    max_iter : int
        Newton iterations per correction (default 12).
    predictor : {"tangent", "secant"}
        Direction of the predictor (default "tangent").
    start_extrapolation : float or None
        The corrector starts from the cubic Hermite extrapolation of the
        last two points and their unit tangents, moved onto the
        corrector's hyperplane ``d^T (v - u_pred) = 0`` (so it converges
        to the same point as from ``u_pred``), when the step is at most
        this many times the distance between those points and both were
        reached along the curve (not by a jump or a corner pass); where
        Newton fails from there it is tried again from ``u_pred``.
        0 or None (the default: the solver decides; harmonic balance sets
        :data:`START_EXTRAPOLATION` where every contact law has a smooth force):
        always from ``u_pred``.
    target_iter : int
        Newton iterations aimed at per correction: the step is multiplied
        by ``grow`` after a correction in fewer (``<= target_iter - 1``),
        by ``shrink`` after one in more (default 4).
    grow, shrink : float
        Step factors of that rule (> 1 and in (0, 1); defaults 1.6, 0.6).
    turn_cos, turn_shrink : float
        After the unit tangent turned by more than arccos(turn_cos) between
        two points, the step is multiplied by ``turn_shrink`` (folds and
        bends are resolved; defaults 0.985, about 10 degrees, and 0.5).
    reject_shrink : float
        Step factor after a rejected step (default 0.5).
    line_search_steps : int
        Trial steps of the damped Newton line search (full step, then
        halved), after which the iteration counts as failed (default 9).
    max_evals_factor : int
        With a step above ``corner_ds``, the corrector gives up after
        ``max_evals_factor * target_iter`` residual evaluations (a step
        that needs many damped iterations is better retried smaller; default 2).
    corner_ds : float
        Below this step a sharp turn or a long correction is accepted as a
        corner of a piecewise-smooth branch (onset of slip); above it such
        a step is rejected as a possible jump to another branch (default 2e-3).
    corner_shrink : float
        Step factor after such a rejection (not below ``corner_ds``; default 0.25: a step
        accepted only at corner size is reached in fewer rejections).
    min_tangent_dot : float
        Above ``corner_ds``, a step whose new unit tangent has a dot
        product with the previous one below this is rejected (default 0.5: a turn by more than
        60 degrees).
    max_distance : float
        Above ``corner_ds``, a step whose corrector moved farther than
        ``max_distance * ds`` from the predicted point is rejected (default 2.0).
    jump_fractions : tuple of float
        Newton at fixed lam tried this far beyond the last point (fractions
        of the parameter range) when the corrector failed at ``ds_min``
        (default (1e-4, 1e-3, 1e-2)).
    max_jumps : int
        Bound on those jumps per branch (default 5).
    jump_tangent_min : float
        A jump's guess follows the tangent when |t_lam| exceeds this (else the last point's
        unknowns; default 1e-3).
    max_dlam : float
        Largest change of lam between consecutive points (inf: none, the default).
    chord_tol : float
        Largest deviation between the straight line joining consecutive
        points and the curve, in the plane (lam, observable), when
        :func:`continuation` is given an ``observe`` function (inf: none). Default 0.005: in
        harmonic balance the plane is gamma and the logarithm of the norm of the response DOF's
        harmonics, so half a percent of the amplitude or 0.005 in gamma; measured against the
        reported amplitude the chords stay within 1 % (``tests/test_hb_trust.py``).
    stall_points, stall_ratio : int, float
        The branch stops as failed where, over the last ``stall_points``
        points, the distance from the first to the last is below
        ``stall_ratio`` times the path through them (it goes back and
        forth); those points are dropped (defaults 100, 1e-6: such a stall measures about
        1e-14, Jenkins at eta 10, beta 1000, 7 x 128 samples; the zigzags at the non-smooth
        corners of branches that do get through stay above 6e-4, Jenkins with separation on the
        grid of docs/hb-robustness.md).
    refine_iter, refine_stol, refine_gtol : int, float, float
        Refinement of a maximum along a branch (:func:`~jointdyn.continuation.post.refine_maximum`):
        at most ``refine_iter`` corrections, until the bracket is ``refine_stol`` of its first width
        or the observable varies by at most ``refine_gtol`` across it (defaults 20, 1e-4, 1e-7; in
        harmonic balance the observable is log q, so 1e-7 is a relative 1e-7 of the amplitude).
    linear : LinearSolveOptions
        How the bordered systems (Newton corrections, tangents) are solved (default
        ``LinearSolveOptions()``).
    """

    ds: float = 0.05
    ds_min: float = 1e-6
    ds_max: float = 0.1
    ds_max_rel: float = 0.02
    max_points: int = 2000
    tol: float = config.CONT_TOL
    max_iter: int = 12
    predictor: str = "tangent"
    start_extrapolation: float | None = None
    target_iter: int = 4
    grow: float = 1.6
    shrink: float = 0.6
    turn_cos: float = 0.985
    turn_shrink: float = 0.5
    reject_shrink: float = 0.5
    line_search_steps: int = 9
    max_evals_factor: int = 2
    corner_ds: float = 2e-3
    corner_shrink: float = 0.25
    min_tangent_dot: float = 0.5
    max_distance: float = 2.0
    jump_fractions: tuple = (1e-4, 1e-3, 1e-2)
    max_jumps: int = 5
    jump_tangent_min: float = 1e-3
    max_dlam: float = math.inf
    chord_tol: float = 0.005
    stall_points: int = 100
    stall_ratio: float = 1e-6
    refine_iter: int = 20
    refine_stol: float = 1e-4
    refine_gtol: float = 1e-7
    linear: LinearSolveOptions = LinearSolveOptions()

    def __post_init__(self) -> None:
        for name in ("ds", "ds_min", "ds_max", "ds_max_rel", "tol", "grow", "max_distance", "corner_ds"):
            V.positive(name, getattr(self, name))
        for name in ("max_dlam", "chord_tol"):
            if not getattr(self, name) > 0:  # inf allowed (no bound)
                raise ValueError(f"{name} must be > 0 (inf: no bound), got {getattr(self, name)!r}")
        for name in ("max_points", "max_iter", "target_iter", "line_search_steps", "max_evals_factor",
                     "stall_points", "refine_iter"):
            V.positive_int(name, getattr(self, name))
        V.positive_int("max_jumps", self.max_jumps, 0)
        for name in ("shrink", "turn_shrink", "reject_shrink", "corner_shrink"):
            V.in_range(name, getattr(self, name), 0.0, 1.0, lo_open=True, hi_open=True)
        for name in ("turn_cos", "min_tangent_dot"):
            V.in_range(name, getattr(self, name), -1.0, 1.0)
        V.nonnegative("jump_tangent_min", self.jump_tangent_min)
        V.positive("refine_stol", self.refine_stol)
        V.nonnegative("refine_gtol", self.refine_gtol)
        if not isinstance(self.linear, LinearSolveOptions):
            raise ValueError(f"linear must be a LinearSolveOptions, got {type(self.linear).__name__}")
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
