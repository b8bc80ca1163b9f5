"""One home per concept: law labels registered with the law, output helpers, the break rule of HB branches."""

from __future__ import annotations

from dataclasses import dataclass

import pytest

from jointdyn.figures._registry import model_label
from jointdyn.laws import ContactLaw, law_label, law_names, register
from jointdyn.laws import _base


def test_builtin_laws_carry_their_labels():
    assert law_label("iwan") == "exact Iwan model"
    assert model_label("iwan") == "exact Iwan model (iwan)"
    assert model_label("jenkins") == "Jenkins element (jenkins)"
    assert model_label("not-a-law") == "not-a-law"
    assert all(law_label(n) for n in law_names())


def test_a_law_registered_without_a_label_is_named_by_its_name(monkeypatch):
    @dataclass(frozen=True, eq=False)
    class _Plain(ContactLaw):
        """A law of a test."""

    monkeypatch.setattr(_base, "_REGISTRY", dict(_base._REGISTRY))
    register("plain-test-law", _Plain)
    register("labelled-test-law", _Plain, label="a labelled law")
    assert law_label("plain-test-law") == "plain-test-law" == model_label("plain-test-law")
    assert model_label("labelled-test-law") == "a labelled law (labelled-test-law)"
    with pytest.raises(ValueError, match="model"):
        law_label("no-such-law")


def test_an_hb_branch_breaks_before_every_point_not_joined():
    from jointdyn.figures.curves import branch_pieces
    from jointdyn.hb import PointStatus

    ps = [PointStatus.START, PointStatus.JOINED, PointStatus.CORNER, PointStatus.AFTER_JUMP, PointStatus.JOINED,
          PointStatus.STOPPED, PointStatus.START, PointStatus.JOINED]
    pieces = branch_pieces([str(s) for s in ps])
    assert [p.tolist() for p in pieces] == [[0, 1, 2], [3, 4], [5], [6, 7]]
    assert [p.tolist() for p in branch_pieces(["joined", "joined"])] == [[0, 1]]
    assert branch_pieces([]) == []


def test_jsonable_has_no_nan_at_any_depth():
    import json
    import math

    import numpy as np

    from jointdyn._io import jsonable

    assert jsonable(np.array([[1.0, math.nan], [math.inf, 2.0]])) == [[1.0, None], [None, 2.0]]
    assert jsonable([1, 2.5]) == [1.0, 2.5]  # through NumPy: one type per array
    assert jsonable(math.nan) is None and jsonable("ok") == "ok" and jsonable({"a": 1}) == {"a": 1}
    json.dumps(jsonable(np.full(3, math.nan)), allow_nan=False)


def test_write_dataset_writes_netcdf_and_one_row_per_point(tmp_path):
    import numpy as np
    import pandas as pd
    import xarray as xr

    from jointdyn._io import write_dataset

    ds = xr.Dataset({"a": ("point", np.arange(3.0)), "h": (("point", "harmonic"), np.ones((3, 2)))})
    nc, csv = write_dataset(ds, tmp_path / "out", "x")
    assert nc.name == "x.nc" and csv.name == "x.csv"
    assert xr.load_dataset(nc).identical(ds)
    assert list(pd.read_csv(csv).columns) == ["point", "a"]
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == ["x.csv", "x.nc"]  # no temporary left


def test_one_name_per_energy_with_the_old_keys_as_deprecated_duplicates():
    import numpy as np

    import jointdyn as jd
    from jointdyn.modes import backbone_dataset, qsma

    b = qsma(jd.System.paper_damper(eta=0.0, model="jenkins"))
    # no Python aliases: one attribute per quantity
    assert not any(hasattr(b, k) for k in ("energy_contact_j", "energy_viscous_j", "energy_contact_J"))
    ds = backbone_dataset(b)
    assert {"contact_energy_J", "energy_viscous_J"} <= set(ds.data_vars)
    assert not {"energy_contact_j", "energy_viscous_j"} & set(ds.data_vars)
    np.testing.assert_array_equal(ds.contact_energy_J.values, b.contact_energy_J)
    # the netCDF keeps the old per-contact name one release, marked deprecated
    np.testing.assert_array_equal(ds.energy_contact_J.values, b.contact_energy_J)
    assert "contact_energy_J" in ds.energy_contact_J.attrs["deprecated"]
