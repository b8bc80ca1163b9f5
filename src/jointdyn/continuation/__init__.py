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
* a fold at a corner (turning by more than a right angle while lam turns
  back: no lam beyond the corner holds a point near it) is passed along
  the tangent of the Jacobian just ahead of the corner, on the side where
  that Jacobian holds (points marked ``corner``, the turn counted as a
  fold); a point found by Newton at fixed lam on the part of the branch
  just walked, oriented back along it, is never taken as the way on;
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
(defaults documented there), those of its linear solves of
:class:`LinearSolveOptions` (``ContinuationOptions.linear``). Bordered linear
systems go through LAPACK, except small ones (``LinearSolveOptions.small_solve``
unknowns or fewer), where a compiled Gaussian elimination is faster
(``benchmarks/bench_linalg.py``).

The package reads top to bottom: :mod:`~jointdyn.continuation.options`
(options, statuses, the result), :mod:`~jointdyn.continuation.linalg` (the
bordered systems, the compiled LU :func:`~jointdyn.continuation.linalg.lu_solve`),
:mod:`~jointdyn.continuation.newton` (the damped corrector),
:mod:`~jointdyn.continuation.walk` (the predictor-corrector walk along a
branch) and :mod:`~jointdyn.continuation.post` (turning points, maxima and
their refinement on a computed branch); :mod:`~jointdyn.continuation.progress`
holds a progress bar over the parameter's range and the progress of the stages
after it (a bar on a terminal, plain lines elsewhere).
"""

from .linalg import preconditioned_by
from .newton import newton
from .options import (START_EXTRAPOLATION, ContinuationOptions, ContinuationResult, ContinuationStatus,
                      LinearSolveOptions, make_options)
from .post import local_maxima, refine_maximum, turning_points
from .progress import ParameterProgress, StageProgress, stage_note, stage_progress
from .walk import continuation

__all__ = ["ContinuationOptions", "LinearSolveOptions", "START_EXTRAPOLATION", "ContinuationStatus",
           "ContinuationResult", "continuation", "newton",
           "preconditioned_by", "turning_points", "make_options", "local_maxima", "refine_maximum", "ParameterProgress",
           "StageProgress", "stage_note", "stage_progress"]
