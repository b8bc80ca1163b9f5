"""Time-domain steady states against harmonic balance on a 20-pair model (docs/performance.md).

Ten blocks of three DOFs (t1, t2, n) in a chain, two node pairs under each against ground (20
pairs, a heavy and a light preload), forced at both ends. Reported in CPU seconds
(``time.process_time``: the development machine is shared): the time integration per period with
and without the pairs (their difference per pair is the pairs' cost), one steady state at gamma = 1,
and harmonic-balance branches (H = 7, 128 samples) across the resonance.
"""

from __future__ import annotations

import time

import numpy as np

import jointdyn as jd
from jointdyn.dynamics import MarchOptions
from jointdyn.hb import continue_hb
from jointdyn.interfaces import Interface


def model(kt: float = 1e3, kn: float = 2e4, blocks: int = 10):
    """(System with the pairs, the same System without them)."""
    n = 3 * blocks
    K, M = np.zeros((n, n)), np.eye(n)
    for b in range(blocks):
        for d, k in enumerate((1e3, 1.3e3, 2e4)):
            i = 3 * b + d
            K[i, i] += k
            if b + 1 < blocks:  # springs to the next block
                j, kc = i + 3, 0.5 * k
                K[i, i] += kc
                K[j, j] += kc
                K[i, j] -= kc
                K[j, i] -= kc
    pairs = [[3 * b, 3 * b + 1, 3 * b + 2, -1, -1, -1] for b in range(blocks) for _ in range(2)]
    itf = Interface(kt=kt, kn=kn, mu=0.5, preload=np.tile([1.0, 0.4], blocks), pairs=pairs)
    f = np.zeros(n)
    f[0] = f[3 * (blocks - 1)] = 0.5
    return jd.System(M=M, C=0.002 * K, K=K, force=f, interfaces=(itf,)), jd.System(M=M, C=0.002 * K, K=K, force=f)


def run(quick: bool = False) -> dict:
    cpu = time.process_time
    s, lin = model()
    g = 1.0
    jd.integrate(s, g, periods=1)  # compiled before timing
    jd.integrate(lin, g, periods=1)
    periods = 5 if quick else 20
    out = {"ndof": s.ndof, "pairs": 20, "steps_per_period": MarchOptions().steps_per_period}
    t0 = cpu()
    jd.integrate(s, g, periods=periods)
    out["td_cpu_per_period_s"] = (cpu() - t0) / periods
    t0 = cpu()
    jd.integrate(lin, g, periods=periods)
    out["td_cpu_per_period_no_pairs_s"] = (cpu() - t0) / periods
    out["td_cpu_per_pair_period_ms"] = 1e3 * (out["td_cpu_per_period_s"] - out["td_cpu_per_period_no_pairs_s"]) / 20
    t0 = cpu()
    r = jd.steady_state(s, g)
    out.update(ss_cpu_s=cpu() - t0, ss_periods=int(r.periods), ss_status=str(r.status))
    if quick:
        return out
    continue_hb(s, 0.99, 1.0, harmonics=7, samples=128)  # compiled before timing
    t0 = cpu()
    br = continue_hb(s, 0.8, 1.2, harmonics=7, samples=128)
    out.update(hb_branch_cpu_s=cpu() - t0, hb_branch_points=len(br.gamma()), hb_status=str(br.status))
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(run()))
