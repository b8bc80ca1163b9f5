"""Cost of the exact Iwan law (``iwan-exact``): ``python benchmarks/run.py --only exact``.

Measured, each beside the full-memory closed form (``jointdyn.Iwan``, the
model it replaces as the default) in the same run:

* kernel steps per second of ``jointdyn.march`` on the same histories for
  the exact law (default capacity), the closed form and the discrete model
  with n = 50 and n = 1000: x = 1.5 x_slip sin(2 pi t), 2000 samples per
  cycle, N = N_ref (1 + 0.5 sin(2 pi t + delta)) with delta = 0 (in phase)
  and 90 deg (the exact law's state then has many pieces); ``ROUNDS``
  rounds, each marching every law once, best of the rounds (CPU time);
* time-domain steady states of the paper damper, a Fig-6-like subset
  (eta 0.01, 0.5, 1.5, 10 x beta 2, 10 x gamma 0.6..1.8, both sweep
  directions with warm starts, ``jointdyn.sweeps.frc_sweep`` in this
  process): CPU seconds of the exact law and of the closed form, rounds
  alternating the two, best of the rounds, and their ratio (issue 9's
  target for the Fig 6 time-domain data set: at most 1.5);
* one harmonic-balance branch of the paper damper (eta 0.5, beta 2, gamma
  0.6..1.8, default settings): seconds with each law (best of rounds).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "src") not in sys.path:
    sys.path.insert(0, str(ROOT / "src"))

ROUNDS = 5
KT, MU, NREF = 1e5, 0.1, 100.0
STEPS = 200_000
SWEEP_ETAS = (0.01, 0.5, 1.5, 10.0)
SWEEP_BETAS = (2.0, 10.0)
TARGET_TD_RATIO = 1.5


def _laws():
    from jointdyn import DiscreteIwan, Iwan
    from jointdyn.laws.exact import ExactIwan

    return {
        "exact": ExactIwan(kt=KT, mu=MU, n_ref=NREF),
        "closed_form": Iwan(kt=KT, mu=MU, n_ref=NREF),
        "discrete_50": DiscreteIwan(kt=KT, mu=MU, n_ref=NREF, n=50),
        "discrete_1000": DiscreteIwan(kt=KT, mu=MU, n_ref=NREF, n=1000),
    }


def _history(n_steps, delta):
    xs = 2.0 * MU * NREF / KT
    t = np.arange(n_steps) / 2000.0
    return 1.5 * xs * np.sin(2 * np.pi * t), NREF * (1.0 + 0.5 * np.sin(2 * np.pi * t + delta))


def _pieces(law, x, N):
    from jointdyn.laws.exact import piece_count

    p = law.params
    s = law.initial_state(x[0], N[0])
    s_new = np.empty_like(s)
    out = []
    for xi, ni in zip(x, N):
        law.step(p, s, s_new, float(xi), float(ni))
        s, s_new = s_new, s
        out.append(piece_count(s))
    return np.array(out)


def kernel_rates(quick):
    from jointdyn import march

    laws = _laws()
    n_steps = STEPS // 10 if quick else STEPS
    out = {}
    for name, delta in (("in_phase", 0.0), ("quadrature", np.pi / 2)):
        x, N = _history(n_steps, delta)
        for law in laws.values():
            march(law, x[:8], N[:8])  # compile or load outside the timing
        best = {k: np.inf for k in laws}
        for _ in range(2 if quick else ROUNDS):
            for k, law in laws.items():
                t0 = time.process_time()
                march(law, x, N)
                best[k] = min(best[k], time.process_time() - t0)
        pc = _pieces(laws["exact"], x[:4000], N[:4000])[2000:]
        out[name] = {
            "steps_per_second": {k: n_steps / v for k, v in best.items()},
            "time_ratio_to_closed_form": {k: v / best["closed_form"] for k, v in best.items()},
            "exact_pieces_max": int(pc.max()),
            "exact_pieces_mean": float(pc.mean()),
        }
    return out


def td_sweeps(quick):
    from jointdyn.sweeps import frc_sweep

    step = 0.2 if quick else 0.05
    gammas = np.round(0.6 + step * np.arange(int(round(1.2 / step)) + 1), 12)
    kw = dict(etas=SWEEP_ETAS, betas=SWEEP_BETAS, directions=("up", "down"), n_workers=1, progress=False)
    models = {"exact": "iwan-exact", "closed_form": "iwan"}
    for model in models.values():
        frc_sweep(gammas[:2], etas=(0.5,), betas=(2.0,), model=model, n_workers=1, progress=False)
    best = {k: np.inf for k in models}
    status = {}
    periods = {}
    for _ in range(1 if quick else 3):
        for k, model in models.items():
            t0 = time.process_time()
            ds = frc_sweep(gammas, model=model, **kw)
            best[k] = min(best[k], time.process_time() - t0)
            status[k] = int((ds.status.values == 0).sum())
            periods[k] = int(ds.periods.sum())
    npts = len(gammas) * len(SWEEP_ETAS) * len(SWEEP_BETAS) * 2
    return {
        "grid": f"{len(SWEEP_ETAS)} eta x {len(SWEEP_BETAS)} beta x {len(gammas)} gamma x 2 directions = {npts} points",
        "cpu_seconds": best,
        "periodic_points": status,
        "periods_integrated": periods,
        "ratio_exact_to_closed_form": best["exact"] / best["closed_form"],
        "target_ratio": TARGET_TD_RATIO,
    }


def hb_branch(quick):
    from jointdyn.hb import frc_hb
    from jointdyn.systems import System

    out = {}
    for k, model in (("exact", "iwan-exact"), ("closed_form", "iwan")):
        s = System.paper_damper(eta=0.5, beta=2.0, model=model)
        ds = frc_hb(s, 0.6, 1.8, progress=False)  # compile or load outside the timing
        best = np.inf
        for _ in range(1 if quick else 3):
            t0 = time.perf_counter()
            ds = frc_hb(s, 0.6, 1.8, progress=False)
            best = min(best, time.perf_counter() - t0)
        out[k] = {"seconds": best, "points": int(ds.sizes["point"]), "status": ds.attrs.get("status")}
    return out


def run(quick: bool = False) -> dict:
    from jointdyn import config

    return {
        "capacity": config.IWAN_EXACT_CAPACITY,
        "kernel": kernel_rates(quick),
        "time_domain": td_sweeps(quick),
        "hb_branch_eta0.5_beta2": hb_branch(quick),
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
