"""Convergence study of the exact Iwan law (``iwan``, the default contact law): docs/exact-iwan.md.

Usage::

    PYTHONPATH=src python docs/scripts/exact_iwan_convergence.py [--write] [--quick]

Computes, and prints as Markdown (with ``--write``: into the block between
the markers of ``docs/exact-iwan.md``):

1. quasi-static loops of Figs 3-4 (kt = 1e5 N/m, mu = 0.1, N0 = 100 N,
   x = 0.5 mm sin(2 pi t), 2000 samples per cycle, 2 cycles; eta 0 .. 1.2,
   delta 0 and 90 deg): energy of the last cycle and the largest force
   difference over it, for the exact law at the default capacity, the
   discrete model (n = 50 .. 4000) and its Richardson extrapolation
   (O(1/n^2): (16 E_4000 - E_1000) / 15), the full-memory closed form and
   the paper's last-reversal rule, all against the exact law without
   merges (capacity ``K_REF``); piece counts over the last cycle;
2. steady states of the paper damper (time domain, tight periodicity
   tolerances) at eta 0.5, 1.5 x beta 2, 10 x a few gammas: amplitude of q
   for the same models;
3. the capacity K: worst differences over the cases of 1 and 2;
4. (not with ``--quick``) the whole Fig 6 grid (time-domain sweeps up and
   down, default tolerances): amplitude differences of the default capacity
   against ``K_REF``, and piece counts over the final period of every point.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

from jointdyn import DiscreteIwan, Iwan, IwanClosedForm, harmonic_loop
from jointdyn._io import atomic_write_text
from jointdyn.dynamics import steady_state
from jointdyn.dynamics import SteadyStateOptions
from jointdyn.laws.exact import piece_count
from jointdyn.systems import PAPER, System

PAGE = Path(__file__).resolve().parents[1] / "exact-iwan.md"
START, END = "<!-- tables:start -->", "<!-- tables:end -->"
#: capacity treated as "no merge" (checked: the piece counts stay below it)
K_REF = 2048
K_DEFAULT = Iwan.__dataclass_fields__["capacity"].default  # the law's default capacity
CAPACITIES = (8, 12, 16, 24, 32, 48, 64)
DISCRETE_N = (50, 200, 1000, 4000)

# --- Figs 3-4 quasi-static loops -------------------------------------------------
QS = dict(kt=1e5, mu=0.1, n_ref=100.0)
QS_AMP = 0.5e-3
QS_ETAS = (0.0, 0.3, 0.6, 0.9, 1.2)
QS_DELTAS = (0.0, 90.0)

# --- paper damper points ---------------------------------------------------------
FRC_ETAS = (0.5, 1.5)
FRC_BETAS = (2.0, 10.0)
FRC_GAMMAS = (0.9, 1.1, 1.2, 1.3, 1.5)
#: periodicity tolerances of the points (much tighter than the defaults, so
#: that differences of 1e-6 between models are resolved)
FRC_TOL = dict(amp_rtol=1e-8, energy_rtol=1e-7)

# --- Fig 6 grid --------------------------------------------------------------------
GRID_ETAS = (0.01, 0.5, 1.5, 10.0)
GRID_BETAS = (0.1, 1.0, 2.0, 5.0, 10.0, 1000.0)
GRID_GAMMAS = np.round(0.6 + 0.01 * np.arange(121), 12)


def _pieces(law, x, N, state=None):
    """Piece counts of ``law`` after every sample of a march."""
    p = law.params
    s = law.initial_state(x[0], N[0]) if state is None else state.copy()
    s_new = np.empty_like(s)
    out = np.empty(x.size, dtype=int)
    for i, (xi, ni) in enumerate(zip(x, N)):
        law.step(p, s, s_new, float(xi), float(ni))
        s, s_new = s_new, s
        out[i] = piece_count(s)
    return out


def _qs_models():
    models = {"exact K=%d" % K: Iwan(**QS, capacity=K) for K in (K_REF,) + CAPACITIES}
    models.update({"discrete n=%d" % n: DiscreteIwan(**QS, n=n) for n in DISCRETE_N})
    models["closed form (full memory)"] = IwanClosedForm(**QS, memory="full")
    models["paper rule (last reversal)"] = IwanClosedForm(**QS, memory="last")
    return models


def quasi_static():
    """Energy of the last cycle and force error over it, per case and model."""
    models = _qs_models()
    fy = QS["mu"] * QS["n_ref"]
    rows = []
    for delta in QS_DELTAS:
        for eta in QS_ETAS:
            res = {name: harmonic_loop(law, QS_AMP, eta=eta, delta_deg=delta) for name, law in models.items()}
            ref = res["exact K=%d" % K_REF]
            last = ref.t >= ref.t[-1] - ref.period  # the last cycle
            e_ref = float(ref.cycles["energy_J"].values[-1])
            pc = _pieces(models["exact K=%d" % K_REF], ref.x, ref.N)[last]
            row = dict(eta=eta, delta=delta, energy=e_ref, pieces_max=int(pc.max()), pieces_mean=float(pc.mean()),
                       diff={}, force={})
            for name, r in res.items():
                e = float(r.cycles["energy_J"].values[-1])
                row["diff"][name] = e / e_ref - 1.0
                row["force"][name] = float(np.max(np.abs(r.T[last] - ref.T[last]))) / fy
            e1000 = e_ref * (1 + row["diff"]["discrete n=1000"])
            e4000 = e_ref * (1 + row["diff"]["discrete n=4000"])
            row["diff"]["Richardson 1000/4000"] = (16 * e4000 - e1000) / 15 / e_ref - 1.0
            rows.append(row)
    return rows


def _frc_models():
    models = {"exact K=%d" % K: (lambda K=K: Iwan(kt=PAPER["kt"], mu=PAPER["mu"], n_ref=PAPER["n0"], capacity=K))
              for K in (K_REF,) + CAPACITIES}
    for n in DISCRETE_N:
        models["discrete n=%d" % n] = lambda n=n: DiscreteIwan(kt=PAPER["kt"], mu=PAPER["mu"], n_ref=PAPER["n0"], n=n)
    models["closed form (full memory)"] = lambda: IwanClosedForm(kt=PAPER["kt"], mu=PAPER["mu"], n_ref=PAPER["n0"])
    models["paper rule (last reversal)"] = lambda: IwanClosedForm(kt=PAPER["kt"], mu=PAPER["mu"], n_ref=PAPER["n0"],
                                                        memory="last")
    return models


def _damper(law, eta, beta):
    p = PAPER
    return System.sdof(m=p["m"], k=p["k"], law=law, f1=law.fy / beta, zeta=0.0, n0=p["n0"], eta=eta, delta_deg=0.0)


def frc_points(gammas=FRC_GAMMAS):
    """Steady amplitudes of q per point and model (tight tolerances)."""
    models = _frc_models()
    rows = []
    for eta in FRC_ETAS:
        for beta in FRC_BETAS:
            for gamma in gammas:
                q = {}
                status = {}
                for name, make in models.items():
                    r = steady_state(_damper(make(), eta, beta), gamma, **FRC_TOL)
                    q[name] = r.amplitude_q
                    status[name] = r.status
                    if name == "exact K=%d" % K_REF:
                        L = r.loop
                        x, N = np.tile(L.x[:, 0], 2), np.tile(L.N[:, 0], 2)
                        pc = _pieces(make(), x, N, state=r.restart.states[0])[L.x.shape[0]:]
                q["Richardson 1000/4000"] = (16 * q["discrete n=4000"] - q["discrete n=1000"]) / 15
                rows.append(dict(eta=eta, beta=beta, gamma=gamma, q=q, status=status, pieces_max=int(pc.max()),
                                 pieces_mean=float(pc.mean())))
    return rows


def _sweep(make, eta, beta, gammas, direction, count_pieces=False):
    """Warm-started time-domain sweep (as jointdyn.sweeps does it): amplitudes
    of q (NaN where not periodic) and, optionally, the largest piece count
    over the final period of each point."""
    order = range(len(gammas)) if direction == "up" else range(len(gammas) - 1, -1, -1)
    q = np.full(len(gammas), np.nan)
    pmax = np.zeros(len(gammas), dtype=int)
    start = None
    for i in order:
        law = make()
        r = steady_state(_damper(law, eta, beta), float(gammas[i]), start=start)
        start = r if r.status == "periodic" else None
        if r.status == "periodic":
            q[i] = r.amplitude_q
            if count_pieces:
                L = r.loop
                pmax[i] = _pieces(law, L.x[:, 0], L.N[:, 0], state=r.restart.states[0]).max()
    return q, pmax


def fig6_grid(gammas=GRID_GAMMAS):
    """Default capacity vs K_REF over the Fig 6 grid; piece counts."""
    kt, mu, n0 = PAPER["kt"], PAPER["mu"], PAPER["n0"]
    out = []
    for eta in GRID_ETAS:
        for beta in GRID_BETAS:
            for d in ("up", "down"):
                t0 = time.process_time()
                q_ref, pmax = _sweep(lambda: Iwan(kt=kt, mu=mu, n_ref=n0, capacity=K_REF), eta, beta, gammas, d,
                                     count_pieces=True)
                t1 = time.process_time()
                q_def, _ = _sweep(lambda: Iwan(kt=kt, mu=mu, n_ref=n0, capacity=K_DEFAULT), eta, beta, gammas, d)
                t2 = time.process_time()
                q_cf, _ = _sweep(lambda: IwanClosedForm(kt=kt, mu=mu, n_ref=n0), eta, beta, gammas, d)
                t3 = time.process_time()
                out.append(dict(eta=eta, beta=beta, direction=d, q_ref=q_ref, q_def=q_def, pieces=pmax,
                                seconds=(t1 - t0, t2 - t1, t3 - t2)))
    return out


# --- tables --------------------------------------------------------------------------
def _pct(v):
    """A relative difference in percent: two digits, small ones in e-notation."""
    return f"{100 * v:+.1e}" if abs(v) < 1e-3 else f"{100 * v:+.2f}"


def qs_table(rows):
    cols = ["exact K=%d" % K_DEFAULT] + ["discrete n=%d" % n for n in DISCRETE_N] + [
        "Richardson 1000/4000", "closed form (full memory)", "paper rule (last reversal)"]
    head = "| delta | eta | E (mJ), exact | pieces max / mean | " + " | ".join(c.replace("exact ", "") for c in cols) + " |"
    lines = [
        "Energy of the last cycle: relative difference (%) to the exact law without merges "
        f"(K = {K_REF}); in brackets, the largest force difference over that cycle in units of fy.",
        "",
        head,
        "|" + "---|" * (4 + len(cols)),
    ]
    for r in rows:
        cells = []
        for c in cols:
            f = r["force"].get(c)
            cells.append(_pct(r["diff"][c]) + ("" if f is None else f" ({f:.1e})"))
        lines.append(f"| {r['delta']:g} | {r['eta']:g} | {1e3 * r['energy']:.5f} | {r['pieces_max']} / "
                     f"{r['pieces_mean']:.1f} | " + " | ".join(cells) + " |")
    return lines


def frc_table(rows):
    ref = "exact K=%d" % K_REF
    cols = ["exact K=%d" % K_DEFAULT] + ["discrete n=%d" % n for n in DISCRETE_N] + [
        "Richardson 1000/4000", "closed form (full memory)", "paper rule (last reversal)"]
    lines = [
        "Steady amplitude of q: relative difference (%) to the exact law without merges "
        f"(K = {K_REF}); time domain, periodicity tolerances {FRC_TOL}.",
        "",
        "| eta | beta | gamma | q, exact | pieces max / mean | " + " | ".join(c.replace("exact ", "") for c in cols) + " |",
        "|" + "---|" * (5 + len(cols)),
    ]
    for r in rows:
        qr = r["q"][ref]
        cells = [_pct(r["q"][c] / qr - 1.0) for c in cols]
        bad = [c for c, s in r["status"].items() if s != "periodic"]
        note = f" (not periodic: {', '.join(bad)})" if bad else ""
        lines.append(f"| {r['eta']:g} | {r['beta']:g} | {r['gamma']:g} | {qr:.6f}{note} | {r['pieces_max']} / "
                     f"{r['pieces_mean']:.1f} | " + " | ".join(cells) + " |")
    return lines


#: worst differences of the default capacity, filled by the tables (summary line)
SUMMARY = {}


def capacity_table(qs_rows, frc_rows):
    lines = [
        f"Capacity K against K = {K_REF} (no merge): worst case over the quasi-static cases above "
        "(force in units of fy, energy per cycle) and over the damper points (amplitude of q).",
        "",
        "| K | max force diff / fy | max energy diff % | max amplitude diff % |",
        "|---|---|---|---|",
    ]
    for K in CAPACITIES:
        name = "exact K=%d" % K
        f = max(r["force"][name] for r in qs_rows)
        e = max(abs(r["diff"][name]) for r in qs_rows)
        a = max(abs(r["q"][name] / r["q"]["exact K=%d" % K_REF] - 1.0) for r in frc_rows)
        lines.append(f"| {K}{' (default)' if K == K_DEFAULT else ''} | {f:.2e} | {100 * e:.2e} | {100 * a:.2e} |")
        if K == K_DEFAULT:
            SUMMARY.update(force=f, energy=e, points=a)
    return lines


def summary() -> str:
    """One sentence on the accuracy of the default capacity."""
    text = (f"**Accuracy of the default (K = {K_DEFAULT}):** against the exact law without merges, the "
            f"force differs by at most {SUMMARY['force']:.1e} fy and the energy per cycle by "
            f"{100 * SUMMARY['energy']:.1e} % on the Fig 3-4 loops, the steady amplitude by "
            f"{100 * SUMMARY['points']:.1e} % at the damper points")
    if "grid" in SUMMARY:
        text += (f" and by {100 * SUMMARY['grid']:.1e} % over the whole Fig 6 grid (there the periodicity "
                 f"tolerance {SteadyStateOptions().amp_rtol:g} of the steady states bounds the comparison)")
    return text + "; the requirement is 0.1 %."


def grid_table(rows):
    rel = []
    lines = [
        f"Fig 6 grid (time domain, default tolerances, up and down sweeps with warm starts, gamma "
        f"{GRID_GAMMAS[0]:g}..{GRID_GAMMAS[-1]:g} step 0.01): default capacity K = {K_DEFAULT} against K = {K_REF}; "
        "pieces = largest piece count over the final period of a point (K = %d). CPU seconds of each sweep "
        "(exact K = %d / exact K = %d / closed form)." % (K_REF, K_REF, K_DEFAULT),
        "",
        "| eta | beta | dir | periodic pts (ref / default) | max amplitude diff % | median % | pieces max | "
        "pieces median | seconds |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    allp = []
    for r in rows:
        ok = np.isfinite(r["q_ref"]) & np.isfinite(r["q_def"])
        d = np.abs(r["q_def"][ok] / r["q_ref"][ok] - 1.0)
        rel.append(d)
        p = r["pieces"][np.isfinite(r["q_ref"])]
        allp.append(p)
        secs = " / ".join(f"{s:.1f}" for s in r["seconds"])
        lines.append(f"| {r['eta']:g} | {r['beta']:g} | {r['direction']} | {int(np.isfinite(r['q_ref']).sum())} / "
                     f"{int(np.isfinite(r['q_def']).sum())} | {100 * d.max() if d.size else float('nan'):.2e} | "
                     f"{100 * np.median(d) if d.size else float('nan'):.1e} | {p.max() if p.size else 0} | "
                     f"{np.median(p) if p.size else 0:g} | {secs} |")
    d = np.concatenate(rel)
    p = np.concatenate(allp)
    SUMMARY["grid"] = float(d.max())
    tot = np.sum([r["seconds"] for r in rows], axis=0)
    lines += ["", f"Whole grid: {d.size} points periodic in both; amplitude difference max {100 * d.max():.2e} %, "
              f"99th percentile {100 * np.percentile(d, 99):.2e} %, median {100 * np.median(d):.1e} %. "
              f"Piece counts: max {p.max()}, 99th percentile {np.percentile(p, 99):g}, median {np.median(p):g}; "
              f"points needing more than {K_DEFAULT} pieces: {int((p > K_DEFAULT).sum())} of {p.size}. "
              f"CPU seconds of the whole grid: exact K = {K_REF} {tot[0]:.1f}, exact K = {K_DEFAULT} {tot[1]:.1f}, "
              f"closed form {tot[2]:.1f}."]
    return lines


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--write", action="store_true", help="update the tables in docs/exact-iwan.md")
    ap.add_argument("--quick", action="store_true", help="fewer damper points, no Fig 6 grid")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    qs = quasi_static()
    frc = frc_points(FRC_GAMMAS[1:3] if args.quick else FRC_GAMMAS)
    parts = ["### Quasi-static loops (Figs 3-4)", ""] + qs_table(qs)
    parts += ["", "### Paper damper, time-domain steady states", ""] + frc_table(frc)
    parts += ["", "### Capacity", ""] + capacity_table(qs, frc)
    if not args.quick:
        parts += ["", "### Fig 6 grid", ""] + grid_table(fig6_grid())
    parts = [summary(), ""] + parts
    parts += ["", f"(computed in {time.perf_counter() - t0:.0f} s wall by docs/scripts/exact_iwan_convergence.py)"]
    text = "\n".join(parts)
    print(text)
    if args.write:
        page = PAGE.read_text()
        head, rest = page.split(START, 1)
        _, tail = rest.split(END, 1)
        atomic_write_text(PAGE, f"{head}{START}\n{text}\n{END}{tail}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
