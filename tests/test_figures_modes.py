"""The nonlinear-mode figure (modes_backbones): its data and its files."""

import math

import numpy as np
import pandas as pd

from jointdyn.figures import figure_names, make_figure
from jointdyn.figures.modes import WEDGE_DEG, WEDGE_LABEL
from jointdyn.systems import PAPER


def test_modes_backbones_data_and_files(tmp_path):
    assert "modes_backbones" in figure_names()
    paths = make_figure("modes_backbones", tmp_path)
    df = pd.read_csv(tmp_path / "modes_backbones_backbones.csv")  # the data the picture was drawn from
    curves = {k: sub for k, sub in df.groupby(["model", "method"])}
    assert set(curves) == {("iwan", "epmc"), ("iwan", "qsma"), ("iwan-paper", "epmc"), ("jenkins", "epmc"),
                           (WEDGE_LABEL, "epmc")}
    wedge = curves.pop((WEDGE_LABEL, "epmc"))
    stuck = math.sqrt(1.0 + PAPER["kt"] / PAPER["k"])
    for sub in curves.values():
        assert (sub.status == "complete").all() and len(sub) >= 50
        q = sub.amplitude_q.values
        assert abs(q[0] / 1e-2 - 1) < 1e-9 and abs(q[-1] / 1e2 - 1) < 1e-9 and np.all(np.diff(q) > 0)
        # from the stuck mode down towards the slipping one (gamma = 1)
        assert abs(sub.gamma.values[0] / stuck - 1) < 1e-3 and 1.0 < sub.gamma.values[-1] < 1.01
    # at constant load the closed form's steady cycles are exact: the same backbone as the exact Iwan law
    a, b = curves[("iwan", "epmc")], curves[("iwan-paper", "epmc")]
    np.testing.assert_allclose(b.amplitude_q.values, a.amplitude_q.values, rtol=1e-12)
    np.testing.assert_allclose(b.gamma.values, a.gamma.values, rtol=1e-12)
    np.testing.assert_allclose(b.damping_ratio.values, a.damping_ratio.values, rtol=1e-9)
    assert {p.suffix for p in paths} >= {".png", ".csv"} and all(p.stat().st_size > 1000 for p in paths)
    # the wedge: stuck, the contact adds kt cos^2 and the closed spring kn sin^2 to k
    th = math.radians(WEDGE_DEG)
    wstuck = math.sqrt(1.0 + (PAPER["kt"] * math.cos(th) ** 2 + PAPER["kn"] * math.sin(th) ** 2) / PAPER["k"])
    assert (wedge.status == "complete").all() and len(wedge) >= 50
    assert abs(wedge.gamma.values[0] / wstuck - 1) < 1e-3
    # a normal load that grows with the motion keeps the friction force growing: at the largest amplitude
    # the damping ratio no longer falls like 1/amplitude as at constant load
    iwan = a.set_index("amplitude_q").damping_ratio
    assert wedge.damping_ratio.values[-1] > 1.5 * iwan.values[-1]
