"""Parameter sweeps: steady-state frequency response on grids of the paper's
groups (eta, beta or F1, delta, gamma), parallel and resumable."""

from ._frc import (
    INT_VARIABLES,
    STATUS_CODES,
    VARIABLES,
    LineSpec,
    default_workers,
    frc_sweep,
    status_name,
    to_frame,
    write_outputs,
)

__all__ = [
    "frc_sweep",
    "LineSpec",
    "STATUS_CODES",
    "VARIABLES",
    "INT_VARIABLES",
    "status_name",
    "to_frame",
    "write_outputs",
    "default_workers",
]
