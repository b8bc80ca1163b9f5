"""Continuation through clustered slip onsets: many pairs with nearly equal preloads begin to slip within a
narrow range of amplitude, on a structure whose first modes lie close together (the chain of
``benchmarks/bench_hb_interface_chain.py`` with its first, soft coupling). The walk must pass them with its
step control, not stall there."""

from __future__ import annotations

import importlib.util
from pathlib import Path

import numpy as np
import jointdyn as jd
from jointdyn.hb.problem import reference_scales
from jointdyn.interfaces import Interface
from jointdyn.modes import epmc

ROOT = Path(__file__).resolve().parents[1]
NODES = 20
#: the pairs' preloads differ by at most this fraction of their mean: every onset within 2e-4 of amplitude
SPREAD = 1e-4


def _chain():
    path = ROOT / "benchmarks" / "bench_hb_interface_chain.py"
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    s = module.chain(NODES, True, module.SOFT_COUPLING)
    P = 10.0 * (1.0 + SPREAD * np.linspace(-1.0, 1.0, NODES))
    pairs = s.interfaces[0].pairs
    return jd.System(M=s.M, C=s.C, K=s.K, force=s.force, output_dof=0,
                     interfaces=(Interface(kt=2e4, kn=5e4, mu=0.5, preload=P, pairs=pairs),))


def test_backbone_passes_twenty_onsets_within_a_narrow_range():
    s = _chain()
    kt, fy = reference_scales(s)
    a = fy / kt
    # the premise: with every pair stuck, the first three modes lie within 8 % of each other
    Ks = s.K + np.diag(np.tile([2e4, 2e4, 5e4], NODES))
    w = np.sqrt(np.sort(np.linalg.eigvalsh(Ks / 0.1)))
    assert w[2] < 1.08 * w[0]
    b = epmc(s, (0.01 * a, 10.0 * a), harmonics=3, samples=64, progress=False)
    assert b.status.value == "complete", b.message
    assert b.amplitude_m[-1] >= 0.999 * 10.0 * a
    # every onset lies between the first and the last point, and the walk did not grind through them:
    # few rejected steps, and the points where the damping rises from its viscous part bunch no more
    # than the step control needs
    assert b.damping_ratio_contacts[0] < 1e-6 * b.damping_ratio[-1]
    assert b.counters["steps_rejected"] <= 0.05 * b.points
    assert b.points < 400
