"""Benchmark of harmonic balance on the robustness grid (issue 9).

Reported:

* ``grid_*``: the whole grid of :mod:`jointdyn.validation.hb_grid` (4 models x
  4 eta x 6 beta, default CLI settings, gamma 0.6:1.8:0.01, each highest
  peak checked against the time domain): wall seconds, CPU seconds of the
  branches, the fraction of branches that cover the range (or are
  unbounded where Den Hartog's bound says so), the fraction of cases
  that pass every check and the number of covered cases whose peak could
  not be compared (the time-domain steady state subharmonic or dependent
  on the start: ``Verdict``);
* ``fig6_hb_default_*``: the Fig 6 harmonic-balance data set with the
  default (exact) model, 4 eta x 6 beta, default settings (harmonics and
  samples chosen automatically), without the time-domain checks, run by
  :func:`~jointdyn.validation.hb_grid.grid_cases` on ``FIG6_WORKERS``
  processes: wall seconds (target <= 5 s on 2 cores), the CPU seconds of
  the branches summed over the cases, and the slowest case;

* ``cli_hb_process_*``: time to first answer, ``jointdyn frc --method hb
  --model jenkins --gamma 0.6:1.8:0.01 --json`` as a whole process with
  warm caches: best of ``CLI_ROUNDS`` runs, wall and CPU seconds (the
  process and its children). The first run, not counted, fills Numba's
  disk cache and Python's bytecode cache, as an installed package has them
  (``pip install`` compiles the bytecode; ``PYTHONDONTWRITEBYTECODE`` is
  ignored for that run only, so that a source checkout is measured in the
  same state). Beside it, alternating run by run, the floor that no
  command of a Numba package goes below: ``python -c "import numpy,
  numba"`` (``cli_hb_process_floor_*``), so that the figure can be read
  on a machine faster or slower than the one of the target (<= 0.7 s
  whole, measured where the floor was about 0.3 s).

``--quick``: the default model's row only (the Fig 6 data set), no time domain.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
CLI_ROUNDS = 3
#: issue 9's target for the whole process, s (set where the import floor was about 0.3 s)
TARGET_CLI_SECONDS = 0.7
#: processes of the Fig 6 data set (the target's 2 cores)
FIG6_WORKERS = 2
CLI_ARGS = ("-m", "jointdyn", "frc", "--method", "hb", "--model", "jenkins", "--gamma", "0.6:1.8:0.01", "--json")
#: the reference process: the imports every compiled command needs
FLOOR_ARGS = ("-c", "import numpy, numba")


def cli_process_seconds(rounds: int = CLI_ROUNDS) -> dict:
    """Wall and CPU seconds of the CLI's hb command as a whole process, best of ``rounds`` (after one
    warm-up run that fills the compile and bytecode caches), and of the import floor ``import numpy,
    numba`` measured alternately with it."""
    import os
    import resource
    import subprocess

    env = {**os.environ, "PYTHONPATH": str(SRC) + os.pathsep + os.environ.get("PYTHONPATH", "")}
    # the warm-up run writes the bytecode cache too
    warm_up = {k: v for k, v in env.items() if k != "PYTHONDONTWRITEBYTECODE"}
    best = {k: float("inf") for k in ("wall", "cpu", "floor_wall", "floor_cpu")}

    def timed(args, run_env):
        before = resource.getrusage(resource.RUSAGE_CHILDREN)
        t = time.perf_counter()
        subprocess.run([sys.executable, *args], env=run_env, stdout=subprocess.DEVNULL, check=True)
        w = time.perf_counter() - t
        after = resource.getrusage(resource.RUSAGE_CHILDREN)
        return w, after.ru_utime - before.ru_utime + after.ru_stime - before.ru_stime

    timed(CLI_ARGS, warm_up)  # fills the compile cache
    timed(FLOOR_ARGS, warm_up)
    for _ in range(rounds):
        for prefix, args in (("", CLI_ARGS), ("floor_", FLOOR_ARGS)):
            w, c = timed(args, env)
            best[prefix + "wall"] = min(best[prefix + "wall"], w)
            best[prefix + "cpu"] = min(best[prefix + "cpu"], c)
    best["above_floor_wall"] = best["wall"] - best["floor_wall"]
    return best


def cli_process(rounds: int = CLI_ROUNDS) -> dict:
    """:func:`cli_process_seconds` under ``cli_hb_process_*`` names, with the target and whether it is met."""
    out = {f"cli_hb_process_{k}_seconds": v for k, v in cli_process_seconds(rounds).items()}
    out["cli_hb_process_target_seconds"] = TARGET_CLI_SECONDS
    out["cli_hb_process_target_met"] = bool(out["cli_hb_process_wall_seconds"] <= TARGET_CLI_SECONDS)
    return out


def run(quick: bool = False) -> dict:
    sys.path.insert(0, str(SRC))
    from jointdyn import config
    from jointdyn.validation.hb_grid import GRID_BETAS, GRID_ETAS, GRID_MODELS, Verdict, grid_case, grid_cases

    grid_case(config.MODEL, 0.5, 2.0, time_domain=False)  # warm-up (compiles or loads the cache)
    t = time.perf_counter()
    fig6 = grid_cases([(config.MODEL, e, b) for e in GRID_ETAS for b in GRID_BETAS], time_domain=False,
                      workers=FIG6_WORKERS)
    slowest = max(fig6, key=lambda c: c.seconds)
    out = {
        "fig6_hb_default_model": config.MODEL,
        "fig6_hb_default_workers": FIG6_WORKERS,
        "fig6_hb_default_seconds": time.perf_counter() - t,
        "fig6_hb_default_branch_cpu_seconds": sum(c.seconds for c in fig6),
        "fig6_hb_default_slowest_case": f"eta {slowest.eta:g}, beta {slowest.beta:g}: {slowest.seconds:.2f} s "
                                        f"({slowest.harmonics} x {slowest.samples})",
        "fig6_hb_default_covered_rate": sum(c.covered for c in fig6) / len(fig6),
    }
    out.update(cli_process(2 if quick else CLI_ROUNDS))
    if quick:
        return out
    t = time.perf_counter()
    cases = [grid_case(m, e, b) for m in GRID_MODELS for e in GRID_ETAS for b in GRID_BETAS]
    out.update({
        "grid_cases": len(cases),
        "grid_seconds": time.perf_counter() - t,
        "grid_branch_cpu_seconds": sum(c.seconds for c in cases),
        "grid_covered_rate": sum(c.covered for c in cases) / len(cases),
        "grid_pass_rate": sum(c.ok for c in cases) / len(cases),
        "grid_not_compared": sum(c.covered and c.verdict in (Verdict.SUBHARMONIC, Verdict.NOT_UNIQUE)
                                 for c in cases),
    })
    return out


if __name__ == "__main__":
    import json

    print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
