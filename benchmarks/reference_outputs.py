"""Reference outputs of one source tree: ``python benchmarks/reference_outputs.py TREE OUTDIR``.

Runs the same workloads with ``TREE/.venv`` (an editable install of TREE), so
that two versions of jointdyn can be compared number by number with
``benchmarks/compare_outputs.py``. The procedure, e.g. for a refactoring
that must leave every output unchanged (OLD: a worktree of the commit before
it, ``git worktree add OLD COMMIT``; NEW: the tree after it, each with its
own virtual environment)::

    python -m venv --system-site-packages OLD/.venv && OLD/.venv/bin/pip install --no-deps -e OLD
    python benchmarks/reference_outputs.py OLD out-old
    python benchmarks/reference_outputs.py NEW out-new
    python benchmarks/compare_outputs.py out-old out-new     # exit 0: every number bit for bit
    python benchmarks/ab.py --old OLD --new NEW --rounds 2 --quick   # speed, alternated

The workloads: the CLI's JSON (``--json``) and files (``--out``) of
response curves by harmonic balance (Jenkins, the exact and closed-form Iwan
laws, a fixed discretisation, the blade system file) and in the time domain,
nonlinear modes (EPMC, QSMA), quasi-static loops (exact and discrete Iwan),
the data of five paper figures, and cases of the harmonic-balance robustness
grid (``jointdyn.validation.hb_grid.grid_cases``, or ``jointdyn.sweeps.hb_grid``
in versions before it moved; floats written with ``repr``, run times left
out). Each workload's exit status and wall time go to ``OUTDIR/log.txt``, its
standard error to ``OUTDIR/NAME.err``.
"""

from __future__ import annotations

import argparse
import subprocess
import sys
import time
from pathlib import Path

#: the five grid cases of every comparison, then seven more spread over the models (``--grid 12``)
GRID_CASES = (("jenkins", 0.5, 1.0), ("iwan-closed", 1.5, 2.0), ("iwan", 0.01, 0.1), ("iwan-paper", 10.0, 1000.0),
              ("iwan-closed", 0.5, 5.0), ("iwan", 1.5, 2.0), ("iwan", 10.0, 10.0), ("iwan-paper", 0.5, 1.0),
              ("iwan-paper", 1.5, 5.0), ("jenkins", 10.0, 0.1), ("jenkins", 1.5, 1000.0), ("iwan-closed", 0.01, 10.0))

_GRID_SCRIPT = r"""
import json, sys
try:
    from jointdyn.validation.hb_grid import grid_cases
except ImportError:
    from jointdyn.sweeps.hb_grid import grid_cases
cases = json.loads(sys.argv[1])
out = []
for c in grid_cases(cases):
    d = {k: (getattr(c, k).name if k == "verdict" else getattr(c, k)) for k in c.__dataclass_fields__ if k != "seconds"}
    out.append({k: (repr(v) if isinstance(v, float) else v) for k, v in d.items()})
print(json.dumps(out, indent=1))
"""


def workloads(out: Path) -> dict[str, list[str]]:
    """CLI arguments of each workload (name -> arguments of ``jointdyn``)."""
    return {
        "frc_hb_jenkins": ["frc", "--method", "hb", "--model", "jenkins", "--gamma", "0.6:1.8:0.01", "--json",
                           "--out", f"{out}/frc_hb_jenkins"],
        "frc_hb_iwan": ["frc", "--method", "hb", "--json", "--out", f"{out}/frc_hb_iwan"],
        "frc_hb_closed": ["frc", "--method", "hb", "--model", "iwan-closed", "--eta", "1.5", "--beta", "2", "--json",
                          "--out", f"{out}/frc_hb_closed"],
        "frc_hb_paper_fixed": ["frc", "--method", "hb", "--model", "iwan-paper", "--eta", "0.01", "--beta", "0.1",
                               "--harmonics", "5", "--samples", "64", "--json"],
        "frc_hb_blade": ["frc", "--method", "hb", "--system", "examples/blade.toml", "--json",
                         "--out", f"{out}/frc_hb_blade"],
        "frc_time_jenkins": ["frc", "--method", "time", "--model", "jenkins", "--gamma", "0.9:1.1:0.05",
                             "--workers", "1", "--json", "--out", f"{out}/frc_time_jenkins"],
        "modes_epmc": ["modes", "--json", "--out", f"{out}/modes_epmc"],
        "modes_qsma": ["modes", "--method", "qsma", "--json", "--out", f"{out}/modes_qsma"],
        "modes_jenkins": ["modes", "--model", "jenkins", "--json"],
        "loop_iwan": ["loop", "--json", "--out", f"{out}/loop_iwan"],
        "loop_discrete": ["loop", "--model", "discrete", "--n", "50", "--eta", "1.5", "--delta", "90", "--json",
                          "--out", f"{out}/loop_discrete"],
        "figures": ["figures", "--only", "fig2", "--only", "fig3", "--only", "fig7", "--only", "fig8",
                    "--only", "energy_delta", "--out", f"{out}/figures"],
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("tree", type=Path, help="source tree with its virtual environment in TREE/.venv")
    ap.add_argument("out", type=Path, help="output folder")
    ap.add_argument("--grid", type=int, default=5, choices=range(0, len(GRID_CASES) + 1), metavar="N",
                    help=f"robustness-grid cases to run, the first N of GRID_CASES (0 to {len(GRID_CASES)}, default 5)")
    ap.add_argument("--only", action="append", help="run only this workload (repeatable; 'grid' for the grid)")
    args = ap.parse_args(argv)
    tree, out = args.tree.resolve(), args.out.resolve()
    jointdyn, python = tree / ".venv/bin/jointdyn", tree / ".venv/bin/python"
    if not jointdyn.is_file():
        print(f"reference_outputs: {jointdyn} not found (make TREE/.venv first)", file=sys.stderr)
        return 2
    out.mkdir(parents=True, exist_ok=True)
    jobs = {name: [str(jointdyn), *a] for name, a in workloads(out).items()}
    if args.grid:
        import json

        jobs["grid"] = [str(python), "-c", _GRID_SCRIPT, json.dumps(GRID_CASES[:args.grid])]
    failed = 0
    for name, cmd in jobs.items():
        if args.only and name not in args.only:
            continue
        t0 = time.perf_counter()
        with open(out / f"{name}.json", "w") as so, open(out / f"{name}.err", "w") as se:
            rc = subprocess.run(cmd, cwd=tree, stdout=so, stderr=se).returncode
        with open(out / "log.txt", "a") as log:
            log.write(f"{name} rc={rc} {time.perf_counter() - t0:.0f}s\n")
        failed += rc not in (0, 3)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
