"""``jointdyn loop --model pair``: one interface node pair under a relative history from CSV."""

import json
import math

import numpy as np
import pandas as pd
import pytest

from jointdyn.cli import main
from jointdyn.drivers import interface_loop
from jointdyn.interfaces import Interface

KT, KN, MU, P = 1e3, 2e3, 0.5, 2.0


def run_cli(argv):
    try:
        return main(argv)
    except SystemExit as exc:
        return exc.code


def _write(path, t, u1, u2, g, header="t,u1,u2,g"):
    np.savetxt(path, np.c_[t, u1, u2, g], delimiter=",", header=header, comments="", fmt="%.17g")


def _orbit(n=2000, cycles=3, g1=0.0):
    t = np.arange(cycles * n + 1) / n
    a = 2.0 * MU * P / KT
    return t, a * np.cos(2 * np.pi * t), a * np.sin(2 * np.pi * t), g1 * np.sin(2 * np.pi * t + 0.5)


PAIR = ["loop", "--model", "pair", "--kt", str(KT), "--kn", str(KN), "--mu", str(MU), "--preload", str(P)]


def test_json_and_csv_of_a_circular_orbit(tmp_path, capsys):
    t, u1, u2, g = _orbit()
    src = tmp_path / "h.csv"
    _write(src, t, u1, u2, g)
    out = tmp_path / "out"
    rc = run_cli([*PAIR, "--input", str(src), "--period", "1", "--json", "--out", str(out)])
    text = capsys.readouterr().out
    assert rc == 0 and len(text.strip().splitlines()) == 1
    d = json.loads(text)
    assert d["model"] == "pair" and d["status"] == "ok" and d["n_cycles"] == 3
    res = interface_loop(Interface(kt=KT, kn=KN, mu=MU, preload=P, pairs=[[0, 1, 2, -1, -1, -1]]), t, u1, u2, g,
                         period=1.0)
    assert d["energy_J"] == res.energy_J
    a, r = 2.0 * MU * P / KT, MU * P / KT
    exact = 2 * math.pi * MU * P * math.sqrt(a * a - r * r)
    assert d["energy_J"] == pytest.approx(exact, rel=2e-3)  # first order in the step (2000 per cycle)
    assert d["slip_fraction"] == 1.0 and d["stick_fraction"] == 0.0 and d["open_fraction"] == 0.0
    assert sorted(p.name for p in out.iterdir()) == ["loop.csv", "loop.png"]
    table = pd.read_csv(out / "loop.csv")
    assert list(table.columns) == ["t", "u1", "u2", "g", "T1", "T2", "N", "state", "inserted"]
    np.testing.assert_array_equal(table["u1"], u1)
    np.testing.assert_array_equal(table["T2"], res.T[:, 0, 1])
    np.testing.assert_array_equal(table["N"], res.N[:, 0])
    # the output is a valid input (its other columns are ignored)
    rc = run_cli([*PAIR, "--input", str(out / "loop.csv"), "--period", "1", "--json"])
    assert rc == 0 and json.loads(capsys.readouterr().out)["energy_J"] == d["energy_J"]


def test_a_line_orbit_is_the_jenkins_loop_of_the_cli(tmp_path, capsys):
    """Along t2 only, at constant load: the energy of ``--model jenkins`` with x = u2, N = P."""
    t = np.linspace(0.0, 2.0, 801)
    x = 3 * MU * P / KT * np.sin(2 * np.pi * t)
    src = tmp_path / "pair.csv"
    _write(src, t, 0 * t, x, 0 * t)
    rc = run_cli([*PAIR, "--input", str(src), "--period", "1", "--json"])
    pair = json.loads(capsys.readouterr().out)
    jen = tmp_path / "jen.csv"
    np.savetxt(jen, np.c_[t, x, np.full_like(t, P)], delimiter=",", header="t,x,N", comments="", fmt="%.17g")
    rc2 = run_cli(["loop", "--model", "jenkins", "--kt", str(KT), "--mu", str(MU), "--n-ref", str(P),
                   "--input", str(jen), "--period", "1", "--json"])
    ref = json.loads(capsys.readouterr().out)
    assert rc == rc2 == 0
    assert pair["energy_J"] == pytest.approx(ref["energy_J"], rel=1e-12)
    assert pair["slip_fraction"] == pytest.approx(ref["macroslip_fraction"], abs=1e-12)


def test_separation_is_reported(tmp_path, capsys):
    t, u1, u2, g = _orbit(n=400, g1=2.0 * P / KN)
    src = tmp_path / "h.csv"
    _write(src, t, u1, u2, g)
    rc = run_cli([*PAIR, "--input", str(src), "--period", "1", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["n_inserted"] > 0
    # open while P + kn g1 sin < 0, i.e. sin < -1/2: a third of the period (up to the linear interpolation)
    assert d["open_fraction"] == pytest.approx(1.0 / 3.0, abs=1e-4)
    assert d["normal_load_min_N"] == 0.0


BAD = [
    ([], "--kn is required"),
    (["--kn", "1e3"], "--preload is required"),
    (["--kn", "1e3", "--preload", "1"], "--input is required"),
    (["--kn", "-1", "--preload", "1", "--input", "IN"], "--kn"),
    (["--kn", "1e3", "--preload", "-1", "--input", "IN"], "--preload"),
    (["--kn", "1e3", "--preload", "1", "--mu", "-1", "--input", "IN"], "--mu"),
    (["--kn", "1e3", "--preload", "1", "--input", "IN", "--amplitude", "1e-3"], "--amplitude"),
    (["--kn", "1e3", "--preload", "1", "--input", "IN", "--n-ref", "3"], "--n-ref"),
    (["--kn", "1e3", "--preload", "1", "--input", "IN", "--period", "100"], "--period"),
    (["--kn", "1e3", "--preload", "1", "--input", "missing.csv"], "--input"),
]


@pytest.mark.parametrize("args, name", BAD)
def test_bad_input_exit_2_no_file(tmp_path, capsys, args, name):
    src = tmp_path / "h.csv"
    t, u1, u2, g = _orbit(n=20, cycles=1)
    _write(src, t, u1, u2, g)
    out = tmp_path / "out"
    out.mkdir()
    args = [str(src) if a == "IN" else (str(tmp_path / a) if a == "missing.csv" else a) for a in args]
    rc = run_cli(["loop", "--model", "pair", *args, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and name in err, err
    assert not any(out.iterdir())


@pytest.mark.parametrize("text, name", [
    ("t,u1,g\n0,0,0\n1,1e-5,0\n", "missing column u2"),
    ("t,u1,u2,g [mm]\n0,0,0,0\n1,1e-5,0,0\n", "has unit 'mm'; expected m"),
    ("t,u1,u2,g\n0,0,0,0\n1,1e-5,0\n", "line 3: expected 4 fields"),
    ("t,u1,u2,g\n0,0,0,0\n1,1e-5,0,nan\n", "line 3: g = 'nan' is not finite"),
])
def test_bad_csv_exit_2_no_file(tmp_path, capsys, text, name):
    src = tmp_path / "bad.csv"
    src.write_text(text)
    out = tmp_path / "out"
    out.mkdir()
    rc = run_cli([*PAIR, "--input", str(src), "--out", str(out), "--json"])
    err = capsys.readouterr().err
    assert rc == 2 and len(err.strip().splitlines()) == 1 and name in err, err
    assert not any(out.iterdir())


def test_preload_is_refused_for_a_contact_law(capsys):
    assert run_cli(["loop", "--preload", "2"]) == 2
    assert "--preload applies to --model pair only" in capsys.readouterr().err
