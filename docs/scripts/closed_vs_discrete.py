"""Closed-form Iwan vs discrete ground truth on the paper's Fig 3 / Fig 4 cases.

Writes the tables of docs/closed-form-vs-discrete.md (between the markers
``<!-- table:begin -->`` / ``<!-- table:end -->`` for the paper's amplitude
0.5 mm, and ``<!-- table-small:begin -->`` / ``<!-- table-small:end -->``
for a microslip-only amplitude of 0.1 mm), computed here:

    PYTHONPATH=src python docs/scripts/closed_vs_discrete.py

Cases (paper section 2.2, docs/model.md section 6): kt = 100 kN/m, mu = 0.1,
N0 = N_ref = 100 N (fy = 10 N), x = 0.5 mm sin(2 pi t),
N = N0 (1 + eta sin(2 pi t + delta)), delta in {0, 90} deg,
eta in {0, 0.3, 0.6, 0.9, 1.2}; 2 cycles from the virgin state, 2000 steps per
cycle (plus the exact separation / re-contact instants), metrics of the
last cycle. Models: ``iwan`` (closed form, Masing's extended memory),
``iwan-paper`` (closed form, the paper's last-reversal rule), ``discrete``
(n = 1000 Jenkins elements, docs/model.md section 5) and, to show that the ground
truth is converged in n, ``discrete`` with n = 4000.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
from tqdm import tqdm

from jointdyn._io import atomic_write_text
from jointdyn.drivers import harmonic_loop
from jointdyn.laws import make_law

KT, MU, N0 = 1.0e5, 0.1, 100.0
A_PAPER, A_SMALL = 0.5e-3, 0.1e-3
FY = MU * N0
ETAS = (0.0, 0.3, 0.6, 0.9, 1.2)
DELTAS = (0.0, 90.0)
STEPS, CYCLES = 2000, 2
DOC = Path(__file__).resolve().parents[1] / "closed-form-vs-discrete.md"
MARKERS = {A_PAPER: "table", A_SMALL: "table-small"}


def last_cycle(model, A, eta, delta_deg, n=1000):
    law = make_law(model, kt=KT, mu=MU, n_ref=N0, **({"n": n} if model == "discrete" else {}))
    r = harmonic_loop(law, A, 1.0, N0, eta=eta, delta_deg=delta_deg, cycles=CYCLES,
                      steps_per_cycle=STEPS)
    sl = r.cycle_slice(-1)
    return r.last_cycle(), r.t[sl], r.T[sl]


def rows(A):
    out = []
    cases = [(d, e) for d in DELTAS for e in ETAS]
    for delta, eta in tqdm(cases, desc=f"A = {A * 1e3:g} mm", disable=None):
        full, t1, T1 = last_cycle("iwan-closed", A, eta, delta)
        paper, t2, T2 = last_cycle("iwan-paper", A, eta, delta)
        disc, t3, T3 = last_cycle("discrete", A, eta, delta)
        fine, _, _ = last_cycle("discrete", A, eta, delta, n=4000)
        assert np.array_equal(t1, t3) and np.array_equal(t2, t3)  # same samples
        Ed = disc["energy_J"]
        out.append(dict(
            delta=delta, eta=eta,
            E_full=full["energy_J"], E_paper=paper["energy_J"], E_disc=Ed,
            d_full=full["energy_J"] / Ed - 1, d_paper=paper["energy_J"] / Ed - 1,
            d_n=fine["energy_J"] / Ed - 1,
            T_full=float(np.max(np.abs(T1 - T3)) / FY), T_paper=float(np.max(np.abs(T2 - T3)) / FY),
            sep=disc["separation_fraction"],
        ))
    return out


def _pct(v):
    """Relative difference in percent, 3 significant digits."""
    return f"{100 * v:+.3g} %"


def table(rs) -> str:
    head = (
        "| delta (deg) | eta | E closed, full memory (mJ) | E closed, paper rule (mJ) | E discrete n=1000 (mJ) "
        "| full vs discrete | paper vs discrete | discrete n=4000 vs n=1000 "
        "| max abs(T_full - T_disc) / fy | max abs(T_paper - T_disc) / fy | separation fraction |\n"
        "|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n"
    )
    lines = [
        f"| {r['delta']:g} | {r['eta']:g} | {1e3 * r['E_full']:.5f} | {1e3 * r['E_paper']:.5f} "
        f"| {1e3 * r['E_disc']:.5f} | {_pct(r['d_full'])} | {_pct(r['d_paper'])} "
        f"| {_pct(r['d_n'])} | {r['T_full']:.2e} | {r['T_paper']:.2e} | {r['sep']:.4f} |"
        for r in rs
    ]
    return head + "\n".join(lines) + "\n"


def main() -> int:
    doc = DOC.read_text()
    for A, key in MARKERS.items():
        begin, end = f"<!-- {key}:begin -->", f"<!-- {key}:end -->"
        if begin not in doc or end not in doc:
            print(f"{DOC}: markers {begin} / {end} missing", file=sys.stderr)
            return 2
        text = table(rows(A))
        pre, rest = doc.split(begin, 1)
        _, post = rest.split(end, 1)
        doc = pre + begin + "\n" + text + end + post
        print(f"A = {A * 1e3:g} mm\n{text}")
    atomic_write_text(DOC, doc)
    return 0


if __name__ == "__main__":
    sys.exit(main())
