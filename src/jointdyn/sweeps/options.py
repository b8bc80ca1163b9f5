"""How a sweep runs its lines: :class:`SweepOptions` (chunks, the local pool, the queue, the progress
refresh), the numbers that belong to the sweeps alone, with their defaults, and the numbers of the
steady state solved at every point (a :class:`~jointdyn.dynamics.options.SteadyStateOptions`)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from .. import _validate as V

if TYPE_CHECKING:
    from ..dynamics.options import SteadyStateOptions

__all__ = ["SweepOptions"]


@dataclass(frozen=True)
class SweepOptions:
    """How :func:`~jointdyn.sweeps.frc_sweep` runs its lines. None of these but ``steady`` changes a result.

    Attributes
    ----------
    chunk_points : int
        Consecutive points of a line solved as one task and saved as one resume checkpoint
        (default 8). An interrupt stops a task after its current point, so this bounds what a
        killed run loses, not what an interrupted one loses.
    pool : {"process", "thread"}
        Local pool for the lines when no Dask client is given (default "process"; the compiled
        kernels release the GIL, so threads also run in parallel).
    tasks_per_worker : int
        Tasks kept queued per worker (lines in progress at once), so that no worker waits for the
        next chunk of a line (default 2).
    progress_poll_s : float
        Seconds between refreshes of the progress bar while chunks run (default 0.2).
    steady : SteadyStateOptions or None
        The numbers of every point's steady state (:class:`~jointdyn.dynamics.options.SteadyStateOptions`;
        default None: its defaults). Given, they are part of each line's checkpoint key (points saved
        with other numbers are not reused) and the Dataset's ``steady_options`` attribute.
    """

    chunk_points: int = 8
    pool: str = "process"
    tasks_per_worker: int = 2
    progress_poll_s: float = 0.2
    steady: SteadyStateOptions | None = None

    def __post_init__(self) -> None:
        V.positive_int("chunk_points", self.chunk_points)
        V.choice("pool", self.pool, ("process", "thread"))
        V.positive_int("tasks_per_worker", self.tasks_per_worker)
        V.positive("progress_poll_s", self.progress_poll_s)
        if self.steady is not None:
            from ..dynamics.options import SteadyStateOptions  # the sweeps' options load without the solver

            if not isinstance(self.steady, SteadyStateOptions):
                raise ValueError(f"steady must be a SteadyStateOptions or None (the defaults), got {self.steady!r}")
