"""BLAS threads (jointdyn._threads): the cores of the affinity mask, one on a busy machine or in a pool's
worker process, restored after the stage."""

from __future__ import annotations

import os
import subprocess
import sys

import numpy as np
from threadpoolctl import threadpool_info

from jointdyn import _threads


def _blas_threads() -> int:
    return max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")


def test_cores_are_those_of_the_affinity_mask_and_one_on_a_busy_machine(monkeypatch):
    cores = len(os.sched_getaffinity(0))
    assert _threads.available_cores() == cores
    monkeypatch.setattr(os, "getloadavg", lambda: (cores - 0.5, 0.0, 0.0))
    assert _threads.free_cores() == cores
    monkeypatch.setattr(os, "getloadavg", lambda: (cores + 0.0, 0.0, 0.0))
    assert _threads.free_cores() == 1


def test_a_stage_limits_the_threads_and_gives_them_back():
    np.linalg.eigvals(np.eye(3))  # NumPy's BLAS loaded
    before = _blas_threads()
    with _threads.blas_threads(1):
        assert _blas_threads() == 1
    assert _blas_threads() == before


def test_a_pool_worker_keeps_one_thread_in_every_stage():
    code = ("import numpy as np; from threadpoolctl import threadpool_info; from jointdyn import _threads\n"
            "_threads.one_blas_thread_per_process()\n"
            "n = lambda: max(i['num_threads'] for i in threadpool_info() if i['user_api'] == 'blas')\n"
            "with _threads.blas_threads():\n    inside = n()\n"
            "print(n(), inside)")
    env = {**os.environ, "PYTHONPATH": os.pathsep.join(p for p in sys.path if p)}
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, env=env, check=True)
    assert out.stdout.split() == ["1", "1"]
