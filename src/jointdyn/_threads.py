"""BLAS threads: as many as the cores this process may run on, one in a worker of a process pool.

OpenBLAS starts as many threads as the machine has CPUs and keeps them
spinning between calls; where they outnumber the cores the process may use
(a CPU affinity mask, a container's cpuset), where several worker processes
each start their own, or where other processes already keep the cores busy,
the threads wait for one another. One ``numpy.linalg.eigvals`` of Hill's
companion matrix of 1722 rows took 67.8 s with OpenBLAS's default 2 threads
and 8.4 s with one thread on a 2-core machine at a load of 8.7 (16.5 s
and 4.0 s at a load of 5.4)
(``benchmarks/bench_hb_stability.py``, ``eigvals_threads``).

:func:`blas_threads` limits the threads of the BLAS libraries loaded in this
process (through ``threadpoolctl``) while the linear algebra of a stage
runs: to the cores of ``os.sched_getaffinity`` by default, one where the
machine's 1-minute load already reaches that number of cores, and one in a
worker process of a sweep (:func:`one_blas_thread_per_process`, called by
the pool's initializer), where the processes themselves use the cores.
"""

from __future__ import annotations

import contextlib
import os

__all__ = ["available_cores", "free_cores", "blas_threads", "one_blas_thread_per_process"]

#: threads for BLAS in this process: None (the cores available) or 1 in a pool's worker process
_PER_PROCESS: int | None = None


def available_cores() -> int:
    """Cores this process may run on (its CPU affinity where the system has one, else ``os.cpu_count``)."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):  # pragma: no cover - no affinity call (macOS, Windows)
        return max(1, os.cpu_count() or 1)


def one_blas_thread_per_process() -> None:
    """Make every later :func:`blas_threads` of this process use one thread, and limit BLAS to one thread
    now (a worker process of a pool: the pool uses the cores)."""
    global _PER_PROCESS
    _PER_PROCESS = 1
    from threadpoolctl import threadpool_limits

    threadpool_limits(limits=1, user_api="blas")


def free_cores() -> int:
    """:func:`available_cores`, or 1 where the 1-minute load average of the machine already reaches them."""
    cores = available_cores()
    try:
        load = os.getloadavg()[0]
    except (AttributeError, OSError):  # pragma: no cover - no load average (Windows)
        return cores
    return cores if load < cores else 1


def blas_threads(limit: int | None = None):
    """A context in which the BLAS libraries of this process use at most ``limit`` threads (default: one in a
    pool's worker process, else :func:`free_cores`)."""
    n = limit if limit is not None else (_PER_PROCESS or free_cores())
    try:
        from threadpoolctl import threadpool_limits
    except ImportError:  # pragma: no cover - a dependency; an environment without it keeps BLAS's default
        return contextlib.nullcontext()
    return threadpool_limits(limits=int(n), user_api="blas")
