"""Cost of the default contact law, the exact Iwan model (``iwan``): ``python benchmarks/run.py --only exact``.

Measured, each beside the full-memory closed form (``iwan-closed``,
``jointdyn.IwanClosedForm``, the law it replaces as the default) in the same
run:

* ``kernel``: steps per second of ``jointdyn.march`` on the same histories
  for the exact law (default capacity), the closed form and the discrete
  model with n = 50 and n = 1000: x = 1.5 x_slip sin(2 pi t), 2000 samples
  per cycle, N = N_ref (1 + 0.5 sin(2 pi t + delta)) with delta = 0 (in
  phase) and 90 deg (the exact law's state then has many pieces); rounds
  that march every law once each, best of the rounds (CPU time);
* ``fig6_time_domain``: the Fig 6 time-domain data set of
  ``jointdyn figures`` (``jointdyn.figures.dynamics``: 4 eta x 6 beta x 121
  gamma x 2 sweep directions = 5808 steady states, warm-started sweeps,
  default settings) with the default model and with the closed form, in
  this process on one core (``frc_sweep(n_workers=1)``, so that CPU time
  measures the work), rounds alternating the two models, best of the
  rounds; their ratio is issue 9's target (at most 1.5). ``--quick`` runs a
  subset (4 eta x beta 2, 10 x 13 gamma x 2 directions);
* ``hb_branch_eta0.5_beta2``: one harmonic-balance branch of the paper
  damper (eta 0.5, beta 2, gamma 0.6..1.8, default settings) with each law,
  wall seconds (best of rounds, alternating; the first call compiles or
  loads and is not timed) and residual evaluations; issue 9's target for
  the default model: 0.1 s. Beside them, in the same rounds, the default
  model with every Newton correction started from the tangent prediction
  (``iwan_prediction_start``: ``start_extrapolation=0``, the corrector
  before the extrapolated start), so that the start's gain is read on the
  machine of the run.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parent.parent
if str(ROOT / "src") not in sys.path:
    sys.path.insert(0, str(ROOT / "src"))

KT, MU, NREF = 1e5, 0.1, 100.0
STEPS = 200_000
#: default model against the closed form, as registered
MODELS = {"iwan": "iwan", "iwan_closed": "iwan-closed"}
TARGET_TD_RATIO = 1.5
TARGET_HB_SECONDS = 0.1
QUICK_GAMMA_STEP = 0.1
QUICK_BETAS = (2.0, 10.0)


def _laws():
    from jointdyn import DiscreteIwan, Iwan, IwanClosedForm

    return {
        "iwan": Iwan(kt=KT, mu=MU, n_ref=NREF),
        "iwan_closed": IwanClosedForm(kt=KT, mu=MU, n_ref=NREF),
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
        for _ in range(2 if quick else 5):
            for k, law in laws.items():
                t0 = time.process_time()
                march(law, x, N)
                best[k] = min(best[k], time.process_time() - t0)
        pc = _pieces(laws["iwan"], x[:4000], N[:4000])[2000:]
        out[name] = {
            "steps_per_second": {k: n_steps / v for k, v in best.items()},
            "time_ratio_to_closed_form": {k: v / best["iwan_closed"] for k, v in best.items()},
            "iwan_pieces_max": int(pc.max()),
            "iwan_pieces_mean": float(pc.mean()),
        }
    return out


def _fig6_grid(quick):
    from jointdyn.figures.dynamics import FIG6_BETAS, FIG6_ETAS, FIG6_GAMMA

    start, stop, step = FIG6_GAMMA
    betas = FIG6_BETAS
    if quick:
        step, betas = QUICK_GAMMA_STEP, QUICK_BETAS
    gammas = np.round(start + step * np.arange(int(round((stop - start) / step)) + 1), 12)
    return FIG6_ETAS, betas, gammas


def fig6_time_domain(quick):
    from jointdyn.sweeps import frc_sweep

    etas, betas, gammas = _fig6_grid(quick)
    kw = dict(etas=etas, betas=betas, directions=("up", "down"), n_workers=1, progress=False)
    for model in MODELS.values():  # compile or load outside the timing
        frc_sweep(gammas[:2], etas=(0.5,), betas=(2.0,), model=model, n_workers=1, progress=False)
    best = {k: np.inf for k in MODELS}
    periodic, periods, min_energy = {}, {}, {}
    for _ in range(1 if quick else 2):
        for k, model in MODELS.items():
            t0 = time.process_time()
            ds = frc_sweep(gammas, model=model, **kw)
            best[k] = min(best[k], time.process_time() - t0)
            ok = ds.status.values == 0
            periodic[k] = int(ok.sum())
            periods[k] = int(ds.periods.sum())
            min_energy[k] = float(ds.energy_contact_J.values[ok].min())
    npts = len(gammas) * len(etas) * len(betas) * 2
    ratio = best["iwan"] / best["iwan_closed"]
    return {
        "grid": (f"{'SUBSET (quick) ' if quick else 'Fig 6: '}{len(etas)} eta x {len(betas)} beta x "
                 f"{len(gammas)} gamma x 2 directions = {npts} points, one core"),
        "cpu_seconds": best,
        "ratio_default_to_closed_form": ratio,
        "target_ratio": TARGET_TD_RATIO,
        "target_met": bool(ratio <= TARGET_TD_RATIO),
        "periodic_points": periodic,
        "periods_integrated": periods,
        "min_energy_contact_J": min_energy,
    }


def hb_branch(quick):
    from jointdyn.continuation import ContinuationOptions
    from jointdyn.hb import frc_hb
    from jointdyn.systems import System

    systems = {k: System.paper_damper(eta=0.5, beta=2.0, model=m) for k, m in MODELS.items()}
    runs = {k: (s, {}) for k, s in systems.items()}
    runs["iwan_prediction_start"] = (systems["iwan"], {"options": ContinuationOptions(start_extrapolation=0.0)})
    out = {}
    for k, (s, kw) in runs.items():
        ds = frc_hb(s, 0.6, 1.8, progress=False, **kw)  # compile or load outside the timing
        out[k] = {"seconds": np.inf, "points": int(ds.sizes["point"]), "status": ds.attrs.get("status"),
                  "residual_evaluations": int(ds.attrs["counter_residual_evaluations"])}
    for _ in range(3 if quick else 7):
        for k, (s, kw) in runs.items():
            t0 = time.perf_counter()
            frc_hb(s, 0.6, 1.8, progress=False, **kw)
            out[k]["seconds"] = min(out[k]["seconds"], time.perf_counter() - t0)
    out["ratio_default_to_prediction_start"] = out["iwan"]["seconds"] / out["iwan_prediction_start"]["seconds"]
    out["target_seconds_default"] = TARGET_HB_SECONDS
    out["target_met"] = bool(out["iwan"]["seconds"] <= TARGET_HB_SECONDS)
    return out


def run(quick: bool = False) -> dict:
    from jointdyn import config
    from jointdyn.laws.exact import IWAN_CAPACITY

    return {
        "default_model": config.MODEL,
        "capacity": IWAN_CAPACITY,
        "kernel": kernel_rates(quick),
        "fig6_time_domain": fig6_time_domain(quick),
        "hb_branch_eta0.5_beta2": hb_branch(quick),
    }


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
