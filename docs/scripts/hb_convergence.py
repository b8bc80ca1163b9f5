"""Harmonic balance: convergence in the number of harmonics, against time integration.

Usage::

    PYTHONPATH=src python docs/scripts/hb_convergence.py [--write]

For a few stable points of the paper's damper (closed-form Iwan law
``iwan-closed``, the law of the study when it was written; no
viscous damping) and of the Jenkins benchmark oscillator, solves HB with
H = 1, 2, 3, 5, 7, 11, 15 harmonics (max(256, 16 H) samples per period)
and compares the amplitude (half peak-to-peak of x) with the time-domain
steady state of :func:`jointdyn.dynamics.steady_state`. Also tabulates the
one-harmonic Jenkins result against the closed-form describing function
as the number of AFT samples grows. With ``--write`` the tables replace
the blocks between the markers in ``docs/harmonic-balance.md``.
"""

from __future__ import annotations

import argparse
import math
import sys
from pathlib import Path


from jointdyn import System
from jointdyn._io import atomic_write_text
from jointdyn.dynamics import steady_state
from jointdyn.hb import harmonic_balance
from jointdyn.laws import Jenkins

PAGE = Path(__file__).resolve().parents[1] / "harmonic-balance.md"
# the describing-function oracle of the tests (one copy of the closed form)
sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tests"))
from test_hb import _df_amplitude  # noqa: E402
HS = (1, 2, 3, 5, 7, 11, 15)
KT, FY, M, K, F1, ZETA = 3e5, 50.0, 10.0, 3.9e5, 20.0, 1e-3


def _jenkins():
    return System.sdof(m=M, k=K, law=Jenkins(kt=KT, mu=0.5, n_ref=100.0), f1=F1, zeta=ZETA)


CASES = (
    ("Jenkins benchmark", _jenkins, 1.25),
    ("iwan-closed eta=0.01 beta=1", lambda: System.paper_damper(eta=0.01, beta=1.0, model="iwan-closed"), 1.1),
    ("iwan-closed eta=0.5 beta=2", lambda: System.paper_damper(eta=0.5, beta=2.0, model="iwan-closed"), 1.1),
    ("iwan-closed eta=0.5 beta=2", lambda: System.paper_damper(eta=0.5, beta=2.0, model="iwan-closed"), 1.5),
    ("iwan-closed eta=1.5 beta=5", lambda: System.paper_damper(eta=1.5, beta=5.0, model="iwan-closed"), 1.4),
    ("iwan-closed eta=10 beta=2", lambda: System.paper_damper(eta=10.0, beta=2.0, model="iwan-closed"), 1.5),
)


def convergence_table() -> str:
    head = "| case | gamma | time-domain q | " + " | ".join(f"H={h}" for h in HS) + " |"
    lines = [head, "|" + "---|" * (3 + len(HS))]
    for name, make, g in CASES:
        s = make()
        ss = steady_state(s, g)
        kt, fy = s.contacts[0].law.kt, s.contacts[0].law.fy
        cells = []
        for h in HS:
            sol = harmonic_balance(s, g, harmonics=h, samples=max(256, 16 * h))
            if not sol.status.ok:
                cells.append("no conv.")
                continue
            rel = (sol.amplitude_m - ss.amplitude_m) / ss.amplitude_m
            cells.append(f"{rel:+.1e}{'' if sol.stable else ' (unst.)'}")
        q = kt * ss.amplitude_m / fy
        lines.append(f"| {name} | {g:g} | {q:.5g} ({ss.status}) | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def df_table() -> str:
    samples = (32, 64, 128, 256, 512, 1024, 4096)
    gammas = (1.25, 1.35, 1.42)
    lines = ["| gamma | DF q | " + " | ".join(f"Ns={n}" for n in samples) + " |", "|" + "---|" * (2 + len(samples))]
    for g in gammas:
        A = _df_amplitude(g)
        cells = []
        for ns in samples:
            sol = harmonic_balance(_jenkins(), g, harmonics=1, samples=ns)
            cells.append(f"{(math.hypot(sol.X[1], sol.X[2]) - A) / A:+.1e}")
        lines.append(f"| {g:g} | {KT * A / FY:.6g} | " + " | ".join(cells) + " |")
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--write", action="store_true", help="update docs/harmonic-balance.md")
    args = ap.parse_args(argv)
    tables = {"convergence": convergence_table(), "df": df_table()}
    for k, v in tables.items():
        print(v + "\n")
    if args.write:
        text = PAGE.read_text()
        for k, v in tables.items():
            a, b = f"<!-- {k}:start -->", f"<!-- {k}:end -->"
            i, j = text.index(a) + len(a), text.index(b)
            text = text[:i] + "\n" + v + "\n" + text[j:]
        atomic_write_text(PAGE, text)
    return 0


if __name__ == "__main__":
    sys.exit(main())
