"""benchmarks/compare_outputs.py: every number compared bit for bit, renames mapped, labels apart."""

from __future__ import annotations

import importlib.util
import json
from pathlib import Path

import numpy as np
import pytest

_PATH = Path(__file__).resolve().parents[1] / "benchmarks" / "compare_outputs.py"
_spec = importlib.util.spec_from_file_location("compare_outputs", _PATH)
co = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(co)


def _pair(tmp_path, name, old, new, write=lambda p, v: p.write_text(v)):
    (tmp_path / "old").mkdir(exist_ok=True)
    (tmp_path / "new").mkdir(exist_ok=True)
    write(tmp_path / "old" / name, old)
    write(tmp_path / "new" / name, new)
    return co.compare_dirs(tmp_path / "old", tmp_path / "new")


def test_identical_files_and_a_missing_one(tmp_path):
    (tmp_path / "old").mkdir()
    (tmp_path / "new").mkdir()
    (tmp_path / "old" / "a.json").write_text('{"x": 1.5}')
    (tmp_path / "new" / "a.json").write_text('{"x": 1.5}')
    (tmp_path / "old" / "b.json").write_text('{"x": 1.5}')
    (tmp_path / "old" / "a.err").write_text("ignored")
    res = co.compare_dirs(tmp_path / "old", tmp_path / "new")
    assert [(r[0], r[1]) for r in res] == [("a.json", "identical"), ("b.json", "MISSING")]
    assert co.main([str(tmp_path / "old"), str(tmp_path / "new")]) == 1


def test_one_ulp_is_a_numeric_difference(tmp_path):
    x = 0.1
    y = np.nextafter(x, 1.0)
    res = _pair(tmp_path, "a.json", json.dumps({"v": [1.0, x]}), json.dumps({"v": [1.0, float(y)]}))
    assert res[0][1] == "NUMERIC-DIFF"
    assert "1 of 2 differ" in res[0][2]["numeric"][0]


def test_renamed_key_and_hyphenated_label_are_same_numbers(tmp_path):
    old = {"branches": [{"energy_contact_j": [[1e-9], [2e-9]], "status": "not periodic"}], "seconds": 3.0}
    new = {"branches": [{"energy_contact_J": [[1e-9], [2e-9]], "status": "not-periodic"}], "seconds": 9.0,
           "title": "added"}
    (rel, verdict, rep), = _pair(tmp_path, "m.json", json.dumps(old), json.dumps(new))
    assert verdict == "same-numbers"
    assert rep["renamed"] and rep["labels_renamed"] == ["branches[0]/status"]
    assert rep["added"] == ["title"] and rep["timing_skipped"] == ["seconds"]
    assert co.main([str(tmp_path / "old"), str(tmp_path / "new")]) == 0


def test_renamed_value_that_changed_is_caught(tmp_path):
    old = {"energy_contact_j": 1.0}
    new = {"energy_contact_J": 1.0000000000000002, "energy_contact_j": 1.0}
    (_, verdict, rep), = _pair(tmp_path, "m.json", json.dumps(old), json.dumps(new))
    assert verdict == "NUMERIC-DIFF" and rep["numeric"][0].startswith("energy_contact_j")


def test_csv_columns_renamed_and_numbers_as_text(tmp_path):
    res = _pair(tmp_path, "t.csv", "gamma,energy_viscous_j\n0.5,1e-3\n", "gamma,energy_viscous_J,new\n0.5,0.001,7\n")
    assert res[0][1] == "same-numbers"
    res = _pair(tmp_path, "t.csv", "gamma,q\n0.5,2.0\n", "gamma,q\n0.5,2.0000000001\n")
    assert res[0][1] == "NUMERIC-DIFF"


def test_removed_number_is_reported(tmp_path):
    res = _pair(tmp_path, "a.json", '{"x": 1.0, "y": 2.0}', '{"x": 1.0}')
    assert res[0][1] == "REMOVED-NUMBERS"


def test_netcdf_variables_attributes_and_nan(tmp_path):
    import xarray as xr

    def write(path, ds):
        ds.to_netcdf(path)

    def ds(v, legend):
        out = xr.Dataset({"q": ("point", np.array([1.0, np.nan, v]))}, coords={"gamma": ("point", [0.1, 0.2, 0.3])})
        out["status"] = ("point", np.array([0, -1, 0]))
        out["status"].attrs["legend"] = legend
        return out

    res = _pair(tmp_path, "f.nc", ds(3.0, "0: periodic, -1: not computed"), ds(3.0, "0: periodic, -1: not-computed"),
                write)
    assert res[0][1] == "same-numbers" and res[0][2]["labels_renamed"] == ["var:status@legend"]
    res = _pair(tmp_path, "f.nc", ds(3.0, "x"), ds(np.nextafter(3.0, 4.0), "x"), write)
    assert res[0][1] == "NUMERIC-DIFF" and res[0][2]["numeric"][0].startswith("var:q")


def test_checkpoint_folder_matched_without_its_hash(tmp_path):
    for side, key in (("old", "a929becaaaca"), ("new", "60c2c5d96567")):
        d = tmp_path / side / "lines" / f"eta0.5_down_{key}"
        d.mkdir(parents=True)
        np.savez(d / "p000000.npz", q=np.array([1.0, 2.0]))
    (rel, verdict, rep), = co.compare_dirs(tmp_path / "old", tmp_path / "new")
    assert verdict in ("identical", "same-numbers")
    assert rep["matched_by_name_without_hash"] == ["lines/eta0.5_down_60c2c5d96567/p000000.npz"]
    np.savez(tmp_path / "new" / "lines" / "eta0.5_down_60c2c5d96567" / "p000000.npz", q=np.array([1.0, 2.5]))
    assert co.compare_dirs(tmp_path / "old", tmp_path / "new")[0][1] == "NUMERIC-DIFF"
