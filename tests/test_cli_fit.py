"""``jointdyn fit``: loops and backbones from CSV files, JSON keys, files, exit statuses."""

from __future__ import annotations

import json

import numpy as np
import pytest

import jointdyn as jd
from jointdyn.cli import main
from jointdyn.identify.backbone import _model

KT, MU, NREF = 1e5, 0.1, 100.0


def _loops_csv(path, model="segalman", amp=(0.05, 1.5), noise=0.01, **lp):
    law = jd.make_law(model, kt=KT, mu=MU, n_ref=NREF, **lp)
    t = np.linspace(0.0, 4.0, 4001)
    x = law.x_slip * np.sin(2 * np.pi * t) * np.interp(t, [0.0, 4.0], amp)
    N = NREF * (1.0 + 0.5 * np.sin(2 * np.pi * t + 0.9))
    T = jd.march(law, x, N)[0]
    T = T + noise * np.abs(T).max() * np.random.default_rng(0).normal(size=t.size)
    np.savetxt(path, np.column_stack([t, x, N, T]), delimiter=",", header="t,x,N,T", comments="")
    return path


def test_loop_fit_json_and_files(tmp_path, capsys):
    src = _loops_csv(tmp_path / "loops.csv", chi=-0.6, beta=0.3)
    out = tmp_path / "out"
    rc = main(["fit", "--input", str(src), "--model", "segalman", "--json", "--out", str(out)])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    assert d["status"] == "identified"
    for key in ("kt", "fy_N", "mu", "chi", "beta"):
        assert key in d["parameters"] and key in d["standard_errors"]
    assert d["parameters"]["kt"] == pytest.approx(KT, rel=0.02)
    assert d["parameters"]["mu"] == pytest.approx(MU, rel=0.02)
    assert d["parameters"]["chi"] == pytest.approx(-0.6, abs=0.03)
    assert d["rms_residual"] > 0.0
    assert {p.name for p in out.iterdir()} == {"fit.json", "fit.csv", "fit.png"}
    assert json.loads((out / "fit.json").read_text())["parameters"] == d["parameters"]
    head = (out / "fit.csv").read_text().splitlines()[0]
    assert head == "x,N,T,t,T_fit"


def test_backbone_fit(tmp_path, capsys):
    law = jd.make_law("iwan", kt=KT, mu=MU, n_ref=NREF)
    A = np.geomspace(0.03, 30.0, 50) * law.x_slip
    w, D = _model(law, 4e5, 0.002, 2.0, A)
    src = tmp_path / "bb.csv"
    np.savetxt(src, np.column_stack([A, w, D]), delimiter=",", header="amplitude_m,omega_rad_s,damping_ratio",
               comments="")
    rc = main(["fit", "--backbone", str(src), "--model", "iwan", "--mass", "2.0", "--json"])
    assert rc == 0
    d = json.loads(capsys.readouterr().out)
    assert d["parameters"]["kt"] == pytest.approx(KT, rel=1e-6)
    assert d["parameters"]["fy_N"] == pytest.approx(MU * NREF, rel=1e-6)
    assert "mu" not in d["parameters"]


def test_a_fit_that_does_not_determine_mu_exits_3_with_its_files(tmp_path, capsys):
    src = _loops_csv(tmp_path / "loops.csv", model="jenkins", amp=(0.2, 0.2))
    out = tmp_path / "out"
    rc = main(["fit", "--input", str(src), "--model", "jenkins", "--json", "--out", str(out)])
    assert rc == 3
    d = json.loads(capsys.readouterr().out)
    assert d["status"] == "partly-identified" and d["parameters"]["mu"] is None
    assert "never slip" in d["not_identifiable"]["mu"]
    assert (out / "fit.json").is_file()


@pytest.mark.parametrize("content,extra,word", [
    ("t,x,N\n0,0,1\n1,1,1\n2,0,1\n3,1,1\n", [], "missing column T"),
    ("t,x,N,T\n0,0,1,0\n1,abc,1,1\n2,0,1,0\n3,1,1,1\n", [], "line 3"),
    ("t,x,N,T\n0,0,1,0\n1,1,1,1\n", [], "at least 10 samples"),
    ("t,x,N,T\n0,0,1,0\n0,1,1,1\n" + "".join(f"{i},{i % 2},1,{i % 2}\n" for i in range(2, 12)), [],
     "line 3: t must be strictly increasing"),
    (None, ["--mass", "2"], "--mass applies"),
])
def test_bad_input_one_line_exit_2_no_file(tmp_path, capsys, content, extra, word):
    src = tmp_path / "loops.csv"
    if content is None:
        _loops_csv(src, model="iwan")
    else:
        src.write_text(content)
    out = tmp_path / "out"
    rc = main(["fit", "--input", str(src), "--model", "iwan", "--out", str(out), *extra])
    err = capsys.readouterr().err
    assert rc == 2 and word in err and len(err.strip().splitlines()) == 1
    assert not out.exists()


def test_backbone_needs_the_mass(tmp_path, capsys):
    src = tmp_path / "bb.csv"
    src.write_text("amplitude_m,omega_rad_s,damping_ratio\n1e-5,100,0.01\n2e-5,99,0.01\n3e-5,98,0.02\n4e-5,97,0.02\n")
    assert main(["fit", "--backbone", str(src), "--model", "iwan"]) == 2
    assert "--mass is required" in capsys.readouterr().err
