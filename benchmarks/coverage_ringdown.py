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

and an Iwan decay through macroslip (:func:`macroslip`; ``--first N`` starts its seeds at N).

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
    ew_max, eD_max, seconds, trimmed, half = [], [], [], [], []
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
        trimmed.append(fit.damping_range["trimmed_top"] + fit.damping_range["trimmed_bottom"])
        half.append(max(h if h is not None else math.inf for h in fit.damping_range["half_width"]))
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
            "damping_range_trimmed_by_seed": trimmed, "damping_half_width_max": max(half),
            "fit_seconds_median": float(np.median(seconds))}


#: the decay through macroslip: released from RELEASE slip displacements, BAND passed (its
#: frequency drifts from the slipping to the stuck one: two spectral peaks), PERIODS periods
MACRO_RELEASE, MACRO_BAND, MACRO_PERIODS = 5.0, (300.0, 750.0), 150


def macroslip(seeds: int, first: int = 0) -> dict:
    """The Iwan SDOF above released from ``MACRO_RELEASE`` slip displacements: its kept decay
    starts at twice the slip displacement. One time integration, white noise of 1 % of the
    peak added per seed (as ``_decay`` does); fit_ringdown fits the whole model to the
    windows. The fitted model's frequency and damping ratio (EPMC's) against EPMC's backbone
    over the amplitudes where the fit says the damping ratio is determined (``damping_range``)
    and, for reference, over every kept window; how often each parameter's interval holds the
    truth (named not determined counts as covered), the largest error of a determined one.
    Seeds ``first`` to ``first + seeds - 1``."""
    from test_identify_ringdown import _decay, _sdof

    from jointdyn.identify import backbone_from_ringdown, fit_ringdown
    from jointdyn.modes import epmc

    system, law = _sdof("iwan")
    t, x0 = _decay(system, law, [MACRO_RELEASE * law.x_slip], 0, math.sqrt(5e5 / 2.0), MACRO_PERIODS, 64,
                   noise=0.0)
    true = {"k": 4e5, "kt": 1e5, "fy_N": 20.0, "zeta": 0.002}
    hits = {k: 0 for k in true}
    named = {k: 0 for k in true}
    worst = {k: 0.0 for k in true}
    held = {k: 0 for k in true}  # the interval holds the truth, named not determined or not
    ew_max, eD_max, eD_all, ranges, seconds, bb = [], [], [], [], [], None
    for seed in range(first, first + seeds):
        x = x0 + 0.01 * np.max(np.abs(x0)) * np.random.default_rng(seed).normal(size=x0.size)
        t0 = time.process_time()
        b = backbone_from_ringdown(t, x, "x", band=MACRO_BAND)
        fit = fit_ringdown(b, mass=2.0, model="iwan")
        seconds.append(time.process_time() - t0)
        if bb is None:
            bb = epmc(system, (0.3 * b.amplitude_m.min(), 1.5 * b.amplitude_m.max()), harmonics=3, progress=False)
        la, at = np.log(bb.amplitude_m), np.log(b.amplitude_m)
        inside = np.array(fit.damping_range["determined"], bool)
        eD = np.abs(fit.fitted["damping_ratio"] / np.interp(at, la, bb.damping_ratio) - 1.0)
        ew_max.append(float(np.max(np.abs(fit.fitted["omega_rad_s"] / np.interp(at, la, bb.omega_rad_s) - 1.0))))
        eD_max.append(float(np.max(eD[inside])) if inside.any() else float("nan"))
        eD_all.append(float(np.max(eD)))
        rng = fit.damping_range
        ranges.append((rng["amplitude_high_m"] and rng["amplitude_high_m"] / law.x_slip,
                       rng["amplitude_low_m"] and rng["amplitude_low_m"] / law.x_slip))
        for k, v in true.items():
            held[k] += bool(fit.intervals[k].covers(v))
            if fit.parameters[k] is None:
                named[k] += 1
                hits[k] += 1
                continue
            hits[k] += bool(fit.intervals[k].covers(v))
            worst[k] = max(worst[k], abs(fit.parameters[k] / v - 1.0))
        print("macroslip", seed, f"A {b.amplitude_m.max() / law.x_slip:.3g} to {b.amplitude_m.min() / law.x_slip:.3g} "
              f"x_slip, omega {ew_max[-1]:.4f} D {eD_max[-1]:.4f} over {ranges[-1][0]:.3g} to {ranges[-1][1]:.3g} "
              f"x_slip (all windows {eD_all[-1]:.4f}), CPU {seconds[-1]:.1f} s", {k: fit.parameters[k] for k in true},
              {k: (fit.intervals[k].low, fit.intervals[k].high) for k in true},
              file=sys.stderr, flush=True)
    return {"seeds": seeds, "omega_error_max": max(ew_max), "damping_error_max": max(eD_max),
            "damping_error_by_seed": eD_max, "damping_error_all_windows_by_seed": eD_all,
            "damping_range_x_slip_by_seed": ranges, "first_seed": first,
            "coverage": {k: h / seeds for k, h in hits.items()},
            "named_not_determined": named, "interval_holds_truth": held, "largest_error_determined": worst,
            "fit_cpu_seconds_median": float(np.median(seconds))}


if __name__ == "__main__":
    args = sys.argv[1:]
    first = 0
    if "--first" in args:  # seeds FIRST to FIRST + N - 1 of the decay through macroslip
        i = args.index("--first")
        first = int(args[i + 1])
        del args[i:i + 2]
    n = int(args[0]) if args else 20
    names = args[1:] or ["iwan", "segalman", "macroslip"]
    print(json.dumps({name: macroslip(n, first) if name == "macroslip" else one(name, n) for name in names},
                     indent=2))
