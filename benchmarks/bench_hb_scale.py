"""Harmonic balance of a reduced model dense on its interface (issue 31): harmonic blocks against the direct path.

The model, fixed before measuring: the shipped lap joint
(:func:`jointdyn.fe.lap_joint`: Craig-Bampton model of 733 DOFs, every
interface DOF coupled to every other, 120 loaded node pairs), with the
figure's modal damping (``jointdyn.figures.lap.LAP_ZETA`` of every mode of the stuck
structure: a dense C) and force (``jointdyn.figures.lap.LAP_FORCE_N`` at the output DOF),
as :func:`jointdyn.figures.lap.lap_joint_system` builds it. Measured at
``SAMPLES`` AFT samples:

- the EPMC backbone of mode 1 over three decades of amplitude
  (``AMPLITUDE_M``), at most ``MAX_POINTS`` points;
- the HB forced-response branch across the first resonance (``BAND_HZ``).

Each with the Newton and tangent solves preconditioned by the harmonic
blocks (``HBOptions.block_preconditioner``, :mod:`jointdyn.hb._precond`)
and, in the same run, by today's direct path (one LU of the whole bordered
matrix, reused through GMRES: the reference), the two sides alternated
(block, direct for the backbone; direct, block for the branch). Each side
runs in a child process of its own, so that its peak resident memory is
its own (``ru_maxrss``). Quick: H = 1 (2199 unknowns, the figure's
harmonics), the backbone only; full: H = 3 (5131 unknowns) and H = 5 (8063),
backbone and branch. Those branches ask for no stability (``stability=False``:
they say ``not-computed``), so that the continuation alone is measured; the
full run then adds the branch with the blocks and its stability as
``continue_hb`` computes it by default (shift-invert Arnoldi at these sizes,
:mod:`jointdyn.hb.hill_arnoldi`), the model unchanged: the issue's target
asks for the branch "with stability". Then the same branch with the stability
of ``STABILITY_FAST`` (the one real shift, ``StabilityOptions.arnoldi_shifts = 1``,
at every ``check_every``-th point with the changes of label located,
:mod:`jointdyn.hb.stability_schedule`; row ``hb_blocks_stability_every``), which
says how many points it checked. Every row reports its wall seconds
(``s``), its CPU seconds (``cpu_s``, the child's) and its peak resident memory.

Condensation onto relative coordinates (:mod:`jointdyn.hb._coordinates`: a
pair's three ``x_a - x_b``, 362 unknowns per harmonic instead of 733), fixed
before measuring: the same branch across ``BAND_HZ`` at H = 1 and H = 3
without stability, condensed (``condense=True``) against today's path
(``condense=False``, the harmonic blocks), the sides alternated (condensed
first at H = 1, blocks first at H = 3), each in its own child process (the
condensed side's CPU seconds include the receptance's eigen-decomposition);
the peaks of the two compared; and the CPU seconds of ONE point's stability
at H = 3 (the point at ``STABILITY_HZ`` solved by each side, then
:func:`jointdyn.hb.floquet.point_stability`: Arnoldi through the condensed
form against the full Jacobian's shift-invert Arnoldi), with the growths
compared. Full run, or alone with ``--condensed``.
"""

from __future__ import annotations

import math
import time

import numpy as np
from _isolated import isolated

SAMPLES = 32
AMPLITUDE_M = (2e-6, 2e-3)
MAX_POINTS = 400
BAND_HZ = (750.0, 805.0)
#: the point whose stability is timed, Hz (inside BAND_HZ)
STABILITY_HZ = 780.0
#: the cheaper stability of the last row: one real shift, every tenth point and where labels change
STABILITY_FAST = {"arnoldi_shifts": 1, "check_every": 10}


def _system():
    from jointdyn.figures import lap

    return lap.lap_joint_system(lap.LAP_FORCE_N, lap.LAP_ZETA)[0]


def _backbone(H: int, blocks: bool) -> dict:
    from jointdyn.figures import lap
    from jointdyn.hb import HBOptions
    from jointdyn.modes import epmc

    s = _system()
    t0 = time.perf_counter()
    b = epmc(s, AMPLITUDE_M, harmonics=H, samples=SAMPLES, max_points=MAX_POINTS, ds_max=lap.LAP_DS_MAX,
             progress=False, hb_options=HBOptions(block_preconditioner=blocks))
    return {"s": time.perf_counter() - t0, "status": b.status.value, "points": int(b.points),
            "counters": {k: int(v) for k, v in b.counters.items() if isinstance(v, (int, np.integer))},
            "amplitude_m": b.amplitude_m.tolist(), "omega_rad_s": b.omega_rad_s.tolist(),
            "damping_ratio": b.damping_ratio.tolist()}


def _branch(H: int, blocks: bool, stability: bool = False, condense: bool = False, fast: bool = False) -> dict:
    from jointdyn.hb import HBOptions, StabilityOptions, continue_hb

    s = _system()
    g0, g1 = (2.0 * math.pi * f / s.w0 for f in BAND_HZ)
    t0 = time.perf_counter()
    opts = StabilityOptions(**STABILITY_FAST) if fast else (None if stability else False)
    br = continue_hb(s, g0, g1, harmonics=H, samples=SAMPLES, condense=condense, progress=False,
                     stability=opts, hb_options=HBOptions(block_preconditioner=blocks))
    peak = max(br.peaks, key=lambda p: p.amplitude_m) if br.peaks else None
    return {"s": time.perf_counter() - t0, "status": br.status.value, "points": int(br.lam.size),
            "counters": {k: int(v) for k, v in br.counters.items() if isinstance(v, (int, np.integer))},
            "stability": br.stability, "unstable_points": int(np.sum(~br.stable)) if stability else None,
            "stability_checked": int(br.stability_checked.sum()),
            "peak_hz": None if peak is None else peak.gamma * s.w0 / (2.0 * math.pi),
            "peak_m": None if peak is None else peak.amplitude_m}


def _stability_point(H: int, condense: bool) -> dict:
    """One point's stability at STABILITY_HZ: the solve, then point_stability timed alone (CPU s)."""
    from jointdyn.hb import StabilityOptions, harmonic_balance
    from jointdyn.hb.floquet import point_stability

    s = _system()
    sol = harmonic_balance(s, 2.0 * math.pi * STABILITY_HZ / s.w0, harmonics=H, samples=SAMPLES,
                           response_dof=s.output_dof, condense=condense, stability=False)
    p = sol.problem
    lam = p.f1_ref
    JX = p.evaluate(sol.X, lam).JX
    c0, t0 = time.process_time(), time.perf_counter()
    stable, growth, _ = point_stability(p, JX, p.omega(lam), StabilityOptions())
    return {"s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0, "status": sol.status.value,
            "unknowns": int(p.size), "stable": bool(stable), "growth": float(growth),
            "amplitude_m": float(sol.amplitude_m)}


def _relative(a, b):
    return None if a is None or b is None else abs(a - b) / abs(b)


def run_condensed() -> dict:
    """The rows of condensation onto relative coordinates (module docstring)."""
    out = {}
    for H, order in ((1, (True, False)), (3, (False, True))):
        for cond in order:
            out[f"H{H}_hb_{'condensed' if cond else 'blocks'}"] = isolated(_branch, H, not cond, False, cond,
                                                                            label="condensed")
        a, b = out[f"H{H}_hb_condensed"], out[f"H{H}_hb_blocks"]
        out[f"H{H}_peak_rel_diff"] = {k: _relative(a.get(k), b.get(k)) for k in ("peak_hz", "peak_m")}
        out[f"H{H}_cpu_ratio_blocks_over_condensed"] = b["cpu_s"] / a["cpu_s"] if a.get("points") else None
    st = {c: isolated(_stability_point, 3, c, label="condensed") for c in (True, False)}
    out["H3_stability_point_condensed"], out["H3_stability_point_full"] = st[True], st[False]
    out["H3_stability_cpu_ratio"] = st[False]["cpu_s"] / st[True]["cpu_s"] if "growth" in st[True] else None
    return out


def _compare_backbones(a: dict, b: dict) -> float:
    """max relative difference of omega and damping of b's points against a's curve (interpolated in log a)."""
    la, lb = np.log(a["amplitude_m"]), np.log(b["amplitude_m"])
    worst = 0.0
    for name in ("omega_rad_s", "damping_ratio"):
        ya = np.interp(lb, la, a[name])
        worst = max(worst, float(np.max(np.abs(np.asarray(b[name]) - ya) / np.abs(ya))))
    return worst


def run(quick: bool) -> dict:
    out = {"model": "lap joint (733 DOFs, 120 pairs, modal damping)", "samples": SAMPLES}
    for H in ((1,) if quick else (3, 5)):
        blk = isolated(_backbone, H, True)
        ref = isolated(_backbone, H, False)
        for name, r in (("blocks", blk), ("direct", ref)):
            out[f"H{H}_epmc_{name}"] = {k: v for k, v in r.items() if k not in ("amplitude_m", "omega_rad_s",
                                                                                  "damping_ratio")}
        out[f"H{H}_epmc_max_rel_diff"] = _compare_backbones(ref, blk) if ref["points"] and blk["points"] else None
        if quick:
            continue
        ref = isolated(_branch, H, False)
        blk = isolated(_branch, H, True)
        out[f"H{H}_hb_direct"], out[f"H{H}_hb_blocks"] = ref, blk
        out[f"H{H}_hb_blocks_stability"] = isolated(_branch, H, True, True)
        out[f"H{H}_hb_blocks_stability_every"] = isolated(_branch, H, True, True, False, True)
    if not quick:
        out["condensed"] = run_condensed()
    return out


if __name__ == "__main__":
    import json
    import sys

    if "--condensed" in sys.argv:
        print(json.dumps(run_condensed(), indent=1))
    else:
        print(json.dumps(run("--full" not in sys.argv), indent=1))
