"""Time-domain dynamics: RK4 integration with exact events, steady states.

Public API: :func:`integrate` (harmonic loads), :func:`integrate_sampled`
(sampled loads), :class:`MarchOptions` (the numbers of their time march),
:class:`Trajectory`, :class:`Restart`, :func:`steady_state`, :class:`SteadyStateOptions` (its numbers) and :class:`SteadyState` (:func:`prepare_kernels`
compiles its kernels ahead, for process pools; :func:`check_period_steps`
refuses a step grid larger than the memory before computing), the statuses
:class:`RunStatus` and :class:`SteadyStatus`, and the monodromy matrix of
the period map (:func:`monodromy_matrix`, :func:`fd_monodromy`).
"""

from ._model import check_period_steps
from .integrate import Restart, Trajectory, integrate, integrate_sampled
from .monodromy import fd_monodromy, monodromy_matrix
from .options import MarchOptions, SteadyStateOptions
from .status import EnergyCheck, RunStatus, SteadyStatus
from .steady import SteadyState, energy_check, prepare_kernels, steady_state

__all__ = [
    "integrate",
    "integrate_sampled",
    "Trajectory",
    "Restart",
    "steady_state",
    "check_period_steps",
    "prepare_kernels",
    "SteadyState",
    "SteadyStateOptions",
    "MarchOptions",
    "RunStatus",
    "SteadyStatus",
    "EnergyCheck",
    "energy_check",
    "monodromy_matrix",
    "fd_monodromy",
]
