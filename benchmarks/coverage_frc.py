"""Coverage of fit_frc's 95 % intervals (``python benchmarks/coverage_frc.py [SEEDS]``).

The response curves of tests/test_identify_frc.py (an SDOF with an Iwan joint, k = 4e5 N/m,
kt = 1e5 N/m, fy = 20 N, zeta = 0.2 %, m = 2 kg; harmonic balance with one harmonic at 5, 15
and 30 N, 50 points each) with 1 % noise on the amplitude, one fit per noise seed: how often
each parameter's profile interval holds the true value (a parameter named as not determined
counts as covered), and the largest relative error. Too slow for the test suite (a fit takes
tens of seconds on one core), so measured here and reported in docs/guide/identify.md.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "src") not in sys.path:
    sys.path.insert(0, str(ROOT / "src"))

TRUE = {"k": 4e5, "kt": 1e5, "fy_N": 20.0, "zeta": 0.002}
#: AFT samples of the curves: with the automatic choice (128) harmonic balance's response differs
#: from the exact one-harmonic model by up to 0.1 % in amplitude, systematically (at 1024: 1.3e-5)
SAMPLES = 1024


def curves():
    """(force N, omega rad/s, amplitude m) of the three HB curves, no noise."""
    import jointdyn as jd
    from jointdyn.hb import frc_hb

    law = jd.make_law("iwan", kt=1e5, mu=0.2, n_ref=100.0)
    cols = []
    for F in (5.0, 15.0, 30.0):
        s = jd.System.sdof(m=2.0, k=4e5, law=law, f1=F, c=2 * 0.002 * math.sqrt(5e5 * 2.0), n0=100.0)
        ds = frc_hb(s, 0.85, 1.1, harmonics=1, samples=SAMPLES, progress=False)
        g, A = np.asarray(ds["gamma"]), np.asarray(ds["amplitude_m"])
        pick = np.linspace(0, g.size - 1, 50).astype(int)
        cols.append(np.column_stack([np.full(50, F), g[pick] * s.w0, A[pick]]))
    return np.concatenate(cols).T


def run(seeds: int) -> dict:
    from jointdyn.identify import fit_frc

    F, w, A0 = curves()
    hits = {n: 0 for n in TRUE}
    worst = {n: 0.0 for n in TRUE}
    seconds = []
    for seed in range(seeds):
        A = A0 * (1.0 + 0.01 * np.random.default_rng(seed).normal(size=A0.size))
        t0 = time.perf_counter()
        fit = fit_frc(F, w, A, mass=2.0, model="iwan")
        seconds.append(time.perf_counter() - t0)
        for n, v in TRUE.items():
            hits[n] += bool(fit.parameters[n] is None or fit.intervals[n].covers(v))
            if fit.parameters[n] is not None:
                worst[n] = max(worst[n], abs(fit.parameters[n] / v - 1.0))
        print(seed, fit.status.value, {n: fit.parameters[n] for n in TRUE},
              {n: fit.intervals[n].covers(v) for n, v in TRUE.items()}, file=sys.stderr, flush=True)
    return {"seeds": seeds, "coverage": {n: h / seeds for n, h in hits.items()}, "largest_relative_error": worst,
            "seconds_median": float(np.median(seconds))}


if __name__ == "__main__":
    print(json.dumps(run(int(sys.argv[1]) if len(sys.argv) > 1 else 20), indent=2))
