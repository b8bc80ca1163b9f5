"""Segalman's law and identification (``python benchmarks/run.py --only identify``).

Measured, each beside its reference in the same run:

* the ``segalman`` kernel (chi = -0.5, beta = 0.2) per step beside the default
  ``iwan`` kernel, alternating repeats of ``jointdyn.march`` (best of each),
  on two histories: a steady cycle with macroslip at constant load (the
  loops of bench_laws) and loops of slowly varying amplitude under a normal
  load varying by 50 % (many linear pieces, merges at the capacity). Target
  (issue 24): within 2x of ``iwan`` per step;
* a loop fit (``jointdyn.fit_loops``, segalman, 4 parameters) of 10^4
  samples, warm (second call), target <= 2 s;
* a backbone fit (``jointdyn.fit_backbone``, iwan, 50 points), warm, target <= 1 s;
* a ring-down of 10^6 samples to a fitted model (``jointdyn.backbone_from_ringdown`` then
  ``fit_ringdown``, iwan: what ``jointdyn fit --ringdown`` runs), warm, target <= 5 s (issue 32), beside one zero-phase band-pass
  of the same signal;
* a response-curve fit (``jointdyn.fit_frc``, iwan) of 3 x 50 points, warm, target <= 30 s
  (issue 32), beside one describing-function evaluation of its amplitudes.
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "src") not in sys.path:
    sys.path.insert(0, str(ROOT / "src"))

TARGET_KERNEL_RATIO = 2.0
TARGET_LOOP_FIT_S = 2.0
TARGET_BACKBONE_FIT_S = 1.0
TARGET_RINGDOWN_S = 5.0
TARGET_FRC_S = 30.0
KT, MU, NREF = 1e5, 0.1, 100.0


def _histories(n):
    xs = 2.0 * MU * NREF / KT
    t = np.arange(n) / 2000.0
    return {
        "steady_macroslip": (1.5 * xs * np.sin(2 * np.pi * t), np.full(n, NREF)),
        "varying_load": (xs * np.sin(2 * np.pi * t) * (0.5 + 0.3 * np.sin(0.37 * t)),
                         NREF * (1.0 + 0.5 * np.sin(2 * np.pi * t + 0.7))),
    }


def _kernels(n, repeats):
    from jointdyn import march, make_law

    laws = {"iwan": make_law("iwan", kt=KT, mu=MU, n_ref=NREF),
            "segalman": make_law("segalman", kt=KT, mu=MU, n_ref=NREF, chi=-0.5, beta=0.2)}
    out = {}
    for label, (x, N) in _histories(n).items():
        best = {k: np.inf for k in laws}
        for law in laws.values():
            march(law, x[:8], N[:8])  # compile / load outside the timing
        for _ in range(repeats):
            for k, law in laws.items():
                t0 = time.perf_counter()
                march(law, x, N)
                best[k] = min(best[k], time.perf_counter() - t0)
        ratio = best["segalman"] / best["iwan"]
        out[label] = {"iwan_ns_per_step": 1e9 * best["iwan"] / n, "segalman_ns_per_step": 1e9 * best["segalman"] / n,
                      "ratio": ratio, "target_ratio": TARGET_KERNEL_RATIO, "target_met": bool(ratio <= TARGET_KERNEL_RATIO),
                      "n_steps": n}
    return out


def _warm(fn, repeats):
    fn()  # compile, caches
    best = np.inf
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t0)
    return best


def _loop_fit(repeats):
    import jointdyn as jd

    law = jd.make_law("segalman", kt=KT, mu=MU, n_ref=NREF, chi=-0.6, beta=0.3)
    t = np.linspace(0.0, 4.0, 10_000)
    x = law.x_slip * np.sin(2 * np.pi * t) * np.interp(t, [0.0, 4.0], [0.05, 1.5])
    N = NREF * (1.0 + 0.5 * np.sin(2 * np.pi * t + 0.9))
    T = jd.march(law, x, N)[0]
    T = T + 0.01 * np.abs(T).max() * np.random.default_rng(0).normal(size=t.size)
    fits = []
    s = _warm(lambda: fits.append(jd.fit_loops(x, N, T, "segalman", n_ref=NREF)), repeats)
    f = fits[-1]
    return {"seconds": s, "samples": t.size, "parameters": 4, "evaluations": f.evaluations, "status": f.status.value,
            "target_s": TARGET_LOOP_FIT_S, "target_met": bool(s <= TARGET_LOOP_FIT_S)}


def _backbone_fit(repeats):
    import jointdyn as jd
    from jointdyn.identify.backbone import _model

    law = jd.make_law("iwan", kt=KT, mu=MU, n_ref=NREF)
    A = np.geomspace(0.03, 30.0, 50) * law.x_slip
    w, D = _model(law, 4e5, 0.002, 2.0, A)
    rng = np.random.default_rng(1)
    w = w * (1.0 + 1e-4 * rng.normal(size=A.size))
    D = D * (1.0 + 1e-2 * rng.normal(size=A.size))
    fits = []
    s = _warm(lambda: fits.append(jd.fit_backbone(A, w, D, mass=2.0, model="iwan")), repeats)
    f = fits[-1]
    return {"seconds": s, "points": A.size, "evaluations": f.evaluations, "status": f.status.value,
            "target_s": TARGET_BACKBONE_FIT_S, "target_met": bool(s <= TARGET_BACKBONE_FIT_S)}


def _ringdown_signal(n):
    """A free decay of n samples whose envelope and phase follow the one-harmonic backbone of an
    Iwan oscillator (d ln A / dt = -D(A) omega(A)), 1 % noise of its peak."""
    import jointdyn as jd
    from jointdyn.identify.backbone import _model

    law = jd.make_law("iwan", kt=KT, mu=MU, n_ref=NREF)
    m, k, zeta = 2.0, 4e5, 0.002
    grid = np.geomspace(1e-3, 2.0, 400) * law.x_slip
    wg, Dg = _model(law, k, zeta, m, grid)
    # time to decay from the top of the grid: dt = -d(ln A) / (D omega)
    rate = 1.0 / (Dg * wg)
    lg = np.log(grid)
    tg = np.concatenate(([0.0], np.cumsum(0.5 * (rate[1:] + rate[:-1]) * np.diff(lg))))[::-1]
    tg = tg[0] - tg
    h = tg[-1] / n  # the record spans the decay (about 600 periods: 1600 samples per period at n = 1e6)
    t = h * np.arange(n)
    amp = np.exp(np.interp(t, tg, lg[::-1]))
    phase = np.cumsum(np.interp(t, tg, wg[::-1])) * h
    x = amp * np.cos(phase)
    return law, t, x + 0.01 * np.abs(x).max() * np.random.default_rng(2).normal(size=n)


def _ringdown_fit(n, repeats):
    """backbone_from_ringdown then fit_ringdown (the fit ``jointdyn fit --ringdown`` makes), beside one zero-phase band-pass of the same
    signal (scipy.signal.sosfiltfilt, the reference) in the same run."""
    from scipy.signal import butter, sosfiltfilt

    import jointdyn as jd

    law, t, x = _ringdown_signal(n)
    out = []

    def chain():
        b = jd.backbone_from_ringdown(t, x, "x")
        out.append((b, jd.fit_ringdown(b, mass=2.0, model="iwan")))

    s = _warm(chain, repeats)
    sos = butter(4, (0.4, 0.6), btype="band", output="sos")
    ref = _warm(lambda: sosfiltfilt(sos, x), repeats)
    b, f = out[-1]
    return {"seconds": s, "samples": n, "points": int(b.amplitude_m.size), "status": f.status.value,
            "reference_sosfiltfilt_s": ref, "target_s": TARGET_RINGDOWN_S, "target_met": bool(s <= TARGET_RINGDOWN_S),
            "kt_rel_error": (f.parameters["kt"] / KT - 1.0) if f.parameters.get("kt") else None}


def _frc_fit(repeats):
    """fit_frc of 3 x 50 points (HB curves, one harmonic, 1 % noise), beside one
    describing-function evaluation of its 150 amplitudes (the reference) in the same run."""
    import math

    import jointdyn as jd
    from jointdyn.hb import frc_hb
    from jointdyn.identify import describing_function

    law = jd.make_law("iwan", kt=KT, mu=0.2, n_ref=NREF)
    cols = []
    for F in (5.0, 15.0, 30.0):
        s = jd.System.sdof(m=2.0, k=4e5, law=law, f1=F, c=2 * 0.002 * math.sqrt(5e5 * 2.0), n0=NREF)
        ds = frc_hb(s, 0.85, 1.1, harmonics=1)
        g, A = np.asarray(ds["gamma"]), np.asarray(ds["amplitude_m"])
        pick = np.linspace(0, g.size - 1, 50).astype(int)
        cols.append(np.column_stack([np.full(50, F), g[pick] * s.w0, A[pick]]))
    F, w, A = np.concatenate(cols).T
    A = A * (1.0 + 0.01 * np.random.default_rng(0).normal(size=A.size))
    fits = []
    sec = _warm(lambda: fits.append(jd.fit_frc(F, w, A, mass=2.0, model="iwan")), repeats)
    ref = _warm(lambda: describing_function(law, A), 20)
    f = fits[-1]
    return {"seconds": sec, "points": int(A.size), "status": f.status.value, "evaluations": f.evaluations,
            "reference_describing_function_s": ref, "target_s": TARGET_FRC_S, "target_met": bool(sec <= TARGET_FRC_S)}


def run(quick: bool) -> dict:
    """Kernel ratio and fit times (module docstring)."""
    repeats = 3 if quick else 7
    n = 100_000 if quick else 1_000_000
    return {"segalman_kernel_vs_iwan": _kernels(n, repeats), "loop_fit_1e4_samples": _loop_fit(max(2, repeats // 2)),
            "backbone_fit_50_points": _backbone_fit(repeats),
            "ringdown_to_model": _ringdown_fit(100_000 if quick else 1_000_000, 1 if quick else 2),
            "frc_fit_3x50_points": _frc_fit(1)}


if __name__ == "__main__":
    import argparse

    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--quick", action="store_true")
    print(json.dumps(run(quick=ap.parse_args().quick), indent=2))
