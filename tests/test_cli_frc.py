"""``jointdyn frc`` in-process: JSON shape, files, bad input (exit 2, no files).

Uses the steady_state test double of test_sweeps (tests only); the real
solver is exercised in test_sweeps' dynamics tests.
"""

from __future__ import annotations

import json

import numpy as np
import pytest

from jointdyn.cli import main
from jointdyn.commands.frc import parse_gamma
from jointdyn.sweeps import _points

from test_sweeps import _Fake


@pytest.fixture
def fake(monkeypatch):
    f = _Fake()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: f)
    return f


def test_json_time(fake, capsys, tmp_path):
    rc = main(["frc", "--gamma", "0.8:1.3:0.1", "--beta", "2", "--eta", "0.5", "--workers", "1",
               "--json", "--out", str(tmp_path)])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "time" and out["eta"] == 0.5 and out["beta"] == 2.0
    assert out["f1"] == pytest.approx(25.0)
    up, down = out["directions"]["up"], out["directions"]["down"]
    assert up["gamma"] == pytest.approx([0.8, 0.9, 1.0, 1.1, 1.2, 1.3])
    assert up["status"] == ["periodic", "periodic", "unbounded", "unbounded", "periodic", "periodic"]
    assert up["amplitude_q"][2] is None  # NaN goes out as null
    assert set(up) == {"gamma", "amplitude_q", "amplitude_m", "offset_m", "max_abs_m", "status", "negative_dissipation",
                       "period_multiple", "not_settled_reason"}
    assert up["negative_dissipation"] == [False] * 6
    assert down["amplitude_q"][4] == pytest.approx(1 / 0.15 + 0.5 / 0.25)
    for name in ("frc.nc", "frc.csv", "frc.png"):
        assert (tmp_path / name).stat().st_size > 0
    assert len(list((tmp_path / "lines").iterdir())) == 2  # one checkpoint folder per line
    assert out["reused_points"] == 0


def test_f1_and_one_direction_and_table(fake, capsys):
    rc = main(["frc", "--gamma", "0.8:0.9:0.1", "--f1", "10", "--sweep", "down", "--workers", "1"])
    assert rc == 0
    text = capsys.readouterr().out
    assert "q_down" in text and "q_up" not in text
    assert {c[0] for c in fake.calls} == {10.0}


def test_parse_gamma():
    np.testing.assert_allclose(parse_gamma("0.6:1.8:0.01"), np.round(np.arange(121) * 0.01 + 0.6, 12))
    assert parse_gamma("1:1:0.1").tolist() == [1.0]


@pytest.mark.parametrize(
    "argv, word",
    [
        (["--gamma", "0.6:1.8"], "--gamma"),
        (["--gamma", "a:b:c"], "--gamma"),
        (["--gamma", "0:1:0.1"], "--gamma START"),
        (["--gamma", "1.8:0.6:0.1"], "--gamma STOP"),
        (["--gamma", "0.6:1.8:0"], "--gamma STEP"),
        (["--beta", "0"], "--beta"),
        (["--beta", "nan"], "--beta"),
        (["--f1", "-3"], "--f1"),
        (["--eta", "-1"], "--eta"),
        (["--model", "coulomb"], "--model"),
        (["--sweep", "sideways"], "--sweep"),
        (["--method", "fem"], "--method"),
        (["--n", "0"], "--n"),
        (["--mu", "0"], "--mu"),
        (["--workers", "0"], "--workers"),
    ],
)
def test_bad_input_exit2_no_files(argv, word, fake, capsys, tmp_path):
    out = tmp_path / "o"
    rc = main(["frc", *argv, "--out", str(out), "--workers", "1"] if "--workers" not in argv
              else ["frc", *argv, "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2
    assert word in err and len(err.strip().splitlines()) == 1
    assert not out.exists()
    assert fake.calls == []


def test_beta_and_f1_exclusive(capsys):
    with pytest.raises(SystemExit) as e:
        main(["frc", "--beta", "1", "--f1", "3"])
    assert e.value.code == 2
    assert "not allowed with" in capsys.readouterr().err


def test_hb_json_and_files(capsys, tmp_path):
    # the discrete contact: the closed form's history-dependent offsets make
    # its HB residual discontinuous near gamma 1.13 here (see harmonic-balance.md)
    rc = main(["frc", "--method", "hb", "--gamma", "1.1:1.3:0.1", "--eta", "0.5", "--beta", "2",
               "--model", "discrete", "--n", "50",
               "--harmonics", "7", "--samples", "128", "--json", "--out", str(tmp_path)])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["method"] == "hb" and out["status"] == "complete"
    br = out["branches"]
    assert len(br) >= 1
    g = [x for b in br for x in b["gamma"]]
    assert min(g) == pytest.approx(1.1) and max(g) == pytest.approx(1.3)
    for b in br:
        assert len(b["stable"]) == len(b["gamma"]) == len(b["amplitude_q"])
        assert all(isinstance(i, int) and 0 <= i < len(b["gamma"]) for i in b["folds"])
    for name in ("frc.nc", "frc.csv", "frc.png"):
        assert (tmp_path / name).stat().st_size > 0


def test_hb_no_stability_is_said_and_only_then(capsys):
    args = ["frc", "--method", "hb", "--gamma", "1.1:1.3:0.1", "--eta", "0.5", "--beta", "2", "--harmonics", "3",
            "--samples", "32", "--json"]
    out = {}
    for extra in ([], ["--no-stability"]):
        assert main(args + extra) == 0
        out[bool(extra)] = json.loads(capsys.readouterr().out)
    assert out[False]["stability"] == "hill" and any(s for b in out[False]["branches"] for s in b["stable"])
    assert out[True]["stability"] == "not-computed"
    assert not any(s for b in out[True]["branches"] for s in b["stable"])
    assert main(["frc", "--method", "time", "--gamma", "0.9:1.1:0.1", "--no-stability", "--json"]) == 2
    assert "--no-stability applies to --method hb only" in capsys.readouterr().err


def test_scheduler_address(fake, capsys):
    from distributed import LocalCluster

    with LocalCluster(n_workers=1, processes=False, threads_per_worker=2, dashboard_address=None) as lc:
        rc = main(["frc", "--gamma", "0.8:0.9:0.1", "--sweep", "up", "--scheduler", lc.scheduler_address, "--json"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["directions"]["up"]["status"] == ["periodic", "periodic"]
    assert len(fake.calls) == 2  # ran on the cluster's in-process workers


def test_table_prints_distinct_gammas_distinctly(fake, capsys):
    """Points 1e-4 apart near 1.79 used to print as '1.79' three times."""
    rc = main(["frc", "--gamma", "1.79:1.7902:0.0001", "--sweep", "up", "--workers", "1"])
    assert rc == 0
    rows = capsys.readouterr().out.strip().splitlines()[1:]
    assert [r.split()[0] for r in rows] == ["1.79", "1.7901", "1.7902"]


def test_table_digits():
    from jointdyn.commands.frc import _digits

    assert _digits([0.6, 0.61, 1.8]) == 4
    assert _digits([1.79, 1.7901]) == 5
    assert _digits([1.0, 1.0 + 2**-52]) == 17
    assert _digits([1.0, 1.0]) == 4  # equal values need no digits to differ
