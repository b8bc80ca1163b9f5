"""The entry points of harmonic balance: a branch in gamma or in another parameter
(:func:`continue_hb`), the frequency-response curve as a Dataset (:func:`frc_hb`) and one solution at
one frequency (:func:`harmonic_balance`).

They validate the request and hand it to the machinery below them:
:mod:`jointdyn.hb.discretisation` (the automatic choice of harmonics and
samples), :mod:`jointdyn.hb.branch` (one branch at a fixed discretisation,
the solution at one point and the homotopy start), :mod:`jointdyn.hb.export`
(the Dataset) and :mod:`jointdyn.hb.results` (what is returned). See
:mod:`jointdyn.hb.branch` for the unbounded responses and the jumps.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _validate as V
from .. import config
from ..continuation import START_EXTRAPOLATION, ContinuationOptions, make_options
from ..systems import System
from .branch import _forcing_problem, _Request, solve_point
from .discretisation import adaptive_branch
from .export import branch_dataset
from .levels import AUTO, Discretisation, Level, check_memory
from .options import HBOptions
from .options import hb_options as _hb_options
from .parameters import GAMMA, parameter_named
from .problem import HBProblem, reference_scales, stuck_stiffness
from .floquet import confirmed_stability, point_stability
from .results import HBBranch, HBSolution, SolveStatus
from .stability_options import StabilityOptions, stability_options

__all__ = ["continue_hb", "frc_hb", "harmonic_balance", "check_mean_position"]

def check_mean_position(system: System) -> None:
    """ValueError where the mean position of ``system`` is not defined with every contact stuck and every
    normal spring (of the contacts and of the interfaces' pairs closed at rest) closed.

    Harmonic balance starts from that static stiffness. A DOF held only by
    stiffnesses many decades apart is ill-conditioned, not free: those
    stiffnesses are named; a DOF held only by pairs open at rest (preload 0)
    names such a pair. A structure held only through the contacts (K + kn
    singular with the tangential contacts free, K + kt + kn not) is
    accepted: harmonic balance then restarts the laws at the reference
    displacement, the preloaded static state, so that a stuck contact holds
    the mean position (:func:`jointdyn.hb.problem.held_by_contacts`). A
    free-free structure (K + kt + kn itself has rigid-body modes, which no
    spring holds: the parts of a bolted beam hung on bungees) is accepted:
    harmonic balance fixes the rigid-body part of the mean at zero
    (:func:`jointdyn.hb.problem.mean_gauge`). A DOF joined to nothing (its
    row of K + kt + kn zero: a forgotten stiffness far more often than a
    free body) is refused, naming it.
    """
    from ..systems import loose_dofs, rigid_mode_dof

    K = stuck_stiffness(system)  # with the normal springs of the contacts and pairs closed at rest
    dof = rigid_mode_dof(K)
    if dof is None:
        return
    if system.ndof <= config.SYSTEM_DENSE_CHECK_MAX_DOF:  # beyond, the null vectors are not computed
        _check_null_space(system, K, dof)
    loose = loose_dofs(K)
    if loose.size:
        raise ValueError(f"the structure has a rigid-body mode even with every contact stuck and every normal "
                         f"spring closed (mostly DOF {int(loose[0])}: held by nothing, joined to no other DOF: its "
                         "row of K + kt + kn is zero), so its mean position is not unique; harmonic balance "
                         "needs one: give that DOF a stiffness in K, or use the time domain (--method time)")


def _check_null_space(system: System, K: np.ndarray, dof: int) -> None:
    """ValueError where the near-null space of the static stiffness ``K`` (N/m) is held by a stiffness many
    decades below the largest (ill-conditioned) or only by pairs open at rest; ``dof`` the DOF named."""
    from ..systems import static_springs

    lam, vecs = np.linalg.eigh(K)
    vecs = vecs[:, lam <= config.SYSTEM_RIGID_MODE_RTOL * abs(lam[-1])]
    springs = static_springs(system)
    holders = [(key, k) for key, k, b in springs if np.abs(b @ vecs).max() > 1e-6]
    if holders:  # held, by a stiffness many decades below the largest: ill-conditioned
        key, k = min(holders, key=lambda h: h[1])
        top_key, top = max([("K", float(np.max(np.abs(system.K))))] + [(sp[0], sp[1]) for sp in springs],
                           key=lambda h: h[1])
        raise ValueError(f"the static stiffness with every contact stuck and every normal spring closed is "
                         f"ill-conditioned, not singular: DOF {dof} is held by {key} = {k:.4g} N/m, {k / top:.3g} "
                         f"times {top_key} = {top:.4g} N/m, below the ratio {config.SYSTEM_RIGID_MODE_RTOL:g} that "
                         f"double precision resolves; bring {key} and {top_key} within that ratio, or use the time "
                         "domain (--method time)")
    opened = [key for key, _, b in static_springs(system, open_pairs=True) if np.abs(b @ vecs).max() > 1e-6]
    if opened:  # held only by pairs that touch without load: the mean is not unique while they are open
        raise ValueError(f"DOF {dof} is held only by {opened[0]}, a pair open at rest (preload 0: it touches "
                         "without load), so its mean position is not unique while the pair is open and harmonic "
                         "balance has no start; give the pair a preload > 0 or that DOF a stiffness in K, or use "
                         "the time domain (--method time)")


def continue_hb(system: System, start: float, stop: float, *, parameter="gamma", gamma: float | None = None,
                harmonics: int | str = AUTO, samples: int | str = AUTO,
                max_step: float | None = None, response_dof: int | None = None,
                options: ContinuationOptions | None = None, backward_after_unbounded: bool = True,
                progress: bool | None = None, condense: bool | None = None,
                stability: StabilityOptions | bool | None = None, hb_options: HBOptions | None = None,
                **overrides) -> HBBranch:
    """Continue harmonic-balance solutions in a scalar parameter.

    Parameters
    ----------
    system : System
        Structure with contacts and forcing f sin(w t); normal loads
        N_c = n0 + n1 sin(w t + delta).
    start, stop : float
        Parameter range (start != stop); the branch starts at ``start``
        from the linear solution with stuck contacts.
    parameter : str or HBParameter
        ``gamma``, ``f1``, ``eta``, ``n0``, ``delta`` or a parameter object
        (:mod:`jointdyn.hb.parameters`, e.g. a ``SystemParameter`` for any
        value that builds the System).
    gamma : float, optional
        w / w0, required unless ``parameter == "gamma"``.
    harmonics : int or "auto"
        Highest harmonic H (>= 1); harmonics 0..H are used. ``"auto"``
        (default): start at ``config.HB_HARMONICS``; every refined peak is
        solved again with 2H + 1 harmonics and, where its amplitude changes
        by more than ``config.HB_AUTO_RTOL``, the branch is computed again
        with more (up to ``hb_options.auto_max_harmonics``).
    samples : int or "auto"
        AFT time samples per period (>= 2H + 2). ``"auto"`` (default):
        start at ``config.HB_SAMPLES`` and double the same way, checked
        with 2 Ns samples (up to ``hb_options.auto_max_samples``). The
        levels used and the check are in ``HBBranch.discretisation``; a
        converged branch costs two extra solves per peak.
    max_step : float, optional
        Largest change of the parameter between consecutive points (in its
        own unit, e.g. a gamma grid spacing); default
        ``hb_options.max_gamma_step`` when the parameter is gamma, none
        beyond the chord bound otherwise.
    response_dof : int, optional
        DOF whose amplitude the step control follows and the peaks report
        (default ``system.response_dof``).
    options : ContinuationOptions, optional
        Step control, in scaled units (unknowns in units of fy/kt of the
        first contact, parameter in its own scale, residual force /
        max(F1, fy)); keyword arguments override its fields (``ds``,
        ``ds_max``, ``max_points`` (per segment), ``chord_tol``, ...). ``chord_tol``
        bounds the distance between the straight lines joining the points
        and the curve in the plane (parameter, log q): 0.005 is half a
        percent of the amplitude.
    backward_after_unbounded : bool
        After a stop short of ``stop`` (unbounded, failed, turned back),
        continue a second segment from ``stop`` backwards, so that both
        ends of the range are covered.
    progress : bool, optional
        Show the progress of each stage (the continuation over the range,
        each level of an automatic choice of harmonics and samples, the
        stability of the points): tqdm bars on a terminal, plain lines on
        stderr elsewhere; the bar over the range only on a terminal when
        None; False: nothing.
    condense : bool, optional
        Condense the problem exactly onto the contact DOFs
        (:mod:`jointdyn.hb.condense`); None chooses by size
        (:func:`~jointdyn.hb.condense.use_condensed`).
    stability : StabilityOptions or False, optional
        How the Floquet exponents are computed (default
        :class:`~jointdyn.hb.stability_options.StabilityOptions`: dense Hill
        up to its ``dense_max_rows`` companion rows, shift-invert Arnoldi
        beyond); False: not computed (``HBBranch.stability`` is
        ``not-computed``, growth NaN).
    hb_options : HBOptions, optional
        Harmonic balance's own numbers (:class:`~jointdyn.hb.options.HBOptions`: the Jacobian's form,
        the bounds of the automatic discretisation, Newton iterations, the end of a branch, folds,
        peaks, the condensation; None: the defaults).

    Returns
    -------
    HBBranch
        With its status (``complete`` only when the range is covered),
        per-point status, refined peaks and uncovered parts of the range.
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    reference_scales(system)
    disc = Discretisation.of(harmonics, samples)
    hbo = _hb_options(hb_options)
    check_memory(system, disc, options=hbo)
    check_mean_position(system)
    par = parameter_named(parameter)
    start = V.finite(par.name + " start", start)
    stop = V.finite(par.name + " stop", stop)
    if start == stop:
        raise ValueError(f"{par.name} range must not be empty (start == stop == {start!r})")
    par.check_range(start, stop)
    dof = system.response_dof if response_dof is None else V.positive_int("response_dof", response_dof, 0)
    if dof >= system.ndof:
        raise ValueError(f"response_dof must be in [0, {system.ndof - 1}], got {dof!r}")
    opt = make_options(options, overrides)
    V.positive_int("max_points", opt.max_points, 2)
    if opt.start_extrapolation is None and all(c.law.smooth_force for c in system.contacts):
        # every force smooth at the onset of slip: the corrector starts from the branch's extrapolation
        opt = dataclasses.replace(opt, start_extrapolation=START_EXTRAPOLATION)
    if max_step is None and par is GAMMA:
        max_step = hbo.max_gamma_step
    if max_step is not None:
        V.positive("max_step", max_step)
    req = _Request(system=system, start=start, stop=stop, parameter=par, gamma=gamma, max_step=max_step, dof=dof,
                   options=opt, backward=backward_after_unbounded, progress=progress, condense=condense,
                   stability=stability_options(stability), hb=hbo)
    return adaptive_branch(req, disc)


def frc_hb(system: System, gamma_start: float, gamma_stop: float, *, harmonics: int | str = AUTO,
           samples: int | str = AUTO, max_step: float | None = None, response_dof: int | None = None,
           options: ContinuationOptions | None = None, progress: bool | None = None, condense: bool | None = None,
           stability: StabilityOptions | bool | None = None, hb_options: HBOptions | None = None, **overrides):
    """Frequency-response curve by harmonic balance and arc-length continuation.

    Harmonics 0..H of every DOF (normalised time tau = w t), contact forces
    by alternating frequency-time with ``samples`` per period (re-contact
    instants located exactly between samples), exact Jacobians by forward
    mode through the march of the contact laws, stability by Hill's method,
    folds as turning points, peaks refined between the points. See
    :func:`continue_hb` for the parameters.

    Parameters
    ----------
    system : System
    gamma_start, gamma_stop : float
        Range of gamma = w / w0 (> 0, distinct); the branch starts at
        ``gamma_start`` from the stuck-contact linear solution.
    harmonics : int or "auto"
        H >= 1, or chosen from the convergence of the peaks (default; see
        :func:`continue_hb`).
    samples : int or "auto"
        >= 2H + 2, or chosen likewise (default).
    max_step : float, optional
        Largest gamma spacing between consecutive points (e.g. the STEP of
        a gamma grid; default ``hb_options.max_gamma_step``, 0.02); the chord
        bound (``chord_tol``) applies in any case.
    response_dof : int, optional
        DOF whose response is reported (default ``system.response_dof``).
    options : ContinuationOptions, optional
        Step control; keyword arguments override its fields (``ds``,
        ``ds_max``, ``max_points``, ``chord_tol``, ``predictor``, ...).
    condense : bool, optional
        Condense exactly onto the contact DOFs (None: by size; see
        :func:`continue_hb`).
    stability : StabilityOptions or False, optional
        How the stability is computed, or False for none (see :func:`continue_hb`).
    hb_options : HBOptions, optional
        Harmonic balance's own numbers (see :func:`continue_hb`).

    Returns
    -------
    xarray.Dataset
        Dims ``point`` and ``peak``; variables ``gamma``, ``amplitude_q``,
        ``amplitude_m``, ``offset_m``, ``max_abs_m``, ``stable``, ``fold``,
        ``point_status``, the refined peaks (``peak_gamma``,
        ``peak_amplitude_q``, ...) and more (see :func:`branch_dataset`);
        attrs ``status`` (``complete`` only when the range is covered;
        ``unbounded``, ``failed``, ``turned-back``, ``max-points``),
        ``message``, ``uncovered``, ``harmonics``, ``samples`` and the
        counters (``counter_*``). A branch that is not complete is never
        silent: its status, message and the ``stopped`` point say where.
    """
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    br = continue_hb(system, V.positive("gamma_start", gamma_start), V.positive("gamma_stop", gamma_stop),
                     parameter=GAMMA, harmonics=harmonics, samples=samples, max_step=max_step,
                     response_dof=response_dof, options=options, progress=progress, condense=condense,
                     stability=stability, hb_options=hb_options, **overrides)
    return branch_dataset(br)


def harmonic_balance(system: System, gamma: float, *, harmonics: int = config.HB_HARMONICS,
                     samples: int = config.HB_SAMPLES, guess=None, response_dof: int = 0,
                     tol: float = config.CONT_TOL, max_iter: int | None = None,
                     condense: bool | None = None, stability: StabilityOptions | bool | None = None,
                     hb_options: HBOptions | None = None) -> HBSolution:
    """Solve the HB equations at one frequency by damped Newton.

    Parameters
    ----------
    system : System
    gamma : float
        w / w0 (> 0).
    harmonics, samples : int
        H >= 1 and AFT samples per period >= 2H + 2.
    guess : ndarray, optional
        Starting coefficients (default: the stuck-contact linear solution;
        if Newton fails from it, a continuation in the forcing amplitude
        from ``hb_options.homotopy_start`` F1 to F1 at this gamma).
    response_dof : int
        DOF reported in the amplitudes.
    tol : float
        Tolerance on the residual scaled by max(F1, fy).
    max_iter : int, optional
        Newton iterations (default ``hb_options.solve_max_iter``, 50).
    condense : bool, optional
        Condense exactly onto the contact DOFs (None: by size; see
        :func:`continue_hb`). The unknowns X (and ``guess``) are then the
        harmonics of the retained DOFs ``problem.dofs``; stability is the full
        structure's (dense Hill on its Jacobian, or Arnoldi through the condensed
        form, :mod:`jointdyn.hb.hill_condensed`).
    stability : StabilityOptions or False, optional
        How the stability is computed, or False for none (see
        :func:`continue_hb`); by Arnoldi, ``multipliers`` are those of the
        exponents found near the imaginary axis.
    hb_options : HBOptions, optional
        Harmonic balance's own numbers (see :func:`continue_hb`); here the Newton iterations, the
        homotopy start, the Jacobian's form and the condensation.

    Returns
    -------
    HBSolution
        ``status`` ``not-converged`` (``status.ok`` False) when Newton failed (no exception).
    """
    gamma = V.positive("gamma", gamma)
    if not isinstance(system, System):
        raise ValueError("system must be a jointdyn.System")
    hbo = _hb_options(hb_options)
    max_iter = hbo.solve_max_iter if max_iter is None else max_iter
    check_memory(system, Discretisation(Level.of(harmonics, samples), False, False), options=hbo)
    check_mean_position(system)
    # the forcing amplitude as the (fixed) parameter: a problem at this gamma
    problem = _forcing_problem(system, gamma, harmonics, samples, condense, hbo)
    X, ok, it = solve_point(problem, gamma, None if guess is None else V.finite_array("guess", guess), tol, max_iter)
    return _make_solution(problem, X, ok, it, response_dof, stability_options(stability))


def _make_solution(problem: HBProblem, X, converged, iterations, response_dof, opts=None) -> HBSolution:
    """HBSolution at X: residual, amplitudes of ``response_dof`` and Hill stability."""
    lam = problem.f1_ref
    ev = problem.evaluate(X, lam)
    amp, off, mx = problem.amplitudes(X, response_dof, lam)
    opts = StabilityOptions() if opts is None else opts
    stable, growth, mult = point_stability(problem, ev.JX, problem.omega(lam), opts)
    if converged and not stable and math.isfinite(growth):  # a marginal growth: the period map, as on a branch
        stable = bool(confirmed_stability(problem, X[None, :], np.array([lam]), np.array([growth]), opts)[0][0])
    status = SolveStatus.CONVERGED if converged else SolveStatus.NOT_CONVERGED
    return HBSolution(problem=problem, X=X, status=status, iterations=int(iterations),
                      residual_norm=float(np.max(np.abs(ev.R))), amplitude_m=amp, offset_m=off, max_abs_m=mx,
                      stable=stable, growth=growth, multipliers=mult, aft_info=ev.info)
