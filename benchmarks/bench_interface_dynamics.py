"""Time integration of a System with interfaces (issue 23): cost per forcing period against the number of pairs.

A chain of 8 nodes (3 DOFs each: t1, t2, n; springs along the chain and to ground) carries a patch of
16, 64 or 256 pairs against the ground, pair i on node i mod 8, with the tangential and normal stiffness
of the patch shared equally among its pairs and random preloads (sum fixed), so that the structure and
its step grid are the same at every size while the pairs stick, slip in 2-D (forcing along t1 and t2,
90 degrees apart) and some open (forcing along n). Measured: the RK4 march of whole periods from the
state after a transient (``Model.run_periods``), the sizes alternating with the same chain without the
patch (the reference: what the structure alone costs), best of several rounds. Reported per size:
seconds per period, steps per period (reversal and opening splits included), the cost the pairs add
per pair and evaluation (ns; four evaluations per step), and its ratio to the 16-pair figure (linear
cost: about 1). The shipped lap joint (``jointdyn.fe.lap_joint``, 120 pairs, 733 DOFs) is measured over
the first fiftieth of a period from rest and reported per step and, times 50, per period: its stiff
interface DOFs (highest mode about 3.0 MHz against 0.8 kHz) make the explicit march take about 24000
grid steps per period, and their ringing splits most of them at pair reversals.
"""

from __future__ import annotations

import math
import time

import numpy as np

NODES = 8


def _chain(npairs, rng):
    import jointdyn as jd

    n = 3 * NODES
    K = np.zeros((n, n))
    for i in range(NODES):
        for d in range(3):
            a = 3 * i + d
            K[a, a] += 2e3
            if i + 1 < NODES:
                b = a + 3
                K[a, a] += 1e3
                K[b, b] += 1e3
                K[a, b] -= 1e3
                K[b, a] -= 1e3
    M = np.eye(n)
    f = np.zeros(n)
    f[0], f[1], f[2] = 3.0, 3.0, 1.0
    ph = np.zeros(n)
    ph[1] = 90.0
    base = dict(M=M, C=0.005 * K, K=K, force=f, force_phase_deg=ph, w0_rad_s=40.0)
    if npairs == 0:
        return jd.System(**base)
    node = np.arange(npairs) % NODES
    pairs = np.stack([3 * node, 3 * node + 1, 3 * node + 2, -np.ones_like(node), -np.ones_like(node),
                      -np.ones_like(node)], axis=1)  # fmt: skip
    share = NODES / npairs  # every node carries the same total stiffness and preload at every size
    P = rng.uniform(0.2, 1.8, npairs) * 2.0 * share
    itf = jd.Interface(kt=1.5e3 * share, kn=3e3 * share, mu=0.3, preload=P, pairs=pairs)
    return jd.System(interfaces=(itf,), **base)


def _period_cost(system, periods):
    from jointdyn.dynamics import MarchOptions
    from jointdyn.dynamics._model import make_model

    model = make_model(system, 40.0, MarchOptions(steps_per_period=256))
    x, v = np.zeros(system.ndof), np.zeros(system.ndof)
    S = model.initial_states(x)
    model.run_periods(x, v, S, 2)  # transient (and compilation on the first call)
    t0 = time.perf_counter()
    res = model.run_periods(x, v, S, periods)
    dt = (time.perf_counter() - t0) / periods
    frac = res.pairs[-1].mean(axis=0)[1:] if res.pairs.shape[1] else np.zeros(3)
    return dt, float(res.summary[:, 6].mean()), frac


def _lap_joint_cost():
    import jointdyn as jd
    from jointdyn import fe
    from jointdyn.dynamics import MarchOptions
    from jointdyn.dynamics._model import make_model

    L = fe.lap_joint()
    f = np.zeros(L.M.shape[0])
    f[L.output_dof] = 50.0
    w1 = 2 * math.pi * L.frequencies_hz["stuck"][0]
    itf = jd.Interface(kt=L.kt, kn=L.kn, mu=L.mu, preload=L.preload, pairs=L.pairs)
    s = jd.System(M=L.M, C=0.02 * w1 * L.M, K=L.K, force=f, interfaces=(itf,), w0_rad_s=w1)
    model = make_model(s, w1, MarchOptions(steps_per_period=256))
    grid = model.segment_grid(0.0, model.period / 50)
    x, v = np.zeros(s.ndof), np.zeros(s.ndof)
    S = model.initial_states(x)
    model.run_grid(x.copy(), v.copy(), S.copy(), model.segment_grid(0.0, model.period / 5000), 1)  # compile
    t0 = time.perf_counter()
    res = model.run_grid(x, v, S, grid, 1)
    dt = time.perf_counter() - t0
    steps = float(res.summary[0, 6])  # grid steps and their splits (reversals, openings) over 1/50 period
    return {"pairs": int(L.npairs), "dofs": int(s.ndof), "grid_steps_per_period": int(model.J),
            "steps_per_period_extrapolated": 50 * steps, "seconds_per_step": dt / steps,
            "seconds_per_period_extrapolated": 50 * dt}


def run(quick: bool) -> dict:
    rng = np.random.default_rng(0)
    sizes = (16, 64, 256)
    rounds = 2 if quick else 4
    periods = 2 if quick else 5
    systems = {n: _chain(n, rng) for n in (0, *sizes)}
    best = {n: (np.inf, 0.0, None) for n in systems}
    for r in range(rounds):
        order = (0, *sizes) if r % 2 == 0 else (*sizes[::-1], 0)
        for n in order:
            dt, steps, frac = _period_cost(systems[n], periods)
            if dt < best[n][0]:
                best[n] = (dt, steps, frac)
    ref, ref_steps, _ = best[0]
    out = {"rounds": rounds, "periods": periods, "reference_seconds_per_period": ref,
           "reference_steps_per_period": ref_steps}
    per = {}
    for n in sizes:
        dt, steps, frac = best[n]
        # the pairs' share: the period's cost minus the structure's at the same number of steps
        added = dt - ref * steps / ref_steps
        per[n] = added / (steps * 4 * n) * 1e9
        out[f"seconds_per_period_{n}"] = dt
        out[f"steps_per_period_{n}"] = steps
        out[f"pair_ns_per_evaluation_{n}"] = per[n]
        out[f"fractions_stick_slip_open_{n}"] = [float(v) for v in frac]
    for n in sizes:
        out[f"pair_cost_ratio_{n}_vs_16"] = per[n] / per[16]
    out["lap_joint"] = _lap_joint_cost()
    return out
