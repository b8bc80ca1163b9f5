"""tmdsimpy's EPMC backbone of the node-pair chain or the shipped lap joint, for the side-by-side of docs/performance.md.

The model is the chain of ``benchmarks/bench_hb_interface_chain.py`` (``chain(nodes)``),
restated here in plain numpy (:func:`chain_model`; tests/test_modes_tmdsimpy_interface.py
checks that it is the same as jointdyn's): ``nodes`` nodes with three DOFs each (t1, t2, n),
M = 0.1 I kg, K the chain springs (1e5, 1.3e5, 2e5 N/m between neighbours along t1, t2, n)
plus ground springs (1e3, 4e3, 1e3 N/m), C = 1e-4 K, and at every node a node pair against
ground: kt = 2e4 N/m, kn = 5e4 N/m, mu = 0.5, preload P_i = 10 (0.2 + exp(-((i - nodes/2) /
(nodes/4))^2)) N. The modal amplitude is the first-harmonic amplitude of DOF 0 (t1 of the
first node); the range is 0.01..10 fy / kt with kt = sum of the pairs' kt and fy = sum of
their slip forces mu P (jointdyn's ``reference_scales``).

tmdsimpy (github.com/tmd-lab/tmdsimpy, MIT) is not a dependency of jointdyn: this script
runs in an interpreter where tmdsimpy and jax are importable (e.g. a scratch virtual
environment with ``jax[cpu]`` and ``PYTHONPATH`` holding tmdsimpy's checkout) and exits
with a message, status 0, where they are not. How tmdsimpy is set up:

* ``VibrationSystem(M, K, C=C)`` and one ``ElasticDryFriction3D(Q_i, T_i, kt, kn, mu, u0=0,
  meso_gap=-P_i / kn)`` per pair (its examples' use: one element per contact point), Q_i the
  3 x n selection of the pair's (t1, t2, n) DOFs and T_i = Q_i^T. tmdsimpy's normal force is
  max(0, kn (u_n - meso_gap)) = max(0, P_i + kn u_n), jointdyn's N = max(0, P + kn g) with
  g = u_n; the preload's own force on the structure is balanced in jointdyn (the structure
  feels N - P), here by a static force P_i on each normal DOF (EPMC's ``Fl[:n]``), so the
  structure is at rest at x = 0 with N = P in both.
* Its tangential law clips each tangential direction to mu N on its own (a square, where
  jointdyn's disc is round); the first mode moves along t1 only (K does not couple the
  directions, and nothing drives t2 or n), where the two are the same 1-D law.
* ``epmc_res`` with harmonics 0..H, ``Nt`` AFT samples and the phase constraint "sine of DOF
  0's first harmonic = 0" (jointdyn's), from the stuck linear mode (K plus kt, kt, kn at each
  node; mass-normalised shape, xi0 = phi^T C phi), in log10 of tmdsimpy's mass-normalised modal
  amplitude ``la``, conditioned as in tmdsimpy's EPMC example (examples/structures/brb_epmc.py:
  ``harmonic_wise_conditioning``, omega and xi by their starting values).
* Solved by tmdsimpy's ``NonlinearSolverOMP`` (full Newton) at ``--points`` equally spaced ``la``
  (:func:`run`), each from the secant prediction of the two previous solutions; a step whose
  Newton fails or whose frequency jumps by more than 10 % is halved (sub-steps). The sweep ends
  at the first ``la`` where no step down to 1e-3 converges (reported). Timed after a first
  residual evaluation that compiles the JAX code.
* tmdsimpy's own ``Continuation`` (pseudo-arc-length) with its EPMC example's configuration
  (:data:`SOLVER_CONFIG`, :data:`CONTINUATION_CONFIG`) left the branch at the onset of slip (it
  jumped to log-amplitudes of order -1e11); ``--continuation`` runs it and reports its points.
* ``--jointdyn TMDSIMPY_JSON`` (in jointdyn's environment) solves jointdyn's EPMC
  (:class:`jointdyn.modes.EPMCProblem`, bordered by the same modal amplitude: a sweep in
  jointdyn's own parameter, DOF 0's amplitude, finds no solution past 3.2e-4 m on this branch) of ``chain(nodes)`` at the
  log-amplitudes of a tmdsimpy result by the same natural continuation, times it, and gives the
  largest differences in DOF 0's amplitude, frequency and damping ratio.

``--model lap`` takes the shipped lap joint instead (:func:`lap_model`: the System of
``benchmarks/bench_hb_scale.py``, 733 DOFs dense, 120 two-sided pairs, each a tmdsimpy element on its
relative coordinates x_a - x_b, the span 2e-6..2e-3 m at the output DOF); jointdyn's side then
assembles its harmonic-block Jacobians as one matrix for the bordered Newton.

Run (prints JSON, ``--out`` writes it)::

    PYTHONPATH=/path/to/tmdsimpy-checkout python docs/scripts/tmdsimpy_chain_epmc.py \\
        --model chain16 --harmonics 5 --samples 128 --out tmdsimpy_chain16.json
    python docs/scripts/tmdsimpy_chain_epmc.py --jointdyn tmdsimpy_chain16.json
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import platform
import subprocess
import sys
import time
from pathlib import Path

import numpy as np

KT, KN, MU = 2e4, 5e4, 0.5


def chain_model(nodes: int) -> dict:
    """M, C, K (kg, N s/m, N/m), preloads P (N), per-pair stiffnesses and mu, the pairs' DOFs (jointdyn's
    ``a_t1, a_t2, a_n, b_t1, b_t2, b_n``, -1 for ground), the output DOF and the amplitude span (m, at the
    output DOF on the linear mode: 0.01..10 fy / kt of the patch) of the chain (module docstring)."""
    n = 3 * nodes
    K = np.zeros((n, n))
    for i in range(nodes - 1):
        for d, kd in enumerate((1e5, 1.3e5, 2e5)):
            a, b = 3 * i + d, 3 * (i + 1) + d
            K[a, a] += kd
            K[b, b] += kd
            K[a, b] -= kd
            K[b, a] -= kd
    K[np.arange(n), np.arange(n)] += np.tile([1e3, 4e3, 1e3], nodes)
    P = 10.0 * (0.2 + np.exp(-((np.arange(nodes) - nodes / 2) / (nodes / 4)) ** 2))
    pairs = np.column_stack((3 * np.arange(nodes)[:, None] + np.arange(3), np.full((nodes, 3), -1)))
    a_ref = MU * P.sum() / (KT * nodes)  # fy / kt of the patch, m
    return {"name": f"chain{nodes}", "M": 0.1 * np.eye(n), "C": 1e-4 * K, "K": K, "P": P,
            "kt": np.full(nodes, KT), "kn": np.full(nodes, KN), "mu": np.full(nodes, MU), "pairs": pairs,
            "output_dof": 0, "span_m": (0.01 * a_ref, 10.0 * a_ref)}


#: the lap joint's span at its output DOF, m: ``benchmarks/bench_hb_scale.py``'s AMPLITUDE_M
LAP_SPAN_M = (2e-6, 2e-3)


def lap_model() -> dict:
    """The shipped lap joint as ``benchmarks/bench_hb_scale.py`` measures it (jointdyn's
    ``figures.lap.lap_joint_system``: 733 DOFs dense, modal damping of the stuck modes, 120 two-sided
    pairs), in the form of :func:`chain_model` (needs jointdyn)."""
    from jointdyn.damping import dense_damping
    from jointdyn.figures import lap

    s, lj = lap.lap_joint_system(lap.LAP_FORCE_N, lap.LAP_ZETA)
    itf = s.interfaces[0]
    npairs = itf.pairs.shape[0]
    per = lambda v: np.broadcast_to(np.asarray(v, dtype=float), (npairs,)).copy()  # noqa: E731
    return {"name": "lap", "M": np.asarray(s.M), "C": np.asarray(dense_damping(s.C)), "K": np.asarray(s.K),
            "P": per(itf.preload), "kt": per(itf.kt), "kn": per(itf.kn), "mu": per(itf.mu),
            "pairs": np.asarray(itf.pairs), "output_dof": int(s.output_dof), "span_m": LAP_SPAN_M}


def model(name: str) -> dict:
    """:func:`chain_model` for ``chainN`` (N nodes), :func:`lap_model` for ``lap``."""
    if name == "lap":
        return lap_model()
    if name.startswith("chain") and name[5:].isdigit():
        return chain_model(int(name[5:]))
    raise ValueError(f"--model must be lap or chainN (N nodes), got {name!r}")


def _selection(pair, n: int) -> np.ndarray:
    """The 3 x n selection of a pair's relative (t1, t2, n) displacement: x[a] - x[b] (-1: ground)."""
    Q = np.zeros((3, n))
    for k in range(3):
        if pair[k] >= 0:
            Q[k, pair[k]] += 1.0
        if pair[3 + k] >= 0:
            Q[k, pair[3 + k]] -= 1.0
    return Q


def _stuck_mode(m: dict):
    """(omega rad/s, mass-normalised shape with a positive output DOF) of the stuck linear first mode."""
    from scipy.linalg import eigh

    n = m["M"].shape[0]
    Ks = m["K"].copy()
    for i, pair in enumerate(m["pairs"]):
        Q = _selection(pair, n)
        Ks += Q.T @ np.diag([m["kt"][i], m["kt"][i], m["kn"][i]]) @ Q
    lam, vec = eigh(Ks, m["M"], subset_by_index=[0, 0])
    phi = vec[:, 0] / math.sqrt(vec[:, 0] @ m["M"] @ vec[:, 0])
    return math.sqrt(lam[0]), phi * np.sign(phi[m["output_dof"]])


def _system(m: dict):
    from tmdsimpy.jax.nlforces import ElasticDryFriction3D
    from tmdsimpy.vibration_system import VibrationSystem

    n = m["M"].shape[0]
    vib = VibrationSystem(m["M"], m["K"], C=m["C"])
    for i, (pair, p) in enumerate(zip(m["pairs"], m["P"])):
        Q = _selection(pair, n)
        vib.add_nl_force(ElasticDryFriction3D(Q, Q.T.copy(), m["kt"][i], m["kn"][i], m["mu"][i], u0=0.0,
                                              meso_gap=-p / m["kn"][i]))
    return vib


#: tmdsimpy's EPMC example (examples/structures/brb_epmc.py, "Normal" settings): its Newton solver's
#: and its continuation's configuration, with more steps allowed (three decades here, not 3.5 of log10)
SOLVER_CONFIG = {"max_steps": 12, "reform_freq": 2, "verbose": False, "xtol": None, "rtol": 1e-9, "etol": None,
                 "xtol_rel": 1e-6, "rtol_rel": None, "etol_rel": None, "stopping_tol": ["xtol"],
                 "accepting_tol": ["xtol_rel", "rtol"]}
DS, DSMAX, DSMIN = 0.08, 0.125 * 1.4, 0.02
#: Newton solves of :func:`run` stop on a conditioned step (2-norm) below XTOL or a residual
#: (2-norm, N) below RTOL: where a pair's state changes between iterates, the residual is not
#: smooth and full Newton can stall above the step tolerance
XTOL, RTOL = 1e-10, 1e-9
#: natural continuation in log10 of the modal amplitude: a step whose Newton fails or whose
#: frequency moves by more than MAX_OMEGA_CHANGE (a fraction) is halved, down to MIN_STEP
MAX_OMEGA_CHANGE, MIN_STEP = 0.1, 1e-3
CONTINUATION_CONFIG = {"DynamicCtoP": True, "TargetNfev": 4, "MaxSteps": 400, "dsmin": DSMIN, "dsmax": DSMAX,
                       "verbose": -1, "corrector": "Ortho", "FracLam": 0.5, "FracLamList": [0.9, 0.1, 1.0, 0.0],
                       "backtrackStop": 0.05}


def _setup(name: str, H: int, Nt: int) -> dict:
    """tmdsimpy's EPMC residual of the model, its starting point and the amplitude span (log10 of its
    mass-normalised modal amplitude: the model's ``span_m`` at its output DOF on the linear mode, and 0.15
    more)."""
    import tmdsimpy.utils.harmonic as hutils

    m = model(name)
    n, dof = m["M"].shape[0], m["output_dof"]
    h = np.arange(H + 1)
    Nhc = hutils.Nhc(h)
    vib = _system(m)
    w0, phi = _stuck_mode(m)
    Fl = np.zeros(n * Nhc)
    for pair, p in zip(m["pairs"], m["P"]):  # static forces on the normal DOFs: balance the preloads
        Fl[:n] += p * _selection(pair, n)[2]
    Fl[2 * n + dof] = 1.0  # phase: sine of DOF 0's first harmonic = 0
    Uwxa0 = np.zeros(n * Nhc + 3)
    Uwxa0[n:2 * n] = phi
    la0 = math.log10(m["span_m"][0] / phi[dof])
    Uwxa0[-3:] = w0, float(phi @ m["C"] @ phi), la0
    count = [0]

    def res(Uwxa, calc_grad=True):
        count[0] += 1
        return vib.epmc_res(Uwxa, Fl, h, Nt=Nt, calc_grad=calc_grad)

    # harmonic-wise conditioning (tmdsimpy's), the static part with a smaller floor, omega and xi by
    # their starting values (as in tmdsimpy's EPMC example)
    CtoP = hutils.harmonic_wise_conditioning(Uwxa0, n, h, delta=1e-3)
    CtoP[:n] = hutils.harmonic_wise_conditioning(Uwxa0, n, h, delta=1e-5)[:n]
    CtoP[-3:-1] = np.abs(Uwxa0[-3:-1])
    return {"n": n, "dof": dof, "res": res, "count": count, "Uwxa0": Uwxa0, "CtoP": CtoP, "span_m": m["span_m"],
            "w0": w0, "la0": la0, "la1": math.log10(m["span_m"][1] / phi[dof]) + 0.15}


def _amplitude_row(Uwxa, R, n: int, dof: int) -> list:
    """[log10 modal amplitude, amplitude of DOF 0 m, omega rad/s, damping ratio xi / (2 omega), largest
    force residual N]."""
    X = np.asarray(Uwxa, dtype=float)
    amp = 10.0 ** X[-1] * math.hypot(X[n + dof], X[2 * n + dof])
    return [float(X[-1]), amp, float(X[-3]), float(X[-2] / (2.0 * X[-3])),
            float(np.max(np.abs(np.asarray(R)[:-2])))]


def run(name: str, H: int, Nt: int, points: int = 40) -> dict:
    """tmdsimpy's EPMC backbone of the model at ``points`` equally spaced values of its log-amplitude
    over the span of :func:`_setup`, up to the first one where Newton finds no solution (module docstring)."""
    from tmdsimpy.jax.solvers import NonlinearSolverOMP

    S = _setup(name, H, Nt)
    n, dof, res, CtoP = S["n"], S["dof"], S["res"], S["CtoP"][:-1]
    t = time.perf_counter()
    res(S["Uwxa0"])  # compiles the JAX code
    compile_s = time.perf_counter() - t
    S["count"][0] = 0
    solver = NonlinearSolverOMP(config={"max_steps": 30, "reform_freq": 1, "verbose": False, "rtol": RTOL,
                                        "stopping_tol": ["xtol", "rtol"]})
    las = np.linspace(S["la0"], S["la1"], points)

    def solve(la, guess):
        fun = solver.conditioning_wrapper(lambda v, calc_grad=True: res(np.hstack((v, la)), calc_grad)[0:2], CtoP)
        with contextlib.redirect_stdout(io.StringIO()):
            Xc, _, _, sol = solver.nsolve(fun, guess / CtoP, xtol=XTOL)
        return np.hstack((np.asarray(Xc) * CtoP, la)), bool(sol["success"])

    path = [S["Uwxa0"]]  # every solved point, sub-steps included
    sols, halvings, stopped = [], 0, None
    t, tc = time.perf_counter(), time.process_time()
    for k, target in enumerate(las):
        la = target
        while stopped is None:  # natural continuation in la; a step that fails or jumps is halved
            x1, x0 = path[-1], path[-2] if len(path) > 1 else path[-1]
            guess = x1[:-1] + (x1[:-1] - x0[:-1]) * (la - x1[-1]) / (x1[-1] - x0[-1]) if x1[-1] != x0[-1] else x1[:-1]
            X, ok = solve(la, guess)
            if ok and X[-3] > 0 and abs(X[-3] - x1[-3]) <= MAX_OMEGA_CHANGE * x1[-3]:
                path.append(X)
                if la == target:
                    break
                la = target
            elif la - x1[-1] < MIN_STEP:
                stopped = float(la)
            else:
                print(f"  halved: la={la:.5f} omega={X[-3]:.4f} converged={ok}", file=sys.stderr, flush=True)
                la, halvings = 0.5 * (x1[-1] + la), halvings + 1
        if stopped is not None:
            break
        sols.append(X)
        last = time.perf_counter() - t, time.process_time() - tc
        print(f"point {k}: la={target:.4f} omega={X[-3]:.6f} after {last[0]:.1f} s", file=sys.stderr, flush=True)
    wall, cpu = time.perf_counter() - t, time.process_time() - tc
    evaluations = S["count"][0]
    rows = [_amplitude_row(X, res(X, False)[0], n, dof) for X in sols]
    return {"model": name, "harmonics": H, "samples": Nt, "wall_s": wall, "cpu_s": cpu, "compile_s": compile_s,
            "residual_evaluations": evaluations, "points": len(rows), "solves": len(path) - 1, "halvings": halvings,
            "wall_s_to_last_point": last[0], "cpu_s_to_last_point": last[1], "no_solution_from_la": stopped,
            "la_range": [S["la0"], S["la1"]], "span_m": list(S["span_m"]),
            "omega_stuck_rad_s": S["w0"], "backbone": rows}


def run_continuation(name: str, H: int, Nt: int) -> dict:
    """tmdsimpy's ``Continuation`` with its EPMC example's recipe over the same span: the points it
    reports (log-amplitude, omega), until it ends or leaves the span."""
    from tmdsimpy.continuation import Continuation
    from tmdsimpy.jax.solvers import NonlinearSolverOMP

    S = _setup(name, H, Nt)
    CtoP = S["CtoP"].copy()
    CtoP[-1] = abs(S["la1"] - S["la0"])
    trail = []

    def progress(XlamP, dirP):
        trail.append([float(XlamP[-1]), float(XlamP[-3])])
        print(f"point la={XlamP[-1]:.4f} omega={XlamP[-3]:.4f} rad/s", file=sys.stderr, flush=True)

    solver = NonlinearSolverOMP(config=dict(SOLVER_CONFIG))
    cont = Continuation(solver, ds0=DS, CtoP=CtoP, config={**CONTINUATION_CONFIG, "callback": progress,
                                                           "xtol": 1e-6 * math.sqrt(S["Uwxa0"].size)})
    t = time.perf_counter()
    with contextlib.redirect_stdout(io.StringIO()):
        try:
            cont.continuation(S["res"], S["Uwxa0"], S["la0"], S["la1"])
        except Exception as exc:  # noqa: BLE001 - what it raised is part of the report
            trail.append([repr(exc)])
    return {"continuation_points": trail, "continuation_wall_s": time.perf_counter() - t}


def _jointdyn_at_modal_amplitude(problem):
    """jointdyn's scaled EPMC residual with log10 of DOF 0's amplitude as one more unknown and one more
    equation, log10 of the modal amplitude sqrt(a1^T M a1 + b1^T M b1) = ``la`` (tmdsimpy's parameter),
    with its exact Jacobian: ``(R, dR/dz, dR/dla)`` of ``z = (v, lam)`` for jointdyn's Newton."""
    n, M = problem.n, problem.system.M

    def residual(z, la):
        v, lam = z[:-1], float(z[-1])
        Rs, Jv, Jlam = problem.residual(v, lam)
        Jv = Jv.toarray() if hasattr(Jv, "toarray") else Jv  # harmonic blocks (a reduced model): as one matrix
        Y = problem.unpack(v, lam)[0] / 10.0 ** lam
        m2 = float(Y[n:2 * n] @ M @ Y[n:2 * n] + Y[2 * n:3 * n] @ M @ Y[2 * n:3 * n])
        g = np.zeros(z.size)
        g[n:3 * n] = np.concatenate((M @ Y[n:2 * n], M @ Y[2 * n:3 * n])) / (m2 * math.log(10.0))
        g[[problem.i_omega, problem.i_xi]] = 0.0  # omega and xi sit where Y holds 1 and 0
        g[-1] = 1.0
        dla = np.zeros(z.size)
        dla[-1] = -1.0
        return np.append(Rs, lam + 0.5 * math.log10(m2) - la), np.vstack((np.column_stack((Jv, Jlam)), g)), dla

    return residual


def jointdyn_system(name: str):
    """jointdyn's System of the model :func:`model` restates: the benchmark's ``chain(N)`` or the lap joint."""
    if name == "lap":
        from jointdyn.figures import lap

        return lap.lap_joint_system(lap.LAP_FORCE_N, lap.LAP_ZETA)[0]
    sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "benchmarks"))
    from bench_hb_interface_chain import chain

    return chain(int(model(name)["P"].size))


def run_jointdyn(reference: dict) -> dict:
    """jointdyn's EPMC (:class:`jointdyn.modes.EPMCProblem` bordered by the modal amplitude, solved by
    :func:`jointdyn.continuation.newton`) of the benchmark's ``chain(nodes)`` at the log-amplitudes of
    a tmdsimpy run, by the same natural continuation (secant predictor, a step halved where Newton
    fails or the frequency jumps), timed after a first solve that loads or compiles the kernels."""
    from jointdyn.continuation import newton
    from jointdyn.modes import EPMCProblem
    from jointdyn.modes import EPMCOptions

    p = EPMCProblem(jointdyn_system(reference["model"]), harmonics=reference["harmonics"],
                    samples=reference["samples"])
    residual = _jointdyn_at_modal_amplitude(p)
    las = [r[0] for r in reference["backbone"]]
    v0 = p.linear_guess()
    Y = p.unpack(v0, 0.0)[0]
    z0 = np.append(v0, las[0] - 0.5 * math.log10(float(Y[p.n:2 * p.n] @ p.system.M @ Y[p.n:2 * p.n])))
    newton(residual, z0, las[0], tol=EPMCOptions().tol, max_iter=30)  # loads or compiles the kernels
    path = [(las[0], z0)]
    rows, halvings, stopped = [], 0, None
    t, tc = time.perf_counter(), time.process_time()
    for target in las:
        la = target
        while stopped is None:
            (l1, z1), (l0, z0) = path[-1], path[-2] if len(path) > 1 else path[-1]
            guess = z1 + (z1 - z0) * (la - l1) / (l1 - l0) if l1 != l0 else z1
            z, ok, _ = newton(residual, guess, la, tol=EPMCOptions().tol, max_iter=30)  # as tmdsimpy's
            w1 = p.unpack(z1[:-1], z1[-1])[1]
            _, w, xi = p.unpack(z[:-1], z[-1])
            if ok and w > 0 and abs(w - w1) <= MAX_OMEGA_CHANGE * w1:
                path.append((la, z))
                if la == target:
                    break
                la = target
            elif la - l1 < MIN_STEP:
                stopped = la
            else:
                la, halvings = 0.5 * (l1 + la), halvings + 1
        if stopped is not None:
            break
        rows.append([target, 10.0 ** float(z[-1]), w, xi / (2.0 * w)])
    wall, cpu = time.perf_counter() - t, time.process_time() - tc
    return {"wall_s": wall, "cpu_s": cpu, "solves": len(path) - 1, "halvings": halvings,
            "no_solution_from_la": stopped, "backbone": rows}


def compare(tmd: dict, jd: dict, rtol: float = 1e-9) -> dict:
    """Largest relative differences of DOF 0's amplitude, frequency and damping ratio over the leading
    points where the two agree to ``rtol`` (``same_points``; past them the sweeps may follow different
    branches), and the differences at the first point past them."""
    b = np.array(jd["backbone"])
    a = np.array(tmd["backbone"])[:len(b), :4]
    d = np.abs(b[:, 1:] / a[:, 1:] - 1.0)
    same = int(np.argmax(d.max(axis=1) > rtol)) if np.any(d.max(axis=1) > rtol) else len(d)
    worst = d[:same].max(axis=0) if same else np.full(3, np.nan)
    out = {"same_points": same, "max_rel_diff_amplitude": float(worst[0]), "max_rel_diff_omega": float(worst[1]),
           "max_rel_diff_damping": float(worst[2])}
    if same < len(d):
        out["first_other_point"] = {"la": float(a[same, 0]), "rel_diff": d[same].tolist()}
    return out


def _provenance(commit: str | None) -> dict:
    import jax
    import scipy
    import tmdsimpy

    folder = Path(tmdsimpy.__file__).resolve().parent
    r = subprocess.run(["git", "-C", str(folder), "rev-parse", "HEAD"], check=False, capture_output=True, text=True)
    return {"tmdsimpy": commit or r.stdout.strip() or "(commit unknown: not a git checkout)",
            "python": platform.python_version(),
            "numpy": np.__version__, "scipy": scipy.__version__, "jax": jax.__version__}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--model", default="chain16", help="chainN (N nodes) or lap (the shipped lap joint)")
    ap.add_argument("--harmonics", type=int, default=5)
    ap.add_argument("--samples", type=int, default=128)
    ap.add_argument("--points", type=int, default=40)
    ap.add_argument("--continuation", action="store_true",
                    help="also try tmdsimpy's Continuation with its EPMC example's recipe")
    ap.add_argument("--jointdyn", metavar="TMDSIMPY_JSON",
                    help="run jointdyn instead, at the amplitudes of this tmdsimpy result, and compare")
    ap.add_argument("--out", help="write the JSON here too")
    ap.add_argument("--tmdsimpy-commit", help="tmdsimpy's commit, where its checkout is not a git work tree")
    args = ap.parse_args(argv)
    if args.jointdyn:  # jointdyn at the amplitudes of a tmdsimpy run (its JSON)
        tmd = json.loads(Path(args.jointdyn).read_text())
        out = run_jointdyn(tmd)
        out.update(compare(tmd, out))
    else:
        try:
            import jax  # noqa: F401
            import tmdsimpy  # noqa: F401
        except ImportError as exc:
            print(f"tmdsimpy side by side skipped: {exc}")
            return 0
        out = run(args.model, args.harmonics, args.samples, args.points)
        if args.continuation:
            out.update(run_continuation(args.model, args.harmonics, args.samples))
        out["provenance"] = _provenance(args.tmdsimpy_commit)
    text = json.dumps(out)
    print(text)
    if args.out:
        Path(args.out).write_text(text + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
