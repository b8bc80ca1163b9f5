"""Time-domain dynamics: RK4 integration with exact events, steady states.

Public API: :func:`integrate` (harmonic loads), :func:`integrate_sampled`
(sampled loads), :class:`Trajectory`, :class:`Restart`,
:func:`steady_state` and :class:`SteadyState`.
"""

from .integrate import Restart, Trajectory, integrate, integrate_sampled
from .steady import STATUSES, SteadyState, steady_state

__all__ = [
    "integrate",
    "integrate_sampled",
    "Trajectory",
    "Restart",
    "steady_state",
    "SteadyState",
    "STATUSES",
]
