"""``jointdyn fit`` with the intervals of issue 32: JSON keys kept and the new ones added, a
microslip backbone that names what it determines (exit 3), loops picked up mid-cycle, and a
file in mm refused (one line, exit 2, no file)."""

from __future__ import annotations

import json
import math

import numpy as np

import jointdyn as jd
from jointdyn.cli import main
from jointdyn.identify import describing_function

KT, MU, NREF = 1e5, 0.1, 100.0


def _loops(path, scale=1.0, start=0):
    law = jd.make_law("iwan", kt=KT, mu=MU, n_ref=NREF)
    t = np.linspace(0.0, 3.0, 1201)
    x = 1.3 * law.x_slip * np.sin(2 * np.pi * t)
    N = np.full(t.size, NREF)
    T = jd.march(law, x, N)[0] + 0.1 * np.random.default_rng(0).normal(size=t.size)
    rows = np.column_stack([t, scale * x, N, T])[start:]
    np.savetxt(path, rows, delimiter=",", header="t,x,N,T", comments="")
    return path


def test_loops_json_keeps_its_keys_and_adds_intervals(tmp_path, capsys):
    src = _loops(tmp_path / "loops.csv", start=470)
    assert main(["fit", "--input", str(src), "--model", "iwan", "--json"]) == 0
    d = json.loads(capsys.readouterr().out)
    old = {"kind", "model", "status", "message", "parameters", "standard_errors", "not_identifiable", "correlation",
           "rms_residual", "n_ref_N", "evaluations"}
    assert old <= set(d)
    assert d["record_start"].startswith("mid-cycle")
    for k in ("kt", "mu", "fy_N"):
        iv = d["intervals"][k]
        assert iv["low"] < d["parameters"][k] < iv["high"] and iv["level"] == 0.95
    assert abs(d["parameters"]["kt"] / KT - 1.0) < 0.01
    assert main(["fit", "--input", str(src), "--model", "iwan"]) == 0
    out = capsys.readouterr().out
    assert "95 %: [" in out and "record mid-cycle" in out


def test_microslip_backbone_exits_3_naming_the_combinations(tmp_path, capsys):
    law = jd.make_law("segalman", kt=KT, mu=MU, n_ref=NREF, chi=-0.5, beta=0.2)
    from jointdyn.identify._microslip import microslip_constants

    pm = microslip_constants(law)[2]
    A = np.geomspace(0.03, 0.95, 25) * pm
    k1, en = describing_function(law, A)
    w = np.sqrt((4e5 + k1) / 2.0)
    D = en / (2 * math.pi * 2.0 * w * w * A * A) + 0.002 * math.sqrt(5e5 / 2.0) / w
    rng = np.random.default_rng(3)
    w, D = w * (1 + 1e-3 * rng.normal(size=A.size)), D + 0.01 * D.max() * rng.normal(size=A.size)
    src = tmp_path / "bb.csv"
    np.savetxt(src, np.column_stack([A, w, D]), delimiter=",", header="amplitude_m,omega_rad_s,damping_ratio",
               comments="")
    assert main(["fit", "--backbone", str(src), "--model", "segalman", "--mass", "2", "--json"]) == 3
    d = json.loads(capsys.readouterr().out)
    assert d["status"] == "partly-identified"
    assert d["parameters"]["kt"] is None and "microslip" in d["not_identifiable"]["kt"]
    combo = d["determined_combinations"]["k_plus_kt"]
    assert combo["interval"]["low"] <= 5e5 <= combo["interval"]["high"] and combo["unit"] == "N/m"
    assert set(d["determined_combinations"]) == {"k_plus_kt", "R", "chi", "zeta"}
    assert main(["fit", "--backbone", str(src), "--model", "segalman", "--mass", "2"]) == 3
    assert "determined: k_plus_kt" in capsys.readouterr().out


def test_loops_in_mm_are_refused(tmp_path, capsys):
    big = _loops(tmp_path / "loops.csv", scale=1e3)  # x in mm: up to 0.26, read as m
    out = tmp_path / "out"
    rc = main(["fit", "--input", str(big), "--model", "iwan", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and "column x" in err and "mm" in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
