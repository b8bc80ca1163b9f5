"""Side-by-side comparison of harmonic-balance branches: jointdyn, tmdsimpy, pyHarm.

Writes the tables of docs/hb-comparison.md (between ``<!-- compare:start -->``
and ``<!-- compare:end -->``), computed here:

    PYTHONPATH=src python docs/scripts/hb_compare.py --write \\
        [--other-python PYTHON] [--tmdsimpy-path DIR]

The system is the Jenkins benchmark of ``benchmarks/bench_hb.py`` (SDOF,
m = 10 kg, k = 3.9e5 N/m, Jenkins kt = 3e5 N/m, fy = 50 N, zeta = 1e-3,
harmonics 0..7, 128 AFT samples per period, gamma = w / w0 from 0.6 to 1.8,
w0 = sqrt(k / m)) at F1 = 20 N (the benchmark) and F1 = 5 N. Each code runs
with its default continuation settings:

* jointdyn: ``frc_hb(system, 0.6, 1.8)``;
* tmdsimpy: ``Continuation(solver, CtoP, RPtoC)`` with the defaults of its
  ``config`` and the conditioning of its examples (harmonic-wise
  ``CtoP`` from the starting point, ``CtoP[-1] = lam1``, ``RPtoC`` from the
  diagonal of the conditioned Jacobian), ``VibrationSystem.hbm_res`` with
  ``VectorJenkins``;
* pyHarm: ``Maestro`` with an ``onlydofs`` substructure, ``GOElement``
  (mass, dto = 2), ``LinearSpring``, ``LinearDamper``, ``Jenkins`` and
  ``CosinusForcing`` connectors, and the ``frf`` analysis with its default
  options.

The other codes are optional: they are not dependencies of jointdyn. A code
runs in this interpreter when it is importable here, else in the
interpreter given by ``--other-python`` (``--tmdsimpy-path``: the folder
that holds tmdsimpy's ``tmdsimpy`` package, added to that interpreter's
path), which prints its points as JSON; a code that runs in neither is
reported as not run. Every code's points are measured in the same way, by
jointdyn, against the same reference:

* q = kt X / fy, X the half peak-to-peak of x(t) from the code's own
  harmonics (:func:`jointdyn.fourier.extrema`);
* the reference curve is jointdyn's harmonic balance solved afresh
  (:func:`jointdyn.hb.harmonic_balance`, same H and samples) at the gamma
  of every point, and at ``CHORD_FRACTIONS`` of every chord; the chord
  error in q is the largest relative distance in q between the straight
  line and the reference at those gammas (what a plot on linear axes
  shows), the chord distance the largest distance across the chord in
  the plane (gamma, ln q) (what jointdyn's ``chord_tol`` bounds, as in
  tests/test_hb_trust.py), the point error the relative distance in q at
  the code's own points (how far the code's curve itself is from the
  reference: the AFT of the three codes differs);
* the reference peak is the maximum of the reference q over gamma (a
  scan near the highest point, then a bounded scalar search);
* wall and CPU seconds: the best of ``REPEATS`` branches after one warm-up
  branch (compilation excluded) in the code's own process.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import json
import math
import os
import platform
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

PAGE = Path(__file__).resolve().parents[1] / "hb-comparison.md"
MARKERS = ("<!-- compare:start -->", "<!-- compare:end -->")

# the Jenkins benchmark (benchmarks/bench_hb.py)
M, K, KT, FY, ZETA = 10.0, 3.9e5, 3e5, 50.0, 1e-3
MU, N0 = 0.5, 100.0
H, SAMPLES = 7, 128
GAMMA_START, GAMMA_STOP = 0.6, 1.8
W0 = math.sqrt(K / M)
C = 2.0 * ZETA * math.sqrt(K * M)
F1S = (20.0, 5.0)

#: fractions of each chord where the reference is solved
CHORD_FRACTIONS = (0.25, 0.5, 0.75)
#: timed branches per code (after one warm-up branch)
REPEATS = 5
#: half-width in gamma of the search for the reference peak around the highest point
PEAK_SEARCH = 0.02
#: points of the scan for the reference peak
PEAK_SCAN = 81
#: absolute tolerance in gamma of the reference peak search
PEAK_XTOL = 1e-7
#: gamma STEP of the robustness grid's CLI runs (``--gamma 0.6:1.8:0.01``), the second jointdyn row
CLI_STEP = 0.01
JOINTDYN_STEP = f"jointdyn, max_step = {CLI_STEP:g}"
CODES = ("jointdyn", JOINTDYN_STEP, "tmdsimpy", "pyHarm")


# ---------------------------------------------------------------- the codes


def _timed(branch):
    """(result of the last call, best wall s, best CPU s, first call wall s)."""
    t = time.perf_counter()
    out = branch()
    first = time.perf_counter() - t
    wall = cpu = math.inf
    for _ in range(REPEATS):
        t, tc = time.perf_counter(), time.process_time()
        out = branch()
        wall = min(wall, time.perf_counter() - t)
        cpu = min(cpu, time.process_time() - tc)
    return out, wall, cpu, first


def run_jointdyn(f1: float, max_step: float | None = None) -> dict:
    """jointdyn's default branch (``frc_hb``): gamma, harmonics of x, timings, refined peak.

    ``max_step``: the largest gamma spacing (None: the API's default, no
    bound; the CLI passes the STEP of ``--gamma``).
    """
    import jointdyn
    from jointdyn.hb import continue_hb
    from jointdyn.hb import branch_dataset

    system = _system(f1)

    def branch():  # what frc_hb does, keeping the branch for its harmonics
        br = continue_hb(system, GAMMA_START, GAMMA_STOP, harmonics=H, samples=SAMPLES, max_step=max_step,
                         progress=False)
        return br, branch_dataset(br)

    (br, ds), wall, cpu, first = _timed(branch)
    coeffs = br.problem.dof_coefficients(br.X, 0, br.lam)
    return {"gamma": br.gamma().tolist(), "coefficients": np.asarray(coeffs).tolist(), "wall_s": wall,
            "cpu_s": cpu, "first_wall_s": first, "status": ds.attrs["status"],
            "refined_peak": (float(ds.attrs["peak_gamma"]), float(ds.attrs["peak_amplitude_q"])),
            "version": f"jointdyn {jointdyn.__version__} at commit {_commit(Path(__file__).resolve().parent)}"}


def run_tmdsimpy(f1: float) -> dict:
    """tmdsimpy's continuation with its default settings (the recipe of its examples)."""
    import tmdsimpy
    import tmdsimpy.utils.harmonic as hutils
    from tmdsimpy.continuation import Continuation
    from tmdsimpy.nlforces.vector_jenkins import VectorJenkins
    from tmdsimpy.solvers import NonlinearSolver
    from tmdsimpy.vibration_system import VibrationSystem

    h = np.arange(H + 1)
    lam0, lam1 = GAMMA_START * W0, GAMMA_STOP * W0

    def branch():
        vib = VibrationSystem(np.array([[M]]), np.array([[K]]), C=np.array([[C]]))
        vib.add_nl_force(VectorJenkins(np.array([[1.0]]), np.array([[1.0]]), KT, FY))
        fl = np.zeros(hutils.Nhc(h))
        fl[1] = f1  # cosine of the first harmonic
        solver = NonlinearSolver()
        u0 = np.zeros_like(fl)
        u0[1] = f1 / (K + KT - M * lam0**2)  # stuck linear response
        x, _, dfdx, _ = solver.nsolve(lambda u: vib.hbm_res(np.hstack((u, lam0)), fl, h, Nt=SAMPLES)[0:2], u0,
                                      verbose=False)
        uw0 = np.hstack((x, lam0))
        ctop = hutils.harmonic_wise_conditioning(uw0, 1, h, delta=1e-3 * abs(x[1]))
        ctop[-1] = lam1
        rptoc = 1.0 / np.max(np.abs(np.diag(dfdx * ctop[:-1])))
        cont = Continuation(solver, CtoP=ctop, RPtoC=rptoc)
        # default config: its progress goes to stdout (kept off the worker's JSON); with
        # verbose < 0 ("silent") it would keep unconverged steps instead of stopping there
        with contextlib.redirect_stdout(io.StringIO()):
            return cont.continuation(lambda uw: vib.hbm_res(uw, fl, h, Nt=SAMPLES), uw0, lam0, lam1)

    xl, wall, cpu, first = _timed(branch)
    return {"gamma": (xl[:, -1] / W0).tolist(), "coefficients": xl[:, :-1].tolist(), "wall_s": wall, "cpu_s": cpu,
            "first_wall_s": first, "status": "",
            "version": f"tmdsimpy (no version number) at commit {_commit(Path(tmdsimpy.__file__).resolve().parent)}"}


def _commit(folder: Path) -> str:
    """The git commit of the checkout holding ``folder``, or '(commit unknown)'."""
    r = subprocess.run(["git", "-C", str(folder), "rev-parse", "HEAD"], check=False, capture_output=True, text=True)
    return r.stdout.strip() if r.returncode == 0 else "(commit unknown)"


def run_pyharm(f1: float) -> dict:
    """pyHarm's nonlinear FRF analysis with its default options (accepted points).

    Run in a temporary folder: pyHarm writes a ``.pyHarm/`` folder where it
    is imported and run.
    """
    here = os.getcwd()
    with tempfile.TemporaryDirectory() as cwd:
        os.chdir(cwd)
        try:
            return _pyharm_branch(f1)
        finally:
            os.chdir(here)


def _pyharm_branch(f1: float) -> dict:
    """The body of :func:`run_pyharm`, in the folder it chose."""
    import logging
    from importlib.metadata import version

    import pyHarm

    logging.disable(logging.CRITICAL)

    def ntn(**kw):
        return {**kw, "connect": {"sub": [0]}, "dirs": [0]}

    data = {
        "system": {"type": "Base", "nh": H, "nti": SAMPLES},
        "substructures": {"sub": {"type": "onlydofs", "nnodes": 1, "ndofs": 1, "matching": [0]}},
        "connectors": {
            "mass": ntn(type="GOElement", dto=2, xo=1, k=M),
            "spring": ntn(type="LinearSpring", k=K),
            "damper": ntn(type="LinearDamper", k=C),
            "jenkins": ntn(type="Jenkins", k=KT, mu=MU, N0=N0),
            "force": ntn(type="CosinusForcing", amp=f1),
        },
        "analysis": {"frf": {"study": "frf", "puls_inf": GAMMA_START * W0, "puls_sup": GAMMA_STOP * W0,
                             "verbose": False}},
    }

    def branch():
        maestro = pyHarm.Maestro(data)
        maestro.operate()
        return np.array([s.x for s in maestro.nls["frf"].SolList if s.flag_accepted])

    x, wall, cpu, first = _timed(branch)
    return {"gamma": (x[:, -1] / W0).tolist(), "coefficients": x[:, :-1].tolist(), "wall_s": wall, "cpu_s": cpu,
            "first_wall_s": first, "status": "", "version": f"pyHarm-os {version('pyharm-os')}"}


def run_jointdyn_step(f1: float) -> dict:
    """jointdyn with the largest gamma spacing of the CLI's ``--gamma 0.6:1.8:0.01``."""
    return run_jointdyn(f1, max_step=CLI_STEP)


RUNNERS = {"jointdyn": run_jointdyn, JOINTDYN_STEP: run_jointdyn_step, "tmdsimpy": run_tmdsimpy,
           "pyHarm": run_pyharm}
MODULES = {"tmdsimpy": "tmdsimpy", "pyHarm": "pyHarm"}


def _importable(module: str) -> bool:
    import importlib.util

    return importlib.util.find_spec(module) is not None


def _run_elsewhere(code: str, f1: float, python: str, tmdsimpy_path: str | None) -> dict:
    """Run one code in another interpreter (``--worker``); its result or ``{"error": ...}``."""
    env = dict(os.environ)
    env.pop("PYTHONPATH", None)
    if tmdsimpy_path:
        env["PYTHONPATH"] = tmdsimpy_path
    cmd = [python, str(Path(__file__).resolve()), "--worker", code, "--f1", repr(f1)]
    with tempfile.TemporaryDirectory() as cwd:  # as in run_pyharm
        r = subprocess.run(cmd, check=False, capture_output=True, text=True, env=env, cwd=cwd)
    lines = [ln for ln in r.stdout.splitlines() if ln.startswith("{")]
    if r.returncode != 0 or not lines:
        tail = (r.stderr.strip().splitlines() or ["no output"])[-1]
        return {"error": f"failed in {python}: {tail}"}
    out = json.loads(lines[-1])
    out["environment"] = _environment(python, env)
    return out


def _environment(python: str, env: dict) -> str:
    code = "import sys, numpy, scipy; print(sys.version.split()[0], numpy.__version__, scipy.__version__)"
    r = subprocess.run([python, "-c", code], check=False, capture_output=True, text=True, env=env)
    py, npv, spv = r.stdout.split()
    return f"Python {py}, numpy {npv}, scipy {spv}"


def run_code(code: str, f1: float, python: str | None, tmdsimpy_path: str | None) -> dict:
    """A code's branch: here if importable, else in ``python``, else ``{"error": ...}``."""
    if code not in MODULES or _importable(MODULES[code]):
        out = RUNNERS[code](f1)
        import scipy

        out["environment"] = f"Python {platform.python_version()}, numpy {np.__version__}, scipy {scipy.__version__}"
        return out
    if python:
        return _run_elsewhere(code, f1, python, tmdsimpy_path)
    return {"error": f"{MODULES[code]} is not importable here and no --other-python was given"}


# ---------------------------------------------------------------- the measures


def _system(f1: float):
    from jointdyn import System
    from jointdyn.laws import Jenkins

    return System.sdof(m=M, k=K, law=Jenkins(kt=KT, mu=MU, n_ref=N0), f1=f1, zeta=ZETA)


class Reference:
    """jointdyn's harmonic balance solved afresh at any gamma (q cached per gamma)."""

    def __init__(self, f1: float):
        self.system = _system(f1)
        self.cache = {}

    def q(self, gamma: float) -> float:
        from jointdyn.hb import harmonic_balance

        g = float(gamma)
        if g not in self.cache:
            sol = harmonic_balance(self.system, g, harmonics=H, samples=SAMPLES)
            if not sol.status.ok:
                raise RuntimeError(f"reference harmonic balance did not converge at gamma = {g}")
            self.cache[g] = KT * sol.amplitude_m / FY
        return self.cache[g]

    def peak(self, g0: float):
        """(gamma, q) of the maximum of the reference within PEAK_SEARCH of g0.

        A scan on PEAK_SCAN points (the curve has a corner at the onset of
        slip, where a bracketing search alone can settle on the wrong side),
        then a bounded scalar search within one scan step of the best.
        """
        from scipy.optimize import minimize_scalar

        grid = np.linspace(g0 - PEAK_SEARCH, g0 + PEAK_SEARCH, PEAK_SCAN)
        best = grid[int(np.argmax([self.q(g) for g in grid]))]
        step = grid[1] - grid[0]
        r = minimize_scalar(lambda g: -self.q(g), bounds=(best - step, best + step), method="bounded",
                            options={"xatol": PEAK_XTOL})
        return (float(r.x), -float(r.fun)) if -r.fun >= self.q(best) else (float(best), self.q(best))


def q_of(coefficients) -> np.ndarray:
    """kt X / fy per point, X the half peak-to-peak of x(t) from its harmonics 0..H."""
    from jointdyn.fourier import extrema

    out = []
    for c in np.asarray(coefficients, dtype=float):
        hi, lo = extrema(c, H)
        out.append(KT * 0.5 * (hi - lo) / FY)
    return np.array(out)


def measures(res: dict, ref: Reference) -> dict:
    """Points, gamma gap, chord and point errors, peak against the reference."""
    g = np.asarray(res["gamma"])
    q = q_of(res["coefficients"])
    inside = (g >= GAMMA_START - 1e-12) & (g <= GAMMA_STOP + 1e-12)
    errs = [abs(qi / ref.q(gi) - 1.0) for gi, qi in zip(g[inside], q[inside])]
    worst = int(np.argmax(errs))
    point_err, point_at = errs[worst], float(g[inside][worst])
    chord_err, at, normal = 0.0, math.nan, 0.0
    lq = np.log(q)
    for i in range(g.size - 1):
        slope = (lq[i + 1] - lq[i]) / (g[i + 1] - g[i])
        for f in CHORD_FRACTIONS:
            gm = g[i] + f * (g[i + 1] - g[i])
            if not GAMMA_START <= gm <= GAMMA_STOP:
                continue
            qr = ref.q(gm)
            e = abs((q[i] + f * (q[i + 1] - q[i])) / qr - 1.0)
            if e > chord_err:
                chord_err, at = e, gm
            normal = max(normal, abs(lq[i] + f * (lq[i + 1] - lq[i]) - math.log(qr)) / math.hypot(1.0, slope))
    top = int(np.argmax(q))
    return {"points": int(g.size), "range": (float(g.min()), float(g.max())), "max_gap": float(np.max(np.abs(np.diff(g)))), "chord_err": chord_err,
            "chord_at": at, "chord_normal": normal, "point_err": point_err, "point_at": point_at, "peak_gamma": float(g[top]),
            "peak_q": float(q[top])}


# ---------------------------------------------------------------- the page


def table(f1: float, rows: dict, ref_peak) -> str:
    gp, qp = ref_peak
    head = (f"**F1 = {f1:g} N.** Reference peak (jointdyn's harmonic balance solved afresh, maximised over "
            f"gamma): gamma = {gp:.5f}, q = {qp:.5f}.")
    columns = ("| code | points | gamma covered | largest gamma gap | largest chord error in q (at gamma) "
               "| largest chord distance in (gamma, ln q) | largest relative point error (at gamma) | highest point: gamma, q "
               "| peak gamma error | peak q error | wall s (CPU s) |")
    lines = [head, "", columns, "|---|---:|---|---:|---|---:|---:|---|---:|---:|---:|"]
    for code in CODES:
        r = rows[code]
        if "error" in r:
            lines.append(f"| {code} | not run: {r['error']} | | | | | | | | | |")
            continue
        m = r["measures"]
        lines.append(
            f"| {code} | {m['points']} | {m['range'][0]:.3f}-{m['range'][1]:.3f} | {m['max_gap']:.4f} | {100 * m['chord_err']:.2f} % ({m['chord_at']:.3f}) "
            f"| {m['chord_normal']:.4f} "
            f"| {m['point_err']:.1e} ({m['point_at']:.3f}) | {m['peak_gamma']:.4f}, {m['peak_q']:.4f} "
            f"| {m['peak_gamma'] - gp:+.4f} | {100 * (m['peak_q'] / qp - 1):+.3f} % "
            f"| {r['wall_s']:.3f} ({r['cpu_s']:.3f}) |")
    for code in (c for c in CODES if rows[c].get("refined_peak")):
        jd = rows[code]["refined_peak"]
        lines += ["", (f"Refined peak reported by {code} (Dataset attributes): gamma = {jd[0]:.5f} "
                       f"({jd[0] - gp:+.1e}), q = {jd[1]:.5f} (relative {jd[1] / qp - 1:+.1e}).")]
    return "\n".join(lines)


def versions(rows_by_f1: dict) -> str:
    seen = {}
    for rows in rows_by_f1.values():
        for code in CODES:
            r = rows[code]
            if "error" not in r:
                seen[code] = f"{r['version']} ({r['environment']})"
    return "\n".join(f"* {code}: {seen[code]}" for code in CODES if code in seen and code != JOINTDYN_STEP)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--write", action="store_true", help="update docs/hb-comparison.md")
    ap.add_argument("--other-python", help="interpreter in which tmdsimpy and pyHarm are importable")
    ap.add_argument("--tmdsimpy-path", help="folder holding tmdsimpy's package, for --other-python")
    ap.add_argument("--worker", choices=list(MODULES), help=argparse.SUPPRESS)
    ap.add_argument("--f1", type=float, help=argparse.SUPPRESS)
    args = ap.parse_args(argv)
    if args.worker:  # print one code's branch as JSON (run by --other-python)
        print(json.dumps(RUNNERS[args.worker](args.f1)))
        return 0
    out = {}
    for f1 in F1S:
        ref = Reference(f1)
        rows = {}
        for code in CODES:
            r = run_code(code, f1, args.other_python, args.tmdsimpy_path)
            if "error" not in r:
                r["measures"] = measures(r, ref)
            rows[code] = r
            print(f"F1={f1:g} {code}: {r.get('measures', r.get('error'))} {r.get('wall_s', '')}", file=sys.stderr,
                  flush=True)
        out[f1] = (rows, ref.peak(rows["jointdyn"]["measures"]["peak_gamma"]))
    text = "\n\n".join(table(f1, rows, pk) for f1, (rows, pk) in out.items())
    text += "\n\nVersions used:\n\n" + versions({f1: rows for f1, (rows, _) in out.items()})
    print(text)
    if args.write:
        from jointdyn._io import atomic_write_text

        page = PAGE.read_text()
        a, b = MARKERS
        i, j = page.index(a) + len(a), page.index(b)
        atomic_write_text(PAGE, page[:i] + "\n" + text + "\n" + page[j:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
