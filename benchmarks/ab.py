"""Old/new comparison of ``benchmarks/run.py`` across two source trees, alternated.

Usage::

    python benchmarks/ab.py --old /path/old-tree --new /path/new-tree --rounds 2 --quick \
        --out ab-results [--only hb --only laws] [--nice 5]
    python benchmarks/ab.py --compare ab-results        # tables again from the saved runs

Each tree needs its own virtual environment at ``TREE/.venv`` (an editable
install of that tree), so that each side runs its own code, its own
``benchmarks/*.py`` and its own Numba cache. The runs alternate
old, new, old, new, ... so that both sides see the same machine load over
time; each run is ``TREE/.venv/bin/python TREE/benchmarks/run.py --json``
started in ``TREE``, and its JSON is saved in ``--out`` with the load average
(``/proc/loadavg``) before and after.

Without ``--only``, only the benchmark modules present in both trees run
(``bench_*.py`` in both ``benchmarks/`` folders); the others are listed.

The comparison takes, for every numeric leaf of the JSON present on both
sides, the best over rounds of each side (the smallest time, the largest
rate), and reports the ratio ``new / old`` of times (for rates, ``old / new``:
above 1 means the new tree is slower either way), flagging ratios above
``--threshold`` (1.10). Leaves are classified by their path: a rate has
``per_s`` (``steps_per_s``, ``rows_per_s_new``) or ``per_second`` in it; a
time has ``seconds``, a part ending in ``_s``, or a ``ns_``/``us_``/``ms_per``
figure; targets, ratios, speedups, counts and sizes are not timings and are
left out of the table (they are listed apart when their values differ).
Cold-compile figures (``compile``, ``cold`` or ``startup`` in the path) are
listed in their own table.

To tell noise from a regression, run the flagged benchmark alone, alternated
several times (``--only NAME --rounds 3``: A, B, A, B, A, B). Figures that
are the same code on both sides (``python_reference_*``, ``*_previous``,
``march_reference_seconds``, ``cli_hb_process_floor_*``) show the noise of
the machine in that run.
"""

from __future__ import annotations

import argparse
import json
import re
import subprocess
import sys
import time
from pathlib import Path

_NOT_TIMING = re.compile(r"target|ratio|speedup|_over_|_vs_|load_average|_mb|bytes|omega|status_counts|rate$")
_RATE = re.compile(r"per_s($|_|/)|per_second")
_TIME = re.compile(r"seconds|_s($|/)|(^|/)cpu_s|(^|/|_)(ns|us|ms)_per")


def _kind(path: str) -> str | None:
    """'rate', 'time' or None (not a timing) for a leaf path ``a/b/c`` (see the module docstring)."""
    if _NOT_TIMING.search(path):
        return None
    if _RATE.search(path):
        return "rate"
    if _TIME.search(path):
        return "time"
    return None


def _leaves(obj, prefix: str = "") -> dict:
    """Numeric leaves (not booleans) of a JSON object, keyed by ``a/b/c`` paths."""
    out = {}
    if isinstance(obj, dict):
        for k, v in obj.items():
            out.update(_leaves(v, f"{prefix}/{k}" if prefix else str(k)))
    elif isinstance(obj, (int, float)) and not isinstance(obj, bool):
        out[prefix] = float(obj)
    return out


def _benches(tree: Path) -> set[str]:
    return {p.stem[len("bench_"):] for p in (tree / "benchmarks").glob("bench_*.py")}


def _loadavg() -> str:
    try:
        return " ".join(Path("/proc/loadavg").read_text().split()[:3])
    except OSError:
        return "?"


def _one_run(tree: Path, only: list[str], quick: bool, nice: int, dest: Path) -> dict:
    cmd = [str(tree / ".venv/bin/python"), str(tree / "benchmarks/run.py"), "--json"]
    cmd += ["--quick"] if quick else []
    for name in only:
        cmd += ["--only", name]
    if nice:
        cmd = ["nice", "-n", str(nice)] + cmd
    before = _loadavg()
    t0 = time.perf_counter()
    proc = subprocess.run(cmd, cwd=tree, capture_output=True, text=True)
    wall = time.perf_counter() - t0
    try:
        result = json.loads(proc.stdout.strip().splitlines()[-1])
    except (IndexError, json.JSONDecodeError):
        result = {"error": f"no JSON (exit {proc.returncode}): {proc.stderr[-2000:]}"}
    record = {"tree": str(tree), "command": cmd, "returncode": proc.returncode, "wall_seconds": wall,
              "loadavg_before": before, "loadavg_after": _loadavg(), "result": result,
              "stderr_tail": proc.stderr[-2000:]}
    dest.write_text(json.dumps(record, indent=1))
    return record


def _best(values: list[float], kind: str) -> float:
    return max(values) if kind == "rate" else min(values)


def compare(runs: dict[str, list[dict]], threshold: float) -> str:
    """Markdown tables comparing the saved runs of both sides (see module docstring)."""
    leaves = {side: [_leaves(r["result"]) for r in recs] for side, recs in runs.items()}
    keys_old = set().union(*leaves["old"]) if leaves["old"] else set()
    keys_new = set().union(*leaves["new"]) if leaves["new"] else set()
    lines = ["| figure | kind | old (best) | new (best) | new/old slowdown | flag |", "|---|---|---|---|---|---|"]
    cold = list(lines)
    changed, flagged = [], []
    for key in sorted(keys_old & keys_new):
        kind = _kind(key)
        old = [d[key] for d in leaves["old"] if key in d]
        new = [d[key] for d in leaves["new"] if key in d]
        if kind is None:
            if set(old) != set(new) and not any(s in key for s in ("seconds", "_s/", "ratio", "speedup")):
                changed.append(f"- `{key}`: old {sorted(set(old))}, new {sorted(set(new))}")
            continue
        bo, bn = _best(old, kind), _best(new, kind)
        slow = (bo / bn if kind == "rate" else bn / bo) if bo > 0 and bn > 0 else float("nan")
        flag = "SLOWER" if slow > threshold else ""
        row = f"| `{key}` | {kind} | {bo:.6g} | {bn:.6g} | {slow:.3f} | {flag} |"
        (cold if ("compile" in key or "cold" in key or "startup" in key) else lines).append(row)
        if flag:
            flagged.append(key)
    text = ["## Timings (best over rounds; slowdown > 1 means the new tree is slower)", *lines, "",
            "## Cold compile and start-up", *cold, ""]
    text += ["## Flagged (> %.2f)" % threshold, *(f"- `{k}`" for k in flagged or ["(none)"]), ""]
    text += ["## Non-timing numbers that differ", *(changed or ["(none)"]), ""]
    text += ["## Keys only in old", *(f"- `{k}`" for k in sorted(keys_old - keys_new)), "",
             "## Keys only in new", *(f"- `{k}`" for k in sorted(keys_new - keys_old)), ""]
    text += ["## Runs", "| side | file | wall s | loadavg before | loadavg after | exit |", "|---|---|---|---|---|---|"]
    for side, recs in runs.items():
        for r in recs:
            text.append(f"| {side} | {r.get('file', '')} | {r['wall_seconds']:.0f} | {r['loadavg_before']} "
                        f"| {r['loadavg_after']} | {r['returncode']} |")
    return "\n".join(text)


def _load(out: Path) -> dict[str, list[dict]]:
    runs = {"old": [], "new": []}
    for path in sorted(out.glob("*-r*.json")):
        side = path.name.split("-", 1)[0]
        if side in runs:
            rec = json.loads(path.read_text())
            rec["file"] = path.name
            runs[side].append(rec)
    return runs


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--old", type=Path, help="old source tree (with .venv)")
    ap.add_argument("--new", type=Path, help="new source tree (with .venv)")
    ap.add_argument("--rounds", type=int, default=2, help="runs per side, alternated (default 2)")
    ap.add_argument("--quick", action="store_true", help="run.py --quick")
    ap.add_argument("--only", action="append", default=None, help="run only bench_<NAME>.py (repeatable)")
    ap.add_argument("--nice", type=int, default=5, help="niceness of the benchmark processes (default 5)")
    ap.add_argument("--out", type=Path, default=Path("ab-results"), help="folder for the saved runs")
    ap.add_argument("--threshold", type=float, default=1.10, help="slowdown flagged above this (default 1.10)")
    ap.add_argument("--compare", type=Path, help="only print the tables of the runs saved in this folder")
    args = ap.parse_args(argv)
    if args.compare:
        print(compare(_load(args.compare), args.threshold))
        return 0
    if args.old is None or args.new is None:
        ap.error("--old and --new are required (or --compare DIR)")
    if args.rounds < 1:
        ap.error(f"--rounds must be >= 1, got {args.rounds}")
    old, new = args.old.resolve(), args.new.resolve()
    both = _benches(old) & _benches(new)
    only = sorted(args.only) if args.only else sorted(both)
    args.out.mkdir(parents=True, exist_ok=True)
    (args.out / "plan.json").write_text(json.dumps({
        "old": str(old), "new": str(new), "rounds": args.rounds, "quick": args.quick, "only": only,
        "only_in_old": sorted(_benches(old) - _benches(new)), "only_in_new": sorted(_benches(new) - _benches(old))},
        indent=1))
    for r in range(args.rounds):
        for side, tree in (("old", old), ("new", new)):
            print(f"round {r + 1}/{args.rounds}: {side} ({tree}) ...", file=sys.stderr, flush=True)
            rec = _one_run(tree, only, args.quick, args.nice, args.out / f"{side}-r{r + 1}.json")
            print(f"  {rec['wall_seconds']:.0f} s, exit {rec['returncode']}, load {rec['loadavg_before']}"
                  f" -> {rec['loadavg_after']}", file=sys.stderr, flush=True)
    report = compare(_load(args.out), args.threshold)
    (args.out / "report.md").write_text(report + "\n")
    print(report)
    return 0


if __name__ == "__main__":
    sys.exit(main())
