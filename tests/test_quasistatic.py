"""Quasi-static driver: histories, exact separation, loop metrics vs closed forms.

Oracles: docs/model.md section 2 energy per cycle, backbone tip of a steady
Masing loop, analytic separation time of N = N0 (1 + eta sin), the virgin
curve after re-contact (docs/model.md section 3), and step-halving convergence.
"""

import math

import numpy as np
import pandas as pd
import pytest

from jointdyn import DiscreteIwan, HarmonicLoad, Iwan, make_law
from tolerances import TEST_ENERGY_RTOL, TEST_QS_FRACTION_ATOL
from jointdyn.drivers import harmonic_history, harmonic_loop, quasistatic, read_history_csv
from jointdyn.laws import MACROSLIP, SEPARATION, STICK_SLIP

KT, MU, N0 = 1e5, 0.1, 100.0
FY = MU * N0
XS = 2 * FY / KT  # 0.2 mm: amplitude at which the steady loop starts to macroslip


def energy_closed_form(A):
    """docs/model.md section 2: energy dissipated per symmetric cycle, J."""
    if A <= XS:
        return KT**2 * A**3 / (3 * FY)
    return 4 * FY * A - 16 * FY**2 / (3 * KT)


def sep_fraction(eta):
    """Fraction of a period with 1 + eta sin(phase) <= 0."""
    return 0.0 if eta <= 1 else (math.pi - 2 * math.asin(1 / eta)) / (2 * math.pi)


def law(name="iwan"):
    return make_law(name, kt=KT, mu=MU, n_ref=N0, **({"n": 1000} if name == "discrete" else {}))


# --- histories ---------------------------------------------------------------
@pytest.mark.parametrize("delta_deg", [0.0, 90.0, math.degrees(2.0)])
def test_harmonic_history_inserts_exact_crossings(delta_deg):
    f, steps, cycles = 2.0, 100, 3
    t, x, N = harmonic_history(0.5e-3, f, N0, eta=1.2, delta_deg=delta_deg, cycles=cycles, steps_per_cycle=steps)
    tc = HarmonicLoad(N0, 1.2 * N0, delta_deg).zero_crossings(2 * math.pi * f, 0.0, cycles / f)
    assert tc.size == 2 * cycles
    assert np.all(np.diff(t) > 0)
    assert t.size == cycles * steps + 1 + tc.size
    for c in tc:
        i = int(np.argmin(np.abs(t - c)))
        assert t[i] == c and N[i] == 0.0
    # no sign change of N strictly inside a step: separation is never smeared
    assert not np.any((N[:-1] > 0) & (N[1:] < 0)) and not np.any((N[:-1] < 0) & (N[1:] > 0))
    # the period boundaries are exact samples, values follow the formulas
    assert set(np.arange(cycles + 1) / f) <= set(t.tolist())
    np.testing.assert_allclose(x, 0.5e-3 * np.sin(2 * math.pi * f * t), rtol=0, atol=1e-18)
    keep = N != 0.0
    np.testing.assert_allclose(N[keep], N0 + 1.2 * N0 * np.sin(2 * math.pi * f * t[keep] + math.radians(delta_deg)), rtol=1e-12)


def test_harmonic_history_crossing_on_grid_point_is_not_duplicated():
    # eta = 2, delta = 0: sin = -1/2 at phases 7 pi/6 and 11 pi/6, i.e. t = 7/12, 11/12
    t, x, N = harmonic_history(1e-4, 1.0, N0, eta=2.0, cycles=2, steps_per_cycle=12)
    assert t.size == 25 and np.all(np.diff(t) > 0)
    for c in (7 / 12, 11 / 12, 19 / 12, 23 / 12):
        i = int(np.argmin(np.abs(t - c)))
        assert abs(t[i] - c) < 1e-15 and N[i] == 0.0
    assert np.count_nonzero(N == 0.0) == 4


def test_harmonic_history_no_crossings_when_in_contact():
    t, x, N = harmonic_history(1e-4, 1.0, N0, eta=0.9, delta_deg=math.degrees(1.0), cycles=2, steps_per_cycle=40, x_offset=1e-4)
    assert t.size == 81 and np.all(N > 0)
    assert np.isclose(x.mean(), 1e-4, atol=2e-6)


def test_unilateral_spring_history_clips_only_in_separation():
    t1, x1, N1 = harmonic_history(0.5e-3, 1.0, N0, eta=1.2, steps_per_cycle=200)
    t2, x2, N2 = harmonic_history(0.5e-3, 1.0, N0, eta=1.2, steps_per_cycle=200, kn=1e5)
    np.testing.assert_array_equal(t1, t2)
    assert np.all(N2 >= 0)
    np.testing.assert_allclose(N2, np.maximum(N1, 0.0), rtol=1e-12, atol=1e-12)
    r1 = quasistatic(law(), t1, x1, N1, period=1.0)
    r2 = quasistatic(law(), t2, x2, N2, period=1.0)
    np.testing.assert_allclose(r1.T, r2.T, rtol=0, atol=1e-9 * FY)


@pytest.mark.parametrize(
    "kwargs, name",
    [
        (dict(amplitude=0.0), "amplitude"),
        (dict(amplitude=-1e-3), "amplitude"),
        (dict(frequency=0.0), "frequency"),
        (dict(frequency=math.nan), "frequency"),
        (dict(n0=-1.0), "n0"),
        (dict(eta=-0.1), "eta"),
        (dict(delta_deg=math.inf), "delta_deg"),
        (dict(cycles=0), "cycles"),
        (dict(cycles=1.5), "cycles"),
        (dict(steps_per_cycle=3), "steps_per_cycle"),
        (dict(x_offset=math.nan), "x_offset"),
        (dict(kn=0.0), "kn"),
    ],
)
def test_harmonic_history_validates(kwargs, name):
    args = dict(amplitude=1e-4, frequency=1.0, n0=N0)
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        harmonic_history(**args)


# --- energy and loop metrics at constant N -------------------------------------
@pytest.mark.parametrize("A", [0.05e-3, 0.15e-3, XS, 0.35e-3, 0.5e-3])
@pytest.mark.parametrize("name", ["iwan", "iwan-paper", "discrete"])
def test_energy_per_cycle_matches_closed_form(A, name):
    r = harmonic_loop(law(name), A, cycles=2, steps_per_cycle=1000)
    assert r.n_cycles == 2
    E = r.last_cycle()["energy_J"]
    assert E == pytest.approx(energy_closed_form(A), rel=TEST_ENERGY_RTOL)
    c = r.last_cycle()
    # steady Masing loop: its tips lie on the backbone (docs/model.md section 2)
    tip = KT * A - (KT * A) ** 2 / (4 * FY) if A <= XS else FY
    assert c["force_max_N"] == pytest.approx(tip, rel=TEST_ENERGY_RTOL)
    assert c["force_min_N"] == pytest.approx(-tip, rel=TEST_ENERGY_RTOL)
    assert c["secant_stiffness_N_per_m"] == pytest.approx(tip / A, rel=TEST_ENERGY_RTOL)
    # loss factor E / (2 pi U), U = k_sec X^2 / 2
    assert c["loss_factor"] == pytest.approx(E / (math.pi * tip * A), rel=1e-12)
    # macroslip only beyond 2 fy / kt (with a step of margin)
    if A < 0.99 * XS:
        assert c["macroslip_fraction"] == 0.0 and c["stick_slip_fraction"] == 1.0
    if A > 1.01 * XS:
        assert c["macroslip_fraction"] > 0.0


def test_macroslip_time_fraction_constant_load():
    """Unloading from +A (phase pi/2) the Masing branch saturates after a
    travel of 2 x_s, at x = A - 2 x_s, i.e. phase pi - asin(1 - 2 x_s / A);
    it then macroslips until the reversal at phase 3 pi/2. Twice per cycle."""
    A = 0.5e-3
    r = harmonic_loop(law("iwan"), A, cycles=2, steps_per_cycle=4000)
    phi = math.pi - math.asin(1 - 2 * XS / A)
    expected = 2 * (1.5 * math.pi - phi) / (2 * math.pi)
    assert r.last_cycle()["macroslip_fraction"] == pytest.approx(expected, abs=2.0 / 4000)


def test_first_cycle_is_work_not_loop_area():
    A = 0.1e-3
    r = harmonic_loop(law("iwan"), A, cycles=3, steps_per_cycle=400)
    E = r.cycles["energy_J"].to_numpy()
    assert E[1] == pytest.approx(E[2], rel=1e-12)
    assert E[0] < E[1]  # the virgin start is not a closed loop


# --- varying normal load ----------------------------------------------------
@pytest.mark.parametrize("delta_deg", [0.0, 90.0, 200.0])
@pytest.mark.parametrize("eta", [0.0, 0.6, 1.0, 1.2, 2.5])
@pytest.mark.parametrize("name", ["iwan", "discrete"])
def test_state_fractions(eta, delta_deg, name):
    r = harmonic_loop(law(name), 0.5e-3, eta=eta, delta_deg=delta_deg, cycles=2, steps_per_cycle=400)
    for _, row in r.cycles.iterrows():
        s = row["stick_slip_fraction"] + row["macroslip_fraction"] + row["separation_fraction"]
        assert s == pytest.approx(1.0, abs=1e-12)
        assert (row["separation_fraction"] > 0) == (eta > 1)
        assert row["separation_fraction"] == pytest.approx(sep_fraction(eta), abs=TEST_QS_FRACTION_ATOL)
    # T = 0 exactly in separation, and the state says so
    open_ = r.N <= 0
    assert np.all(r.T[open_] == 0.0)
    assert np.array_equal(r.code == SEPARATION, open_)
    assert set(np.unique(r.code)) <= {STICK_SLIP, MACROSLIP, SEPARATION}
    assert np.all(np.abs(r.T) <= MU * np.maximum(r.N, 0) * (1 + 1e-9) + 1e-12)


def test_recontact_starts_virgin_curve_at_exact_instant():
    """After re-contact at x_c the closed form follows G_oa(q - q_c; alpha)."""
    r = harmonic_loop(law("iwan"), 0.5e-3, eta=1.2, delta_deg=0.0, cycles=2, steps_per_cycle=2000)
    rec = np.flatnonzero((r.N[:-1] == 0) & (r.N[1:] > 0))
    assert rec.size == 2
    for i in rec:
        xc = r.x[i]
        for j in range(i + 1, i + 20):
            q = KT * (r.x[j] - xc) / FY
            a = r.N[j] / N0
            u = abs(q)
            g = u - u * u / (4 * a) if u < 2 * a else a
            assert r.T[j] == pytest.approx(FY * math.copysign(g, q), rel=1e-9, abs=1e-12)


@pytest.mark.parametrize(
    "name, delta_deg, rtol",
    [
        ("iwan", 0.0, 1e-4),
        ("iwan-paper", 0.0, 1e-4),
        ("iwan-paper", 90.0, 1e-4),
        ("discrete", 0.0, 1e-4),
        ("discrete", 90.0, 1e-4),
        # the full-memory closed form restarts a branch where the clip lets go
        # after a reversal under falling N; that instant is located only to a
        # step, so this case converges at O(dt) (measured ~2e-4 at 500 -> 1000)
        ("iwan", 90.0, 1e-3),
    ],
)
def test_separation_converges_with_step(name, delta_deg, rtol):
    """With exact crossing instants the loop converges at O(dt^2): halving the
    step barely moves the energy (a separation smeared over a step would move
    it at O(dt))."""
    E = [
        harmonic_loop(law(name), 0.5e-3, eta=1.2, delta_deg=delta_deg, steps_per_cycle=s)
        .last_cycle()["energy_J"]
        for s in (500, 1000)
    ]
    assert abs(E[1] / E[0] - 1) < rtol


def test_discrete_matches_closed_form_at_constant_load_with_offset():
    a = harmonic_loop(Iwan(KT, MU, N0), 0.3e-3, x_offset=0.1e-3, steps_per_cycle=500).last_cycle()
    b = harmonic_loop(DiscreteIwan(KT, MU, N0, n=1000), 0.3e-3, x_offset=0.1e-3, steps_per_cycle=500).last_cycle()
    assert a["energy_J"] == pytest.approx(b["energy_J"], rel=TEST_ENERGY_RTOL)


# --- general histories ---------------------------------------------------------
def test_sampled_sign_change_inserts_crossing():
    t = np.array([0.0, 1.0, 2.0, 3.0])
    x = np.array([0.0, 1e-5, 2e-5, 3e-5])
    N = np.array([100.0, -100.0, -50.0, 150.0])
    r = quasistatic(law("iwan"), t, x, N)
    assert r.n_inserted == 2
    np.testing.assert_allclose(r.t, [0.0, 0.5, 1.0, 2.0, 2.25, 3.0])
    np.testing.assert_allclose(r.x, [0.0, 0.5e-5, 1e-5, 2e-5, 2.25e-5, 3e-5])
    assert r.n_cycles == 1 and r.period is None
    # N <= 0 on [0.5, 2.25] exactly
    assert r.last_cycle()["separation_fraction"] == pytest.approx(1.75 / 3.0, abs=TEST_QS_FRACTION_ATOL)
    # contact restarts at 2.25: virgin curve from x = 2.25e-5
    q = KT * 0.75e-5 / FY
    assert r.T[-1] == pytest.approx(FY * (q - q * q / (4 * 1.5)), rel=1e-12)


def test_period_windows_between_samples():
    """A steady loop has the same area over any window of one period."""
    t, x, N = harmonic_history(0.3e-3, 1.0, N0, cycles=4, steps_per_cycle=2000)
    shift = 0.1234567  # the history starts between grid samples, so do the windows
    keep = t > shift
    t = np.concatenate(([0.0], t[keep] - shift))
    x = np.concatenate(([0.3e-3 * math.sin(2 * math.pi * shift)], x[keep]))
    N = np.concatenate(([N0], N[keep]))
    assert not np.any(np.isin([1.0, 2.0, 3.0], t))
    r = quasistatic(law("iwan"), t, x, N, period=1.0)
    assert r.n_cycles == 3
    np.testing.assert_allclose(r.cycles["t_start_s"], [0.0, 1.0, 2.0], atol=1e-12)
    E = r.cycles["energy_J"].to_numpy()
    assert E[-1] == pytest.approx(energy_closed_form(0.3e-3), rel=TEST_ENERGY_RTOL)
    assert E[-1] == pytest.approx(E[-2], rel=1e-6)


def test_cycle_slice_covers_last_period():
    r = harmonic_loop(law("iwan"), 0.2e-3, cycles=3, steps_per_cycle=100)
    sl = r.cycle_slice(-1)
    assert r.t[sl][0] == pytest.approx(2.0) and r.t[sl][-1] == pytest.approx(3.0)
    assert len(r.t[sl]) == 101
    with pytest.raises(ValueError, match="cycle"):
        r.cycle_slice(3)
    assert list(r.state[:1]) == ["stick-slip"]


@pytest.mark.parametrize(
    "t, x, N, kw, name",
    [
        ([0, 1, 2], [0, 1e-5], [1, 1, 1], {}, "same length"),
        ([0, 1, 2], [0, np.nan, 1e-5], [1, 1, 1], {}, "x"),
        ([0, 1, 2], [0, 1e-5, 0], [1, np.inf, 1], {}, "N"),
        ([0, 2, 1], [0, 1e-5, 0], [1, 1, 1], {}, "t"),
        ([0, 1, 1], [0, 1e-5, 0], [1, 1, 1], {}, "t"),
        ([0], [0], [1], {}, "t"),
        ([0, 1, 2], [0, 1e-5, 0], [1, 1, 1], {"period": 0.0}, "period"),
        ([0, 1, 2], [0, 1e-5, 0], [1, 1, 1], {"period": 2.5}, "period"),
    ],
)
def test_quasistatic_validates(t, x, N, kw, name):
    with pytest.raises(ValueError, match=name):
        quasistatic(law("iwan"), t, x, N, **kw)


def test_quasistatic_rejects_non_law():
    with pytest.raises(ValueError, match="law"):
        quasistatic("iwan", [0, 1], [0, 1e-5], [1, 1])


# --- CSV ---------------------------------------------------------------------
def test_read_history_csv_roundtrip(tmp_path):
    t, x, N = harmonic_history(0.5e-3, 1.0, N0, eta=1.2, cycles=2, steps_per_cycle=200)
    p = tmp_path / "h.csv"
    pd.DataFrame({"N": N, "t": t, "x": x, "extra": 1}).to_csv(p, index=False, float_format="%.17g")
    t2, x2, N2 = read_history_csv(p)
    np.testing.assert_array_equal(t, t2)
    np.testing.assert_array_equal(x, x2)
    np.testing.assert_array_equal(N, N2)
    a = quasistatic(law("iwan"), t2, x2, N2, period=1.0).last_cycle()
    b = harmonic_loop(law("iwan"), 0.5e-3, eta=1.2, steps_per_cycle=200).last_cycle()
    assert a == pytest.approx(b, rel=1e-12)


@pytest.mark.parametrize(
    "text, name",
    [
        ("t,x\n0,0\n1,1e-5\n", "missing column N"),
        ("t,x,N\n0,0,1\n1,1e-5,1\n2,,\n", "line 4: x is empty"),
        ("t,x,N\n0,0,1\n1,,1\n2,0,1\n", "line 3: x is empty"),
        ("t,x,N\n0,0,1\n0,1e-5,1\n", "line 3: t must be strictly increasing"),
        ("t,x,N\n0,0,1\n1,nan,1\n", "line 3: x = 'nan' is not finite"),
        ("t,x,N\n0,0,1\n1,abc,1\n", "line 3: x = 'abc' is not a number"),
        ("t,x,N\n0,0,1\n", "at least 2"),
        ("", "no data"),
    ],
)
def test_read_history_csv_validates(tmp_path, text, name):
    p = tmp_path / "bad.csv"
    p.write_text(text)
    with pytest.raises(ValueError, match=name):
        read_history_csv(p)


def test_read_history_csv_missing_file(tmp_path):
    with pytest.raises(ValueError, match="path must be an existing file"):
        read_history_csv(tmp_path / "nope.csv")


def _branch_microslip_fractions(r):
    """Time fractions of stick-slip on the unloading and loading branches."""
    sl = r.cycle_slice(-1)
    dx = np.diff(r.x[sl])
    dt = np.diff(r.t[sl])
    cc = r.code[sl][1:]
    unl, lod = dx < 0, dx > 0
    return (
        np.sum(dt[unl & (cc == STICK_SLIP)]) / np.sum(dt[unl]),
        np.sum(dt[lod & (cc == STICK_SLIP)]) / np.sum(dt[lod]),
    )


@pytest.mark.parametrize("delta_deg, sign", [(0.0, +1), (90.0, -1)])
def test_paper_trends_of_state_regions(delta_deg, sign):
    """Paper section 2.2: in phase, as eta grows, the stick-slip part of the
    unloading branch grows and that of the loading branch shrinks (macroslip
    the other way round); out of phase (90 deg) the reverse."""
    fr = np.array([
        _branch_microslip_fractions(harmonic_loop(law("iwan"), 0.5e-3, eta=eta, delta_deg=delta_deg,
                                                  steps_per_cycle=1000))
        for eta in (0.0, 0.3, 0.6, 0.9)
    ])
    assert np.all(sign * np.diff(fr[:, 0]) > 0)  # unloading
    assert np.all(-sign * np.diff(fr[:, 1]) > 0)  # loading
