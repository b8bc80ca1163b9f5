"""Convergence study of the time integrator (docs/time-integration.md).

Steady-state half peak-to-peak amplitude of the paper damper (docs/model.md
section 6, closed-form Iwan law, beta = 2) against the number of RK4 steps
per forcing period, for a case that stays in contact (eta = 0.5) and one
that separates twice per period (eta = 1.5), with the event handling of
jointdyn (step boundaries at separation/re-contact, steps split at velocity
reversals) and, for comparison, without it (fixed steps that only look at
the samples). The reference is the event-handling run at 8192 steps.

Usage::

    PYTHONPATH=src python docs/scripts/convergence.py [--write]

prints the Markdown table; ``--write`` also replaces the table between the
markers in docs/time-integration.md (atomically).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parent.parent / "src"))

from jointdyn._io import atomic_write_text  # noqa: E402
from jointdyn.dynamics import steady_state  # noqa: E402
from jointdyn.systems import System  # noqa: E402

CASES = [
    ("contact", dict(eta=0.5, beta=2.0, model="iwan-closed"), 1.1),
    ("separation", dict(eta=1.5, beta=2.0, model="iwan-closed"), 1.1),
]
STEPS = [32, 64, 128, 256, 512, 1024]
REF_STEPS = 8192
BEGIN = "<!-- convergence:begin -->"
END = "<!-- convergence:end -->"


def _amp(system, gamma, spp, events):
    r = steady_state(system, gamma, steps_per_period=spp, keep_loop=False, amp_rtol=1e-6, energy_rtol=1e-5,
                     max_periods=4000, _events=events)  # fmt: skip
    return r


def table() -> str:
    lines = [
        "| case | steps/period | q (events) | rel. error | q (no events) | rel. error | periods | status |",
        "|---|---:|---:|---:|---:|---:|---:|---|",
    ]
    for name, kw, gamma in CASES:
        s = System.paper_damper(**kw)
        ref = _amp(s, gamma, REF_STEPS, True)
        qref = ref.amplitude_q
        for spp in STEPS:
            a = _amp(s, gamma, spp, True)
            b = _amp(s, gamma, spp, False)
            ea = abs(a.amplitude_q / qref - 1)
            eb = abs(b.amplitude_q / qref - 1)
            st = a.status if a.status == b.status else f"{a.status} / {b.status}"
            lines.append(
                f"| {name} (eta={kw['eta']}, beta={kw['beta']}, gamma={gamma}) | {spp} | {a.amplitude_q:.6f} | "
                f"{ea:.1e} | {b.amplitude_q:.6f} | {eb:.1e} | {a.periods} | {st} |"
            )
        lines.append(
            f"| reference | {REF_STEPS} | {qref:.8f} | | | | {ref.periods} | {ref.status} |"
        )
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="update docs/time-integration.md")
    args = ap.parse_args(argv)
    t0 = time.perf_counter()
    tab = table()
    print(tab)
    print(f"\n({time.perf_counter() - t0:.1f} s)", file=sys.stderr)
    if args.write:
        page = HERE.parent / "time-integration.md"
        text = page.read_text()
        i, j = text.index(BEGIN), text.index(END)
        atomic_write_text(page, text[: i + len(BEGIN)] + "\n" + tab + "\n" + text[j:])
    return 0


if __name__ == "__main__":
    sys.exit(main())
