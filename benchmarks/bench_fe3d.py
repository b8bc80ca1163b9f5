"""A user's 3-D bolted joint at scale: EPMC backbone and HB branch with stability, harmonic blocks against direct.

The model, fixed before measuring: :func:`jointdyn.bolted.bolted_lap` with
its defaults (two steel plates, 75 mm overlap, one bolt of 20 kN whose
pressure is a Gaussian of radius 20 mm around its axis, 200 node pairs,
kn = 2e13 N/m^3 per area, mu = 0.3; Craig-Bampton onto the pairs, the
output and 12 fixed-interface modes: 1213 DOFs, dense), modal damping
``ZETA`` of every mode of the stuck structure (a dense C). From the stuck
first mode (output amplitude 1) the onset amplitude of each pair,
``mu P_i / (kt_i |u_t,i|)``, gives the first onset ``a1`` (the smallest)
and the last (the largest); then

- the EPMC backbone of mode 1 over three decades of output amplitude,
  ``a1 / 10`` to ``100 a1`` (stuck to deep slip), at most ``MAX_POINTS``
  points;
- the HB forced-response branch across the first resonance, from
  ``BAND[0]`` times the slipping structure's first frequency to ``BAND[1]``
  times the stuck one's, with stability (the branch's own choice of
  stability path), under a force at the output whose linear stuck
  resonance would reach ``FORCE_AMPLITUDE`` times a1.

Each with the Newton and tangent solves preconditioned by the harmonic
blocks (``HBOptions.block_preconditioner``) and, in the same run, by the
direct path (one LU of the whole bordered matrix: the reference),
alternated (blocks, direct for the backbone; direct, blocks for the
branch), each side in a child process of its own (its peak resident memory,
``ru_maxrss``; the model is built once, in a child too, and read from a
file). Quick: H = 1 at 32 samples, the backbones only (the branches with
their stability ran past 15 CPU minutes a side at H = 1 on the shared
2-core machine without finishing: measured, not a quick figure); full: H = 1
at 32 samples, H = 3 and H = 5 at 64 samples, backbones and branches. Each side reports its CPU seconds beside the wall
seconds (the machine is shared).
"""

from __future__ import annotations

import math
import os
import json
import sys
import tempfile
import time

import numpy as np
from _isolated import isolated

ZETA = 0.002
MAX_POINTS = 400
#: backbone: output amplitudes from a1 / DECADES_BELOW to a1 * DECADES_ABOVE
BELOW, ABOVE = 10.0, 100.0
#: branch band: BAND[0] x the slipping first frequency to BAND[1] x the stuck one
BAND = (0.9, 1.05)
#: branch force: linear stuck resonance amplitude at the output, in units of a1
FORCE_AMPLITUDE = 10.0


def _build(path: str) -> dict:
    from jointdyn.bolted import bolted_lap

    t0, c0 = time.perf_counter(), time.process_time()
    j = bolted_lap()
    np.savez(path, M=j.M, K=j.K, pairs=j.pairs, kt=j.kt, kn=j.kn, mu=j.mu, preload=j.preload,
             output_dof=j.output_dof)  # fmt: skip
    return {"s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0, "dofs": int(j.M.shape[0]),
            "full_dofs": j.full_dofs, "pairs": j.npairs, "reduction_error": j.reduction_error,
            "stiffness_ratio": j.stiffness_ratio,
            "frequencies_hz": {k: [float(x) for x in v] for k, v in j.frequencies_hz.items()}}


def _model(path: str):
    """(system without force, onsets) from the saved model: the first and last onset amplitudes, m."""
    from scipy.linalg import eigh

    from jointdyn.bolted import BoltedJoint

    with np.load(path) as z:
        d = {k: z[k] for k in z.files}
    j = BoltedJoint(M=d["M"], K=d["K"], pairs=d["pairs"], kt=d["kt"], kn=d["kn"], mu=d["mu"], preload=d["preload"],
                    area=np.ones_like(d["kt"]), xy=np.zeros((d["kt"].size, 2)), bolt_xy=np.zeros(2),
                    bolt_force_n=float(d["preload"].sum()), output_dof=int(d["output_dof"]), full_dofs=0,
                    reduction_error=float("nan"), stiffness_ratio=float("nan"))  # fmt: skip
    lam, phi = eigh(j.linear_K("stuck"), j.M, subset_by_index=[0, 0])
    v = phi[:, 0] / phi[j.output_dof, 0]
    p = j.pairs
    ut = np.hypot(v[p[:, 0]] - v[p[:, 3]], v[p[:, 1]] - v[p[:, 4]])
    onset = j.mu * j.preload / (j.kt * np.maximum(ut, 1e-300))
    return j, float(onset.min()), float(onset.max()), float(np.sqrt(lam[0])), float(phi[j.output_dof, 0] ** 2)


def _setup(path: str, with_force: bool):
    j, a1, alast, w1, phi2 = _model(path)
    # x = F phi_out^2 / (2 zeta w1^2) at the stuck linear resonance (mass-normalised mode)
    force = FORCE_AMPLITUDE * a1 * 2.0 * ZETA * w1**2 / phi2 if with_force else 0.0
    return j.system(force, ZETA), j, a1, alast


def _backbone(path: str, H: int, samples: int, blocks: bool) -> dict:
    from jointdyn.hb import HBOptions
    from jointdyn.modes import epmc

    s, _, a1, _ = _setup(path, False)
    t0, c0 = time.perf_counter(), time.process_time()
    b = epmc(s, (a1 / BELOW, a1 * ABOVE), harmonics=H, samples=samples, max_points=MAX_POINTS, progress=False,
             hb_options=HBOptions(block_preconditioner=blocks))
    return {"s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0, "status": b.status.value,
            "points": int(b.points),
            "counters": {k: int(v) for k, v in b.counters.items() if isinstance(v, (int, np.integer))},
            "amplitude_m": b.amplitude_m.tolist(), "omega_rad_s": b.omega_rad_s.tolist(),
            "damping_ratio": b.damping_ratio.tolist()}


def _branch(path: str, H: int, samples: int, blocks: bool) -> dict:
    from jointdyn.hb import HBOptions, continue_hb

    s, j, _, _ = _setup(path, True)
    f_slip, f_stuck = j.natural_frequencies_hz("slip", 1)[0], j.natural_frequencies_hz("stuck", 1)[0]
    g0, g1 = 2.0 * math.pi * BAND[0] * f_slip / s.w0, 2.0 * math.pi * BAND[1] * f_stuck / s.w0
    t0, c0 = time.perf_counter(), time.process_time()
    br = continue_hb(s, g0, g1, harmonics=H, samples=samples, condense=False, progress=False, stability=None,
                     hb_options=HBOptions(block_preconditioner=blocks))
    peak = max(br.peaks, key=lambda p: p.amplitude_m) if br.peaks else None
    return {"s": time.perf_counter() - t0, "cpu_s": time.process_time() - c0, "status": br.status.value,
            "points": int(br.lam.size), "force_n": float(s.force[s.output_dof]),
            "counters": {k: int(v) for k, v in br.counters.items() if isinstance(v, (int, np.integer))},
            "unstable_points": int(np.sum(np.asarray(br.growth) > 0.0)),
            "stability_computed": int(np.sum(np.isfinite(np.asarray(br.growth)))),
            "peak_hz": None if peak is None else peak.gamma * s.w0 / (2.0 * math.pi),
            "peak_m": None if peak is None else peak.amplitude_m,
            "stability": br.stability, "gamma": np.asarray(br.lam).tolist(),
            "amplitude_m": np.asarray(br.response()[0]).tolist()}


def _compare(a: dict, b: dict, x: str, names, log: bool) -> float:
    """max relative difference of b's values against a's curve (interpolated in x, or log x)."""
    xa, xb = np.asarray(a[x]), np.asarray(b[x])
    if log:
        xa, xb = np.log(xa), np.log(xb)
    order = np.argsort(xa)
    worst = 0.0
    for name in names:
        ya = np.interp(xb, xa[order], np.asarray(a[name])[order])
        worst = max(worst, float(np.max(np.abs(np.asarray(b[name]) - ya) / np.abs(ya))))
    return worst


def _strip(r: dict, keys) -> dict:
    return {k: v for k, v in r.items() if k not in keys}


def run(quick: bool) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        path = os.path.join(tmp, "bolted.npz")
        out = {"model": isolated(_build, path, label="bench_fe3d"), "zeta": ZETA}
        _, _, a1, alast = _setup(path, False)[:4]
        out["model"].update(first_onset_m=a1, last_onset_m=alast, backbone_m=[a1 / BELOW, a1 * ABOVE])
        for H, samples in (((1, 32),) if quick else ((1, 32), (3, 64), (5, 64))):
            blk = isolated(_backbone, path, H, samples, True, label="bench_fe3d")
            ref = isolated(_backbone, path, H, samples, False, label="bench_fe3d")
            curve = ("amplitude_m", "omega_rad_s", "damping_ratio")
            out[f"H{H}_epmc_blocks"], out[f"H{H}_epmc_direct"] = _strip(blk, curve), _strip(ref, curve)
            if ref["points"] and blk["points"]:
                out[f"H{H}_epmc_max_rel_diff"] = _compare(ref, blk, "amplitude_m", curve[1:], True)
            if quick:
                continue
            ref = isolated(_branch, path, H, samples, False, label="bench_fe3d")
            blk = isolated(_branch, path, H, samples, True, label="bench_fe3d")
            out[f"H{H}_hb_direct"], out[f"H{H}_hb_blocks"] = (_strip(r, ("gamma", "amplitude_m")) for r in (ref, blk))
            if ref["points"] and blk["points"]:
                out[f"H{H}_hb_max_rel_diff"] = _compare(ref, blk, "gamma", ("amplitude_m",), False)
    return out


if __name__ == "__main__":
    print(json.dumps(run("--full" not in sys.argv), indent=1))
