"""A steady state that repeats only every K forcing periods says K everywhere
(JSON, CSV, netCDF, the table), and a not-settled point says why."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np
import pandas as pd
import pytest
import xarray as xr

from jointdyn import config
from jointdyn.cli import main
from jointdyn.dynamics import Restart
from jointdyn.sweeps import _frc, _points
from jointdyn.sweeps._points import not_settled_reason
from test_sweeps import _FakeSS


@dataclasses.dataclass
class _SS(_FakeSS):
    message: str = ""


def _fake(system, gamma, *, start=None, keep_loop=True, **kw):
    """gamma 0.9: periodic; 1.0: a 4T orbit; 1.1: slowly converging; 1.2: period 7 (beyond the multiples looked for)."""
    restart = Restart(np.array([1.0]), np.array([gamma]), np.zeros((1, 1)))
    nan = math.nan
    if gamma < 0.95:
        return _SS("periodic", gamma, 2.0, 2e-4, 0.0, 2e-4, 1.0, 0.0, 1.0, 3, 1, restart, message="integration")
    if gamma < 1.05:
        return _SS("periodic", gamma, 3.0, 3e-4, 0.0, 3e-4, 1.0, 0.0, 1.0, 12, 4, restart, message="integration")
    detail = "slowly-converging" if gamma < 1.15 else "period-7"
    return _SS("not-settled", gamma, nan, nan, nan, nan, nan, nan, nan, 50, 0, restart, message=detail)


@pytest.fixture
def fake(monkeypatch):
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _fake)


def test_not_settled_reason_codes():
    reasons = config.SWEEP_NOT_SETTLED_REASONS
    ss = _fake(None, 1.1)
    assert reasons[not_settled_reason(ss)] == "slowly-converging"
    assert reasons[not_settled_reason(_fake(None, 1.2))] == "long-period"
    assert reasons[not_settled_reason(dataclasses.replace(ss, message="quasi-periodic-or-chaotic"))] == \
        "quasi-periodic-or-chaotic"
    assert not_settled_reason(_fake(None, 1.0)) == 0


def test_multiple_and_reason_everywhere(fake, capsys, tmp_path):
    argv = ["frc", "--gamma", "0.9:1.2:0.1", "--sweep", "up", "--workers", "1", "--out", str(tmp_path)]
    assert main([*argv, "--json"]) == 0
    up = json.loads(capsys.readouterr().out)["directions"]["up"]
    assert up["status"] == ["periodic", "periodic", "not-settled", "not-settled"]
    assert up["period_multiple"] == [1, 4, 0, 0]
    assert up["not_settled_reason"] == [None, None, "slowly-converging", "long-period"]
    with xr.open_dataset(tmp_path / "frc.nc", engine="scipy") as ds:
        line = ds.sel(direction="up").squeeze()
        assert line.period_multiple.values.tolist() == [1, 4, 0, 0]
        assert line.not_settled_reason.values.tolist() == [0, 0, 1, 3]
        assert ds.not_settled_reason.attrs["flag_meanings"] == " ".join(config.SWEEP_NOT_SETTLED_REASONS)
    df = pd.read_csv(tmp_path / "frc.csv")
    assert df.period_multiple.tolist() == [1, 4, 0, 0]
    assert df.not_settled_reason_name.fillna("").tolist() == ["", "", "slowly-converging", "long-period"]
    assert main(argv) == 0  # the table (resumed from --out)
    text = capsys.readouterr().out
    rows = [line.split() for line in text.splitlines()]
    assert rows[2][-1] == "periodic-4T" and rows[1][-1] == "periodic"
    assert "periodic-KT: the steady state repeats every K forcing periods" in text
    assert "not settled at gamma 1.1 (up): slowly-converging, still converging" in text
    assert "not settled at gamma 1.2 (up): long-period, repeats only after" in text
