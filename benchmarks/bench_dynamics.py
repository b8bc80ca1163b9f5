"""Steady-state sweep speed of jointdyn.dynamics (issue 3).

For representative paper-damper cases, a sweep of gamma up and down with warm
starts (the way sweeps use ``steady_state``): seconds per point, periods and
RK4 steps per point. Reference measured in the same run: ``drivers.march`` of
the same law over as many samples as the sweep made law evaluations (four
per RK4 step), so ``ratio_vs_march`` is the integrator's cost per law
evaluation relative to a bare compiled law loop.
"""

from __future__ import annotations

import time

import numpy as np


def _sweep(system, gammas):
    from jointdyn.dynamics import steady_state

    per, steps, status = [], [], {}
    t0 = time.perf_counter()
    for direction in (gammas, gammas[::-1]):
        prev = None
        for g in direction:
            r = steady_state(system, float(g), start=prev, keep_loop=False)
            prev = r if r.status.ok else None
            per.append(r.periods)
            steps.append(r.steps)
            key = r.status if r.status.ok else f"{r.status}:{r.message}"
            status[key] = status.get(key, 0) + 1
    dt = time.perf_counter() - t0
    return dt, np.array(per), np.array(steps), status


def run(quick: bool) -> dict:
    from jointdyn.drivers import march
    from jointdyn.dynamics import steady_state
    from jointdyn.systems import System

    ng = 20 if quick else 100
    gammas = np.linspace(0.5, 2.0, ng)
    cases = [("eta0.5_beta2", dict(eta=0.5, beta=2.0)), ("eta1.5_beta2", dict(eta=1.5, beta=2.0)),
             ("eta0.5_beta1000", dict(eta=0.5, beta=1000.0))]  # fmt: skip
    from jointdyn import config

    out = {"gammas_per_direction": ng, "model": config.MODEL}
    for name, kw in cases:
        s = System.paper_damper(**kw)
        steady_state(s, 1.0, max_periods=10)  # compile / load the cache
        dt, per, steps, status = _sweep(s, gammas)
        npts = 2 * ng
        law = s.contacts[0].law
        nev = int(4 * steps.sum())
        x = 1e-4 * np.sin(np.linspace(0.0, 2 * np.pi * steps.sum() / 256, nev))
        N = np.full(nev, law.n_ref)
        t0 = time.perf_counter()
        march(law, x, N)
        tref = time.perf_counter() - t0
        out[name] = {
            "seconds_per_point": dt / npts,
            "periods_per_point_mean": float(per.mean()),
            "periods_per_point_max": int(per.max()),
            "steps_per_point_mean": float(steps.mean()),
            "status_counts": status,
            "march_reference_seconds": tref,
            "ratio_vs_march": dt / tref,
        }
    return out
