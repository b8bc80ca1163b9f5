"""Continuation parameters of harmonic balance: how a scalar p enters the problem.

A parameter object tells :class:`~jointdyn.hb.problem.HBProblem` what a
value p of the parameter fixes, with the exact derivative along p:

* ``frequency(problem, p) -> (w, dw/dp)``: forcing angular frequency, rad/s;
* ``forcing(problem, p) -> (f, df/dp)``: forcing amplitudes per DOF (N),
  ``df/dp`` None when p does not enter the forcing;
* ``contact_loads(problem, p) -> (coefficients, derivatives)``: per
  contact the normal-load coefficients ``(n0, n1, delta)`` of
  N = n0 + n1 sin(w t + delta) (N, N, rad) and their derivatives along p
  (None when p does not enter the loads); the problem turns them into
  samples over the period and their derivatives (one place, see
  ``problem.py``);
* ``scale(problem, start)``: the unit of p in which the continuation steps
  (a unit change of the scaled parameter is comparable with a change of
  the response by fy/kt);
* ``check_range(start, stop)``: ValueError naming the parameter when the
  range is outside what the parameter allows;
* ``enters_forcing``, ``enters_loads``: whether p enters the forcing or
  the loads (what does not depend on p is built once);
* ``needs_gamma``: True when the frequency is not the parameter (the
  problem then takes gamma = w / w0 as a fixed value).

Built-ins (exact derivatives): :data:`GAMMA` (w / w0), :data:`F1` (forcing
amplitude, the force vector scaled so that its largest entry is f1),
:data:`ETA` (N1 / N0 of every contact), :data:`N0` (static normal load of
every contact, eta kept), :data:`DELTA` (phase of every contact's normal
load, in degrees like every phase of the API). :class:`SystemParameter` continues in any value that builds a
:class:`~jointdyn.System` (a friction coefficient, a stiffness, a mass):
its derivative dR/dp is a central difference of the residual, not exact.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

import numpy as np

from .. import _validate as V

__all__ = ["HBParameter", "Gamma", "F1Amplitude", "LoadRatio", "StaticLoad", "LoadPhase", "SystemParameter",
           "GAMMA", "F1", "ETA", "N0", "DELTA", "PARAMETERS", "parameter_named"]

class HBParameter:
    """Base of the continuation parameters of harmonic balance (protocol in the module docstring).

    Defaults describe a parameter that enters neither the frequency, the
    forcing nor the loads; subclasses override what their parameter moves.
    """

    name: str = "p"
    enters_forcing: bool = False
    enters_loads: bool = False
    needs_gamma: bool = True

    def frequency(self, problem, p: float):
        """(w, dw/dp): forcing angular frequency (rad/s) at p and its derivative."""
        return problem.gamma_fixed * problem.w0, 0.0

    def forcing(self, problem, p: float):
        """(f, df/dp): forcing amplitudes per DOF (N) at p, derivative or None."""
        return problem.f_dir * problem.f1_ref, None

    def contact_loads(self, problem, p: float):
        """(coefficients, derivatives): ``(nc, 3)`` rows (n0, n1, delta), derivative rows or None."""
        return problem.load_coefficients, None

    def scale(self, problem, start: float) -> float:
        """Unit of p for the continuation's scaled parameter."""
        return 1.0

    def check_range(self, start: float, stop: float) -> None:
        """ValueError naming the parameter when [start, stop] is not allowed (finite by default)."""
        V.finite(self.name + " start", start)
        V.finite(self.name + " stop", stop)

    def __repr__(self) -> str:
        return f"<HB parameter {self.name}>"


class Gamma(HBParameter):
    """gamma = w / w0 (> 0): w = gamma w0, dw/dgamma = w0."""

    name = "gamma"
    needs_gamma = False

    def frequency(self, problem, p):
        return p * problem.w0, problem.w0

    def check_range(self, start, stop):
        V.positive("gamma_start", start)
        V.positive("gamma_stop", stop)


class F1Amplitude(HBParameter):
    """Forcing amplitude f1 (N, > 0): f = f1 f_dir, f_dir the force vector over its largest entry."""

    name = "f1"
    enters_forcing = True

    def forcing(self, problem, p):
        return problem.f_dir * p, problem.f_dir

    def scale(self, problem, start):
        return max(problem.f1_ref, 1.0)

    def check_range(self, start, stop):
        V.positive("f1 start", start)
        V.positive("f1 stop", stop)


class LoadRatio(HBParameter):
    """eta = N1 / N0 (>= 0) of every contact: n1 = eta n0."""

    name = "eta"
    enters_loads = True

    def contact_loads(self, problem, p):
        co = problem.load_coefficients.copy()
        d = np.zeros_like(co)
        co[:, 1] = p * co[:, 0]
        d[:, 1] = co[:, 0]
        return co, d

    def check_range(self, start, stop):
        V.nonnegative("eta start", start)
        V.nonnegative("eta stop", stop)


class StaticLoad(HBParameter):
    """Static normal load n0 (N, > 0) of every contact, eta = n1 / n0 kept."""

    name = "n0"
    enters_loads = True

    def contact_loads(self, problem, p):
        co = problem.load_coefficients.copy()
        d = np.zeros_like(co)
        eta = co[:, 1] / co[:, 0]
        co[:, 0] = p
        co[:, 1] = eta * p
        d[:, 0] = 1.0
        d[:, 1] = eta
        return co, d

    def scale(self, problem, start):
        return max(problem.load_coefficients[0, 0], 1.0)

    def check_range(self, start, stop):
        V.positive("n0 start", start)
        V.positive("n0 stop", stop)


class LoadPhase(HBParameter):
    """Phase delta of every contact's normal load, degrees (the parameter
    value; the load coefficients hold it in radians)."""

    name = "delta"
    enters_loads = True

    def contact_loads(self, problem, p):
        co = problem.load_coefficients.copy()
        d = np.zeros_like(co)
        co[:, 2] = np.deg2rad(p)
        d[:, 2] = np.pi / 180.0
        return co, d


GAMMA = Gamma()
F1 = F1Amplitude()
ETA = LoadRatio()
N0 = StaticLoad()
DELTA = LoadPhase()

#: the built-in parameters by name
_BUILTIN = {p.name: p for p in (GAMMA, F1, ETA, N0, DELTA)}
#: names of the built-in parameters
PARAMETERS = tuple(_BUILTIN)


def parameter_named(parameter) -> HBParameter:
    """The parameter object for a built-in name, or ``parameter`` itself if it is one."""
    if isinstance(parameter, HBParameter):
        return parameter
    return _BUILTIN[V.choice("parameter", parameter, PARAMETERS)]


class _FixedFrequency(HBParameter):
    """The system as given, at a fixed angular frequency w (the sub-problems of :class:`SystemParameter`)."""

    name = "fixed"
    needs_gamma = False

    def __init__(self, w: float):
        self.w = float(w)

    def frequency(self, problem, p):
        return self.w, 0.0


@dataclass(frozen=True, eq=False)
class SystemParameter(HBParameter):
    """Any value that builds a System: ``build(p)`` returns the System at p.

    The forcing frequency is fixed (w = gamma w0, w0 of the System given
    to the problem, normally ``build(start)``); everything else (matrices,
    contacts, laws, forcing, loads) is that of ``build(p)``. The residual
    at p is the harmonic-balance residual of ``build(p)``; its derivative
    along p is the central difference
    ``(R(p + h) - R(p - h)) / (2 h)`` with ``h = fd_step``
    times ``scale_value`` (or |p|; error O(h^2) plus rounding of order
    eps |R| / h), the
    only derivative of harmonic balance that is not exact: use a built-in
    parameter where one exists.

    Parameters
    ----------
    name : str
        Name of the parameter (e.g. ``"mu"``), used in messages and as the
        Dataset variable.
    build : callable
        ``build(p) -> System`` with the same number of DOFs and contacts
        for every p.
    scale_value : float, optional
        Unit of p for the continuation and the difference step (default:
        |start| for the continuation, |p| for the step; 1 at 0).
    lower, upper : float
        Allowed range of p (default unbounded).
    fd_step : float
        Central-difference step of dR/dp relative to the scale of p (default 6e-6: about eps^(1/3),
        which balances the O(h^2) error and rounding; in (0, 1)).
    """

    name: str = field()  # no default (the base class's "p" is not one)
    build: Callable = field()
    scale_value: float | None = None
    lower: float = -math.inf
    upper: float = math.inf
    fd_step: float = 6e-6

    def __post_init__(self) -> None:
        V.in_range("fd_step", self.fd_step, 0.0, 1.0, lo_open=True, hi_open=True)

    enters_forcing = True
    enters_loads = True

    def scale(self, problem, start):
        if self.scale_value is not None:
            return V.positive("scale", self.scale_value)
        return abs(start) if start != 0.0 else 1.0

    def check_range(self, start, stop):
        for what, v in (("start", start), ("stop", stop)):
            V.in_range(f"{self.name} {what}", v, self.lower, self.upper)

    def step(self, p: float) -> float:
        """Central-difference step h at p: ``fd_step`` times the scale (or |p|, or 1)."""
        unit = self.scale_value if self.scale_value is not None else (abs(p) if p != 0.0 else 1.0)
        return self.fd_step * unit
