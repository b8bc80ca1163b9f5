"""Measure jointdyn's speed and write docs/performance.md.

Usage::

    python docs/scripts/performance.py [--quick] [--no-figures] [--keep DIR]

Runs ``benchmarks/run.py --json`` and times ``jointdyn figures`` twice in
fresh processes: first with an empty Numba cache (what a first run after
installing costs: every kernel is compiled) and then with the cache that run
filled (every later run), plus each figure alone with the warm cache. It
records the machine and its load while measuring (the load average counts
every process on the machine, not only ours), and rewrites the block between
``<!-- performance:begin -->`` and ``<!-- performance:end -->`` of
docs/performance.md. README.md links there instead of quoting numbers, so
that every timing claim comes from a run of this script.
"""

from __future__ import annotations

import argparse
import datetime as _dt
import json
import os
import platform
import resource
import subprocess
import sys
import tempfile
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]
PAGE = ROOT / "docs" / "performance.md"
BEGIN, END = "<!-- performance:begin -->", "<!-- performance:end -->"


def _env(cache: Path | None = None) -> dict:
    env = dict(os.environ)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT / "src"), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    env["MPLBACKEND"] = "Agg"
    if cache is not None:
        env["NUMBA_CACHE_DIR"] = str(cache)
    return env


def _timed(cmd: list[str], env: dict) -> dict:
    """Wall seconds, CPU seconds of the child processes, and the 1-minute load before and after."""
    load0 = os.getloadavg()[0]
    cpu0 = resource.getrusage(resource.RUSAGE_CHILDREN)
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=ROOT, env=env, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    cpu1 = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(cmd)} failed:\n{proc.stderr[-3000:]}")
    cpu = (cpu1.ru_utime - cpu0.ru_utime) + (cpu1.ru_stime - cpu0.ru_stime)
    return {"wall_s": wall, "cpu_s": cpu, "load_before": load0, "load_after": os.getloadavg()[0],
            "stdout": proc.stdout}


def machine() -> dict:
    cpu = platform.processor() or platform.machine()
    try:
        for line in Path("/proc/cpuinfo").read_text().splitlines():
            if line.startswith("model name"):
                cpu = line.split(":", 1)[1].strip()
                break
    except OSError:
        pass
    mem = ""
    try:
        kb = int(next(ln for ln in Path("/proc/meminfo").read_text().splitlines() if ln.startswith("MemTotal"))
                 .split()[1])
        mem = f"{kb / 2**20:.0f} GiB"
    except (OSError, StopIteration, ValueError):
        pass
    import numba
    import numpy

    return {"date (UTC)": _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M"), "CPU": cpu,
            "cores": os.cpu_count(), "memory": mem, "platform": platform.platform(),
            "Python": platform.python_version(), "NumPy": numpy.__version__, "Numba": numba.__version__}


def time_figures(quick: bool, keep: Path | None = None) -> dict:
    from jointdyn.figures import figure_names

    out = {}
    with tempfile.TemporaryDirectory() as tmp:
        cache = Path(tmp) / "numba-cache"
        cache.mkdir()
        figs = keep if keep is not None else Path(tmp) / "figs"
        cmd = [sys.executable, "-m", "jointdyn", "figures", "--out", str(figs)]
        out["all, cold cache"] = _timed(cmd, _env(cache))
        out["all, warm cache"] = _timed(cmd, _env(cache))
        if not quick:
            for name in figure_names():
                out[name] = _timed(cmd + ["--only", name], _env(cache))
    return out


def run_benchmarks(quick: bool) -> dict:
    cmd = [sys.executable, str(ROOT / "benchmarks" / "run.py"), "--json"] + (["--quick"] if quick else [])
    res = _timed(cmd, _env())
    data = json.loads(res.pop("stdout").strip().splitlines()[-1])
    return {"timing": res, "results": data}


def _flat(prefix: str, value, rows: list) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _flat(f"{prefix}.{k}" if prefix else str(k), v, rows)
    elif isinstance(value, bool) or isinstance(value, str):
        rows.append((prefix, str(value)))
    elif isinstance(value, (int, float)):
        rows.append((prefix, f"{value:.4g}"))
    elif isinstance(value, list) and len(value) <= 8:
        rows.append((prefix, ", ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in value)))


def render(mach: dict, figs: dict | None, bench: dict | None, quick: bool) -> str:
    lines = [f"Measured by `python docs/scripts/performance.py{' --quick' if quick else ''}` "
             f"on {mach['date (UTC)']} UTC.", "", "| machine | |", "|---|---|"]
    lines += [f"| {k} | {v} |" for k, v in mach.items() if k != "date (UTC)"]
    if figs:
        lines += ["", "## `jointdyn figures`", "",
                  "Each line is one fresh process. *Cold*: an empty Numba cache, so every kernel is compiled "
                  "first (the first run after installing). *Warm*: the cache filled by the cold run (every later "
                  "run). CPU time counts all processes of the run (sweeps use every core), so CPU time above wall "
                  "time means parallel work; the load average counts every process on the machine, ours included.",
                  "", "| run | wall (s) | CPU (s) | load before | load after |", "|---|---:|---:|---:|---:|"]
        for name, r in figs.items():
            lines.append(f"| {name} | {r['wall_s']:.1f} | {r['cpu_s']:.1f} | {r['load_before']:.2f} | "
                         f"{r['load_after']:.2f} |")
    if bench:
        t = bench["timing"]
        lines += ["", "## `benchmarks/run.py`", "",
                  f"The whole benchmark took {t['wall_s']:.0f} s wall, {t['cpu_s']:.0f} s CPU (load "
                  f"{t['load_before']:.2f} before, {t['load_after']:.2f} after). Every result, as it printed it "
                  "(what each number means: the docstring of each `benchmarks/bench_*.py`):", "",
                  "| result | value |", "|---|---:|"]
        rows: list = []
        _flat("", bench["results"], rows)
        lines += [f"| `{k}` | {v} |" for k, v in rows]
    return "\n".join(lines)


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="short benchmark, no per-figure times")
    ap.add_argument("--no-figures", action="store_true", help="skip the timing of jointdyn figures")
    ap.add_argument("--no-benchmarks", action="store_true", help="skip benchmarks/run.py")
    ap.add_argument("--keep", type=Path, help="keep the figures written by the timed runs in this folder "
                    "(for docs/scripts/paper_figures.py --from)")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(ROOT / "src"))
    mach = machine()
    figs = None if args.no_figures else time_figures(args.quick, args.keep)
    bench = None if args.no_benchmarks else run_benchmarks(args.quick)
    text = PAGE.read_text()
    i, j = text.index(BEGIN) + len(BEGIN), text.index(END)
    PAGE.write_text(text[:i] + "\n" + render(mach, figs, bench, args.quick) + "\n" + text[j:])
    print(PAGE)
    return 0


if __name__ == "__main__":
    sys.exit(main())
