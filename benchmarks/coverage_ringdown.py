"""Ring-downs over noise seeds (``python benchmarks/coverage_ringdown.py [SEEDS]``).

The free decays of tests/test_identify_ringdown.py (an SDOF, m = 2 kg, k = 4e5 N/m,
kt = 1e5 N/m, fy = 20 N, zeta = 0.2 %, with an Iwan or a Segalman joint (chi = -0.5,
beta = 0.1), released from 0.4 slip displacements, computed by jointdyn's time integration,
64 samples per period) with white noise of 1 % of the record's peak, one noise seed each:

* the extracted backbone against the EPMC backbone (three harmonics) of the same model: the
  largest relative error of the frequency and of the damping ratio over the kept amplitudes;
* :func:`jointdyn.identify.fit_ringdown`: how often each determined combination's 95 %
  interval holds the true value (one named not determined counts as covered), the largest
  relative error of each determined one, and how often each was named not determined.

Too slow for the test suite at 20 seeds (a Segalman fit takes up to 20 s on a loaded core);
the tests run a few seeds, and the numbers are reported in docs/guide/identify.md.
"""

from __future__ import annotations

import json
import math
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
for p in (ROOT / "src", ROOT / "tests"):
    if str(p) not in sys.path:
        sys.path.insert(0, str(p))


def one(name: str, seeds: int) -> dict:
    from test_identify_ringdown import _against_epmc, _decay, _sdof

    from jointdyn.identify import backbone_from_ringdown, fit_ringdown
    from jointdyn.identify._microslip import microslip_constants

    system, law = _sdof(name)
    chi, R, _ = microslip_constants(law)
    true = {"k_plus_kt": 5e5, "R": R, "zeta": 0.002} | ({"chi": chi} if name == "segalman" else {})
    hits = {k: 0 for k in true}
    named = {k: 0 for k in true}
    worst = {k: 0.0 for k in true}
    ew_max, eD_max, seconds = [], [], []
    for seed in range(seeds):
        t, x = _decay(system, law, [0.4 * law.x_slip], 0, math.sqrt(5e5 / 2.0), 150, 64, seed=seed)
        b = backbone_from_ringdown(t, x, "x")
        ew, eD = _against_epmc(system, b)
        ew_max.append(float(np.max(np.abs(ew))))
        eD_max.append(float(np.max(np.abs(eD))))
        t0 = time.perf_counter()
        fit = fit_ringdown(b, mass=2.0, model=name)
        seconds.append(time.perf_counter() - t0)
        c = fit.determined_combinations
        for k, v in true.items():
            iv = c[k]["interval"]
            if "not_determined" in c[k]:
                named[k] += 1
                hits[k] += 1
                continue
            hits[k] += bool((iv["low"] is None or iv["low"] <= v) and (iv["high"] is None or v <= iv["high"]))
            err = abs(c[k]["value"] - v) if k == "chi" else abs(c[k]["value"] / v - 1.0)
            worst[k] = max(worst[k], err)
        print(name, seed, f"omega {ew_max[-1]:.4f} D {eD_max[-1]:.4f}",
              {k: (c[k]["value"], "named" if "not_determined" in c[k] else "") for k in true}, file=sys.stderr,
              flush=True)
    return {"seeds": seeds, "omega_error_max": max(ew_max), "damping_error_max": max(eD_max),
            "damping_error_by_seed": eD_max, "coverage": {k: h / seeds for k, h in hits.items()},
            "named_not_determined": named, "largest_error_determined": worst,
            "fit_seconds_median": float(np.median(seconds))}


if __name__ == "__main__":
    n = int(sys.argv[1]) if len(sys.argv) > 1 else 20
    names = sys.argv[2:] or ["iwan", "segalman"]
    print(json.dumps({name: one(name, n) for name in names}, indent=2))
