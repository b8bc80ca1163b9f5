"""A sweep rerun on another gamma grid reuses every finished point whose
inputs match: the same line (system, direction, settings, versions) reached
through the same gammas, so with the same warm starts."""

from __future__ import annotations

import pytest
import xarray as xr

from jointdyn.sweeps import SweepOptions, _points, frc_sweep
from jointdyn.sweeps._family import LineSpec
from test_sweeps import GAMMAS, _Fake, _results


@pytest.fixture
def swap(monkeypatch):
    """``swap()``: a fresh recording solver double in place, returned."""
    def install():
        f = _Fake()
        monkeypatch.setattr(_points, "_steady_state_fn", lambda: f)
        return f

    return install


@pytest.mark.parametrize("chunk", [2, 8])
def test_one_more_point_reuses_every_point_before_it(swap, tmp_path, monkeypatch, chunk):
    kw = dict(options=SweepOptions(chunk_points=chunk), etas=[0.5], betas=[1.0], n_workers=1, progress=False,
              out=tmp_path)
    swap()
    frc_sweep(GAMMAS, **kw)
    longer = [*GAMMAS, 1.4]  # one more point at the top of the grid
    again = swap()
    ds = frc_sweep(longer, **kw)
    # up: the six points before the new one have the same inputs; down starts at the new point, so
    # every point of it has another warm start: recomputed
    assert ds.attrs["reused_points"] == len(GAMMAS) and ds.attrs["stale_points"] == 0
    assert sorted(c[1] for c in again.calls) == sorted([1.4, *longer])
    fresh_solver = swap()
    fresh = frc_sweep(longer, **{**kw, "out": None})
    assert len(fresh_solver.calls) == 2 * len(longer)
    xr.testing.assert_identical(_results(ds), _results(fresh))
    # one more point at the bottom: now the down line's points before it are reused
    lower = [0.7, *longer]
    third = swap()
    ds = frc_sweep(lower, **kw)
    assert ds.attrs["reused_points"] == len(longer)
    assert sorted(c[1] for c in third.calls) == sorted([0.7, *lower])
    swap()
    xr.testing.assert_identical(_results(ds), _results(frc_sweep(lower, **{**kw, "out": None})))


def test_a_point_inserted_inside_the_grid_reuses_the_points_before_it(swap, tmp_path, monkeypatch):
    kw = dict(options=SweepOptions(chunk_points=1), etas=[0.5], betas=[1.0], directions=("up",), n_workers=1,
              progress=False, out=tmp_path)
    swap()
    frc_sweep(GAMMAS, **kw)  # 0.8 ... 1.3
    finer = sorted([*GAMMAS, 0.95])
    again = swap()
    ds = frc_sweep(finer, **kw)
    assert ds.attrs["reused_points"] == 2  # 0.8, 0.9: reached through the same gammas
    assert [c[1] for c in again.calls] == [0.95, 1.0, 1.1, 1.2, 1.3]
    swap()
    xr.testing.assert_identical(_results(ds), _results(frc_sweep(finer, **{**kw, "out": None})))


def test_checkpoint_folder_leaves_out_the_grid_only():
    base = dict(label="eta0.5", system="ab" * 20, direction="up", gammas=(0.9, 1.0))
    same = LineSpec(**{**base, "gammas": (0.9, 1.0, 1.1)})
    assert same.folder == LineSpec(**base).folder and same.resume_key() == LineSpec(**base).resume_key()
    assert same.key != LineSpec(**base).key  # the line itself is another
    for other in ({"label": "eta0.6"}, {"system": "cd" * 20}, {"direction": "down"}, {"steps_per_period": 512},
                  {"dofs": (1,)}, {"loop_outputs": True}):
        spec = LineSpec(**{**base, **other})
        assert spec.folder != LineSpec(**base).folder and spec.resume_key() != LineSpec(**base).resume_key()
