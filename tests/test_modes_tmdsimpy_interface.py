"""EPMC of an interface (node pairs) against an established tool: tmdsimpy's backbone of the pair chain.

The model is the chain of ``benchmarks/bench_hb_interface_chain.py`` (16 nodes, a node pair
against ground at every node, H = 5, 128 samples); the tmdsimpy numbers and their provenance
are in ``reference_tmdsimpy_interface.py``, the script that computed them is
``docs/scripts/tmdsimpy_chain_epmc.py`` (run outside the package, where tmdsimpy is installed).
"""

from __future__ import annotations

import importlib.util
import math
from pathlib import Path

import numpy as np
import pytest

import tolerances as tol
from jointdyn.continuation import newton
from jointdyn.modes import EPMCOptions, EPMCProblem
from reference_tmdsimpy_interface import HARMONICS, NODES, ONE_BRANCH, SAMPLES, TMDSIMPY_CHAIN_EPMC

ROOT = Path(__file__).resolve().parents[1]
#: Newton iterations per solve (as many as tmdsimpy's solves were allowed)
MAX_ITER = 30


def _module(relative: str):
    """A module of the repository outside the package, loaded from its path."""
    path = ROOT / relative
    spec = importlib.util.spec_from_file_location(path.stem, path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def _chain():
    return _module("benchmarks/bench_hb_interface_chain.py").chain(NODES)


def test_the_script_model_is_the_benchmark_chain():
    """What the tmdsimpy script builds (plain numpy) is jointdyn's chain: M, C, K and every pair."""
    s = _chain()
    m = _module("docs/scripts/tmdsimpy_chain_epmc.py").chain_model(NODES)
    for name in ("M", "C", "K"):
        np.testing.assert_array_equal(getattr(s, name), m[name])
    (itf,) = s.interfaces
    np.testing.assert_array_equal(itf.preload, m["P"])
    for name in ("kt", "kn", "mu"):
        np.testing.assert_array_equal(np.broadcast_to(getattr(itf, name), (NODES,)), m[name])
    pairs = np.full((NODES, 6), -1)
    pairs[:, :3] = 3 * np.arange(NODES)[:, None] + np.arange(3)  # (t1, t2, n) of node i against ground
    np.testing.assert_array_equal(itf.pairs, pairs)
    np.testing.assert_array_equal(m["pairs"], pairs)
    assert s.output_dof == m["output_dof"] == 0


def _at_modal_amplitude(problem: EPMCProblem):
    """jointdyn's EPMC residual bordered by the modal amplitude, the one the script solved with
    (``docs/scripts/tmdsimpy_chain_epmc.py``: ``_jointdyn_at_modal_amplitude``)."""
    return _module("docs/scripts/tmdsimpy_chain_epmc.py")._jointdyn_at_modal_amplitude(problem)


def _backbone_at(problem: EPMCProblem, las):
    """(DOF 0's amplitude m, omega rad/s, damping ratio) at each log10 modal amplitude of ``las``
    (increasing), as the script solved jointdyn's side: Newton from the secant prediction of the two
    previous solutions, a step halved where Newton fails or the frequency moves by more than 10 %."""
    residual = _at_modal_amplitude(problem)
    v0 = problem.linear_guess()
    Y = problem.unpack(v0, 0.0)[0]
    lam0 = las[0] - 0.5 * math.log10(float(Y[problem.n:2 * problem.n] @ problem.system.M @ Y[problem.n:2 * problem.n]))
    path = [(las[0], np.append(v0, lam0))]
    out = []
    for target in las:
        la = target
        while True:
            (l1, z1), (l0, z0) = path[-1], path[-2] if len(path) > 1 else path[-1]
            guess = z1 + (z1 - z0) * (la - l1) / (l1 - l0) if l1 != l0 else z1
            z, ok, _ = newton(residual, guess, la, tol=EPMCOptions().tol, max_iter=MAX_ITER)
            w1 = problem.unpack(z1[:-1], z1[-1])[1]
            _, w, xi = problem.unpack(z[:-1], z[-1])
            if ok and abs(w - w1) <= 0.1 * w1:
                path.append((la, z))
                if la == target:
                    break
                la = target
            else:
                assert la - l1 > 1e-4, f"no EPMC solution near modal amplitude 10**{la:.4f}"
                la = 0.5 * (l1 + la)
        out.append((10.0 ** z[-1], w, xi / (2.0 * w)))
    return np.array(out)


def test_epmc_of_the_pair_chain_equals_tmdsimpy():
    """Stick, the onset of slip at the chain's ends, then more and more of the patch slipping: at every
    recorded modal amplitude, DOF 0's amplitude, the frequency and the damping ratio equal tmdsimpy's
    to rounding.

    The first mode moves the chain along t1 only (K couples no directions), so every pair sees a
    1-D tangential motion at its constant preload: there tmdsimpy's element (each direction clipped
    to mu N at the samples) and jointdyn's (the exact straight path between samples, radially
    returned onto the disc) are the same map, and both codes project with the same trapezoidal
    rule over the same samples: the same discrete equations (measured largest differences over the
    compared points: 1.7e-13 in DOF 0's amplitude, 1.8e-13 in the frequency, 2.9e-12 in the damping
    ratio), hence ``TEST_MODES_TMDSIMPY_SAME_RTOL``. The points are followed in tmdsimpy's
    parameter, the modal amplitude: the same sweep in DOF 0's amplitude (jointdyn's parameter) finds
    no solution past 3.2e-4 m on this branch. Compared: the points before the branch splits
    (``ONE_BRANCH``, reference_tmdsimpy_interface.py).
    """
    problem = EPMCProblem(_chain(), harmonics=HARMONICS, samples=SAMPLES)
    ref = np.array(TMDSIMPY_CHAIN_EPMC)[:ONE_BRANCH]
    got = _backbone_at(problem, ref[:, 0])
    np.testing.assert_allclose(got, ref[:, 1:], rtol=tol.TEST_MODES_TMDSIMPY_SAME_RTOL)
    # the compared range: stick (the viscous damping only), the onset of slip, then slip over more
    # and more of the patch with a falling frequency and a damping ratio 100 times the viscous one
    assert ref[0, 2] == pytest.approx(math.sqrt((1e3 + 2e4) / 0.1), rel=1e-12)
    assert ref[0, 1] < 0.02 * 1.602e-4 and ref[-1, 1] > 2 * 1.602e-4
    assert ref[-1, 2] < 0.75 * ref[0, 2] and ref[:, 3].max() > 100 * ref[0, 3]
