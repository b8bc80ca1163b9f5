"""Modal damping as an operator against the dense C it stands for, on a sparse structure with interfaces.

The model, fixed before measuring: the chain of ``bench_hb_interface_chain``
(nodes with three DOFs, a node pair against ground at every node, its
stiff ``COUPLING``) with modal damping ratio ``ZETA`` in every mode of the
stuck structure (``jd.stuck_stiffness``), once as the dense n x n C
(``modal_damping(..., form="array")``: the Jacobian of harmonic balance is
dense in every harmonic block) and once as the operator
(``form="operator"``: the Jacobian stays sparse, the Rayleigh part of C in
it and the rest applied as an operator, :mod:`jointdyn.hb._damped`).
Measured, the two sides alternated (dense, operator for the branch;
operator, dense for the backbone), each in a child process of its own:
the HB forced-response branch across the first resonance (gamma
``BAND``) and the EPMC backbone of mode 1 over ``AMPLITUDE`` (times the
chain's fy / kt), at most ``MAX_POINTS`` points each: seconds, points,
solver counters, peak resident memory, and the largest relative difference
of the operator's result from the dense one (the branch's peak amplitude;
the backbone's frequency and damping interpolated in amplitude).

Quick: 40 nodes (120 DOFs), H = 3, 64 samples (840 unknowns; the
continuation's large solves and the sparse path's density bound lowered to
this size, as the tests do); full:
167 nodes (501 DOFs), H = 3, 64 samples (3507 unknowns).
"""

from __future__ import annotations

import math
import time

import numpy as np

ZETA = 0.002
BAND = (0.9, 1.1)
AMPLITUDE = (0.05, 5.0)
MAX_POINTS = 300
H, NS = 3, 64


def _system(nodes: int, operator: bool):
    import jointdyn as jd
    from bench_hb_interface_chain import COUPLING, chain

    s = chain(nodes, coupling=COUPLING)
    C = jd.modal_damping(s.M, jd.stuck_stiffness(s), ZETA, form="operator" if operator else "array")
    return jd.System(M=s.M, C=C, K=s.K, interfaces=s.interfaces, force=s.force, force_phase_deg=s.force_phase_deg,
                     output_dof=s.output_dof)


def _lower(quick: bool) -> dict:
    """The large-solve paths at the quick model's size (where the dense C still makes it dense): the shared
    thresholds set in config, harmonic balance's Hill bound as its ``hb_options``, the walk's own as its
    ``linear`` option (returned as keyword arguments)."""
    from jointdyn import config
    from jointdyn.continuation import LinearSolveOptions
    from jointdyn.hb import HBOptions

    if not quick:
        return {}
    config.CONT_KRYLOV_SOLVE = 0
    config.CONT_SPARSE_DENSITY = 0.1
    return {"linear": LinearSolveOptions(small_solve=0), "hb_options": HBOptions(dense_max_unknowns=0)}


def _counters(c) -> dict:
    return {k: int(v) for k, v in c.items() if isinstance(v, (int, np.integer))}


def _branch(nodes: int, operator: bool, quick: bool) -> dict:
    from jointdyn.hb import continue_hb

    extra = _lower(quick)
    s = _system(nodes, operator)
    t0 = time.perf_counter()
    br = continue_hb(s, *BAND, harmonics=H, samples=NS, condense=False, progress=False, max_points=MAX_POINTS,
                     **extra)
    return {"s": time.perf_counter() - t0, "status": br.status.value, "points": int(br.lam.size),
            "peak_m": float(br.response()[0].max()), "counters": _counters(br.counters)}


def _backbone(nodes: int, operator: bool, quick: bool) -> dict:
    from jointdyn.hb.problem import reference_scales
    from jointdyn.modes import epmc

    extra = _lower(quick)
    s = _system(nodes, operator)
    kt, fy = reference_scales(s)
    t0 = time.perf_counter()
    b = epmc(s, tuple(a * fy / kt for a in AMPLITUDE), harmonics=H, samples=NS, max_points=MAX_POINTS,
             progress=False, **extra)
    return {"s": time.perf_counter() - t0, "status": b.status.value, "points": int(b.points),
            "counters": _counters(b.counters), "amplitude_m": b.amplitude_m.tolist(),
            "omega_rad_s": b.omega_rad_s.tolist(), "damping_ratio": b.damping_ratio.tolist()}


def run(quick: bool) -> dict:
    from _isolated import isolated
    from bench_hb_scale import _compare_backbones

    nodes = 40 if quick else 167
    out = {"model": f"chain of {nodes} nodes ({3 * nodes} DOFs, {nodes} pairs), zeta {ZETA} (stuck modes)",
           "H": H, "samples": NS}
    dense = isolated(_branch, nodes, False, quick)
    op = isolated(_branch, nodes, True, quick)
    out["hb_dense"], out["hb_operator"] = dense, op
    out["hb_speedup"] = dense["s"] / op["s"]
    out["hb_peak_rel_diff"] = abs(op["peak_m"] / dense["peak_m"] - 1.0)
    op = isolated(_backbone, nodes, True, quick)
    dense = isolated(_backbone, nodes, False, quick)
    drop = ("amplitude_m", "omega_rad_s", "damping_ratio")
    out["epmc_operator"] = {k: v for k, v in op.items() if k not in drop}
    out["epmc_dense"] = {k: v for k, v in dense.items() if k not in drop}
    out["epmc_speedup"] = dense["s"] / op["s"]
    out["epmc_max_rel_diff"] = (_compare_backbones(dense, op) if op["points"] > 1 and dense["points"] > 1
                                else math.nan)
    return out


if __name__ == "__main__":
    import json
    import sys
    from pathlib import Path

    sys.path.insert(0, str(Path(__file__).resolve().parent))
    print(json.dumps(run("--full" not in sys.argv), indent=1))
