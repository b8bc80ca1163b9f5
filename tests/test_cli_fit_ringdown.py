"""``jointdyn fit --ringdown``: a free decay in a CSV file to a backbone (written with the
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


def _decay(path, per=64, periods=150, zeta=0.0025, column="x", steady=False):
    t = np.arange(0.0, periods * T0, T0 / per)
    env = np.ones(t.size) if steady else np.exp(-zeta * W0 * t)
    y = 1e-4 * env * np.cos(W0 * math.sqrt(1 - zeta * zeta) * t)
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
    # the written backbone, fitted with --backbone, gives the same result
    assert main(["fit", "--backbone", str(out / "ringdown_backbone.csv"), "--model", "iwan", "--mass", "2",
                 "--json"]) == 3
    again = json.loads(capsys.readouterr().out)
    assert again["determined_combinations"]["k_plus_kt"]["value"] == pytest.approx(
        d["determined_combinations"]["k_plus_kt"]["value"], rel=1e-9)


@pytest.mark.parametrize("kw,word", [
    (dict(periods=8), "shorter than"),
    (dict(per=6), "aliased"),
    (dict(steady=True), "no decay"),
    (dict(column="displacement"), "exactly one of x"),
])
def test_bad_ringdowns_one_line_exit_2_no_file(tmp_path, capsys, kw, word):
    src = _decay(tmp_path / "decay.csv", **kw)
    out = tmp_path / "out"
    rc = main(["fit", "--ringdown", str(src), "--model", "iwan", "--mass", "2", "--out", str(out)])
    err = capsys.readouterr().err
    assert rc == 2 and word in err and len(err.strip().splitlines()) == 1 and "--ringdown" in err
    assert not out.exists()
