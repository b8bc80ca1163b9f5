"""What ``jointdyn frc --system`` shows of a structure of your own: the
amplitude of its output DOFs in mm (table and frc.png), not q of the first
contact; the file's ``title`` in frc.nc, frc.png and the JSON; titles that
wrap instead of running off the picture.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
import xarray as xr

from jointdyn import hb  # noqa: F401 - a plain import: a broken package fails here, never skips
from jointdyn.commands import _frc_report as report
from jointdyn.commands import frc as frc_cmd
from test_cli_system import SYSTEM, _cli


@pytest.fixture
def system_file(tmp_path):
    p = tmp_path / "joint.toml"
    p.write_text(SYSTEM)
    return p


def _table_rows(stdout: str) -> list[list[str]]:
    return [line.split() for line in stdout.splitlines()]


def test_time_table_in_mm_and_title_in_every_output(system_file, capsys, tmp_path):
    out = tmp_path / "run"
    argv = ["frc", "--system", str(system_file), "--gamma", "0.9:1.1:0.1", "--workers", "1", "--out", str(out)]
    rc, stdout, _ = _cli(capsys, [*argv, "--json"])
    assert rc == 0
    res = json.loads(stdout)
    rc, table, _ = _cli(capsys, argv)  # resumed from --out: every point reused
    assert rc == 0
    rows = _table_rows(table)
    assert table.splitlines()[0] == "two masses on a joint: amplitude (half peak-to-peak) of DOF 1, 0, mm"
    assert rows[1] == ["gamma", "x1_up", "x0_up", "status", "x1_down", "x0_down", "status"]
    for i, row in enumerate(rows[2:5]):
        up = res["directions"]["up"]
        assert float(row[1]) == pytest.approx(1e3 * up["amplitude_m"][i], rel=1e-4)
        assert float(row[2]) == pytest.approx(1e3 * up["dofs"]["0"]["amplitude_m"][i], rel=1e-4)
        assert row[3] == "periodic"
    # not q = kt X / fy of the contact (about 10 here, against amplitudes of a fraction of a mm)
    assert float(rows[2][1]) != pytest.approx(res["directions"]["up"]["amplitude_q"][0], rel=1e-2)
    with xr.open_dataset(out / "frc.nc", engine="scipy") as ds:
        assert ds.attrs["title"] == "two masses on a joint"
        assert ds.attrs["summary"].startswith("steady-state frequency response")


def test_hb_outputs_each_output_dof(system_file, capsys, tmp_path):
    argv = ["frc", "--method", "hb", "--system", str(system_file), "--gamma", "0.9:1.0:0.1", "--harmonics", "5",
            "--samples", "128"]
    rc, stdout, _ = _cli(capsys, [*argv, "--json", "--out", str(tmp_path / "hb")])
    assert rc == 0
    res = json.loads(stdout)
    first = res["branches"][0]
    assert set(first["dofs"]) == {"0", "1"}
    assert first["dofs"]["1"]["amplitude_m"] == first["amplitude_m"]  # the output DOF, as before
    assert len(first["dofs"]["0"]["amplitude_m"]) == len(first["gamma"])
    assert all(a > 0 for a in first["dofs"]["0"]["amplitude_m"])
    with xr.open_dataset(tmp_path / "hb" / "frc.nc", engine="scipy") as ds:
        assert ds.attrs["title"] == "two masses on a joint"
    rc, table, _ = _cli(capsys, argv)
    assert rc == 0
    lines = table.splitlines()
    assert lines[0].endswith("of DOF 1, 0, mm") and lines[3].split() == ["gamma", "x1", "x0"]
    first_point = lines[4].split()
    assert float(first_point[1]) == pytest.approx(1e3 * first["amplitude_m"][0], rel=1e-4)
    assert float(first_point[2]) == pytest.approx(1e3 * first["dofs"]["0"]["amplitude_m"][0], rel=1e-4)


def test_plot_shows_mm_of_the_output_dof_for_a_system_and_q_for_the_paper():
    sysd = {"title": "t", "file": "t.toml", "response_dof": 2, "dofs": [0, 2], "w0_rad_s": 1.0}
    r = {"amplitude_q": [5.0, None], "amplitude_m": [1e-3, 2e-3], "dofs": {"0": {"amplitude_m": [3e-3, None]}}}
    system = {"method": "time", "system": sysd}
    np.testing.assert_array_equal(report.y_values(r, system), [1.0, 2.0])
    np.testing.assert_array_equal(report.dof_mm(r, system, 0), [3.0, np.nan])
    assert report.output_dofs(system) == [2, 0]
    assert report.y_label(system) == "amplitude of the output DOFs, mm (half peak-to-peak)"
    assert report.curve_label(system, "sweep up") == "DOF 2, sweep up"
    alone = {"method": "time", "system": {**sysd, "dofs": [2]}}
    assert report.y_label(alone) == "amplitude of DOF 2, mm (half peak-to-peak)"
    assert report.curve_label(alone, "sweep up") == "sweep up"
    paper = {"method": "time", "eta": 0.5}
    np.testing.assert_array_equal(report.y_values(r, paper), [5.0, np.nan])
    assert "q = kt x / fy" in report.y_label(paper) and report.output_dofs(paper) == []
    assert report.peak_value({"amplitude_m": 1e-3, "amplitude_q": 7.0}, system) == pytest.approx(1.0)
    assert report.peak_value({"amplitude_m": 1e-3, "amplitude_q": 7.0}, paper) == 7.0


def test_long_titles_wrap():
    sysd = {"title": "a blade with a wedge damper under its platform, preload 20 N, " * 3,
            "file": "/a/long/path/blade_with_a_wedge_damper.toml", "response_dof": 2, "w0_rad_s": 1234.5}
    title = frc_cmd._plot_title({"method": "time", "system": sysd})
    lines = title.split("\n")
    assert len(lines) > 2 and all(len(line) <= report.TITLE_WIDTH for line in lines)
    assert " ".join(lines).split() == frc_cmd._title_text({"method": "time", "system": sysd}).split()


def test_modes_carries_the_file_title(capsys, tmp_path, monkeypatch):
    from test_modes_cli import SYSTEM_TOML

    from jointdyn.commands import modes as modes_cmd

    f = tmp_path / "two.toml"
    f.write_text('title = "two masses, the first on a joint"\n' + SYSTEM_TOML)
    titles = []
    plot = modes_cmd._plot
    monkeypatch.setattr(modes_cmd, "_plot", lambda ds, title, path: (titles.append(title), plot(ds, title, path)))
    rc, stdout, _ = _cli(capsys, ["modes", "--method", "qsma", "--system", str(f), "--amplitude", "1e-6:1e-4",
                                  "--json", "--out", str(tmp_path / "m")])
    assert rc == 0
    res = json.loads(stdout)
    assert res["title"] == "two masses, the first on a joint" and res["system"] == "two.toml"
    with xr.open_dataset(tmp_path / "m" / "modes.nc", engine="scipy") as ds:
        assert ds.attrs["title"] == "two masses, the first on a joint"
    assert titles == ["two masses, the first on a joint (two.toml)"]
    assert (tmp_path / "m" / "modes.png").stat().st_size > 0
