"""Sweeps of systems with interfaces (docs/model.md section 10): every node pair's energy per period and
stick / slip / open fractions per point in the sweep's Dataset and its CSV table, the same serially, in a
local process pool and on Dask, and the same numbers as the steady state of a single point."""

from __future__ import annotations

import numpy as np
import xarray as xr

import jointdyn as jd
from jointdyn.interfaces import Interface
from jointdyn.sweeps import SweepOptions, frc_sweep, to_frame

M4 = np.diag([1.0, 1.0, 1.0, 2.0])
K4 = np.diag([1e3, 1.2e3, 2e3, 4e3])
K4[0, 3] = K4[3, 0] = -200.0
GAMMAS = [0.8, 1.0, 1.2]


def _system(mu=0.5):
    """Two pairs with 2-D slip (forcing in two directions, 90 degrees apart); the second pair's normal
    load follows the motion of DOF 2."""
    itf = Interface(kt=[1.5e3, 800.0], kn=[1.5e3, 3e3], mu=mu, preload=[0.5, 0.2],
                    pairs=[[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]])
    return jd.System(M=M4, C=0.01 * K4, K=K4, force=[0.5, 0.25, 0.0, 0.0], force_phase_deg=[0.0, 90.0, 0.0, 0.0],
                     interfaces=(itf,))


def test_pair_results_per_point_with_units_and_in_the_table():
    s = _system()
    ds = frc_sweep(s, GAMMAS, directions=("up",), n_workers=1, progress=False)
    assert (ds.status.values == 0).all()
    for name in ("pair_energy_J", "pair_stick_fraction", "pair_slip_fraction", "pair_open_fraction"):
        assert ds[name].dims == ("direction", "gamma", "pair") and ds.sizes["pair"] == 2
        assert ds[name].attrs["units"] == ("J" if name.endswith("_J") else "1")
    frac = sum(ds[f"pair_{k}_fraction"] for k in ("stick", "slip", "open"))
    np.testing.assert_allclose(frac.values, 1.0, rtol=0, atol=1e-12)
    # no scalar contacts: the pairs are all the contact dissipation, and they slip
    np.testing.assert_allclose(ds.pair_energy_J.sum("pair").values, ds.energy_contact_J.values, rtol=1e-12)
    assert (ds.pair_slip_fraction.values > 0.0).all() and (ds.pair_energy_J.values > 0.0).all()
    # the first point of the line is solved cold, as a single steady state
    r = jd.steady_state(s, GAMMAS[0])
    one = ds.sel(direction="up", gamma=GAMMAS[0])
    np.testing.assert_array_equal(one.pair_energy_J.values, r.pair_energy_J)
    np.testing.assert_array_equal(one.pair_slip_fraction.values, r.pair_slip)
    np.testing.assert_array_equal(one.pair_open_fraction.values, r.pair_open)
    table = to_frame(ds)
    for p in (0, 1):
        np.testing.assert_array_equal(table[f"pair_energy_J_p{p}"].values, ds.pair_energy_J.values[0, :, p])
        assert f"pair_stick_fraction_p{p}" in table


def test_systems_without_interfaces_get_no_pair_dimension():
    law = jd.make_law("jenkins", kt=1e3, mu=0.3, n_ref=1.0)
    s = jd.System(M=M4, C=0.01 * K4, K=K4, contacts=(jd.Contact(law, dof=3, normal=jd.ConstantLoad(1.0)),),
                  force=[0.5, 0.0, 0.0, 0.0])
    ds = frc_sweep(s, [1.0], directions=("up",), n_workers=1, progress=False)
    assert "pair" not in ds.dims and "pair_energy_J" not in ds


def test_family_with_and_without_interfaces_pool_and_dask_equal_serial():
    """A family of Systems with different numbers of pairs (the narrower padded with NaN): serial ==
    local process pool == Dask (2 workers), with chunks of 2 points continuing across workers."""
    from distributed import Client, LocalCluster

    one_pair = _system()
    itf = one_pair.interfaces[0]
    narrow = Interface(kt=itf.kt[:1], kn=itf.kn[:1], mu=itf.mu[:1], preload=itf.preload[:1], pairs=itf.pairs[:1])
    family = {"two pairs": one_pair, "one pair": jd.System(M=M4, C=0.01 * K4, K=K4, force=one_pair.force,
                                                           force_phase_deg=one_pair.force_phase_deg,
                                                           interfaces=(narrow,))}
    kw = dict(progress=False, directions=("up",))
    serial = frc_sweep(family, GAMMAS, **kw, n_workers=1)
    assert serial.pair_energy_J.dims == ("system", "direction", "gamma", "pair")
    assert np.isnan(serial.pair_energy_J.sel(system="one pair", pair=1)).all()
    assert np.isfinite(serial.pair_energy_J.sel(system="one pair", pair=0)).all()
    pooled = frc_sweep(family, GAMMAS, **kw, options=SweepOptions(chunk_points=2), n_workers=2)
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            dist = frc_sweep(family, GAMMAS, **kw, options=SweepOptions(chunk_points=2), client=client)
    xr.testing.assert_identical(serial, pooled)
    xr.testing.assert_identical(serial, dist)


def test_resumed_sweep_keeps_the_pair_results(tmp_path, monkeypatch):
    kw = dict(options=SweepOptions(chunk_points=2), directions=("up",), n_workers=1, progress=False, out=tmp_path)
    full = frc_sweep(_system(), GAMMAS, **kw)
    again = frc_sweep(_system(), GAMMAS, **kw)
    assert again.attrs["reused_points"] == len(GAMMAS)
    xr.testing.assert_identical(again.pair_energy_J, full.pair_energy_J)
    xr.testing.assert_identical(again.pair_open_fraction, full.pair_open_fraction)


def test_command_line_time_sweep_writes_the_pairs(tmp_path, capsys):
    import json

    from jointdyn.cli import main

    p = tmp_path / "sys.toml"
    p.write_text(SYSTEM)
    out = tmp_path / "out"
    rc = main(["frc", "--system", str(p), "--gamma", "0.9:1.1:0.1", "--sweep", "up", "--json", "--out", str(out)])
    res = json.loads(capsys.readouterr().out)
    assert rc == 0
    up = res["directions"]["up"]
    ds = xr.open_dataset(out / "frc.nc")
    pe = ds.pair_energy_J.sel(direction="up").values
    assert ds.pair_energy_J.attrs["units"] == "J" and pe.shape == (3, 2)
    np.testing.assert_allclose(up["energy_interface_J"], pe.sum(axis=1), rtol=1e-12)
    np.testing.assert_allclose(up["pairs"]["energy_J"], pe, rtol=1e-12)
    for k in ("stick", "slip", "open"):
        np.testing.assert_allclose(up["pairs"][f"{k}_fraction"], ds[f"pair_{k}_fraction"].sel(direction="up").values)
    ds.close()
    import pandas as pd

    table = pd.read_csv(out / "frc.csv")
    assert {"pair_energy_J_p0", "pair_slip_fraction_p1", "pair_open_fraction_p0"} <= set(table.columns)


SYSTEM = """\
[structure]
M = [[1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 1.0, 0.0], [0.0, 0.0, 0.0, 2.0]]
K = [[1e3, 0.0, 0.0, -200.0], [0.0, 1.2e3, 0.0, 0.0], [0.0, 0.0, 2e3, 0.0], [-200.0, 0.0, 0.0, 4e3]]
C = [[10.0, 0.0, 0.0, -2.0], [0.0, 12.0, 0.0, 0.0], [0.0, 0.0, 20.0, 0.0], [-2.0, 0.0, 0.0, 40.0]]

[[force]]
dof = 0
amplitude = 0.5

[[force]]
dof = 1
amplitude = 0.25
phase_deg = 90.0

[[interface]]
kt = [1.5e3, 800.0]
kn = [1.5e3, 3e3]
mu = 0.5
preload = [0.5, 0.2]
pairs = [[0, 1, 2, -1, -1, -1], [3, -1, 2, 0, -1, -1]]
"""
