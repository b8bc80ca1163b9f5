"""One benchmark side in a child process of its own: its peak resident memory and CPU seconds are its own.

``isolated(fn, *args)`` runs ``fn(*args)`` (a dict) in a forked child and returns that dict with
``peak_rss_mb`` (``ru_maxrss``) added, and ``cpu_s`` (user + system CPU seconds of the whole child)
unless ``fn`` timed its own work as ``cpu_s``; an
exception in the child comes back as ``{"error": ..., "points": 0}`` so that the parent reports it and
goes on with the other side instead of waiting for a result that never comes. ``label``, when given,
prints each side's scalar results on stderr as it ends (long runs show where they are).
"""

from __future__ import annotations

import json
import multiprocessing
import resource
import sys


def _child(conn, fn, args):
    try:
        out = fn(*args)
    except Exception as exc:  # the parent reports it and goes on with the other side
        out = {"error": f"{type(exc).__name__}: {exc}", "points": 0}
    usage = resource.getrusage(resource.RUSAGE_SELF)
    out.setdefault("cpu_s", usage.ru_utime + usage.ru_stime)
    out["peak_rss_mb"] = usage.ru_maxrss / 1024.0
    conn.send(out)
    conn.close()


def isolated(fn, *args, label: str | None = None) -> dict:
    """fn(*args) in a child process (its own peak memory and CPU time); the parent waits."""
    ctx = multiprocessing.get_context("fork")
    a, b = ctx.Pipe(duplex=False)
    p = ctx.Process(target=_child, args=(b, fn, args))
    p.start()
    out = a.recv()
    p.join()
    if label is not None:
        print(f"{label}: {fn.__name__}{args[1:]}: " + json.dumps({k: v for k, v in out.items() if not isinstance(v, list)}),
              file=sys.stderr, flush=True)  # fmt: skip
    return out
