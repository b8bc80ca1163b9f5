"""Monodromy check of harmonic-balance solutions (independent of Hill's method).

:func:`monodromy_multipliers` integrates the equations of motion over one
period from the HB orbit's state at a Poincare section with the RK4 core of
:mod:`jointdyn.dynamics` (the same march as time integration and shooting,
events located inside the steps) and differentiates the period map by
central finite differences in the 2n positions and velocities
(:func:`jointdyn.dynamics.monodromy_matrix`). The contact law states at
the section come from marching each law over a few periods of the HB
displacement.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np

from .. import _validate as V
from .. import config
from ..drivers import march as march_law
from ..fourier import basis, derivative_matrix
from ..kinematics import HarmonicLoad, contact_kinematics, normal_load_samples, tangential_history
from ..laws import MACROSLIP, SEPARATION
from ..systems import System

__all__ = ["monodromy_multipliers"]


def _system_at(problem, f, loads) -> System:
    """The problem's System with the forcing f and contact loads (n0, n1, delta) of a parameter value."""
    s = problem.system
    contacts = tuple(dataclasses.replace(c, normal=HarmonicLoad(n0, n1, math.degrees(dl)))
                     for c, (n0, n1, dl, _) in zip(problem.contacts, loads))  # fmt: skip
    return System(M=s.M, C=s.C, K=s.K, contacts=contacts, force=f, force_phase_deg=s.force_phase_deg)


def _section_phase(problem, X, p) -> float:
    """Phase (rad) of the Poincare section: a sample where every contact is
    open, else where every contact is in macroslip (there the contact state
    holds the least memory), else 0."""
    ev = problem.evaluate(X, p)
    codes = np.array(ev.code).reshape(len(ev.code), -1)
    for target in (SEPARATION, MACROSLIP):
        hit = np.flatnonzero(np.all(codes == target, axis=0))
        if hit.size:
            return 2.0 * np.pi * int(hit[hit.size // 2]) / problem.Ns
    return 0.0


def monodromy_multipliers(problem, X, p, *, steps_per_period: int | None = None, eps: float | None = None,
                          warm_periods: int | None = None, warm_samples: int | None = None,
                          march=None) -> np.ndarray:  # fmt: skip
    """Floquet multipliers from finite differences of the period map.

    Parameters
    ----------
    problem : HBProblem
        The harmonic-balance problem (system, parameter).
    X : ndarray
        HB coefficients of the periodic solution.
    p : float
        Parameter value.
    steps_per_period : int, optional
        RK4 base steps per period (default ``march.steps_per_period``, 256; events and reversals add
        steps); replaces that field.
    eps : float, optional
        Relative perturbation of positions (scaled by the amplitude) and
        velocities (scaled by w times the amplitude); default
        ``dynamics.monodromy.MONODROMY_FD_STEP``.
    warm_periods, warm_samples : int, optional
        Periods of the HB displacement, and samples per period, marched
        through each contact law to obtain the contact state at the section
        (defaults ``config.MONODROMY_WARM_PERIODS``, ``config.MONODROMY_WARM_SAMPLES``).
    march : MarchOptions, optional
        The numbers of the time march that integrates the period map
        (:class:`~jointdyn.dynamics.options.MarchOptions`; None: the defaults).

    Returns
    -------
    ndarray complex (2n,)
        Eigenvalues of the finite-difference monodromy matrix.
    """
    warm = V.positive_int("warm_periods", config.MONODROMY_WARM_PERIODS if warm_periods is None else warm_periods)
    ns = V.positive_int("warm_samples", config.MONODROMY_WARM_SAMPLES if warm_samples is None else warm_samples, 4)
    w, f, loads = problem._split(p)
    system = _system_at(problem, f, loads)
    kin = contact_kinematics(system)
    H, n = problem.H, system.ndof
    Xm = problem.full_coefficients(X, p).reshape(problem.nh, n)
    tau0 = _section_phase(problem, X, p)
    e0 = basis(H, np.array([tau0]))[0]
    x0 = e0 @ Xm
    v0 = w * (e0 @ (derivative_matrix(H) @ Xm))
    tt = tau0 + np.arange(warm * ns + 1) * (2.0 * np.pi / ns)
    xs = basis(H, tt) @ Xm
    U = tangential_history(kin.arrays, np.ascontiguousarray(xs))
    N = normal_load_samples(kin, tt)
    S = np.zeros((len(system.contacts), max([c.law.state_size for c in system.contacts], default=1)))
    for i, c in enumerate(system.contacts):
        s = march_law(c.law, np.ascontiguousarray(U[:, i]), N[i])[3]
        S[i, : s.size] = s
    amp = max(float(np.max(np.abs(xs))), 1e-12)
    from ..dynamics import monodromy_matrix  # the RK4 march of the time-domain layer

    J = monodromy_matrix(system, w, tau0 / w, x0, v0, S, amplitude=amp, eps=eps, steps_per_period=steps_per_period,
                         march=march)
    return np.linalg.eigvals(J)
