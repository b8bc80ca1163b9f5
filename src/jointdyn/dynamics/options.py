"""What the time domain is asked apart from its system and its frequency: :class:`MarchOptions` (the
numbers of the time march: its steps, their bounds, the reversal splits, the event merge, the re-contact
load, the blow-up factor) and :class:`SteadyStateOptions` (every number of
:func:`~jointdyn.dynamics.steady_state`'s own, with the march it runs in its field ``march``).

The march is shared by :func:`~jointdyn.dynamics.integrate`, the steady states, the time domain's
monodromy (:func:`~jointdyn.dynamics.monodromy.monodromy_matrix`) and harmonic balance's monodromy check
(:func:`~jointdyn.hb.monodromy.monodromy_multipliers`): each takes a :class:`MarchOptions`, the steady
state through ``SteadyStateOptions.march`` and a sweep through ``SweepOptions.steady``."""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

from .. import _validate as V

__all__ = ["MarchOptions", "march_options", "march_with_steps", "SteadyStateOptions", "steady_options"]

#: RK4 is stable for w h up to 2 sqrt(2) (the imaginary-axis bound of its stability region)
_RK4_STABLE_WH = 2.0 * math.sqrt(2.0)


@dataclass(frozen=True)
class MarchOptions:
    """The numbers of the time march (explicit RK4 with exact events, ``dynamics/_core.py``).

    Attributes
    ----------
    steps_per_period : int
        Base RK4 steps per forcing period before events and reversal splits, raised where
        ``max_omega_h`` or ``spring_omega_h`` asks (default 256; >= 4).
    max_omega_h : float
        The steps per period are raised so that w_max h <= this, w_max (rad/s) the stiffest linear mode
        with every contact stuck and every normal spring closed, h (s) the base step; RK4 is stable up
        to w h = 2 sqrt(2) (default 1.0; in (0, 2 sqrt(2)]).
    spring_omega_h : float
        Once a normal spring opens, the run is repeated with the steps refined so that w_max h <= this:
        every re-contact sets the normal DOFs ringing at their own frequency, and RK4 at w h = 1 damps
        that ringing numerically by about 0.3 % of its energy per step, which shows in the energy
        balance (measured on the coupled paper damper, eta 1.5: 6e-3 at w h = 0.85, 2e-6 at 0.21)
        (default 0.3; in (0, ``max_omega_h``]).
    max_splits : int
        At most this many splits of one grid step at velocity reversals of the contacts and state
        changes (default 4; >= 0).
    event_merge : float
        A separation or re-contact instant (or a slope change of a sampled load) closer than this
        fraction of a base step to a grid point moves that point instead of adding one (default 1e-6;
        in [0, 0.5)).
    recontact_alpha : float
        Normal load put at a re-contact instant, as a fraction of n0 (harmonic) or of the largest
        |sample| (sampled load), N/N; > 0 so that the committed law state is "in contact, virgin at
        the re-contact point" (default 1e-12; in (0, 1)).
    blowup_factor : float
        A state larger than this factor times (|f|/k_min + sum fy/kt), m (times the fastest frequency
        for velocities), or than this factor times the starting state, is a blow-up (default 1e8; in
        (1, inf)).
    """

    steps_per_period: int = 256
    max_omega_h: float = 1.0
    spring_omega_h: float = 0.3
    max_splits: int = 4
    event_merge: float = 1e-6
    recontact_alpha: float = 1e-12
    blowup_factor: float = 1e8

    def __post_init__(self) -> None:
        for name, least in (("steps_per_period", 4), ("max_splits", 0)):
            object.__setattr__(self, name, V.positive_int(name, getattr(self, name), least))
        object.__setattr__(self, "max_omega_h",
                           V.in_range("max_omega_h", self.max_omega_h, 0.0, _RK4_STABLE_WH, lo_open=True))
        object.__setattr__(self, "spring_omega_h",
                           V.in_range("spring_omega_h", self.spring_omega_h, 0.0, self.max_omega_h, lo_open=True))
        object.__setattr__(self, "event_merge", V.in_range("event_merge", self.event_merge, 0.0, 0.5, hi_open=True))
        object.__setattr__(self, "recontact_alpha",
                           V.in_range("recontact_alpha", self.recontact_alpha, 0.0, 1.0, lo_open=True, hi_open=True))
        object.__setattr__(self, "blowup_factor",
                           V.in_range("blowup_factor", self.blowup_factor, 1.0, math.inf, lo_open=True, hi_open=True))


def march_options(value, name: str = "march") -> MarchOptions:
    """``value`` as MarchOptions: None (the defaults) or MarchOptions (ValueError naming ``name`` otherwise)."""
    if value is None:
        return MarchOptions()
    if not isinstance(value, MarchOptions):
        raise ValueError(f"{name} must be a MarchOptions or None (the defaults), got {V.short_repr(value)}")
    return value


def march_with_steps(march, steps_per_period=None, *, name: str = "march",
                     steps_name: str = "steps_per_period") -> MarchOptions:  # fmt: skip
    """``march`` (:func:`march_options`) with its ``steps_per_period`` replaced by ``steps_per_period``
    where given (an integer >= 4; ValueError naming ``steps_name`` otherwise): the ``steps_per_period``
    keyword of the public entry points, which replaces the field of their ``options``."""
    march = march_options(march, name)
    if steps_per_period is None:
        return march
    spp = V.positive_int(steps_name, steps_per_period, 4)
    return march if spp == march.steps_per_period else replace(march, steps_per_period=spp)


@dataclass(frozen=True)
class SteadyStateOptions:
    """The numbers of a time-domain steady state: its march, the linear start, periodicity tests,
    classification and shooting.

    Attributes
    ----------
    march : MarchOptions
        The time march the steady state runs, its steps per period included (default ``MarchOptions()``,
        256 steps per period).
    linear_iters : int
        Describing-function solves of the equivalent-linearisation start, at most (default 30; >= 1).
    linear_rtol : float
        That iteration stops once the complex amplitude changes by less than this, relative: it only
        seeds the integration, which does the rest (default 1e-2).
    amp_rtol : float
        Relative tolerance on the half peak-to-peak amplitude and on the period-boundary state, the
        Poincare points (default 1e-4).
    energy_rtol : float
        Relative tolerance on the energy per period (default 1e-3).
    balance_rtol : float
        Work of the forcing = dissipation per period to this, relative; the energy integrals carry the
        discretisation error (default 1e-2).
    check_periods : int
        Windows (of p periods) that must agree (default 3; >= 2).
    max_multiple : int
        Largest period multiple p accepted as a periodic steady state (default 4).
    detect_multiple : int
        Longer multiples, up to this, are detected and reported as ``not-settled``, detail
        ``period-P``, instead of running to ``max_periods`` (default 12; >= ``max_multiple``).
    multiple_decay : float
        A multiple p > 1 is accepted only when the largest one-period mismatch over the last K p
        periods is at least this fraction of that over the K p periods before: no decaying beat
        (default 0.97; in (0, 1]).
    stall_periods : int
        After shooting, a run stops as ``quasi-periodic-or-chaotic`` when the largest one-period
        mismatch over the last ``stall_periods`` / 2 periods is at least ``stall_ratio`` times that over
        the half before (default 240; >= 2).
    stall_ratio : float
        See ``stall_periods`` (default 0.9; in (0, 1]).
    max_periods : int
        Cap on integrated periods (default 1500).
    chunk : int
        Periods integrated between two checks (default 8).
    shoot_after : float
        Shooting (Newton on the period map) when the estimated number of periods to converge exceeds
        this (default 40).
    shoot_maxit : int
        Newton iterations of one shooting attempt (default 12).
    shoot_maxstep : float
        Largest Newton step of shooting, relative to the amplitude (default 1.0).
    shoot_halvings : int
        Step halvings of the line search of shooting (default 8).
    shoot_clean_state : bool
        Before shooting (section at phase 0), rebuild the law states from the last period alone, forgetting
        the transient's memory (default True).
    max_shots : int
        Shooting attempts per run (default 3; >= 0).
    shoot_fd : float
        Relative finite-difference step of the monodromy matrix of shooting (default 1e-6).
    floquet_tol : float
        A Floquet multiplier above 1 + this marks an unstable orbit (default 1e-3).
    growth_periods : int
        A response is unbounded when its amplitude increases over this many consecutive periods ...
        (default 40; >= 2)
    growth_ratio : float
        ... with increments of the second half at least this fraction of the first (default 0.9; in
        (0, 1]) ...
    unbounded_q : float
        ... and the amplitude of x[response_dof] above this many fy/kt of the first contact: friction
        saturated, only then can friction lose (default 20).
    """

    march: MarchOptions = MarchOptions()
    linear_iters: int = 30
    linear_rtol: float = 1e-2
    amp_rtol: float = 1e-4
    energy_rtol: float = 1e-3
    balance_rtol: float = 1e-2
    check_periods: int = 3
    max_multiple: int = 4
    detect_multiple: int = 12
    multiple_decay: float = 0.97
    stall_periods: int = 240
    stall_ratio: float = 0.9
    max_periods: int = 1500
    chunk: int = 8
    shoot_after: float = 40
    shoot_maxit: int = 12
    shoot_maxstep: float = 1.0
    shoot_halvings: int = 8
    shoot_clean_state: bool = True
    max_shots: int = 3
    shoot_fd: float = 1e-6
    floquet_tol: float = 1e-3
    growth_periods: int = 40
    growth_ratio: float = 0.9
    unbounded_q: float = 20.0

    def __post_init__(self) -> None:
        march_options(self.march)
        ints = {"linear_iters": 1, "check_periods": 2, "max_multiple": 1, "detect_multiple": 1,
                "stall_periods": 2, "max_periods": 1, "chunk": 1, "shoot_maxit": 1, "shoot_halvings": 1,
                "max_shots": 0, "growth_periods": 2}
        for name, least in ints.items():
            object.__setattr__(self, name, V.positive_int(name, getattr(self, name), least))
        if self.detect_multiple < self.max_multiple:
            raise ValueError(f"detect_multiple must be an integer >= max_multiple = {self.max_multiple}, "
                             f"got {self.detect_multiple!r}")
        for name in ("linear_rtol", "amp_rtol", "energy_rtol", "balance_rtol", "shoot_after", "shoot_maxstep", "shoot_fd",
                     "floquet_tol", "unbounded_q"):
            object.__setattr__(self, name, V.positive(name, getattr(self, name)))
        for name in ("multiple_decay", "stall_ratio", "growth_ratio"):
            object.__setattr__(self, name, V.in_range(name, getattr(self, name), 0.0, 1.0, lo_open=True))
        if not isinstance(self.shoot_clean_state, bool):
            raise ValueError(f"shoot_clean_state must be True or False, got {self.shoot_clean_state!r}")


def steady_options(value) -> SteadyStateOptions:
    """``value`` as SteadyStateOptions: None (the defaults) or SteadyStateOptions (ValueError naming
    ``options`` otherwise)."""
    if value is None:
        return SteadyStateOptions()
    if not isinstance(value, SteadyStateOptions):
        raise ValueError(f"options must be a SteadyStateOptions or None (the defaults), got {value!r}")
    return value
