"""Parameter sweeps: steady-state frequency response of any System, of
labelled Systems, or of the paper damper's grid of groups (eta, beta or F1,
delta), over gamma; parallel, resumable chunk by chunk, per-DOF and
per-contact outputs."""

from . import _frc
from ._frc import *  # noqa: F403 - the public names are _frc.__all__
from ._points import LoopStatistics, loop_statistics

__all__ = [*_frc.__all__, "LoopStatistics", "loop_statistics"]
