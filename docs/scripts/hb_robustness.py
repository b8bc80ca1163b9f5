"""Robustness grid of harmonic balance with default settings.

Writes the table of docs/hb-robustness.md (between ``<!-- grid:start -->``
and ``<!-- grid:end -->``), computed here:

    PYTHONPATH=src python docs/scripts/hb_robustness.py --write [--workers N]

Models {default exact, closed form with full memory, the paper's rule,
Jenkins} x eta {0.01, 0.5, 1.5, 10} x beta {0.1, 1, 2, 5, 10, 1000}, gamma
0.6:1.8:0.01, every other setting the CLI's default
(:mod:`jointdyn.validation.hb_grid`): each branch must cover the range (or be
unbounded where Den Hartog's bound says it must), and its highest peak
must agree with the time-domain steady state at the same gamma within 1 %.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from jointdyn._io import atomic_write_text
from jointdyn.validation.hb_folds import fold_check, fold_table
from jointdyn.validation.hb_grid import (
    GRID_BETAS,
    GRID_ETAS,
    GRID_MODELS,
    grid_cases,
    grid_table,
)

PAGE = Path(__file__).resolve().parents[1] / "hb-robustness.md"


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--write", action="store_true", help="update docs/hb-robustness.md")
    ap.add_argument("--workers", type=int, default=1, help="processes running the cases (default 1)")
    ap.add_argument("--folds", action="store_true",
                    help="check the grid's folds against time-domain sweeps (the folds table) instead")
    args = ap.parse_args(argv)
    if args.folds:
        return _folds(args.write)
    cases = grid_cases([(m, e, b) for m in GRID_MODELS for e in GRID_ETAS for b in GRID_BETAS],
                       workers=args.workers)
    for c in cases:
        print(f"{c.model} eta={c.eta:g} beta={c.beta:g}: {c.status} ok={c.ok} {c.verdict} err={c.peak_error:+.3g} "
              f"{c.seconds:.2f} s", file=sys.stderr, flush=True)
    table = grid_table(cases)
    print(table)
    if args.write:
        _write_between("<!-- grid:start -->", "<!-- grid:end -->", table)
    return 0


def _folds(write: bool) -> int:
    """The folds table: every grid case with folds, checked by time-domain sweeps up and down."""
    checks = []
    for model in GRID_MODELS:
        for eta in GRID_ETAS:
            for beta in GRID_BETAS:
                c = fold_check(model, eta, beta)
                if c is not None:
                    print(f"{model} eta={eta:g} beta={beta:g}: {len(c.folds)} folds, {c.verdict}",
                          file=sys.stderr, flush=True)
                    checks.append(c)
    table = fold_table(checks)
    print(table)
    if write:
        _write_between("<!-- folds:start -->", "<!-- folds:end -->", table)
    return 0


def _write_between(a: str, b: str, table: str) -> None:
    text = PAGE.read_text()
    i, j = text.index(a) + len(a), text.index(b)
    atomic_write_text(PAGE, text[:i] + "\n" + table + "\n" + text[j:])


if __name__ == "__main__":
    sys.exit(main())
