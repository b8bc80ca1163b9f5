"""``jointdyn loop``: JSON, files, CSV input, and bad input (exit 2, no file)."""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from jointdyn.cli import main
from tolerances import TEST_ENERGY_RTOL, TEST_QS_FRACTION_ATOL
from jointdyn.drivers import harmonic_history

KT, MU, N0, A = 1e5, 0.1, 100.0, 0.5e-3
FY = MU * N0
KEYS = {
    "energy_J",
    "energy_per_cycle_J",  # deprecated duplicate of energy_J, kept for one release
    "force_max_N",
    "force_min_N",
    "separation_fraction",
    "macroslip_fraction",
    "stick_slip_fraction",
    "secant_stiffness_N_per_m",
    "loss_factor",
    "model",
    "parameters",
}


def run_cli(argv):
    """main() in-process; argparse errors raise SystemExit, return its code."""
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def loop_json(capsys, *args):
    grid = [] if "--input" in args else ["--steps-per-cycle", "400"]  # the grid is refused with --input
    rc = run_cli(["loop", "--json", *grid, *args])
    out = capsys.readouterr().out
    assert rc == 0
    assert len(out.strip().splitlines()) == 1
    return json.loads(out)


def test_json_default_matches_closed_form(capsys):
    d = loop_json(capsys)
    assert KEYS <= set(d)
    assert d["model"] == "iwan" and d["parameters"]["capacity"] == 32
    assert d["parameters"]["kt_N_per_m"] == KT and d["parameters"]["amplitude_m"] == A
    # docs/model.md section 2, A > 2 fy / kt: E = 4 fy A - 16 fy^2 / (3 kt)
    assert d["energy_J"] == pytest.approx(4 * FY * A - 16 * FY**2 / (3 * KT), rel=TEST_ENERGY_RTOL)
    assert d["force_max_N"] == pytest.approx(FY) and d["force_min_N"] == pytest.approx(-FY)
    assert d["secant_stiffness_N_per_m"] == pytest.approx(FY / A)
    assert d["separation_fraction"] == 0.0
    total = d["stick_slip_fraction"] + d["macroslip_fraction"] + d["separation_fraction"]
    assert total == pytest.approx(1.0, abs=1e-12)
    assert 0 < d["loss_factor"] < 1


@pytest.mark.parametrize("model", ["iwan", "iwan-closed", "iwan-paper", "discrete", "jenkins"])
def test_json_separation(capsys, model):
    n = ("--n", "200") if model == "discrete" else ()
    d = loop_json(capsys, "--model", model, "--eta", "1.2", "--delta", "90", *n)
    expected = (math.pi - 2 * math.asin(1 / 1.2)) / (2 * math.pi)
    assert d["separation_fraction"] == pytest.approx(expected, abs=TEST_QS_FRACTION_ATOL)
    assert d["parameters"]["delta_deg"] == 90.0
    assert d["energy_J"] > 0
    assert d["force_max_N"] <= MU * N0 * 2.2 + 1e-9
    if model == "discrete":
        assert d["parameters"]["n"] == 200


def test_kn_gives_same_loop(capsys):
    a = loop_json(capsys, "--eta", "1.2")
    b = loop_json(capsys, "--eta", "1.2", "--kn", "1e5")
    assert b["parameters"]["kn_N_per_m"] == 1e5
    for k in KEYS - {"parameters", "model"}:
        assert a[k] == pytest.approx(b[k], rel=1e-9, abs=1e-12)


def test_out_writes_csv_and_png(tmp_path, capsys):
    out = tmp_path / "res"
    rc = run_cli(["loop", "--eta", "1.2", "--steps-per-cycle", "200", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and "energy per cycle" in text
    assert sorted(p.name for p in out.iterdir()) == ["loop.csv", "loop.png"]
    df = pd.read_csv(out / "loop.csv")
    assert list(df.columns) == ["t", "x", "N", "T", "state", "inserted"]
    assert not df["inserted"].any()  # the harmonic grid already holds the crossing instants
    assert set(df["state"]) == {"stick-slip", "macroslip", "separation"}
    assert np.all(df.loc[df["state"] == "separation", "T"] == 0.0)
    assert np.all(df.loc[df["N"] <= 0, "state"] == "separation")
    assert len(df) == 2 * 200 + 1 + 4  # grid plus 2 separation + 2 re-contact instants
    assert (out / "loop.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def _write_history(path, cycles=2, steps=200, eta=1.2):
    t, x, N = harmonic_history(A, 1.0, N0, eta=eta, cycles=cycles, steps_per_cycle=steps)
    pd.DataFrame({"t": t, "x": x, "N": N}).to_csv(path, index=False, float_format="%.17g")


def test_input_csv(tmp_path, capsys):
    p = tmp_path / "h.csv"
    _write_history(p)
    whole = loop_json(capsys, "--input", str(p))
    assert whole["parameters"]["input"] == str(p) and whole["cycle_is_period"] is False
    per = loop_json(capsys, "--input", str(p), "--period", "1")
    ref = loop_json(capsys, "--eta", "1.2", "--steps-per-cycle", "200")
    for k in KEYS - {"parameters", "model"}:
        assert per[k] == pytest.approx(ref[k], rel=1e-12, abs=1e-15)
    # the whole history (2 cycles, starting virgin) is one window: its work
    assert whole["energy_J"] > per["energy_J"]
    assert whole["t_end_s"] == 2.0


BAD = [
    (["--kt", "0"], "--kt"),
    (["--kt", "-1e5"], "--kt"),
    (["--n-ref", "0"], "--n-ref"),
    (["--n-ref", "-5"], "--n-ref"),
    (["--n", "0"], "--n"),
    (["--steps-per-cycle", "0"], "--steps-per-cycle"),
    (["--steps-per-cycle", "2"], "--steps-per-cycle"),
    (["--mu", "-0.1"], "--mu"),
    (["--mu", "nan"], "--mu"),
    (["--amplitude", "nan"], "--amplitude"),
    (["--amplitude", "0"], "--amplitude"),
    (["--frequency", "inf"], "--frequency"),
    (["--eta", "-1"], "--eta"),
    (["--delta", "nan"], "--delta"),
    (["--cycles", "0"], "--cycles"),
    (["--kn", "-1"], "--kn"),
    (["--model", "coulomb"], "--model"),
    (["--period", "1"], "--period"),
    (["--input", "does-not-exist.csv"], "--input"),
]


def _check_failed(rc, capsys, out, name):
    err = capsys.readouterr().err
    assert rc == 2
    assert len(err.strip().splitlines()) == 1, err
    assert name in err
    assert not out.exists() or not any(out.iterdir())


@pytest.mark.parametrize("args, name", BAD)
def test_bad_input_exit_2_no_file(tmp_path, capsys, args, name):
    out = tmp_path / "out"
    rc = run_cli(["loop", "--out", str(out), *args])
    _check_failed(rc, capsys, out, name)


BAD_CSV = [
    ("t,x,N\n0,0,100\n1,1e-5,100\n2,2e-5\n", "line 4: expected 3 fields"),
    ("t,x,N\n0,0,100\n1,1e-5,\n2,2e-5,\n", "line 3: N is empty"),
    ("t,x,N\n0,0,100\n2,1e-5,100\n1,2e-5,100\n", "line 4: t must be strictly increasing"),
    ("t,x\n0,0\n1,1e-5\n", "missing column N"),
    ("T,x,N\n0,0,100\n1,1e-5,100\n", "missing column t"),
    ("t,x,N\n0,0,100\n1,nan,100\n", "line 3: x = 'nan' is not finite"),
    ("t,x,N\n0,0,100\n1,inf,100\n", "line 3: x = 'inf' is not finite"),
]


@pytest.mark.parametrize("text, name", BAD_CSV)
def test_bad_csv_exit_2_no_file(tmp_path, capsys, text, name):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    out = tmp_path / "out"
    out.mkdir()  # an existing empty directory must stay empty
    rc = run_cli(["loop", "--input", str(p), "--out", str(out), "--json"])
    _check_failed(rc, capsys, out, name)


def test_kn_with_input_rejected(tmp_path, capsys):
    p = tmp_path / "h.csv"
    _write_history(p, cycles=1, steps=20)
    out = tmp_path / "out"
    rc = run_cli(["loop", "--input", str(p), "--kn", "1e5", "--out", str(out)])
    _check_failed(rc, capsys, out, "--kn")


def test_out_is_a_file(tmp_path, capsys):
    f = tmp_path / "file"
    f.write_text("keep")
    rc = run_cli(["loop", "--out", str(f)])
    assert rc == 2 and "--out" in capsys.readouterr().err
    assert f.read_text() == "keep"


def test_subprocess_json():
    env = dict(os.environ)
    src = str(Path(__file__).resolve().parents[1] / "src")
    env["PYTHONPATH"] = src + os.pathsep + env.get("PYTHONPATH", "")
    r = subprocess.run(
        [sys.executable, "-m", "jointdyn", "loop", "--json", "--eta", "0.6", "--steps-per-cycle", "200"],
        capture_output=True, text=True, env=env, check=False,
    )
    assert r.returncode == 0, r.stderr
    d = json.loads(r.stdout)
    assert KEYS <= set(d) and d["parameters"]["eta"] == 0.6
    assert d["separation_fraction"] == 0.0 and d["force_max_N"] == pytest.approx(1.6 * FY)


# --- what --input changes in the history, said out loud ----------------------------
def _sampled_history(path, rows=801, n_offset=100.0, n_amp=120.0):
    """Two 1-s cycles sampled off the crossing instants (they get inserted)."""
    t = np.linspace(0.0, 2.0, rows)
    x = A * np.sin(2 * np.pi * t)
    N = n_offset + n_amp * np.sin(2 * np.pi * t + 1.0)
    pd.DataFrame({"t": t, "x": x, "N": N}).to_csv(path, index=False, float_format="%.17g")
    return t, x, N


def test_input_inserted_rows_are_marked(tmp_path, capsys):
    p = tmp_path / "h.csv"
    t, x, N = _sampled_history(p)
    out = tmp_path / "o"
    d = loop_json(capsys, "--input", str(p), "--period", "1", "--out", str(out))
    df = pd.read_csv(out / "loop.csv")
    assert df["inserted"].dtype == bool
    assert d["n_inserted"] == int(df["inserted"].sum()) == len(df) - len(t) == 4
    # the rows not inserted are exactly the input, in order
    kept = df.loc[~df["inserted"]]
    np.testing.assert_array_equal(kept["t"].to_numpy(), t)
    np.testing.assert_array_equal(kept["x"].to_numpy(), x)
    np.testing.assert_array_equal(kept["N"].to_numpy(), N)
    assert np.all(df.loc[df["inserted"], "N"] == 0.0)
    assert d["remainder_s"] == 0.0 and d["warnings"] == []
    rc = run_cli(["loop", "--input", str(p), "--period", "1"])
    text = capsys.readouterr().out
    assert rc == 0 and "801 from --input + 4 inserted" in text


def test_input_period_remainder_is_reported(tmp_path, capsys):
    p = tmp_path / "h.csv"
    _sampled_history(p)
    d = loop_json(capsys, "--input", str(p), "--period", "0.75")
    assert d["n_cycles"] == 2 and d["t_end_s"] == pytest.approx(1.5)
    assert d["remainder_s"] == pytest.approx(0.5)
    rc = run_cli(["loop", "--input", str(p), "--period", "0.75"])
    text = capsys.readouterr().out
    assert rc == 0 and "not analysed       the last 0.5 s (after t = 1.5 s)" in text


def test_contact_never_closes_is_a_warning(tmp_path, capsys):
    p = tmp_path / "h.csv"
    _sampled_history(p, n_offset=-5.0, n_amp=1.0)
    rc = run_cli(["loop", "--input", str(p), "--json"])
    cap = capsys.readouterr()
    d = json.loads(cap.out)
    assert rc == 0
    assert d["energy_J"] == 0.0 and d["secant_stiffness_N_per_m"] == 0.0  # the result stays
    assert len(d["warnings"]) == 1 and "never closes" in d["warnings"][0]
    assert cap.err.strip().splitlines() == [f"jointdyn loop: warning: {d['warnings'][0]}"]


def test_harmonic_report_fields(capsys):
    d = loop_json(capsys, "--eta", "1.2")
    assert d["n_inserted"] == 0 and d["remainder_s"] == 0.0 and d["warnings"] == []
