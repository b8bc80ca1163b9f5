"""Benchmark of the linear algebra of harmonic balance: hand-written compiled
routines against LAPACK, at the sizes users run.

Systems: a chain of n = 1, 2, 5, 10, 20, 50 masses (m = 10 kg, springs 3.9e5
N/m, light damping) with a Jenkins contact (kt = 3e5 N/m, fy = 50 N) at the
first mass, forced at the first mass; H = 7 harmonics, 128 samples; the HB
Jacobian at a response where the contact slips part of the period.

* Hill eigenvalues: all eigenvalues of the companion matrix (2 n (2H+1)
  rows: 30 to 1500) with the parity split, by LAPACK in the two paths of
  ``jointdyn.hb.stability``: the batch (``_hill_growth_batch``: the
  companions of a branch's points as one stack, one ``numpy.linalg.eigvals``
  call per parity block; here 32 copies of the matrix, the time per point)
  and one point at a time (``_hill_eigvals_lapack``), for a constant normal
  load (the split applies: two blocks of half the rows) and a varying one
  (the whole matrix).
* Bordered solves: one Newton correction of the continuation
  (n (2H+1) + 1 unknowns: 16 to 751), by the compiled Gaussian elimination
  and by LAPACK ``dgesv`` (``numpy.linalg.solve``).
* AFT projection: the force coefficients and their derivatives of one
  contact, ``F = P Tc`` and ``G = P dT`` (P: 2H+1 rows by Ns samples; dT:
  Ns rows by 2H+2 directions, as with the continuation parameter), by the
  compiled loops of ``jointdyn.hb._aft._project`` and by ``np.dot`` (BLAS)
  in a compiled function, beside one whole evaluation of the paper's damper
  at the same size. The loops are slower than BLAS; they are kept because
  Numba's ``np.dot`` imports ``scipy.linalg`` when its code is loaded from
  the cache (0.2-0.4 s of the start of every ``jointdyn frc --method hb``),
  and this table says what they cost in exchange.
* Cold compile of each hand-written path (fresh ``NUMBA_CACHE_DIR``, in a
  subprocess), the cost they add to a first run.

Each timing is the best of repeats (CPU time), both paths measured in the
same process one after the other. The threshold ``LinearSolveOptions.small_solve`` (largest size given to the
compiled path) is set from this table, measured with ``OPENBLAS_NUM_THREADS=1``
(on a shared machine a threaded BLAS spins on busy cores and its CPU time
says nothing about the algorithm).
"""

from __future__ import annotations

import os
import subprocess
import sys
import tempfile
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
DOFS = (1, 2, 5, 10, 20, 50)
H = 7

_COMPILE = r"""
import sys, time
import numpy as np
which = sys.argv[1]
from jointdyn.hb import stability as S
from jointdyn.continuation import linalg as K
t = time.process_time()
if which == "lu":
    Jy = np.eye(3); Jl = np.ones(3); d = np.ones(4)
    K._newton_direction_small(Jy, Jl, d, np.ones(3), np.ones(4), np.ones(4))
    K._tangent_small(Jy, Jl, d)
print(time.process_time() - t)
"""


def _chain(n, eta):
    import numpy as np

    from jointdyn import HarmonicLoad, System
    from jointdyn.laws import Jenkins
    from jointdyn.systems import Contact

    k = 3.9e5
    K = np.zeros((n, n))
    K[0, 0] = k  # spring to ground, then springs between neighbours
    for i in range(n - 1):
        K[i, i] += k
        K[i + 1, i + 1] += k
        K[i, i + 1] = K[i + 1, i] = -k
    M = 10.0 * np.eye(n)
    f = np.zeros(n)
    f[0] = 40.0
    law = Jenkins(kt=3e5, mu=0.5, n_ref=100.0)
    return System(M=M, C=1e-4 * K, K=K, force=f,
                  contacts=(Contact(law, dof=0, normal=HarmonicLoad(100.0, eta * 100.0, phase_deg=np.degrees(0.3))),))


def _jacobian(n, eta):
    """(problem, JX, w): the HB Jacobian where the contact slips part of the period."""
    import numpy as np

    from jointdyn.hb import HBProblem

    p = HBProblem(_chain(n, eta), harmonics=H, samples=128)
    g = 1.1
    X = p.linear_guess(g)
    q = abs(X[2 * p.n]) * 3e5 / 50.0  # first-harmonic sine coefficient of DOF 0 in units of fy/kt
    ev = p.evaluate(X * (3.0 / max(q, 1e-12)), g)
    assert np.any(ev.code != 0) and np.any(ev.code == 0), "the contact must stick part of the period"
    return p, ev.JX, p.omega(g)


def _best(fn, budget):
    """Best CPU time of fn() over repeats filling about ``budget`` seconds (at least 2)."""
    fn()
    best = float("inf")
    spent = 0.0
    reps = 0
    while reps < 2 or spent < budget:
        t = time.process_time()
        fn()
        dt = time.process_time() - t
        best = min(best, dt)
        spent += dt
        reps += 1
    return best


def _hill_row(n, eta, budget):
    import numpy as np

    from jointdyn.hb import StabilityOptions
    from jointdyn.hb import stability as S

    p, JX, w = _jacobian(n, eta)
    M, C = p.system.M, p.system.C
    D2iJ, B1, _, parity = S._hill_parts(M, C, H)
    JXs = np.repeat(JX[None], 32, axis=0)
    ws = np.full(32, w)
    batched = _best(lambda: S._hill_growth_batch(D2iJ, JXs, B1[0], B1[1], ws, parity, 2 * n), budget) / 32
    lapack = _best(lambda: S._hill_eigvals_lapack(JX, M, C, w, H), budget)
    chosen = _best(lambda: S._hill_all(JX, M, C, w, H, StabilityOptions().small_eig), budget)
    split = S._parity_blocks(S._hill_matrix(JX, M, C, w, H), parity) is not None
    return {"dofs": n, "companion_rows": 2 * JX.shape[0], "parity_split": split,
            "batch_per_point_s": batched, "lapack_s": lapack, "lapack_over_batch": lapack / batched,
            "default_path_s": chosen}


def _solve_row(n, budget):
    import numpy as np

    from jointdyn.continuation import linalg as K

    p, JX, w = _jacobian(n, 0.0)
    rng = np.random.default_rng(1)
    size = JX.shape[0]
    Jy = JX / 3e5  # scaled as in the continuation (unknowns in fy/kt, residual in fy)
    Jl = rng.standard_normal(size)
    d = rng.standard_normal(size + 1)
    d /= np.linalg.norm(d)
    R = rng.standard_normal(size) * 1e-3
    v = rng.standard_normal(size + 1)
    u = v + 1e-3 * d
    compiled = _best(lambda: K._newton_direction_small(Jy, Jl, d, R, v, u), budget)
    lapack = _best(lambda: K._lapack_solve(K._bordered(Jy, Jl, d), K._border_rhs(R, d, v, u)), budget)
    chosen = _best(lambda: K._newton_direction(Jy, Jl, d, R, v, u), budget)
    a = K._newton_direction_small(Jy, Jl, d, R, v, u)[0]
    b = K._lapack_solve(K._bordered(Jy, Jl, d), K._border_rhs(R, d, v, u))[0]
    return {"dofs": n, "unknowns": size + 1, "compiled_s": compiled, "lapack_s": lapack,
            "lapack_over_compiled": lapack / compiled, "default_path_s": chosen,
            "max_rel_diff": float(np.max(np.abs(a - b)) / np.max(np.abs(b)))}


_DOT = None


def _dot_projection():
    """``np.dot`` for the projection, compiled once here (not in jointdyn: it imports scipy.linalg)."""
    global _DOT
    if _DOT is None:
        import numba
        import numpy as np

        @numba.njit(cache=False)
        def dot(P, Tc, dT, F, G):
            F[:] = np.dot(P, Tc)
            G[:] = np.dot(P, dT)

        _DOT = dot
    return _DOT


def _projection_row(h, ns, budget):
    import numpy as np

    from jointdyn import System
    from jointdyn.hb import HBProblem
    from jointdyn.hb import _aft as A

    rng = np.random.default_rng(2)
    m = 2 * h + 1
    nd = m + 1
    P = rng.standard_normal((m, ns))
    Tc = rng.standard_normal(ns)
    dT = rng.standard_normal((ns, nd))
    T = np.empty((1, ns))
    proj = (np.empty(m), np.empty((m, nd)))
    F2, G2 = np.empty(m), np.empty((m, nd))
    dot = _dot_projection()
    reps = 200

    def loops():
        for _ in range(reps):
            A._project(0, P, Tc, dT, T, proj)

    def blas():
        for _ in range(reps):
            dot(P, Tc, dT, F2, G2)

    looped = _best(loops, budget) / reps
    blased = _best(blas, budget) / reps
    assert np.allclose(proj[0], F2) and np.allclose(proj[1], G2)
    p = HBProblem(System.paper_damper(eta=0.5, beta=2.0), harmonics=h, samples=ns)
    g = 1.2
    X = p.linear_guess(g)
    evaluation = _best(lambda: p.evaluate(X, g), budget)
    return {"harmonics": h, "samples": ns, "directions": nd, "loops_s": looped, "blas_s": blased,
            "loops_over_blas": looped / blased, "paper_damper_evaluation_s": evaluation,
            "extra_share_of_evaluation": (looped - blased) / evaluation}


def _cold_compile(which):
    env = dict(os.environ)
    env["PYTHONPATH"] = str(SRC) + os.pathsep + env.get("PYTHONPATH", "")
    with tempfile.TemporaryDirectory() as cache:
        env["NUMBA_CACHE_DIR"] = cache
        r = subprocess.run([sys.executable, "-c", _COMPILE, which], capture_output=True, text=True, env=env,
                           check=True)
    return float(r.stdout.split()[-1])


def run(quick: bool = False) -> dict:
    sys.path.insert(0, str(SRC))
    from jointdyn.continuation import LinearSolveOptions
    from jointdyn.hb import StabilityOptions

    dofs = DOFS[:-1] if quick else DOFS
    budget = 0.05 if quick else 0.3
    out = {
        "harmonics": H,
        "hill_eigenvalues": [_hill_row(n, eta, budget) for n in dofs for eta in (0.0, 0.5)],
        "bordered_solve": [_solve_row(n, budget) for n in dofs],
        "aft_projection": [_projection_row(h, ns, budget) for h, ns in ((7, 128), (7, 256), (15, 512))],
        "thresholds": {"small_eig": StabilityOptions().small_eig, "CONT_SMALL_SOLVE": LinearSolveOptions().small_solve},
    }
    if not quick:
        out["cold_compile_s"] = {"bordered_lu": _cold_compile("lu")}
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
