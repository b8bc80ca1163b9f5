"""What a time-domain steady state is asked apart from its system and its frequency:
:class:`SteadyStateOptions` (every number of :func:`~jointdyn.dynamics.steady_state`'s own, with its default).

The time march's fixed numbers (the step bounds ``w h``, the reversal splits, the event merge, the
re-contact load, the blow-up factor) stay constants of :mod:`jointdyn.dynamics._model`: the march is
shared by the integration, the steady states and the monodromy of both the time domain and harmonic
balance. The default steps per period of a steady state is the march's ``TI_STEPS_PER_PERIOD``."""

from __future__ import annotations

from dataclasses import dataclass

from .. import _validate as V
from ._model import TI_STEPS_PER_PERIOD

__all__ = ["SteadyStateOptions", "steady_options"]


@dataclass(frozen=True)
class SteadyStateOptions:
    """The numbers of a time-domain steady state: periodicity tests, classification and shooting.

    Attributes
    ----------
    steps_per_period : int
        Base RK4 steps per forcing period before events and reversal splits, raised where the stiffest
        stuck mode asks (default 256, the march's ``TI_STEPS_PER_PERIOD``; >= 4).
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

    steps_per_period: int = TI_STEPS_PER_PERIOD
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
        ints = {"steps_per_period": 4, "check_periods": 2, "max_multiple": 1, "detect_multiple": 1,
                "stall_periods": 2, "max_periods": 1, "chunk": 1, "shoot_maxit": 1, "shoot_halvings": 1,
                "max_shots": 0, "growth_periods": 2}
        for name, least in ints.items():
            object.__setattr__(self, name, V.positive_int(name, getattr(self, name), least))
        if self.detect_multiple < self.max_multiple:
            raise ValueError(f"detect_multiple must be an integer >= max_multiple = {self.max_multiple}, "
                             f"got {self.detect_multiple!r}")
        for name in ("amp_rtol", "energy_rtol", "balance_rtol", "shoot_after", "shoot_maxstep", "shoot_fd",
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
