"""Sweeps: warm-start chaining, restart after unbounded points, resume,
parallel == serial, input validation, outputs.

The machinery tests use a tiny deterministic stand-in for
``jointdyn.dynamics.steady_state`` (defined here, tests only) whose result
depends on the warm start, so that chaining and restarts are observable; the
tests marked ``dynamics`` run the real time-domain solver on small grids.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

from jointdyn.sweeps import STATUS_CODES, frc_sweep, status_name
from jointdyn.sweeps import _frc


# --- test double of jointdyn.dynamics.steady_state ------------------------
@dataclass
class _FakeSS:
    status: str
    gamma: float
    amplitude_q: float
    amplitude_m: float
    offset_m: float
    max_abs_m: float
    energy_contact_J: float
    energy_viscous_J: float
    work_force_J: float
    periods: int
    period_multiple: int
    restart: object
    steps: int = 0


class _Fake:
    """amplitude = 1/|gamma - 1.05| + 0.5 * (warm-start amplitude);
    'unbounded' inside 1.0 <= gamma <= 1.1 (records every call)."""

    def __init__(self):
        self.calls = []

    def __call__(self, system, gamma, *, start=None, keep_loop=True, **kw):
        self.calls.append((float(system.force[0]), gamma, None if start is None else start.gamma))
        base = 1.0 / abs(gamma - 1.05)
        if 1.0 <= gamma <= 1.1:
            return _FakeSS("unbounded", gamma, *([math.nan] * 4), math.nan, 0.0, math.nan, 7, 0, None)
        a = base + (0.5 * start.amplitude_q if start is not None else 0.0)
        eta = system.contacts[0].eta
        return _FakeSS("periodic", gamma, a, a * 1e-4, eta * 1e-5, a * 1.1e-4, a, 0.0, a, 3, 1, a)


@pytest.fixture
def fake(monkeypatch):
    f = _Fake()
    monkeypatch.setattr(_frc, "_steady_state_fn", lambda: f)
    return f


GAMMAS = [0.8, 0.9, 1.0, 1.1, 1.2, 1.3]


def test_chain_and_restart_after_unbounded(fake):
    ds = frc_sweep(GAMMAS, etas=[0.5], betas=[2.0], n_workers=1, progress=False)
    up = ds.sel(eta=0.5, beta=2.0, delta=0.0, direction="up")
    down = ds.sel(eta=0.5, beta=2.0, delta=0.0, direction="down")
    # up: 0.8 cold, 0.9 warm from 0.8, 1.0 and 1.1 unbounded, 1.2 cold (restart), 1.3 warm
    starts_up = [c[2] for c in fake.calls[:6]]
    assert starts_up == [None, 0.8, 0.9, None, None, 1.2]
    starts_down = [c[2] for c in fake.calls[6:]]
    assert starts_down == [None, 1.3, 1.2, None, None, 0.9]
    b = lambda g: 1 / abs(g - 1.05)  # noqa: E731
    assert up.amplitude_q.sel(gamma=0.9) == pytest.approx(b(0.9) + 0.5 * b(0.8))
    assert up.amplitude_q.sel(gamma=1.2) == pytest.approx(b(1.2))
    assert down.amplitude_q.sel(gamma=1.2) == pytest.approx(b(1.2) + 0.5 * b(1.3))
    codes = up.status.values.tolist()
    assert codes == [0, 0, 2, 2, 0, 0]
    assert [status_name(c) for c in codes[:3]] == ["periodic", "periodic", "unbounded"]
    assert ds.amplitude_q.dims == ("eta", "beta", "delta", "direction", "gamma")
    # F1 = mu N0 / beta = 25 N reached the system
    assert {c[0] for c in fake.calls} == {25.0}
    assert ds.f1.values.tolist() == [25.0]


def test_f1_dimension(fake):
    ds = frc_sweep([0.8, 1.3], f1s=[10.0, 50.0], directions=("up",), n_workers=1, progress=False)
    assert ds.amplitude_q.dims == ("eta", "f1", "delta", "direction", "gamma")
    assert sorted({c[0] for c in fake.calls}) == [10.0, 50.0]
    np.testing.assert_allclose(ds.beta.values, [5.0, 1.0])


def test_resume_after_interrupt_does_not_recompute(fake, tmp_path):
    kw = dict(etas=[0.5, 1.5], betas=[1.0, 2.0], n_workers=1, progress=False, out=tmp_path)
    full = frc_sweep(GAMMAS, **{**kw, "out": tmp_path / "ref"})
    n_lines = 2 * 2 * 2

    class Stop(Exception):
        pass

    seen = []

    def stop_after_3(spec, computed):
        seen.append(computed)
        if len(seen) == 3:
            raise Stop

    fake.calls.clear()
    with pytest.raises(Stop):
        frc_sweep(GAMMAS, **kw, on_line=stop_after_3)
    assert len(list((tmp_path / "lines").glob("*.nc"))) == 3
    assert not (tmp_path / "frc.nc").exists()
    fake.calls.clear()
    flags = []
    again = frc_sweep(GAMMAS, **kw, on_line=lambda s, c: flags.append(c))
    assert flags.count(False) == 3 and flags.count(True) == n_lines - 3
    assert len(fake.calls) == (n_lines - 3) * len(GAMMAS)
    xr.testing.assert_identical(again, full)
    # a third run computes nothing
    fake.calls.clear()
    frc_sweep(GAMMAS, **kw)
    assert fake.calls == []
    # outputs
    back = xr.open_dataset(tmp_path / "frc.nc", engine="scipy")
    np.testing.assert_array_equal(back.amplitude_q.values, full.amplitude_q.values)
    np.testing.assert_array_equal(back.status.values, full.status.values)
    import pandas as pd

    df = pd.read_csv(tmp_path / "frc.csv")
    assert len(df) == 2 * 2 * 2 * len(GAMMAS)
    assert set(df.status_name) == {"periodic", "unbounded"}


def test_changed_spec_is_recomputed(fake, tmp_path):
    frc_sweep(GAMMAS, directions=("up",), n_workers=1, progress=False, out=tmp_path)
    fake.calls.clear()
    frc_sweep(GAMMAS, directions=("up",), zeta=0.01, n_workers=1, progress=False, out=tmp_path)
    assert len(fake.calls) == len(GAMMAS)


def test_threads_and_dask_equal_serial(fake, monkeypatch):
    from distributed import Client, LocalCluster

    kw = dict(etas=[0.5, 1.5], betas=[1.0, 2.0, 5.0], progress=False)
    serial = frc_sweep(GAMMAS, **kw, n_workers=1)
    with monkeypatch.context() as mp:  # the local pool kind for this call only
        mp.setattr(_frc.config, "SWEEP_POOL", "thread")
        threads = frc_sweep(GAMMAS, **kw, n_workers=2)
    xr.testing.assert_identical(serial, threads)
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            dist = frc_sweep(GAMMAS, **kw, client=client)
    xr.testing.assert_identical(serial, dist)


@pytest.mark.parametrize(
    "kw, word",
    [
        (dict(gammas=[]), "gamma"),
        (dict(gammas=[0.5, -1.0]), "gamma"),
        (dict(gammas=[0.5, 0.0]), "gamma"),
        (dict(gammas=[0.5, float("nan")]), "gamma"),
        (dict(gammas=[0.5, 0.5]), "gamma"),
        (dict(betas=[0.0]), "beta"),
        (dict(betas=[float("nan")]), "beta"),
        (dict(etas=[-0.1]), "eta"),
        (dict(etas=[float("inf")]), "eta"),
        (dict(f1s=[-1.0]), "f1"),
        (dict(betas=[1.0], f1s=[1.0]), "f1"),
        (dict(deltas=[float("nan")]), "delta"),
        (dict(model="coulomb"), "model"),
        (dict(directions=("sideways",)), "direction"),
        (dict(directions=()), "direction"),
        (dict(n=0), "n"),
        (dict(zeta=-0.1), "zeta"),
        (dict(m=-1.0), "m"),
        (dict(n_workers=0), "n_workers"),
        (dict(steps_per_period=2), "steps_per_period"),
    ],
)
def test_bad_input(kw, word, fake):
    args = dict(gammas=[0.9, 1.2], n_workers=1)
    args.update(kw)
    g = args.pop("gammas")
    with pytest.raises(ValueError, match=word):
        frc_sweep(g, progress=False, **args)
    assert fake.calls == []


def test_status_codes_match_config():
    from jointdyn import config

    assert STATUS_CODES == {n: i for i, n in enumerate(config.SWEEP_STATUS)}
    assert status_name(-1) == "not-computed"


# --- with the real time-domain solver -------------------------------------
def test_linear_stuck_limit_real_solver():
    """eta = 0, beta = 1000 (F1 = 0.05 N): the joint hardly slips, so the
    response is the linear one with stiffness k + kt:
    q = kt / fy * F1 / (k + kt - m w^2), w = gamma sqrt(k/m)."""
    g = [0.8, 1.6]
    ds = frc_sweep(g, etas=[0.0], betas=[1000.0], directions=("up",), n_workers=1, progress=False)
    q = ds.amplitude_q.sel(eta=0.0, beta=1000.0, delta=0.0, direction="up").values
    assert (ds.status.values == 0).all()
    k, m, kt, fy = 3.9e5, 10.0, 3e5, 50.0
    w = np.asarray(g) * math.sqrt(k / m)
    q_lin = kt / fy * 0.05 / np.abs(k + kt - m * w**2)
    np.testing.assert_allclose(q, q_lin, rtol=0.01)


def test_real_solver_serial_equals_dask_and_resume(tmp_path):
    """Deterministic: serial == Dask LocalCluster; an interrupted sweep
    resumes to the identical result without recomputing finished lines."""
    from distributed import Client, LocalCluster

    g = [0.9, 1.0, 1.1]
    kw = dict(etas=[0.5, 1.5], betas=[2.0], progress=False)
    serial = frc_sweep(g, **kw, n_workers=1)
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            dist = frc_sweep(g, **kw, client=client)
    xr.testing.assert_identical(serial, dist)
    pooled = frc_sweep(g, **kw, n_workers=2)  # local process pool (config.SWEEP_POOL)
    xr.testing.assert_identical(serial, pooled)

    class Stop(Exception):
        pass

    def stop(spec, computed):
        raise Stop

    with pytest.raises(Stop):
        frc_sweep(g, **kw, n_workers=1, out=tmp_path, on_line=stop)
    calls = []
    real = _frc._solve_line
    import unittest.mock as um

    with um.patch.object(_frc, "_solve_line", side_effect=lambda s: calls.append(s) or real(s)):
        again = frc_sweep(g, **kw, n_workers=1, out=tmp_path)
    assert len(calls) == 3  # 4 lines, 1 loaded
    xr.testing.assert_identical(again, serial)


def test_energy_balance_real_solver():
    """Undamped (zeta = 0) steady state: the work of the force per period
    equals the energy the contact dissipates (delta sweep, contact and
    separation)."""
    ds = frc_sweep([0.8], etas=[0.5, 1.5], betas=[1.0], deltas=[0.0, 90.0], directions=("up",),
                   n_workers=1, progress=False)
    assert (ds.status.values == 0).all()
    np.testing.assert_allclose(ds.energy_contact_J.values, ds.work_force_J.values, rtol=1e-3)
    assert (ds.energy_contact_J.values > 0).all()


def test_gamma_order_does_not_matter(fake):
    a = frc_sweep(GAMMAS, n_workers=1, progress=False)
    b = frc_sweep(GAMMAS[::-1], n_workers=1, progress=False)
    xr.testing.assert_identical(a, b)


def test_line_keys_distinct_and_stable():
    from jointdyn.sweeps import LineSpec

    base = dict(eta=0.5, beta=2.0, f1=None, delta_deg=0.0, direction="up", gammas=(0.9, 1.0))
    variants = [
        {}, {"eta": 0.5000001}, {"beta": None, "f1": 2.0}, {"delta_deg": 90.0}, {"direction": "down"},
        {"gammas": (0.9, 1.0, 1.1)}, {"model": "discrete"}, {"law_params": (("n", 200),)}, {"zeta": 0.01},
        {"overrides": (("m", 11.0),)}, {"steps_per_period": 512},
    ]
    keys = [LineSpec(**{**base, **v}).key for v in variants]
    assert len(set(keys)) == len(keys)
    assert LineSpec(**base).key == LineSpec(**base).key


@settings(max_examples=8, deadline=None)
@given(st.integers(min_value=1, max_value=7))
def test_resume_from_any_interruption(k):
    """Stopping after any k of 8 lines and resuming gives the uninterrupted
    result and computes exactly the 8 - k missing lines."""
    import tempfile
    from pathlib import Path
    from unittest import mock

    f = _Fake()
    kw = dict(etas=[0.5, 1.5], betas=[1.0, 2.0], n_workers=1, progress=False)

    class Stop(Exception):
        pass

    with mock.patch.object(_frc, "_steady_state_fn", lambda: f), tempfile.TemporaryDirectory() as d:
        full = frc_sweep(GAMMAS, **kw)
        done = []

        def stop(spec, computed):
            done.append(spec)
            if len(done) == k:
                raise Stop

        with pytest.raises(Stop):
            frc_sweep(GAMMAS, **kw, out=Path(d), on_line=stop)
        f.calls.clear()
        again = frc_sweep(GAMMAS, **kw, out=Path(d))
        assert len(f.calls) == (8 - k) * len(GAMMAS)
        xr.testing.assert_identical(again, full)
