"""Statuses of the time-domain layer: one run of the RK4 core, one steady state.

Both are :class:`jointdyn.status.Status` enumerations: members compare equal
to their string values (``"ok"``, ``"periodic"``, ...), which files, tables
and JSON carry.
"""

from __future__ import annotations

from ..status import Status
from ._core import RUN_BLOWUP, RUN_OK, RUN_OVERFLOW

__all__ = ["EnergyCheck", "RunStatus", "SteadyStatus", "run_status"]

#: rounding floor of the contact-dissipation check of a periodic state: the
#: contact's energy per period may fall below zero by the period's
#: energy-balance residual |W - E_contact - E_viscous| plus this fraction of
#: |W| + |E_contact| + |E_viscous| before it is flagged as energy created
SS_DISSIPATION_FLOOR = 1e-12


class RunStatus(Status):
    """Outcome of one call of the compiled RK4 runner (:attr:`Trajectory.status`).

    The member at position ``code`` is the runner's status ``RUN_*`` (see
    :func:`run_status`).
    """

    OK = "ok", "the integration covered the requested time", True
    BLOW_UP = "blow-up", "the state became non-finite or astronomically large: the run stopped"
    OVERFLOW = "buffer-overflow", "the sample buffer was full (the caller repeats the run with a larger one)"


# the compiled codes are the positions of the members
assert (RunStatus.OK.code, RunStatus.BLOW_UP.code, RunStatus.OVERFLOW.code) == (RUN_OK, RUN_BLOWUP, RUN_OVERFLOW)


_RUN_STATUSES = tuple(RunStatus)


def run_status(code: int) -> RunStatus:
    """The :class:`RunStatus` of a runner status code ``RUN_*``."""
    return _RUN_STATUSES[code]


class SteadyStatus(Status):
    """Classification of a :func:`~jointdyn.dynamics.steady_state` result."""

    PERIODIC = "periodic", "the response repeats with the forcing period or a small multiple of it", True
    NOT_SETTLED = "not-settled", "no periodic state within the period budget (see the message)"
    UNBOUNDED = "unbounded", "the response grows without bound (or the integration blew up)"


class EnergyCheck(Status):
    """Passivity check of a periodic steady state (:attr:`SteadyState.energy_check`).

    Over a periodic orbit a passive contact dissipates ``energy_contact_J >=
    0``; a value below zero by more than the period's energy-balance residual
    (plus a rounding floor, ``SS_DISSIPATION_FLOOR``) means that the
    contact law created energy (e.g. the paper's closed form at some points)
    or that the orbit is not accurate enough to tell.
    """

    PASSIVE = "passive", "the contact dissipates energy over the period (within the energy-balance residual)", True
    NEGATIVE_DISSIPATION = "negative-dissipation", "the contact creates energy over the period, beyond the residual"
    NOT_CHECKED = "not-checked", "no periodic state to check", True
