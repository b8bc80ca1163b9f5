"""CSV history reader (issue 12): rows per second and peak memory of
:func:`jointdyn.read_history_csv` beside the previous reader.

``run(quick)`` writes a history file (``t, x, N`` with 17 significant digits,
as ``loop.csv`` and ``pandas.to_csv(float_format="%.17g")`` write them) and
reads it with each reader in a fresh subprocess, alternating previous and
new, ``ROUNDS`` rounds (1 in quick mode). Each child imports everything
first, then measures the CPU time of the read (``time.process_time``) and
the growth of its peak resident memory over the resident memory before the
read: Linux's high-water mark ``VmHWM`` is reset through
``/proc/self/clear_refs`` first, so that import-time peaks do not hide it
(elsewhere ``resource.getrusage`` maxrss). Resident memory sees the
compiled parsers' buffers, which tracemalloc does not. Reported:
best of the rounds for time, largest for memory, and

- ``rows_per_s_new`` / ``rows_per_s_previous`` and their ratio ``speedup``;
- ``peak_mb_new`` / ``peak_mb_previous`` and ``peak_over_float_data_new``
  (peak growth / the 24 bytes per row of the three float64 columns);
- ``identical``: both readers return the same arrays bit for bit.

The previous reader is copied below verbatim (it converted every cell with
``float`` in a Python loop).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np

ROWS = 2_000_000
ROWS_QUICK = 100_000
ROUNDS = 3


# --- the previous reader, verbatim (reference) ---------------------------------------------
def previous_read_history_csv(path):
    import pandas as pd

    from jointdyn import _validate as V

    path = Path(path)
    if not path.is_file():
        raise ValueError(f"input must be an existing CSV file, got {str(path)!r}")
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False, skipinitialspace=True)
    except (pd.errors.EmptyDataError, pd.errors.ParserError, UnicodeDecodeError) as exc:
        raise ValueError(f"input {str(path)!r} is not a readable CSV file: {exc}") from None
    df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in ("t", "x", "N") if c not in df.columns]
    if missing:
        raise ValueError(
            f"input CSV must have columns t, x, N (SI units); missing {', '.join(missing)} "
            f"(found {', '.join(df.columns) or 'none'})"
        )
    cols = {}
    lengths = {}
    for name in ("t", "x", "N"):
        raw = [s.strip() for s in df[name].tolist()]
        filled = [i for i, s in enumerate(raw) if s != ""]
        n = filled[-1] + 1 if filled else 0
        if len(filled) != n:
            row = next(i for i in range(n) if raw[i] == "")
            raise ValueError(f"column {name} has an empty cell at data row {row + 1}")
        vals = np.empty(n)
        for i in range(n):
            try:
                vals[i] = float(raw[i])
            except ValueError:
                raise ValueError(f"column {name} must be numeric, got {raw[i]!r} at data row {i + 1}") from None
        cols[name] = vals
        lengths[name] = n
    V.same_length(**cols)
    n = lengths["t"]
    if n < 2:
        raise ValueError(f"input CSV must have at least 2 samples, got {n}")
    t = V.increasing("t", V.finite_array("t", cols["t"]))
    x = V.finite_array("x", cols["x"])
    N = V.finite_array("N", cols["N"])
    return t, x, N


# --- measurement ----------------------------------------------------------------------------
def _write_history(path: Path, rows: int) -> None:
    import pandas as pd

    rng = np.random.default_rng(0)
    t = np.arange(rows) * 1e-4
    x = 5e-4 * np.sin(2 * np.pi * t) + 1e-6 * rng.standard_normal(rows)
    N = 100.0 + 120.0 * np.sin(2 * np.pi * t + 1.0)
    pd.DataFrame({"t": t, "x": x, "N": N}).to_csv(path, index=False, float_format="%.17g")


def _status_kb(field: str) -> int | None:
    try:
        with open("/proc/self/status") as fh:
            for line in fh:
                if line.startswith(field + ":"):
                    return int(line.split()[1])
    except OSError:
        pass
    return None


def _reset_peak() -> bool:
    """Reset VmHWM to the current resident size (Linux >= 4.0)."""
    try:
        with open("/proc/self/clear_refs", "w") as fh:
            fh.write("5")
    except OSError:
        return False
    return _status_kb("VmHWM") is not None


def _child(which: str, path: str, dump: str | None) -> None:
    """Read ``path`` with one reader; print CPU seconds and peak growth."""
    import resource
    import time

    import pandas  # noqa: F401 - imported before the baseline is taken

    from jointdyn import read_history_csv

    reader = previous_read_history_csv if which == "previous" else read_history_csv
    hwm = _reset_peak()
    base = _status_kb("VmRSS") if hwm else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    c0 = time.process_time()
    t, x, N = reader(path)
    cpu = time.process_time() - c0
    peak = _status_kb("VmHWM") if hwm else resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    if dump:
        np.save(dump, np.stack([t, x, N]))
    print(json.dumps({"cpu_s": cpu, "peak_bytes": (peak - base) * 1024, "rows": int(t.size),
                      "method": "VmHWM" if hwm else "maxrss"}))


def _measure(which: str, path: Path, dump: Path | None = None) -> dict:
    src = str(Path(__file__).resolve().parents[1] / "src")
    env = dict(os.environ)
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    cmd = [sys.executable, __file__, "--child", which, str(path)] + ([str(dump)] if dump else [])
    r = subprocess.run(cmd, capture_output=True, text=True, env=env, check=True)
    return json.loads(r.stdout.strip().splitlines()[-1])


def run(quick: bool = False) -> dict:
    rows = ROWS_QUICK if quick else ROWS
    rounds = 1 if quick else ROUNDS
    with tempfile.TemporaryDirectory(prefix="jointdyn-bench-io-") as tmp:
        path = Path(tmp) / "history.csv"
        _write_history(path, rows)
        size = path.stat().st_size
        runs = {"previous": [], "new": []}
        for k in range(rounds):
            for which in ("previous", "new"):  # alternating, fresh process each
                dump = Path(tmp) / f"{which}.npy" if k == 0 else None
                runs[which].append(_measure(which, path, dump))
        identical = bool(np.array_equal(np.load(Path(tmp) / "previous.npy"), np.load(Path(tmp) / "new.npy")))
    float_bytes = 24 * rows
    best = {w: min(r["cpu_s"] for r in runs[w]) for w in runs}
    peak = {w: max(r["peak_bytes"] for r in runs[w]) for w in runs}
    return {
        "rows": rows,
        "file_mb": size / 1e6,
        "rounds": rounds,
        "rows_per_s_new": rows / best["new"],
        "rows_per_s_previous": rows / best["previous"],
        "speedup": best["previous"] / best["new"],
        "seconds_new": best["new"],
        "seconds_previous": best["previous"],
        "peak_mb_new": peak["new"] / 1e6,
        "peak_mb_previous": peak["previous"] / 1e6,
        "peak_over_float_data_new": peak["new"] / float_bytes,
        "peak_over_float_data_previous": peak["previous"] / float_bytes,
        "identical": identical,
        "cpu_s_all": {w: [round(r["cpu_s"], 4) for r in runs[w]] for w in runs},
        "memory_method": runs["new"][0]["method"],
    }


if __name__ == "__main__":
    if len(sys.argv) >= 4 and sys.argv[1] == "--child":
        _child(sys.argv[2], sys.argv[3], sys.argv[4] if len(sys.argv) > 4 else None)
    else:
        print(json.dumps(run(quick="--quick" in sys.argv), indent=2))
