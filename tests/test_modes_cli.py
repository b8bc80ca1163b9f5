"""``jointdyn modes`` in-process: JSON shape, files, methods, system files, exit
statuses (2 for bad input with no file, 3 for a backbone that stops short)."""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from jointdyn.cli import main
from jointdyn._exit import EXIT_INCOMPLETE
from jointdyn.commands.modes import parse_amplitude

FILES = ("modes.nc", "modes.csv", "modes.png")

SYSTEM_TOML = """
[structure]
M = [[10.0, 0.0], [0.0, 1.0]]
K = [[4.0e5, -1.0e5], [-1.0e5, 1.0e5]]

[[force]]
dof = 0
amplitude = 25.0

[[contact]]
law = "iwan"
kt = 3.0e5
mu = 0.5
tangential = { dof = 0 }
normal = { n0 = 100.0 }

[output]
dof = 0
"""


def test_default_json_and_files(capsys, tmp_path):
    rc = main(["modes", "--json", "--harmonics", "3", "--out", str(tmp_path)])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "complete" and out["method"] == "epmc" and out["mode"] == 1
    br = out["branches"][0]
    a = np.array(br["amplitude_m"])
    assert a.size >= 50 and a[0] == pytest.approx(50 / 3e5 * 1e-2) and a[-1] == pytest.approx(50 / 3e5 * 1e2)
    assert len(br["omega_rad_s"]) == a.size == len(br["damping_ratio"])
    assert br["omega_rad_s"][0] == pytest.approx(np.sqrt(6.9e5 / 10), rel=1e-3)
    for name in FILES:
        assert (tmp_path / name).stat().st_size > 0
    ds = xr.load_dataset(tmp_path / "modes.nc")
    np.testing.assert_allclose(ds.amplitude_m, a)
    assert ds.attrs["status"] == "complete" and ds.attrs["harmonics"] == 3


def test_qsma_table(capsys):
    rc = main(["modes", "--method", "qsma", "--amplitude", "1e-5:1e-3", "--model", "jenkins"])
    assert rc == 0
    text = capsys.readouterr().out
    assert text.startswith("qsma backbone of mode 1 (paper's damper, jenkins): status complete")
    assert len(text.splitlines()) == 2 + 2 * 40 + 1


def test_partial_backbone_exits_3_and_writes_its_status(capsys, tmp_path):
    rc = main(["modes", "--max-points", "5", "--json", "--out", str(tmp_path)])
    assert rc == EXIT_INCOMPLETE == 3
    out = json.loads(capsys.readouterr().out)
    assert out["status"] == "max-points" and len(out["branches"][0]["amplitude_m"]) == 5
    assert xr.load_dataset(tmp_path / "modes.nc").attrs["status"] == "max-points"


def test_system_file(capsys, tmp_path):
    f = tmp_path / "two.toml"
    f.write_text(SYSTEM_TOML)
    rc = main(["modes", "--system", str(f), "--amplitude", "1e-6:1e-3", "--harmonics", "3", "--mode", "2", "--json"])
    assert rc == 0
    out = json.loads(capsys.readouterr().out)
    lam = np.linalg.eigvals(np.linalg.solve(np.diag([10.0, 1.0]), [[7.0e5, -1.0e5], [-1.0e5, 1.0e5]]))
    assert out["omega_linear_rad_s"] == pytest.approx(np.sqrt(max(lam.real)), rel=1e-12)
    assert out["system"] == "two.toml" and out["status"] == "complete"


@pytest.mark.parametrize("argv, word", [
    (["--amplitude", "1e-3:1e-4"], "--amplitude MAX must be > MIN"),
    (["--amplitude", "1e-3"], "--amplitude must be MIN:MAX"),
    (["--amplitude", "a:b"], "--amplitude must be MIN:MAX of numbers"),
    (["--mode", "0"], "--mode must be an integer >= 1"),
    (["--mode", "2"], r"--mode must be in [1, 1]"),
    (["--method", "foo"], "--method must be one of epmc, qsma"),
    (["--method", "qsma", "--harmonics", "3"], "--harmonics applies to --method epmc only"),
    (["--harmonics", "0"], "--harmonics must be an integer >= 1"),
    (["--samples", "8"], "--samples must be an integer >= 16"),
    (["--max-points", "1"], "--max-points must be an integer >= 2"),
    (["--model", "nope"], "--model must be one of"),
    (["--law-param", "capacity=1"], "capacity"),
    (["--output-dof", "3"], r"--output-dof must be in [0, 0]"),
    (["--system", "/nonexistent.toml"], "--system must be an existing file"),
])
def test_bad_input_exit2_no_files(argv, word, capsys, tmp_path):
    out = tmp_path / "o"
    rc = main(["modes", *argv, "--out", str(out)])
    assert rc == 2
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1 and word in err
    assert not out.exists()


def test_system_file_with_a_prescribed_harmonic_load_is_refused(capsys, tmp_path):
    f = tmp_path / "h.toml"
    f.write_text(SYSTEM_TOML.replace("normal = { n0 = 100.0 }", "normal = { n0 = 100.0, n1 = 50.0, phase_deg = 0.0 }"))
    rc = main(["modes", "--system", str(f), "--out", str(tmp_path / "o")])
    assert rc == 2
    err = capsys.readouterr().err
    assert "contact 0: its normal load is a harmonic load with n1 = 50 N, prescribed at a forcing frequency" in err
    assert not (tmp_path / "o").exists()
    with pytest.raises(SystemExit):
        main(["modes", "--system", str(f), "--model", "iwan", "--json", "--mode"])
    rc = main(["modes", "--system", str(f), "--model", "iwan"])
    assert rc == 2 and "cannot be combined with --system" in capsys.readouterr().err


def test_parse_amplitude():
    assert parse_amplitude("1e-6:2.5e-3") == (1e-6, 2.5e-3)
