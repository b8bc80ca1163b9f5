"""Parameter sweeps: steady-state frequency response on grids of the paper's
groups (eta, beta or F1, delta, gamma), parallel and resumable."""

from . import _frc
from ._frc import *  # noqa: F403 - the public names are _frc.__all__

__all__ = list(_frc.__all__)
