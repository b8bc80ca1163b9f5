"""Benchmark of harmonic balance condensed onto the contact DOFs (issue 10).

Structure: a rod of ``NDOF`` = 1000 masses in a chain fixed at both ends
(total mass 20 kg, spring 2e5 N/m x NDOF per link, so that its lowest
natural frequency stays near 100 rad/s), Rayleigh damping C = 0.5 M + 1e-5 K,
two Jenkins contacts to ground (kt = 3e5 N/m, mu = 0.5) at DOFs NDOF/3
(normal load 100 + 30 sin(w t + 20 deg) N) and 2 NDOF/3 (80 N), forcing 60 N
at DOF NDOF/2; harmonics 0..7, 128 samples, gamma 0.6 to 1.8, response at
the first contact DOF. Reference: the same two contacts on a 2-DOF
structure, the Guyan (static) reduction of the rod onto the two contact DOFs
(forcing reduced the same way), solved uncondensed.

Reported: CPU seconds per branch with the stability of every point (best
of ``ROUNDS`` rounds alternating the two, each branch on a freshly built
System so that the 1000-DOF branch includes its eigen-decomposition), of
which the stability (the CPU seconds spent in the stability functions of
:func:`jointdyn.hb.floquet.growths` where :mod:`jointdyn.hb.branch` calls it, timed
around each call: dense Hill for the 2-DOF model, Arnoldi through the
condensed form for the 1000-DOF rod) and the rest (``*_branch_only_seconds``:
continuation, AFT diagnostics, peaks), points, the stability method, the
decomposition's CPU seconds, and the ratios of the branches without their
stability (``ratio_branch``, ``ratio_per_point``) and with it
(``ratio_with_stability``).
Measured in a subprocess with single-threaded BLAS (``*_NUM_THREADS=1``)
for both sides: on a shared machine a multi-threaded LAPACK spends CPU
time waiting.
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

ROUNDS = 4
NDOF = 1000
SRC = Path(__file__).resolve().parents[1] / "src"

_MEASURE = r"""
import json, sys, time
import numpy as np
import jointdyn.hb.branch as hb_branch
from jointdyn import System
from jointdyn.hb import frc_hb
from jointdyn.hb.condense import receptance
from jointdyn.kinematics import HarmonicLoad
from jointdyn.laws import Jenkins
from jointdyn.systems import Contact

n, rounds = int(sys.argv[1]), int(sys.argv[2])
law = Jenkins(kt=3e5, mu=0.5, n_ref=100.0)
i1, i2 = n // 3, (2 * n) // 3


def rod():
    k, m = 2e5 * n, 20.0 / n
    K = 2.0 * k * np.eye(n) - k * np.eye(n, k=1) - k * np.eye(n, k=-1)
    M = m * np.eye(n)
    f = np.zeros(n)
    f[n // 2] = 60.0
    return M, K, f


def contacts(d1, d2):
    return (Contact(law=law, dof=d1, normal=HarmonicLoad(100.0, 30.0, 20.0)),
            Contact(law=law, dof=d2, normal=HarmonicLoad(80.0, 0.0, 0.0)))


def large():
    M, K, f = rod()
    return System(M=M, C=0.5 * M + 1e-5 * K, K=K, contacts=contacts(i1, i2), force=f)


def small():
    # Guyan reduction onto (i1, i2): x = T x_c, T = [I; -K_oo^-1 K_oc]
    M, K, f = rod()
    c = np.array([i1, i2])
    o = np.setdiff1d(np.arange(n), c)
    T = np.zeros((n, 2))
    T[c, [0, 1]] = 1.0
    T[o] = -np.linalg.solve(K[np.ix_(o, o)], K[np.ix_(o, c)])
    Mr, Kr = T.T @ M @ T, T.T @ K @ T
    return System(M=Mr, C=0.5 * Mr + 1e-5 * Kr, K=Kr, contacts=contacts(0, 1), force=T.T @ f)


spent = [0.0]


def timed(fn):
    def wrapper(*args, **kwargs):
        t = time.process_time()
        try:
            return fn(*args, **kwargs)
        finally:
            spent[0] += time.process_time() - t
    return wrapper


hb_branch.growths = timed(hb_branch.growths)


def branch(s, condense, dof):
    spent[0] = 0.0
    t = time.process_time()
    ds = frc_hb(s, 0.6, 1.8, harmonics=7, samples=128, progress=False, condense=condense, response_dof=dof)
    return time.process_time() - t, spent[0], ds


branch(small(), False, 0)  # warm-up: compiled code loaded or compiled
branch(large(), True, i1)
best = {"small": (float("inf"),), "large": (float("inf"),)}
for _ in range(rounds):
    s = small()
    t, ts, ds_s = branch(s, False, 0)
    best["small"] = min(best["small"], (t, ts))
    s = large()
    t, ts, ds_l = branch(s, True, i1)
    best["large"] = min(best["large"], (t, ts))
    rec_seconds = receptance(s).seconds
print(json.dumps(dict(
    small_branch_seconds=best["small"][0], large_branch_seconds=best["large"][0],
    small_stability_seconds=best["small"][1], large_stability_seconds=best["large"][1],
    small_branch_only_seconds=best["small"][0] - best["small"][1],
    large_branch_only_seconds=best["large"][0] - best["large"][1],
    small_stability=ds_s.attrs["stability"], large_stability=ds_l.attrs["stability"],
    small_unstable_points=int((~ds_s.stable.values.astype(bool)).sum()),
    large_unstable_points=int((~ds_l.stable.values.astype(bool)).sum()),
    small_points=int(ds_s.sizes["point"]), large_points=int(ds_l.sizes["point"]),
    small_status=ds_s.attrs["status"], large_status=ds_l.attrs["status"],
    large_condensed=int(ds_l.attrs["condensed"]), large_unknown_dofs=int(ds_l.attrs["unknown_dofs"]),
    decomposition_seconds=rec_seconds,
    small_peak_m=float(ds_s.amplitude_m.max()), large_peak_m=float(ds_l.amplitude_m.max()))))
"""


def run(quick: bool = False) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = str(SRC) + os.pathsep + env.get("PYTHONPATH", "")
    for var in ("OMP_NUM_THREADS", "OPENBLAS_NUM_THREADS", "MKL_NUM_THREADS"):
        env[var] = "1"
    rounds = 1 if quick else ROUNDS
    r = subprocess.run([sys.executable, "-c", _MEASURE, str(NDOF), str(rounds)], capture_output=True, text=True,
                       env=env, check=True)
    out = json.loads(r.stdout.strip().splitlines()[-1])
    out["system"] = (f"rod of {NDOF} DOFs, 2 Jenkins contacts, Rayleigh damping, H=7, 128 samples, gamma 0.6-1.8, "
                     "vs its Guyan reduction onto the 2 contact DOFs")
    # the branches compared without their stability (dense Hill on 2 DOFs, Arnoldi on 1000), as before it
    # was computed at any size; with it, the 1000-DOF branch's whole time against the target of 60 s
    out["ratio_branch"] = out["large_branch_only_seconds"] / out["small_branch_only_seconds"]
    out["ratio_per_point"] = ((out["large_branch_only_seconds"] / out["large_points"])
                              / (out["small_branch_only_seconds"] / out["small_points"]))
    out["ratio_with_stability"] = out["large_branch_seconds"] / out["small_branch_seconds"]
    out["target_ratio_branch"] = 3.0
    out["target_large_branch_seconds"] = 60.0
    return out


if __name__ == "__main__":
    print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
