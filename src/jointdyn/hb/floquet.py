"""The stability of harmonic-balance solutions of a problem: one dispatcher for every solver.

A branch (:mod:`jointdyn.hb.branch`), a single solution
(:func:`jointdyn.hb.frc.harmonic_balance`) and the tests ask the same
question of an :class:`~jointdyn.hb.problem.HBProblem`: the Floquet
exponents of the periodic solution with Jacobian JX at w, by the method
that :meth:`StabilityOptions.method_for <jointdyn.hb.stability_options.StabilityOptions.method_for>`
gives for the size of Hill's companion matrix (2 n (2H+1) rows, n the
structure's DOFs):

- ``dense``: every eigenvalue of Hill's matrix (:mod:`jointdyn.hb.stability`),
  on the full Jacobian (a condensed problem's recovered on all DOFs,
  :meth:`~jointdyn.hb.condense.CondensedHBProblem.full_jacobian`);
- ``arnoldi``: the exponents nearest the imaginary axis by shift-invert
  Arnoldi (:mod:`jointdyn.hb.hill_arnoldi`), a condensed problem's through
  its condensed form (:mod:`jointdyn.hb.hill_condensed`, nothing of the full
  size built);
- ``none``: not computed (growth NaN).

A point is stable when its growth max Re(s) / w is at most
``StabilityOptions.rtol``; a growth between ``rtol`` and ``confirm`` is
decided by the time-domain period map (:func:`confirmed_stability`), for
branches and single solutions alike.
"""

from __future__ import annotations

import math

import numpy as np

from .._threads import blas_threads
from ..damping import dense_damping
from .stability import hill_growth, hill_stability
from .stability_options import StabilityOptions

__all__ = ["companion_rows", "confirmed_stability", "growths", "point_stability", "stability_method"]


def companion_rows(problem) -> int:
    """Rows of Hill's companion matrix of ``problem``: 2 n (2H+1), n the DOFs of its whole structure."""
    return 2 * problem.system.ndof * problem.nh


def stability_method(problem, options: StabilityOptions) -> str:
    """``dense``, ``arnoldi`` or ``none``: the method ``options`` choose for ``problem``'s size."""
    return options.method_for(companion_rows(problem))


def _matrices(problem):
    return problem.system.M, dense_damping(problem.system.C)


def _dense_growths(problem, JXs, ws, options: StabilityOptions) -> np.ndarray:
    if problem.condensed:
        JXs = np.array([problem.full_jacobian(J, w) for J, w in zip(JXs, ws)])
    M, C = _matrices(problem)
    return hill_growth(JXs, M, C, ws, problem.H, options)


def _arnoldi(problem, JX, w: float, options: StabilityOptions):
    """:class:`~jointdyn.hb.hill_arnoldi.ArnoldiExponents` of one point (Arnoldi's modules imported only here)."""
    if problem.condensed:
        from .hill_condensed import condensed_hill_exponents

        return condensed_hill_exponents(problem, JX, w, options)
    from .hill_arnoldi import hill_arnoldi_exponents

    M, C = _matrices(problem)
    return hill_arnoldi_exponents(JX, M, C, w, problem.H, options)


def growths(problem, JXs, ws, options: StabilityOptions, method: str | None = None) -> np.ndarray:
    """max Re(s) / w of the Floquet exponents of many points of ``problem``.

    Parameters
    ----------
    problem : HBProblem
        The problem the Jacobians belong to (a condensed one's are condensed).
    JXs : sequence of (N, N) arrays
        dR/dX at each point, N/m (dense for ``dense``; any form the Arnoldi path takes otherwise).
    ws : array_like (points,)
        Angular frequencies, rad/s.
    options : StabilityOptions
    method : str, optional
        :func:`stability_method` of ``problem`` (computed when None).

    Returns
    -------
    ndarray (points,)
        The growth of each point; NaN where ``method`` is ``none``.
    """
    method = stability_method(problem, options) if method is None else method
    ws = np.asarray(ws, dtype=float)
    if method == "none":
        return np.full(ws.size, math.nan)
    if method == "dense":
        return _dense_growths(problem, JXs, ws, options)
    return np.array([_arnoldi(problem, J, float(w), options).growth for J, w in zip(JXs, ws)])


def point_stability(problem, JX, w: float, options: StabilityOptions | None = None):
    """(stable, max Re(s) / w, Floquet multipliers) of one solution of ``problem`` by Hill's criterion.

    The multipliers are all 2n of the dense method, or those of the
    exponents Arnoldi found near the imaginary axis; (False, NaN, empty)
    where the method is ``none``. The marginal growths that
    :func:`confirmed_stability` hands to the period map are not decided
    here (it needs the solution, not only its Jacobian).
    """
    opts = StabilityOptions() if options is None else options
    method = stability_method(problem, opts)
    if method == "none":
        return False, math.nan, np.empty(0, dtype=complex)
    if method == "dense":
        J = problem.full_jacobian(JX, w) if problem.condensed else JX
        M, C = _matrices(problem)
        return hill_stability(np.asarray(J), M, C, w, problem.H, opts)
    with blas_threads():  # ARPACK's BLAS-2 work: 2 OpenBLAS threads on 2 busy cores are slower than one
        found = _arnoldi(problem, JX, w, opts)
    return found.growth <= opts.rtol, found.growth, np.exp(found.exponents * (2.0 * math.pi / w))


def confirmed_stability(problem, X, lam, growth, options: StabilityOptions):
    """(stable, number of monodromy checks): Hill's criterion, with marginal growth decided by the monodromy.

    Hill's method truncated to H harmonics is only approximate where the
    contact force has a corner (the onset of slip of a Jenkins element on
    an otherwise undamped oscillator gives Re(s)/w of a few 1e-6 at
    points whose period map is contracting). A growth between
    ``options.rtol`` and ``options.confirm`` (StabilityOptions) is
    therefore decided by the Floquet multipliers of the time-domain period
    map (:func:`~jointdyn.hb.monodromy.monodromy_multipliers`): unstable
    when one lies outside the unit circle by more than
    ``2 pi options.rtol``. Systems with interfaces keep Hill's criterion there: the
    time-domain period map does not march interfaces yet.

    Parameters
    ----------
    problem : HBProblem
    X : ndarray (points, N)
        Harmonic coefficients of each point, m.
    lam : ndarray (points,)
        The continuation parameter at each point.
    growth : ndarray (points,)
        max Re(s) / w of each point (:func:`growths`).
    options : StabilityOptions
    """
    from .monodromy import monodromy_multipliers

    growth = np.asarray(growth, dtype=float)
    stable = growth <= options.rtol
    if problem.has_interfaces:
        return stable, 0
    marginal = np.flatnonzero(~stable & (growth < options.confirm))
    for i in marginal:
        mu = np.max(np.abs(monodromy_multipliers(problem, X[i], lam[i])))
        stable[i] = mu <= 1.0 + 2.0 * math.pi * options.rtol
    return stable, int(marginal.size)
