"""Stability of harmonic-balance points: dense Hill against shift-invert Arnoldi, and BLAS threads.

The model, fixed before measuring: the chain of
``bench_hb_interface_chain.py`` with scalar Jenkins contacts (3 DOFs per
node, a contact at every node), at gamma = 1 and H = 3, 32 samples; the
Jacobian of the solved point is the input of both methods. Rows are those of
Hill's companion matrix, 2 n (2H + 1).

- ``dense_vs_arnoldi``: per size, the time of one point by dense Hill
  (:func:`jointdyn.hb.hill_growth`: every eigenvalue) and by Arnoldi
  (:func:`jointdyn.hb.hill_arnoldi_exponents`, default
  :class:`~jointdyn.hb.StabilityOptions`), alternated, best of ``REPEATS``,
  one BLAS thread; the growth max Re(s)/w of both and the largest distance
  (over w) of an exponent found by Arnoldi from the dense one nearest it.
  Quick: 294 to 1722 rows; full: also 3990 (the last size that the dense
  method ran at before) and 4410 rows;
- ``beyond``: Arnoldi alone on a chain beyond 4000 rows (quick: 4410, full:
  also 8400);
- ``lap_joint`` (full only): a reduced model dense on its interface, the
  lap joint of ``bench_hb_scale.py`` (733 DOFs, 120 pairs) solved at 760 Hz
  with H = 1 (4398 companion rows), its Jacobian by harmonic blocks:
  Arnoldi, and dense Hill on the same Jacobian, with the BLAS threads of
  :func:`jointdyn._threads.blas_threads`;
- ``eigvals_threads``: one ``numpy.linalg.eigvals`` of the dense companion
  matrix of 1722 rows with BLAS's default threads and with one thread
  (``threadpoolctl``), alternated.
"""

from __future__ import annotations

import os
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))

H = 3
REPEATS = 2


def _point(nodes: int):
    """(system, Jacobian, w) of the chain of ``nodes`` nodes solved at gamma = 1."""
    from bench_hb_interface_chain import chain

    from jointdyn.hb import harmonic_balance

    s = chain(nodes, pairs=False)
    sol = harmonic_balance(s, 1.0, harmonics=H, samples=32, stability=False)
    p = sol.problem
    return s, p.evaluate(sol.X, p.f1_ref).JX, p.omega(p.f1_ref)


def _best(fn, repeats=REPEATS):
    out, best = None, float("inf")
    for _ in range(repeats):
        t = time.perf_counter()
        out = fn()
        best = min(best, time.perf_counter() - t)
    return out, best


def _compare(nodes: int) -> dict:
    from threadpoolctl import threadpool_limits

    from jointdyn.hb import hill_arnoldi_exponents, hill_exponents

    s, JX, w = _point(nodes)
    with threadpool_limits(limits=1, user_api="blas"):
        hill_arnoldi_exponents(JX, s.M, s.C, w, H)  # imports and first calls out of the timing
        td, ta = float("inf"), float("inf")
        for _ in range(REPEATS):
            (sel, _), t = _best(lambda: hill_exponents(JX, s.M, s.C, w, H), 1)
            td = min(td, t)
            a, t = _best(lambda: hill_arnoldi_exponents(JX, s.M, s.C, w, H), 1)
            ta = min(ta, t)
    diff = max(float(np.min(np.abs(sel - z))) for z in a.exponents) / w
    return {"rows": 2 * JX.shape[0], "dense_s": td, "arnoldi_s": ta, "ratio": td / ta,
            "growth_dense": float(sel[0].real) / w, "growth_arnoldi": a.growth,
            "max_exponent_diff_over_w": diff, "exponents_found": int(a.exponents.size), "band_over_w": a.band / w}


def _beyond(nodes: int) -> dict:
    from threadpoolctl import threadpool_limits

    from jointdyn.hb import hill_arnoldi_exponents

    s, JX, w = _point(nodes)
    with threadpool_limits(limits=1, user_api="blas"):
        a, t = _best(lambda: hill_arnoldi_exponents(JX, s.M, s.C, w, H), 1)
    return {"rows": 2 * JX.shape[0], "arnoldi_s": t, "growth_arnoldi": a.growth,
            "exponents_found": int(a.exponents.size), "band_over_w": a.band / w}


def _lap() -> dict:
    import math

    from bench_hb_scale import _system

    from jointdyn._threads import blas_threads
    from jointdyn.hb import harmonic_balance, hill_arnoldi_exponents, hill_exponents

    s = _system()
    sol = harmonic_balance(s, 2.0 * math.pi * 760.0 / s.w0, harmonics=1, samples=32, stability=False, condense=False)
    p = sol.problem
    w = p.omega(p.f1_ref)
    JX = p.evaluate_blocks(sol.X, p.f1_ref).JX
    with blas_threads():
        a, ta = _best(lambda: hill_arnoldi_exponents(JX, s.M, s.C, w, p.H), 1)
        (sel, lam), td = _best(lambda: hill_exponents(JX.toarray(), s.M, s.C, w, p.H), 1)
    return {"rows": 2 * p.size, "solved": bool(sol.status.ok), "arnoldi_s": ta, "dense_s": td,
            "growth_arnoldi": a.growth, "top_arnoldi_1_s": [a.exponents[0].real, a.exponents[0].imag],
            "growth_dense": float(sel[0].real) / w, "top_dense_1_s": [float(sel[0].real), float(sel[0].imag)],
            "max_exponent_diff_over_w": max(float(np.min(np.abs(lam - z))) for z in a.exponents) / w,
            "w_rad_s": w, "load_1min": os.getloadavg()[0]}


def _threads(nodes: int = 41) -> dict:
    from threadpoolctl import threadpool_info, threadpool_limits

    from jointdyn.hb.stability import _hill_matrix

    s, JX, w = _point(nodes)
    A = _hill_matrix(JX, s.M, s.C, w, H)
    default = max(i["num_threads"] for i in threadpool_info() if i["user_api"] == "blas")
    times = {"default": [], "one": []}
    for _ in range(REPEATS):
        times["default"].append(_best(lambda: np.linalg.eigvals(A), 1)[1])
        with threadpool_limits(limits=1, user_api="blas"):
            times["one"].append(_best(lambda: np.linalg.eigvals(A), 1)[1])
    return {"rows": A.shape[0], "default_threads": default, "cores_available": len(os.sched_getaffinity(0)),
            "default_s": min(times["default"]), "one_thread_s": min(times["one"]),
            "load_1min": os.getloadavg()[0]}


def run(quick: bool) -> dict:
    sizes = (7, 14, 29, 41) if quick else (7, 14, 29, 41, 95, 105)
    lap = {} if quick else {"lap_joint": _lap()}
    return {**lap, "model": "scalar-contact chain (bench_hb_interface_chain, pairs=False), gamma 1, H = 3, 32 samples",
            "load_1min": os.getloadavg()[0],
            "dense_vs_arnoldi": [_compare(k) for k in sizes],
            "beyond": [_beyond(k) for k in ((105,) if quick else (105, 200))],
            "eigvals_threads": _threads()}


if __name__ == "__main__":
    import json

    print(json.dumps(run("--full" not in sys.argv), indent=1))
