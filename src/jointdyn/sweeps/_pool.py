"""Where sweep chunks run, and how a sweep stops without losing finished work.

Executors (one interface: ``submit(task)``, ``next_result(timeout)``,
``progress()``, ``request_stop()``, ``close()``):

- :class:`SerialExecutor`: in this process, one chunk at a time;
- :class:`LocalExecutor`: a local pool of processes (``fork`` on Linux:
  workers inherit the compiled kernels and the family's Systems) or threads;
- :class:`DaskExecutor`: a ``distributed.Client`` (the Systems are scattered
  once to every worker).

Process workers ignore SIGINT (the sweep's process handles it) and end when
their parent dies, even by SIGKILL: each asks the kernel for a death signal
(Linux ``prctl(PR_SET_PDEATHSIG, SIGKILL)``) and runs a watchdog thread that
exits when its parent process changes (the fallback where prctl is
missing). They count finished points in a shared counter (the progress bar
moves per point) and check a shared stop flag between points.

:func:`run_chunks` feeds the lines' chunks to an executor, a line's next
chunk as soon as the previous one is back (warm starts need the order),
and hands every finished chunk to a callback (which saves it). On
KeyboardInterrupt it sets the stop flag, so that each running chunk returns
after its current point, hands those partial chunks to the callback too,
and re-raises: an interrupt loses at most the points in progress (on a Dask
cluster too: the stop flag is a ``distributed.Event``, and each finished
point is logged as an event on the sweep's topic, which the client
subscribes to, so that the progress bar moves per point there as well).
"""

from __future__ import annotations

import collections
import contextlib
import ctypes
import os
import queue
import signal
import threading

from .._threads import one_blas_thread_per_process
from ._points import Context, solve_chunk

__all__ = ["SerialExecutor", "LocalExecutor", "DaskExecutor", "run_chunks", "die_with_parent", "detach_worker", "process_context"]

#: prctl option: signal sent to this process when its parent thread exits (linux/prctl.h)
PR_SET_PDEATHSIG = 1
#: exit status of a worker whose parent died
EXIT_ORPHANED = 1
#: seconds between checks of a worker process that its parent is alive (the fallback where the
#: kernel's parent-death signal is not available)
PARENT_POLL_S = 0.5

#: Systems and context of this worker process (set by its initializer)
_WORKER: tuple | None = None


def _watch_parent(parent_pid: int, poll_s: float) -> None:
    """Exit this process as soon as its parent is no longer ``parent_pid``."""
    stop = threading.Event()
    while not stop.wait(poll_s):
        if os.getppid() != parent_pid:
            os._exit(EXIT_ORPHANED)


def die_with_parent(parent_pid: int) -> None:
    """Make this (worker) process end when its parent ``parent_pid`` dies.

    Asks the kernel for SIGKILL at the parent's death (Linux prctl) and
    starts a daemon thread polling the parent pid every
    :data:`PARENT_POLL_S` seconds (any POSIX system). Exits at once
    if the parent is already gone.
    """
    try:
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGKILL), 0, 0, 0)
    except (OSError, AttributeError):  # pragma: no cover - not Linux
        pass
    if os.getppid() != parent_pid:
        os._exit(EXIT_ORPHANED)
    threading.Thread(target=_watch_parent, args=(parent_pid, PARENT_POLL_S), daemon=True,
                     name="jointdyn-parent-watchdog").start()


def process_context():
    """The multiprocessing context of worker processes: fork (Linux), so that workers inherit the compiled
    kernels and the Systems and do not re-import the caller's __main__ (spawn would, breaking scripts
    without a main guard); spawn elsewhere."""
    import multiprocessing as mp

    return mp.get_context("fork" if "fork" in mp.get_all_start_methods() else "spawn")


def detach_worker(parent_pid: int) -> None:
    """Set up a worker process: SIGINT ignored (the parent handles Ctrl-C), death with the parent."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    die_with_parent(parent_pid)


def _init_worker(systems, stop, counter, parent_pid) -> None:
    """Initializer of a process worker: :func:`detach_worker`, the family's Systems and the shared stop
    flag and point counter."""
    global _WORKER
    detach_worker(parent_pid)
    one_blas_thread_per_process()  # the pool's processes use the cores
    _WORKER = (systems, Context(stop, counter))


def _solve_in_worker(task):
    systems, ctx = _WORKER
    return solve_chunk(task, systems[task.system_index], ctx)


class _Counter:
    """A thread-safe integer with the ``get_lock()``/``value`` interface of
    ``multiprocessing.Value``."""

    def __init__(self):
        self._lock = threading.Lock()
        self.value = 0

    def get_lock(self):
        """The lock guarding ``value``."""
        return self._lock


class _EventCounter:
    """Counts finished points on a Dask worker: each is logged as an event on
    the sweep's topic (the client's subscription adds them up)."""

    def __init__(self, topic: str):
        self.topic = topic

    def add(self, k: int) -> None:
        """Log ``k`` finished points (nothing outside a Dask worker)."""
        from distributed import get_worker

        try:
            worker = get_worker()
        except ValueError:  # not running on a worker: nobody to tell
            return
        worker.log_event(self.topic, int(k))


class SerialExecutor:
    """Chunks run one at a time in this process (``next_result`` runs the next)."""

    def __init__(self, systems, on_point=None):
        self.systems = systems
        self.ctx = Context(counter=_Counter(), on_point=on_point)
        self.tasks = collections.deque()
        self.capacity = 1

    def submit(self, task) -> None:
        """Queue a chunk (it runs when its result is asked for)."""
        self.tasks.append(task)

    def pending(self) -> int:
        """Chunks submitted and not yet run."""
        return len(self.tasks)

    def next_result(self, timeout):
        """Run the next queued chunk here and return its result (``timeout`` unused)."""
        task = self.tasks.popleft()
        return solve_chunk(task, self.systems[task.system_index], self.ctx)

    def progress(self) -> int:
        """Points finished so far."""
        return self.ctx.counter.value

    def request_stop(self) -> None:
        """Drop the queued chunks (the running one stops at its interrupt)."""
        self.ctx.stop.set()
        self.tasks.clear()

    def close(self) -> None:
        """Drop what is queued."""
        self.tasks.clear()


class LocalExecutor:
    """A local pool of ``workers`` processes (``kind="process"``) or threads, ``tasks_per_worker`` tasks
    queued per worker (``SweepOptions.tasks_per_worker``)."""

    def __init__(self, systems, workers: int, kind: str, tasks_per_worker: int = 2):
        import concurrent.futures as cf

        self.systems = systems
        self.futures = set()
        self.capacity = tasks_per_worker * workers
        self.threads = kind == "thread"
        if self.threads:
            self.ctx = Context(counter=_Counter())
            self.pool = cf.ThreadPoolExecutor(max_workers=workers)
            return
        mpc = process_context()
        self.ctx = Context(stop=mpc.Event(), counter=mpc.Value("q", 0))
        self.pool = cf.ProcessPoolExecutor(max_workers=workers, mp_context=mpc, initializer=_init_worker,
                                           initargs=(systems, self.ctx.stop, self.ctx.counter, os.getpid()))

    def submit(self, task) -> None:
        """Start a chunk on the pool."""
        if self.threads:
            fut = self.pool.submit(solve_chunk, task, self.systems[task.system_index], self.ctx)
        else:
            fut = self.pool.submit(_solve_in_worker, task)
        self.futures.add(fut)

    def pending(self) -> int:
        """Chunks submitted and not yet returned."""
        return len(self.futures)

    def next_result(self, timeout):
        """A finished chunk, or None after ``timeout`` seconds; a chunk's error is raised."""
        import concurrent.futures as cf

        done, _ = cf.wait(self.futures, timeout=timeout, return_when=cf.FIRST_COMPLETED)
        if not done:
            return None
        fut = next(iter(done))
        self.futures.discard(fut)
        return fut.result()

    def progress(self) -> int:
        """Points finished so far (counted by the workers)."""
        return self.ctx.counter.value

    def request_stop(self) -> None:
        """Ask every running chunk to return after its current point."""
        self.ctx.stop.set()

    def close(self) -> None:
        """Stop the running chunks after their current point and end the pool."""
        self.ctx.stop.set()
        for f in self.futures:
            f.cancel()
        self.pool.shutdown(wait=True, cancel_futures=True)


class DaskExecutor:
    """Chunks on a Dask cluster through a connected ``distributed.Client``, ``tasks_per_worker`` tasks
    queued per worker thread (``SweepOptions.tasks_per_worker``)."""

    def __init__(self, systems, client, tasks_per_worker: int = 2):
        import uuid

        from distributed import Event

        self.client = client
        self.systems = client.scatter(list(systems), broadcast=True)
        # the stop request reaches the running chunks through the scheduler, checked between points
        name = f"jointdyn-sweep-{uuid.uuid4().hex}"
        self.ctx = Context(stop=Event(f"{name}-stop", client=client), counter=_EventCounter(f"{name}-points"))
        self.results = queue.Queue()
        self.futures = set()
        self.done_points = 0  # points of the chunks returned
        self.logged_points = 0  # points the workers reported one by one
        client.subscribe_topic(self.ctx.counter.topic, self._on_points)
        self.capacity = tasks_per_worker * max(1, sum(client.nthreads().values()))

    def submit(self, task) -> None:
        """Start a chunk on the cluster."""
        fut = self.client.submit(solve_chunk, task, self.systems[task.system_index], self.ctx, pure=False)
        self.futures.add(fut)
        fut.add_done_callback(self.results.put)

    def pending(self) -> int:
        """Chunks submitted and not yet returned."""
        return len(self.futures)

    def next_result(self, timeout):
        """A finished chunk, or None after ``timeout`` seconds; a chunk's error is raised."""
        try:
            fut = self.results.get(timeout=timeout)
        except queue.Empty:
            return None
        self.futures.discard(fut)
        res = fut.result()
        self.done_points += res.done
        return res

    def _on_points(self, event) -> None:
        """The client's handler of the points topic: ``event`` is ``(time, k)``."""
        self.logged_points += event[1]

    def progress(self) -> int:
        """Points finished so far: those the workers reported one by one, or
        those of the chunks returned when that is more (an event still on its way)."""
        return max(self.done_points, self.logged_points)

    def request_stop(self) -> None:
        """Ask every running chunk to return after its current point (queued
        chunks return at once, empty)."""
        self.ctx.stop.set()

    def close(self) -> None:
        """Cancel what is left and drop the stop flag from the scheduler."""
        if self.futures:
            self.client.cancel(list(self.futures))
        self.futures.clear()
        with contextlib.suppress(Exception):  # a client already closing has nothing left to clear
            self.ctx.stop.clear()
        with contextlib.suppress(Exception):
            self.client.unsubscribe_topic(self.ctx.counter.topic)


def _drain(executor, lines, on_chunk, poll_s: float) -> None:
    """After a stop request: collect the chunks still running (partial ones included), waiting ``poll_s``
    seconds at a time."""
    while executor.pending():
        res = executor.next_result(poll_s)
        if res is not None:
            lines[res.line].accept(res)
            on_chunk(lines[res.line], res)


def run_chunks(lines, executor, chunk_points: int, on_chunk, on_poll=None, poll_s: float = 0.2) -> None:
    """Run every line's remaining points on ``executor``, chunk by chunk.

    Parameters
    ----------
    lines : list
        Line runs (``next_task(n)``, ``accept(result)``, ``finished``),
        indexed by the ``line`` of their tasks.
    executor
        One of the executors of this module.
    chunk_points : int
        Points per chunk.
    on_chunk : callable
        ``on_chunk(line, result)`` after each chunk is back (saves it).
    on_poll : callable, optional
        Called while waiting (every ``poll_s`` seconds) and
        after each chunk (progress).
    poll_s : float
        Seconds between those calls while chunks run (``SweepOptions.progress_poll_s``).

    Raises
    ------
    KeyboardInterrupt
        After an interrupt, once the partial chunks are handed to ``on_chunk``.
    ValueError
        A chunk's error (a solver's refusal of a System), once the chunks
        still running are stopped after their current point and handed to
        ``on_chunk``.
    """
    waiting = collections.deque(line for line in lines if not line.finished)
    try:
        while waiting or executor.pending():
            while waiting and executor.pending() < executor.capacity:
                executor.submit(waiting.popleft().next_task(chunk_points))
            res = executor.next_result(poll_s)
            if on_poll is not None:
                on_poll()
            if res is None:
                continue
            line = lines[res.line]
            line.accept(res)
            on_chunk(line, res)
            if res.interrupted:
                raise KeyboardInterrupt
            if not line.finished:
                waiting.appendleft(line)
    except KeyboardInterrupt:
        executor.request_stop()
        _drain(executor, lines, on_chunk, poll_s)
        raise
    except Exception:
        # a chunk failed (a solver's refusal of a System): keep what the others finish, report the first error
        executor.request_stop()
        with contextlib.suppress(Exception):
            _drain(executor, lines, on_chunk, poll_s)
        raise
    finally:
        executor.close()
