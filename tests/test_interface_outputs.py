"""Per-pair results of systems with interfaces in the command line's files and JSON: `jointdyn frc --method
hb --system` and `jointdyn modes --system` write every node pair's energy per cycle and stick / slip / open
fractions per point (netCDF, dims point x pair, with units), the total per point in the CSV, and both in
the JSON; the numbers are those of the solvers' own results."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import xarray as xr

from jointdyn.cli import main

from test_sweep_interfaces import SYSTEM


def _files(out, stem):
    ds = xr.load_dataset(out / f"{stem}.nc")
    return ds, pd.read_csv(out / f"{stem}.csv")


def _check_pairs(ds, table, one, npoints):
    assert ds.pair_energy_J.dims == ("point", "pair") and ds.sizes["pair"] == 2
    assert ds.pair_energy_J.attrs["units"] == "J" and ds.energy_interface_J.attrs["units"] == "J"
    for k in ("stick", "slip", "open"):
        assert ds[f"pair_{k}_fraction"].attrs["units"] == "1"
    frac = sum(ds[f"pair_{k}_fraction"].values for k in ("stick", "slip", "open"))
    np.testing.assert_allclose(frac, 1.0, rtol=0, atol=1e-12)
    np.testing.assert_allclose(ds.energy_interface_J.values, ds.pair_energy_J.values.sum(axis=1), rtol=1e-12)
    np.testing.assert_allclose(table.energy_interface_J.values, ds.energy_interface_J.values, rtol=1e-12)
    assert len(one["energy_interface_J"]) == npoints
    np.testing.assert_allclose(np.array(one["pairs"]["energy_J"]).sum(axis=1), one["energy_interface_J"], rtol=1e-12)
    assert np.max(ds.pair_slip_fraction.values) > 0.0 and np.max(ds.energy_interface_J.values) > 0.0


def test_hb_branch_files_and_json_carry_the_pairs(tmp_path, capsys):
    p = tmp_path / "sys.toml"
    p.write_text(SYSTEM)
    out = tmp_path / "hb"
    rc = main(["frc", "--method", "hb", "--system", str(p), "--gamma", "0.8:1.2:0.1", "--harmonics", "3",
               "--samples", "32", "--json", "--out", str(out)])
    res = json.loads(capsys.readouterr().out)
    assert rc == 0 and res["status"] == "complete"
    ds, table = _files(out, "frc")
    (one,) = res["branches"]
    _check_pairs(ds, table, one, ds.sizes["point"])
    np.testing.assert_allclose(one["pairs"]["energy_J"], ds.pair_energy_J.values, rtol=1e-12)
    np.testing.assert_allclose(one["pairs"]["open_fraction"], ds.pair_open_fraction.values, rtol=0, atol=0)


def test_modes_files_and_json_carry_the_pairs(tmp_path, capsys):
    from jointdyn.files import read_system_file
    from jointdyn.modes import epmc

    p = tmp_path / "sys.toml"
    p.write_text(SYSTEM)
    out = tmp_path / "modes"
    rc = main(["modes", "--system", str(p), "--harmonics", "3", "--samples", "32", "--amplitude", "1e-6:1e-3",
               "--json", "--out", str(out)])
    res = json.loads(capsys.readouterr().out)
    assert rc == 0 and res["status"] == "complete"
    ds, table = _files(out, "modes")
    (one,) = res["branches"]
    _check_pairs(ds, table, one, ds.sizes["point"])
    # the same backbone by the API: its pair energies, and the fractions of its last point's evaluation
    bb = epmc(read_system_file(p).system, (1e-6, 1e-3), harmonics=3, samples=32, progress=False)
    np.testing.assert_allclose(ds.pair_energy_J.values, bb.pair_energy_J, rtol=1e-12, atol=0)
    q = bb.problem
    last = q.hb.pair_results(bb.X[-1], q.evaluate(bb.X[-1], bb.omega_rad_s[-1]))
    np.testing.assert_array_equal(ds.pair_slip_fraction.values[-1], last["slip"])
    # large amplitude: the pairs slip for part of the period; small: they stick throughout
    assert 0.0 < last["slip"].max() and ds.pair_stick_fraction.values[0].min() == 1.0
