"""Benchmarks of jointdyn: ``python benchmarks/run.py --json [--quick]``.

Every ``bench_*.py`` module beside this file defines ``run(quick) -> dict``;
their results are gathered into one JSON object. Each speed is reported next
to a ratio against a reference implementation measured in the same run, since
absolute timings on shared machines are noisy.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import os
import platform
import sys
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--json", action="store_true", help="print one JSON object")
    ap.add_argument("--quick", action="store_true", help="short run")
    ap.add_argument("--only", action="append", help="run only bench_<NAME>.py")
    args = ap.parse_args(argv)
    sys.path.insert(0, str(HERE))
    out = {
        "machine": {"python": platform.python_version(), "cpus": os.cpu_count(), "platform": platform.platform()},
        "quick": bool(args.quick),
    }
    t0 = time.perf_counter()
    failed = []
    for path in sorted(HERE.glob("bench_*.py")):
        name = path.stem[len("bench_"):]
        if args.only and name not in args.only:
            continue
        spec = importlib.util.spec_from_file_location(path.stem, path)
        mod = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(mod)
        if not args.json:
            print(f"running {path.name} ...", file=sys.stderr)
        try:
            out[name] = mod.run(quick=args.quick)
        except Exception as exc:  # the other benchmarks still run; the exit status says one failed
            out[name] = {"error": f"{type(exc).__name__}: {exc}"}
            failed.append(name)
    out["total_seconds"] = time.perf_counter() - t0
    if args.json:
        print(json.dumps(out))
    else:
        print(json.dumps(out, indent=2))
    if failed:
        print(f"benchmarks failed: {', '.join(failed)}", file=sys.stderr)
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
