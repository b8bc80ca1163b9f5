"""Sweeps: warm-start chaining, restart after unbounded points, chunking,
resume from chunk checkpoints (after an interrupt, across solver versions),
parallel == serial, families of Systems, per-DOF and per-contact outputs,
input validation, outputs.

The machinery tests use a tiny deterministic stand-in for
``jointdyn.dynamics.steady_state`` (defined here, tests only) whose result
depends on the warm start, so that chaining and restarts are observable;
the tests at the end run the real time-domain solver on small grids.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

import numpy as np
import pytest
import xarray as xr
from hypothesis import given, settings
from hypothesis import strategies as st

import jointdyn as jd
from jointdyn.dynamics import Restart
from jointdyn.sweeps import STATUS_CODES, LineSpec, SweepOptions, frc_sweep, status_name, to_frame
from jointdyn.sweeps import _frc, _points
from tolerances import (
    TEST_SWEEP_CONTACT_ENERGY_RTOL,
    TEST_SWEEP_NORMAL_EXTREME_RTOL,
    TEST_SWEEP_NORMAL_MEAN_RTOL,
    TEST_SWEEP_SAME_RTOL,
    TEST_TI_ENERGY_RTOL,
)


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
    loop: object = None


class _Fake:
    """amplitude = 1/|gamma - 1.05| + 0.5 * (warm-start amplitude);
    'unbounded' inside 1.0 <= gamma <= 1.1 (records every call). The warm
    start is a Restart holding (amplitude,) in x and (gamma,) in v, so that
    it survives a checkpoint; ``interrupt_at`` raises KeyboardInterrupt at
    that call (counted from 1) as Ctrl-C would."""

    def __init__(self, interrupt_at=None):
        self.calls = []
        self.interrupt_at = interrupt_at

    def __call__(self, system, gamma, *, start=None, keep_loop=True, **kw):
        if self.interrupt_at is not None and len(self.calls) + 1 == self.interrupt_at:
            raise KeyboardInterrupt
        self.calls.append((float(system.force[0]), gamma, None if start is None else float(start.v[0])))
        if 1.0 <= gamma <= 1.1:
            return _FakeSS("unbounded", gamma, *([math.nan] * 4), math.nan, 0.0, math.nan, 7, 0, None)
        a = 1.0 / abs(gamma - 1.05) + (0.5 * float(start.x[0]) if start is not None else 0.0)
        eta = system.contacts[0].eta
        restart = Restart(np.array([a]), np.array([gamma]), np.zeros((1, 1)))
        return _FakeSS("periodic", gamma, a, a * 1e-4, eta * 1e-5, a * 1.1e-4, a, 0.0, a, 3, 1, restart)


@pytest.fixture
def fake(monkeypatch):
    f = _Fake()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: f)
    return f


GAMMAS = [0.8, 0.9, 1.0, 1.1, 1.2, 1.3]


def _expected_line(gammas, direction):
    """The fake's amplitudes along one line, by a plain loop (NaN where unbounded)."""
    order = list(gammas) if direction == "up" else list(gammas)[::-1]
    out, prev = {}, None
    for g in order:
        if 1.0 <= g <= 1.1:
            out[g], prev = math.nan, None
            continue
        a = 1.0 / abs(g - 1.05) + (0.5 * prev if prev is not None else 0.0)
        out[g], prev = a, a
    return [out[g] for g in gammas]


def test_chain_and_restart_after_unbounded(fake):
    ds = frc_sweep(GAMMAS, etas=[0.5], betas=[2.0], n_workers=1, progress=False)
    up = ds.sel(eta=0.5, beta=2.0, delta=0.0, direction="up")
    down = ds.sel(eta=0.5, beta=2.0, delta=0.0, direction="down")
    # up: 0.8 cold, 0.9 warm from 0.8, 1.0 and 1.1 unbounded, 1.2 cold (restart), 1.3 warm
    starts_up = [c[2] for c in fake.calls[:6]]
    assert starts_up == [None, 0.8, 0.9, None, None, 1.2]
    starts_down = [c[2] for c in fake.calls[6:]]
    assert starts_down == [None, 1.3, 1.2, None, None, 0.9]
    np.testing.assert_array_equal(up.amplitude_q.values, _expected_line(GAMMAS, "up"))
    np.testing.assert_array_equal(down.amplitude_q.values, _expected_line(GAMMAS, "down"))
    codes = up.status.values.tolist()
    assert codes == [0, 0, 2, 2, 0, 0]
    assert [status_name(c) for c in codes[:3]] == ["periodic", "periodic", "unbounded"]
    assert ds.amplitude_q.dims == ("eta", "beta", "delta", "direction", "gamma")
    # F1 = mu N0 / beta = 25 N reached the system
    assert {c[0] for c in fake.calls} == {25.0}
    assert ds.f1.values.tolist() == [25.0]


@pytest.mark.parametrize("chunk", [1, 2, 5, 100])
def test_chunking_does_not_change_results(chunk, fake, monkeypatch):
    """A line run as chunks of any size continues each chunk from the
    previous chunk's last state: the same result as one plain loop."""
    g = [0.5 + 0.05 * i for i in range(20)]
    ds = frc_sweep(g, etas=[0.5], betas=[2.0], n_workers=1, progress=False, options=SweepOptions(chunk_points=chunk))
    for d in ("up", "down"):
        got = ds.amplitude_q.sel(eta=0.5, beta=2.0, delta=0.0, direction=d).values
        np.testing.assert_array_equal(got, _expected_line(g, d))


def test_f1_dimension(fake):
    ds = frc_sweep([0.8, 1.3], f1s=[10.0, 50.0], directions=("up",), n_workers=1, progress=False)
    assert ds.amplitude_q.dims == ("eta", "f1", "delta", "direction", "gamma")
    assert sorted({c[0] for c in fake.calls}) == [10.0, 50.0]
    np.testing.assert_allclose(ds.beta.values, [5.0, 1.0])


def _results(ds):
    """The Dataset without the attributes about the run (reused points)."""
    out = ds.copy()
    for key in _frc.RUN_ATTRIBUTES:
        out.attrs.pop(key)
    return out


def _checkpoint_points(root):
    return sum(int(np.load(p)["done"]) for p in root.glob("lines/*/*.npz"))


def test_interrupt_keeps_finished_points_and_resume_reuses_them(monkeypatch, tmp_path):
    """Ctrl-C at the 10th point of a serial sweep: the 9 finished points are
    saved (across chunk boundaries), the rerun reuses exactly them, says so,
    computes only the rest and equals the uninterrupted sweep."""
    kw = dict(options=SweepOptions(chunk_points=4), etas=[0.5, 1.5], betas=[1.0], n_workers=1, progress=False)
    ref = _Fake()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: ref)
    full = frc_sweep(GAMMAS, **kw)
    stop = _Fake(interrupt_at=10)
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: stop)
    with pytest.raises(KeyboardInterrupt):
        frc_sweep(GAMMAS, **kw, out=tmp_path)
    assert _checkpoint_points(tmp_path) == 9
    assert not (tmp_path / "frc.nc").exists()
    again = _Fake()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: again)
    ds = frc_sweep(GAMMAS, **kw, out=tmp_path)
    assert ds.attrs["reused_points"] == 9 and ds.attrs["stale_points"] == 0
    assert len(again.calls) == 4 * len(GAMMAS) - 9
    xr.testing.assert_identical(_results(ds), _results(full))
    # the file holds the results only, however the run went
    with xr.open_dataset(tmp_path / "frc.nc", engine="scipy") as written:
        assert set(written.attrs) == set(_results(full).attrs)
        for name in full.data_vars:
            np.testing.assert_array_equal(written[name].values, full[name].values)


@settings(max_examples=10, deadline=None)
@given(st.integers(min_value=1, max_value=24), st.integers(min_value=1, max_value=7))
def test_resume_from_any_interruption(k, chunk):
    """Interrupting at any point with any chunk size and resuming gives the
    uninterrupted result and computes exactly the points not yet finished."""
    import tempfile
    from pathlib import Path
    from unittest import mock

    kw = dict(etas=[0.5, 1.5], betas=[1.0, 2.0], directions=("up",), n_workers=1, progress=False,
              options=SweepOptions(chunk_points=chunk))
    total = 4 * len(GAMMAS)
    with tempfile.TemporaryDirectory() as d:
        with mock.patch.object(_points, "_steady_state_fn", lambda: _Fake()):
            full = frc_sweep(GAMMAS, **kw)
        stop = _Fake(interrupt_at=k)
        with mock.patch.object(_points, "_steady_state_fn", lambda: stop):
            with pytest.raises(KeyboardInterrupt):
                frc_sweep(GAMMAS, **kw, out=Path(d))
        f = _Fake()
        with mock.patch.object(_points, "_steady_state_fn", lambda: f):
            again = frc_sweep(GAMMAS, **kw, out=Path(d))
        assert again.attrs["reused_points"] == k - 1
        assert len(f.calls) == total - (k - 1)
        xr.testing.assert_identical(_results(again), _results(full))


def test_other_solver_version_is_recomputed_not_reused(fake, tmp_path, monkeypatch):
    from jointdyn.dynamics import version

    frc_sweep(GAMMAS, directions=("up",), n_workers=1, progress=False, out=tmp_path)
    fake.calls.clear()
    same = frc_sweep(GAMMAS, directions=("up",), n_workers=1, progress=False, out=tmp_path)
    assert same.attrs["reused_points"] == len(GAMMAS) and fake.calls == []
    monkeypatch.setattr(version, "SOLVER_VERSION", version.SOLVER_VERSION + 1)
    newer = frc_sweep(GAMMAS, directions=("up",), n_workers=1, progress=False, out=tmp_path)
    assert newer.attrs["reused_points"] == 0 and newer.attrs["stale_points"] == len(GAMMAS)
    assert len(fake.calls) == len(GAMMAS)
    # the new solver's checkpoints replaced the old ones
    fake.calls.clear()
    assert frc_sweep(GAMMAS, directions=("up",), n_workers=1, progress=False,
                     out=tmp_path).attrs["reused_points"] == len(GAMMAS)
    assert fake.calls == []


def test_changed_spec_is_recomputed(fake, tmp_path):
    frc_sweep(GAMMAS, directions=("up",), n_workers=1, progress=False, out=tmp_path)
    fake.calls.clear()
    frc_sweep(GAMMAS, directions=("up",), zeta=0.01, n_workers=1, progress=False, out=tmp_path)
    assert len(fake.calls) == len(GAMMAS)


def test_progress_moves_per_point_and_shows_the_reused(fake, tmp_path, monkeypatch):
    import tqdm

    bars = []

    class Bar:
        def __init__(self, total, initial=0, **kw):
            self.total, self.n, self.steps, self.postfix = total, initial, [], None
            bars.append(self)

        def update(self, k):
            self.n += k
            self.steps.append(k)

        def set_postfix_str(self, text):
            self.postfix = text

        def close(self):
            pass

    monkeypatch.setattr(tqdm, "tqdm", Bar)
    frc_sweep(GAMMAS, directions=("up",), n_workers=1, out=tmp_path)
    assert bars[0].steps == [1] * len(GAMMAS) and bars[0].n == bars[0].total == len(GAMMAS)
    frc_sweep(GAMMAS, directions=("up", "down"), n_workers=1, out=tmp_path)
    assert bars[1].total == 2 * len(GAMMAS) and bars[1].steps == [1] * len(GAMMAS)
    assert "reused 6" in bars[1].postfix


def test_dask_progress_moves_per_point(monkeypatch):
    """On a Dask cluster each finished point reaches the client while its
    chunk still runs: before solving a point, the (in-process) worker waits
    until the client has counted every earlier point of the chunk; the bar
    then ends at the total."""
    import time

    import tqdm
    from distributed import Client, LocalCluster

    from jointdyn.sweeps import _pool

    executors, seen, bars = [], [], []
    init = _pool.DaskExecutor.__init__

    def keep(self, *a, **kw):
        init(self, *a, **kw)
        executors.append(self)

    monkeypatch.setattr(_pool.DaskExecutor, "__init__", keep)
    inner = _Fake()

    def solver(system, gamma, **kw):
        done = len(inner.calls)
        for _ in range(3000):  # the client hears of each point before the next one starts
            if executors[0].progress() >= done:
                break
            time.sleep(0.01)
        seen.append((done, executors[0].progress()))
        return inner(system, gamma, **kw)

    class Bar:
        def __init__(self, total, initial=0, **kw):
            self.total, self.n = total, initial
            bars.append(self)

        def update(self, k):
            self.n += k

        def set_postfix_str(self, text):
            pass

        def close(self):
            pass

    monkeypatch.setattr(tqdm, "tqdm", Bar)
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: solver)
    gammas = [0.7, 0.75, 0.8, 0.85, 0.9, 0.95]  # one chunk of six points
    with LocalCluster(n_workers=1, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            frc_sweep(gammas, directions=("up",), client=client)
    assert len(gammas) <= SweepOptions().chunk_points
    assert seen == [(k, k) for k in range(len(gammas))]
    assert bars[0].n == bars[0].total == len(gammas)


def test_threads_and_dask_equal_serial(fake, monkeypatch):
    from distributed import Client, LocalCluster

    kw = dict(etas=[0.5, 1.5], betas=[1.0, 2.0, 5.0], progress=False)
    serial = frc_sweep(GAMMAS, **kw, n_workers=1)
    threads = frc_sweep(GAMMAS, **kw, n_workers=2, options=SweepOptions(pool="thread", chunk_points=2))
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
        (dict(dofs=[1]), "dofs"),
        (dict(dofs=[-1]), "dofs"),
    ],
)
def test_bad_input(kw, word, fake):
    args = dict(gammas=[0.9, 1.2], n_workers=1)
    args.update(kw)
    g = args.pop("gammas")
    with pytest.raises(ValueError, match=word):
        frc_sweep(g, progress=False, **args)
    assert fake.calls == []


@pytest.mark.parametrize(
    "call, word",
    [
        (lambda s: frc_sweep(s, progress=False), "gammas must be given"),
        (lambda s: frc_sweep(s, [1.0], etas=[0.5], progress=False), "etas"),
        (lambda s: frc_sweep(s, [1.0], model="iwan", n0=3.0, progress=False), "model, n0"),
        (lambda s: frc_sweep([1.0], [1.0], progress=False), "gammas is given twice"),
        (lambda s: frc_sweep({"": s}, [1.0], progress=False), "labels"),
        (lambda s: frc_sweep({"a": 3}, [1.0], progress=False), re.escape("system['a'] must be a System")),
        (lambda s: frc_sweep({}, [1.0], progress=False), "non-empty mapping"),
        (lambda s: frc_sweep(s, [1.0], dofs=[0, 0], progress=False), "dofs"),
    ],
)
def test_bad_system_form(call, word, fake):
    with pytest.raises(ValueError, match=word):
        call(jd.System.paper_damper())
    assert fake.calls == []


def test_status_codes_are_the_steady_state_statuses_own_codes():
    from jointdyn.dynamics import SteadyStatus
    from jointdyn.sweeps import NOT_COMPUTED, NOT_COMPUTED_NAME

    assert STATUS_CODES == {s.value: s.code for s in SteadyStatus} == {"periodic": 0, "not-settled": 1, "unbounded": 2}
    assert all(status_name(s.code) == s.value for s in SteadyStatus)
    assert status_name(NOT_COMPUTED) == NOT_COMPUTED_NAME == "not-computed"


def test_gamma_order_does_not_matter(fake):
    a = frc_sweep(GAMMAS, n_workers=1, progress=False)
    b = frc_sweep(GAMMAS[::-1], n_workers=1, progress=False)
    xr.testing.assert_identical(a, b)


def test_line_keys_distinct_and_stable():
    base = dict(label="eta0.5", system="ab" * 20, direction="up", gammas=(0.9, 1.0))
    variants = [
        {}, {"label": "eta0.6"}, {"system": "cd" * 20}, {"direction": "down"}, {"gammas": (0.9, 1.0, 1.1)},
        {"gammas": (0.9, 1.0000000000000002)}, {"steps_per_period": 512}, {"dofs": (1,)},
        {"loop_outputs": True},
    ]
    keys = [LineSpec(**{**base, **v}).key for v in variants]
    assert len(set(keys)) == len(keys)
    assert LineSpec(**base).key == LineSpec(**base).key
    assert LineSpec(**{**base, "label": "a b/c"}).key.startswith("a_b_c_up_")


def test_fingerprint_sees_every_part_of_a_system():
    from jointdyn.sweeps._family import fingerprint

    law = jd.make_law("iwan", kt=3e5, mu=0.5, n_ref=100.0)
    M, K = np.diag([2.0, 1.0]), np.array([[3e5, -1e5], [-1e5, 1e5]])

    def make(**kw):
        args = dict(M=M, C=None, K=K, contacts=(jd.Contact(law, dof=0, normal=jd.HarmonicLoad(100.0, 20.0)),),
                    force=[1.0, 0.0])
        args.update(kw)
        return jd.System(**args)

    base = make()
    variants = [
        make(M=np.diag([2.0, 1.0 + 1e-15])),
        make(C=1e-3 * K),
        make(force=[1.0, 1e-300]),
        make(force_phase_deg=[0.0, 10.0]),
        make(w0_rad_s=300.0),
        make(output_dof=1),
        make(contacts=(jd.Contact(law, dof=0, normal=jd.HarmonicLoad(100.0, 20.0, phase_deg=1.0)),)),
        make(contacts=(jd.Contact(law, dof=1, dof2=0, normal=jd.HarmonicLoad(100.0, 20.0)),)),
        make(contacts=(jd.Contact(jd.make_law("iwan", kt=3e5, mu=0.4, n_ref=100.0), dof=0,
                                  normal=jd.HarmonicLoad(100.0, 20.0)),)),
        make(contacts=(jd.Contact(jd.make_law("iwan-paper", kt=3e5, mu=0.5, n_ref=100.0), dof=0,
                                  normal=jd.HarmonicLoad(100.0, 20.0)),)),
    ]
    prints = [fingerprint(s) for s in (base, *variants)]
    assert len(set(prints)) == len(prints)
    assert fingerprint(make()) == prints[0]


# --- families of Systems ---------------------------------------------------------------
def test_paper_grid_is_a_family_of_paper_damper_systems(fake):
    """The keyword grid computes exactly what the same paper_damper Systems
    give as a labelled family."""
    grid = frc_sweep(GAMMAS, etas=[0.5, 1.5], betas=[2.0], n_workers=1, progress=False)
    fam = frc_sweep({f"eta{e}": jd.System.paper_damper(eta=e, beta=2.0) for e in (0.5, 1.5)}, GAMMAS,
                    loop_outputs=False, n_workers=1, progress=False)
    assert fam.amplitude_q.dims == ("system", "direction", "gamma")
    assert fam.system.values.tolist() == ["eta0.5", "eta1.5"]
    np.testing.assert_array_equal(fam.w0_rad_s.values, [math.sqrt(3.9e4)] * 2)
    for name in ("amplitude_q", "status", "periods"):
        np.testing.assert_array_equal(fam[name].values, grid[name].isel(beta=0, delta=0).values)


def test_single_system_dims(fake):
    s = jd.System.paper_damper(eta=0.5, beta=2.0)
    ds = frc_sweep(s, GAMMAS, n_workers=1, progress=False, loop_outputs=False)
    assert ds.amplitude_q.dims == ("direction", "gamma")
    assert ds.attrs["w0_rad_s"] == pytest.approx(math.sqrt(3.9e4)) and ds.attrs["fy_N"] == 50.0
    assert list(to_frame(ds).columns[:2]) == ["direction", "gamma"]


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


def test_real_solver_serial_equals_dask_and_pool():
    """Deterministic: serial == Dask LocalCluster == local process pool,
    with chunks of 2 points (lines continue across chunks on other workers)."""
    from distributed import Client, LocalCluster

    g = [0.9, 1.0, 1.1, 1.2, 1.3]
    kw = dict(etas=[0.5, 1.5], betas=[2.0], progress=False)
    serial = frc_sweep(g, **kw, n_workers=1)
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            dist = frc_sweep(g, **kw, options=SweepOptions(chunk_points=2), client=client)
    pooled = frc_sweep(g, **kw, options=SweepOptions(chunk_points=2), n_workers=2)  # local process pool
    xr.testing.assert_identical(serial, dist)
    xr.testing.assert_identical(serial, pooled)


def test_energy_balance_real_solver():
    """Undamped (zeta = 0) steady state: the work of the force per period
    equals the energy the contact dissipates (delta sweep, contact and
    separation)."""
    ds = frc_sweep([0.8], etas=[0.5, 1.5], betas=[1.0], deltas=[0.0, 90.0], directions=("up",),
                   n_workers=1, progress=False)
    assert (ds.status.values == 0).all()
    np.testing.assert_allclose(ds.energy_contact_J.values, ds.work_force_J.values, rtol=1e-3)
    assert (ds.energy_contact_J.values > 0).all()


def _two_dof(n1, *, mu=0.3, phase_deg=30.0, law="iwan"):
    """Two masses, the first against ground through a contact with a
    harmonic prescribed load, the second forced."""
    law = jd.make_law(law, kt=2e5, mu=mu, n_ref=100.0)
    contact = jd.Contact(law, dof=0, normal=jd.HarmonicLoad(100.0, n1, phase_deg=phase_deg))
    M, K = np.diag([2.0, 1.0]), np.array([[3e5, -1e5], [-1e5, 1e5]])
    return jd.System(M, 1e-3 * K, K, contacts=(contact,), force=[0.0, 20.0], output_dof=1)


@pytest.mark.parametrize("n1", [40.0, 150.0], ids=["in-contact", "separation"])
def test_loop_outputs_of_a_two_dof_system(n1):
    """Per-DOF and per-contact outputs against what they must equal: the
    solver's own amplitude and offset of the response DOF, its total
    contact energy, the prescribed load's mean and extremes, the fraction of
    the period with a tensile prescribed load (separation)."""
    s = _two_dof(n1)
    g = [0.7, 1.0, 1.3]
    ds = frc_sweep(s, g, dofs=[0, 1], directions=("up",), n_workers=1, progress=False)
    one = ds.sel(direction="up")
    assert (one.status.values == 0).all()
    amp1 = one.dof_amplitude_m.sel(dof=1).values
    np.testing.assert_allclose(amp1, one.amplitude_m.values, rtol=TEST_SWEEP_SAME_RTOL)
    np.testing.assert_allclose(one.dof_offset_m.sel(dof=1).values, one.offset_m.values,
                               atol=TEST_SWEEP_SAME_RTOL * amp1.max())
    e = one.contact_energy_J.sel(contact=0).values
    np.testing.assert_allclose(e, one.energy_contact_J.values, rtol=TEST_SWEEP_CONTACT_ENERGY_RTOL)
    np.testing.assert_allclose(one.work_force_J.values, one.energy_contact_J.values + one.energy_viscous_J.values,
                               rtol=TEST_TI_ENERGY_RTOL)
    nmax = one.normal_max_N.sel(contact=0).values
    nmin = one.normal_min_N.sel(contact=0).values
    np.testing.assert_allclose(nmax, 100.0 + n1, rtol=TEST_SWEEP_NORMAL_EXTREME_RTOL)
    frac = one.state_fraction.sel(contact=0)
    np.testing.assert_allclose(frac.sum("state").values, 1.0, rtol=1e-12)
    if n1 < 100.0:
        np.testing.assert_allclose(nmin, 100.0 - n1, rtol=TEST_SWEEP_NORMAL_EXTREME_RTOL)
        np.testing.assert_allclose(one.normal_mean_N.sel(contact=0).values, 100.0, rtol=TEST_SWEEP_NORMAL_MEAN_RTOL)
        assert (frac.sel(state="separation").values == 0).all()
    else:
        assert (nmin == 0).all()
        # open while 100 + n1 sin(phase) < 0: a fraction (pi - 2 asin(100 / n1)) / (2 pi) of the period
        open_ = (math.pi - 2 * math.asin(100.0 / n1)) / (2 * math.pi)
        np.testing.assert_allclose(frac.sel(state="separation").values, open_, atol=4.0 / 256)
        # mean of max(0, n0 + n1 sin) over a period: closed over (-a, pi + a), a = asin(n0 / n1)
        a = math.asin(100.0 / n1)
        mean = (100.0 * (math.pi + 2 * a) + 2 * n1 * math.cos(a)) / (2 * math.pi)
        np.testing.assert_allclose(one.normal_mean_N.sel(contact=0).values, mean, rtol=TEST_SWEEP_NORMAL_MEAN_RTOL)


def test_contact_energy_converges_with_the_step():
    """The per-contact energy (trapezoid of T du over the recorded steps) is
    second order: halving the step divides its deviation from the solver's
    accurate total by about four."""
    s = _two_dof(40.0)
    dev = []
    for spp in (256, 512):
        ds = frc_sweep(s, [1.0], directions=("up",), steps_per_period=spp, n_workers=1, progress=False)
        one = ds.sel(direction="up", gamma=1.0)
        dev.append(abs(float(one.contact_energy_J.sel(contact=0)) / float(one.energy_contact_J) - 1.0))
    assert 2.5 < dev[0] / dev[1] < 6.0, dev


def test_stuck_and_slipping_limits_have_their_states():
    """A Jenkins contact with mu huge sticks all period, elastic: it
    dissipates nothing (the trapezoid of T du is exact for an elastic
    contact; what remains is the recorded period's closure, within the
    steady-state tolerance); with mu tiny it slips (macroslip) most of the
    period."""
    stuck = frc_sweep(_two_dof(40.0, mu=1e3, law="jenkins"), [1.0], directions=("up",), n_workers=1,
                      progress=False)
    one = stuck.sel(direction="up", gamma=1.0)
    assert float(one.state_fraction.sel(contact=0, state="stick-slip")) == 1.0
    assert abs(float(one.contact_energy_J.sel(contact=0))) < 1e-6 * float(one.energy_viscous_J)
    slip = frc_sweep(_two_dof(40.0, mu=1e-3, law="jenkins"), [1.0], directions=("up",), n_workers=1,
                     progress=False)
    assert float(slip.state_fraction.sel(direction="up", gamma=1.0, contact=0, state="macroslip")) > 0.8


def test_system_family_pool_and_dask_equal_serial():
    """A mapping {label: System} with per-DOF and per-contact outputs: serial
    == local process pool == Dask, with chunks of 2 points (lines continue
    across chunks on other workers; the Systems travel by pickle)."""
    from distributed import Client, LocalCluster

    family = {"light": _two_dof(40.0), "separating": _two_dof(150.0, law="jenkins")}
    kw = dict(dofs=[0, 1], progress=False)
    g = [0.8, 1.0, 1.2]
    serial = frc_sweep(family, g, **kw, n_workers=1)
    assert serial.sizes["system"] == 2 and list(serial.system.values) == ["light", "separating"]
    pooled = frc_sweep(family, g, **kw, options=SweepOptions(chunk_points=2), n_workers=2)
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            dist = frc_sweep(family, g, **kw, options=SweepOptions(chunk_points=2), client=client)
    xr.testing.assert_identical(serial, pooled)
    xr.testing.assert_identical(serial, dist)


def test_damaged_checkpoint_is_recomputed_from_there(fake, tmp_path, monkeypatch):
    """A truncated chunk file (a full disk, a partial copy) and the
    temporary file a kill during an atomic write leaves behind: the chunks
    before the damage are reused, the rest recomputed, the result unchanged."""
    kw = dict(options=SweepOptions(chunk_points=2), directions=("up",), n_workers=1, progress=False, out=tmp_path)
    full = frc_sweep(GAMMAS, **kw)
    (line,) = (tmp_path / "lines").iterdir()
    chunks = sorted(line.glob("p*.npz"))
    assert len(chunks) == 3
    chunks[1].write_bytes(chunks[1].read_bytes()[:100])
    (line / ".p000004.npz.abc123.npz").write_bytes(b"half-written")
    fake.calls.clear()
    again = frc_sweep(GAMMAS, **kw)
    assert again.attrs["reused_points"] == 2 and len(fake.calls) == len(GAMMAS) - 2
    xr.testing.assert_identical(_results(again), _results(full))
    fake.calls.clear()
    assert frc_sweep(GAMMAS, **kw).attrs["reused_points"] == len(GAMMAS) and fake.calls == []


def test_atomic_path_leaves_the_old_file_on_failure(tmp_path):
    """A writer that fails half-way leaves the previous file as it was and
    no temporary file; one that finishes replaces it."""
    from jointdyn._io import atomic_path

    target = tmp_path / "frc.csv"
    target.write_text("old")
    with pytest.raises(RuntimeError):
        with atomic_path(target) as tmp:
            tmp.write_text("half")
            raise RuntimeError("disk full")
    assert target.read_text() == "old" and sorted(p.name for p in tmp_path.iterdir()) == ["frc.csv"]
    with atomic_path(target) as tmp:
        tmp.write_text("new")
    assert target.read_text() == "new" and sorted(p.name for p in tmp_path.iterdir()) == ["frc.csv"]


class _Refusing(_Fake):
    """The fake solver, refusing (ValueError, as a solver refuses a System)
    the paper damper with eta = 1.5 from gamma 1.0 on."""

    def __call__(self, system, gamma, **kw):
        if system.contacts[0].eta == 1.5 and gamma >= 1.0:
            raise ValueError("contact 0: refused by this solver")
        return super().__call__(system, gamma, **kw)


@pytest.mark.parametrize("pool", ["serial", "thread"])
def test_refused_system_is_named_and_the_finished_points_kept(pool, tmp_path, monkeypatch):
    """A solver's refusal of one System of a family: one ValueError naming
    the System by its label; the points finished before it (the other
    System's, and this one's first chunk) are saved and reused by a rerun,
    which equals the uninterrupted sweep."""
    family = {f"eta{e}": jd.System.paper_damper(eta=e, beta=2.0) for e in (0.5, 1.5)}
    kw = dict(options=SweepOptions(chunk_points=2, pool="thread"), directions=("up",), loop_outputs=False,
              progress=False, n_workers=1 if pool == "serial" else 2)
    refusing = _Refusing()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: refusing)
    with pytest.raises(ValueError) as exc:
        frc_sweep(family, GAMMAS, **kw, out=tmp_path)
    assert str(exc.value) == "system 'eta1.5': contact 0: refused by this solver"
    saved = {d.name.split("_")[0]: sum(int(np.load(p)["done"]) for p in d.glob("p*.npz"))
             for d in (tmp_path / "lines").iterdir()}
    assert saved["eta1.5"] == 2  # the chunk before gamma 1.0
    if pool == "serial":  # lines in order: the first one finished before the refusal
        assert saved["eta0.5"] == len(GAMMAS)
    assert not (tmp_path / "frc.nc").exists()
    again = _Fake()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: again)
    ds = frc_sweep(family, GAMMAS, **kw, out=tmp_path)
    assert ds.attrs["reused_points"] == sum(saved.values())
    assert len(again.calls) == 2 * len(GAMMAS) - sum(saved.values())
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _Fake())
    xr.testing.assert_identical(_results(ds), _results(frc_sweep(family, GAMMAS, **kw)))


def test_interrupt_on_dask_keeps_every_finished_point(tmp_path, monkeypatch):
    """Ctrl-C during a sweep on a Dask cluster: the running chunks stop after
    their current point (a distributed stop flag) and every point finished
    anywhere is saved; the rerun reuses exactly them and equals the
    uninterrupted sweep."""
    from distributed import Client, LocalCluster

    kw = dict(options=SweepOptions(chunk_points=4), etas=[0.5, 1.5], betas=[1.0, 2.0], directions=("up",),
              progress=False)
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: _Fake())
    full = frc_sweep(GAMMAS, **kw, n_workers=1)
    stop = _Fake(interrupt_at=9)
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: stop)
    with LocalCluster(n_workers=2, processes=False, threads_per_worker=1, dashboard_address=None) as lc:
        with Client(lc) as client:
            with pytest.raises(KeyboardInterrupt):
                frc_sweep(GAMMAS, **kw, client=client, out=tmp_path)
    finished = len(stop.calls)  # each recorded call returned a point (the 9th raised instead)
    assert 0 < finished < 4 * len(GAMMAS)
    assert _checkpoint_points(tmp_path) == finished
    again = _Fake()
    monkeypatch.setattr(_points, "_steady_state_fn", lambda: again)
    ds = frc_sweep(GAMMAS, **kw, n_workers=1, out=tmp_path)
    assert ds.attrs["reused_points"] == finished and len(again.calls) == 4 * len(GAMMAS) - finished
    xr.testing.assert_identical(_results(ds), _results(full))
