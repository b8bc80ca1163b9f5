"""Error table of the Craig-Bampton reduction: docs/reduction.md.

Usage::

    PYTHONPATH=src python docs/scripts/reduction_table.py [--write]

A fixed-free chain of 60 masses (0.5 kg, springs 2e5 N/m) with a Jenkins
contact (kt 3e5 N/m, mu 0.5, preload 100 N) at DOF 30 on a normal spring
(kn 3e5 N/m) at the free end, forced at DOF 20 (300 N) and at the normal
DOF (30 N, phase 60 deg), 2 % modal damping, is reduced with
``reduce_system`` keeping 0 .. all fixed-interface modes. For each
reduction: the worst relative error of the lowest 3 and 10 natural
frequencies and the smallest MAC of the lowest 10 modes (normal spring
closed, contact free), and the steady state at gamma 1 and 4 (near the
lowest and the fourth mode): amplitude of the contact DOF and energy dissipated by the
contact per period against the full model, with the CPU time of the
steady state (the reduced models drop the chain's stiff modes: larger
steps). Prints Markdown; ``--write`` puts it between the markers of
docs/reduction.md.
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

import jointdyn as jd
from jointdyn._io import atomic_write_text
from jointdyn.reduction import default_boundary, reduce_system

PAGE = Path(__file__).resolve().parents[1] / "reduction.md"
START, END = "<!-- table:start -->", "<!-- table:end -->"
N_DOF, MODES, GAMMAS = 60, (0, 2, 4, 8, 16, 32), (1.0, 4.0)


def chain(n: int = N_DOF) -> jd.System:
    """The structure described in the module docstring."""
    M = np.diag(np.full(n, 0.5))
    k = 2e5
    K = np.zeros((n, n))
    for i in range(n - 1):
        K[i : i + 2, i : i + 2] += k * np.array([[1.0, -1.0], [-1.0, 1.0]])
    K[0, 0] += k
    K[-1, -1] += 0.5 * k
    spring = jd.NormalSpring(kn=3e5, preload=100.0, dof=n - 1)
    contact = jd.Contact(jd.make_law("jenkins", kt=3e5, mu=0.5, n_ref=100.0), dof=n // 2, normal=spring)
    f, ph = np.zeros(n), np.zeros(n)
    f[n // 3], f[n - 1], ph[n - 1] = 300.0, 30.0, 60.0
    bare = jd.System(M, None, K, contacts=(contact,), force=f, force_phase_deg=ph)
    C = jd.modal_damping(M, bare.K_reference, 0.02)
    return jd.System(M, C, K, contacts=(contact,), force=f, force_phase_deg=ph, output_dof=n // 2)


def _steady(system, gamma):
    t = time.process_time()
    r = jd.steady_state(system, gamma, response_dof=system.response_dof)
    return r, time.process_time() - t


def table() -> str:
    full = chain()
    nb = len(default_boundary(full))
    jd.steady_state(full, 1.0, max_periods=2)  # compile outside the timings
    ref = {g: _steady(full, g) for g in GAMMAS}
    head = ["modes", "size", "freq. err. 1-3", "freq. err. 1-10", "min MAC 1-10"]
    for g in GAMMAS:
        head += [f"amplitude err. (gamma {g:g})", f"dissipation err. (gamma {g:g})", f"CPU s (gamma {g:g})"]
    rows = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
    for n_modes in (*MODES, N_DOF - nb):
        red, cb = reduce_system(full, n_modes)
        cells = [str(n_modes), str(cb.size), f"{cb.error.worst(3):.1e}", f"{cb.error.worst(10):.1e}",
                 f"{np.min(cb.error.mac[:10]):.6f}"]
        for g in GAMMAS:
            r, cpu = _steady(red, g)
            f, _ = ref[g]
            if r.status != "periodic":
                cells += [str(r.status.value), "", f"{cpu:.2f}"]
                continue
            cells += [f"{r.amplitude_m / f.amplitude_m - 1:+.1e}", f"{r.energy_contact_J / f.energy_contact_J - 1:+.1e}",
                      f"{cpu:.2f}"]
        rows.append("| " + " | ".join(cells) + " |")
    full_cells = ["full", str(N_DOF), "", "", ""]
    for g in GAMMAS:
        f, cpu = ref[g]
        full_cells += [f"{f.amplitude_m:.4e} m", f"{f.energy_contact_J:.4e} J", f"{cpu:.2f}"]
    rows.append("| " + " | ".join(full_cells) + " |")
    return "\n".join(rows)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--write", action="store_true", help="update the table in docs/reduction.md")
    args = ap.parse_args(argv)
    text = table()
    print(text)
    if args.write:
        page = PAGE.read_text()
        head, rest = page.split(START, 1)
        _, tail = rest.split(END, 1)
        atomic_write_text(PAGE, f"{head}{START}\n{text}\n{END}{tail}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
