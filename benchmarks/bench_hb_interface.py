"""Harmonic balance with interfaces (issue 23): AFT evaluation cost per node pair against the number of pairs.

One AFT evaluation of the pairs (``hb._aft_pairs.pairs_aft_kernel()``: samples of
(u1, u2, g), the march with exact derivatives along the 3 (2H+1)
coefficients of each pair until the slider repeats, projection and scatter
of the 3 x 3 harmonic blocks), H = 5 and 128 samples, at 16 and 256 pairs,
beside the evaluation of the same number of scalar contacts (a Jenkins
element under a normal spring, the contacts' compiled AFT of
``hb._aft``) at 16: the sizes alternate, best of several rounds.

The pairs sit on 16 nodes of three DOFs each against ground (pair i on node
i mod 16) with preloads spread over a factor 4, so that at 256 pairs every
node carries 16 pairs in different states; the unknowns (and the Jacobian
the pairs are scattered into) are those of the 16 nodes at both sizes, so
the figure is the cost of the pairs' AFT itself, not that of a larger
linear part. The orbit of every node is a random harmonic motion of
amplitude about the slip displacement: stick, slip and separation occur.
Reported: microseconds per pair per evaluation at 16 and 256 pairs, their
ratio (target <= 1.2: cost linear in the number of pairs), the periods
marched, and the scalar contacts' cost per contact.

Times are the CPU time of the calling thread (``time.thread_time``), not
wall-clock: on a machine shared with other work, a call of tens of
milliseconds (256 pairs) is preempted far more often than one of one or two
(16 pairs), which measured 5-7x "per pair" in wall-clock on a 2-core machine
under a load of 9, against 1.0x in CPU time.
"""

from __future__ import annotations

import time

import numpy as np

TARGET_RATIO = 1.2
H, NS, NODES = 5, 128, 16


def _problem(npairs):
    import jointdyn as jd
    from jointdyn.hb.problem import HBProblem
    from jointdyn.interfaces import Interface

    n = 3 * NODES
    rng = np.random.default_rng(1)
    node = np.arange(npairs) % NODES
    pairs = np.full((npairs, 6), -1, dtype=np.int64)
    pairs[:, :3] = 3 * node[:, None] + np.arange(3)
    itf = Interface(kt=1e3, kn=1e3, mu=0.5, preload=rng.uniform(0.5, 2.0, npairs), pairs=pairs)
    s = jd.System(M=np.eye(n), C=None, K=1e3 * np.eye(n), force=np.ones(n), interfaces=(itf,))
    q = HBProblem(s, harmonics=H, samples=NS)
    X = rng.normal(size=q.size) * 1e-3
    return q, X


def _contacts(nc):
    import jointdyn as jd
    from jointdyn.hb.problem import HBProblem
    from jointdyn.kinematics import NormalSpring
    from jointdyn.laws.discrete import Jenkins

    n = 2 * nc
    cs = tuple(jd.Contact(Jenkins(kt=1e3, mu=0.5, n_ref=1.0), dof=2 * i,
                          normal=NormalSpring(kn=1e3, preload=1.0, dof=2 * i + 1)) for i in range(nc))
    s = jd.System(M=np.eye(n), C=None, K=1e3 * np.eye(n), force=np.ones(n), contacts=cs)
    q = HBProblem(s, harmonics=H, samples=NS)
    return q, np.random.default_rng(2).normal(size=q.size) * 1e-3


def _time(q, X, count):
    """Microseconds (CPU) per pair of the pairs' AFT kernel alone; for the scalar contacts, per contact of
    their whole evaluation (it includes their problem's linear part, small at 32 DOFs)."""
    from jointdyn.hb._aft import HB_PERIODIC_RTOL
    from jointdyn.hb._aft_pairs import pairs_aft_kernel

    if not q.has_interfaces:
        t0 = time.thread_time()
        ev = q.evaluate(X, 1.0)
        return (time.thread_time() - t0) / count * 1e6, ev
    npairs = q.pair_params.shape[0]
    R, JX = np.zeros(q.size), np.zeros((q.size, q.size))
    T, N, code, info = np.empty((npairs, q.Ns, 2)), np.empty((npairs, q.Ns)), np.empty((npairs, q.Ns), np.int8), np.zeros(3)
    kernel = pairs_aft_kernel()
    t0 = time.thread_time()
    kernel(q.pair_positions, q.pair_params, X, q.n, q.E, q.P, *q._pair_dirs, int(q.max_passes),
           float(HB_PERIODIC_RTOL), R, JX, q._no_blocks, T, N, code, info)
    t = (time.thread_time() - t0) / count * 1e6
    return t, type("Ev", (), {"info": info, "pair_code": code})


def run(quick: bool) -> dict:
    rounds = 3 if quick else 7
    cases = {16: _problem(16), 256: _problem(256)}
    ref = _contacts(16)
    for q, X in (*cases.values(), ref):
        q.evaluate(X, 1.0)  # compile / load the cache
    best = {16: np.inf, 256: np.inf, "contacts": np.inf}
    passes = {}
    for r in range(rounds):
        for n in ((16, 256) if r % 2 == 0 else (256, 16)):
            q, X = cases[n]
            t, ev = _time(q, X, n)
            best[n] = min(best[n], t)
            passes[n] = float(ev.info[0])
        best["contacts"] = min(best["contacts"], _time(*ref, 16)[0])
    codes = np.bincount(cases[256][0].evaluate(cases[256][1], 1.0).pair_code.ravel(), minlength=3)
    codes = codes / codes.sum()
    out = {"harmonics": H, "samples": NS, "rounds": rounds, "target_ratio": TARGET_RATIO,
           "us_per_pair_16": best[16], "us_per_pair_256": best[256], "ratio_256_vs_16": best[256] / best[16],
           "us_per_scalar_contact_16": best["contacts"], "aft_periods_16": passes[16], "aft_periods_256": passes[256],
           "state_fractions_256": {"stick": float(codes[0]), "slip": float(codes[1]), "open": float(codes[2])}}
    out["within_target"] = bool(out["ratio_256_vs_16"] <= TARGET_RATIO)
    return out
