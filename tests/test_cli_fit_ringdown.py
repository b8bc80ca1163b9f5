"""``jointdyn fit --ringdown`` and ``--frc``: a free decay in a CSV file to a backbone (written with the
``--backbone`` columns) to a fitted model; bad ring-downs refused with one line, exit 2, no
file."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from jointdyn.cli import main

W0 = 500.0
T0 = 2.0 * math.pi / W0


def _decay(path, per=64, periods=150, zeta=0.0025, column="x", steady=False, two=False):
    t = np.arange(0.0, periods * T0, T0 / per)
    env = np.ones(t.size) if steady else np.exp(-zeta * W0 * t)
    y = 1e-4 * env * np.cos(W0 * math.sqrt(1 - zeta * zeta) * t)
    if two:  # a second mode 8 % above the first, as strong: both in one band
        y = y + 1e-4 * np.exp(-zeta * 1.08 * W0 * t) * np.cos(1.08 * W0 * t)
    np.savetxt(path, np.column_stack([t, y]), delimiter=",", header=f"t,{column}", comments="")
    return path


def test_a_linear_ringdown_is_written_as_a_backbone_and_fitted(tmp_path, capsys):
    src = _decay(tmp_path / "decay.csv")
    out = tmp_path / "out"
    rc = main(["fit", "--ringdown", str(src), "--model", "iwan", "--mass", "2", "--json", "--out", str(out)])
    d = json.loads(capsys.readouterr().out)
    # a linear decay never slips: the fit names what it cannot determine (exit 3)
    assert rc == 3 and d["status"] == "partly-identified"
    assert d["determined_combinations"]["k_plus_kt"]["value"] == pytest.approx(2.0 * W0 ** 2, rel=1e-3)
    assert d["determined_combinations"]["zeta"]["value"] == pytest.approx(0.0025, rel=0.01)
    bb = (out / "ringdown_backbone.csv").read_text().splitlines()
    assert bb[0] == "amplitude_m,omega_rad_s,damping_ratio" and len(bb) > 10
    # a noise-free linear decay determines its damping ratio everywhere: no point trimmed
    rng = d["damping_range"]
    assert rng["points"] == len(bb) - 1 and rng["trimmed_top"] == rng["trimmed_bottom"] == 0
    # --ringdown fits the decay's windows (fit_ringdown), and says so; the written backbone,
    # fitted with --backbone, gives the same stiffness (measured 2.4e-9 apart) and its own
    # narrower interval (its points come from one smooth model)
    assert "windows" in d["message"]
    assert main(["fit", "--backbone", str(out / "ringdown_backbone.csv"), "--model", "iwan", "--mass", "2",
                 "--json"]) == 3
    again = json.loads(capsys.readouterr().out)
    assert again["determined_combinations"]["k_plus_kt"]["value"] == pytest.approx(
        d["determined_combinations"]["k_plus_kt"]["value"], rel=1e-6)


def test_a_ringdown_through_macroslip_says_and_writes_its_damping_range(tmp_path, capsys):
    """The Iwan oscillator released from 5 slip displacements with 1 % noise (seed 0, as
    tests/test_identify_ringdown.py): the fit determines the damping ratio within 5 % over part of
    the decay only; the JSON says which, the console prints it, fit.csv marks the points and
    ringdown_backbone.csv holds those of the range."""
    from test_identify_ringdown import _decay as decay
    from test_identify_ringdown import _sdof

    system, law = _sdof("iwan")
    t, x = decay(system, law, [5.0 * law.x_slip], 0, math.sqrt(5e5 / 2.0), 150, 64)
    src = tmp_path / "decay.csv"
    np.savetxt(src, np.column_stack([t, x]), delimiter=",", header="t,x", comments="")
    out = tmp_path / "out"
    base = ["fit", "--ringdown", str(src), "--model", "iwan", "--mass", "2", "--band",
            f"{300 / (2 * math.pi)}:{750 / (2 * math.pi)}", "--out", str(out)]
    assert main(base) == 3
    text = capsys.readouterr().out
    assert "damping range: determined within +-5 % (95 %)" in text
    d = json.loads((out / "fit.json").read_text())
    rng = d["damping_range"]
    assert rng["points"] >= 2 and rng["trimmed_top"] + rng["trimmed_bottom"] > 0
    assert rng["points"] + rng["trimmed_top"] + rng["trimmed_bottom"] == len(rng["determined"])
    rows = np.loadtxt(out / "ringdown_backbone.csv", delimiter=",", skiprows=1, ndmin=2)
    assert rows.shape[0] == rng["points"]
    assert rows[:, 0].max() == pytest.approx(rng["amplitude_high_m"], rel=1e-12)
    assert rows[:, 0].min() == pytest.approx(rng["amplitude_low_m"], rel=1e-12)
    header = (out / "fit.csv").read_text().splitlines()[0].split(",")
    assert "damping_determined" in header


@pytest.mark.parametrize("kw,word", [
    (dict(periods=8), "shorter than"),
    (dict(per=6), "aliased"),
    (dict(steady=True), "no decay"),
    (dict(two=True), "two modes in the band"),
    (dict(column="displacement"), "exactly one of x"),
])
def test_bad_ringdowns_one_line_exit_2_no_file(tmp_path, capsys, kw, word):
    src = _decay(tmp_path / "decay.csv", **kw)
    out = tmp_path / "out"
    rc = main(["fit", "--ringdown", str(src), "--model", "iwan", "--mass", "2", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and word in err and len(err.strip().splitlines()) == 1 and "--ringdown" in err
    assert not out.exists()


def test_band_picks_one_mode_of_two_and_bad_bands_are_refused(tmp_path, capsys):
    """Two modes 8 % apart: refused without --band (the message names it), fitted with a band around the
    first (Hz); a bad band is one line naming --band, exit 2, no file."""
    src = _decay(tmp_path / "decay.csv", two=True)
    base = ["fit", "--ringdown", str(src), "--model", "iwan", "--mass", "2"]
    assert main(base) == 2
    assert "--band LOW:HIGH" in capsys.readouterr().err
    hz = W0 / (2.0 * math.pi)
    rc = main(base + ["--band", f"{0.93 * hz}:{1.03 * hz}", "--json"])
    d = json.loads(capsys.readouterr().out)
    assert rc == 3 and d["determined_combinations"]["k_plus_kt"]["value"] == pytest.approx(2.0 * W0 ** 2, rel=1e-2)
    out = tmp_path / "out"
    for band, word in (("80", "LOW:HIGH"), ("90:80", "HIGH must be > LOW"), ("-1:80", "--band LOW"),
                       ("a:b", "numbers")):
        assert main(base + [f"--band={band}", "--out", str(out)]) == 2
        err = capsys.readouterr().err
        assert word in err and "--band" in err and len(err.strip().splitlines()) == 1 and not out.exists()
    loops = tmp_path / "loops.csv"
    loops.write_text("t,x,N,T\n0,0,1,0\n1,1,1,1\n2,0,1,0\n3,-1,1,-1\n")
    assert main(["fit", "--input", str(loops), "--band", "70:80"]) == 2
    assert "--band applies to ring-down fits" in capsys.readouterr().err


def _curves(path, levels=(5.0, 15.0, 30.0), n=50):
    import jointdyn as jd
    from jointdyn.hb import frc_hb

    law = jd.make_law("iwan", kt=1e5, mu=0.2, n_ref=100.0)
    rows = []
    for F in levels:
        s = jd.System.sdof(m=2.0, k=4e5, law=law, f1=F, c=2 * 0.002 * math.sqrt(5e5 * 2.0), n0=100.0)
        ds = frc_hb(s, 0.85, 1.1, harmonics=1)
        g, A = np.asarray(ds["gamma"]), np.asarray(ds["amplitude_m"])
        pick = np.linspace(0, g.size - 1, n).astype(int)
        rows.append(np.column_stack([np.full(n, F), g[pick] * s.w0, A[pick]]))
    np.savetxt(path, np.concatenate(rows), delimiter=",", header="force_N,omega_rad_s,amplitude_m", comments="")
    return path


def test_response_curves_from_a_file_are_fitted(tmp_path, capsys):
    """``jointdyn fit --frc``: the plumbing (the accuracy is tests/test_identify_frc.py's): curves
    made by HB without noise give the parameters to 1 %, the files are written."""
    src = _curves(tmp_path / "curves.csv")
    out = tmp_path / "out"
    rc = main(["fit", "--frc", str(src), "--model", "iwan", "--mass", "2", "--json", "--out", str(out)])
    d = json.loads(capsys.readouterr().out)
    assert rc == 0 and d["kind"] == "frc" and d["status"] == "identified"
    for name, true in (("k", 4e5), ("kt", 1e5), ("fy_N", 20.0), ("zeta", 0.002)):
        assert d["parameters"][name] == pytest.approx(true, rel=0.01), name
    assert {p.name for p in out.iterdir()} == {"fit.json", "fit.csv", "fit.png"}


@pytest.mark.parametrize("content,extra,word", [
    ("force_N,omega_rad_s\n1,2\n1,3\n1,4\n1,5\n", ["--mass", "2"], "missing column amplitude_m"),
    ("force_N,omega_rad_s,amplitude_m\n1,2,3\n1,3,3\n1,4,3\n1,5,3\n1,6,3\n1,7,3\n", [], "--mass is required with --frc"),
])
def test_bad_response_curves_one_line_exit_2(tmp_path, capsys, content, extra, word):
    src = tmp_path / "curves.csv"
    src.write_text(content)
    rc = main(["fit", "--frc", str(src), "--model", "iwan", *extra])
    err = capsys.readouterr().err
    assert rc == 2 and word in err and len(err.strip().splitlines()) == 1
