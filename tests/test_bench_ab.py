"""benchmarks/ab.py: timings told from other numbers, best over rounds, slowdowns flagged either way round."""

from __future__ import annotations

import importlib.util
from pathlib import Path

_PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "ab.py"
_spec = importlib.util.spec_from_file_location("bench_ab", _PATH)
ab = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ab)


def test_kinds_by_path():
    assert ab._kind("laws/iwan/steps_per_s") == "rate"
    assert ab._kind("io/rows_per_s_new") == "rate"
    assert ab._kind("exact/kernel/quadrature/steps_per_second/iwan") == "rate"
    assert ab._kind("laws/iwan/ns_per_step") == "time"
    assert ab._kind("laws/jit/cold_compile/iwan_first_call_s") == "time"
    assert ab._kind("exact/fig6_time_domain/cpu_seconds/iwan") == "time"
    assert ab._kind("normal_spring/x/cpu_s_per_point_spring") == "time"
    for other in ("laws/iwan/target_steps_per_s", "laws/iwan/speedup_vs_python", "modes/large_target_seconds",
                  "dynamics/x/ratio_vs_march", "hb/points", "hb_grid/fig6_hb_default_covered_rate", "io/peak_mb_new"):
        assert ab._kind(other) is None, other


def _run(result, wall=1.0):
    return {"result": result, "wall_seconds": wall, "loadavg_before": "1 1 1", "loadavg_after": "1 1 1",
            "returncode": 0}


def test_compare_best_of_rounds_and_flags():
    old1 = {"hb": {"branch_seconds": 1.0, "points": 3}, "laws": {"steps_per_s": 100.0}, "gone": {"x_s": 1}}
    old2 = {"hb": {"branch_seconds": 2.0, "points": 3}, "laws": {"steps_per_s": 50.0}}
    new1 = {"hb": {"branch_seconds": 1.05, "points": 4}, "laws": {"steps_per_s": 80.0}, "added": {"y_s": 1}}
    new2 = {"hb": {"branch_seconds": 1.5, "points": 4}, "laws": {"steps_per_s": 60.0}}
    runs = {"old": [_run(old1), _run(old2)], "new": [_run(new1), _run(new2)]}
    text = ab.compare(runs, 1.10)
    assert "| `hb/branch_seconds` | time | 1 | 1.05 | 1.050 |  |" in text
    assert "| `laws/steps_per_s` | rate | 100 | 80 | 1.250 | SLOWER |" in text
    flagged = text.split("## Flagged")[1].split("##")[0]
    assert "laws/steps_per_s" in flagged and "hb/branch_seconds" not in flagged
    assert "`hb/points`: old [3.0], new [4.0]" in text
    assert "- `gone/x_s`" in text.split("## Keys only in old")[1].split("##")[0]
    assert "- `added/y_s`" in text.split("## Keys only in new")[1]
