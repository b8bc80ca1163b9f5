"""Quasi-static figures (fig2, fig3, fig4, fig4_discrete): data and files."""

import math

import numpy as np
import pytest

from tolerances import TEST_ENERGY_RTOL, TEST_QS_FRACTION_ATOL
from jointdyn.figures import FIGURES, figure_names, make_figure

QS_FIGS = ["fig2", "fig3", "fig4", "fig4_discrete"]


def test_registered():
    names = figure_names()
    assert set(QS_FIGS) <= set(names)


def test_fig2_two_kinds_of_loop():
    t = FIGURES["fig2"].compute()
    m = t["metrics"].set_index("amplitude_m")
    small, large = m.loc[0.1e-3], m.loc[0.5e-3]
    assert small["macroslip_fraction"] == 0.0 and large["macroslip_fraction"] > 0.0
    kt, fy = 1e5, 10.0
    assert small["energy_J"] == pytest.approx(kt**2 * 0.1e-3**3 / (3 * fy), rel=TEST_ENERGY_RTOL)
    assert large["energy_J"] == pytest.approx(4 * fy * 0.5e-3 - 16 * fy**2 / (3 * kt), rel=TEST_ENERGY_RTOL)


@pytest.mark.parametrize("name, delta", [("fig3", 0.0), ("fig4", 90.0)])
def test_fig3_fig4_tables(name, delta):
    t = FIGURES[name].compute()
    loops, m = t["loops"], t["metrics"]
    assert {"eta", "t", "x", "N", "T", "state", "model"} <= set(loops.columns)
    assert sorted(m["eta"]) == [0.0, 0.3, 0.6, 0.9, 1.2]
    assert (m["delta_deg"] == delta).all()
    for _, row in m.iterrows():
        eta = row["eta"]
        expected = 0.0 if eta <= 1 else (math.pi - 2 * math.asin(1 / eta)) / (2 * math.pi)
        assert row["separation_fraction"] == pytest.approx(expected, abs=TEST_QS_FRACTION_ATOL)
    # one steady cycle per eta, T = 0 where separated; peak force mu N0 (1 +
    # eta) in phase (macroslip at the largest load), at most that at 90 deg
    # (the exact law: elements re-stick while the load rises)
    for eta, g in loops.groupby("eta"):
        assert g["t"].max() - g["t"].min() == pytest.approx(1.0)
        assert np.all(g.loc[g["state"] == "separation", "T"] == 0.0)
        if delta == 0.0:
            assert g["T"].max() == pytest.approx(10.0 * (1 + eta), rel=1e-3)
        else:
            assert 0.99 * 10.0 * (1 + eta) <= g["T"].max() <= 10.0 * (1 + eta) * (1 + 1e-12)
    assert set(m["model"]) == {"iwan"}


def test_fig4_discrete_has_three_models():
    m = FIGURES["fig4_discrete"].compute()["metrics"]
    assert set(m["model"]) == {"iwan-closed", "iwan-paper", "discrete"}
    e = m.pivot(index="eta", columns="model", values="energy_J")
    # eta = 0: all agree with the closed form; eta > 0: the closed forms dissipate less
    assert e.loc[0.0, "iwan-closed"] == pytest.approx(e.loc[0.0, "discrete"], rel=TEST_ENERGY_RTOL)
    assert (e.loc[[0.3, 0.6, 0.9, 1.2], "iwan-paper"] < e.loc[[0.3, 0.6, 0.9, 1.2], "discrete"]).all()


def test_make_figure_writes_png(tmp_path):
    paths = make_figure("fig3", tmp_path)
    names = sorted(p.name for p in paths)
    assert names == ["fig3.png", "fig3.svg", "fig3_loops.csv", "fig3_metrics.csv"]
    assert (tmp_path / "fig3.png").read_bytes()[:4] == b"\x89PNG"
